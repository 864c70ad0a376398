//! The `bench panorama` sweep: the showcase's far scene as a cube-map sky, seen from eyes
//! moved away from where it was captured, against the geometry from there: measured error
//! and the predicted parallax, where the method fails; and time against rendering it.
//! Beside the panorama held from the capture point, the same eyes walked in order as the
//! frames of a [`Sky`] that re-captures, two faces a frame ([`Sky::spread`]), ahead of
//! where its predicted parallax passes [`SPREAD_TOLERANCE_PX`]: its frame time (its faces'
//! renders included) and error against the geometry's, one chart of error against time.

use crate::bench::sweep::{self, CsvRow, Timing};
use crate::bench::{Progress, RunFlags, Sweep};
use crate::showcase::{self, Showcase};
use crate::timing::Summary;
use engine::Draw;
use glam::Vec3;
use ibr::capture::capture_batch;
use ibr::metrics::{compare_seen, ImageError};
use ibr::panorama::{CubeMap, Sky};
use std::time::Instant;

/// The spread sky re-captures past this much predicted parallax (the showcase's sky's).
pub const SPREAD_TOLERANCE_PX: f32 = 3.0;
/// Faces of a re-capture the spread sky renders a frame.
pub const SPREAD_FACES: usize = 2;

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
    /// The spread sky's frame at this eye (the eyes walked in order): its time (update,
    /// faces rendered and view; one run, the update changes it), its error against the
    /// geometry and the faces it rendered.
    pub spread_ms: f64,
    pub spread_error: ImageError,
    pub spread_faces: usize,
}

impl CsvRow for Row {
    const HEADER: &'static str =
        "moved,width,height,panorama_ms,geometry_ms,psnr_db,mean_abs,frac_over,predicted_px,\
         spread_ms,spread_psnr_db,spread_faces";

    fn csv(&self) -> String {
        format!(
            "{:.3},{},{},{:.3},{:.3},{:.3},{:.3},{:.5},{:.3},{:.3},{:.3},{}",
            self.moved,
            self.width,
            self.height,
            self.panorama.median_ms,
            self.geometry.median_ms,
            self.error.psnr_capped(99.0),
            self.error.mean_abs,
            self.error.frac_over,
            self.predicted_px,
            self.spread_ms,
            self.spread_error.psnr_capped(99.0),
            self.spread_faces,
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
    let range = (10.0, 400.0);
    let mut sky = Sky::new(
        &draws,
        lighting,
        centre,
        settings.face,
        range,
        SPREAD_TOLERANCE_PX,
    )
    .spread(SPREAD_FACES);
    let mut tick = sweep::ticker(settings.moves.len(), progress);
    let mut rows = Vec::new();
    for (k, &moved) in settings.moves.iter().enumerate() {
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
        // The spread sky's frame: where the eye will be `lead` frames on is the walk's
        // eye as many moves on (the path is known), or its last.
        let ahead = settings.moves[(k + sky.lead()).min(settings.moves.len() - 1)];
        let ahead = centre + Vec3::new(ahead, 0.0, 0.0);
        let t = Instant::now();
        let step = sky.update(&draws, lighting, eye, ahead, focal);
        let spread_view = sky.map.view(&camera, w, h);
        let spread_ms = t.elapsed().as_secs_f64() * 1e3;
        let (view, truth) = (view.expect("a frame"), truth.expect("a frame"));
        let Ok((error, _)) = compare_seen(&view, &truth) else {
            continue;
        };
        let Ok((spread_error, _)) = compare_seen(&spread_view, &truth) else {
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
            spread_ms,
            spread_error,
            spread_faces: step.faces,
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
    let held = rows
        .iter()
        .map(|r| (r.panorama.median_ms, r.error.psnr_capped(50.0)))
        .collect();
    let spread = rows
        .iter()
        .map(|r| (r.spread_ms, r.spread_error.psnr_capped(50.0)))
        .collect();
    // The geometry is the reference: its error is none (the cap).
    let geometry = rows.iter().map(|r| (r.geometry.median_ms, 50.0)).collect();
    vec![
        (
            "panorama_time.png",
            Chart::Scatter(Lines::new(
                "Error against frame time: the panorama held, re-captured spread, the geometry",
                "frame time (ms)",
                "PSNR against the geometry (dB, capped at 50)",
                vec![
                    Line::new("panorama held from the capture point", held),
                    Line::new("sky re-captured, 2 faces a frame (Sky::spread)", spread),
                    Line::new("geometry (the reference)", geometry),
                ],
            )),
        ),
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
            "moved {:>5.2} {}x{}  panorama {:>7.2} ms  geometry {:>7.2} ms  PSNR {:>6.2} dB  off {:>5.1}%  predicted {:>6.1} px  spread sky {:>7.2} ms {:>6.2} dB {} faces",
            r.moved,
            r.width,
            r.height,
            r.panorama.median_ms,
            r.geometry.median_ms,
            r.error.psnr_capped(99.0),
            100.0 * r.error.frac_over,
            r.predicted_px,
            r.spread_ms,
            r.spread_error.psnr_capped(99.0),
            r.spread_faces,
        ))
    }

    fn charts(&self, rows: &[Row]) -> Vec<(&'static str, crate::chart::Chart)> {
        charts(rows)
    }
}
