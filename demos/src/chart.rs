//! PNG charts of benchmark rows, drawn with plotters' bitmap backend.
//!
//! Text is drawn by plotters' pure-Rust `ab_glyph` renderer with DejaVu Sans embedded in
//! the binary ([`font_bytes`]; `$PARALLAX_FONT` may name another TrueType file), so building
//! needs no font libraries and every chart has its titles, axes and legends on any machine.
//! Should drawing with text still fail, the chart is drawn without it (axes, grid, series
//! and points) rather than not at all, and the caller is told.

mod dots;
mod font;
mod lines;
mod plot;
mod style;

pub use dots::{LineAndDots, Point};
pub use font::font_bytes;
pub use lines::{Line, Lines};
pub use plot::Layout;

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

    /// A file in a directory of its own (tests run in parallel, and the text test removes
    /// its directory when done).
    fn temp(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!(
            "parallax-chart-{}-{}",
            std::process::id(),
            name.trim_end_matches(".png")
        ));
        std::fs::create_dir_all(&dir).expect("temp dir");
        dir.join(name)
    }

    fn inside(b: &[i32; 4], area: &[i32; 4]) -> bool {
        b[0] >= area[0] && b[1] >= area[1] && b[2] <= area[2] && b[3] <= area[3]
    }

    fn overlap(a: &[i32; 4], b: &[i32; 4]) -> bool {
        !(a[2] <= b[0] || b[2] <= a[0] || a[3] <= b[1] || b[3] <= a[1])
    }

    /// A crowded chart: three lines on the same points (as flat, depth image and LDI in
    /// the portal sweep), every point labelled, long labels at the right edge (as
    /// "octahedral 8x8x128px" was clipped), counts like 1.024M next to 2.025M. No two drawn
    /// label boxes overlap, none covers a marker, all lie inside the plot area and the
    /// image, the legend lies beside the plot area and every label is either drawn or
    /// counted as dropped.
    #[test]
    fn crowded_labels_never_overlap_nor_clip() {
        let xs = [1.0, 1.1, 1.2, 1.3, 5.0, 9.9, 10.0];
        let line = |name: &str, dy: f64| {
            let pts: Vec<(f64, f64)> = xs.iter().map(|&x| (x, x * 2.0 + dy)).collect();
            let labels = xs
                .iter()
                .map(|&x| format!("octahedral 8x8x{x}px"))
                .collect();
            Line::new(name, pts).labelled(labels)
        };
        let lines = Lines::new(
            "Crowded",
            "x",
            "y",
            vec![
                line("flat", 0.0),
                line("depth image", 0.0),
                line("ldi", 0.05),
            ],
        );
        let path = temp("crowded.png");
        let (drawn, layout) = draw_layout(&path, &Chart::Lines(lines)).expect("drawn");
        assert_eq!(drawn, Drawn::WithText);
        let image = [0, 0, layout.image.0 as i32, layout.image.1 as i32];
        assert!(!layout.labels.is_empty());
        assert_eq!(layout.labels.len() + layout.dropped, 3 * xs.len());
        assert_eq!(layout.markers.len(), 3 * xs.len());
        for (i, a) in layout.labels.iter().enumerate() {
            assert!(
                inside(a, &layout.plot) && inside(a, &image),
                "{a:?} clipped"
            );
            for m in &layout.markers {
                assert!(!overlap(a, m), "label {a:?} covers marker {m:?}");
            }
            for b in &layout.labels[i + 1..] {
                assert!(!overlap(a, b), "labels {a:?} and {b:?} overlap");
            }
        }
        let legend = layout.legend.expect("three series: a legend");
        assert!(inside(&legend, &image), "{legend:?}");
        assert!(!overlap(&legend, &layout.plot), "legend over the data");
        // The rendered image really has text inside each label box.
        let img = image::open(&path).expect("a PNG").to_rgb8();
        for b in &layout.labels {
            let dark = (b[1]..b[3])
                .flat_map(|y| (b[0]..b[2]).map(move |x| (x as u32, y as u32)))
                .filter(|&(x, y)| img.get_pixel(x, y).0.iter().all(|&c| c < 100))
                .count();
            assert!(dark > 10, "label box {b:?} holds {dark} dark pixels");
        }
    }

    /// A PSNR of identical images is drawn on the "exact" line near the top of the axis,
    /// and the axis range comes from the finite values: 40 dB sits high in the plot, not at
    /// 40% of a 0..99 axis.
    #[test]
    fn exact_values_go_to_the_axis_top() {
        let lines = Lines::new(
            "PSNR",
            "x",
            "PSNR (dB)",
            vec![
                Line::new("warped", vec![(0.0, 40.0), (1.0, 20.0)]),
                Line::new("geometry", vec![(0.0, 99.0), (1.0, 99.0)]),
            ],
        )
        .exact_at(99.0);
        let (_, layout) = draw_layout(&temp("exact.png"), &Chart::Lines(lines)).expect("drawn");
        let [_, top, _, bottom] = layout.plot;
        let height = f64::from(bottom - top);
        let level = |b: &[i32; 4]| (f64::from(bottom) - f64::from(b[1] + b[3]) / 2.0) / height;
        // Markers in order: warped 40, warped 20, geometry, geometry.
        let m = &layout.markers;
        assert_eq!(m.len(), 4);
        assert!(
            level(&m[0]) > 0.7 && level(&m[0]) < 0.9,
            "40 dB at {}",
            level(&m[0])
        );
        for exact in &m[2..] {
            assert!(
                (level(exact) - 0.93).abs() < 0.01,
                "exact at {}",
                level(exact)
            );
        }
        assert!(layout.legend.is_some(), "the legend names the exact line");
    }

    /// Two quantities, two axes: refreshes (0..4) on the left, milliseconds (20..40) on the
    /// right; each line's largest value reaches near the top of its own axis.
    #[test]
    fn a_second_quantity_gets_the_right_axis() {
        let lines = Lines::new(
            "Two axes",
            "frame",
            "refreshes",
            vec![
                Line::new("refreshes", vec![(0.0, 4.0), (1.0, 0.0), (2.0, 2.0)]),
                Line::new("frame time", vec![(0.0, 20.0), (1.0, 40.0), (2.0, 30.0)]).on_right(),
            ],
        )
        .right_axis("frame time (ms)");
        let (_, layout) = draw_layout(&temp("two.png"), &Chart::Lines(lines)).expect("drawn");
        let [_, top, _, bottom] = layout.plot;
        let height = f64::from(bottom - top);
        let level = |b: &[i32; 4]| (f64::from(bottom) - f64::from(b[1] + b[3]) / 2.0) / height;
        let m = &layout.markers;
        // Both maxima at 1/1.15 of their axis (ranges from zero, 15% headroom).
        for (k, want) in [(0, 1.0 / 1.15), (4, 1.0 / 1.15), (3, 0.5 / 1.15)] {
            assert!(
                (level(&m[k]) - want).abs() < 0.02,
                "marker {k} at {}",
                level(&m[k])
            );
        }
    }
}
