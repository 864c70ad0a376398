//! Error prediction without rendering (parallax and resolution against the tolerance),
//! and the screen geometry the scheduler needs: a sphere's pixel rectangle and the view
//! frustum test.

use super::{Capture, Config, Predicted};
use crate::metrics::Rect;
use engine::{Camera, Projection, Rgba, Sphere};
use glam::{Mat4, Vec3, Vec4};

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
pub const RESAMPLING: f32 = 0.15;
/// Texel displacement per pixel of parallax (fitted; up to 0.5 in theory).
pub const DISPLACEMENT: f32 = 0.57;

/// Pixels per radian at the centre of an image `height` pixels tall.
pub(crate) fn pixels_per_radian(camera: &Camera, height: u32) -> f32 {
    match camera.projection {
        Projection::Perspective { fov_y, .. } => {
            height as f32 * 0.5 / (fov_y * 0.5).tan().max(1e-6)
        }
        Projection::Orthographic { .. } => height as f32,
        Projection::Frustum {
            bottom, top, near, ..
        } => height as f32 * near / (top - bottom).abs().max(1e-6),
    }
}

/// The power-of-two texture side for a sphere of `radius` at `dist` (its screen diameter
/// rounded up), clamped to `[min, max]`.
pub fn needed_side(radius: f32, dist: f32, px_per_radian: f32, min: u32, max: u32) -> u32 {
    let px = 2.0 * px_per_radian * (radius / dist.max(1e-6)).min(1e3);
    let px = if px.is_finite() {
        px.ceil() as u32
    } else {
        max
    };
    px.max(1)
        .checked_next_power_of_two()
        .unwrap_or(max)
        .clamp(min.max(1), max.max(min.max(1)))
}

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

/// The pixel rectangle covering a sphere's projection (grown by 2 pixels), or `None` when
/// it is behind the eye or off the image.
pub fn screen_rect(camera: &Camera, center: Vec3, radius: f32, w: u32, h: u32) -> Option<Rect> {
    RectProjector::new(camera, w, h).rect(center, radius)
}

/// [`screen_rect`] for many spheres under one camera: the camera's matrices taken once.
#[derive(Clone, Copy, Debug)]
pub struct RectProjector {
    view: Mat4,
    clip: Mat4,
    right: Vec3,
    up: Vec3,
    fwd: Vec3,
    w: u32,
    h: u32,
}

impl RectProjector {
    /// Projects onto a `w` x `h` image from `camera`.
    pub fn new(camera: &Camera, w: u32, h: u32) -> Self {
        let to_world = camera.view.inverse();
        RectProjector {
            view: camera.view,
            clip: camera.clip_from_world(),
            right: to_world.x_axis.truncate().normalize_or_zero(),
            up: to_world.y_axis.truncate().normalize_or_zero(),
            fwd: -to_world.z_axis.truncate().normalize_or_zero(),
            w,
            h,
        }
    }

    /// [`screen_rect`] of the sphere at `center` of `radius`.
    pub fn rect(&self, center: Vec3, radius: f32) -> Option<Rect> {
        let (w, h) = (self.w, self.h);
        // View space looks down -Z: a sphere wholly at or behind the eye's plane is not seen.
        let depth = -self.view.transform_point3(center).z;
        if depth + radius <= 0.0 {
            return None;
        }
        let (mut lo, mut hi) = (
            glam::Vec2::splat(f32::INFINITY),
            glam::Vec2::splat(f32::NEG_INFINITY),
        );
        for corner in [-1.0f32, 1.0] {
            for sx in [-1.0f32, 1.0] {
                for sy in [-1.0f32, 1.0] {
                    let p = center + (self.right * sx + self.up * sy + self.fwd * corner) * radius;
                    let c = self.clip * p.extend(1.0);
                    if c.w <= 1e-6 {
                        return Some(Rect::new(0, 0, w, h));
                    }
                    let ndc = glam::Vec2::new(c.x, c.y) / c.w;
                    let px = glam::Vec2::new(
                        (ndc.x * 0.5 + 0.5) * w as f32,
                        (0.5 - ndc.y * 0.5) * h as f32,
                    );
                    lo = lo.min(px);
                    hi = hi.max(px);
                }
            }
        }
        if !(lo.is_finite() && hi.is_finite())
            || hi.x < 0.0
            || hi.y < 0.0
            || lo.x > w as f32
            || lo.y > h as f32
        {
            return None;
        }
        let x0 = lo.x.max(0.0) as u32;
        let y0 = lo.y.max(0.0) as u32;
        let x1 = (hi.x.ceil().max(0.0) as u32).min(w);
        let y1 = (hi.y.ceil().max(0.0) as u32).min(h);
        Some(Rect::new(x0, y0, x1.saturating_sub(x0), y1.saturating_sub(y0)).grow(2, w, h))
    }
}

impl RectProjector {
    /// The pixels of the screen rectangle around `points`, clipped to the image; `None`
    /// when one of them is at or behind the eye's plane.
    pub fn points_area(&self, points: &[Vec3]) -> Option<f32> {
        let (w, h) = (self.w as f32, self.h as f32);
        let (mut lo, mut hi) = (
            glam::Vec2::splat(f32::INFINITY),
            glam::Vec2::splat(f32::NEG_INFINITY),
        );
        for &p in points {
            let c = self.clip * p.extend(1.0);
            if c.w.is_nan() || c.w <= 1e-6 {
                return None;
            }
            let px = glam::Vec2::new((c.x / c.w * 0.5 + 0.5) * w, (0.5 - c.y / c.w * 0.5) * h);
            (lo, hi) = (lo.min(px), hi.max(px));
        }
        let (lo, hi) = (lo.max(glam::Vec2::ZERO), hi.min(glam::Vec2::new(w, h)));
        let size = (hi - lo).max(glam::Vec2::ZERO);
        let area = size.x * size.y;
        area.is_finite().then_some(area)
    }
}

/// The six planes of a view frustum (Gribb and Hartmann), for sphere tests: what the
/// planner and the benchmarks' error measures count as visible.
#[derive(Clone, Copy, Debug)]
pub struct Frustum([Vec4; 6]);

impl Frustum {
    /// The frustum of the clip-from-world matrix `m`.
    pub fn new(m: Mat4) -> Self {
        let r = [m.row(0), m.row(1), m.row(2), m.row(3)];
        let planes = [
            r[3] + r[0],
            r[3] - r[0],
            r[3] + r[1],
            r[3] - r[1],
            r[2],
            r[3] - r[2],
        ];
        Frustum(planes.map(|p| {
            let n = p.truncate().length();
            if n > 0.0 {
                p / n
            } else {
                p
            }
        }))
    }

    /// Whether a sphere is at least partly inside (conservative).
    pub fn sees(&self, c: Vec3, r: f32) -> bool {
        if !(c.is_finite() && r.is_finite()) {
            return false;
        }
        self.0.iter().all(|p| p.truncate().dot(c) + p.w >= -r)
    }
}
