//! The `bench scaling` sweep: frame time follows pixels, not triangles, once impostors
//! stand in for the geometry.
//!
//! The scene is the [`City`] of [`Settings::grid`] x [`Settings::grid`] buildings (one subject
//! each, on a ground plate), its faces split finer and finer so its triangle count grows
//! over three orders of magnitude with the same silhouettes and screen coverage. The camera
//! flies a short segment of the [`Path::Orbit`] path, 50 degree vertical field of view:
//! [`Settings::frames`] poses from [`Settings::path_start`], [`Settings::path_step`] of the orbit apart
//! (the full sweep: 1e-4 of the orbit, 0.036 units, a hundredth of a building's width, per
//! frame).
//!
//! Two series, one CSV row per point and mode ([`Row::HEADER`]):
//! - `triangles`: a city of each of [`Settings::triangle_counts`] at [`Settings::fixed_resolution`].
//! - `resolution`: the city of [`Settings::resolution_triangles`] at each of
//!   [`Settings::resolutions`].
//! - `subjects`: cities of more and more buildings ([`Settings::subject_grids`]) of about
//!   [`Settings::subject_triangles`] triangles each, at [`Settings::fixed_resolution`].
//!
//! and, per series and mode, a least-squares line (`time = a + b x`, x the triangles or the
//! pixels) in a `triangles_fit` or `resolution_fit` row: `slope` (ns per triangle or per
//! pixel), `intercept_ms` and `r2`.
//!
//! Modes, at each point, over the same poses:
//! - `geometry`: one `Renderer::render` of the ground and every building's meshes. Timed:
//!   building the draw list and the render (clear included).
//! - `impostors`: [`ImpostorSet::update`] (the per-frame error prediction, and any
//!   refreshes it schedules within the budget of [`Settings::impostors`]: up to 8 per frame),
//!   then one `Renderer::render` of the ground and [`ImpostorSet::draws`]. Timed: update,
//!   draw list and render. Frames whose update refreshed nothing are the *steady* frames
//!   (`median_ms`, `min_ms`, `p90_ms`, the counters); frames with refreshes are summarised
//!   apart (`refresh_frames`, `refresh_median_ms`), since their cost is the capture's, which
//!   does grow with the triangles (`capture_triangles`). `update_ms` and `render_ms` are
//!   the medians of the update part and of the rest (draw list and render) of the steady
//!   frames; geometry's `render_ms` is its whole frame.
//!
//! Interleaving: the machine is noisy (other work comes and goes), so every point of a
//! series sees the same conditions: the timed poses are split into [`Settings::rounds`] rounds
//! of `frames / rounds` consecutive poses, and within a round each pose is rendered for
//! every point in turn (geometry frame, then impostor frame) before the camera moves on.
//! Untimed, at the start of a round, for each point: [`Settings::warmup`] geometry frames at
//! the round's first pose, then a fresh [`ImpostorSet`] updated once there with an
//! unlimited refresh budget (everything in view captured for this camera and image
//! height: [`warm_up`]), then `warmup` impostor frames there. So every round starts from
//! the same impostor state, and the impostors refresh as the eye moves on (at the default
//! 0.125 degree tolerance, from the fifth frame of a round in the full sweep).
//!
//! Counters (`triangles_set_up`, `fragments_shaded`, `fragments_written`, `images`) are those
//! of the last steady frame.
//!
//! [`ImpostorSet::update`]: ibr::impostor::ImpostorSet::update
//! [`ImpostorSet::draws`]: ibr::impostor::ImpostorSet::draws
//! [`ImpostorSet`]: ibr::impostor::ImpostorSet
//! [`Row::HEADER`]: crate::bench::sweep::CsvRow::HEADER

mod fit;
mod frames;
mod measure;
mod report;
mod row;

pub use fit::{fit_line, Fit};
pub use frames::{camera, geometry_frame, impostor_frame, pose, warm_up};
pub use report::{approx, charts, impostor_change, ScalingSweep};
pub use row::{Row, Timing};

use crate::bench::sweep::ticker;
use crate::city::{City, Path};
use engine::Renderer;
use ibr::impostor::Config;
use measure::{measure, rows_of, Point, Samples};

/// The city's seed (same buildings at every triangle count).
pub const SEED: u64 = 7;

/// How much the sweep measures.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Buildings per side of the city.
    pub grid: u32,
    /// Nominal triangle counts of the `triangles` series (the city gets about that many),
    /// at `fixed_resolution`.
    pub triangle_counts: Vec<usize>,
    pub fixed_resolution: (u32, u32),
    /// Target sizes of the `resolution` series, city of `resolution_triangles`.
    pub resolutions: Vec<(u32, u32)>,
    pub resolution_triangles: usize,
    /// The `subjects` series: cities of `grid x grid` buildings for each of
    /// `subject_grids`, about `subject_triangles` triangles each, at `fixed_resolution`.
    pub subject_grids: Vec<u32>,
    pub subject_triangles: usize,
    /// The parallax tolerance of the `subjects` series' impostors, degrees (the other
    /// settings as [`Settings::impostors`]).
    pub subject_tolerance_deg: f32,
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

impl Settings {
    /// The full sweep.
    pub fn full() -> Settings {
        Settings {
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
            subject_grids: vec![2, 3, 4],
            subject_triangles: 64_000,
            subject_tolerance_deg: 0.5,
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
    pub fn quick() -> Settings {
        Settings {
            frames: 10,
            rounds: 2,
            ..Settings::full()
        }
    }

    /// A seconds-long smoke run (tests): a small city, two small counts and sizes.
    pub fn tiny() -> Settings {
        Settings {
            grid: 4,
            triangle_counts: vec![1_000, 20_000],
            fixed_resolution: (160, 90),
            resolutions: vec![(160, 90), (320, 180)],
            resolution_triangles: 20_000,
            subject_grids: vec![1, 2],
            subject_triangles: 2_000,
            subject_tolerance_deg: 0.5,
            warmup: 0,
            frames: 4,
            rounds: 2,
            ..Settings::full()
        }
    }

    /// Progress steps: the poses of the three series.
    pub fn steps(&self) -> usize {
        3 * self.frames.max(self.rounds.max(1))
    }
}

/// Runs the sweep; `progress` is called before each measurement with its 0-based index,
/// the total, and what it is.
pub fn run(settings: &Settings, mut progress: impl FnMut(usize, usize, &str)) -> Vec<Row> {
    let mut renderer = Renderer::new();
    let mut rows = Vec::new();
    let mut tick = ticker(settings.steps(), &mut progress);
    let mut measured = |settings: &Settings, name, cities, sizes: &[(u32, u32)], x| {
        series(
            settings,
            name,
            cities,
            sizes,
            x,
            &mut renderer,
            &mut tick,
            &mut rows,
        );
    };
    let fixed = [settings.fixed_resolution];
    let by_triangles = settings.triangle_counts.iter();
    let cities = by_triangles
        .map(|&n| City::with_triangles(settings.grid, n, SEED))
        .collect();
    measured(settings, "triangles", cities, &fixed, |r| {
        r.triangles as f64
    });
    // Few large subjects against many: the same triangles a subject, more of them.
    let mut subject_plan = settings.clone();
    subject_plan.impostors.tolerance.degrees = settings.subject_tolerance_deg;
    let per = settings.subject_triangles;
    let by_count = settings.subject_grids.iter();
    let cities = by_count
        .map(|&g| City::with_triangles(g, per * (g * g) as usize, SEED))
        .collect();
    measured(&subject_plan, "subjects", cities, &fixed, |r| {
        r.subjects as f64
    });
    let cities = vec![City::with_triangles(
        settings.grid,
        settings.resolution_triangles,
        SEED,
    )];
    measured(settings, "resolution", cities, &settings.resolutions, |r| {
        r.pixels() as f64
    });
    rows
}

/// Measures one series: every city at every size (or each city at the one size), then its
/// rows and fits (`x` picks the fit's x).
fn series(
    settings: &Settings,
    name: &'static str,
    cities: Vec<City>,
    sizes: &[(u32, u32)],
    x: fn(&Row) -> f64,
    renderer: &mut Renderer,
    tick: &mut dyn FnMut(String),
    rows: &mut Vec<Row>,
) {
    let mut points: Vec<Point> = (0..cities.len())
        .flat_map(|i| sizes.iter().map(move |&size| (i, size)))
        .map(|(city_index, size)| Point {
            city_index,
            size,
            geometry: Samples::default(),
            impostors: Samples::default(),
        })
        .collect();
    measure(settings, name, &cities, &mut points, renderer, tick);
    let threads = rayon::current_num_threads();
    rows_of(name, &points, &cities, threads, x, rows);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::sweep::CsvRow;
    use engine::FrameStats;

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
            subjects: 4,
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
