//! The planner's settings and what it reports: the budgets, the scope they hold over, the
//! configuration, each object's choice and the frame's report; the debug view's tints.

use crate::core::CostModel;
use engine::Rgba;

/// The debug view's colours (`Planner::set_tints`), by representation in the planner's
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
    /// object's screen rectangle (`Estimate`), per object or over the frame ([`Scope`]).
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
    /// shows: `frame_budget`, `occlusion`), with a margin for its spread so that it
    /// holds on 99% of frames ([`Report::bound`], `frame_budget`). Objects
    /// may then err more where that buys most time; hysteresis discounts the
    /// representation in use by [`Config::min_saving`] of its time.
    Frame,
}

/// The default [`Config::spread`]: see there. Fitted on `bench budget` (BENCHMARKS.md).
pub const SPREAD: f32 = 0.5;

/// Settings of a `Planner`.
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
    /// pays for it (a representation may say its own: `Representation::payback_frames`),
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

pub use crate::core::REASK_MOVE;

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
