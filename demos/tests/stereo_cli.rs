//! `stereo` end to end on a random-dot stereogram whose disparities are known by
//! construction: a square at disparity 10 over a background at 4.

use std::path::Path;
use std::process::{Command, Output};

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
    let run = stereo(&[
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
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
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
