//! The showcase's world moment headless at low resolution, a few frames: its PNGs,
//! `summary.json`'s `world` part with the keys every part has, and the planner's readout
//! per frame (nodes opened, and every object in view drawn exactly once by the cut).

use demos::showcase::world::READOUT_ROWS;
use serde_json::Value;
use std::path::PathBuf;

mod showcase_common;
use showcase_common::run_showcase;

const FRAMES: usize = 4;

/// Runs `showcase --world` headless at 160 x 96 into `name` with `args`; its folder,
/// standard output and parsed summary.
fn run_world(name: &str, args: &[&str]) -> (PathBuf, String, Value) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    let frames = FRAMES.to_string();
    let dir_arg = dir.to_string_lossy().into_owned();
    let mut all: Vec<&str> = args.to_vec();
    all.extend([
        "--headless",
        &dir_arg,
        "--world",
        "--frames",
        &frames,
        "-W",
        "160",
        "-H",
        "96",
    ]);
    let stdout = run_showcase(&all);
    let text = std::fs::read_to_string(dir.join("summary.json")).expect("summary.json written");
    let summary = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}: {text}"));
    (dir, stdout, summary)
}

/// The number just before `word` in `line` (`12 NODES OPENED` -> 12).
fn before(line: &str, word: &str) -> u64 {
    let at = line
        .find(word)
        .unwrap_or_else(|| panic!("{word:?} in {line}"));
    let n = line[..at].split_whitespace().last().expect("a number");
    n.trim_start_matches('(')
        .parse()
        .unwrap_or_else(|_| panic!("{n:?} before {word:?} in {line}"))
}

#[test]
fn the_world_moment_runs_headless_with_its_readout_and_summary() {
    let (dir, stdout, s) = run_world("showcase_world", &[]);
    for i in 0..FRAMES {
        let img = image::open(dir.join(format!("world_{i:04}.png")))
            .expect("world frame decodes")
            .to_rgba8();
        assert_eq!(img.dimensions(), (160, 96));
    }
    assert!(!dir.join(format!("world_{FRAMES:04}.png")).exists());
    // The readout is drawn in at the top left, in the window's text colour.
    let first = image::open(dir.join("world_0000.png"))
        .expect("frame")
        .to_rgba8();
    let text = (0..40)
        .flat_map(|y| (0..160).map(move |x| (x, y)))
        .filter(|&(x, y)| first.get_pixel(x, y).0 == [255, 255, 128, 255])
        .count();
    assert!(text > 50, "{text} readout pixels");
    // Only the world: the other parts are there with no frames.
    let parts = s["parts"].as_object().expect("parts");
    for part in ["tour", "building", "views"] {
        assert_eq!(parts[part]["frames"].as_u64(), Some(0), "{part}");
    }
    let world = &parts["world"];
    assert_eq!(world["frames"].as_u64(), Some(FRAMES as u64));
    let ms = world["ms"].as_object().expect("ms");
    let mut keys: Vec<&str> = ms.keys().map(String::as_str).collect();
    keys.sort();
    assert_eq!(keys, ["max", "max_frame", "median", "p90", "p99"]);
    let f = |k: &str| ms[k].as_f64().expect(k);
    assert!(f("median") > 0.0 && f("median") <= f("p90"), "{ms:?}");
    assert!(f("p90") <= f("p99") && f("p99") <= f("max"), "{ms:?}");
    assert!(ms["max_frame"].as_u64().expect("max_frame") < FRAMES as u64);
    // The error measured against all the geometry: there, and null for the other parts.
    let error = &world["error_levels"];
    let (mean, worst) = (error["mean"].as_f64(), error["worst"].as_f64());
    assert!(
        matches!((mean, worst), (Some(m), Some(w)) if 0.0 <= m && m <= w),
        "{error}"
    );
    assert!(parts["tour"]["error_levels"].is_null());
    // One readout line a frame: the cut opened nodes, and drew every object in view once.
    let lines: Vec<&str> = stdout.lines().filter(|l| l.contains("WORLD ")).collect();
    assert_eq!(lines.len(), FRAMES, "{stdout}");
    for line in &lines {
        assert!(before(line, "NODES OPENED") > 0, "{line}");
        let objects = before(line, "OBJECTS  ");
        let (once, in_view) = (before(line, "of "), before(line, "in view drawn once"));
        assert!(in_view > 0 && in_view <= objects, "{line}");
        assert!(line.contains("MEASURED ERROR "), "{line}");
        assert_eq!(once, in_view, "{line}");
        assert!(
            before(line, "GEOMETRY") + before(line, "IMAGES") > 0,
            "{line}"
        );
    }
    // After the loading frames the far field is imaged.
    assert!(before(lines[FRAMES - 1], "IMAGES") > 0, "{stdout}");
}

#[test]
fn the_world_moment_is_the_same_on_one_and_two_threads() {
    let (one, _, _) = run_world("showcase_world_1", &["--threads", "1"]);
    let (two, _, _) = run_world("showcase_world_2", &["--threads", "2"]);
    for i in 0..FRAMES {
        let name = format!("world_{i:04}.png");
        let a = image::open(one.join(&name))
            .expect("frame")
            .to_rgba8()
            .into_raw();
        let b = image::open(two.join(&name))
            .expect("frame")
            .to_rgba8()
            .into_raw();
        // Below the readout (which shows each run's own times): the same pixels.
        let below = (READOUT_ROWS * 160 * 4) as usize;
        assert_eq!(a.len(), b.len());
        assert!(
            a[below..] == b[below..],
            "{name} differs between 1 and 2 threads"
        );
    }
}
