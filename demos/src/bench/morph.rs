//! The `bench morph` sweep: view morphing along the path from one view to the other,
//! against the geometry rendered from each in-between camera: the morph with its prewarp
//! (correspondences from depth, and from the stereo matcher) beside the plain image morph
//! without it, which is not shape preserving. Two views of the showcase's plaza, turned
//! toward its centre from either side (not parallel), and a wider pair.

use crate::bench::sweep::{self, CsvRow, Timing};
use crate::bench::{Progress, RunFlags, Sweep};
use crate::showcase::{self, Showcase};
use crate::timing::Summary;
use engine::{Draw, Lighting};
use glam::Vec3;
use ibr::capture::capture_batch;
use ibr::metrics::{compare_seen, ImageError};
use ibr::morph::{plain_morph, Correspondence, ViewMorph};
use std::time::Instant;

/// What a sweep measures.
#[derive(Clone, Debug)]
pub struct Settings {
    pub width: u32,
    pub height: u32,
    /// Points along each path, ends included.
    pub steps: usize,
    pub timing: Timing,
}

impl Settings {
    pub fn tiny() -> Settings {
        Settings {
            width: 128,
            height: 96,
            steps: 3,
            timing: Timing::once(),
        }
    }

    pub fn quick() -> Settings {
        Settings {
            width: 320,
            height: 240,
            steps: 5,
            timing: Timing::new(0, 2, 1),
        }
    }

    pub fn full() -> Settings {
        Settings {
            width: 640,
            height: 480,
            steps: 11,
            timing: Timing::new(1, 3, 2),
        }
    }
}

/// One method at one point of one path.
#[derive(Clone, Debug)]
pub struct Row {
    pub path: String,
    pub method: String,
    pub s: f32,
    pub width: u32,
    pub height: u32,
    pub time: Summary,
    /// Against the geometry, over the pixels both cover.
    pub error: ImageError,
    /// The share of the geometry's pixels the view covers.
    pub covered: f64,
}

impl CsvRow for Row {
    const HEADER: &'static str =
        "path,method,s,width,height,frames,median_ms,psnr_db,mean_abs,frac_over,covered";

    fn csv(&self) -> String {
        format!(
            "{},{},{:.3},{},{},{},{:.3},{:.3},{:.3},{:.5},{:.5}",
            self.path,
            self.method,
            self.s,
            self.width,
            self.height,
            self.time.frames,
            self.time.median_ms,
            self.error.psnr_capped(99.0),
            self.error.mean_abs,
            self.error.frac_over,
            self.covered,
        )
    }
}

/// The paths: `(name, first eye, second eye)`, both looking at the plaza's centre.
const PATHS: [(&str, Vec3, Vec3); 2] = [
    (
        "near",
        Vec3::new(-2.0, 3.0, 12.0),
        Vec3::new(2.0, 3.0, 12.0),
    ),
    (
        "wide",
        Vec3::new(-5.0, 3.5, 11.0),
        Vec3::new(5.0, 3.5, 11.0),
    ),
];

/// The methods compared.
const METHODS: [&str; 3] = ["morph-depth", "morph-stereo", "plain"];

/// Runs the sweep.
pub fn run(
    settings: &Settings,
    progress: &mut dyn FnMut(usize, usize, &str),
) -> Result<Vec<Row>, String> {
    let show = Showcase::new();
    let draws: Vec<Draw<'_>> = show.scene.draws().collect();
    let lighting: &Lighting = &show.scene.lighting;
    let (w, h) = (settings.width, settings.height);
    let target = Vec3::new(0.0, 1.0, 0.0);
    let steps = settings.steps.max(2);
    let mut tick = sweep::ticker(PATHS.len() * steps, progress);
    let mut rows = Vec::new();
    for (name, a, b) in PATHS {
        let cameras = [a, b].map(|eye| showcase::camera(eye, target, w, h));
        let views = capture_batch(&draws, &cameras, lighting, w, h);
        let (first, second) = (&views[0], &views[1]);
        let make = |how| ViewMorph::new(first, second, how).map_err(|e| format!("{name}: {e}"));
        let by_depth = make(Correspondence::Depth)?;
        // Stereo on the prewarped pair: disparities up to a fifth of its width.
        let max_disparity = by_depth.prewarped().left.width() / 5;
        let by_stereo = make(Correspondence::Stereo { max_disparity })?;
        for k in 0..steps {
            let s = k as f32 / (steps - 1) as f32;
            tick(format!("{name} s {s:.2}"));
            let camera = by_depth.camera_at(s);
            let truth = capture_batch(&draws, &[camera], lighting, w, h).remove(0);
            for method in METHODS {
                let mut last = None;
                let times = settings.timing.run(|| {
                    let t = Instant::now();
                    last = Some(match method {
                        "morph-depth" => by_depth.frame(s).0,
                        "morph-stereo" => by_stereo.frame(s).0,
                        _ => plain_morph(first, second, s),
                    });
                    t.elapsed()
                });
                let view = last.expect("at least one frame");
                let (error, covered) = compare_seen(&view, &truth).map_err(|e| e.to_string())?;
                rows.push(Row {
                    path: name.into(),
                    method: method.into(),
                    s,
                    width: w,
                    height: h,
                    time: Summary::of(&times),
                    error,
                    covered,
                });
            }
        }
    }
    Ok(rows)
}

/// `(file, chart)` for every chart of the sweep: error along each path.
pub fn charts(rows: &[Row]) -> Vec<(&'static str, crate::chart::Chart)> {
    use crate::chart::{Chart, Line, Lines};
    let mut lines = Vec::new();
    for (path, _, _) in PATHS {
        for method in METHODS {
            let points: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.path == path && r.method == method)
                .map(|r| (f64::from(r.s), r.error.psnr_capped(50.0)))
                .collect();
            if !points.is_empty() {
                lines.push(Line::new(format!("{method}, {path}"), points));
            }
        }
    }
    vec![(
        "morph_path.png",
        Chart::Lines(Lines::new(
            "View morphing along the path between two views, against the geometry",
            "s (0: first view, 1: second)",
            "PSNR over the pixels both cover (dB, capped at 50: the plain morph at s 0 is the first view)",
            lines,
        )),
    )]
}

/// The `morph` sweep (the module docs).
#[derive(Clone, Copy, Debug)]
pub struct MorphSweep;

impl Sweep for MorphSweep {
    const NAME: &'static str = "morph";
    const ABOUT: &'static str = "View morphing along the path between two views, with and without the prewarp, against the geometry";
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
        run(settings, progress)
    }

    fn line(&self, r: &Row) -> Option<String> {
        Some(format!(
            "{:<5} {:<13} s {:.2} {}x{} median {:>8.2} ms  PSNR {:>6.2} dB  off {:>5.1}%  covered {:>5.1}%",
            r.path,
            r.method,
            r.s,
            r.width,
            r.height,
            r.time.median_ms,
            r.error.psnr_capped(99.0),
            100.0 * r.error.frac_over,
            100.0 * r.covered,
        ))
    }

    fn charts(&self, rows: &[Row]) -> Vec<(&'static str, crate::chart::Chart)> {
        charts(rows)
    }
}
