//! Error prediction without rendering: parallax and resolution against the tolerance.

use super::{relief, Capture, Config, Predicted};
use crate::core::Subject;
use engine::{Rgba, Sphere};
use glam::Vec3;

/// The error of a captured impostor of a subject now at `bounds` and `version`, seen from
/// `eye`, needing a `needed`-side texture.
pub(super) fn predict(
    capture: Option<&Capture>,
    (bounds, version): (Sphere, u64),
    eye: Vec3,
    needed: u32,
    px_per_radian: f32,
    cfg: &Config,
) -> Predicted {
    let Some(c) = capture else {
        return Predicted {
            needed_side: needed,
            ratio: f32::INFINITY,
            ..Default::default()
        };
    };
    // atan2(|a x b|, a . b): well conditioned for the tiny angles that matter here.
    let (a, b) = (c.near - eye, c.far - eye);
    let radians = a.cross(b).length().atan2(a.dot(b));
    let degrees = radians.to_degrees();
    let pixels = radians * px_per_radian;
    let octaves = (needed as f32 / c.side as f32).log2().abs();
    let b = bounds;
    let dist = eye.distance(b.center);
    let levels = image_error(c, dist, pixels, px_per_radian);
    let t = cfg.tolerance;
    let parallax = match (t.levels, t.pixels) {
        // What staleness adds: a refresh cannot remove the fresh image's resampling error.
        (Some(l), _) => (levels - image_error(c, dist, 0.0, px_per_radian)) / l.max(1e-6),
        (None, Some(px)) => pixels / px.max(1e-6),
        (None, None) => degrees / t.degrees.max(1e-6),
    };
    let moved = b.center.distance(c.center) > 1e-3 * c.radius.max(1e-6)
        || (b.radius - c.radius).abs() > 1e-3 * c.radius.max(1e-6);
    let ratio = if version != c.version || moved {
        f32::INFINITY
    } else {
        parallax.max(octaves / t.octaves.max(1e-6))
    };
    Predicted {
        degrees,
        pixels,
        levels,
        needed_side: needed,
        octaves,
        ratio: if ratio.is_nan() { f32::INFINITY } else { ratio },
    }
}

/// The predicted image error with `parallax_px` of parallax (the near and far ends of the
/// subject's depth range that far apart on screen) seen from `dist`: the image's
/// neighbour difference per screen pixel, times the mean displacement of its texels plus
/// a resampling floor. Mean absolute 8-bit error over the subject's screen rectangle.
///
/// Surfaces spread over the depth range move between 0 (at the quad's plane) and half the
/// parallax (at the ends) against the image; [`DISPLACEMENT`] and [`RESAMPLING`] are fitted
/// so that the measured error is at most the prediction on 95% of the calibration run's
/// images (`bench impostors`, BENCHMARKS.md).
pub(crate) fn image_error(c: &Capture, dist: f32, parallax_px: f32, px_per_radian: f32) -> f32 {
    // The subject's diameter on screen, pixels: the image's texels are this much larger
    // or smaller there.
    let screen = 2.0 * (c.radius / dist.max(c.radius * 1.0001)).asin() * px_per_radian;
    let scale = c.side as f32 / screen.max(1.0);
    scale * (RESAMPLING * c.gradient + DISPLACEMENT * c.depth_gradient * parallax_px)
}

/// Texels of error a fresh image makes by resampling alone (fitted).
pub(super) const RESAMPLING: f32 = 0.15;
/// Texel displacement per pixel of parallax (fitted; up to 0.5 in theory).
pub(super) const DISPLACEMENT: f32 = 0.57;

/// Green at 0, yellow at the tolerance, red at twice it and beyond.
pub fn error_color(ratio: f32) -> Rgba {
    let t = if ratio.is_finite() {
        ratio.clamp(0.0, 2.0)
    } else {
        2.0
    };
    if t <= 1.0 {
        Rgba::new(t, 1.0, 0.1, 1.0)
    } else {
        Rgba::new(1.0, 2.0 - t, 0.1, 1.0)
    }
}

/// Whether a box impostor's image `capture` of `subject` shows some face of its box,
/// seen from `eye`, with less than a texel a pixel across ([`relief::face_stretch`]) and
/// more stretched than an image taken from `eye` at `fresh_side` texels would be: a face
/// the capture eye saw edge-on or from behind, seen at an angle now. Such an image is
/// invalid, whatever its parallax. An image just taken passes from its own eye, even where
/// the largest side gives under a texel a pixel (a subject near the eye, its faces seen
/// at a slant): a rebuild would not do better.
pub(super) fn stretched<S: Subject>(
    capture: Option<&Capture>,
    subject: &S,
    eye: Vec3,
    ppr: f32,
    fresh_side: u32,
) -> bool {
    let Some(c) = capture else { return false };
    let corners = subject.corners();
    let held = relief::face_stretch(c, &corners, eye, ppr);
    if held <= relief::MAX_STRETCH {
        return false;
    }
    let b = subject.bounds();
    let fresh = Capture::new(eye, b.center, b.radius, fresh_side, c.version)
        .map_or(0.0, |f| relief::face_stretch(&f, &corners, eye, ppr));
    held > fresh * STRETCH_GAIN
}

/// How much more stretched than a fresh image's ([`stretched`]) a held image's faces must
/// be before it is invalid: a rebuild must gain something clear of rounding.
const STRETCH_GAIN: f32 = 1.01;

/// A sphere of `radius` seen from `dist`: its disc's width on screen, pixels (the angle it
/// subtends, not the tangent the power-of-two sizing takes, so a little wider near it).
fn disc(radius: f32, dist: f32, ppr: f32) -> f32 {
    2.0 * (radius / dist.max(radius * 1.0001)).asin() * ppr
}

/// The texture side for [`super::ImpostorSet::side_step`]: the disc's width rounded up to
/// a multiple of `step`, within the config's sides.
pub(super) fn stepped_side(radius: f32, dist: f32, ppr: f32, step: u32, cfg: &Config) -> u32 {
    let step = step.max(1);
    let px = disc(radius, dist, ppr);
    let side = if px.is_finite() {
        (px / step as f32).ceil().min(1e6) as u32 * step
    } else {
        cfg.max_side
    };
    side.clamp(cfg.min_side.max(1), cfg.max_side.max(cfg.min_side.max(1)))
}

/// Whether the image `capture` holds under a texel a screen pixel now, its subject's disc
/// at `bounds` seen from `dist` wider than its side (an image at the largest side is not:
/// no refresh would hold more).
pub(super) fn outgrown(c: Option<&Capture>, b: Sphere, dist: f32, ppr: f32, max: u32) -> bool {
    c.is_some_and(|c| c.side < max && disc(b.radius, dist, ppr) > c.side as f32)
}
