//! Runtime impostors as one of the planner's representations: each object's image, its
//! error predicted by the calibrated model ([`super::Predicted::levels`]), refreshed when
//! the planner asks.

use super::predict::RESAMPLING;
use super::{image_error, needed_side, pixels_per_radian, predict, pull_near, ImpostorSet, Shape};
use crate::core::FrameView;
use crate::core::Subject;
use crate::core::PRIOR_GRADIENT;
use crate::core::REASK_MOVE;
use crate::core::{image_bytes, Estimate, Representation, Sight, Work};
use engine::{AlphaMode, Draw, Rgba};
use glam::Vec3;

/// The gradient an image of a subject never captured is expected to have, learnt from the
/// images taken so far: a least-squares line in `1 / side` (an image's outline adds
/// differences in proportion to its side, its inside in proportion to its area, so the
/// mean per texel is about `a / side + b`).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct GradientPrior {
    n: f64,
    sx: f64,
    sy: f64,
    sxx: f64,
    sxy: f64,
}

impl GradientPrior {
    pub(crate) fn add(&mut self, side: u32, gradient: f32) {
        if !gradient.is_finite() || side == 0 {
            return;
        }
        let (x, y) = (1.0 / f64::from(side), f64::from(gradient));
        self.n += 1.0;
        self.sx += x;
        self.sy += y;
        self.sxx += x * x;
        self.sxy += x * y;
    }

    /// The expected gradient of a `side`-texel image.
    pub(crate) fn at(&self, side: u32) -> f32 {
        if self.n < 1.0 {
            return PRIOR_GRADIENT;
        }
        let mean = self.sy / self.n;
        let var = self.sxx - self.sx * self.sx / self.n;
        if var <= 1e-12 {
            return mean as f32;
        }
        let a = (self.sxy - self.sx * self.sy / self.n) / var;
        let b = (self.sy - a * self.sx) / self.n;
        (a / f64::from(side.max(1)) + b).max(0.0) as f32
    }
}

impl<S: Subject + Send + Sync> Representation<S> for ImpostorSet {
    fn name(&self) -> &str {
        "impostors"
    }

    /// `None` within [`super::Config::transition`] radii (the image is refreshed every
    /// frame there in the set's own update; the planner draws geometry instead) and where
    /// the subject's disc on screen is wider than [`super::Config::max_side`] texels (less
    /// than a texel per pixel). An image
    /// whose subject changed, moved, or needs a larger texture than it has by
    /// [`super::Tolerance::octaves`], or (a [`Shape::Box`]) shows a face of its box with
    /// less than a texel a pixel across ([`super::relief::face_stretch`]), has infinite
    /// error.
    fn estimate(&self, i: usize, subject: &S, sight: &Sight<'_>) -> Option<Estimate> {
        let imp = self.impostors.get(i)?;
        let cfg = &self.config;
        if !sight.sane() || sight.within(cfg.transition) {
            return None;
        }
        let (b, ppr) = (sight.bounds, sight.px_per_radian);
        let needed = needed_side(b.radius, sight.distance, ppr, cfg.min_side, cfg.max_side);
        // An image the largest texture cannot give a texel per screen pixel would show
        // blurred beside sharp geometry: not offered.
        // The planner asks again only once the eye has moved REASK_MOVE of its distance:
        // the disc may grow that much before the next answer.
        let disc = 2.0 * (b.radius / sight.distance).min(1.0).asin() * ppr;
        if disc * (1.0 + REASK_MOVE) > cfg.max_side as f32 {
            return None;
        }
        let held = imp.capture.as_ref().filter(|_| imp.slot.is_some());
        // What a draw shades: the disc's square times the share of it the trimmed quad
        // covers; without an image, the disc.
        let pixels = match held {
            Some(_) => sight.pixels * (4.0 / std::f32::consts::PI) * imp.coverage,
            None => sight.pixels,
        };
        let (error, rebuilt) = match held {
            Some(c) => {
                // Its resolution judged as the image a texel per pixel would be: taken
                // denser, it is that much larger than the side a texel a pixel needs.
                let d = (c.side as f32 / needed.max(1) as f32).clamp(1.0, self.density.max(1.0));
                let side = c.side as f32 / d;
                let octaves = (needed as f32 / side).log2();
                let coarse = needed as f32 > side && octaves >= cfg.tolerance.octaves;
                // Its error per screen pixel: `image_error` scales the gradient per texel by
                // texels per screen pixel, so the density it was taken at cancels out.
                let now = (b, subject.version());
                let p = predict(Some(c), now, sight.eye, needed, ppr, cfg);
                // A box face the capture eye saw edge-on, seen at an angle now: invalid.
                let side = self.fresh_side(b, sight.distance, ppr);
                let stretched = self.shape == Shape::Box
                    && super::stretched(held, subject, sight.eye, ppr, side);
                let error = if p.ratio.is_finite() && !coarse && !stretched {
                    p.levels
                } else {
                    f32::INFINITY
                };
                // A rebuild predicted as the image a texel a pixel would be, its texels as
                // much smaller than the held image's as that is larger than `needed`: from
                // the capture eye, `rebuilt` is `error` without parallax, and a still
                // camera never rebuilds. (Until session 13 that factor was `d`, capped at
                // `density`: when the power of two taken at `density` texels a pixel was
                // more than `density` times `needed`, 4 at 2.5 or 3, `rebuilt` came out
                // lower than `error` from the capture eye and the planner rebuilt the
                // same image every frame.)
                let e = (c.side as f32 / needed.max(1) as f32).max(1.0);
                let fresh = super::Capture {
                    side: needed,
                    gradient: c.gradient * e,
                    depth_gradient: c.depth_gradient * e,
                    ..*c
                };
                // An image the planner draws now is judged as taken (so it is kept fresh as
                // before); one it does not, after the eye's present motion
                // ([`ImpostorSet::rebuild_life`]).
                let ahead = if imp.drawn {
                    0.0
                } else {
                    self.parallax_ahead(b, sight.eye, ppr)
                };
                (error, image_error(&fresh, sight.distance, ahead, ppr))
            }
            None => {
                // As `image_error` for a fresh image: texels per screen pixel times the
                // resampling of the expected gradient.
                let screen = 2.0 * (b.radius / sight.distance).min(1.0).asin() * ppr;
                let scale = needed as f32 / screen.max(1.0);
                (f32::INFINITY, scale * RESAMPLING * self.prior.at(needed))
            }
        };
        let texels = (needed, needed);
        let triangles = subject.triangle_count();
        Some(Estimate::image(error, rebuilt, pixels, triangles, texels))
    }

    /// Re-renders the objects' images from the eye, side by side (as
    /// [`ImpostorSet::update`] does its own refreshes).
    fn rebuild(&mut self, objects: &[usize], subjects: &mut [S], view: &FrameView<'_>) -> Work {
        let eye = view.camera.eye();
        // Taken at `density` texels per pixel, as far as the largest side allows.
        let ppr = pixels_per_radian(view.camera, view.height);
        self.jobs.clear();
        for &i in objects {
            let (Some(s), true) = (subjects.get(i), i < self.impostors.len()) else {
                continue;
            };
            let b = s.bounds();
            let side = self.fresh_side(b, eye.distance(b.center), ppr);
            self.impostors[i].predicted.needed_side = side;
            if let Some(job) = self.begin_refresh(i, s, eye) {
                self.jobs.push(job);
            }
        }
        self.render_jobs(subjects, view.lighting);
        let mut work = Work::default();
        for k in 0..self.jobs.len() {
            let job = self.jobs[k];
            work.triangles += self.workers[k].stats.triangles_set_up;
            work.pixels += u64::from(job.capture.side).pow(2);
            work.captures += 1;
            self.finish_refresh(job, k);
        }
        work
    }

    /// Tints the images of the objects drawn this frame (a texture taken from the pool since
    /// [`Representation::set_tint`] gets it here).
    fn prepare(&mut self, objects: &[usize], _subjects: &[S], view: &FrameView<'_>) {
        self.last_eye = Some(view.camera.eye());
        for imp in &mut self.impostors {
            imp.drawn = false;
        }
        for &i in objects {
            if let Some(imp) = self.impostors.get_mut(i) {
                imp.drawn = true;
            }
        }
        let tint = self.plan_tint.unwrap_or(Rgba::WHITE);
        let alpha = match self.cutout {
            Some(cutoff) => AlphaMode::Mask { cutoff },
            None => AlphaMode::Blend,
        };
        for &i in objects {
            if let Some(slot) = self.impostors.get(i).and_then(|imp| imp.slot) {
                self.pool.set_tint(slot, tint);
                self.pool.set_alpha(slot, alpha);
            }
        }
    }

    /// The image's quad, pulled to the object's nearest corner; other shapes where they are.
    fn draw<'a>(&'a self, i: usize, subject: &'a S, eye: Vec3, out: &mut Vec<Draw<'a>>) {
        if let Some(mut d) = self.quad_draw(i) {
            if self.shape == Shape::Quad {
                d.transform = pull_near(subject, eye);
            }
            out.push(d);
        }
    }

    fn release(&mut self, i: usize) {
        if let Some(imp) = self.impostors.get_mut(i) {
            if let Some(slot) = imp.slot.take() {
                self.pool.release(slot);
            }
            imp.capture = None;
        }
    }

    /// Every pooled texture's material takes `tint` (white without).
    fn set_tint(&mut self, tint: Option<Rgba>) {
        self.plan_tint = tint;
        for slot in 0..self.pool.usage().1 {
            self.pool.set_tint(slot, tint.unwrap_or(Rgba::WHITE));
        }
    }

    fn memory(&self) -> usize {
        let held = self.impostors.iter().filter(|imp| imp.slot.is_some());
        held.filter_map(|imp| imp.capture.as_ref())
            .map(|c| image_bytes(c.side, c.side))
            .sum()
    }
}

impl ImpostorSet {
    /// The parallax, pixels at `ppr`, that an image of a subject with bounds `b` taken
    /// from `eye` shows after [`ImpostorSet::rebuild_life`] more frames of the eye's last
    /// step (from the planner's last frame to `eye`), measured as [`super::predict`] does
    /// (the angle between the ends of the sphere's diameter along the capture ray); 0
    /// without a life, a last frame, or a step.
    fn parallax_ahead(&self, b: engine::Sphere, eye: Vec3, ppr: f32) -> f32 {
        let (Some(k), Some(last)) = (self.rebuild_life, self.last_eye) else {
            return 0.0;
        };
        let step = eye - last;
        if !step.is_finite() || step == Vec3::ZERO {
            return 0.0;
        }
        let dir = (b.center - eye).normalize_or_zero();
        let later = eye + step * k.max(0.0);
        let (a, c) = (
            b.center - dir * b.radius - later,
            b.center + dir * b.radius - later,
        );
        let radians = a.cross(c).length().atan2(a.dot(c));
        if radians.is_finite() {
            radians * ppr
        } else {
            f32::INFINITY
        }
    }

    /// The side [`Representation::rebuild`] takes an image of a subject with bounds `b` at
    /// `dist` from the eye at: [`ImpostorSet::density`] texels a pixel, within the sides the
    /// config allows.
    fn fresh_side(&self, b: engine::Sphere, dist: f32, ppr: f32) -> u32 {
        let (lo, hi) = (self.config.min_side, self.config.max_side);
        needed_side(b.radius, dist, ppr * self.density.max(1.0), lo, hi)
    }
}
