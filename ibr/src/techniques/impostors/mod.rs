//! Dynamic impostors (Schaufler 1995; Harris and Lastra 2001): a subject rendered offscreen
//! from the current eye into an image fitted to its bounding sphere, drawn as a quad
//! through its centre facing the capture eye, and re-rendered only when its predicted
//! error grows too large.
//!
//! Per frame, [`ImpostorSet::update`] predicts each impostor's error without rendering:
//! - *parallax*: the angle at the eye between the stored near and far points of the
//!   subject (the ends of its bounding sphere's diameter along the capture ray); 0 from
//!   the capture eye, growing as the eye translates. Rotating in place changes nothing.
//! - *resolution*: the power-of-two texture side the subject needs now against the one
//!   its image has, in octaves (with [`ImpostorSet::side_step`], the side is the disc's
//!   rounded up to the step, and an image the disc has outgrown is invalid).
//!
//! An impostor whose error reaches its tolerance is invalid. Invalid impostors are
//! re-rendered largest error first within a per-frame budget (a count, and optionally
//! milliseconds: the count the measured cost of recent refreshes fits in; optionally a
//! credit of texels each frame earns, [`ImpostorSet::texel_budget`]), the frame's
//! refreshes rendered side by side on the thread pool; subjects just outside the view
//! (within [`Config::prewarm`]) are refreshed after them when the budget has room, so they
//! come into view with a fresh image. The others keep drawing their (stale) image, but
//! never one whose predicted error is over [`Config::fallback_ratio`] times the tolerance:
//! that subject is drawn as geometry until it can be refreshed ([`Fallback::Stale`]).
//! With the eye inside a subject's sphere, or no image to show (never captured, texture
//! pool exhausted), the subject is drawn as geometry. Within a band just outside the
//! sphere the image is refreshed every frame, so the switch to geometry does not pop.
//! Textures come from a [`Pool`]; impostors culled for long release theirs.
//!
//! # Example
//!
//! An impostor of a small mesh: rendered at the first update, kept while the eye barely
//! moves, rendered again once the eye has gone a quarter turn round it, and drawn.
//!
//! ```
//! use engine::procedural::cuboid;
//! use engine::{Camera, FrameOptions, Lighting, Material, Renderer, Rgba, Target};
//! use glam::{Mat4, Vec3};
//! use ibr::impostor::{Config, ImpostorSet, Mode};
//! use ibr::subject::MeshGroup;
//! use std::sync::Arc;
//!
//! let crate_mesh = Arc::new(cuboid(Vec3::ONE));
//! let white = Arc::new(Material::lit(Rgba::WHITE));
//! let mut subjects = vec![MeshGroup::new().with(crate_mesh, white, Mat4::IDENTITY)];
//! let mut set = ImpostorSet::new(Config::default(), subjects.len());
//! let lighting = Lighting::default();
//! let (w, h) = (64, 64);
//! let seen_from = |eye: Vec3| Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 0.5, 1.0);
//!
//! // No image yet: one is rendered, and drawn.
//! let report = set.update(&mut subjects, &seen_from(Vec3::new(0.0, 0.0, 10.0)), h, &lighting);
//! assert_eq!((report.refreshes, report.images), (1, 1));
//! assert_eq!(set.impostors[0].mode, Mode::Image);
//!
//! // A millimetre to the side: far under the 0.125 degree parallax tolerance.
//! let report = set.update(&mut subjects, &seen_from(Vec3::new(0.001, 0.0, 10.0)), h, &lighting);
//! assert_eq!(report.refreshes, 0);
//!
//! // A quarter turn round the subject: the image is invalid and rendered again.
//! let camera = seen_from(Vec3::new(10.0, 0.0, 0.0));
//! let report = set.update(&mut subjects, &camera, h, &lighting);
//! assert_eq!(report.refreshes, 1);
//! assert_eq!(set.impostors[0].refreshes, 2);
//!
//! // Drawn: the image's quad covers the subject's place on screen.
//! let mut draws = Vec::new();
//! set.draws(&subjects, &mut draws);
//! let mut target = Target::new(w, h);
//! let opts = FrameOptions::default();
//! Renderer::new().render(draws.iter().copied(), &camera, &lighting, &mut target, &opts);
//! assert_ne!(target.pixel(w / 2, h / 2), target.pixel(0, 0));
//! ```

mod cells;
mod plan;
mod predict;
mod refresh;
mod relief;
mod technique;

pub use technique::Impostored;

use crate::core::pixels_per_radian;
use crate::core::{needed_side, pull_near, screen_rect, Capture, Frustum, Pool};
pub use predict::error_color;
use predict::{image_error, outgrown, predict, stepped_side, stretched};
use refresh::{Job, Worker};

pub(crate) use crate::core::Budget;
use crate::core::Scheduler;
use crate::core::Subject;
use crate::metrics::{self, ImageError, Options, Region};
use engine::{Camera, Draw, FrameOptions, Lighting, Mesh, Renderer, Rgba, Target};
use glam::{Mat4, Vec3, Vec4};
use std::time::Instant;

/// When an impostor is invalid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// Largest parallax angle, degrees (the SkyWorks default 0.125).
    pub degrees: f32,
    /// If set, the parallax limit in screen pixels instead (at the image centre).
    pub pixels: Option<f32>,
    /// If set, the limit on the image error staleness adds instead ([`Predicted::levels`]
    /// less what a fresh image predicts: mean absolute 8-bit error over the subject's
    /// screen rectangle); takes precedence.
    pub levels: Option<f32>,
    /// Largest resolution mismatch, octaves (1: the needed side is another power of two).
    pub octaves: f32,
}

impl Default for Tolerance {
    fn default() -> Self {
        Tolerance {
            degrees: 0.125,
            pixels: None,
            levels: None,
            octaves: 1.0,
        }
    }
}

/// Settings of an [`ImpostorSet`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    /// When an impostor is invalid and needs a refresh.
    pub tolerance: Tolerance,
    /// Refreshes allowed per frame (a count, optionally a time).
    pub budget: Budget,
    /// Smallest texture side, pixels.
    pub min_side: u32,
    /// Largest texture side, pixels.
    pub max_side: u32,
    /// Textures the pool may hold.
    pub pool_slots: usize,
    /// Frames an impostor may stay culled before its texture goes back to the pool.
    pub release_after: u32,
    /// Within this many radii of the centre the image is refreshed every frame (the
    /// approach to the switch to geometry, which happens at 1 radius).
    pub transition: f32,
    /// An image whose predicted error ratio is above this after the frame's refreshes is
    /// not shown: its subject is drawn as geometry ([`Fallback::Stale`]). Infinity never
    /// falls back.
    pub fallback_ratio: f32,
    /// Subjects within this fraction of the view's half-width beyond its edges are
    /// refreshed ahead of coming into view, after every visible one.
    pub prewarm: f32,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            tolerance: Tolerance::default(),
            budget: Budget {
                refreshes: 8,
                time: None,
            },
            min_side: 16,
            max_side: 512,
            pool_slots: 256,
            release_after: 120,
            transition: 1.25,
            fallback_ratio: 2.0,
            prewarm: 0.25,
        }
    }
}

/// What an impostor's image is drawn on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Shape {
    /// A quad through the subject's centre facing the capture eye.
    #[default]
    Quad,
    /// A grid whose nodes stand on the subject's captured surface ([`relief`]): images and
    /// geometry occlude one another per pixel at their subjects' depths. For opaque
    /// subjects (their captures write depth), drawn as cutouts.
    Relief,
    /// The subject's box ([`Subject::corners`]) with the image projected onto it from the
    /// capture eye ([`relief`]): the box's own outline and depth. For subjects that fill
    /// their box (buildings): the image's coverage is spread two texels beyond the
    /// outline, so only the box's faces bound what is drawn.
    Box,
}

/// The predicted error of one impostor this frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Predicted {
    /// Parallax angle at the eye between the stored near and far points, degrees.
    pub degrees: f32,
    /// The same angle in pixels at the image centre.
    pub pixels: f32,
    /// The image error it makes, predicted: mean absolute 8-bit error over the subject's
    /// screen rectangle, from the parallax in pixels and how busy the image is
    /// (`Capture::gradient`, per screen pixel), calibrated so that the measured error is
    /// at most this on most images (`bench impostors`, the calibration series).
    pub levels: f32,
    /// The texture side the subject needs now.
    pub needed_side: u32,
    /// `|log2(needed / current)|`.
    pub octaves: f32,
    /// The larger of the two errors over their tolerances: invalid at 1 and above
    /// (infinite when the subject changed or was never captured).
    pub ratio: f32,
}

/// How an impostor's subject is drawn this frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Mode {
    /// Its image.
    Image,
    /// As geometry, and why.
    Geometry(Fallback),
    /// Not at all: outside the view.
    #[default]
    Culled,
}

/// Why a subject is drawn as geometry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fallback {
    /// The eye is inside its bounding sphere.
    Inside,
    /// It has no image yet and the budget or the pool had no room for one.
    NoImage,
    /// Its image is too stale to show (over [`Config::fallback_ratio`]) and the budget had
    /// no room to refresh it.
    Stale,
}

/// One impostor's state.
#[derive(Debug, Default)]
pub struct Impostor {
    capture: Option<Capture>,
    slot: Option<usize>,
    culled_frames: u32,
    /// This frame's predicted error.
    pub predicted: Predicted,
    /// How its subject is drawn this frame.
    pub mode: Mode,
    /// Times re-rendered.
    pub refreshes: u64,
    quad: Mesh,
    /// The share of its capture's square that its quad, trimmed to its covered cells,
    /// covers (0 to 1): what drawing it shades, against the square.
    coverage: f32,
    /// Drawn by the planner in its last frame ([`ImpostorSet::rebuild_life`]).
    drawn: bool,
}

impl Impostor {
    /// Where and how its image was taken; `None` before the first refresh and after its
    /// texture is released.
    pub fn capture(&self) -> Option<&Capture> {
        self.capture.as_ref()
    }
    /// Whether it holds a texture of the [`Pool`].
    pub fn has_texture(&self) -> bool {
        self.slot.is_some()
    }
}

/// What one [`ImpostorSet::update`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Report {
    /// Impostors re-rendered this frame (pre-warmed ones included).
    pub refreshes: usize,
    /// Invalid impostors left stale (over budget or out of textures).
    pub stale: usize,
    /// Subjects drawn as their image.
    pub images: usize,
    /// Subjects drawn as geometry, for any [`Fallback`].
    pub geometry: usize,
    /// Subjects outside the view, not drawn.
    pub culled: usize,
    /// Largest predicted error ratio ([`Predicted::ratio`]) over the drawn images.
    pub max_ratio: f32,
    /// Mean predicted error ratio over the drawn images (0 when none is drawn).
    pub mean_ratio: f32,
    /// Images drawn with a predicted error over the tolerance (ratio above 1).
    pub over_tolerance: usize,
    /// Subjects drawn as geometry because their image was too stale ([`Fallback::Stale`]).
    pub stale_fallbacks: usize,
    /// Refreshes of subjects just outside the view (pre-warming).
    pub prewarmed: usize,
    /// Triangles rendered by the refreshes.
    pub capture_triangles: u64,
    /// Texels the refreshes rendered (their images' areas, summed): a capture's cost is
    /// its fill, so this is what [`ImpostorSet::texel_budget`] bounds.
    pub capture_texels: u64,
    /// Fragments the refreshes shaded.
    pub capture_fragments: u64,
    /// Pool textures in use.
    pub pool_used: usize,
    /// Textures the pool holds, in use or free.
    pub pool_size: usize,
}

/// Impostors for a list of subjects (one per subject, same order).
#[derive(Debug)]
pub struct ImpostorSet {
    /// Settings; may be changed between frames.
    pub config: Config,
    /// One impostor per subject, in the subjects' order.
    pub impostors: Vec<Impostor>,
    pool: Pool,
    renderer: Renderer,
    /// One capturer per refresh of a frame, run side by side.
    workers: Vec<Worker>,
    /// The frame's refreshes (reused).
    jobs: Vec<Job>,
    /// Colour impostors by predicted error (green 0, yellow at the tolerance, red at 2x).
    pub debug_tint: bool,
    /// Ranks refresh candidates within the budget (shared with image layers).
    scheduler: Scheduler,
    /// What the images taken so far say about the next one's gradient (the planner's
    /// prior for subjects never captured).
    prior: plan::GradientPrior,
    /// The planner's debug tint of the images it draws ([`crate::core::Representation::set_tint`]).
    plan_tint: Option<Rgba>,
    /// Draw the images the planner chooses as cutouts: pixels at least this covered kept
    /// opaque, the others dropped, as the rasterizer covers a pixel by its centre, so an
    /// image's silhouette matches its geometry's instead of a half-texel blended fringe
    /// around it (`None`, the default: blended).
    pub cutout: Option<f32>,
    /// What each image is drawn on ([`Shape::Quad`], the default).
    pub shape: Shape,
    /// Texels per screen pixel the planner's images are taken at, at least (1, the
    /// default: the power of two at or above the subject's disc). At 2 a cutout's
    /// silhouette, halfway between texel centres, is half as far from the geometry's.
    pub density: f32,
    /// Texels the refreshes of one [`ImpostorSet::update`] may render together, besides
    /// the count of [`Config::budget`] (`None`, the default: no bound). The first refresh
    /// of a frame is always allowed; the next ones, in their rank order, only while their
    /// images' areas summed stay within it, the others left for later frames. A capture's
    /// cost is its fill, so this keeps a frame's refresh work bounded by a counter, the
    /// same at any thread count and machine load (a time budget is not).
    pub texel_budget: Option<u64>,
    /// Texels the refreshes may still render ([`ImpostorSet::texel_budget`]).
    texel_credit: i64,
    /// Frames a planner's rebuild must stay useful (`None`, the default: judged as taken):
    /// with `Some(k)`, the error a rebuild is predicted to have ([`Estimate::rebuilt`]) is
    /// its error after `k` more frames of the eye's last step (the parallax the fresh image
    /// would show from there), so an image the moving eye would leave within `k` frames is
    /// not rebuilt: its subject stays as it is drawn (geometry) until the eye slows. A still
    /// eye's rebuilds are judged as before.
    ///
    /// [`Estimate::rebuilt`]: crate::core::Estimate::rebuilt
    pub rebuild_life: Option<f32>,
    /// The eye of the planner's last frame ([`crate::core::Representation::prepare`]).
    last_eye: Option<Vec3>,
    /// Refreshes' texture sides: the subject's disc on screen rounded up to a multiple of
    /// this, and an image invalid once the disc outgrows it, so a texel a screen pixel or
    /// more at about the texels needed (`None`, the default: the power of two at or above
    /// the disc, up to four times the texels, invalid an octave away).
    pub side_step: Option<u32>,
}

impl ImpostorSet {
    /// A set of `count` impostors, none captured yet, with an empty texture pool of at most
    /// `config.pool_slots` textures.
    pub fn new(config: Config, count: usize) -> Self {
        ImpostorSet {
            pool: Pool::new(config.pool_slots),
            config,
            impostors: (0..count).map(|_| Impostor::default()).collect(),
            renderer: Renderer::new(),
            workers: Vec::new(),
            jobs: Vec::new(),
            debug_tint: false,
            scheduler: Scheduler::default(),
            prior: plan::GradientPrior::default(),
            plan_tint: None,
            cutout: None,
            shape: Shape::Quad,
            density: 1.0,
            texel_budget: None,
            texel_credit: 0,
            rebuild_life: None,
            last_eye: None,
            side_step: None,
        }
    }

    /// The texture pool the impostors' images live in.
    pub fn pool(&self) -> &Pool {
        &self.pool
    }

    /// Predicts every impostor's error for `camera` (an image `height` pixels tall),
    /// refreshes the worst within the budget (and pre-warms subjects about to come into
    /// view), and decides how each subject is drawn. Subjects drawn as geometry are
    /// prepared for `camera`.
    pub fn update<S: Subject + Send>(
        &mut self,
        subjects: &mut [S],
        camera: &Camera,
        height: u32,
        lighting: &Lighting,
    ) -> Report {
        let n = subjects.len().min(self.impostors.len());
        let eye = camera.eye();
        let clip = camera.clip_from_world();
        let frustum = Frustum::new(clip);
        let widen = 1.0 / (1.0 + self.config.prewarm.max(0.0));
        let wide = Frustum::new(Mat4::from_diagonal(Vec4::new(widen, widen, 1.0, 1.0)) * clip);
        let px_per_radian = pixels_per_radian(camera, height);
        let cfg = self.config;
        self.scheduler.clear();
        for (i, (imp, s)) in self.impostors.iter_mut().zip(subjects.iter()).enumerate() {
            let b = s.bounds();
            let visible = frustum.sees(b.center, b.radius);
            if !visible {
                imp.mode = Mode::Culled;
                imp.culled_frames = imp.culled_frames.saturating_add(1);
                if imp.culled_frames > cfg.release_after {
                    if let Some(slot) = imp.slot.take() {
                        self.pool.release(slot);
                        imp.capture = None;
                    }
                }
                if !wide.sees(b.center, b.radius) {
                    continue;
                }
            } else {
                imp.culled_frames = 0;
            }
            let dist = eye.distance(b.center);
            if dist.partial_cmp(&b.radius) != Some(std::cmp::Ordering::Greater) {
                if visible {
                    imp.mode = Mode::Geometry(Fallback::Inside);
                }
                imp.predicted = Predicted::default();
                continue;
            }
            let needed = match self.side_step {
                Some(step) => stepped_side(b.radius, dist, px_per_radian, step, &cfg),
                None => needed_side(b.radius, dist, px_per_radian, cfg.min_side, cfg.max_side),
            };
            let now = (b, s.version());
            let held = imp.capture.as_ref();
            imp.predicted = predict(held, now, eye, needed, px_per_radian, &cfg);
            // Its own refreshes take `needed` texels a side.
            let max = cfg.max_side;
            let outgrown = self.side_step.is_some() && outgrown(held, b, dist, px_per_radian, max);
            if outgrown
                || self.shape == Shape::Box && stretched(held, s, eye, px_per_radian, needed)
            {
                imp.predicted.ratio = f32::INFINITY;
            }
            if visible {
                imp.mode = if imp.slot.is_some() && imp.capture.is_some() {
                    Mode::Image
                } else {
                    Mode::Geometry(Fallback::NoImage)
                };
            }
            let near = visible && dist < b.radius * cfg.transition;
            if imp.predicted.ratio >= 1.0 || near {
                let priority = if near { f32::MAX } else { imp.predicted.ratio };
                self.scheduler.push(visible, priority, i);
            }
        }
        let mut report = Report::default();
        self.begin_refreshes(subjects, eye, n, &mut report);
        report.refreshes = self.jobs.len();
        let start = Instant::now();
        self.render_jobs(subjects, lighting);
        self.scheduler.measured(self.jobs.len(), start.elapsed());
        for k in 0..self.jobs.len() {
            let job = self.jobs[k];
            report.capture_triangles += self.workers[k].stats.triangles_set_up;
            report.capture_fragments += self.workers[k].stats.fragments_shaded;
            self.finish_refresh(job, k);
        }
        let mut ratio_sum = 0.0;
        for (imp, s) in self.impostors.iter_mut().zip(subjects.iter_mut()) {
            if imp.mode == Mode::Image && imp.predicted.ratio > cfg.fallback_ratio {
                imp.mode = Mode::Geometry(Fallback::Stale);
                report.stale_fallbacks += 1;
            }
            match imp.mode {
                Mode::Image => {
                    report.images += 1;
                    report.max_ratio = report.max_ratio.max(imp.predicted.ratio);
                    report.over_tolerance += (imp.predicted.ratio > 1.0) as usize;
                    ratio_sum += imp.predicted.ratio;
                    if let Some(slot) = imp.slot {
                        let tint = if self.debug_tint {
                            error_color(imp.predicted.ratio)
                        } else {
                            Rgba::WHITE
                        };
                        self.pool.set_tint(slot, tint);
                    }
                }
                Mode::Geometry(_) => {
                    report.geometry += 1;
                    s.prepare(camera, height);
                }
                Mode::Culled => report.culled += 1,
            }
        }
        report.mean_ratio = ratio_sum / report.images.max(1) as f32;
        (report.pool_used, report.pool_size) = self.pool.usage();
        report
    }

    /// Ranks the refreshes this frame wants and begins those the refresh budget and the
    /// texel credit pay for (the first `n` subjects only); the rest are counted stale.
    fn begin_refreshes<S: Subject>(
        &mut self,
        subjects: &[S],
        eye: Vec3,
        n: usize,
        report: &mut Report,
    ) {
        let budget = self.scheduler.rank(&self.config.budget);
        self.jobs.clear();
        if let Some(t) = self.texel_budget {
            // Unspent credit is kept up to one largest capture (or a frame's budget).
            let cap = (u64::from(self.config.max_side).pow(2)).max(t) as i64;
            self.texel_credit = (self.texel_credit + t as i64).min(cap);
        }
        for k in 0..self.scheduler.ranked().len() {
            let c = self.scheduler.ranked()[k];
            let (visible, i) = (c.visible, c.index);
            let side = self.impostors.get(i).map_or(0, |m| m.predicted.needed_side);
            let area = i64::from(side).pow(2);
            // The every-frame refreshes near a subject ([`Config::transition`], ranked at
            // `f32::MAX`) go ahead on credit; the others, never-captured ones (ranked at
            // infinity) included, wait until the credit pays for them.
            let near = c.priority == f32::MAX;
            let over = self.texel_budget.is_some() && !near && area > self.texel_credit;
            if self.jobs.len() >= budget || i >= n || over {
                report.stale += visible as usize;
                continue;
            }
            match self.begin_refresh(i, &subjects[i], eye) {
                Some(job) => {
                    let area = u64::from(job.capture.side).pow(2);
                    report.capture_texels += area;
                    if self.texel_budget.is_some() {
                        self.texel_credit -= area as i64;
                    }
                    self.jobs.push(job);
                    report.prewarmed += !visible as usize;
                }
                None => report.stale += visible as usize,
            }
        }
    }

    /// Appends this frame's draws: images as quads, the rest as their subjects' geometry.
    pub fn draws<'a, S: Subject>(&'a self, subjects: &'a [S], out: &mut Vec<Draw<'a>>) {
        for (i, (imp, s)) in self.impostors.iter().zip(subjects).enumerate() {
            match imp.mode {
                Mode::Image => out.extend(self.image_draw(i)),
                Mode::Geometry(_) => s.draws(out),
                Mode::Culled => {}
            }
        }
    }

    /// As [`ImpostorSet::draws`], with each image's quad scaled about `eye` (the same
    /// pixels, only nearer) to the depth of its subject's nearest corner
    /// ([`Subject::corners`]) along the line of sight: a quad through the centre of a
    /// building standing on the ground would have the ground in front of its walls hide
    /// the bottom of its image; pulled to the nearest corner, nothing in front of the
    /// subject's box hides it. Other shapes ([`ImpostorSet::shape`]) are drawn where they
    /// are.
    pub fn draws_near<'a, S: Subject>(
        &'a self,
        subjects: &'a [S],
        eye: Vec3,
        out: &mut Vec<Draw<'a>>,
    ) {
        for (i, (imp, s)) in self.impostors.iter().zip(subjects).enumerate() {
            match imp.mode {
                Mode::Image => out.extend(self.image_draw(i).map(|mut d| {
                    if self.shape == Shape::Quad {
                        d.transform = pull_near(s, eye);
                    }
                    d
                })),
                Mode::Geometry(_) => s.draws(out),
                Mode::Culled => {}
            }
        }
    }

    /// The quad and material of impostor `i`'s image whatever its mode (world space,
    /// identity transform), if it has one.
    fn quad_draw(&self, i: usize) -> Option<Draw<'_>> {
        let imp = self.impostors.get(i)?;
        imp.capture.as_ref()?;
        Some(Draw {
            mesh: &imp.quad,
            material: self.pool.material(imp.slot?)?,
            transform: Mat4::IDENTITY,
        })
    }

    /// The quad that draws impostor `i`'s image (world space, identity transform), when it
    /// is drawn as an image this frame. Callers may change the transform, e.g. scale the
    /// quad about the eye to move it nearer in depth without changing its pixels.
    pub fn image_draw(&self, i: usize) -> Option<Draw<'_>> {
        if self.impostors.get(i)?.mode != Mode::Image {
            return None;
        }
        self.quad_draw(i)
    }

    /// The measured error of impostor `i` this frame: its image and its subject rendered
    /// as geometry from `camera` into `width` x `height` images, compared over the
    /// subject's screen rectangle. `None` unless it is drawn as an image this frame.
    pub fn measure<S: Subject>(
        &mut self,
        i: usize,
        subject: &mut S,
        camera: &Camera,
        (width, height): (u32, u32),
        lighting: &Lighting,
    ) -> Option<ImageError> {
        let imp = self.impostors.get(i)?;
        if imp.mode != Mode::Image {
            return None;
        }
        let material = self.pool.material(imp.slot?)?.clone();
        let material = engine::Material {
            base_color: Rgba::WHITE,
            ..material
        };
        let clear = FrameOptions {
            clear: Some(Rgba::new(0.0, 0.0, 0.0, 0.0)),
            ..Default::default()
        };
        let mut truth = Target::new(width, height);
        subject.prepare(camera, height);
        let mut draws = Vec::new();
        subject.draws(&mut draws);
        self.renderer
            .render(draws, camera, lighting, &mut truth, &clear);
        let mut image = Target::new(width, height);
        let quad = Draw {
            mesh: &imp.quad,
            material: &material,
            transform: Mat4::IDENTITY,
        };
        self.renderer
            .render([quad], camera, lighting, &mut image, &clear);
        let b = subject.bounds();
        let rect = screen_rect(camera, b.center, b.radius, width, height)?;
        let opts = Options {
            region: Region::Rect(rect),
            ..Options::default()
        };
        metrics::compare(&truth, &image, &opts).ok()
    }
}

#[cfg(test)]
mod tests;
