//! A world of many objects at frame rate: a hierarchy over the objects ([`Tree`], a
//! bounding volume hierarchy built once and refitted where objects move), whose nodes are
//! subjects of their own ([`Cluster`]: every object under the node), so any image
//! representation of the planner seam can capture a whole node into one image; and a
//! planner choosing per node ([`Hierarchy`]): a node in view is one image when its
//! predicted error is within the budget, else its children are considered, and nodes off
//! the view are skipped whole (after Shade et al. 96, Schaufler and Stuerzlinger 96,
//! Maciel and Shirley 95). The frame's cost follows the nodes the cut opens and the
//! pixels, not the number of objects.
//!
//! Like the object planner, it uses only the core's interfaces: the representations are
//! given by the caller (the catalogue's, or a technique's own), never named here.

mod bvh;
mod cluster;
mod cut;
mod far;
mod far_mesh;

pub use bvh::{Node, Tree, NONE};
pub use cluster::Cluster;
pub use cut::{Hierarchy, TreeConfig, TreeReport};
pub use far::{FarConfig, FarField, FarReport, Side, Split};

use crate::core::{Counters, FrameView, Subject, Technique};
use engine::{Draw, FrameStats, Target};

impl<S: Subject + Send + Sync> Technique for Hierarchy<S> {
    fn name(&self) -> &str {
        "planner-tree"
    }
    fn prepare(&mut self, view: &FrameView<'_>) {
        self.plan(view);
    }
    fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        Hierarchy::draws(self, out);
    }
    fn passes(&self, view: &FrameView<'_>, target: &mut Target) -> FrameStats {
        Hierarchy::passes(self, view, target)
    }
    /// Nodes drawn as images, objects drawn as geometry, and the frame's rebuilds.
    fn counters(&self) -> Counters {
        let r = &self.report;
        Counters {
            images: r.images as u64,
            quads: r.images as u64,
            geometry: r.geometry as u64,
            refreshes: (r.rebuilds + r.far.tiles) as u64,
            ..Counters::default()
        }
    }
    fn reference<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        self.objects().iter().for_each(|s| s.draws(out));
    }
}

#[cfg(test)]
mod compose_tests;
#[cfg(test)]
mod far_tests;
#[cfg(test)]
mod lod_tests;
#[cfg(test)]
mod tests;
