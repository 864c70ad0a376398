//! The `bench billboards` sweep: what billboards cost and how far billboard trees are from
//! the meshes they replace.
//!
//! Seven series in four groups, one CSV row per point ([`Row::HEADER`]):
//! - `count`: screen-facing, alpha-blended glow particles ([`sprites::glow`] 64 px, 0.15
//!   world units wide) scattered in a box 10 to 30 units in front of the camera, at
//!   [`Settings::count_size`], for each of [`Settings::counts`].
//! - `resolution`: the same particles, [`Settings::resolution_count`] of them, at each of
//!   [`Settings::resolutions`].
//! - `accuracy_fade` and `accuracy_top`: a pine and a broadleaf tree drawn as meshes (the
//!   ground truth: lit, vertex-coloured) and as axial billboards showing sprites baked once
//!   from the meshes ([`sprites::bake_upright`], seen from +Z, same lighting,
//!   [`Settings::bake_px`] tall), each alone over a transparent background in a square image
//!   of [`Settings::accuracy_size`], seen from 11 units away from the tree's mid-height point
//!   (the trees are 5 tall; 40 degree field of view) at each view elevation of
//!   [`Settings::elevations`] (measured at that point) and each azimuth of [`Settings::azimuths`]
//!   (0 = the baked side; the billboard turns to face every azimuth but keeps showing the
//!   baked side, as in a game). The billboard fades by the elevation seen from its base
//!   (its pivot), a few degrees more than the nominal one. Billboards are alpha-tested
//!   (`AlphaMode::Mask { cutoff: 0.5 }`, opaque pass).
//!   `accuracy_fade` uses [`Facing::UPRIGHT`] (fades out between 55 and 75 degrees);
//!   `accuracy_top` adds the baked top-down sprite ([`AxialFallback::top`]). The error is
//!   [`ibr::metrics`] over the union of both images' covered rectangles (grown by 2
//!   pixels), pooled over trees and azimuths ([`ImageError::pooled`]).
//! - `trees_mesh`, `trees_billboard` and `trees_nailboard`: a forest of
//!   [`Settings::tree_counts`] trees (pines and broadleaves, 3 to 7 units tall, at random on
//!   a 200 x 200 square of a flat ground plane) seen from one camera 12 units up at
//!   [`Settings::tree_size`]: as meshes (statically batched: one merged mesh per kind, so
//!   the renderer sees three draws with the ground), as alpha-tested [`Facing::UPRIGHT`]
//!   billboards of sprites baked 128 px tall (one batch per kind), or as the showcase's
//!   forest draws its trees: nailboards of views baked [`Settings::bake_px`] square from 12
//!   azimuths and 20 elevations, each fragment at its texel's depth, found by the parallax
//!   search (`nailboards.rs`). The image series' rows carry their error against the mesh
//!   forest's frame.
//!
//! Timing: every frame is timed as two parts, `build` (computing the billboard [`View`] and
//! [`BillboardBatch::build`]: quad generation, and for blended batches the back-to-front
//! sort; zero for meshes) and `render` (`Renderer::render` alone, clear included). Columns
//! `build_ms` and `render_ms` are their medians; `median_ms`, `min_ms` and `p90_ms` are of
//! their sum. Accuracy rows are not timed (empty time columns); timing rows have no error
//! columns.
//!
//! [`sprites::glow`]: ibr::sprites::glow
//! [`sprites::bake_upright`]: ibr::sprites::bake_upright
//! [`Facing::UPRIGHT`]: ibr::Facing::UPRIGHT
//! [`AxialFallback::top`]: ibr::AxialFallback::top
//! [`ImageError::pooled`]: ibr::metrics::ImageError::pooled
//! [`View`]: ibr::View
//! [`Row::HEADER`]: crate::bench::sweep::CsvRow::HEADER

mod accuracy;
mod nailboards;
mod particles;
mod report;
mod row;
mod trees;

pub use accuracy::orbit_camera;
pub use particles::{particle_camera, particles};
pub use report::{charts, BillboardsSweep, PSNR_CAP_DB};
pub use row::{Row, Times};
pub use trees::forest_camera;

use crate::bench::raster::count_name;
use crate::bench::sweep::{ticker, Timing};
use accuracy::accuracy;
use engine::{Lighting, Renderer, Target};
use ibr::BillboardBatch;
use particles::measure;
use std::time::Duration;
use trees::trees;

pub use crate::bench::sweep::MIN_FRAMES;

/// How much the sweep measures.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Particle counts of the `count` series, at `count_size`.
    pub counts: Vec<usize>,
    pub count_size: (u32, u32),
    /// Target sizes of the `resolution` series, with `resolution_count` particles.
    pub resolutions: Vec<(u32, u32)>,
    pub resolution_count: usize,
    /// View elevations (degrees) of the accuracy series.
    pub elevations: Vec<f32>,
    /// View azimuths (degrees from the baked side) pooled at each elevation.
    pub azimuths: Vec<f32>,
    /// Side of the square accuracy images, and height of the baked sprites, in pixels.
    pub accuracy_size: u32,
    pub bake_px: u32,
    /// Tree counts of the `trees_*` series, at `tree_size`.
    pub tree_counts: Vec<usize>,
    pub tree_size: (u32, u32),
    /// How each measurement times its frames.
    pub timing: Timing,
}

impl Settings {
    /// The full sweep.
    pub fn full() -> Settings {
        Settings {
            counts: vec![1_000, 10_000, 100_000, 1_000_000],
            count_size: (1280, 720),
            resolutions: vec![
                (320, 240),
                (640, 480),
                (1280, 720),
                (1920, 1080),
                (2560, 1440),
                (3840, 2160),
            ],
            resolution_count: 10_000,
            elevations: (0..=9).map(|i| i as f32 * 10.0).collect(),
            azimuths: vec![0.0, 90.0, 180.0, 270.0],
            accuracy_size: 256,
            bake_px: 256,
            tree_counts: vec![100, 1_000, 10_000, 50_000],
            tree_size: (1280, 720),
            timing: Timing::new(2, 21, 2),
        }
    }

    /// Every point of the full sweep with few frames: about a minute at most.
    pub fn quick() -> Settings {
        Settings {
            timing: Timing {
                warmup: 1,
                frames: 5,
                time_limit: Duration::from_millis(600),
            },
            ..Settings::full()
        }
    }

    /// A seconds-long smoke run (tests): small counts and sizes, four elevations.
    pub fn tiny() -> Settings {
        Settings {
            counts: vec![100, 1_000],
            count_size: (320, 240),
            resolutions: vec![(160, 120), (320, 240)],
            resolution_count: 1_000,
            elevations: vec![0.0, 30.0, 60.0, 90.0],
            azimuths: vec![0.0, 180.0],
            accuracy_size: 96,
            bake_px: 96,
            tree_counts: vec![50, 200],
            tree_size: (320, 240),
            timing: Timing {
                warmup: 0,
                frames: 2,
                time_limit: Duration::from_millis(100),
            },
        }
    }

    /// Measurements the sweep makes (progress steps).
    pub fn steps(&self) -> usize {
        self.counts.len()
            + self.resolutions.len()
            + 2 * self.elevations.len()
            + 3 * self.tree_counts.len()
    }
}

/// Runs the whole sweep; `progress` is called before each measurement with its 0-based
/// index, the total, and what it is.
pub fn run(settings: &Settings, mut progress: impl FnMut(usize, usize, &str)) -> Vec<Row> {
    let mut rows = Vec::with_capacity(settings.steps());
    let mut tick = ticker(settings.steps(), &mut progress);
    let mut renderer = Renderer::new();
    let threads = rayon::current_num_threads();
    let lighting = Lighting::default();
    // Times a batch of particles into `target`: the batch's triangles and the measurement.
    let mut particles_in = |target: &mut Target, batch: &mut [BillboardBatch; 1]| {
        let camera = particle_camera(target.width(), target.height());
        let measured = measure(
            &mut renderer,
            target,
            &camera,
            &lighting,
            &[],
            &mut [&mut batch[0]],
            settings,
        );
        (batch[0].mesh().triangle_count() as u64, measured)
    };

    let size = settings.count_size;
    let mut target = Target::new(size.0, size.1);
    for &n in &settings.counts {
        tick(format!("count {}", count_name(n as u64)));
        let (triangles, measured) = particles_in(&mut target, &mut [particles(n, 1)]);
        let value = n as f64;
        rows.push(Row::timed(
            "count",
            "billboards",
            value,
            size,
            n as u64,
            triangles,
            measured,
        ));
    }
    drop(target);

    let mut batch = [particles(settings.resolution_count, 1)];
    for &(w, h) in &settings.resolutions {
        tick(format!("resolution {w}x{h}"));
        let (triangles, measured) = particles_in(&mut Target::new(w, h), &mut batch);
        let n = settings.resolution_count as u64;
        let value = w as f64 * h as f64;
        rows.push(Row::timed(
            "resolution",
            "pixels",
            value,
            (w, h),
            n,
            triangles,
            measured,
        ));
    }
    drop(batch);

    accuracy(settings, &mut renderer, threads, &mut tick, &mut rows);
    trees(settings, &mut renderer, &mut tick, &mut rows);
    rows
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::sweep::CsvRow;
    use engine::FrameStats;
    use glam::Vec3;
    use ibr::metrics::ImageError;

    #[test]
    fn csv_rows_match_the_header_with_and_without_times() {
        let timed = Row {
            series: "count",
            param: "billboards",
            value: 1000.0,
            width: 320,
            height: 240,
            items: 1000,
            triangles: 2000,
            threads: 2,
            times: Some(Times::default()),
            stats: FrameStats::default(),
            error: None,
        };
        let n = Row::HEADER.split(',').count();
        assert_eq!(timed.csv().split(',').count(), n);
        let accuracy = Row {
            times: None,
            error: ImageError::pooled([]),
            ..timed
        };
        assert_eq!(accuracy.csv().split(',').count(), n);
    }

    #[test]
    fn the_orbit_camera_looks_at_its_centre_from_every_elevation() {
        let c = Vec3::new(0.0, 2.5, 0.0);
        for el in [0.0, 45.0, 90.0] {
            for az in [0.0, 90.0, 200.0] {
                let cam = orbit_camera(c, 11.0, az, el, 0.7);
                assert!((cam.eye().distance(c) - 11.0).abs() < 1e-3);
                assert!((cam.forward() - (c - cam.eye()).normalize()).length() < 1e-3);
                assert!(cam.view.is_finite());
            }
        }
    }
}
