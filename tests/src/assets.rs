//! The shared third-party test assets (`<workspace>/../shared/assets`): where they are, the
//! skip-or-fail rule when they are absent, and the model table of their `MANIFEST.md`.
//!
//! Tests that need the assets call [`require`]: it returns the folder, or prints
//! `SKIPPED: ../shared/assets not found` and returns `None` so the test can return early,
//! except under CI (`CI=true`), where missing assets fail the test instead.

use std::path::{Path, PathBuf};

/// `<workspace root>/../shared/assets` (it may not exist).
pub fn dir() -> PathBuf {
    let tests_crate = Path::new(env!("CARGO_MANIFEST_DIR"));
    let workspace = tests_crate.parent().unwrap_or(tests_crate);
    workspace.join("..").join("shared").join("assets")
}

/// The assets folder if present. If absent: under `CI=true` panics (the test fails);
/// otherwise prints a visible `SKIPPED` notice (naming `test`) and returns `None`.
pub fn require(test: &str) -> Option<PathBuf> {
    let d = dir();
    if d.join("MANIFEST.md").is_file() {
        return Some(d);
    }
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!(
            "{test}: ../shared/assets not found at {} (required when CI=true)",
            d.display()
        );
    }
    // Written to the process's stderr directly: the test harness captures `print!` and
    // `eprint!` of passing tests, and a skip must be seen in a plain `cargo test` run.
    use std::io::Write;
    let _ = writeln!(
        std::io::stderr(),
        "SKIPPED: ../shared/assets not found ({test})"
    );
    None
}

/// One row of the manifest's model table.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ModelEntry {
    /// Path relative to the assets folder.
    pub file: String,
    /// `OBJ`, `glTF`, `glTF-Binary` or `glTF-Embedded`.
    pub format: String,
    pub triangles: usize,
    pub vertices: usize,
    pub textures: usize,
}

/// The OBJ and glTF rows of `MANIFEST.md` in `dir` (empty if it cannot be read).
pub fn manifest_models(dir: &Path) -> Vec<ModelEntry> {
    let Ok(text) = std::fs::read_to_string(dir.join("MANIFEST.md")) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for line in text.lines() {
        let cols: Vec<&str> = line.split('|').map(str::trim).collect();
        // "| file | format | triangles | vertices | textures | ..." -> cols[0] is empty.
        if cols.len() < 6 || !(cols[2] == "OBJ" || cols[2].starts_with("glTF")) {
            continue;
        }
        let num = |s: &str| s.replace(',', "").parse::<usize>().ok();
        if let (Some(t), Some(v), Some(x)) = (num(cols[3]), num(cols[4]), num(cols[5])) {
            out.push(ModelEntry {
                file: cols[1].to_string(),
                format: cols[2].to_string(),
                triangles: t,
                vertices: v,
                textures: x,
            });
        }
    }
    out
}
