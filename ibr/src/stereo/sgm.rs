//! Semi-global matching (Hirschmüller 2008): a census transform of each image (a 5x5
//! window's comparisons with its centre, 24 bits), the Hamming distance between census
//! codes as the matching cost of every pixel and disparity, drawn toward twice the pair's
//! match at half width and a quarter height (`prior`: coarse to fine, so that a
//! repeated pattern's aliases do not win), costs aggregated along eight
//! paths (`L(p, d) = C(p, d) + min(L(p - r, d), L(p - r, d ± 1) + P1, min_k L(p - r, k) +
//! P2) - min_k L(p - r, k)`), their sum's best disparity per pixel refined by a parabola,
//! and checked as [`super::BlockMatch`] checks: unique, and consistent with the right
//! image's best match (read from the same sums along the other diagonal of the volume).
//!
//! The paths run in two raster passes (Hirschmüller's own scheme): top-left to bottom-right
//! for the four directions that arrive from the left and from above, and back for the
//! other four, on two threads, each keeping only the previous row of its paths and
//! writing its sums of four. A path's cost is at most the largest census cost (24) plus
//! `P2`, so with the default penalties paths are bytes (32 lanes to an AVX2 vector) and so
//! are a pass's sums of four; larger penalties take 16 bits, with the same results. The
//! matching costs are computed once, a byte per pixel and disparity, for both passes; with
//! the passes' sums that is 3 bytes per pixel and disparity (5 with a large `P2`), kept in
//! [`SgmBuffers`] from one pair to the next. Integer sums: the same answer at any thread
//! count.

use super::block::{left_right_checked, parabola, textured, MIN_TEXTURE};
use super::{Disparity, StereoError};
use rayon::prelude::*;

/// Semi-global matching's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sgm {
    /// Disparities `0..max_disparity` are searched (at most 65,535).
    pub max_disparity: u32,
    /// The penalties of a disparity change of one, and of more, between neighbours on a
    /// path (in census bits; above 4,000 they act as 4,000).
    pub p1: u16,
    /// The penalty of a disparity change of more than one (census bits).
    pub p2: u16,
    /// The best sum must be below `1 - uniqueness` times the best away from it.
    pub uniqueness: f32,
    /// Largest difference (pixels) between the left and the right image's matches.
    pub lr_tolerance: f32,
    /// Least luminance range (of 1) over a pixel's 5x5 window for it to be matched
    /// ([`super::block::MIN_TEXTURE`] by default; 0 takes what the paths give flat regions).
    pub min_texture: f32,
    /// Coarse to fine (`prior`): the pair is matched at half width (a quarter height)
    /// first, and each matching cost raised by one per pixel of disparity beyond 3 from
    /// twice the small match, by at most this (0: off; above 8 it acts as 8).
    pub prior: u8,
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
            prior: 4,
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

/// Memory semi-global matching reuses from one pair to the next: the two passes' sums, 2
/// bytes per pixel and disparity (4 with a large P2). Keep one beside an [`Sgm`] to match a
/// stream of pairs ([`Sgm::run_with`]) without allocating, and touching fresh pages, every
/// time.
#[derive(Clone, Debug, Default)]
pub struct SgmBuffers {
    /// Matching costs, a byte per pixel and disparity.
    costs: Vec<u8>,
    narrow: [Vec<u8>; 2],
    wide: [Vec<u16>; 2],
    /// Each pixel's expected disparity, and the small match's buffers.
    expected: Vec<u16>,
    coarse: Option<Box<SgmBuffers>>,
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
        self.run_with(&mut SgmBuffers::default(), left, right, width, height)
    }

    /// [`Sgm::run`], in `buffers`' memory.
    pub fn run_with(
        &self,
        buffers: &mut SgmBuffers,
        left: &[f32],
        right: &[f32],
        width: u32,
        height: u32,
    ) -> Result<Disparity, StereoError> {
        if let Some(empty) = Disparity::inputs(left, right, width, height)? {
            return Ok(empty);
        }
        let (w, h) = (width as usize, height as usize);
        // (At most 65,535: disparities are kept as 16-bit integers.)
        let n = self.max_disparity.clamp(1, u32::from(u16::MAX)) as usize;
        let cap = self.prior.min(prior::MAX_PRIOR);
        let ((cl, cr), ()) = rayon::join(
            || rayon::join(|| census(left, w, h), || census(right, w, h)),
            || {
                buffers.expected.clear();
                if cap > 0 {
                    let coarse = buffers.coarse.get_or_insert_with(Box::default);
                    let images = (left, right);
                    prior::expected(self, coarse, images, (w, h), &mut buffers.expected);
                }
            },
        );
        let codes = Codes {
            left: &cl,
            right: &cr,
            expected: &buffers.expected,
            prior: prior::Prior::new(n, cap),
            w,
            n,
        };
        // Every pixel's matching costs, computed once for both passes, row by row.
        let costs = &mut buffers.costs;
        costs.resize(w * h * n, 0);
        costs
            .par_chunks_mut(w * n)
            .enumerate()
            .for_each(|(y, row)| codes.row(y, row));
        let costs = &buffers.costs[..];
        // Path costs fit in bytes while the largest census cost plus P2 does (twice the
        // lanes a vector), and a pass's sums of four while four times that does (half the
        // memory); the same sums either way.
        let p2 = u32::from(self.p2.min(MAX_PENALTY));
        let max_cost = u32::from(MAX_CENSUS + cap);
        let path_bytes = max_cost + p2 < u32::from(u8::MAX);
        let sum_bytes = 4 * (max_cost + p2) < u32::from(u8::MAX);
        let mut left_best = vec![(f32::INFINITY, false); w * h];
        let mut right_best = vec![f32::INFINITY; w * h];
        let best = (&mut left_best[..], &mut right_best[..]);
        match (path_bytes, sum_bytes) {
            (true, true) => self.aggregate::<u8, u8>(costs, (w, n), &mut buffers.narrow, best),
            (true, false) => self.aggregate::<u8, u16>(costs, (w, n), &mut buffers.wide, best),
            _ => self.aggregate::<u16, u16>(costs, (w, n), &mut buffers.wide, best),
        }
        Ok(left_right_checked(
            width,
            height,
            &left_best,
            |i| right_best[i],
            self.lr_tolerance,
            &textured(left, w, h, self.min_texture),
        ))
    }

    /// Both passes into `sums` (in paths of `L`, stored as `T`), side by side, then per row
    /// the eight paths' sums, the left image's best disparities and the right image's
    /// (right pixel (xr, y): the best d over S(xr + d, y, d)) into `best`.
    fn aggregate<L: Lane, T: Stored>(
        &self,
        costs: &[u8],
        (w, n): (usize, usize),
        sums: &mut [Vec<T>; 2],
        (left_best, right_best): (&mut [(f32, bool)], &mut [f32]),
    ) {
        let [forward, backward] = sums;
        for s in [&mut *forward, &mut *backward] {
            s.resize(costs.len(), T::default());
        }
        rayon::join(
            || self.pass::<L, T>(costs, (w, n), false, forward),
            || self.pass::<L, T>(costs, (w, n), true, backward),
        );
        let row = w * n;
        left_best
            .par_chunks_mut(w)
            .zip(right_best.par_chunks_mut(w))
            .zip(forward.par_chunks(row).zip(backward.par_chunks(row)))
            .for_each_init(
                || (Vec::new(), Vec::new()),
                |(sums, low), ((lb, rb), (f, b))| {
                    sums.clear();
                    sums.extend(f.iter().zip(b.iter()).map(|(f, b)| f.load() + b.load()));
                    for (x, best) in lb.iter_mut().enumerate() {
                        *best = choose(&sums[x * n..(x + 1) * n], self.uniqueness);
                    }
                    choose_right(sums, n, low, rb);
                },
            );
    }

    /// One raster pass over the image: forward (rows top to bottom, pixels left to right)
    /// along the four directions arriving from the left, above-left, above and above-right;
    /// or (`back`) the mirror of it, the other four. Returns each pixel's sum of its four
    /// paths' costs, `n` a pixel, row-major.
    fn pass<L: Lane, T: Stored>(
        &self,
        costs: &[u8],
        (w, n): (usize, usize),
        back: bool,
        sums: &mut [T],
    ) {
        let h = costs.len() / (w * n).max(1);
        // A path's costs at a pixel, padded with a `u16::MAX` on each side so that the
        // neighbours `d - 1` and `d + 1` are plain shifted slices.
        let m = n + 2;
        let padded = |len: usize| {
            let mut v = vec![L::default(); len * m];
            for p in v.chunks_exact_mut(m) {
                (p[0], p[m - 1]) = (L::NONE, L::NONE);
            }
            v
        };
        // Previous and current rows of the three paths from the row before (above-left,
        // above, above-right in the pass's own orientation), and the path from the left.
        let (mut prev, mut cur) = ([(); 3].map(|_| padded(w)), [(); 3].map(|_| padded(w)));
        let (mut prev_low, mut cur_low) = (
            [(); 3].map(|_| vec![L::default(); w]),
            [(); 3].map(|_| vec![L::default(); w]),
        );
        // The path from the left: the previous pixel's costs and the current one's.
        let (mut left, mut left_next) = (padded(1), padded(1));
        let mut left_low = L::default();
        let (p1, p2) = (
            L::penalty(self.p1.min(MAX_PENALTY)),
            L::penalty(self.p2.min(MAX_PENALTY)),
        );
        for vy in 0..h {
            let y = if back { h - 1 - vy } else { vy };
            let cost = &costs[y * w * n..][..w * n];
            for vx in 0..w {
                let x = if back { w - 1 - vx } else { vx };
                let c = &cost[x * n..(x + 1) * n];
                let mut out = [L::default(); 4];
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
                    s[i] = T::store(a[i].wide() + b[i].wide() + c[i].wide() + d[i].wide());
                }
            }
            std::mem::swap(&mut prev, &mut cur);
            std::mem::swap(&mut prev_low, &mut cur_low);
        }
    }
}

/// The largest penalty used (larger ones act as this): eight paths' sums of matching costs
/// (at most 24 + 8) plus it stay below `u16::MAX`, the sums' "none" mark.
const MAX_PENALTY: u16 = 4000;

/// The largest census cost (24 bits differ).
const MAX_CENSUS: u8 = 24;

/// The census codes of both images, and what a row of matching costs needs.
struct Codes<'a> {
    left: &'a [u32],
    right: &'a [u32],
    /// Per pixel, the disparity its costs are drawn toward (empty: none), and by how much.
    expected: &'a [u16],
    prior: prior::Prior,
    w: usize,
    n: usize,
}

impl Codes<'_> {
    /// Row `y`'s matching costs, `n` a pixel: left pixel `(x, y)` at disparity `d` against
    /// right pixel `(x - d, y)`; past the right image's edge, the cost of its first
    /// column's match (no information). Then drawn toward the expected disparities, if any.
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
        if let Some(expected) = self.expected.get(y * w..(y + 1) * w) {
            for (c, &e) in cost.chunks_exact_mut(n).zip(expected) {
                self.prior.draw(c, e);
            }
        }
    }
}

/// A path's first pixel: its costs are the matching costs. Returns their least.
#[inline(always)]
fn start<L: Lane>(c: &[u8], out: &mut [L]) -> L {
    let mut low = L::NONE;
    for (o, &c) in out[1..=c.len()].iter_mut().zip(c) {
        *o = L::cost(c);
        low = low.min(*o);
    }
    low
}

/// A path's next pixel from the previous one's costs `prev` (padded) and their least
/// `low`: `L(d) = C(d) + min(L'(d), L'(d ± 1) + P1, low + P2) - low`, into `out` (padded).
/// Returns the least of the new costs. Never below zero: every term of the `min` is at
/// least `low`, and at most `P2` above it, so `C(d) + (min - low)` stays in range.
#[inline(always)]
fn step<L: Lane>(c: &[u8], prev: &[L], low: L, out: &mut [L], p1: L, p2: L) -> L {
    let n = c.len();
    let jump = low.saturating_add(p2);
    let (below, at, above) = (&prev[..n], &prev[1..=n], &prev[2..n + 2]);
    let out = &mut out[1..=n];
    let mut least = L::NONE;
    for d in 0..n {
        let best = at[d]
            .min(below[d].saturating_add(p1))
            .min(above[d].saturating_add(p1))
            .min(jump);
        let v = L::cost(c[d]).add(best.sub(low));
        out[d] = v;
        least = least.min(v);
    }
    least
}

/// The right image's best disparities along one row of sums (`n` a left pixel): right
/// pixel `xr`'s is the least of `S(xr + d, d)` over `d` (the first of equal ones), refined
/// by a parabola through its neighbours on that diagonal; infinity where it has none. One
/// pass over the sums in memory order, keeping each right pixel's least so far in `low`.
fn choose_right(sums: &[u16], n: usize, low: &mut Vec<u32>, out: &mut [f32]) {
    let w = out.len();
    low.clear();
    low.resize(w, u32::MAX);
    // `low` holds the right pixels last first (`low[w - 1 - xr]`), so that left pixel x's
    // sums, right pixels x, x - 1, ..., as d grows, meet it in memory order: a forward
    // loop, which the compiler vectorises. A sum and its disparity packed as
    // `sum << 16 | d`: the least key is the least sum, the first of equal ones.
    for (x, s) in sums.chunks_exact(n).enumerate() {
        let m = n.min(x + 1);
        let base = w - 1 - x;
        for (d, (e, &v)) in low[base..base + m].iter_mut().zip(&s[..m]).enumerate() {
            *e = (*e).min(u32::from(v) << 16 | d as u32);
        }
    }
    low.reverse();
    let at = |xr: usize, d: usize| {
        sums.get((xr + d) * n + d)
            .filter(|&&v| xr + d < w && d < n && v != u16::MAX)
    };
    for (xr, (o, &key)) in out.iter_mut().zip(low.iter()).enumerate() {
        let (c, k) = ((key >> 16) as u16, (key & 0xffff) as usize);
        *o = if c == u16::MAX {
            f32::INFINITY
        } else {
            match (k.checked_sub(1).and_then(|j| at(xr, j)), at(xr, k + 1)) {
                (Some(&a), Some(&b)) => parabola(k, a as f32, c as f32, b as f32),
                _ => k as f32,
            }
        };
    }
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

mod lanes;
mod prior;

use lanes::{Lane, Stored};

#[cfg(test)]
mod tests;
