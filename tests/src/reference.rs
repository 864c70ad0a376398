//! Slow, obviously-correct references for the rasterizer, written from the engine's
//! documented conventions only (never from its code):
//!
//! * [`Raster`]: exact coverage. A world point `p` goes to clip space as
//!   `camera.clip_from_world() * p` (evaluated here in `f64`), to the screen as
//!   `x = (ndc_x * 0.5 + 0.5) * W`, `y = (0.5 - ndc_y * 0.5) * H` (y down, pixel centres at
//!   `(i + 0.5, j + 0.5)`), and is snapped to `round(v * 256)` in `i64`. A pixel centre is
//!   covered when it is strictly inside all three edges, or exactly on an edge that is a
//!   *top* edge (exactly horizontal, triangle below it) or a *left* edge (triangle to its
//!   right). Only valid for triangles the pipeline does not clip (wholly between the near
//!   and far planes); [`Raster::screen_tri`] refuses the others.
//! * [`RayCast`]: analytic visibility. A ray through a pixel centre, cut to the segment
//!   between the near and far planes, is intersected with each triangle in `f64`; the
//!   nearest hit wins. Depth comes from the view distance of the hit. It needs no clipping,
//!   so it is the reference for triangles that cross the near plane or are huge.
//!
//! Both are plain loops over pixels and triangles: slow, but each step is one line of
//! textbook geometry.

use engine::Camera;
use glam::{DMat4, DVec3, DVec4, Vec3};

/// Sub-pixel steps per pixel (8 bits).
pub const SUBPIXEL: i64 = 256;

/// Counts, per pixel (row-major), how many triangles cover each pixel centre.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Counts {
    pub width: u32,
    pub height: u32,
    pub counts: Vec<u32>,
}

impl Counts {
    pub fn new(width: u32, height: u32) -> Self {
        Counts {
            width,
            height,
            counts: vec![0; width as usize * height as usize],
        }
    }

    pub fn get(&self, x: u32, y: u32) -> u32 {
        self.counts[(y * self.width + x) as usize]
    }
}

/// A triangle on the screen, snapped to fixed point (`SUBPIXEL` steps per pixel, y down).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ScreenTri {
    pub v: [(i64, i64); 3],
}

impl ScreenTri {
    /// Twice the signed area in y-down screen coordinates. Negative means clockwise on the
    /// screen, which is counter-clockwise in NDC (y up): a front face.
    pub fn area2(&self) -> i128 {
        let [(ax, ay), (bx, by), (cx, cy)] = self.v;
        (bx - ax) as i128 * (cy - ay) as i128 - (cx - ax) as i128 * (by - ay) as i128
    }

    pub fn is_front(&self) -> bool {
        self.area2() < 0
    }

    /// Does the triangle own the centre of pixel `(px, py)` under the top-left rule?
    pub fn covers(&self, px: i64, py: i64) -> bool {
        if self.area2() == 0 {
            return false;
        }
        let s = (px * SUBPIXEL + SUBPIXEL / 2, py * SUBPIXEL + SUBPIXEL / 2);
        (0..3).all(|i| {
            let p = self.v[i];
            let q = self.v[(i + 1) % 3];
            let r = self.v[(i + 2) % 3];
            // Which side of the line p -> q a point is on.
            let side = |t: (i64, i64)| -> i128 {
                (q.0 - p.0) as i128 * (t.1 - p.1) as i128
                    - (q.1 - p.1) as i128 * (t.0 - p.0) as i128
            };
            let inside_sign = side(r).signum();
            let e = side(s) * inside_sign;
            if e != 0 {
                return e > 0;
            }
            // Exactly on the edge: the gradient of `side`, turned to point inside, tells
            // which way the triangle lies from this edge.
            let nx = -((q.1 - p.1) as i128) * inside_sign;
            let ny = (q.0 - p.0) as i128 * inside_sign;
            let left = nx > 0; // the triangle is to the right of the edge
            let top = q.1 == p.1 && ny > 0; // horizontal, the triangle below it (y down)
            left || top
        })
    }

    /// Signed distances (pixels, positive inside) from the centre of pixel `(px, py)` to
    /// the three edge lines.
    pub fn edge_distances(&self, px: i64, py: i64) -> [f64; 3] {
        let s = (
            (px as f64 + 0.5) * SUBPIXEL as f64,
            (py as f64 + 0.5) * SUBPIXEL as f64,
        );
        std::array::from_fn(|i| {
            let p = self.v[i];
            let q = self.v[(i + 1) % 3];
            let r = self.v[(i + 2) % 3];
            let (dx, dy) = ((q.0 - p.0) as f64, (q.1 - p.1) as f64);
            let side = |t: (f64, f64)| dx * (t.1 - p.1 as f64) - dy * (t.0 - p.0 as f64);
            let sign = side((r.0 as f64, r.1 as f64)).signum();
            let len = (dx * dx + dy * dy).sqrt().max(1e-300);
            side(s) * sign / len / SUBPIXEL as f64
        })
    }

    /// Is the pixel centre within `eps` pixels of the triangle's boundary (inside the
    /// triangle grown by `eps`, but not inside it shrunk by `eps`)?
    pub fn near_boundary(&self, px: i64, py: i64, eps: f64) -> bool {
        if self.area2() == 0 {
            return false;
        }
        let d = self.edge_distances(px, py);
        d.iter().all(|&e| e > -eps) && !d.iter().all(|&e| e > eps)
    }

    /// Inclusive pixel range whose centres can be inside, clamped to `w` x `h`.
    pub fn pixel_box(&self, w: u32, h: u32) -> Option<(i64, i64, i64, i64)> {
        let xs = self.v.map(|v| v.0);
        let ys = self.v.map(|v| v.1);
        let lo = |m: i64| (m - SUBPIXEL / 2).div_euclid(SUBPIXEL);
        let hi = |m: i64| (m - SUBPIXEL / 2).div_euclid(SUBPIXEL) + 1;
        let x0 = lo(*xs.iter().min()?).max(0);
        let y0 = lo(*ys.iter().min()?).max(0);
        let x1 = hi(*xs.iter().max()?).min(w as i64 - 1);
        let y1 = hi(*ys.iter().max()?).min(h as i64 - 1);
        (x0 <= x1 && y0 <= y1).then_some((x0, y0, x1, y1))
    }
}

/// The exact coverage reference for one camera and target size.
#[derive(Clone, Copy, Debug)]
pub struct Raster {
    pub clip_from_world: DMat4,
    pub width: u32,
    pub height: u32,
}

/// Why [`Raster::screen_tri`] cannot place a triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NotOnScreen {
    /// A vertex is not finite.
    NonFinite,
    /// A vertex is outside the near/far range: the pipeline would clip this triangle.
    NeedsClipping,
}

impl Raster {
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        Raster {
            clip_from_world: camera.clip_from_world().as_dmat4(),
            width,
            height,
        }
    }

    /// Screen position (pixels, y down) of a world point, unsnapped; `None` unless the
    /// point is strictly in front of the eye.
    pub fn to_screen(&self, p: Vec3) -> Option<(f64, f64)> {
        let c = self.clip_from_world * DVec4::new(p.x as f64, p.y as f64, p.z as f64, 1.0);
        if c.w <= 0.0 || !c.is_finite() {
            return None;
        }
        let (nx, ny) = (c.x / c.w, c.y / c.w);
        Some((
            (nx * 0.5 + 0.5) * self.width as f64,
            (0.5 - ny * 0.5) * self.height as f64,
        ))
    }

    /// The snapped screen triangle of world-space vertices.
    pub fn screen_tri(&self, p: [Vec3; 3]) -> Result<ScreenTri, NotOnScreen> {
        let mut v = [(0i64, 0i64); 3];
        for k in 0..3 {
            let c =
                self.clip_from_world * DVec4::new(p[k].x as f64, p[k].y as f64, p[k].z as f64, 1.0);
            if !c.is_finite() {
                return Err(NotOnScreen::NonFinite);
            }
            // Reversed depth: z / w is 1 on the near plane and 0 on the far plane.
            if !(c.w > 0.0 && c.z >= 0.0 && c.z <= c.w) {
                return Err(NotOnScreen::NeedsClipping);
            }
            let (sx, sy) = self.to_screen(p[k]).ok_or(NotOnScreen::NeedsClipping)?;
            v[k] = (
                (sx * SUBPIXEL as f64).round() as i64,
                (sy * SUBPIXEL as f64).round() as i64,
            );
        }
        Ok(ScreenTri { v })
    }

    /// Adds the coverage of `tri` to `counts`; returns how many pixels it covered.
    /// `cull_back` skips back faces (counter-clockwise in NDC is front).
    pub fn add(&self, counts: &mut Counts, tri: &ScreenTri, cull_back: bool) -> u64 {
        if cull_back && !tri.is_front() {
            return 0;
        }
        let Some((x0, y0, x1, y1)) = tri.pixel_box(self.width, self.height) else {
            return 0;
        };
        let mut n = 0;
        for y in y0..=y1 {
            for x in x0..=x1 {
                if tri.covers(x, y) {
                    counts.counts[(y * self.width as i64 + x) as usize] += 1;
                    n += 1;
                }
            }
        }
        n
    }

    /// Per-pixel coverage counts of a list of world-space triangles.
    ///
    /// # Panics
    /// If a triangle would be clipped by the pipeline (use [`RayCast`] for those).
    pub fn counts(&self, tris: &[[Vec3; 3]], cull_back: bool) -> Counts {
        let mut c = Counts::new(self.width, self.height);
        for t in tris {
            let st = self
                .screen_tri(*t)
                .unwrap_or_else(|e| panic!("reference raster cannot place {t:?}: {e:?}"));
            self.add(&mut c, &st, cull_back);
        }
        c
    }

    /// Pixels whose centre lies within `eps` pixels of an edge of any of the triangles.
    pub fn near_edges(&self, tris: &[[Vec3; 3]], eps: f64) -> Vec<bool> {
        let mut out = vec![false; self.width as usize * self.height as usize];
        for t in tris {
            let Ok(st) = self.screen_tri(*t) else {
                continue;
            };
            let Some((x0, y0, x1, y1)) = st.pixel_box(self.width, self.height) else {
                continue;
            };
            let g = eps.ceil() as i64 + 1;
            for y in (y0 - g).max(0)..=(y1 + g).min(self.height as i64 - 1) {
                for x in (x0 - g).max(0)..=(x1 + g).min(self.width as i64 - 1) {
                    if st.near_boundary(x, y, eps) {
                        out[(y * self.width as i64 + x) as usize] = true;
                    }
                }
            }
        }
        out
    }
}

/// A ray hit: which triangle, how far along the view direction, and its reversed depth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub tri: usize,
    /// View distance (view-space -z for perspective and orthographic cameras alike).
    pub dist: f64,
}

/// The analytic ray-cast reference for one camera and target size.
#[derive(Clone, Copy, Debug)]
pub struct RayCast {
    world_from_clip: DMat4,
    view: DMat4,
    pub width: u32,
    pub height: u32,
    pub near: f64,
    pub far: f64,
    pub perspective: bool,
}

/// Möller-Trumbore: the parameter `t` of the segment `o + t d` where it meets triangle
/// `v`, with the barycentric test inclusive. `None` for a miss or a parallel segment.
pub fn intersect(o: DVec3, d: DVec3, v: [DVec3; 3]) -> Option<f64> {
    let e1 = v[1] - v[0];
    let e2 = v[2] - v[0];
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - v[0];
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let w = d.dot(q) * inv;
    if w < 0.0 || u + w > 1.0 {
        return None;
    }
    Some(e2.dot(q) * inv)
}

impl RayCast {
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        let (near, far) = camera.near_far();
        RayCast {
            world_from_clip: camera.clip_from_world().as_dmat4().inverse(),
            view: camera.view.as_dmat4(),
            width,
            height,
            near: near as f64,
            far: far as f64,
            perspective: camera.projection.is_perspective(),
        }
    }

    /// The visible part of the ray through screen point `(sx, sy)` (pixels, y down): the
    /// world-space points on the near and far planes.
    pub fn segment(&self, sx: f64, sy: f64) -> (DVec3, DVec3) {
        let nx = sx / self.width as f64 * 2.0 - 1.0;
        let ny = 1.0 - sy / self.height as f64 * 2.0;
        // Reversed depth: NDC z = 1 is the near plane, 0 the far plane.
        let a = self.world_from_clip * DVec4::new(nx, ny, 1.0, 1.0);
        let b = self.world_from_clip * DVec4::new(nx, ny, 0.0, 1.0);
        (a.truncate() / a.w, b.truncate() / b.w)
    }

    /// View distance of a world point.
    pub fn view_distance(&self, p: DVec3) -> f64 {
        -(self.view * p.extend(1.0)).z
    }

    /// The reversed depth the conventions assign to a view distance: 1 on the near plane,
    /// 0 on the far plane, affine in `1 / dist` (perspective) or in `dist` (orthographic).
    pub fn reversed_depth(&self, dist: f64) -> f64 {
        let (n, f) = (self.near, self.far);
        if self.perspective {
            n * (f - dist) / (dist * (f - n))
        } else {
            (f - dist) / (f - n)
        }
    }

    /// The inverse of [`RayCast::reversed_depth`].
    pub fn distance_from_reversed(&self, d: f64) -> f64 {
        let (n, f) = (self.near, self.far);
        if self.perspective {
            n * f / (d * (f - n) + n)
        } else {
            f - d * (f - n)
        }
    }

    /// Nearest hit of the visible ray segment through `(sx, sy)` with `tris`.
    /// `cull_back` ignores triangles seen from their back (clockwise) side.
    pub fn cast(&self, sx: f64, sy: f64, tris: &[[DVec3; 3]], cull_back: bool) -> Option<Hit> {
        let (a, b) = self.segment(sx, sy);
        let d = b - a;
        let mut best: Option<Hit> = None;
        for (i, t) in tris.iter().enumerate() {
            if cull_back {
                // Counter-clockwise seen from the front: its normal faces the viewer.
                let n = (t[1] - t[0]).cross(t[2] - t[0]);
                if n.dot(d) >= 0.0 {
                    continue;
                }
            }
            let Some(s) = intersect(a, d, *t) else {
                continue;
            };
            if !(0.0..=1.0).contains(&s) {
                continue;
            }
            let dist = self.view_distance(a + d * s);
            let nearer = match best {
                None => true,
                Some(h) => dist < h.dist,
            };
            if nearer {
                best = Some(Hit { tri: i, dist });
            }
        }
        best
    }

    /// Every surface the visible ray segment through `(sx, sy)` crosses, nearest first:
    /// the view distances of its hits with `tris`, hits closer than `merge` (view units) to
    /// the previous one counted once (a ray through the edge shared by two triangles of one
    /// surface hits both). The k-th entry is what depth peeling's layer k shows.
    pub fn cast_all(&self, sx: f64, sy: f64, tris: &[[DVec3; 3]], merge: f64) -> Vec<f64> {
        let (a, b) = self.segment(sx, sy);
        let d = b - a;
        let mut hits: Vec<f64> = tris
            .iter()
            .filter_map(|t| intersect(a, d, *t))
            .filter(|s| (0.0..=1.0).contains(s))
            .map(|s| self.view_distance(a + d * s))
            .collect();
        hits.sort_by(f64::total_cmp);
        hits.dedup_by(|later, kept| *later - *kept < merge);
        hits
    }

    /// [`RayCast::cast`] at the centre of pixel `(x, y)`.
    pub fn cast_pixel(&self, x: u32, y: u32, tris: &[[DVec3; 3]], cull_back: bool) -> Option<Hit> {
        self.cast(x as f64 + 0.5, y as f64 + 0.5, tris, cull_back)
    }

    /// The answers at 8 points on a circle of radius `eps` pixels around the centre of
    /// pixel `(x, y)`: a pixel whose centre is that close to a boundary sees different
    /// answers there.
    pub fn ring(
        &self,
        x: u32,
        y: u32,
        eps: f64,
        tris: &[[DVec3; 3]],
        cull_back: bool,
    ) -> [Option<Hit>; 8] {
        std::array::from_fn(|k| {
            let a = k as f64 * std::f64::consts::FRAC_PI_4;
            self.cast(
                x as f64 + 0.5 + eps * a.cos(),
                y as f64 + 0.5 + eps * a.sin(),
                tris,
                cull_back,
            )
        })
    }
}

/// World-space triangles in `f64`.
pub fn to_f64(tris: &[[Vec3; 3]]) -> Vec<[DVec3; 3]> {
    tris.iter().map(|t| t.map(|p| p.as_dvec3())).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(v: [(i64, i64); 3]) -> ScreenTri {
        ScreenTri {
            v: v.map(|(x, y)| (x * SUBPIXEL / 2, y * SUBPIXEL / 2)),
        }
    }

    /// Coordinates in half pixels: (1, 1) is the centre of pixel (0, 0).
    #[test]
    fn top_left_rule_by_hand() {
        // Axis-aligned square [1, 5] x [1, 5] half-pixels = pixel centres (0,0) .. (2,2) on
        // its boundary, split along a diagonal through centres (0,0), (1,1), (2,2).
        let upper = tri([(1, 1), (5, 1), (5, 5)]);
        let lower = tri([(1, 1), (5, 5), (1, 5)]);
        let owners = |x, y| (upper.covers(x, y) as u8, lower.covers(x, y) as u8);
        // The diagonal is a left edge of `upper` (the triangle is to its right) and a right
        // edge of `lower`, so `upper` owns the pixel centres on it, corner (0, 0) included.
        assert_eq!(owners(0, 0), (1, 0));
        assert_eq!(owners(1, 1), (1, 0));
        assert_eq!(
            owners(1, 0),
            (1, 0),
            "top edge belongs to the triangle below"
        );
        assert_eq!(
            owners(0, 1),
            (0, 1),
            "left edge belongs to the triangle right of it"
        );
        assert_eq!(owners(0, 2), (0, 0), "bottom edge is not owned");
        assert_eq!(owners(2, 1), (0, 0), "right edge is not owned");
        assert_eq!(owners(2, 2), (0, 0), "bottom-right corner is not owned");
        assert_eq!(owners(2, 0), (0, 0), "top-right corner: right edge");
        // Winding does not matter.
        let rev = ScreenTri {
            v: [upper.v[0], upper.v[2], upper.v[1]],
        };
        for y in -1..4 {
            for x in -1..4 {
                assert_eq!(rev.covers(x, y), upper.covers(x, y));
            }
        }
        assert!(!upper.is_front() && rev.is_front());
    }

    #[test]
    fn degenerate_covers_nothing() {
        let line = tri([(1, 1), (3, 3), (5, 5)]);
        assert!((0..4).all(|i| !line.covers(i, i)));
    }

    #[test]
    fn ray_hits_and_misses() {
        let v = [
            DVec3::new(-1.0, -1.0, -5.0),
            DVec3::new(1.0, -1.0, -5.0),
            DVec3::new(0.0, 1.0, -5.0),
        ];
        let t = intersect(DVec3::ZERO, DVec3::new(0.0, 0.0, -10.0), v).unwrap();
        assert!((t - 0.5).abs() < 1e-15);
        assert!(intersect(DVec3::ZERO, DVec3::new(1.0, 0.0, 0.0), v).is_none());
        assert!(intersect(DVec3::new(5.0, 0.0, 0.0), DVec3::new(0.0, 0.0, -10.0), v).is_none());
    }

    #[test]
    fn depth_formulas_invert_each_other_and_hit_the_ends() {
        let cam = Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 1.0, 1.0)
            .with_depth_range(0.1, 100.0);
        let rc = RayCast::new(&cam, 10, 10);
        assert!((rc.reversed_depth(rc.near) - 1.0).abs() < 1e-12);
        assert!(rc.reversed_depth(rc.far).abs() < 1e-12);
        for d in [0.2, 1.0, 7.5, 99.0] {
            assert!((rc.distance_from_reversed(rc.reversed_depth(d)) - d).abs() < 1e-9 * d);
        }
        // The centre ray runs along the view direction from the near to the far plane.
        let (a, b) = rc.segment(5.0, 5.0);
        assert!((a - DVec3::new(0.0, 0.0, 2.9)).length() < 1e-6, "{a}");
        assert!((b - DVec3::new(0.0, 0.0, -97.0)).length() < 1e-3, "{b}");
    }
}
