//! Subjects: the things an image can stand in for (a mesh group, a cloud of particles),
//! described by a bounding sphere and the draws that render them as geometry.
//!
//! Impostors (runtime and baked) capture a subject by rendering its draws offscreen; the
//! frame falls back to the same draws when an image will not do.

use engine::{Camera, Draw, Material, Mesh, Sphere};
use glam::{Mat4, Vec3};
use std::sync::Arc;

/// Something an impostor can replace.
pub trait Subject {
    /// World-space bounding sphere of everything [`Subject::draws`] draws.
    fn bounds(&self) -> Sphere;

    /// Makes view-dependent geometry (billboards facing the camera) before [`Subject::draws`]
    /// is called for `camera` and an image `height` pixels tall. Most subjects need nothing.
    fn prepare(&mut self, _camera: &Camera, _height: u32) {}

    /// Appends the draws that render the subject as geometry.
    fn draws<'s>(&'s self, out: &mut Vec<Draw<'s>>);

    /// Changes whenever the subject's appearance changes (animation), so images of it can
    /// be invalidated. Constant for static subjects.
    fn version(&self) -> u64 {
        0
    }

    /// Triangles drawn by [`Subject::draws`] (for the triangles-against-pixels figures).
    fn triangle_count(&self) -> usize;
}

/// A group of meshes placed in the world: a building, a tree, a statue.
#[derive(Clone, Debug, Default)]
pub struct MeshGroup {
    pub parts: Vec<Part>,
    /// Bumped by whoever changes `parts` (see [`Subject::version`]).
    pub version: u64,
}

/// One mesh of a [`MeshGroup`], with its material and object -> world transform.
#[derive(Clone, Debug)]
pub struct Part {
    pub mesh: Arc<Mesh>,
    pub material: Arc<Material>,
    pub transform: Mat4,
}

impl MeshGroup {
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a part; returns `self` for chaining.
    pub fn with(mut self, mesh: Arc<Mesh>, material: Arc<Material>, transform: Mat4) -> Self {
        self.parts.push(Part {
            mesh,
            material,
            transform,
        });
        self
    }
}

impl Subject for MeshGroup {
    fn bounds(&self) -> Sphere {
        let spheres: Vec<Sphere> = self
            .parts
            .iter()
            .map(|p| {
                let s = p.mesh.bounding_sphere();
                let t = p.transform;
                let scale = t
                    .x_axis
                    .truncate()
                    .length()
                    .max(t.y_axis.truncate().length())
                    .max(t.z_axis.truncate().length());
                Sphere {
                    center: t.transform_point3(s.center),
                    radius: s.radius * scale,
                }
            })
            .filter(|s| s.center.is_finite() && s.radius.is_finite())
            .collect();
        enclose(&spheres)
    }

    fn draws<'s>(&'s self, out: &mut Vec<Draw<'s>>) {
        out.extend(self.parts.iter().map(|p| Draw {
            mesh: &p.mesh,
            material: &p.material,
            transform: p.transform,
        }));
    }

    fn version(&self) -> u64 {
        self.version
    }

    fn triangle_count(&self) -> usize {
        self.parts.iter().map(|p| p.mesh.triangle_count()).sum()
    }
}

/// A sphere around `spheres` (centred on their bounding box; a unit sphere at the origin
/// for none).
pub fn enclose(spheres: &[Sphere]) -> Sphere {
    if spheres.is_empty() {
        return Sphere {
            center: Vec3::ZERO,
            radius: 0.0,
        };
    }
    let lo = spheres
        .iter()
        .fold(Vec3::splat(f32::INFINITY), |a, s| a.min(s.center - s.radius));
    let hi = spheres
        .iter()
        .fold(Vec3::splat(f32::NEG_INFINITY), |a, s| a.max(s.center + s.radius));
    let center = (lo + hi) * 0.5;
    let radius = spheres
        .iter()
        .map(|s| s.center.distance(center) + s.radius)
        .fold(0.0, f32::max);
    Sphere { center, radius }
}
