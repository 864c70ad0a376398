//! The showcase's light-field statue alone beside its geometry from four eyes (front,
//! side, back, above), written to `DIR/<eye>_truth.png` and `DIR/<eye>_lf.png` with the
//! error of each, and the start-up costs:
//! `cargo run --release -p demos --example statue -- [DIR] [--raw] [--no-depth-correction]`
//! (`--raw`: the unquantised capture instead of the codebook).

use demos::showcase::lightfield::{urn, Statue, ST, STATUE_AT, UV};
use engine::{Camera, FrameOptions, Light, Lighting, Renderer, Rgba, Target};
use glam::Vec3;
use ibr::lightfield::{LightField, LightFieldObject, Slab};
use ibr::subject::Subject;
use ibr::technique::{FrameLoop, FrameView, Technique};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let flag = |f: &str| args.iter().any(|a| a == f);
    let dir = args
        .iter()
        .find(|a| !a.starts_with("--"))
        .cloned()
        .unwrap_or_else(|| "out/statue".into());
    std::fs::create_dir_all(&dir).expect("an output folder");
    let lighting = Lighting {
        ambient: Rgba::new(0.3, 0.3, 0.32, 1.0),
        lights: vec![Light::Directional {
            direction: Vec3::new(-0.4, -1.0, -0.5).normalize(),
            color: Rgba::new(0.9, 0.88, 0.8, 1.0),
        }],
    };
    let mut statue = Statue::new(&lighting);
    println!(
        "captured in {:.2} s, quantised in {:.2} s: {:.2} MB held, {:.1} MB raw ({:.0}:1)",
        statue.capture.as_secs_f64(),
        statue.quantise.as_secs_f64(),
        statue.bytes() as f64 / 1e6,
        statue.raw_bytes as f64 / 1e6,
        statue.ratio()
    );
    let geometry = urn(STATUE_AT);
    let bounds = geometry.bounds();
    if flag("--raw") {
        let mut draws = Vec::new();
        geometry.draws(&mut draws);
        let slabs = Slab::cube(bounds.center, bounds.radius, [UV, UV, ST, ST]).expect("slabs");
        let raw = slabs
            .iter()
            .filter(|s| s.forward().y < 0.5)
            .map(|s| LightField::capture(&draws, &statue.lighting, *s))
            .collect();
        let mut object = LightFieldObject::with_slabs("raw statue", raw, bounds);
        object.reference = Some(urn(STATUE_AT));
        statue.object = object;
    }
    statue.object.lookup.depth_correction = !flag("--no-depth-correction");
    let (w, h) = (240, 180);
    let mut renderer = Renderer::new();
    let mut frames = FrameLoop::new();
    let opts = FrameOptions {
        clear: Some(Rgba::new(0.2, 0.2, 0.25, 1.0)),
        ..Default::default()
    };
    let eyes = [
        ("front", Vec3::new(0.0, 3.6, 14.4)),
        ("side", Vec3::new(-10.8, 4.8, 7.2)),
        ("back", Vec3::new(9.6, 7.2, -2.4)),
        ("above", Vec3::new(1.2, 14.4, 3.6)),
    ];
    for (name, offset) in eyes {
        let cam = Camera::look_at(STATUE_AT + offset, bounds.center, Vec3::Y, 0.5, 1.0)
            .with_aspect(w, h)
            .with_depth_range(0.1, 100.0);
        let view = FrameView::still(&cam, w, h, &statue.lighting);
        let mut truth = Target::new(w, h);
        let mut draws = Vec::new();
        geometry.draws(&mut draws);
        frames.render(&mut renderer, draws, &mut [], &view, &mut truth, &opts);
        let mut image = Target::new(w, h);
        let mut list: [&mut dyn Technique; 1] = [&mut statue.object];
        frames.render(&mut renderer, [], &mut list, &view, &mut image, &opts);
        let e = statue.measure(&cam, w, h);
        println!(
            "{name:>5}: {:?}, {}",
            statue.object.showing(),
            e.map_or("not measured".into(), |e| format!(
                "PSNR {:.1} dB against the geometry",
                e.psnr_db
            ))
        );
        for (kind, t) in [("truth", &truth), ("lf", &image)] {
            let path = format!("{dir}/{name}_{kind}.png");
            image::save_buffer(&path, &t.to_rgba8(), w, h, image::ColorType::Rgba8)
                .expect("a writable output folder");
        }
    }
}
