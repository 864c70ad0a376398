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

mod frame_budget;
pub mod occlusion;
mod technique;

use crate::core::Priced;
pub use crate::core::{image_bytes, CostModel, Estimate, Geometry, Representation, Sight, Work};
pub use frame_budget::Z99;

use crate::core::FrameView;
use crate::core::Rect;
use crate::core::Subject;
use crate::core::{Frustum, RectProjector};
use crate::metrics::RectUnion;
use engine::{Camera, Draw, FrameStats, Material, Rgba, Sphere, Target};
use occlusion::Occlusion;
use rayon::prelude::*;
use std::sync::{Mutex, PoisonError};

/// The debug view's colours ([`Planner::set_tints`]), by representation in the planner's
/// order (cycling past the eighth), with their names for a legend: geometry first in the
/// usual order, so white; images tinted green, blue, ...
pub const TINTS: [(&str, Rgba); 8] = [
    ("white", Rgba::new(1.0, 1.0, 1.0, 1.0)),
    ("green", Rgba::new(0.3, 1.0, 0.3, 1.0)),
    ("blue", Rgba::new(0.35, 0.55, 1.0, 1.0)),
    ("magenta", Rgba::new(1.0, 0.35, 1.0, 1.0)),
    ("yellow", Rgba::new(1.0, 1.0, 0.3, 1.0)),
    ("cyan", Rgba::new(0.3, 1.0, 1.0, 1.0)),
    ("orange", Rgba::new(1.0, 0.6, 0.2, 1.0)),
    ("violet", Rgba::new(0.6, 0.35, 1.0, 1.0)),
];

/// The debug colour of the `r`-th representation, and its name ([`TINTS`]).
pub fn tint(r: usize) -> (&'static str, Rgba) {
    TINTS[r % TINTS.len()]
}

/// What a frame may spend.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budgets {
    /// Largest predicted error, in the impostors' unit: mean absolute 8-bit error over the
    /// object's screen rectangle ([`Estimate`]), per object or over the frame ([`Scope`]).
    /// 0: geometry only.
    pub error: f32,
    /// What the error budget bounds.
    pub scope: Scope,
    /// Predicted frame time, milliseconds (`None`: no limit).
    pub time_ms: Option<f32>,
    /// Rebuilds per frame.
    pub rebuilds: usize,
    /// Predicted milliseconds of rebuilds per frame (`None`: no limit; the first
    /// candidate is always allowed).
    pub rebuild_ms: Option<f32>,
    /// Bytes every representation may hold together (`None`: no limit): a rebuild that
    /// would pass it waits (its object may take another representation's instead) until
    /// unused data is released ([`Config::release_after`]).
    pub memory: Option<usize>,
}

impl Default for Budgets {
    fn default() -> Self {
        Budgets {
            error: 2.0,
            scope: Scope::Object,
            time_ms: None,
            rebuilds: 8,
            rebuild_ms: None,
            memory: None,
        }
    }
}

/// What the error budget bounds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Scope {
    /// Every object's predicted error.
    #[default]
    Object,
    /// The frame's error (the mean error over the pixels the visible objects' rectangles
    /// cover, each object's error weighted by its rectangle's area times the share of it that
    /// shows: `frame_budget`, [`occlusion`]), with a margin for its spread so that it
    /// holds on 99% of frames ([`Report::bound`], `frame_budget`). Objects
    /// may then err more where that buys most time; hysteresis discounts the
    /// representation in use by [`Config::min_saving`] of its time.
    Frame,
}

/// The default [`Config::spread`]: see there. Fitted on `bench budget` (BENCHMARKS.md).
pub const SPREAD: f32 = 0.5;

/// Settings of a [`Planner`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    /// The error, time, rebuild and memory budgets.
    pub budgets: Budgets,
    /// A representation not in use takes over only within this fraction of the error
    /// budget (in use, it keeps up to the whole budget).
    pub hysteresis: f32,
    /// A representation not in use takes over only if it saves this fraction of the
    /// predicted draw time.
    pub min_saving: f32,
    /// A rebuild that only saves time is worth it if the time saved over this many frames
    /// pays for it (a representation may say its own: [`Representation::payback_frames`]),
    /// and within the object's horizon ([`Config::horizon`]).
    pub payback_frames: f32,
    /// Frames an object just come into view is expected to stay. A rebuild's time is
    /// spread over at most its horizon, this plus the frames it has been in view without a
    /// break, whatever its payback: an object long in view is expected to stay about as
    /// long again, and one just come into view may leave before a bake meant to last a
    /// minute pays back. Infinite: every object is expected to stay.
    pub horizon: f32,
    /// Frames an object's data may stay unused before its representation releases it.
    pub release_after: u32,
    /// How far an object's measured error scatters about its prediction, as a fraction of
    /// it: the frame scope keeps a bound that holds on 99% of frames, the mean plus 2.3
    /// times the spread of the objects' weighted errors (`frame_budget`). 0: the mean
    /// alone.
    pub spread: f32,
    /// Every representation is asked for an object's prediction at least once in this
    /// many frames (1: every frame). Between, only those on the object's front when last
    /// all were asked (no other option then both cheaper and more accurate, as it was, or
    /// rebuilt, its rebuild spread over the payback frames) and the one in use are asked,
    /// while the eye stays within [`REASK_MOVE`] of the object's distance of where it was
    /// and the object is unchanged: an option far from the front does not reach it in a
    /// few frames, and predicting eight representations of every object of a world every
    /// frame is most of the planning.
    pub reask: u32,
    /// The cost model that prices draws and rebuilds in predicted milliseconds.
    pub cost: CostModel,
}

/// How far the eye may move, as a fraction of its distance from an object, before every
/// representation is asked for the object's prediction again ([`Config::reask`]).
pub const REASK_MOVE: f32 = 0.05;

impl Default for Config {
    fn default() -> Self {
        Config {
            budgets: Budgets::default(),
            hysteresis: 0.75,
            min_saving: 0.15,
            payback_frames: 30.0,
            horizon: 30.0,
            release_after: 120,
            spread: SPREAD,
            reask: 8,
            cost: CostModel::default(),
        }
    }
}

/// Why an object is drawn with a predicted error over the error budget.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Over {
    /// The time budget moved it to a cheaper representation.
    Time,
    /// A rebuild would have brought it within the budget, but the rebuild budget (its
    /// count, milliseconds or the memory budget) ran out.
    Rebuilds,
    /// No representation could draw it within the budget, even rebuilt.
    Nothing,
}

/// One object's representation this frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Choice {
    /// Index into the planner's representations; `None` when culled.
    pub rep: Option<usize>,
    /// Predicted error, in the unit of [`Budgets::error`].
    pub error: f32,
    /// Predicted draw time, milliseconds.
    pub ms: f32,
    /// Rebuilt this frame.
    pub rebuilt: bool,
    /// Drawn over the error budget, and why.
    pub over: Option<Over>,
}

/// What the last frame's plan did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Report {
    /// Objects drawn by each representation (in the planner's order).
    pub counts: Vec<usize>,
    /// Objects off the view, not drawn.
    pub culled: usize,
    /// Visible objects whose representation changed since the frame before.
    pub switches: usize,
    /// Rebuilds made this frame.
    pub rebuilds: usize,
    /// Rebuilds wanted but left for a later frame.
    pub deferred: usize,
    /// Objects drawn over the error budget.
    pub over_budget: usize,
    /// Of those, objects the time budget moved to a cheaper representation ([`Over::Time`]).
    pub over_time: usize,
    /// Of those, objects whose rebuild the rebuild budget left out ([`Over::Rebuilds`]).
    pub over_rebuilds: usize,
    /// Of those, objects no representation could draw within it ([`Over::Nothing`]).
    pub over_nothing: usize,
    /// Predicted milliseconds of drawing.
    pub draw_ms: f32,
    /// Predicted milliseconds of the frame's rebuilds.
    pub rebuild_ms: f32,
    /// Largest predicted error of a drawn object, in the unit of [`Budgets::error`].
    pub max_error: f32,
    /// The frame's error: the mean over the pixels the visible objects' rectangles cover,
    /// of each object's error over its rectangle times the part of it that shows
    /// (`frame_budget`), in the unit of [`Budgets::error`].
    pub mean_error: f32,
    /// The bound on the frame's mean error that holds on 99% of frames (the mean plus the
    /// spread, [`Config::spread`]): what the frame scope keeps within the budget.
    pub bound: f32,
    /// The spread of the frame's mean error per unit of [`Config::spread`]: the root sum
    /// of the squared weighted errors over the pixels the rectangles cover (`bound =
    /// mean_error + 2.326 * spread * scatter`).
    pub scatter: f32,
    /// Pixels the visible objects' screen rectangles cover (each once): the frame's error
    /// is a mean over these.
    pub covered: u64,
    /// Bytes every representation holds.
    pub memory: usize,
    /// Predictions asked of the representations ([`Config::reask`]): a work counter.
    pub estimates: usize,
    /// Measured milliseconds of planning (predicting, choosing, the report and the
    /// representations' `prepare`; rebuilds left out), for benchmarks: wall-clock time, so
    /// never compared in tests.
    pub planning_ms: f32,
}

impl Report {
    /// Predicted frame time, milliseconds.
    pub fn predicted_ms(&self) -> f32 {
        self.draw_ms + self.rebuild_ms
    }
}

/// Objects per chunk of the predictions run side by side.
const CHUNK: usize = 256;

/// What a chunk of objects' predictions found: the visible objects (index, pixels,
/// rectangle, bounds, horizon: [`Config::horizon`]) and their estimates
/// (representation-major within an object).
#[derive(Default)]
struct Seen {
    objects: Vec<(usize, f32, Rect, Sphere, f32)>,
    estimates: Vec<Option<Priced>>,
    /// Predictions asked.
    asked: usize,
}

/// What the planner keeps of an object's last prediction by every representation
/// ([`Config::reask`]).
#[derive(Clone, Copy, Debug, Default)]
struct Asked {
    /// The representations on the object's front then (bit `r`); 0: none known.
    front: u32,
    /// The eye's offset from the object's centre then, and the object's version.
    offset: glam::Vec3,
    version: u64,
}

impl Asked {
    /// Whether the front still stands for object `i` in frame `frame`, seen from `offset`
    /// (the eye less its centre), at `version`, asking all every `reask` frames.
    fn stands(&self, i: usize, frame: u32, reask: u32, offset: glam::Vec3, version: u64) -> bool {
        let due = (frame as usize)
            .wrapping_add(i)
            .is_multiple_of(reask.max(1) as usize);
        let moved = offset.distance(self.offset) > REASK_MOVE * self.offset.length();
        self.front != 0 && !due && !moved && version == self.version
    }
}

/// The representations a front is kept for ([`Asked::front`]'s bits): any past these is
/// asked every frame.
const FRONT_REPS: usize = 32;

/// The representations (bit `r`) with an option on the front of `est`: none both cheaper
/// and more accurate (as it is, or rebuilt with its rebuild spread over `payback[r]`
/// frames, at most the object's `horizon`).
fn front(est: &[Option<Priced>], payback: &[f32], horizon: f32) -> u32 {
    let mut options = [(0.0f32, 0.0f32, 0usize); 2 * FRONT_REPS];
    let mut n = 0;
    for (r, e) in est.iter().enumerate().take(FRONT_REPS) {
        let Some(e) = e else { continue };
        if e.error.is_finite() {
            options[n] = (e.ms, e.error, r);
            n += 1;
        }
        if e.rebuilds && e.rebuilt.is_finite() {
            let frames = payback.get(r).copied().unwrap_or(1.0).min(horizon);
            options[n] = (e.ms + e.rebuild_ms / frames.max(1.0), e.rebuilt, r);
            n += 1;
        }
    }
    let options = &options[..n];
    let mut mask = 0;
    for &(t, e, r) in options {
        let beaten = options
            .iter()
            .any(|&(u, f, _)| u <= t && f <= e && (u < t || f < e));
        if !beaten {
            mask |= 1 << r;
        }
    }
    mask
}

/// Visible object `v`'s estimates, one per representation of `nr` (found by `at`).
fn estimates<'s>(seen: &'s [Seen], at: &[(u32, u32)], nr: usize, v: usize) -> &'s [Option<Priced>] {
    let (c, k) = at[v];
    &seen[c as usize].estimates[k as usize..k as usize + nr]
}

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
        let work = self.objects.par_chunks(CHUNK).zip(self.seen.par_iter_mut());
        let work = work.zip(self.asked.par_chunks_mut(CHUNK));
        let work = work.zip(self.in_view.par_chunks_mut(CHUNK));
        work.enumerate()
            .for_each(|(c, (((chunk, seen), asked), in_view))| {
                seen.objects.clear();
                seen.estimates.clear();
                seen.asked = 0;
                for (k, s) in chunk.iter().enumerate() {
                    let bounds = s.bounds();
                    if !frustum.sees(bounds.center, bounds.radius) {
                        in_view[k] = 0;
                        continue;
                    }
                    let horizon = floor + in_view[k] as f32;
                    in_view[k] = in_view[k].saturating_add(1);
                    let i = c * CHUNK + k;
                    let (offset, version) = (eye - bounds.center, s.version());
                    let known = asked[k].stands(i, frame, reask, offset, version);
                    let first = seen.estimates.len();
                    // Corners once for every representation (geometry's box, a layer's warp).
                    let sight = base.at(bounds).with_corners(s.corners());
                    let pixels = sight.pixels;
                    let rect = project.rect(bounds.center, bounds.radius);
                    let rect = rect.unwrap_or_default();
                    seen.objects.push((i, pixels, rect, bounds, horizon));
                    // The least time of an exact option so far: a representation that cannot
                    // draw for less is never chosen, so it is not asked (unless in use).
                    let mut exact = f32::INFINITY;
                    for (r, rep) in reps.iter().enumerate() {
                        let dominated =
                            least_ms[r].is_finite() && before[i] != Some(r) && least_ms[r] >= exact;
                        let off_front = known
                            && r < FRONT_REPS
                            && asked[k].front & (1 << r) == 0
                            && before[i] != Some(r);
                        let e = if dominated || off_front {
                            None
                        } else {
                            seen.asked += 1;
                            let e = rep.estimate(i, s, &sight).filter(|e| !e.error.is_nan());
                            e.map(|e| Priced::new(&e, cost))
                        };
                        if let Some(e) = e.filter(|e| e.error <= 0.0) {
                            exact = exact.min(e.ms);
                        }
                        seen.estimates.push(e);
                    }
                    if !known {
                        let front = front(&seen.estimates[first..], payback, horizon);
                        asked[k] = Asked {
                            front,
                            offset,
                            version,
                        };
                    }
                }
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

    /// Step 2: each visible object's cheapest representation within the budget as things
    /// are, with hysteresis; rebuild candidates for step 3.
    fn choose_as_is(&mut self, previous: &[Option<usize>]) {
        let cfg = self.config;
        let budget = cfg.budgets.error.max(0.0);
        let nr = self.reps.len();
        self.rebuilds.clear();
        if cfg.budgets.scope == Scope::Frame {
            self.choose_for_frame(previous);
            return;
        }
        let mut rebuilds = std::mem::take(&mut self.rebuilds);
        for (v, &i) in self.visible.iter().enumerate() {
            let est = estimates(&self.seen, &self.at, nr, v);
            let current = previous[i];
            let ms = |e: &Priced| e.ms;
            let limit = |r: usize| {
                if Some(r) == current {
                    budget
                } else {
                    budget * cfg.hysteresis
                }
            };
            // Cheapest within its limit (ties: earlier representation).
            let mut best: Option<(usize, f32)> = None;
            for (r, e) in est.iter().enumerate() {
                let Some(e) = e else { continue };
                let fits = e.error.is_finite() && e.error <= limit(r);
                if fits && best.is_none_or(|(_, b)| ms(e) < b) {
                    best = Some((r, ms(e)));
                }
            }
            // Keep the one in use unless the other saves enough.
            if let (Some((b, b_ms)), Some(c)) = (best, current) {
                if let Some(Some(e)) = est.get(c) {
                    if b != c && e.error <= budget && b_ms > ms(e) * (1.0 - cfg.min_saving) {
                        best = Some((c, ms(e)));
                    }
                }
            }
            let within = best.is_some();
            // None within: the least error (ties: cheaper).
            let best = best.or_else(|| {
                let mut least: Option<(usize, f32, f32)> = None;
                for (r, e) in est.iter().enumerate() {
                    let Some(e) = e else { continue };
                    let better = least
                        .is_none_or(|(_, err, m)| e.error < err || (e.error == err && ms(e) < m));
                    if better {
                        least = Some((r, e.error, ms(e)));
                    }
                }
                least.map(|(r, _, m)| (r, m))
            });
            let Some((r0, ms0)) = best else {
                self.choices[i] = Choice {
                    over: Some(Over::Nothing),
                    error: f32::INFINITY,
                    ..Choice::default()
                };
                continue;
            };
            let err0 = est[r0].map_or(f32::INFINITY, |e| e.error);
            self.choices[i] = Choice {
                rep: Some(r0),
                error: err0,
                ms: ms0,
                rebuilt: false,
                over: (!within).then_some(Over::Nothing),
            };
            self.rebuild_candidates(v, i, r0, err0, ms0, budget, current, &mut rebuilds);
        }
        self.rebuilds = rebuilds;
    }

    /// Step 2 with the budget over the frame ([`Scope::Frame`]): each object's option at
    /// the frame's multiplier, and the rebuilds worth more than they cost at it (by the
    /// time and weighted error they save, net of the rebuild spread over
    /// [`Config::payback_frames`]).
    fn choose_for_frame(&mut self, previous: &[Option<usize>]) {
        let cfg = self.config;
        let nr = self.reps.len();
        let (seen, at, visible) = (&self.seen, &self.at, &self.visible);
        let (weights, horizons) = (&self.weights, &self.horizons);
        let object = |v: usize| frame_budget::Object {
            est: estimates(seen, at, nr, v),
            weight: weights[v],
            current: previous[visible[v]],
            horizon: horizons[v],
        };
        let w = frame_budget::Weights {
            stick: cfg.min_saving,
            payback: &self.payback,
            spread: cfg.spread,
        };
        let mut options = std::mem::take(&mut self.options);
        options.fill(self.visible.len(), object, self.area, &w);
        let price = frame_budget::price(&options, cfg.budgets.error, &mut self.warm);
        let mut rebuilds = std::mem::take(&mut self.rebuilds);
        // Each object's best as it is, side by side (each alone: the same at any count).
        let mut picks = std::mem::take(&mut self.picks);
        (0..self.visible.len())
            .into_par_iter()
            .map(|k| options.pick(k, price).0)
            .collect_into_vec(&mut picks);
        for (k, &i) in self.visible.iter().enumerate() {
            let as_is = picks[k];
            // Drawn as it is unless a rebuild happens (the rebuild budget decides): every
            // rebuild that scores better is a candidate, the best taken first.
            for b in options.rebuilds(k) {
                let value = as_is.map_or(f64::MAX, |n| price.score(&n) - price.score(b));
                if value > 0.0 {
                    rebuilds.push(Rebuild {
                        tier: if as_is.is_none() { 0 } else { 2 },
                        key: value.min(f64::from(f32::MAX)) as f32,
                        object: i,
                        rep: b.rep,
                    });
                }
            }
            self.choices[i] = match as_is {
                Some(p) => Choice {
                    rep: Some(p.rep),
                    error: p.error,
                    ms: p.ms,
                    rebuilt: false,
                    over: None,
                },
                None => Choice {
                    over: Some(Over::Nothing),
                    error: f32::INFINITY,
                    ..Choice::default()
                },
            };
        }
        self.options = options;
        self.rebuilds = rebuilds;
        self.picks = picks;
    }

    /// The rebuilds of visible object `v` (object `i`), now drawn by `r0` with `err0` in
    /// `ms0`, one per representation that qualifies, appended to `out`: see the tiers in
    /// the module docs. Step 3 takes at most one per object, the best that fits.
    #[allow(clippy::too_many_arguments)]
    fn rebuild_candidates(
        &self,
        v: usize,
        i: usize,
        r0: usize,
        err0: f32,
        ms0: f32,
        budget: f32,
        current: Option<usize>,
        out: &mut Vec<Rebuild>,
    ) {
        let cfg = self.config;
        let nr = self.reps.len();
        let est = estimates(&self.seen, &self.at, nr, v);
        let pixels = self.pixels_of(v);
        let horizon = self.horizons[v];
        for (r, e) in est.iter().enumerate() {
            let Some(e) = e else { continue };
            let within = e.rebuilt <= budget * cfg.hysteresis;
            if !e.rebuilds || !within {
                continue;
            }
            let (ms, rb) = (e.ms, e.rebuild_ms);
            let frames = self.payback[r].min(horizon);
            let cand = if err0 > budget {
                Some((0, (err0 - e.rebuilt).min(1e6) * pixels - ms))
            } else if r == r0 && Some(r) == current && e.error > budget * cfg.hysteresis {
                Some((1, e.error / budget.max(1e-6)))
            } else if ms < ms0 * (1.0 - cfg.min_saving) && (ms0 - ms) * frames >= rb {
                Some((2, ms0 - ms - rb / frames.max(1.0)))
            } else {
                None
            };
            if let Some((tier, key)) = cand {
                out.push(Rebuild {
                    tier,
                    key,
                    object: i,
                    rep: r,
                });
            }
        }
    }

    /// The screen pixels of visible object `v` ([`Sight::pixels`], at least 1).
    fn pixels_of(&self, v: usize) -> f32 {
        self.pixels[v].max(1.0)
    }

    /// Each visible object's weight in the frame's error (its rectangle's pixels times the
    /// share of it that showed in the last frame: [`occlusion`]), and the pixels the rectangles cover on a `width` x `height` target
    /// (each once, at least 1): see [`frame_budget`].
    fn weigh(&mut self, camera: &Camera, width: u32, height: u32) {
        let hidden = self
            .occlusion
            .get_mut()
            .unwrap_or_else(PoisonError::into_inner);
        let (then, visible, rects) = (&self.then, &self.visible, &self.rects);
        hidden.weigh(
            visible.len(),
            |k| then.get(visible[k]).copied().flatten(),
            |k| rects[k].width as f32 * rects[k].height as f32,
            camera,
            (width, height),
            &mut self.weights,
        );
        // This frame's bounds, for the next frame's lookups (none for what is not drawn).
        self.then.clear();
        self.then.resize(self.objects.len(), None);
        for seen in &self.seen[..self.objects.len().div_ceil(CHUNK)] {
            for &(i, _, _, bounds, _) in &seen.objects {
                self.then[i] = Some(bounds);
            }
        }
        let covered = self.cover.area(width, height, self.rects.iter().copied());
        self.covered = covered;
        self.area = (covered as f64).max(1.0);
    }

    /// Takes what the finished frame `target`, seen from `camera`, hides for the next
    /// frame's weights ([`occlusion`]).
    pub fn observe_frame(&self, target: &Target, camera: &Camera) {
        let mut hidden = self
            .occlusion
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        hidden.observe(target, camera);
    }

    /// Step 3: the ranked rebuilds within the budget, each representation's in one call.
    fn rebuild(&mut self, view: &FrameView<'_>) {
        let cfg = self.config;
        let nr = self.reps.len();
        if cfg.budgets.rebuild_ms.is_some() {
            // Under a time budget, what a rebuild is worth per millisecond it takes: one
            // long bake must not take the place of many short rebuilds worth more in all.
            for c in &mut self.rebuilds {
                let Ok(v) = self.visible.binary_search(&c.object) else {
                    continue;
                };
                if let Some(e) = estimates(&self.seen, &self.at, nr, v)[c.rep] {
                    c.key /= e.rebuild_ms.max(1e-3);
                }
            }
        }
        self.rebuilds.sort_by(|a, b| {
            a.tier
                .cmp(&b.tier)
                .then(b.key.total_cmp(&a.key))
                .then(a.object.cmp(&b.object))
        });
        let slot = |planner: &Self, i: usize| planner.visible.binary_search(&i).ok();
        let mut taken = 0;
        let mut spent = 0.0;
        // Bytes held now, and what the rebuilds taken will hold (counted in full: an image
        // replaced is freed only after).
        let mut held: usize = match cfg.budgets.memory {
            Some(_) => self.held.iter().sum(),
            None => 0,
        };
        // Per object: 1 once a rebuild is taken, 2 while one is deferred.
        self.state.clear();
        self.state.resize(self.objects.len(), 0);
        let mut chosen = Vec::new();
        for c in &self.rebuilds {
            if self.state[c.object] == 1 {
                continue;
            }
            let Some(v) = slot(self, c.object) else {
                continue;
            };
            let Some(e) = estimates(&self.seen, &self.at, nr, v)[c.rep] else {
                continue;
            };
            let ms = e.rebuild_ms;
            let over_ms = cfg
                .budgets
                .rebuild_ms
                .is_some_and(|t| taken > 0 && spent + ms > t);
            let over_memory = cfg.budgets.memory.is_some_and(|m| held + e.memory > m);
            if taken >= cfg.budgets.rebuilds || over_ms || over_memory {
                self.state[c.object] = 2;
                if c.tier == 0 {
                    self.choices[c.object].over = Some(Over::Rebuilds);
                }
                continue;
            }
            self.state[c.object] = 1;
            taken += 1;
            spent += ms;
            held += e.memory;
            chosen.push((c.rep, c.object, e));
        }
        self.report.deferred = self.state.iter().filter(|&&s| s == 2).count();
        self.report.rebuild_ms = spent;
        self.report.rebuilds = taken;
        for r in 0..nr {
            self.batch.clear();
            self.batch
                .extend(chosen.iter().filter(|c| c.0 == r).map(|c| c.1));
            if self.batch.is_empty() {
                continue;
            }
            self.batch.sort_unstable();
            self.reps[r].rebuild(&self.batch, &mut self.objects, view);
            self.held[r] = self.reps[r].memory();
        }
        for (r, i, e) in chosen {
            self.idle[i * nr + r] = 0;
            self.choices[i] = Choice {
                rep: Some(r),
                error: e.rebuilt,
                ms: e.ms,
                rebuilt: true,
                over: None,
            };
        }
    }

    /// Step 4: cheaper representations, least added error per millisecond saved first,
    /// until the predicted frame fits the time budget.
    fn fit_time(&mut self) {
        let cfg = self.config;
        let nr = self.reps.len();
        let draw: f32 = self.choices.iter().map(|c| c.ms).sum();
        let mut total = draw + self.report.rebuild_ms;
        let Some(limit) = cfg.budgets.time_ms else {
            return;
        };
        if total <= limit {
            return;
        }
        // (added error x pixels per ms saved, object, representation, saving)
        let mut moves: Vec<(f32, usize, usize, f32)> = Vec::new();
        for (v, &i) in self.visible.iter().enumerate() {
            let c = self.choices[i];
            let Some(r0) = c.rep else { continue };
            let pixels = self.pixels_of(v);
            let mut best: Option<(f32, usize, f32)> = None;
            for r in 0..nr {
                let Some(e) = estimates(&self.seen, &self.at, nr, v)[r] else {
                    continue;
                };
                // A representation rebuilt this frame is drawn at its rebuilt error.
                let err = if r == r0 { c.error } else { e.error };
                let ms = e.ms;
                if r == r0 || ms >= c.ms || !err.is_finite() {
                    continue;
                }
                let ratio = (err - c.error).max(0.0) * pixels / (c.ms - ms);
                if best.is_none_or(|b| ratio < b.0) {
                    best = Some((ratio, r, c.ms - ms));
                }
            }
            if let Some((ratio, r, saving)) = best {
                moves.push((ratio, i, r, saving));
            }
        }
        moves.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        for (_, i, r, saving) in moves {
            if total <= limit {
                break;
            }
            let v = self.visible.binary_search(&i).unwrap_or(0);
            let Some(e) = estimates(&self.seen, &self.at, nr, v)[r] else {
                continue;
            };
            let over = e.error > cfg.budgets.error;
            self.choices[i] = Choice {
                rep: Some(r),
                error: e.error,
                ms: e.ms,
                rebuilt: false,
                over: over.then_some(Over::Time),
            };
            total -= saving;
        }
    }

    /// The report, idle counts and releases, and prepares objects and representations for
    /// their draws.
    fn finish(&mut self, view: &FrameView<'_>, previous: &[Option<usize>]) {
        let cfg = self.config;
        let nr = self.reps.len();
        let budget = cfg.budgets.error.max(0.0);
        let r = &mut self.report;
        r.counts.clear();
        r.counts.resize(nr, 0);
        (r.culled, r.switches, r.over_budget) = (0, 0, 0);
        (r.over_time, r.over_rebuilds, r.over_nothing) = (0, 0, 0);
        (r.draw_ms, r.max_error) = (0.0, 0.0);
        // The frame's mean and bound over what is drawn (what nothing draws is reported
        // apart); over the frame, objects are over only when the bound is.
        let (mut sum, mut squares) = (0.0f64, 0.0f64);
        for (v, &i) in self.visible.iter().enumerate() {
            let c = &self.choices[i];
            if c.rep.is_some() {
                let e = f64::from(c.error) * f64::from(self.weights[v]);
                (sum, squares) = (sum + e, squares + e * e);
            }
        }
        let margin = Z99 * f64::from(cfg.spread.max(0.0));
        let r = &mut self.report;
        r.mean_error = frame_budget::bound(sum, squares, self.area, 0.0) as f32;
        r.scatter = frame_budget::bound(0.0, squares, self.area, 1.0) as f32;
        r.bound = frame_budget::bound(sum, squares, self.area, margin) as f32;
        r.covered = self.covered;
        let frame_over = cfg.budgets.scope == Scope::Frame
            && !self.visible.is_empty()
            && (r.bound > budget || r.bound.is_nan());
        let allowed = match cfg.budgets.scope {
            Scope::Object => budget,
            Scope::Frame if frame_over => budget,
            Scope::Frame => f32::INFINITY,
        };
        for &i in &self.visible {
            let c = &mut self.choices[i];
            if c.error <= allowed && c.rep.is_some() {
                c.over = None;
            } else if c.over.is_none() {
                c.over = Some(Over::Nothing);
            }
            let Some(rep) = c.rep else {
                r.over_budget += 1;
                r.over_nothing += 1;
                continue;
            };
            r.counts[rep] += 1;
            self.idle[i * nr + rep] = 0;
            r.switches += usize::from(previous[i].is_some_and(|p| p != rep));
            r.draw_ms += c.ms;
            r.max_error = r.max_error.max(c.error);
            match c.over {
                Some(Over::Time) => r.over_time += 1,
                Some(Over::Rebuilds) => r.over_rebuilds += 1,
                Some(Over::Nothing) => r.over_nothing += 1,
                None => {}
            }
            r.over_budget += usize::from(c.over.is_some());
            if self.reps[rep].draws_subject() {
                self.objects[i].prepare(view.camera, view.height);
            }
        }
        r.culled = self.objects.len() - self.visible.len();
        for i in 0..self.objects.len() {
            for k in 0..nr {
                if self.idle[i * nr + k] == cfg.release_after.saturating_add(1) {
                    self.reps[k].release(i);
                    self.touched[k] = true;
                }
            }
        }
        for (k, rep) in self.reps.iter_mut().enumerate() {
            self.batch.clear();
            let drawn = self.choices.iter().enumerate();
            self.batch
                .extend(drawn.filter(|(_, c)| c.rep == Some(k)).map(|(i, _)| i));
            rep.prepare(&self.batch, &self.objects, view);
        }
        for (k, rep) in self.reps.iter().enumerate() {
            if std::mem::take(&mut self.touched[k]) {
                self.held[k] = rep.memory();
            }
        }
        self.report.memory = self.held.iter().sum();
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
mod by_technique;
#[cfg(test)]
mod occlusion_tests;
#[cfg(test)]
mod ranking_tests;
#[cfg(test)]
pub(crate) mod tests;
