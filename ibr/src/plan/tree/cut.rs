//! The per-node planner: each frame a cut through the hierarchy, chosen top down (breadth
//! first, so the large far clusters are served before the small near ones).
//!
//! A node off the view is skipped whole. A node in view is drawn as one image (of the
//! image representations given, the cheapest whose predicted error, as it is or rebuilt
//! this frame within the rebuild budget, is within [`TreeConfig::budget`]); else its
//! children are considered (also when the node's image would have to be rebuilt but both
//! children's images are within the budget as they are: drawing those costs no rebuild);
//! a leaf that no image will do for draws its objects' geometry (each in view). When the rebuild budget is spent, a node whose image errs within
//! [`TreeConfig::stale`] times the budget is drawn stale (counted in
//! [`TreeReport::over`]) rather than opened. Planning asks estimates only of the nodes it
//! visits: its cost follows the nodes opened, not the objects in the world.

use super::bvh::{Node, Tree};
use super::cluster::Cluster;
use super::far::{FarConfig, FarField, FarReport, Side, Split};
use crate::core::{CostModel, FrameView, Frustum, Representation, Sight, Subject, Work};
use engine::{Draw, FrameStats, Target};
use glam::Vec3;
use std::collections::VecDeque;
use std::sync::Arc;

mod compose;
use compose::Choice;

/// Settings of a [`Hierarchy`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TreeConfig {
    /// Largest predicted error of a node drawn as an image, levels (the impostors' unit).
    pub budget: f32,
    /// Objects per leaf, at most.
    pub leaf: usize,
    /// Rebuilds per frame,
    pub rebuilds: usize,
    /// and their predicted milliseconds (a node whose image alone costs more is never
    /// imaged: its children are).
    pub rebuild_ms: f32,
    /// While loading, the first `.0` frames planned, `.1` predicted milliseconds of
    /// rebuilds instead (a game loading a level takes its images then).
    pub loading: (u32, f32),
    /// A node whose image errs within this many times the budget is drawn stale, once the
    /// rebuild budget is spent, rather than opened.
    pub stale: f32,
    /// A rebuild is taken only if it costs no more than this many frames of drawing the
    /// node's objects as geometry.
    pub payback: f32,
    /// Frames an unused image is kept before it is released.
    pub release_after: u32,
    /// Predicted milliseconds of work.
    pub cost: CostModel,
    /// Measured milliseconds one capture costs besides what [`TreeConfig::cost`] prices
    /// (the capture's renderer, target and texture set up for a small image: about half a
    /// millisecond in the world against the model's tenth), charged against
    /// [`TreeConfig::rebuild_ms`] for each node image rebuilt and each far-field tile
    /// captured (with the tiles' triangles): the budget then holds the frame's captures,
    /// node images and far field together, after loading. 0: as the cost model alone.
    pub capture_ms: f32,
    /// The far field: everything beyond a distance as one image mesh with depth, the cut
    /// stopping at its boundary (`None`: the cut covers the whole world).
    pub far: Option<FarConfig>,
    /// Objects drawn as geometry take their coarsest level of detail whose geometric
    /// deviation projects within this many pixels ([`Subject::draws_seen`]; 0: always full).
    pub lod_px: f32,
    /// A node image's captures draw each object at its coarsest level of detail deviating
    /// within `.0` texels of an image `.1` texels across the node (its largest image side):
    /// (0, 0) draws the full meshes ([`Cluster::with_capture_lod`]).
    pub capture_lod: (f32, u32),
    /// A node's image is composed of its children's images (Shade et al. 96's hierarchical
    /// image cache) when a child holds one erring within this fraction of the budget: its
    /// capture draws those images' quads, and the other child's objects, instead of all its
    /// objects, so it costs texels, not objects. The composed image is one resampling
    /// further from the geometry: it inherits the largest error of the images it drew,
    /// added to its own prediction from then on. 0: never composed.
    pub compose: f32,
}

impl Default for TreeConfig {
    fn default() -> Self {
        TreeConfig {
            budget: 2.0,
            leaf: 4,
            rebuilds: 16,
            rebuild_ms: 6.0,
            loading: (0, 0.0),
            stale: 2.0,
            payback: 4.0,
            release_after: 60,
            cost: CostModel::default(),
            capture_ms: 0.0,
            far: None,
            lod_px: 0.5,
            capture_lod: (0.0, 0),
            compose: 0.0,
        }
    }
}

/// What the last frame's cut did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TreeReport {
    /// Nodes visited,
    pub visited: usize,
    /// skipped off the view,
    pub culled: usize,
    /// and opened (their children considered).
    pub opened: usize,
    /// Estimates asked.
    pub estimates: usize,
    /// Nodes drawn as one image each,
    pub images: usize,
    /// and objects drawn as their geometry.
    pub geometry: usize,
    /// Objects the images stand for.
    pub imaged_objects: usize,
    /// Images rebuilt,
    pub rebuilds: usize,
    /// and their predicted milliseconds (with [`TreeConfig::capture_ms`] each),
    pub rebuild_ms: f32,
    /// and measured ones (the captures' wall time: reported only, never planned with, so
    /// the cut does not depend on the machine's load),
    pub capture_ms: f32,
    /// and the triangles their captures drew (at [`TreeConfig::capture_lod`]),
    pub captured_triangles: usize,
    /// in this many draws.
    pub captured_draws: usize,
    /// Images drawn over the budget (stale, the rebuild budget spent).
    pub over: usize,
    /// Predicted error of the images, weighted by their pixels,
    pub mean_error: f32,
    /// and the largest.
    pub max_error: f32,
    /// Bytes the representations hold.
    pub memory: usize,
    /// The planner's own time this frame (the cut, without rebuilds), milliseconds.
    pub planning_ms: f32,
    /// Nodes refitted by the last [`Hierarchy::update`].
    pub refitted: usize,
    /// Objects in nodes in view left to the shown far field,
    pub far_objects: usize,
    /// the far field's captures this frame,
    pub far: FarReport,
    /// their measured milliseconds (part of [`TreeReport::capture_ms`]),
    pub far_ms: f32,
    /// and the triangles of its meshes in view.
    pub far_triangles: usize,
    /// Triangles of the objects drawn as geometry, at the levels of detail drawn.
    pub geometry_triangles: usize,
    /// Rebuilds composed of their children's images ([`TreeConfig::compose`]; part of
    /// [`TreeReport::rebuilds`]),
    pub composed: usize,
    /// and the texels of the images they drew.
    pub composed_texels: u64,
}

/// A hierarchy over objects and the image representations its nodes may take.
pub struct Hierarchy<S> {
    /// Settings; may be changed between frames.
    pub config: TreeConfig,
    tree: Tree,
    objects: Arc<Vec<S>>,
    clusters: Vec<Cluster<S>>,
    reps: Vec<Box<dyn Representation<Cluster<S>>>>,
    /// This frame's images (node, representation, predicted error) and geometry objects.
    images: Vec<(u32, u8, f32)>,
    geometry: Vec<u32>,
    /// Per representation, the nodes to rebuild and those drawn (scratch).
    batch: Vec<Vec<usize>>,
    queue: VecDeque<u32>,
    /// Per node, the frame it was last drawn as an image; the images held.
    used: Vec<u32>,
    held: Vec<(u32, u8)>,
    /// Per node, the error its image inherited from the images it was composed of; the
    /// frame's composed rebuilds (node, representation, which children are images).
    inherited: Vec<f32>,
    composing: Vec<(u32, u8, [bool; 2])>,
    frame: u32,
    eye: Vec3,
    /// The frame's pixels per radian (for the geometry's levels of detail).
    px_per_radian: f32,
    /// The far field, when [`TreeConfig::far`] is set, and the frame's frustum.
    far: Option<FarField>,
    frustum: Option<Frustum>,
    /// What the last [`Hierarchy::plan`] did.
    pub report: TreeReport,
}

impl<S> std::fmt::Debug for Hierarchy<S> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Hierarchy")
            .field("config", &self.config)
            .field("objects", &self.objects.len())
            .field("nodes", &self.tree.nodes().len())
            .field("report", &self.report)
            .finish()
    }
}

/// The box of a subject's corners.
fn box_of<S: Subject>(s: &S) -> (Vec3, Vec3) {
    let c = s.corners();
    let lo = c.iter().fold(Vec3::splat(f32::MAX), |a, &p| a.min(p));
    let hi = c.iter().fold(Vec3::splat(f32::MIN), |a, &p| a.max(p));
    (lo, hi)
}

impl<S: Subject + Send + Sync> Hierarchy<S> {
    /// The hierarchy over `objects`; `reps` makes the image representations for a number
    /// of nodes (each node is one of their objects, a [`Cluster`]).
    pub fn new(
        config: TreeConfig,
        objects: Vec<S>,
        reps: impl FnOnce(usize) -> Vec<Box<dyn Representation<Cluster<S>>>>,
    ) -> Self {
        let boxes: Vec<(Vec3, Vec3)> = objects.iter().map(box_of).collect();
        let tree = Tree::build(&boxes, config.leaf);
        let objects = Arc::new(objects);
        let members = Arc::new(tree.order().to_vec());
        let clusters = tree
            .nodes()
            .iter()
            .map(|n| {
                let (first, count) = (n.first, n.count);
                let b = (n.lo, n.hi);
                Cluster::new(objects.clone(), members.clone(), first, count, b, 0)
                    .with_capture_lod(config.capture_lod.0, config.capture_lod.1)
            })
            .collect();
        let n = tree.nodes().len();
        let reps = reps(n);
        Hierarchy {
            config,
            used: vec![0; n],
            inherited: vec![0.0; n],
            composing: Vec::new(),
            batch: vec![Vec::new(); reps.len()],
            tree,
            objects,
            clusters,
            reps,
            images: Vec::new(),
            geometry: Vec::new(),
            queue: VecDeque::new(),
            held: Vec::new(),
            frame: 0,
            eye: Vec3::ZERO,
            px_per_radian: 0.0,
            far: config.far.map(FarField::new),
            frustum: None,
            report: TreeReport::default(),
        }
    }

    /// The hierarchy.
    pub fn tree(&self) -> &Tree {
        &self.tree
    }

    /// The objects.
    pub fn objects(&self) -> &[S] {
        &self.objects
    }

    /// The last frame's images: (node, representation, predicted error).
    pub fn images(&self) -> &[(u32, u8, f32)] {
        &self.images
    }

    /// The far field, when [`TreeConfig::far`] is set.
    pub fn far(&self) -> Option<&FarField> {
        self.far.as_ref()
    }

    /// The last frame's objects drawn as geometry.
    pub fn geometry(&self) -> &[u32] {
        &self.geometry
    }

    /// Changes the objects `moved` by `change` and refits the hierarchy where they are:
    /// only the nodes on their paths to the root change version (so only images of those
    /// are retaken). Returns the nodes refitted ([`TreeReport::refitted`]).
    pub fn update(&mut self, moved: &[usize], mut change: impl FnMut(usize, &mut S)) -> usize {
        let empty = Arc::new(Vec::new());
        for c in &mut self.clusters {
            c.let_go(&empty);
        }
        let mut boxes = Vec::with_capacity(moved.len());
        // The clusters let go, so the objects are held here alone.
        if let Some(objects) = Arc::get_mut(&mut self.objects) {
            for &i in moved {
                if let Some(s) = objects.get_mut(i) {
                    change(i, s);
                    boxes.push((i, box_of(s)));
                }
            }
        }
        let refitted = self.tree.refit(&boxes).len();
        for (c, n) in self.clusters.iter_mut().zip(self.tree.nodes()) {
            c.take(&self.objects, (n.lo, n.hi), n.version);
        }
        self.report.refitted = refitted;
        refitted
    }

    /// Chooses the frame's cut (module docs), rebuilds within the budget and prepares the
    /// images. Returns the report.
    pub fn plan(&mut self, view: &FrameView<'_>) -> &TreeReport {
        let far_ms = self.step_far(view);
        let start = std::time::Instant::now();
        let cfg = self.config;
        let camera = view.camera;
        let eye = camera.eye();
        self.eye = eye;
        let at_eye = engine::Sphere {
            center: eye,
            radius: 0.0,
        };
        let base = Sight::new(camera, view.width, view.height, at_eye);
        self.px_per_radian = base.px_per_radian;
        let (mut report, frustum, split) = self.begin(camera, far_ms);
        let (mut weighted, mut weight) = (0.0f64, 0.0f64);
        let rebuild_ms = self.rebuild_budget(&report.far);
        while let Some(k) = self.queue.pop_front() {
            report.visited += 1;
            let node = self.tree.nodes()[k as usize];
            let sphere = node.sphere();
            if !frustum.sees(sphere.center, sphere.radius) {
                report.culled += 1;
                continue;
            }
            if let Some(split) = &split {
                if self.far_side(&node, split, &mut report) {
                    continue;
                }
            }
            let cluster = &self.clusters[k as usize];
            let sight = base.at(sphere).with_corners(cluster.corners());
            let geometry_ms = cfg.cost.ms(Work {
                triangles: cluster.triangle_count() as u64,
                pixels: sight.pixels as u64,
                ..Default::default()
            });
            let [as_is, fresh, stale] = self.options(
                k as usize,
                &base,
                &sight,
                geometry_ms,
                &mut report.estimates,
            );
            let room = |f: &Choice| {
                let ms = report.rebuild_ms + f.rebuild + cfg.capture_ms;
                report.rebuilds < cfg.rebuilds && ms <= rebuild_ms
            };
            let open_instead = as_is.is_none()
                && fresh.is_some()
                && self.children_will_do(k as usize, &base, &mut report.estimates);
            let take = match (as_is, fresh) {
                (Some(a), _) => Some(a),
                (None, Some(_)) if open_instead => None,
                (None, Some(f)) if room(&f) => {
                    report.rebuilds += 1;
                    report.rebuild_ms += f.rebuild + cfg.capture_ms;
                    self.batch[f.rep].push(k as usize);
                    self.inherited[k as usize] = f.composed.map_or(0.0, |c| c.error);
                    if let Some(c) = f.composed {
                        self.composing.push((k, f.rep as u8, c.images));
                    }
                    Some(f)
                }
                _ => stale.inspect(|_| report.over += 1),
            };
            if let Some(Choice { rep, error, .. }) = take {
                self.images.push((k, rep as u8, error));
                report.imaged_objects += node.count as usize;
                let px = f64::from(sight.pixels.max(1.0));
                weighted += f64::from(error) * px;
                weight += px;
                report.max_error = report.max_error.max(error);
                continue;
            }
            if node.is_leaf() {
                for &i in self.tree.objects_of(k as usize) {
                    let b = self.objects[i as usize].bounds();
                    if frustum.sees(b.center, b.radius) {
                        self.geometry.push(i);
                    }
                }
                continue;
            }
            report.opened += 1;
            // Nearer child first (the order images are drawn in does not matter: depth).
            let [a, b] = node.children;
            let d = |c: u32| self.tree.nodes()[c as usize].sphere().center.distance(eye);
            let (a, b) = if d(b) < d(a) { (b, a) } else { (a, b) };
            self.queue.push_back(a);
            self.queue.push_back(b);
        }
        report.images = self.images.len();
        report.geometry = self.geometry.len();
        report.geometry_triangles = self.geometry_triangles();
        report.mean_error = if weight > 0.0 {
            (weighted / weight) as f32
        } else {
            0.0
        };
        let planned = start.elapsed();
        let captures = std::time::Instant::now();
        self.rebuild_and_prepare(view, &mut report);
        report.capture_ms = captures.elapsed().as_secs_f32() * 1e3 + far_ms;
        report.planning_ms = planned.as_secs_f32() * 1e3;
        self.report = report;
        &self.report
    }

    /// The frame's predicted milliseconds for node images' rebuilds: the loading
    /// allowance during the loading frames, else [`TreeConfig::rebuild_ms`] less what the
    /// shown far field's re-capture `far` took this frame (its triangles and
    /// [`TreeConfig::capture_ms`] a tile; its first field is a level's load, as the
    /// loading frames are, and is not charged).
    fn rebuild_budget(&self, far: &FarReport) -> f32 {
        let cfg = &self.config;
        if self.frame <= cfg.loading.0 {
            return cfg.loading.1.max(cfg.rebuild_ms);
        }
        let far_ms = if far.shown && far.tiles > 0 {
            far.triangles as f32 * cfg.cost.ns_per_triangle * 1e-6
                + far.tiles as f32 * cfg.capture_ms
        } else {
            0.0
        };
        cfg.rebuild_ms - far_ms.min(cfg.rebuild_ms)
    }

    /// Starts a frame's cut seen by `camera`: the report (with the far field's), the
    /// view's frustum, the far field's split, the scratch cleared and the root queued.
    fn begin(
        &mut self,
        camera: &engine::Camera,
        far_ms: f32,
    ) -> (TreeReport, Frustum, Option<Split>) {
        self.frame = self.frame.wrapping_add(1);
        let frustum = Frustum::new(camera.clip_from_world());
        let mut report = TreeReport {
            refitted: self.report.refitted,
            far_ms,
            ..TreeReport::default()
        };
        self.frustum = Some(frustum);
        let split = self.far.as_ref().and_then(FarField::split);
        if let Some(far) = &self.far {
            report.far = far.report;
            report.far_triangles = far.triangles_seen(&frustum);
        }
        self.images.clear();
        self.geometry.clear();
        self.batch.iter_mut().for_each(Vec::clear);
        self.queue.clear();
        if !self.tree.nodes().is_empty() {
            self.queue.push_back(0);
        }
        (report, frustum, split)
    }

    /// Steps the far field's captures for the frame (within its triangle budget, the
    /// loading one during the loading frames and until a first field is shown); returns
    /// their wall time, milliseconds.
    fn step_far(&mut self, view: &FrameView<'_>) -> f32 {
        let Some(cfg) = self.config.far else {
            self.far = None;
            return 0.0;
        };
        let start = std::time::Instant::now();
        let far = self.far.get_or_insert_with(|| FarField::new(cfg));
        // The first field is a level's load: at the loading budget until it is shown.
        let loading = self.frame.wrapping_add(1) <= self.config.loading.0 || far.split().is_none();
        far.config = cfg;
        let budget = if loading {
            cfg.loading_triangles.max(cfg.triangles)
        } else {
            cfg.triangles
        };
        let size = (view.width, view.height);
        let world = (&self.tree, &self.objects[..]);
        far.step(view.camera, size, view.lighting, world, budget);
        start.elapsed().as_secs_f32() * 1e3
    }

    /// The cut at `node` against the far field's `split`: a node wholly the field's is
    /// left to it (true: done), one with none of its objects is the cut's (false), one
    /// across is opened (true), but a leaf across is the cut's whole (false: drawn as one
    /// image, or its objects as geometry, as any node of the cut).
    fn far_side(&mut self, node: &Node, split: &Split, report: &mut TreeReport) -> bool {
        match split.side(node.lo, node.hi) {
            Side::Near => return false,
            Side::Far => {
                report.far_objects += node.count as usize;
                return true;
            }
            Side::Across => {}
        }
        if node.is_leaf() {
            return false;
        }
        report.opened += 1;
        self.queue.extend(node.children);
        true
    }

    /// Rebuilds the batches (their wall time is [`TreeReport::capture_ms`]), releases images
    /// long unused, prepares every representation
    /// with the nodes it draws.
    fn rebuild_and_prepare(&mut self, view: &FrameView<'_>, report: &mut TreeReport) {
        self.compose_batch(view.camera.eye(), report);
        for (r, rep) in self.reps.iter_mut().enumerate() {
            let batch = &mut self.batch[r];
            if batch.is_empty() {
                continue;
            }
            batch.sort_unstable();
            let mut scratch = Vec::new();
            for &k in batch.iter() {
                report.captured_triangles += self.clusters[k].captured_triangles(&mut scratch);
                report.captured_draws += scratch.len();
            }
            rep.rebuild(batch, &mut self.clusters, view);
            for &k in batch.iter() {
                self.clusters[k].uncompose();
                if !self.held.contains(&(k as u32, r as u8)) {
                    self.held.push((k as u32, r as u8));
                }
            }
        }
        for &(k, _, _) in &self.images {
            self.used[k as usize] = self.frame;
        }
        let (frame, after) = (self.frame, self.config.release_after);
        let (used, reps) = (&self.used, &mut self.reps);
        self.held.retain(|&(k, r)| {
            let keep = frame.wrapping_sub(used[k as usize]) <= after;
            if !keep {
                reps[r as usize].release(k as usize);
            }
            keep
        });
        for (r, rep) in self.reps.iter_mut().enumerate() {
            let batch = &mut self.batch[r];
            batch.clear();
            let mine = self.images.iter().filter(|x| usize::from(x.1) == r);
            batch.extend(mine.map(|x| x.0 as usize));
            batch.sort_unstable();
            rep.prepare(batch, &self.clusters, view);
        }
        report.memory = self.reps.iter().map(|r| r.memory()).sum();
        report.memory += self.far.as_ref().map_or(0, FarField::memory);
    }

    /// The frame's draws: each image node's image, each geometry object's triangles, the
    /// far field's meshes in view.
    pub fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        if let (Some(far), Some(frustum)) = (&self.far, &self.frustum) {
            far.draws(frustum, out);
        }
        for &(k, r, _) in &self.images {
            let k = k as usize;
            self.reps[usize::from(r)].draw(k, &self.clusters[k], self.eye, out);
        }
        let (eye, ppr, tolerance) = (self.eye, self.px_per_radian, self.config.lod_px);
        for &i in &self.geometry {
            self.objects[i as usize].draws_seen(eye, ppr, tolerance, out);
        }
    }

    /// Triangles of this frame's geometry objects at the levels of detail drawn.
    fn geometry_triangles(&self) -> usize {
        let (eye, ppr, tolerance) = (self.eye, self.px_per_radian, self.config.lod_px);
        let mut draws = Vec::new();
        for &i in &self.geometry {
            self.objects[i as usize].draws_seen(eye, ppr, tolerance, &mut draws);
        }
        draws.iter().map(|d| d.mesh.triangle_count()).sum()
    }

    /// Every representation's image passes over the rendered frame.
    pub fn passes(&self, view: &FrameView<'_>, target: &mut Target) -> FrameStats {
        let mut stats = FrameStats::default();
        for rep in &self.reps {
            stats += rep.passes(view, target);
        }
        stats
    }
}
