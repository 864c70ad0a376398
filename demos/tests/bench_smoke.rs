//! Runs the `bench` binary's smallest sweep end to end and checks what it writes: a CSV
//! with a header and rows, and charts that are real PNG images.

use std::path::PathBuf;
use std::process::Command;

fn out_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn raster_sweep_writes_csv_and_png_charts() {
    let dir = out_dir("bench_smoke_raster");
    let out = Command::new(env!("CARGO_BIN_EXE_bench"))
        .args(["raster", "--quick", "--tiny", "--no-models", "--out"])
        .arg(&dir)
        .output()
        .expect("bench runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "bench failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );

    let csv = std::fs::read_to_string(dir.join("raster.csv")).expect("raster.csv written");
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    assert_eq!(&header[..3], ["series", "mesh", "triangles"]);
    assert!(header.contains(&"median_ms") && header.contains(&"fragments_shaded"));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert!(rows.len() >= 4, "{csv}");
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    for r in &rows {
        assert_eq!(r.len(), header.len(), "{r:?}");
        let median: f64 = r[col("median_ms")].parse().unwrap();
        assert!(median > 0.0 && median.is_finite());
        let shaded: u64 = r[col("fragments_shaded")].parse().unwrap();
        assert!(shaded > 0, "the torus is on screen: {r:?}");
    }
    assert!(rows.iter().any(|r| r[0] == "resolution"));
    assert!(rows.iter().any(|r| r[0] == "triangles"));

    for name in ["raster_resolution.png", "raster_triangles.png"] {
        let bytes = std::fs::read(dir.join(name)).expect("chart written");
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{name} is a PNG");
        let img = image::load_from_memory(&bytes).expect("chart decodes");
        assert!(img.width() >= 400 && img.height() >= 300);
    }
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
