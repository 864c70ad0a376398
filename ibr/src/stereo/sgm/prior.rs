//! Coarse to fine: the pair matched at half width (and a quarter height) first, and each
//! full-size pixel's costs drawn toward twice its small match. A repeated pattern matches
//! equally well at its aliases, a period or two away, and the paths only carry what tells
//! them apart (an edge where the alias would match something else) for a few pixels; in
//! the small images the pattern is blurred and the surfaces' outlines decide. Disparity
//! runs along rows, so rows are averaged four at a time, which halves the small match's
//! cost against half height: the whole match took 39.8 to 40.6 ms against 42.4 to 44.4
//! (`stereo_frame -- --runs 20 --sgm`, three alternated runs each), with bad 2 within a
//! point on the `bench stereo` pairs.

use super::{Sgm, SgmBuffers};
use rayon::prelude::*;

/// Disparities within this many pixels of the expected one cost nothing extra: a small
/// match one pixel off is two at full size, plus its rounding.
const SLACK: u32 = 3;

/// The largest `Sgm::prior` used.
pub(super) const MAX_PRIOR: u8 = 8;

/// Images smaller than this on either side are matched at full size only.
const MIN_SIDE: usize = 16;

/// Pixels of a row, and rows, averaged into one pixel of the small images.
const ACROSS: usize = 2;
const DOWN: usize = 4;

/// Per pixel of the `w` x `h` pair, the disparity its costs are drawn toward (twice its
/// small match, rounded), or `u16::MAX` where the small match is unknown; into `out`.
/// Empty when the images are too small.
pub(super) fn expected(
    sgm: &Sgm,
    coarse: &mut SgmBuffers,
    (left, right): (&[f32], &[f32]),
    (w, h): (usize, usize),
    out: &mut Vec<u16>,
) {
    out.clear();
    if w < MIN_SIDE || h < MIN_SIDE {
        return;
    }
    let (wc, hc) = (w / ACROSS, h / DOWN);
    let small = |image: &[f32]| -> Vec<f32> {
        let mut small = vec![0.0; wc * hc];
        small.par_chunks_mut(wc).enumerate().for_each(|(y, row)| {
            for (x, v) in row.iter_mut().enumerate() {
                let mut sum = 0.0;
                for r in DOWN * y..DOWN * (y + 1) {
                    let pixels = &image[r * w + ACROSS * x..][..ACROSS];
                    sum += pixels.iter().sum::<f32>();
                }
                *v = sum / (ACROSS * DOWN) as f32;
            }
        });
        small
    };
    let (l, r) = rayon::join(|| small(left), || small(right));
    let settings = Sgm {
        max_disparity: sgm.max_disparity.div_ceil(ACROSS as u32),
        // Every small pixel the paths can place: flat ones are where the pull helps.
        min_texture: 0.0,
        prior: 0,
        ..*sgm
    };
    let Ok(d) = settings.run_with(coarse, &l, &r, wc as u32, hc as u32) else {
        return;
    };
    out.resize(w * h, u16::MAX);
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let coarse = &d.data[(y / DOWN).min(hc - 1) * wc..][..wc];
        for (x, e) in row.iter_mut().enumerate() {
            let v = ACROSS as f32 * coarse[(x / ACROSS).min(wc - 1)];
            *e = if v.is_finite() {
                (v.round() as u32).min(u32::from(u16::MAX - 1)) as u16
            } else {
                u16::MAX
            };
        }
    });
}

/// What [`Prior::draw`] adds: for offsets `j` from the expected disparity (stored at
/// `j + n`, `j` in `-n..n`), one per pixel beyond [`SLACK`], at most the cap.
#[derive(Clone, Debug, Default)]
pub(super) struct Prior {
    n: usize,
    table: Vec<u8>,
}

impl Prior {
    pub(super) fn new(n: usize, cap: u8) -> Self {
        let table = (0..2 * n)
            .map(|i| {
                let off = (i as u32).abs_diff(n as u32).saturating_sub(SLACK);
                off.min(u32::from(cap)) as u8
            })
            .collect();
        Prior { n, table }
    }

    /// Raises one pixel's costs `c` (disparities 0, 1, ...: `n` of them) by one per pixel
    /// of disparity beyond [`SLACK`] from `expected`, by at most the cap: a slice of the
    /// table added, 32 bytes to a vector.
    #[inline]
    pub(super) fn draw(&self, c: &mut [u8], expected: u16) {
        let e = usize::from(expected);
        if e == usize::from(u16::MAX) || e >= self.n {
            // Unknown, or past the range (its costs all raised alike: no preference).
            return;
        }
        let window = &self.table[self.n - e..][..c.len()];
        for (c, &p) in c.iter_mut().zip(window) {
            *c += p;
        }
    }
}
