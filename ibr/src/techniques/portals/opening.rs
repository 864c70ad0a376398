//! A portal's opening (a door or window: a planar convex quad) and its outline on screen:
//! clipped against the near plane, projected to pixels, and taken a row at a time (a row
//! of a convex outline is one run of pixels).

use engine::Camera;
use glam::{Vec2, Vec3, Vec4};

/// A doorway or window: four corners in world space, counter-clockwise as seen from the
/// near side (the side the viewer stands on while the portal is warped).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Opening {
    /// The four corners, world space, counter-clockwise as seen from the near side.
    pub corners: [Vec3; 4],
}

impl Opening {
    /// An upright rectangle `width` x `height` whose bottom edge's midpoint is `base`,
    /// facing `toward` (the near side; horizontal, `Y` up).
    pub fn upright(base: Vec3, width: f32, height: f32, toward: Vec3) -> Self {
        let n = Vec3::new(toward.x, 0.0, toward.z).normalize_or(Vec3::Z);
        let right = Vec3::Y.cross(n) * (width * 0.5);
        let up = Vec3::Y * height;
        Opening {
            corners: [
                base - right,
                base + right,
                base + right + up,
                base - right + up,
            ],
        }
    }

    /// The mean of the four corners, world space.
    pub fn center(&self) -> Vec3 {
        self.corners.iter().copied().sum::<Vec3>() * 0.25
    }

    /// Unit normal toward the near side.
    pub fn normal(&self) -> Vec3 {
        let [a, b, _, d] = self.corners;
        (b - a).cross(d - a).normalize_or_zero()
    }

    /// Signed distance of `p` from the opening's plane, positive on the near side.
    pub fn side(&self, p: Vec3) -> f32 {
        (p - self.center()).dot(self.normal())
    }

    /// Whether `p`, projected onto the plane along the normal, falls inside the opening.
    pub fn over(&self, p: Vec3) -> bool {
        let n = self.normal();
        (0..4).all(|i| {
            let (a, b) = (self.corners[i], self.corners[(i + 1) % 4]);
            (b - a).cross(p - a).dot(n) >= 0.0
        })
    }

    /// Whether anything of the sphere (`center`, `radius`) can be seen from `eye` (on the
    /// near side) through the opening: it reaches past the opening's plane and into the
    /// pyramid from the eye through the opening's edges. Conservative (a sphere near a
    /// corner of the pyramid may be kept though hidden); an eye on or past the plane sees
    /// everything.
    pub fn sees(&self, eye: Vec3, center: Vec3, radius: f32) -> bool {
        let side = self.side(eye);
        if side.is_nan() || side <= 0.0 || !center.is_finite() || !radius.is_finite() {
            return true;
        }
        if self.side(center) > radius {
            return false;
        }
        let mid = self.center() - eye;
        (0..4).all(|i| {
            let (a, b) = (self.corners[i] - eye, self.corners[(i + 1) % 4] - eye);
            let n = a.cross(b).normalize_or_zero();
            // Inward: the opening's centre is inside the pyramid.
            let n = if n.dot(mid) < 0.0 { -n } else { n };
            n.dot(center - eye) >= -radius
        })
    }

    /// The opening's outline in `camera`'s `width` x `height` image: clipped against the
    /// near plane, in pixels (y down). `None` when nothing of it is in front of the eye.
    pub fn outline(&self, camera: &Camera, width: u32, height: u32) -> Option<Outline> {
        let m = camera.clip_from_world();
        let (near, _) = camera.near_far();
        // w is the distance along the view axis for every perspective projection; keep
        // what lies beyond the near plane (and in front for orthographic, w = 1).
        let clip = self.corners.map(|c| m * c.extend(1.0));
        let min_w = if camera.projection.is_perspective() {
            near
        } else {
            0.0
        };
        let mut pts = [Vec2::ZERO; 8];
        let mut n = 0;
        for i in 0..4 {
            let (a, b) = (clip[i], clip[(i + 1) % 4]);
            let (da, db) = (a.w - min_w, b.w - min_w);
            if da >= 0.0 {
                pts[n] = to_pixel(a, width, height);
                n += 1;
            }
            if (da >= 0.0) != (db >= 0.0) {
                let t = da / (da - db);
                pts[n] = to_pixel(a + (b - a) * t, width, height);
                n += 1;
            }
        }
        let pts = &pts[..n];
        if n < 3 || pts.iter().any(|p| !p.is_finite()) {
            return None;
        }
        let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
        for p in pts {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        let clamp = |v: f32, n: u32| v.clamp(0.0, n as f32) as u32;
        let bounds = [
            clamp(lo.x.floor(), width),
            clamp(lo.y.floor(), height),
            clamp(hi.x.ceil(), width),
            clamp(hi.y.ceil(), height),
        ];
        if bounds[0] >= bounds[2] || bounds[1] >= bounds[3] {
            return None;
        }
        let mut outline = Outline {
            points: [Vec2::ZERO; 8],
            len: n,
            bounds,
        };
        outline.points[..n].copy_from_slice(pts);
        Some(outline)
    }
}

fn to_pixel(c: Vec4, width: u32, height: u32) -> Vec2 {
    let inv = 1.0 / c.w.max(f32::MIN_POSITIVE);
    Vec2::new(
        (c.x * inv + 1.0) * 0.5 * width as f32,
        (1.0 - c.y * inv) * 0.5 * height as f32,
    )
}

/// A convex outline in pixels, and the pixel rectangle `[x0, y0, x1, y1)` around it
/// (clamped to the image).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outline {
    points: [Vec2; 8],
    len: usize,
    /// The pixel rectangle `[x0, y0, x1, y1)` around the outline, clamped to the image.
    pub bounds: [u32; 4],
}

impl Outline {
    /// The outline's corners in pixels (x right, y down), in order; at most 8 after clipping.
    pub fn points(&self) -> &[Vec2] {
        &self.points[..self.len]
    }

    /// Whether the centre of pixel `(x, y)` lies inside (edges included), whichever way the
    /// outline winds.
    pub fn contains(&self, x: u32, y: u32) -> bool {
        let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
        let pts = self.points();
        let (mut pos, mut neg) = (false, false);
        for i in 0..pts.len() {
            let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
            let e = (b - a).perp_dot(p - a);
            pos |= e > 0.0;
            neg |= e < 0.0;
        }
        !(pos && neg)
    }

    /// Pixels covered (centres inside).
    pub fn area_px(&self) -> u64 {
        let [_, y0, _, y1] = self.bounds;
        (y0..y1)
            .map(|y| {
                let (a, b) = self.span(y);
                u64::from(b - a)
            })
            .sum()
    }

    /// The pixels `[a, b)` of row `y` (within the bounds) whose centres are inside: the
    /// pixels [`Outline::contains`] takes, as a row of a convex outline is one run. Solved
    /// from the edges' lines, then its ends settled by `contains` itself, so a row costs a
    /// few tests rather than one per pixel.
    pub fn span(&self, y: u32) -> (u32, u32) {
        let [x0, _, x1, _] = self.bounds;
        let pts = self.points();
        // The winding: twice the signed area.
        let area: f32 = (0..pts.len())
            .map(|i| pts[i].perp_dot(pts[(i + 1) % pts.len()]))
            .sum();
        let (mut a, mut b) = if area.abs() < 1.0 {
            // Too thin to solve for: every pixel of the row, settled below.
            (x0, x1)
        } else {
            // Each edge keeps the centres on its inner side: `s (C - d.y px) >= 0`.
            let (s, yc) = (area.signum(), y as f32 + 0.5);
            let (mut lo, mut hi) = (f32::NEG_INFINITY, f32::INFINITY);
            for i in 0..pts.len() {
                let (p, d) = (pts[i], pts[(i + 1) % pts.len()] - pts[i]);
                let c = d.x * (yc - p.y) + d.y * p.x;
                if s * d.y > 0.0 {
                    hi = hi.min(c / d.y);
                } else if s * d.y < 0.0 {
                    lo = lo.max(c / d.y);
                } else if s * c < 0.0 {
                    (lo, hi) = (f32::INFINITY, f32::NEG_INFINITY);
                }
            }
            let clamp = |v: f32| v.clamp(x0 as f32, x1 as f32) as u32;
            let a = clamp((lo - 0.5).ceil());
            (a, clamp((hi - 0.5).floor() + 1.0).max(a))
        };
        if a >= b {
            // Empty as solved: start from its nearest pixel, then grow.
            b = a.min(x1);
            a = b;
        }
        while a > x0 && self.contains(a - 1, y) {
            a -= 1;
        }
        while b < x1 && self.contains(b, y) {
            b += 1;
        }
        while a < b && !self.contains(a, y) {
            a += 1;
        }
        while b > a && !self.contains(b - 1, y) {
            b -= 1;
        }
        (a, b)
    }
}
