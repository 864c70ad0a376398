//! A short, low-resolution headless tour: `summary.json` has the shape, and each
//! image-based attraction's PSNR against its geometry and its flicker stay within bounds.
//!
//! The goals (issue 39) are mean >= 30 dB, worst >= 25 dB and flicker <= 1.5 for every
//! attraction; the attractions are being fixed on other branches, so the bounds below are
//! what this branch's code achieves in this run, with a margin, each with its gap to the
//! goal. Raise them as the attractions improve.

use serde_json::Value;
use std::path::PathBuf;

mod showcase_common;
use showcase_common::run_showcase;

const W: &str = "240";
const H: &str = "136";
const FRAMES: &str = "24";

/// Bounds of one attraction: least mean PSNR, least worst PSNR (dB), most flicker
/// (`None`: not measured, the figure must be `null`).
struct Bound {
    name: &'static str,
    technique: &'static str,
    part: &'static str,
    mean: Option<f64>,
    worst: Option<f64>,
    flicker: Option<f64>,
}

const GOAL: (f64, f64, f64) = (30.0, 25.0, 1.5);

/// Runs the tour `--no-save` (the summary is written anyway) and parses its summary.
fn summary() -> Value {
    run("showcase_attractions", &["--frames", FRAMES])
}

/// Runs the showcase headless into `name` with `args` at [`W`] x [`H`], `--no-save`, and
/// parses its summary.
fn run(name: &str, args: &[&str]) -> Value {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    let dir_arg = dir.to_string_lossy().into_owned();
    let mut all: Vec<&str> = vec!["--headless", &dir_arg];
    all.extend(args);
    all.extend(["-W", W, "-H", H, "--no-save"]);
    let stdout = run_showcase(&all);
    assert!(stdout.contains("summary (frame times exclude"), "{stdout}");
    assert!(
        !dir.join("frame_0000.png").exists(),
        "--no-save wrote frames"
    );
    let text = std::fs::read_to_string(dir.join("summary.json")).expect("summary.json written");
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}: {text}"))
}

#[test]
fn summary_has_the_shape_and_the_attractions_stay_within_bounds() {
    let s = summary();
    let frames = [("tour", 24), ("building", 12), ("views", 3), ("world", 3)];
    let parts = s["parts"].as_object().expect("parts");
    assert_eq!(parts.len(), 4);
    for (part, n) in frames {
        let p = &parts[part];
        assert_eq!(p["frames"].as_u64(), Some(n), "{part}");
        let ms = p["ms"].as_object().expect("ms");
        let keys: Vec<&str> = ms.keys().map(String::as_str).collect();
        let mut want = ["median", "p90", "p99", "max", "max_frame"];
        want.sort();
        let mut keys = keys;
        keys.sort();
        assert_eq!(keys, want, "{part}");
        let f = |k: &str| ms[k].as_f64().expect(k);
        assert!(
            f("median") > 0.0 && f("median") <= f("p90"),
            "{part}: {ms:?}"
        );
        assert!(
            f("p90") <= f("p99") && f("p99") <= f("max"),
            "{part}: {ms:?}"
        );
        assert!(ms["max_frame"].as_u64().expect("max_frame") < n, "{part}");
    }
    let list = s["attractions"].as_array().expect("attractions");
    assert_eq!(list.len(), BOUNDS.len());
    // Every figure first, so a failure shows them all.
    for a in list {
        println!("{a}");
    }
    for (a, b) in list.iter().zip(&BOUNDS) {
        let name = a["name"].as_str().expect("name");
        assert_eq!(name, b.name);
        assert_eq!(a["technique"].as_str(), Some(b.technique), "{name}");
        assert_eq!(a["part"].as_str(), Some(b.part), "{name}");
        let n = a["frames"].as_u64().expect("frames");
        let (mean, worst) = (&a["psnr_db"]["mean"], &a["psnr_db"]["worst"]);
        let flicker = &a["flicker"];
        println!(
            "{name}: {n} frames, PSNR {mean} / {worst} dB, flicker {flicker} (goals {:?})",
            GOAL
        );
        check(name, "mean PSNR", mean, b.mean, |v, b| v >= b);
        check(name, "worst PSNR", worst, b.worst, |v, b| v >= b);
        check(name, "flicker", flicker, b.flicker, |v, b| v <= b);
        if b.mean.is_some() {
            assert!(n > 0, "{name}: measured in no frame");
            let (m, w) = (mean.as_f64().unwrap(), worst.as_f64().unwrap());
            assert!(w <= m, "{name}: worst {w} above mean {m}");
        }
    }
}

/// The views moment alone, two frames of each part: each of its attractions has a flicker
/// (its two frames are consecutive), measured 1.00, 0.97 and 0.95 (layers, panorama,
/// morph): within the goal.
#[test]
fn the_views_attractions_have_a_flicker() {
    let s = run("showcase_views_flicker", &["--frames", "6", "--views"]);
    let list = s["attractions"].as_array().expect("attractions");
    for a in list.iter().filter(|a| a["part"] == "views") {
        assert_eq!(a["frames"].as_u64(), Some(2), "{a}");
        let f = a["flicker"].as_f64().unwrap_or_else(|| panic!("{a}"));
        assert!(f > 0.0 && f <= 1.3, "{a}");
    }
}

/// `value` is a number within `bound` by `ok`, or `null` when there is no bound.
fn check(name: &str, what: &str, value: &Value, bound: Option<f64>, ok: fn(f64, f64) -> bool) {
    match bound {
        Some(b) => {
            let v = value
                .as_f64()
                .unwrap_or_else(|| panic!("{name}: {what} {value}"));
            assert!(ok(v, b), "{name}: {what} {v} outside its bound {b}");
        }
        None => assert!(value.is_null(), "{name}: {what} {value}, expected null"),
    }
}

/// Bounds per attraction, in the summary's order: this run's figures (240x136, 24 tour
/// frames) less a margin of about 1.5 dB (flicker: +0.3 or more), each with its gap to the
/// goals [`GOAL`].
const BOUNDS: [Bound; 8] = [
    // Measured 30.1 / 28.1 dB over 4 frames, flicker 0.97, with the outline from geometry
    // and raw 8 x 8 slabs (session 11; 22.0 / 20.9 with the light field's own outline and
    // 4096 codewords; the urn, and geometry where it is under 24 px on screen): meets
    // the goals.
    Bound {
        name: "statue",
        technique: "light field",
        part: "tour",
        mean: Some(28.5),
        worst: Some(26.5),
        flicker: Some(1.3),
    },
    // Measured 49.2 dB in the one frame warped at this size (the rooms drawn as geometry
    // are now the occluder, not in the mask; a warp leaving over 5% of its opening holes
    // draws its room's geometry): meets the goals; flicker not measured here (no two
    // consecutive warped frames; 1.01 over 33 frames at 640x360).
    Bound {
        name: "portals",
        technique: "LDI portals",
        part: "building",
        mean: Some(45.0),
        worst: Some(45.0),
        flicker: None,
    },
    // Measured 40.8 / 40.8 dB (51.5 before its first frame drew all its layers as images
    // made while loading, not 16 re-rendered and the rest as geometry): meets the PSNR
    // goals; flicker not measured.
    Bound {
        name: "background",
        technique: "image layers",
        part: "views",
        mean: Some(39.0),
        worst: Some(39.0),
        flicker: None,
    },
    // Measured 28.6 / 28.6 dB (release binary of the same source, these arguments), since
    // session 11 the panorama carrying the far land (a ring of mountains 650 to 1,200 units
    // away) and the plaza's scene drawn in front; 24.6 before, holding the trees and hills
    // 60 units away. At 640x360 and 1280x720 31.9 / 30.3 and 34.6 / 32.6 dB (BENCHMARKS.md);
    // here, at 240x136, the ridges' outlines are a larger share of its few pixels (3% of
    // the frame): 1.4 dB short of the mean, the worst meets its goal; flicker not measured.
    Bound {
        name: "sky",
        technique: "panorama",
        part: "views",
        mean: Some(27.5),
        worst: Some(27.5),
        flicker: None,
    },
    // Measured 25.9 / 25.9 dB: mean 4.1 dB short, worst meets its goal;
    // flicker not measured.
    Bound {
        name: "morph",
        technique: "view morph",
        part: "views",
        mean: Some(24.0),
        worst: Some(24.0),
        flicker: None,
    },
    // Measured 39.7 / 29.6 dB, flicker 1.00, since session 11: each impostor's image is
    // projected onto its building's box (`Shape::Box`), so its outline and depth are the
    // box's and images and geometry occlude one another per pixel; meets the goals.
    // Before, 22.8 / 20.7 as cutouts on a quad at the nearest corner: silhouettes half a
    // texel off and slivers drawn over nearer buildings (20.5 / 16.5 at one texel a
    // pixel); over the buildings drawn from images alone (those drawn as geometry are the
    // occluder).
    // Session 12: 43.0 / 31.1 dB (39.7 / 29.6 before), the images taken at 3 texels a
    // pixel (was 2) and retaken once a box face their eye saw edge-on shows; session 13,
    // with a rebuild priced as the image it takes: 42.7 / 31.3.
    Bound {
        name: "city",
        technique: "impostors",
        part: "tour",
        mean: Some(41.5),
        worst: Some(29.5),
        flicker: Some(1.3),
    },
    // Measured 30.99 / 25.58 dB, flicker 1.00, since session 30: each fragment shows the
    // texel whose surface lies on its ray (`ViewAtlas::parallax`: the views are
    // orthographic, the tour sees them in perspective) and the views are read no coarser
    // than level 1.5 (`ViewAtlas::max_lod`: the meshes are drawn sharp), on one level
    // (`DepthOffset`: not blended across two; 31.00 / 26.38 blended, the worst frame at
    // this size 0.8 dB lower on one level where at 640 x 360 and 1280 x 720 it is within
    // 0.03); 25.84 / 20.96 before, the bounds raised 25.6 / 20.6 -> 30.5 / 25.3 (the
    // goals, 30 / 25, met).
    // Measured 25.84 / 20.96 dB, flicker 1.00, since session 29: the sprites drawn as
    // nailboards (a flat outline, each fragment at its texel's own depth, tested before
    // its colour is read); 25.32 / 20.97 before, the mean bound raised 25.1 -> 25.6.
    // Measured 25.32 / 20.97 dB, flicker 1.00, since session 19: each view's depth node
    // the nearest surface within 0.3 of a node spacing of it (was half a spacing: a node
    // stood at a crown's front its share only grazed); 25.05 / 20.96 before, the mean
    // bound raised 24.8 -> 25.1.
    // Measured 25.05 / 20.96 dB, flicker 1.01, since session 18: each sprite drawn over
    // its view's trim as baked, not grown a screen pixel (24.91 / 20.96 before; the mean
    // bound raised 24.6 -> 24.8).
    // Measured 24.9 / 21.0 dB, flicker 1.01, since session 16: the views baked from 10
    // degrees below the horizon (the hills' trees seen from the plaza) and each view's
    // depth on a 5 x 5 grid (was 3 x 3: a trunk's foot stood at its crown's front, over the
    // nearer trees); main had 24.3 / 21.0 at this size.
    // Measured 24.3 / 21.0 dB, flicker 1.01, since session 15: the pine's views stood lower
    // the higher they were baked (`ViewAtlas::pivot_steep`: from above its outline is its
    // lowest cone's rim); main had 24.2 / 21.0 at this size (the worst frame unchanged).
    // Session 14: 24.2 / 21.0 dB, flicker 1.01: each view stood on the plane
    // through its crown's centre (`ViewAtlas::pivot`; through the tree's centre a near
    // crown showed a pixel low and small), the view chosen from up in the crown (its sunlit
    // rim showed brighter), 12 views over the half turn from the sun mirrored on the other
    // half (`ViewAtlas::bake_turned`). Session 13: 23.2 / 17.1.
    // Measured 23.3 / 17.1 dB, flicker 1.01, since session 12: the trees are turned about
    // the vertical (one outline from every azimuth, `ibr_layer::lathe`) and baked from 8
    // azimuths every 5 degrees of elevation (was 12 every 10). The worst frame at this size
    // lost 1.2 dB (18.3 before) where at 640 x 360 and 1280 x 720 it gained 1.3 (18.2 ->
    // 19.5, 18.3 -> 19.6): the bound's worst is lowered to match, not raised. Session 10:
    // 23.1 / 18.3, the views baked under the light the forest receives (the sun and the
    // ambient), the trees matte, elevations every 10 degrees (was 20). Session 9: 21.0 /
    // 17.3, the sprites carrying their trees' depth (each view's 3 x 3 grid,
    // `ViewAtlas::relief`) and smooth-shaded crowns; before, 20.0 / 16.0 as flat cutouts,
    // 14.7 / 13.0 from one side bake. Over the billboards' pixels alone (the trees drawn as
    // meshes are the occluder), against the tree meshes where the billboards stand. 6.7 and
    // 7.9 dB short of the PSNR goals: most of what is left is on outlines (pixels one
    // render covers and the other not: the orthographic bake against the mesh in
    // perspective, a sub-pixel shift that flips whole rows of aliased pixels) and crown
    // against crown; flicker within.
    Bound {
        name: "forest",
        technique: "billboards",
        part: "tour",
        mean: Some(30.5),
        worst: Some(25.3),
        flicker: Some(1.3),
    },
    // Measured 41.5 / 26.8 dB, flicker 1.00 (against particles prepared for the frame's
    // eye; the clouds judged by their parallax in pixels, 1 px): meets the goals. Before
    // the puffs faced the eye point they faced the image plane, and a cloud near the
    // view's edge covered less than its image taken straight on showed: 31.7 / 21.9 dB.
    Bound {
        name: "clouds",
        technique: "cloud impostors",
        part: "tour",
        mean: Some(40.0),
        worst: Some(25.3),
        flicker: Some(1.3),
    },
];
