//! Texture level of detail for the shaders: a row's from its covered lanes' widest
//! footprint ([`row_lod`]), or one for a whole triangle where its footprint hardly varies
//! ([`triangle_lod`]).

use super::{Row, F8, M8};
use crate::setup::{Plane, Tri};
use crate::texture::Texture;

/// The widest spread of levels of detail over a triangle's box for which one level stands
/// for all its rows ([`triangle_lod`]): the level taken is then within half of it (1/8 of
/// a level, at most an eighth of a trilinear blend's weight) of the one each row would take.
/// Over the 720p tour (small triangles counted too) a quarter would take one level for 69%
/// of the trilinear rows, 1/16 for 21%.
pub const LOD_SPREAD: f32 = 1.0 / 4.0;

/// The level of detail of `row` (its covered lanes' widest footprint, as a GPU's 2 x 2 quad
/// shares one), texture `tex` with `uv = [[u0, u1 - u0, u2 - u0], [v0, ..]]` over the
/// triangle and `bary` the row's [`barycentrics`]. d(l1)/dx = (d(l1/w)/dx - l1 d(1/w)/dx) w, and likewise for y and l2.
#[inline(always)]
pub fn row_lod(tri: &Tri, uv: [[f32; 3]; 2], tex: &Texture, row: &Row, bary: [F8; 3]) -> f32 {
    let [l1, l2, w] = bary;
    let [[_, du1, du2], [_, dv1, dv2]] = uv;
    let d = |pl: &Plane, lam: F8| {
        (
            (F8::splat(pl.dx) - lam * F8::splat(tri.iw.dx)) * w,
            (F8::splat(pl.dy) - lam * F8::splat(tri.iw.dy)) * w,
        )
    };
    let (a1x, a1y) = d(&tri.l1, l1);
    let (a2x, a2y) = d(&tri.l2, l2);
    let (tw, th) = (
        F8::splat(tex.width() as f32),
        F8::splat(tex.height() as f32),
    );
    let (du1, du2) = (F8::splat(du1), F8::splat(du2));
    let (dv1, dv2) = (F8::splat(dv1), F8::splat(dv2));
    let dudx = a1x.mul_add(du1, a2x * du2) * tw;
    let dvdx = a1x.mul_add(dv1, a2x * dv2) * th;
    let dudy = a1y.mul_add(du1, a2y * du2) * tw;
    let dvdy = a1y.mul_add(dv1, a2y * dv2) * th;
    let rho2 = dudx
        .mul_add(dudx, dvdx * dvdx)
        .max(dudy.mul_add(dudy, dvdy * dvdy));
    0.5 * fast_log2(widest(rho2, row.covered))
}

/// One level of detail for every row of the triangle, or `None` if its footprint may
/// spread [`LOD_SPREAD`] levels or more over the triangle's bounding box.
///
/// The footprint's derivatives are `N / (1/w)^2` with `N` linear in one screen axis only
/// (`d(l1)/dx = (l1.dx (1/w) - (l1/w) (1/w).dx) / (1/w)^2`, whose `x` terms cancel), and
/// `1/w` is linear: over the box each takes its extremes at the corners, which bound the
/// squared footprint `rho2` from below and above. The level taken is the middle of the two
/// bounds' levels (by [`fast_log2`], monotonic, as the rows use), so it is within half the
/// spread of every row's. Mostly met by camera-facing sprites and distant triangles.
pub fn triangle_lod(tri: &Tri, uv: [[f32; 3]; 2], tex: &Texture) -> Option<f32> {
    // Non-finite inputs would slip through the minima and maxima below: worked out per row.
    let [[_, du1, du2], [_, dv1, dv2]] = uv;
    let planes = [tri.iw, tri.l1, tri.l2].map(|p| [p.c, p.dx, p.dy]);
    if !planes
        .iter()
        .flatten()
        .chain(&[du1, du2, dv1, dv2])
        .all(|v| v.is_finite())
    {
        return None;
    }
    let bw = tri.bbox[2].saturating_sub(tri.bbox[0]) as f32;
    let bh = tri.bbox[3].saturating_sub(tri.bbox[1]) as f32;
    let iw = &tri.iw;
    let corner = |x: f32, y: f32| iw.c + iw.dx * x + iw.dy * y;
    let c = [
        corner(0.0, 0.0),
        corner(bw, 0.0),
        corner(0.0, bh),
        corner(bw, bh),
    ];
    let iw_lo = c[0].min(c[1]).min(c[2].min(c[3]));
    let iw_hi = c[0].max(c[1]).max(c[2].max(c[3]));
    if iw_lo <= 0.0 {
        return None;
    }
    let nx = |l: &Plane, y: f32| l.dx * (iw.c + iw.dy * y) - iw.dx * (l.c + l.dy * y);
    let ny = |l: &Plane, x: f32| l.dy * (iw.c + iw.dx * x) - iw.dy * (l.c + l.dx * x);
    let (tw, th) = (tex.width() as f32, tex.height() as f32);
    // The magnitude's range of a linear function whose ends are `a` and `b`.
    let range = |a: f32, b: f32| {
        let lo = if (a >= 0.0) == (b >= 0.0) {
            a.abs().min(b.abs())
        } else {
            0.0
        };
        (lo, a.abs().max(b.abs()))
    };
    let along = |n: &dyn Fn(&Plane, f32) -> f32, s: f32, d1: f32, d2: f32, size: f32| {
        (n(&tri.l1, s) * d1 + n(&tri.l2, s) * d2) * size
    };
    let ux = range(along(&nx, 0.0, du1, du2, tw), along(&nx, bh, du1, du2, tw));
    let vx = range(along(&nx, 0.0, dv1, dv2, th), along(&nx, bh, dv1, dv2, th));
    let uy = range(along(&ny, 0.0, du1, du2, tw), along(&ny, bw, du1, du2, tw));
    let vy = range(along(&ny, 0.0, dv1, dv2, th), along(&ny, bw, dv1, dv2, th));
    let (lo4, hi4) = ((iw_hi * iw_hi).powi(2), (iw_lo * iw_lo).powi(2));
    let lo = (ux.0 * ux.0 + vx.0 * vx.0).max(uy.0 * uy.0 + vy.0 * vy.0) / lo4;
    let hi = (ux.1 * ux.1 + vx.1 * vx.1).max(uy.1 * uy.1 + vy.1 * vy.1) / hi4;
    // Overflow (an infinite bound, or NaN from it) is worked out per row.
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    let (a, b) = (0.5 * fast_log2(lo), 0.5 * fast_log2(hi));
    (b - a < LOD_SPREAD).then_some(0.5 * (a + b))
}

/// The largest of the lanes of `rho2` set in `covered`, NaN lanes left out, and at least 0:
/// the same value as folding `f32::max` from 0 over those lanes (the squared footprints are
/// `>= 0` or NaN, and a zero's sign is lost in [`fast_log2`]), by a tree of maxima
/// without a branch per lane.
#[inline(always)]
pub(super) fn widest(rho2: F8, covered: u32) -> f32 {
    let zero = F8::splat(0.0);
    // `>= 0` is false for NaN, so those lanes become 0 as the skipped lanes do.
    let keep = M8::from_bits(covered).and(rho2.ge(zero));
    let m = keep.select(rho2, zero).to_array();
    // No NaN is left: a plain comparison is the maximum, in two independent halves.
    let max = |a: f32, b: f32| if b > a { b } else { a };
    let lo = max(max(m[0], m[1]), max(m[2], m[3]));
    let hi = max(max(m[4], m[5]), max(m[6], m[7]));
    max(lo, hi)
}

/// `log2` from the float's bits, exact at powers of two and within 0.09 between: plenty for
/// choosing a mip level. Tiny and non-finite inputs are clamped.
#[inline]
pub(super) fn fast_log2(x: f32) -> f32 {
    let x = if x.is_finite() { x.max(1e-20) } else { 1e20 };
    x.to_bits() as f32 * (1.0 / (1u32 << 23) as f32) - 127.0
}
