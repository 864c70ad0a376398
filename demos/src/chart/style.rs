//! How a series looks: its colour, marker shape and line dash, so series are told apart
//! by shape and dash as well as colour, and the legend drawn beside the plot.

use super::{Error, SERIES};
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

/// A marker shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Marker {
    Disc,
    Square,
    Triangle,
    Diamond,
    Cross,
    Ring,
    None,
}

/// A line's dash.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Dash {
    Solid,
    Dashed,
    Dotted,
}

/// A series' look.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Style {
    pub(super) colour: RGBColor,
    pub(super) marker: Marker,
    pub(super) dash: Dash,
    /// Whether its points are joined by a line.
    pub(super) joined: bool,
}

const MARKERS: [Marker; 6] = [
    Marker::Disc,
    Marker::Square,
    Marker::Triangle,
    Marker::Diamond,
    Marker::Cross,
    Marker::Ring,
];
const DASHES: [Dash; 3] = [Dash::Solid, Dash::Dashed, Dash::Dotted];

impl Style {
    /// The `k`th data series: colour, marker and dash all change with `k` (markers repeat
    /// after six, dashes after three, colours after fourteen, so no two of the first
    /// fourteen series look alike even in grey).
    pub(super) fn series(k: usize, joined: bool) -> Style {
        Style {
            colour: SERIES[k % SERIES.len()],
            marker: MARKERS[k % MARKERS.len()],
            dash: DASHES[k % DASHES.len()],
            joined,
        }
    }

    /// A reference line (identity, tolerance): grey, dashed, no markers.
    pub(super) fn reference(k: usize) -> Style {
        Style {
            colour: RGBColor(90 + 40 * (k % 3) as u8, 90, 90),
            marker: Marker::None,
            dash: [Dash::Dashed, Dash::Dotted][k % 2],
            joined: true,
        }
    }
}

/// Draws `marker` centred on pixel `(x, y)` of `area`.
pub(super) fn draw_marker(
    area: &DrawingArea<BitMapBackend, Shift>,
    marker: Marker,
    (x, y): (i32, i32),
    colour: RGBColor,
) -> Result<(), Error> {
    let line = colour.stroke_width(2);
    match marker {
        Marker::Disc => area.draw(&Circle::new((x, y), 4, colour.filled()))?,
        Marker::Ring => area.draw(&Circle::new((x, y), 6, line))?,
        Marker::Square => area.draw(&Rectangle::new([(x - 5, y - 5), (x + 5, y + 5)], line))?,
        Marker::Triangle => area.draw(&PathElement::new(
            vec![(x, y - 7), (x + 6, y + 4), (x - 6, y + 4), (x, y - 7)],
            line,
        ))?,
        Marker::Diamond => area.draw(&Polygon::new(
            vec![(x, y - 6), (x + 5, y), (x, y + 6), (x - 5, y)],
            colour.filled(),
        ))?,
        Marker::Cross => {
            area.draw(&PathElement::new(
                vec![(x - 5, y - 5), (x + 5, y + 5)],
                line,
            ))?;
            area.draw(&PathElement::new(
                vec![(x - 5, y + 5), (x + 5, y - 5)],
                line,
            ))?;
        }
        Marker::None => {}
    }
    Ok(())
}

/// Draws a solid, dashed or dotted pixel polyline.
pub(super) fn draw_path(
    area: &DrawingArea<BitMapBackend, Shift>,
    pts: &[(i32, i32)],
    style: &Style,
) -> Result<(), Error> {
    let s = style.colour.stroke_width(2);
    let pts = pts.to_vec();
    match style.dash {
        Dash::Solid => area.draw(&PathElement::new(pts, s))?,
        Dash::Dashed => area.draw(&DashedPathElement::new(pts, 8, 5, s))?,
        Dash::Dotted => area.draw(&DashedPathElement::new(pts, 2, 4, s))?,
    }
    Ok(())
}

/// Legend text size.
pub(super) const LEGEND_FONT: u32 = 13;
/// Width of a legend's sample (line and marker) before its text.
const SAMPLE: i32 = 36;
const ROW: i32 = 20;

/// The pixel size of a legend of `entries` (`text_width` measures a name).
pub(super) fn legend_size(
    entries: &[(String, Style)],
    text_width: impl Fn(&str) -> i32,
) -> (i32, i32) {
    let w = entries
        .iter()
        .map(|(n, _)| text_width(n))
        .max()
        .unwrap_or(0);
    (SAMPLE + 14 + w, 10 + ROW * entries.len() as i32)
}

/// Draws the legend with its top-left corner at `at`, `size` from [`legend_size`].
pub(super) fn draw_legend(
    area: &DrawingArea<BitMapBackend, Shift>,
    entries: &[(String, Style)],
    at: (i32, i32),
    size: (i32, i32),
) -> Result<(), Error> {
    area.draw(&Rectangle::new(
        [at, (at.0 + size.0, at.1 + size.1)],
        BLACK.stroke_width(1),
    ))?;
    for (i, (name, style)) in entries.iter().enumerate() {
        let y = at.1 + 5 + ROW * i as i32 + ROW / 2;
        let (x0, x1) = (at.0 + 6, at.0 + 6 + SAMPLE - 6);
        if style.joined {
            draw_path(area, &[(x0, y), (x1, y)], style)?;
        }
        draw_marker(area, style.marker, ((x0 + x1) / 2, y), style.colour)?;
        area.draw(&Text::new(
            name.clone(),
            (at.0 + SAMPLE + 8, y - 8),
            ("sans-serif", LEGEND_FONT).into_font(),
        ))?;
    }
    Ok(())
}
