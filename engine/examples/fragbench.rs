//! Times the engine alone on one model: loads an OBJ or glTF, renders it `FRAMES` times at
//! `W`x`H` from the `render` CLI's default camera (eye 0,0,3, fov-y 60) and prints the
//! median frame time and the last frame's counters. A quick loop for profiling the raster
//! and shade stages without building the demos (`perf record`, `valgrind --tool=callgrind`):
//!
//! `cargo run --release -p engine --example fragbench -- MODEL [W H FRAMES THREADS [peer]]`
//!
//! `peer` lights the scene as `../shared/peers/llvmpipe_textured.py` does (ambient 0.2, one
//! white light of 0.8 from (0.4, 0.8, 0.45), no highlights, the texture's bytes read as unorm).

use engine::{
    Camera, Encoding, FrameOptions, Light, Lighting, Renderer, Rgba, Shading, Target, Texture,
};
use glam::Vec3;
use std::path::Path;
use std::time::Instant;

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(path) = args.first() else {
        return Err("usage: fragbench MODEL [W H FRAMES THREADS [peer]]".into());
    };
    let num = |i: usize, d: usize| -> Result<usize, String> {
        args.get(i).map_or(Ok(d), |s| {
            s.parse().map_err(|e| format!("argument {i} ({s}): {e}"))
        })
    };
    let (w, h, frames, threads) = (num(1, 1280)?, num(2, 720)?, num(3, 20)?, num(4, 2)?);
    let mut scene = engine::load::model(Path::new(path))
        .map_err(|e| e.to_string())?
        .scene;
    if args.get(5).map(String::as_str) == Some("peer") {
        scene.lighting = Lighting {
            ambient: Rgba::new(0.2, 0.2, 0.2, 1.0),
            lights: vec![Light::Directional {
                direction: -Vec3::new(0.4, 0.8, 0.45),
                color: Rgba::new(0.8, 0.8, 0.8, 1.0),
            }],
        };
        for m in &mut scene.materials {
            if let Shading::Lit { specular, .. } = &mut m.shading {
                *specular = 0.0;
            }
            // The peer's texture is not sRGB: its bytes re-read as unorm, as `render
            // --peer-light` does.
            if let Some(t) = &m.base_texture {
                let l = &t.levels()[0];
                let unorm = Texture::from_packed(
                    l.width,
                    l.height,
                    l.texels.clone(),
                    Encoding::Unorm,
                    false,
                );
                m.base_texture = unorm.map(std::sync::Arc::new);
            }
        }
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| e.to_string())?;
    let camera = Camera::look_at(
        Vec3::new(0.0, 0.0, 3.0),
        Vec3::ZERO,
        Vec3::Y,
        60f32.to_radians(),
        w as f32 / h as f32,
    );
    let mut target = Target::new(w as u32, h as u32);
    let mut renderer = Renderer::new();
    let opts = FrameOptions::default();
    let mut times = Vec::new();
    let mut stats = Default::default();
    pool.install(|| {
        for _ in 0..frames + 2 {
            let t = Instant::now();
            stats = renderer.render_scene(&scene, &camera, &mut target, &opts);
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
    });
    let mut warm = times[2..].to_vec();
    warm.sort_by(f64::total_cmp);
    println!("{stats:?}");
    println!(
        "fragbench {w}x{h} threads={threads} median_ms={:.3} min_ms={:.3} frames={frames}",
        warm[warm.len() / 2],
        warm[0]
    );
    Ok(())
}
