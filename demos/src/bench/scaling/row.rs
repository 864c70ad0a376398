//! The sweep's CSV rows: a measured point's [`Timing`] or a fitted line.

use super::Fit;
use crate::bench::sweep::CsvRow;
use crate::timing::Summary;
use engine::FrameStats;

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
    /// Mean absolute error of the steady frames against the geometry frames at the same
    /// poses (8-bit levels; geometry: 0).
    pub mae: Option<f64>,
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
    /// Buildings in the city (fit rows: 0).
    pub subjects: usize,
    /// Fit rows: slope in ns per triangle or per pixel, intercept in ms.
    pub fit: Option<Fit>,
}

impl Row {
    pub fn pixels(&self) -> u64 {
        self.width as u64 * self.height as u64
    }
}

impl CsvRow for Row {
    const HEADER: &'static str = "series,mode,triangles,width,height,pixels,threads,frames,median_ms,min_ms,p90_ms,mean_ms,update_ms,render_ms,refresh_frames,refresh_median_ms,refreshes,capture_triangles,images,triangles_set_up,fragments_shaded,fragments_written,slope_ns,intercept_ms,r2,mae,subjects";

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
        let mae = self
            .timing
            .and_then(|t| t.mae)
            .map_or(String::new(), |e| format!("{e:.4}"));
        format!(
            "{},{},{},{},{},{},{},{},{},{},{}",
            self.series,
            self.mode,
            self.triangles,
            self.width,
            self.height,
            self.pixels(),
            self.threads,
            timing,
            fit,
            mae,
            self.subjects
        )
    }
}
