//! Procedural meshes: tori, spheres, boxes, planes, height fields, terrain and a few game
//! props (trees, rocks, a house), all with unit normals, uvs and vertex colours.
//!
//! Rules: every builder is deterministic (randomness comes from the tiny [`XorShift`] seeded
//! by the caller, never from the system); every mesh passes [`Mesh::validate`]; triangles are
//! counter-clockwise seen from the side their normals point to, so closed meshes have a
//! positive signed volume. Smooth surfaces share vertices (seams are duplicated so uvs stay
//! continuous); faceted props (rocks, tree crowns, houses) use one vertex per corner per
//! face so their normals are the face normals. Meshes are built in object space with +Y up.

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
struct Builder {
    mesh: Mesh,
}

impl Builder {
    fn vertex(&mut self, p: Vec3, n: Vec3, uv: Vec2, c: Rgba) -> u32 {
        let m = &mut self.mesh;
        m.positions.push(p);
        m.normals.push(n.normalize_or(Vec3::Y));
        m.uvs.push(uv);
        m.colors.push(c);
        (m.positions.len() - 1) as u32
    }

    fn tri(&mut self, a: u32, b: u32, c: u32) {
        self.mesh.indices.extend([a, b, c]);
    }

    /// A faceted triangle, wound so its normal agrees with `outward`.
    fn flat_tri(&mut self, mut p: [Vec3; 3], c: Rgba, outward: Vec3) {
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
    fn flat_quad(&mut self, p: [Vec3; 4], c: Rgba, outward: Vec3) {
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
    fn lattice(&mut self, base: u32, u: u32, v: u32) {
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
    fn oriented_tri(&mut self, a: u32, b: u32, c: u32) {
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

    fn finish(self) -> Mesh {
        debug_assert!(self.mesh.validate().is_ok());
        self.mesh
    }
}

/// Uvs for a facet: its corners projected on the plane across its dominant normal axis.
fn planar_uvs(p: &[Vec3; 3], n: Vec3) -> [Vec2; 3] {
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
fn normal_color(n: Vec3) -> Rgba {
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

/// A torus around the Y axis: `u` segments around the ring of radius `major`, `v` around
/// the tube of radius `minor`; exactly `2 * u * v` triangles. Colours follow the normals.
pub fn torus(major: f32, minor: f32, u: u32, v: u32) -> Mesh {
    let (u, v) = (u.max(3), v.max(3));
    let mut b = Builder::default();
    for i in 0..=u {
        let th = TAU * i as f32 / u as f32;
        let (s, c) = th.sin_cos();
        for j in 0..=v {
            let ph = TAU * j as f32 / v as f32;
            let n = Vec3::new(c * ph.cos(), ph.sin(), s * ph.cos());
            let p = Vec3::new(c * major, 0.0, s * major) + minor * n;
            let uv = Vec2::new(i as f32 / u as f32, j as f32 / v as f32);
            b.vertex(p, n, uv, normal_color(n));
        }
    }
    b.lattice(0, u, v);
    b.finish()
}

/// The peers' torus (major 0.95, minor 0.38, untilted) with `n` triangles: exactly `n`
/// when `n / 2` factors into a grid of aspect between 1/4 and 16 (every even `n` the
/// benchmarks use does), otherwise the closest such grid.
pub fn torus_with_triangles(n: u32) -> Mesh {
    let (u, v) = factor_grid((n / 2).max(9), 2.0);
    torus(0.95, 0.38, u.max(3), v.max(3))
}

/// A UV sphere of `rings` latitude bands and `segments` longitude segments:
/// `2 * segments * (rings - 1)` triangles (one triangle per segment at each pole).
pub fn uv_sphere(radius: f32, rings: u32, segments: u32) -> Mesh {
    let (r, s) = (rings.max(2), segments.max(3));
    let mut b = Builder::default();
    for i in 0..=r {
        let lat = PI * i as f32 / r as f32;
        for j in 0..=s {
            let lon = TAU * j as f32 / s as f32;
            // Pole vertices sit at the segment's middle longitude so their uvs are centred.
            let lon_uv = if i == 0 || i == r {
                (j as f32 + 0.5) / s as f32
            } else {
                j as f32 / s as f32
            };
            let n = Vec3::new(lat.sin() * lon.cos(), lat.cos(), -lat.sin() * lon.sin());
            let uv = Vec2::new(lon_uv, i as f32 / r as f32);
            b.vertex(n * radius, n, uv, normal_color(n));
        }
    }
    let nv = s + 1;
    for i in 0..r {
        for j in 0..s {
            let a = i * nv + j;
            let bb = (i + 1) * nv + j;
            let c = (i + 1) * nv + j + 1;
            let d = i * nv + j + 1;
            if i != 0 {
                b.oriented_tri(a, bb, d);
            }
            if i != r - 1 {
                b.oriented_tri(bb, c, d);
            }
        }
    }
    b.finish()
}

/// An axis-aligned box of the given full size centred on the origin: 12 triangles, one
/// uv square per face, white.
pub fn cuboid(size: Vec3) -> Mesh {
    let mut b = Builder::default();
    add_box(&mut b, Vec3::ZERO, size * 0.5, Rgba::WHITE);
    b.finish()
}

fn add_box(b: &mut Builder, center: Vec3, half: Vec3, color: Rgba) {
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let n = Vec3::from_array(std::array::from_fn(|k| if k == axis { sign } else { 0.0 }));
            let (t1, t2) = match axis {
                0 => (Vec3::Z, Vec3::Y),
                1 => (Vec3::X, Vec3::Z),
                _ => (Vec3::X, Vec3::Y),
            };
            let c = center + n * half;
            let (e1, e2) = (t1 * half, t2 * half);
            b.flat_quad(
                [c - e1 - e2, c + e1 - e2, c + e1 + e2, c - e1 + e2],
                color,
                n,
            );
        }
    }
}

/// A flat `width` x `depth` plane in XZ facing +Y, cut into `nx` x `nz` cells:
/// `2 * nx * nz` triangles, uvs spanning [0, 1], white.
pub fn plane(width: f32, depth: f32, nx: u32, nz: u32) -> Mesh {
    let (nx, nz) = (nx.max(1), nz.max(1));
    let mut b = Builder::default();
    for i in 0..=nx {
        for j in 0..=nz {
            let (fu, fv) = (i as f32 / nx as f32, j as f32 / nz as f32);
            let p = Vec3::new((fu - 0.5) * width, 0.0, (fv - 0.5) * depth);
            b.vertex(p, Vec3::Y, Vec2::new(fu, fv), Rgba::WHITE);
        }
    }
    b.lattice(0, nx, nz);
    b.finish()
}

/// A `width` x `height` quad in XY facing +Z, centred on the origin (a card or billboard):
/// 2 triangles, uvs with v down.
pub fn quad(width: f32, height: f32) -> Mesh {
    let (hw, hh) = (width * 0.5, height * 0.5);
    let mut b = Builder::default();
    b.vertex(
        Vec3::new(-hw, -hh, 0.0),
        Vec3::Z,
        Vec2::new(0.0, 1.0),
        Rgba::WHITE,
    );
    b.vertex(
        Vec3::new(hw, -hh, 0.0),
        Vec3::Z,
        Vec2::new(1.0, 1.0),
        Rgba::WHITE,
    );
    b.vertex(
        Vec3::new(hw, hh, 0.0),
        Vec3::Z,
        Vec2::new(1.0, 0.0),
        Rgba::WHITE,
    );
    b.vertex(
        Vec3::new(-hw, hh, 0.0),
        Vec3::Z,
        Vec2::new(0.0, 0.0),
        Rgba::WHITE,
    );
    b.tri(0, 1, 2);
    b.tri(0, 2, 3);
    b.finish()
}

/// The peers' `grid`: a wavy height field `z = amp sin(3.1 x) cos(2.3 y)` over
/// `[-half_w, half_w] x [-half_h, half_h]`, facing +Z, with about `n` triangles (exactly
/// `n` for even `n` that factor well, as [`torus_with_triangles`]); colours from position.
pub fn wave_grid(n: u32, half_w: f32, half_h: f32, amp: f32) -> Mesh {
    let (u, v) = factor_grid((n / 2).max(1), half_w / half_h);
    let mut b = Builder::default();
    for i in 0..=u {
        let x = -half_w + 2.0 * half_w * i as f32 / u as f32;
        for j in 0..=v {
            let y = -half_h + 2.0 * half_h * j as f32 / v as f32;
            let z = amp * (3.1 * x).sin() * (2.3 * y).cos();
            let dzdx = amp * 3.1 * (3.1 * x).cos() * (2.3 * y).cos();
            let dzdy = -amp * 2.3 * (3.1 * x).sin() * (2.3 * y).sin();
            let n = Vec3::new(-dzdx, -dzdy, 1.0);
            let (fu, fv) = (i as f32 / u as f32, j as f32 / v as f32);
            let zc = if amp != 0.0 { z / (2.0 * amp) } else { 0.0 };
            let c = Rgba::new(fu, fv, 0.5 + zc * 0.5, 1.0);
            b.vertex(Vec3::new(x, y, z), n, Vec2::new(fu, 1.0 - fv), c);
        }
    }
    b.lattice(0, u, v);
    b.finish()
}

/// Smooth lattice value noise in [0, 1] with quintic fade, seeded.
pub fn value_noise(x: f32, z: f32, seed: u64) -> f32 {
    fn hash(ix: i32, iz: i32, seed: u64) -> f32 {
        let mut h = seed
            ^ (ix as u32 as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
            ^ (iz as u32 as u64).wrapping_mul(0xc2b2_ae3d_27d4_eb4f);
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
        h ^= h >> 33;
        (h >> 40) as f32 / (1u64 << 24) as f32
    }
    let (fx, fz) = (x.floor(), z.floor());
    let (ix, iz) = (fx as i32, fz as i32);
    let (tx, tz) = (x - fx, z - fz);
    let fade = |t: f32| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let (sx, sz) = (fade(tx), fade(tz));
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let top = lerp(hash(ix, iz, seed), hash(ix + 1, iz, seed), sx);
    let bottom = lerp(hash(ix, iz + 1, seed), hash(ix + 1, iz + 1, seed), sx);
    lerp(top, bottom, sz)
}

/// A terrain height field: fractal value noise, optionally flattened near the centre so a
/// scene can stand there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Terrain {
    /// Side of the square patch, centred on the origin in XZ.
    pub size: f32,
    /// Cells per side: the mesh has `2 * cells * cells` triangles.
    pub cells: u32,
    /// Peak-to-valley height scale.
    pub height: f32,
    /// Size of the largest noise feature.
    pub feature: f32,
    /// Within this distance of the origin the ground eases to height 0.
    pub flat_radius: f32,
    pub seed: u64,
}

impl Default for Terrain {
    fn default() -> Self {
        Terrain {
            size: 80.0,
            cells: 96,
            height: 7.0,
            feature: 18.0,
            flat_radius: 12.0,
            seed: 7,
        }
    }
}

impl Terrain {
    /// Ground height at a world XZ point (any point, inside the patch or not).
    pub fn height_at(&self, x: f32, z: f32) -> f32 {
        let mut sum = 0.0;
        let (mut amp, mut freq, mut norm) = (1.0, 1.0 / self.feature.max(1e-3), 0.0);
        for octave in 0..5u64 {
            sum += amp * value_noise(x * freq, z * freq, self.seed.wrapping_add(octave * 101));
            norm += amp;
            amp *= 0.5;
            freq *= 2.0;
        }
        let h = (sum / norm - 0.35) * self.height;
        let r = (x * x + z * z).sqrt();
        if self.flat_radius > 0.0 {
            let t = ((r - self.flat_radius) / self.flat_radius).clamp(0.0, 1.0);
            let t = t * t * (3.0 - 2.0 * t);
            h * t
        } else {
            h
        }
    }

    /// Unit normal of the ground at a world XZ point (central differences).
    pub fn normal_at(&self, x: f32, z: f32) -> Vec3 {
        let e = 0.5 * self.size / self.cells.max(1) as f32;
        let dx = self.height_at(x + e, z) - self.height_at(x - e, z);
        let dz = self.height_at(x, z + e) - self.height_at(x, z - e);
        Vec3::new(-dx, 2.0 * e, -dz).normalize_or(Vec3::Y)
    }

    /// The mesh: colours by height and slope (sand, grass, rock, snow), uvs of one unit per
    /// 4 world units (for a tiling texture).
    pub fn mesh(&self) -> Mesh {
        let n = self.cells.max(1);
        let mut b = Builder::default();
        let sand = Rgba::from_srgb8(194, 178, 128);
        let grass = Rgba::from_srgb8(86, 140, 58);
        let rock = Rgba::from_srgb8(120, 112, 104);
        let snow = Rgba::from_srgb8(235, 238, 245);
        let mix = |a: Rgba, b: Rgba, t: f32| {
            let t = t.clamp(0.0, 1.0);
            Rgba::new(
                a.r + (b.r - a.r) * t,
                a.g + (b.g - a.g) * t,
                a.b + (b.b - a.b) * t,
                1.0,
            )
        };
        for i in 0..=n {
            let x = (i as f32 / n as f32 - 0.5) * self.size;
            for j in 0..=n {
                let z = (j as f32 / n as f32 - 0.5) * self.size;
                let y = self.height_at(x, z);
                let nrm = self.normal_at(x, z);
                let rel = y / self.height.max(1e-3);
                let mut c = mix(sand, grass, (rel + 0.08) * 12.0);
                c = mix(c, rock, (0.93 - nrm.y) * 8.0);
                c = mix(c, snow, (rel - 0.45) * 8.0);
                b.vertex(Vec3::new(x, y, z), nrm, Vec2::new(x, z) * 0.25, c);
            }
        }
        b.lattice(0, n, n);
        b.finish()
    }
}

/// A closed cylinder of radius `radius` from y = 0 to y = `height`: `4 * segments`
/// triangles (smooth side, flat fanned caps), white.
pub fn cylinder(radius: f32, height: f32, segments: u32) -> Mesh {
    let mut b = Builder::default();
    add_cylinder(
        &mut b,
        Mat4::IDENTITY,
        radius,
        radius,
        height,
        segments,
        Rgba::WHITE,
    );
    b.finish()
}

/// A frustum (cylinder when `r0 == r1`) transformed by `xf` (rigid plus uniform scale).
fn add_cylinder(b: &mut Builder, xf: Mat4, r0: f32, r1: f32, h: f32, segments: u32, c: Rgba) {
    let s = segments.max(3);
    let base = b.mesh.positions.len() as u32;
    let slope = (r0 - r1) / h.max(1e-6);
    for i in 0..=s {
        let th = TAU * i as f32 / s as f32;
        let (sn, cs) = th.sin_cos();
        let n = xf.transform_vector3(Vec3::new(cs, slope, -sn));
        for (k, (r, y)) in [(r0, 0.0), (r1, h)].into_iter().enumerate() {
            let p = xf.transform_point3(Vec3::new(cs * r, y, -sn * r));
            b.vertex(p, n, Vec2::new(i as f32 / s as f32, 1.0 - k as f32), c);
        }
    }
    b.lattice(base, s, 1);
    for (r, y, ny) in [(r0, 0.0, -1.0), (r1, h, 1.0)] {
        let n = xf.transform_vector3(Vec3::new(0.0, ny, 0.0));
        let center = b.vertex(
            xf.transform_point3(Vec3::new(0.0, y, 0.0)),
            n,
            Vec2::splat(0.5),
            c,
        );
        let first = b.mesh.positions.len() as u32;
        for i in 0..s {
            let th = TAU * i as f32 / s as f32;
            let (sn, cs) = th.sin_cos();
            let p = xf.transform_point3(Vec3::new(cs * r, y, -sn * r));
            b.vertex(p, n, Vec2::new(0.5 + 0.5 * cs, 0.5 + 0.5 * sn), c);
        }
        for i in 0..s {
            b.oriented_tri(center, first + i, first + (i + 1) % s);
        }
    }
}

/// A closed cone of base radius `radius` on y = 0 with its apex at y = `height`:
/// `2 * segments` triangles, faceted, white.
pub fn cone(radius: f32, height: f32, segments: u32) -> Mesh {
    let mut b = Builder::default();
    add_cone(
        &mut b,
        Vec3::ZERO,
        radius,
        height,
        segments,
        Rgba::WHITE,
        None,
    );
    b.finish()
}

/// A faceted cone; `jitter` shades alternate facets slightly for a low-poly look.
fn add_cone(
    b: &mut Builder,
    at: Vec3,
    r: f32,
    h: f32,
    segments: u32,
    c: Rgba,
    mut rng: Option<&mut XorShift>,
) {
    let s = segments.max(3);
    let apex = at + Vec3::Y * h;
    let center = at + Vec3::Y * (h / 3.0);
    let ring = |i: u32| {
        let th = TAU * i as f32 / s as f32;
        at + Vec3::new(th.cos() * r, 0.0, -th.sin() * r)
    };
    for i in 0..s {
        let (p0, p1) = (ring(i), ring(i + 1));
        let shade = rng.as_deref_mut().map_or(1.0, |g| g.range(0.85, 1.1));
        let cc = Rgba::new(c.r * shade, c.g * shade, c.b * shade, c.a);
        let mid = (p0 + p1 + apex) / 3.0;
        b.flat_tri([p0, p1, apex], cc, mid - center);
        b.flat_tri([p0, at, p1], cc, -Vec3::Y);
    }
}

/// An icosphere: the icosahedron subdivided `subdivisions` times, `20 * 4^k` triangles,
/// smooth normals, spherical uvs, white.
pub fn icosphere(radius: f32, subdivisions: u32) -> Mesh {
    let (verts, tris) = ico_lattice(subdivisions.min(7));
    let mut b = Builder::default();
    for v in &verts {
        let uv = Vec2::new(0.5 + v.z.atan2(v.x) / TAU, 0.5 - v.y.asin() / PI);
        b.vertex(*v * radius, *v, uv, Rgba::WHITE);
    }
    for t in tris {
        b.oriented_tri(t[0], t[1], t[2]);
    }
    b.finish()
}

/// Unit-sphere vertices and triangles of a subdivided icosahedron (shared vertices).
fn ico_lattice(subdivisions: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut verts: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .into_iter()
    .map(|(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut tris: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut mids = std::collections::HashMap::new();
        let mut mid = |a: u32, b: u32, verts: &mut Vec<Vec3>| -> u32 {
            *mids.entry((a.min(b), a.max(b))).or_insert_with(|| {
                verts.push(((verts[a as usize] + verts[b as usize]) * 0.5).normalize());
                (verts.len() - 1) as u32
            })
        };
        let mut next = Vec::with_capacity(tris.len() * 4);
        for [a, b, c] in tris {
            let ab = mid(a, b, &mut verts);
            let bc = mid(b, c, &mut verts);
            let ca = mid(c, a, &mut verts);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        tris = next;
    }
    (verts, tris)
}

/// A faceted blob: an icosphere of `subdivisions` whose vertices are pushed in and out by
/// `bumpiness` (a fraction of the radius), squashed vertically by `squash`.
fn add_blob(
    b: &mut Builder,
    center: Vec3,
    radius: f32,
    squash: f32,
    subdivisions: u32,
    bumpiness: f32,
    color: Rgba,
    rng: &mut XorShift,
) {
    let (verts, tris) = ico_lattice(subdivisions);
    let pts: Vec<Vec3> = verts
        .iter()
        .map(|v| {
            let r = radius * (1.0 + rng.range(-bumpiness, bumpiness));
            center + Vec3::new(v.x * r, v.y * r * squash, v.z * r)
        })
        .collect();
    for t in tris {
        let p = t.map(|i| pts[i as usize]);
        let shade = rng.range(0.88, 1.08);
        let c = Rgba::new(color.r * shade, color.g * shade, color.b * shade, color.a);
        // The bumps are small against the radius, so the facet faces away from the centre.
        b.flat_tri(p, c, (p[0] + p[1] + p[2]) / 3.0 - center);
    }
}

/// What kind of crown a [`tree`] gets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TreeKind {
    /// Stacked cones.
    Pine,
    /// A lumpy faceted ball.
    Broadleaf,
}

/// A low-poly tree standing on the origin, about `height` tall: a tapered trunk and a
/// crown, vertex-coloured (bark brown, leaf green varied by `seed`), under 500 triangles.
pub fn tree(kind: TreeKind, height: f32, seed: u64) -> Mesh {
    let mut rng = XorShift::new(seed);
    let mut b = Builder::default();
    let bark = Rgba::from_srgb8(96, 64, 40);
    let trunk_h = height * if kind == TreeKind::Pine { 0.3 } else { 0.45 };
    let trunk_r = height * 0.05;
    add_cylinder(
        &mut b,
        Mat4::IDENTITY,
        trunk_r,
        trunk_r * 0.7,
        trunk_h + height * 0.05,
        8,
        bark,
    );
    let hue = rng.range(-0.08, 0.08);
    let leaf = Rgba::new((0.07 + hue).max(0.0), 0.32 + hue * 0.5, 0.06, 1.0);
    match kind {
        TreeKind::Pine => {
            let layers = 3;
            let crown_h = height - trunk_h;
            for k in 0..layers {
                let f = k as f32 / layers as f32;
                let y = trunk_h + crown_h * f * 0.62;
                let r = height * 0.28 * (1.0 - f * 0.55);
                add_cone(
                    &mut b,
                    Vec3::new(0.0, y, 0.0),
                    r,
                    crown_h * (1.0 - f * 0.62),
                    9,
                    leaf,
                    Some(&mut rng),
                );
            }
        }
        TreeKind::Broadleaf => {
            let r = height * 0.3;
            let leaf = Rgba::new(leaf.r * 1.3, leaf.g * 1.25, leaf.b, 1.0);
            add_blob(
                &mut b,
                Vec3::new(0.0, height - r, 0.0),
                r,
                0.9,
                1,
                0.12,
                leaf,
                &mut rng,
            );
        }
    }
    b.finish()
}

/// A faceted grey rock of about `radius` centred on the origin (80 triangles).
pub fn rock(radius: f32, seed: u64) -> Mesh {
    let mut rng = XorShift::new(seed);
    let mut b = Builder::default();
    let g = rng.range(0.28, 0.4);
    let color = Rgba::new(g, g * 0.97, g * 0.92, 1.0);
    add_blob(&mut b, Vec3::ZERO, radius, 0.65, 1, 0.22, color, &mut rng);
    b.finish()
}

/// A small house standing on the origin: `width` (X) by `depth` (Z) walls `wall_h` high,
/// a gabled roof `roof_h` high along X, a door on +Z and a chimney; 44 triangles,
/// vertex-coloured.
pub fn house(width: f32, depth: f32, wall_h: f32, roof_h: f32) -> Mesh {
    let mut b = Builder::default();
    let (hw, hd) = (width * 0.5, depth * 0.5);
    let wall = Rgba::from_srgb8(226, 214, 186);
    let roof = Rgba::from_srgb8(150, 52, 40);
    let door = Rgba::from_srgb8(80, 50, 30);
    add_box(
        &mut b,
        Vec3::new(0.0, wall_h * 0.5, 0.0),
        Vec3::new(hw, wall_h * 0.5, hd),
        wall,
    );
    // Roof prism with a small overhang: ridge along X.
    let (ow, od) = (hw * 1.08, hd * 1.15);
    let y0 = wall_h;
    let y1 = wall_h + roof_h;
    let center = Vec3::new(0.0, y0 + roof_h / 3.0, 0.0);
    let [a, bb, c, d] = [
        Vec3::new(-ow, y0, od),
        Vec3::new(ow, y0, od),
        Vec3::new(ow, y0, -od),
        Vec3::new(-ow, y0, -od),
    ];
    let (r0, r1) = (Vec3::new(-ow, y1, 0.0), Vec3::new(ow, y1, 0.0));
    let out = |p: &[Vec3]| p.iter().copied().sum::<Vec3>() / p.len() as f32 - center;
    b.flat_quad([a, bb, r1, r0], roof, out(&[a, bb, r1, r0]));
    b.flat_quad([c, d, r0, r1], roof, out(&[c, d, r0, r1]));
    b.flat_quad([a, d, c, bb], roof, -Vec3::Y);
    b.flat_tri([a, r0, d], wall, -Vec3::X);
    b.flat_tri([bb, c, r1], wall, Vec3::X);
    // Door: a thin slab on the +Z wall.
    add_box(
        &mut b,
        Vec3::new(0.0, wall_h * 0.3, hd + 0.02),
        Vec3::new(width * 0.1, wall_h * 0.3, 0.02),
        door,
    );
    // Chimney through the back slope.
    add_box(
        &mut b,
        Vec3::new(hw * 0.5, y0 + roof_h * 0.8, -hd * 0.4),
        Vec3::new(width * 0.06, roof_h * 0.55, width * 0.06),
        roof,
    );
    b.finish()
}

/// A few huge overlapping, interpenetrating triangles facing +Z around the origin, as the
/// peers' `huge` scene (fill-rate bound): `n` triangles, each covering much of a view of
/// the unit square from z = 3.
pub fn huge_triangles(n: u32, seed: u64) -> Mesh {
    let mut rng = XorShift::new(seed);
    let mut b = Builder::default();
    let n = n.max(1);
    for k in 0..n {
        let z = -1.0 + 2.0 * (((k as u64 * 7919) % n as u64) as f32 + 0.5) / n as f32;
        let ang = rng.range(0.0, TAU);
        let r = rng.range(1.8, 3.2);
        let (cx, cy) = (rng.range(-0.7, 0.7), rng.range(-0.7, 0.7));
        let p: [Vec3; 3] = std::array::from_fn(|m| {
            let a = ang + m as f32 * TAU / 3.0 + rng.range(-0.3, 0.3);
            let dz = rng.range(-0.45, 0.45);
            Vec3::new(
                cx + r * a.cos(),
                cy + r * a.sin(),
                (z + dz).clamp(-1.15, 1.15),
            )
        });
        let c = Rgba::new(
            rng.range(0.15, 1.0),
            rng.range(0.15, 1.0),
            rng.range(0.15, 1.0),
            1.0,
        );
        b.flat_tri(p, c, Vec3::Z);
    }
    b.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Six times the signed volume: positive when triangles wind counter-clockwise seen
    /// from outside.
    fn volume(m: &Mesh) -> f32 {
        m.indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b, c] = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
                a.dot(b.cross(c))
            })
            .sum::<f32>()
            / 6.0
    }

    /// Every triangle's winding agrees with its vertices' normals.
    fn winding_matches_normals(m: &Mesh) -> bool {
        m.indices.chunks_exact(3).all(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
            let n: Vec3 = t.iter().map(|&i| m.normals[i as usize]).sum();
            let g = (b - a).cross(c - a);
            g.length_squared() == 0.0 || g.dot(n) > 0.0
        })
    }

    fn check(m: &Mesh, closed: bool) {
        m.validate().unwrap();
        let n = m.positions.len();
        assert!(n > 0);
        assert_eq!(m.normals.len(), n);
        assert_eq!(m.uvs.len(), n);
        assert_eq!(m.colors.len(), n);
        for nrm in &m.normals {
            assert!((nrm.length() - 1.0).abs() < 1e-4, "normal {nrm}");
        }
        assert!(m.positions.iter().all(|p| p.is_finite()));
        assert!(m.uvs.iter().all(|p| p.is_finite()));
        assert!(winding_matches_normals(m));
        if closed {
            assert!(volume(m) > 0.0, "signed volume {}", volume(m));
        }
    }

    #[test]
    fn torus_has_exactly_2uv_triangles_and_encloses_its_volume() {
        let m = torus(1.0, 0.25, 48, 24);
        assert_eq!(m.triangle_count(), 2 * 48 * 24);
        check(&m, true);
        let exact = 2.0 * PI * PI * 1.0 * 0.25 * 0.25;
        assert!((volume(&m) - exact).abs() < 0.05 * exact);
        for (p, n) in m.positions.iter().zip(&m.normals) {
            let ring = Vec3::new(p.x, 0.0, p.z).normalize() * 1.0;
            assert!((*p - ring).normalize().dot(*n) > 0.999);
        }
    }

    #[test]
    fn torus_with_triangles_is_exact_for_benchmark_sizes() {
        for n in [1_000, 10_000, 100_000, 1_000_000, 2_000_000] {
            assert_eq!(factor_grid(n / 2, 2.0).0 * factor_grid(n / 2, 2.0).1, n / 2);
        }
        let m = torus_with_triangles(10_000);
        assert_eq!(m.triangle_count(), 10_000);
        check(&m, true);
    }

    #[test]
    fn sphere_counts_volume_and_outward_normals() {
        let m = uv_sphere(2.0, 12, 20);
        assert_eq!(m.triangle_count(), 2 * 20 * 11);
        check(&m, true);
        let exact = 4.0 / 3.0 * PI * 8.0;
        assert!((volume(&m) - exact).abs() < 0.05 * exact);
        for (p, n) in m.positions.iter().zip(&m.normals) {
            assert!(p.normalize().dot(*n) > 0.999);
        }
    }

    #[test]
    fn box_plane_quad() {
        let b = cuboid(Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(b.triangle_count(), 12);
        check(&b, true);
        assert!((volume(&b) - 6.0).abs() < 1e-4);
        let p = plane(4.0, 2.0, 5, 3);
        assert_eq!(p.triangle_count(), 30);
        check(&p, false);
        assert!(p.indices.chunks_exact(3).all(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| p.positions[t[k] as usize]);
            (b - a).cross(c - a).y > 0.0
        }));
        let q = quad(2.0, 1.0);
        assert_eq!(q.triangle_count(), 2);
        check(&q, false);
    }

    #[test]
    fn wave_grid_matches_the_peers_grid() {
        let g = wave_grid(100_000, 3.1, 1.8, 0.15);
        assert_eq!(g.triangle_count(), 100_000);
        check(&g, false);
        assert!(g.normals.iter().all(|n| n.z > 0.0));
        assert!(g.positions.iter().all(|p| p.z.abs() <= 0.15 + 1e-6));
    }

    #[test]
    fn terrain_is_deterministic_and_smooth() {
        let t = Terrain {
            cells: 40,
            ..Default::default()
        };
        let a = t.mesh();
        assert_eq!(a.triangle_count(), 2 * 40 * 40);
        check(&a, false);
        assert_eq!(a, t.mesh());
        let other = Terrain { seed: 8, ..t }.mesh();
        assert_ne!(a.positions, other.positions);
        // Flat in the middle, varied outside, no cliffs between neighbouring samples.
        assert_eq!(t.height_at(0.5, -0.3), 0.0);
        let hs: Vec<f32> = (0..200)
            .map(|i| t.height_at(30.0, i as f32 * 0.1 - 10.0))
            .collect();
        assert!(hs.windows(2).all(|w| (w[1] - w[0]).abs() < 0.5));
        assert!(
            hs.iter().cloned().fold(f32::MIN, f32::max)
                - hs.iter().cloned().fold(f32::MAX, f32::min)
                > 0.1
        );
    }

    #[test]
    fn solids_are_closed_and_outward() {
        let c = cylinder(0.5, 2.0, 16);
        assert_eq!(c.triangle_count(), 4 * 16);
        check(&c, true);
        let exact = PI * 0.25 * 2.0;
        assert!((volume(&c) - exact).abs() < 0.05 * exact);
        let k = cone(1.0, 3.0, 12);
        assert_eq!(k.triangle_count(), 24);
        check(&k, true);
        let ico = icosphere(1.0, 2);
        assert_eq!(ico.triangle_count(), 20 * 16);
        check(&ico, true);
    }

    #[test]
    fn props_are_valid_deterministic_and_outward() {
        for kind in [TreeKind::Pine, TreeKind::Broadleaf] {
            let t = tree(kind, 4.0, 3);
            check(&t, true);
            assert!(t.triangle_count() < 500);
            assert_eq!(t, tree(kind, 4.0, 3));
            let s = t.bounding_sphere();
            assert!(s.radius < 4.0 && s.center.y > 1.0);
        }
        let r = rock(1.0, 5);
        assert_eq!(r.triangle_count(), 80);
        check(&r, true);
        assert_ne!(r, rock(1.0, 6));
        let h = house(4.0, 3.0, 2.5, 1.5);
        assert_eq!(h.triangle_count(), 44);
        check(&h, true);
    }

    #[test]
    fn huge_triangles_face_the_camera() {
        let m = huge_triangles(16, 2);
        assert_eq!(m.triangle_count(), 16);
        check(&m, false);
        assert!(m.normals.iter().all(|n| n.z > 0.0));
    }

    #[test]
    fn xorshift_is_deterministic_and_uniform_enough() {
        let mut a = XorShift::new(0);
        let mut b = XorShift::new(0);
        let xs: Vec<f32> = (0..10_000).map(|_| a.next_f32()).collect();
        assert!(xs.iter().all(|&x| (0.0..1.0).contains(&x)));
        assert_eq!(
            xs[..5],
            (0..5).map(|_| b.next_f32()).collect::<Vec<_>>()[..]
        );
        let mean = xs.iter().sum::<f32>() / xs.len() as f32;
        assert!((mean - 0.5).abs() < 0.02);
        assert_ne!(XorShift::new(1).next_u64(), XorShift::new(2).next_u64());
    }
}
