//! Chart drawing shared by every kind: axis ranges and labels, the mesh, the legend beside
//! the plot, and the lines, markers and point labels a chart kind ([`Body`]) lays out in
//! pixels. Point labels go through one placer ([`place_labels`]) for the whole chart, so
//! no two overlap, none covers a marker and none leaves the plot area.

use super::style::{draw_legend, draw_marker, draw_path, legend_size, Marker, Style, LEGEND_FONT};
use super::{Error, SIZE};
use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::prelude::*;
use std::path::Path;

/// Axis labels: 1.5, 20, 300, 4k, 2.5M.
fn short(v: f64) -> String {
    let a = v.abs();
    let trim = |s: String| {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    };
    if a >= 1e6 {
        format!("{}M", trim(format!("{:.2}", v / 1e6)))
    } else if a >= 1e3 {
        format!("{}k", trim(format!("{:.1}", v / 1e3)))
    } else if a >= 10.0 {
        format!("{v:.0}")
    } else {
        trim(format!("{v:.2}"))
    }
}

/// Axis range of `values`: from zero, or whole decades on a log axis.
fn range(values: impl Iterator<Item = f64> + Clone, log: bool) -> (f64, f64) {
    let lo = values.clone().fold(f64::INFINITY, f64::min);
    let hi = values.fold(f64::NEG_INFINITY, f64::max);
    if !lo.is_finite() || !hi.is_finite() {
        return (if log { 0.1 } else { 0.0 }, 1.0);
    }
    if log {
        // Whole decades, so every log axis has labelled ticks.
        let lo = lo.max(1e-3);
        let decade = |v: f64, up: bool| {
            let e = v.log10();
            10f64.powf(if up { e.ceil() } else { e.floor() })
        };
        (decade(lo * 0.8, false), decade(hi.max(lo) * 1.25, true))
    } else {
        (0.0, hi.max(1e-3) * 1.15)
    }
}

/// A chart's title, axis descriptions and scales.
pub(super) struct Axes<'a> {
    pub(super) title: &'a str,
    pub(super) x_desc: &'a str,
    pub(super) y_desc: &'a str,
    pub(super) log_x: bool,
    pub(super) log_y: bool,
    /// The second (right, linear) y axis' description, when some points are on it.
    pub(super) y2_desc: Option<&'a str>,
}

/// An axis of plotted values (linear or logarithmic).
pub(super) trait Axis: Ranged<ValueType = f64> + ValueFormatter<f64> {}
impl<T: Ranged<ValueType = f64> + ValueFormatter<f64>> Axis for T {}

pub(super) type Context<'a, 'b, X, Y> = ChartContext<'a, BitMapBackend<'b>, Cartesian2d<X, Y>>;

/// A polyline in pixels and how it looks.
pub(super) type Polyline = (Vec<(i32, i32)>, Style);

/// A marker at a pixel, with its label (empty for none).
pub(super) struct Mark {
    pub(super) at: (i32, i32),
    pub(super) marker: Marker,
    pub(super) colour: RGBColor,
    pub(super) label: String,
}

/// Maps a data point to image pixels.
pub(super) type ToPixel<'a> = &'a dyn Fn((f64, f64)) -> (i32, i32);

/// Where a chart kind's points go in pixels.
pub(super) struct Map<'a> {
    /// A point on the left y axis.
    pub(super) left: ToPixel<'a>,
    /// A point on the right y axis (the left one's mapping when there is none).
    pub(super) right: ToPixel<'a>,
    /// Where "exact" points go on the left y axis.
    pub(super) exact_y: f64,
}

/// What a chart draws inside its axes.
pub(super) trait Body {
    /// Every finite drawn point on the left y axis (they set the axis ranges); "exact"
    /// points are not among them.
    fn points(&self) -> Vec<(f64, f64)>;
    /// The points on the right y axis (set its range).
    fn points_right(&self) -> Vec<(f64, f64)> {
        Vec::new()
    }
    /// Whether some point is "exact" (drawn at the top of the y axis, see [`Body::layout`]).
    fn has_exact(&self) -> bool {
        false
    }
    /// The legend's entries (drawn beside the plot when there are two or more).
    fn legend(&self) -> Vec<(String, Style)>;
    /// The lines and markers in pixels.
    fn layout(&self, map: &Map) -> (Vec<Polyline>, Vec<Mark>);
}

/// Where a chart's parts went, in image pixels `[x0, y0, x1, y1]`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Layout {
    /// The image's size.
    pub image: (u32, u32),
    /// The plot area (inside the axes).
    pub plot: [i32; 4],
    /// The point labels drawn (the ones that had no free place are left out).
    pub labels: Vec<[i32; 4]>,
    /// Labels asked for but left out for want of room.
    pub dropped: usize,
    /// The markers drawn.
    pub markers: Vec<[i32; 4]>,
    /// The legend, when drawn.
    pub legend: Option<[i32; 4]>,
}

/// Point label text size.
const LABEL_FONT: u32 = 14;

/// The pixel width and height of `text` in the chart font at `size` (an estimate of 9
/// pixels a character when no font is usable).
fn text_size(text: &str, size: u32, with_font: bool) -> (i32, i32) {
    let guess = (text.chars().count() as i32 * 9, size as i32 + 3);
    if !with_font {
        return guess;
    }
    match ("sans-serif", size).into_font().box_size(text) {
        Ok((w, h)) => (w as i32 + 2, (h as i32).max(size as i32) + 2),
        Err(_) => guess,
    }
}

/// Draws `body` on `axes` (ranges fitted to its points) into a PNG at `path`.
pub(super) fn plot(
    path: &Path,
    axes: &Axes,
    body: &impl Body,
    text: bool,
) -> Result<Layout, Error> {
    let points = body.points();
    let right = body.points_right();
    let (x0, x1) = range(points.iter().chain(&right).map(|p| p.0), axes.log_x);
    let y2 = axes
        .y2_desc
        .filter(|_| !right.is_empty())
        .map(|desc| (desc, range(right.iter().map(|p| p.1), false)));
    let (y0, mut y1) = range(points.iter().map(|p| p.1), axes.log_y);
    let exact = body.has_exact();
    if exact {
        // Headroom above the finite values for the "exact" arrows.
        y1 = if axes.log_y {
            y1 * 2.0
        } else {
            y0 + (y1 - y0) * 1.12
        };
    }
    let exact_y = if axes.log_y {
        y0 * (y1 / y0).powf(0.93)
    } else {
        y0 + (y1 - y0) * 0.93
    };
    let entries = if text { body.legend() } else { Vec::new() };
    let legend =
        (entries.len() >= 2).then(|| legend_size(&entries, |s| text_size(s, LEGEND_FONT, text).0));
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let mut builder = ChartBuilder::on(&root);
    builder.margin(16);
    if let Some((w, _)) = legend {
        builder.margin_right(16 + w + 12);
    }
    if text {
        // The title is drawn below, centred on the image (not on the plot, which a legend
        // beside it moves left), at a size that fits.
        builder.margin_top(16 + TITLE_BAND);
        builder.x_label_area_size(48).y_label_area_size(64);
        if y2.is_some() {
            builder.right_y_label_area_size(64);
        }
    }
    // The four axis kinds have different coordinate types.
    let (plot_area, lines, marks) = match (axes.log_x, axes.log_y) {
        (true, true) => inside(
            builder.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?,
            axes,
            body,
            text,
            exact_y,
            y2,
        )?,
        (true, false) => inside(
            builder.build_cartesian_2d((x0..x1).log_scale(), y0..y1)?,
            axes,
            body,
            text,
            exact_y,
            y2,
        )?,
        (false, true) => inside(
            builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())?,
            axes,
            body,
            text,
            exact_y,
            y2,
        )?,
        (false, false) => inside(
            builder.build_cartesian_2d(x0..x1, y0..y1)?,
            axes,
            body,
            text,
            exact_y,
            y2,
        )?,
    };
    if text {
        title(&root, axes.title)?;
    }
    let mut layout = Layout {
        image: SIZE,
        plot: plot_area,
        ..Layout::default()
    };
    for (pts, style) in &lines {
        draw_path(&root, pts, style)?;
    }
    for m in &marks {
        draw_marker(&root, m.marker, m.at, m.colour)?;
        if m.marker != Marker::None {
            layout.markers.push(marker_box(m.marker, m.at));
        }
    }
    if text {
        draw_labels(&root, &marks, &mut layout, plot_area)?;
    }
    if let Some(size) = legend {
        let at = (SIZE.0 as i32 - 16 - size.0, plot_area[1]);
        draw_legend(&root, &entries, at, size)?;
        layout.legend = Some([at.0, at.1, at.0 + size.0, at.1 + size.1]);
    }
    root.present()?;
    Ok(layout)
}

/// Draws the marks' labels where [`place_labels`] finds room (none for some: counted in
/// `layout.dropped`), each box placed recorded in `layout.labels`.
fn draw_labels(
    root: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    marks: &[Mark],
    layout: &mut Layout,
    plot_area: [i32; 4],
) -> Result<(), Error> {
    let wanted: Vec<(&Mark, (i32, i32))> = marks
        .iter()
        .filter(|m| !m.label.is_empty())
        .map(|m| (m, text_size(&m.label, LABEL_FONT, true)))
        .collect();
    let anchors: Vec<Anchor> = wanted.iter().map(|(m, size)| (m.at, *size)).collect();
    let boxes = place_labels(&anchors, &layout.markers, plot_area);
    for ((m, _), b) in wanted.iter().zip(&boxes) {
        match b {
            Some(b) => {
                root.draw(&Text::new(
                    m.label.clone(),
                    (b[0] + 1, b[1] + 1),
                    ("sans-serif", LABEL_FONT).into_font(),
                ))?;
                layout.labels.push(*b);
            }
            None => layout.dropped += 1,
        }
    }
    Ok(())
}

/// Height of the band the title takes above the plot.
const TITLE_BAND: i32 = 30;

/// Draws `text` centred at the top of the image, at 24 pixels or smaller to fit its width.
fn title(
    root: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    text: &str,
) -> Result<(), Error> {
    let room = SIZE.0 as i32 - 24;
    let mut size = 24;
    while size > 12 && text_size(text, size, true).0 > room {
        size -= 1;
    }
    let w = text_size(text, size, true).0.min(room);
    root.draw(&Text::new(
        text.to_string(),
        ((SIZE.0 as i32 - w) / 2, 10),
        ("sans-serif", size).into_font(),
    ))?;
    Ok(())
}

/// The pixel box a marker covers.
fn marker_box(marker: Marker, (x, y): (i32, i32)) -> [i32; 4] {
    match marker {
        Marker::None => [x, y, x, y],
        _ => [x - 7, y - 7, x + 7, y + 7],
    }
}

/// Lines (and markers) of a chart kind.
type Drawn = ([i32; 4], Vec<Polyline>, Vec<Mark>);

/// The grid, tick labels and axis descriptions; then the body's lines and markers in pixels.
fn inside<'a, 'b: 'a, X: Axis, Y: Axis>(
    mut chart: Context<'a, 'b, X, Y>,
    axes: &Axes,
    body: &impl Body,
    text: bool,
    exact_y: f64,
    y2: Option<(&str, (f64, f64))>,
) -> Result<Drawn, Error> {
    let mut mesh = chart.configure_mesh();
    if text {
        mesh.x_desc(axes.x_desc)
            .y_desc(axes.y_desc)
            .x_label_formatter(&|x: &f64| short(*x))
            .y_label_formatter(&|y: &f64| short(*y));
    } else {
        mesh.x_labels(0).y_labels(0);
    }
    mesh.draw()?;
    let area = chart.plotting_area().get_pixel_range();
    let area = [area.0.start, area.1.start, area.0.end, area.1.end];
    let left = |p: (f64, f64)| chart.backend_coord(&p);
    let Some((desc, (r0, r1))) = y2 else {
        let map = Map {
            left: &left,
            right: &left,
            exact_y,
        };
        let (lines, marks) = body.layout(&map);
        return Ok((area, lines, marks));
    };
    // The right axis maps only y; x stays the left axis' (so its range is a placeholder).
    let mut dual = chart.set_secondary_coord(0.0..1.0, r0..r1);
    if text {
        dual.configure_secondary_axes()
            .y_desc(desc)
            .y_label_formatter(&|y: &f64| short(*y))
            .draw()?;
    }
    let left = |p: (f64, f64)| dual.backend_coord(&p);
    let right = |p: (f64, f64)| {
        (
            left(p).0,
            dual.borrow_secondary().backend_coord(&(0.0, p.1)).1,
        )
    };
    let map = Map {
        left: &left,
        right: &right,
        exact_y,
    };
    let (lines, marks) = body.layout(&map);
    Ok((area, lines, marks))
}

/// A label's anchor pixel and its size in pixels.
pub(super) type Anchor = ((i32, i32), (i32, i32));

/// Where each label goes, as a pixel box `[x0, y0, x1, y1]`: beside its anchor point
/// (`(anchor, (width, height))`), inside `area`, covering no marker of `markers` and
/// overlapping no label placed before it. Sixteen places around the point are tried, the
/// nearest first; a label with no free place is left out (`None`) rather than drawn over
/// another or clipped.
pub(super) fn place_labels(
    anchors: &[Anchor],
    markers: &[[i32; 4]],
    area: [i32; 4],
) -> Vec<Option<[i32; 4]>> {
    let mut placed: Vec<[i32; 4]> = Vec::new();
    anchors
        .iter()
        .map(|&((x, y), (w, h))| {
            let g = 9;
            let mut spots = vec![
                (g, -h / 2),
                (g, -h - 2),
                (g, 3),
                (-w - g, -h / 2),
                (-w - g, -h - 2),
                (-w - g, 3),
                (-w / 2, -h - g),
                (-w / 2, g),
            ];
            // Further out, for crowded points.
            for k in [1, 2] {
                let d = k * (h + 2);
                spots.extend([
                    (g, -h / 2 - d),
                    (g, -h / 2 + d),
                    (-w - g, -h / 2 - d),
                    (-w - g, -h / 2 + d),
                ]);
            }
            let free = spots
                .iter()
                .map(|&(dx, dy)| [x + dx, y + dy, x + dx + w, y + dy + h])
                .find(|b| {
                    let inside =
                        b[0] >= area[0] && b[2] <= area[2] && b[1] >= area[1] && b[3] <= area[3];
                    inside
                        && placed.iter().all(|o| !overlap(b, o))
                        && markers.iter().all(|o| !overlap(b, o))
                });
            if let Some(b) = free {
                placed.push(b);
            }
            free
        })
        .collect()
}

/// Whether two pixel boxes share any pixel.
pub(super) fn overlap(a: &[i32; 4], b: &[i32; 4]) -> bool {
    !(a[2] <= b[0] || b[2] <= a[0] || a[3] <= b[1] || b[3] <= a[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_never_overlap_and_stay_inside() {
        let area = [50, 20, 900, 560];
        // Crowded: twenty points along a line a few pixels apart, and some on the edges.
        let mut anchors: Vec<Anchor> = (0..20)
            .map(|k| ((60 + 4 * k, 540 - 3 * k), (64, 17)))
            .collect();
        anchors.extend([((895, 25), (80, 17)), ((52, 555), (56, 17))]);
        let markers: Vec<[i32; 4]> = anchors
            .iter()
            .map(|&((x, y), _)| [x - 7, y - 7, x + 7, y + 7])
            .collect();
        let boxes = place_labels(&anchors, &markers, area);
        let placed: Vec<[i32; 4]> = boxes.iter().flatten().copied().collect();
        assert!(placed.len() >= 4, "some labels fit: {placed:?}");
        assert!(placed.len() < anchors.len(), "crowded ones are left out");
        for (i, a) in placed.iter().enumerate() {
            assert!(a[0] >= area[0] && a[2] <= area[2] && a[1] >= area[1] && a[3] <= area[3]);
            assert!(
                markers.iter().all(|m| !overlap(a, m)),
                "{a:?} covers a marker"
            );
            for b in &placed[i + 1..] {
                assert!(!overlap(a, b), "{a:?} {b:?}");
            }
        }
        // Apart, every label is placed, right of its point and centred on it.
        let apart = [
            ((100, 300), (40, 16)),
            ((400, 300), (40, 16)),
            ((700, 300), (40, 16)),
        ];
        let boxes = place_labels(&apart, &[], area);
        assert!(boxes.iter().all(Option::is_some));
        assert_eq!(boxes[0], Some([109, 292, 149, 308]));
    }

    /// Axis labels carry no noise digits.
    #[test]
    fn short_numbers() {
        assert_eq!(short(100_002.0), "100k");
        assert_eq!(short(2_500_000.0), "2.5M");
        assert_eq!(short(1.5), "1.5");
        assert_eq!(short(20.0), "20");
    }
}
