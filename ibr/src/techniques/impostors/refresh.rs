//! Refreshing impostor images: a texture and a capture per refresh. The frame's refreshes
//! run side by side on the thread pool, each on a worker of its own (one [`Capturer`]): it
//! captures, copies the image into its texture (with mipmaps), and measures what the
//! image covers and its gradients (and, for a relief, its depth grid, [`super::relief`]);
//! the texture is then swapped into the pool and the quad trimmed to the covered cells
//! ([`super::cells`]), or the relief built over the covered part.

use super::cells::Cells;
use super::{relief, Capture, ImpostorSet, Mode, Shape};
use crate::core::Rect;
use crate::core::Subject;
use crate::core::{refresh_side_by_side, Refresher};
use engine::{FrameStats, Lighting, Rgba, Target, Texture};
use glam::Vec3;

/// A refresh's own [`Refresher`] (its image is copied into the refresher's texture, traded
/// for the pool's), its counters, and what [`measure`] found, with its row scratch.
#[derive(Debug, Default)]
pub(super) struct Worker {
    refresher: Refresher,
    pub(super) stats: FrameStats,
    measured: Measured,
    rows: Rows,
    /// The relief's depth grid ([`Shape::Relief`]).
    grid: relief::Grid,
    /// The box's subject corners ([`Shape::Box`]), and the spread image with its scratch.
    corners: Option<[Vec3; 8]>,
    spread: [Vec<u32>; 2],
}

/// One refresh of a frame: which impostor, from where, into which texture.
#[derive(Clone, Copy, Debug)]
pub(super) struct Job {
    i: usize,
    pub(super) capture: Capture,
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
        // Keep the current slot, whatever its side: the refresh swaps its texture in
        // ([`crate::core::Pool::swap_texture`], resized as it is refilled), so trading the slot
        // for a free one of the new side only churned the pool (a new slot for nearly
        // every node capture of the world's fly-over).
        let slot = match imp.slot {
            Some(s) => s,
            None => self.pool.acquire(side)?,
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
        let shape = self.shape;
        let (jobs, workers) = (&mut self.jobs, &mut self.workers);
        refresh_side_by_side(
            jobs,
            |j| j.i,
            subjects,
            workers,
            |job, subject, w| {
                let camera = job.capture.camera();
                let side = job.capture.side;
                // A box's image is spread before it becomes the texture: one copy (and
                // one mip chain) instead of two.
                let nocopy = shape == Shape::Box;
                w.stats = if nocopy {
                    w.refresher
                        .capture(subject, &camera, lighting, (side, side))
                } else {
                    w.refresher.render(subject, &camera, lighting, (side, side))
                };
                let target = w.refresher.target();
                w.measured = measure(target, &job.capture, &mut w.rows);
                w.grid.rect = None;
                w.corners = None;
                match (shape, w.measured.covered) {
                    (Shape::Relief, Some(r)) => {
                        let r = r.grow(1, side, side);
                        relief::grid(target, &job.capture, r, &mut w.grid);
                    }
                    (Shape::Box, Some(r)) => {
                        let [out, scratch] = &mut w.spread;
                        relief::dilate(target, r, out, scratch);
                        let enc = target.encoding();
                        let tex = w
                            .refresher
                            .texture
                            .get_or_insert_with(|| Texture::solid(Rgba::TRANSPARENT));
                        tex.refill(side, side, enc, true, |t| t.copy_from_slice(out));
                        w.corners = Some(subject.corners());
                    }
                    _ if nocopy => w.refresher.keep(),
                    _ => {}
                }
            },
        );
    }

    /// Trades worker `k`'s texture for the job's and trims the quad to the image.
    pub(super) fn finish_refresh(&mut self, job: Job, k: usize) {
        let Job { i, capture, slot } = job;
        let w = &mut self.workers[k];
        if let Some(tex) = w.refresher.texture.as_mut() {
            self.pool.swap_texture(slot, tex);
        }
        let side = capture.side;
        let Measured {
            gradient,
            depth_gradient,
            covered,
            ..
        } = w.measured;
        let capture = Capture {
            gradient,
            depth_gradient,
            ..capture
        };
        self.prior.add(side, gradient);
        let imp = &mut self.impostors[i];
        let m = &mut imp.quad;
        m.clear();
        imp.coverage = 0.0;
        // Trim the quad to the covered cells of the image, within the covered part (one
        // texel of margin for the bilinear fringe): tall or flat subjects and clusters of
        // small objects leave much of the square empty, and every empty texel on screen
        // would still be tested and shaded. A relief is built over the covered part.
        if let Some(corners) = &w.corners {
            imp.coverage = relief::write_box(&capture, corners, m);
        } else if w.grid.rect.is_some() {
            imp.coverage = relief::write(&capture, &w.grid, m);
        } else if let Some(r) = covered {
            let r = r.grow(1, side, side);
            let [_, _, tr, tl] = capture.corners;
            let down = capture.corners[0] - tl;
            let at = |uv: glam::Vec2| tl + (tr - tl) * uv.x + down * uv.y;
            imp.coverage = w.measured.cells.write(r, at, m);
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

/// What a refresh's image holds, besides its texels: the bounds of its covered texels
/// (alpha above 0, as [`crate::metrics::covered_rect`] finds them) and its gradients.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Measured {
    pub(super) covered: Option<Rect>,
    /// The cells of a coarse grid within a texel of a covered texel.
    pub(super) cells: Cells,
    /// [`Capture::gradient`].
    pub(super) gradient: f32,
    /// [`Capture::depth_gradient`].
    pub(super) depth_gradient: f32,
}

/// Two rows of an image's stored pixels and of their surfaces' distances from the quad's
/// plane, and one row of depths as stored, reused.
#[derive(Debug, Default)]
pub(super) struct Rows {
    px: [Vec<u32>; 2],
    off: [Vec<f32>; 2],
    depth: Vec<f32>,
}

/// Reads `t` once, two rows at a time: the covered texels' bounds, the mean absolute
/// difference between horizontally and vertically neighbouring texels over RGB of the
/// stored 8-bit values ([`Capture::gradient`]), and the same with each difference weighted
/// by its surface's distance from the quad's plane in radii ([`Capture::depth_gradient`];
/// the nearer texel of a pair that holds a surface).
pub(super) fn measure(t: &Target, c: &Capture, rows: &mut Rows) -> Measured {
    let (w, h) = (t.width() as usize, t.height());
    let camera = c.camera();
    let plane = c.eye.distance(c.center);
    // Row y's pixels and distances from the plane in radii (0 where nothing was drawn).
    let fill = |y: u32, px: &mut Vec<u32>, off: &mut Vec<f32>, depth: &mut Vec<f32>| {
        t.read_row(y, px, depth);
        off.clear();
        off.extend(depth.iter().map(|&d| {
            if d > 0.0 {
                ((camera.view_depth_from_reversed(d) - plane).abs() / c.radius).min(1.0)
            } else {
                0.0
            }
        }));
    };
    let diff = |p: u32, q: u32| {
        let (p, q) = (p.to_le_bytes(), q.to_le_bytes());
        (0..3).map(|k| p[k].abs_diff(q[k]) as u64).sum::<u64>()
    };
    let (mut sum, mut weighted, mut n) = (0u64, 0f64, 0u64);
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, u32::MAX, 0, 0);
    let mut cells = Cells::new(w as u32);
    if h > 0 {
        let [px0, px1] = &mut rows.px;
        let [off0, off1] = &mut rows.off;
        fill(0, px0, off0, &mut rows.depth);
        for y in 0..h {
            let below = y + 1 < h;
            if below {
                fill(y + 1, px1, off1, &mut rows.depth);
            }
            if let Some(first) = px0.iter().position(|p| p >> 24 != 0) {
                let last = px0.iter().rposition(|p| p >> 24 != 0).unwrap_or(first);
                (x0, x1) = (x0.min(first), x1.max(last + 1));
                (y0, y1) = (y0.min(y), y + 1);
                let covered = px0[first..=last].iter().enumerate();
                let covered = covered.filter(|(_, p)| *p >> 24 != 0);
                cells.mark_row(y, covered.map(|(x, _)| (first + x) as u32));
            }
            for x in 0..w {
                let (p, dp) = (px0[x], off0[x]);
                // The same pairs, in the same order, as texel by texel: right, then below.
                if x + 1 < w {
                    let d = diff(p, px0[x + 1]);
                    sum += d;
                    weighted += d as f64 * dp.max(off0[x + 1]) as f64;
                    n += 3;
                }
                if below {
                    let d = diff(p, px1[x]);
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
    Measured {
        covered: (x1 > 0).then(|| Rect::new(x0 as u32, y0, (x1 - x0) as u32, y1 - y0)),
        cells,
        gradient: sum as f32 / n as f32,
        depth_gradient: (weighted / n as f64) as f32,
    }
}
