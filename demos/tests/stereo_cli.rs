//! `stereo` end to end on a random-dot stereogram whose disparities are known by
//! construction: a square at disparity 10 over a background at 4; and, with `--cameras`,
//! on a verged pair the engine renders (two views turned toward each other, not rectified),
//! whose depth is checked against a render of the scene from the camera `stereo` writes;
//! bad captures and cameras that cannot be rectified are one-line errors.

use engine::{Camera, Lighting, Projection};
use glam::{Mat4, Vec3};
use ibr::capture::capture_batch;
use ibr::images::transforms::read_transforms;
use std::path::Path;
use std::process::Command;

mod common;
mod stereo_common;
use common::Tmp;
use stereo_common::*;

const W: usize = 96;
const H: usize = 64;

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

    assert_the_warped_view_agrees(&tmp, &out);
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

/// A new view from between the eyes, in the scene's coordinates, by the 3D warp of the
/// capture `stereo` wrote to `out`: its depth agrees with a render from there.
fn assert_the_warped_view_agrees(tmp: &Tmp, out: &Path) {
    let n = (VW * VH) as usize;
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
