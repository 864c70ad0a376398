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
//!   its image has, in octaves.
//!
//! An impostor whose error reaches its tolerance is invalid. Invalid impostors are
//! re-rendered largest error first within a per-frame budget; the others keep drawing
//! their (stale) image. With the eye inside a subject's sphere, or no image to show (never
//! captured, texture pool exhausted), the subject is drawn as geometry. Within a band just
//! outside the sphere the image is refreshed every frame, so the switch to geometry does
//! not pop. Textures come from a [`Pool`]; impostors culled for long release theirs.

mod capture;
mod pool;
mod predict;

pub use capture::{capture_camera, Capture};
pub use pool::Pool;
pub use predict::{error_color, needed_side, screen_rect};

use predict::{pixels_per_radian, predict, Frustum};

use crate::billboard::{push_quad, UvRect};
use crate::metrics::{self, ImageError, Options, Region};
use crate::subject::Subject;
use engine::{Camera, Draw, FrameOptions, Lighting, Mesh, Renderer, Rgba, Target};
use glam::{Mat4, Vec3};
use std::time::{Duration, Instant};

/// When an impostor is invalid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// Largest parallax angle, degrees (the SkyWorks default 0.125).
    pub degrees: f32,
    /// If set, the parallax limit in screen pixels instead (at the image centre).
    pub pixels: Option<f32>,
    /// Largest resolution mismatch, octaves (1: the needed side is another power of two).
    pub octaves: f32,
}

impl Default for Tolerance {
    fn default() -> Self {
        Tolerance {
            degrees: 0.125,
            pixels: None,
            octaves: 1.0,
        }
    }
}

/// How much re-rendering a frame may do.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    /// Most impostors re-rendered per frame.
    pub refreshes: usize,
    /// Stop starting refreshes once this much time has gone (interactive use; makes the
    /// refresh schedule depend on the machine, so tests and benchmarks leave it `None`).
    pub time: Option<Duration>,
}

/// Settings of an [`ImpostorSet`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    pub tolerance: Tolerance,
    pub budget: Budget,
    /// Smallest and largest texture side.
    pub min_side: u32,
    pub max_side: u32,
    /// Textures the pool may hold.
    pub pool_slots: usize,
    /// Frames an impostor may stay culled before its texture goes back to the pool.
    pub release_after: u32,
    /// Within this many radii of the centre the image is refreshed every frame (the
    /// approach to the switch to geometry, which happens at 1 radius).
    pub transition: f32,
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
        }
    }
}

/// The predicted error of one impostor this frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Predicted {
    /// Parallax angle at the eye between the stored near and far points, degrees.
    pub degrees: f32,
    /// The same angle in pixels at the image centre.
    pub pixels: f32,
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
}

/// One impostor's state.
#[derive(Debug, Default)]
pub struct Impostor {
    capture: Option<Capture>,
    slot: Option<usize>,
    culled_frames: u32,
    pub predicted: Predicted,
    pub mode: Mode,
    /// Times re-rendered.
    pub refreshes: u64,
    quad: Mesh,
}

impl Impostor {
    pub fn capture(&self) -> Option<&Capture> {
        self.capture.as_ref()
    }
    pub fn has_texture(&self) -> bool {
        self.slot.is_some()
    }
}

/// What one [`ImpostorSet::update`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Report {
    pub refreshes: usize,
    /// Invalid impostors left stale (over budget or out of textures).
    pub stale: usize,
    pub images: usize,
    pub geometry: usize,
    pub culled: usize,
    /// Largest and mean predicted error ratio over the drawn images.
    pub max_ratio: f32,
    pub mean_ratio: f32,
    /// Triangles rendered by the refreshes.
    pub capture_triangles: u64,
    /// Textures in use and in the pool.
    pub pool_used: usize,
    pub pool_size: usize,
}

/// Impostors for a list of subjects (one per subject, same order).
#[derive(Debug)]
pub struct ImpostorSet {
    pub config: Config,
    pub impostors: Vec<Impostor>,
    pool: Pool,
    renderer: Renderer,
    scratch: Target,
    /// Colour impostors by predicted error (green 0, yellow at the tolerance, red at 2x).
    pub debug_tint: bool,
    order: Vec<(f32, usize)>,
}

impl ImpostorSet {
    pub fn new(config: Config, count: usize) -> Self {
        ImpostorSet {
            pool: Pool::new(config.pool_slots),
            config,
            impostors: (0..count).map(|_| Impostor::default()).collect(),
            renderer: Renderer::new(),
            scratch: Target::new(0, 0),
            debug_tint: false,
            order: Vec::new(),
        }
    }

    pub fn pool(&self) -> &Pool {
        &self.pool
    }

    /// Predicts every impostor's error for `camera` (an image `height` pixels tall),
    /// refreshes the worst within the budget, and decides how each subject is drawn.
    /// Subjects drawn as geometry are prepared for `camera`.
    pub fn update<S: Subject>(
        &mut self,
        subjects: &mut [S],
        camera: &Camera,
        height: u32,
        lighting: &Lighting,
    ) -> Report {
        let start = Instant::now();
        let n = subjects.len().min(self.impostors.len());
        let eye = camera.eye();
        let frustum = Frustum::new(camera.clip_from_world());
        let px_per_radian = pixels_per_radian(camera, height);
        let cfg = self.config;
        self.order.clear();
        for (i, (imp, s)) in self.impostors.iter_mut().zip(subjects.iter()).enumerate() {
            let b = s.bounds();
            if !frustum.sees(b.center, b.radius) {
                imp.mode = Mode::Culled;
                imp.culled_frames = imp.culled_frames.saturating_add(1);
                if imp.culled_frames > cfg.release_after {
                    if let Some(slot) = imp.slot.take() {
                        self.pool.release(slot);
                        imp.capture = None;
                    }
                }
                continue;
            }
            imp.culled_frames = 0;
            let dist = eye.distance(b.center);
            if dist.partial_cmp(&b.radius) != Some(std::cmp::Ordering::Greater) {
                imp.mode = Mode::Geometry(Fallback::Inside);
                imp.predicted = Predicted::default();
                continue;
            }
            let needed = needed_side(b.radius, dist, px_per_radian, cfg.min_side, cfg.max_side);
            imp.predicted = predict(imp.capture.as_ref(), s, eye, needed, px_per_radian, &cfg);
            imp.mode = if imp.slot.is_some() && imp.capture.is_some() {
                Mode::Image
            } else {
                Mode::Geometry(Fallback::NoImage)
            };
            let near = dist < b.radius * cfg.transition;
            if imp.predicted.ratio >= 1.0 || near {
                let priority = if near { f32::MAX } else { imp.predicted.ratio };
                self.order.push((priority, i));
            }
        }
        // Largest error first; ties by index so the schedule is deterministic.
        self.order
            .sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let mut report = Report::default();
        for k in 0..self.order.len() {
            let i = self.order[k].1;
            let over_time = cfg.budget.time.is_some_and(|t| start.elapsed() >= t);
            if report.refreshes >= cfg.budget.refreshes || over_time || i >= n {
                report.stale += 1;
                continue;
            }
            if self.refresh(i, &mut subjects[i], eye, lighting, &mut report) {
                report.refreshes += 1;
            } else {
                report.stale += 1;
            }
        }
        let mut ratio_sum = 0.0;
        for (imp, s) in self.impostors.iter_mut().zip(subjects.iter_mut()) {
            match imp.mode {
                Mode::Image => {
                    report.images += 1;
                    report.max_ratio = report.max_ratio.max(imp.predicted.ratio);
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

    /// Re-renders impostor `i` from `eye`. Returns `false` when there was no texture for it
    /// (pool exhausted); it then keeps any old image.
    fn refresh<S: Subject>(
        &mut self,
        i: usize,
        subject: &mut S,
        eye: Vec3,
        lighting: &Lighting,
        report: &mut Report,
    ) -> bool {
        let b = subject.bounds();
        let imp = &mut self.impostors[i];
        let side = imp.predicted.needed_side.max(1);
        let Some(capture) = Capture::new(eye, b.center, b.radius, side, subject.version()) else {
            return false;
        };
        // Keep the current texture when it has the right size; else trade it in.
        let slot = match imp.slot {
            Some(s) if imp.capture.as_ref().is_some_and(|c| c.side == side) => s,
            old => {
                let Some(new) = self.pool.acquire(side) else {
                    return false;
                };
                if let Some(old) = old {
                    self.pool.release(old);
                }
                new
            }
        };
        imp.slot = Some(slot);
        let camera = capture.camera();
        subject.prepare(&camera, side);
        let mut draws = Vec::new();
        subject.draws(&mut draws);
        self.scratch.resize(side, side);
        let clear = FrameOptions {
            clear: Some(Rgba::new(0.0, 0.0, 0.0, 0.0)),
            ..Default::default()
        };
        let stats = self
            .renderer
            .render(draws, &camera, lighting, &mut self.scratch, &clear);
        report.capture_triangles += stats.triangles_set_up;
        if let Some(tex) = self.pool.texture_mut(slot) {
            self.scratch.copy_to_texture(tex);
        }
        let m = &mut imp.quad;
        m.clear();
        // Trim the quad to the covered part of the image (one texel of margin for the
        // bilinear fringe): tall or flat subjects leave much of the square empty, and every
        // empty texel on screen would still be shaded and blended.
        if let Some(r) = metrics::covered_rect(&self.scratch, metrics::Coverage::Alpha) {
            let r = r.grow(1, side, side);
            let f = |p: u32| p as f32 / side as f32;
            let (u0, u1, v0, v1) = (f(r.x), f(r.x + r.width), f(r.y), f(r.y + r.height));
            let [_, _, tr, tl] = capture.corners;
            let down = capture.corners[0] - tl;
            let at = |u: f32, v: f32| tl + (tr - tl) * u + down * v;
            let quad = [at(u0, v1), at(u1, v1), at(u1, v0), at(u0, v0)];
            let uv = UvRect {
                min: glam::Vec2::new(u0, v0),
                max: glam::Vec2::new(u1, v1),
            };
            push_quad(m, quad, uv, Rgba::WHITE, 1.0);
        }
        m.colors.clear();
        imp.capture = Some(capture);
        imp.mode = Mode::Image;
        imp.refreshes += 1;
        imp.predicted.ratio = 0.0;
        imp.predicted.degrees = 0.0;
        imp.predicted.pixels = 0.0;
        imp.predicted.octaves = 0.0;
        true
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

    /// The quad that draws impostor `i`'s image (world space, identity transform), when it
    /// is drawn as an image this frame. Callers may change the transform, e.g. scale the
    /// quad about the eye to move it nearer in depth without changing its pixels.
    pub fn image_draw(&self, i: usize) -> Option<Draw<'_>> {
        let imp = self.impostors.get(i)?;
        if imp.mode != Mode::Image {
            return None;
        }
        Some(Draw {
            mesh: &imp.quad,
            material: self.pool.material(imp.slot?)?,
            transform: Mat4::IDENTITY,
        })
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
