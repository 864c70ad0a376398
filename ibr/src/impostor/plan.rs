//! Runtime impostors as one of the planner's representations: each object's image, its
//! error predicted by the calibrated model ([`super::Predicted::levels`]), refreshed when
//! the planner asks.

use super::predict::RESAMPLING;
use super::{image_error, needed_side, pixels_per_radian, predict, pull_near, ImpostorSet};
use crate::plan::{Estimate, Representation, Sight, Work};
use crate::subject::Subject;
use crate::technique::FrameView;
use engine::Draw;
use glam::Vec3;

/// The neighbour difference assumed for an object never captured (8-bit levels per
/// texel), until its first image measures its own: a busy image, so the first estimate
/// errs high.
pub const PRIOR_GRADIENT: f32 = 8.0;

/// Bytes of an image `side` texels square with its mipmaps.
fn image_bytes(side: u32) -> usize {
    (side as usize).pow(2) * 4 * 4 / 3
}

impl<S: Subject + Send> Representation<S> for ImpostorSet {
    fn name(&self) -> &str {
        "impostors"
    }

    /// `None` within [`super::Config::transition`] radii (the image is refreshed every
    /// frame there in the set's own update; the planner draws geometry instead). An image
    /// whose subject changed, moved, or needs a larger texture than it has by
    /// [`super::Tolerance::octaves`] has infinite error.
    fn estimate(&self, i: usize, subject: &S, sight: &Sight<'_>) -> Option<Estimate> {
        let imp = self.impostors.get(i)?;
        let cfg = &self.config;
        if sight.within(cfg.transition) {
            return None;
        }
        let (b, ppr) = (sight.bounds, sight.px_per_radian);
        let needed = needed_side(b.radius, sight.distance, ppr, cfg.min_side, cfg.max_side);
        let held = imp.capture.as_ref().filter(|_| imp.slot.is_some());
        let (error, rebuilt) = match held {
            Some(c) => {
                let p = predict(Some(c), subject, sight.eye, needed, ppr, cfg);
                let coarse = needed > c.side && p.octaves >= cfg.tolerance.octaves;
                let error = if p.ratio.is_finite() && !coarse {
                    p.levels
                } else {
                    f32::INFINITY
                };
                let fresh = super::Capture { side: needed, ..*c };
                (error, image_error(&fresh, sight.distance, 0.0, ppr))
            }
            None => (f32::INFINITY, RESAMPLING * PRIOR_GRADIENT),
        };
        Some(Estimate {
            error,
            rebuilt,
            draw: Work {
                triangles: 2,
                pixels: sight.pixels as u64,
                captures: 0,
            },
            rebuild: Work {
                triangles: subject.triangle_count() as u64,
                pixels: u64::from(needed) * u64::from(needed),
                captures: 1,
            },
            memory: image_bytes(needed),
        })
    }

    /// Re-renders the objects' images from the eye, side by side (as
    /// [`ImpostorSet::update`] does its own refreshes).
    fn rebuild(&mut self, objects: &[usize], subjects: &mut [S], view: &FrameView<'_>) -> Work {
        let eye = view.camera.eye();
        let ppr = pixels_per_radian(view.camera, view.height);
        let (lo, hi) = (self.config.min_side, self.config.max_side);
        self.jobs.clear();
        for &i in objects {
            let (Some(s), true) = (subjects.get(i), i < self.impostors.len()) else {
                continue;
            };
            let b = s.bounds();
            let side = needed_side(b.radius, eye.distance(b.center), ppr, lo, hi);
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

    /// The image's quad, pulled to the object's nearest corner.
    fn draw<'a>(&'a self, i: usize, subject: &'a S, eye: Vec3, out: &mut Vec<Draw<'a>>) {
        if let Some(mut d) = self.quad_draw(i) {
            d.transform = pull_near(subject, eye);
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

    fn memory(&self) -> usize {
        let held = self.impostors.iter().filter(|imp| imp.slot.is_some());
        held.filter_map(|imp| imp.capture.as_ref())
            .map(|c| image_bytes(c.side))
            .sum()
    }
}
