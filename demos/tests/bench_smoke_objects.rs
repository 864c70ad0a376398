//! Runs `bench objects` at its smallest setting (`--quick --tiny`: worlds of 16 and 64
//! objects, geometry beside the per-node planner) and checks what it writes: a CSV row
//! per object count and method, and its three charts.

mod bench_common;
use bench_common::*;

#[test]
fn objects_sweep_writes_csv_and_png_charts() {
    let (dir, csv) = run_sweep("objects", &[]);
    let t = Table::parse(&csv);
    assert_eq!(&t.header[..3], ["scene", "method", "budget"]);
    let col = |r: &Vec<&str>, name: &str| r[t.col(name)].to_string();
    let counts: Vec<usize> = t
        .rows
        .iter()
        .map(|r| t.num(r, "objects") as usize)
        .collect();
    // 16 and 64 objects, the nearest squares of lots (4 x 4 and 8 x 8).
    assert!(counts.iter().all(|&n| n == 16 || n == 64), "{csv}");
    for n in [16, 64] {
        let of = |m: &str| {
            t.rows
                .iter()
                .filter(|r| t.num(r, "objects") as usize == n && col(r, "method") == m)
                .count()
        };
        assert_eq!((of("geometry"), of("planner-tree")), (1, 1), "{n}: {csv}");
    }
    for r in &t.rows {
        assert_eq!(col(r, "scene"), "world", "{csv}");
        let median = t.num(r, "median_ms");
        assert!(median > 0.0 && median.is_finite(), "{r:?}");
        let measured = t.num(r, "measured_mean");
        assert!((0.0..=255.0).contains(&measured), "{r:?}");
        if col(r, "method") == "geometry" {
            // Geometry is the truth it is measured against.
            assert_eq!(measured, 0.0, "{r:?}");
        }
    }
    // More objects, more triangles (the same mix of objects).
    let tris = |n: usize| {
        let r = t.rows.iter().find(|r| t.num(r, "objects") as usize == n);
        t.num(r.expect("a row"), "triangles")
    };
    assert!(tris(64) > 2.0 * tris(16), "{csv}");
    assert_charts(
        &dir,
        &[
            "objects_time.png",
            "objects_error.png",
            "objects_time_error.png",
        ],
    );
}
