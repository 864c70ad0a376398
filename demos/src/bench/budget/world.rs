//! The large procedural world `bench budget` plans over: a square of lots, each holding one
//! instance of a few shared prototype meshes (buildings of three detail levels, trees,
//! rocks and torus statues), tens of thousands of objects and over ten million triangles,
//! and the low fly-over the runs follow.

use crate::city::{building, daylight, ground};
use engine::procedural::{self, TreeKind, XorShift};
use engine::{Camera, Lighting, Material, Mesh, Rgba, Shading};
use glam::{Mat4, Vec3};
use ibr::subject::{MeshGroup, Subject};
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
        let statue_mesh = procedural::torus_with_triangles(3000);
        protos.push((Arc::new(statue_mesh), Arc::new(statue)));
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
                objects.push(MeshGroup::new().with(mesh, material, place));
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
