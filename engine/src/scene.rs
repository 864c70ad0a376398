//! Scenes: meshes, materials and the instances that place them, plus lighting.
//!
//! A scene owns its data; the renderer borrows it for one frame. Loaders return a
//! [`Scene`]; procedural builders add to one.

use crate::light::Lighting;
use crate::material::Material;
use crate::mesh::{Mesh, Sphere};
use glam::Mat4;

/// A mesh placed in the world with one material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    /// Index into [`Scene::meshes`].
    pub mesh: usize,
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// Object -> world.
    pub transform: Mat4,
}

/// A scene: what to draw and how it is lit.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scene {
    /// The meshes, each in its own object space; instances may share one.
    pub meshes: Vec<Mesh>,
    /// The materials; instances may share one.
    pub materials: Vec<Material>,
    /// What is drawn, in order; an instance whose indices are out of range is skipped.
    pub instances: Vec<Instance>,
    /// The lights [`Renderer::render_scene`](crate::Renderer::render_scene) shades the
    /// scene's [`Shading::Lit`](crate::Shading::Lit) materials with.
    pub lighting: Lighting,
}

/// One draw handed to the renderer: a mesh, a material, an object -> world transform.
#[derive(Clone, Copy, Debug)]
pub struct Draw<'a> {
    /// The triangles, in object space.
    pub mesh: &'a Mesh,
    /// How they are shaded, tested and blended.
    pub material: &'a Material,
    /// Object space -> world space.
    pub transform: Mat4,
}

impl Scene {
    /// Adds a mesh and a material and one instance of them; returns the instance index.
    pub fn add(&mut self, mesh: Mesh, material: Material, transform: Mat4) -> usize {
        self.meshes.push(mesh);
        self.materials.push(material);
        self.instances.push(Instance {
            mesh: self.meshes.len() - 1,
            material: self.materials.len() - 1,
            transform,
        });
        self.instances.len() - 1
    }

    /// The draws of every instance whose mesh and material exist (others are skipped).
    pub fn draws(&self) -> impl Iterator<Item = Draw<'_>> + Clone {
        self.instances.iter().filter_map(|i| {
            Some(Draw {
                mesh: self.meshes.get(i.mesh)?,
                material: self.materials.get(i.material)?,
                transform: i.transform,
            })
        })
    }

    /// The triangles of every drawable instance (an instanced mesh counts once per
    /// instance).
    pub fn triangle_count(&self) -> usize {
        self.draws().map(|d| d.mesh.triangle_count()).sum()
    }

    /// A world-space sphere around every instance (for framing a camera).
    pub fn bounding_sphere(&self) -> Sphere {
        let spheres: Vec<Sphere> = self
            .draws()
            .map(|d| {
                let s = d.mesh.bounding_sphere();
                let scale = d
                    .transform
                    .x_axis
                    .truncate()
                    .length()
                    .max(d.transform.y_axis.truncate().length())
                    .max(d.transform.z_axis.truncate().length());
                Sphere {
                    center: d.transform.transform_point3(s.center),
                    radius: s.radius * scale,
                }
            })
            .filter(|s| s.center.is_finite() && s.radius.is_finite())
            .collect();
        if spheres.is_empty() {
            return Sphere {
                center: glam::Vec3::ZERO,
                radius: 1.0,
            };
        }
        let center = spheres.iter().map(|s| s.center).sum::<glam::Vec3>() / spheres.len() as f32;
        let radius = spheres
            .iter()
            .map(|s| s.center.distance(center) + s.radius)
            .fold(0.0, f32::max);
        Sphere { center, radius }
    }
}
