//! Occlusion through blended draws: the draws that write no depth (impostors, clouds,
//! glass) rendered once more into a small transparent target that crops the camera's view
//! to the flare's tap disc, whose alpha then says how much of the light each tap lets
//! through.
//!
//! The depth taps of [`super::occlusion`] see opaque and alpha-tested surfaces; this pass
//! sees the rest. Alpha blending accumulates `a + d (1 - a)`, so a pixel's alpha is the
//! opacity of everything blended over it: an impostor's coverage, a cloud's accumulated
//! opacity. Additive draws (glows, lasers, the flare itself) emit light and hide nothing, so
//! they are left out. For a point light the crop's far plane sits at the light, so only what
//! lies in front of it counts.

use super::Projected;
use engine::{
    BlendMode, Camera, Cull, Draw, Encoding, FrameOptions, Lighting, Renderer, Rgba, Target,
};
use glam::Vec2;

/// Side of the probe target, pixels (the tap disc's bounding square).
pub const PROBE_SIDE: u32 = 24;

/// The probe's target, kept between frames.
#[derive(Clone, Debug)]
pub struct Probe {
    target: Target,
    /// The disc's bounding square in the main image, pixels: `min` and side.
    min: Vec2,
    side: f32,
}

impl Default for Probe {
    fn default() -> Self {
        Probe {
            target: Target::with_encoding(PROBE_SIDE, PROBE_SIDE, Encoding::Unorm),
            min: Vec2::ZERO,
            side: 1.0,
        }
    }
}

/// Whether a draw can hide the light without writing depth: alpha-blended, not additive.
pub fn hides_without_depth(draw: &Draw<'_>) -> bool {
    draw.material.is_blended() && draw.material.blend != BlendMode::Additive
}

impl Probe {
    /// Renders the blended, non-additive `draws` (others are skipped) over a transparent
    /// background, seen by `camera` cropped to the square of half side `radius_px` around
    /// `light` in a `width` x `height` image. Returns whether anything was drawn.
    pub fn render<'a>(
        &mut self,
        renderer: &mut Renderer,
        draws: impl IntoIterator<Item = Draw<'a>>,
        lighting: &Lighting,
        camera: &Camera,
        light: &Projected,
        radius_px: f32,
        width: u32,
        height: u32,
    ) -> bool {
        let half = radius_px.max(0.5);
        self.min = light.pixel - Vec2::splat(half);
        self.side = 2.0 * half;
        let mut crop = camera.crop(self.min, self.min + Vec2::splat(self.side), width, height);
        if light.depth > 0.0 {
            // A point light: nothing behind it may count. Its view distance is the far plane.
            let (near, _) = camera.near_far();
            let far = camera.view_depth_from_reversed(light.depth);
            if far.is_nan() || far <= near {
                self.target.clear(Rgba::TRANSPARENT);
                return false;
            }
            crop = crop.with_depth_range(near, far);
        }
        let opts = FrameOptions {
            clear: Some(Rgba::TRANSPARENT),
            cull: Cull::PerMaterial,
        };
        let stats = renderer.render(
            draws.into_iter().filter(hides_without_depth),
            &crop,
            lighting,
            &mut self.target,
            &opts,
        );
        stats.fragments_shaded > 0
    }

    /// The fraction of light passing the blended draws at `pixel` of the main image (1 where
    /// nothing blended covers it or outside the probed square).
    pub fn transmittance(&self, pixel: Vec2) -> f32 {
        let p = (pixel - self.min) / self.side * PROBE_SIDE as f32;
        if !(p.x >= 0.0 && p.y >= 0.0) {
            return 1.0;
        }
        self.target
            .color_linear(p.x as u32, p.y as u32)
            .map_or(1.0, |c| (1.0 - c.a).clamp(0.0, 1.0))
    }
}
