//! The warp of a layer's image: the affine map (or the perspective one, a homography) from
//! its texels to the screen fitted (least squares) to its characteristic points, and what it
//! costs in accuracy: how far the points' true projections lie from where the warp puts
//! them, and how far its scale has drifted from the image's.

use engine::Camera;
use glam::{DMat3, DVec3, Mat2, Mat3, Vec2, Vec3, Vec3Swizzles, Vec4Swizzles};

/// `screen = m * texel + t`, in pixels (x right, y down, pixel centres at half-integers,
/// as [`Camera::crop`] and [`Camera::pixel_ray`] take them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Affine {
    /// Linear part: screen pixels per texel along each texel axis (its columns).
    pub m: Mat2,
    /// Translation: where texel (0, 0)'s corner lands on screen, pixels.
    pub t: Vec2,
}

impl Affine {
    /// Texels `scale` pixels wide with texel 0's corner at screen `origin`.
    pub fn scaled(scale: f32, origin: Vec2) -> Affine {
        Affine {
            m: Mat2::from_diagonal(Vec2::splat(scale)),
            t: origin,
        }
    }

    /// The screen position of `texel`, pixels.
    pub fn apply(&self, texel: Vec2) -> Vec2 {
        self.m * texel + self.t
    }

    /// The least-squares affine map taking `from[k]` to `to[k]`. Directions in which the
    /// points do not spread (a flat layer seen edge-on puts its corners on a line) keep
    /// `prior`'s scale, so the map stays invertible: a little ridge toward `prior` weighs
    /// nothing where the points spread.
    pub fn fit(from: &[Vec2], to: &[Vec2], prior: f32) -> Affine {
        let n = from.len().min(to.len()).max(1) as f32;
        let fu = from.iter().copied().sum::<Vec2>() / n;
        let fq = to.iter().copied().sum::<Vec2>() / n;
        let (mut uu, mut qu) = (Mat2::ZERO, Mat2::ZERO);
        for (&u, &q) in from.iter().zip(to) {
            let (du, dq) = (u - fu, q - fq);
            // Outer products: column j of `a b^T` is `a * b[j]`.
            uu += Mat2::from_cols(du * du.x, du * du.y);
            qu += Mat2::from_cols(dq * du.x, dq * du.y);
        }
        let ridge = 1e-6 * (uu.x_axis.x + uu.y_axis.y) + 1e-9;
        let uu = uu + Mat2::from_diagonal(Vec2::splat(ridge));
        let qu = qu + Mat2::from_diagonal(Vec2::splat(ridge * prior));
        let m = qu * uu.inverse();
        let m = if m.is_finite() {
            m
        } else {
            Mat2::from_diagonal(Vec2::splat(prior))
        };
        Affine { m, t: fq - m * fu }
    }

    /// The largest distance between where the map puts `from[k]` and `to[k]`, pixels.
    pub fn max_error(&self, from: &[Vec2], to: &[Vec2]) -> f32 {
        from.iter()
            .zip(to)
            .map(|(&u, &q)| self.apply(u).distance(q))
            .fold(0.0, f32::max)
    }

    /// The map's largest and smallest stretch (singular values of `m`).
    pub fn stretch(&self) -> (f32, f32) {
        let [a, c, b, d] = self.m.to_cols_array();
        let (e, f) = ((a + d) * 0.5, (a - d) * 0.5);
        let (g, h) = ((c + b) * 0.5, (c - b) * 0.5);
        let (q, r) = (e.hypot(h), f.hypot(g));
        (q + r, (q - r).abs())
    }

    /// The inverse map (screen to texels), `None` when `m` is singular.
    pub fn inverse(&self) -> Option<Affine> {
        let det = self.m.determinant();
        if det.abs() < 1e-12 || !det.is_finite() {
            return None;
        }
        let m = self.m.inverse();
        Some(Affine {
            m,
            t: -(m * self.t),
        })
    }
}

/// `screen ~ h * (texel, 1)`: a perspective warp (the affine ones have `(0, 0, 1)` for a
/// bottom row). Pixels as [`Affine`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Homography {
    /// The 3x3 matrix taking homogeneous texel coordinates `(x, y, 1)` to homogeneous
    /// screen pixels (divide by the third component).
    pub h: Mat3,
}

impl From<Affine> for Homography {
    fn from(a: Affine) -> Self {
        Homography {
            h: Mat3::from_cols(
                a.m.x_axis.extend(0.0),
                a.m.y_axis.extend(0.0),
                a.t.extend(1.0),
            ),
        }
    }
}

impl Homography {
    /// `texel` on the screen, and the homogeneous weight it came with (`None` where the
    /// weight is not positive: behind the warp's horizon).
    pub fn map(&self, texel: Vec2) -> Option<(Vec2, f32)> {
        let p = self.h * texel.extend(1.0);
        (p.z > 1e-12 && p.is_finite()).then(|| (p.xy() / p.z, p.z))
    }

    /// The largest distance between where the warp puts `from[k]` and `to[k]` (infinite
    /// when one is behind its horizon).
    pub fn max_error(&self, from: &[Vec2], to: &[Vec2]) -> f32 {
        from.iter()
            .zip(to)
            .map(|(&u, &q)| self.map(u).map_or(f32::INFINITY, |(p, _)| p.distance(q)))
            .fold(0.0, f32::max)
    }

    /// The screen-to-texel warp, `None` when singular.
    pub fn inverse(&self) -> Option<Homography> {
        let det = self.h.determinant();
        (det.abs() > 1e-20 && det.is_finite()).then(|| Homography {
            h: self.h.inverse(),
        })
    }

    /// The warp's local linear part (pixels per texel) at `texel`.
    pub fn jacobian(&self, texel: Vec2) -> Mat2 {
        let p = self.h * texel.extend(1.0);
        let w = p.z;
        let r = self.h.row(2);
        // d(x/w)/du = (h00 w - x h20) / w^2, and so on.
        let col = |k: usize| {
            let c = self.h.col(k);
            Vec2::new(c.x * w - p.x * r[k], c.y * w - p.y * r[k]) / (w * w)
        };
        Mat2::from_cols(col(0), col(1))
    }

    /// The least-squares perspective map taking `from[k]` to `to[k]` (the direct linear
    /// transform on points normalised to mean 0 and mean distance sqrt 2, Hartley's
    /// conditioning); `None` when the points do not fix one (fewer than four in general
    /// position: a flat layer seen edge-on).
    pub fn fit(from: &[Vec2], to: &[Vec2]) -> Option<Homography> {
        let n = from.len().min(to.len());
        if n < 4 {
            return None;
        }
        let (tf, tt) = (normaliser(&from[..n]), normaliser(&to[..n]));
        // Normal equations of the 2n x 8 system with h22 = 1.
        let mut ata = [[0f64; 8]; 8];
        let mut atb = [0f64; 8];
        for (&u, &q) in from.iter().zip(to) {
            let u = tf * DVec3::new(u.x as f64, u.y as f64, 1.0);
            let q = tt * DVec3::new(q.x as f64, q.y as f64, 1.0);
            let rows = [
                ([u.x, u.y, 1.0, 0.0, 0.0, 0.0, -u.x * q.x, -u.y * q.x], q.x),
                ([0.0, 0.0, 0.0, u.x, u.y, 1.0, -u.x * q.y, -u.y * q.y], q.y),
            ];
            for (a, b) in rows {
                for i in 0..8 {
                    atb[i] += a[i] * b;
                    for j in 0..8 {
                        ata[i][j] += a[i] * a[j];
                    }
                }
            }
        }
        let x = solve8(ata, atb)?;
        let hn = DMat3::from_cols_array(&[x[0], x[3], x[6], x[1], x[4], x[7], x[2], x[5], 1.0]);
        let h = tt.inverse() * hn * tf;
        let h = h / h.z_axis.z;
        let h = h.as_mat3();
        h.is_finite().then_some(Homography { h })
    }
}

/// The similarity that moves `points` to mean 0 and mean distance sqrt 2.
fn normaliser(points: &[Vec2]) -> DMat3 {
    let n = points.len().max(1) as f64;
    let mean = points.iter().map(|p| p.as_dvec2()).sum::<glam::DVec2>() / n;
    let spread = points
        .iter()
        .map(|p| (p.as_dvec2() - mean).length())
        .sum::<f64>()
        / n;
    let s = if spread > 1e-12 {
        std::f64::consts::SQRT_2 / spread
    } else {
        1.0
    };
    DMat3::from_cols(
        DVec3::new(s, 0.0, 0.0),
        DVec3::new(0.0, s, 0.0),
        DVec3::new(-s * mean.x, -s * mean.y, 1.0),
    )
}

/// Solves the 8 x 8 system by Gaussian elimination with partial pivoting; `None` when it is
/// (nearly) singular.
fn solve8(mut a: [[f64; 8]; 8], mut b: [f64; 8]) -> Option<[f64; 8]> {
    let scale = a
        .iter()
        .flatten()
        .fold(0f64, |m, v| m.max(v.abs()))
        .max(1e-300);
    for c in 0..8 {
        let p = (c..8).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))?;
        if a[p][c].abs() < 1e-10 * scale {
            return None;
        }
        a.swap(c, p);
        b.swap(c, p);
        for r in c + 1..8 {
            let f = a[r][c] / a[c][c];
            for k in c..8 {
                a[r][k] -= f * a[c][k];
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = [0f64; 8];
    for c in (0..8).rev() {
        let s: f64 = (c + 1..8).map(|k| a[c][k] * x[k]).sum();
        x[c] = (b[c] - s) / a[c][c];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Where `p` lands on a `width` x `height` image of `camera` (pixels) and its distance
/// along the view direction; `None` at or behind the near plane.
pub fn project(camera: &Camera, p: Vec3, width: u32, height: u32) -> Option<(Vec2, f32)> {
    Projector::new(camera, width, height).project(p)
}

/// The world point at pixel `px` of a `width` x `height` image of `camera`, `z` along its
/// view direction (the inverse of [`project`]).
pub fn unproject(camera: &Camera, px: Vec2, z: f32, width: u32, height: u32) -> Vec3 {
    Unprojector::new(camera, width, height).unproject(px, z)
}

/// [`project`] for many points of one camera and image: the matrix taken once.
#[derive(Clone, Copy, Debug)]
pub struct Projector {
    view: glam::Mat4,
    clip: glam::Mat4,
    near: f32,
    size: Vec2,
}

impl Projector {
    /// A projector for `camera` rendering a `width` x `height` image.
    pub fn new(camera: &Camera, width: u32, height: u32) -> Projector {
        Projector {
            view: camera.view,
            clip: camera.gl_view_proj(),
            near: camera.near_far().0,
            size: Vec2::new(width as f32, height as f32),
        }
    }

    /// [`project`].
    pub fn project(&self, p: Vec3) -> Option<(Vec2, f32)> {
        let z = -(self.view * p.extend(1.0)).z;
        if z.is_nan() || z <= self.near {
            return None;
        }
        let clip = self.clip * p.extend(1.0);
        let ndc = clip.xy() / clip.w;
        let px = Vec2::new(ndc.x + 1.0, 1.0 - ndc.y) * 0.5 * self.size;
        px.is_finite().then_some((px, z))
    }
}

/// [`unproject`] for many points of one camera and image: the inverses taken once.
#[derive(Clone, Copy, Debug)]
pub struct Unprojector {
    unclip: glam::Mat4,
    eye: Vec3,
    forward: Vec3,
    size: Vec2,
}

impl Unprojector {
    /// An unprojector for `camera` rendering a `width` x `height` image.
    pub fn new(camera: &Camera, width: u32, height: u32) -> Unprojector {
        let to_world = camera.view.inverse();
        Unprojector {
            unclip: camera.gl_view_proj().inverse(),
            eye: to_world.w_axis.truncate(),
            forward: -to_world.z_axis.truncate().normalize_or_zero(),
            size: Vec2::new(width as f32, height as f32),
        }
    }

    /// [`unproject`]: the point along the pixel's ray (through the near and far planes, as
    /// [`Camera::pixel_ray`]) at `z` along the view direction.
    pub fn unproject(&self, px: Vec2, z: f32) -> Vec3 {
        let ndc = Vec2::new(
            2.0 * px.x / self.size.x - 1.0,
            1.0 - 2.0 * px.y / self.size.y,
        );
        let near = self.unclip * glam::Vec4::new(ndc.x, ndc.y, -1.0, 1.0);
        let far = self.unclip * glam::Vec4::new(ndc.x, ndc.y, 1.0, 1.0);
        let origin = near.truncate() / near.w;
        let dir = (far.truncate() / far.w - origin).normalize_or_zero();
        let along = self.forward.dot(dir);
        let t = if along.abs() > 1e-9 {
            (z - self.forward.dot(origin - self.eye)) / along
        } else {
            0.0
        };
        origin + dir * t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pts() -> Vec<Vec2> {
        (0..8)
            .map(|k| Vec2::new((k * 37 % 11) as f32, (k * 23 % 7) as f32 * 1.5))
            .collect()
    }

    #[test]
    fn fits_an_affine_map_exactly() {
        let truth = Affine {
            m: Mat2::from_cols(Vec2::new(1.3, -0.2), Vec2::new(0.4, 0.9)),
            t: Vec2::new(12.0, -3.0),
        };
        let from = pts();
        let to: Vec<Vec2> = from.iter().map(|&u| truth.apply(u)).collect();
        let fit = Affine::fit(&from, &to, 1.0);
        assert!(fit.max_error(&from, &to) < 1e-3, "{fit:?}");
        let back = fit.inverse().expect("invertible");
        assert!(
            back.apply(fit.apply(Vec2::new(3.0, 4.0)))
                .distance(Vec2::new(3.0, 4.0))
                < 1e-3
        );
        // A rotation by 30 degrees scaled by 2 stretches by 2 both ways.
        let r = Affine {
            m: Mat2::from_angle(0.52) * 2.0,
            t: Vec2::ZERO,
        };
        let (hi, lo) = r.stretch();
        assert!(
            (hi - 2.0).abs() < 1e-5 && (lo - 2.0).abs() < 1e-5,
            "{hi} {lo}"
        );
        let shear = Affine {
            m: Mat2::from_cols(Vec2::new(3.0, 0.0), Vec2::new(0.0, 0.5)),
            t: Vec2::ZERO,
        };
        assert_eq!(shear.stretch(), (3.0, 0.5));
    }

    #[test]
    fn collinear_points_keep_the_prior_scale_across_the_line() {
        let from: Vec<Vec2> = (0..8).map(|k| Vec2::new(k as f32, 5.0)).collect();
        let to: Vec<Vec2> = from
            .iter()
            .map(|u| Vec2::new(2.0 * u.x + 1.0, 7.0))
            .collect();
        let fit = Affine::fit(&from, &to, 2.0);
        assert!(fit.m.is_finite() && fit.t.is_finite());
        assert!(fit.max_error(&from, &to) < 1e-3);
        let (hi, lo) = fit.stretch();
        assert!(
            (hi - 2.0).abs() < 1e-3 && (lo - 2.0).abs() < 1e-3,
            "{hi} {lo}"
        );
        let one = Affine::fit(&[Vec2::ONE], &[Vec2::new(4.0, 4.0)], 1.0);
        assert!(one.apply(Vec2::ONE).distance(Vec2::new(4.0, 4.0)) < 1e-4);
    }

    #[test]
    fn fits_a_perspective_map_exactly_and_refuses_a_line() {
        let truth = Homography {
            h: Mat3::from_cols(
                Vec3::new(1.2, 0.1, 0.002),
                Vec3::new(-0.3, 0.9, -0.001),
                Vec3::new(40.0, 12.0, 1.0),
            ),
        };
        let from = pts();
        let to: Vec<Vec2> = from
            .iter()
            .map(|&u| truth.map(u).expect("in front").0)
            .collect();
        let fit = Homography::fit(&from, &to).expect("a fit");
        assert!(fit.max_error(&from, &to) < 1e-3, "{fit:?}");
        // The Jacobian against finite differences.
        let at = Vec2::new(4.0, 3.0);
        let j = fit.jacobian(at);
        let e = 1e-2;
        let d = |dv: Vec2| (fit.map(at + dv).unwrap().0 - fit.map(at - dv).unwrap().0) / (2.0 * e);
        assert!((j.x_axis - d(Vec2::X * e)).length() < 1e-2, "{j:?}");
        assert!((j.y_axis - d(Vec2::Y * e)).length() < 1e-2, "{j:?}");
        let back = fit.inverse().expect("invertible");
        let p = fit.map(at).unwrap().0;
        assert!(back.map(p).unwrap().0.distance(at) < 1e-3);
        // An affine map is a homography.
        let a = Affine::scaled(2.0, Vec2::new(3.0, 4.0));
        let h = Homography::from(a);
        assert!(h.map(Vec2::ONE).unwrap().0.distance(a.apply(Vec2::ONE)) < 1e-6);
        // Points on a line fix no homography.
        let line: Vec<Vec2> = (0..8).map(|k| Vec2::new(k as f32, 2.0)).collect();
        assert!(Homography::fit(&line, &line).is_none());
    }

    #[test]
    fn unproject_inverts_project() {
        let camera = Camera::look_at(Vec3::new(1.0, 2.0, 5.0), Vec3::ZERO, Vec3::Y, 1.0, 1.5)
            .with_depth_range(0.1, 100.0);
        let p = Vec3::new(0.3, -0.4, 0.2);
        let (px, z) = project(&camera, p, 120, 80).expect("in front");
        assert!(unproject(&camera, px, z, 120, 80).distance(p) < 1e-4);
        assert!(project(&camera, Vec3::new(2.0, 4.0, 10.0), 120, 80).is_none());
    }
}
