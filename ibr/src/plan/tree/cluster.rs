//! A node of the hierarchy as a subject: all of its objects, drawn together, so any image
//! representation (a runtime impostor, a layer) can capture the whole node into one image
//! and stand in for it (Shade et al. 96's cached node images). The objects are shared
//! between every node's cluster; a node's version is its tree node's, bumped when an
//! object under it moves, so an image of it knows it is stale. For one capture a cluster may
//! be composed ([`Part`]): its children's images drawn in place of their objects (Shade et
//! al. 96's hierarchical image cache), so the capture costs texels, not objects.

use crate::core::{box_corners, Subject};
use engine::{AlphaMode, Draw, Material, Mesh, Rgba, Sphere};
use glam::{Mat4, Vec3};
use std::sync::Arc;

/// What a composed cluster's capture draws for one of its children.
#[derive(Clone, Debug)]
pub(super) enum Part {
    /// The child's image: its quad (world space after the transform) and material (the
    /// image's texture shared, drawn as an untinted cutout).
    Image(Box<(Mesh, Material, Mat4)>),
    /// The child's objects `members[first..first + count]`, as geometry.
    Objects(u32, u32),
}

impl Part {
    /// The part drawing `draw`'s image: untinted, a cutout at half coverage (the capture
    /// keeps depth, so nearer images hide farther ones).
    pub(super) fn image(draw: &Draw<'_>) -> Part {
        let material = Material {
            base_color: Rgba::WHITE,
            alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
            ..draw.material.clone()
        };
        Part::Image(Box::new((draw.mesh.clone(), material, draw.transform)))
    }

    /// Texels of its image's texture (0 for objects).
    pub(super) fn texels(&self) -> u64 {
        match self {
            Part::Image(image) => image
                .1
                .base_texture
                .as_ref()
                .map_or(0, |t| u64::from(t.width()) * u64::from(t.height())),
            Part::Objects(..) => 0,
        }
    }
}

/// Every object of one node of the hierarchy.
#[derive(Clone, Debug)]
pub struct Cluster<S> {
    objects: Arc<Vec<S>>,
    members: Arc<Vec<u32>>,
    first: u32,
    count: u32,
    lo: Vec3,
    hi: Vec3,
    triangles: usize,
    overdraw: f32,
    version: u64,
    /// Deviation its captures may draw, as a fraction of its bounding sphere's diameter
    /// (0: full meshes; [`Cluster::with_capture_lod`]).
    capture_lod: f32,
    /// Drawn instead of its objects while not empty ([`Cluster::compose`]).
    composed: Vec<Part>,
    /// Triangles a capture of its objects draws ([`Cluster::capture_triangles`]).
    capture_triangles: usize,
}

impl<S: Subject> Cluster<S> {
    /// The cluster of `members[first..first + count]` of `objects`, in the box `lo..hi`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn new(
        objects: Arc<Vec<S>>,
        members: Arc<Vec<u32>>,
        first: u32,
        count: u32,
        (lo, hi): (Vec3, Vec3),
        version: u64,
    ) -> Self {
        let mut c = Cluster {
            objects,
            members,
            first,
            count,
            lo,
            hi,
            triangles: 0,
            overdraw: 1.0,
            version,
            capture_lod: 0.0,
            composed: Vec::new(),
            capture_triangles: 0,
        };
        let (mut tris, mut over) = (0, 1.0f32);
        for s in c.iter() {
            tris += s.triangle_count();
            over = over.max(s.overdraw());
        }
        (c.triangles, c.overdraw, c.capture_triangles) = (tris, over, tris);
        c
    }

    /// Counts [`Cluster::capture_triangles`] again.
    fn count_capture(&mut self) {
        if self.capture_lod <= 0.0 {
            self.capture_triangles = self.triangles;
            return;
        }
        let mut scratch = Vec::new();
        let n = self.captured_triangles(&mut scratch);
        self.capture_triangles = n;
    }

    /// Triangles a capture of its objects draws, at the levels of detail of
    /// [`Cluster::with_capture_lod`] (its [`Subject::triangle_count`] without one, the full
    /// meshes): what a
    /// rebuild of its image is priced at. Counted when it is made and when its node
    /// changes, so pricing a rebuild does not visit its objects.
    pub(super) fn capture_triangles(&self) -> usize {
        self.capture_triangles
    }

    /// The cluster whose [`Subject::draws`] (what an image of it captures) draws each
    /// object at its coarsest level of detail deviating within `px` texels of an image
    /// `side` texels across its bounding sphere (an image of the node is at most that side,
    /// so its texels are at least that large); `px` 0 draws the full meshes.
    pub(super) fn with_capture_lod(mut self, px: f32, side: u32) -> Self {
        self.capture_lod = if side == 0 {
            0.0
        } else {
            px.max(0.0) / side as f32
        };
        self.count_capture();
        self
    }

    /// Triangles its captures draw ([`Subject::draws`], at the levels of detail of
    /// [`Cluster::with_capture_lod`]); `scratch` is cleared and left holding the draws.
    pub(super) fn captured_triangles<'s>(&'s self, scratch: &mut Vec<Draw<'s>>) -> usize {
        scratch.clear();
        self.draws(scratch);
        scratch.iter().map(|d| d.mesh.triangle_count()).sum()
    }

    /// Until [`Cluster::uncompose`], its [`Subject::draws`] (what a capture draws) are
    /// `parts`: its children's images, or their objects.
    pub(super) fn compose(&mut self, parts: impl IntoIterator<Item = Part>) {
        self.composed.clear();
        self.composed.extend(parts);
    }

    /// Its draws are its objects' again.
    pub(super) fn uncompose(&mut self) {
        self.composed.clear();
    }

    /// Draws `members[first..first + count]` at the capture's levels of detail.
    fn draw_objects<'s>(&'s self, first: u32, count: u32, out: &mut Vec<Draw<'s>>) {
        let range = first as usize..(first + count) as usize;
        let objects = self.members[range]
            .iter()
            .map(|&i| &self.objects[i as usize]);
        let tolerance = self.capture_lod * (self.hi - self.lo).length();
        if tolerance <= 0.0 {
            objects.for_each(|s| s.draws(out));
            return;
        }
        // Seen from one unit off its bounding sphere at one pixel per `tolerance` radians,
        // an object's level of detail deviates within `tolerance` world units (one pixel
        // there): each part's distance is measured to its own sphere, which a one-part
        // object's is; a part inside a larger object is judged from at least as far.
        for s in objects {
            let b = s.bounds();
            let eye = b.center + Vec3::Y * (b.radius + 1.0);
            s.draws_seen(eye, 1.0 / tolerance, 1.0, out);
        }
    }

    /// Its objects.
    pub fn iter(&self) -> impl Iterator<Item = &S> {
        let range = self.first as usize..(self.first + self.count) as usize;
        self.members[range]
            .iter()
            .map(|&i| &self.objects[i as usize])
    }

    /// How many objects it holds.
    pub fn len(&self) -> usize {
        self.count as usize
    }

    /// Whether it holds none.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Drops its hold on the shared objects (so they can be changed in place).
    pub(super) fn let_go(&mut self, empty: &Arc<Vec<S>>) {
        self.objects = empty.clone();
    }

    /// Holds `objects` again, with the box and version of its node.
    pub(super) fn take(&mut self, objects: &Arc<Vec<S>>, (lo, hi): (Vec3, Vec3), version: u64) {
        self.objects = objects.clone();
        let changed = version != self.version;
        (self.lo, self.hi, self.version) = (lo, hi, version);
        if changed {
            self.count_capture();
        }
    }
}

impl<S: Subject> Subject for Cluster<S> {
    fn bounds(&self) -> Sphere {
        Sphere {
            center: (self.lo + self.hi) * 0.5,
            radius: ((self.hi - self.lo) * 0.5).length().max(1e-6),
        }
    }
    fn draws<'s>(&'s self, out: &mut Vec<Draw<'s>>) {
        if self.composed.is_empty() {
            self.draw_objects(self.first, self.count, out);
            return;
        }
        for part in &self.composed {
            match part {
                Part::Image(image) => out.push(Draw {
                    mesh: &image.0,
                    material: &image.1,
                    transform: image.2,
                }),
                &Part::Objects(first, count) => self.draw_objects(first, count, out),
            }
        }
    }
    fn version(&self) -> u64 {
        self.version
    }
    fn triangle_count(&self) -> usize {
        self.triangles
    }
    fn overdraw(&self) -> f32 {
        self.overdraw
    }
    fn corners(&self) -> [Vec3; 8] {
        box_corners(self.lo, self.hi)
    }
}
