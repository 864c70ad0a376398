//! Runs the `bench` binary's smallest sweeps end to end and checks what they write: a CSV
//! with a header and rows, and charts that are real PNG images.

mod bench_common;
use bench_common::*;
use std::process::Command;

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
    for name in [
        "count",
        "resolution",
        "trees_mesh",
        "trees_billboard",
        "trees_nailboard",
    ] {
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
    let nb = series("trees_nailboard");
    assert_eq!(nb.len(), mesh.len(), "{csv}");
    for ((m, b), n) in mesh.iter().zip(&bb).zip(&nb) {
        assert_eq!(num(m, "value"), num(b, "value"));
        assert_eq!(num(m, "value"), num(n, "value"));
        for r in [b, n] {
            assert!(
                num(r, "triangles") * 10.0 < num(m, "triangles"),
                "{m:?} {r:?}"
            );
            // Error against the mesh forest on the same frame: none for the meshes
            // themselves, some for the images.
            assert!(num(r, "mae") > 0.0 && num(r, "mae") < 255.0, "{r:?}");
        }
        assert_eq!(num(m, "mae"), 0.0, "{m:?}");
        // The showcase's nailboards (a view near the eye's direction, per-texel depth)
        // err less than one baked side on a flat quad (tiny sweep: 0.16 against 0.23
        // levels at 50 trees, 1.03 against 1.27 at 200).
        assert!(num(n, "mae") < num(b, "mae"), "{n:?} {b:?}");
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
    // Twice the resolution each way: about 4x the impostor fragments, about the same
    // triangles.
    let res = of("resolution", "impostors");
    let ratio = num(res[1], "fragments_shaded") / num(res[0], "fragments_shaded");
    assert!(
        num(res[1], "pixels") == 4.0 * num(res[0], "pixels"),
        "{res:?}"
    );
    assert!((3.2..=4.8).contains(&ratio), "{ratio} {res:?}");
    // About the same triangles: each image's quad is the mesh over its covered cells of an
    // 8 x 8 grid whatever its texels, which a finer image may trace a cell or two apart.
    let tris = num(res[1], "triangles_set_up") / num(res[0], "triangles_set_up");
    assert!((0.8..=1.25).contains(&tris), "{tris} {res:?}");

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
    // The shapes on the same frames: the buildings are boxes, so the image projected onto
    // the box is nearer its geometry than on a quad through the centre.
    let exact = |p: &str| methods.iter().find(|r| r[2] == p).copied();
    let quad = exact("runtime").expect("quad row");
    for p in ["runtime_relief", "runtime_box"] {
        let r = exact(p).unwrap_or_else(|| panic!("{p} row: {csv}"));
        assert_eq!(r[3], quad[3], "the same tolerance first: {r:?}");
        assert!(
            num(r, "median_ms") > 0.0 && num(r, "mae_mean") > 0.0,
            "{r:?}"
        );
    }
    let boxed = exact("runtime_box").unwrap();
    assert!(
        num(boxed, "mae_mean") < num(quad, "mae_mean"),
        "{boxed:?} {quad:?}"
    );

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
