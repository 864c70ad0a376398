//! The sweep's CSV row, the error and prediction figures it carries, and the row
//! builders shared by every series.

use super::scene::{path_name, RunOut};
use super::Settings;
use crate::bench::sweep::CsvRow;
use crate::city::Path as CityPath;
use crate::timing::Summary;
use ibr::impostor::Predicted;
use ibr::metrics::ImageError;
use std::time::Duration;

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
    /// Predicted image error (mean absolute 8-bit levels).
    pub levels_mean: f64,
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
    /// Octahedral method rows: views per side and frame pixels (the parameters as data;
    /// `policy` spells them for the CSV).
    pub octahedral: Option<(u32, u32)>,
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
    /// A row of `series` on `path` by `policy` over `impostors` buildings at the settings'
    /// size, with nothing measured.
    pub(super) fn empty(
        series: &'static str,
        path: CityPath,
        policy: String,
        settings: &Settings,
        impostors: usize,
    ) -> Row {
        Row {
            series,
            path: path_name(path),
            policy,
            tolerance_deg: None,
            octahedral: None,
            frame: None,
            impostor: None,
            width: settings.size.0,
            height: settings.size.1,
            impostors,
            frames: 0,
            refreshes: 0,
            new_captures: 0,
            capture_px: None,
            interval_frames: None,
            time: None,
            update_ms: None,
            errors: None,
            predicted: None,
            memory_bytes: None,
            setup_ms: None,
            triangles: 0,
        }
    }

    /// Refreshes per frame after warm-up.
    pub fn refreshes_per_frame(&self) -> f64 {
        self.refreshes as f64 / self.frames.max(1) as f64
    }
}

impl CsvRow for Row {
    const HEADER: &'static str = "series,path,policy,tolerance_deg,frame,impostor,width,height,impostors,frames,refreshes,refreshes_per_frame,new_captures,capture_kpx_per_frame,interval_frames,median_ms,p90_ms,min_ms,mean_ms,update_ms,images_per_frame,mae_mean,mae_max,worst_mae,psnr_db,psnr_min_db,max_abs,frac_over,coverage_mismatch,predicted_deg_mean,predicted_deg_max,predicted_px_mean,predicted_levels_mean,memory_bytes,setup_ms,triangles";

    fn csv(&self) -> String {
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
            Some(p) => format!(
                "{:.5},{:.5},{:.4},{:.4}",
                p.deg_mean, p.deg_max, p.px_mean, p.levels_mean
            ),
            None => ",,,".into(),
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

/// A tolerance as written in the settings (`0.03`, not `0.029999999329447746`).
pub(super) fn deg(t: f32) -> f64 {
    t.to_string().parse().unwrap_or(t as f64)
}

pub(super) fn mean_ms(d: &[Duration]) -> f64 {
    d.iter().map(|d| d.as_secs_f64() * 1e3).sum::<f64>() / d.len().max(1) as f64
}

pub(super) fn predicted_stats(p: &[Predicted]) -> PredictedStats {
    let n = p.len().max(1) as f64;
    let mean = |f: fn(&Predicted) -> f32| p.iter().map(|x| f(x) as f64).sum::<f64>() / n;
    PredictedStats {
        deg_mean: mean(|x| x.degrees),
        deg_max: p.iter().map(|x| x.degrees as f64).fold(0.0, f64::max),
        px_mean: mean(|x| x.pixels),
        levels_mean: mean(|x| x.levels),
    }
}

/// A row of a run of impostors.
pub(super) fn impostor_row(
    series: &'static str,
    path: CityPath,
    policy: String,
    tolerance: Option<f32>,
    settings: &Settings,
    n: usize,
    run: &RunOut,
) -> Row {
    let frames: Vec<Vec<ImageError>> = run
        .measured
        .iter()
        .map(|f| f.iter().map(|m| m.2).collect())
        .collect();
    Row {
        tolerance_deg: tolerance.map(deg),
        frames: run.times.len(),
        refreshes: run.refreshes,
        new_captures: run.new_captures,
        capture_px: Some(run.capture_px),
        time: Some(Summary::of(&run.times)),
        update_ms: Some(mean_ms(&run.update)),
        errors: Some(Errors::of_frames(&frames)),
        predicted: Some(predicted_stats(&run.predicted)),
        memory_bytes: Some(run.memory),
        triangles: run.triangles,
        ..Row::empty(series, path, policy, settings, n)
    }
}

/// A geometry row.
pub(super) fn geometry_row(
    series: &'static str,
    path: CityPath,
    settings: &Settings,
    n: usize,
    times: &[Duration],
    triangles: u64,
) -> Row {
    Row {
        frames: times.len(),
        time: Some(Summary::of(times)),
        triangles,
        ..Row::empty(series, path, "geometry".into(), settings, n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_rows_match_the_header() {
        let n = Row::HEADER.split(',').count();
        let row = geometry_row("geometry", CityPath::Rotate, &Settings::tiny(), 9, &[], 0);
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
