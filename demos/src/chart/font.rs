//! The font charts draw their text with: DejaVu Sans, embedded in the binary (the `dejavu`
//! crate, so a machine without system fonts still gets titles, axes and legends), or the
//! TrueType file `$PARALLAX_FONT` names.

use plotters::prelude::FontStyle;
use std::sync::OnceLock;

/// The font's bytes: `$PARALLAX_FONT`'s file when it is set and readable, else the
/// embedded DejaVu Sans.
pub fn font_bytes() -> &'static [u8] {
    static BYTES: OnceLock<&'static [u8]> = OnceLock::new();
    BYTES.get_or_init(|| {
        let chosen = std::env::var_os("PARALLAX_FONT").and_then(|p| std::fs::read(p).ok());
        match chosen {
            // Kept for the life of the program, as plotters keeps registered fonts.
            Some(bytes) => Box::leak(bytes.into_boxed_slice()),
            None => dejavu::sans::regular(),
        }
    })
}

/// Registers [`font_bytes`] as plotters' "sans-serif" once; whether text can be drawn.
pub(super) fn font_ready() -> bool {
    static READY: OnceLock<bool> = OnceLock::new();
    *READY.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, font_bytes()).is_ok()
    })
}
