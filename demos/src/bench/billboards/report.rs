//! The sweep's charts.

use super::{Row, Times};
use crate::bench::raster::count_name;
use crate::bench::{Progress, RunFlags, Sweep};
use crate::chart::{Chart, Line, Lines};
use ibr::metrics::ImageError;

/// Highest PSNR drawn in charts (identical images have an infinite PSNR).
pub const PSNR_CAP_DB: f64 = 99.0;

/// The sweep's charts: file name and chart.
pub fn charts(rows: &[Row]) -> Vec<(&'static str, Chart)> {
    let of = |series: &'static str| rows.iter().filter(move |r| r.series == series);
    let times = |series: &'static str, x: fn(&Row) -> f64, pick: fn(&Times) -> f64, name: &str| {
        let points = of(series).filter_map(|r| Some((x(r), pick(r.times.as_ref()?))));
        Line::new(name, points.collect())
    };
    let parts = |series: &'static str, x: fn(&Row) -> f64| {
        vec![
            times(series, x, |t| t.total.median_ms, "build + render"),
            times(series, x, |t| t.render.median_ms, "render"),
            times(series, x, |t| t.build.median_ms, "build (quads + sort)"),
        ]
    };
    let size_of = |series: &'static str| {
        of(series)
            .next()
            .map_or(String::new(), |r| format!(" at {}x{}", r.width, r.height))
    };
    let mut res = parts("resolution", |r| r.value / 1e6);
    res[0].labels = of("resolution")
        .map(|r| format!("{}x{}", r.width, r.height))
        .collect();
    let n = of("resolution").next().map_or(0, |r| r.items);
    let accuracy = |name: &str, y_desc: &str, pick: fn(&ImageError) -> f64| {
        let line = |series: &'static str, label: &str| {
            let points = of(series).filter_map(|r| Some((r.value, pick(r.error.as_ref()?))));
            Line::new(label, points.collect())
        };
        Lines::new(
            format!("Billboard trees against meshes: {name} vs view elevation"),
            "view elevation (degrees)",
            y_desc,
            vec![
                line("accuracy_fade", "fade out (Facing::UPRIGHT)"),
                line("accuracy_top", "fade to top-down sprite"),
            ],
        )
    };
    let total = |t: &Times| t.total.median_ms;
    let value = |r: &Row| r.value;
    vec![
        (
            "billboards_count.png",
            Lines::new(
                format!("Blended particles: frame time vs count{}", size_of("count")),
                "billboards",
                "median time (ms)",
                parts("count", value),
            )
            .log(true, true),
        ),
        (
            "billboards_resolution.png",
            Lines::new(
                format!(
                    "Blended particles: frame time vs resolution ({})",
                    count_name(n)
                ),
                "megapixels",
                "median time (ms)",
                res,
            ),
        ),
        (
            "billboards_accuracy_psnr.png",
            accuracy("PSNR", "PSNR (dB)", |e| e.psnr_capped(PSNR_CAP_DB)),
        ),
        (
            "billboards_accuracy_mae.png",
            accuracy("mean error", "mean absolute error (8-bit levels)", |e| {
                e.mean_abs
            }),
        ),
        (
            "billboards_trees.png",
            Lines::new(
                format!("Forest: frame time vs trees{}", size_of("trees_mesh")),
                "trees",
                "median frame time (ms)",
                vec![
                    times("trees_mesh", value, total, "mesh trees"),
                    times(
                        "trees_billboard",
                        value,
                        total,
                        "billboard trees (build + render)",
                    ),
                    times(
                        "trees_nailboard",
                        value,
                        total,
                        "nailboard trees, the showcase's (build + render)",
                    ),
                ],
            )
            .log(true, true),
        ),
    ]
    .into_iter()
    .chain([("billboards_trees_error_time.png", trees_error_time(rows))])
    .map(|(name, lines)| (name, Chart::Lines(lines)))
    .collect()
}

/// Speed against accuracy on the same frames: each forest's median frame time and its
/// error against the mesh forest (the meshes are the reference, error 0), one point per
/// tree count, labelled with it.
fn trees_error_time(rows: &[Row]) -> Lines {
    let line = |series: &str, name: &str| {
        let (mut points, mut labels) = (Vec::new(), Vec::new());
        for r in rows.iter().filter(|r| r.series == series) {
            if let (Some(t), Some(e)) = (&r.times, &r.error) {
                points.push((t.total.median_ms, e.mean_abs));
                labels.push(format!("{} trees", count_name(r.items)));
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
        "Forest: error against frame time (billboards vs the mesh trees they replace)",
        "median frame time (ms)",
        "mean absolute error vs mesh forest (8-bit levels)",
        vec![
            line("trees_mesh", "mesh trees (the reference)"),
            line("trees_billboard", "billboard trees"),
            line(
                "trees_nailboard",
                "nailboard trees (views, per-texel depth)",
            ),
        ],
    )
    .log(true, false)
}

/// The `billboards` sweep (the module docs of [`super`]).
#[derive(Clone, Copy, Debug)]
pub struct BillboardsSweep;

impl Sweep for BillboardsSweep {
    const NAME: &'static str = "billboards";
    const ABOUT: &'static str = "Billboard frame time against count and resolution, billboard-tree error against view elevation, and billboard and nailboard against mesh trees";
    const ROWS: &'static str = "measurements";
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
        let what = format!("{:<16} {:<13} {:>9}", r.series, r.param, r.value);
        Some(match (&r.times, &r.error) {
                (Some(t), _) => format!(
                    "{what} {:>4}x{:<4} {:>9} tris  build {:>8.3} ms  render {:>8.3} ms  total {:>8.3} ms ({} frames)",
                    r.width, r.height, r.triangles, t.build.median_ms, t.render.median_ms, t.total.median_ms, t.total.frames
                ),
                (None, Some(e)) => format!(
                    "{what} {:>4}x{:<4} PSNR {:>6.2} dB  MAE {:>6.2}  max {:>3}  over {:>5.1}%  coverage {:>5.1}%",
                    r.width,
                    r.height,
                    e.psnr_db,
                    e.mean_abs,
                    e.max_abs,
                    e.frac_over * 100.0,
                    e.coverage_mismatch * 100.0
                ),
                (None, None) => format!("{what} (nothing measured)"),
            })
    }

    fn charts(&self, rows: &[Row]) -> Vec<(&'static str, Chart)> {
        charts(rows)
    }
}
