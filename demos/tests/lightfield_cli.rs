//! `lightfield` end to end: a model captured, compressed, inspected and rendered; a
//! `render --capture` folder rebinned (sparse capture); bad input is a one-line error; a
//! compressed file is not compressed again; a view that shows nothing is warned about;
//! the flags are the other tools' (`-W/-H`, negative numbers in vectors).

use std::path::Path;
use std::process::{Command, Output};

mod common;
use common::{Tmp, TWO_SQUARES as SCENE};

fn lightfield(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lightfield"))
        .args(args)
        .output()
        .expect("run")
}

fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn len(p: &Path) -> u64 {
    std::fs::metadata(p).map_or(0, |m| m.len())
}

#[test]
fn a_model_is_captured_compressed_and_rendered() {
    let tmp = Tmp::new("lightfield-cli", "model");
    let obj = tmp.path("scene.obj");
    std::fs::write(&obj, SCENE).unwrap();
    let (raw, vq) = (tmp.path("scene.plf"), tmp.path("scene_vq.plf"));
    let log = ok(&lightfield(&[
        "capture",
        "--obj",
        s(&obj),
        "--out",
        s(&raw),
        "--uv",
        "6",
        "--st",
        "48",
        "--aperture",
        "2",
    ]));
    assert!(
        log.contains("6912 samples") || log.contains("82944 samples"),
        "{log}"
    );
    let log = ok(&lightfield(&[
        "compress",
        s(&raw),
        "--out",
        s(&vq),
        "--codewords",
        "64",
        "--tile",
        "1x1x2x2",
    ]));
    assert!(log.contains("1x1x2x2"), "{log}");
    assert!(
        len(&vq) * 4 < len(&raw),
        "{} against {}",
        len(&vq),
        len(&raw)
    );
    let log = ok(&lightfield(&["info", s(&vq)]));
    assert!(
        log.contains("6 x 6 (uv) by 48 x 48 (st)") && log.contains("quantised"),
        "{log}"
    );
    // One view, then a sweep of three across the camera plane.
    let png = tmp.path("view.png");
    ok(&lightfield(&[
        "render",
        s(&vq),
        "--png",
        s(&png),
        "--size",
        "80x60",
    ]));
    let view = image::open(&png).unwrap().to_rgba8();
    assert_eq!(view.dimensions(), (80, 60));
    // The red square in the middle, in front of the back square.
    let c = view.get_pixel(40, 30);
    assert!(c[0] > 150 && c[1] < 80 && c[2] < 80, "{c:?}");
    let frames = tmp.path("frames");
    let log = ok(&lightfield(&[
        "render",
        s(&raw),
        "--out",
        s(&frames),
        "--frames",
        "3",
        "-W",
        "80",
        "-H",
        "60",
    ]));
    assert_eq!(log.lines().count(), 3, "{log}");
    let first = image::open(frames.join("0000.png")).unwrap().to_rgba8();
    let last = image::open(frames.join("0002.png")).unwrap().to_rgba8();
    assert_ne!(first, last, "the sweep shows parallax");
}

#[test]
fn a_slab_with_its_camera_plane_at_infinity_is_captured_and_rendered() {
    let tmp = Tmp::new("lightfield-cli", "infinite");
    let obj = tmp.path("scene.obj");
    std::fs::write(&obj, SCENE).unwrap();
    let plf = tmp.path("ortho.plf");
    ok(&lightfield(&[
        "capture",
        "--obj",
        s(&obj),
        "--out",
        s(&plf),
        "--uv",
        "6",
        "--st",
        "48",
        "--infinite",
        "uv",
    ]));
    let log = ok(&lightfield(&["info", s(&plf)]));
    assert!(
        log.contains("uv plane at infinity") && log.contains("depth kept: false"),
        "{log}"
    );
    let png = tmp.path("view.png");
    ok(&lightfield(&[
        "render",
        s(&plf),
        "--png",
        s(&png),
        "--size",
        "80x60",
    ]));
    // The red square in the middle, seen from the middle direction.
    let view = image::open(&png).unwrap().to_rgba8();
    let c = view.get_pixel(40, 30);
    assert!(c[0] > 150 && c[1] < 80 && c[2] < 80, "{c:?}");
    let both = lightfield(&[
        "capture",
        "--obj",
        s(&obj),
        "--out",
        s(&plf),
        "--infinite",
        "xy",
    ]);
    assert!(!both.status.success());
}

#[test]
fn a_capture_folder_is_rebinned() {
    let tmp = Tmp::new("lightfield-cli", "sparse");
    let obj = tmp.path("scene.obj");
    std::fs::write(&obj, SCENE).unwrap();
    let cap = tmp.path("cap");
    let out = Command::new(env!("CARGO_BIN_EXE_render"))
        .args(["--obj", s(&obj), "--eye", "0,0,5", "--target", "0,0,0"])
        .args(["--shading", "vertex", "-W", "64", "-H", "64"])
        .args(["--capture", s(&cap), "--views", "5", "--spread", "20"])
        .output()
        .expect("run");
    ok(&out);
    let plf = tmp.path("sparse.plf");
    let log = ok(&lightfield(&[
        "capture",
        "--transforms",
        s(&cap),
        "--out",
        s(&plf),
        "--uv",
        "4",
        "--st",
        "32",
    ]));
    assert!(
        log.contains("rebinned") && log.contains("invented"),
        "{log}"
    );
    let png = tmp.path("view.png");
    ok(&lightfield(&[
        "render",
        s(&plf),
        "--png",
        s(&png),
        "-W",
        "64",
        "-H",
        "64",
    ]));
}

#[test]
fn bad_input_is_one_line_naming_the_problem() {
    let tmp = Tmp::new("lightfield-cli", "bad");
    let junk = tmp.path("junk.plf");
    std::fs::write(&junk, b"not a light field").unwrap();
    let missing = tmp.path("missing.obj");
    let out = tmp.path("o.plf");
    for (args, want) in [
        (vec!["info", s(&junk)], "junk.plf"),
        (vec!["render", s(&junk), "--png", s(&out)], "junk.plf"),
        (
            vec!["capture", "--obj", s(&missing), "--out", s(&out)],
            "missing.obj",
        ),
        (
            vec!["compress", s(&junk), "--out", s(&out), "--tile", "3x2x2x2"],
            "powers of two",
        ),
        (vec!["capture", "--out", s(&out)], "--obj"),
        (
            vec![
                "capture",
                "--obj",
                s(&missing),
                "--out",
                s(&out),
                "--uv",
                "4096",
                "--st",
                "4096",
            ],
            "samples",
        ),
    ] {
        let o = lightfield(&args);
        assert!(!o.status.success(), "{args:?} succeeded");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(want), "{args:?}: {err}");
    }
}

/// A small model captured into `dir` (raw) and compressed (the pair's paths).
fn captured(tmp: &Tmp) -> (std::path::PathBuf, std::path::PathBuf) {
    let obj = tmp.path("scene.obj");
    std::fs::write(&obj, SCENE).unwrap();
    let (raw, vq) = (tmp.path("scene.plf"), tmp.path("scene_vq.plf"));
    ok(&lightfield(&[
        "capture",
        "--obj",
        s(&obj),
        "--out",
        s(&raw),
        "--uv",
        "4",
        "--st",
        "32",
    ]));
    ok(&lightfield(&[
        "compress",
        s(&raw),
        "--out",
        s(&vq),
        "--codewords",
        "32",
        "--tile",
        "1x1x2x2",
    ]));
    (raw, vq)
}

#[test]
fn a_compressed_file_is_not_compressed_again() {
    let tmp = Tmp::new("lightfield-cli", "twice");
    let (_, vq) = captured(&tmp);
    let again = tmp.path("again.plf");
    let o = lightfield(&["compress", s(&vq), "--out", s(&again)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success(),
        "compressed twice: {}",
        String::from_utf8_lossy(&o.stdout)
    );
    assert!(
        err.starts_with("lightfield: error: ") && err.contains("already compressed"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!again.exists(), "nothing written");
}

#[test]
fn a_view_that_shows_nothing_is_warned_about_in_one_line() {
    let tmp = Tmp::new("lightfield-cli", "nothing");
    let (raw, _) = captured(&tmp);
    let png = tmp.path("away.png");
    // Looking away from the object, from in front of it.
    let o = lightfield(&[
        "render",
        s(&raw),
        "--png",
        s(&png),
        "-W",
        "40",
        "-H",
        "30",
        "--eye",
        "0,0,30",
        "--target",
        "0,0,60",
    ]);
    ok(&o);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(png.exists());
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("lightfield: warning: ") && err.contains("no pixel"),
        "{err}"
    );
    // A view that shows it says nothing.
    let o = lightfield(&["render", s(&raw), "--png", s(&png), "-W", "40", "-H", "30"]);
    ok(&o);
    assert!(
        o.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn render_takes_the_shared_flags_and_negative_numbers_in_vectors() {
    let tmp = Tmp::new("lightfield-cli", "flags");
    let (raw, _) = captured(&tmp);
    let (a, b, c) = (tmp.path("a.png"), tmp.path("b.png"), tmp.path("c.png"));
    // -W/-H as every other tool; --size the older spelling, the same frame.
    ok(&lightfield(&[
        "render",
        s(&raw),
        "--png",
        s(&a),
        "-W",
        "48",
        "-H",
        "32",
        "--eye=-0.3,0.2,6",
        "--target=-0.01,-0.02,-0.25",
        "--up=-0.1,1,0",
    ]));
    // The same vectors as separate arguments, negative numbers first.
    ok(&lightfield(&[
        "render",
        s(&raw),
        "--png",
        s(&b),
        "--width",
        "48",
        "--height",
        "32",
        "--eye",
        "-0.3,0.2,6",
        "--target",
        "-0.01,-0.02,-0.25",
        "--up",
        "-0.1,1,0",
    ]));
    ok(&lightfield(&[
        "render",
        s(&raw),
        "--png",
        s(&c),
        "--size",
        "48x32",
        "--eye",
        "-0.3,0.2,6",
        "--target",
        "-0.01,-0.02,-0.25",
        "--up",
        "-0.1,1,0",
    ]));
    let (a, b, c) = (
        image::open(&a).unwrap().to_rgba8(),
        image::open(&b).unwrap().to_rgba8(),
        image::open(&c).unwrap().to_rgba8(),
    );
    assert_eq!(a.dimensions(), (48, 32));
    assert!(a == b && a == c, "the spellings differ");
    // The view shows the red square (what --target looks at).
    let p = a.get_pixel(24, 16);
    assert!(p[0] > 150 && p[1] < 80 && p[2] < 80, "{p:?}");
    let both = lightfield(&[
        "render",
        s(&raw),
        "--png",
        s(&tmp.path("both.png")),
        "--size",
        "48x32",
        "-W",
        "48",
    ]);
    assert!(!both.status.success());
    // Capture's vectors too.
    let obj = tmp.path("scene.obj");
    ok(&lightfield(&[
        "capture",
        "--obj",
        s(&obj),
        "--out",
        s(&tmp.path("side.plf")),
        "--uv",
        "2",
        "--st",
        "8",
        "--look",
        "-1,0,-1",
        "--up",
        "-0,1,0",
    ]));
}

#[test]
fn help_opens_with_this_tools_job() {
    let o = lightfield(&["--help"]);
    let help = ok(&o);
    let first = help.lines().next().unwrap_or_default();
    assert!(
        first.contains("light slabs")
            && first.contains("render views")
            && !first.contains("showcase"),
        "{first}"
    );
}
