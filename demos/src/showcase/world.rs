//! The showcase's world moment (`showcase --world`, O in the window): a fly-over of the
//! world of many objects ([`crate::world::World`], [`SIDE`] x [`SIDE`] lots) drawn by the
//! per-node planner ([`crate::world::tree_planner`], as `bench budget`'s frame scope draws
//! it): each node of a hierarchy over the objects in view is one runtime impostor of all
//! its objects when its predicted error is within [`BUDGET`], else its children are
//! considered, and the nearest objects are drawn as geometry. Its readout is the planner's
//! ([`WorldTour::readout`]): nodes opened, images drawn, objects as geometry, the images'
//! predicted error, planning and frame time, and, once [`WorldTour::measure`] compared the
//! frame with all the geometry from the same eye (outside the frame's time), the measured
//! error. Headless frames carry the readout drawn in ([`WorldTour::annotate`]), as the
//! window draws it.
//!
//! The first [`LOADING`] frames take images as a game loading a level would (more
//! captures a frame), so the fly-over starts with its far field imaged.

use super::moment::MomentFrame;
use crate::font;
use crate::world::{tree_planner, tree_scale, TreePlan, World, TREE_HEIGHT};
use engine::{Camera, Draw, FrameOptions, FrameStats, Renderer, Rgba, Target};
use ibr::impostor::Frustum;
use ibr::metrics::{self, Options};
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
/// Frames [`WorldTour::load`] plans at most (the far field's first capture takes one or
/// two at its loading budget).
pub const LOAD_FRAMES: u32 = 16;
/// The fly-over's part a frame: `bench budget`'s pace (a quarter of it in 24 frames),
/// about 2.4 units a frame in the default world.
pub const STEP: f32 = 0.01;
/// The clear colour (the budget sweep's sky).
pub const CLEAR: Rgba = Rgba::new(0.55, 0.65, 0.8, 1.0);

/// Image rows the readout is drawn over ([`WorldTour::annotate`]): its three lines of text
/// from row 4, ten rows apart, each over a backing box two rows taller than the glyphs.
pub const READOUT_ROWS: u32 = 4 + 10 * 2 + font::GLYPH_H as u32 + 3;

/// The world, its planner, the frame loop's memory and the last frame's time.
#[derive(Debug)]
pub struct WorldTour {
    pub world: World,
    pub planner: Hierarchy<MeshGroup>,
    /// How the planner was made (its target height is the last frame's, [`tree_scale`]).
    plan: TreePlan,
    frame: MomentFrame,
    /// The last frame's time (plan, captures and render).
    pub last_time: Duration,
    /// The last measured frame's error against all the geometry ([`WorldTour::measure`]),
    pub measured: Option<Measured>,
    /// and the render of all the geometry it was measured against (kept between frames).
    truth: Target,
}

/// A frame's error against a render of all the world's geometry from the same eye.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Measured {
    /// Mean absolute channel difference over the frame, levels (the budget's unit).
    pub mean_abs: f64,
    /// PSNR over the frame, dB (capped at 99).
    pub psnr_db: f64,
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
            height: TREE_HEIGHT,
        };
        let planner = tree_planner(world.objects.clone(), plan);
        WorldTour {
            world,
            planner,
            plan,
            frame: MomentFrame::default(),
            last_time: Duration::ZERO,
            measured: None,
            truth: Target::new(0, 0),
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
    /// frame's counters (the planner's are in [`WorldTour::report`]). A target whose
    /// height scales the world's pixel settings otherwise than the planner's
    /// ([`tree_scale`]: the first frame taller than 360 pixels, a resized window) makes a
    /// new planner for it first, which loads as the first one did.
    pub fn render(
        &mut self,
        renderer: &mut Renderer,
        camera: &Camera,
        target: &mut Target,
    ) -> FrameStats {
        let start = Instant::now();
        if tree_scale(target.height()) != tree_scale(self.plan.height) {
            self.plan.height = target.height();
            self.planner = tree_planner(self.world.objects.clone(), self.plan);
        }
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

    /// Loads the world for `width` x `height` frames before the fly-over, as a game loads
    /// a level: the planner made for that height ([`tree_scale`]) plans its [`LOADING`]
    /// frames (more captures each) from the fly-over's first eye into a scratch target, and
    /// more while its far field is not yet shown (up to [`LOAD_FRAMES`]), so the first
    /// frame shown is an ordinary one (at 1280x720 the first frame, the load, took 205 to
    /// 217 ms). Returns the frames planned.
    pub fn load(&mut self, renderer: &mut Renderer, width: u32, height: u32) -> u32 {
        let mut target = Target::new(width, height);
        let camera = self.camera(0, width, height);
        let mut frames = 0;
        let far_pending = |t: &Self| t.planner.far().is_some_and(|f| f.split().is_none());
        while frames < LOADING || (far_pending(self) && frames < LOAD_FRAMES) {
            self.render(renderer, &camera, &mut target);
            frames += 1;
        }
        frames
    }

    /// The world of [`SIDE`] x [`SIDE`] lots loaded for `width` x `height` frames
    /// ([`WorldTour::load`]).
    pub fn loaded(renderer: &mut Renderer, width: u32, height: u32) -> Self {
        let mut tour = Self::new();
        tour.load(renderer, width, height);
        tour
    }

    /// What the planner's last cut did.
    pub fn report(&self) -> &TreeReport {
        &self.planner.report
    }

    /// Renders all the world's geometry (the ground and every object) from `camera` and
    /// compares `frame`, the planner's render from it, with it: the frame's measured error,
    /// kept for the readout ([`WorldTour::measured`]). Not part of the frame's time.
    pub fn measure(
        &mut self,
        renderer: &mut Renderer,
        camera: &Camera,
        frame: &Target,
    ) -> Measured {
        let (w, h) = (frame.width(), frame.height());
        if (self.truth.width(), self.truth.height()) != (w, h) {
            self.truth = Target::new(w, h);
        }
        let mut all: Vec<Draw<'_>> = Vec::new();
        self.world.ground.draws(&mut all);
        self.world.objects.iter().for_each(|o| o.draws(&mut all));
        let opts = FrameOptions {
            clear: Some(CLEAR),
            ..FrameOptions::default()
        };
        let lighting = &self.world.lighting;
        renderer.render(all, camera, lighting, &mut self.truth, &opts);
        let m = match metrics::compare(frame, &self.truth, &Options::default()) {
            Ok(e) => Measured {
                mean_abs: e.mean_abs,
                psnr_db: e.psnr_capped(99.0),
            },
            // The same size by construction: no other failure.
            Err(_) => Measured::default(),
        };
        self.measured = Some(m);
        m
    }

    /// The readout in three lines (the window's and the headless frames' text): the
    /// world and the cut, the images' predicted and measured error, the times.
    pub fn readout_lines(&self) -> [String; 3] {
        let r = self.report();
        let measured = self.measured.map_or(String::new(), |m| {
            format!(
                "  MEASURED ERROR {:.2} (PSNR {:.1} DB)",
                m.mean_abs, m.psnr_db
            )
        });
        [
            format!(
                "WORLD {} OBJECTS  {} NODES OPENED  {} IMAGES ({} OBJECTS)  {} GEOMETRY  {} REBUILDS  FAR {}",
                self.world.objects.len(),
                r.opened,
                r.images,
                r.imaged_objects,
                r.geometry,
                r.rebuilds,
                r.far_objects,
            ),
            format!(
                "PREDICTED ERROR {:.2} MAX {:.2} (BUDGET {:.0}){measured}",
                r.mean_error, r.max_error, self.planner.config.budget,
            ),
            format!(
                "PLAN {:.2} MS  CAPTURES {:.1} MS (PREDICTED {:.1})  FRAME {:.1} MS",
                r.planning_ms,
                r.capture_ms,
                r.rebuild_ms,
                self.last_time.as_secs_f64() * 1e3
            ),
        ]
    }

    /// One line for the window and the console: [`WorldTour::readout_lines`] joined.
    pub fn readout(&self) -> String {
        self.readout_lines().join("  ")
    }

    /// Draws the readout ([`WorldTour::readout_lines`]) over a `width` x `height` RGBA8
    /// image, top left, one line under another (the window's text drawing).
    pub fn annotate(&self, rgba: &mut [u8], width: u32, height: u32) {
        let (w, h) = (width as usize, height as usize);
        if rgba.len() < w * h * 4 {
            return;
        }
        let mut pixels: Vec<u32> = rgba
            .chunks_exact(4)
            .map(|p| u32::from_be_bytes([0, p[0], p[1], p[2]]))
            .collect();
        for (k, line) in self.readout_lines().iter().enumerate() {
            font::draw_text(&mut pixels, w, h, 4, 4 + 10 * k, 1, line, 0x00ff_ff80);
        }
        for (p, &c) in rgba.chunks_exact_mut(4).zip(&pixels) {
            let [_, r, g, b] = c.to_be_bytes();
            (p[0], p[1], p[2]) = (r, g, b);
        }
    }

    /// How often the last frame drew each object in view of `camera` (the camera it was
    /// rendered from): under an image, as geometry or in the far field. In view is what no enclosing volume rules out: the object's bounding
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
        // The far field's objects, once however many of its tiles show them.
        let mut far = vec![false; objects.len()];
        let captured = self.planner.far().into_iter().flat_map(|f| f.captured());
        captured.for_each(|i| far[i as usize] = true);
        drawn
            .iter_mut()
            .zip(&far)
            .for_each(|(d, &f)| *d += u32::from(f));
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
    use crate::world::TREE_REBUILD_MS;

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

    /// Loaded ahead, the first frame shown takes only an ordinary frame's captures (within
    /// [`crate::world::TREE_REBUILD_MS`] predicted), its far field already shown; without
    /// the load the first frame took the loading frames' captures.
    #[test]
    fn a_loaded_tour_starts_with_an_ordinary_frame() {
        let (w, h) = (160, 96);
        let (mut renderer, mut target) = (Renderer::new(), Target::new(w, h));
        let mut cold = WorldTour::with_side(24);
        cold.render(&mut renderer, &cold.camera(0, w, h), &mut target);
        let first = *cold.report();
        assert!(first.rebuild_ms > TREE_REBUILD_MS, "{first:?}");
        let mut tour = WorldTour::with_side(24);
        let frames = tour.load(&mut renderer, w, h);
        assert!((LOADING..=LOAD_FRAMES).contains(&frames), "{frames}");
        tour.render(&mut renderer, &tour.camera(0, w, h), &mut target);
        let r = *tour.report();
        assert!(r.rebuild_ms <= TREE_REBUILD_MS, "{r:?}");
        assert!(r.far.shown && r.images > 0, "{r:?}");
        let c = tour.coverage(&tour.camera(0, w, h));
        assert_eq!((c.missing, c.twice), (0, 0), "{c:?}");
    }

    /// A frame at `budget` after the loading frames, 160 x 96, and its measured error.
    /// With `full_meshes`, every object drawn as geometry (or captured) at its full mesh.
    fn measured_at(budget: f32, full_meshes: bool) -> (WorldTour, Target, Measured) {
        let mut tour = WorldTour::with_side(16);
        tour.planner.config.budget = budget;
        if full_meshes {
            tour.planner.config.lod_px = 0.0;
            if let Some(far) = tour.planner.config.far.as_mut() {
                far.lod_px = 0.0;
            }
        }
        let (mut renderer, mut target) = (Renderer::new(), Target::new(160, 96));
        for i in 0..=LOADING as usize {
            let camera = tour.camera(i, 160, 96);
            tour.render(&mut renderer, &camera, &mut target);
        }
        let camera = tour.camera(LOADING as usize, 160, 96);
        let m = tour.measure(&mut renderer, &camera, &target);
        (tour, target, m)
    }

    /// At a budget no image meets and with every object at its full mesh (no level of
    /// detail), every object in view is geometry: the frame is the render of all the
    /// geometry, and the measured error nothing. With the levels of detail (statues at
    /// 0.5 px of deviation) the error is the coarser meshes' alone: measured, and tiny. At
    /// the moment's budget, images stand in: an error, small and finite, in the readout.
    #[test]
    fn the_measured_error_is_against_all_the_geometry() {
        let (tour, _, m) = measured_at(0.0, true);
        assert_eq!(tour.report().images, 0, "{:?}", tour.report());
        assert_eq!((m.mean_abs, m.psnr_db), (0.0, 99.0), "{m:?}");
        let (tour, _, m) = measured_at(0.0, false);
        assert!(tour.planner.config.lod_px > 0.0);
        assert_eq!(tour.report().images, 0, "{:?}", tour.report());
        assert!(m.mean_abs < 0.25, "levels of detail alone: {m:?}");
        let (tour, _, m) = measured_at(BUDGET, false);
        assert!(tour.report().images > 0, "{:?}", tour.report());
        assert!(m.mean_abs > 0.0 && m.mean_abs < 10.0, "{m:?}");
        assert_eq!(tour.measured, Some(m));
        let line = tour.readout();
        assert!(
            line.contains(&format!("MEASURED ERROR {:.2}", m.mean_abs)),
            "{line}"
        );
    }

    /// The readout drawn into a frame changes the pixels of its three lines at the top
    /// left, and none below them.
    #[test]
    fn the_readout_is_drawn_into_headless_frames() {
        let (tour, target, _) = measured_at(BUDGET, false);
        let plain = target.to_rgba8();
        let mut annotated = plain.clone();
        tour.annotate(&mut annotated, 160, 96);
        let row = 160 * 4;
        let changed = |rows: std::ops::Range<usize>| {
            rows.flat_map(|y| y * row..(y + 1) * row)
                .filter(|&i| plain[i] != annotated[i])
                .count()
        };
        let rows = READOUT_ROWS as usize;
        assert!(changed(0..rows) > 100, "{}", changed(0..rows));
        assert_eq!(changed(rows..96), 0);
        assert!(
            changed(rows - 4..rows) > 0,
            "the last line is within the rows"
        );
    }
}
