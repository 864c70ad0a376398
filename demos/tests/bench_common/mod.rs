//! What the `bench` smoke tests share: running a sweep at its smallest, reading its CSV,
//! checking its charts.
#![allow(dead_code)] // each test binary uses some of these

use std::path::{Path, PathBuf};
use std::process::Command;

pub fn out_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Runs `bench SWEEP --quick --tiny [extra] --out DIR` and returns DIR and the text of
/// `DIR/SWEEP.csv`.
pub fn run_sweep(sweep: &str, extra: &[&str]) -> (PathBuf, String) {
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
pub struct Table<'a> {
    pub header: Vec<&'a str>,
    pub rows: Vec<Vec<&'a str>>,
}

impl<'a> Table<'a> {
    pub fn parse(csv: &'a str) -> Table<'a> {
        let mut lines = csv.lines();
        let header: Vec<&str> = lines.next().expect("header").split(',').collect();
        let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
        for r in &rows {
            assert_eq!(r.len(), header.len(), "{r:?}");
        }
        Table { header, rows }
    }

    pub fn col(&self, name: &str) -> usize {
        self.header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("no {name} column"))
    }

    pub fn num(&self, r: &[&str], name: &str) -> f64 {
        r[self.col(name)]
            .parse()
            .unwrap_or_else(|_| panic!("{name} of {r:?}"))
    }

    /// The rows whose first two fields are `a` and `b`.
    pub fn of(&self, a: &str, b: &str) -> Vec<&Vec<&'a str>> {
        self.rows
            .iter()
            .filter(|r| r[0] == a && r[1] == b)
            .collect()
    }
}

/// Asserts that each of `names` under `dir` is a PNG chart of a sensible size.
pub fn assert_charts(dir: &Path, names: &[&str]) {
    for name in names {
        let bytes = std::fs::read(dir.join(name)).expect("chart written");
        assert_chart(name, &bytes);
    }
}

/// Asserts that `bytes` is a PNG chart of a sensible size.
pub fn assert_chart(name: &str, bytes: &[u8]) {
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{name} is a PNG");
    let img = image::load_from_memory(bytes).expect("chart decodes");
    assert!(img.width() >= 400 && img.height() >= 300);
}
