//! A block matcher: for each left pixel, the disparity whose window of absolute
//! differences of luminance (sum over a square window) is least, refined to a fraction of
//! a pixel by a parabola through the costs around it, kept only when clearly better than
//! the rest (uniqueness) and when the right image's own best match points back to it
//! (left-right consistency); unknown (infinite) otherwise. Rows in parallel on the thread
//! pool, the same answer at any thread count.

use super::{Disparity, StereoError};
use crate::core::DepthImage;
use rayon::prelude::*;

/// A block matcher's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlockMatch {
    /// Disparities `0..max_disparity` are searched.
    pub max_disparity: u32,
    /// The window is `2 radius + 1` pixels square.
    pub radius: u32,
    /// The best cost must be below `1 - uniqueness` times the best away from it.
    pub uniqueness: f32,
    /// Largest difference (pixels) between the left and the right image's matches.
    pub lr_tolerance: f32,
    /// Least luminance range (of 1) over a pixel's 5x5 window for it to be matched
    /// ([`MIN_TEXTURE`] by default; 0 matches flat regions too).
    pub min_texture: f32,
}

impl Default for BlockMatch {
    fn default() -> Self {
        BlockMatch {
            max_disparity: 64,
            radius: 3,
            uniqueness: 0.05,
            lr_tolerance: 1.0,
            min_texture: MIN_TEXTURE,
        }
    }
}

/// Luminance (0 to 255) of an image's premultiplied linear colour, composited over black.
pub fn luminance(image: &DepthImage) -> Vec<f32> {
    image
        .color
        .iter()
        .map(|c| {
            255.0
                * (0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b)
                    .clamp(0.0, 1.0)
                    .sqrt()
        })
        .collect()
}

/// Luminance (0 to 255, as [`luminance`]) of RGBA8 sRGB pixels (a PNG's), alpha ignored.
pub fn luminance_rgba8(rgba: &[u8]) -> Vec<f32> {
    rgba.chunks_exact(4)
        .map(|p| {
            let c = engine::Rgba::from_srgb8(p[0], p[1], p[2]);
            255.0
                * (0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b)
                    .clamp(0.0, 1.0)
                    .sqrt()
        })
        .collect()
}

impl BlockMatch {
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
        // Window sums of |L(x) - R(x - d)| for every d: per row of the output, the costs
        // of its pixels at every disparity (w n), from box sums over rows.
        let costs = |side_left: bool| -> Vec<f32> {
            let mut all = vec![f32::INFINITY; w * h * n];
            all.par_chunks_mut(w * n).enumerate().for_each(|(y, row)| {
                let r = self.radius as i64;
                for d in 0..n {
                    // Column sums of the differences over the window's rows, then along x.
                    let mut col = vec![0.0f32; w];
                    let mut ok = vec![true; w];
                    for x in 0..w {
                        let (xl, xr) = if side_left {
                            (x as i64, x as i64 - d as i64)
                        } else {
                            (x as i64 + d as i64, x as i64)
                        };
                        if xl < 0 || xr < 0 || xl >= w as i64 || xr >= w as i64 {
                            ok[x] = false;
                            continue;
                        }
                        let mut s = 0.0;
                        for dy in -r..=r {
                            let yy = (y as i64 + dy).clamp(0, h as i64 - 1) as usize;
                            s += (left[yy * w + xl as usize] - right[yy * w + xr as usize]).abs();
                        }
                        col[x] = s;
                    }
                    for x in 0..w {
                        let (a, b) = (
                            (x as i64 - r).max(0) as usize,
                            (x as i64 + r).min(w as i64 - 1) as usize,
                        );
                        if (a..=b).all(|k| ok[k]) {
                            row[x * n + d] = col[a..=b].iter().sum::<f32>();
                        }
                    }
                }
            });
            all
        };
        let (cl, cr) = (costs(true), costs(false));
        let best =
            |c: &[f32]| -> Vec<(f32, bool)> { c.par_chunks(n).map(|k| self.choose(k)).collect() };
        let (bl, br) = (best(&cl), best(&cr));
        Ok(left_right_checked(
            width,
            height,
            &bl,
            |i| br[i].0,
            self.lr_tolerance,
            &textured(left, w, h, self.min_texture),
        ))
    }

    /// The best disparity of one pixel's costs, refined by a parabola, and whether it is
    /// unique.
    fn choose(&self, costs: &[f32]) -> (f32, bool) {
        let Some((k, &c)) = costs
            .iter()
            .enumerate()
            .filter(|(_, c)| c.is_finite())
            .min_by(|a, b| a.1.total_cmp(b.1).then(a.0.cmp(&b.0)))
        else {
            return (f32::INFINITY, false);
        };
        let second = costs
            .iter()
            .enumerate()
            .filter(|&(j, c)| c.is_finite() && j.abs_diff(k) > 1)
            .map(|(_, &c)| c)
            .fold(f32::INFINITY, f32::min);
        // A least cost at the range's far end is not known to be a minimum: the true one
        // may lie beyond the search.
        let unique =
            (c < (1.0 - self.uniqueness) * second || !second.is_finite()) && k + 1 < costs.len();
        let mut d = k as f32;
        if k > 0 && k + 1 < costs.len() && costs[k - 1].is_finite() && costs[k + 1].is_finite() {
            d = parabola(k, costs[k - 1], c, costs[k + 1]);
        }
        (d, unique)
    }
}

/// The matchers' default least luminance range (of 1) over a pixel's 5x5 window for it to
/// be matched: below it the window is flat, holds nothing to match on (a plain wall), and
/// any disparity would be made up. Half a level of an 8-bit image: only truly flat windows.
/// Semi-global matching's paths often interpolate a flat plane between textured edges
/// correctly; set the matcher's `min_texture` to 0 to take what they give.
pub const MIN_TEXTURE: f32 = 0.5 / 255.0;

/// Per pixel of a `w` x `h` luminance image, whether its 5x5 window (clamped at the edges)
/// spans at least `min`: rows of ranges over five columns, then over five rows.
pub(super) fn textured(image: &[f32], w: usize, h: usize, min: f32) -> Vec<bool> {
    if w == 0 || h == 0 {
        return Vec::new();
    }
    if min <= 0.0 && image.par_iter().all(|v| v.is_finite()) {
        // Every finite window spans at least nothing.
        return vec![true; w * h];
    }
    // Per pixel, the least and greatest of its row's five (edges clamped), row by row.
    let mut lo = vec![0.0; w * h];
    let mut hi = vec![0.0; w * h];
    lo.par_chunks_mut(w)
        .zip(hi.par_chunks_mut(w))
        .zip(image.par_chunks(w))
        .for_each(|((lo, hi), row)| {
            for x in 0..w {
                let window = &row[x.saturating_sub(2)..(x + 3).min(w)];
                lo[x] = window.iter().fold(f32::INFINITY, |a, &v| a.min(v));
                hi[x] = window.iter().fold(f32::NEG_INFINITY, |a, &v| a.max(v));
            }
        });
    // Then over the five rows around each, element by element along the rows.
    let mut out = vec![false; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, out)| {
        let rows = y.saturating_sub(2)..(y + 3).min(h);
        let mut a = vec![f32::INFINITY; w];
        let mut b = vec![f32::NEG_INFINITY; w];
        for r in rows {
            let (l, g) = (&lo[r * w..(r + 1) * w], &hi[r * w..(r + 1) * w]);
            for x in 0..w {
                a[x] = a[x].min(l[x]);
                b[x] = b[x].max(g[x]);
            }
        }
        for ((o, a), b) in out.iter_mut().zip(&a).zip(&b) {
            *o = b - a >= min;
        }
    });
    out
}

/// The disparity map of the left image's best matches `left_best` (disparity, unique),
/// keeping those that are unique, on `textured` pixels, and that the right image's best
/// match `right_best(i)` (at pixel `i`) points back to within `tolerance` pixels; a match
/// past the right image's edge is no match.
pub(super) fn left_right_checked(
    width: u32,
    height: u32,
    left_best: &[(f32, bool)],
    right_best: impl Fn(usize) -> f32,
    tolerance: f32,
    textured: &[bool],
) -> Disparity {
    let w = width as usize;
    let data = left_best
        .iter()
        .enumerate()
        .map(|(i, &(dl, unique))| {
            let (x, y) = (i % w, i / w);
            let xr = x as f32 - dl;
            if !unique || !textured[i] || !dl.is_finite() || xr < 0.0 {
                return f32::INFINITY;
            }
            let dr = right_best(y * w + xr.round() as usize);
            if dr.is_finite() && (dl - dr).abs() <= tolerance {
                dl
            } else {
                f32::INFINITY
            }
        })
        .collect();
    Disparity::new(width, height, data).expect("finite, not negative, or infinite")
}

/// The least of the parabola through costs `a`, `c`, `b` at `k - 1`, `k`, `k + 1` (`c`
/// the least of the three): `k` moved by at most half a step.
pub(super) fn parabola(k: usize, a: f32, c: f32, b: f32) -> f32 {
    let curve = a - 2.0 * c + b;
    let shift = if curve > 0.0 {
        (0.5 * (a - b) / curve).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    k as f32 + shift
}

#[cfg(test)]
mod tests;
