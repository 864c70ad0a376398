//! The warp sweep's charts: error and holes against the eye's move, and error against time
//! beside the geometry frame.

use super::Row;
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
