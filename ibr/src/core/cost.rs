//! Predicted cost: the work a representation does (triangles set up, pixels shaded,
//! offscreen captures started) and the measured per-unit times that turn work into
//! milliseconds.

use super::represent::Estimate;
use std::ops::{Add, AddAssign};

/// Work one draw or rebuild does, in the renderer's own counters' units.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Work {
    /// Triangles submitted.
    pub triangles: u64,
    /// Pixels of lit geometry shaded.
    pub pixels: u64,
    /// Pixels of images drawn (textured and blended over the frame).
    pub image_pixels: u64,
    /// Offscreen renders started (each clears and resolves a target of its own).
    pub captures: u64,
    /// Image passes run (one per object an image pass draws: its buffers cleared, its
    /// work dispatched).
    pub passes: u64,
    /// Pixels image passes cover (each object's rectangle: warped into, holes filled,
    /// composited).
    pub pass_pixels: u64,
    /// Reference samples image passes read (a depth image's texels warped, a light
    /// field's samples blended).
    pub samples: u64,
}

impl Add for Work {
    type Output = Work;
    fn add(self, o: Work) -> Work {
        Work {
            triangles: self.triangles + o.triangles,
            pixels: self.pixels + o.pixels,
            image_pixels: self.image_pixels + o.image_pixels,
            captures: self.captures + o.captures,
            passes: self.passes + o.passes,
            pass_pixels: self.pass_pixels + o.pass_pixels,
            samples: self.samples + o.samples,
        }
    }
}

impl AddAssign for Work {
    fn add_assign(&mut self, o: Work) {
        *self = *self + o;
    }
}

/// Per-unit times, fitted by least squares to measured frames (`bench budget --calibrate`
/// renders the city at several triangle counts with the same silhouettes and many distant
/// tori, stacks of lit and of image quads, batches of impostor rebuilds, and the image
/// passes of depth images, LDIs and light fields at three sizes, and prints a model;
/// BENCHMARKS.md gives the runs the defaults come from). Times are for the whole
/// machine (both cores), as a frame sees them. One cost per triangle is a compromise: the
/// city's mid-sized triangles alone fit 84 to 93 ns, distant tori's 24.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CostModel {
    /// Nanoseconds per triangle submitted.
    pub ns_per_triangle: f32,
    /// Nanoseconds per pixel of lit geometry.
    pub ns_per_pixel: f32,
    /// Nanoseconds per pixel of an image (textured, blended).
    pub ns_per_image_pixel: f32,
    /// Microseconds per offscreen render, besides its triangles and pixels.
    pub us_per_capture: f32,
    /// Nanoseconds per texel of an offscreen render besides shading it (clearing,
    /// resolving and copying it out): a rebuild's `pixels` are its captures' texels
    /// ([`CostModel::rebuild_ms`]).
    pub ns_per_capture_texel: f32,
    /// Microseconds per image pass, besides its pixels and samples.
    pub us_per_pass: f32,
    /// Nanoseconds per pixel an image pass covers.
    pub ns_per_pass_pixel: f32,
    /// Nanoseconds per reference sample an image pass reads.
    pub ns_per_sample: f32,
}

impl Default for CostModel {
    /// The fit of `cargo run --release --bin bench -- budget --calibrate` on the 2-core
    /// reference machine (BENCHMARKS.md, "Choosing representations").
    fn default() -> Self {
        CostModel {
            ns_per_triangle: 28.0,
            ns_per_pixel: 5.8,
            ns_per_image_pixel: 6.4,
            // Captures: two runs with a second, nearer batch fitted 7.0 and 7.6 us per
            // capture and 21.1 and 20.4 ns per captured texel (one batch alone had put all
            // on the captures: 13 us, under-predicting near rebuilds up to threefold).
            us_per_capture: 7.3,
            ns_per_capture_texel: 20.8,
            // Image passes: the mean of two runs' fits (37 and 66 us per pass, 82 and 80 ns
            // per pixel). Warps cost more per pixel than light fields (93 against 48 ns)
            // though they read a tenth of the samples, so the shared fit puts no cost on
            // samples: one cost per pass pixel is a compromise, as per triangle is.
            us_per_pass: 52.0,
            ns_per_pass_pixel: 81.0,
            ns_per_sample: 0.0,
        }
    }
}

impl CostModel {
    /// The predicted time of `w`, milliseconds.
    pub fn ms(&self, w: Work) -> f32 {
        let ns = w.triangles as f32 * self.ns_per_triangle
            + w.pixels as f32 * self.ns_per_pixel
            + w.image_pixels as f32 * self.ns_per_image_pixel
            + w.pass_pixels as f32 * self.ns_per_pass_pixel
            + w.samples as f32 * self.ns_per_sample;
        let us = w.captures as f32 * self.us_per_capture + w.passes as f32 * self.us_per_pass;
        ns * 1e-6 + us * 1e-3
    }

    /// The predicted time of a rebuild doing `w`, milliseconds: [`CostModel::ms`] plus
    /// what its captures' texels (its `pixels`) cost besides shading.
    pub fn rebuild_ms(&self, w: Work) -> f32 {
        self.ms(w) + w.pixels as f32 * self.ns_per_capture_texel * 1e-6
    }
}

/// An [`Estimate`] priced in milliseconds, as the planner keeps it: a world's estimates are
/// a hundred thousand a frame, read several times over, so they are kept small.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Priced {
    /// [`Estimate::error`].
    pub error: f32,
    /// [`Estimate::rebuilt`].
    pub rebuilt: f32,
    /// Drawing it, milliseconds.
    pub ms: f32,
    /// Rebuilding it, milliseconds ([`CostModel::rebuild_ms`]), if it needs a rebuild at
    /// all.
    pub rebuild_ms: f32,
    /// Whether it needs a rebuild at all.
    pub rebuilds: bool,
    /// [`Estimate::memory`].
    pub memory: usize,
}

impl Priced {
    /// `e` priced by `cost`.
    pub(crate) fn new(e: &Estimate, cost: &CostModel) -> Priced {
        let rebuilds = e.rebuild != Work::default();
        Priced {
            error: e.error,
            rebuilt: e.rebuilt,
            ms: cost.ms(e.draw),
            rebuild_ms: if rebuilds {
                cost.rebuild_ms(e.rebuild)
            } else {
                0.0
            },
            rebuilds,
            memory: e.memory,
        }
    }
}
