//! The `bench layers` sweep: image layers ([`ibr::layers`], Lengyel and Snyder) against
//! runtime impostors ([`ibr::impostor`]) on the same scene, the procedural [`City`] (one
//! layer or one impostor per building, the ground drawn as geometry), over the same
//! frames of the translation and rotation paths the impostor benchmark flies.
//!
//! Layers warp affinely (`layers`, the paper's) or perspectively where that fits their
//! points better (`layers-persp`). All are driven by one threshold in pixels: a layer's
//! geometric error (how far its box
//! corners' projections lie from where its affine warp puts them) and an impostor's
//! parallax at the image centre ([`ibr::impostor::Tolerance::pixels`]). The refresh budget
//! is unlimited and stale images are never swapped for geometry, so each run's error is its
//! threshold's alone. Per row, over the frames after the first (in which every image is
//! taken):
//! - `refreshes_per_frame`: images re-rendered, and `capture_kpx_per_frame`, thousands of
//!   pixels those renders covered (the refresh work, whatever the machine's load);
//! - `median_ms`, `mean_ms`: the frame (the technique's `prepare`, refreshes included,
//!   and the render), through the [`FrameLoop`];
//! - `mean_abs`, `psnr_db`, `frac_over`: the frame against a render of all the geometry
//!   from the same eye, over the whole frame ([`ibr::metrics::compare`], pooled over the
//!   frames);
//! - `predicted_px_max`: the largest predicted error of a drawn image after the frame's
//!   refreshes.
//!
//! `geometry` rows are the buildings drawn as geometry (error 0 by definition).

use crate::bench::impostors::frame_camera;
use crate::bench::sweep::{self, CsvRow};
use crate::bench::{Progress, RunFlags, Sweep};
use crate::city::{City, Path as CityPath};
use crate::timing::Summary;
use engine::{Draw, FrameOptions, Renderer, Rgba, Target};
use ibr::impostor::{self, Impostored, Tolerance};
use ibr::layers::{self, Layered};
use ibr::metrics::{self, ImageError, Options};
use ibr::schedule::Budget;
use ibr::subject::{MeshGroup, Subject};
use ibr::technique::{FrameLoop, FrameView, Technique};
use std::time::Duration;

/// What a sweep measures.
#[derive(Clone, Debug)]
pub struct Settings {
    pub grid: u32,
    pub detail: u32,
    pub size: (u32, u32),
    /// Thresholds, pixels.
    pub tolerances: Vec<f32>,
    /// Frames per run, the first (every image taken) left out of the figures.
    pub frames: usize,
    /// The paths, each with the share of it a run covers ([`City::path`]'s `t`).
    pub paths: Vec<(CityPath, f32)>,
}

impl Settings {
    /// The impostor benchmark's city and paths: 4 x 4 buildings, the eye sliding 3 units
    /// or turning 51.6 degrees over 41 frames at 640 x 360.
    pub fn full() -> Settings {
        Settings {
            grid: 4,
            detail: 10,
            size: (640, 360),
            tolerances: vec![0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0],
            frames: 41,
            paths: vec![(CityPath::Translate, 0.25), (CityPath::Rotate, 1.0)],
        }
    }

    /// Every point of the full sweep over fewer frames.
    pub fn quick() -> Settings {
        Settings {
            frames: 21,
            ..Settings::full()
        }
    }

    /// A seconds-long smoke run (tests).
    pub fn tiny() -> Settings {
        Settings {
            grid: 2,
            detail: 2,
            size: (160, 96),
            tolerances: vec![0.5, 8.0],
            frames: 9,
            ..Settings::full()
        }
    }
}

/// One run.
#[derive(Clone, Debug)]
pub struct Row {
    pub path: &'static str,
    /// `layers` (affine), `layers-persp` (perspective), `impostors` or `geometry`.
    pub method: &'static str,
    /// Pixels (0 for geometry).
    pub tolerance_px: f32,
    pub width: u32,
    pub height: u32,
    pub refreshes_per_frame: f64,
    pub capture_kpx_per_frame: f64,
    pub time: Summary,
    pub error: ImageError,
    pub predicted_px_max: f32,
}

impl CsvRow for Row {
    const HEADER: &'static str = "path,method,tolerance_px,width,height,frames,refreshes_per_frame,capture_kpx_per_frame,median_ms,mean_ms,mean_abs,psnr_db,frac_over,predicted_px_max";

    fn csv(&self) -> String {
        format!(
            "{},{},{},{},{},{},{:.3},{:.2},{:.3},{:.3},{:.4},{:.3},{:.5},{:.3}",
            self.path,
            self.method,
            self.tolerance_px,
            self.width,
            self.height,
            self.time.frames,
            self.refreshes_per_frame,
            self.capture_kpx_per_frame,
            self.time.median_ms,
            self.time.mean_ms,
            self.error.mean_abs,
            self.error.psnr_capped(99.0),
            self.error.frac_over,
            self.predicted_px_max,
        )
    }
}

/// Runs the sweep.
pub fn run(settings: &Settings, progress: &mut dyn FnMut(usize, usize, &str)) -> Vec<Row> {
    let city = City::new(settings.grid, settings.detail, 7);
    let runs = settings.paths.len() * (1 + 3 * settings.tolerances.len());
    let mut tick = sweep::ticker(runs, progress);
    let mut rows = Vec::new();
    for &(path, span) in &settings.paths {
        let name = crate::bench::impostors::path_name(path);
        let fly = |method: Method, tolerance_px: f32| {
            let flight = Flight::new(&city, settings, path, span);
            let out = match method {
                Method::Geometry => flight.fly(&mut NoImages(city.buildings.clone())),
                Method::Layers => flight.fly(&mut layered(&city, tolerance_px, false)),
                Method::Perspective => flight.fly(&mut layered(&city, tolerance_px, true)),
                Method::Impostors => flight.fly(&mut impostored(&city, tolerance_px)),
            };
            out.row(name, method, tolerance_px, settings)
        };
        tick(format!("{name} geometry"));
        rows.extend(fly(Method::Geometry, 0.0));
        for &t in &settings.tolerances {
            for method in [Method::Layers, Method::Perspective, Method::Impostors] {
                tick(format!("{name} {} {t} px", method.name()));
                rows.extend(fly(method, t));
            }
        }
    }
    rows
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Method {
    Geometry,
    Layers,
    Perspective,
    Impostors,
}

impl Method {
    fn name(self) -> &'static str {
        match self {
            Method::Geometry => "geometry",
            Method::Layers => "layers",
            Method::Perspective => "layers-persp",
            Method::Impostors => "impostors",
        }
    }
}

/// The city's buildings as layers at `tolerance_px` (affine, or perspective where that
/// fits better), unlimited budget, never falling back.
fn layered(city: &City, tolerance_px: f32, perspective: bool) -> Layered<MeshGroup> {
    let cfg = layers::Config {
        tolerance_px,
        perspective,
        budget: Budget::count(usize::MAX),
        fallback_ratio: f32::INFINITY,
        ..layers::Config::default()
    };
    Layered::new("layers", cfg, city.buildings.clone())
}

/// The city's buildings as runtime impostors at `tolerance_px` of parallax, the same
/// budget and fallback as the layers.
fn impostored(city: &City, tolerance_px: f32) -> Impostored<MeshGroup> {
    let cfg = impostor::Config {
        tolerance: Tolerance {
            pixels: Some(tolerance_px),
            ..Tolerance::default()
        },
        budget: Budget::count(usize::MAX),
        fallback_ratio: f32::INFINITY,
        prewarm: 0.0,
        ..impostor::Config::default()
    };
    let mut imp = Impostored::new("impostors", cfg, city.buildings.clone());
    imp.near = true;
    imp
}

/// The buildings as plain geometry, as a technique.
struct NoImages(Vec<MeshGroup>);

impl Technique for NoImages {
    fn name(&self) -> &str {
        "geometry"
    }
    fn prepare(&mut self, _: &FrameView<'_>) {}
    fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        self.0.iter().for_each(|s| s.draws(out));
    }
}

/// One run's frames, and what it measured.
struct Flight<'c> {
    city: &'c City,
    path: CityPath,
    span: f32,
    frames: usize,
    size: (u32, u32),
    times: Vec<Duration>,
    errors: Vec<ImageError>,
    refreshes: u64,
    capture_px: u64,
    predicted_px_max: f32,
}

impl<'c> Flight<'c> {
    fn new(city: &'c City, settings: &Settings, path: CityPath, span: f32) -> Self {
        Flight {
            city,
            path,
            span,
            frames: settings.frames.max(2),
            size: settings.size,
            times: Vec::new(),
            errors: Vec::new(),
            refreshes: 0,
            capture_px: 0,
            predicted_px_max: 0.0,
        }
    }

    /// Flies the path with `t` drawing the buildings, the ground as scene geometry.
    fn fly<T: Technique + Probe>(mut self, t: &mut T) -> Self {
        let (w, h) = self.size;
        let opts = FrameOptions {
            clear: Some(Rgba::new(0.55, 0.65, 0.8, 1.0)),
            ..FrameOptions::default()
        };
        let mut ground = Vec::new();
        self.city.ground.draws(&mut ground);
        let (mut renderer, mut frame_loop) = (Renderer::new(), FrameLoop::new());
        let (mut target, mut truth) = (Target::new(w, h), Target::new(w, h));
        let lighting = &self.city.lighting;
        let (mut before, mut after) = (Vec::new(), Vec::new());
        for f in 0..self.frames {
            let camera = frame_camera(self.city, self.path, self.span, f, self.frames, self.size);
            let view = FrameView::still(&camera, w, h, lighting);
            let scene = ground.iter().copied();
            let techniques: &mut [&mut dyn Technique] = &mut [t];
            frame_loop.render(&mut renderer, scene, techniques, &view, &mut target, &opts);
            before.clear();
            before.append(&mut after);
            t.images(&mut after);
            if f == 0 {
                continue;
            }
            self.times.push(frame_loop.times.total);
            self.refreshes += t.counters().refreshes;
            let refreshed = after.iter().zip(&before).filter(|(a, b)| a.0 > b.0);
            self.capture_px += refreshed.map(|(a, _)| a.1).sum::<u64>();
            self.predicted_px_max = self.predicted_px_max.max(t.predicted_px_max());
            let mut all = ground.clone();
            self.city.buildings.iter().for_each(|b| b.draws(&mut all));
            renderer.render(all, &camera, lighting, &mut truth, &opts);
            if let Ok(e) = metrics::compare(&truth, &target, &Options::default()) {
                self.errors.push(e);
            }
        }
        self
    }

    /// The run's row (`None` when no frame was measured).
    fn row(
        self,
        path: &'static str,
        method: Method,
        tolerance_px: f32,
        settings: &Settings,
    ) -> Option<Row> {
        let frames = self.times.len().max(1) as f64;
        Some(Row {
            path,
            method: method.name(),
            tolerance_px,
            width: settings.size.0,
            height: settings.size.1,
            refreshes_per_frame: self.refreshes as f64 / frames,
            capture_kpx_per_frame: self.capture_px as f64 / frames / 1e3,
            time: Summary::of(&self.times),
            error: ImageError::pooled(&self.errors)?,
            predicted_px_max: self.predicted_px_max,
        })
    }
}

/// What a run reads from its technique after each frame: per image, the times it was
/// rendered and the pixels it covers (so a run can count what the frame's refreshes
/// rendered), and the largest predicted error (pixels) of an image it drew.
trait Probe {
    fn images(&self, out: &mut Vec<(u64, u64)>);
    fn predicted_px_max(&self) -> f32;
}

impl Probe for NoImages {
    fn images(&self, _: &mut Vec<(u64, u64)>) {}
    fn predicted_px_max(&self) -> f32 {
        0.0
    }
}

impl Probe for Layered<MeshGroup> {
    fn images(&self, out: &mut Vec<(u64, u64)>) {
        out.extend(self.set.layers.iter().map(|l| {
            let (w, h) = l.image_size().unwrap_or((0, 0));
            (l.refreshes, u64::from(w) * u64::from(h))
        }));
    }
    fn predicted_px_max(&self) -> f32 {
        self.report.max_px
    }
}

impl Probe for Impostored<MeshGroup> {
    fn images(&self, out: &mut Vec<(u64, u64)>) {
        out.extend(self.set.impostors.iter().map(|i| {
            let side = i.capture().map_or(0, |c| u64::from(c.side));
            (i.refreshes, side * side)
        }));
    }
    fn predicted_px_max(&self) -> f32 {
        let images = self
            .set
            .impostors
            .iter()
            .filter(|i| i.mode == impostor::Mode::Image);
        images.map(|i| i.predicted.pixels).fold(0.0, f32::max)
    }
}

/// `(file, chart)` for every chart of the sweep.
pub fn charts(rows: &[Row]) -> Vec<(&'static str, crate::chart::Chart)> {
    use crate::chart::{Chart, Line, Lines};
    let mut out = Vec::new();
    for path in ["translate", "rotate"] {
        // Points labelled with their threshold (none for the geometry, which has none).
        let series = |method: &str, f: &dyn Fn(&Row) -> (f64, f64), labelled: bool| {
            let of: Vec<&Row> = rows
                .iter()
                .filter(|r| r.path == path && r.method == method)
                .collect();
            let labels = (of.iter())
                .map(|r| match labelled && method != "geometry" {
                    true => format!("{}px", r.tolerance_px),
                    false => String::new(),
                })
                .collect();
            Line::new(
                format!("{method} ({path})"),
                of.into_iter().map(f).collect(),
            )
            .labelled(labels)
        };
        let refreshes = |r: &Row| (f64::from(r.tolerance_px), r.refreshes_per_frame);
        let speed = |r: &Row| (r.time.median_ms, r.error.mean_abs);
        let (file_r, file_t) = match path {
            "translate" => (
                "layers_refreshes_translate.png",
                "layers_time_error_translate.png",
            ),
            _ => (
                "layers_refreshes_rotate.png",
                "layers_time_error_rotate.png",
            ),
        };
        out.push((
            file_r,
            Chart::Lines(Lines::new(
                "Re-renders per frame against the threshold",
                "threshold (pixels)",
                "images re-rendered per frame",
                vec![
                    series("layers", &refreshes, false),
                    series("layers-persp", &refreshes, false),
                    series("impostors", &refreshes, false),
                ],
            )),
        ));
        out.push((
            file_t,
            Chart::Lines(Lines::new(
                "Speed against error, beside the geometry (labels: threshold)",
                "frame time (ms, median)",
                "mean absolute error against the geometry (8-bit levels)",
                vec![
                    series("layers", &speed, true),
                    series("layers-persp", &speed, true),
                    series("impostors", &speed, true),
                    series("geometry", &speed, true),
                ],
            )),
        ));
    }
    out
}

/// The `layers` sweep (the module docs).
#[derive(Clone, Copy, Debug)]
pub struct LayersSweep;

impl Sweep for LayersSweep {
    const NAME: &'static str = "layers";
    const ABOUT: &'static str = "Image layers against runtime impostors on the city: re-renders, error and frame time against the threshold";
    type Flags = RunFlags;
    type Settings = Settings;
    type Row = Row;

    fn settings(&self, flags: &RunFlags) -> Result<Settings, String> {
        Ok(flags.pick(Settings::tiny, Settings::quick, Settings::full))
    }

    fn rows(
        &self,
        settings: &Settings,
        _: &RunFlags,
        progress: Progress,
    ) -> Result<Vec<Row>, String> {
        Ok(run(settings, progress))
    }

    fn line(&self, r: &Row) -> Option<String> {
        Some(format!(
            "{:<9} {:<9} {:>5} px {}x{}  refreshes {:>6.2}/frame ({:>7.1} kpx)  median {:>7.2} ms  mean abs {:>6.3}  PSNR {:>6.2} dB  off {:>5.2}%  predicted max {:>6.2} px",
            r.path,
            r.method,
            r.tolerance_px,
            r.width,
            r.height,
            r.refreshes_per_frame,
            r.capture_kpx_per_frame,
            r.time.median_ms,
            r.error.mean_abs,
            r.error.psnr_capped(99.0),
            100.0 * r.error.frac_over,
            r.predicted_px_max,
        ))
    }

    fn charts(&self, rows: &[Row]) -> Vec<(&'static str, crate::chart::Chart)> {
        charts(rows)
    }
}
