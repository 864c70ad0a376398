//! Subjects: the things an image can stand in for (a mesh group, a cloud of particles),
//! described by a bounding sphere and the draws that render them as geometry.
//!
//! Impostors (runtime and baked) capture a subject by rendering its draws offscreen; the
//! frame falls back to the same draws when an image will not do.

use engine::{Camera, Draw, Material, Mesh, Scene, Sphere};
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

    /// Appends the draws that render the subject as geometry seen from `eye` at
    /// `px_per_radian`, each mesh replaced by its coarsest level of detail whose geometric
    /// deviation stays within `tolerance_px` pixels there (see [`Part::with_lods`]). By
    /// default the full [`Subject::draws`].
    fn draws_seen<'s>(
        &'s self,
        _eye: Vec3,
        _px_per_radian: f32,
        _tolerance_px: f32,
        out: &mut Vec<Draw<'s>>,
    ) {
        self.draws(out);
    }

    /// Changes whenever the subject's appearance changes (animation), so images of it can
    /// be invalidated. Constant for static subjects.
    fn version(&self) -> u64 {
        0
    }

    /// Triangles drawn by [`Subject::draws`] (for the triangles-against-pixels figures).
    fn triangle_count(&self) -> usize;

    /// Fragments its draws shade per pixel of its bounding sphere's disc, seen from
    /// anywhere: 1 for opaque surfaces (the depth test keeps the nearest), more for
    /// blended layers that are all shaded (a cloud's overlapping particles). The planner's
    /// cost of drawing it as geometry.
    fn overdraw(&self) -> f32 {
        1.0
    }

    /// World-space corners of a box around everything [`Subject::draws`] draws: the
    /// characteristic points an image layer's warp is fitted to. By default the cube around
    /// [`Subject::bounds`]; subjects that know a tighter box say so.
    fn corners(&self) -> [Vec3; 8] {
        let b = self.bounds();
        box_corners(b.center - b.radius, b.center + b.radius)
    }
}

/// The eight corners of the axis-aligned box `lo..hi`.
pub fn box_corners(lo: Vec3, hi: Vec3) -> [Vec3; 8] {
    std::array::from_fn(|k| {
        Vec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

/// A boxed subject is a subject, so one impostor set can hold subjects of several kinds
/// (`Vec<Box<dyn Subject + Send>>`: buildings and clouds under one budget).
impl<T: Subject + ?Sized> Subject for Box<T> {
    fn bounds(&self) -> Sphere {
        (**self).bounds()
    }
    fn prepare(&mut self, camera: &Camera, height: u32) {
        (**self).prepare(camera, height);
    }
    fn draws<'s>(&'s self, out: &mut Vec<Draw<'s>>) {
        (**self).draws(out);
    }
    fn draws_seen<'s>(&'s self, eye: Vec3, ppr: f32, tolerance: f32, out: &mut Vec<Draw<'s>>) {
        (**self).draws_seen(eye, ppr, tolerance, out);
    }
    fn version(&self) -> u64 {
        (**self).version()
    }
    fn triangle_count(&self) -> usize {
        (**self).triangle_count()
    }
    fn overdraw(&self) -> f32 {
        (**self).overdraw()
    }
    fn corners(&self) -> [Vec3; 8] {
        (**self).corners()
    }
}

/// A group of meshes placed in the world: a building, a tree, a statue.
#[derive(Clone, Debug, Default)]
pub struct MeshGroup {
    /// The meshes, each with its material and transform.
    pub parts: Vec<Part>,
    /// Bumped by whoever changes `parts` (see [`Subject::version`]).
    pub version: u64,
}

/// One mesh of a [`MeshGroup`], with its material and object -> world transform.
#[derive(Clone, Debug)]
pub struct Part {
    /// The mesh, in object space.
    pub mesh: Arc<Mesh>,
    /// Its material.
    pub material: Arc<Material>,
    /// Object -> world transform.
    pub transform: Mat4,
    /// The mesh's object-space bounding sphere and box, and which mesh they were computed
    /// for (by address): bounds are asked for every frame, and a mesh may have a million
    /// vertices.
    local: (usize, Sphere, Option<(Vec3, Vec3)>),
    /// Coarser stand-ins for `mesh`, finest first, each with its largest distance from
    /// `mesh`'s surface in object-space units (see [`Part::with_lods`]).
    lods: Vec<(Arc<Mesh>, f32)>,
}

impl Part {
    /// A part drawing `mesh` with `material`, placed by `transform` (object -> world); the
    /// mesh's bounds are computed once here.
    pub fn new(mesh: Arc<Mesh>, material: Arc<Material>, transform: Mat4) -> Self {
        let local = (
            Arc::as_ptr(&mesh) as usize,
            mesh.bounding_sphere(),
            mesh.bounding_box(),
        );
        Part {
            mesh,
            material,
            transform,
            local,
            lods: Vec::new(),
        }
    }

    /// The part with levels of detail: coarser meshes, finest first, each with its
    /// geometric deviation from `mesh` (object-space units, the larger of the two one-sided
    /// distances between the surfaces). [`Subject::draws_seen`] draws the coarsest whose
    /// deviation, scaled by the transform and projected at the part's nearest distance
    /// from the eye, is within its pixel tolerance; [`Subject::draws`] and images stay full.
    pub fn with_lods(mut self, lods: Vec<(Arc<Mesh>, f32)>) -> Self {
        self.lods = lods;
        self
    }

    /// The mesh [`Subject::draws_seen`] draws for this part seen from `eye` (see
    /// [`Part::with_lods`]): `mesh` unless a coarser one deviates within `tolerance_px`.
    pub fn mesh_seen(&self, eye: Vec3, px_per_radian: f32, tolerance_px: f32) -> &Arc<Mesh> {
        if self.lods.is_empty() {
            return &self.mesh;
        }
        let b = self.bounds();
        let t = self.transform;
        let scale = t.x_axis.truncate().length();
        let scale = scale.max(t.y_axis.truncate().length());
        let scale = scale.max(t.z_axis.truncate().length());
        let distance = (b.center.distance(eye) - b.radius).max(1e-3);
        let fits = |dev: f32| dev * scale * px_per_radian / distance <= tolerance_px;
        let coarsest = self.lods.iter().rev().find(|(_, dev)| fits(*dev));
        coarsest.map_or(&self.mesh, |(m, _)| m)
    }

    /// World-space box around the part: the box around its object-space box's corners
    /// (the cached box unless `mesh` was replaced); `None` for a mesh with no finite vertex.
    pub fn world_box(&self) -> Option<(Vec3, Vec3)> {
        let (lo, hi) = if self.local.0 == Arc::as_ptr(&self.mesh) as usize {
            self.local.2
        } else {
            self.mesh.bounding_box()
        }?;
        let world = box_corners(lo, hi).map(|c| self.transform.transform_point3(c));
        let lo = world.iter().fold(Vec3::splat(f32::MAX), |a, &c| a.min(c));
        let hi = world.iter().fold(Vec3::splat(f32::MIN), |a, &c| a.max(c));
        (lo.is_finite() && hi.is_finite()).then_some((lo, hi))
    }

    /// World-space bounding sphere (the cached one unless `mesh` was replaced).
    pub fn bounds(&self) -> Sphere {
        let s = if self.local.0 == Arc::as_ptr(&self.mesh) as usize {
            self.local.1
        } else {
            self.mesh.bounding_sphere()
        };
        let t = self.transform;
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
    }
}

impl MeshGroup {
    /// An empty group (no parts, version 0).
    pub fn new() -> Self {
        Self::default()
    }

    /// A group of some of a scene's instances (a loaded glTF's node subtree, say: its
    /// instances' indices), each mesh and material copied once into shared storage.
    /// Indices out of range are skipped.
    pub fn from_scene(scene: &Scene, instances: impl IntoIterator<Item = usize>) -> Self {
        let mut meshes: Vec<Option<Arc<Mesh>>> = vec![None; scene.meshes.len()];
        let mut materials: Vec<Option<Arc<Material>>> = vec![None; scene.materials.len()];
        let mut group = MeshGroup::new();
        for i in instances {
            let Some(inst) = scene.instances.get(i) else {
                continue;
            };
            let (Some(mesh), Some(material)) = (
                scene.meshes.get(inst.mesh).map(|m| {
                    meshes[inst.mesh]
                        .get_or_insert_with(|| Arc::new(m.clone()))
                        .clone()
                }),
                scene.materials.get(inst.material).map(|m| {
                    materials[inst.material]
                        .get_or_insert_with(|| Arc::new(m.clone()))
                        .clone()
                }),
            ) else {
                continue;
            };
            group.parts.push(Part::new(mesh, material, inst.transform));
        }
        group
    }

    /// Adds a part; returns `self` for chaining.
    pub fn with(mut self, mesh: Arc<Mesh>, material: Arc<Material>, transform: Mat4) -> Self {
        self.parts.push(Part::new(mesh, material, transform));
        self
    }
}

impl Subject for MeshGroup {
    fn bounds(&self) -> Sphere {
        let finite = |s: &Sphere| s.center.is_finite() && s.radius.is_finite();
        let spheres = self.parts.iter().map(Part::bounds).filter(finite);
        // Each part's sphere worked out once (`enclose` takes them twice), on the stack
        // for the few parts most groups have: bounds are asked of every object every frame.
        let none = Sphere {
            center: Vec3::ZERO,
            radius: 0.0,
        };
        let mut few = [none; 8];
        if self.parts.len() <= few.len() {
            let mut n = 0;
            for s in spheres {
                few[n] = s;
                n += 1;
            }
            return enclose(few[..n].iter().copied());
        }
        enclose(spheres)
    }

    fn draws<'s>(&'s self, out: &mut Vec<Draw<'s>>) {
        out.extend(self.parts.iter().map(|p| Draw {
            mesh: &p.mesh,
            material: &p.material,
            transform: p.transform,
        }));
    }

    fn draws_seen<'s>(&'s self, eye: Vec3, ppr: f32, tolerance: f32, out: &mut Vec<Draw<'s>>) {
        out.extend(self.parts.iter().map(|p| Draw {
            mesh: p.mesh_seen(eye, ppr, tolerance),
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

    /// The box around the parts' world boxes.
    fn corners(&self) -> [Vec3; 8] {
        let boxes = self.parts.iter().filter_map(Part::world_box);
        let (lo, hi) = boxes.fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), (l, h)| (lo.min(l), hi.max(h)),
        );
        if lo.x > hi.x {
            let b = self.bounds();
            return box_corners(b.center, b.center);
        }
        box_corners(lo, hi)
    }
}

/// A sphere around `spheres` (centred on their bounding box; radius 0 at the origin for
/// none). Takes the spheres twice (box, then radius), so pass a cheap iterator.
pub fn enclose(spheres: impl Iterator<Item = Sphere> + Clone) -> Sphere {
    let (lo, hi) = spheres.clone().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), s| (lo.min(s.center - s.radius), hi.max(s.center + s.radius)),
    );
    if lo.x > hi.x {
        return Sphere {
            center: Vec3::ZERO,
            radius: 0.0,
        };
    }
    let center = (lo + hi) * 0.5;
    if !center.is_finite() {
        return Sphere {
            center: Vec3::ZERO,
            radius: 0.0,
        };
    }
    let radius = spheres
        .map(|s| s.center.distance(center) + s.radius)
        .fold(0.0, f32::max);
    Sphere { center, radius }
}

#[cfg(test)]
mod tests {
    use super::*;
    use engine::procedural;

    #[test]
    fn group_bounds_follow_transforms_and_replaced_meshes() {
        let unit = Arc::new(procedural::uv_sphere(1.0, 8, 16));
        let m = Arc::new(Material::default());
        let mut g = MeshGroup::new()
            .with(
                unit.clone(),
                m.clone(),
                Mat4::from_translation(Vec3::X * 3.0),
            )
            .with(unit, m, Mat4::from_scale(Vec3::splat(2.0)));
        let b = g.bounds();
        // Spheres at x = 3 (radius 1) and 0 (radius 2): box x in [-2, 4], centre x = 1.
        assert!((b.center - Vec3::X).length() < 1e-3, "{b:?}");
        assert!((b.radius - 3.0).abs() < 1e-3, "{b:?}");
        g.parts[0].transform = Mat4::from_translation(Vec3::X * 5.0);
        assert!((g.bounds().radius - 4.0).abs() < 1e-3);
        g.parts[0].mesh = Arc::new(procedural::uv_sphere(3.0, 8, 16));
        let b = g.bounds();
        assert!(
            (b.center - Vec3::X * 3.0).length() < 1e-3 && (b.radius - 5.0).abs() < 1e-3,
            "{b:?}"
        );
        assert_eq!(MeshGroup::new().bounds().radius, 0.0);
    }

    #[test]
    fn a_group_from_scene_instances_shares_their_meshes() {
        let mut scene = Scene::default();
        let a = scene.add(
            procedural::cuboid(Vec3::ONE),
            Material::default(),
            Mat4::IDENTITY,
        );
        let b = scene.add(
            procedural::uv_sphere(1.0, 4, 8),
            Material::default(),
            Mat4::IDENTITY,
        );
        // A second instance of the cube, moved: the group shares one copy of the mesh.
        scene.instances.push(engine::Instance {
            transform: Mat4::from_translation(Vec3::X * 4.0),
            ..scene.instances[a]
        });
        let g = MeshGroup::from_scene(&scene, [a, 2, 99]);
        assert_eq!(g.parts.len(), 2, "index 99 skipped");
        assert!(Arc::ptr_eq(&g.parts[0].mesh, &g.parts[1].mesh));
        assert_eq!(g.triangle_count(), 24);
        let mut draws = Vec::new();
        g.draws(&mut draws);
        assert_eq!(draws[1].transform, scene.instances[2].transform);
        let _ = b;
    }
}
