//! How much of the view a quad covers: its corners clipped to the near plane and to the
//! image, the polygon's area. An estimate of the fragments drawing it shades (exact up to
//! the rasterizer's pixel-centre rule), for deciding how to draw many blended quads.

use glam::{Mat4, Vec2, Vec3, Vec4};

/// The share of the image (0 to 1) the convex quad `corners` covers seen through
/// `clip_from_world`: the quad clipped to `w > 0` (in front of the eye) in clip space, then
/// to the image's square in normalised device coordinates (Sutherland-Hodgman), its area
/// over the square's 4. Non-finite corners cover nothing.
pub(crate) fn screen_share(corners: &[Vec3; 4], clip_from_world: &Mat4) -> f32 {
    if corners.iter().any(|c| !c.is_finite()) {
        return 0.0;
    }
    let clip = corners.map(|c| *clip_from_world * c.extend(1.0));
    // Clip to w >= a small positive value (what is behind the eye never shows), then to the
    // image square one edge at a time; a quad clipped by five planes has at most 9 corners.
    const NEAR_W: f32 = 1e-5;
    let mut poly = Poly::default();
    for k in 0..4 {
        let (a, b) = (clip[k], clip[(k + 1) % 4]);
        let project = |p: Vec4| Vec2::new(p.x / p.w, p.y / p.w);
        if a.w >= NEAR_W {
            poly.push(project(a));
        }
        if (a.w >= NEAR_W) != (b.w >= NEAR_W) {
            let t = (NEAR_W - a.w) / (b.w - a.w);
            poly.push(project(a + (b - a) * t));
        }
    }
    for (axis, sign) in [(0, 1.0f32), (0, -1.0), (1, 1.0), (1, -1.0)] {
        let inside = |p: Vec2| sign * p[axis] <= 1.0;
        let mut out = Poly::default();
        let pts = poly.points();
        for k in 0..pts.len() {
            let (a, b) = (pts[k], pts[(k + 1) % pts.len()]);
            if inside(a) {
                out.push(a);
            }
            if inside(a) != inside(b) {
                let t = (sign - a[axis]) / (b[axis] - a[axis]);
                out.push(a + (b - a) * t);
            }
        }
        poly = out;
    }
    let poly = poly.points();
    let n = poly.len();
    let twice: f32 = (0..n).map(|k| poly[k].perp_dot(poly[(k + 1) % n])).sum();
    let share = twice.abs() * 0.5 / 4.0;
    if share.is_finite() {
        share.min(1.0)
    } else {
        0.0
    }
}

/// A clipped polygon's corners, on the stack.
#[derive(Default)]
struct Poly {
    points: [Vec2; 12],
    len: usize,
}

impl Poly {
    fn push(&mut self, p: Vec2) {
        if let Some(slot) = self.points.get_mut(self.len) {
            *slot = p;
            self.len += 1;
        }
    }
    fn points(&self) -> &[Vec2] {
        &self.points[..self.len]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use engine::Camera;

    fn camera() -> Camera {
        Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 1.0, 1.0)
    }

    fn square(center: Vec3, half: f32) -> [Vec3; 4] {
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .map(|(x, y)| center + Vec3::new(x * half, y * half, 0.0))
    }

    #[test]
    fn a_quad_in_view_covers_its_projected_area() {
        let cam = camera();
        let m = cam.clip_from_world();
        // At distance 5 with fov_y 1 rad the image is 2 * 5 * tan(0.5) high: a square of
        // half-side 1 covers (2 / that)^2 of it.
        let side = 2.0 * 5.0 * 0.5f32.tan();
        let share = screen_share(&square(Vec3::ZERO, 1.0), &m);
        assert!((share - (2.0 / side).powi(2)).abs() < 1e-4, "{share}");
        // Half off the right edge: about half as much.
        let edge = Vec3::new(side / 2.0, 0.0, 0.0);
        let half = screen_share(&square(edge, 1.0), &m);
        assert!((half - share / 2.0).abs() < 1e-4, "{half}");
        // Larger than the view: the whole image, no more.
        assert_eq!(screen_share(&square(Vec3::ZERO, 50.0), &m), 1.0);
    }

    #[test]
    fn behind_the_eye_or_beside_it_covers_nothing() {
        let m = camera().clip_from_world();
        assert_eq!(
            screen_share(&square(Vec3::new(0.0, 0.0, 9.0), 1.0), &m),
            0.0
        );
        // Beside the eye, in its plane, facing along the view: outside the image.
        let beside = [
            Vec3::new(3.0, -1.0, 6.0),
            Vec3::new(3.0, -1.0, 4.0),
            Vec3::new(3.0, 1.0, 4.0),
            Vec3::new(3.0, 1.0, 6.0),
        ];
        assert_eq!(screen_share(&beside, &m), 0.0);
        let nan = [Vec3::NAN; 4];
        assert_eq!(screen_share(&nan, &m), 0.0);
    }

    #[test]
    fn a_quad_through_the_eye_plane_covers_what_lies_in_front() {
        let m = camera().clip_from_world();
        // A floor from behind the eye to far ahead, below it: the lower part of the image.
        let floor = [
            Vec3::new(-100.0, -1.0, 10.0),
            Vec3::new(100.0, -1.0, 10.0),
            Vec3::new(100.0, -1.0, -100.0),
            Vec3::new(-100.0, -1.0, -100.0),
        ];
        let share = screen_share(&floor, &m);
        assert!(share > 0.4 && share < 0.5, "{share}");
    }
}
