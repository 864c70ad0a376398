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

/// A 256x256 texture of random grey levels in blocks of `cell` x `cell` texels.
fn noise(cell: usize) -> Arc<Texture> {
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
fn with_scene<R>(f: impl FnOnce(&[Draw<'_>]) -> R) -> R {
    with_cards(
        &[(12.0, Vec3::ZERO, 2), (1.2, Vec3::new(0.5, 0.3, 1.5), 2)],
        f,
    )
}

/// Square cards facing +z, each `(size, centre, texture cell in texels)`, on nothing
/// (transparent where no card is); handed to `f` as draws.
fn with_cards<R>(cards: &[(f32, Vec3, usize)], f: impl FnOnce(&[Draw<'_>]) -> R) -> R {
    let placed: Vec<(f32, Mat4, usize)> = cards
        .iter()
        .map(|&(size, at, cell)| (size, Mat4::from_translation(at), cell))
        .collect();
    with_placed(&placed, f)
}

/// Square cards, each `(size, transform of a card facing +z at the origin, texture cell)`,
/// on nothing; handed to `f` as draws.
fn with_placed<R>(cards: &[(f32, Mat4, usize)], f: impl FnOnce(&[Draw<'_>]) -> R) -> R {
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
    write_images(dir, &render(cameras))
}

/// `images` written in `dir` as [`write_capture`] writes them.
fn write_images(dir: &Path, images: &[DepthImage]) -> PathBuf {
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

/// `stereo`'s stdout, failing the test with its stderr unless it succeeds; and its stderr.
fn stereo_out(args: &[&str]) -> (String, String) {
    let run = stereo(args);
    let err = String::from_utf8_lossy(&run.stderr).into_owned();
    assert!(run.status.success(), "{err}");
    (String::from_utf8_lossy(&run.stdout).into_owned(), err)
}

/// A card on nothing (transparent around it), seen by two parallel cameras: the rectified
/// views are the originals, so 100% of each lies inside its original, however much of it
/// is transparent (the old count said what share showed something). With `--fill`, by
/// either matcher, no pixel where the left view saw nothing gets a disparity, and the card
/// itself is matched.
#[test]
fn coverage_counts_the_background_and_fill_keeps_off_it() {
    let tmp = Tmp::new("stereo-cli", "card-on-nothing");
    let cameras = [
        camera(
            Vec3::new(-0.2, 0.0, 4.0),
            Vec3::new(-0.2, 0.0, 0.0),
            Vec3::Y,
        ),
        camera(Vec3::new(0.2, 0.0, 4.0), Vec3::new(0.2, 0.0, 0.0), Vec3::Y),
    ];
    let images = with_cards(&[(1.6, Vec3::ZERO, 4)], |draws| {
        capture_batch(draws, &cameras, &Lighting::default(), VW, VH)
    });
    let n = (VW * VH) as usize;
    let nothing = images[0].color.iter().filter(|c| c.a == 0.0).count();
    assert!(nothing > n / 2, "{nothing} of {n} pixels show nothing");
    let json = write_images(&tmp.path("cap"), &images);
    let left = image::open(tmp.path("cap").join("view0.png"))
        .unwrap()
        .to_rgba8();
    for method in ["sgm", "block"] {
        let out = tmp.path(method);
        let (stdout, _) = stereo_out(&[
            "--cameras",
            json.to_str().unwrap(),
            "--method",
            method,
            "--fill",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(
            stdout.contains("100.0% of the left view and 100.0% of the right inside the originals"),
            "{stdout}"
        );
        let d = pfm(&out.join("disparity.pfm"));
        // Nothing seen: alpha 0 in the left photograph and around it (the rectified view
        // resamples it bilinearly).
        let clear = |x: i64, y: i64| {
            (-1..=1).all(|dy| {
                (-1..=1).all(|dx| {
                    let (u, v) = (x + dx, y + dy);
                    u < 0
                        || v < 0
                        || u >= VW as i64
                        || v >= VH as i64
                        || left.get_pixel(u as u32, v as u32)[3] == 0
                })
            })
        };
        let (mut painted, mut card, mut matched) = (0, 0, 0);
        for y in 0..VH as i64 {
            for x in 0..VW as i64 {
                let v = d.data[(y * VW as i64 + x) as usize];
                if clear(x, y) {
                    painted += v.is_finite() as u32;
                } else if left.get_pixel(x as u32, y as u32)[3] == 255 {
                    card += 1;
                    matched += v.is_finite() as u32;
                }
            }
        }
        assert_eq!(painted, 0, "{method}: disparities where nothing was seen");
        assert!(
            card > 2000 && matched * 10 >= card * 9,
            "{method}: {matched} of {card}"
        );
    }
}

/// The random-dot pair with its background transparent (only the square and a frame
/// around it seen): `--fill` paints no transparent pixel, by either matcher (it used to
/// paint each row from end to end).
#[test]
fn fill_leaves_transparent_pixels_of_a_rectified_pair_unknown() {
    let tmp = Tmp::new("stereo-cli", "dots-on-nothing");
    let left = dots(1);
    let mut right = dots(2);
    for y in 0..H {
        for x in 10..W {
            right[y * W + x - 10] = left[y * W + x];
        }
    }
    // Seen: a rectangle around the square (left), the same shifted by 10 (right).
    let seen = |x: usize, y: usize, shift: usize| {
        (26 - shift..78 - shift).contains(&x) && (8..56).contains(&y)
    };
    let write = |path: &Path, grey: &[u8], shift: usize| {
        let rgba: Vec<u8> = (0..W * H)
            .flat_map(|i| {
                let g = grey[i];
                let a = if seen(i % W, i / W, shift) { 255 } else { 0 };
                [g, g, g, a]
            })
            .collect();
        image::save_buffer(path, &rgba, W as u32, H as u32, image::ColorType::Rgba8).unwrap();
    };
    let (lp, rp) = (tmp.path("left.png"), tmp.path("right.png"));
    write(&lp, &left, 0);
    write(&rp, &right, 10);
    for method in ["block", "sgm"] {
        let out = tmp.path(method);
        stereo_ok(&[
            "--left",
            lp.to_str().unwrap(),
            "--right",
            rp.to_str().unwrap(),
            "--max-disparity",
            "16",
            "--method",
            method,
            "--fill",
            "--out",
            out.to_str().unwrap(),
        ]);
        let d = pfm(&out.join("disparity.pfm"));
        let (mut painted, mut inside, mut right_px) = (0, 0, 0);
        for y in 0..H {
            for x in 0..W {
                let v = d.data[y * W + x];
                if !seen(x, y, 0) {
                    painted += v.is_finite() as u32;
                } else {
                    inside += 1;
                    right_px += ((v - 10.0).abs() <= 1.0) as u32;
                }
            }
        }
        assert_eq!(
            painted, 0,
            "{method}: disparities on the transparent background"
        );
        assert!(
            right_px * 10 >= inside * 8,
            "{method}: {right_px} of {inside} right"
        );
    }
}

/// `disparity.png` carries a colour key under the map: the map's rows, then a strip whose
/// bar runs from the colour of disparity 0 (blue) to that of the range's top (red), red
/// never falling and blue never rising along it.
#[test]
fn the_disparity_picture_has_a_colour_key() {
    let tmp = Tmp::new("stereo-cli", "key");
    let (lp, rp) = (tmp.path("l.png"), tmp.path("r.png"));
    write_grey(&lp, &dots(1));
    write_grey(&rp, &dots(1));
    let out = tmp.path("out");
    stereo_ok(&[
        "--left",
        lp.to_str().unwrap(),
        "--right",
        rp.to_str().unwrap(),
        "--max-disparity",
        "16",
        "--out",
        out.to_str().unwrap(),
    ]);
    let png = image::open(out.join("disparity.png")).unwrap().to_rgba8();
    let (w, h) = png.dimensions();
    assert_eq!(w, W as u32);
    assert!(
        h > H as u32 + 10,
        "{h} rows: no key under the {H} of the map"
    );
    // The bar: the longest run of non-black pixels in a row of the strip.
    let run = |y: u32| {
        let row: Vec<[u8; 3]> = (0..w)
            .map(|x| {
                let p = png.get_pixel(x, y);
                [p[0], p[1], p[2]]
            })
            .collect();
        let lit: Vec<usize> = (0..w as usize).filter(|&x| row[x] != [0, 0, 0]).collect();
        let first = lit.first().copied().unwrap_or(0);
        let last = lit.last().copied().unwrap_or(0);
        row[first..=last].to_vec()
    };
    let bar = (H as u32..h)
        .map(run)
        .max_by_key(|r| {
            let distinct: std::collections::HashSet<_> = r.iter().collect();
            distinct.len()
        })
        .unwrap();
    assert!(bar.len() >= W / 2, "a bar {} pixels long", bar.len());
    let (first, last) = (bar[0], bar[bar.len() - 1]);
    assert!(first[2] > 200 && first[0] < 40, "blue at 0: {first:?}");
    assert!(last[0] > 200 && last[2] < 40, "red at the top: {last:?}");
    for p in bar.windows(2) {
        assert!(
            p[1][0] >= p[0][0] && p[1][2] <= p[0][2],
            "not monotonic: {p:?}"
        );
    }
}

#[test]
fn help_opens_with_the_tools_own_job() {
    let run = stereo(&["--help"]);
    assert!(run.status.success());
    let help = String::from_utf8_lossy(&run.stdout);
    let first = help.lines().next().unwrap_or("");
    assert!(
        first.starts_with("stereo: depth from a stereo pair"),
        "{first}"
    );
    assert!(help.contains("--out"), "{help}");
}

/// The focal length in pixels of the hand-written capture below (160 x 120).
const FL: f32 = 142.0;
/// cos and sin of 3 degrees: each camera of the pair is turned 3 degrees toward the other.
const C3: f32 = 0.998_629_5;
const S3: f32 = 0.052_335_955;

/// The pair of the hand-written capture: eyes at (-0.3, 0, 3) and (0.3, 0, 3), 6 degrees
/// apart, the camera-to-world matrices typed in [`FOREIGN`].
fn foreign_cameras() -> [Camera; 2] {
    let c2w = |rows: [[f32; 4]; 3]| {
        Mat4::from_cols_array_2d(&[
            [rows[0][0], rows[1][0], rows[2][0], 0.0],
            [rows[0][1], rows[1][1], rows[2][1], 0.0],
            [rows[0][2], rows[1][2], rows[2][2], 0.0],
            [rows[0][3], rows[1][3], rows[2][3], 1.0],
        ])
    };
    let projection = Projection::Perspective {
        fov_y: 2.0 * (0.5 * VH as f32 / FL).atan(),
        aspect: VW as f32 / VH as f32,
        near: 0.1,
        far: 50.0,
    };
    [
        c2w([
            [C3, 0.0, -S3, -0.3],
            [0.0, 1.0, 0.0, 0.0],
            [S3, 0.0, C3, 3.0],
        ]),
        c2w([
            [C3, 0.0, S3, 0.3],
            [0.0, 1.0, 0.0, 0.0],
            [-S3, 0.0, C3, 3.0],
        ]),
    ]
    .map(|m| Camera {
        view: m.inverse(),
        projection,
    })
}

/// The capture as nerfstudio writes one (its `transforms.json` documentation: shared
/// intrinsics `fl_x`, `fl_y`, `cx`, `cy`, `w`, `h`, `camera_model`; per frame `file_path`,
/// `depth_file_path`, and `transform_matrix` camera to world, OpenGL axes), typed here.
const FOREIGN: &str = r#"{
  "camera_model": "OPENCV",
  "fl_x": 142.0, "fl_y": 142.0, "cx": 80.0, "cy": 60.0, "w": 160, "h": 120,
  "k1": 0.0, "k2": 0.0, "p1": 0.0, "p2": 0.0,
  "frames": [
    {
      "file_path": "images/frame_00001.png",
      "depth_file_path": "depths/frame_00001.pfm",
      "transform_matrix": [
        [0.9986295, 0.0, -0.052335955, -0.3],
        [0.0, 1.0, 0.0, 0.0],
        [0.052335955, 0.0, 0.9986295, 3.0],
        [0.0, 0.0, 0.0, 1.0]
      ]
    },
    {
      "file_path": "images/frame_00002.png",
      "depth_file_path": "depths/frame_00002.pfm",
      "transform_matrix": [
        [0.9986295, 0.0, 0.052335955, 0.3],
        [0.0, 1.0, 0.0, 0.0],
        [-0.052335955, 0.0, 0.9986295, 3.0],
        [0.0, 0.0, 0.0, 1.0]
      ]
    }
  ]
}"#;

/// The scene of the foreign capture: a wall at z = 0 (disparity 28 in the pair) and a
/// card 0.6 across at z = 1.8 (disparity 71: beyond the README's 32 and the old default
/// of 64).
fn foreign_scene(cameras: &[Camera]) -> Vec<DepthImage> {
    with_cards(
        &[(12.0, Vec3::ZERO, 2), (0.6, Vec3::new(0.0, 0.0, 1.8), 8)],
        |draws| capture_batch(draws, cameras, &Lighting::default(), VW, VH),
    )
}

/// A PFM as the Middlebury tools write one: `Pf`, the size, `-1` (little-endian), rows
/// bottom to top.
fn hand_pfm(path: &Path, w: u32, h: u32, data: &[f32]) {
    let mut bytes = format!("Pf\n{w} {h}\n-1.0\n").into_bytes();
    for y in (0..h).rev() {
        for x in 0..w {
            bytes.extend_from_slice(&data[(y * w + x) as usize].to_le_bytes());
        }
    }
    std::fs::write(path, bytes).unwrap();
}

/// Writes the foreign capture in `dir` (with its depth maps or without) and returns its
/// JSON's path.
fn write_foreign(dir: &Path, depth: bool) -> PathBuf {
    std::fs::create_dir_all(dir.join("images")).unwrap();
    std::fs::create_dir_all(dir.join("depths")).unwrap();
    for (i, image) in foreign_scene(&foreign_cameras()).iter().enumerate() {
        let name = format!("frame_{:05}", i + 1);
        engine::load::write_png_rgba8(
            &dir.join("images").join(format!("{name}.png")),
            VW,
            VH,
            &srgb8(image),
        )
        .unwrap();
        assert!(
            image.depth.iter().all(|z| z.is_finite()),
            "the wall fills the view"
        );
        hand_pfm(
            &dir.join("depths").join(format!("{name}.pfm")),
            VW,
            VH,
            &image.depth,
        );
    }
    let text = if depth {
        FOREIGN.to_string()
    } else {
        FOREIGN
            .lines()
            .filter(|l| !l.contains("depth_file_path"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    let json = dir.join("transforms.json");
    std::fs::write(&json, text).unwrap();
    json
}

/// `out`'s disparities against the exact ones: the scene rendered from the camera `stereo`
/// wrote (the rectified left camera), `fl_x baseline / z` (the baseline 0.6, the focal
/// length the capture's). Returns the share of the pixels matched, the share of the
/// matched ones within a pixel, and the share of the card's pixels (true disparity above
/// 60) within a pixel.
fn against_truth(out: &Path) -> (f64, f64, f64) {
    let d = pfm(&out.join("disparity.pfm"));
    let written = read_transforms(&out.join("transforms.json")).expect("a capture");
    let truth = &foreign_scene(&[written[0].camera])[0];
    let (mut matched, mut right, mut card, mut card_right) = (0usize, 0usize, 0usize, 0usize);
    for (i, z) in truth.depth.iter().enumerate() {
        let want = FL * 0.6 / z;
        let ok = (d.data[i] - want).abs() <= 1.0;
        matched += d.data[i].is_finite() as usize;
        right += ok as usize;
        if want > 60.0 {
            card += 1;
            card_right += ok as usize;
        }
    }
    assert!(card > 2000, "{card} pixels of the card");
    (
        matched as f64 / d.data.len() as f64,
        right as f64 / matched.max(1) as f64,
        card_right as f64 / card as f64,
    )
}

/// Asserts that `out`'s map is right (measured with the range from depth: 62% of all
/// pixels within a pixel of the truth, most of the rest out of the right view or hidden
/// by the card; 94% of the card within a pixel).
fn assert_right(out: &Path, what: &str) {
    let (matched, right, card) = against_truth(out);
    assert!(
        matched > 0.55 && right > 0.9 && card > 0.85,
        "{what}: {matched} matched, {right} of them within a pixel, {card} of the card"
    );
}

/// A two-frame capture written as nerfstudio writes one, 6 degrees verged, with a card
/// nearer than the README's `--max-disparity 32` and the old default 64 reach: without the
/// flag the range comes from its depth maps (and, without them, from a coarse search) and
/// the map is right against the exact disparities; forced to 32, most of the card sits at
/// the limit and one warning line says so. The capture `stereo` writes then reads back and
/// warps at its own eye to the same image.
#[test]
fn a_foreign_capture_is_matched_over_its_own_range() {
    let tmp = Tmp::new("stereo-cli", "foreign");
    let json = write_foreign(&tmp.path("with-depth"), true);
    let out = tmp.path("out");
    let (stdout, stderr) = stereo_out(&[
        "--cameras",
        json.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(stdout.contains("from the capture's depth"), "{stdout}");
    assert!(stderr.is_empty(), "{stderr}");
    assert_right(&out, "range from depth");

    // Without depth maps: the coarse search.
    let bare = write_foreign(&tmp.path("bare"), false);
    let out2 = tmp.path("out-bare");
    let (stdout, stderr) = stereo_out(&[
        "--cameras",
        bare.to_str().unwrap(),
        "--out",
        out2.to_str().unwrap(),
    ]);
    assert!(stdout.contains("coarse search"), "{stdout}");
    assert!(stderr.is_empty(), "{stderr}");
    assert_right(&out2, "coarse search");

    // Forced to the README's 32: a warning, one line.
    let (stdout, stderr) = stereo_out(&[
        "--cameras",
        json.to_str().unwrap(),
        "--max-disparity",
        "32",
        "--out",
        tmp.path("out-32").to_str().unwrap(),
    ]);
    assert_eq!(stderr.lines().count(), 1, "{stdout} {stderr}");
    assert!(
        stderr.contains("warning")
            && stderr.contains("limit")
            && stderr.contains("--max-disparity"),
        "{stderr}"
    );

    // The written capture at its own eye: the 3D warp gives its image back.
    round_trip(&out);
}

/// Reads the one-frame capture in `out` and warps it at its own camera: every pixel with a
/// depth lands on itself with its colour (PSNR over them >= 60 dB), and no pixel without
/// one is filled.
fn round_trip(out: &Path) {
    use ibr::warp::{Prepared, WarpOptions, Warper};
    let written = read_transforms(&out.join("transforms.json")).expect("a capture");
    let image = &written[0];
    let options = WarpOptions::default();
    let mut warper = Warper::new();
    warper.begin(&image.camera, image.width(), image.height());
    warper.add_prepared(&Prepared::from_image(image, options.edge), &options);
    let warped = warper.output();
    let (mut sum, mut n, mut missing) = (0.0f64, 0usize, 0usize);
    for (i, c) in image.color.iter().enumerate() {
        if !image.depth[i].is_finite() {
            continue;
        }
        if !warped.is_filled(i) {
            missing += 1;
            continue;
        }
        let g = warped.color_linear(i);
        for (a, b) in [(g.r, c.r), (g.g, c.g), (g.b, c.b), (g.a, c.a)] {
            sum += f64::from(a - b).powi(2);
        }
        n += 4;
    }
    assert!(n > 4 * 2000, "{n} values compared");
    assert_eq!(missing, 0, "pixels with depth that did not land");
    let mse = sum / n as f64;
    let psnr = if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (1.0 / mse).log10()
    };
    assert!(psnr >= 60.0, "{psnr:.1} dB");
}

/// Captures `stereo` writes from pairs at arbitrary poses (a seeded sweep of orientations,
/// positions, baselines, vergence and image sizes) read back and warp at their own eye to
/// their own image (>= 60 dB over the pixels with a depth, each of them landing).
#[test]
fn captures_written_at_arbitrary_poses_round_trip() {
    let tmp = Tmp::new("stereo-cli", "poses");
    let mut rng = XorShift::new(40);
    let mut uniform =
        |lo: f32, hi: f32| lo + (hi - lo) * (rng.next_u64() % 10_000) as f32 / 10_000.0;
    for case in 0..6 {
        let (w, h) = (uniform(96.0, 200.0) as u32, uniform(72.0, 150.0) as u32);
        let pose = Mat4::from_translation(Vec3::new(
            uniform(-5.0, 5.0),
            uniform(-5.0, 5.0),
            uniform(-5.0, 5.0),
        )) * Mat4::from_euler(
            glam::EulerRot::YXZ,
            uniform(-3.1, 3.1),
            uniform(-0.6, 0.6),
            uniform(-0.3, 0.3),
        );
        let (baseline, verge) = (uniform(0.2, 0.6), uniform(0.0, 4.0).to_radians());
        let right =
            pose * Mat4::from_translation(Vec3::X * baseline) * Mat4::from_rotation_y(verge);
        let projection = Projection::Perspective {
            fov_y: FOV_Y,
            aspect: w as f32 / h as f32,
            near: 0.1,
            far: 50.0,
        };
        let cameras = [pose, right].map(|m| Camera {
            view: m.inverse(),
            projection,
        });
        // A wall 4 units ahead of the left camera and a card 2.5 ahead, in its frame.
        let images = with_placed(
            &[
                (
                    20.0,
                    pose * Mat4::from_translation(Vec3::new(0.0, 0.0, -4.0)),
                    2,
                ),
                (
                    1.0,
                    pose * Mat4::from_translation(Vec3::new(0.3, 0.1, -2.5)),
                    4,
                ),
            ],
            |draws| capture_batch(draws, &cameras, &Lighting::default(), w, h),
        );
        let dir = tmp.path(&format!("case{case}"));
        let json = write_images(&dir.join("cap"), &images);
        let out = dir.join("out");
        stereo_out(&[
            "--cameras",
            json.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        round_trip(&out);
    }
}
