//! PNG charts of benchmark rows, drawn with plotters' bitmap backend.
//!
//! Text is drawn by plotters' pure-Rust `ab_glyph` renderer, from a TrueType font found at
//! run time ([`font_file`]: `$PARALLAX_FONT`, else DejaVu Sans, Liberation Sans or any
//! `.ttf` under the usual font folders), so building needs no font libraries. When no font
//! can be found or read, the chart is drawn without any text (axes, grid, series and
//! points only) rather than failing, and the caller is told so it can say it.

mod font;
mod lines;
mod plot;
mod raster;

pub use font::font_file;
pub use lines::{Line, Lines};
pub use raster::{resolution_chart, triangles_chart, LineAndDots};

use font::font_ready;
use lines::{Dots, Joined};
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
const SERIES: [RGBColor; 4] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
];

/// A chart ready to draw with [`draw`].
#[derive(Clone, Debug)]
pub enum Chart {
    /// Each line's points joined.
    Lines(Lines),
    /// Each line's points as dots, not joined (a scatter: one colour per line, repeating
    /// after four).
    Scatter(Lines),
    /// One labelled line and loose labelled dots.
    LineAndDots(LineAndDots),
}

/// Draws a chart as a PNG, with text when a font is usable (see the module docs). Points
/// with a non-finite coordinate (or, on a log axis, one at or below zero) of a
/// [`Chart::Lines`] or [`Chart::Scatter`] are left out.
pub fn draw(path: &Path, chart: &Chart) -> Result<Drawn, Error> {
    match chart {
        Chart::Lines(spec) => {
            with_fallback(|text| plot(path, &spec.axes(), &Joined::of(spec), text))
        }
        Chart::Scatter(spec) => {
            with_fallback(|text| plot(path, &spec.axes(), &Dots::of(spec), text))
        }
        Chart::LineAndDots(spec) => with_fallback(|text| plot(path, &spec.axes(), spec, text)),
    }
}

/// Draws with text when a font is usable; without when none is, or when drawing with text
/// fails.
fn with_fallback(mut draw: impl FnMut(bool) -> Result<(), Error>) -> Result<Drawn, Error> {
    if !font_ready() {
        draw(false)?;
        return Ok(Drawn::WithoutText);
    }
    match draw(true) {
        Ok(()) => Ok(Drawn::WithText),
        Err(_) => {
            draw(false)?;
            Ok(Drawn::WithoutText)
        }
    }
}
