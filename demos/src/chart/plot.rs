//! Chart drawing shared by every kind: axis ranges and labels, the mesh, legends and
//! point labels, and the [`Body`] a chart kind draws inside its axes.

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
}

/// An axis of plotted values (linear or logarithmic).
pub(super) trait Axis: Ranged<ValueType = f64> + ValueFormatter<f64> {}
impl<T: Ranged<ValueType = f64> + ValueFormatter<f64>> Axis for T {}

pub(super) type Context<'a, 'b, X, Y> = ChartContext<'a, BitMapBackend<'b>, Cartesian2d<X, Y>>;

/// What a chart draws inside its axes.
pub(super) trait Body {
    /// Every drawn point (they set the axis ranges).
    fn points(&self) -> Vec<(f64, f64)>;
    fn draw<'a, 'b: 'a, X: Axis, Y: Axis>(
        &self,
        chart: &mut Context<'a, 'b, X, Y>,
        text: bool,
    ) -> Result<(), Error>;
}

/// Draws `body` on `axes` (ranges fitted to its points) into a PNG at `path`.
pub(super) fn plot(path: &Path, axes: &Axes, body: &impl Body, text: bool) -> Result<(), Error> {
    let points = body.points();
    let (x0, x1) = range(points.iter().map(|p| p.0), axes.log_x);
    let (y0, y1) = range(points.iter().map(|p| p.1), axes.log_y);
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let mut builder = ChartBuilder::on(&root);
    builder.margin(16);
    if text {
        builder
            .caption(axes.title, ("sans-serif", 24))
            .x_label_area_size(48)
            .y_label_area_size(64);
    }
    // The four axis kinds have different coordinate types.
    match (axes.log_x, axes.log_y) {
        (true, true) => inside(
            builder.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?,
            axes,
            body,
            text,
        )?,
        (true, false) => inside(
            builder.build_cartesian_2d((x0..x1).log_scale(), y0..y1)?,
            axes,
            body,
            text,
        )?,
        (false, true) => inside(
            builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())?,
            axes,
            body,
            text,
        )?,
        (false, false) => inside(
            builder.build_cartesian_2d(x0..x1, y0..y1)?,
            axes,
            body,
            text,
        )?,
    }
    root.present()?;
    Ok(())
}

/// The grid, tick labels and axis descriptions, then the body.
fn inside<'a, 'b: 'a, X: Axis, Y: Axis>(
    mut chart: Context<'a, 'b, X, Y>,
    axes: &Axes,
    body: &impl Body,
    text: bool,
) -> Result<(), Error> {
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
    body.draw(&mut chart, text)
}

/// The legend box, at `position`.
pub(super) fn legend<'a, 'b: 'a, X: Axis, Y: Axis>(
    chart: &mut Context<'a, 'b, X, Y>,
    position: SeriesLabelPosition,
) -> Result<(), Error> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}

/// Text labels at points.
pub(super) fn labels<'a, X: Axis, Y: Axis>(
    chart: &mut Context<X, Y>,
    labelled: impl Iterator<Item = ((f64, f64), &'a str)>,
) -> Result<(), Error> {
    let area = chart.plotting_area().get_pixel_range();
    let area = [area.0.start, area.1.start, area.0.end, area.1.end];
    let labelled: Vec<((f64, f64), &str)> = labelled.filter(|(_, l)| !l.is_empty()).collect();
    let anchors: Vec<((i32, i32), usize)> = labelled
        .iter()
        .map(|(p, l)| (chart.backend_coord(p), l.chars().count()))
        .collect();
    let boxes = place_labels(&anchors, area);
    chart.draw_series(labelled.iter().zip(&anchors).zip(boxes).filter_map(
        |(((p, l), ((x, y), _)), b)| {
            let b = b?;
            let offset = (b[0] - x, b[1] - y);
            Some(
                EmptyElement::at(*p)
                    + Text::new(l.to_string(), offset, ("sans-serif", 14).into_font()),
            )
        },
    ))?;
    Ok(())
}

/// Where each label goes, as a pixel box `[x0, y0, x1, y1]`: beside its anchor point
/// (`chars` characters of 14-pixel text, 8 pixels each), inside `area`, overlapping no
/// label placed before it. Four places are tried (right above, right below, left above,
/// left below); a label with no free place is left out (`None`) rather than drawn over
/// another.
pub(super) fn place_labels(
    anchors: &[((i32, i32), usize)],
    area: [i32; 4],
) -> Vec<Option<[i32; 4]>> {
    let mut placed: Vec<[i32; 4]> = Vec::new();
    anchors
        .iter()
        .map(|&((x, y), chars)| {
            let (w, h) = (chars as i32 * 8, 16);
            let spots = [(6, -h - 2), (6, 4), (-w - 6, -h - 2), (-w - 6, 4)];
            let free = spots
                .iter()
                .map(|&(dx, dy)| [x + dx, y + dy, x + dx + w, y + dy + h])
                .find(|b| {
                    let inside =
                        b[0] >= area[0] && b[2] <= area[2] && b[1] >= area[1] && b[3] <= area[3];
                    inside && placed.iter().all(|o| !overlap(b, o))
                });
            if let Some(b) = free {
                placed.push(b);
            }
            free
        })
        .collect()
}

fn overlap(a: &[i32; 4], b: &[i32; 4]) -> bool {
    !(a[2] <= b[0] || b[2] <= a[0] || a[3] <= b[1] || b[3] <= a[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_never_overlap_and_stay_inside() {
        let area = [50, 20, 900, 560];
        // Crowded: twenty points along a line a few pixels apart, and some on the edges.
        let mut anchors: Vec<((i32, i32), usize)> =
            (0..20).map(|k| ((60 + 4 * k, 540 - 3 * k), 8)).collect();
        anchors.extend([((895, 25), 10), ((52, 555), 7), ((400, 300), 0)]);
        let boxes = place_labels(&anchors, area);
        let placed: Vec<[i32; 4]> = boxes.iter().flatten().copied().collect();
        assert!(placed.len() >= 4, "some labels fit: {placed:?}");
        assert!(placed.len() < anchors.len(), "crowded ones are left out");
        for (i, a) in placed.iter().enumerate() {
            assert!(a[0] >= area[0] && a[2] <= area[2] && a[1] >= area[1] && a[3] <= area[3]);
            for b in &placed[i + 1..] {
                assert!(!overlap(a, b), "{a:?} {b:?}");
            }
        }
        // Apart, every label is placed, right above its point.
        let apart = [((100, 300), 5), ((400, 300), 5), ((700, 300), 5)];
        let boxes = place_labels(&apart, area);
        assert!(boxes.iter().all(Option::is_some));
        assert_eq!(boxes[0], Some([106, 282, 146, 298]));
    }
}
