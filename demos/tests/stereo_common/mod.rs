//! What the `stereo` end-to-end tests share: running the tool, the verged pair's scene
//! (textured cards), its cameras, renders and captures, and reading what it writes.
#![allow(dead_code)] // each test binary uses some of these

use engine::procedural::{self, XorShift};
use engine::{Camera, Draw, Encoding, Lighting, Material, Mesh, Rgba, Texture};
use glam::{Mat4, Vec3};
use ibr::capture::capture_batch;
use ibr::images::transforms::srgb8;
use ibr::images::DepthImage;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::Arc;

pub fn stereo(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_stereo"))
        .args(args)
        .output()
        .expect("run")
}

/// Runs `stereo` and fails the test with its stderr unless it succeeds.
pub fn stereo_ok(args: &[&str]) {
    let run = stereo(args);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

/// The verged pair's size.
pub const VW: u32 = 160;
pub const VH: u32 = 120;
/// Its cameras' vertical field of view (radians): a focal length of about 142 pixels.
pub const FOV_Y: f32 = 0.8;

/// A 256x256 texture of random grey levels in blocks of `cell` x `cell` texels.
pub fn noise(cell: usize) -> Arc<Texture> {
    let mut rng = XorShift::new(7);
    let n = 256 / cell;
    let cells: Vec<u8> = (0..n * n).map(|_| (rng.next_u64() % 256) as u8).collect();
    let px: Vec<u8> = (0..256 * 256)
        .flat_map(|i| {
            let v = cells[(i / 256 / cell) * n + (i % 256) / cell];
            [v, v, v, 255]
        })
        .collect();
    Arc::new(Texture::from_rgba8(256, 256, &px, Encoding::Srgb).expect("a texture"))
}

/// A textured wall 12 units across at z = 0, filling every view here, and a card 1.2
/// across 1.5 units in front of it; handed to `f` as draws.
pub fn with_scene<R>(f: impl FnOnce(&[Draw<'_>]) -> R) -> R {
    with_cards(
        &[(12.0, Vec3::ZERO, 2), (1.2, Vec3::new(0.5, 0.3, 1.5), 2)],
        f,
    )
}

/// Square cards facing +z, each `(size, centre, texture cell in texels)`, on nothing
/// (transparent where no card is); handed to `f` as draws.
pub fn with_cards<R>(cards: &[(f32, Vec3, usize)], f: impl FnOnce(&[Draw<'_>]) -> R) -> R {
    let placed: Vec<(f32, Mat4, usize)> = cards
        .iter()
        .map(|&(size, at, cell)| (size, Mat4::from_translation(at), cell))
        .collect();
    with_placed(&placed, f)
}

/// Square cards, each `(size, transform of a card facing +z at the origin, texture cell)`,
/// on nothing; handed to `f` as draws.
pub fn with_placed<R>(cards: &[(f32, Mat4, usize)], f: impl FnOnce(&[Draw<'_>]) -> R) -> R {
    let card = |size: f32, cell: usize| {
        let mut mesh = procedural::quad(size, size);
        mesh.colors.clear();
        let material = Material::unlit(Rgba::WHITE)
            .with_texture(noise(cell))
            .double_sided(true);
        (mesh, material)
    };
    let parts: Vec<((Mesh, Material), Mat4)> = cards
        .iter()
        .map(|&(size, transform, cell)| (card(size, cell), transform))
        .collect();
    let draws: Vec<Draw<'_>> = parts
        .iter()
        .map(|((mesh, material), transform)| Draw {
            mesh,
            material,
            transform: *transform,
        })
        .collect();
    f(&draws)
}

/// A camera of the pair's size and field of view at `eye` looking at `target`.
pub fn camera(eye: Vec3, target: Vec3, up: Vec3) -> Camera {
    Camera::look_at(eye, target, up, FOV_Y, VW as f32 / VH as f32).with_depth_range(0.1, 50.0)
}

/// The scene seen from `cameras`.
pub fn render(cameras: &[Camera]) -> Vec<DepthImage> {
    with_scene(|draws| capture_batch(draws, cameras, &Lighting::default(), VW, VH))
}

/// The scene seen from `cameras`, written in `dir` as photographs with their cameras: PNGs
/// and a hand-written `transforms.json` (camera to world, OpenGL axes, no depth maps).
pub fn write_capture(dir: &Path, cameras: &[Camera]) -> PathBuf {
    write_images(dir, &render(cameras))
}

/// `images` written in `dir` as [`write_capture`] writes them.
pub fn write_images(dir: &Path, images: &[DepthImage]) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let (w, h) = (images[0].width(), images[0].height());
    let focal = 0.5 * h as f32 / (0.5 * FOV_Y).tan();
    let mut frames = Vec::new();
    for (i, image) in images.iter().enumerate() {
        let name = format!("view{i}.png");
        engine::load::write_png_rgba8(&dir.join(&name), w, h, &srgb8(image)).unwrap();
        let c2w = image.camera.view.inverse();
        // The last row exact, as a tool writing its poses in double precision has it.
        let rows: Vec<String> = (0..3)
            .map(|r| {
                let v = c2w.row(r);
                format!("[{}, {}, {}, {}]", v.x, v.y, v.z, v.w)
            })
            .chain(["[0, 0, 0, 1]".to_string()])
            .collect();
        frames.push(format!(
            "{{\"file_path\": \"{name}\", \"transform_matrix\": [{}]}}",
            rows.join(", ")
        ));
    }
    let json = dir.join("transforms.json");
    std::fs::write(
        &json,
        format!(
            "{{\"fl_x\": {focal}, \"fl_y\": {focal}, \"frames\": [{}]}}",
            frames.join(", ")
        ),
    )
    .unwrap();
    json
}

/// The verged pair: eyes 0.4 apart (the right one a little higher and rolled), each
/// turned about 4 degrees toward the other, looking at a point 1 unit in front of the wall.
pub fn verged() -> [Camera; 2] {
    let target = Vec3::new(0.0, 0.0, 1.0);
    [
        camera(Vec3::new(-0.2, 0.0, 4.0), target, Vec3::Y),
        camera(Vec3::new(0.2, 0.03, 4.0), target, Vec3::new(0.03, 1.0, 0.0)),
    ]
}

pub fn pfm(path: &Path) -> engine::load::FloatImage {
    engine::load::parse_pfm(&std::fs::read(path).unwrap()).expect("a PFM")
}

/// Asserts that `run` failed with exit code 1 and one line on stderr holding each of
/// `words`.
pub fn fails_with(run: &Output, words: &[&str]) {
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    for w in words {
        assert!(err.contains(w), "no {w:?} in {err}");
    }
}

/// `stereo`'s stdout, failing the test with its stderr unless it succeeds; and its stderr.
pub fn stereo_out(args: &[&str]) -> (String, String) {
    let run = stereo(args);
    let err = String::from_utf8_lossy(&run.stderr).into_owned();
    assert!(run.status.success(), "{err}");
    (String::from_utf8_lossy(&run.stdout).into_owned(), err)
}
