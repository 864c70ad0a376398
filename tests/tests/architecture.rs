//! ARCHITECTURE.md stays a true map: every path it names in backticks exists.

use std::path::Path;

#[test]
fn every_path_in_the_code_map_exists() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let text = std::fs::read_to_string(root.join("ARCHITECTURE.md")).expect("ARCHITECTURE.md");
    let mut checked = 0;
    let mut missing = Vec::new();
    for (i, part) in text.split('`').enumerate() {
        // odd parts are inside backticks
        let looks_like_path = part.contains('/')
            && !part.contains(' ')
            && part
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "_./-".contains(c));
        if i % 2 == 1 && looks_like_path {
            checked += 1;
            if !root.join(part).exists() {
                missing.push(part.to_string());
            }
        }
    }
    assert!(
        checked >= 10,
        "expected the code map to name paths, found {checked}"
    );
    assert!(
        missing.is_empty(),
        "ARCHITECTURE.md names missing paths: {missing:?}"
    );
}
