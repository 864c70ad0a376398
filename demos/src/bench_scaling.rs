//! The `bench scaling` sweep: frame time follows pixels, not triangles, once impostors
//! stand in for the geometry.
//!
//! The scene is the [`City`] of [`Plan::grid`] x [`Plan::grid`] buildings (one subject
//! each, on a ground plate), its faces split finer and finer so its triangle count grows
//! over three orders of magnitude with the same silhouettes and screen coverage. The camera
//! flies a short segment of the [`Path::Orbit`] path, 50 degree vertical field of view:
//! [`Plan::frames`] poses from [`Plan::path_start`], [`Plan::path_step`] of the orbit apart
//! (the full plan: 1e-4 of the orbit, 0.036 units, a hundredth of a building's width, per
//! frame).
//!
//! Two series, one CSV row per point and mode ([`Row::HEADER`]):
//! - `triangles`: a city of each of [`Plan::triangle_counts`] at [`Plan::fixed_resolution`].
//! - `resolution`: the city of [`Plan::resolution_triangles`] at each of
//!   [`Plan::resolutions`].
//!
//! and, per series and mode, a least-squares line (`time = a + b x`, x the triangles or the
//! pixels) in a `triangles_fit` or `resolution_fit` row: `slope` (ns per triangle or per
//! pixel), `intercept_ms` and `r2`.
//!
//! Modes, at each point, over the same poses:
//! - `geometry`: one `Renderer::render` of the ground and every building's meshes. Timed:
//!   building the draw list and the render (clear included).
//! - `impostors`: [`ImpostorSet::update`] (the per-frame error prediction, and any
//!   refreshes it schedules within the budget of [`Plan::impostors`]: up to 8 per frame),
//!   then one `Renderer::render` of the ground and [`ImpostorSet::draws`]. Timed: update,
//!   draw list and render. Frames whose update refreshed nothing are the *steady* frames
//!   (`median_ms`, `min_ms`, `p90_ms`, the counters); frames with refreshes are summarised
//!   apart (`refresh_frames`, `refresh_median_ms`), since their cost is the capture's, which
//!   does grow with the triangles (`capture_triangles`). `update_ms` and `render_ms` are
//!   the medians of the update part and of the rest (draw list and render) of the steady
//!   frames; geometry's `render_ms` is its whole frame.
//!
//! Interleaving: the machine is noisy (other work comes and goes), so every point of a
//! series sees the same conditions: the timed poses are split into [`Plan::rounds`] rounds
//! of `frames / rounds` consecutive poses, and within a round each pose is rendered for
//! every point in turn (geometry frame, then impostor frame) before the camera moves on.
//! Untimed, at the start of a round, for each point: [`Plan::warmup`] geometry frames at
//! the round's first pose, then a fresh [`ImpostorSet`] updated once there with an
//! unlimited refresh budget (everything in view captured for this camera and image
//! height: [`warm_up`]), then `warmup` impostor frames there. So every round starts from
//! the same impostor state, and the impostors refresh as the eye moves on (at the default
//! 0.125 degree tolerance, from the fifth frame of a round in the full plan).
//!
//! Counters (`triangles_set_up`, `fragments_shaded`, `fragments_written`, `images`) are those
//! of the last steady frame.

use crate::chart::{Chart, Line, Lines};
use crate::city::{City, Path};
use crate::sweep::{ticker, CsvRow};
use crate::timing::Summary;
use engine::{Camera, Draw, FrameOptions, FrameStats, Renderer, Rgba, Target};
use ibr::impostor::{Config, ImpostorSet};
use ibr::subject::Subject;
use std::time::{Duration, Instant};

/// The city's seed (same buildings at every triangle count).
pub const SEED: u64 = 7;

/// How much the sweep measures.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// Buildings per side of the city.
    pub grid: u32,
    /// Nominal triangle counts of the `triangles` series (the city gets about that many),
    /// at `fixed_resolution`.
    pub triangle_counts: Vec<usize>,
    pub fixed_resolution: (u32, u32),
    /// Target sizes of the `resolution` series, city of `resolution_triangles`.
    pub resolutions: Vec<(u32, u32)>,
    pub resolution_triangles: usize,
    /// The camera path, where the timed segment starts on it, and how far the camera moves
    /// along it per frame (both in the path's [0, 1] parameter).
    pub path: Path,
    pub path_start: f32,
    pub path_step: f32,
    /// Impostor settings (tolerance, refresh budget, texture sides).
    pub impostors: Config,
    /// Untimed frames of each mode per round.
    pub warmup: usize,
    /// Timed frames (poses) per point and mode, split over `rounds`.
    pub frames: usize,
    pub rounds: usize,
}

impl Plan {
    /// The full sweep.
    pub fn full() -> Plan {
        Plan {
            grid: 10,
            triangle_counts: vec![1_000, 10_000, 100_000, 1_000_000, 2_000_000],
            fixed_resolution: (1280, 720),
            resolutions: vec![
                (320, 180),
                (640, 360),
                (1280, 720),
                (1920, 1080),
                (2560, 1440),
                (3840, 2160),
            ],
            resolution_triangles: 1_000_000,
            path: Path::Orbit,
            path_start: 0.125,
            path_step: 1e-4,
            impostors: Config::default(),
            warmup: 1,
            frames: 30,
            rounds: 6,
        }
    }

    /// Every point of the full sweep with fewer frames (two rounds of five): about a
    /// minute.
    pub fn quick() -> Plan {
        Plan {
            frames: 10,
            rounds: 2,
            ..Plan::full()
        }
    }

    /// A seconds-long smoke run (tests): a small city, two small counts and sizes.
    pub fn tiny() -> Plan {
        Plan {
            grid: 4,
            triangle_counts: vec![1_000, 20_000],
            fixed_resolution: (160, 90),
            resolutions: vec![(160, 90), (320, 180)],
            resolution_triangles: 20_000,
            warmup: 0,
            frames: 4,
            rounds: 2,
            ..Plan::full()
        }
    }

    /// Progress steps: the poses of the two series.
    pub fn steps(&self) -> usize {
        2 * self.frames.max(self.rounds.max(1))
    }
}

/// What the timed frames of one point and mode came to.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timing {
    /// Steady frames: every geometry frame; impostor frames without refreshes.
    pub steady: Summary,
    /// The update part of the steady impostor frames (zero for geometry).
    pub update: Summary,
    /// The rest of the steady frames: draw list and render (geometry: the whole frame).
    pub render: Summary,
    /// Impostor frames with at least one refresh.
    pub refresh: Summary,
    /// Impostors refreshed over the timed frames, and the triangles those captures drew.
    pub refreshes: u64,
    pub capture_triangles: u64,
}

/// A least-squares line `y = intercept + slope x` and its coefficient of determination.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Fit {
    pub slope: f64,
    pub intercept: f64,
    pub r2: f64,
    pub points: usize,
}

/// Fits `y = a + b x` by least squares; `None` for fewer than two distinct x.
pub fn fit_line(points: &[(f64, f64)]) -> Option<Fit> {
    let n = points.len() as f64;
    if points.len() < 2 {
        return None;
    }
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    if sxx <= 0.0 || !sxx.is_finite() {
        return None;
    }
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let ss_tot: f64 = points.iter().map(|p| (p.1 - my).powi(2)).sum();
    let ss_res: f64 = points
        .iter()
        .map(|p| (p.1 - intercept - slope * p.0).powi(2))
        .sum();
    let r2 = if ss_tot > 0.0 {
        1.0 - ss_res / ss_tot
    } else {
        1.0
    };
    Some(Fit {
        slope,
        intercept,
        r2,
        points: points.len(),
    })
}

/// One CSV row: a measured point (`timing`) or a fitted line (`fit`).
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// `triangles`, `resolution`, `triangles_fit` or `resolution_fit`.
    pub series: &'static str,
    /// `geometry` or `impostors`.
    pub mode: &'static str,
    /// The city's triangles (fit rows of the `triangles` series: 0).
    pub triangles: u64,
    /// Image size (fit rows of the `resolution` series: 0 x 0).
    pub width: u32,
    pub height: u32,
    pub threads: usize,
    pub timing: Option<Timing>,
    /// Counters of the last steady frame.
    pub stats: FrameStats,
    /// Buildings drawn as images in the last steady frame (geometry: 0).
    pub images: usize,
    /// Fit rows: slope in ns per triangle or per pixel, intercept in ms.
    pub fit: Option<Fit>,
}

impl Row {
    pub fn pixels(&self) -> u64 {
        self.width as u64 * self.height as u64
    }
}

impl CsvRow for Row {
    const HEADER: &'static str = "series,mode,triangles,width,height,pixels,threads,frames,median_ms,min_ms,p90_ms,mean_ms,update_ms,render_ms,refresh_frames,refresh_median_ms,refreshes,capture_triangles,images,triangles_set_up,fragments_shaded,fragments_written,slope_ns,intercept_ms,r2";

    fn csv(&self) -> String {
        let timing = match &self.timing {
            Some(t) => format!(
                "{},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{},{:.4},{},{},{},{},{},{}",
                t.steady.frames,
                t.steady.median_ms,
                t.steady.min_ms,
                t.steady.p90_ms,
                t.steady.mean_ms,
                t.update.median_ms,
                t.render.median_ms,
                t.refresh.frames,
                t.refresh.median_ms,
                t.refreshes,
                t.capture_triangles,
                self.images,
                self.stats.triangles_set_up,
                self.stats.fragments_shaded,
                self.stats.fragments_written
            ),
            None => ",,,,,,,,,,,,,,".to_string(),
        };
        let fit = match &self.fit {
            Some(f) => format!("{:.6},{:.4},{:.5}", f.slope * 1e6, f.intercept, f.r2),
            None => ",,".to_string(),
        };
        format!(
            "{},{},{},{},{},{},{},{},{}",
            self.series,
            self.mode,
            self.triangles,
            self.width,
            self.height,
            self.pixels(),
            self.threads,
            timing,
            fit
        )
    }
}

/// The sweep's camera at `t` along `path` for a `width` x `height` image.
pub fn camera(city: &City, path: Path, t: f32, (width, height): (u32, u32)) -> Camera {
    let (eye, target) = city.path(path, t);
    Camera::look_at(eye, target, glam::Vec3::Y, 50f32.to_radians(), 1.0)
        .with_aspect(width, height)
        .with_depth_range(0.5, city.half_extent * 8.0)
}

/// The frame's clear colour: a pale sky.
fn clear() -> FrameOptions {
    FrameOptions {
        clear: Some(Rgba::new(0.55, 0.65, 0.8, 1.0)),
        ..Default::default()
    }
}

/// One geometry frame: the ground and every building's meshes.
pub fn geometry_frame(
    renderer: &mut Renderer,
    city: &City,
    camera: &Camera,
    target: &mut Target,
) -> FrameStats {
    let mut draws: Vec<Draw> = Vec::with_capacity(city.buildings.len() + 1);
    city.ground.draws(&mut draws);
    for b in &city.buildings {
        b.draws(&mut draws);
    }
    renderer.render(draws, camera, &city.lighting, target, &clear())
}

/// One impostor frame: update the impostors for `camera`, then render the ground and
/// their draws. Returns the update's report, the counters and the update's duration.
pub fn impostor_frame(
    renderer: &mut Renderer,
    city: &mut City,
    set: &mut ImpostorSet,
    camera: &Camera,
    target: &mut Target,
) -> (ibr::impostor::Report, FrameStats, Duration) {
    let t0 = Instant::now();
    let report = set.update(&mut city.buildings, camera, target.height(), &city.lighting);
    let update = t0.elapsed();
    let mut draws: Vec<Draw> = Vec::with_capacity(city.buildings.len() + 1);
    city.ground.draws(&mut draws);
    set.draws(&city.buildings, &mut draws);
    let stats = renderer.render(draws, camera, &city.lighting, target, &clear());
    (report, stats, update)
}

/// Captures every impostor that needs it for `camera` (unlimited budget, untimed).
pub fn warm_up(city: &mut City, set: &mut ImpostorSet, camera: &Camera, height: u32) {
    let budget = set.config.budget;
    set.config.budget.refreshes = usize::MAX;
    set.config.budget.time = None;
    set.update(&mut city.buildings, camera, height, &city.lighting);
    set.config.budget = budget;
}

/// One point of a series, measured over the rounds.
struct Point {
    city_index: usize,
    size: (u32, u32),
    geometry: Samples,
    impostors: Samples,
}

/// Frame samples of one point and mode.
#[derive(Default)]
struct Samples {
    steady: Vec<Duration>,
    update: Vec<Duration>,
    render: Vec<Duration>,
    refresh: Vec<Duration>,
    refreshes: u64,
    capture_triangles: u64,
    stats: FrameStats,
    images: usize,
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
        }
    }
}

/// The path parameter of pose `i`.
pub fn pose(plan: &Plan, i: usize) -> f32 {
    plan.path_start + plan.path_step * i as f32
}

/// Measures `points` (cities and sizes) in rounds, frame by frame in turn.
fn measure(
    plan: &Plan,
    series: &str,
    cities: &mut [City],
    points: &mut [Point],
    renderer: &mut Renderer,
    tick: &mut dyn FnMut(String),
) {
    let rounds = plan.rounds.max(1);
    let frames = plan.frames.max(rounds);
    for round in 0..rounds {
        let poses = (round * frames / rounds)..((round + 1) * frames / rounds);
        // Set up every point of the round: targets, warm-up frames at the first pose, and a
        // fresh impostor set with everything in view captured there.
        let mut live: Vec<(Target, ImpostorSet)> = points
            .iter()
            .map(|p| {
                let city = &mut cities[p.city_index];
                let mut target = Target::new(p.size.0, p.size.1);
                let first = camera(city, plan.path, pose(plan, poses.start), p.size);
                for _ in 0..plan.warmup {
                    geometry_frame(renderer, city, &first, &mut target);
                }
                let mut set = ImpostorSet::new(plan.impostors, city.buildings.len());
                warm_up(city, &mut set, &first, p.size.1);
                for _ in 0..plan.warmup {
                    impostor_frame(renderer, city, &mut set, &first, &mut target);
                }
                (target, set)
            })
            .collect();
        for i in poses {
            tick(format!("{series}: frame {}/{frames}", i + 1));
            for (p, (target, set)) in points.iter_mut().zip(&mut live) {
                let city = &mut cities[p.city_index];
                let cam = camera(city, plan.path, pose(plan, i), p.size);
                let t0 = Instant::now();
                let stats = geometry_frame(renderer, city, &cam, target);
                let took = t0.elapsed();
                p.geometry.steady.push(took);
                p.geometry.render.push(took);
                p.geometry.stats = stats;

                let t0 = Instant::now();
                let (report, stats, update) = impostor_frame(renderer, city, set, &cam, target);
                let took = t0.elapsed();
                let s = &mut p.impostors;
                s.refreshes += report.refreshes as u64;
                s.capture_triangles += report.capture_triangles;
                if report.refreshes == 0 {
                    s.steady.push(took);
                    s.update.push(update);
                    s.render.push(took.saturating_sub(update));
                    s.stats = stats;
                    s.images = report.images;
                } else {
                    s.refresh.push(took);
                }
            }
        }
    }
}

/// The rows of measured points, then one fit row per mode (`x` picks the fit's x).
fn rows_of(
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
        let fixed_size = series == "triangles";
        let fit_row = Row {
            series: if fixed_size {
                "triangles_fit"
            } else {
                "resolution_fit"
            },
            mode,
            triangles: if fixed_size { 0 } else { first.triangles },
            width: if fixed_size { first.width } else { 0 },
            height: if fixed_size { first.height } else { 0 },
            threads,
            timing: None,
            stats: FrameStats::default(),
            images: 0,
            fit: fit_line(&pts),
        };
        rows.push(fit_row);
    }
}

/// Runs the sweep; `progress` is called before each measurement with its 0-based index,
/// the total, and what it is.
pub fn run(plan: &Plan, mut progress: impl FnMut(usize, usize, &str)) -> Vec<Row> {
    let threads = rayon::current_num_threads();
    let mut renderer = Renderer::new();
    let mut rows = Vec::new();
    let mut tick = ticker(plan.steps(), &mut progress);

    let mut cities: Vec<City> = plan
        .triangle_counts
        .iter()
        .map(|&n| City::with_triangles(plan.grid, n, SEED))
        .collect();
    let mut points: Vec<Point> = (0..cities.len())
        .map(|i| Point {
            city_index: i,
            size: plan.fixed_resolution,
            geometry: Samples::default(),
            impostors: Samples::default(),
        })
        .collect();
    measure(
        plan,
        "triangles",
        &mut cities,
        &mut points,
        &mut renderer,
        &mut tick,
    );
    rows_of(
        "triangles",
        &points,
        &cities,
        threads,
        |r| r.triangles as f64,
        &mut rows,
    );
    drop(cities);

    let mut cities = vec![City::with_triangles(
        plan.grid,
        plan.resolution_triangles,
        SEED,
    )];
    let mut points: Vec<Point> = plan
        .resolutions
        .iter()
        .map(|&size| Point {
            city_index: 0,
            size,
            geometry: Samples::default(),
            impostors: Samples::default(),
        })
        .collect();
    measure(
        plan,
        "resolution",
        &mut cities,
        &mut points,
        &mut renderer,
        &mut tick,
    );
    rows_of(
        "resolution",
        &points,
        &cities,
        threads,
        |r| r.pixels() as f64,
        &mut rows,
    );
    rows
}

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

/// The sweep's charts: file name and chart.
pub fn charts(rows: &[Row]) -> Vec<(&'static str, Chart)> {
    let of = |series: &'static str, mode: &'static str| {
        rows.iter()
            .filter(move |r| r.series == series && r.mode == mode)
    };
    let measured = |series: &'static str, mode: &'static str, x: fn(&Row) -> f64, name: String| {
        let points = of(series, mode).filter_map(|r| {
            let t = r.timing?;
            (t.steady.frames > 0).then(|| (x(r), t.steady.median_ms))
        });
        Line::new(name, points.collect())
    };
    let fit_of = |series: &'static str, mode: &'static str| {
        rows.iter()
            .find(|r| r.series == series && r.mode == mode)
            .and_then(|r| r.fit)
    };
    let size = of("triangles", "geometry")
        .next()
        .map_or(String::new(), |r| format!(" at {}x{}", r.width, r.height));
    let fit_name = |series: &'static str, mode: &'static str, unit: &str| {
        fit_of(series, mode).map_or(String::new(), |f| {
            format!(
                ": {:.3} ms + {:.4} ns/{unit}, R2 {:.3}",
                f.intercept,
                f.slope * 1e6,
                f.r2
            )
        })
    };
    let tri = |r: &Row| r.triangles as f64;
    let mut lines = vec![
        measured(
            "triangles",
            "geometry",
            tri,
            format!(
                "geometry{}",
                fit_name("triangles_fit", "geometry", "triangle")
            ),
        ),
        measured(
            "triangles",
            "impostors",
            tri,
            format!(
                "impostors, frames without refreshes{}",
                fit_name("triangles_fit", "impostors", "triangle")
            ),
        ),
    ];
    let refresh = of("triangles", "impostors").filter_map(|r| {
        let t = r.timing?;
        (t.refresh.frames > 0).then(|| (tri(r), t.refresh.median_ms))
    });
    let refresh = Line::new("impostors, frames with refreshes", refresh.collect());
    if !refresh.points.is_empty() {
        lines.push(refresh);
    }
    let by_triangles = Lines::new(
        format!("City: frame time vs triangles{size}"),
        "triangles",
        "median frame time (ms)",
        lines,
    )
    .log(true, true);

    let mpx = |r: &Row| r.pixels() as f64 / 1e6;
    let fitted = |mode: &'static str| {
        let xs: Vec<f64> = of("resolution", mode).map(mpx).collect();
        let lo = xs.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let points = fit_of("resolution_fit", mode)
            .filter(|_| lo < hi)
            .map_or(Vec::new(), |f| {
                [lo, hi]
                    .iter()
                    .map(|&x| (x, f.intercept + f.slope * x * 1e6))
                    .collect()
            });
        let name = fit_name("resolution_fit", mode, "pixel");
        Line::new(format!("{mode}, fit{name}"), points)
    };
    let mut imp = measured(
        "resolution",
        "impostors",
        mpx,
        "impostors (measured)".into(),
    );
    imp.labels = of("resolution", "impostors")
        .filter(|r| r.timing.is_some_and(|t| t.steady.frames > 0))
        .map(|r| format!("{}x{}", r.width, r.height))
        .collect();
    let tris = of("resolution", "impostors")
        .next()
        .map_or(String::new(), |r| approx(r.triangles));
    let by_pixels = Lines::new(
        format!("City of {tris} triangles: frame time vs pixels"),
        "megapixels",
        "median frame time (ms)",
        vec![
            imp,
            fitted("impostors"),
            measured("resolution", "geometry", mpx, "geometry (measured)".into()),
            fitted("geometry"),
        ],
    );
    vec![
        ("scaling_triangles.png", Chart::Lines(by_triangles)),
        ("scaling_resolution.png", Chart::Lines(by_pixels)),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fit_recovers_a_line_and_scores_noise_lower() {
        let exact: Vec<(f64, f64)> = (0..5).map(|i| (i as f64, 2.0 + 3.0 * i as f64)).collect();
        let f = fit_line(&exact).unwrap();
        assert!((f.slope - 3.0).abs() < 1e-12 && (f.intercept - 2.0).abs() < 1e-12);
        assert!((f.r2 - 1.0).abs() < 1e-12);
        let noisy = [(0.0, 0.0), (1.0, 2.0), (2.0, 1.0), (3.0, 3.0)];
        let g = fit_line(&noisy).unwrap();
        assert!(g.r2 > 0.0 && g.r2 < 1.0, "{g:?}");
        assert!(fit_line(&[(1.0, 1.0)]).is_none());
        assert!(fit_line(&[(1.0, 1.0), (1.0, 2.0)]).is_none());
        assert_eq!(approx(1_024_002), "1.024M");
        assert_eq!(approx(9_002), "9.002k");
        assert_eq!(approx(2_000_000), "2M");
        assert_eq!(approx(642), "642");
    }

    #[test]
    fn csv_rows_match_the_header_with_and_without_times() {
        let n = Row::HEADER.split(',').count();
        let timed = Row {
            series: "triangles",
            mode: "impostors",
            triangles: 1002,
            width: 160,
            height: 90,
            threads: 2,
            timing: Some(Timing::default()),
            stats: FrameStats::default(),
            images: 3,
            fit: None,
        };
        assert_eq!(timed.csv().split(',').count(), n);
        let fit = Row {
            series: "resolution_fit",
            timing: None,
            fit: Some(Fit::default()),
            ..timed
        };
        assert_eq!(fit.csv().split(',').count(), n);
    }
}
