//! Clip stage: homogeneous clipping of triangles against the near and far planes, and
//! against a guard band far outside the viewport in x and y.
//!
//! Triangles inside the guard band are never clipped in x/y: the rasterizer's scissor (the
//! bounding box clamped to the target) handles them, and only the guard band keeps the
//! fixed-point coordinates within range. A triangle crossing the near plane is cut, never
//! dropped or wrapped. Intersections are computed from the inside vertex towards the outside
//! one whatever the edge's direction, so two triangles sharing a clipped edge get the same
//! new vertex and no crack.

use crate::space::{distance64, GuardBand, BOTTOM, FAR, LEFT, NEAR, RIGHT, TOP};
use crate::vertex::MAX_VARYINGS;
use glam::Vec4;

/// A vertex in clip space with its varyings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipVert {
    pub pos: Vec4,
    pub vary: [f32; MAX_VARYINGS],
}

/// Most vertices a triangle clipped by six planes can have.
pub const MAX_POLY: usize = 9;

/// Clips a triangle against the planes in `planes` (an OR of outcodes). Writes the polygon
/// into `out` and returns its vertex count (0 when nothing is left). Only the first
/// `n_vary` varyings are interpolated.
pub fn clip_triangle(
    tri: [ClipVert; 3],
    planes: u8,
    g: GuardBand,
    n_vary: usize,
    out: &mut [ClipVert; MAX_POLY],
) -> usize {
    let mut a = [tri[0]; MAX_POLY];
    a[..3].copy_from_slice(&tri);
    let mut n = 3;
    let mut b = [tri[0]; MAX_POLY];
    for plane in [NEAR, FAR, LEFT, RIGHT, BOTTOM, TOP] {
        if planes & plane == 0 {
            continue;
        }
        let mut m = 0;
        for i in 0..n {
            let (p, q) = (a[i], a[(i + 1) % n]);
            let (dp, dq) = (
                distance64(p.pos.as_dvec4(), plane, g),
                distance64(q.pos.as_dvec4(), plane, g),
            );
            if dp >= 0.0 && m < MAX_POLY {
                b[m] = p;
                m += 1;
            }
            if (dp >= 0.0) != (dq >= 0.0) && m < MAX_POLY {
                b[m] = if dp >= 0.0 {
                    lerp(p, q, dp / (dp - dq), n_vary, plane, g)
                } else {
                    lerp(q, p, dq / (dq - dp), n_vary, plane, g)
                };
                m += 1;
            }
        }
        std::mem::swap(&mut a, &mut b);
        n = m;
        if n < 3 {
            return 0;
        }
    }
    out[..n].copy_from_slice(&a[..n]);
    n
}

/// The point at `t` from `a` to `b`, computed in f64 and put exactly on the plane it was
/// cut by, so its projection cannot fall outside the plane's range.
#[inline]
fn lerp(a: ClipVert, b: ClipVert, t: f64, n_vary: usize, plane: u8, g: GuardBand) -> ClipVert {
    let (pa, pb) = (a.pos.as_dvec4(), b.pos.as_dvec4());
    let mut p = pa + (pb - pa) * t;
    match plane {
        NEAR => p.z = p.w,
        FAR => p.z = 0.0,
        LEFT => p.x = -(g.gx as f64) * p.w,
        RIGHT => p.x = g.gx as f64 * p.w,
        BOTTOM => p.y = -(g.gy as f64) * p.w,
        _ => p.y = g.gy as f64 * p.w,
    }
    let mut v = a;
    v.pos = p.as_vec4();
    let t = t as f32;
    for k in 0..n_vary {
        v.vary[k] = a.vary[k] + (b.vary[k] - a.vary[k]) * t;
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::space::outcode;

    const G: GuardBand = GuardBand { gx: 4.0, gy: 4.0 };

    fn cv(x: f32, y: f32, z: f32, w: f32) -> ClipVert {
        ClipVert {
            pos: Vec4::new(x, y, z, w),
            vary: [x; MAX_VARYINGS],
        }
    }

    #[test]
    fn outcodes() {
        assert_eq!(outcode(Vec4::new(0.0, 0.0, 0.5, 1.0), G), 0);
        assert_eq!(outcode(Vec4::new(0.0, 0.0, 1.5, 1.0), G), NEAR);
        assert_eq!(outcode(Vec4::new(0.0, 0.0, -0.1, 1.0), G), FAR);
        assert_eq!(outcode(Vec4::new(5.0, 0.0, 0.5, 1.0), G), RIGHT);
        // behind the eye: w < 0 violates the near plane
        assert_ne!(outcode(Vec4::new(0.0, 0.0, 0.2, -1.0), G) & NEAR, 0);
        assert_eq!(
            outcode(Vec4::NAN, G),
            0,
            "NaN is caught before clipping, not here"
        );
    }

    #[test]
    fn near_plane_cut_keeps_the_inside_part() {
        let tri = [
            cv(0.0, 0.0, 0.5, 1.0),
            cv(1.0, 0.0, 2.0, 1.0),
            cv(0.0, 1.0, 2.0, 1.0),
        ];
        let mut out = [tri[0]; MAX_POLY];
        let n = clip_triangle(tri, NEAR, G, 1, &mut out);
        assert_eq!(n, 3);
        for v in &out[..n] {
            assert!(v.pos.w - v.pos.z >= 0.0);
            assert!(
                (v.vary[0] - v.pos.x).abs() < 1e-6,
                "varyings follow positions"
            );
        }
    }

    #[test]
    fn shared_edge_gives_identical_vertices_both_ways() {
        let p = cv(0.3, -0.2, 0.4, 1.0);
        let q = cv(-0.7, 0.9, 3.0, 1.1);
        let r1 = cv(1.0, 1.0, 0.2, 1.0);
        let r2 = cv(-1.0, -1.0, 0.3, 1.0);
        let mut o1 = [p; MAX_POLY];
        let mut o2 = [p; MAX_POLY];
        let n1 = clip_triangle([p, q, r1], NEAR, G, 1, &mut o1);
        let n2 = clip_triangle([q, p, r2], NEAR, G, 1, &mut o2);
        let cut = |o: &[ClipVert]| {
            o.iter()
                .filter(|v| (v.pos.w - v.pos.z).abs() < 1e-6 && v.pos.x > -0.8 && v.pos.x < 0.31)
                .map(|v| v.pos)
                .collect::<Vec<_>>()
        };
        let c1 = cut(&o1[..n1]);
        let c2 = cut(&o2[..n2]);
        assert!(c1.iter().any(|a| c2.contains(a)), "{c1:?} vs {c2:?}");
    }

    #[test]
    fn wholly_outside_gives_nothing() {
        let tri = [
            cv(0.0, 0.0, 2.0, 1.0),
            cv(1.0, 0.0, 2.0, 1.0),
            cv(0.0, 1.0, 3.0, 1.0),
        ];
        let mut out = [tri[0]; MAX_POLY];
        assert_eq!(clip_triangle(tri, NEAR, G, 0, &mut out), 0);
    }
}
