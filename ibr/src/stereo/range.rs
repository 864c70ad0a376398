//! The disparity range to search, chosen rather than guessed: from depth when the pair
//! has it (the disparity `f b / z` of its nearest point after rectification), else from a
//! coarse search (a match of the pair shrunk to about 128 pixels across, over half its
//! width); and the share of matches that sit at a range's limit, the sign that it was too
//! small. A surface nearer than the range reaches is matched at its end or, more often,
//! to an alias anywhere within it (semi-global matching's left-right check rejects most
//! matches at the very end), so the share counts both the final map's matches at the
//! limit ([`at_limit`]) and the coarse search's matches at or beyond it
//! ([`Coarse::beyond`]).

use super::{Disparity, Sgm};

/// The fewest disparities searched.
pub const MIN_RANGE: u32 = 8;
/// The most (the matchers take more, but no pair here needs it).
pub const MAX_RANGE: u32 = 1024;

/// The number of disparities (`0..n`) that holds every point of the depth maps `depths`
/// (distances along the rectified optical axis, infinite where nothing; one map per view
/// of the rectified pair), for a focal length of `focal_px` and a baseline of `baseline`:
/// the nearest point's disparity with a margin of 5% and 2 pixels. `None` when no depth
/// is finite and positive.
pub fn from_depth(depths: &[&[f32]], focal_px: f32, baseline: f32) -> Option<u32> {
    let nearest = depths
        .iter()
        .flat_map(|d| d.iter())
        .copied()
        .filter(|z| z.is_finite() && *z > 0.0)
        .fold(f32::INFINITY, f32::min);
    let fb = focal_px * baseline;
    if !nearest.is_finite() || fb.is_nan() || fb <= 0.0 {
        return None;
    }
    Some(clamped(1.05 * fb / nearest + 2.0))
}

/// What a coarse search of a pair found: its matched disparities, scaled to the full
/// size, sorted; and the factor it shrank the pair by.
#[derive(Clone, Debug)]
pub struct Coarse {
    /// The disparities matched at the coarse size, times `scale` (full-size pixels),
    /// ascending.
    pub disparities: Vec<f32>,
    /// The factor the pair was shrunk by on each axis (1 = full size).
    pub scale: u32,
}

/// A coarse search of the pair (luminance, `w` x `h`): both images box-filtered down by a
/// power of two to about 128 pixels across and matched by semi-global matching over half
/// their width. `None` when the pair is too small or nothing matches.
pub fn coarse(left: &[f32], right: &[f32], w: u32, h: u32) -> Option<Coarse> {
    let mut k = 1u32;
    while w / (2 * k) >= 128 && h / (2 * k) >= 16 && k < 8 {
        k *= 2;
    }
    let (sw, sh) = (w / k, h / k);
    if sw < 8 || sh < 8 {
        return None;
    }
    let (l, r) = (shrink(left, w, k, sw, sh), shrink(right, w, k, sw, sh));
    let d = Sgm {
        max_disparity: (sw / 2).clamp(4, MAX_RANGE),
        ..Sgm::default()
    }
    .run(&l, &r, sw, sh)
    .ok()?;
    let mut disparities: Vec<f32> = d
        .data
        .into_iter()
        .filter(|v| v.is_finite())
        .map(|v| v * k as f32)
        .collect();
    if disparities.is_empty() {
        return None;
    }
    disparities.sort_by(f32::total_cmp);
    Some(Coarse {
        disparities,
        scale: k,
    })
}

impl Coarse {
    /// The number of disparities the pair needs: the 99th percentile of the matches with
    /// a margin of 10% and one coarse pixel.
    pub fn range(&self) -> u32 {
        let d = &self.disparities;
        let p99 = d[(d.len() * 99 / 100).min(d.len() - 1)];
        clamped(1.1 * (p99 + self.scale as f32))
    }

    /// The share of the coarse matches a search over `0..n` cannot hold: at its last
    /// disparity or beyond (less a coarse pixel's rounding).
    pub fn beyond(&self, n: u32) -> f64 {
        let limit = n.saturating_sub(1) as f32 - 0.5 * self.scale as f32;
        let at = self.disparities.iter().filter(|&&v| v >= limit).count();
        at as f64 / self.disparities.len().max(1) as f64
    }
}

/// `n` rounded up, within [`MIN_RANGE`] and [`MAX_RANGE`].
fn clamped(n: f32) -> u32 {
    (n.ceil().max(0.0) as u32).clamp(MIN_RANGE, MAX_RANGE)
}

/// `image` (`w` pixels a row) averaged over `k` x `k` blocks into `sw` x `sh`.
fn shrink(image: &[f32], w: u32, k: u32, sw: u32, sh: u32) -> Vec<f32> {
    let (w, k) = (w as usize, k as usize);
    let mut out = Vec::with_capacity(sw as usize * sh as usize);
    for y in 0..sh as usize {
        for x in 0..sw as usize {
            let sum: f32 = (0..k)
                .flat_map(|j| {
                    let row = (y * k + j) * w + x * k;
                    image[row..row + k].iter()
                })
                .sum();
            out.push(sum / (k * k) as f32);
        }
    }
    out
}

/// The share of `d`'s known disparities at the limit of a search over `0..n`: within half
/// a pixel of `n - 1` (0 when none is known).
pub fn at_limit(d: &Disparity, n: u32) -> f64 {
    let limit = n.saturating_sub(1) as f32 - 0.5;
    let (mut known, mut at) = (0usize, 0usize);
    for &v in d.data.iter().filter(|v| v.is_finite()) {
        known += 1;
        at += (v >= limit) as usize;
    }
    at as f64 / known.max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stereo::luminance;
    use crate::stereo::scenes::{slanted, H, W};

    #[test]
    fn the_range_from_depth_holds_the_nearest_point() {
        let inf = f32::INFINITY;
        // f b = 100: the nearest point, at 2, has disparity 50.
        let n = from_depth(&[&[inf, 4.0, 2.0], &[3.0]], 200.0, 0.5).unwrap();
        assert_eq!(n, (1.05f32 * 50.0 + 2.0).ceil() as u32);
        assert_eq!(from_depth(&[&[inf, 0.0]], 200.0, 0.5), None);
        // Far points only: the least range.
        assert_eq!(from_depth(&[&[1e6]], 200.0, 0.5), Some(MIN_RANGE));
    }

    #[test]
    fn shrinking_averages_blocks() {
        let image: Vec<f32> = (0..16).map(|i| i as f32).collect();
        // 4 x 4 to 2 x 2: the mean of each 2 x 2 block.
        assert_eq!(shrink(&image, 4, 2, 2, 2), vec![2.5, 4.5, 10.5, 12.5]);
    }

    /// On the slanted card test pair (its true disparities known by rendering), the coarse
    /// search's range holds the true disparities and is not many times wider.
    #[test]
    fn the_coarse_search_covers_the_true_disparities() {
        let pair = slanted();
        let truth: Vec<f32> = pair
            .truth
            .data
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .collect();
        let most = truth.iter().copied().fold(0.0f32, f32::max);
        let (l, r) = (luminance(&pair.left), luminance(&pair.right));
        let found = coarse(&l, &r, W, H).expect("a textured pair matches");
        let n = found.range();
        assert!(n as f32 > most, "range {n} for disparities up to {most}");
        assert!((n as f32) < 2.0 * most + 16.0, "range {n} for {most}");
        // A range that holds them leaves few matches beyond it; half of it, many.
        assert!(found.beyond(n) < 0.02, "{}", found.beyond(n));
        let half = (0.5 * most) as u32;
        assert!(found.beyond(half) > 0.2, "{}", found.beyond(half));
    }

    #[test]
    fn matches_at_the_end_of_the_range_are_counted() {
        let inf = f32::INFINITY;
        let d = Disparity::new(4, 1, vec![15.0, 14.6, 3.0, inf]).unwrap();
        assert!((at_limit(&d, 16) - 2.0 / 3.0).abs() < 1e-9);
        assert_eq!(at_limit(&d, 64), 0.0);
    }
}
