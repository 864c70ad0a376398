//! Scene builders and render helpers shared by the integration tests: a deterministic
//! random source, a pixel-exact orthographic camera, lattices and fans of triangles, and
//! the "count buffer" (additive blending that adds exactly one unorm step per layer).

use crate::reference::Counts;
use engine::{
    AlphaMode, BlendMode, Camera, Cull, Encoding, FrameOptions, FrameStats, Material, Mesh,
    Projection, Renderer, Rgba, Scene, Target,
};
use glam::{Mat4, Vec3};

/// SplitMix64: a tiny deterministic generator, so every run draws the same scenes.
#[derive(Clone, Debug)]
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }
}

/// An orthographic camera under which world `(x, -y, z)` lands exactly on screen pixel
/// coordinates `(x, y)` of a `width` x `height` target (use [`px`]). View depth is `-z`.
pub fn pixel_camera(width: u32, height: u32) -> Camera {
    Camera {
        view: Mat4::IDENTITY,
        projection: Projection::Orthographic {
            left: 0.0,
            right: width as f32,
            bottom: -(height as f32),
            top: 0.0,
            near: 0.5,
            far: 10.0,
        },
    }
}

/// Rounds to the 1/256-pixel grid the rasterizer snaps to.
pub fn quantize(v: f64) -> f32 {
    ((v * 256.0).round() / 256.0) as f32
}

/// The world point seen at screen position `(x, y)` (pixels, y down) by [`pixel_camera`],
/// quantized to the snapping grid so the engine's `f32` projection and the reference's
/// `f64` one snap to the same fixed-point vertex.
pub fn px(x: f64, y: f64) -> Vec3 {
    Vec3::new(quantize(x), -quantize(y), -1.0)
}

/// An indexed mesh of one triangle list.
pub fn mesh(positions: Vec<Vec3>, indices: Vec<u32>) -> Mesh {
    Mesh {
        positions,
        indices,
        ..Default::default()
    }
}

/// An unindexed mesh of separate triangles.
pub fn soup(tris: &[[Vec3; 3]]) -> Mesh {
    mesh(
        tris.iter().flatten().copied().collect(),
        (0..tris.len() as u32 * 3).collect(),
    )
}

/// The triangles of a mesh (indices must be in range).
pub fn triangles(m: &Mesh) -> Vec<[Vec3; 3]> {
    m.indices
        .chunks_exact(3)
        .map(|t| std::array::from_fn(|k| m.positions[t[k] as usize]))
        .collect()
}

/// Additive, unlit, untextured, double-sided, no depth test: every covering triangle adds
/// exactly 1/255 to R, G and B, so a unorm target's red byte counts the layers.
pub fn count_material() -> Material {
    Material {
        base_color: Rgba::new(1.0, 1.0, 1.0, 1.0 / 255.0),
        alpha_mode: AlphaMode::Blend,
        blend: BlendMode::Additive,
        double_sided: true,
        depth_test: false,
        ..Default::default()
    }
}

/// Renders `meshes` with [`count_material`] (no culling) and reads back the layer counts.
pub fn render_counts(
    meshes: &[Mesh],
    camera: &Camera,
    width: u32,
    height: u32,
) -> (Counts, FrameStats) {
    let mut scene = Scene::default();
    for m in meshes {
        scene.add(m.clone(), count_material(), Mat4::IDENTITY);
    }
    let mut target = Target::with_encoding(width, height, Encoding::Unorm);
    let opts = FrameOptions {
        clear: Some(Rgba::BLACK),
        cull: Cull::None,
    };
    let stats = Renderer::new().render_scene(&scene, camera, &mut target, &opts);
    let mut c = Counts::new(width, height);
    for y in 0..height {
        for x in 0..width {
            c.counts[(y * width + x) as usize] = target.pixel(x, y).expect("inside") & 0xff;
        }
    }
    (c, stats)
}

/// A lattice `origin + i a + j b` covering a disc of `radius` around `origin`, split into
/// two triangles per cell. `diagonal(i, j)` picks the split; `flip(i, j)` reverses the
/// cell's winding; `jitter` moves interior points (already in pixels). Positions go through
/// `place` (e.g. [`px`]), once per lattice point, so shared vertices are identical.
pub struct Lattice<'a> {
    pub origin: (f64, f64),
    pub a: (f64, f64),
    pub b: (f64, f64),
    pub n: i32,
    pub diagonal: &'a dyn Fn(i32, i32) -> bool,
    pub flip: &'a dyn Fn(i32, i32) -> bool,
    pub jitter: &'a dyn Fn(i32, i32) -> (f64, f64),
}

impl std::fmt::Debug for Lattice<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Lattice")
            .field("origin", &self.origin)
            .field("a", &self.a)
            .field("b", &self.b)
            .field("n", &self.n)
            .finish_non_exhaustive()
    }
}

impl Lattice<'_> {
    pub fn build(&self, place: &dyn Fn(f64, f64) -> Vec3) -> Mesh {
        let n = self.n;
        let side = (2 * n + 1) as u32;
        let idx = |i: i32, j: i32| ((j + n) as u32) * side + (i + n) as u32;
        let mut positions = Vec::with_capacity((side * side) as usize);
        for j in -n..=n {
            for i in -n..=n {
                let (jx, jy) = (self.jitter)(i, j);
                let (fi, fj) = (i as f64, j as f64);
                positions.push(place(
                    self.origin.0 + fi * self.a.0 + fj * self.b.0 + jx,
                    self.origin.1 + fi * self.a.1 + fj * self.b.1 + jy,
                ));
            }
        }
        let mut indices = Vec::new();
        for j in -n..n {
            for i in -n..n {
                let (p00, p10, p01, p11) =
                    (idx(i, j), idx(i + 1, j), idx(i, j + 1), idx(i + 1, j + 1));
                let tris = if (self.diagonal)(i, j) {
                    [[p00, p10, p11], [p00, p11, p01]]
                } else {
                    [[p00, p10, p01], [p10, p11, p01]]
                };
                for t in tris {
                    if (self.flip)(i, j) {
                        indices.extend([t[0], t[2], t[1]]);
                    } else {
                        indices.extend(t);
                    }
                }
            }
        }
        mesh(positions, indices)
    }
}

/// A fan of `spokes` triangles around `centre`, rim points at `radius` from angle `phase`
/// (radians), through `place`. Rim points are computed once each.
pub fn fan(
    centre: (f64, f64),
    radius: f64,
    spokes: u32,
    phase: f64,
    place: &dyn Fn(f64, f64) -> Vec3,
) -> Mesh {
    let mut positions = vec![place(centre.0, centre.1)];
    for k in 0..spokes {
        let a = phase + std::f64::consts::TAU * k as f64 / spokes as f64;
        positions.push(place(
            centre.0 + radius * a.cos(),
            centre.1 + radius * a.sin(),
        ));
    }
    let mut indices = Vec::new();
    for k in 0..spokes {
        indices.extend([0, 1 + k, 1 + (k + 1) % spokes]);
    }
    mesh(positions, indices)
}

/// Renders `scene` into a fresh target of `encoding` with the given culling; black clear.
pub fn render(
    scene: &Scene,
    camera: &Camera,
    width: u32,
    height: u32,
    encoding: Encoding,
    cull: Cull,
) -> (Target, FrameStats) {
    let mut target = Target::with_encoding(width, height, encoding);
    let opts = FrameOptions {
        clear: Some(Rgba::BLACK),
        cull,
    };
    let stats = Renderer::new().render_scene(scene, camera, &mut target, &opts);
    (target, stats)
}

/// The red byte of every pixel, row-major.
pub fn red_bytes(t: &Target) -> Vec<u8> {
    let mut out = Vec::with_capacity(t.width() as usize * t.height() as usize);
    for y in 0..t.height() {
        for x in 0..t.width() {
            out.push((t.pixel(x, y).expect("inside") & 0xff) as u8);
        }
    }
    out
}

/// The subjects' lighting of the impostor and flare tests: grey ambient and a white sun from
/// above and slightly behind.
pub fn sun_lighting() -> engine::Lighting {
    engine::Lighting {
        ambient: Rgba::new(0.3, 0.3, 0.3, 1.0),
        lights: vec![engine::Light::Directional {
            direction: Vec3::new(-0.3, -1.0, -0.5).normalize(),
            color: Rgba::WHITE,
        }],
    }
}
