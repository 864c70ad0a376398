//! The `bench impostors` sweep: what runtime impostors ([`ibr::impostor`]) cost and how far
//! their images are from the geometry they replace, on the procedural [`City`].
//!
//! **Scene.** [`City::new`]`(grid, detail, seed)`: one impostor per building (the ground
//! plate is always drawn as geometry), lit by the city's sun, seen through a 60 degree
//! (vertical) perspective camera at [`Plan::size`]. A *run* flies [`Plan::frames`] frames
//! along the first part of a camera path ([`City::path`] with `t` from 0 to the path's span,
//! [`Plan::span`]): frame 0 is the warm-up (every visible impostor takes its first image)
//! and is left out of every figure. In the full plan (4 x 4 buildings, 6 units apart,
//! 41 frames) the `translate` eye slides 3 units (0.075 per frame), the `rotate` eye turns
//! 51.6 degrees in place (1.29 per frame) and the `orbit` eye circles 15 degrees of its
//! 22.8-unit circle (0.15 units per frame).
//!
//! **Frame time** (`median_ms`, `p90_ms`, `min_ms`, `mean_ms`): [`ImpostorSet::update`]
//! (prediction, scheduling and the refresh renders) plus `Renderer::render` of the frame
//! (ground plus one draw per impostor image or per subject drawn as geometry, clear
//! included), timed together per frame with `std::time::Instant`; `update_ms` is the mean
//! of the update part. Measuring the error is not timed.
//!
//! **Measured error.** After each timed frame, every impostor drawn as an image is measured
//! with [`ImpostorSet::measure`]: its image (the textured quad) and its building rendered as
//! geometry from the current eye, each alone over a transparent clear at the frame's size,
//! compared with [`ibr::metrics`] over the building's bounding-sphere screen rectangle
//! (grown by 2 pixels; the empty background around the building inside that rectangle is
//! compared too, so means are per rectangle pixel, not per building pixel). Occlusion by
//! other buildings is not part of it: each image is judged against its own geometry.
//! Per frame the images' errors are pooled ([`ImageError::pooled`]: as one image made of
//! all their rectangles, means weighted by pixel count, PSNR from the pooled squared error,
//! the largest `max_abs`). A row then gives, over its frames (warm-up excluded):
//! - `mae_mean`: mean over frames of the frame's pooled mean absolute error (8-bit levels);
//! - `mae_max`: the worst frame's pooled mean absolute error;
//! - `worst_mae`: the largest single image's mean absolute error in any frame;
//! - `psnr_db`, `frac_over`, `coverage_mismatch`: pooled over all frames and images;
//!   `psnr_min_db`: the worst frame's pooled PSNR; `max_abs`: the largest channel difference.
//! - `images_per_frame`: images measured per frame; `predicted_deg_mean` / `_max`: the
//!   predicted parallax of the drawn images after the frame's refreshes (a refreshed image
//!   counts 0).
//!
//! **Series** (one CSV row each, [`Row::HEADER`]):
//! - `sweep`: error-driven refresh (the library's policy) at each tolerance of
//!   [`Plan::tolerances`] (degrees of parallax; the resolution tolerance stays 1 octave) on
//!   the `translate` and `rotate` paths, with an unlimited refresh budget so every invalid
//!   impostor is refreshed in the frame it becomes invalid: the error reflects the
//!   tolerance alone. `new_captures` counts images taken for impostors that had none
//!   (buildings entering the view); the rest of `refreshes` re-render stale images.
//!   `capture_kpx_per_frame`: thousands of pixels the refreshes render per frame (each a
//!   `side` x `side` capture, `side` the power of two at or above the building's screen
//!   diameter): the refresh work, independent of the machine's load.
//! - `geometry`: the same paths with every building drawn as geometry (frame time only).
//! - `fixed`: for each `sweep` tolerance on `translate`, a fixed-interval policy given the
//!   same number of refreshes. The [`ImpostorSet`] runs with infinite tolerances (it never
//!   refreshes on its own) and the policy forces refreshes by bumping buildings'
//!   [`ibr::subject::MeshGroup::version`] (a changed subject's image is invalid at once,
//!   and the budget is unlimited): a round-robin over the buildings at a fixed rate of
//!   `R / (frames - 1)` per frame, `R` the error-driven run's refreshes after warm-up, so
//!   every building is refreshed every `interval_frames = buildings * (frames - 1) / R`
//!   frames (fractional intervals alternate between the neighbouring whole numbers).
//!   `refreshes` is what the set actually did.
//! - `calibration`: predicted against measured error. One run along the `translate` span
//!   with refreshes disabled after the warm-up (budget 0), so each image ages as the eye
//!   slides; one row per image per frame with its predicted parallax
//!   (`predicted_deg_mean`, `predicted_px_mean`) and its own measured error (`frame`,
//!   `impostor` say which).
//! - `method`: runtime impostors against baked octahedral impostors
//!   ([`ibr::octahedral`], [`Layout::Hemi`]) against geometry on the `orbit` span. Frame
//!   time as above (for octahedral impostors the per-frame [`OctahedralImpostor::update`],
//!   which recomposes each image from three baked views on the CPU, is the update part,
//!   and `refreshes` counts recomposed images); memory is texel bytes held (the runtime
//!   pool's [`ibr::impostor::Pool::bytes`] at the end of the run; the atlases and composed
//!   images of [`OctahedralImpostor::bytes`]); `setup_ms` is the bake (octahedral),
//!   `update_ms` the per-frame cost, refreshes included (runtime). Octahedral images are
//!   measured exactly as [`ImpostorSet::measure`] measures runtime ones
//!   ([`measure_draws`], checked against it in the tests); geometry is measured the same
//!   way against itself (0: the renderer is deterministic).

use crate::chart::{Line, Lines};
use crate::city::{City, Path as CityPath};
use crate::timing::Summary;
use engine::{Camera, Draw, FrameOptions, Lighting, Renderer, Rgba, Sphere, Target};
use ibr::impostor::{self, Budget, Config, ImpostorSet, Mode, Tolerance};
use ibr::metrics::{self, ImageError, Options, Region};
use ibr::octahedral::{Layout, OctahedralImpostor};
use ibr::subject::Subject;
use plotters::prelude::SeriesLabelPosition;
use std::io::Write;
use std::path::Path;
use std::time::{Duration, Instant};

/// How much the sweep measures.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// Buildings per side of the city and face subdivision ([`City::new`]).
    pub grid: u32,
    pub detail: u32,
    pub seed: u64,
    /// Frame size.
    pub size: (u32, u32),
    /// Parallax tolerances of the `sweep` series, degrees.
    pub tolerances: Vec<f32>,
    /// Frames per run, warm-up frame included.
    pub frames: usize,
    /// Share of each path ([`City::path`]'s `t`) a run covers: `translate` (also the
    /// calibration run's), `rotate` and `orbit`.
    pub translate_span: f32,
    pub rotate_span: f32,
    pub orbit_span: f32,
    /// Tolerances (degrees) of the runtime impostors in the method comparison.
    pub method_tolerances: Vec<f32>,
    /// Octahedral impostors of the method comparison ([`Layout::Hemi`]): views per side
    /// and frame pixels.
    pub octahedral: Vec<(u32, u32)>,
}

impl Plan {
    /// The full sweep.
    pub fn full() -> Plan {
        Plan {
            grid: 4,
            detail: 10,
            seed: 7,
            size: (640, 360),
            tolerances: vec![0.03, 0.0625, 0.125, 0.25, 0.5, 1.0, 2.0],
            frames: 41,
            translate_span: 0.25,
            rotate_span: 1.0,
            orbit_span: 1.0 / 24.0,
            method_tolerances: vec![0.125, 1.0],
            octahedral: vec![(8, 64), (8, 128), (16, 64)],
        }
    }

    /// Every point of the full sweep over fewer frames.
    pub fn quick() -> Plan {
        Plan {
            frames: 21,
            ..Plan::full()
        }
    }

    /// A seconds-long smoke run (tests): a 3 x 3 city at 256 x 144, three tolerances.
    pub fn tiny() -> Plan {
        Plan {
            grid: 3,
            detail: 2,
            seed: 7,
            size: (256, 144),
            tolerances: vec![0.03, 0.25, 2.0],
            frames: 17,
            method_tolerances: vec![0.125],
            octahedral: vec![(8, 32)],
            ..Plan::full()
        }
    }

    /// The span of `path` a run covers.
    pub fn span(&self, path: CityPath) -> f32 {
        match path {
            CityPath::Translate => self.translate_span,
            CityPath::Rotate => self.rotate_span,
            CityPath::Orbit => self.orbit_span,
        }
    }

    /// Runs the sweep makes (progress steps).
    pub fn steps(&self) -> usize {
        // sweep and geometry on two paths, fixed on one, calibration, methods.
        2 * (self.tolerances.len() + 1)
            + self.tolerances.len()
            + 1
            + 1
            + self.method_tolerances.len()
            + self.octahedral.len()
    }
}

/// Error figures of a row (see the module docs for what is pooled).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Errors {
    /// Frames measured and images measured in them.
    pub frames: usize,
    pub images: usize,
    pub mae_mean: f64,
    pub mae_max: f64,
    pub worst_mae: f64,
    /// Pooled over every image of every frame.
    pub pooled: Option<ImageError>,
    pub psnr_min_db: f64,
}

impl Errors {
    /// Folds per-frame lists of per-image errors into a row's figures (frames with no
    /// image are skipped).
    pub fn of_frames(frames: &[Vec<ImageError>]) -> Errors {
        let per_frame: Vec<ImageError> = frames.iter().filter_map(ImageError::pooled).collect();
        let n = per_frame.len();
        Errors {
            frames: n,
            images: frames.iter().map(Vec::len).sum(),
            mae_mean: per_frame.iter().map(|e| e.mean_abs).sum::<f64>() / n.max(1) as f64,
            mae_max: per_frame.iter().map(|e| e.mean_abs).fold(0.0, f64::max),
            worst_mae: frames
                .iter()
                .flatten()
                .map(|e| e.mean_abs)
                .fold(0.0, f64::max),
            pooled: ImageError::pooled(&per_frame),
            psnr_min_db: per_frame
                .iter()
                .map(|e| e.psnr_db)
                .fold(f64::INFINITY, f64::min),
        }
    }
}

/// Predicted parallax over the drawn images (refreshed images count as 0).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PredictedStats {
    pub deg_mean: f64,
    pub deg_max: f64,
    pub px_mean: f64,
}

/// One CSV row.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// `sweep`, `geometry`, `fixed`, `calibration` or `method`.
    pub series: &'static str,
    /// `translate`, `rotate` or `orbit`.
    pub path: &'static str,
    /// `error` (error-driven), `fixed`, `frozen` (calibration), `geometry`, `runtime` or
    /// `octahedral_NxP` (N x N views of P pixels).
    pub policy: String,
    pub tolerance_deg: Option<f64>,
    /// Calibration rows: which frame and which impostor.
    pub frame: Option<usize>,
    pub impostor: Option<usize>,
    pub width: u32,
    pub height: u32,
    pub impostors: usize,
    /// Frames after warm-up.
    pub frames: usize,
    /// Refreshes after warm-up, and how many of them were first images.
    pub refreshes: u64,
    pub new_captures: u64,
    /// Pixels rendered by the refreshes after warm-up (each a `side` x `side` capture).
    pub capture_px: Option<u64>,
    pub interval_frames: Option<f64>,
    pub time: Option<Summary>,
    pub update_ms: Option<f64>,
    pub errors: Option<Errors>,
    pub predicted: Option<PredictedStats>,
    pub memory_bytes: Option<u64>,
    pub setup_ms: Option<f64>,
    /// Triangles set up by the last frame's render (captures not included).
    pub triangles: u64,
}

impl Row {
    pub const HEADER: &'static str = "series,path,policy,tolerance_deg,frame,impostor,width,height,impostors,frames,refreshes,refreshes_per_frame,new_captures,capture_kpx_per_frame,interval_frames,median_ms,p90_ms,min_ms,mean_ms,update_ms,images_per_frame,mae_mean,mae_max,worst_mae,psnr_db,psnr_min_db,max_abs,frac_over,coverage_mismatch,predicted_deg_mean,predicted_deg_max,predicted_px_mean,memory_bytes,setup_ms,triangles";

    /// Refreshes per frame after warm-up.
    pub fn refreshes_per_frame(&self) -> f64 {
        self.refreshes as f64 / self.frames.max(1) as f64
    }

    pub fn csv(&self) -> String {
        fn opt<T: std::fmt::Display>(v: Option<T>) -> String {
            v.map_or(String::new(), |v| v.to_string())
        }
        fn f(v: Option<f64>, digits: usize) -> String {
            v.map_or(String::new(), |v| format!("{v:.digits$}"))
        }
        let time = match &self.time {
            Some(t) => format!(
                "{:.4},{:.4},{:.4},{:.4}",
                t.median_ms, t.p90_ms, t.min_ms, t.mean_ms
            ),
            None => ",,,".into(),
        };
        let errors = match &self.errors {
            Some(e) => {
                let p = e.pooled;
                format!(
                    "{:.3},{:.4},{:.4},{:.4},{},{},{},{},{}",
                    e.images as f64 / e.frames.max(1) as f64,
                    e.mae_mean,
                    e.mae_max,
                    e.worst_mae,
                    f(p.map(|p| p.psnr_db), 3),
                    f(p.map(|_| e.psnr_min_db), 3),
                    opt(p.map(|p| p.max_abs)),
                    f(p.map(|p| p.frac_over), 5),
                    f(p.map(|p| p.coverage_mismatch), 5),
                )
            }
            None => ",,,,,,,,".into(),
        };
        let predicted = match &self.predicted {
            Some(p) => format!("{:.5},{:.5},{:.4}", p.deg_mean, p.deg_max, p.px_mean),
            None => ",,".into(),
        };
        format!(
            "{},{},{},{},{},{},{},{},{},{},{},{:.4},{},{},{},{},{},{},{},{},{},{}",
            self.series,
            self.path,
            self.policy,
            opt(self.tolerance_deg),
            opt(self.frame),
            opt(self.impostor),
            self.width,
            self.height,
            self.impostors,
            self.frames,
            self.refreshes,
            self.refreshes_per_frame(),
            self.new_captures,
            f(
                self.capture_px
                    .map(|p| p as f64 / 1e3 / self.frames.max(1) as f64),
                2
            ),
            f(self.interval_frames, 3),
            time,
            f(self.update_ms, 4),
            errors,
            predicted,
            opt(self.memory_bytes),
            f(self.setup_ms, 2),
            self.triangles
        )
    }
}

/// Writes rows as CSV with a header row.
pub fn write_csv(path: &Path, rows: &[Row]) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(f, "{}", Row::HEADER)?;
    for r in rows {
        writeln!(f, "{}", r.csv())?;
    }
    f.flush()
}

/// The path's name in rows.
pub fn path_name(p: CityPath) -> &'static str {
    match p {
        CityPath::Translate => "translate",
        CityPath::Rotate => "rotate",
        CityPath::Orbit => "orbit",
    }
}

/// The camera of frame `f` of `frames` along the first `span` of `path`.
pub fn frame_camera(
    city: &City,
    path: CityPath,
    span: f32,
    f: usize,
    frames: usize,
    size: (u32, u32),
) -> Camera {
    let t = span * f as f32 / (frames.max(2) - 1) as f32;
    let (eye, target) = city.path(path, t);
    Camera::look_at(eye, target, glam::Vec3::Y, 60f32.to_radians(), 1.0)
        .with_aspect(size.0, size.1)
        .with_depth_range(0.5, city.half_extent * 12.0)
}

/// The frame's clear: an opaque sky.
fn frame_options() -> FrameOptions {
    FrameOptions {
        clear: Some(Rgba::new(0.55, 0.65, 0.8, 1.0)),
        ..Default::default()
    }
}

/// The error of `image` against `truth`, measured exactly as [`ImpostorSet::measure`]
/// measures an impostor: each rendered alone over a transparent clear into a `width` x
/// `height` target from `camera`, compared over the screen rectangle of the sphere
/// `bounds` ([`impostor::screen_rect`]). `None` when the sphere is off the image.
pub fn measure_draws<'a>(
    renderer: &mut Renderer,
    truth: impl IntoIterator<Item = Draw<'a>>,
    image: impl IntoIterator<Item = Draw<'a>>,
    camera: &Camera,
    (width, height): (u32, u32),
    lighting: &Lighting,
    bounds: Sphere,
) -> Option<ImageError> {
    let clear = FrameOptions {
        clear: Some(Rgba::new(0.0, 0.0, 0.0, 0.0)),
        ..Default::default()
    };
    let mut t = Target::new(width, height);
    renderer.render(truth, camera, lighting, &mut t, &clear);
    let mut i = Target::new(width, height);
    renderer.render(image, camera, lighting, &mut i, &clear);
    let rect = impostor::screen_rect(camera, bounds.center, bounds.radius, width, height)?;
    let opts = Options {
        region: Region::Rect(rect),
        ..Options::default()
    };
    metrics::compare(&t, &i, &opts).ok()
}

/// How a run decides refreshes.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Policy {
    /// The set's own error-driven schedule at a tolerance (degrees), unlimited budget.
    Error(f32),
    /// Infinite tolerances; a round-robin bumps `rate` buildings' versions per frame.
    Fixed { rate: f64 },
    /// Error-driven warm-up, then a budget of 0 (calibration).
    Frozen,
}

/// The set's configuration for a tolerance (degrees; infinite: never refresh on its
/// own) with an unlimited budget.
fn config(degrees: f32, octaves: f32) -> Config {
    Config {
        tolerance: Tolerance {
            degrees,
            pixels: None,
            octaves,
        },
        budget: Budget {
            refreshes: usize::MAX,
            time: None,
        },
        ..Config::default()
    }
}

/// What one run of impostors along a path measured.
struct RunOut {
    times: Vec<Duration>,
    update: Vec<Duration>,
    /// Per frame after warm-up: (impostor, predicted degrees, predicted pixels, error)
    /// of every measured image.
    measured: Vec<Vec<(usize, f32, f32, ImageError)>>,
    /// Per frame after warm-up: predicted degrees and pixels of every drawn image.
    predicted: Vec<(f32, f32)>,
    refreshes: u64,
    new_captures: u64,
    capture_px: u64,
    memory: u64,
    triangles: u64,
}

/// Flies `frames` frames of runtime impostors along the first `span` of `path`.
fn run_impostors(
    city: &mut City,
    path: CityPath,
    span: f32,
    frames: usize,
    size: (u32, u32),
    policy: Policy,
) -> RunOut {
    let n = city.buildings.len();
    let cfg = match policy {
        Policy::Error(deg) => config(deg, 1.0),
        Policy::Fixed { .. } => config(f32::INFINITY, f32::INFINITY),
        Policy::Frozen => config(Tolerance::default().degrees, 1.0),
    };
    let mut set = ImpostorSet::new(cfg, n);
    let mut renderer = Renderer::new();
    let mut target = Target::new(size.0, size.1);
    let opts = frame_options();
    let lighting = city.lighting.clone();
    let mut out = RunOut {
        times: Vec::new(),
        update: Vec::new(),
        measured: Vec::new(),
        predicted: Vec::new(),
        refreshes: 0,
        new_captures: 0,
        capture_px: 0,
        memory: 0,
        triangles: 0,
    };
    let (mut credit, mut next) = (0.0f64, 0usize);
    for f in 0..frames {
        let camera = frame_camera(city, path, span, f, frames, size);
        match policy {
            Policy::Fixed { rate } if f > 0 => {
                credit += rate;
                while credit >= 1.0 - 1e-9 && n > 0 {
                    city.buildings[next].version += 1;
                    next = (next + 1) % n;
                    credit -= 1.0;
                }
            }
            Policy::Frozen if f == 1 => set.config.budget.refreshes = 0,
            _ => {}
        }
        let had: Vec<(bool, u64)> = set
            .impostors
            .iter()
            .map(|i| (i.capture().is_some(), i.refreshes))
            .collect();
        let t0 = Instant::now();
        let report = set.update(&mut city.buildings, &camera, size.1, &lighting);
        let t1 = Instant::now();
        let mut draws = Vec::new();
        city.ground.draws(&mut draws);
        set.draws(&city.buildings, &mut draws);
        let stats = renderer.render(draws, &camera, &lighting, &mut target, &opts);
        let t2 = Instant::now();
        if f == 0 {
            continue;
        }
        out.times.push(t2 - t0);
        out.update.push(t1 - t0);
        out.refreshes += report.refreshes as u64;
        out.new_captures += set
            .impostors
            .iter()
            .zip(&had)
            .filter(|(i, h)| !h.0 && i.capture().is_some())
            .count() as u64;
        out.capture_px += set
            .impostors
            .iter()
            .zip(&had)
            .filter(|(i, h)| i.refreshes > h.1)
            .filter_map(|(i, _)| i.capture().map(|c| (c.side as u64).pow(2)))
            .sum::<u64>();
        out.triangles = stats.triangles_set_up;
        let mut frame = Vec::new();
        for i in 0..n {
            if set.impostors[i].mode != Mode::Image {
                continue;
            }
            let p = set.impostors[i].predicted;
            out.predicted.push((p.degrees, p.pixels));
            if let Some(e) = set.measure(i, &mut city.buildings[i], &camera, size, &lighting) {
                frame.push((i, p.degrees, p.pixels, e));
            }
        }
        out.measured.push(frame);
    }
    out.memory = set.pool().bytes() as u64;
    out
}

/// Flies `frames` frames with every building drawn as geometry: frame times (warm-up
/// excluded) and the last frame's triangles.
fn run_geometry(
    city: &City,
    path: CityPath,
    span: f32,
    frames: usize,
    size: (u32, u32),
) -> (Vec<Duration>, u64) {
    let mut renderer = Renderer::new();
    let mut target = Target::new(size.0, size.1);
    let opts = frame_options();
    let mut times = Vec::new();
    let mut triangles = 0;
    for f in 0..frames {
        let camera = frame_camera(city, path, span, f, frames, size);
        let t0 = Instant::now();
        let mut draws = Vec::new();
        city.ground.draws(&mut draws);
        for b in &city.buildings {
            b.draws(&mut draws);
        }
        let stats = renderer.render(draws, &camera, &city.lighting, &mut target, &opts);
        if f > 0 {
            times.push(t0.elapsed());
            triangles = stats.triangles_set_up;
        }
    }
    (times, triangles)
}

/// A tolerance as written in the plan (`0.03`, not `0.029999999329447746`).
fn deg(t: f32) -> f64 {
    t.to_string().parse().unwrap_or(t as f64)
}

fn mean_ms(d: &[Duration]) -> f64 {
    d.iter().map(|d| d.as_secs_f64() * 1e3).sum::<f64>() / d.len().max(1) as f64
}

fn predicted_stats(p: &[(f32, f32)]) -> PredictedStats {
    let n = p.len().max(1) as f64;
    PredictedStats {
        deg_mean: p.iter().map(|x| x.0 as f64).sum::<f64>() / n,
        deg_max: p.iter().map(|x| x.0 as f64).fold(0.0, f64::max),
        px_mean: p.iter().map(|x| x.1 as f64).sum::<f64>() / n,
    }
}

/// A row of a run of impostors.
fn impostor_row(
    series: &'static str,
    path: CityPath,
    policy: String,
    tolerance: Option<f32>,
    plan: &Plan,
    n: usize,
    run: &RunOut,
) -> Row {
    let frames: Vec<Vec<ImageError>> = run
        .measured
        .iter()
        .map(|f| f.iter().map(|m| m.3).collect())
        .collect();
    Row {
        series,
        path: path_name(path),
        policy,
        tolerance_deg: tolerance.map(deg),
        frame: None,
        impostor: None,
        width: plan.size.0,
        height: plan.size.1,
        impostors: n,
        frames: run.times.len(),
        refreshes: run.refreshes,
        new_captures: run.new_captures,
        capture_px: Some(run.capture_px),
        interval_frames: None,
        time: Some(Summary::of(&run.times)),
        update_ms: Some(mean_ms(&run.update)),
        errors: Some(Errors::of_frames(&frames)),
        predicted: Some(predicted_stats(&run.predicted)),
        memory_bytes: Some(run.memory),
        setup_ms: None,
        triangles: run.triangles,
    }
}

/// A geometry row.
fn geometry_row(
    series: &'static str,
    path: CityPath,
    plan: &Plan,
    n: usize,
    times: &[Duration],
    triangles: u64,
) -> Row {
    Row {
        series,
        path: path_name(path),
        policy: "geometry".into(),
        tolerance_deg: None,
        frame: None,
        impostor: None,
        width: plan.size.0,
        height: plan.size.1,
        impostors: n,
        frames: times.len(),
        refreshes: 0,
        new_captures: 0,
        capture_px: None,
        interval_frames: None,
        time: Some(Summary::of(times)),
        update_ms: None,
        errors: None,
        predicted: None,
        memory_bytes: None,
        setup_ms: None,
        triangles,
    }
}

/// Runs the whole sweep; `progress` is called before each run with its 0-based index,
/// the total, and what it is.
pub fn run(plan: &Plan, mut progress: impl FnMut(usize, usize, &str)) -> Vec<Row> {
    let total = plan.steps();
    let mut step = 0;
    let mut tick = |what: String| {
        progress(step, total, &what);
        step += 1;
    };
    let mut city = City::new(plan.grid, plan.detail, plan.seed);
    let n = city.buildings.len();
    let mut rows = Vec::new();

    // Tolerance sweep (and the geometry reference) on translate and rotate.
    for path in [CityPath::Translate, CityPath::Rotate] {
        tick(format!("geometry {}", path_name(path)));
        let (times, tris) = run_geometry(&city, path, plan.span(path), plan.frames, plan.size);
        rows.push(geometry_row("geometry", path, plan, n, &times, tris));
        for &tol in &plan.tolerances {
            tick(format!("sweep {} {tol} deg", path_name(path)));
            let out = run_impostors(
                &mut city,
                path,
                plan.span(path),
                plan.frames,
                plan.size,
                Policy::Error(tol),
            );
            rows.push(impostor_row(
                "sweep",
                path,
                "error".into(),
                Some(tol),
                plan,
                n,
                &out,
            ));
        }
    }

    // Fixed interval at the error-driven runs' refresh counts.
    let translate: Vec<(f32, u64, usize)> = rows
        .iter()
        .filter(|r| r.series == "sweep" && r.path == "translate")
        .map(|r| (r.tolerance_deg.unwrap_or(0.0) as f32, r.refreshes, r.frames))
        .collect();
    for (tol, refreshes, frames) in translate {
        tick(format!("fixed interval matching {tol} deg"));
        let rate = refreshes as f64 / frames.max(1) as f64;
        let out = run_impostors(
            &mut city,
            CityPath::Translate,
            plan.translate_span,
            plan.frames,
            plan.size,
            Policy::Fixed { rate },
        );
        let mut row = impostor_row(
            "fixed",
            CityPath::Translate,
            "fixed".into(),
            Some(tol),
            plan,
            n,
            &out,
        );
        row.interval_frames = (rate > 0.0).then(|| n as f64 / rate);
        rows.push(row);
    }

    // Calibration: images age along translate.
    tick("calibration".into());
    let out = run_impostors(
        &mut city,
        CityPath::Translate,
        plan.translate_span,
        plan.frames,
        plan.size,
        Policy::Frozen,
    );
    for (k, frame) in out.measured.iter().enumerate() {
        for &(i, deg, px, e) in frame {
            rows.push(Row {
                series: "calibration",
                path: "translate",
                policy: "frozen".into(),
                tolerance_deg: None,
                frame: Some(k + 1),
                impostor: Some(i),
                width: plan.size.0,
                height: plan.size.1,
                impostors: n,
                frames: 1,
                refreshes: 0,
                new_captures: 0,
                capture_px: None,
                interval_frames: None,
                time: None,
                update_ms: None,
                errors: Some(Errors::of_frames(&[vec![e]])),
                predicted: Some(PredictedStats {
                    deg_mean: deg as f64,
                    deg_max: deg as f64,
                    px_mean: px as f64,
                }),
                memory_bytes: None,
                setup_ms: None,
                triangles: 0,
            });
        }
    }

    // Methods on the orbit.
    methods(plan, &mut city, &mut tick, &mut rows);
    rows
}

/// The `method` rows: geometry, runtime impostors at each of
/// [`Plan::method_tolerances`], and each octahedral configuration of [`Plan::octahedral`].
fn methods(plan: &Plan, city: &mut City, tick: &mut dyn FnMut(String), rows: &mut Vec<Row>) {
    let path = CityPath::Orbit;
    let n = city.buildings.len();
    tick("method geometry".into());
    let (times, tris) = run_geometry(city, path, plan.orbit_span, plan.frames, plan.size);
    let mut row = geometry_row("method", path, plan, n, &times, tris);
    // The reference against itself, measured like every other method.
    let mut renderer = Renderer::new();
    let mut frames = Vec::new();
    for f in 1..plan.frames {
        let camera = frame_camera(city, path, plan.orbit_span, f, plan.frames, plan.size);
        let mut frame = Vec::new();
        for b in &city.buildings {
            let (mut truth, mut image) = (Vec::new(), Vec::new());
            b.draws(&mut truth);
            b.draws(&mut image);
            if let Some(e) = measure_draws(
                &mut renderer,
                truth,
                image,
                &camera,
                plan.size,
                &city.lighting,
                b.bounds(),
            ) {
                frame.push(e);
            }
        }
        frames.push(frame);
    }
    row.errors = Some(Errors::of_frames(&frames));
    rows.push(row);
    for &tol in &plan.method_tolerances {
        tick(format!("method runtime {tol} deg"));
        let out = run_impostors(
            city,
            path,
            plan.orbit_span,
            plan.frames,
            plan.size,
            Policy::Error(tol),
        );
        rows.push(impostor_row(
            "method",
            path,
            "runtime".into(),
            Some(tol),
            plan,
            n,
            &out,
        ));
    }
    octahedral_methods(plan, city, tick, rows);
}

/// The octahedral `method` rows: every building baked ([`Layout::Hemi`]) for each
/// configuration of [`Plan::octahedral`], then flown like the runtime impostors. An
/// impostor whose bounding sphere is off the image ([`impostor::screen_rect`]) is neither
/// updated nor drawn. `refreshes` counts recomposed images.
fn octahedral_methods(
    plan: &Plan,
    city: &mut City,
    tick: &mut dyn FnMut(String),
    rows: &mut Vec<Row>,
) {
    let path = CityPath::Orbit;
    let span = plan.span(path);
    let n = city.buildings.len();
    let (w, h) = plan.size;
    let lighting = city.lighting.clone();
    let opts = frame_options();
    for &(grid, px) in &plan.octahedral {
        tick(format!("method octahedral {grid}x{grid} views of {px} px"));
        let t0 = Instant::now();
        let mut imps: Vec<OctahedralImpostor> = city
            .buildings
            .iter_mut()
            .map(|b| OctahedralImpostor::bake(b, &lighting, grid, px, Layout::Hemi))
            .collect();
        let bake = t0.elapsed();
        let memory: usize = imps.iter().map(|i| i.bytes()).sum();
        let (mut renderer, mut measurer) = (Renderer::new(), Renderer::new());
        let mut target = Target::new(w, h);
        let (mut times, mut update, mut frames) = (Vec::new(), Vec::new(), Vec::new());
        let (mut recomposed, mut triangles) = (0u64, 0u64);
        for f in 0..plan.frames {
            let camera = frame_camera(city, path, span, f, plan.frames, plan.size);
            let t0 = Instant::now();
            let mut seen = vec![false; n];
            let mut fresh = 0u64;
            for ((imp, b), seen) in imps.iter_mut().zip(&city.buildings).zip(&mut seen) {
                let s = b.bounds();
                *seen = impostor::screen_rect(&camera, s.center, s.radius, w, h).is_some();
                if *seen && imp.update(&camera) {
                    fresh += 1;
                }
            }
            let t1 = Instant::now();
            let mut draws = Vec::new();
            city.ground.draws(&mut draws);
            draws.extend(
                imps.iter()
                    .zip(&seen)
                    .filter(|(_, s)| **s)
                    .map(|(i, _)| i.draw()),
            );
            let stats = renderer.render(draws, &camera, &lighting, &mut target, &opts);
            let t2 = Instant::now();
            if f == 0 {
                continue;
            }
            times.push(t2 - t0);
            update.push(t1 - t0);
            recomposed += fresh;
            triangles = stats.triangles_set_up;
            let mut frame = Vec::new();
            for ((imp, b), _) in imps.iter().zip(&city.buildings).zip(&seen).filter(|x| *x.1) {
                let mut truth = Vec::new();
                b.draws(&mut truth);
                if let Some(e) = measure_draws(
                    &mut measurer,
                    truth,
                    [imp.draw()],
                    &camera,
                    plan.size,
                    &lighting,
                    b.bounds(),
                ) {
                    frame.push(e);
                }
            }
            frames.push(frame);
        }
        rows.push(Row {
            series: "method",
            path: path_name(path),
            policy: format!("octahedral_{grid}x{px}"),
            tolerance_deg: None,
            frame: None,
            impostor: None,
            width: w,
            height: h,
            impostors: n,
            frames: times.len(),
            refreshes: recomposed,
            new_captures: 0,
            capture_px: None,
            interval_frames: None,
            time: Some(Summary::of(&times)),
            update_ms: Some(mean_ms(&update)),
            errors: Some(Errors::of_frames(&frames)),
            predicted: None,
            memory_bytes: Some(memory as u64),
            setup_ms: Some(bake.as_secs_f64() * 1e3),
            triangles,
        });
    }
}

/// Highest PSNR drawn in charts (identical images have an infinite PSNR).
pub const PSNR_CAP_DB: f64 = 99.0;

/// The sweep's line charts: file name and chart, ready for [`crate::chart::lines_chart`].
pub fn charts(rows: &[Row]) -> Vec<(&'static str, Lines)> {
    let sweep = |path: &'static str| {
        rows.iter()
            .filter(move |r| r.series == "sweep" && r.path == path)
    };
    let line = |name: &str, pts: Vec<(f64, f64)>| Line {
        name: name.to_string(),
        points: pts,
        labels: Vec::new(),
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
    let mut out = Vec::new();
    out.push((
        "impostors_error.png",
        Lines {
            title: format!("Impostor error vs parallax tolerance{size}"),
            x_desc: "tolerance (degrees)".into(),
            y_desc: "measured mean abs. error (8-bit levels)".into(),
            lines: vec![
                line("translate: mean over frames", by_tol("translate", &mae)),
                line("translate: worst frame", by_tol("translate", &mae_max)),
                line("rotate: mean over frames", by_tol("rotate", &mae)),
                line("rotate: worst frame", by_tol("rotate", &mae_max)),
            ],
            log_x: true,
            log_y: false,
            legend: SeriesLabelPosition::UpperLeft,
        },
    ));
    let rpf = |r: &Row| Some(r.refreshes_per_frame());
    let rerefresh = |r: &Row| Some((r.refreshes - r.new_captures) as f64 / r.frames.max(1) as f64);
    out.push((
        "impostors_refreshes.png",
        Lines {
            title: "Refreshes per frame vs parallax tolerance (after warm-up)".into(),
            x_desc: "tolerance (degrees)".into(),
            y_desc: "refreshes per frame".into(),
            lines: vec![
                line("translate", by_tol("translate", &rpf)),
                line("rotate (all)", by_tol("rotate", &rpf)),
                line(
                    "rotate (re-renders of stale images)",
                    by_tol("rotate", &rerefresh),
                ),
            ],
            log_x: true,
            log_y: false,
            legend: SeriesLabelPosition::UpperRight,
        },
    ));
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
    out.push((
        "impostors_frame_time.png",
        Lines {
            title: format!("Frame time vs parallax tolerance{size}"),
            x_desc: "tolerance (degrees)".into(),
            y_desc: "median frame time (ms)".into(),
            lines: vec![
                line("translate: impostors", by_tol("translate", &med)),
                line("rotate: impostors", by_tol("rotate", &med)),
                line("translate: geometry", flat("translate")),
                line("rotate: geometry", flat("rotate")),
            ],
            log_x: true,
            log_y: false,
            legend: SeriesLabelPosition::UpperRight,
        },
    ));
    let policy = |series: &'static str, pick: &dyn Fn(&Row) -> Option<f64>| -> Vec<(f64, f64)> {
        let mut v: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.series == series && r.path == "translate")
            .filter_map(|r| Some((r.refreshes_per_frame(), pick(r)?)))
            .collect();
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
        v
    };
    out.push((
        "impostors_fixed.png",
        Lines {
            title: "Error-driven vs fixed-interval refresh at equal refresh counts (translate)"
                .into(),
            x_desc: "refreshes per frame".into(),
            y_desc: "measured mean abs. error (8-bit levels)".into(),
            lines: vec![
                line("error-driven: mean over frames", policy("sweep", &mae)),
                line("fixed interval: mean over frames", policy("fixed", &mae)),
                line("error-driven: worst frame", policy("sweep", &mae_max)),
                line("fixed interval: worst frame", policy("fixed", &mae_max)),
            ],
            log_x: true,
            log_y: false,
            legend: SeriesLabelPosition::UpperRight,
        },
    ));
    let methods: Vec<&Row> = rows.iter().filter(|r| r.series == "method").collect();
    out.push((
        "impostors_methods.png",
        Lines {
            title: "Orbit: measured error vs frame time by method".into(),
            x_desc: "median frame time (ms)".into(),
            y_desc: "measured mean abs. error (8-bit levels)".into(),
            lines: methods
                .iter()
                .map(|r| Line {
                    name: String::new(),
                    points: r
                        .time
                        .zip(r.errors)
                        .map(|(t, e)| vec![(t.median_ms, e.mae_mean)])
                        .unwrap_or_default(),
                    labels: vec![method_label(r)],
                })
                .collect(),
            log_x: false,
            log_y: false,
            legend: SeriesLabelPosition::UpperRight,
        },
    ));
    out
}

/// A method row's short name: `geometry`, `runtime 0.125 deg`, `octahedral 8x64`.
pub fn method_label(r: &Row) -> String {
    match (r.policy.as_str(), r.tolerance_deg) {
        ("runtime", Some(t)) => format!("runtime {t} deg"),
        (p, _) if p.starts_with("octahedral_") => {
            let (grid, px) = p["octahedral_".len()..]
                .split_once('x')
                .unwrap_or(("?", "?"));
            format!("octahedral {grid}x{grid}x{px}px")
        }
        (p, _) => p.replace('_', " "),
    }
}

/// The calibration scatter: predicted parallax against each image's measured error, and
/// the means of 8 equal-width bins of predicted parallax.
pub fn calibration_chart(rows: &[Row]) -> Lines {
    let pts = calibration_points(rows);
    let bins = calibration_bins(&pts, 8);
    Lines {
        title: "Predicted parallax vs measured error (translate, no refresh after warm-up)".into(),
        x_desc: "predicted parallax (degrees)".into(),
        y_desc: "measured mean abs. error (8-bit levels)".into(),
        lines: vec![
            Line {
                name: "one image in one frame".into(),
                points: pts,
                labels: Vec::new(),
            },
            Line {
                name: "mean of a bin of predicted parallax".into(),
                points: bins.iter().map(|b| (b.0, b.1)).collect(),
                labels: Vec::new(),
            },
        ],
        log_x: false,
        log_y: false,
        legend: SeriesLabelPosition::UpperLeft,
    }
}

/// The calibration rows' (predicted degrees, measured mean absolute error) pairs.
pub fn calibration_points(rows: &[Row]) -> Vec<(f64, f64)> {
    rows.iter()
        .filter(|r| r.series == "calibration")
        .filter_map(|r| Some((r.predicted?.deg_mean, r.errors?.mae_mean)))
        .collect()
}

/// The calibration pairs in `bins` equal-width bins of predicted degrees (empty bins left
/// out): mean predicted degrees, mean measured error, and the pairs in the bin.
pub fn calibration_bins(points: &[(f64, f64)], bins: usize) -> Vec<(f64, f64, usize)> {
    let hi = points.iter().map(|p| p.0).fold(0.0, f64::max);
    let bins = bins.max(1);
    let mut acc = vec![(0.0, 0.0, 0usize); bins];
    for &(x, y) in points {
        let k = if hi > 0.0 {
            ((x / hi * bins as f64) as usize).min(bins - 1)
        } else {
            0
        };
        acc[k].0 += x;
        acc[k].1 += y;
        acc[k].2 += 1;
    }
    acc.into_iter()
        .filter(|a| a.2 > 0)
        .map(|(x, y, n)| (x / n as f64, y / n as f64, n))
        .collect()
}

/// Pearson's correlation of the pairs (`None` for fewer than 2 or a constant coordinate).
pub fn correlation(points: &[(f64, f64)]) -> Option<f64> {
    let n = points.len() as f64;
    if points.len() < 2 {
        return None;
    }
    let (mx, my) = (
        points.iter().map(|p| p.0).sum::<f64>() / n,
        points.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for &(x, y) in points {
        sxy += (x - mx) * (y - my);
        sxx += (x - mx) * (x - mx);
        syy += (y - my) * (y - my);
    }
    (sxx > 0.0 && syy > 0.0).then(|| sxy / (sxx * syy).sqrt())
}

/// Least-squares slope of y on x (`None` for fewer than 2 points or a constant x).
pub fn slope(points: &[(f64, f64)]) -> Option<f64> {
    let n = points.len() as f64;
    if points.len() < 2 {
        return None;
    }
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// Per impostor of the calibration run: (impostor, Pearson r, slope in levels per
/// degree, pairs), for impostors with at least 3 pairs.
pub fn calibration_per_impostor(rows: &[Row]) -> Vec<(usize, f64, f64, usize)> {
    let mut by: std::collections::BTreeMap<usize, Vec<(f64, f64)>> = Default::default();
    for r in rows.iter().filter(|r| r.series == "calibration") {
        if let (Some(i), Some(p), Some(e)) = (r.impostor, r.predicted, r.errors) {
            by.entry(i).or_default().push((p.deg_mean, e.mae_mean));
        }
    }
    by.into_iter()
        .filter(|(_, v)| v.len() >= 3)
        .filter_map(|(i, v)| Some((i, correlation(&v)?, slope(&v)?, v.len())))
        .collect()
}

/// A paragraph on the calibration run: correlation over all pairs and per impostor, and
/// binned means.
pub fn calibration_summary(rows: &[Row]) -> Option<String> {
    let pts = calibration_points(rows);
    if pts.is_empty() {
        return None;
    }
    let mut s = format!(
        "calibration: {} images; Pearson r (predicted degrees, measured MAE) = {}",
        pts.len(),
        correlation(&pts).map_or("n/a".into(), |r| format!("{r:.3}"))
    );
    let per = calibration_per_impostor(rows);
    if !per.is_empty() {
        let mut r: Vec<f64> = per.iter().map(|p| p.1).collect();
        let mut k: Vec<f64> = per.iter().map(|p| p.2).collect();
        r.sort_by(f64::total_cmp);
        k.sort_by(f64::total_cmp);
        s += &format!(
            "\n  per impostor ({}): r min {:.3}, median {:.3}; slope {:.3} to {:.3} levels per degree (median {:.3})",
            per.len(),
            r[0],
            r[r.len() / 2],
            k[0],
            k[k.len() - 1],
            k[k.len() / 2]
        );
    }
    for (x, y, n) in calibration_bins(&pts, 8) {
        s += &format!("\n  predicted {x:>7.3} deg: measured MAE {y:>7.3} ({n} images)");
    }
    Some(s)
}

/// Prints one row of the sweep (the CLI's summary).
pub fn print_row(r: &Row) {
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
    println!("{what} {time}{update}{refresh}{error}{predicted}{extra}");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_rows_match_the_header() {
        let n = Row::HEADER.split(',').count();
        let row = geometry_row("geometry", CityPath::Rotate, &Plan::tiny(), 9, &[], 0);
        assert_eq!(row.csv().split(',').count(), n);
        let full = Row {
            errors: Some(Errors::of_frames(&[vec![]])),
            predicted: Some(PredictedStats::default()),
            interval_frames: Some(2.5),
            tolerance_deg: Some(0.5),
            ..row
        };
        assert_eq!(full.csv().split(',').count(), n);
    }

    #[test]
    fn measure_draws_agrees_with_impostor_set_measure() {
        let mut city = City::new(2, 2, 3);
        let size = (128, 72);
        let lighting = city.lighting.clone();
        let cam0 = frame_camera(&city, CityPath::Translate, 1.0, 0, 5, size);
        let cam = frame_camera(&city, CityPath::Translate, 1.0, 2, 5, size);
        let mut renderer = Renderer::new();
        let mut checked = 0;
        for i in 0..city.buildings.len() {
            // A set of one, so its draws are this image's quad alone.
            let one = &mut city.buildings[i..i + 1];
            let mut set = ImpostorSet::new(config(0.125, 1.0), 1);
            set.update(one, &cam0, size.1, &lighting);
            set.config.budget.refreshes = 0;
            set.update(one, &cam, size.1, &lighting);
            let Some(a) = set.measure(0, &mut one[0], &cam, size, &lighting) else {
                continue;
            };
            let mut image = Vec::new();
            set.draws(one, &mut image);
            let mut truth = Vec::new();
            one[0].draws(&mut truth);
            let b = measure_draws(
                &mut renderer,
                truth,
                image,
                &cam,
                size,
                &lighting,
                one[0].bounds(),
            )
            .expect("on screen");
            assert_eq!(a, b);
            assert!(a.mean_abs > 0.0, "the eye moved: {a:?}");
            checked += 1;
        }
        assert!(checked >= 2);
    }

    #[test]
    fn errors_pool_frames_and_keep_the_worst() {
        let e = |mae: f64, px: u64| ImageError {
            psnr_db: 20.0,
            mse: mae * mae,
            mean_abs: mae,
            max_abs: (mae * 3.0) as u8,
            frac_over: 0.0,
            coverage_mismatch: 0.0,
            pixels: px,
        };
        let r = Errors::of_frames(&[vec![e(1.0, 100), e(3.0, 100)], vec![], vec![e(4.0, 50)]]);
        assert_eq!((r.frames, r.images), (2, 3));
        assert!((r.mae_mean - 3.0).abs() < 1e-12, "(2 + 4) / 2: {r:?}");
        assert_eq!((r.mae_max, r.worst_mae), (4.0, 4.0));
        let p = r.pooled.unwrap();
        assert_eq!(p.pixels, 250);
        assert!((p.mean_abs - 2.4).abs() < 1e-12);
    }
}
