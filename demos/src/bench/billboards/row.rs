//! The sweep's CSV rows: a timing row's [`Times`] or an accuracy row's error.

use crate::bench::sweep::CsvRow;
use crate::timing::Summary;
use engine::FrameStats;
use ibr::metrics::ImageError;

/// Frame times of a measurement: the build part, the render part, and their sum.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Times {
    pub build: Summary,
    pub render: Summary,
    pub total: Summary,
}

/// One measurement: a CSV row.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// `count`, `resolution`, `accuracy_fade`, `accuracy_top`, `trees_mesh`,
    /// `trees_billboard` or `trees_nailboard`.
    pub series: &'static str,
    /// What the series sweeps: `billboards`, `pixels`, `elevation_deg` or `trees`.
    pub param: &'static str,
    pub value: f64,
    pub width: u32,
    pub height: u32,
    /// Billboards (particles) or trees in the frame.
    pub items: u64,
    /// Triangles submitted to the renderer (accuracy rows: the pine billboard's image at
    /// azimuth 0).
    pub triangles: u64,
    pub threads: usize,
    /// `None` for accuracy rows.
    pub times: Option<Times>,
    /// Counters of the last timed frame (accuracy rows: the pine billboard's image at
    /// azimuth 0).
    pub stats: FrameStats,
    /// `None` for the particle rows; the forest rows' error against the mesh forest on the
    /// same frame (the meshes' own: 0).
    pub error: Option<ImageError>,
}

impl Row {
    /// A timing row (no error columns) of `items` billboards or trees in `triangles`, at
    /// `value` of `param`.
    pub(super) fn timed(
        series: &'static str,
        param: &'static str,
        value: f64,
        (width, height): (u32, u32),
        items: u64,
        triangles: u64,
        (times, stats): (Times, FrameStats),
    ) -> Row {
        Row {
            series,
            param,
            value,
            width,
            height,
            items,
            triangles,
            threads: rayon::current_num_threads(),
            times: Some(times),
            stats,
            error: None,
        }
    }
}

impl CsvRow for Row {
    const HEADER: &'static str = "series,param,value,width,height,items,triangles,threads,frames,build_ms,render_ms,median_ms,min_ms,p90_ms,triangles_set_up,fragments_shaded,psnr_db,mae,max_abs,frac_over,coverage_mismatch";

    fn csv(&self) -> String {
        let times = match &self.times {
            Some(t) => format!(
                "{},{:.4},{:.4},{:.4},{:.4},{:.4}",
                t.total.frames,
                t.build.median_ms,
                t.render.median_ms,
                t.total.median_ms,
                t.total.min_ms,
                t.total.p90_ms
            ),
            None => ",,,,,".to_string(),
        };
        let error = match &self.error {
            Some(e) => format!(
                "{:.3},{:.4},{},{:.5},{:.5}",
                e.psnr_db, e.mean_abs, e.max_abs, e.frac_over, e.coverage_mismatch
            ),
            None => ",,,,".to_string(),
        };
        format!(
            "{},{},{},{},{},{},{},{},{},{},{},{}",
            self.series,
            self.param,
            self.value,
            self.width,
            self.height,
            self.items,
            self.triangles,
            self.threads,
            times,
            self.stats.triangles_set_up,
            self.stats.fragments_shaded,
            error
        )
    }
}
