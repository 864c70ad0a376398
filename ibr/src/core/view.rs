//! View and screen maths every technique and the planner share: pixels per radian, the
//! texture side a sphere needs, a sphere's pixel rectangle ([`screen_rect`], many at once
//! with [`RectProjector`]), the view frustum test ([`Frustum`]) and the pixel rectangle
//! itself ([`Rect`]).

use engine::{Camera, Projection};
use glam::{Mat4, Vec3, Vec4};

/// A pixel rectangle: columns `x .. x + width`, rows `y .. y + height`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Rect {
    /// Left column.
    pub x: u32,
    /// Top row.
    pub y: u32,
    /// Columns covered.
    pub width: u32,
    /// Rows covered.
    pub height: u32,
}

impl Rect {
    /// The rectangle of `width` x `height` pixels with top-left pixel `(x, y)`.
    pub fn new(x: u32, y: u32, width: u32, height: u32) -> Self {
        Rect {
            x,
            y,
            width,
            height,
        }
    }

    /// Whether it holds no pixel.
    pub fn is_empty(&self) -> bool {
        self.width == 0 || self.height == 0
    }

    /// The smallest rectangle holding both (an empty one adds nothing).
    pub fn union(self, other: Rect) -> Rect {
        if self.is_empty() {
            return other;
        }
        if other.is_empty() {
            return self;
        }
        let x0 = self.x.min(other.x);
        let y0 = self.y.min(other.y);
        let x1 = (self.x + self.width).max(other.x + other.width);
        let y1 = (self.y + self.height).max(other.y + other.height);
        Rect::new(x0, y0, x1 - x0, y1 - y0)
    }

    /// The part inside a `width` x `height` image (possibly empty).
    pub fn clip(self, width: u32, height: u32) -> Rect {
        let x0 = self.x.min(width);
        let y0 = self.y.min(height);
        let x1 = self.x.saturating_add(self.width).min(width);
        let y1 = self.y.saturating_add(self.height).min(height);
        Rect::new(x0, y0, x1 - x0, y1 - y0)
    }

    /// This rectangle grown by `margin` pixels on every side, clipped to the image.
    pub fn grow(self, margin: u32, width: u32, height: u32) -> Rect {
        let x0 = self.x.saturating_sub(margin);
        let y0 = self.y.saturating_sub(margin);
        let x1 = self.x.saturating_add(self.width).saturating_add(margin);
        let y1 = self.y.saturating_add(self.height).saturating_add(margin);
        Rect::new(x0, y0, x1 - x0, y1 - y0).clip(width, height)
    }
}

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
pub(crate) fn needed_side(radius: f32, dist: f32, px_per_radian: f32, min: u32, max: u32) -> u32 {
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

    /// Whether a point is inside (on every plane's inner side; false for non-finite points).
    pub fn contains(&self, p: Vec3) -> bool {
        p.is_finite() && self.0.iter().all(|q| q.truncate().dot(p) + q.w >= 0.0)
    }
}
