//! McMillan's warping equation: where a reference pixel with known depth lands in another
//! camera's image, evaluated incrementally along a row.
//!
//! For a reference pixel centre `x1 = (u, v, 1)` (pixels, y down) with depth `z` along the
//! reference camera's optical axis, its generalised disparity is `δ = 1 / z` and
//!
//! ```text
//! x2 ≅ A x1 + δ b,      A = K2 R K1⁻¹,   b = K2 t
//! ```
//!
//! where `K` maps view space to homogeneous pixels, `(R, t)` takes reference view space to
//! target view space, and `≅` is equality up to scale: the target pixel is `(h.x / h.z,
//! h.y / h.z)` for `h = A x1 + δ b`. This is McMillan's `x2 ≅ δ(x1) P2⁻¹(C1 − C2) +
//! P2⁻¹ P1 x1` with our pixel conventions. Along a row `A x1` grows by `A`'s first column per
//! pixel, so a sample costs three adds, three multiply-adds for `δ b`, and one divide. `h.z`
//! is the target depth times `δ` (positive in front of the target eye), so the target depth
//! is `h.z / δ` and a sample at infinity (`δ = 0`, sky) moves by the rotation alone.

use crate::core::Intrinsics;
use engine::Camera;
use glam::{Mat3, Vec2, Vec3};

/// The warp from one camera's image to another's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Equation {
    /// Columns of `A`: `A x1 = u a[0] + v a[1] + a[2]`.
    pub a: [Vec3; 3],
    /// `K2 t`: how disparity moves a sample.
    pub b: Vec3,
    /// The target eye in reference homogeneous pixels (`K1` times the eye in reference view
    /// space): its `z` is positive when the target eye is in front of the reference camera.
    pub epipole: Vec3,
}

/// View space -> homogeneous pixels: `(x, y, z) -> (fx x - cx z, -fy y - cy z, -z)`.
fn k(i: &Intrinsics) -> Mat3 {
    Mat3::from_cols(
        Vec3::new(i.fl_x, 0.0, 0.0),
        Vec3::new(0.0, -i.fl_y, 0.0),
        Vec3::new(-i.cx, -i.cy, -1.0),
    )
}

/// Homogeneous pixels -> the view-space ray with axial length 1.
fn k_inv(i: &Intrinsics) -> Mat3 {
    Mat3::from_cols(
        Vec3::new(1.0 / i.fl_x, 0.0, 0.0),
        Vec3::new(0.0, -1.0 / i.fl_y, 0.0),
        Vec3::new(-i.cx / i.fl_x, i.cy / i.fl_y, -1.0),
    )
}

impl Equation {
    /// The warp from `reference` (a `w1` x `h1` image) to `target` (`w2` x `h2`). `None`
    /// when either camera is orthographic or the result is not finite.
    pub fn new(
        reference: &Camera,
        w1: u32,
        h1: u32,
        target: &Camera,
        w2: u32,
        h2: u32,
    ) -> Option<Self> {
        let k1 = Intrinsics::of(&reference.projection, w1, h1)?;
        let k2 = Intrinsics::of(&target.projection, w2, h2)?;
        let m = target.view * reference.view.inverse();
        let r = Mat3::from_mat4(m);
        let t = m.w_axis.truncate();
        let a = k(&k2) * r * k_inv(&k1);
        let b = k(&k2) * t;
        let eye2_in_1 = reference.view.transform_point3(target.eye());
        let epipole = k(&k1) * eye2_in_1;
        let eq = Equation {
            a: [a.x_axis, a.y_axis, a.z_axis],
            b,
            epipole,
        };
        (a.is_finite() && b.is_finite() && epipole.is_finite()).then_some(eq)
    }

    /// `A x1` at the pixel centre `(x + 0.5, y + 0.5)`.
    #[inline]
    pub fn base(&self, x: u32, y: u32) -> Vec3 {
        let (u, v) = (x as f32 + 0.5, y as f32 + 0.5);
        self.a[0] * u + self.a[1] * v + self.a[2]
    }

    /// Where a sample with disparity `disparity` and base `base` lands: target pixel
    /// position and depth along the target's axis. `None` behind the target eye.
    #[inline]
    pub fn land(&self, base: Vec3, disparity: f32) -> Option<(Vec2, f32)> {
        let h = base + self.b * disparity;
        if h.z.is_nan() || h.z <= 0.0 {
            return None;
        }
        let inv = 1.0 / h.z;
        let depth = if disparity > 0.0 {
            h.z / disparity
        } else {
            f32::INFINITY
        };
        Some((Vec2::new(h.x * inv, h.y * inv), depth))
    }

    /// The target-pixel displacement of one reference pixel step in x and in y at a sample
    /// (`base`, `disparity`), where the disparity changes by `dd` per step along each axis
    /// (the surface's slope; zero for a surface facing the reference camera). The columns
    /// of the warp's Jacobian.
    #[inline]
    pub fn stretch(&self, base: Vec3, disparity: f32, dd: Vec2) -> (Vec2, Vec2) {
        let h = base + self.b * disparity;
        let inv = 1.0 / h.z;
        let p = Vec2::new(h.x, h.y) * inv;
        let column = |dh: Vec3| (Vec2::new(dh.x, dh.y) - p * dh.z) * inv;
        (
            column(self.a[0] + self.b * dd.x),
            column(self.a[1] + self.b * dd.y),
        )
    }

    /// The epipole (the target eye's image) in reference pixels, and whether the target eye
    /// is in front of the reference camera. For an eye in the reference's image plane the
    /// epipole is at infinity: a far point in its direction, counted as in front (the
    /// traversal toward it is the same either way).
    pub fn epipole_pixel(&self) -> (Vec2, bool) {
        let e = self.epipole;
        let far = 1e7;
        if e.z.abs() <= 1e-6 * (e.x.abs() + e.y.abs()) || e.z == 0.0 {
            let dir = Vec2::new(e.x, e.y).normalize_or_zero();
            return (dir * far, true);
        }
        let p = Vec2::new(e.x, e.y) / e.z;
        (p.clamp(Vec2::splat(-far), Vec2::splat(far)), e.z > 0.0)
    }
}
