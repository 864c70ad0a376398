//! `stereo` end to end on a random-dot stereogram whose disparities are known by
//! construction: a square at disparity 10 over a background at 4; and, with `--cameras`,
//! on a verged pair the engine renders (two views turned toward each other, not rectified),
//! whose depth is checked against a render of the scene from the camera `stereo` writes;
//! bad captures and cameras that cannot be rectified are one-line errors.

use engine::procedural::{self, XorShift};
use engine::{Camera, Draw, Encoding, Lighting, Material, Mesh, Projection, Rgba, Texture};
use glam::{Mat4, Vec3};
use ibr::capture::capture_batch;
use ibr::images::transforms::{read_transforms, srgb8};
use ibr::images::DepthImage;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::Arc;

mod common;
use common::Tmp;

const W: usize = 96;
const H: usize = 64;

fn stereo(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_stereo"))
        .args(args)
        .output()
        .expect("run")
}

/// Runs `stereo` and fails the test with its stderr unless it succeeds.
fn stereo_ok(args: &[&str]) {
    let run = stereo(args);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

/// Random grey levels in 2x2 blocks (a fixed linear congruential sequence).
fn dots(seed: u64) -> Vec<u8> {
    let mut s = seed;
    let mut next = || {
        s = s
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (s >> 56) as u8
    };
    let cells: Vec<u8> = (0..(W / 2) * (H / 2)).map(|_| next()).collect();
    (0..W * H)
        .map(|i| cells[(i / W / 2) * (W / 2) + (i % W) / 2])
        .collect()
}

/// The square's pixels (in the left image).
fn in_square(x: usize, y: usize) -> bool {
    (36..68).contains(&x) && (16..48).contains(&y)
}

fn write_grey(path: &Path, grey: &[u8]) {
    let rgba: Vec<u8> = grey.iter().flat_map(|&g| [g, g, g, 255]).collect();
    image::save_buffer(path, &rgba, W as u32, H as u32, image::ColorType::Rgba8).unwrap();
}

#[test]
fn a_random_dot_pair_gives_its_disparities_and_depth() {
    let tmp = Tmp::new("stereo-cli", "dots");
    let left = dots(1);
    // The right image: fresh dots where nothing lands, then the background shifted by 4
    // and the square, in front, by 10 (right pixel x - d shows left pixel x).
    let mut right = dots(2);
    for pass in [false, true] {
        for y in 0..H {
            for x in 0..W {
                if in_square(x, y) == pass {
                    let d = if pass { 10 } else { 4 };
                    if x >= d {
                        right[y * W + x - d] = left[y * W + x];
                    }
                }
            }
        }
    }
    let (lp, rp) = (tmp.path("left.png"), tmp.path("right.png"));
    write_grey(&lp, &left);
    write_grey(&rp, &right);
    let out = tmp.path("out");
    stereo_ok(&[
        "--left",
        lp.to_str().unwrap(),
        "--right",
        rp.to_str().unwrap(),
        "--max-disparity",
        "16",
        "--focal-px",
        "100",
        "--baseline",
        "0.5",
        "--out",
        out.to_str().unwrap(),
    ]);
    let read = |name: &str| {
        engine::load::parse_pfm(&std::fs::read(out.join(name)).unwrap()).expect("a PFM")
    };
    let (d, z) = (read("disparity.pfm"), read("depth.pfm"));
    assert_eq!((d.width, d.height), (W as u32, H as u32));
    // Inside the square and on the background away from edges: right to within a pixel.
    let (mut right_px, mut total) = (0, 0);
    for y in 6..H - 6 {
        for x in 20..W - 6 {
            let near_edge = (30..74).contains(&x) && (10..54).contains(&y) && !in_square(x, y)
                || in_square(x, y) && !(42..62).contains(&x);
            if near_edge || !(22..42).contains(&y) && in_square(x, y) {
                continue;
            }
            let want = if in_square(x, y) { 10.0 } else { 4.0 };
            total += 1;
            right_px += ((d.data[y * W + x] - want).abs() <= 1.0) as u32;
        }
    }
    assert!(
        total > 2000 && right_px * 10 >= total * 9,
        "{right_px} of {total}"
    );
    // Depth fx b / d at the square's centre: 100 x 0.5 / 10.
    let c = 32 * W + 52;
    assert!((z.data[c] - 5.0).abs() < 0.5, "{}", z.data[c]);
    assert!(out.join("disparity.png").exists());
    // The left view with its camera, as a capture the warp command takes: a new view a
    // little to the right (depth 5 at the square, 12.5 behind it).
    let json = out.join("transforms.json");
    assert!(json.exists(), "a depth image with its camera");
    let view = tmp.path("view.png");
    let warp = Command::new(env!("CARGO_BIN_EXE_warp"))
        .args(["--capture", json.to_str().unwrap(), "--eye", "0.1,0,0"])
        .args([
            "--target", "0.1,0,-1", "--fov-y", "35.5", "-W", "96", "-H", "64",
        ])
        .args(["--png", view.to_str().unwrap()])
        .output()
        .expect("run warp");
    assert!(
        warp.status.success(),
        "{}",
        String::from_utf8_lossy(&warp.stderr)
    );
    let img = image::open(&view).unwrap().to_rgba8();
    assert_eq!(img.dimensions(), (W as u32, H as u32));
    assert!(img.pixels().filter(|p| p[3] > 0).count() > W * H / 2);
}

#[test]
fn images_of_different_sizes_are_one_line_naming_both() {
    let tmp = Tmp::new("stereo-cli", "sizes");
    let (lp, rp) = (tmp.path("a.png"), tmp.path("b.png"));
    write_grey(&lp, &dots(1));
    image::save_buffer(&rp, &[0u8; 4 * 8 * 8], 8, 8, image::ColorType::Rgba8).unwrap();
    let run = stereo(&[
        "--left",
        lp.to_str().unwrap(),
        "--right",
        rp.to_str().unwrap(),
        "--out",
        tmp.path("o").to_str().unwrap(),
    ]);
    assert!(!run.status.success());
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("a.png") && err.contains("b.png") && err.contains("96x64"),
        "{err}"
    );
    let missing = stereo(&["--left", "nope.png", "--right", "nope.png", "--out", "o"]);
    assert!(!missing.status.success());
    assert!(String::from_utf8_lossy(&missing.stderr).contains("nope.png"));
}

/// The verged pair's size.
const VW: u32 = 160;
const VH: u32 = 120;
/// Its cameras' vertical field of view (radians): a focal length of about 142 pixels.
const FOV_Y: f32 = 0.8;

/// A 256x256 texture of random grey levels in blocks of 2x2 texels.
fn noise() -> Arc<Texture> {
    let mut rng = XorShift::new(7);
    let cells: Vec<u8> = (0..128 * 128)
        .map(|_| (rng.next_u64() % 256) as u8)
        .collect();
    let px: Vec<u8> = (0..256 * 256)
        .flat_map(|i| {
            let v = cells[(i / 256 / 2) * 128 + (i % 256) / 2];
            [v, v, v, 255]
        })
        .collect();
    Arc::new(Texture::from_rgba8(256, 256, &px, Encoding::Srgb).expect("a texture"))
}

/// A textured wall 12 units across at z = 0, filling every view here, and a card 1.2
/// across 1.5 units in front of it; handed to `f` as draws.
fn with_scene<R>(f: impl FnOnce(&[Draw<'_>]) -> R) -> R {
    let texture = noise();
    let card = |size: f32| {
        let mut mesh = procedural::quad(size, size);
        mesh.colors.clear();
        let material = Material::unlit(Rgba::WHITE)
            .with_texture(texture.clone())
            .double_sided(true);
        (mesh, material)
    };
    let parts: Vec<((Mesh, Material), Mat4)> = vec![
        (card(12.0), Mat4::IDENTITY),
        (card(1.2), Mat4::from_translation(Vec3::new(0.5, 0.3, 1.5))),
    ];
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
fn camera(eye: Vec3, target: Vec3, up: Vec3) -> Camera {
    Camera::look_at(eye, target, up, FOV_Y, VW as f32 / VH as f32).with_depth_range(0.1, 50.0)
}

/// The scene seen from `cameras`.
fn render(cameras: &[Camera]) -> Vec<DepthImage> {
    with_scene(|draws| capture_batch(draws, cameras, &Lighting::default(), VW, VH))
}

/// The scene seen from `cameras`, written in `dir` as photographs with their cameras: PNGs
/// and a hand-written `transforms.json` (camera to world, OpenGL axes, no depth maps).
fn write_capture(dir: &Path, cameras: &[Camera]) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let focal = 0.5 * VH as f32 / (0.5 * FOV_Y).tan();
    let mut frames = Vec::new();
    for (i, image) in render(cameras).iter().enumerate() {
        let name = format!("view{i}.png");
        engine::load::write_png_rgba8(&dir.join(&name), VW, VH, &srgb8(image)).unwrap();
        let c2w = image.camera.view.inverse();
        let rows: Vec<String> = (0..4)
            .map(|r| {
                let v = c2w.row(r);
                format!("[{}, {}, {}, {}]", v.x, v.y, v.z, v.w)
            })
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
fn verged() -> [Camera; 2] {
    let target = Vec3::new(0.0, 0.0, 1.0);
    [
        camera(Vec3::new(-0.2, 0.0, 4.0), target, Vec3::Y),
        camera(Vec3::new(0.2, 0.03, 4.0), target, Vec3::new(0.03, 1.0, 0.0)),
    ]
}

fn pfm(path: &Path) -> engine::load::FloatImage {
    engine::load::parse_pfm(&std::fs::read(path).unwrap()).expect("a PFM")
}

#[test]
fn a_verged_pair_is_rectified_matched_and_placed_in_the_scene() {
    let tmp = Tmp::new("stereo-cli", "verged");
    let [left, right] = verged();
    let turn = left.forward().angle_between(right.forward()).to_degrees();
    assert!(
        turn > 7.0,
        "the views are {turn} degrees apart: not rectified"
    );
    let json = write_capture(&tmp.path("cap"), &[left, right]);
    let out = tmp.path("out");
    stereo_ok(&[
        "--cameras",
        json.to_str().unwrap(),
        "--max-disparity",
        "32",
        "--out",
        out.to_str().unwrap(),
    ]);
    let (d, z) = (pfm(&out.join("disparity.pfm")), pfm(&out.join("depth.pfm")));
    assert_eq!((d.width, d.height), (VW, VH), "the rectified size");
    assert_eq!((z.width, z.height), (VW, VH));
    assert!(out.join("disparity.png").exists());

    // The depth image: the rectified left camera where the left eye is.
    let written = read_transforms(&out.join("transforms.json")).expect("a capture");
    assert_eq!(written.len(), 1);
    let view = &written[0];
    let eye = view.camera.eye();
    assert!(
        eye.distance(left.eye()) < 1e-3,
        "eye {eye} not {}",
        left.eye()
    );
    let facing = view.camera.forward();
    assert!(
        facing.dot(Vec3::NEG_Z) > 0.999,
        "rectified toward the wall: {facing}"
    );
    assert!(facing.angle_between(left.forward()) > 0.03, "turned");

    // Turned, the rectified view sees a strip the original did not: unknown there.
    let n = (VW * VH) as usize;
    let outside: Vec<usize> = (0..n).filter(|&i| view.color[i].a <= 0.0).collect();
    assert!(
        outside.len() >= 4 * VH as usize,
        "{} outside",
        outside.len()
    );
    for &i in &outside {
        assert!(
            d.data[i] == f32::INFINITY
                && z.data[i] == f32::INFINITY
                && view.depth[i] == f32::INFINITY,
            "pixel {i} outside the original has disparity {} and depth {}",
            d.data[i],
            z.data[i]
        );
    }
    // A clear majority of what the view sees (all of it textured) is matched.
    let inside = n - outside.len();
    let matched: Vec<usize> = (0..n).filter(|&i| d.data[i].is_finite()).collect();
    assert!(
        matched.len() * 10 >= inside * 8,
        "{} of {inside} matched",
        matched.len()
    );
    assert!(matched.iter().all(|&i| z.data[i] == view.depth[i]));

    // Its depth against the scene rendered from the written camera (measured: 94% of the
    // matched pixels within 3%, the median error 1%).
    let truth = &render(&[view.camera])[0];
    let mut errors: Vec<f32> = matched
        .iter()
        .map(|&i| (z.data[i] - truth.depth[i]).abs() / truth.depth[i])
        .collect();
    errors.sort_by(f32::total_cmp);
    let close = errors.iter().filter(|&&e| e <= 0.03).count();
    assert!(
        close * 10 >= matched.len() * 8,
        "{close} of {} within 3% of the true depth",
        matched.len()
    );
    let median = errors[errors.len() / 2];
    assert!(median < 0.02, "median depth error {median}");

    // A new view from between the eyes, in the scene's coordinates, by the 3D warp: its
    // depth agrees with a render from there.
    let depth_out = tmp.path("view.pfm");
    let fov_deg = FOV_Y.to_degrees().to_string();
    let warp = Command::new(env!("CARGO_BIN_EXE_warp"))
        .args(["--capture", out.to_str().unwrap(), "--eye", "0,0,4"])
        .args([
            "--target", "0,0,1", "--fov-y", &fov_deg, "-W", "160", "-H", "120",
        ])
        .args([
            "--fill",
            "none",
            "--png",
            tmp.path("view.png").to_str().unwrap(),
        ])
        .args(["--depth-out", depth_out.to_str().unwrap()])
        .output()
        .expect("run warp");
    assert!(
        warp.status.success(),
        "{}",
        String::from_utf8_lossy(&warp.stderr)
    );
    let warped = pfm(&depth_out);
    let middle = Camera {
        view: Mat4::look_at_rh(Vec3::new(0.0, 0.0, 4.0), Vec3::new(0.0, 0.0, 1.0), Vec3::Y),
        projection: Projection::Perspective {
            fov_y: FOV_Y,
            aspect: VW as f32 / VH as f32,
            near: 0.1,
            far: 100.0,
        },
    };
    let truth = &render(&[middle])[0];
    let landed: Vec<usize> = (0..n).filter(|&i| warped.data[i].is_finite()).collect();
    let agree = landed
        .iter()
        .filter(|&&i| (warped.data[i] - truth.depth[i]).abs() <= 0.05 * truth.depth[i])
        .count();
    assert!(
        landed.len() * 2 >= n,
        "{} of {n} pixels warped",
        landed.len()
    );
    assert!(
        agree * 10 >= landed.len() * 9,
        "{agree} of {} warped pixels within 5% of the true depth",
        landed.len()
    );
}

/// Asserts that `run` failed with exit code 1 and one line on stderr holding each of
/// `words`.
fn fails_with(run: &Output, words: &[&str]) {
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    for w in words {
        assert!(err.contains(w), "no {w:?} in {err}");
    }
}

#[test]
fn captures_that_are_not_a_pair_or_cannot_be_rectified_are_one_line_errors() {
    let tmp = Tmp::new("stereo-cli", "bad-captures");
    let out = tmp.path("out");
    let with = |json: &Path| {
        stereo(&[
            "--cameras",
            json.to_str().unwrap(),
            "--max-disparity",
            "16",
            "--out",
            out.to_str().unwrap(),
        ])
    };
    let [left, right] = verged();
    let third = camera(Vec3::new(0.6, 0.0, 4.0), Vec3::ZERO, Vec3::Y);
    let three = write_capture(&tmp.path("three"), &[left, right, third]);
    fails_with(&with(&three), &["3 frames", "exactly 2"]);
    // The right eye straight ahead of the left: motion toward the scene.
    let along = write_capture(
        &tmp.path("along"),
        &[
            camera(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y),
            camera(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y),
        ],
    );
    fails_with(
        &with(&along),
        &["cannot rectify", "baseline", "view direction"],
    );
    // Views of two sizes.
    let sizes = write_capture(&tmp.path("sizes"), &[left, right]);
    image::save_buffer(
        tmp.path("sizes").join("view1.png"),
        &[128u8; 4 * 80 * 60],
        80,
        60,
        image::ColorType::Rgba8,
    )
    .unwrap();
    fails_with(&with(&sizes), &["160x120", "80x60"]);
    assert!(!out.exists(), "nothing written");
    // The cameras give the focal length and the baseline: the flags are refused.
    let flags = stereo(&[
        "--cameras",
        sizes.to_str().unwrap(),
        "--focal-px",
        "100",
        "--baseline",
        "0.5",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!flags.status.success());
    assert!(String::from_utf8_lossy(&flags.stderr).contains("--focal-px"));
    // One form or the other.
    let neither = stereo(&["--out", out.to_str().unwrap()]);
    assert!(!neither.status.success());
    assert!(String::from_utf8_lossy(&neither.stderr).contains("--cameras"));
}
