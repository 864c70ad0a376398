//! Runs the showcase binary headless and checks the frames it writes and what it prints.

use std::path::PathBuf;

mod showcase_common;
use showcase_common::run_showcase;
use std::process::Command;

/// Runs the showcase headless into `dir` with `args`, `frames` frames at 160 x 90; its
/// standard output (it must succeed).
fn run_headless(dir: &std::path::Path, args: &[&str], frames: usize) -> String {
    let frames = frames.to_string();
    let dir_arg = dir.to_string_lossy().into_owned();
    let mut all: Vec<&str> = args.to_vec();
    all.extend([
        "--headless",
        &dir_arg,
        "--frames",
        &frames,
        "-W",
        "160",
        "-H",
        "90",
    ]);
    run_showcase(&all)
}

#[test]
fn headless_writes_frames_and_prints_statistics() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("showcase_headless");
    let _ = std::fs::remove_dir_all(&dir);
    let stdout = run_headless(&dir, &[], 3);
    for word in ["median", "min", "p90", "fragments_shaded", "triangles_in"] {
        assert!(stdout.contains(word), "missing {word:?} in:\n{stdout}");
    }
    let mut frames = Vec::new();
    for i in 0..3 {
        let path = dir.join(format!("frame_{i:04}.png"));
        let img = image::open(&path).expect("frame decodes").to_rgba8();
        assert_eq!(img.dimensions(), (160, 90));
        frames.push(img);
    }
    assert!(!dir.join("frame_0003.png").exists());
    // Then the building walkthrough: half as many frames (at least one).
    assert!(stdout.contains("portals over the tour:"), "{stdout}");
    let building = image::open(dir.join("building_0000.png"))
        .expect("building frame")
        .to_rgba8();
    assert_eq!(building.dimensions(), (160, 90));
    assert!(!dir.join("building_0001.png").exists());
    // Then the views moment: three frames at least, the layers', the panorama sky's and
    // the morph's.
    for word in [
        "LAYERED BACKGROUND",
        "layered background: 1 frames",
        "PANORAMA SKY",
        "VIEW MORPH",
        "panorama sky: 1 frames",
        "view morph: 1 frames",
    ] {
        assert!(stdout.contains(word), "missing {word:?} in:\n{stdout}");
    }
    let views = image::open(dir.join("views_0000.png"))
        .expect("views frame")
        .to_rgba8();
    assert_eq!(views.dimensions(), (160, 90));
    assert!(dir.join("views_0002.png").exists());
    assert!(!dir.join("views_0003.png").exists());
    // Where each views frame's time went: a row a frame, a column a stage, then the CPU time
    // of all threads showing it and of the thread that called.
    let csv = std::fs::read_to_string(dir.join("views_times.csv")).expect("views_times.csv");
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(
        lines[0],
        "frame,ms,layers,sky,morph_canvas,postwarp,over_sky,geometry_render,readout,cpu,cpu_caller"
    );
    assert_eq!(lines.len(), 4, "{csv}");
    assert!(
        lines[1..].iter().all(|l| l.split(',').count() == 11),
        "{csv}"
    );
    // Sky at the top, something else (ground, objects) at the bottom, and the camera moves.
    let f = &frames[0];
    let top = f.get_pixel(80, 2).0;
    let bottom = f.get_pixel(80, 87).0;
    assert!(top[2] > top[0], "sky is blue: {top:?}");
    assert_ne!(top, bottom);
    assert_ne!(frames[0].as_raw(), frames[1].as_raw());
}

#[test]
fn headless_frames_do_not_depend_on_thread_count() {
    let run = |name: &str, threads: &str| {
        let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
        let _ = std::fs::remove_dir_all(&dir);
        let status = Command::new(env!("CARGO_BIN_EXE_showcase"))
            .arg("--headless")
            .arg(&dir)
            .args([
                "--frames",
                "2",
                "-W",
                "96",
                "-H",
                "64",
                "--threads",
                threads,
            ])
            .output()
            .expect("showcase runs")
            .status;
        assert!(status.success());
        std::fs::read(dir.join("frame_0001.png")).unwrap()
    };
    assert_eq!(
        run("showcase_threads_1", "1"),
        run("showcase_threads_2", "2")
    );
}

#[test]
fn headless_debug_view_tints_impostors_and_prints_their_statistics() {
    let run = |name: &str, debug: bool| {
        let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
        let _ = std::fs::remove_dir_all(&dir);
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_showcase"));
        cmd.arg("--headless")
            .arg(&dir)
            .args(["--frames", "3", "-W", "160", "-H", "90"]);
        if debug {
            cmd.arg("--debug-impostors");
        }
        let out = cmd.output().expect("showcase runs");
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(
            out.status.success(),
            "{stdout}\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let frame = image::open(dir.join("frame_0000.png"))
            .expect("frame decodes")
            .to_rgba8();
        (stdout, frame)
    };
    let (stdout, tinted) = run("showcase_debug_impostors", true);
    for words in [
        "impostors: 14 clouds; planner: 25 buildings as geometry, impostors, layers (debug view",
        "geometry=white impostors=green layers=blue",
        "refreshes: total",
        "per frame, peak",
        "predicted error ratio (1 = tolerance or budget) of the images shown: max",
        "frames showing an image over its tolerance: ",
        "city: ",
        "building-frames as geometry ",
        "last frame: CLOUDS",
        "last frame: CITY GEOMETRY",
        "median",
    ] {
        assert!(stdout.contains(words), "missing {words:?} in:\n{stdout}");
    }
    // Images were made: the first frame captures the visible clouds and city's first few.
    let total: usize = stdout
        .split("refreshes: total ")
        .nth(1)
        .and_then(|s| s.split(',').next())
        .and_then(|s| s.trim().parse().ok())
        .expect("a total");
    assert!(total > 0, "{stdout}");
    // The first frame sees the city behind the house: its fresh impostors turn green, the
    // buildings drawn as geometry flat white.
    let (plain_out, plain) = run("showcase_plain_impostors", false);
    assert!(!plain_out.contains("debug view"));
    let greener = plain
        .pixels()
        .zip(tinted.pixels())
        .filter(|(p, q)| q[1] as i32 - q[0] as i32 > 40 && (p[1] as i32 - p[0] as i32) < 40)
        .count();
    assert!(greener > 20, "{greener} pixels turned green");
    let white = |p: &image::Rgba<u8>| p.0[..3] == [255; 3];
    let whiter = plain
        .pixels()
        .zip(tinted.pixels())
        .filter(|(p, q)| white(q) && !white(p))
        .count();
    eprintln!("{greener} pixels turned green, {whiter} white");
    assert!(whiter > 20, "{whiter} pixels turned white");
}

#[test]
fn the_building_tour_warps_its_rooms_through_portals() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("showcase_building");
    let _ = std::fs::remove_dir_all(&dir);
    // 24 frames: at 12 the walk's steps are so long that every warp of the LDIs built so
    // far leaves more than `MAX_LDI_HOLES` of its opening as holes, and each such portal
    // draws its room's geometry instead (2 of 34 portal-frames warp at 24, 24 of 89 at 60).
    const FRAMES: usize = 24;
    let stdout = run_headless(&dir, &["--building", "--debug-portals"], FRAMES);
    // "portals over the tour: N warped and M drawn as geometry ...": some warped.
    let warped: u64 = stdout
        .split("portals over the tour: ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no portal summary in:\n{stdout}"));
    assert!(warped > 0, "{stdout}");
    for word in [
        "LDI rebuilds",
        "samples warped",
        "holes",
        "tinted green",
        "PORTALS",
    ] {
        assert!(stdout.contains(word), "missing {word:?} in:\n{stdout}");
    }
    for i in 0..FRAMES {
        let img = image::open(dir.join(format!("building_{i:04}.png"))).expect("frame decodes");
        assert_eq!(img.width(), 160);
    }
}
