//! The interleaved measurement of a series' points (rounds, warm-up, timed frames) and the
//! rows they come to.

use super::frames::{camera, geometry_frame, impostor_frame, pose, warm_up};
use super::{fit_line, Row, Settings, Timing};
use crate::city::City;
use crate::timing::Summary;
use engine::{FrameStats, Renderer, Target};
use ibr::impostor::Impostored;
use ibr::metrics::{self, Options};
use ibr::subject::MeshGroup;
use ibr::technique::FrameLoop;
use std::time::Duration;

/// One point of a series, measured over the rounds.
pub(super) struct Point {
    pub(super) city_index: usize,
    pub(super) size: (u32, u32),
    pub(super) geometry: Samples,
    pub(super) impostors: Samples,
}

/// Frame samples of one point and mode.
#[derive(Default)]
pub(super) struct Samples {
    steady: Vec<Duration>,
    update: Vec<Duration>,
    render: Vec<Duration>,
    refresh: Vec<Duration>,
    refreshes: u64,
    capture_triangles: u64,
    stats: FrameStats,
    images: usize,
    /// Per steady frame: mean absolute error against the geometry frame at the same pose.
    errors: Vec<f64>,
}

impl Samples {
    fn timing(&self) -> Timing {
        Timing {
            steady: Summary::of(&self.steady),
            update: Summary::of(&self.update),
            render: Summary::of(&self.render),
            refresh: Summary::of(&self.refresh),
            refreshes: self.refreshes,
            capture_triangles: self.capture_triangles,
            mae: (!self.errors.is_empty())
                .then(|| self.errors.iter().sum::<f64>() / self.errors.len() as f64),
        }
    }
}

/// Measures `points` (cities and sizes) in rounds, frame by frame in turn.
pub(super) fn measure(
    settings: &Settings,
    series: &str,
    cities: &[City],
    points: &mut [Point],
    renderer: &mut Renderer,
    tick: &mut dyn FnMut(String),
) {
    let rounds = settings.rounds.max(1);
    let frames = settings.frames.max(rounds);
    let mut frame_loop = FrameLoop::new();
    for round in 0..rounds {
        let poses = (round * frames / rounds)..((round + 1) * frames / rounds);
        // Set up every point of the round: targets, warm-up frames at the first pose, and a
        // fresh impostor set with everything in view captured there.
        let mut live: Vec<(Target, Impostored<MeshGroup>)> = points
            .iter()
            .map(|p| {
                let city = &cities[p.city_index];
                let mut target = Target::new(p.size.0, p.size.1);
                let first = camera(city, settings.path, pose(settings, poses.start), p.size);
                for _ in 0..settings.warmup {
                    geometry_frame(renderer, &mut frame_loop, city, &first, &mut target);
                }
                let mut imp = warm_up(city, settings.impostors, &first, &target);
                for _ in 0..settings.warmup {
                    impostor_frame(
                        renderer,
                        &mut frame_loop,
                        city,
                        &mut imp,
                        &first,
                        &mut target,
                    );
                }
                (target, imp)
            })
            .collect();
        for i in poses {
            tick(format!("{series}: frame {}/{frames}", i + 1));
            for (p, (target, imp)) in points.iter_mut().zip(&mut live) {
                let city = &cities[p.city_index];
                let cam = camera(city, settings.path, pose(settings, i), p.size);
                let stats = geometry_frame(renderer, &mut frame_loop, city, &cam, target);
                let took = frame_loop.times.total;
                p.geometry.steady.push(took);
                p.geometry.render.push(took);
                p.geometry.stats = stats;
                p.geometry.errors.push(0.0);
                // The geometry frame is the ground truth of the impostor frame that follows.
                let truth = target.clone();

                let (report, stats) =
                    impostor_frame(renderer, &mut frame_loop, city, imp, &cam, target);
                let (took, update) = (frame_loop.times.total, frame_loop.times.prepare);
                let s = &mut p.impostors;
                s.refreshes += report.refreshes as u64;
                s.capture_triangles += report.capture_triangles;
                if report.refreshes == 0 {
                    s.steady.push(took);
                    s.update.push(update);
                    s.render.push(took.saturating_sub(update));
                    s.stats = stats;
                    s.images = report.images;
                    if let Ok(e) = metrics::compare(target, &truth, &Options::default()) {
                        s.errors.push(e.mean_abs);
                    }
                } else {
                    s.refresh.push(took);
                }
            }
        }
    }
}

/// The rows of measured points, then one fit row per mode (`x` picks the fit's x).
pub(super) fn rows_of(
    series: &'static str,
    points: &[Point],
    cities: &[City],
    threads: usize,
    x: fn(&Row) -> f64,
    rows: &mut Vec<Row>,
) {
    let start = rows.len();
    for p in points {
        let triangles = cities[p.city_index].triangle_count() as u64;
        for (mode, s) in [("geometry", &p.geometry), ("impostors", &p.impostors)] {
            rows.push(Row {
                series,
                mode,
                triangles,
                width: p.size.0,
                height: p.size.1,
                threads,
                timing: Some(s.timing()),
                stats: s.stats,
                images: s.images,
                subjects: cities[p.city_index].buildings.len(),
                fit: None,
            });
        }
    }
    for mode in ["geometry", "impostors"] {
        let pts: Vec<(f64, f64)> = rows[start..]
            .iter()
            .filter(|r| r.mode == mode)
            .filter_map(|r| {
                let t = r.timing?;
                (t.steady.frames > 0).then(|| (x(r), t.steady.median_ms))
            })
            .collect();
        let first = &rows[start];
        let fixed_size = series != "resolution";
        let fit_row = Row {
            series: match series {
                "triangles" => "triangles_fit",
                "subjects" => "subjects_fit",
                _ => "resolution_fit",
            },
            mode,
            triangles: if fixed_size { 0 } else { first.triangles },
            width: if fixed_size { first.width } else { 0 },
            height: if fixed_size { first.height } else { 0 },
            threads,
            timing: None,
            stats: FrameStats::default(),
            images: 0,
            subjects: 0,
            fit: fit_line(&pts),
        };
        rows.push(fit_row);
    }
}
