//! A node of the hierarchy as a subject: all of its objects, drawn together, so any image
//! representation (a runtime impostor, a layer) can capture the whole node into one image
//! and stand in for it (Shade et al. 96's cached node images). The objects are shared
//! between every node's cluster; a node's version is its tree node's, bumped when an
//! object under it moves, so an image of it knows it is stale.

use crate::core::{box_corners, Subject};
use engine::{Draw, Sphere};
use glam::Vec3;
use std::sync::Arc;

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
        };
        let (mut tris, mut over) = (0, 1.0f32);
        for s in c.iter() {
            tris += s.triangle_count();
            over = over.max(s.overdraw());
        }
        (c.triangles, c.overdraw) = (tris, over);
        c
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
        self
    }

    /// Triangles its captures draw ([`Subject::draws`], at the levels of detail of
    /// [`Cluster::with_capture_lod`]); `scratch` is cleared and left holding the draws.
    pub(super) fn captured_triangles<'s>(&'s self, scratch: &mut Vec<Draw<'s>>) -> usize {
        scratch.clear();
        self.draws(scratch);
        scratch.iter().map(|d| d.mesh.triangle_count()).sum()
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
        (self.lo, self.hi, self.version) = (lo, hi, version);
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
        let tolerance = self.capture_lod * (self.hi - self.lo).length();
        if tolerance <= 0.0 {
            self.iter().for_each(|s| s.draws(out));
            return;
        }
        // Seen from one unit off its bounding sphere at one pixel per `tolerance` radians,
        // an object's level of detail deviates within `tolerance` world units (one pixel
        // there): each part's distance is measured to its own sphere, which a one-part
        // object's is; a part inside a larger object is judged from at least as far.
        for s in self.iter() {
            let b = s.bounds();
            let eye = b.center + Vec3::Y * (b.radius + 1.0);
            s.draws_seen(eye, 1.0 / tolerance, 1.0, out);
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
