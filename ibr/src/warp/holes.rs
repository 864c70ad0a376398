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
//!
//! Depth is read as the warp stores it, as disparity: "farther than `d` by more than a
//! relative `edge`" is `δ (1 - edge) > δ'`-style comparisons, exact equivalents of the depth
//! ones. Pull-push averages the stored bytes (sRGB-encoded, premultiplied) and runs row
//! by row on the thread pool; the pixels it gives do not depend on the thread count.

use super::warped::{Warped, HOLE};
use rayon::prelude::*;

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

/// Whether two disparities are of one surface: depths within a relative `edge` of each
/// other (`|z_a - z_b| <= edge min(z)` is `|δ_a - δ_b| <= edge min(δ)`).
#[inline]
fn similar(a: f32, b: f32, edge: f32) -> bool {
    a == b || (a - b).abs() <= edge * a.min(b)
}

/// Counts the holes of a warped image by kind; `edge` is the relative depth difference
/// that separates surfaces.
pub fn classify(image: &Warped, edge: f32) -> HoleStats {
    let (w, h) = (image.width(), image.height());
    let sample = |x: i64, y: i64| -> Option<f32> {
        if x < 0 || y < 0 || x >= w as i64 || y >= h as i64 {
            return None;
        }
        let d = image.disparity[(y as u32 * w + x as u32) as usize];
        (d >= 0.0).then_some(d)
    };
    // The nearest sample within reach from (x, y) along (dx, dy).
    let seek = |x: u32, y: u32, dx: i64, dy: i64| {
        (1..=CRACK_REACH as i64).find_map(|s| sample(x as i64 + dx * s, y as i64 + dy * s))
    };
    (0..h)
        .into_par_iter()
        .map(|y| {
            let mut stats = HoleStats::default();
            for x in 0..w {
                if image.disparity[(y * w + x) as usize] >= 0.0 {
                    continue;
                }
                let pair = |d: (i64, i64)| match (seek(x, y, d.0, d.1), seek(x, y, -d.0, -d.1)) {
                    (Some(a), Some(b)) => similar(a, b, edge),
                    _ => false,
                };
                if pair((1, 0)) || pair((0, 1)) || pair((1, 1)) || pair((1, -1)) {
                    stats.cracks += 1;
                } else {
                    stats.disocclusions += 1;
                }
            }
            stats
        })
        .reduce(HoleStats::default, |a, b| HoleStats {
            cracks: a.cracks + b.cracks,
            disocclusions: a.disocclusions + b.disocclusions,
        })
}

/// A pull-push pyramid level above the image: weighted colour means (stored byte values),
/// weights, disparities.
#[derive(Clone, Debug, Default)]
struct Level {
    w: u32,
    h: u32,
    color: Vec<[f32; 4]>,
    weight: Vec<f32>,
    disparity: Vec<f32>,
}

impl Level {
    fn reset(&mut self, w: u32, h: u32) {
        let n = (w * h) as usize;
        self.w = w;
        self.h = h;
        self.color.clear();
        self.color.resize(n, [0.0; 4]);
        self.weight.clear();
        self.weight.resize(n, 0.0);
        self.disparity.clear();
        self.disparity.resize(n, HOLE);
    }
}

/// Scratch memory of the fill, reused frame to frame.
#[derive(Debug, Default)]
pub struct Filler {
    /// Levels 1, 2, ... of the pyramid (level 0 is the image).
    levels: Vec<Level>,
    /// Background fill: the nearest farthest sample of each hole.
    best: Vec<Option<usize>>,
}

impl Filler {
    /// Fills the holes of `image` by `fill`; `edge` is the relative depth difference that
    /// separates surfaces. Returns the pixels filled.
    pub fn fill(&mut self, image: &mut Warped, fill: Fill, edge: f32) -> u64 {
        match fill {
            Fill::None => 0,
            Fill::PullPush => self.pull_push(image, edge),
            Fill::Background => background(image, &mut self.best),
        }
    }

    fn pull_push(&mut self, image: &mut Warped, edge: f32) -> u64 {
        let (w, h) = (image.width(), image.height());
        if w == 0 || h == 0 || (w == 1 && h == 1) {
            return 0;
        }
        // Pull: level 1 from the image, then halve until one pixel.
        if self.levels.is_empty() {
            self.levels.push(Level::default());
        }
        pull_image(image, &mut self.levels[0], edge);
        let mut k = 0;
        while self.levels[k].w > 1 || self.levels[k].h > 1 {
            if self.levels.len() == k + 1 {
                self.levels.push(Level::default());
            }
            let (fine, coarse) = self.levels.split_at_mut(k + 1);
            pull(&fine[k], &mut coarse[0], edge);
            k += 1;
        }
        // Push: each level's missing weight taken from the (already complete) level above;
        // at the image only its holes change.
        for k in (0..k).rev() {
            let (fine, coarse) = self.levels.split_at_mut(k + 1);
            push(&mut fine[k], &coarse[0], edge);
        }
        push_image(image, &self.levels[0], edge)
    }
}

/// One coarser level: each cell combines its up to 2 x 2 children, keeping only those
/// within `edge` of the farthest (the background), weights summed and capped at one.
fn pull(fine: &Level, coarse: &mut Level, edge: f32) {
    let (fw, fh) = (fine.w, fine.h);
    let (w, h) = (fw.div_ceil(2), fh.div_ceil(2));
    coarse.reset(w, h);
    let keep = 1.0 - edge;
    coarse
        .color
        .par_chunks_mut(w as usize)
        .zip(coarse.weight.par_chunks_mut(w as usize))
        .zip(coarse.disparity.par_chunks_mut(w as usize))
        .enumerate()
        .for_each(|(y, ((color, weight), disparity))| {
            for x in 0..w as usize {
                let mut kids = [([0.0f32; 4], 0.0f32, HOLE); 4];
                let mut far = f32::INFINITY;
                for (k, (dx, dy)) in [(0, 0), (1, 0), (0, 1), (1, 1)].into_iter().enumerate() {
                    let (fx, fy) = (2 * x + dx, 2 * y + dy);
                    if fx < fw as usize && fy < fh as usize {
                        let i = fy * fw as usize + fx;
                        kids[k] = (fine.color[i], fine.weight[i], fine.disparity[i]);
                        if kids[k].1 > 0.0 {
                            far = far.min(kids[k].2);
                        }
                    }
                }
                let (mut c, mut wsum, mut dsum) = ([0.0f32; 4], 0.0f32, 0.0f32);
                for (fc, wt, d) in kids {
                    // Within `edge` of the farthest: `z >= z_far (1 - edge)`.
                    if wt <= 0.0 || !(d * keep <= far || d == far) {
                        continue;
                    }
                    for (acc, v) in c.iter_mut().zip(fc) {
                        *acc += v * wt;
                    }
                    wsum += wt;
                    dsum += d * wt;
                }
                if wsum > 0.0 {
                    let inv = 1.0 / wsum;
                    color[x] = c.map(|v| v * inv);
                    weight[x] = wsum.min(1.0);
                    disparity[x] = dsum * inv;
                }
            }
        });
}

/// Level 1 from the image: [`pull`] for cells whose children weigh one where filled, read
/// two image rows at a time.
fn pull_image(image: &Warped, coarse: &mut Level, edge: f32) {
    let (fw, fh) = (image.width() as usize, image.height() as usize);
    let (w, h) = (fw.div_ceil(2), fh.div_ceil(2));
    coarse.reset(w as u32, h as u32);
    let keep = 1.0 - edge;
    coarse
        .color
        .par_chunks_mut(w)
        .zip(coarse.weight.par_chunks_mut(w))
        .zip(coarse.disparity.par_chunks_mut(w))
        .enumerate()
        .for_each(|(y, ((color, weight), disparity))| {
            let r0 = 2 * y * fw;
            let r1 = if 2 * y + 1 < fh { r0 + fw } else { r0 };
            let rows = [r0, r1];
            let both_rows = 2 * y + 1 < fh;
            for x in 0..w {
                let x1 = if 2 * x + 1 < fw { 2 * x + 1 } else { 2 * x };
                let both_cols = 2 * x + 1 < fw;
                // The cell's children: (index, present).
                let kids = [
                    (rows[0] + 2 * x, true),
                    (rows[0] + x1, both_cols),
                    (rows[1] + 2 * x, both_rows),
                    (rows[1] + x1, both_rows && both_cols),
                ];
                let mut far = f32::INFINITY;
                for &(i, present) in &kids {
                    let d = image.disparity[i];
                    if present && d >= 0.0 {
                        far = far.min(d);
                    }
                }
                if far == f32::INFINITY {
                    continue;
                }
                let (mut c, mut wsum, mut dsum) = ([0.0f32; 4], 0.0f32, 0.0f32);
                for &(i, present) in &kids {
                    let d = image.disparity[i];
                    if !present || d < 0.0 || !(d * keep <= far || d == far) {
                        continue;
                    }
                    let b = image.color[i].to_le_bytes();
                    for (acc, v) in c.iter_mut().zip(b) {
                        *acc += f32::from(v);
                    }
                    wsum += 1.0;
                    dsum += d;
                }
                let inv = 1.0 / wsum;
                color[x] = c.map(|v| v * inv);
                weight[x] = wsum.min(1.0);
                disparity[x] = dsum * inv;
            }
        });
}

/// Completes a level from the level above: `c = w c + (1 - w) c_parent` with the parent's
/// colour taken bilinearly (so fills are smooth), the weight becoming one where the
/// parent has any. A partly covered cell nearer than its parent by more than `edge` is
/// foreground beside a hole that the background continues into: it yields to the parent,
/// so foreground colour never flows into the hole.
fn push(fine: &mut Level, coarse: &Level, edge: f32) {
    let w = fine.w as usize;
    let keep = 1.0 - edge;
    fine.color
        .par_chunks_mut(w)
        .zip(fine.weight.par_chunks_mut(w))
        .zip(fine.disparity.par_chunks_mut(w))
        .enumerate()
        .for_each(|(y, ((color, weight), disparity))| {
            for x in 0..w {
                let wt = weight[x];
                if wt >= 1.0 {
                    continue;
                }
                let Some((pc, pd)) = parent(coarse, x as u32, y as u32, edge) else {
                    continue;
                };
                // Nearer than the parent by more than `edge`: `z < z_parent (1 - edge)`.
                let wt = if wt > 0.0 && disparity[x] * keep > pd {
                    0.0
                } else {
                    wt
                };
                let k = 1.0 - wt;
                let c = color[x];
                color[x] = std::array::from_fn(|i| c[i] * wt + pc[i] * k);
                if wt <= 0.0 {
                    disparity[x] = pd;
                }
                weight[x] = 1.0;
            }
        });
}

/// Fills the image's holes from level 1 (its samples stay as they are). Returns the pixels
/// filled.
fn push_image(image: &mut Warped, coarse: &Level, edge: f32) -> u64 {
    let w = image.width() as usize;
    image
        .color
        .par_chunks_mut(w)
        .zip(image.disparity.par_chunks_mut(w))
        .enumerate()
        .map(|(y, (color, disparity))| {
            let mut filled = 0;
            for x in 0..w {
                if disparity[x] >= 0.0 {
                    continue;
                }
                let Some((pc, pd)) = parent(coarse, x as u32, y as u32, edge) else {
                    continue;
                };
                let byte = |v: f32| (v + 0.5).clamp(0.0, 255.0) as u8;
                color[x] = u32::from_le_bytes(pc.map(byte));
                disparity[x] = pd;
                filled += 1;
            }
            filled
        })
        .sum()
}

/// The coarse level's colour and disparity under fine pixel `(x, y)`: bilinear over the
/// parent cells that hold something and lie within `edge` of the farthest of them (so a
/// hole beside foreground takes the background's colour).
fn parent(coarse: &Level, x: u32, y: u32, edge: f32) -> Option<([f32; 4], f32)> {
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
        .map(|&(i, _)| coarse.disparity[i])
        .fold(f32::INFINITY, f32::min);
    let keep = 1.0 - edge;
    let (mut c, mut wsum) = ([0.0f32; 4], 0.0f32);
    for (i, wt) in taps {
        let d = coarse.disparity[i];
        if coarse.weight[i] <= 0.0 || wt <= 0.0 || !(d * keep <= far || d == far) {
            continue;
        }
        for (acc, v) in c.iter_mut().zip(coarse.color[i]) {
            *acc += v * wt;
        }
        wsum += wt;
    }
    (wsum > 0.0).then(|| {
        let inv = 1.0 / wsum;
        (c.map(|v| v * inv), far)
    })
}

/// Fills each hole with the farthest of the nearest samples to its left, right, top and
/// bottom (read from the unfilled image). Returns the pixels filled.
fn background(image: &mut Warped, best: &mut Vec<Option<usize>>) -> u64 {
    let (w, h) = (image.width() as usize, image.height() as usize);
    if w == 0 || h == 0 {
        return 0;
    }
    let disparity = &image.disparity;
    best.clear();
    best.resize(w * h, None);
    // One sweep along a line of pixels: each hole considers the last sample passed, and
    // keeps the farthest (least disparity) of those its sweeps offer.
    let mut sweep = |line: &mut dyn Iterator<Item = usize>| {
        let mut last: Option<usize> = None;
        for i in line {
            if disparity[i] >= 0.0 {
                last = Some(i);
            } else if let Some(s) = last {
                if best[i].is_none_or(|b| disparity[s] < disparity[b]) {
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
            image.disparity[i] = image.disparity[s];
            count += 1;
        }
    }
    count
}
