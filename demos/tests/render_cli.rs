//! The `render` binary end to end: face ids and vertex colours in the PNG, depth file size
//! and coverage, the timing line's format, and one-line errors (no panics) on bad input.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const W: u32 = 64;
const H: u32 = 48;

mod common;
use common::Tmp;

/// A unit quad at z = 0 as two triangles with vertex colours: triangle 1 is the half below
/// the diagonal y = x, triangle 2 the half above.
const QUAD: &str = "\
v -1 -1 0 1 0 0
v 1 -1 0 0 1 0
v 1 1 0 0 0 1
v -1 1 0 1 1 0
f 1 2 3
f 1 3 4
";

fn render(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_render"))
        .args(args)
        .output()
        .expect("run render")
}

fn rgba(png: &PathBuf) -> image::RgbaImage {
    image::open(png).expect("decode PNG").to_rgba8()
}

fn depth(path: &PathBuf) -> Vec<f32> {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(bytes.len(), (W * H * 4) as usize);
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

fn assert_ok(out: &Output) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "render failed: {err}");
    assert!(!err.contains("panicked"), "{err}");
}

/// Depth < 1 exactly where the colour is not the background.
fn assert_depth_matches_coverage(img: &image::RgbaImage, d: &[f32]) {
    let mut covered = 0;
    for (i, px) in img.pixels().enumerate() {
        let drawn = px.0[..3] != [0, 0, 0];
        assert_eq!(drawn, d[i] < 1.0, "pixel {i}: {:?} depth {}", px.0, d[i]);
        assert_eq!(px.0[3], 255);
        covered += drawn as usize;
    }
    assert!(covered > 100, "quad covers only {covered} pixels");
}

/// Renders `obj` at W x H with `shading` into a PNG and a depth file; asserts success.
fn render_to(obj: &Path, shading: &str, png: &Path, dep: &Path) {
    let (w, h) = (W.to_string(), H.to_string());
    let out = render(&[
        "--obj",
        obj.to_str().unwrap(),
        "-W",
        &w,
        "-H",
        &h,
        "--shading",
        shading,
        "--png",
        png.to_str().unwrap(),
        "--depth",
        dep.to_str().unwrap(),
    ]);
    assert_ok(&out);
}

#[test]
fn faceid_and_vertex_images_and_depth() {
    let t = Tmp::new("render-cli", "images");
    let obj = t.path("quad.obj");
    std::fs::write(&obj, QUAD).unwrap();
    let (png, dep) = (t.path("faceid.png"), t.path("faceid.f32"));
    render_to(&obj, "faceid", &png, &dep);
    let img = rgba(&png);
    assert_eq!(img.dimensions(), (W, H));
    // Right of and below the centre: world x > 0, y < 0, so y < x: triangle 1.
    assert_eq!(img.get_pixel(40, 30).0, [1, 0, 0, 255]);
    // Left of and above the centre: triangle 2.
    assert_eq!(img.get_pixel(24, 18).0, [2, 0, 0, 255]);
    assert_eq!(img.get_pixel(0, 0).0, [0, 0, 0, 255]);
    let d = depth(&dep);
    assert_depth_matches_coverage(&img, &d);
    // The quad is at distance 3 from the eye: window depth of z_view = -3.
    let (n, f) = (0.1f32, 100.0f32);
    let ndc = (f + n) / (f - n) - 2.0 * f * n / ((f - n) * 3.0);
    assert!((d[(30 * W + 40) as usize] - (0.5 * ndc + 0.5)).abs() < 1e-5);

    let (png, dep) = (t.path("vertex.png"), t.path("vertex.f32"));
    render_to(&obj, "vertex", &png, &dep);
    let img = rgba(&png);
    assert_depth_matches_coverage(&img, &depth(&dep));
    // Near the bottom-right corner (vertex 2, green) the colour is mostly green.
    let px = img.get_pixel(44, 36).0;
    assert!(px[1] > 150 && px[0] < 100 && px[2] < 100, "{px:?}");
}

#[test]
fn frames_prints_the_timing_line_last() {
    let t = Tmp::new("render-cli", "timing");
    let obj = t.path("quad.obj");
    std::fs::write(&obj, QUAD).unwrap();
    let out = render(&[
        "--obj",
        obj.to_str().unwrap(),
        "-W",
        "32",
        "-H",
        "24",
        "--frames",
        "2",
        "--warmup",
        "1",
        "--threads",
        "1",
    ]);
    assert_ok(&out);
    let stdout = String::from_utf8(out.stdout).unwrap();
    let last = stdout.lines().last().expect("a line");
    let f: Vec<&str> = last.split(' ').collect();
    assert_eq!(f.len(), 9, "{last}");
    assert_eq!(
        &f[..5],
        ["render", "quad.obj", "32x24", "tris=2", "threads=1"],
        "{last}"
    );
    for (field, key) in f[5..8].iter().zip(["median_ms=", "min_ms=", "p90_ms="]) {
        let v = field.strip_prefix(key).unwrap_or_else(|| panic!("{last}"));
        let (int, frac) = v.split_once('.').unwrap_or_else(|| panic!("{last}"));
        assert!(int.parse::<u64>().is_ok() && frac.len() == 3, "{last}");
        assert!(frac.chars().all(|c| c.is_ascii_digit()), "{last}");
    }
    assert_eq!(f[8], "frames=2", "{last}");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("render: stats:"), "{stderr}");
}

/// Runs and checks: failure with `code`, and exactly one error line, `render: error: ...`
/// naming `needle`, as the last line of stderr (progress lines may come before it).
fn assert_one_line_error(args: &[&str], code: i32, needle: &str) {
    let out = render(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    let errors: Vec<&&str> = lines.iter().filter(|l| l.contains("error")).collect();
    assert_eq!(errors.len(), 1, "{args:?}: {err}");
    let last = lines.last().unwrap();
    assert!(last.starts_with("render: error: "), "{err}");
    assert!(last.contains(needle), "{needle:?} not in {err}");
}

#[test]
fn errors_are_one_line_without_panics() {
    let t = Tmp::new("render-cli", "errors");
    let obj = t.path("quad.obj");
    std::fs::write(&obj, QUAD).unwrap();
    let o = obj.to_str().unwrap();
    let missing = t.path("missing.obj");
    assert_one_line_error(&["--obj", missing.to_str().unwrap()], 1, "missing.obj");
    assert_one_line_error(
        &["--gltf", t.path("none.glb").to_str().unwrap()],
        1,
        "none.glb",
    );
    assert_one_line_error(&["--obj", o, "--eye", "1,2"], 1, "--eye");
    assert_one_line_error(&["--obj", o, "--eye", "1,2,x"], 1, "--eye");
    assert_one_line_error(&["--obj", o, "--shading", "shiny"], 1, "shiny");
    assert_one_line_error(&["--obj", o, "-W", "0"], 1, "size");
    assert_one_line_error(&["--obj", o, "--eye", "0,0,0"], 1, "same point");
    assert_one_line_error(&["--obj", o, "--near", "5", "--far", "1"], 1, "near");
    let unwritable = t.path("no/such/dir/out.png");
    assert_one_line_error(
        &["--obj", o, "--png", unwritable.to_str().unwrap()],
        1,
        "out.png",
    );
    // A path that cannot be written although its folder exists (it is a folder).
    let dir = t.path("adir");
    std::fs::create_dir_all(&dir).unwrap();
    assert_one_line_error(&["--obj", o, "--depth", dir.to_str().unwrap()], 1, "adir");
    let garbage = t.path("garbage.obj");
    std::fs::write(&garbage, "not an obj\n").unwrap();
    assert_one_line_error(&["--obj", garbage.to_str().unwrap()], 1, "garbage.obj");
    // Usage errors from clap itself.
    assert_one_line_error(&[], 2, "required");
    assert_one_line_error(&["--obj", o, "--gltf", o], 2, "cannot be used");
}

#[test]
fn an_empty_scene_renders_an_empty_frame_with_a_notice() {
    let t = Tmp::new("render-cli", "empty");
    let (gltf, obj) = (t.path("empty.gltf"), t.path("empty.obj"));
    std::fs::write(
        &gltf,
        r#"{"asset":{"version":"2.0"},"scenes":[{}],"scene":0}"#,
    )
    .unwrap();
    std::fs::write(&obj, "# nothing yet\n").unwrap();
    for (flag, file) in [("--gltf", &gltf), ("--obj", &obj)] {
        let (png, dep) = (t.path("empty.png"), t.path("empty.f32"));
        let (w, h) = (W.to_string(), H.to_string());
        let out = render(&[
            flag,
            file.to_str().unwrap(),
            "-W",
            &w,
            "-H",
            &h,
            "--png",
            png.to_str().unwrap(),
            "--depth",
            dep.to_str().unwrap(),
        ]);
        assert_ok(&out);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("render: notice: the scene has nothing to draw"),
            "{err}"
        );
        let img = rgba(&png);
        assert!(
            img.pixels().all(|p| p.0 == [0, 0, 0, 255]),
            "{flag}: not empty"
        );
        assert!(
            depth(&dep).iter().all(|&d| d == 1.0),
            "{flag}: depth written"
        );
    }
}
