//! Runs the `bench` binary's smallest image-based sweeps end to end (warp, portals, light
//! fields, stereo, morph, panorama, layers, budget) and checks what they write: a CSV with
//! a header and rows, and charts that are real PNG images.

mod bench_common;
use bench_common::*;
use std::process::Command;

#[test]
fn warp_sweep_writes_csv_and_png_charts() {
    let (dir, csv) = run_sweep("warp", &[]);
    let t = Table::parse(&csv);
    assert_eq!(&t.header[..3], ["series", "value", "method"]);
    let rows: Vec<&Vec<&str>> = t.rows.iter().collect();
    let method = t.col("method");
    // At the home eye one reference is the truth: warped to itself it is exact.
    let home: Vec<_> = rows
        .iter()
        .filter(|r| {
            r[0] == "distance"
                && r[1] == "0"
                && ["points", "splats", "splats-background"].contains(&r[method])
                && t.num(r, "references") == 1.0
        })
        .collect();
    assert_eq!(home.len(), 3, "{csv}");
    for r in home {
        assert_eq!(t.num(r, "psnr_db"), 99.0, "{r:?}");
        assert_eq!(t.num(r, "holes"), 0.0, "{r:?}");
    }
    // Moving away opens holes with one reference; two references close most of them.
    let holes = |refs: f64| {
        rows.iter()
            .filter(|r| {
                r[0] == "distance"
                    && r[1] == "0.2"
                    && r[method] == "splats"
                    && t.num(r, "references") == refs
            })
            .map(|r| t.num(r, "holes"))
            .next()
            .expect("a point")
    };
    assert!(holes(1.0) > 0.01 && holes(2.0) < holes(1.0) / 2.0, "{csv}");
    // Every warp point warped samples; every point has a time.
    for r in &rows {
        assert!(t.num(r, "median_ms") > 0.0, "{r:?}");
        if r[method] != "geometry" {
            assert!(t.num(r, "samples") > 0.0, "{r:?}");
        }
    }
    // The speed series times both fills.
    for fill in ["splats", "splats-background"] {
        assert!(
            rows.iter().any(|r| r[0] == "speed" && r[method] == fill),
            "{fill}: {csv}"
        );
    }
    assert!(rows.iter().any(|r| r[method] == "ldi"), "{csv}");
    // The home view's mesh was drawn.
    assert!(
        rows.iter()
            .any(|r| r[method] == "mesh" && t.num(r, "samples") > 0.0),
        "{csv}"
    );
    assert_charts(
        &dir,
        &[
            "warp_distance.png",
            "warp_angle.png",
            "warp_holes.png",
            "warp_time.png",
            "warp_predicted.png",
        ],
    );
}

#[test]
fn portals_sweep_writes_csv_and_png_charts() {
    let (dir, csv) = run_sweep("portals", &[]);
    let t = Table::parse(&csv);
    assert_eq!(&t.header[..3], ["series", "method", "t"]);
    // Every method at every furniture size; the portals give the rasterizer the hall alone
    // and warp as many samples whatever the rooms hold, while geometry gets every triangle.
    let sizes: Vec<f64> = t
        .of("triangles", "geometry")
        .iter()
        .map(|r| t.num(r, "room_triangles"))
        .collect();
    assert_eq!(sizes.len(), 2, "{csv}");
    for method in ["flat", "depth-image", "ldi"] {
        let rows = t.of("triangles", method);
        assert_eq!(rows.len(), 2, "{method}: {csv}");
        assert_eq!(
            t.num(rows[0], "triangles_in"),
            t.num(rows[1], "triangles_in")
        );
        let (a, b) = (t.num(rows[0], "samples"), t.num(rows[1], "samples"));
        assert!(
            a > 0.0 && (a - b).abs() <= 0.02 * a,
            "{method}: {a} and {b}"
        );
        assert!(t.num(rows[0], "psnr_db") > 25.0, "{method}: {csv}");
    }
    let geometry = t.of("triangles", "geometry");
    assert!(t.num(geometry[1], "triangles_in") > t.num(geometry[0], "triangles_in"));
    assert!(t.rows.iter().any(|r| r[0] == "walk"), "{csv}");
    assert_charts(
        &dir,
        &[
            "portals_triangles.png",
            "portals_resolution.png",
            "portals_walk_error.png",
            "portals_walk_time.png",
            "portals_time_error.png",
        ],
    );
}

#[test]
fn lightfield_sweep_writes_csv_and_png_charts() {
    let (dir, csv) = run_sweep("lightfield", &[]);
    let t = Table::parse(&csv);
    assert_eq!(&t.header[..3], ["series", "method", "eye_class"]);
    // Every lookup at every density and every eye, with an error against geometry.
    for lookup in ["nearest", "bilinear-uv", "quadrilinear", "quadrilinear-dc"] {
        let rows = t.of("density", lookup);
        assert_eq!(rows.len(), 2 * 6, "{lookup}: {csv}");
        for r in rows {
            let psnr = t.num(r, "psnr_db");
            assert!(psnr > 10.0 && psnr.is_finite(), "{lookup}: {r:?}");
            assert!(t.num(r, "rays") > 0.0 && t.num(r, "pixels") > 0.0, "{r:?}");
        }
    }
    // The outline from geometry, at every eye on the raw base slab, beside the same
    // lookup without it.
    for method in ["quadrilinear-dc", "dc+outline"] {
        let rows = t.of("outline", method);
        assert_eq!(rows.len(), 6, "{method}: {csv}");
        for r in rows {
            let psnr = t.num(r, "psnr_db");
            assert!(psnr > 10.0 && psnr.is_finite(), "{method}: {r:?}");
        }
    }
    // Quantised rows: smaller than raw in memory and on disk.
    for r in t.of("codebook", "quadrilinear-dc") {
        assert!(t.num(r, "bytes") < t.num(r, "raw_bytes"), "{r:?}");
        assert!(t.num(r, "file_bytes") < t.num(r, "raw_file_bytes"), "{r:?}");
    }
    // The light field casts as many rays and reads about as many samples whatever the
    // object's triangles (the tessellation moves its silhouette a little); the geometry
    // gets them all.
    let lf = t.of("triangles", "quadrilinear-dc");
    assert_eq!(lf.len(), 2, "{csv}");
    assert_eq!(t.num(lf[0], "rays"), t.num(lf[1], "rays"));
    let (a, b) = (t.num(lf[0], "taps"), t.num(lf[1], "taps"));
    assert!((a - b).abs() <= 0.05 * a, "{a} and {b} samples read");
    let geometry = t.of("triangles", "geometry");
    assert!(t.num(geometry[1], "triangles") > t.num(geometry[0], "triangles"));
    assert_charts(
        &dir,
        &[
            "lightfield_density.png",
            "lightfield_st.png",
            "lightfield_compression.png",
            "lightfield_sparse.png",
            "lightfield_time_error.png",
            "lightfield_resolution.png",
            "lightfield_triangles.png",
        ],
    );
}

/// Whether `python3` can import OpenCV (the stereo sweep's peer). `.ci/run` installs it; a
/// machine without it runs the sweep without the peer, saying so.
fn opencv_available() -> bool {
    Command::new("python3")
        .args(["-c", "import cv2"])
        .output()
        .is_ok_and(|o| o.status.success())
}

#[test]
fn stereo_sweep_writes_csv_and_png_charts() {
    let opencv = opencv_available();
    if !opencv {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "CI installs OpenCV for python3 (.ci/run): the stereo sweep's peer must run there"
        );
        eprintln!(
            "stereo_sweep_writes_csv_and_png_charts: python3 has no cv2 (pip install opencv-python-headless); the OpenCV rows are not checked"
        );
    }
    let (dir, csv) = run_sweep("stereo", &[]);
    let t = Table::parse(&csv);
    assert_eq!(&t.header[..2], ["pair", "method"]);
    let pairs = [
        "plaza",
        "cards",
        "slanted",
        "thin",
        "low-texture",
        "repeated",
        "unrectified",
    ];
    let mut methods = vec!["block", "sgm"];
    if opencv {
        methods.extend(["opencv-sgbm", "opencv-sgbm-hh"]);
    }
    for pair in pairs {
        // Every matcher measured on every pair, read back from the files the peer wrote.
        for method in &methods {
            let rows = t.of(pair, method);
            assert_eq!(rows.len(), 1, "{pair} {method}: {csv}");
            let r = rows[0];
            for col in ["nonocc_bad2", "all_bad2", "nonocc_unknown"] {
                let v = t.num(r, col);
                assert!((0.0..=1.0).contains(&v), "{pair} {method} {col}: {v}");
            }
            assert!(t.num(r, "median_ms") > 0.0, "{pair} {method}: {csv}");
        }
        for file in ["left.png", "right.png", "truth.pfm"] {
            assert!(
                dir.join("stereo").join(pair).join(file).is_file(),
                "{pair}/{file}"
            );
        }
    }
    // On textured cards semi-global matching gets nearly every visible pixel within two.
    for pair in ["cards", "slanted"] {
        let r = t.of(pair, "sgm")[0];
        assert!(t.num(r, "nonocc_bad2") < 0.05, "{pair}: {csv}");
    }
    assert_charts(&dir, &["stereo_time_error.png", "stereo_pairs.png"]);
}

#[test]
fn morph_sweep_writes_csv_and_png_charts() {
    let (dir, csv) = run_sweep("morph", &[]);
    let t = Table::parse(&csv);
    assert_eq!(&t.header[..3], ["path", "method", "s"]);
    for path in ["near", "wide"] {
        for method in ["morph-depth", "morph-stereo", "plain"] {
            let rows = t.of(path, method);
            assert_eq!(rows.len(), 3, "{path} {method}: {csv}");
            for r in rows {
                assert!(t.num(r, "psnr_db") > 5.0, "{path} {method}: {r:?}");
                assert!(t.num(r, "median_ms") > 0.0);
            }
        }
        // Halfway between non-parallel views the prewarped morph keeps shape; the plain
        // one does not.
        let mid = |m: &str| t.num(t.of(path, m)[1], "psnr_db");
        assert!(mid("morph-depth") > mid("plain"), "{path}: {csv}");
    }
    assert_charts(&dir, &["morph_path.png"]);
}

#[test]
fn panorama_sweep_writes_csv_and_png_charts() {
    let (dir, csv) = run_sweep("panorama", &[]);
    let t = Table::parse(&csv);
    assert_eq!(t.header[0], "moved");
    assert_eq!(t.rows.len(), 2, "{csv}");
    let (at, away) = (&t.rows[0], &t.rows[1]);
    // At the capture point nothing is predicted; away from it the prediction and the
    // share of wrong pixels grow.
    assert_eq!(t.num(at, "predicted_px"), 0.0);
    assert!(t.num(away, "predicted_px") > 0.0);
    assert!(t.num(away, "frac_over") > t.num(at, "frac_over"), "{csv}");
    // The spread sky at the same eyes: fresh at the capture point (its error the held
    // panorama's there), and a frame time for each eye.
    assert_eq!(t.num(at, "spread_psnr_db"), t.num(at, "psnr_db"), "{csv}");
    assert!(t.rows.iter().all(|r| t.num(r, "spread_ms") > 0.0), "{csv}");
    let charts = [
        "panorama_time.png",
        "panorama_distance.png",
        "panorama_predicted.png",
    ];
    assert_charts(&dir, &charts);
}

#[test]
fn layers_sweep_writes_csv_and_png_charts() {
    let (dir, csv) = run_sweep("layers", &[]);
    let t = Table::parse(&csv);
    assert_eq!(&t.header[..3], ["path", "method", "tolerance_px"]);
    for path in ["translate", "rotate"] {
        assert_eq!(t.of(path, "geometry").len(), 1, "{csv}");
        let (layers, impostors) = (t.of(path, "layers"), t.of(path, "impostors"));
        let persp = t.of(path, "layers-persp");
        assert_eq!(
            (layers.len(), persp.len(), impostors.len()),
            (2, 2, 2),
            "{csv}"
        );
        for (r, tol) in layers.iter().chain(&persp).zip([0.5, 8.0, 0.5, 8.0]) {
            // Refreshed in the frame it passes the threshold: no drawn layer is over it.
            assert!(t.num(r, "predicted_px_max") <= tol + 1e-3, "{path}: {r:?}");
            assert!(t.num(r, "psnr_db") > 20.0, "{path}: {r:?}");
        }
        // A looser threshold re-renders no more.
        let refreshes = |r: &[&str]| t.num(r, "refreshes_per_frame");
        assert!(
            refreshes(layers[1]) <= refreshes(layers[0]),
            "{path}: {csv}"
        );
    }
    // Turning in place moves every point by one homography: the perspective warp follows
    // it, the affine one re-renders.
    let refreshes = |m: &str| t.num(t.of("rotate", m)[0], "refreshes_per_frame");
    assert!(refreshes("layers-persp") < refreshes("layers"), "{csv}");
    // Sliding sideways, a layer's image is the size of its screen rectangle; an
    // impostor's is the power of two around its bounding sphere: layers render fewer
    // pixels for the same threshold.
    let (layers, impostors) = (t.of("translate", "layers"), t.of("translate", "impostors"));
    for (l, i) in layers.iter().zip(&impostors) {
        let kpx = |r: &[&str]| t.num(r, "capture_kpx_per_frame");
        assert!(kpx(l) < kpx(i), "{csv}");
    }
    assert_charts(
        &dir,
        &[
            "layers_refreshes_translate.png",
            "layers_time_error_translate.png",
            "layers_refreshes_rotate.png",
            "layers_time_error_rotate.png",
        ],
    );
}

#[test]
fn budget_sweep_writes_csv_and_png_charts() {
    let (dir, csv) = run_sweep("budget", &[]);
    let t = Table::parse(&csv);
    assert_eq!(&t.header[..3], ["scene", "method", "budget"]);
    for scene in ["city", "world"] {
        let geometry = t.of(scene, "geometry");
        assert_eq!(geometry.len(), 1, "{csv}");
        // Geometry is the truth it is measured against.
        assert_eq!(t.num(geometry[0], "measured_mean"), 0.0, "{csv}");
        for method in ["impostors", "planner", "layers"] {
            assert_eq!(t.of(scene, method).len(), 1, "{scene} {method}: {csv}");
        }
        // The frame scope also at its larger budget.
        let whole: Vec<f64> = t
            .of(scene, "planner-frame")
            .iter()
            .map(|r| t.num(r, "budget"))
            .collect();
        assert_eq!(whole, [4.0, 16.0], "{scene}: {csv}");
        let planner = t.of(scene, "planner")[0];
        // The planner draws within its predicted budget and shows every object.
        assert!(
            t.num(planner, "predicted_max") <= t.num(planner, "budget"),
            "{csv}"
        );
        assert!(t.num(planner, "psnr_db") > 20.0, "{csv}");
    }
    assert_charts(
        &dir,
        &["budget_time_error_city.png", "budget_time_error_world.png"],
    );
}

#[test]
fn budget_calibration_fits_a_cost_model() {
    let dir = out_dir("bench_smoke_calibrate");
    let out = Command::new(env!("CARGO_BIN_EXE_bench"))
        .args(["budget", "--calibrate", "--tiny", "--out"])
        .arg(&dir)
        .output()
        .expect("bench runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}");
    assert!(stdout.contains("cost model:"), "{stdout}");
    let csv = std::fs::read_to_string(dir.join("calibrate.csv")).expect("calibrate.csv");
    let t = Table::parse(&csv);
    for experiment in ["triangles", "pixels", "images", "captures"] {
        assert!(t.rows.iter().any(|r| r[0] == experiment), "{csv}");
    }
}
