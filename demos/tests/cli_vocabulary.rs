//! The command-line tools' shared vocabulary, end to end (issue 40): negative numbers in
//! vector flags without `=`, the same flag names in `render`, `warp` and `morph` (old
//! spellings still taken), each `--help` opening with its own job, and `warp`'s warning
//! when the view misses what the references saw.

use std::path::Path;
use std::process::{Command, Output};

mod common;
use common::{Tmp, TWO_SQUARES as SCENE};

fn run(bin: &str, args: &[&str]) -> Output {
    Command::new(bin).args(args).output().expect("run")
}

fn ok(out: &Output) -> String {
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "failed: {err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

const RENDER: &str = env!("CARGO_BIN_EXE_render");
const WARP: &str = env!("CARGO_BIN_EXE_warp");
const MORPH: &str = env!("CARGO_BIN_EXE_morph");

/// A capture of the two squares: three views around the origin from `0,0,4`.
fn capture(tmp: &Tmp) -> std::path::PathBuf {
    let obj = tmp.path("scene.obj");
    std::fs::write(&obj, SCENE).unwrap();
    let cap = tmp.path("cap");
    let mut args = vec!["--obj", s(&obj), "--eye", "0,0,4", "--target", "0,0,0"];
    args.extend(["--shading", "vertex", "-W", "64", "-H", "48"]);
    args.extend(["--capture", s(&cap), "--views", "3", "--spread", "20"]);
    ok(&run(RENDER, &args));
    cap
}

fn bytes(path: &Path) -> Vec<u8> {
    image::open(path).expect("a PNG").to_rgba8().into_raw()
}

#[test]
fn vector_flags_take_negative_numbers_without_equals() {
    let tmp = Tmp::new("cli-vocabulary", "negative");
    let obj = tmp.path("scene.obj");
    std::fs::write(&obj, SCENE).unwrap();
    // render: `--eye -1,2,3` is the same camera as `--eye=-1,2,3`.
    let (spaced, joined) = (tmp.path("spaced.png"), tmp.path("joined.png"));
    let size = ["-W", "48", "-H", "32"];
    let mut a = vec!["--obj", s(&obj), "--out", s(&spaced), "--eye", "-1,2,3"];
    a.extend(["--target", "-0.1,-0.2,0", "--up", "0,1,-0"]);
    a.extend(size);
    ok(&run(RENDER, &a));
    let mut b = vec!["--obj", s(&obj), "--out", s(&joined), "--eye=-1,2,3"];
    b.extend(["--target=-0.1,-0.2,0", "--up=0,1,-0"]);
    b.extend(size);
    ok(&run(RENDER, &b));
    let view = bytes(&spaced);
    assert_eq!(view, bytes(&joined));
    assert!(
        view.chunks_exact(4).any(|p| p != [0, 0, 0, 255]),
        "the squares are in view"
    );
    // A flag where a vector should be is still refused (a usage error, one line).
    let out = run(RENDER, &["--obj", s(&obj), "--eye", "--target", "1,2,3"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.starts_with("render: error: ") && err.trim_end().lines().count() == 1,
        "{err}"
    );

    // warp: negative target and reference eye.
    let cap = capture(&tmp);
    let png = tmp.path("warped.png");
    let mut w = vec!["--capture", s(&cap), "--eye", "-0.4,0.3,3.9"];
    w.extend(["--target", "-0.1,0,0", "--out", s(&png)]);
    ok(&run(WARP, &w));
    assert!(png.is_file());

    // morph: a negative number reaches the tool's own check instead of clap's
    // "unexpected argument".
    let out = run(
        MORPH,
        &[
            "--capture",
            s(&cap),
            "--t",
            "-0.5",
            "--out",
            s(&tmp.path("m")),
        ],
    );
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.starts_with("morph: error: --t -0.5: the parameter runs from 0 to 1"),
        "{err}"
    );
}

/// Each tool's `--help`: its first line, and the whole text.
fn help(bin: &str) -> (String, String) {
    let out = run(bin, &["--help"]);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "{bin} --help failed");
    let first = text.lines().next().unwrap_or_default().to_string();
    (first, text)
}

#[test]
fn each_help_opens_with_its_own_job_and_the_shared_flags() {
    let tools = [
        (RENDER, "Render one OBJ or glTF model"),
        (WARP, "new view from depth images"),
        (MORPH, "in-between views"),
        (env!("CARGO_BIN_EXE_showcase"), "showcase"),
        (env!("CARGO_BIN_EXE_bench"), "benchmark"),
    ];
    let mut firsts = Vec::new();
    for (bin, job) in tools {
        let (first, text) = help(bin);
        assert!(first.contains(job), "{bin}: {first:?} does not say {job:?}");
        assert!(
            !text.contains("the render CLI and the bench CLI"),
            "{bin}: {first}"
        );
        assert!(!firsts.contains(&first), "{bin}: {first:?} shared");
        firsts.push(first);
    }
    // The shared vocabulary where the tool has the idea; old spellings hidden.
    for bin in [RENDER, WARP] {
        let (_, text) = help(bin);
        for flag in [
            "-W, --width",
            "-H, --height",
            "--eye <X,Y,Z>",
            "--target <X,Y,Z>",
            "--up <X,Y,Z>",
            "--fov-y <DEG>",
            "--out <FILE>",
        ] {
            assert!(text.contains(flag), "{bin}: no {flag:?} in\n{text}");
        }
        assert!(!text.contains("--png <"), "{bin}: --png shown in\n{text}");
    }
    assert!(help(MORPH).1.contains("--out <DIR>"));
}

#[test]
fn old_spellings_still_work() {
    let tmp = Tmp::new("cli-vocabulary", "aliases");
    let cap = capture(&tmp);
    let obj = tmp.path("scene.obj");
    let (old, new) = (tmp.path("old.png"), tmp.path("new.png"));
    let args = |flag: &'static str, path: &Path| -> Vec<String> {
        let mut v: Vec<String> = ["--obj", s(&obj), "--width", "40", "--height", "30", flag]
            .map(String::from)
            .to_vec();
        v.push(s(path).to_string());
        v
    };
    ok(&Command::new(RENDER)
        .args(args("--png", &old))
        .output()
        .unwrap());
    ok(&Command::new(RENDER)
        .args(args("--out", &new))
        .output()
        .unwrap());
    assert_eq!(bytes(&old), bytes(&new));
    assert_eq!(image::open(&old).unwrap().width(), 40);
    let (old, new) = (tmp.path("wold.png"), tmp.path("wnew.png"));
    for (flag, path) in [("--png", &old), ("--out", &new)] {
        let a = ["--capture", s(&cap), "--eye", "0.3,0,3.9", flag, s(path)];
        ok(&run(WARP, &a));
    }
    assert_eq!(bytes(&old), bytes(&new));
}

/// Issue 40: an eye that sees nothing of what the references saw gave an empty view
/// without a word; now one warning line. A view that sees the squares gives none.
#[test]
fn warp_warns_when_the_view_misses_the_references() {
    let tmp = Tmp::new("cli-vocabulary", "warp-empty");
    let cap = capture(&tmp);
    let png = tmp.path("away.png");
    // From the middle reference's eye, looking away from the squares.
    let away = ["--eye", "0,0,4", "--target", "0,0,9", "--out", s(&png)];
    let mut a = vec!["--capture", s(&cap)];
    a.extend(away);
    let err = ok(&run(WARP, &a));
    let warnings: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("warp: warning: "))
        .collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(
        warnings[0].contains(&format!("cover 0 of {} pixels", 64 * 48)),
        "{}",
        warnings[0]
    );
    // The references' eyes: on an arc of radius 4 about the origin, 10 degrees either side
    // of 0,0,4, so their mean is 0,0,4 (1 + 2 cos 10) / 3 = 0,0,3.9595.
    assert!(
        warnings[0].contains("taken from around 0,0,3.95")
            && warnings[0].contains("--eye/--target"),
        "{}",
        warnings[0]
    );
    let toward = ["--eye", "0.2,0,3.8", "--target", "0,0,0", "--out", s(&png)];
    let mut a = vec!["--capture", s(&cap)];
    a.extend(toward);
    let err = ok(&run(WARP, &a));
    assert!(!err.contains("warning"), "{err}");
}
