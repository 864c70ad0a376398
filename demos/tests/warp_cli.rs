//! `render --capture` and `warp` end to end: a capture written by the engine is read back
//! and warped to a new camera, agreeing with a render from that camera; bad input is a
//! one-line error naming the file.

use std::path::Path;
use std::process::{Command, Output};

mod common;
use common::{Tmp, TWO_SQUARES as SCENE};

fn run(bin: &str, args: &[&str]) -> Output {
    Command::new(bin).args(args).output().expect("run")
}

fn render(args: &[&str]) -> Output {
    run(env!("CARGO_BIN_EXE_render"), args)
}

fn warp(args: &[&str]) -> Output {
    run(env!("CARGO_BIN_EXE_warp"), args)
}

fn ok(out: &Output) {
    assert!(
        out.status.success(),
        "failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn a_capture_warps_to_what_a_render_from_there_shows() {
    let tmp = Tmp::new("warp-cli", "roundtrip");
    let obj = tmp.path("scene.obj");
    std::fs::write(&obj, SCENE).unwrap();
    let cap = tmp.path("cap");
    let common = [
        "--shading",
        "vertex",
        "-W",
        "96",
        "-H",
        "72",
        "--target",
        "0,0,0",
    ];
    let mut args = vec!["--obj", s(&obj), "--eye", "0,0,4", "--capture", s(&cap)];
    args.extend(["--views", "3", "--spread", "24"]);
    args.extend(common);
    ok(&render(&args));
    for f in ["transforms.json", "images/0000.png", "depth/0002.pfm"] {
        assert!(cap.join(f).is_file(), "{f} written");
    }
    // A view between the captured ones, a little higher.
    let (png, truth, holes, depth) = (
        tmp.path("warped.png"),
        tmp.path("truth.png"),
        tmp.path("holes.png"),
        tmp.path("warped.pfm"),
    );
    let out = warp(&[
        "--capture",
        s(&cap.join("transforms.json")),
        "--eye",
        "0.6,0.4,3.9",
        "--fov-y",
        "60",
        "--png",
        s(&png),
        "--holes",
        s(&holes),
        "--depth-out",
        s(&depth),
    ]);
    ok(&out);
    let log = String::from_utf8_lossy(&out.stderr);
    assert!(log.contains("2 of 3 reference(s)"), "{log}");
    let mut args = vec!["--obj", s(&obj), "--eye", "0.6,0.4,3.9", "--png", s(&truth)];
    args.extend(common);
    ok(&render(&args));
    let a = image::open(&png).unwrap().to_rgba8();
    let b = image::open(&truth).unwrap().to_rgba8();
    assert_eq!(a.dimensions(), (96, 72));
    // The capture holds the bytes the render CLI writes (unorm vertex colours), and the
    // warp writes them back as they were read: compare the bytes.
    let mut off = 0;
    for (pa, pb) in a.pixels().zip(b.pixels()) {
        let d = (0..3)
            .map(|c| (f32::from(pa[c]) - f32::from(pb[c])).abs() / 255.0)
            .fold(0.0, f32::max);
        if d > 0.1 {
            off += 1;
        }
    }
    assert!(off < 96 * 72 / 20, "{off} pixels differ from the render");
    // Depth: the squares are 3.5 to 5 units from this eye.
    let d = engine::load::float_image(&depth).unwrap();
    let centre = d.data[(36 * 96 + 48) as usize];
    assert!(centre > 3.0 && centre < 4.0, "{centre}");
    let mask = image::open(&holes).unwrap().to_rgba8();
    assert_eq!(mask.dimensions(), (96, 72));
}

#[test]
fn bad_input_is_one_line_naming_the_file() {
    let tmp = Tmp::new("warp-cli", "bad");
    let json = tmp.path("transforms.json");
    std::fs::write(&json, r#"{"camera_angle_x": 1, "frames": []}"#).unwrap();
    let png = tmp.path("o.png");
    for (args, want) in [
        (vec!["--capture", s(&json)], "frames"),
        (
            vec!["--capture", s(&tmp.path("missing.json"))],
            "missing.json",
        ),
        (
            vec![
                "--colour",
                s(&tmp.path("c.png")),
                "--depth",
                s(&tmp.path("d.pfm")),
            ],
            "c.png",
        ),
    ] {
        let mut all = args.clone();
        all.extend(["--eye", "0,0,3", "--png", s(&png)]);
        let out = warp(&all);
        assert_eq!(out.status.code(), Some(1));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.starts_with("warp: error: ") && err.contains(want),
            "{err}"
        );
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    }
}
