//! Runs the `bench` binary's smallest sweeps end to end and checks what they write: a CSV
//! with a header and rows, and charts that are real PNG images.

use std::path::{Path, PathBuf};
use std::process::Command;

fn out_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Runs `bench SWEEP --quick --tiny [extra] --out DIR` and returns DIR and the text of
/// `DIR/SWEEP.csv`.
fn run_sweep(sweep: &str, extra: &[&str]) -> (PathBuf, String) {
    let dir = out_dir(&format!("bench_smoke_{sweep}"));
    let out = Command::new(env!("CARGO_BIN_EXE_bench"))
        .args([sweep, "--quick", "--tiny"])
        .args(extra)
        .arg("--out")
        .arg(&dir)
        .output()
        .expect("bench runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "bench failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.join(format!("{sweep}.csv")))
        .unwrap_or_else(|e| panic!("{sweep}.csv written: {e}"));
    (dir, csv)
}

/// A sweep's CSV: the header's columns and the rows' fields, every row as long as the
/// header.
struct Table<'a> {
    header: Vec<&'a str>,
    rows: Vec<Vec<&'a str>>,
}

impl<'a> Table<'a> {
    fn parse(csv: &'a str) -> Table<'a> {
        let mut lines = csv.lines();
        let header: Vec<&str> = lines.next().expect("header").split(',').collect();
        let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
        for r in &rows {
            assert_eq!(r.len(), header.len(), "{r:?}");
        }
        Table { header, rows }
    }

    fn col(&self, name: &str) -> usize {
        self.header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("no {name} column"))
    }

    fn num(&self, r: &[&str], name: &str) -> f64 {
        r[self.col(name)]
            .parse()
            .unwrap_or_else(|_| panic!("{name} of {r:?}"))
    }

    /// The rows whose first two fields are `a` and `b`.
    fn of(&self, a: &str, b: &str) -> Vec<&Vec<&'a str>> {
        self.rows
            .iter()
            .filter(|r| r[0] == a && r[1] == b)
            .collect()
    }
}

/// Asserts that each of `names` under `dir` is a PNG chart of a sensible size.
fn assert_charts(dir: &Path, names: &[&str]) {
    for name in names {
        let bytes = std::fs::read(dir.join(name)).expect("chart written");
        assert_chart(name, &bytes);
    }
}

#[test]
fn raster_sweep_writes_csv_and_png_charts() {
    let (dir, csv) = run_sweep("raster", &["--no-models"]);
    let t = Table::parse(&csv);
    assert_eq!(&t.header[..3], ["series", "mesh", "triangles"]);
    assert!(t.header.contains(&"median_ms") && t.header.contains(&"fragments_shaded"));
    assert!(t.rows.len() >= 4, "{csv}");
    for r in &t.rows {
        let median = t.num(r, "median_ms");
        assert!(median > 0.0 && median.is_finite());
        assert!(
            t.num(r, "fragments_shaded") > 0.0,
            "the torus is on screen: {r:?}"
        );
    }
    assert!(t.rows.iter().any(|r| r[0] == "resolution"));
    assert!(t.rows.iter().any(|r| r[0] == "triangles"));

    assert_charts(&dir, &["raster_resolution.png", "raster_triangles.png"]);
}

/// Asserts that `bytes` is a PNG chart of a sensible size.
fn assert_chart(name: &str, bytes: &[u8]) {
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{name} is a PNG");
    let img = image::load_from_memory(bytes).expect("chart decodes");
    assert!(img.width() >= 400 && img.height() >= 300);
}

#[test]
fn billboards_sweep_writes_csv_and_png_charts() {
    let (dir, csv) = run_sweep("billboards", &[]);
    let t = Table::parse(&csv);
    assert_eq!(&t.header[..3], ["series", "param", "value"]);
    let (col, num) = (
        |name: &str| t.col(name),
        |r: &[&str], name: &str| t.num(r, name),
    );
    let series =
        |name: &str| -> Vec<&Vec<&str>> { t.rows.iter().filter(|r| r[0] == name).collect() };

    // Timed series: finite positive times, build and render apart, something drawn.
    for name in ["count", "resolution", "trees_mesh", "trees_billboard"] {
        let timed = series(name);
        assert!(timed.len() >= 2, "{name}: {csv}");
        for r in timed {
            for c in ["build_ms", "render_ms", "median_ms", "min_ms", "p90_ms"] {
                let t = num(r, c);
                assert!(t.is_finite() && t >= 0.0, "{c} of {r:?}");
            }
            assert!(
                num(r, "render_ms") > 0.0 && num(r, "median_ms") > 0.0,
                "{r:?}"
            );
            assert!(
                num(r, "median_ms") >= num(r, "render_ms").max(num(r, "build_ms")),
                "{r:?}"
            );
            assert!(num(r, "fragments_shaded") > 0.0, "{r:?}");
            assert!(num(r, "triangles") > 0.0, "{r:?}");
            // Particle rows carry no error; forest rows their error against the meshes.
            let forest = r[0].starts_with("trees_");
            assert_eq!(
                r[col("psnr_db")].is_empty(),
                !forest,
                "error columns: {r:?}"
            );
        }
    }
    // More billboards, more triangles; billboard trees submit far fewer than mesh trees.
    let count = series("count");
    assert!(num(count[1], "triangles") > num(count[0], "triangles"));
    let (mesh, bb) = (series("trees_mesh"), series("trees_billboard"));
    for (m, b) in mesh.iter().zip(&bb) {
        assert_eq!(num(m, "value"), num(b, "value"));
        assert!(
            num(b, "triangles") * 10.0 < num(m, "triangles"),
            "{m:?} {b:?}"
        );
        // Error against the mesh forest on the same frame: none for the meshes themselves,
        // some for the billboards.
        assert_eq!(num(m, "mae"), 0.0, "{m:?}");
        assert!(num(b, "mae") > 0.0 && num(b, "mae") < 255.0, "{b:?}");
    }

    // Accuracy: errors, no times; the upright billboard's error grows from level views
    // to views from above, where it has faded out and the top-down sprite does better.
    let (fade, top) = (series("accuracy_fade"), series("accuracy_top"));
    assert!(fade.len() >= 3 && fade.len() == top.len(), "{csv}");
    for r in fade.iter().chain(&top) {
        assert!(r[col("median_ms")].is_empty(), "{r:?}");
        let psnr = num(r, "psnr_db");
        let mae = num(r, "mae");
        assert!(psnr.is_finite() && psnr > 0.0, "{r:?}");
        assert!(mae > 0.0 && mae < 255.0, "{r:?}");
    }
    let (level, above) = (fade[0], fade[fade.len() - 1]);
    assert_eq!(num(level, "value"), 0.0);
    assert!(num(above, "value") >= 60.0);
    assert!(
        num(level, "psnr_db") > num(above, "psnr_db"),
        "{level:?} {above:?}"
    );
    assert!(num(level, "mae") < num(above, "mae"), "{level:?} {above:?}");
    assert!(
        num(level, "coverage_mismatch") < num(above, "coverage_mismatch"),
        "{level:?} {above:?}"
    );
    let top_above = top[top.len() - 1];
    assert!(
        num(top_above, "psnr_db") > num(above, "psnr_db"),
        "{top_above:?}"
    );
    // Below the fade the two variants draw the same thing.
    assert_eq!(num(top[0], "psnr_db"), num(level, "psnr_db"));

    assert_charts(
        &dir,
        &[
            "billboards_count.png",
            "billboards_resolution.png",
            "billboards_accuracy_psnr.png",
            "billboards_accuracy_mae.png",
            "billboards_trees.png",
            "billboards_trees_error_time.png",
        ],
    );
}

#[test]
fn unknown_sweeps_and_missing_out_are_usage_errors() {
    let bench = env!("CARGO_BIN_EXE_bench");
    let no_out = Command::new(bench).args(["raster"]).output().unwrap();
    assert!(!no_out.status.success());
    assert!(String::from_utf8_lossy(&no_out.stderr).contains("--out"));
    let unknown = Command::new(bench)
        .args(["nope", "--out", "x"])
        .output()
        .unwrap();
    assert!(!unknown.status.success());
}

#[test]
fn scaling_sweep_writes_csv_and_png_charts() {
    let (dir, csv) = run_sweep("scaling", &[]);
    let t = Table::parse(&csv);
    assert_eq!(&t.header[..3], ["series", "mode", "triangles"]);
    let (col, num, of) = (
        |name: &str| t.col(name),
        |r: &[&str], name: &str| t.num(r, name),
        |series: &str, mode: &str| t.of(series, mode),
    );

    // Measured points: finite times, steady frames, something drawn.
    for series in ["triangles", "resolution"] {
        for mode in ["geometry", "impostors"] {
            let pts = of(series, mode);
            assert!(pts.len() >= 2, "{series} {mode}: {csv}");
            for r in pts {
                assert!(num(r, "frames") >= 1.0, "steady frames: {r:?}");
                for c in ["median_ms", "min_ms", "p90_ms", "render_ms"] {
                    let t = num(r, c);
                    assert!(t.is_finite() && t > 0.0, "{c} of {r:?}");
                }
                assert!(num(r, "fragments_shaded") > 0.0, "{r:?}");
                assert!(r[col("r2")].is_empty(), "{r:?}");
            }
        }
        // One fit row per mode, with a slope, an intercept and R^2 in [0, 1].
        for mode in ["geometry", "impostors"] {
            let fit = of(&format!("{series}_fit"), mode);
            assert_eq!(fit.len(), 1, "{csv}");
            let r2 = num(fit[0], "r2");
            assert!((0.0..=1.0 + 1e-9).contains(&r2), "{:?}", fit[0]);
            assert!(num(fit[0], "slope_ns").is_finite() && num(fit[0], "intercept_ms").is_finite());
            assert!(fit[0][col("median_ms")].is_empty());
        }
    }

    // Pixels, not triangles: over the same screen, impostor frames set up the same
    // triangles and shade the same fragments at every triangle count; geometry sets up
    // more and more.
    let (geo, imp) = (of("triangles", "geometry"), of("triangles", "impostors"));
    assert!(num(geo[1], "triangles") > 10.0 * num(geo[0], "triangles"));
    for (g, i) in geo.iter().zip(&imp) {
        assert_eq!(num(g, "triangles"), num(i, "triangles"));
        assert_eq!(
            num(i, "triangles_set_up"),
            num(imp[0], "triangles_set_up"),
            "{i:?}"
        );
        assert_eq!(
            num(i, "fragments_shaded"),
            num(imp[0], "fragments_shaded"),
            "{i:?}"
        );
        assert!(num(i, "images") > 0.0 && num(g, "images") == 0.0);
        // Error against the geometry frames at the same poses: none for the geometry,
        // some (less than a level or so on average) for the images.
        assert_eq!(num(g, "mae"), 0.0, "{g:?}");
        assert!(num(i, "mae") > 0.0 && num(i, "mae") < 16.0, "{i:?}");
    }
    assert!(
        num(geo[1], "triangles_set_up") > 5.0 * num(geo[0], "triangles_set_up"),
        "{geo:?}"
    );
    assert!(num(imp[0], "triangles_set_up") < num(geo[0], "triangles_set_up"));
    // Twice the resolution each way: about 4x the impostor fragments, the same triangles.
    let res = of("resolution", "impostors");
    let ratio = num(res[1], "fragments_shaded") / num(res[0], "fragments_shaded");
    assert!(
        num(res[1], "pixels") == 4.0 * num(res[0], "pixels"),
        "{res:?}"
    );
    assert!((3.2..=4.8).contains(&ratio), "{ratio} {res:?}");
    assert_eq!(
        num(res[0], "triangles_set_up"),
        num(res[1], "triangles_set_up")
    );

    assert_charts(
        &dir,
        &[
            "scaling_triangles.png",
            "scaling_resolution.png",
            "scaling_error_time.png",
            "scaling_subjects.png",
        ],
    );
}

#[test]
fn impostors_sweep_writes_csv_and_png_charts() {
    let (dir, csv) = run_sweep("impostors", &[]);
    let t = Table::parse(&csv);
    assert_eq!(
        &t.header[..4],
        ["series", "path", "policy", "tolerance_deg"]
    );
    let (rows, num, of) = (
        &t.rows,
        |r: &[&str], name: &str| t.num(r, name),
        |series: &str, path: &str| t.of(series, path),
    );

    // Every impostor run is timed and measured: finite times, errors in range.
    for r in rows.iter().filter(|r| r[0] == "sweep" || r[0] == "fixed") {
        let median = num(r, "median_ms");
        assert!(median > 0.0 && median.is_finite(), "{r:?}");
        assert!(num(r, "images_per_frame") > 0.0, "{r:?}");
        let (mean, worst) = (num(r, "mae_mean"), num(r, "mae_max"));
        assert!(mean > 0.0 && mean <= worst && worst < 255.0, "{r:?}");
        assert!(num(r, "worst_mae") >= worst, "{r:?}");
        assert!(num(r, "psnr_db") > 15.0, "{r:?}");
    }
    let (translate, rotate) = (of("sweep", "translate"), of("sweep", "rotate"));
    assert!(
        translate.len() >= 3 && translate.len() == rotate.len(),
        "{csv}"
    );
    let (fine, coarse) = (translate[0], translate[translate.len() - 1]);
    assert!(num(fine, "tolerance_deg") < num(coarse, "tolerance_deg"));
    // Translating: a finer tolerance refreshes more and errs less.
    assert!(
        num(fine, "refreshes") > 2.0 * num(coarse, "refreshes"),
        "{fine:?} {coarse:?}"
    );
    assert!(
        num(coarse, "mae_mean") >= num(fine, "mae_mean"),
        "{fine:?} {coarse:?}"
    );
    assert!(num(coarse, "predicted_deg_mean") > num(fine, "predicted_deg_mean"));
    // Rotating in place causes no parallax: after warm-up nothing is re-rendered (only
    // buildings coming into view take a first image), whatever the tolerance.
    for r in &rotate {
        assert_eq!(num(r, "refreshes"), num(r, "new_captures"), "{r:?}");
        assert!(num(r, "predicted_deg_max") < 1e-3, "rounding only: {r:?}");
    }
    // Fixed interval: the error-driven run's refresh count.
    let fixed = of("fixed", "translate");
    assert_eq!(fixed.len(), translate.len());
    for (f, e) in fixed.iter().zip(&translate) {
        assert_eq!(num(f, "tolerance_deg"), num(e, "tolerance_deg"));
        let (nf, ne) = (num(f, "refreshes"), num(e, "refreshes"));
        assert!((nf - ne).abs() <= 0.05 * ne + 1.0, "{f:?} {e:?}");
    }
    // Calibration: images age without refresh, so the error grows with the parallax.
    let calibration = of("calibration", "translate");
    assert!(calibration.len() >= 10, "{csv}");
    let (young, old): (Vec<_>, Vec<_>) = calibration
        .iter()
        .partition(|r| num(r, "frame") <= num(calibration[calibration.len() - 1], "frame") / 2.0);
    let mean =
        |v: &[&&Vec<&str>], c: &str| v.iter().map(|r| num(r, c)).sum::<f64>() / v.len() as f64;
    assert!(mean(&old, "predicted_deg_mean") > mean(&young, "predicted_deg_mean"));
    assert!(mean(&old, "mae_mean") > mean(&young, "mae_mean"), "{csv}");
    // Methods: geometry is its own reference; both kinds of impostor are measured.
    let methods = of("method", "orbit");
    let policy = |p: &str| methods.iter().find(|r| r[2].starts_with(p)).copied();
    let geometry = policy("geometry").expect("geometry row");
    assert_eq!(num(geometry, "mae_mean"), 0.0);
    for p in ["runtime", "octahedral_"] {
        let r = policy(p).unwrap_or_else(|| panic!("{p} row: {csv}"));
        assert!(
            num(r, "mae_mean") > 0.0 && num(r, "memory_bytes") > 0.0,
            "{r:?}"
        );
        assert!(num(r, "median_ms") > 0.0, "{r:?}");
    }
    assert!(num(policy("octahedral_").unwrap(), "setup_ms") > 0.0);

    assert_charts(
        &dir,
        &[
            "impostors_error.png",
            "impostors_refreshes.png",
            "impostors_frame_time.png",
            "impostors_fixed.png",
            "impostors_calibration.png",
            "impostors_methods.png",
        ],
    );
}

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
    assert_charts(&dir, &["panorama_distance.png", "panorama_predicted.png"]);
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
