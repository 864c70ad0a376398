//! Choosing each object's representation every frame: the cheapest whose predicted error is
//! within the error budget, rebuilds spent where they lower error or cost most, and the
//! frame kept within a time budget by relaxing error where that costs least.
//!
//! A [`Planner`] owns a scene's objects ([`Subject`]s) and a list of [`Representation`]s
//! (geometry, runtime impostors, image layers, ...), none special-cased. Each frame
//! ([`Planner::plan`]):
//! 1. *Cull*: objects whose bounding sphere is off the view are not drawn; what their
//!    representations hold for them is released after [`Config::release_after`] frames
//!    unused.
//! 2. *Choose as things are*: every representation predicts each visible object's error
//!    and draw cost ([`Estimate`], without rendering); between the frames that ask them
//!    all ([`Config::reask`]), only those on the object's front then and the one in use.
//!    The object takes the cheapest within the error budget. Hysteresis: a
//!    representation the object is not using must be within [`Config::hysteresis`] times
//!    the budget, and cheaper by [`Config::min_saving`], to take over; the one in use
//!    keeps it up to the budget. If none is within the budget, the least error is taken
//!    (and reported).
//! 3. *Rebuild*: candidates are ranked in three tiers: objects over the error budget (by
//!    the error a rebuild removes, times their pixels), images in use that have aged past
//!    the hysteresis band (so they stay in use), then objects a rebuilt image would make
//!    cheaper (by the time saved, net of the rebuild spread over
//!    [`Config::payback_frames`], or the representation's own
//!    [`Representation::payback_frames`], but never more frames than the object is
//!    expected to stay in view: [`Config::horizon`]); under a budget of rebuild
//!    milliseconds, by that worth per predicted millisecond of the rebuild, so that one
//!    long bake does not crowd out many short rebuilds). They are taken within the rebuild budget (a count,
//!    and optionally predicted milliseconds and the bytes every representation may hold), at
//!    most one per object (the best that fits: an object whose octahedral bake would pass
//!    the memory budget may take an impostor instead), and each representation rebuilds
//!    its share in one call (side by side).
//! 4. *Fit the time budget*: while the frame's predicted time is over
//!    [`Budgets::time_ms`], objects move to a cheaper representation, least added error
//!    (times pixels) per millisecond saved first. Objects drawn over the error budget are
//!    reported with the reason ([`Over`]).
//!
//! Predictions run side by side over chunks of objects and are gathered in object order;
//! choosing is sequential and ordered by object index (rebuilds are the representations'
//! own, deterministic), so the same frames make the same choices at any thread count.
//!
//! A debug view ([`Planner::set_tints`]) colours each object by the representation that
//! draws it, the `r`-th in the planner's order taking the `r`-th colour of [`TINTS`]
//! (white, green, blue, magenta, yellow, cyan; then again from white).
//!
//! # Example
//!
//! One object (a sphere of a few thousand triangles), drawn either as its geometry or as
//! a runtime impostor, under an error budget of 2 levels per object; one planning step
//! chooses a representation whose predicted error is within the budget.
//!
//! ```
//! use engine::procedural::uv_sphere;
//! use engine::{Camera, Lighting, Material, Rgba};
//! use glam::{Mat4, Vec3};
//! use ibr::impostor::{self, ImpostorSet};
//! use ibr::plan::{Budgets, Config, Geometry, Planner, Representation};
//! use ibr::subject::MeshGroup;
//! use ibr::technique::FrameView;
//! use std::sync::Arc;
//!
//! let ball = MeshGroup::new().with(
//!     Arc::new(uv_sphere(1.0, 32, 64)),
//!     Arc::new(Material::lit(Rgba::WHITE)),
//!     Mat4::IDENTITY,
//! );
//! let budgets = Budgets { error: 2.0, ..Budgets::default() };
//! let config = Config { budgets, ..Config::default() };
//! let reps: Vec<Box<dyn Representation<MeshGroup>>> = vec![
//!     Box::new(Geometry),
//!     Box::new(ImpostorSet::new(impostor::Config::default(), 1)),
//! ];
//! let mut planner = Planner::new(config, vec![ball], reps);
//!
//! let camera = Camera::look_at(Vec3::new(0.0, 2.0, 40.0), Vec3::ZERO, Vec3::Y, 0.8, 16.0 / 9.0);
//! let lighting = Lighting::default();
//! let report = planner.plan(&FrameView::still(&camera, 320, 180, &lighting)).clone();
//!
//! let choice = planner.choices()[0];
//! let rep = choice.rep.expect("in view, so drawn");
//! assert!(["geometry", "impostors"].contains(&planner.names()[rep]));
//! assert!(choice.error <= budgets.error);
//! assert!(report.max_error <= budgets.error);
//! assert_eq!(report.over_budget, 0);
//!
//! let mut draws = Vec::new();
//! planner.draws(&mut draws);
//! assert!(!draws.is_empty());
//! ```

mod ask;
mod choose;
mod frame_budget;
pub mod occlusion;
mod settings;
mod technique;
pub mod tree;

use crate::core::Priced;
pub use crate::core::{image_bytes, CostModel, Estimate, Geometry, Representation, Sight, Work};
use ask::{estimates, Ask, Asked, Seen, CHUNK};
pub use frame_budget::Z99;
pub use settings::*;

use crate::core::FrameView;
use crate::core::Rect;
use crate::core::Subject;
use crate::core::{Frustum, RectProjector};
use crate::metrics::RectUnion;
use engine::{Camera, Draw, FrameStats, Material, Sphere, Target};
use occlusion::Occlusion;
use rayon::prelude::*;
use std::sync::{Mutex, PoisonError};

/// A rebuild a frame could do.
#[derive(Clone, Copy, Debug)]
struct Rebuild {
    tier: u8,
    key: f32,
    object: usize,
    rep: usize,
}

/// Objects and the representations the planner chooses among each frame.
pub struct Planner<S> {
    /// Settings; may be changed between frames.
    pub config: Config,
    /// The objects planned for, indexed as the representations' and [`Planner::choices`].
    pub objects: Vec<S>,
    reps: Vec<Box<dyn Representation<S>>>,
    choices: Vec<Choice>,
    /// Frames since each representation last drew or rebuilt each object (object-major).
    idle: Vec<u32>,
    /// Per object, its front when every representation was last asked, and frames planned.
    asked: Vec<Asked>,
    frame: u32,
    /// The cost model and payback frames the fronts were found with (another forgets them).
    fronts_by: (CostModel, Vec<f32>),
    /// This frame's visible objects, in order, and scratch.
    visible: Vec<usize>,
    pixels: Vec<f32>,
    /// Per visible object, the frames a rebuild of it may pay back over at most
    /// ([`Config::horizon`]).
    horizons: Vec<f32>,
    /// Per object, the frames it has been in view without a break before this one.
    in_view: Vec<u32>,
    /// Visible objects' screen rectangles, their weights in the frame's error (their
    /// areas, at least 1, times the share of them that shows) and the pixels the
    /// rectangles cover.
    rects: Vec<Rect>,
    /// Each representation's payback frames ([`Representation::payback_frames`]).
    payback: Vec<f32>,
    /// Per object, what step 3 did with its rebuilds this frame.
    state: Vec<u8>,
    /// The frame budget's last multipliers, where the next frame's bisections start.
    warm: [f64; 2],
    /// Each chunk of objects' predictions (reused frame to frame).
    seen: Vec<Seen>,
    weights: Vec<f32>,
    /// The pixels the visible objects' rectangles cover (each once); `area` is it as a
    /// float, at least 1.
    covered: u64,
    area: f64,
    cover: RectUnion,
    /// Per representation, its least time to draw anything this frame (scratch).
    least: Vec<f32>,
    /// What the last finished frame hid ([`occlusion`]): taken in `observe`, behind `&self`.
    occlusion: Mutex<Occlusion>,
    /// Each object's bounds in the last frame planned, where it was visible.
    then: Vec<Option<Sphere>>,
    /// Where each visible object's estimates are: its chunk in `seen`, and the first of
    /// them there (one per representation). Left where the chunks put them: a world's
    /// estimates are megabytes a frame.
    at: Vec<(u32, u32)>,
    rebuilds: Vec<Rebuild>,
    /// The frame scope's options and each object's pick (reused frame to frame).
    options: frame_budget::Options,
    picks: Vec<Option<frame_budget::Pick>>,
    batch: Vec<usize>,
    /// What the last [`Planner::plan`] did.
    pub report: Report,
    eye: glam::Vec3,
    /// Each object's representation of the frame before (reused).
    previous: Vec<Option<usize>>,
    /// Bytes each representation holds, taken again only after it rebuilt or released
    /// (scanning every object's slot is a cost in a world of thousands), and which released
    /// this frame.
    held: Vec<usize>,
    touched: Vec<bool>,
    /// The debug view: on, and the flat unlit material of each representation's colour
    /// that replaces the subject's own in the draws of those that draw the subject.
    tinted: bool,
    flat: Vec<Material>,
}

impl<S> std::fmt::Debug for Planner<S> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let names: Vec<&str> = self.reps.iter().map(|r| r.name()).collect();
        f.debug_struct("Planner")
            .field("config", &self.config)
            .field("objects", &self.objects.len())
            .field("representations", &names)
            .field("report", &self.report)
            .finish()
    }
}

impl<S: Subject + Send + Sync> Planner<S> {
    /// A planner over `objects`, choosing among `reps` (each sized for these objects).
    pub fn new(config: Config, objects: Vec<S>, reps: Vec<Box<dyn Representation<S>>>) -> Self {
        let n = objects.len();
        let r = reps.len();
        let held = reps.iter().map(|r| r.memory()).collect();
        Planner {
            config,
            objects,
            reps,
            choices: vec![Choice::default(); n],
            idle: vec![0; n * r],
            asked: vec![Asked::default(); n],
            frame: 0,
            fronts_by: (CostModel::default(), Vec::new()),
            visible: Vec::new(),
            pixels: Vec::new(),
            horizons: Vec::new(),
            in_view: vec![0; n],
            rects: Vec::new(),
            payback: Vec::new(),
            state: Vec::new(),
            warm: [0.0; 2],
            seen: Vec::new(),
            weights: Vec::new(),
            covered: 0,
            area: 0.0,
            cover: RectUnion::default(),
            least: Vec::new(),
            occlusion: Mutex::default(),
            then: Vec::new(),
            at: Vec::new(),
            rebuilds: Vec::new(),
            options: frame_budget::Options::default(),
            picks: Vec::new(),
            batch: Vec::new(),
            report: Report::default(),
            eye: glam::Vec3::ZERO,
            previous: Vec::with_capacity(n),
            held,
            touched: vec![false; r],
            tinted: false,
            flat: (0..r)
                .map(|k| Material {
                    name: "plan tint".into(),
                    vertex_colors: false,
                    ..Material::unlit(tint(k).1)
                })
                .collect(),
        }
    }

    /// The debug view (see the module docs): with `on`, every image-based representation
    /// multiplies its images by its colour ([`Representation::set_tint`]) and the draws of
    /// those that draw the subject itself (geometry) take a flat unlit material of theirs,
    /// mesh and transform kept; off, the frame is drawn as before.
    pub fn set_tints(&mut self, on: bool) {
        self.tinted = on;
        for (k, rep) in self.reps.iter_mut().enumerate() {
            rep.set_tint(on.then(|| tint(k).1));
        }
    }

    /// Whether the debug view is on.
    pub fn tints(&self) -> bool {
        self.tinted
    }

    /// The representations' names, in order.
    pub fn names(&self) -> Vec<&str> {
        self.reps.iter().map(|r| r.name()).collect()
    }

    /// The `r`-th representation, in the planner's order; `None` past the last.
    pub fn representation(&self, r: usize) -> Option<&dyn Representation<S>> {
        self.reps.get(r).map(|b| b.as_ref())
    }

    /// Every object's choice of the last frame.
    pub fn choices(&self) -> &[Choice] {
        &self.choices
    }

    /// The last frame's visible objects and their weights in the frame's error (their
    /// rectangles' pixels times the share of them that shows, [`occlusion`]).
    pub fn weights(&self) -> (&[usize], &[f32]) {
        (&self.visible, &self.weights)
    }

    /// Chooses every object's representation for `view`, rebuilds within the budget, and
    /// prepares the objects for drawing (see the module docs). Returns the report.
    pub fn plan(&mut self, view: &FrameView<'_>) -> &Report {
        let start = std::time::Instant::now();
        let camera = view.camera;
        let eye = camera.eye();
        self.eye = eye;
        let frustum = Frustum::new(camera.clip_from_world());
        let mut previous = std::mem::take(&mut self.previous);
        previous.clear();
        previous.extend(self.choices.iter().map(|c| c.rep));
        self.visible.clear();
        self.payback.clear();
        let own = self.reps.iter().map(|r| r.payback_frames());
        self.payback
            .extend(own.map(|p| p.unwrap_or(self.config.payback_frames)));
        self.pixels.clear();
        self.horizons.clear();
        self.rects.clear();
        self.at.clear();
        for idle in &mut self.idle {
            *idle = idle.saturating_add(1);
        }
        // Culled objects keep the default choice; visible ones are chosen below.
        self.choices.fill(Choice::default());
        // Predictions side by side over chunks of objects, gathered in object order (so the
        // same at any thread count).
        let chunks = self.objects.len().div_ceil(CHUNK);
        if self.seen.len() < chunks {
            self.seen.resize_with(chunks, Seen::default);
        }
        let reps = &self.reps;
        let cost = &self.config.cost;
        let base = Sight::new(
            camera,
            view.width,
            view.height,
            Sphere {
                center: eye,
                radius: 0.0,
            },
        );
        let before = &previous;
        let project = RectProjector::new(camera, view.width, view.height);
        self.asked.resize(self.objects.len(), Asked::default());
        self.in_view.resize(self.objects.len(), 0);
        if self.fronts_by.0 != self.config.cost || self.fronts_by.1 != self.payback {
            self.asked.fill(Asked::default());
            self.fronts_by.0 = self.config.cost;
            self.fronts_by.1.clone_from(&self.payback);
        }
        let (frame, reask, payback) = (self.frame, self.config.reask, &self.payback);
        let floor = self.config.horizon;
        // Each representation's least time to draw anything (infinite: no bound known).
        let mut least = std::mem::take(&mut self.least);
        least.clear();
        least.extend(reps.iter().map(|r| match r.least_draw() {
            w if w == Work::default() => f32::INFINITY,
            w => cost.ms(w),
        }));
        let least_ms = &least;
        let ask = Ask {
            reps,
            cost,
            base,
            before,
            project: &project,
            frustum: &frustum,
            least_ms,
            payback,
            eye,
            frame,
            reask,
            floor,
        };
        let work = self.objects.par_chunks(CHUNK).zip(self.seen.par_iter_mut());
        let work = work.zip(self.asked.par_chunks_mut(CHUNK));
        let work = work.zip(self.in_view.par_chunks_mut(CHUNK));
        work.enumerate()
            .for_each(|(c, (((chunk, seen), asked), in_view))| {
                ask.chunk(c, chunk, seen, asked, in_view);
            });
        self.least = least;
        self.frame = self.frame.wrapping_add(1);
        self.report.estimates = self.seen[..chunks].iter().map(|s| s.asked).sum();
        let nr = self.reps.len();
        for (c, seen) in self.seen[..chunks].iter().enumerate() {
            for (k, &(i, pixels, rect, _, horizon)) in seen.objects.iter().enumerate() {
                self.visible.push(i);
                self.pixels.push(pixels);
                self.horizons.push(horizon);
                self.rects.push(rect);
                self.at.push((c as u32, (k * nr) as u32));
            }
        }
        self.weigh(camera, view.width, view.height);
        self.choose_as_is(&previous);
        let chosen = start.elapsed();
        self.rebuild(view);
        let rebuilt = std::time::Instant::now();
        self.fit_time();
        self.finish(view, &previous);
        self.previous = previous;
        self.report.planning_ms = (chosen + rebuilt.elapsed()).as_secs_f32() * 1e3;
        &self.report
    }

    /// Appends every visible object's draws, by its chosen representation (in the debug
    /// view, the subject's own draws with its representation's flat material).
    pub fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        for (i, c) in self.choices.iter().enumerate() {
            if let Some(r) = c.rep {
                let first = out.len();
                self.reps[r].draw(i, &self.objects[i], self.eye, out);
                if self.tinted && self.reps[r].draws_subject() {
                    for d in &mut out[first..] {
                        d.material = &self.flat[r];
                    }
                }
            }
        }
    }

    /// Runs every representation's image passes over the frame rendered from
    /// [`Planner::draws`] (in the planner's order); returns their work.
    pub fn passes(&self, view: &FrameView<'_>, target: &mut Target) -> FrameStats {
        let mut stats = FrameStats::default();
        for rep in &self.reps {
            stats += rep.passes(view, target);
        }
        stats
    }
}

#[cfg(test)]
mod budget_tests;
#[cfg(test)]
mod by_technique;
#[cfg(test)]
mod catalog_tests;
#[cfg(test)]
mod occlusion_tests;
#[cfg(test)]
mod ranking_tests;
#[cfg(test)]
pub(crate) mod tests;
