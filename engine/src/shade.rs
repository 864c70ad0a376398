//! Shade stage: fragment shaders, one per family of materials, each run on a row of 8
//! pixels at a time (or on a pack of a triangle's rows in a block, 8 pixels in all: [`Row`]).
//!
//! A shader first `prepare`s a triangle (fetches its three vertices' varyings once per
//! triangle and tile), then `shade`s rows, writing straight linear RGB and alpha for all 8
//! lanes; the rasterizer decides which lanes it keeps. Attributes are interpolated with
//! perspective-correct barycentrics: `l1 = (l1/w) / (1/w)`, from planes set up per triangle.
//! Texture level of detail comes from the analytic screen-space derivatives of those
//! barycentrics, so no 2x2 quads are needed; one level is taken for a row's (or a pack's)
//! covered lanes, their widest footprint, or once for the whole triangle where bounds on
//! its footprint over its box show the level spreads less than [`lod::LOD_SPREAD`].

use crate::light::{Light, Lighting};
use crate::material::{AlphaMode, Material, Shading};
use crate::setup::{Plane, Tri, FRONT};
use crate::texture::{Filter, Texture};
use crate::vertex::{COL, NRM, POS, UV};
use glam::{Vec3, Vec4};
use std::ops::{Div, Mul};

pub use crate::simd::LANES;
use crate::simd::{F8, M8};
#[cfg(test)]
use lod::{fast_log2, widest, LOD_SPREAD};
pub use lod::{row_lod, triangle_lod};
use nailboard::Parallax;

/// 8 lanes of one channel.
pub type Lane = F8;

/// Where a vector's lanes sit: pixel `x0 + lane` of row `y`, relative to the plane
/// reference; or, for a pack of rows of a triangle in one block shaded together (see
/// `raster`), each lane at its own pixel of its own row.
#[derive(Clone, Copy, Debug)]
pub struct Row {
    /// `x - rx` of the block's first pixel.
    pub fx: f32,
    /// Each lane's `y - ry` (the same in every lane for a whole row).
    pub ys: F8,
    /// Each lane's pixel within the block's row: `F8::ramp()` for a whole row.
    pub xs: F8,
    /// The lanes the triangle covers in this row (bit `l` for lane `l`), whether or not they
    /// pass the depth test: their footprints choose the row's level of detail, so a pixel's
    /// texture level does not depend on what was drawn before it (nor on the pre-pass).
    pub covered: u32,
}

impl Row {
    /// The 8 pixels of row `fy` from the block's first pixel `fx`.
    #[inline(always)]
    pub fn whole(fx: f32, fy: f32, covered: u32) -> Self {
        Row {
            fx,
            ys: F8::splat(fy),
            xs: F8::ramp(),
            covered,
        }
    }
}

/// A plane at the lanes of `row`. Each lane's value is the one a whole row through its pixel
/// gives (the same operations in the same order: `c + dx fx`, plus `dy y`, then `dx x`
/// fused), so packing rows changes no lane's value.
#[inline(always)]
pub fn eval(p: &Plane, row: &Row) -> Lane {
    let base = F8::splat(p.c + p.dx * row.fx) + F8::splat(p.dy) * row.ys;
    F8::splat(p.dx).mul_add(row.xs, base)
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
    /// Straight linear `[r, g, b, a]` for the 8 lanes of `row`; only the lanes set in
    /// `mask` will be used, so a shader may skip per-lane work for the others.
    fn shade(&self, p: &Self::Prepared, tri: &Tri, row: &Row, mask: u32, out: &mut [Lane; 4]);
    /// For a material with a [`crate::material::DepthOffset`], what lies behind the lanes
    /// set in `mask` ([`Behind`]); `None` (the default) where the fragments' depth is the
    /// triangle's. The rasterizer asks this before shading and tests the moved depth
    /// first, so a nailboard's fragments hidden at their own depth, or uncovered, are never
    /// shaded (offset reads only, not the colour's reads and lighting); it then shades the
    /// others with [`FragShader::shade_behind`].
    #[inline(always)]
    fn behind(&self, p: &Self::Prepared, tri: &Tri, row: &Row, mask: u32) -> Option<Behind> {
        let _ = (p, tri, row, mask);
        None
    }
    /// [`FragShader::shade`] for lanes [`FragShader::behind`] found `behind`: reading the
    /// texture where it says each lane's surface is.
    #[inline(always)]
    fn shade_behind(
        &self,
        p: &Self::Prepared,
        tri: &Tri,
        row: &Row,
        mask: u32,
        behind: &Behind,
        out: &mut [Lane; 4],
    ) {
        let _ = behind;
        self.shade(p, tri, row, mask, out);
    }
}

/// What lies behind a nailboard's lanes ([`FragShader::behind`]).
#[derive(Clone, Copy, Debug)]
pub struct Behind {
    /// Each lane's view depth behind the triangle's (view units, `>= 0`).
    pub depth: Lane,
    /// The lanes the offset image covers (the others hold no surface and are dropped).
    pub keep: u32,
    /// Each lane's texture coordinates: the fragment's own, or with
    /// [`crate::material::DepthOffset::parallax`] those of the texel whose surface lies on
    /// its ray.
    pub uv: [Lane; 2],
}

/// The texture coordinates of a [`GeneralShader`]'s triangle at barycentrics `l1`, `l2`.
#[inline(always)]
fn uv_at(p: &GeneralTri, l1: Lane, l2: Lane) -> [Lane; 2] {
    let at = |c: usize| {
        let [a0, d1, d2] = p.attr[c];
        l1.mul_add(F8::splat(d1), l2.mul_add(F8::splat(d2), F8::splat(a0)))
    };
    [at(UV), at(UV + 1)]
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
            tri.color().to_le_bytes().map(|b| b as f32 / 255.0)
        } else {
            self.color
        }
    }
    #[inline]
    fn shade(&self, p: &[f32; 4], _: &Tri, _: &Row, _: u32, out: &mut [Lane; 4]) {
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
    /// `[c0, c1 - c0, c2 - c0]`, channels in a `Vec4` each (one SSE register: no scalar
    /// stores that a wide reload would have to wait for).
    type Prepared = [Vec4; 3];
    #[inline]
    fn prepare(&self, tri: &Tri, vary: &[f32]) -> Self::Prepared {
        let base = Vec4::from_array(self.base);
        let v = |k: usize| {
            let o = tri.vary[k] as usize;
            vary.get(o..o + 4).map_or(Vec4::ZERO, Vec4::from_slice) * base
        };
        let c0 = v(0);
        [c0, v(1) - c0, v(2) - c0]
    }
    #[inline]
    fn shade(&self, p: &Self::Prepared, tri: &Tri, row: &Row, _: u32, out: &mut [Lane; 4]) {
        let (l1, l2, _) = barycentrics(tri, row);
        let [a0, d1, d2] = p.map(|v| v.to_array());
        for c in 0..4 {
            out[c] = l1.mul_add(
                F8::splat(d1[c]),
                l2.mul_add(F8::splat(d2[c]), F8::splat(a0[c])),
            );
        }
    }
}

/// Everything else: textures, vertex colours, Lambert + Blinn-Phong lighting.
#[derive(Debug)]
pub struct GeneralShader<'a> {
    pub material: &'a Material,
    pub lighting: &'a Lighting,
    /// [`light_dirs`] of `lighting`, worked out once a frame.
    pub light_dirs: &'a [Vec3],
    pub eye: Vec3,
}

/// Towards each directional light of `lighting`, unit length (zero for point lights), in
/// `out`: the vector [`GeneralShader`]'s lighting would otherwise normalise on every row.
pub fn light_dirs(lighting: &Lighting, out: &mut Vec<Vec3>) {
    out.clear();
    out.extend(lighting.lights.iter().map(|l| match *l {
        Light::Directional { direction, .. } => -direction.normalize_or_zero(),
        Light::Point { .. } => Vec3::ZERO,
    }));
}

/// Per-triangle data of [`GeneralShader`].
#[derive(Clone, Copy, Debug)]
pub struct GeneralTri {
    /// `[v0, v1 - v0, v2 - v0]` for each of the 12 varyings.
    attr: [[f32; 3]; 12],
    face_normal: Vec3,
    front: bool,
    /// The shading normal when the three vertex normals are the same (flat faces): the
    /// per-lane normalisation's result, worked out once with the same operations.
    flat_normal: Option<Vec3>,
    /// Bit `i` set: light `i` may reach the triangle (bit 63 stands for every light from
    /// 63 on). A point light whose range ends before the triangle's nearest point adds
    /// exactly nothing there, so the shader skips it.
    reach: u64,
    /// Whether the lanes need the interpolated position: only highlights and the point
    /// lights in `reach` read it (worked out once here rather than on every row).
    needs_pos: bool,
    /// One level of detail for all the triangle's rows, when its footprint over the
    /// triangle's box is known to spread less than [`lod::LOD_SPREAD`] levels
    /// ([`triangle_lod`]); `None` works it out row by row ([`row_lod`]).
    lod: Option<f32>,
    /// For a material with a depth offset ([`nailboard::depth_scale`]): the view depth
    /// behind the triangle of a texel offset of 1 (red over alpha) at view depth 1; `None`
    /// without.
    depth_scale: Option<f32>,
    /// For a depth offset with [`crate::material::DepthOffset::parallax`]: the triangle's terms of the
    /// search for each fragment's texel.
    parallax: Option<Parallax>,
}

/// [`GeneralTri::flat_normal`]: the shader's normalisation of a constant interpolated
/// normal, in the same operations and order as its lanes (`x x + (y y + z z)`, then
/// `sign / sqrt`), so flat faces shade to the same bits either way.
fn flat_normal(attr: &[[f32; 3]; 12], face: Vec3, front: bool) -> Option<Vec3> {
    let [x, y, z] = [0, 1, 2].map(|c| attr[NRM + c]);
    if [x, y, z].iter().any(|a| a[1] != 0.0 || a[2] != 0.0) {
        return None;
    }
    let n = Vec3::new(x[0], y[0], z[0]);
    let len2 = n.x * n.x + (n.y * n.y + n.z * n.z);
    // As in the lanes: a NaN length also takes the face normal.
    let has = len2 > 1e-12;
    if !has {
        return Some(face);
    }
    let sign = if front { 1.0 } else { -1.0 };
    let inv = sign / len2.sqrt();
    Some(Vec3::new(n.x * inv, n.y * inv, n.z * inv))
}

/// The bit of light `i` in [`GeneralTri::reach`].
#[inline(always)]
fn light_bit(i: usize) -> u64 {
    1 << i.min(63)
}

/// Which of `lighting`'s lights may reach the triangle `p`: directional lights always; a
/// point light unless the triangle lies wholly beyond its range, judged from the bounding
/// sphere about the centroid with a margin (1% of the range, plus a thousandth of the
/// triangle's radius) that covers the rounding of interpolated positions.
fn reach(lighting: &Lighting, p: [Vec3; 3]) -> u64 {
    let c = (p[0] + p[1] + p[2]) / 3.0;
    let r = p.iter().map(|q| q.distance(c)).fold(0.0f32, f32::max);
    let mut bits = 0;
    for (i, light) in lighting.lights.iter().enumerate() {
        let near = match *light {
            Light::Directional { .. } => true,
            Light::Point {
                position, range, ..
            } => {
                let gap = position.distance(c) - r;
                // NaN anywhere keeps the light (the comparison fails).
                let beyond = gap > range.max(1e-6) * 1.01 + r * 1e-3;
                !beyond
            }
        };
        if near || i >= 63 {
            bits |= light_bit(i);
        }
    }
    bits
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
        let front = tri.flags() & FRONT != 0;
        let (reach, needs_pos) = match self.material.shading {
            Shading::Lit { specular, .. } => {
                let bits = reach(self.lighting, [p(0), p(1), p(2)]);
                let point = |(i, l): (usize, &Light)| {
                    matches!(l, Light::Point { .. }) && bits & light_bit(i) != 0
                };
                let any_point = self.lighting.lights.iter().enumerate().any(point);
                (bits, specular != 0.0 || any_point)
            }
            _ => (0, false),
        };
        // Small triangles (within 8 x 8 pixels) have a few rows to shade: bounding their
        // footprint costs about as much as working it out for each row.
        let lod = match &self.material.base_texture {
            Some(tex)
                if self.material.sampler.filter == Filter::Trilinear
                    && tri.vertices().is_some() =>
            {
                triangle_lod(tri, [attr[UV], attr[UV + 1]], tex)
            }
            _ => None,
        };
        // A nailboard's terms: its offset's view depth, and its parallax search's (`None`
        // without `DepthOffset::parallax`).
        let (depth_scale, parallax) = match (&self.material.depth_offset, self.material.alpha_mode)
        {
            (Some(d), AlphaMode::Mask { .. }) if self.material.base_texture.is_some() => {
                let edges = [p(0), p(1) - p(0), p(2) - p(0)];
                let uv = [attr[UV], attr[UV + 1]];
                (
                    Some(nailboard::depth_scale(d, edges, uv, n, self.eye)),
                    Parallax::new(d, edges, uv, n, self.eye),
                )
            }
            _ => (None, None),
        };
        GeneralTri {
            parallax,
            attr,
            lod,
            depth_scale,
            face_normal: n,
            front,
            flat_normal: flat_normal(&attr, n, front),
            reach,
            needs_pos,
        }
    }

    fn shade(&self, p: &GeneralTri, tri: &Tri, row: &Row, mask: u32, out: &mut [Lane; 4]) {
        self.shade_lanes(p, tri, row, mask, None, out);
    }

    #[inline]
    fn shade_behind(
        &self,
        p: &GeneralTri,
        tri: &Tri,
        row: &Row,
        mask: u32,
        behind: &Behind,
        out: &mut [Lane; 4],
    ) {
        self.shade_lanes(p, tri, row, mask, Some(behind.uv), out);
    }

    #[inline]
    fn behind(&self, p: &GeneralTri, tri: &Tri, row: &Row, mask: u32) -> Option<Behind> {
        let (Some(k), Some(d), Some(tex)) = (
            p.depth_scale,
            &self.material.depth_offset,
            &self.material.base_texture,
        ) else {
            return None;
        };
        let (l1, l2, w) = barycentrics(tri, row);
        let lod = self.lod(p, tri, row, tex, [l1, l2, w]);
        Some(nailboard::behind(
            d,
            &self.material.sampler,
            p.parallax.as_ref(),
            k,
            lod,
            uv_at(p, l1, l2),
            w,
            mask,
        ))
    }
}

impl GeneralShader<'_> {
    /// [`FragShader::shade`], reading the texture at `uv` where given (a nailboard's
    /// [`Behind::uv`]), else at the fragments' own.
    #[inline(always)]
    fn shade_lanes(
        &self,
        p: &GeneralTri,
        tri: &Tri,
        row: &Row,
        mask: u32,
        uv: Option<[Lane; 2]>,
        out: &mut [Lane; 4],
    ) {
        let m = self.material;
        let (l1, l2, w) = barycentrics(tri, row);
        let at = |c: usize| {
            let [a0, d1, d2] = p.attr[c];
            l1.mul_add(F8::splat(d1), l2.mul_add(F8::splat(d2), F8::splat(a0)))
        };
        let base = m.base_color.to_array();
        let mut rgba: [F8; 4] = std::array::from_fn(|c| F8::splat(base[c]));
        if m.vertex_colors {
            for c in 0..4 {
                rgba[c] = rgba[c] * at(COL + c);
            }
        }
        if let Some(tex) = &m.base_texture {
            let lod = self.lod(p, tri, row, tex, [l1, l2, w]);
            let keep = M8::from_bits(mask);
            let [u, v] = uv.unwrap_or_else(|| uv_at(p, l1, l2));
            // A nailboard's colour (shaded through `shade_behind`) is read as its offset is,
            // bilinearly on the level nearest `lod` (`DepthOffset`'s docs).
            let t = match uv {
                Some(_) => tex.bilinear8_lod(&m.sampler, lod, u, v, keep),
                None => tex.sample8_lanes(&m.sampler, u, v, lod, keep),
            };
            if tex.is_opaque() {
                // Alpha 1 everywhere: premultiplied is straight, and alpha stays as it is.
                for c in 0..3 {
                    rgba[c] = rgba[c] * t[c];
                }
            } else {
                // Samples are premultiplied; the shader works in straight colour.
                let a = t[3];
                let inv = a
                    .gt(F8::splat(0.0))
                    .select(F8::splat(1.0) / a, F8::splat(0.0));
                for c in 0..3 {
                    rgba[c] = rgba[c] * t[c] * inv;
                }
                rgba[3] = rgba[3] * a;
            }
        }
        if let Shading::Lit {
            specular,
            shininess,
        } = m.shading
        {
            let pos = if p.needs_pos {
                V3::new(at(POS), at(POS + 1), at(POS + 2))
            } else {
                V3::splat(Vec3::ZERO)
            };
            let n = match p.flat_normal {
                Some(n) => V3::splat(n),
                None => self.normal(p, &at),
            };
            let lit = light8(
                self.lighting,
                self.light_dirs,
                p.reach,
                self.eye,
                &pos,
                &n,
                specular,
                shininess,
            );
            for c in 0..3 {
                rgba[c] = rgba[c].mul_add(lit[0][c], lit[1][c]);
            }
        }
        let e = m.emissive;
        for (c, v) in [e.r, e.g, e.b].into_iter().enumerate() {
            if v != 0.0 {
                rgba[c] = rgba[c] + F8::splat(v);
            }
        }
        *out = rgba;
    }

    /// The texture's level of detail for `row`: one for the triangle where its footprint
    /// hardly varies, else one for the row (the largest footprint among the covered
    /// lanes); 0 for samplers without mipmaps; at most a nailboard's
    /// [`crate::material::DepthOffset::max_lod`].
    #[inline(always)]
    fn lod(&self, p: &GeneralTri, tri: &Tri, row: &Row, tex: &Texture, lw: [Lane; 3]) -> f32 {
        let lod = match (self.material.sampler.filter, p.lod) {
            (Filter::Trilinear, Some(lod)) => lod,
            (Filter::Trilinear, None) => row_lod(tri, [p.attr[UV], p.attr[UV + 1]], tex, row, lw),
            _ => return 0.0,
        };
        match &self.material.depth_offset {
            Some(d) => lod.min(d.max_lod),
            None => lod,
        }
    }

    /// The interpolated normal of 8 lanes, unit length, facing the viewer.
    #[inline(always)]
    fn normal(&self, p: &GeneralTri, at: &impl Fn(usize) -> F8) -> V3 {
        let n = V3::new(at(NRM), at(NRM + 1), at(NRM + 2));
        let len2 = n.dot(&n);
        // Interpolated normals face the front side: flip them on back faces (two-sided
        // lighting). The face normal already faces the viewer; it stands in for missing
        // normals.
        let sign = if p.front { 1.0 } else { -1.0 };
        let has = len2.gt(F8::splat(1e-12));
        let inv_len = has.select(F8::splat(sign) / len2.sqrt(), F8::splat(0.0));
        let f = p.face_normal;
        V3::new(
            has.select(n.x * inv_len, F8::splat(f.x)),
            has.select(n.y * inv_len, F8::splat(f.y)),
            has.select(n.z * inv_len, F8::splat(f.z)),
        )
    }
}

/// Three lanes-of-8 coordinates.
#[derive(Clone, Copy, Debug)]
struct V3 {
    x: F8,
    y: F8,
    z: F8,
}

impl V3 {
    #[inline(always)]
    fn new(x: F8, y: F8, z: F8) -> Self {
        V3 { x, y, z }
    }
    #[inline(always)]
    fn splat(v: Vec3) -> Self {
        V3::new(F8::splat(v.x), F8::splat(v.y), F8::splat(v.z))
    }
    #[inline(always)]
    fn sub(&self, o: &V3) -> V3 {
        V3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
    #[inline(always)]
    fn add(&self, o: &V3) -> V3 {
        V3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
    #[inline(always)]
    fn dot(&self, o: &V3) -> F8 {
        self.x.mul_add(o.x, self.y.mul_add(o.y, self.z * o.z))
    }
    /// Unit length, or zero for a zero vector.
    #[inline(always)]
    fn normalize(&self) -> (V3, F8) {
        let len = self.dot(self).sqrt();
        let inv = len
            .gt(F8::splat(0.0))
            .select(F8::splat(1.0) / len, F8::splat(0.0));
        (V3::new(self.x * inv, self.y * inv, self.z * inv), len)
    }
}

/// Diffuse factor and specular term per RGB channel for 8 surface points: Lambert plus
/// Blinn-Phong, with Schlick's rational stand-in for `pow(n.h, shininess)`
/// (`t / (s - s t + t)`), which needs no transcendental per lane. Lights whose bit is clear
/// in `reach` are skipped (they add exactly zero there).
#[allow(clippy::too_many_arguments)] // reason: the frame's lights and the lanes' surface
fn light8(
    lighting: &Lighting,
    dirs: &[Vec3],
    reach: u64,
    eye: Vec3,
    pos: &V3,
    n: &V3,
    spec: f32,
    shin: f32,
) -> [[F8; 3]; 2] {
    let a = lighting.ambient;
    let zero = F8::splat(0.0);
    let mut diff = [F8::splat(a.r), F8::splat(a.g), F8::splat(a.b)];
    let mut sp = [zero; 3];
    // No highlights: the view and half vectors are not needed (the terms they feed are
    // multiplied by `spec = 0`, so skipping them changes no pixel).
    let highlights = spec != 0.0;
    let view = if highlights {
        V3::splat(eye).sub(pos).normalize().0
    } else {
        V3::splat(Vec3::ZERO)
    };
    let shin = F8::splat(shin.max(0.0));
    for (i, light) in lighting.lights.iter().enumerate() {
        if reach & light_bit(i) == 0 {
            continue;
        }
        let (l, color, att) = match *light {
            Light::Directional { direction, color } => (
                V3::splat(
                    dirs.get(i)
                        .copied()
                        .unwrap_or_else(|| -direction.normalize_or_zero()),
                ),
                color,
                F8::splat(1.0),
            ),
            Light::Point {
                position,
                color,
                range,
            } => {
                let (l, dist) = V3::splat(position).sub(pos).normalize();
                let x = (dist * F8::splat(1.0 / range.max(1e-6))).min(F8::splat(1.0));
                let k = F8::splat(1.0) - x * x;
                (l, color, k * k / dist.mul_add(dist, F8::splat(1.0)))
            }
        };
        let ndl = n.dot(&l).max(zero);
        let d = ndl * att;
        for (c, v) in [color.r, color.g, color.b].into_iter().enumerate() {
            diff[c] = F8::splat(v).mul_add(d, diff[c]);
        }
        if !highlights {
            continue;
        }
        let (h, _) = l.add(&view).normalize();
        let t = n.dot(&h).max(zero);
        let lit = ndl.gt(zero);
        let s = t / (shin - shin * t + t).max(F8::splat(1e-12));
        let s = lit.select(s * F8::splat(spec) * att, zero);
        for (c, v) in [color.r, color.g, color.b].into_iter().enumerate() {
            sp[c] = F8::splat(v).mul_add(s, sp[c]);
        }
    }
    [diff, sp]
}

mod lod;
mod nailboard;
#[cfg(test)]
mod tests;
