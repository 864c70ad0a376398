//! The sweep's charts and its printed summary.

use super::calibration::{calibration_chart, calibration_levels_chart};
use super::methods::method_label;
use super::row::Row;
use crate::bench::{Progress, RunFlags, Sweep};
use crate::chart::{Chart, Line, Lines};

/// Highest PSNR drawn in charts (identical images have an infinite PSNR).
pub const PSNR_CAP_DB: f64 = 99.0;

/// The sweep's charts: file name and chart (the calibration scatter last).
pub fn charts(rows: &[Row]) -> Vec<(&'static str, Chart)> {
    let sweep = |path: &'static str| {
        rows.iter()
            .filter(move |r| r.series == "sweep" && r.path == path)
    };
    let by_tol = |path: &'static str, pick: &dyn Fn(&Row) -> Option<f64>| -> Vec<(f64, f64)> {
        sweep(path)
            .filter_map(|r| Some((r.tolerance_deg?, pick(r)?)))
            .collect()
    };
    let mae = |r: &Row| r.errors.map(|e| e.mae_mean);
    let mae_max = |r: &Row| r.errors.map(|e| e.mae_max);
    let size = rows
        .first()
        .map_or(String::new(), |r| format!(" at {}x{}", r.width, r.height));
    let tolerance = "tolerance (degrees)";
    let error = "measured mean abs. error (8-bit levels)";
    let by_tolerance = |title: String, y_desc: &str, lines: Vec<Line>| {
        Lines::new(title, tolerance, y_desc, lines).log(true, false)
    };
    let error_chart = by_tolerance(
        format!("Impostor error vs parallax tolerance{size}"),
        error,
        vec![
            Line::new("translate: mean over frames", by_tol("translate", &mae)),
            Line::new("translate: worst frame", by_tol("translate", &mae_max)),
            Line::new("rotate: mean over frames", by_tol("rotate", &mae)),
            Line::new("rotate: worst frame", by_tol("rotate", &mae_max)),
        ],
    );
    let rpf = |r: &Row| Some(r.refreshes_per_frame());
    let rerefresh = |r: &Row| Some((r.refreshes - r.new_captures) as f64 / r.frames.max(1) as f64);
    let refreshes = by_tolerance(
        "Refreshes per frame vs parallax tolerance (after warm-up)".into(),
        "refreshes per frame",
        vec![
            Line::new("translate", by_tol("translate", &rpf)),
            Line::new("rotate (all)", by_tol("rotate", &rpf)),
            Line::new(
                "rotate (re-renders of stale images)",
                by_tol("rotate", &rerefresh),
            ),
        ],
    );
    let med = |r: &Row| r.time.map(|t| t.median_ms);
    let tols: Vec<f64> = sweep("translate").filter_map(|r| r.tolerance_deg).collect();
    let flat = |path: &str| -> Vec<(f64, f64)> {
        rows.iter()
            .find(|r| r.series == "geometry" && r.path == path)
            .and_then(|r| r.time)
            .map_or(Vec::new(), |t| {
                tols.iter().map(|&x| (x, t.median_ms)).collect()
            })
    };
    let frame_time = by_tolerance(
        format!("Frame time vs parallax tolerance{size}"),
        "median frame time (ms)",
        vec![
            Line::new("translate: impostors", by_tol("translate", &med)),
            Line::new("rotate: impostors", by_tol("rotate", &med)),
            Line::new("translate: geometry", flat("translate")),
            Line::new("rotate: geometry", flat("rotate")),
        ],
    );
    let policy = |series: &'static str, pick: &dyn Fn(&Row) -> Option<f64>| -> Vec<(f64, f64)> {
        let mut v: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.series == series && r.path == "translate")
            .filter_map(|r| Some((r.refreshes_per_frame(), pick(r)?)))
            .collect();
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
        v
    };
    let fixed = Lines::new(
        "Error-driven vs fixed-interval refresh at equal refresh counts (translate)",
        "refreshes per frame",
        error,
        vec![
            Line::new("error-driven: mean over frames", policy("sweep", &mae)),
            Line::new("fixed interval: mean over frames", policy("fixed", &mae)),
            Line::new("error-driven: worst frame", policy("sweep", &mae_max)),
            Line::new("fixed interval: worst frame", policy("fixed", &mae_max)),
        ],
    )
    .log(true, false);
    let methods = rows.iter().filter(|r| r.series == "method").map(|r| Line {
        name: String::new(),
        points: r
            .time
            .zip(r.errors)
            .map(|(t, e)| vec![(t.median_ms, e.mae_mean)])
            .unwrap_or_default(),
        labels: vec![method_label(r)],
        reference: false,
        right: false,
    });
    let methods = Lines::new(
        "Orbit: measured error vs frame time by method",
        "median frame time (ms)",
        error,
        methods.collect(),
    );
    vec![
        ("impostors_error.png", Chart::Lines(error_chart)),
        ("impostors_refreshes.png", Chart::Lines(refreshes)),
        ("impostors_frame_time.png", Chart::Lines(frame_time)),
        ("impostors_fixed.png", Chart::Lines(fixed)),
        ("impostors_methods.png", Chart::Lines(methods)),
        (
            "impostors_calibration.png",
            Chart::Scatter(calibration_chart(rows)),
        ),
        (
            "impostors_calibration_levels.png",
            Chart::Scatter(calibration_levels_chart(rows)),
        ),
    ]
}

/// One row of the sweep as the CLI prints it.
pub fn row_line(r: &Row) -> String {
    let what = format!(
        "{:<11} {:<9} {:<16} {:>7}",
        r.series,
        r.path,
        method_label(r),
        r.tolerance_deg.map_or(String::new(), |t| format!("{t}")),
    );
    let time = r.time.map_or(String::new(), |t| {
        format!("median {:>8.3} ms  p90 {:>8.3}", t.median_ms, t.p90_ms)
    });
    let update = r
        .update_ms
        .map_or(String::new(), |u| format!("  update {u:>7.3} ms"));
    let refresh = if r.policy == "geometry" {
        String::new()
    } else {
        format!(
            "  refreshes/frame {:>6.2} (new {:>3}{})",
            r.refreshes_per_frame(),
            r.new_captures,
            r.capture_px.map_or(String::new(), |p| format!(
                ", {:.0} kpx",
                p as f64 / 1e3 / r.frames.max(1) as f64
            ))
        )
    };
    let error = r
        .errors
        .and_then(|e| Some((e, e.pooled?)))
        .map_or(String::new(), |(e, p)| {
            format!(
                "  MAE {:>6.3} (worst frame {:>6.3}, image {:>6.3})  PSNR {:>6.2} dB",
                e.mae_mean,
                e.mae_max,
                e.worst_mae,
                p.psnr_capped(PSNR_CAP_DB)
            )
        });
    let predicted = r.predicted.map_or(String::new(), |p| {
        format!("  predicted {:>6.3} deg", p.deg_mean)
    });
    let extra = match (r.memory_bytes, r.setup_ms) {
        (Some(m), Some(s)) => format!("  {:.1} MiB, bake {s:.1} ms", m as f64 / 1048576.0),
        (Some(m), None) => format!("  {:.1} MiB", m as f64 / 1048576.0),
        _ => String::new(),
    };
    format!("{what} {time}{update}{refresh}{error}{predicted}{extra}")
}

/// The `impostors` sweep (the module docs of [`super`]).
#[derive(Clone, Copy, Debug)]
pub struct ImpostorsSweep;

impl Sweep for ImpostorsSweep {
    const NAME: &'static str = "impostors";
    const ABOUT: &'static str = "Runtime impostors: frame time, refreshes and measured error against the parallax tolerance; fixed-interval refresh; predicted against measured error; octahedral";
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
        (r.series != "calibration").then(|| row_line(r))
    }

    fn summary(&self, rows: &[Row]) -> Vec<String> {
        super::calibration_summary(rows).into_iter().collect()
    }

    fn charts(&self, rows: &[Row]) -> Vec<(&'static str, Chart)> {
        charts(rows)
    }
}
