//! The `bench panorama` sweep: the showcase's far scene as a cube-map sky, seen from eyes
//! moved away from where it was captured, against the geometry from there: measured error
//! and the predicted parallax, where the method fails; and time against rendering it.

use crate::bench::sweep::{self, CsvRow, Timing};
use crate::bench::{Progress, RunFlags, Sweep};
use crate::showcase::{self, Showcase};
use crate::timing::Summary;
use engine::Draw;
use glam::Vec3;
use ibr::capture::capture_batch;
use ibr::metrics::{compare_seen, ImageError};
use ibr::panorama::CubeMap;
use std::time::Instant;

/// What a sweep measures.
#[derive(Clone, Debug)]
pub struct Settings {
    pub width: u32,
    pub height: u32,
    /// Cube faces' side.
    pub face: u32,
    /// How far the eye moves from the capture point (scene units).
    pub moves: Vec<f32>,
    pub timing: Timing,
}

impl Settings {
    pub fn tiny() -> Settings {
        Settings {
            width: 96,
            height: 64,
            face: 64,
            moves: vec![0.0, 2.0],
            timing: Timing::once(),
        }
    }

    pub fn quick() -> Settings {
        Settings {
            width: 320,
            height: 180,
            face: 256,
            moves: vec![0.0, 0.5, 1.0, 2.0, 4.0],
            timing: Timing::new(0, 2, 1),
        }
    }

    pub fn full() -> Settings {
        Settings {
            width: 640,
            height: 360,
            face: 512,
            moves: vec![0.0, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0],
            timing: Timing::new(1, 3, 2),
        }
    }
}

/// One eye.
#[derive(Clone, Debug)]
pub struct Row {
    pub moved: f32,
    pub width: u32,
    pub height: u32,
    /// The panorama view and the geometry's frame.
    pub panorama: Summary,
    pub geometry: Summary,
    pub error: ImageError,
    pub predicted_px: f32,
}

impl CsvRow for Row {
    const HEADER: &'static str =
        "moved,width,height,panorama_ms,geometry_ms,psnr_db,mean_abs,frac_over,predicted_px";

    fn csv(&self) -> String {
        format!(
            "{:.3},{},{},{:.3},{:.3},{:.3},{:.3},{:.5},{:.3}",
            self.moved,
            self.width,
            self.height,
            self.panorama.median_ms,
            self.geometry.median_ms,
            self.error.psnr_capped(99.0),
            self.error.mean_abs,
            self.error.frac_over,
            self.predicted_px,
        )
    }
}

/// Runs the sweep: the plaza's scene captured from above its centre, everything beyond 10
/// units kept (the far scene a sky would hold), viewed looking out over the plaza from eyes
/// moved sideways.
pub fn run(settings: &Settings, progress: &mut dyn FnMut(usize, usize, &str)) -> Vec<Row> {
    let show = Showcase::new();
    let draws: Vec<Draw<'_>> = show.scene.draws().collect();
    let lighting = &show.scene.lighting;
    let centre = Vec3::new(0.0, 3.0, 0.0);
    let (w, h) = (settings.width, settings.height);
    let map = CubeMap::capture(&draws, lighting, centre, settings.face, 10.0, 400.0);
    let mut tick = sweep::ticker(settings.moves.len(), progress);
    let mut rows = Vec::new();
    for &moved in &settings.moves {
        tick(format!("moved {moved}"));
        let eye = centre + Vec3::new(moved, 0.0, 0.0);
        let camera = showcase::camera(eye, eye + Vec3::new(0.3, -0.1, -1.0), w, h)
            .with_depth_range(10.0, 400.0);
        let focal = camera.projection.gl_matrix().x_axis.x * 0.5 * w as f32;
        let mut view = None;
        let panorama = settings.timing.run(|| {
            let t = Instant::now();
            view = Some(map.view(&camera, w, h));
            t.elapsed()
        });
        let mut truth = None;
        let geometry = settings.timing.run(|| {
            let t = Instant::now();
            truth = Some(capture_batch(&draws, &[camera], lighting, w, h).remove(0));
            t.elapsed()
        });
        let (view, truth) = (view.expect("a frame"), truth.expect("a frame"));
        let Ok((error, _)) = compare_seen(&view, &truth) else {
            continue;
        };
        rows.push(Row {
            moved,
            width: w,
            height: h,
            panorama: Summary::of(&panorama),
            geometry: Summary::of(&geometry),
            error,
            predicted_px: map.predicted_px(eye, focal),
        });
    }
    rows
}

/// `(file, chart)` for every chart of the sweep.
pub fn charts(rows: &[Row]) -> Vec<(&'static str, crate::chart::Chart)> {
    use crate::chart::{Chart, Line, Lines};
    let psnr = rows
        .iter()
        .map(|r| (f64::from(r.moved), r.error.psnr_capped(50.0)))
        .collect();
    let over = rows
        .iter()
        .map(|r| (f64::from(r.predicted_px), 100.0 * r.error.frac_over))
        .collect();
    vec![
        (
            "panorama_distance.png",
            Chart::Lines(Lines::new(
                "Cube-map sky against the geometry as the eye leaves the capture point",
                "distance from the capture point (units)",
                "PSNR (dB, capped at 50)",
                vec![Line::new("panorama", psnr)],
            )),
        ),
        (
            "panorama_predicted.png",
            Chart::Lines(Lines::new(
                "Predicted parallax against measured error",
                "predicted parallax of the nearest point (pixels)",
                "pixels off by more than 8 levels (%)",
                vec![Line::new("panorama", over)],
            )),
        ),
    ]
}

/// The `panorama` sweep (the module docs).
#[derive(Clone, Copy, Debug)]
pub struct PanoramaSweep;

impl Sweep for PanoramaSweep {
    const NAME: &'static str = "panorama";
    const ABOUT: &'static str = "A cube-map sky seen from eyes moved away from where it was captured, against the geometry: measured and predicted error";
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
            "moved {:>5.2} {}x{}  panorama {:>7.2} ms  geometry {:>7.2} ms  PSNR {:>6.2} dB  off {:>5.1}%  predicted {:>6.1} px",
            r.moved,
            r.width,
            r.height,
            r.panorama.median_ms,
            r.geometry.median_ms,
            r.error.psnr_capped(99.0),
            100.0 * r.error.frac_over,
            r.predicted_px,
        ))
    }

    fn charts(&self, rows: &[Row]) -> Vec<(&'static str, crate::chart::Chart)> {
        charts(rows)
    }
}
