//! ARCHITECTURE.md stays a true map: every path it names in backticks exists, every file
//! named bare in a code-map entry exists beside that entry's paths, and every type an entry
//! names (`CamelCase` in backticks) is defined in one of the files that entry points to.

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn text() -> String {
    std::fs::read_to_string(root().join("ARCHITECTURE.md")).expect("ARCHITECTURE.md")
}

/// The backticked parts of `s`.
fn ticked(s: &str) -> impl Iterator<Item = &str> {
    s.split('`').skip(1).step_by(2)
}

/// A path from the repository root; an absolute one (`/proc`) is not the map's and is never
/// walked (walking it hung the test once).
fn is_path(part: &str) -> bool {
    part.contains('/')
        && !part.starts_with('/')
        && part
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "_./-".contains(c))
}

#[test]
fn every_path_in_the_code_map_exists() {
    let text = text();
    let paths: Vec<&str> = ticked(&text).filter(|p| is_path(p)).collect();
    assert!(
        paths.len() >= 10,
        "the code map names {} paths",
        paths.len()
    );
    let missing: Vec<&&str> = paths.iter().filter(|p| !root().join(p).exists()).collect();
    assert!(
        missing.is_empty(),
        "ARCHITECTURE.md names missing paths: {missing:?}"
    );
}

/// The code map's entries: a line starting `- ` and its indented continuation lines.
fn entries(text: &str) -> Vec<String> {
    let map = text
        .split("## Code map")
        .nth(1)
        .and_then(|t| t.split("\n## ").next())
        .expect("a code map section");
    let mut out: Vec<String> = Vec::new();
    for line in map.lines() {
        let t = line.trim_start();
        if t.starts_with("- ") {
            out.push(t.to_string());
        } else if line.starts_with("  ") && !t.is_empty() {
            if let Some(last) = out.last_mut() {
                last.push(' ');
                last.push_str(t);
            }
        }
    }
    out
}

/// Every `.rs` file under `p` (itself if a file).
fn rust_files(p: &Path, out: &mut Vec<PathBuf>) {
    if p.is_dir() {
        for e in std::fs::read_dir(p).into_iter().flatten().flatten() {
            rust_files(&e.path(), out);
        }
    } else if p.extension().is_some_and(|e| e == "rs") {
        out.push(p.to_path_buf());
    }
}

#[test]
fn entries_name_files_beside_them_and_types_where_they_are_defined() {
    let text = text();
    let (mut types_checked, mut problems) = (0, Vec::new());
    for entry in entries(&text) {
        let parts: Vec<&str> = ticked(&entry).collect();
        let paths: Vec<PathBuf> = parts
            .iter()
            .filter(|p| is_path(p))
            .map(|p| root().join(p))
            .collect();
        // Folders the entry's paths point into, for bare file names (`build.rs`).
        let dirs: Vec<PathBuf> = paths
            .iter()
            .map(|p| {
                if p.is_dir() {
                    p.clone()
                } else {
                    p.with_extension("")
                }
            })
            .chain(
                paths
                    .iter()
                    .filter_map(|p| p.parent().map(Path::to_path_buf)),
            )
            .collect();
        let mut files = Vec::new();
        for p in &paths {
            rust_files(p, &mut files);
        }
        for bare in parts
            .iter()
            .filter(|p| p.ends_with(".rs") && !p.contains('/'))
        {
            match dirs.iter().map(|d| d.join(bare)).find(|f| f.exists()) {
                Some(f) => files.push(f),
                None => problems.push(format!("{bare} (in the entry {entry:.60})")),
            }
        }
        if files.is_empty() {
            continue;
        }
        let sources: String = files
            .iter()
            .filter_map(|f| std::fs::read_to_string(f).ok())
            .collect();
        let names = parts.iter().filter(|p| {
            p.len() > 1
                && p.starts_with(|c: char| c.is_ascii_uppercase())
                && p.chars().all(|c| c.is_ascii_alphanumeric())
                && p.chars().any(|c| c.is_ascii_lowercase())
        });
        for name in names {
            types_checked += 1;
            let defined = ["struct", "enum", "trait", "type"]
                .iter()
                .any(|k| sources.contains(&format!("{k} {name}")));
            if !defined {
                problems.push(format!("{name} is not defined in the files of {entry:.60}"));
            }
        }
    }
    assert!(types_checked >= 30, "{types_checked} types checked");
    assert!(
        problems.is_empty(),
        "ARCHITECTURE.md misplaces: {problems:#?}"
    );
}
