//! The portal sweep as the CLI runs it ([`PortalsSweep`]: its rows printed) and its charts:
//! frame time against the triangles behind the doorways and against resolution, error and
//! time along the walkthrough, and error against time for every walkthrough frame (where
//! the methods differ: from their build eyes they agree).

use super::{Row, METHODS};
use crate::bench::{Progress, RunFlags, Sweep};
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

/// The `portals` sweep (the module docs of [`super`]).
#[derive(Clone, Copy, Debug)]
pub struct PortalsSweep;

impl Sweep for PortalsSweep {
    const NAME: &'static str = "portals";
    const ABOUT: &'static str = "Rooms through LDI portals, depth-image and flat portals, or as geometry: time against triangles and resolution, error along a walkthrough";
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
        if r.series == "walk" {
            return None;
        }
        let err = r.error.map_or(String::new(), |e| {
            format!(
                "PSNR {:>6.2} dB  MAE {:>5.2}",
                e.psnr_capped(99.0),
                e.mean_abs
            )
        });
        Some(format!(
                "{:<10} {:<11} {:>9} tris {:>4}x{:<4} median {:>8.3} ms  {:>8} tris in  {:>8} samples  {:>8} px  {err}",
                r.series,
                r.method,
                r.room_triangles,
                r.width,
                r.height,
                r.time.median_ms,
                r.triangles_in,
                r.samples,
                r.pixels,
            ))
    }

    fn summary(&self, rows: &[Row]) -> Vec<String> {
        let mut out = Vec::new();
        for m in ["geometry", "flat", "depth-image", "ldi"] {
            let walk: Vec<&Row> = rows
                .iter()
                .filter(|r| r.series == "walk" && r.method == m)
                .collect();
            if walk.is_empty() {
                continue;
            }
            let n = walk.len() as f64;
            let mean_ms = walk.iter().map(|r| r.time.median_ms).sum::<f64>() / n;
            let max_ms = walk.iter().map(|r| r.time.median_ms).fold(0.0, f64::max);
            let psnr: Vec<f64> = walk
                .iter()
                .filter_map(|r| r.error.map(|e| e.psnr_capped(99.0)))
                .collect();
            let min_psnr = psnr.iter().copied().fold(f64::INFINITY, f64::min);
            let rebuilds: u64 = walk.iter().map(|r| r.rebuilds).sum();
            out.push(format!(
                "walk       {m:<11} {} frames  mean {mean_ms:>7.3} ms  max {max_ms:>7.3} ms  rebuilds {rebuilds}  lowest PSNR {}",
                walk.len(),
                if psnr.is_empty() { "-".to_string() } else { format!("{min_psnr:.2} dB") },
            ));
        }
        out
    }

    fn charts(&self, rows: &[Row]) -> Vec<(&'static str, Chart)> {
        charts(rows)
    }
}
