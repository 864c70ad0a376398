//! Semi-global matching (Hirschmüller 2008): a census transform of each image (a 5x5
//! window's comparisons with its centre, 24 bits), the Hamming distance between census
//! codes as the matching cost of every pixel and disparity, costs aggregated along eight
//! paths (`L(p, d) = C(p, d) + min(L(p - r, d), L(p - r, d ± 1) + P1, min_k L(p - r, k) +
//! P2) - min_k L(p - r, k)`), their sum's best disparity per pixel refined by a parabola,
//! and checked as [`super::BlockMatch`] checks: unique, and consistent with the right
//! image's best match (read from the same sums along the other diagonal of the volume).
//!
//! The paths run in two raster passes (Hirschmüller's own scheme): top-left to bottom-right
//! for the four directions that arrive from the left and from above, and back for the
//! other four, on two threads, each keeping only the previous row of its paths and
//! writing its sums as 16-bit integers (a path's cost is at most the largest census cost
//! plus `P2`, so eight fit). Costs are computed row by row as a pass reaches them, so
//! memory is the two passes' sums, 4 bytes per pixel and disparity. Integer sums: the same
//! answer at any thread count.

use super::block::{left_right_checked, parabola, textured, MIN_TEXTURE};
use super::{Disparity, StereoError};
use rayon::prelude::*;

/// Semi-global matching's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sgm {
    /// Disparities `0..max_disparity` are searched.
    pub max_disparity: u32,
    /// The penalties of a disparity change of one, and of more, between neighbours on a
    /// path (in census bits; above 4,000 they act as 4,000).
    pub p1: u16,
    pub p2: u16,
    /// The best sum must be below `1 - uniqueness` times the best away from it.
    pub uniqueness: f32,
    /// Largest difference (pixels) between the left and the right image's matches.
    pub lr_tolerance: f32,
    /// Least luminance range (of 1) over a pixel's 5x5 window for it to be matched
    /// ([`super::block::MIN_TEXTURE`] by default; 0 takes what the paths give flat regions).
    pub min_texture: f32,
}

impl Default for Sgm {
    fn default() -> Self {
        Sgm {
            max_disparity: 64,
            p1: 3,
            p2: 20,
            uniqueness: 0.03,
            lr_tolerance: 1.0,
            min_texture: MIN_TEXTURE,
        }
    }
}

/// The 5x5 census code of each pixel of a `w` x `h` luminance image (edges clamped): bit
/// per neighbour, row by row of the window, set where the neighbour is darker than the
/// centre. Row by row in parallel; each of the window's 24 offsets a pass over the row
/// (padded by two clamped pixels each side), which the compiler vectorises.
fn census(image: &[f32], w: usize, h: usize) -> Vec<u32> {
    let mut codes = vec![0u32; w * h];
    codes.par_chunks_mut(w).enumerate().for_each(|(y, codes)| {
        let row = |dy: isize| {
            let yy = (y as isize + dy).clamp(0, h as isize - 1) as usize;
            let r = &image[yy * w..(yy + 1) * w];
            let mut padded = Vec::with_capacity(w + 4);
            padded.extend([r[0], r[0]]);
            padded.extend_from_slice(r);
            padded.extend([r[w - 1], r[w - 1]]);
            padded
        };
        let centre = &image[y * w..(y + 1) * w];
        for dy in -2..=2isize {
            let padded = row(dy);
            for dx in -2..=2isize {
                if dx == 0 && dy == 0 {
                    continue;
                }
                let shifted = &padded[(2 + dx) as usize..][..w];
                for ((code, &n), &c) in codes.iter_mut().zip(shifted).zip(centre) {
                    *code = *code << 1 | u32::from(n < c);
                }
            }
        }
    });
    codes
}

impl Sgm {
    /// The left image's disparities (`left` and `right` luminance, `width` x `height`).
    /// An error when the images are not both `width x height`.
    pub fn run(
        &self,
        left: &[f32],
        right: &[f32],
        width: u32,
        height: u32,
    ) -> Result<Disparity, StereoError> {
        if let Some(empty) = Disparity::inputs(left, right, width, height)? {
            return Ok(empty);
        }
        let (w, h) = (width as usize, height as usize);
        let n = self.max_disparity.max(1) as usize;
        let (cl, cr) = rayon::join(|| census(left, w, h), || census(right, w, h));
        let codes = Codes {
            left: &cl,
            right: &cr,
            w,
            n,
        };
        let (forward, backward) = rayon::join(
            || self.pass(&codes, h, false),
            || self.pass(&codes, h, true),
        );
        // Per row: the eight paths' sums, the left image's best disparities, and the right
        // image's (right pixel (xr, y): the best d over S(xr + d, y, d)).
        let mut left_best = vec![(f32::INFINITY, false); w * h];
        let mut right_best = vec![f32::INFINITY; w * h];
        let row = w * n;
        left_best
            .par_chunks_mut(w)
            .zip(right_best.par_chunks_mut(w))
            .zip(forward.par_chunks(row).zip(backward.par_chunks(row)))
            .for_each(|((lb, rb), (f, b))| {
                let sums: Vec<u16> = f.iter().zip(b).map(|(f, b)| f + b).collect();
                for (x, best) in lb.iter_mut().enumerate() {
                    *best = choose(&sums[x * n..(x + 1) * n], self.uniqueness);
                }
                let mut diagonal = vec![u16::MAX; n];
                for (xr, best) in rb.iter_mut().enumerate() {
                    for (d, s) in diagonal.iter_mut().enumerate() {
                        let x = xr + d;
                        *s = if x < w { sums[x * n + d] } else { u16::MAX };
                    }
                    *best = choose(&diagonal, 0.0).0;
                }
            });
        Ok(left_right_checked(
            width,
            height,
            &left_best,
            |i| right_best[i],
            self.lr_tolerance,
            &textured(left, w, h, self.min_texture),
        ))
    }

    /// One raster pass over the image: forward (rows top to bottom, pixels left to right)
    /// along the four directions arriving from the left, above-left, above and above-right;
    /// or (`back`) the mirror of it, the other four. Returns each pixel's sum of its four
    /// paths' costs, `n` a pixel, row-major.
    fn pass(&self, codes: &Codes, h: usize, back: bool) -> Vec<u16> {
        let (w, n) = (codes.w, codes.n);
        // A path's costs at a pixel, padded with a `u16::MAX` on each side so that the
        // neighbours `d - 1` and `d + 1` are plain shifted slices.
        let m = n + 2;
        let padded = |len: usize| {
            let mut v = vec![0u16; len * m];
            for p in v.chunks_exact_mut(m) {
                (p[0], p[m - 1]) = (u16::MAX, u16::MAX);
            }
            v
        };
        // Previous and current rows of the three paths from the row before (above-left,
        // above, above-right in the pass's own orientation), and the path from the left.
        let (mut prev, mut cur) = ([(); 3].map(|_| padded(w)), [(); 3].map(|_| padded(w)));
        let (mut prev_low, mut cur_low) = (
            [(); 3].map(|_| vec![0u16; w]),
            [(); 3].map(|_| vec![0u16; w]),
        );
        // The path from the left: the previous pixel's costs and the current one's.
        let (mut left, mut left_next) = (padded(1), padded(1));
        let mut left_low = 0u16;
        let mut cost = vec![0u8; w * n];
        let mut sums = vec![0u16; w * h * n];
        let (p1, p2) = (self.p1.min(MAX_PENALTY), self.p2.min(MAX_PENALTY));
        for vy in 0..h {
            let y = if back { h - 1 - vy } else { vy };
            codes.row(y, &mut cost);
            for vx in 0..w {
                let x = if back { w - 1 - vx } else { vx };
                let c = &cost[x * n..(x + 1) * n];
                let mut out = [0u16; 4];
                // From the left (in the pass's orientation).
                out[0] = if vx == 0 {
                    start(c, &mut left_next)
                } else {
                    step(c, &left, left_low, &mut left_next, p1, p2)
                };
                left_low = out[0];
                std::mem::swap(&mut left, &mut left_next);
                // From the row before: above-left, above, above-right.
                for (k, dx) in [-1isize, 0, 1].into_iter().enumerate() {
                    let from = vx as isize + dx;
                    let o = &mut cur[k][vx * m..(vx + 1) * m];
                    out[k + 1] = if vy == 0 || from < 0 || from >= w as isize {
                        start(c, o)
                    } else {
                        let f = from as usize;
                        step(c, &prev[k][f * m..(f + 1) * m], prev_low[k][f], o, p1, p2)
                    };
                    cur_low[k][vx] = out[k + 1];
                }
                let s = &mut sums[(y * w + x) * n..][..n];
                let at = |k: usize| &cur[k][vx * m + 1..][..n];
                let (a, b, c, d) = (&left[1..=n], at(0), at(1), at(2));
                for i in 0..n {
                    s[i] = a[i] + b[i] + c[i] + d[i];
                }
            }
            std::mem::swap(&mut prev, &mut cur);
            std::mem::swap(&mut prev_low, &mut cur_low);
        }
        sums
    }
}

/// The largest penalty used (larger ones act as this): eight paths' sums of census costs
/// (at most 24) plus it stay below `u16::MAX`, the sums' "none" mark.
const MAX_PENALTY: u16 = 4000;

/// The census codes of both images, and what a row of matching costs needs.
struct Codes<'a> {
    left: &'a [u32],
    right: &'a [u32],
    w: usize,
    n: usize,
}

impl Codes<'_> {
    /// Row `y`'s matching costs, `n` a pixel: left pixel `(x, y)` at disparity `d` against
    /// right pixel `(x - d, y)`; past the right image's edge, the cost of its first
    /// column's match (no information).
    fn row(&self, y: usize, cost: &mut [u8]) {
        let (w, n) = (self.w, self.n);
        let (left, right) = (
            &self.left[y * w..(y + 1) * w],
            &self.right[y * w..(y + 1) * w],
        );
        for (x, c) in cost.chunks_exact_mut(n).enumerate() {
            let l = left[x];
            if x + 1 >= n {
                // Right pixels x, x - 1, ..., x - n + 1.
                for (c, &r) in c.iter_mut().zip(right[x + 1 - n..=x].iter().rev()) {
                    *c = (l ^ r).count_ones() as u8;
                }
            } else {
                for (d, c) in c.iter_mut().enumerate() {
                    *c = (l ^ right[x.saturating_sub(d)]).count_ones() as u8;
                }
            }
        }
    }
}

/// A path's first pixel: its costs are the matching costs. Returns their least.
#[inline(always)]
fn start(c: &[u8], out: &mut [u16]) -> u16 {
    let mut low = u16::MAX;
    for (o, &c) in out[1..=c.len()].iter_mut().zip(c) {
        *o = u16::from(c);
        low = low.min(*o);
    }
    low
}

/// A path's next pixel from the previous one's costs `prev` (padded) and their least
/// `low`: `L(d) = C(d) + min(L'(d), L'(d ± 1) + P1, low + P2) - low`, into `out` (padded).
/// Returns the least of the new costs. Never below zero: every term of the `min` is at
/// least `low`.
#[inline(always)]
fn step(c: &[u8], prev: &[u16], low: u16, out: &mut [u16], p1: u16, p2: u16) -> u16 {
    let n = c.len();
    let jump = low.saturating_add(p2);
    let (below, at, above) = (&prev[..n], &prev[1..=n], &prev[2..n + 2]);
    let out = &mut out[1..=n];
    let mut least = u16::MAX;
    for d in 0..n {
        let best = at[d]
            .min(below[d].saturating_add(p1))
            .min(above[d].saturating_add(p1))
            .min(jump);
        let v = u16::from(c[d]) + best - low;
        out[d] = v;
        least = least.min(v);
    }
    least
}

/// The best disparity of one pixel's sums (`u16::MAX`: none there), refined by a parabola,
/// and whether it is unique (below `1 - uniqueness` times the best more than one away).
/// The first of equal bests. Plain minimums over the slice (`u16::MAX` never wins while
/// anything else is there), which the compiler vectorises.
fn choose(sums: &[u16], uniqueness: f32) -> (f32, bool) {
    let least = |s: &[u16]| s.iter().fold(u16::MAX, |m, &v| m.min(v));
    let c = least(sums);
    if c == u16::MAX {
        return (f32::INFINITY, false);
    }
    let k = sums.iter().position(|&s| s == c).unwrap_or(0);
    let n = sums.len();
    let second = least(&sums[..k.saturating_sub(1)]).min(least(&sums[(k + 2).min(n)..]));
    // A least sum at the range's far end is not known to be a minimum: the true one may
    // lie beyond the search.
    let unique =
        (second == u16::MAX || (c as f32) < (1.0 - uniqueness) * second as f32) && k + 1 < n;
    let near = |j: Option<usize>| j.and_then(|j| sums.get(j)).filter(|s| **s != u16::MAX);
    let d = match (near(k.checked_sub(1)), near(Some(k + 1))) {
        (Some(&a), Some(&b)) => parabola(k, a as f32, c as f32, b as f32),
        _ => k as f32,
    };
    (d, unique)
}

#[cfg(test)]
mod tests;
