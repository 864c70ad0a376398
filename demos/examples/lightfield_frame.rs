//! Times a light-field frame: a lit torus captured into a 32 x 32 (uv) by 256 x 256 (st)
//! slab, then rendered at 1280x720 from an eye between the capture cameras, the slab
//! filling most of the frame, by each lookup; prints capture time, frame times and the
//! pixels and samples read:
//! `cargo run --release -p demos --example lightfield_frame`.
//! Wall-clock figures from a shared machine.

use engine::{procedural, Camera, Draw, Light, Lighting, Material, Rgba};
use glam::{Mat4, Vec3};
use ibr::lightfield::{render, Interpolation, LightField, Lookup, Rect3, Slab};
use ibr::warp::Warped;
use std::time::Instant;

fn main() {
    let mesh = procedural::torus(0.7, 0.3, 96, 48);
    let mat = Material::lit(Rgba::new(0.8, 0.5, 0.3, 1.0));
    let draws = [Draw {
        mesh: &mesh,
        material: &mat,
        transform: Mat4::from_rotation_x(1.0),
    }];
    let lighting = Lighting {
        ambient: Rgba::new(0.3, 0.3, 0.3, 1.0),
        lights: vec![Light::Directional {
            direction: Vec3::new(-0.4, -1.0, -0.6).normalize(),
            color: Rgba::new(0.9, 0.9, 0.9, 1.0),
        }],
    };
    let square = |z: f32, size: f32| {
        Rect3::centered(Vec3::new(0.0, 0.0, z), Vec3::X * size, Vec3::NEG_Y * size)
    };
    let slab = Slab::new(
        square(4.0, 2.0),
        square(0.0, 2.4),
        [32, 32, 256, 256],
        0.5,
        20.0,
    )
    .expect("slab");
    let start = Instant::now();
    let lf = LightField::capture(&draws, &lighting, slab);
    println!(
        "capture: 32x32 views of 256x256 ({} samples) in {:.2} s on {} threads",
        lf.samples.len(),
        start.elapsed().as_secs_f64(),
        rayon::current_num_threads()
    );
    let (w, h) = (1280, 720);
    let eye = Vec3::new(0.13, -0.07, 4.0);
    let camera = Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 0.62, w as f32 / h as f32)
        .with_depth_range(0.1, 30.0);
    let mut out = Warped::new(0, 0, camera);
    for (name, interpolation, depth_correction) in [
        ("nearest", Interpolation::Nearest, false),
        ("bilinear uv", Interpolation::BilinearUv, false),
        ("quadrilinear", Interpolation::Quadrilinear, false),
        (
            "quadrilinear, depth-corrected",
            Interpolation::Quadrilinear,
            true,
        ),
    ] {
        let lookup = Lookup {
            interpolation,
            depth_correction,
        };
        let mut best = f64::INFINITY;
        let mut frame = Default::default();
        for _ in 0..8 {
            let t = Instant::now();
            frame = render(&lf, &camera, w, h, lookup, &mut out);
            best = best.min(t.elapsed().as_secs_f64());
        }
        println!("{name:32} {:7.2} ms (best of 8)  {frame:?}", best * 1e3);
    }
}
