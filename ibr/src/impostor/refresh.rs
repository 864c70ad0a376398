//! Refreshing impostor images: a texture and a capture per refresh, the frame's refreshes
//! captured side by side on the thread pool (one [`Capturer`] each), then copied into their
//! textures with the quad trimmed to what the image covers.

use super::{Capture, ImpostorSet, Mode};
use crate::billboard::{push_quad, UvRect};
use crate::capture::Capturer;
use crate::metrics;
use crate::subject::Subject;
use crate::technique::recycle;
use engine::{Draw, Encoding, FrameStats, Lighting, Rgba, Target};
use glam::Vec3;
use rayon::prelude::*;

/// A refresh's own capturer (renderer and target), draw list, and the image's gradients
/// ([`gradients`], measured on the worker's thread) with their row scratch.
#[derive(Debug, Default)]
pub(super) struct Worker {
    capturer: Capturer,
    draws: Vec<Draw<'static>>,
    pub(super) stats: FrameStats,
    gradients: (f32, f32),
    rows: Rows,
}

/// One refresh of a frame: which impostor, from where, into which texture.
#[derive(Clone, Copy, Debug)]
pub(super) struct Job {
    i: usize,
    capture: Capture,
    slot: usize,
}

impl ImpostorSet {
    /// Where and into which texture impostor `i` is re-rendered from `eye`; `None` when
    /// there is no texture for it (pool exhausted: it keeps any old image).
    pub(super) fn begin_refresh<S: Subject>(
        &mut self,
        i: usize,
        subject: &S,
        eye: Vec3,
    ) -> Option<Job> {
        let b = subject.bounds();
        let imp = &mut self.impostors[i];
        let side = imp.predicted.needed_side.max(1);
        let capture = Capture::new(eye, b.center, b.radius, side, subject.version())?;
        // Keep the current texture when it has the right size; else trade it in.
        let slot = match imp.slot {
            Some(s) if imp.capture.as_ref().is_some_and(|c| c.side == side) => s,
            old => {
                let new = self.pool.acquire(side)?;
                if let Some(old) = old {
                    self.pool.release(old);
                }
                new
            }
        };
        imp.slot = Some(slot);
        Some(Job { i, capture, slot })
    }

    /// Renders the frame's refreshes, one worker each, side by side on the thread pool
    /// (each writes only its own target, so the images do not depend on the thread count).
    pub(super) fn render_jobs<S: Subject + Send>(
        &mut self,
        subjects: &mut [S],
        lighting: &Lighting,
    ) {
        if self.jobs.is_empty() {
            return;
        }
        while self.workers.len() < self.jobs.len() {
            self.workers.push(Worker::default());
        }
        // The jobs' subjects, in the jobs' order (indices are distinct).
        self.jobs.sort_by_key(|j| j.i);
        let mut wanted = self.jobs.iter().map(|j| j.i).peekable();
        let mut chosen: Vec<&mut S> = Vec::with_capacity(self.jobs.len());
        for (i, s) in subjects.iter_mut().enumerate() {
            if wanted.peek() == Some(&i) {
                wanted.next();
                chosen.push(s);
            }
        }
        self.jobs.truncate(chosen.len());
        self.jobs
            .par_iter()
            .zip(chosen.par_iter_mut())
            .zip(self.workers.par_iter_mut())
            .with_max_len(1)
            .for_each(|((job, subject), w)| {
                let camera = job.capture.camera();
                let side = job.capture.side;
                subject.prepare(&camera, side);
                let mut draws = recycle(std::mem::take(&mut w.draws));
                subject.draws(&mut draws);
                let (drawn, enc) = (draws.iter().copied(), Encoding::Srgb);
                w.capturer.render(drawn, &camera, lighting, side, side, enc);
                w.stats = w.capturer.last_stats();
                w.draws = recycle(draws);
                w.gradients = gradients(w.capturer.target(), &job.capture, &mut w.rows);
            });
    }

    /// Copies worker `k`'s image into the job's texture and trims the quad to it.
    pub(super) fn finish_refresh(&mut self, job: Job, k: usize) {
        let Job { i, capture, slot } = job;
        let target = self.workers[k].capturer.target();
        let side = capture.side;
        if let Some(tex) = self.pool.texture_mut(slot) {
            target.copy_to_texture(tex);
        }
        let (gradient, depth_gradient) = self.workers[k].gradients;
        let capture = Capture {
            gradient,
            depth_gradient,
            ..capture
        };
        let imp = &mut self.impostors[i];
        let m = &mut imp.quad;
        m.clear();
        // Trim the quad to the covered part of the image (one texel of margin for the
        // bilinear fringe): tall or flat subjects leave much of the square empty, and every
        // empty texel on screen would still be shaded and blended.
        if let Some(r) = metrics::covered_rect(target, metrics::Coverage::Alpha) {
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
        // A pre-warmed subject stays culled until it comes into view.
        if imp.mode != Mode::Culled {
            imp.mode = Mode::Image;
        }
        imp.refreshes += 1;
        imp.predicted.ratio = 0.0;
        imp.predicted.degrees = 0.0;
        imp.predicted.pixels = 0.0;
        imp.predicted.octaves = 0.0;
    }
}

/// Two rows of an image's stored pixels and of their surfaces' distances from the quad's
/// plane, reused.
#[derive(Debug, Default)]
struct Rows {
    px: [Vec<[u8; 4]>; 2],
    off: [Vec<f32>; 2],
}

/// The mean absolute difference between horizontally and vertically neighbouring texels
/// of `t`, over RGB of the stored 8-bit values ([`Capture::gradient`]), and the same with
/// each difference weighted by its surface's distance from the quad's plane in radii
/// ([`Capture::depth_gradient`]; the nearer texel of a pair that holds a surface). Each
/// texel is read and its distance computed once (two rows at a time).
fn gradients(t: &Target, c: &Capture, rows: &mut Rows) -> (f32, f32) {
    let (w, h) = (t.width(), t.height());
    let camera = c.camera();
    let plane = c.eye.distance(c.center);
    // Row y's pixels and distances from the plane in radii (0 where nothing was drawn).
    let fill = |y: u32, px: &mut Vec<[u8; 4]>, off: &mut Vec<f32>| {
        px.clear();
        off.clear();
        for x in 0..w {
            px.push(t.pixel(x, y).unwrap_or(0).to_le_bytes());
            let d = t.depth_reversed(x, y).unwrap_or(0.0);
            off.push(if d > 0.0 {
                ((camera.view_depth_from_reversed(d) - plane).abs() / c.radius).min(1.0)
            } else {
                0.0
            });
        }
    };
    let diff = |p: &[u8; 4], q: &[u8; 4]| (0..3).map(|k| p[k].abs_diff(q[k]) as u64).sum::<u64>();
    let (mut sum, mut weighted, mut n) = (0u64, 0f64, 0u64);
    if h > 0 {
        let [px0, px1] = &mut rows.px;
        let [off0, off1] = &mut rows.off;
        fill(0, px0, off0);
        for y in 0..h {
            let below = y + 1 < h;
            if below {
                fill(y + 1, px1, off1);
            }
            for x in 0..w as usize {
                let (p, dp) = (&px0[x], off0[x]);
                // The same pairs, in the same order, as texel by texel: right, then below.
                if x + 1 < w as usize {
                    let d = diff(p, &px0[x + 1]);
                    sum += d;
                    weighted += d as f64 * dp.max(off0[x + 1]) as f64;
                    n += 3;
                }
                if below {
                    let d = diff(p, &px1[x]);
                    sum += d;
                    weighted += d as f64 * dp.max(off1[x]) as f64;
                    n += 3;
                }
            }
            std::mem::swap(px0, px1);
            std::mem::swap(off0, off1);
        }
    }
    let n = n.max(1);
    (sum as f32 / n as f32, (weighted / n as f64) as f32)
}
