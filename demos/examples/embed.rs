//! Embedding Parallax in a game: a glTF model, tower blocks the planner draws as geometry or
//! impostors under an error budget, a billboard forest and a sun flare, in one frame loop into
//! a `minifb` window, or headless to a PNG. `cargo run --release -p demos --example embed --
//! [--headless OUT.png] [--frames N] [--model FILE.gltf]`

use engine::procedural::{self, TreeKind, XorShift};
use engine::{load, AlphaMode, Camera, FrameOptions, Lighting, Material, Renderer, Rgba, Target};
use glam::{Mat4, Vec2, Vec3};
use ibr::flare::{FlareSource, LensFlare};
use ibr::impostor::{self, ImpostorSet};
use ibr::plan::{self, Geometry, Planner, Representation};
use ibr::subject::MeshGroup;
use ibr::technique::{Flare, FrameLoop, FrameView, Technique};
use ibr::{sprites, Billboard, BillboardBatch, Facing};
use minifb::{Key, Window};
use std::{f32::consts::TAU, path::Path, sync::Arc, time::Instant};

const SAMPLE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../assets/models/sample.gltf");

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    // `--flag value`: Some(Some(value)), `--flag` alone: Some(None).
    let arg = |name: &str| {
        let value = |i: usize| args.get(i + 1).filter(|v| !v.starts_with("--"));
        args.iter().position(|a| a == name).map(value)
    };
    let frames: usize = arg("--frames").flatten().map_or(Ok(60), |n| n.parse())?;
    let (w, h) = (960, 540);

    // The scene: a glTF model (the project's sample unless --model), on grass, in sunlight.
    let loaded = load::model(Path::new(arg("--model").flatten().map_or(SAMPLE, |m| m)))?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    let mut scene = loaded.scene;
    for instance in &mut scene.instances {
        instance.transform = Mat4::from_translation(Vec3::Y) * instance.transform;
    }
    let to_sun = Vec3::new(-0.6, 0.4, -1.0).normalize();
    scene.lighting = Lighting::white_sun(0.35, -to_sun);
    let grass = Material::lit(Rgba::new(0.25, 0.45, 0.2, 1.0));
    scene.add(procedural::plane(80.0, 80.0, 8, 8), grass, Mat4::IDENTITY);

    // A few tower blocks (2,560 triangles each), each drawn as its geometry or a runtime
    // impostor: the planner takes the cheaper whose predicted error is within 2 levels.
    let mut rng = XorShift::new(7);
    let mut towers = Vec::new();
    for i in 0..6 {
        let size = Vec3::new(2.5, rng.range(2.5, 5.0), 2.5);
        let wall = Rgba::new(rng.range(0.4, 0.8), 0.5, 0.4, 1.0);
        let (mesh, white) = (
            demos::city::building(size, 16, wall),
            Material::lit(Rgba::WHITE),
        );
        let at = Vec3::new(4.0 * i as f32 - 10.0, 0.0, -9.0 - rng.range(0.0, 4.0));
        let at = Mat4::from_translation(at);
        towers.push(MeshGroup::new().with(Arc::new(mesh), Arc::new(white), at));
    }
    let impostors = ImpostorSet::new(impostor::Config::default(), towers.len());
    let reps: Vec<Box<dyn Representation<MeshGroup>>> =
        vec![Box::new(Geometry), Box::new(impostors)];
    let mut config = plan::Config::default();
    config.budgets.error = 2.0;
    let mut planner = Planner::new(config, towers, reps);

    // A billboard forest: a pine baked once into a sprite, 300 upright quads facing the eye.
    let pine = procedural::tree(TreeKind::Pine, 1.0, 1);
    let lit = Material::lit(Rgba::WHITE);
    let sprite = sprites::bake_upright(&pine, &lit, &scene.lighting, Vec3::X, 96);
    let mut leaves = Material::unlit(Rgba::WHITE).with_texture(sprite.texture.clone());
    leaves.alpha_mode = AlphaMode::Dither;
    let mut forest = BillboardBatch::new(leaves);
    while forest.items.len() < 300 {
        let (a, r) = (rng.range(0.0, TAU), rng.range(12.0, 35.0));
        let size = Vec2::new(sprite.size.x / sprite.size.y, 1.0) * rng.range(2.5, 5.0);
        let at = Vec3::new(r * a.cos(), 0.0, r * a.sin());
        let mut tree = Billboard::new(at, Facing::UPRIGHT, size);
        (tree.pivot, tree.region) = (sprite.pivot, sprite.side);
        forest.push(tree);
    }

    // A lens flare on the sun, dimmed by whatever is drawn in front of it.
    let (lens, source) = (LensFlare::default(), FlareSource::Directional(to_sun));
    let mut flare = Flare { lens, source };

    // The frame loop: each frame every technique prepares, adds its draws to the scene's,
    // runs its image passes and observes the finished frame.
    let mut window = match arg("--headless") {
        Some(_) => None,
        None => Window::new("Parallax embed", w as usize, h as usize, Default::default())
            .map_err(|e| eprintln!("no window ({e}): {frames} frames headless"))
            .ok(),
    };
    let (mut renderer, mut frame) = (Renderer::new(), FrameLoop::new());
    let mut target = Target::new(w, h);
    let sky = Some(Rgba::new(0.45, 0.65, 0.9, 1.0));
    let opts = FrameOptions {
        clear: sky,
        ..FrameOptions::default()
    };
    let (start, mut last, mut times, mut pixels) = (Instant::now(), 0.0, Vec::new(), Vec::new());
    for n in 1.. {
        let t = window
            .as_ref()
            .map_or(n as f32 / 30.0, |_| start.elapsed().as_secs_f32());
        let eye = Vec3::new(4.0 * (0.15 * t).sin(), 1.6, 6.0 + (0.1 * t).cos());
        let camera = Camera::look_at(eye, Vec3::new(0.0, 1.2, -2.0), Vec3::Y, 1.05, 1.0)
            .with_aspect(w, h)
            .with_depth_range(0.1, 200.0);
        let mut view = FrameView::still(&camera, w, h, &scene.lighting);
        (view.time, view.dt, last) = (t, t - last, t);
        let mut techniques: [&mut dyn Technique; 3] = [&mut planner, &mut forest, &mut flare];
        let (r, draws) = (&mut renderer, scene.draws());
        frame.render(r, draws, &mut techniques, &view, &mut target, &opts);
        times.push(frame.times.total.as_secs_f64() * 1e3);
        match window.as_mut() {
            Some(win) if win.is_open() && !win.is_key_down(Key::Escape) => {
                target.write_rgb_u32(&mut pixels);
                win.update_with_buffer(&pixels, w as usize, h as usize)?;
            }
            None if n < frames => {}
            _ => break,
        }
    }

    // Headless: the last frame as a PNG, and the median frame time.
    if window.is_none() {
        let out = arg("--headless").flatten().map_or("embed.png", |o| o);
        load::write_png_rgba8(Path::new(out), w, h, &target.to_rgba8())?;
        times.sort_by(f64::total_cmp);
        let (median, counts) = (times[times.len() / 2], &planner.report.counts);
        println!("{out}: median {median:.1} ms a frame; towers by geometry, impostor: {counts:?}");
    }
    Ok(())
}
