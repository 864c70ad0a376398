//! The `bench impostors` sweep: what runtime impostors ([`ibr::impostor`]) cost and how far
//! their images are from the geometry they replace, on the procedural [`City`].
//!
//! **Scene.** [`City::new`]`(grid, detail, seed)`: one impostor per building (the ground
//! plate is always drawn as geometry), lit by the city's sun, seen through a 60 degree
//! (vertical) perspective camera at [`Settings::size`]. A *run* flies [`Settings::frames`] frames
//! along the first part of a camera path ([`City::path`] with `t` from 0 to the path's span,
//! [`Settings::span`]): frame 0 is the warm-up (every visible impostor takes its first image)
//! and is left out of every figure. In the full sweep (4 x 4 buildings, 6 units apart,
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
//!   [`Settings::tolerances`] (degrees of parallax; the resolution tolerance stays 1 octave) on
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
//!   ([`ibr::octahedral`], [`Layout::Hemi`]) against geometry on the `orbit` span, the
//!   runtime images drawn on each [`ibr::impostor::Shape`] (a quad, a relief, the
//!   building's box; relief and box as cutouts) on the same frames. Frame
//!   time as above (for octahedral impostors the per-frame [`OctahedralImpostor::update`],
//!   which recomposes each image from three baked views on the CPU, is the update part,
//!   and `refreshes` counts recomposed images); memory is texel bytes held (the runtime
//!   pool's [`ibr::impostor::Pool::bytes`] at the end of the run; the atlases and composed
//!   images of [`OctahedralImpostor::bytes`]); `setup_ms` is the bake (octahedral),
//!   `update_ms` the per-frame cost, refreshes included (runtime). Octahedral images are
//!   measured exactly as [`ImpostorSet::measure`] measures runtime ones
//!   ([`measure_draws`], checked against it in the tests); geometry is measured the same
//!   way against itself (0: the renderer is deterministic).

mod calibration;
mod methods;
mod report;
mod row;
mod scene;
mod tolerance;

pub use calibration::{
    calibration_bins, calibration_chart, calibration_levels, calibration_levels_chart,
    calibration_per_impostor, calibration_points, calibration_summary, correlation, slope,
};
pub use methods::method_label;
pub use report::{charts, row_line, ImpostorsSweep, PSNR_CAP_DB};
pub use row::{Errors, PredictedStats, Row};
pub use scene::{frame_camera, measure_draws, path_name};

use crate::bench::sweep::ticker;
use crate::city::{City, Path as CityPath};

/// How much the sweep measures.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
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

impl Settings {
    /// The full sweep.
    pub fn full() -> Settings {
        Settings {
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
    pub fn quick() -> Settings {
        Settings {
            frames: 21,
            ..Settings::full()
        }
    }

    /// A seconds-long smoke run (tests): a 3 x 3 city at 256 x 144, three tolerances.
    pub fn tiny() -> Settings {
        Settings {
            grid: 3,
            detail: 2,
            seed: 7,
            size: (256, 144),
            tolerances: vec![0.03, 0.25, 2.0],
            frames: 17,
            method_tolerances: vec![0.125],
            octahedral: vec![(8, 32)],
            ..Settings::full()
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
            + self.method_tolerances.len() * methods::SHAPES.len()
            + self.octahedral.len()
    }
}

/// Runs the whole sweep; `progress` is called before each run with its 0-based index,
/// the total, and what it is.
pub fn run(settings: &Settings, mut progress: impl FnMut(usize, usize, &str)) -> Vec<Row> {
    let mut tick = ticker(settings.steps(), &mut progress);
    let mut city = City::new(settings.grid, settings.detail, settings.seed);
    let mut rows = Vec::new();
    tolerance::sweep(settings, &mut city, &mut tick, &mut rows);
    tolerance::fixed(settings, &mut city, &mut tick, &mut rows);
    calibration::run(settings, &mut city, &mut tick, &mut rows);
    methods::methods(settings, &mut city, &mut tick, &mut rows);
    rows
}
