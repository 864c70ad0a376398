//! Shade stage: fragment shaders, one per family of materials, each run on a row of 8
//! pixels at a time.
//!
//! A shader first `prepare`s a triangle (fetches its three vertices' varyings once per
//! triangle and tile), then `shade`s rows, writing straight linear RGB and alpha for all 8
//! lanes; the rasterizer decides which lanes it keeps. Attributes are interpolated with
//! perspective-correct barycentrics: `l1 = (l1/w) / (1/w)`, from planes set up per triangle.
//! Texture level of detail comes from the analytic screen-space derivatives of those
//! barycentrics, so no 2x2 quads are needed.

use crate::light::{Light, Lighting};
use crate::material::{Material, Shading};
use crate::setup::{Plane, Tri, FRONT};
use crate::vertex::{COL, NRM, POS, UV};
use glam::Vec3;
use std::ops::{Div, Mul};

use crate::simd::F8;
pub use crate::simd::LANES;

/// 8 lanes of one channel.
pub type Lane = F8;

/// Where a row of lanes sits: pixel `x0 + lane`, row `y`, relative to the plane reference.
#[derive(Clone, Copy, Debug)]
pub struct Row {
    /// `x - rx` of lane 0.
    pub fx: f32,
    /// `y - ry`.
    pub fy: f32,
}

#[inline(always)]
pub fn eval(p: &Plane, row: &Row) -> Lane {
    let base = p.c + p.dx * row.fx + p.dy * row.fy;
    F8::splat(p.dx).mul_add(F8::ramp(), F8::splat(base))
}

/// Perspective-correct barycentrics of vertices 1 and 2, and `w`, for 8 lanes.
#[inline]
pub fn barycentrics(tri: &Tri, row: &Row) -> (Lane, Lane, Lane) {
    let iw = eval(&tri.iw, row);
    let a = eval(&tri.l1, row);
    let b = eval(&tri.l2, row);
    let w = F8::splat(1.0).div(iw);
    (a.mul(w), b.mul(w), w)
}

/// A fragment shader over rows of 8 lanes.
pub trait FragShader: Sync {
    /// Per-triangle data, prepared once per triangle and tile.
    type Prepared;
    fn prepare(&self, tri: &Tri, vary: &[f32]) -> Self::Prepared;
    /// Straight linear `[r, g, b, a]` for the 8 lanes of `row`.
    fn shade(&self, p: &Self::Prepared, tri: &Tri, row: &Row, out: &mut [Lane; 4]);
}

/// One colour per triangle: unlit untextured materials, face ids, flat faces.
#[derive(Clone, Copy, Debug)]
pub struct ConstShader {
    pub color: [f32; 4],
    /// Take the colour from the triangle's packed `color` instead (unorm bytes).
    pub per_triangle: bool,
}

impl FragShader for ConstShader {
    type Prepared = [f32; 4];
    #[inline]
    fn prepare(&self, tri: &Tri, _: &[f32]) -> [f32; 4] {
        if self.per_triangle {
            tri.color.to_le_bytes().map(|b| b as f32 / 255.0)
        } else {
            self.color
        }
    }
    #[inline]
    fn shade(&self, p: &[f32; 4], _: &Tri, _: &Row, out: &mut [Lane; 4]) {
        for c in 0..4 {
            out[c] = F8::splat(p[c]);
        }
    }
}

/// Interpolated vertex colour times a base colour, unlit.
#[derive(Clone, Copy, Debug)]
pub struct ColorShader {
    pub base: [f32; 4],
}

impl FragShader for ColorShader {
    /// `[c0, c1 - c0, c2 - c0]` per channel.
    type Prepared = [[f32; 3]; 4];
    #[inline]
    fn prepare(&self, tri: &Tri, vary: &[f32]) -> Self::Prepared {
        let v = |k: usize, c: usize| vary[tri.vary[k] as usize + c] * self.base[c];
        std::array::from_fn(|c| [v(0, c), v(1, c) - v(0, c), v(2, c) - v(0, c)])
    }
    #[inline]
    fn shade(&self, p: &Self::Prepared, tri: &Tri, row: &Row, out: &mut [Lane; 4]) {
        let (l1, l2, _) = barycentrics(tri, row);
        for c in 0..4 {
            let [a0, d1, d2] = p[c];
            out[c] = l1.mul_add(F8::splat(d1), l2.mul_add(F8::splat(d2), F8::splat(a0)));
        }
    }
}

/// Everything else: textures, vertex colours, Lambert + Blinn-Phong lighting.
#[derive(Debug)]
pub struct GeneralShader<'a> {
    pub material: &'a Material,
    pub lighting: &'a Lighting,
    pub eye: Vec3,
}

/// Per-triangle data of [`GeneralShader`].
#[derive(Clone, Copy, Debug)]
pub struct GeneralTri {
    /// `[v0, v1 - v0, v2 - v0]` for each of the 12 varyings.
    attr: [[f32; 3]; 12],
    face_normal: Vec3,
    front: bool,
}

impl FragShader for GeneralShader<'_> {
    type Prepared = GeneralTri;
    fn prepare(&self, tri: &Tri, vary: &[f32]) -> GeneralTri {
        let v = |k: usize, c: usize| vary[tri.vary[k] as usize + c];
        let attr = std::array::from_fn(|c| [v(0, c), v(1, c) - v(0, c), v(2, c) - v(0, c)]);
        let p = |k: usize| Vec3::new(v(k, POS), v(k, POS + 1), v(k, POS + 2));
        // Setup made the winding positive on a y-down screen (clockwise as seen), so this
        // order of the cross product points towards the viewer.
        let n = (p(2) - p(0)).cross(p(1) - p(0)).normalize_or_zero();
        GeneralTri {
            attr,
            face_normal: n,
            front: tri.flags & FRONT != 0,
        }
    }

    fn shade(&self, p: &GeneralTri, tri: &Tri, row: &Row, out: &mut [Lane; 4]) {
        let m = self.material;
        let (l1, l2, w) = barycentrics(tri, row);
        let (l1, l2, w) = (l1.to_array(), l2.to_array(), w.to_array());
        let mut res = [[0.0f32; LANES]; 4];
        let at = |c: usize, l: usize| {
            let [a0, d1, d2] = p.attr[c];
            a0 + l1[l] * d1 + l2[l] * d2
        };
        let base = m.base_color;
        for l in 0..LANES {
            let mut rgba = [base.r, base.g, base.b, base.a];
            if m.vertex_colors {
                for c in 0..4 {
                    rgba[c] *= at(COL + c, l);
                }
            }
            if let Some(tex) = &m.base_texture {
                let (u, v) = (at(UV, l), at(UV + 1, l));
                // d(l1)/dx = (d(l1/w)/dx - l1 * d(1/w)/dx) * w, and likewise for y and l2.
                let d = |pl: &Plane, lam: f32| {
                    (
                        (pl.dx - lam * tri.iw.dx) * w[l],
                        (pl.dy - lam * tri.iw.dy) * w[l],
                    )
                };
                let (a1x, a1y) = d(&tri.l1, l1[l]);
                let (a2x, a2y) = d(&tri.l2, l2[l]);
                let [_, du1, du2] = p.attr[UV];
                let [_, dv1, dv2] = p.attr[UV + 1];
                let (tw, th) = (tex.width() as f32, tex.height() as f32);
                let dudx = (a1x * du1 + a2x * du2) * tw;
                let dvdx = (a1x * dv1 + a2x * dv2) * th;
                let dudy = (a1y * du1 + a2y * du2) * tw;
                let dvdy = (a1y * dv1 + a2y * dv2) * th;
                let rho2 = (dudx * dudx + dvdx * dvdx).max(dudy * dudy + dvdy * dvdy);
                let lod = 0.5 * rho2.max(1e-20).log2();
                let s = tex.sample(&m.sampler, u, v, lod).unpremultiply();
                rgba[0] *= s.r;
                rgba[1] *= s.g;
                rgba[2] *= s.b;
                rgba[3] *= s.a;
            }
            if let Shading::Lit {
                specular,
                shininess,
            } = m.shading
            {
                let pos = Vec3::new(at(POS, l), at(POS + 1, l), at(POS + 2, l));
                let mut n = Vec3::new(at(NRM, l), at(NRM + 1, l), at(NRM + 2, l));
                // Interpolated normals face the front side: flip them on back faces (two-sided
                // lighting). The face normal already faces the viewer.
                n = if n.length_squared() <= 1e-12 {
                    p.face_normal
                } else if p.front {
                    n.normalize()
                } else {
                    -n.normalize()
                };
                let lit = light(self.lighting, self.eye, pos, n, specular, shininess);
                for c in 0..3 {
                    rgba[c] = rgba[c] * lit[0][c] + lit[1][c];
                }
            }
            rgba[0] += m.emissive.r;
            rgba[1] += m.emissive.g;
            rgba[2] += m.emissive.b;
            for c in 0..4 {
                res[c][l] = rgba[c];
            }
        }
        for c in 0..4 {
            out[c] = F8::from_array(res[c]);
        }
    }
}

/// Diffuse factor and specular term, per RGB channel, at a surface point.
fn light(
    lighting: &Lighting,
    eye: Vec3,
    pos: Vec3,
    n: Vec3,
    spec: f32,
    shin: f32,
) -> [[f32; 3]; 2] {
    let a = lighting.ambient;
    let mut diff = [a.r, a.g, a.b];
    let mut sp = [0.0; 3];
    let view = (eye - pos).normalize_or_zero();
    for light in &lighting.lights {
        let (l, color, att) = match *light {
            Light::Directional { direction, color } => (-direction.normalize_or_zero(), color, 1.0),
            Light::Point {
                position,
                color,
                range,
            } => {
                let d = position - pos;
                let dist = d.length();
                let x = (dist / range.max(1e-6)).min(1.0);
                let falloff = (1.0 - x * x) * (1.0 - x * x) / (1.0 + dist * dist);
                (d / dist.max(1e-12), color, falloff)
            }
        };
        let ndl = n.dot(l);
        if ndl <= 0.0 || !ndl.is_finite() {
            continue;
        }
        let h = (l + view).normalize_or_zero();
        let s = spec * n.dot(h).max(0.0).powf(shin) * att;
        let d = ndl * att;
        diff[0] += color.r * d;
        diff[1] += color.g * d;
        diff[2] += color.b * d;
        sp[0] += color.r * s;
        sp[1] += color.g * s;
        sp[2] += color.b * s;
    }
    [diff, sp]
}
