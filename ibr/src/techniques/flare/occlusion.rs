//! Where the light is and how much of it shows: its projection onto the image, and its
//! visibility in a finished frame, from depth taps over a disc around it (opaque and
//! alpha-tested surfaces) dimmed by the blended draws in front of it ([`super::probe`]).

use super::probe::Probe;
use super::FlareSource;
use crate::core::Capturer;
use engine::{Camera, Draw, Lighting, Target};
use glam::Vec2;
use std::f32::consts::TAU;

/// The light as the camera sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projected {
    /// Position in pixels (x right, y down; pixel centres at +0.5), possibly off screen.
    pub pixel: Vec2,
    /// The reversed depth a surface must not exceed to leave the light visible (0 for a
    /// directional light: only cleared pixels).
    pub depth: f32,
}

/// Projects `source` for `camera` onto a `width` x `height` image. `None` when it is behind
/// the eye, at the eye, outside the depth range (point light), not finite, or the image is
/// empty.
pub fn project(camera: &Camera, source: FlareSource, width: u32, height: u32) -> Option<Projected> {
    if width == 0 || height == 0 {
        return None;
    }
    let m = camera.clip_from_world();
    let (clip, point) = match source {
        FlareSource::Point(p) => (m * p.extend(1.0), true),
        FlareSource::Directional(d) => (m * d.normalize_or_zero().extend(0.0), false),
    };
    if !(clip.w > 1e-6 && clip.is_finite()) {
        return None;
    }
    let ndc = clip.truncate() / clip.w;
    if point && !(0.0..=1.0).contains(&ndc.z) {
        return None;
    }
    let size = Vec2::new(width as f32, height as f32);
    let pixel = (Vec2::new(ndc.x, -ndc.y) * 0.5 + 0.5) * size;
    pixel.is_finite().then_some(Projected {
        pixel,
        depth: if point { ndc.z } else { 0.0 },
    })
}

/// The fraction of `samples` depth taps (a golden-angle spiral filling a disc of `radius_px`
/// around the light) where nothing nearer than the light was drawn. Taps off the image
/// count as hidden: a light leaving the screen fades out smoothly instead of staying at full
/// strength until its centre crosses the edge.
pub fn occlusion(target: &Target, light: &Projected, samples: u32, radius_px: f32) -> f32 {
    occlusion_through(target, light, samples, radius_px, |_| 1.0)
}

/// [`occlusion`] with each visible tap weighted by `transmittance` at its pixel (the light
/// let through by what the depth buffer does not see).
pub fn occlusion_through(
    target: &Target,
    light: &Projected,
    samples: u32,
    radius_px: f32,
    transmittance: impl Fn(Vec2) -> f32,
) -> f32 {
    let n = samples.clamp(1, 4096);
    let radius = tap_radius(radius_px);
    let limit = light.depth + light.depth.abs() * 1e-4;
    let golden = TAU * (1.0 - 1.0 / 1.618_034);
    let visible: f32 = (0..n)
        .map(|i| {
            let r = radius * ((i as f32 + 0.5) / n as f32).sqrt();
            let (s, c) = (i as f32 * golden).sin_cos();
            let p = light.pixel + Vec2::new(c, s) * r;
            if !(p.x >= 0.0 && p.y >= 0.0) {
                return 0.0;
            }
            // `as` saturates; `depth_reversed` is `None` off the image.
            let open = target
                .depth_reversed(p.x as u32, p.y as u32)
                .is_some_and(|d| d <= limit);
            if open {
                transmittance(p).clamp(0.0, 1.0)
            } else {
                0.0
            }
        })
        .sum();
    visible / n as f32
}

/// The tap disc's radius: NaN as 0, at most 1e6 pixels.
pub(super) fn tap_radius(radius_px: f32) -> f32 {
    if radius_px.is_nan() {
        0.0
    } else {
        radius_px.clamp(0.0, 1e6)
    }
}

/// The finished frame a flare measures its light in.
#[derive(Clone, Copy, Debug)]
pub struct Seen<'s> {
    /// The frame after its opaque and blended passes.
    pub target: &'s Target,
    /// The camera the frame was rendered with.
    pub camera: &'s Camera,
    /// The frame's lighting, used to shade the blended occluders when they are captured.
    pub lighting: &'s Lighting,
}

/// The light's visibility in a finished frame: the depth taps, each dimmed by the blended
/// `draws` in front of it (captured with `capturer` only when some tap is open).
pub fn measure<'a>(
    capturer: &mut Capturer,
    seen: &Seen<'_>,
    draws: impl IntoIterator<Item = Draw<'a>>,
    light: &Projected,
    samples: u32,
    radius_px: f32,
) -> f32 {
    let depth_only = occlusion(seen.target, light, samples, radius_px);
    if depth_only == 0.0 {
        return 0.0;
    }
    let size = (seen.target.width(), seen.target.height());
    let radius = tap_radius(radius_px);
    match Probe::capture(
        capturer,
        draws,
        seen.lighting,
        seen.camera,
        light,
        radius,
        size,
    ) {
        Some(probe) => occlusion_through(seen.target, light, samples, radius, |p| {
            probe.transmittance(p)
        }),
        None => depth_only,
    }
}
