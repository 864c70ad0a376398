//! The portal sweep's charts: frame time against the triangles behind the doorways and
//! against resolution, error and time along the walkthrough, and error against time for
//! every walkthrough frame (where the methods differ: from their build eyes they agree).

use super::{Row, METHODS};
use crate::chart::{Chart, Line, Lines};

/// PSNR of identical images (at and above it a value is drawn as "exact").
const EXACT: f64 = 99.0;

/// `(file, chart)` for every chart of the sweep.
pub fn charts(rows: &[Row]) -> Vec<(&'static str, Chart)> {
    let lines = |series: &str, x: fn(&Row) -> f64, y: fn(&Row) -> f64, labelled: bool| {
        METHODS
            .iter()
            .map(|(m, _)| {
                let of: Vec<&Row> = rows
                    .iter()
                    .filter(|r| r.series == series && r.method == *m)
                    .collect();
                // Labelled with the walkthrough position (the geometry's are all exact).
                let labels = (of.iter())
                    .map(|r| match labelled && r.method != "geometry" {
                        true => format!("t{:.2}", r.t),
                        false => String::new(),
                    })
                    .collect();
                Line::new(*m, of.iter().map(|&r| (x(r), y(r))).collect()).labelled(labels)
            })
            .collect::<Vec<_>>()
    };
    let ms = |r: &Row| r.time.median_ms;
    // Identical images (the geometry against itself) are "exact", drawn at the axis top.
    fn psnr(r: &Row) -> f64 {
        if r.method == "geometry" {
            return EXACT;
        }
        r.error.map_or(f64::NAN, |e| e.psnr_capped(EXACT))
    }
    let size = |series: &str| {
        rows.iter()
            .find(|r| r.series == series)
            .map_or(String::new(), |r| format!(" ({}x{})", r.width, r.height))
    };
    let walk_tris = rows
        .iter()
        .find(|r| r.series == "walk")
        .map_or(0, |r| r.room_triangles);
    vec![
        (
            "portals_triangles.png",
            Chart::Lines(
                Lines::new(
                    format!(
                        "Frame time against the triangles behind the doorways{}",
                        size("triangles")
                    ),
                    "triangles behind the doorways",
                    "median frame time (ms)",
                    lines("triangles", |r| r.room_triangles as f64, ms, false),
                )
                .log(true, true),
            ),
        ),
        (
            "portals_resolution.png",
            Chart::Lines(
                Lines::new(
                    format!(
                        "Frame time against resolution ({walk_tris} triangles behind the doorways)"
                    ),
                    "pixels",
                    "median frame time (ms)",
                    lines("resolution", |r| (r.width * r.height) as f64, ms, false),
                )
                .log(true, true),
            ),
        ),
        (
            "portals_walk_error.png",
            Chart::Lines(
                Lines::new(
                    format!("Error along the walkthrough{}", size("walk")),
                    "walkthrough (0: hall, 0.6: turning to the middle door, 1: inside its room)",
                    "PSNR against geometry (dB)",
                    lines("walk", |r| r.t as f64, psnr, false),
                )
                .exact_at(EXACT),
            ),
        ),
        (
            "portals_walk_time.png",
            Chart::Lines(Lines::new(
                format!(
                    "Frame time along the walkthrough, rebuilds included{}",
                    size("walk")
                ),
                "walkthrough (0: hall, 0.6: turning to the middle door, 1: inside its room)",
                "frame time (ms)",
                lines("walk", |r| r.t as f64, ms, false),
            )),
        ),
        (
            "portals_time_error.png",
            Chart::Scatter(
                Lines::new(
                    format!(
                        "Error against frame time, each frame of the walkthrough{}",
                        size("walk")
                    ),
                    "frame time, builds included (ms); labels: walkthrough position t",
                    "PSNR against geometry (dB)",
                    lines("walk", ms, psnr, true),
                )
                .log(true, false)
                .exact_at(EXACT),
            ),
        ),
    ]
}
