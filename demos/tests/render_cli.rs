//! The `render` binary end to end: face ids and vertex colours in the PNG, depth file size
//! and coverage, the timing line's format, one-line errors (no panics) on bad input, the
//! capture's colour files byte for byte the PNG's in every shading, and the warning when
//! the model is out of view.

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
    // The stages line: every stage's median, a number of milliseconds.
    let stages = stderr
        .lines()
        .find_map(|l| l.strip_prefix("render: stages: "))
        .unwrap_or_else(|| panic!("{stderr}"));
    let keys: Vec<&str> = stages
        .split(' ')
        .map(|kv| kv.split('=').next().unwrap())
        .collect();
    assert_eq!(
        keys,
        [
            "vertex_ms",
            "front_ms",
            "tiles_ms",
            "raster_sum_ms",
            "resolve_sum_ms"
        ],
        "{stages}"
    );
    for kv in stages.split(' ') {
        let v: f64 = kv.split('=').nth(1).and_then(|v| v.parse().ok()).expect(kv);
        assert!(v.is_finite() && v >= 0.0, "{stages}");
    }
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

/// The quad with a normal, so the lit and textured shadings light it.
const QUAD_LIT: &str = "\
v -1 -1 0 1 0 0
v 1 -1 0 0 1 0
v 1 1 0 0 0 1
v -1 1 0 1 1 0
vn 0 0 1
f 1//1 2//1 3//1
f 1//1 3//1 4//1
";

/// Issue 40: the capture's colour files hold what `--out` writes for the same view, in
/// the shading's encoding (before, the unorm shadings were sRGB-encoded: face id 1 was
/// written as 13).
#[test]
fn a_capture_holds_the_bytes_of_the_png_for_every_shading() {
    let t = Tmp::new("render-cli", "capture-bytes");
    let obj = t.path("quad.obj");
    std::fs::write(&obj, QUAD_LIT).unwrap();
    let (w, h) = (W.to_string(), H.to_string());
    for shading in ["flat", "vertex", "faceid", "lit", "textured"] {
        // Straight on (the face ids' pixels are known) and from an oblique eye.
        for eye in ["0,0,3", "0.7,-0.4,2.6"] {
            let (png, cap) = (t.path("view.png"), t.path("cap"));
            let _ = std::fs::remove_dir_all(&cap);
            let out = render(&[
                "--obj",
                obj.to_str().unwrap(),
                "-W",
                &w,
                "-H",
                &h,
                "--shading",
                shading,
                "--eye",
                eye,
                "--out",
                png.to_str().unwrap(),
                "--capture",
                cap.to_str().unwrap(),
                "--views",
                "1",
            ]);
            assert_ok(&out);
            let (view, captured) = (rgba(&png), rgba(&cap.join("images/0000.png")));
            assert_eq!(view.dimensions(), captured.dimensions());
            let drawn = view.pixels().filter(|p| p.0 != [0, 0, 0, 255]).count();
            assert!(drawn > 300, "{shading} from {eye}: {drawn} pixels drawn");
            let differ = view.pixels().zip(captured.pixels()).filter(|(a, b)| a != b);
            assert_eq!(differ.count(), 0, "{shading} from {eye}: capture differs");
            if shading == "faceid" && eye == "0,0,3" {
                // The triangles of faceid_and_vertex_images_and_depth, ids 1 and 2.
                assert_eq!(captured.get_pixel(40, 30).0, [1, 0, 0, 255]);
                assert_eq!(captured.get_pixel(24, 18).0, [2, 0, 0, 255]);
            }
        }
    }
}

/// Issue 40: a model outside the default camera's view gave an all-black PNG without a
/// word. Now one warning line names the coverage and a camera that frames the model, and
/// that camera does.
#[test]
fn a_model_out_of_view_is_warned_about_with_a_camera_that_frames_it() {
    let t = Tmp::new("render-cli", "out-of-view");
    let far = t.path("far.obj");
    // The quad moved to (100, 100, -50): the default camera at (0, 0, 3) looks at the origin.
    let moved: String = QUAD
        .lines()
        .map(|l| match l.strip_prefix("v ") {
            Some(rest) => {
                let f: Vec<f32> = rest.split(' ').map(|x| x.parse().unwrap()).collect();
                format!(
                    "v {} {} {} {} {} {}\n",
                    f[0] + 100.0,
                    f[1] + 100.0,
                    f[2] - 50.0,
                    f[3],
                    f[4],
                    f[5]
                )
            }
            None => format!("{l}\n"),
        })
        .collect();
    std::fs::write(&far, moved).unwrap();
    let png = t.path("far.png");
    let (w, h) = (W.to_string(), H.to_string());
    let size = ["-W", &w, "-H", &h];
    let mut args = vec![
        "--obj",
        far.to_str().unwrap(),
        "--out",
        png.to_str().unwrap(),
    ];
    args.extend(size);
    let out = render(&args);
    assert_ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    let warnings: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("render: warning: "))
        .collect();
    assert_eq!(warnings.len(), 1, "{err}");
    let line = warnings[0];
    assert!(
        line.contains(&format!("covers 0 of {} pixels", W * H)),
        "{line}"
    );
    assert!(line.contains("(centre 100,100,-50)"), "{line}");
    assert!(rgba(&png).pixels().all(|p| p.0 == [0, 0, 0, 255]));
    // The suggested camera frames the model: no warning, and most of the quad in view.
    let hint = line.split("try ").nth(1).expect("a suggestion");
    let hint: Vec<&str> = hint.split_whitespace().collect();
    let mut args = vec![
        "--obj",
        far.to_str().unwrap(),
        "--out",
        png.to_str().unwrap(),
    ];
    args.extend(size);
    args.extend(&hint);
    let out = render(&args);
    assert_ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("warning"), "{hint:?}: {err}");
    let drawn = rgba(&png)
        .pixels()
        .filter(|p| p.0 != [0, 0, 0, 255])
        .count();
    assert!(drawn > (W * H / 10) as usize, "{hint:?}: {drawn} pixels");
    // A framed model: no warning.
    let quad = t.path("quad.obj");
    std::fs::write(&quad, QUAD).unwrap();
    let mut args = vec![
        "--obj",
        quad.to_str().unwrap(),
        "--out",
        png.to_str().unwrap(),
    ];
    args.extend(size);
    let out = render(&args);
    assert_ok(&out);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("warning"));
}
