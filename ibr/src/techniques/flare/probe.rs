//! Occlusion through blended draws: the draws that write no depth (impostors, clouds,
//! glass) captured once more ([`crate::core::Capturer`]) into a small transparent image
//! that crops the camera's view to the flare's tap disc, whose alpha then says how much of
//! the light each tap lets through.
//!
//! The depth taps of [`super::occlusion`] see opaque and alpha-tested surfaces; this pass
//! sees the rest. Alpha blending accumulates `a + d (1 - a)`, so a pixel's alpha is the
//! opacity of everything blended over it: an impostor's coverage, a cloud's accumulated
//! opacity. Additive draws (glows, lasers, the flare itself) emit light and hide nothing, so
//! they are left out. For a point light the crop's far plane sits at the light, so only what
//! lies in front of it counts.

use super::Projected;
use crate::core::Capturer;
use engine::{BlendMode, Camera, Draw, Encoding, Lighting, Target};
use glam::Vec2;

/// Side of the probe image, pixels (the tap disc's bounding square).
pub const PROBE_SIDE: u32 = 24;

/// Whether a draw can hide the light without writing depth: alpha-blended, not additive.
pub fn hides_without_depth(draw: &Draw<'_>) -> bool {
    draw.material.is_blended() && draw.material.blend != BlendMode::Additive
}

/// The blended draws' opacity around a light, as captured.
#[derive(Debug)]
pub struct Probe<'c> {
    image: &'c Target,
    /// The disc's bounding square in the main image, pixels: `min` and side.
    min: Vec2,
    side: f32,
}

impl<'c> Probe<'c> {
    /// Captures the blended, non-additive `draws` (others are skipped) with `capturer` over
    /// a transparent background, seen by `camera` cropped to the square of half side
    /// `radius_px` around `light` in a `width` x `height` image. `None` when nothing was
    /// drawn there (or a point light has no depth range in front of it).
    pub fn capture<'a>(
        capturer: &'c mut Capturer,
        draws: impl IntoIterator<Item = Draw<'a>>,
        lighting: &Lighting,
        camera: &Camera,
        light: &Projected,
        radius_px: f32,
        (width, height): (u32, u32),
    ) -> Option<Self> {
        let half = radius_px.max(0.5);
        let (min, side) = (light.pixel - Vec2::splat(half), 2.0 * half);
        let mut crop = camera.crop(min, min + Vec2::splat(side), width, height);
        if light.depth > 0.0 {
            // A point light: nothing behind it may count. Its view distance is the far plane.
            let (near, _) = camera.near_far();
            let far = camera.view_depth_from_reversed(light.depth);
            if far.is_nan() || far <= near {
                return None;
            }
            crop = crop.with_depth_range(near, far);
        }
        let blended = draws.into_iter().filter(hides_without_depth);
        let (n, enc) = (PROBE_SIDE, Encoding::Unorm);
        capturer.render(blended, &crop, lighting, n, n, enc);
        let capturer: &'c Capturer = capturer;
        let drew = capturer.last_stats().fragments_written > 0;
        drew.then_some(Probe {
            image: capturer.target(),
            min,
            side,
        })
    }

    /// The fraction of light passing the blended draws at `pixel` of the main image (1 where
    /// nothing blended covers it or outside the probed square).
    pub fn transmittance(&self, pixel: Vec2) -> f32 {
        let p = (pixel - self.min) / self.side * PROBE_SIDE as f32;
        if !(p.x >= 0.0 && p.y >= 0.0) {
            return 1.0;
        }
        self.image
            .color_linear(p.x as u32, p.y as u32)
            .map_or(1.0, |c| (1.0 - c.a).clamp(0.0, 1.0))
    }
}
