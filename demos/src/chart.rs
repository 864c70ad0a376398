//! PNG charts of benchmark rows, drawn with plotters' bitmap backend.
//!
//! Text is drawn by plotters' pure-Rust `ab_glyph` renderer with DejaVu Sans embedded in
//! the binary ([`font_bytes`]; `$PARALLAX_FONT` may name another TrueType file), so building
//! needs no font libraries and every chart has its titles, axes and legends on any machine.
//! Should drawing with text still fail, the chart is drawn without it (axes, grid, series
//! and points) rather than not at all, and the caller is told.

mod font;
mod lines;
mod plot;
mod raster;
mod style;

pub use font::font_bytes;
pub use lines::{Line, Lines};
pub use plot::Layout;
pub use raster::{resolution_chart, triangles_chart, LineAndDots};

use font::font_ready;
use lines::Series;
use plot::plot;
use plotters::prelude::*;
use std::path::Path;

type Error = Box<dyn std::error::Error>;

/// Whether a chart got its text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Drawn {
    WithText,
    /// No usable font: drawn without captions, labels or legends.
    WithoutText,
}

const SIZE: (u32, u32) = (960, 600);
/// Series colours in order (the first four as before; fourteen in all, so a chart of up to
/// fourteen lines, such as the warp sweep's thirteen methods, tells every line apart).
const SERIES: [RGBColor; 14] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
    RGBColor(0, 0, 0),
    RGBColor(0, 0, 128),
    RGBColor(128, 0, 0),
    RGBColor(0, 128, 128),
];

/// A chart ready to draw with [`draw`].
#[derive(Clone, Debug)]
pub enum Chart {
    /// Each line's points joined.
    Lines(Lines),
    /// Each line's points as dots, not joined (a scatter: one colour and marker per line),
    /// reference lines joined.
    Scatter(Lines),
    /// One labelled line and loose labelled dots.
    LineAndDots(LineAndDots),
}

/// Draws a chart as a PNG, with text when a font is usable (see the module docs). Points
/// with a non-finite coordinate (or, on a log axis, one at or below zero) of a
/// [`Chart::Lines`] or [`Chart::Scatter`] are left out.
pub fn draw(path: &Path, chart: &Chart) -> Result<Drawn, Error> {
    draw_layout(path, chart).map(|(drawn, _)| drawn)
}

/// [`draw`], also telling where the plot area, point labels, markers and legend went.
pub fn draw_layout(path: &Path, chart: &Chart) -> Result<(Drawn, Layout), Error> {
    match chart {
        Chart::Lines(spec) => {
            with_fallback(|text| plot(path, &spec.axes(), &Series::of(spec, true), text))
        }
        Chart::Scatter(spec) => {
            with_fallback(|text| plot(path, &spec.axes(), &Series::of(spec, false), text))
        }
        Chart::LineAndDots(spec) => with_fallback(|text| plot(path, &spec.axes(), spec, text)),
    }
}

/// Draws with text when a font is usable; without when none is, or when drawing with text
/// fails.
fn with_fallback(
    mut draw: impl FnMut(bool) -> Result<Layout, Error>,
) -> Result<(Drawn, Layout), Error> {
    if !font_ready() {
        return Ok((Drawn::WithoutText, draw(false)?));
    }
    match draw(true) {
        Ok(layout) => Ok((Drawn::WithText, layout)),
        Err(_) => Ok((Drawn::WithoutText, draw(false)?)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Text comes from the embedded font, whatever fonts the machine has: a chart's title
    /// band holds dark text pixels.
    #[test]
    fn charts_always_have_text() {
        assert!(font_bytes().len() > 100_000, "a whole TrueType font");
        let dir = std::env::temp_dir().join(format!("parallax-chart-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let path = dir.join("text.png");
        let lines = Lines::new(
            "A title to read",
            "x",
            "y",
            vec![Line::new("a line", vec![(0.0, 1.0), (1.0, 2.0)])],
        );
        assert_eq!(
            draw(&path, &Chart::Lines(lines)).expect("drawn"),
            Drawn::WithText
        );
        let img = image::open(&path).expect("a PNG").to_rgb8();
        let dark = (0..40)
            .flat_map(|y| (0..img.width()).map(move |x| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0.iter().all(|&c| c < 100))
            .count();
        assert!(dark > 100, "{dark} dark pixels in the title band");
        std::fs::remove_dir_all(&dir).ok();
    }
}
