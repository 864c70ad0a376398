//! The warp sweep as the CLI runs it ([`WarpSweep`]: its rows printed) and its charts:
//! error and holes against the eye's move, and error against time beside the geometry
//! frame.

use super::Row;
use crate::bench::{Progress, RunFlags, Sweep};
use crate::chart::{Chart, Line, Lines};

/// The methods in chart order: (method, references).
fn methods(rows: &[Row]) -> Vec<(&'static str, usize)> {
    let mut out: Vec<(&'static str, usize)> = Vec::new();
    for r in rows
        .iter()
        .filter(|r| r.method != "geometry" && r.series != "speed")
    {
        if !out.contains(&(r.method, r.references)) {
            out.push((r.method, r.references));
        }
    }
    out
}

fn name(method: &str, refs: usize) -> String {
    format!("{method}, {refs} ref{}", if refs == 1 { "" } else { "s" })
}

/// A point's setting: the eye's sideways move (`d0.2`) or orbit (`a30`).
fn setting(r: &Row) -> String {
    match r.series {
        "angle" => format!("a{}", r.value),
        _ => format!("d{}", r.value),
    }
}

/// `(file, chart)` for every chart of the sweep.
pub fn charts(rows: &[Row]) -> Vec<(&'static str, Chart)> {
    let size = rows.first().map_or(String::new(), |r| {
        format!(" ({}x{}, {} triangles)", r.width, r.height, r.triangles)
    });
    let series_lines = |series: &str, y: fn(&Row) -> f64| -> Vec<Line> {
        methods(rows)
            .into_iter()
            .map(|(m, n)| {
                let points = rows
                    .iter()
                    .filter(|r| r.series == series && r.method == m && r.references == n)
                    .map(|r| (r.value as f64, y(r)))
                    .collect();
                Line::new(name(m, n), points)
            })
            .collect()
    };
    let psnr = |r: &Row| r.error.map_or(f64::NAN, |e| e.psnr_capped(99.0));
    let mut out = vec![
        (
            "warp_distance.png",
            Chart::Lines(
                Lines::new(
                    format!("Warped view against geometry, eye moved sideways{size}"),
                    "sideways move (fraction of the city's half width)",
                    "PSNR (dB)",
                    series_lines("distance", psnr),
                )
                .exact_at(99.0),
            ),
        ),
        (
            "warp_angle.png",
            Chart::Lines(
                Lines::new(
                    format!("Warped view against geometry, eye orbiting the centre{size}"),
                    "orbit (degrees)",
                    "PSNR (dB)",
                    series_lines("angle", psnr),
                )
                .exact_at(99.0),
            ),
        ),
        (
            "warp_holes.png",
            Chart::Lines(Lines::new(
                format!("Holes before filling, eye moved sideways{size}"),
                "sideways move (fraction of the city's half width)",
                "holes (fraction of the frame)",
                series_lines("distance", |r| r.holes),
            )),
        ),
    ];
    // Predicted parallax against measured error, single references (the prediction is the
    // nearest reference's).
    let predicted: Vec<Line> = methods(rows)
        .into_iter()
        .filter(|&(m, n)| n == 1 && m != "ldi")
        .map(|(m, n)| {
            let points = rows
                .iter()
                .filter(|r| r.method == m && r.references == n && r.series != "speed")
                .filter_map(|r| Some((r.predicted_px as f64, r.error?.mean_abs)))
                .collect();
            Line::new(name(m, n), points)
        })
        .collect();
    out.push((
        "warp_predicted.png",
        Chart::Scatter(Lines::new(
            format!("Predicted parallax against measured error, one reference{size}"),
            "predicted parallax spread (pixels)",
            "mean absolute error (8-bit levels)",
            predicted,
        )),
    ));
    // Error against time: every measured frame of each method, and the geometry's, each
    // labelled with its eye's move (d: sideways fraction, a: orbit degrees).
    let mut lines: Vec<Line> = methods(rows)
        .into_iter()
        .map(|(m, n)| {
            let (points, labels) = rows
                .iter()
                .filter(|r| r.method == m && r.references == n && r.series != "speed")
                .filter_map(|r| Some(((r.time.median_ms, r.error?.mean_abs), setting(r))))
                .unzip();
            Line::new(name(m, n), points).labelled(labels)
        })
        .collect();
    lines.push(Line::new(
        "geometry (the truth)",
        rows.iter()
            .filter(|r| r.method == "geometry")
            .map(|r| (r.time.median_ms, 0.0))
            .collect(),
    ));
    out.push((
        "warp_time.png",
        Chart::Scatter(Lines::new(
            format!("Error against frame time, every eye of the sweep{size}"),
            "frame time (ms, median); labels: eye move (d: sideways, a: orbit degrees)",
            "mean absolute error (8-bit levels)",
            lines,
        )),
    ));
    out
}

/// The `warp` sweep (the module docs of [`super`]).
#[derive(Clone, Copy, Debug)]
pub struct WarpSweep;

impl Sweep for WarpSweep {
    const NAME: &'static str = "warp";
    const ABOUT: &'static str =
        "Depth images warped to moved eyes: error, holes and time against geometry";
    const ROWS: &'static str = "points";
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
        let err = r.error.map_or(String::new(), |e| {
            format!(
                "PSNR {:>6.2} dB (seen {:>6.2})  MAE {:>5.2}  over {:>5.1}%",
                e.psnr_capped(99.0),
                r.psnr_seen.min(99.0),
                e.mean_abs,
                e.frac_over * 100.0
            )
        });
        let rate = if r.samples > 0 {
            format!(
                "  {:.0} M samples/s",
                r.samples as f64 / r.time.median_ms / 1e3
            )
        } else {
            String::new()
        };
        Some(format!(
            "{:<8} {:>5} {:<8} {} ref  {:>4}x{:<4} median {:>8.3} ms  holes {:>5.2}%  {err}{rate}",
            r.series,
            r.value,
            r.method,
            r.references,
            r.width,
            r.height,
            r.time.median_ms,
            r.holes * 100.0
        ))
    }

    fn charts(&self, rows: &[Row]) -> Vec<(&'static str, Chart)> {
        charts(rows)
    }
}
