//! The tour's levels of detail: the terrain cut into patch draws (the renderer's cull pass
//! skips those outside the view) and, each frame, every patch, the torus and the spheres
//! pointed at the coarsest of their meshes whose silhouette error stays under
//! [`MAX_ERROR_PX`] at their distance. Applied for the span of one render and restored
//! after it, so between frames the scene is the one [`Showcase::new`](super::Showcase::new)
//! built (one-draw terrain, full meshes), as the views moment takes it.

use engine::procedural;
use engine::{Camera, Mesh, Scene};
use glam::{Mat4, Vec3};
use std::f32::consts::PI;

/// Patches per side of the terrain (its cells per side must be a multiple).
pub const PATCHES: u32 = 10;
/// Largest silhouette error, pixels, a coarser mesh may make at its distance.
pub const MAX_ERROR_PX: f32 = 0.5;
/// A terrain patch's levels: one vertex every `step` cells inside, its border kept full.
const TERRAIN_STEPS: [u32; 3] = [1, 2, 4];
/// The torus's levels, `(u, v)` segments as [`procedural::torus`] takes them, finest first.
const TORUS_LEVELS: [(u32, u32); 7] = [
    (96, 48),
    (64, 32),
    (48, 24),
    (32, 16),
    (24, 12),
    (16, 8),
    (12, 6),
];
/// The spheres' levels, `(rings, segments)` as [`procedural::uv_sphere`] takes them.
const SPHERE_LEVELS: [(u32, u32); 5] = [(24, 48), (16, 32), (12, 24), (8, 16), (6, 12)];

/// The sagitta of a chord spanning `TAU / segments` of a circle of `radius`: how far a
/// circle cut into `segments` straight pieces lies inside the true one, at most.
pub fn sagitta(radius: f32, segments: u32) -> f32 {
    radius * (1.0 - (PI / segments.max(1) as f32).cos())
}

/// One instance whose mesh is picked per frame.
#[derive(Clone, Debug)]
struct Chain {
    instance: usize,
    /// Scene mesh indices, finest first, with each one's deviation from the true surface
    /// (object units; increasing).
    levels: Vec<(usize, f32)>,
    /// The finest mesh's object-space bounding box.
    bounds: (Vec3, Vec3),
}

/// What the tour's meshes are made of before [`TourLod::install`].
#[derive(Clone, Debug)]
struct Plan {
    /// The terrain's cells per side.
    cells: u32,
    terrain_instance: usize,
    torus: usize,
    /// The torus's `(major, minor)` radii.
    torus_radii: (f32, f32),
    /// Instances of the unit sphere (radius 1, colours cleared).
    spheres: Vec<usize>,
}

/// The tour's levels of detail: the plan, then once installed the chains and the levels
/// the last frame drew.
#[derive(Clone, Debug)]
pub struct TourLod {
    plan: Plan,
    chains: Vec<Chain>,
    /// The level each chain drew last ([`TourLod::apply`]), finest = 0.
    picked: Vec<usize>,
    /// Patches' chains are `chains[..patches]`.
    patches: usize,
    /// The scene's instance count without the patches (those past it are patches 1 on).
    base: usize,
    /// The one-draw terrain's mesh.
    whole_mesh: usize,
    max_error_px: f32,
}

impl TourLod {
    /// A plan over the scene as the showcase builds it: the one-draw terrain of `cells`
    /// per side at `terrain_instance`, the torus's instance and radii, and the unit
    /// spheres' instances.
    pub(super) fn new(
        cells: u32,
        terrain_instance: usize,
        torus: (usize, f32, f32),
        spheres: Vec<usize>,
    ) -> TourLod {
        TourLod {
            plan: Plan {
                cells,
                terrain_instance,
                torus: torus.0,
                torus_radii: (torus.1, torus.2),
                spheres,
            },
            chains: Vec::new(),
            picked: Vec::new(),
            patches: 0,
            base: 0,
            whole_mesh: 0,
            max_error_px: MAX_ERROR_PX,
        }
    }

    /// Sets the largest error a level may make, pixels (0 keeps every mesh at its finest).
    pub fn set_max_error_px(&mut self, px: f32) {
        self.max_error_px = px;
    }

    /// Whether [`TourLod::install`] has run.
    pub fn installed(&self) -> bool {
        !self.chains.is_empty()
    }

    /// Terrain patches installed (0 before).
    pub fn patch_count(&self) -> usize {
        self.patches
    }

    /// Whether the scene's instance `k` draws terrain while [`TourLod::apply`]'s patches
    /// are in place (the terrain's own instance and the patches appended after it).
    pub fn is_terrain(&self, k: usize) -> bool {
        k == self.plan.terrain_instance || (self.patches > 1 && k >= self.base)
    }

    /// The level each patch drew last, then the torus's and the spheres'.
    pub fn picked(&self) -> &[usize] {
        &self.picked
    }

    /// Adds the patches' and the coarser meshes to `scene` (once; no instance yet: see
    /// [`TourLod::apply`]). The full-resolution patches hold the one-draw terrain's
    /// triangles, in its order, with its vertices' attributes; each object's finest level
    /// is its own mesh.
    pub fn install(&mut self, scene: &mut Scene) {
        if self.installed() {
            return;
        }
        let p = self.plan.clone();
        let whole = scene.instances[p.terrain_instance];
        self.whole_mesh = whole.mesh;
        self.base = scene.instances.len();
        let patches = terrain_patches(&scene.meshes[whole.mesh], p.cells);
        for (k, levels) in patches.into_iter().enumerate() {
            let bounds = levels[0].0.bounding_box().unwrap_or_default();
            let levels = levels
                .into_iter()
                .map(|(mesh, err)| (push_mesh(scene, mesh), err))
                .collect();
            let instance = if k == 0 {
                p.terrain_instance
            } else {
                self.base + k - 1
            };
            self.chains.push(Chain {
                instance,
                levels,
                bounds,
            });
        }
        self.patches = self.chains.len();
        let (major, minor) = p.torus_radii;
        let torus_levels = TORUS_LEVELS.map(|(u, v)| {
            let err = sagitta(major + minor, u) + sagitta(minor, v);
            (procedural::torus(major, minor, u, v), err)
        });
        self.add_chain(scene, p.torus, torus_levels.into());
        let mut sphere_levels = None;
        for &i in &p.spheres {
            let levels = sphere_levels.get_or_insert_with(|| {
                SPHERE_LEVELS
                    .map(|(rings, segments)| {
                        let mut m = procedural::uv_sphere(1.0, rings, segments);
                        m.colors.clear();
                        let err = sagitta(1.0, segments).max(sagitta(1.0, 2 * rings));
                        (m, err)
                    })
                    .into_iter()
                    .map(|(m, err)| (push_mesh(scene, m), err))
                    .collect::<Vec<_>>()
            });
            let bounds = scene.meshes[levels[0].0].bounding_box().unwrap_or_default();
            self.chains.push(Chain {
                instance: i,
                levels: levels.clone(),
                bounds,
            });
        }
        for c in &mut self.chains[self.patches..] {
            c.levels[0].0 = scene.instances[c.instance].mesh;
        }
        self.picked = vec![0; self.chains.len()];
    }

    /// Puts back what [`TourLod::apply`] changed: the patches' instances taken off (the
    /// terrain's own instance drawing the one-draw terrain again) and every object at its
    /// finest mesh.
    pub fn restore(&self, scene: &mut Scene) {
        if !self.installed() {
            return;
        }
        scene.instances.truncate(self.base);
        scene.instances[self.plan.terrain_instance].mesh = self.whole_mesh;
        for c in &self.chains[self.patches..] {
            scene.instances[c.instance].mesh = c.levels[0].0;
        }
    }

    /// A chain of freshly made `levels` (finest first) for `instance`.
    fn add_chain(&mut self, scene: &mut Scene, instance: usize, levels: Vec<(Mesh, f32)>) {
        let bounds = levels[0].0.bounding_box().unwrap_or_default();
        let levels = levels
            .into_iter()
            .map(|(m, err)| (push_mesh(scene, m), err))
            .collect();
        self.chains.push(Chain {
            instance,
            levels,
            bounds,
        });
    }

    /// Draws the terrain as its patches (the terrain's instance the first, the others
    /// appended, so every other instance keeps its index) and points every chain's
    /// instance at its coarsest mesh whose error, seen from `camera` on an image `height`
    /// pixels tall, is under the largest error (installing first); undone by
    /// [`TourLod::restore`].
    /// The distance is the eye's to the finest mesh's box in object space, which for the
    /// tour's transforms (rotations, uniform scales, translations) is the world distance
    /// over the scale, as the error is: their ratio is the same in both spaces.
    pub fn apply(&mut self, scene: &mut Scene, camera: &Camera, height: u32) {
        self.install(scene);
        self.restore(scene);
        let template = scene.instances[self.plan.terrain_instance];
        scene.instances.extend((1..self.patches).map(|_| template));
        let focal = 0.5 * height as f32 * camera.projection.reversed_z_matrix().y_axis.y;
        let eye = camera.eye();
        for (c, picked) in self.chains.iter().zip(&mut self.picked) {
            let inst = &mut scene.instances[c.instance];
            let d = distance_to_box(object_eye(inst.transform, eye), c.bounds);
            let fits = |err: f32| err * focal <= self.max_error_px * d;
            let level = (0..c.levels.len())
                .rev()
                .find(|&k| fits(c.levels[k].1))
                .unwrap_or(0);
            inst.mesh = c.levels[level].0;
            *picked = level;
        }
    }
}

/// Pushes `mesh` to `scene`; its index.
fn push_mesh(scene: &mut Scene, mesh: Mesh) -> usize {
    scene.meshes.push(mesh);
    scene.meshes.len() - 1
}

/// `eye` in the object space of `transform`.
fn object_eye(transform: Mat4, eye: Vec3) -> Vec3 {
    transform.inverse().transform_point3(eye)
}

/// Distance from `p` to the box `(lo, hi)` (0 inside).
fn distance_to_box(p: Vec3, (lo, hi): (Vec3, Vec3)) -> f32 {
    (lo - p).max(p - hi).max(Vec3::ZERO).length()
}

/// The levels of every terrain patch, `PATCHES` x `PATCHES` of them in rows, each finest
/// first with its height error against the full grid (object units): see [`patch`].
fn terrain_patches(whole: &Mesh, cells: u32) -> Vec<Vec<(Mesh, f32)>> {
    let side = cells / PATCHES;
    assert_eq!(
        side * PATCHES,
        cells,
        "terrain cells not a multiple of the patches"
    );
    let mut out = Vec::new();
    for pi in 0..PATCHES {
        for pj in 0..PATCHES {
            let levels = TERRAIN_STEPS
                .iter()
                .filter(|&&s| side.is_multiple_of(s) && (s == 1 || s.is_multiple_of(2)))
                .map(|&s| patch(whole, cells, (pi * side, pj * side), side, s))
                .collect();
            out.push(levels);
        }
    }
    out
}

/// The patch of `side` x `side` cells from grid vertex `(i0, j0)` of the terrain mesh
/// `whole` (`cells` per side, vertex `i * (cells + 1) + j`, two triangles per cell as
/// `Builder::lattice` makes them), at one vertex every `step` cells, and its largest
/// height error. Step 1 copies the cells' triangles as they are. Coarser steps keep every
/// vertex of the patch's border: a cell of `step` x `step` on the border is a fan from its
/// centre over its ring, with every border vertex on its border sides, so two patches of
/// any levels share the same border edges and leave no crack between them.
fn patch(whole: &Mesh, cells: u32, (i0, j0): (u32, u32), side: u32, step: u32) -> (Mesh, f32) {
    let nv = cells + 1;
    let global = |li: u32, lj: u32| (i0 + li) * nv + (j0 + lj);
    let mut b = PatchBuilder::new(whole, side);
    if step == 1 {
        for li in 0..side {
            for lj in 0..side {
                let cell = ((i0 + li) * cells + (j0 + lj)) as usize;
                for t in 0..2 {
                    let tri = &whole.indices[6 * cell + 3 * t..6 * cell + 3 * t + 3];
                    let local = tri.iter().map(|&g| {
                        let (gi, gj) = (g / nv, g % nv);
                        b.vertex(gi - i0, gj - j0, g)
                    });
                    let [a, bb, c]: [u32; 3] = local.collect::<Vec<_>>().try_into().unwrap();
                    b.mesh.indices.extend([a, bb, c]);
                }
            }
        }
        return (b.mesh, 0.0);
    }
    let coarse = side / step;
    for ci in 0..coarse {
        for cj in 0..coarse {
            let (i, j) = (ci * step, cj * step);
            let border = [cj == 0, ci == coarse - 1, cj == coarse - 1, ci == 0];
            if !border.iter().any(|&x| x) {
                let [a, bb, c, d] = [(i, j), (i + step, j), (i + step, j + step), (i, j + step)];
                b.tri(a, bb, c, global);
                b.tri(a, c, d, global);
                continue;
            }
            // The ring: the four sides in turn, every vertex on a border side.
            let corners = [(i, j), (i + step, j), (i + step, j + step), (i, j + step)];
            let mut ring = Vec::new();
            for (s, &full) in border.iter().enumerate() {
                let (from, to) = (corners[s], corners[(s + 1) % 4]);
                let n = if full { step } else { 1 };
                for k in 0..n {
                    let f = |a: u32, b: u32| (a * (n - k) + b * k) / n;
                    ring.push((f(from.0, to.0), f(from.1, to.1)));
                }
            }
            let m = (i + step / 2, j + step / 2);
            for k in 0..ring.len() {
                b.tri(m, ring[k], ring[(k + 1) % ring.len()], global);
            }
        }
    }
    let err = b.height_error();
    (b.mesh, err)
}

/// Builds a patch's mesh from the whole terrain's vertices, each copied once.
struct PatchBuilder<'a> {
    whole: &'a Mesh,
    side: u32,
    /// Local vertex index by patch grid vertex, `u32::MAX` for not yet copied.
    local: Vec<u32>,
    mesh: Mesh,
}

impl<'a> PatchBuilder<'a> {
    fn new(whole: &'a Mesh, side: u32) -> Self {
        PatchBuilder {
            whole,
            side,
            local: vec![u32::MAX; ((side + 1) * (side + 1)) as usize],
            mesh: Mesh::default(),
        }
    }

    /// The local index of patch grid vertex `(li, lj)`, whole-mesh vertex `g`.
    fn vertex(&mut self, li: u32, lj: u32, g: u32) -> u32 {
        let slot = &mut self.local[(li * (self.side + 1) + lj) as usize];
        if *slot == u32::MAX {
            let (w, m, g) = (self.whole, &mut self.mesh, g as usize);
            *slot = m.positions.len() as u32;
            m.positions.push(w.positions[g]);
            m.normals.push(w.normals[g]);
            m.uvs.push(w.uvs[g]);
            m.colors.push(w.colors[g]);
        }
        *slot
    }

    /// A triangle over grid vertices, wound to agree with its vertices' normals as the
    /// whole terrain's are.
    fn tri(&mut self, a: (u32, u32), b: (u32, u32), c: (u32, u32), g: impl Fn(u32, u32) -> u32) {
        let [a, b, c] = [a, b, c].map(|(i, j)| self.vertex(i, j, g(i, j)));
        let m = &self.mesh;
        let [pa, pb, pc] = [a, b, c].map(|i| m.positions[i as usize]);
        let n = [a, b, c].map(|i| m.normals[i as usize]);
        let geo = (pb - pa).cross(pc - pa);
        let tri = if geo.dot(n[0] + n[1] + n[2]) < 0.0 {
            [a, c, b]
        } else {
            [a, b, c]
        };
        self.mesh.indices.extend(tri);
    }

    /// The largest vertical distance from a vertex of the full grid under the patch to
    /// the patch's surface above or below it.
    fn height_error(&self) -> f32 {
        let w = self.whole;
        let (lo, hi) = self.mesh.bounding_box().unwrap_or_default();
        let full: Vec<Vec3> = w
            .positions
            .iter()
            .copied()
            .filter(|p| p.x >= lo.x && p.x <= hi.x && p.z >= lo.z && p.z <= hi.z)
            .collect();
        let mut err = 0.0f32;
        for t in self.mesh.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| self.mesh.positions[i as usize]);
            let (x0, x1) = (a.x.min(b.x).min(c.x), a.x.max(b.x).max(c.x));
            let (z0, z1) = (a.z.min(b.z).min(c.z), a.z.max(b.z).max(c.z));
            let det = (b.x - a.x) * (c.z - a.z) - (c.x - a.x) * (b.z - a.z);
            if det.abs() < 1e-12 {
                continue;
            }
            for p in full
                .iter()
                .filter(|p| p.x >= x0 && p.x <= x1 && p.z >= z0 && p.z <= z1)
            {
                let u = ((p.x - a.x) * (c.z - a.z) - (c.x - a.x) * (p.z - a.z)) / det;
                let v = ((b.x - a.x) * (p.z - a.z) - (p.x - a.x) * (b.z - a.z)) / det;
                if u >= -1e-4 && v >= -1e-4 && u + v <= 1.0 + 1e-4 {
                    let y = a.y + u * (b.y - a.y) + v * (c.y - a.y);
                    err = err.max((p.y - y).abs());
                }
            }
        }
        err
    }
}

#[cfg(test)]
mod tests;
