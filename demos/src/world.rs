//! The large procedural world of `bench budget`, `bench objects` and the showcase's world
//! moment: a square of lots, each holding one instance of a few shared prototype meshes
//! (buildings of three detail levels, trees, rocks and torus statues), tens of thousands
//! of objects and over ten million triangles, the low fly-over they follow, and the
//! per-node planner they draw it with ([`tree_planner`]: a hierarchy over the objects whose
//! nodes are drawn as one runtime impostor each, [`ibr::plan::tree`]).
//!
//! Used by `bench` and `showcase` alike; it builds only on [`crate::city`] (a leaf), so
//! neither imports the other through it.

use crate::city::{building, daylight};
use engine::procedural::{self, TreeKind, XorShift};
use engine::{
    Camera, FrameOptions, FrameStats, Lighting, Material, Mesh, Renderer, Rgba, Shading, Target,
};
use glam::{Mat4, Vec3};
use ibr::impostor::{self, ImpostorSet, Tolerance};
use ibr::plan::tree::{Cluster, FarConfig, Hierarchy, TreeConfig};
use ibr::plan::Representation;
use ibr::schedule::Budget;
use ibr::subject::{MeshGroup, Part, Subject};
use std::sync::Arc;

/// Lot side, world units.
pub const LOT: f32 = 6.0;

/// Objects on a ground plate, and the light.
#[derive(Clone, Debug)]
pub struct World {
    pub objects: Vec<MeshGroup>,
    pub ground: MeshGroup,
    pub lighting: Lighting,
    /// Half the side of the square the lots fill.
    pub half_extent: f32,
}

impl World {
    /// `side` x `side` lots (deterministic for `seed`).
    pub fn new(side: u32, seed: u64) -> World {
        World::scaled(side, seed, 1.0)
    }

    /// `side` x `side` lots filling the square of `footprint` x `footprint` lots of
    /// [`LOT`]: each lot, and the object on it, scaled by `footprint / side` (the objects
    /// and their placement those of [`World::new`] for `seed`, shrunk about the centre).
    /// The worlds of every `side` cover the same ground and are flown the same way
    /// ([`World::camera`] depends only on the footprint): the same pixels, `side`^2
    /// objects in them (`bench objects`).
    pub fn in_footprint(side: u32, seed: u64, footprint: u32) -> World {
        let side = side.max(1);
        World::scaled(side, seed, footprint.max(1) as f32 / side as f32)
    }

    /// `side` x `side` lots of `scale` [`LOT`]s, each object scaled by `scale`.
    fn scaled(side: u32, seed: u64, scale: f32) -> World {
        let side = side.max(1);
        let lot = LOT * scale;
        let half_extent = side as f32 * lot * 0.5;
        let mut rng = XorShift::new(seed);
        let lit = |specular: f32| {
            Arc::new(Material {
                shading: Shading::Lit {
                    specular,
                    shininess: 16.0,
                },
                ..Material::default()
            })
        };
        let (plain, shiny) = (lit(0.1), lit(0.4));
        // (mesh, material) prototypes; buildings of three detail levels in two colours.
        let mut protos: Vec<(Arc<Mesh>, Arc<Material>)> = Vec::new();
        let mut building_lods = Vec::new();
        for (k, wall) in [
            (6, Rgba::new(0.7, 0.6, 0.5, 1.0)),
            (8, Rgba::new(0.55, 0.6, 0.68, 1.0)),
            (10, Rgba::new(0.72, 0.52, 0.42, 1.0)),
        ] {
            let mesh = building(Vec3::new(3.2, 7.0 + k as f32, 3.0), k, wall);
            building_lods.push(vec![
                (Arc::new(merged_building(&mesh, k)), MERGED_DEVIATION),
                (Arc::new(boxed_building(&mesh, k)), cell_side(&mesh, k)),
            ]);
            protos.push((Arc::new(mesh), plain.clone()));
        }
        for (kind, seed) in [(TreeKind::Pine, 3), (TreeKind::Broadleaf, 4)] {
            protos.push((Arc::new(procedural::tree(kind, 5.0, seed)), plain.clone()));
        }
        protos.push((Arc::new(procedural::rock(1.2, 9)), plain.clone()));
        let statue = Material {
            vertex_colors: false,
            base_color: Rgba::new(0.75, 0.62, 0.3, 1.0),
            ..(*shiny).clone()
        };
        let statue_mesh = procedural::torus_with_triangles(STATUE.0);
        protos.push((Arc::new(statue_mesh), Arc::new(statue)));
        let statue_lods = statue_lods();
        let mut objects = Vec::with_capacity((side * side) as usize);
        for gz in 0..side {
            for gx in 0..side {
                let pick = rng.range(0.0, 1.0);
                let p = match pick {
                    x if x < 0.4 => (rng.range(0.0, 2.99)) as usize,
                    x if x < 0.75 => 3 + (rng.range(0.0, 1.99)) as usize,
                    x if x < 0.85 => 5,
                    _ => 6,
                };
                let x = (gx as f32 + 0.5) * lot - half_extent + rng.range(-0.8, 0.8) * scale;
                let z = (gz as f32 + 0.5) * lot - half_extent + rng.range(-0.8, 0.8) * scale;
                let lift = if p == 6 { 1.6 * scale } else { 0.0 };
                let place = Mat4::from_translation(Vec3::new(x, lift, z))
                    * Mat4::from_rotation_y(rng.range(0.0, std::f32::consts::TAU))
                    * Mat4::from_scale(Vec3::splat(rng.range(0.8, 1.2) * scale));
                let (mesh, material) = protos[p].clone();
                let mut part = Part::new(mesh, material, place);
                if p == 6 {
                    part = part.with_lods(statue_lods.clone());
                } else if p < 3 {
                    part = part.with_lods(building_lods[p].clone());
                }
                objects.push(MeshGroup {
                    parts: vec![part],
                    version: 0,
                });
            }
        }
        World {
            objects,
            ground: {
                let colour = Rgba::from_srgb8(92, 104, 84);
                tiled_ground(half_extent * 2.2, colour, GROUND_TILES)
            },
            lighting: daylight(),
            half_extent,
        }
    }

    /// Triangles of every object (the ground left out).
    pub fn triangle_count(&self) -> usize {
        self.objects.iter().map(|o| o.triangle_count()).sum()
    }

    /// The fly-over at `t` in [0, 1]: 20 units up over the near edge, gliding sideways
    /// across the middle fifth of the world while looking into it and down, seeing as far
    /// as the far edge.
    pub fn camera(&self, t: f32, (w, h): (u32, u32)) -> Camera {
        let e = self.half_extent;
        let t = t.clamp(0.0, 1.0);
        let eye = Vec3::new(e * (0.4 * t - 0.2), 20.0, e * 0.9);
        let target = eye + Vec3::new(0.15, -0.32, -1.0);
        Camera::look_at(eye, target, Vec3::Y, 1.0, w as f32 / h.max(1) as f32)
            .with_depth_range(0.5, e * 2.2)
    }

    /// The world as plain geometry on `ground`, from `camera` into a new `w` x `h` target
    /// cleared to [`SKY`]: every object drawn as its meshes (the reference the planner's
    /// frames are measured against, and the tests' view of what covers which pixels).
    pub fn render_geometry(
        &self,
        ground: &MeshGroup,
        camera: &Camera,
        (w, h): (u32, u32),
    ) -> (Target, FrameStats) {
        let mut draws = Vec::new();
        ground.draws(&mut draws);
        self.objects.iter().for_each(|o| o.draws(&mut draws));
        let mut target = Target::new(w, h);
        let opts = FrameOptions {
            clear: Some(SKY),
            ..FrameOptions::default()
        };
        let stats = Renderer::new().render(draws, camera, &self.lighting, &mut target, &opts);
        (target, stats)
    }
}

/// The world's sky: the clear colour of its frames.
pub const SKY: Rgba = Rgba::new(0.55, 0.65, 0.8, 1.0);

/// The ground's pieces a side ([`tiled_ground`]): cut in 32 x 32, the world's ground
/// shaded 24% fewer fragments a frame at 640x360 (298,000 against 393,000; at 1280x720
/// 1.17 M against 1.55 M; BENCHMARKS.md, issue 41, session 11).
pub const GROUND_TILES: u32 = 32;

/// The ground plate of [`crate::city::ground`] (`side` a side, lit in `color`) cut into
/// `n` x `n` square draws of two triangles each, sharing their edges' vertices exactly (one
/// lattice, split by cell). The renderer draws opaque draws near to far by the nearest
/// point of their boxes: one plate's nearest point is under the eye, so it was drawn
/// first and everything standing on it shaded over it; cut, each piece goes after the
/// nearer objects that hide it, and its hidden pixels are rejected before they are shaded.
pub fn tiled_ground(side: f32, color: Rgba, n: u32) -> MeshGroup {
    let n = n.max(1);
    let mut plate = procedural::plane(side, side, n, n);
    plate.colors.clear();
    let material = Arc::new(Material::lit(color));
    // The cell a triangle's centre lies in (the plate spans [-side/2, side/2] in x and z).
    let cell = |p: Vec3| {
        ((p / side + 0.5) * n as f32)
            .floor()
            .clamp(Vec3::ZERO, Vec3::splat(n as f32 - 1.0))
    };
    let mut pieces: Vec<Mesh> = vec![Mesh::default(); (n * n) as usize];
    for t in plate.indices.chunks_exact(3) {
        let centre = t.iter().map(|&v| plate.positions[v as usize]).sum::<Vec3>() / 3.0;
        let c = cell(centre);
        let piece = &mut pieces[(c.z as u32 * n + c.x as u32) as usize];
        for &v in t {
            let v = v as usize;
            let at = piece
                .positions
                .iter()
                .position(|&p| p == plate.positions[v]);
            let k = at.unwrap_or_else(|| {
                piece.positions.push(plate.positions[v]);
                piece.normals.push(plate.normals[v]);
                piece.uvs.push(plate.uvs[v]);
                piece.positions.len() - 1
            });
            piece.indices.push(k as u32);
        }
    }
    let mut group = MeshGroup::new();
    for piece in pieces.into_iter().filter(|p| !p.indices.is_empty()) {
        group = group.with(Arc::new(piece), material.clone(), Mat4::IDENTITY);
    }
    group
}

/// The deviation given the merged buildings' level of detail ([`merged_building`]), object
/// units: the surface is the same (0), but not 0, so that a tolerance of 0 (every object at
/// its full mesh: `TreeConfig::lod_px`, `FarConfig::lod_px`) still draws the full mesh.
pub const MERGED_DEVIATION: f32 = 1e-6;

/// The building `full` ([`building`] with `k` x `k` cells a face) in fewer triangles with
/// the same picture, the world's buildings' level of detail ([`MERGED_DEVIATION`]): the objects
/// drawn as geometry and the far field's captures draw it, the node images and the measured
/// error's reference the full mesh. Each face's cells are merged along a row where the
/// colour does not change across them (a run of cells whose left and right edges carry the
/// same two colours: its colour varies only up the face, so one quad interpolates it as its
/// cells did), and rows of one colour into one quad (the roof); the other cells are kept
/// with their own diagonal. Its vertices are a selection of `full`'s, so positions,
/// normals and colours are `full`'s own. The windows' cells merge into one run a row:
/// 24 `k` + 2 triangles against 10 `k`^2 (k = 10: 242 against 1,000).
pub fn merged_building(full: &Mesh, k: u32) -> Mesh {
    let n = k as usize + 1;
    let faces = full.positions.len() / (n * n);
    let mut m = Mesh::default();
    let mut new_index = vec![u32::MAX; full.positions.len()];
    for f in 0..faces {
        let at = |i: usize, j: usize| f * n * n + j * n + i;
        let colour = |i: usize, j: usize| full.colors.get(at(i, j)).copied();
        // Rectangles of cells (i0, i1, j0, j1) covering the face.
        let mut pieces: Vec<[usize; 4]> = Vec::new();
        let mut open: Option<usize> = None;
        for j in 0..n - 1 {
            let one = colour(0, j);
            if (0..n).all(|i| colour(i, j) == one && colour(i, j + 1) == one) {
                match open {
                    Some(p) if colour(0, pieces[p][2]) == one => pieces[p][3] = j + 1,
                    _ => {
                        pieces.push([0, n - 1, j, j + 1]);
                        open = Some(pieces.len() - 1);
                    }
                }
                continue;
            }
            open = None;
            let flat = |i: usize| {
                colour(i, j) == colour(i + 1, j) && colour(i, j + 1) == colour(i + 1, j + 1)
            };
            let mut i = 0;
            while i < n - 1 {
                let mut end = i + 1;
                if flat(i) {
                    while end < n - 1 && flat(end) {
                        end += 1;
                    }
                }
                pieces.push([i, end, j, j + 1]);
                i = end;
            }
        }
        for [i0, i1, j0, j1] in pieces {
            let quad = [at(i0, j0), at(i1, j0), at(i1, j1), at(i0, j1)];
            let mut index = |v: usize| {
                if new_index[v] == u32::MAX {
                    new_index[v] = m.positions.len() as u32;
                    m.positions.push(full.positions[v]);
                    if let Some(&normal) = full.normals.get(v) {
                        m.normals.push(normal);
                    }
                    if let Some(&uv) = full.uvs.get(v) {
                        m.uvs.push(uv);
                    }
                    if let Some(&c) = full.colors.get(v) {
                        m.colors.push(c);
                    }
                }
                new_index[v]
            };
            let [a, b, c, d] = quad.map(&mut index);
            m.indices.extend_from_slice(&[a, b, c, a, c, d]);
        }
    }
    m
}

/// The building `full` ([`building`] with `k` x `k` cells a face) as its box: each face
/// one quad (10 triangles) of the face's mean colour (its triangles' vertex colours
/// averaged by area, as the cells are equal), the coarsest level of the world's buildings.
/// It drops the windows, features a cell high ([`cell_side`]), so it is drawn only where a
/// cell projects within the level-of-detail tolerance (half a pixel at 360 rows): there
/// the windows are under a pixel, and a point-sampled pixel on the face is wall or window
/// by where its centre falls, which the mean stands for on average. Its vertices are the
/// faces' corners, `full`'s own positions and normals.
pub fn boxed_building(full: &Mesh, k: u32) -> Mesh {
    let n = k as usize + 1;
    let faces = full.positions.len() / (n * n);
    let per_face = 2 * (k * k) as usize;
    let mut m = Mesh::default();
    for f in 0..faces {
        let at = |i: usize, j: usize| f * n * n + j * n + i;
        let triangles = full
            .indices
            .chunks_exact(3)
            .skip(f * per_face)
            .take(per_face);
        let mut sum = [0.0f32; 4];
        for t in triangles {
            for &v in t {
                let c = full.colors.get(v as usize).copied().unwrap_or(Rgba::WHITE);
                for (s, x) in sum.iter_mut().zip([c.r, c.g, c.b, c.a]) {
                    *s += x;
                }
            }
        }
        let w = 1.0 / (3 * per_face.max(1)) as f32;
        let mean = Rgba::new(sum[0] * w, sum[1] * w, sum[2] * w, sum[3] * w);
        let base = m.positions.len() as u32;
        for v in [at(0, 0), at(n - 1, 0), at(n - 1, n - 1), at(0, n - 1)] {
            m.positions.push(full.positions[v]);
            if let Some(&normal) = full.normals.get(v) {
                m.normals.push(normal);
            }
            m.colors.push(mean);
        }
        m.indices
            .extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    m
}

/// The largest side of a cell of the building `full` ([`building`] with `k` x `k` cells a
/// face), object units: the deviation given its box ([`boxed_building`]), the size of the
/// window bands the box drops.
pub fn cell_side(full: &Mesh, k: u32) -> f32 {
    let side = full
        .bounding_box()
        .map_or(0.0, |(lo, hi)| (hi - lo).max_element());
    side / k.max(1) as f32
}

/// Triangles of the world's torus statue, and of its coarser levels of detail, finest
/// first: the statues are 15% of the objects and over half the triangles, so the near
/// ones drawn as geometry and the far field's captures take the coarsest level whose
/// deviation projects within half a pixel ([`TreeConfig::lod_px`], [`FarConfig::lod_px`]);
/// images of clusters and the measured error's reference draw the full mesh. The two
/// coarsest (12 segments around the ring by 4 around the tube, and 8 by 3) are for
/// statues a few pixels across, `bench objects`' 100k shrunk to a tenth.
pub const STATUE: (u32, [u32; 4]) = (3000, [800, 200, 96, 48]);

/// The statue's levels of detail ([`STATUE`]), each with its deviation from the full mesh:
/// both meshes' bounds from the true torus summed ([`procedural::torus_deviation`]).
pub fn statue_lods() -> Vec<(Arc<Mesh>, f32)> {
    let full = procedural::torus_deviation(STATUE.0);
    STATUE
        .1
        .iter()
        .map(|&n| {
            let mesh = Arc::new(procedural::torus_with_triangles(n));
            (mesh, procedural::torus_deviation(n) + full)
        })
        .collect()
}

/// The largest cluster image at 640x360, texels a side: a node wider than that on screen
/// is opened (the cut's clusters stay small on screen, so each is cheap to retake and slow
/// to go stale as the eye moves). 72, not 64: the measured mean error's headroom spent on
/// fewer near objects as geometry (`bench budget --scene world`, 640x360: 283 objects as
/// geometry and 0.91 levels at 72, 345 and 0.72 at 64, 243 and 1.06, over the goal of 1.0,
/// at 80; BENCHMARKS.md, issue 41, session 11).
pub const TREE_SIDE: u32 = 72;

/// The largest cluster image for a `height`-pixel target: [`TREE_SIDE`] scaled
/// ([`tree_scale`]).
pub fn tree_side(height: u32) -> u32 {
    (TREE_SIDE as f32 * tree_scale(height)).round() as u32
}

/// The target height, pixels, at which the world's pixel settings hold as given
/// ([`TREE_SIDE`], the geometry's and the far field's level-of-detail tolerance, the far
/// field's parallax); a taller target scales them with its height ([`tree_scale`]).
pub const TREE_HEIGHT: u32 = 360;

/// How much a `height`-pixel target scales the world's pixel settings: its height over
/// [`TREE_HEIGHT`], never below 1. At twice the pixels a node's image has twice the
/// texels a side and the geometry's levels of detail twice the pixels of deviation, so the
/// cut stands at the same angular error and opens the same nodes as at 640x360 (with the
/// 64-texel cap at 1280x720 it opened twice as deep: 1,072 objects as geometry against
/// 345). Below [`TREE_HEIGHT`] the settings stay as given.
pub fn tree_scale(height: u32) -> f32 {
    (height as f32 / TREE_HEIGHT as f32).max(1.0)
}

/// The hierarchy planner's predicted milliseconds of captures per frame after loading:
/// node images' rebuilds (each charged [`TREE_CAPTURE_MS`] besides the cost model) and
/// the shown far field's re-capture (its triangles and [`TREE_CAPTURE_MS`] a tile) share
/// it ([`TreeConfig::capture_ms`]). Until session 18 it was 8 ms of node rebuilds alone,
/// priced at the cost model's tenth of a millisecond each, and never bound; the frames
/// of `bench budget --scene world` paid 1 to 12 node captures and a 50,000-triangle far
/// tile besides (BENCHMARKS.md, issue 41, session 18).
pub const TREE_REBUILD_MS: f32 = 4.0;

/// What one node image's capture costs besides the cost model's price of its triangles
/// and texels, milliseconds: `bench budget --scene world --stages` at 640x360, the 8
/// frames before the far field's re-capture, node captures alone: a median of 0.61 ms
/// a capture for main's build at load 2 to 3 (0.38 to 0.78), the cost model predicting
/// 0.04 to 0.25. Set below that median, as this build no longer builds a pool texture
/// for each new slot; at load 8 its captures measured 0.31 to 2.87 ms, too loaded to fit,
/// so 0.4 is a judgement, not a fit (BENCHMARKS.md, issue 41, session 18).
pub const TREE_CAPTURE_MS: f32 = 0.4;

/// A node image's rebuild draws its children's images in place of their objects when a
/// child's image errs within this fraction of the budget ([`TreeConfig::compose`]; Shade
/// et al. 96's hierarchical image cache): its capture then follows texels, not objects.
pub const TREE_COMPOSE: f32 = 0.5;

/// The world's far field for a `height`-pixel target: everything beyond [`FAR_DISTANCE`]
/// of the eye as one image mesh with depth, captured in 8 x 8 tiles (split where one is
/// over the budget) within [`FAR_TRIANGLES`] a frame (4 M while loading), re-captured when
/// the eye's move makes 24 pixels of parallax at that distance at 640x360 (scaled with the
/// height, [`tree_scale`], as its captures' level-of-detail tolerance).
pub fn far_config(height: u32) -> FarConfig {
    let scale = tree_scale(height);
    let far = FarConfig::default();
    FarConfig {
        distance: FAR_DISTANCE,
        triangles: FAR_TRIANGLES,
        parallax: 24.0 * scale,
        lod_px: far.lod_px * scale,
        ..far
    }
}

/// Triangles the far field's re-capture draws a frame after loading. A re-capture of the
/// world's field is millions of triangles, a background task over many frames: at 150,000
/// a frame it took 6.3 to 12.9 ms of a 640x360 frame's prepare (medians of runs at load 6
/// to 10; 1.3 to 2.1 ms at 50,000) and never completed in `bench budget`'s 24 frames
/// either way, so the frame pays a third as much for a refresh that completes about three
/// times later (55 tiles pending at 50,000, one a frame; BENCHMARKS.md, issue 41, session
/// 12).
pub const FAR_TRIANGLES: u64 = 50_000;

/// The far field's distance, world units (about 40 lots): nearer, the field's parallax
/// as the eye moves before its re-capture completes made the measured error pass 1 level
/// in the fly-over (`bench budget --scene world`: 2.07 at 80 units, 0.91 at 150, 0.70 at
/// 250; BENCHMARKS.md).
pub const FAR_DISTANCE: f32 = 250.0;

/// How a [`tree_planner`] plans.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TreePlan {
    /// Largest predicted error of a node drawn as one image, levels.
    pub budget: f32,
    /// Image rebuilds per frame, at most.
    pub rebuilds: usize,
    /// The first `.0` frames take images within `.1` predicted milliseconds of rebuilds
    /// (a game loading a level), the later ones within [`TREE_REBUILD_MS`].
    pub loading: (u32, f32),
    /// The target's height, pixels: the pixel settings scale with it ([`tree_scale`]).
    pub height: u32,
}

impl TreePlan {
    /// The plan the world's tests take for a `height`-pixel target: `bench budget`'s
    /// defaults (16 levels, a sixteenth of the objects rebuilt a frame and 16 at least, 4
    /// loading frames within 40 predicted milliseconds of rebuilds).
    pub fn for_tests(world: &World, height: u32) -> Self {
        TreePlan {
            budget: 16.0,
            rebuilds: (world.objects.len() / 16).max(16),
            loading: (4, 40.0),
            height,
        }
    }
}

/// The per-node planner over a hierarchy of `objects`, each node drawn as one runtime
/// impostor of all its objects (at most [`TREE_SIDE`] texels a side at 640x360, scaled
/// with the target's height, [`tree_scale`]) when its predicted error is within the
/// budget, else its children considered.
pub fn tree_planner(objects: Vec<MeshGroup>, plan: TreePlan) -> Hierarchy<MeshGroup> {
    tree_planner_drawing(objects, plan, Some(TREE_CUTOUT))
}

/// [`tree_planner`] with its node images drawn as cutouts at `cutout` coverage, or blended
/// (`None`).
pub fn tree_planner_drawing(
    objects: Vec<MeshGroup>,
    plan: TreePlan,
    cutout: Option<f32>,
) -> Hierarchy<MeshGroup> {
    let config = TreeConfig {
        budget: plan.budget,
        rebuilds: plan.rebuilds,
        rebuild_ms: TREE_REBUILD_MS,
        capture_ms: TREE_CAPTURE_MS,
        loading: plan.loading,
        far: Some(far_config(plan.height)),
        lod_px: TreeConfig::default().lod_px * tree_scale(plan.height),
        capture_lod: (TREE_CAPTURE_PX, tree_side(plan.height)),
        compose: TREE_COMPOSE,
        ..TreeConfig::default()
    };
    let images = impostor::Config {
        max_side: tree_side(plan.height),
        ..image_config(plan.budget, plan.rebuilds)
    };
    Hierarchy::new(config, objects, |nodes| {
        let mut set = ImpostorSet::new(images, nodes);
        set.cutout = cutout;
        vec![Box::new(set) as Box<dyn Representation<Cluster<MeshGroup>>>]
    })
}

/// A node image's captures draw each object at its coarsest level of detail deviating
/// within this many texels of the node's largest image ([`TreeConfig::capture_lod`]): the
/// merged buildings (the same picture) and the statues' coarser tori. `bench budget --scene
/// world` at 640x360 (24 frames, the same cut: 5.83 rebuilds a frame): 103,448 triangles
/// captured against 478,642 with full meshes (-78%; 1280x720: 142,156 against 540,424),
/// measured mean error 0.8950 in both (1280x720: 0.8371 against 0.8372). The captures'
/// time did not follow: they are not triangle bound (BENCHMARKS.md, issue 41, session 17).
pub const TREE_CAPTURE_PX: f32 = 0.5;

/// The node images are drawn as cutouts: a texel at least this covered is opaque, the
/// others dropped ([`ImpostorSet::cutout`]). Opaque, the images write depth and are drawn
/// near to far with the geometry, so the ground and farther images behind them are
/// rejected before they are shaded; blended, every image fragment was shaded over what was
/// behind it. `bench budget --scene world` at 640x360 (a temporary per-stage print, load
/// 6 to 7): fragments shaded 322,161 to 261,054 a frame (-19%, none blended against
/// 76,504), measured mean error 0.911 to 0.913 levels (BENCHMARKS.md, issue 41, session 12).
pub const TREE_CUTOUT: f32 = 0.5;

/// Runtime impostor settings: refreshed past `levels` of predicted staleness, `rebuilds`
/// a frame, enough textures for every object.
pub fn image_config(levels: f32, rebuilds: usize) -> impostor::Config {
    impostor::Config {
        tolerance: Tolerance {
            levels: Some(levels),
            ..Tolerance::default()
        },
        budget: Budget::count(rebuilds),
        pool_slots: 1 << 16,
        prewarm: 0.0,
        ..impostor::Config::default()
    }
}
