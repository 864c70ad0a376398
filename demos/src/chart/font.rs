//! The TrueType font charts draw their text with, found at run time.

use plotters::prelude::FontStyle;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The font file charts use: `$PARALLAX_FONT` when set, else the first of DejaVu Sans,
/// Liberation Sans, or any `.ttf` file found under the usual font folders.
pub fn font_file() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("PARALLAX_FONT") {
        return Some(PathBuf::from(p));
    }
    fn walk(dir: &Path, depth: u32, out: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        let mut entries: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
        entries.sort();
        for p in entries {
            if p.is_dir() && depth < 4 {
                walk(&p, depth + 1, out);
            } else if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("ttf")) {
                out.push(p);
            }
        }
    }
    let mut found = Vec::new();
    for dir in [
        "/usr/share/fonts",
        "/usr/local/share/fonts",
        "/Library/Fonts",
        "C:\\Windows\\Fonts",
    ] {
        walk(Path::new(dir), 0, &mut found);
    }
    let named = |name: &str| {
        found
            .iter()
            .find(|p| p.file_name().is_some_and(|f| f.eq_ignore_ascii_case(name)))
            .cloned()
    };
    named("DejaVuSans.ttf")
        .or_else(|| named("LiberationSans-Regular.ttf"))
        .or_else(|| named("Arial.ttf"))
        .or_else(|| found.into_iter().next())
}

/// Registers [`font_file`] as plotters' "sans-serif" once; whether text can be drawn.
pub(super) fn font_ready() -> bool {
    static READY: OnceLock<bool> = OnceLock::new();
    *READY.get_or_init(|| {
        let Some(bytes) = font_file().and_then(|p| std::fs::read(p).ok()) else {
            return false;
        };
        // plotters keeps fonts for the life of the program; this runs once.
        let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
        plotters::style::register_font("sans-serif", FontStyle::Normal, bytes).is_ok()
    })
}
