//! The background-side fill: each hole takes the farthest of the nearest samples to its
//! left, right, top and bottom (the first of those in that order among equals), read from
//! the unfilled image. Work follows the holes, in three passes on the thread pool:
//! 1. **find**: each row's holes as bits, 64 pixels to a word (a 64-column strip's);
//! 2. **choose**: strip by strip, top to bottom, from the bits alone: each row's runs of
//!    holes, and for each hole the farther of its run's two ends (left unless right is
//!    strictly farther); each column's runs, and for each hole the farthest of that pick,
//!    the column run's top end and its bottom end, in that order;
//! 3. **write**: row by row, each hole takes the colour and disparity chosen for it.
//!
//! Only holes touch the strips' planes, which are laid out strip by strip (each strip owns
//! a slice) and kept from frame to frame, as are the bits.

use super::super::warped::{Warped, HOLE};
use engine::simd::{F8, LANES};
use rayon::prelude::*;

/// Columns per strip: the bits of a word.
const STRIP: usize = 64;

/// The background fill's scratch memory.
#[derive(Debug, Default)]
pub(super) struct Background {
    /// Row by row, a word per strip: bit `c` set where column `c` of the strip is a hole.
    bits: Vec<u64>,
    /// Strip by strip (a strip's rows, each its columns), per hole: the colour and the
    /// disparity it takes ([`HOLE`]: nothing), first its row's pick.
    color: Vec<u32>,
    disparity: Vec<f32>,
    /// Per column of each strip: the row its open run of holes began at.
    start: Vec<u32>,
}

impl Background {
    /// Fills the holes of `image`; returns how many it filled, and how many there were.
    pub(super) fn fill(&mut self, image: &mut Warped) -> (u64, u64) {
        let (w, h) = (image.width() as usize, image.height() as usize);
        if w == 0 || h == 0 {
            return (0, 0);
        }
        let strips = w.div_ceil(STRIP);
        let area = STRIP * h;
        self.bits.resize(strips * h, 0);
        // Only holes' entries of the planes are read, each after it is written.
        self.color.resize(strips * area, 0);
        self.disparity.resize(strips * area, HOLE);
        self.start.resize(strips * STRIP, 0);
        self.bits
            .par_chunks_mut(strips)
            .zip(image.disparity.par_chunks(w))
            .for_each(|(bits, row)| {
                for (word, pixels) in bits.iter_mut().zip(row.chunks(STRIP)) {
                    *word = hole_bits(pixels);
                }
            });
        let (bits, unfilled) = (&self.bits, &*image);
        self.color
            .par_chunks_mut(area)
            .zip(self.disparity.par_chunks_mut(area))
            .zip(self.start.par_chunks_mut(STRIP))
            .enumerate()
            .for_each(|(k, ((color, disparity), start))| {
                let strip = Strip {
                    k,
                    width: STRIP.min(w - k * STRIP),
                    image: unfilled,
                    bits,
                };
                strip.choose(start, (color, disparity));
            });
        let (color, disparity) = (&self.color, &self.disparity);
        image
            .color
            .par_chunks_mut(w)
            .zip(image.disparity.par_chunks_mut(w))
            .zip(bits.par_chunks(strips))
            .enumerate()
            .map(|(y, ((row_color, row), words))| {
                let (mut filled, mut holes) = (0, 0);
                for (k, &word) in words.iter().enumerate() {
                    holes += u64::from(word.count_ones());
                    let width = STRIP.min(w - k * STRIP);
                    let base = k * area + y * width;
                    for_each_bit(word, |col| {
                        let i = base + col;
                        if disparity[i] >= 0.0 {
                            let x = k * STRIP + col;
                            (row_color[x], row[x]) = (color[i], disparity[i]);
                            filled += 1;
                        }
                    });
                }
                (filled, holes)
            })
            .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
    }
}

/// Bit `i` set where `pixels[i]` is a hole: negative, or NaN (not a sample). At most 64.
#[inline(always)]
fn hole_bits(pixels: &[f32]) -> u64 {
    let mut bits = 0u64;
    let whole = pixels.len() / LANES * LANES;
    for (k, group) in pixels[..whole].chunks_exact(LANES).enumerate() {
        let samples = F8::load(group).ge(F8::splat(0.0)).bits();
        bits |= u64::from(!samples & 0xff) << (k * LANES);
    }
    for (i, &d) in pixels.iter().enumerate().skip(whole) {
        bits |= u64::from(d.partial_cmp(&0.0).is_none_or(|o| o.is_lt())) << i;
    }
    bits
}

/// Calls `f` with the index of each bit set in `word`, lowest first.
#[inline(always)]
fn for_each_bit(mut word: u64, mut f: impl FnMut(usize)) {
    while word != 0 {
        f(word.trailing_zeros() as usize);
        word &= word - 1;
    }
}

/// The words whose bits are 1 from bit `b` on, and below bit `b` (`b` at most 64).
fn from(b: usize) -> u64 {
    if b >= 64 {
        0
    } else {
        u64::MAX << b
    }
}

/// One strip of the choose pass: columns `64 k..64 k + width`.
struct Strip<'a> {
    k: usize,
    width: usize,
    image: &'a Warped,
    /// Every row's hole bits, a word per strip.
    bits: &'a [u64],
}

impl Strip<'_> {
    /// Walks the strip top to bottom: each hole's row pick into `chosen` (colour,
    /// disparity), then, as each column's run of holes ends, its top and bottom ends in
    /// turn where strictly farther.
    fn choose(&self, start: &mut [u32], chosen: (&mut [u32], &mut [f32])) {
        let (w, h) = (self.image.width() as usize, self.image.height() as usize);
        let (color, disparity) = chosen;
        let (image_color, d) = (&self.image.color, &self.image.disparity);
        let start = &mut start[..self.width];
        let strips = w.div_ceil(STRIP);
        let x0 = self.k * STRIP;
        // Bit `c` set while column `c` is in a run of holes.
        let mut open = 0u64;
        let end_run = |col: usize, y0: usize, y1: usize, chosen: (&mut [u32], &mut [f32])| {
            let x = x0 + col;
            let top = y0.checked_sub(1).map(|y| y * w + x);
            let bottom = (y1 < h).then_some(y1 * w + x);
            for c in [top, bottom].into_iter().flatten() {
                for y in y0..y1 {
                    let i = y * self.width + col;
                    // Nothing yet (a hole's negative disparity), or strictly farther.
                    if chosen.1[i] < 0.0 || d[c] < chosen.1[i] {
                        (chosen.0[i], chosen.1[i]) = (image_color[c], d[c]);
                    }
                }
            }
        };
        for y in 0..h {
            let words = &self.bits[y * strips..(y + 1) * strips];
            let bits = words[self.k];
            // The row's runs through this strip: each hole's pick.
            let mut rest = bits;
            while rest != 0 {
                let c0 = rest.trailing_zeros() as usize;
                let c1 = (c0 + (!(rest >> c0)).trailing_zeros() as usize).min(STRIP);
                rest &= !from(c0) | from(c1);
                let (a, b) = run(words, x0 + c0, x0 + c1, w);
                let left = a.checked_sub(1).map(|x| y * w + x);
                let right = (b < w).then_some(y * w + b);
                let pick = match (left, right) {
                    (Some(l), Some(r)) if d[r] < d[l] => Some(r),
                    (Some(l), _) => Some(l),
                    (None, r) => r,
                };
                let row = y * self.width..(y + 1) * self.width;
                let value = pick.map_or((0, HOLE), |p| (image_color[p], d[p]));
                color[row.clone()][c0..c1].fill(value.0);
                disparity[row][c0..c1].fill(value.1);
            }
            // Columns whose runs start or end here.
            let mut changes = bits ^ open;
            while changes != 0 {
                let col = changes.trailing_zeros() as usize;
                changes &= changes - 1;
                if bits >> col & 1 == 1 {
                    start[col] = y as u32;
                } else {
                    end_run(col, start[col] as usize, y, (&mut *color, &mut *disparity));
                }
            }
            open = bits;
        }
        for_each_bit(open, |col| {
            end_run(col, start[col] as usize, h, (&mut *color, &mut *disparity));
        });
    }
}

/// The whole run of holes `[a, b)` of a row (`words`: its hole bits) that holds the holes
/// `[x0, x1)`, found from the bits, across words when it reaches past them. `w`: the row's
/// length (bits past it are 0).
fn run(words: &[u64], x0: usize, x1: usize, w: usize) -> (usize, usize) {
    // The last sample before `x0`: the highest 0 bit below it.
    let mut a = 0;
    let (mut k, mut below) = (x0 / STRIP, x0 % STRIP);
    loop {
        let samples = !words[k] & !from(below);
        if samples != 0 {
            a = k * STRIP + 64 - samples.leading_zeros() as usize;
            break;
        }
        if k == 0 {
            break;
        }
        (k, below) = (k - 1, STRIP);
    }
    // The first sample from `x1` on: the lowest 0 bit, within the row.
    let mut b = w;
    let (mut k, mut at) = (x1 / STRIP, x1 % STRIP);
    while k < words.len() {
        let samples = !words[k] & from(at);
        if samples != 0 {
            b = (k * STRIP + samples.trailing_zeros() as usize).min(w);
            break;
        }
        (k, at) = (k + 1, 0);
    }
    (a, b)
}

#[cfg(test)]
mod tests;
