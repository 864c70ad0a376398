//! Procedural meshes: tori, spheres, boxes, planes, height fields, terrain and a few game
//! props (trees, rocks, a house), all with unit normals, uvs and vertex colours.
//!
//! Rules: every builder is deterministic (randomness comes from the tiny [`XorShift`] seeded
//! by the caller, never from the system); every mesh passes [`Mesh::validate`]; triangles are
//! counter-clockwise seen from the side their normals point to, so closed meshes have a
//! positive signed volume. Smooth surfaces share vertices (seams are duplicated so uvs stay
//! continuous); faceted props (rocks, tree crowns, houses) use one vertex per corner per
//! face so their normals are the face normals. Meshes are built in object space with +Y up.

mod scenery;
mod shapes;
#[cfg(test)]
mod tests;

pub use scenery::*;
pub use shapes::*;

use crate::color::Rgba;
use crate::mesh::Mesh;
use glam::{Mat4, Vec2, Vec3};
use std::f32::consts::{PI, TAU};

/// A tiny xorshift64* generator: deterministic, seedable, good enough for scenery.
#[derive(Clone, Debug)]
pub struct XorShift(u64);

impl XorShift {
    /// A generator from any seed (0 included).
    pub fn new(seed: u64) -> Self {
        // splitmix64 of the seed, so nearby seeds give unrelated streams and 0 is not stuck.
        let mut z = seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        XorShift((z ^ (z >> 31)) | 1)
    }

    /// The next 64 pseudo-random bits (xorshift64*: period 2^64 - 1, not for cryptography).
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    /// Uniform in [0, 1).
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next_f32()
    }
}

/// Collects vertices and triangles.
#[derive(Debug, Default)]
pub(super) struct Builder {
    mesh: Mesh,
}

impl Builder {
    pub(super) fn vertex(&mut self, p: Vec3, n: Vec3, uv: Vec2, c: Rgba) -> u32 {
        let m = &mut self.mesh;
        m.positions.push(p);
        m.normals.push(n.normalize_or(Vec3::Y));
        m.uvs.push(uv);
        m.colors.push(c);
        (m.positions.len() - 1) as u32
    }

    pub(super) fn tri(&mut self, a: u32, b: u32, c: u32) {
        self.mesh.indices.extend([a, b, c]);
    }

    /// A faceted triangle, wound so its normal agrees with `outward`.
    pub(super) fn flat_tri(&mut self, mut p: [Vec3; 3], c: Rgba, outward: Vec3) {
        let mut n = (p[1] - p[0]).cross(p[2] - p[0]);
        if n.dot(outward) < 0.0 {
            p.swap(1, 2);
            n = -n;
        }
        let n = n.normalize_or(outward.normalize_or(Vec3::Y));
        let uv = planar_uvs(&p, n);
        for k in 0..3 {
            let i = self.vertex(p[k], n, uv[k], c);
            self.mesh.indices.push(i);
        }
    }

    /// A faceted planar quad `p0 p1 p2 p3` (in order around its edge), uvs at its corners.
    pub(super) fn flat_quad(&mut self, p: [Vec3; 4], c: Rgba, outward: Vec3) {
        let mut n = (p[1] - p[0]).cross(p[2] - p[0]);
        let mut order = [0usize, 1, 2, 3];
        if n.dot(outward) < 0.0 {
            order = [0, 3, 2, 1];
            n = -n;
        }
        let n = n.normalize_or(Vec3::Y);
        let uvs = [
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 0.0),
        ];
        let base = self.mesh.positions.len() as u32;
        for &k in &order {
            self.vertex(p[k], n, uvs[k], c);
        }
        self.tri(base, base + 1, base + 2);
        self.tri(base, base + 2, base + 3);
    }

    /// Triangles of a `u` x `v` cell lattice of `(u + 1) * (v + 1)` vertices starting at
    /// `base`, vertex `(i, j)` at `base + i * (v + 1) + j`; each triangle is wound to agree
    /// with its vertices' normals.
    pub(super) fn lattice(&mut self, base: u32, u: u32, v: u32) {
        let nv = v + 1;
        for i in 0..u {
            for j in 0..v {
                let a = base + i * nv + j;
                let b = base + (i + 1) * nv + j;
                let c = base + (i + 1) * nv + j + 1;
                let d = base + i * nv + j + 1;
                self.oriented_tri(a, b, c);
                self.oriented_tri(a, c, d);
            }
        }
    }

    /// A triangle over existing vertices, wound to agree with the sum of their normals.
    pub(super) fn oriented_tri(&mut self, a: u32, b: u32, c: u32) {
        let m = &self.mesh;
        let [pa, pb, pc] = [a, b, c].map(|i| m.positions[i as usize]);
        let n = [a, b, c].map(|i| m.normals[i as usize]);
        let geo = (pb - pa).cross(pc - pa);
        if geo.dot(n[0] + n[1] + n[2]) < 0.0 {
            self.tri(a, c, b);
        } else {
            self.tri(a, b, c);
        }
    }

    pub(super) fn finish(self) -> Mesh {
        debug_assert!(self.mesh.validate().is_ok());
        self.mesh
    }
}

/// Uvs for a facet: its corners projected on the plane across its dominant normal axis.
pub(super) fn planar_uvs(p: &[Vec3; 3], n: Vec3) -> [Vec2; 3] {
    let a = n.abs();
    p.map(|q| {
        if a.x >= a.y && a.x >= a.z {
            Vec2::new(q.z, -q.y)
        } else if a.y >= a.z {
            Vec2::new(q.x, q.z)
        } else {
            Vec2::new(q.x, -q.y)
        }
    })
}

/// `0.5 + 0.5 n`, the peers' colour-from-normal rule.
pub(super) fn normal_color(n: Vec3) -> Rgba {
    let c = (n * 0.5 + Vec3::splat(0.5)).clamp(Vec3::ZERO, Vec3::ONE);
    Rgba::new(c.x, c.y, c.z, 1.0)
}

/// `(u, v)` with `u * v == quads` and `u / v` as close to `aspect` as possible (the peers'
/// `_factor_grid`); falls back to an approximate grid when `quads` factors badly.
pub fn factor_grid(quads: u32, aspect: f32) -> (u32, u32) {
    let quads = quads.max(1);
    let mut best: Option<(f32, u32, u32)> = None;
    let mut v = 1;
    while v * v <= quads {
        if quads.is_multiple_of(v) {
            let u = quads / v;
            let score = ((u as f32 / v as f32) / aspect).ln().abs();
            if best.is_none_or(|b| score < b.0) {
                best = Some((score, u, v));
            }
        }
        v += 1;
    }
    match best {
        Some((score, u, v)) if score < 8f32.ln() => (u, v),
        _ => {
            let v = ((quads as f32 / aspect).sqrt().round() as u32).max(1);
            let u = ((quads as f32 / v as f32).round() as u32).max(1);
            (u, v)
        }
    }
}
