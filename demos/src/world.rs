//! The large procedural world of `bench budget`, `bench objects` and the showcase's world
//! moment: a square of lots, each holding one instance of a few shared prototype meshes
//! (buildings of three detail levels, trees, rocks and torus statues), tens of thousands
//! of objects and over ten million triangles, the low fly-over they follow, and the
//! per-node planner they draw it with ([`tree_planner`]: a hierarchy over the objects whose
//! nodes are drawn as one runtime impostor each, [`ibr::plan::tree`]).
//!
//! Used by `bench` and `showcase` alike; it builds only on [`crate::city`] (a leaf), so
//! neither imports the other through it.

use crate::city::{building, daylight, ground};
use engine::procedural::{self, TreeKind, XorShift};
use engine::{Camera, Lighting, Material, Mesh, Rgba, Shading};
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
        let side = side.max(1);
        let half_extent = side as f32 * LOT * 0.5;
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
        for (k, wall) in [
            (6, Rgba::new(0.7, 0.6, 0.5, 1.0)),
            (8, Rgba::new(0.55, 0.6, 0.68, 1.0)),
            (10, Rgba::new(0.72, 0.52, 0.42, 1.0)),
        ] {
            let mesh = building(Vec3::new(3.2, 7.0 + k as f32, 3.0), k, wall);
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
                let x = (gx as f32 + 0.5) * LOT - half_extent + rng.range(-0.8, 0.8);
                let z = (gz as f32 + 0.5) * LOT - half_extent + rng.range(-0.8, 0.8);
                let lift = if p == 6 { 1.6 } else { 0.0 };
                let place = Mat4::from_translation(Vec3::new(x, lift, z))
                    * Mat4::from_rotation_y(rng.range(0.0, std::f32::consts::TAU))
                    * Mat4::from_scale(Vec3::splat(rng.range(0.8, 1.2)));
                let (mesh, material) = protos[p].clone();
                let mut part = Part::new(mesh, material, place);
                if p == 6 {
                    part = part.with_lods(statue_lods.clone());
                }
                objects.push(MeshGroup {
                    parts: vec![part],
                    version: 0,
                });
            }
        }
        World {
            objects,
            ground: ground(half_extent * 2.2, Rgba::from_srgb8(92, 104, 84)),
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
}

/// Triangles of the world's torus statue, and of its coarser levels of detail, finest
/// first: the statues are 15% of the objects and over half the triangles, so the near
/// ones drawn as geometry and the far field's captures take the coarsest level whose
/// deviation projects within half a pixel ([`TreeConfig::lod_px`], [`FarConfig::lod_px`]);
/// images of clusters and the measured error's reference draw the full mesh.
pub const STATUE: (u32, [u32; 2]) = (3000, [800, 200]);

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

/// The largest cluster image, texels a side: a node wider than that on screen is opened
/// (the cut's clusters stay small on screen, so each is cheap to retake and slow to go
/// stale as the eye moves).
pub const TREE_SIDE: u32 = 64;

/// The hierarchy planner's predicted milliseconds of rebuilds (cluster images) per frame:
/// the share of a 60 Hz frame left to captures (measured at budget 16 in the world, 24
/// frames: 40 to 60 ms a frame, its prepare, the captures, 15 to 25 ms of it).
pub const TREE_REBUILD_MS: f32 = 8.0;

/// The world's far field: everything beyond [`FAR_DISTANCE`] of the eye as one image mesh
/// with depth, captured in 8 x 8 tiles (split where one is over the budget) within 150,000
/// triangles a frame (4 M while loading), re-captured when the eye's move makes 24 pixels
/// of parallax at that distance.
pub fn far_config() -> FarConfig {
    FarConfig {
        distance: FAR_DISTANCE,
        triangles: 150_000,
        parallax: 24.0,
        ..FarConfig::default()
    }
}

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
}

/// The per-node planner over a hierarchy of `objects`, each node drawn as one runtime
/// impostor of all its objects (at most [`TREE_SIDE`] texels a side) when its predicted
/// error is within the budget, else its children considered.
pub fn tree_planner(objects: Vec<MeshGroup>, plan: TreePlan) -> Hierarchy<MeshGroup> {
    let config = TreeConfig {
        budget: plan.budget,
        rebuilds: plan.rebuilds,
        rebuild_ms: TREE_REBUILD_MS,
        loading: plan.loading,
        far: Some(far_config()),
        ..TreeConfig::default()
    };
    let images = impostor::Config {
        max_side: TREE_SIDE,
        ..image_config(plan.budget, plan.rebuilds)
    };
    Hierarchy::new(config, objects, |nodes| {
        vec![Box::new(ImpostorSet::new(images, nodes))
            as Box<dyn Representation<Cluster<MeshGroup>>>]
    })
}

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
