//! Procedural scenery: value noise, height-field terrain, trees, rocks and a house.

use super::*;

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
    /// Seed of the noise: the same seed gives the same terrain.
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

/// A faceted blob: an icosphere of `subdivisions` whose vertices are pushed in and out by
/// `bumpiness` (a fraction of the radius), squashed vertically by `squash`.
pub(super) fn add_blob(
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
    let trunk_h = trunk_height(kind, height);
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
    let leaf = leaf_color(kind, &mut rng);
    match kind {
        TreeKind::Pine => {
            for (y, r, h) in pine_cones(height) {
                add_cone(
                    &mut b,
                    Vec3::new(0.0, y, 0.0),
                    r,
                    h,
                    9,
                    leaf,
                    Some(&mut rng),
                );
            }
        }
        TreeKind::Broadleaf => {
            let r = height * 0.3;
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

/// The trunk's height of a [`tree`] of `kind`, `height` tall (the crown stands on it).
pub fn trunk_height(kind: TreeKind, height: f32) -> f32 {
    height * if kind == TreeKind::Pine { 0.3 } else { 0.45 }
}

/// The leaf green of a [`tree`] of `kind`, its hue drawn from `rng` (one draw, the first
/// [`tree`] makes): a broadleaf's lighter than a pine's.
pub fn leaf_color(kind: TreeKind, rng: &mut XorShift) -> Rgba {
    let hue = rng.range(-0.08, 0.08);
    let leaf = Rgba::new((0.07 + hue).max(0.0), 0.32 + hue * 0.5, 0.06, 1.0);
    match kind {
        TreeKind::Pine => leaf,
        TreeKind::Broadleaf => Rgba::new(leaf.r * 1.3, leaf.g * 1.25, leaf.b, 1.0),
    }
}

/// The stacked cones of a pine [`tree`] `height` tall, lowest first: each cone's base
/// height, base radius and height (apex above its base).
pub fn pine_cones(height: f32) -> [(f32, f32, f32); 3] {
    let trunk_h = trunk_height(TreeKind::Pine, height);
    let crown_h = height - trunk_h;
    std::array::from_fn(|k| {
        let f = k as f32 / 3.0;
        let y = trunk_h + crown_h * f * 0.62;
        let r = height * 0.28 * (1.0 - f * 0.55);
        (y, r, crown_h * (1.0 - f * 0.62))
    })
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
