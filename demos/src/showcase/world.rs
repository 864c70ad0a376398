//! The showcase's world moment (`showcase --world`, O in the window): a fly-over of the
//! world of many objects ([`crate::world::World`], [`SIDE`] x [`SIDE`] lots) drawn by the
//! per-node planner ([`crate::world::tree_planner`], as `bench budget`'s frame scope draws
//! it): each node of a hierarchy over the objects in view is one runtime impostor of all
//! its objects when its predicted error is within [`BUDGET`], else its children are
//! considered, and the nearest objects are drawn as geometry. Its readout is the planner's
//! ([`WorldTour::readout`]): nodes opened, images drawn, objects as geometry, the images'
//! predicted error, planning and frame time.
//!
//! The first [`LOADING`] frames take images as a game loading a level would (more
//! captures a frame), so the fly-over starts with its far field imaged.

use super::moment::MomentFrame;
use crate::world::{tree_planner, TreePlan, World};
use engine::{Camera, FrameStats, Renderer, Rgba, Target};
use ibr::impostor::Frustum;
use ibr::plan::tree::{Hierarchy, TreeReport, NONE};
use ibr::subject::{MeshGroup, Subject};
use ibr::technique::FrameView;
use std::time::{Duration, Instant};

/// Lots a side: 6,400 objects, about 5 M triangles.
pub const SIDE: u32 = 80;
/// The planner's error budget per node image, levels (the budget sweep's frame scope at
/// 16 measures under one level in the world).
pub const BUDGET: f32 = 16.0;
/// Frames that take images at [`LOADING_MS`] of predicted captures.
pub const LOADING: u32 = 4;
/// Predicted milliseconds of captures a loading frame (the other planners' rebuild budget
/// in `bench budget`).
pub const LOADING_MS: f32 = 40.0;
/// The fly-over's part a frame: `bench budget`'s pace (a quarter of it in 24 frames),
/// about 2.4 units a frame in the default world.
pub const STEP: f32 = 0.01;
/// The clear colour (the budget sweep's sky).
pub const CLEAR: Rgba = Rgba::new(0.55, 0.65, 0.8, 1.0);

/// The world, its planner, the frame loop's memory and the last frame's time.
#[derive(Debug)]
pub struct WorldTour {
    pub world: World,
    pub planner: Hierarchy<MeshGroup>,
    frame: MomentFrame,
    /// The last frame's time (plan, captures and render).
    pub last_time: Duration,
}

/// Which objects in view the last frame drew, and how often (from the planner's cut: the
/// objects under each node drawn as an image, and those drawn as geometry).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Coverage {
    /// Objects whose bounding sphere is in the view frustum,
    pub in_view: usize,
    /// of them drawn exactly once,
    pub once: usize,
    /// not drawn at all,
    pub missing: usize,
    /// and drawn more than once.
    pub twice: usize,
}

impl WorldTour {
    /// The world of [`SIDE`] x [`SIDE`] lots.
    pub fn new() -> Self {
        Self::with_side(SIDE)
    }

    /// The world of `side` x `side` lots and its planner (a sixteenth of the objects
    /// rebuilt a frame at most, 16 at least, as in `bench budget`).
    pub fn with_side(side: u32) -> Self {
        let world = World::new(side, 11);
        let plan = TreePlan {
            budget: BUDGET,
            rebuilds: (world.objects.len() / 16).max(16),
            loading: (LOADING, LOADING_MS),
        };
        let planner = tree_planner(world.objects.clone(), plan);
        WorldTour {
            world,
            planner,
            frame: MomentFrame::default(),
            last_time: Duration::ZERO,
        }
    }

    /// The camera at frame `i` of the fly-over (sideways across the middle fifth of the
    /// world, [`STEP`] of it a frame, then held at its end), for a `width` x `height`
    /// image.
    pub fn camera(&self, i: usize, width: u32, height: u32) -> Camera {
        self.camera_at(i as f32 * STEP, width, height)
    }

    /// The camera at `t` in [0, 1] of the fly-over.
    pub fn camera_at(&self, t: f32, width: u32, height: u32) -> Camera {
        self.world.camera(t, (width, height))
    }

    /// Renders the ground as geometry and the objects through the planner; returns the
    /// frame's counters (the planner's are in [`WorldTour::report`]).
    pub fn render(
        &mut self,
        renderer: &mut Renderer,
        camera: &Camera,
        target: &mut Target,
    ) -> FrameStats {
        let start = Instant::now();
        let view = FrameView::still(
            camera,
            target.width(),
            target.height(),
            &self.world.lighting,
        );
        let stats = self.frame.render(
            renderer,
            |d| self.world.ground.draws(d),
            &mut self.planner,
            &view,
            target,
            CLEAR,
        );
        self.last_time = start.elapsed();
        stats
    }

    /// What the planner's last cut did.
    pub fn report(&self) -> &TreeReport {
        &self.planner.report
    }

    /// One line for the window and the console: the planner's last cut.
    pub fn readout(&self) -> String {
        let r = self.report();
        format!(
            "WORLD {} OBJECTS  {} NODES OPENED  {} IMAGES ({} OBJECTS)  {} GEOMETRY  \
             {} REBUILDS  PREDICTED ERROR {:.2} MAX {:.2} (BUDGET {:.0})  PLAN {:.2} MS  FRAME {:.1} MS",
            self.world.objects.len(),
            r.opened,
            r.images,
            r.imaged_objects,
            r.geometry,
            r.rebuilds,
            r.mean_error,
            r.max_error,
            self.planner.config.budget,
            r.planning_ms,
            self.last_time.as_secs_f64() * 1e3
        )
    }

    /// How often the last frame drew each object in view of `camera` (the camera it was
    /// rendered from). In view is what no enclosing volume rules out: the object's bounding
    /// sphere in the view frustum, and the sphere of every node above it too (a node's
    /// sphere holds its box, which holds its objects' geometry: an object under a node
    /// off the view is off it, however far its own, looser sphere reaches).
    pub fn coverage(&self, camera: &Camera) -> Coverage {
        let objects = &self.world.objects;
        let mut drawn = vec![0u32; objects.len()];
        let tree = self.planner.tree();
        for &(k, _, _) in self.planner.images() {
            for &i in tree.objects_of(k as usize) {
                drawn[i as usize] += 1;
            }
        }
        for &i in self.planner.geometry() {
            drawn[i as usize] += 1;
        }
        let frustum = Frustum::new(camera.clip_from_world());
        let nodes = tree.nodes();
        let node_seen = |mut k: u32| {
            while k != NONE {
                let s = nodes[k as usize].sphere();
                if !frustum.sees(s.center, s.radius) {
                    return false;
                }
                k = nodes[k as usize].parent;
            }
            true
        };
        let mut c = Coverage::default();
        for (i, (o, &n)) in objects.iter().zip(&drawn).enumerate() {
            let b = o.bounds();
            let leaf = tree.leaf_of(i).unwrap_or(NONE);
            if !frustum.sees(b.center, b.radius) || !node_seen(leaf) {
                continue;
            }
            c.in_view += 1;
            match n {
                0 => c.missing += 1,
                1 => c.once += 1,
                _ => c.twice += 1,
            }
        }
        c
    }
}

impl Default for WorldTour {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small world flown over at low resolution: the cut opens nodes, draws images and
    /// geometry, and every object in view once (an image's objects are under its node,
    /// each geometry object is in a leaf the cut reached: no object twice, none left out).
    #[test]
    fn the_cut_draws_every_object_in_view_once() {
        let mut tour = WorldTour::with_side(24);
        let (mut renderer, mut target) = (Renderer::new(), Target::new(160, 96));
        let n = LOADING as usize + 3;
        for i in 0..n {
            let camera = tour.camera(i, 160, 96);
            tour.render(&mut renderer, &camera, &mut target);
            let c = tour.coverage(&camera);
            let r = *tour.report();
            assert!(r.opened > 0 && c.in_view > 0, "{r:?} {c:?}");
            assert_eq!((c.missing, c.twice), (0, 0), "frame {i}: {c:?}");
            assert_eq!(c.once, c.in_view);
            assert!(r.images + r.geometry > 0);
        }
        assert!(tour.report().images > 0, "after loading, images drawn");
    }
}
