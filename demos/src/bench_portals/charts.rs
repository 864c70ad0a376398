//! The portal sweep's charts: frame time against the triangles behind the doorways and
//! against resolution, error and time along the walkthrough, and error against time for
//! every walkthrough frame (where the methods differ: from their build eyes they agree).

use super::{Row, METHODS};
use crate::chart::{Chart, Line, Lines};
use plotters::prelude::SeriesLabelPosition;

/// `(file, chart)` for every chart of the sweep.
pub fn charts(rows: &[Row]) -> Vec<(&'static str, Chart)> {
    let lines = |series: &str, x: fn(&Row) -> f64, y: fn(&Row) -> f64, geometry: bool| {
        METHODS
            .iter()
            .filter(|(m, _)| geometry || *m != "geometry")
            .map(|(m, _)| {
                let points = rows
                    .iter()
                    .filter(|r| r.series == series && r.method == *m)
                    .map(|r| (x(r), y(r)))
                    .collect();
                Line::new(*m, points)
            })
            .collect::<Vec<_>>()
    };
    let ms = |r: &Row| r.time.median_ms;
    fn psnr(r: &Row) -> f64 {
        if r.method == "geometry" {
            return 99.0;
        }
        r.error.map_or(f64::NAN, |e| e.psnr_capped(99.0))
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
                    lines("triangles", |r| r.room_triangles as f64, ms, true),
                )
                .log(true, true)
                .legend(SeriesLabelPosition::UpperLeft),
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
                    lines("resolution", |r| (r.width * r.height) as f64, ms, true),
                )
                .log(true, true)
                .legend(SeriesLabelPosition::UpperLeft),
            ),
        ),
        (
            "portals_walk_error.png",
            Chart::Lines(
                Lines::new(
                    format!("Error along the walkthrough{}", size("walk")),
                    "walkthrough (0: hall, 0.6: turning to the middle door, 1: inside its room)",
                    "PSNR against geometry (dB; geometry is the reference, 99)",
                    lines("walk", |r| r.t as f64, psnr, true),
                )
                .legend(SeriesLabelPosition::LowerLeft),
            ),
        ),
        (
            "portals_walk_time.png",
            Chart::Lines(
                Lines::new(
                    format!(
                        "Frame time along the walkthrough, rebuilds included{}",
                        size("walk")
                    ),
                    "walkthrough (0: hall, 0.6: turning to the middle door, 1: inside its room)",
                    "frame time (ms)",
                    lines("walk", |r| r.t as f64, ms, true),
                )
                .legend(SeriesLabelPosition::UpperLeft),
            ),
        ),
        (
            "portals_time_error.png",
            Chart::Scatter(
                Lines::new(
                    format!(
                        "Error against frame time, each frame of the walkthrough{}",
                        size("walk")
                    ),
                    "frame time, builds included (ms)",
                    "PSNR against geometry (dB; geometry is the reference, 99)",
                    lines("walk", ms, psnr, true),
                )
                .log(true, false)
                .legend(SeriesLabelPosition::LowerRight),
            ),
        ),
    ]
}
