//! Predicted cost: the work a representation does (triangles set up, pixels shaded,
//! offscreen captures started) and the measured per-unit times that turn work into
//! milliseconds.

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
    /// Reference samples read by image passes (a depth image's texels warped, a light
    /// field's samples blended), besides the pixels they write.
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
/// tori, stacks of lit and of image quads, and batches of impostor rebuilds, and prints a
/// model; BENCHMARKS.md gives the runs the defaults come from). Times are for the whole
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
            us_per_capture: 13.0,
            ns_per_sample: 5.0,
        }
    }
}

impl CostModel {
    /// The predicted time of `w`, milliseconds.
    pub fn ms(&self, w: Work) -> f32 {
        let ns = w.triangles as f32 * self.ns_per_triangle
            + w.pixels as f32 * self.ns_per_pixel
            + w.image_pixels as f32 * self.ns_per_image_pixel
            + w.samples as f32 * self.ns_per_sample;
        ns * 1e-6 + w.captures as f32 * self.us_per_capture * 1e-3
    }
}
