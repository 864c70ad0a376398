//! Holes in a warped image: counted by kind, and filled without dragging foreground colour
//! across a depth edge.
//!
//! - A **crack** is a hole between samples of one surface (foreshortening, rounding): within
//!   [`CRACK_REACH`] pixels on two opposite sides there are samples of similar depth.
//! - A **disocclusion** is any other hole: a surface no reference saw, beside a depth edge
//!   or where the references end.
//!
//! Filling ([`Fill`]): pull-push (Gortler et al. 96) with the weights normalised as Kraus
//! 2009 does (sums of weighted colour and weight, weight capped at one per cell), where a
//! coarse cell keeps only its **farthest** samples (within the edge tolerance of the
//! farthest), so a disocclusion is filled from the background; or the background side
//! directly: the farthest of the nearest samples left, right, up and down. Filled pixels
//! take the depth of what filled them, so depth tests against geometry still work.

use super::is_filled;
use crate::images::{DepthImage, EMPTY};
use engine::Premul;

/// How far (pixels) a crack's two sides may be apart.
pub const CRACK_REACH: u32 = 2;

/// Holes by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HoleStats {
    pub cracks: u64,
    pub disocclusions: u64,
}

impl HoleStats {
    pub fn total(&self) -> u64 {
        self.cracks + self.disocclusions
    }
}

/// How holes are filled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fill {
    /// Left as holes.
    None,
    /// Depth-aware pull-push.
    PullPush,
    /// The background side: the farthest of the nearest samples in the four directions.
    Background,
}

/// Counts the holes of a warped image by kind; `edge` is the relative depth difference
/// that separates surfaces.
pub fn classify(image: &DepthImage, edge: f32) -> HoleStats {
    let (w, h) = (image.width(), image.height());
    let mut stats = HoleStats::default();
    let sample = |x: i64, y: i64| -> Option<f32> {
        if x < 0 || y < 0 || x >= w as i64 || y >= h as i64 {
            return None;
        }
        let i = (y as u32 * w + x as u32) as usize;
        is_filled(image.color[i]).then_some(image.depth[i])
    };
    // The nearest sample within reach from (x, y) along (dx, dy).
    let seek = |x: u32, y: u32, dx: i64, dy: i64| {
        (1..=CRACK_REACH as i64).find_map(|s| sample(x as i64 + dx * s, y as i64 + dy * s))
    };
    let similar = |a: f32, b: f32| a == b || (a - b).abs() <= edge * a.min(b);
    for y in 0..h {
        for x in 0..w {
            if is_filled(image.color[(y * w + x) as usize]) {
                continue;
            }
            let pair = |d: (i64, i64)| match (seek(x, y, d.0, d.1), seek(x, y, -d.0, -d.1)) {
                (Some(a), Some(b)) => similar(a, b),
                _ => false,
            };
            if pair((1, 0)) || pair((0, 1)) || pair((1, 1)) || pair((1, -1)) {
                stats.cracks += 1;
            } else {
                stats.disocclusions += 1;
            }
        }
    }
    stats
}

/// A pull-push pyramid level: weighted colour sums, weights, depths.
#[derive(Clone, Debug, Default)]
struct Level {
    w: u32,
    h: u32,
    color: Vec<Premul>,
    weight: Vec<f32>,
    depth: Vec<f32>,
}

/// Scratch memory of the fill, reused frame to frame.
#[derive(Debug, Default)]
pub struct Filler {
    levels: Vec<Level>,
    /// Background fill: the nearest farthest sample of each hole.
    best: Vec<Option<usize>>,
}

impl Filler {
    /// Fills the holes of `image` by `fill`; `edge` is the relative depth difference that
    /// separates surfaces. Returns the pixels filled.
    pub fn fill(&mut self, image: &mut DepthImage, fill: Fill, edge: f32) -> u64 {
        match fill {
            Fill::None => 0,
            Fill::PullPush => self.pull_push(image, edge),
            Fill::Background => background(image, &mut self.best),
        }
    }

    fn pull_push(&mut self, image: &mut DepthImage, edge: f32) -> u64 {
        let (w, h) = (image.width(), image.height());
        if w == 0 || h == 0 {
            return 0;
        }
        // Level 0: the image, weight 1 where filled.
        let mut count = 0;
        {
            if self.levels.is_empty() {
                self.levels.push(Level::default());
            }
            let l0 = &mut self.levels[0];
            l0.w = w;
            l0.h = h;
            l0.color.clear();
            l0.weight.clear();
            l0.depth.clear();
            for (c, d) in image.color.iter().zip(&image.depth) {
                let f = is_filled(*c);
                l0.color.push(if f { *c } else { Premul::TRANSPARENT });
                l0.weight.push(if f { 1.0 } else { 0.0 });
                l0.depth.push(if f { *d } else { EMPTY });
            }
        }
        // Pull: halve until one pixel.
        let mut k = 0;
        while self.levels[k].w > 1 || self.levels[k].h > 1 {
            if self.levels.len() == k + 1 {
                self.levels.push(Level::default());
            }
            let (fine, coarse) = self.levels.split_at_mut(k + 1);
            pull(&fine[k], &mut coarse[0], edge);
            k += 1;
        }
        let top = k;
        // Push: each level's missing weight taken from the (already complete) level above.
        for k in (0..top).rev() {
            let (fine, coarse) = self.levels.split_at_mut(k + 1);
            push(&mut fine[k], &coarse[0], edge);
        }
        let l0 = &self.levels[0];
        for i in 0..image.color.len() {
            if !is_filled(image.color[i]) && l0.weight[i] > 0.0 {
                image.color[i] = l0.color[i];
                image.depth[i] = l0.depth[i];
                count += 1;
            }
        }
        count
    }
}

/// One coarser level: each cell combines its up to 2 x 2 children, keeping only those
/// within `edge` of the farthest (the background), weights summed and capped at one.
fn pull(fine: &Level, coarse: &mut Level, edge: f32) {
    let (w, h) = (fine.w.div_ceil(2), fine.h.div_ceil(2));
    coarse.w = w;
    coarse.h = h;
    let n = (w * h) as usize;
    coarse.color.clear();
    coarse.color.resize(n, Premul::TRANSPARENT);
    coarse.weight.clear();
    coarse.weight.resize(n, 0.0);
    coarse.depth.clear();
    coarse.depth.resize(n, EMPTY);
    for y in 0..h {
        for x in 0..w {
            let kids = [(0, 0), (1, 0), (0, 1), (1, 1)]
                .map(|(dx, dy)| (2 * x + dx, 2 * y + dy))
                .map(|(fx, fy)| {
                    (fx < fine.w && fy < fine.h)
                        .then(|| (fy * fine.w + fx) as usize)
                        .filter(|&i| fine.weight[i] > 0.0)
                });
            let far = kids
                .iter()
                .flatten()
                .map(|&i| fine.depth[i])
                .fold(0.0f32, f32::max);
            let (mut c, mut wsum, mut dsum) = ([0.0f32; 4], 0.0f32, 0.0f32);
            for &i in kids.iter().flatten() {
                let d = fine.depth[i];
                if !(d >= far * (1.0 - edge) || d == far) {
                    continue;
                }
                let wt = fine.weight[i];
                let fc = fine.color[i];
                for (acc, v) in c.iter_mut().zip([fc.r, fc.g, fc.b, fc.a]) {
                    *acc += v * wt;
                }
                wsum += wt;
                dsum += if d.is_finite() { d * wt } else { 0.0 };
            }
            if wsum > 0.0 {
                let i = (y * w + x) as usize;
                let inv = 1.0 / wsum;
                // The cell's colour is the weighted mean; its weight is capped at one.
                coarse.color[i] = Premul {
                    r: c[0] * inv,
                    g: c[1] * inv,
                    b: c[2] * inv,
                    a: c[3] * inv,
                };
                coarse.weight[i] = wsum.min(1.0);
                coarse.depth[i] = if far.is_finite() { dsum * inv } else { far };
            }
        }
    }
}

/// Completes a level from the level above: `c = w c + (1 - w) c_parent` with the parent's
/// colour taken bilinearly (so fills are smooth), the weight becoming one where the
/// parent has any. A partly covered cell nearer than its parent by more than `edge` is
/// foreground beside a hole that the background continues into: it yields to the parent,
/// so foreground colour never flows into the hole.
fn push(fine: &mut Level, coarse: &Level, edge: f32) {
    for y in 0..fine.h {
        for x in 0..fine.w {
            let i = (y * fine.w + x) as usize;
            let wt = fine.weight[i];
            if wt >= 1.0 {
                continue;
            }
            let Some((pc, pd)) = parent(coarse, x, y, edge) else {
                continue;
            };
            let c = fine.color[i];
            let wt = if wt > 0.0 && fine.depth[i] < pd * (1.0 - edge) {
                0.0
            } else {
                wt
            };
            let k = 1.0 - wt;
            fine.color[i] = Premul {
                r: c.r * wt + pc.r * k,
                g: c.g * wt + pc.g * k,
                b: c.b * wt + pc.b * k,
                a: c.a * wt + pc.a * k,
            };
            if wt <= 0.0 {
                fine.depth[i] = pd;
            }
            fine.weight[i] = 1.0;
        }
    }
}

/// The coarse level's colour and depth under fine pixel `(x, y)`: bilinear over the
/// parent cells that hold something and lie within `edge` of the farthest of them (so a
/// hole beside foreground takes the background's colour).
fn parent(coarse: &Level, x: u32, y: u32, edge: f32) -> Option<(Premul, f32)> {
    // Fine pixel centre in coarse pixel units.
    let fx = (x as f32 + 0.5) * 0.5 - 0.5;
    let fy = (y as f32 + 0.5) * 0.5 - 0.5;
    let (x0, y0) = (fx.floor(), fy.floor());
    let (tx, ty) = (fx - x0, fy - y0);
    let taps = [
        (0, 0, (1.0 - tx) * (1.0 - ty)),
        (1, 0, tx * (1.0 - ty)),
        (0, 1, (1.0 - tx) * ty),
        (1, 1, tx * ty),
    ]
    .map(|(dx, dy, wt)| {
        let cx = (x0 as i64 + dx).clamp(0, coarse.w as i64 - 1) as u32;
        let cy = (y0 as i64 + dy).clamp(0, coarse.h as i64 - 1) as u32;
        let i = (cy * coarse.w + cx) as usize;
        (i, wt)
    });
    let far = taps
        .iter()
        .filter(|&&(i, wt)| coarse.weight[i] > 0.0 && wt > 0.0)
        .map(|&(i, _)| coarse.depth[i])
        .fold(0.0f32, f32::max);
    let (mut c, mut wsum) = ([0.0f32; 4], 0.0f32);
    for (i, wt) in taps {
        let d = coarse.depth[i];
        if coarse.weight[i] <= 0.0 || wt <= 0.0 || !(d >= far * (1.0 - edge) || d == far) {
            continue;
        }
        let p = coarse.color[i];
        for (acc, v) in c.iter_mut().zip([p.r, p.g, p.b, p.a]) {
            *acc += v * wt;
        }
        wsum += wt;
    }
    (wsum > 0.0).then(|| {
        let inv = 1.0 / wsum;
        (
            Premul {
                r: c[0] * inv,
                g: c[1] * inv,
                b: c[2] * inv,
                a: c[3] * inv,
            },
            far,
        )
    })
}

/// Fills each hole with the farthest of the nearest samples to its left, right, top and
/// bottom (read from the unfilled image). Returns the pixels filled.
fn background(image: &mut DepthImage, best: &mut Vec<Option<usize>>) -> u64 {
    let (w, h) = (image.width() as usize, image.height() as usize);
    if w == 0 || h == 0 {
        return 0;
    }
    // Nearest filled sample in each direction, by four sweeps.
    let filled = |i: usize| is_filled(image.color[i]);
    best.clear();
    best.resize(w * h, None);
    // One sweep along a line of pixels: each hole considers the last sample passed, and
    // keeps the farthest of those its sweeps offer.
    let mut sweep = |line: &mut dyn Iterator<Item = usize>| {
        let mut last: Option<usize> = None;
        for i in line {
            if filled(i) {
                last = Some(i);
            } else if let Some(s) = last {
                if best[i].is_none_or(|b| image.depth[s] > image.depth[b]) {
                    best[i] = Some(s);
                }
            }
        }
    };
    for y in 0..h {
        sweep(&mut (y * w..(y + 1) * w));
        sweep(&mut (y * w..(y + 1) * w).rev());
    }
    for x in 0..w {
        sweep(&mut (0..h).map(|y| y * w + x));
        sweep(&mut (0..h).rev().map(|y| y * w + x));
    }
    let mut count = 0;
    for (i, b) in best.iter().enumerate() {
        if let Some(s) = *b {
            image.color[i] = image.color[s];
            image.depth[i] = image.depth[s];
            count += 1;
        }
    }
    count
}
