//! Reversed depth and view distance for the raster stage: soft particles' distances and
//! nailboards' moved depths ([`DepthToView`]).

use crate::camera::Camera;
use crate::shade::Lane;
use crate::simd::F8;

/// Converts reversed depth to view distance, for soft particles, and moves a reversed
/// depth back by a view distance, for nailboards ([`crate::material::DepthOffset`]).
#[derive(Clone, Copy, Debug)]
pub struct DepthToView {
    camera: Camera,
    /// Perspective: `1/w = d * scale + base` for view depth `w` and reversed depth `d`
    /// (`d = n (f - w) / (w (f - n))`, so `scale = (f - n) / (n f)`, `base = 1 / f`; an
    /// infinite far plane gives `1 / n` and 0). Orthographic: `w = f - d (f - n)`, and
    /// `scale = 1 / (f - n)` is the depth a view unit takes.
    scale: f32,
    base: f32,
    perspective: bool,
}

impl DepthToView {
    pub fn new(camera: Camera) -> Self {
        let (n, f) = camera.near_far();
        let perspective = camera.projection.is_perspective();
        let (scale, base) = match (perspective, f.is_finite()) {
            (true, true) => ((f - n) / (n * f), 1.0 / f),
            (true, false) => (1.0 / n, 0.0),
            (false, _) => (1.0 / (f - n), 0.0),
        };
        DepthToView {
            camera,
            scale,
            base,
            perspective,
        }
    }
    #[inline]
    pub(super) fn view(&self, d: f32) -> f32 {
        self.camera.view_depth_from_reversed(d)
    }

    /// The reversed depths of the points `dw` view units (`>= 0`) behind those at
    /// reversed depth `z`, along the same rays: `1/w' = 1 / (w + dw)`, in 8 lanes.
    #[inline(always)]
    pub fn behind(&self, z: Lane, dw: Lane) -> Lane {
        if !self.perspective {
            return z - dw * F8::splat(self.scale);
        }
        let (scale, base) = (F8::splat(self.scale), F8::splat(self.base));
        let iw = z.mul_add(scale, base);
        let moved = iw / dw.mul_add(iw, F8::splat(1.0));
        (moved - base) / scale
    }
}
