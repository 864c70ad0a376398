//! Nailboard fragments ([`DepthOffset`]): how far behind its triangle each fragment's
//! surface lies, read from the offset image; with [`DepthOffset::parallax`], first which
//! texel's surface lies on the fragment's own ray.
//!
//! The parallax search. The images are an orthographic view along the triangle's normal:
//! the texel at the reference plane's point `q` (the plane `lift * unit` behind the
//! triangle, where the image is as baked) shows the surface at `q + n o(q)`, `o` its
//! offset toward the eye. The ray through the fragment's point `q` meets the height `o`
//! above the plane at `q + (e - q) o / D` (`e` the eye, `D` its distance to the plane),
//! straight above the plane's point `q + (f - q) o / D`, `f` the eye's foot on it. In
//! texture coordinates (affine on the plane, and the triangle is the plane scaled about
//! the eye: the same coordinates) that is `uv + (uv_f - uv) t`, `t = o / D`, with
//! `o / D = (lift - scale * frac) len / d` for an offset `frac` (red over alpha), `len`
//! the triangle's world length per unit of `u` and `d` the eye's distance to it. The
//! search takes `frac` at the fragment's own texel (the nearest surface where that is
//! uncovered) and steps to the texel it points at; where that texel is covered and its
//! offset is the one stepped with (within the tolerance: the ray meets its surface) the
//! fragment shows it. Elsewhere (outlines, steps in depth) it steps again with that
//! texel's offset and keeps the second step on the same test; else the fragment reads its
//! own texel (as without parallax). Outside an outline the first step reaches into the
//! image and the second steps back out to an uncovered texel or to an offset that
//! disagrees: the outline is not dilated.

use super::{Behind, Lane};
use crate::material::DepthOffset;
use crate::simd::{F8, M8};
use crate::texture::Sampler;
use glam::Vec3;

/// [`super::GeneralTri::depth_scale`]: `scale * unit / d` for `offset`, `d` the eye's
/// distance to the triangle's plane (`p = [p0, p1 - p0, p2 - p0]`, `face` its unit normal,
/// `uv` its `[u0, du1, du2]` and `[v0, dv1, dv2]`). The triangle's world length per unit
/// of `u` is `len = s unit`, `s = 1 - lift len / d` the scaling about the eye that carried
/// the reference plane (at `d / s`) `lift unit` nearer. A point `o` behind the plane along
/// its normal, seen through the plane's point at view depth `w`, lies on the same ray at
/// view depth `w (1 + o / d)`. 0 where that is not finite or `s <= 0`.
pub(super) fn depth_scale(
    offset: &DepthOffset,
    p: [Vec3; 3],
    uv: [[f32; 3]; 2],
    face: Vec3,
    eye: Vec3,
) -> f32 {
    let (len, d) = len_and_distance(p, uv, face, eye);
    let s = 1.0 - offset.lift * len / d;
    let k = offset.scale * len / (s * d);
    if k.is_finite() && s > 0.0 {
        k
    } else {
        0.0
    }
}

/// The triangle's world length per unit of `u`, and the eye's distance to its plane.
fn len_and_distance(p: [Vec3; 3], uv: [[f32; 3]; 2], face: Vec3, eye: Vec3) -> (f32, f32) {
    let [[_, du1, du2], [_, dv1, dv2]] = uv;
    let det = du1 * dv2 - du2 * dv1;
    let len = ((p[1] * dv2 - p[2] * dv1) / det).length();
    (len, (eye - p[0]).dot(face).abs())
}

/// One triangle's terms of the parallax search (module docs).
#[derive(Clone, Copy, Debug)]
pub(super) struct Parallax {
    /// The texture coordinates of the eye's foot on the triangle's plane.
    foot: [f32; 2],
    /// `t = lift - scale * frac`, in these units: `lift len / d` and `scale len / d`.
    lift: f32,
    scale: f32,
    /// [`DepthOffset::parallax`].
    tolerance: f32,
}

impl Parallax {
    /// The terms for the triangle `p` (`[p0, p1 - p0, p2 - p0]`, unit normal `face`, `uv`
    /// as [`depth_scale`] takes them) seen from `eye`; `None` without
    /// [`DepthOffset::parallax`] or where they are not finite (a degenerate triangle).
    pub(super) fn new(
        offset: &DepthOffset,
        p: [Vec3; 3],
        uv: [[f32; 3]; 2],
        face: Vec3,
        eye: Vec3,
    ) -> Option<Parallax> {
        let tolerance = offset.parallax?;
        let (len, d) = len_and_distance(p, uv, face, eye);
        // The foot's barycentrics in the triangle's plane (its edges' Gram system).
        let r = eye - face * (eye - p[0]).dot(face) - p[0];
        let (e1, e2) = (p[1], p[2]);
        let (g11, g12, g22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
        let (r1, r2) = (e1.dot(r), e2.dot(r));
        let det = g11 * g22 - g12 * g12;
        let b1 = (r1 * g22 - r2 * g12) / det;
        let b2 = (g11 * r2 - g12 * r1) / det;
        let [[u0, du1, du2], [v0, dv1, dv2]] = uv;
        let terms = Parallax {
            foot: [u0 + b1 * du1 + b2 * du2, v0 + b1 * dv1 + b2 * dv2],
            lift: offset.lift * len / d,
            scale: offset.scale * len / d,
            tolerance,
        };
        let finite = [terms.foot[0], terms.foot[1], terms.lift, terms.scale];
        finite.iter().all(|x| x.is_finite()).then_some(terms)
    }

    /// Where the ray of the fragment at `uv` meets the height of offset `frac`, dropped
    /// onto the plane.
    #[inline(always)]
    fn step(&self, uv: [Lane; 2], frac: Lane) -> [Lane; 2] {
        let t = F8::splat(self.lift) - F8::splat(self.scale) * frac;
        [0, 1].map(|c| (F8::splat(self.foot[c]) - uv[c]).mul_add(t, uv[c]))
    }
}

/// [`super::FragShader::behind`] for a nailboard: the offset image read (with `sampler`,
/// bilinearly on the mip level nearest `lod`: half a trilinear read; a nearest texel was
/// cheaper still but stepped the depth a texel at a time, 3 times the mean error against
/// the mesh) at each lane's texel (`uv`, or where the parallax search finds it), that
/// offset as view depth (`k` the triangle's [`depth_scale`], `w` the lanes' view depth),
/// the lanes it covers among `mask`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn behind(
    offset: &DepthOffset,
    sampler: &Sampler,
    parallax: Option<&Parallax>,
    k: f32,
    lod: f32,
    uv: [Lane; 2],
    w: Lane,
    mask: u32,
) -> Behind {
    let zero = F8::splat(0.0);
    let keep = M8::from_bits(mask);
    let read = |[u, v]: [Lane; 2]| {
        let s = offset.texture.bilinear8_lod(sampler, lod, u, v, keep);
        let covered = s[3].gt(zero);
        (covered, covered.select(s[0] / s[3], zero))
    };
    let (mut covered, mut frac) = read(uv);
    let mut at = uv;
    if let Some(p) = parallax {
        // Where the fragment's own texel is uncovered, its ray is tried at the nearest
        // surface's height (offset 0). Tried and not kept (session 30): the first step's
        // read on the nearest level's texel (-0.9 dB on the forest's worst frame), and no
        // read at the fragment's own texel, the search started at offset 0 (-0.4 dB mean).
        let tol = F8::splat(p.tolerance);
        let first = p.step(uv, frac);
        let (c1, f1) = read(first);
        let mut met = c1.and(covered).and((f1 - frac).abs().lt(tol));
        let (mut to, mut c, mut f) = (first, c1, f1);
        // The second step only for rows where some lane's first reached a covered texel
        // that did not agree (a lane whose first reached none cannot meet the test): 20 to
        // 22% of the forest's rows take it, 40 to 45% where every lane not met did (session
        // 30, the pixels the same).
        if c1.and_not(met).bits() & mask != 0 {
            let second = p.step(uv, f1);
            let (c2, f2) = read(second);
            let again = c1.and(c2).and((f2 - f1).abs().lt(tol)).and_not(met);
            to = [0, 1].map(|k| again.select(second[k], to[k]));
            (c, f) = (again.or(c.and_not(again)), again.select(f2, f));
            met = met.or(again);
        }
        at = [0, 1].map(|k| met.select(to[k], uv[k]));
        covered = met.and(c).or(covered.and_not(met));
        frac = met.select(f, frac);
    }
    // A texel the offset image leaves uncovered holds no surface: dropped unshaded.
    Behind {
        depth: frac * F8::splat(k) * w,
        keep: covered.bits() & mask,
        uv: at,
    }
}
