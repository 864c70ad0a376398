//! The sweep's charts and the figures its summary prints.

use super::{Fit, Row, Timing};
use crate::bench::{Progress, RunFlags, Sweep};
use crate::chart::{Chart, Line, Lines};

/// The change of a steady impostor median (`pick`: of the whole frame, the update or the
/// render) from the fewest to the most triangles of the `triangles` series up to `up_to`
/// (inclusive), as a fraction `(last - first) / first`, with the triangle counts compared.
pub fn impostor_change(
    rows: &[Row],
    up_to: u64,
    pick: fn(&Timing) -> f64,
) -> Option<(u64, u64, f64)> {
    let pts: Vec<(u64, f64)> = rows
        .iter()
        .filter(|r| r.series == "triangles" && r.mode == "impostors" && r.triangles <= up_to)
        .filter_map(|r| Some((r.triangles, pick(&r.timing?))))
        .filter(|p| p.1 > 0.0)
        .collect();
    let lo = pts.iter().min_by_key(|p| p.0)?;
    let hi = pts.iter().max_by_key(|p| p.0)?;
    (hi.0 > lo.0).then(|| (lo.0, hi.0, (hi.1 - lo.1) / lo.1))
}

/// A count with up to three decimals of thousands or millions: 642, 9.002k, 1.024M.
pub fn approx(n: u64) -> String {
    let v = n as f64;
    let (scaled, unit) = if v >= 1e6 {
        (v / 1e6, "M")
    } else if v >= 1e3 {
        (v / 1e3, "k")
    } else {
        return n.to_string();
    };
    let digits = format!("{scaled:.3}");
    format!(
        "{}{unit}",
        digits.trim_end_matches('0').trim_end_matches('.')
    )
}

/// A count for a point label, to three significant digits: 642, 9k, 100k, 1.02M (the
/// city's few extra triangles, as in 100.002k, are noise on a chart).
pub fn label_count(n: u64) -> String {
    let v = n as f64;
    let (scaled, unit) = match v {
        v if v >= 1e6 => (v / 1e6, "M"),
        v if v >= 1e3 => (v / 1e3, "k"),
        _ => return n.to_string(),
    };
    let decimals = match scaled {
        s if s >= 100.0 => 0,
        s if s >= 10.0 => 1,
        _ => 2,
    };
    let digits = format!("{scaled:.decimals$}");
    let digits = match digits.contains('.') {
        true => digits.trim_end_matches('0').trim_end_matches('.'),
        false => &digits,
    };
    format!("{digits}{unit}")
}

/// The rows of a series drawn one way.
fn of<'a>(
    rows: &'a [Row],
    series: &'static str,
    mode: &'static str,
) -> impl Iterator<Item = &'a Row> + 'a {
    rows.iter()
        .filter(move |r| r.series == series && r.mode == mode)
}

/// The steady frames' median time against `x`, where there are steady frames.
fn measured(
    rows: &[Row],
    series: &'static str,
    mode: &'static str,
    x: fn(&Row) -> f64,
    name: String,
) -> Line {
    let points = of(rows, series, mode).filter_map(|r| {
        let t = r.timing?;
        (t.steady.frames > 0).then(|| (x(r), t.steady.median_ms))
    });
    Line::new(name, points.collect())
}

/// The fitted line of a fit series drawn one way.
fn fit_of(rows: &[Row], series: &'static str, mode: &'static str) -> Option<Fit> {
    rows.iter()
        .find(|r| r.series == series && r.mode == mode)
        .and_then(|r| r.fit)
}

/// The fit as a line name's suffix (empty without a fit).
fn fit_name(rows: &[Row], series: &'static str, mode: &'static str, unit: &str) -> String {
    fit_of(rows, series, mode).map_or(String::new(), |f| {
        format!(
            ": {:.3} ms + {:.4} ns/{unit}, R2 {:.3}",
            f.intercept,
            f.slope * 1e6,
            f.r2
        )
    })
}

/// The target size of the triangle series, as a title's suffix.
fn size(rows: &[Row]) -> String {
    of(rows, "triangles", "geometry")
        .next()
        .map_or(String::new(), |r| format!(" at {}x{}", r.width, r.height))
}

/// Mean time over all of a run's frames, steady and refreshing by their counts.
fn mean_all(r: &Row) -> Option<f64> {
    let t = r.timing?;
    let n = (t.steady.frames + t.refresh.frames) as f64;
    let sum =
        t.steady.mean_ms * t.steady.frames as f64 + t.refresh.mean_ms * t.refresh.frames as f64;
    (n > 0.0).then(|| sum / n)
}

fn tri(r: &Row) -> f64 {
    r.triangles as f64
}

fn mpx(r: &Row) -> f64 {
    r.pixels() as f64 / 1e6
}

/// Frame time against triangles: geometry, impostors without and with refreshes, and
/// the impostors' mean over all frames.
fn by_triangles(rows: &[Row]) -> Lines {
    let mut lines = vec![
        measured(
            rows,
            "triangles",
            "geometry",
            tri,
            format!(
                "geometry{}",
                fit_name(rows, "triangles_fit", "geometry", "triangle")
            ),
        ),
        measured(
            rows,
            "triangles",
            "impostors",
            tri,
            format!(
                "impostors, frames without refreshes{}",
                fit_name(rows, "triangles_fit", "impostors", "triangle")
            ),
        ),
    ];
    let refresh = of(rows, "triangles", "impostors").filter_map(|r| {
        let t = r.timing?;
        (t.refresh.frames > 0).then(|| (tri(r), t.refresh.median_ms))
    });
    let refresh = Line::new("impostors, frames with refreshes", refresh.collect());
    if !refresh.points.is_empty() {
        lines.push(refresh);
        // What a run costs on average: steady and refreshing frames by their counts.
        let all = of(rows, "triangles", "impostors").filter_map(|r| Some((tri(r), mean_all(r)?)));
        lines.push(Line::new("impostors, mean over all frames", all.collect()));
    }
    Lines::new(
        format!("City: frame time vs triangles{}", size(rows)),
        "triangles",
        "median frame time (ms)",
        lines,
    )
    .log(true, true)
}

/// The fitted line of the resolution series drawn one way, over the measured pixels.
fn fitted(rows: &[Row], mode: &'static str) -> Line {
    let xs: Vec<f64> = of(rows, "resolution", mode).map(mpx).collect();
    let lo = xs.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let points = fit_of(rows, "resolution_fit", mode)
        .filter(|_| lo < hi)
        .map_or(Vec::new(), |f| {
            [lo, hi]
                .iter()
                .map(|&x| (x, f.intercept + f.slope * x * 1e6))
                .collect()
        });
    let name = fit_name(rows, "resolution_fit", mode, "pixel");
    Line::new(format!("{mode}, fit{name}"), points)
}

/// Frame time against pixels, measured and fitted, impostors and geometry.
fn by_pixels(rows: &[Row]) -> Lines {
    let mut imp = measured(
        rows,
        "resolution",
        "impostors",
        mpx,
        "impostors (measured)".into(),
    );
    imp.labels = of(rows, "resolution", "impostors")
        .filter(|r| r.timing.is_some_and(|t| t.steady.frames > 0))
        .map(|r| format!("{}x{}", r.width, r.height))
        .collect();
    let tris = of(rows, "resolution", "impostors")
        .next()
        .map_or(String::new(), |r| approx(r.triangles));
    Lines::new(
        format!("City of {tris} triangles: frame time vs pixels"),
        "megapixels",
        "median frame time (ms)",
        vec![
            imp,
            fitted(rows, "impostors"),
            measured(
                rows,
                "resolution",
                "geometry",
                mpx,
                "geometry (measured)".into(),
            ),
            fitted(rows, "geometry"),
        ],
    )
}

/// Speed against accuracy on the same poses: each city's steady frame time and its
/// error against the geometry frames (geometry: 0), labelled with its triangles.
fn by_error(rows: &[Row]) -> Lines {
    let error_time = |mode: &'static str, name: &str| {
        let (mut points, mut labels) = (Vec::new(), Vec::new());
        for r in of(rows, "triangles", mode) {
            if let Some(t) = r.timing.filter(|t| t.steady.frames > 0) {
                points.push((t.steady.median_ms, t.mae.unwrap_or(f64::NAN)));
                labels.push(label_count(r.triangles));
            }
        }
        Line {
            name: name.into(),
            points,
            labels,
            reference: false,
            right: false,
        }
    };
    Lines::new(
        format!("City: error against frame time{}", size(rows)),
        "median frame time (ms)",
        "mean absolute error vs geometry (8-bit levels)",
        vec![
            error_time("geometry", "geometry (the reference)"),
            error_time("impostors", "impostors, frames without refreshes"),
        ],
    )
    .log(true, false)
}

/// Many subjects of the same size: where impostors cross geometry as subjects are added.
fn by_subjects(rows: &[Row]) -> Lines {
    let count = |r: &Row| r.subjects as f64;
    let all = of(rows, "subjects", "impostors").filter_map(|r| Some((count(r), mean_all(r)?)));
    let per = of(rows, "subjects", "geometry")
        .find(|r| r.subjects > 0)
        .map_or(String::new(), |r| approx(r.triangles / r.subjects as u64));
    Lines::new(
        format!(
            "City of {per}-triangle buildings: frame time vs buildings{}",
            size(rows)
        ),
        "buildings (subjects)",
        "frame time (ms)",
        vec![
            measured(
                rows,
                "subjects",
                "geometry",
                count,
                "geometry, median".into(),
            ),
            measured(
                rows,
                "subjects",
                "impostors",
                count,
                "impostors, median of frames without refreshes".into(),
            ),
            Line::new("impostors, mean over all frames", all.collect()),
        ],
    )
}

/// The sweep's charts: file name and chart.
pub fn charts(rows: &[Row]) -> Vec<(&'static str, Chart)> {
    vec![
        ("scaling_triangles.png", Chart::Lines(by_triangles(rows))),
        ("scaling_resolution.png", Chart::Lines(by_pixels(rows))),
        ("scaling_error_time.png", Chart::Lines(by_error(rows))),
        ("scaling_subjects.png", Chart::Lines(by_subjects(rows))),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Point labels keep three significant digits, without the trailing noise of the
    /// city's counts (100.002k on the old charts).
    #[test]
    fn label_counts_are_short() {
        assert_eq!(label_count(100_002), "100k");
        assert_eq!(label_count(1_024_002), "1.02M");
        assert_eq!(label_count(9_002), "9k");
        assert_eq!(label_count(12_345), "12.3k");
        assert_eq!(label_count(642), "642");
        assert_eq!(label_count(2_000_000), "2M");
    }
}

/// The `scaling` sweep (the module docs of [`super`]).
#[derive(Clone, Copy, Debug)]
pub struct ScalingSweep;

impl Sweep for ScalingSweep {
    const NAME: &'static str = "scaling";
    const ABOUT: &'static str = "The city as geometry and through impostors: frame time against triangles and against pixels, with fitted lines";
    type Flags = RunFlags;
    type Settings = super::Settings;
    type Row = Row;

    fn settings(&self, flags: &RunFlags) -> Result<super::Settings, String> {
        Ok(flags.pick(
            super::Settings::tiny,
            super::Settings::quick,
            super::Settings::full,
        ))
    }

    fn rows(
        &self,
        settings: &super::Settings,
        _: &RunFlags,
        progress: Progress,
    ) -> Result<Vec<Row>, String> {
        Ok(super::run(settings, progress))
    }

    fn line(&self, r: &Row) -> Option<String> {
        let what = format!(
            "{:<14} {:<9} {:>9} tris {:>4}x{:<4}",
            r.series, r.mode, r.triangles, r.width, r.height
        );
        Some(match (&r.timing, &r.fit) {
                (Some(t), _) => format!(
                    "{what} median {:>9.3} ms  p90 {:>9.3}  update {:>6.3}  render {:>9.3}  ({} frames; {} with refreshes, median {:.3} ms)  set up {:>8}  shaded {:>9}",
                    t.steady.median_ms,
                    t.steady.p90_ms,
                    t.update.median_ms,
                    t.render.median_ms,
                    t.steady.frames,
                    t.refresh.frames,
                    t.refresh.median_ms,
                    r.stats.triangles_set_up,
                    r.stats.fragments_shaded
                ),
                (None, Some(f)) => format!(
                    "{what} fit: {:.4} ms + {:.6} ns per {}, R^2 {:.4}",
                    f.intercept,
                    f.slope * 1e6,
                    if r.series == "triangles_fit" { "triangle" } else { "pixel" },
                    f.r2
                ),
                (None, None) => format!("{what} (nothing measured)"),
            })
    }

    fn summary(&self, rows: &[Row]) -> Vec<String> {
        type Pick = fn(&Timing) -> f64;
        let parts: [(&str, Pick); 3] = [
            ("frame", |t| t.steady.median_ms),
            ("update", |t| t.update.median_ms),
            ("draw list + render", |t| t.render.median_ms),
        ];
        let mut out = Vec::new();
        for (part, pick) in parts {
            if let Some((lo, hi, change)) = impostor_change(rows, 1_500_000, pick) {
                out.push(format!(
                    "bench: impostor {part} median (frames without refreshes) from {lo} to {hi} triangles: {:+.1}%",
                    change * 100.0
                ));
            }
        }
        out
    }

    fn charts(&self, rows: &[Row]) -> Vec<(&'static str, Chart)> {
        charts(rows)
    }
}
