//! Semi-global matching (Hirschmüller 2008): a census transform of each image (a 5x5
//! window's comparisons with its centre, 24 bits), the Hamming distance between census
//! codes as the matching cost of every pixel and disparity, costs aggregated along eight
//! paths (`L(p, d) = C(p, d) + min(L(p - r, d), L(p - r, d ± 1) + P1, min_k L(p - r, k) +
//! P2) - min_k L(p - r, k)`), their sum's best disparity per pixel refined by a parabola,
//! and checked as [`super::BlockMatch`] checks: unique, and consistent with the right
//! image's best match (read from the same sums along the other diagonal of the volume).
//! Lines of a path in parallel; integer sums, so the same answer at any thread count.

use super::block::{left_right_checked, parabola};
use super::{Disparity, StereoError};
use rayon::prelude::*;

/// Semi-global matching's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sgm {
    /// Disparities `0..max_disparity` are searched.
    pub max_disparity: u32,
    /// The penalties of a disparity change of one, and of more, between neighbours on a
    /// path (in census bits).
    pub p1: u16,
    pub p2: u16,
    /// The best sum must be below `1 - uniqueness` times the best away from it.
    pub uniqueness: f32,
    /// Largest difference (pixels) between the left and the right image's matches.
    pub lr_tolerance: f32,
}

impl Default for Sgm {
    fn default() -> Self {
        Sgm {
            max_disparity: 64,
            p1: 3,
            p2: 20,
            uniqueness: 0.03,
            lr_tolerance: 1.0,
        }
    }
}

/// The eight path directions `(dx, dy)`.
const PATHS: [(i32, i32); 8] = [
    (1, 0),
    (-1, 0),
    (0, 1),
    (0, -1),
    (1, 1),
    (-1, -1),
    (1, -1),
    (-1, 1),
];

/// The 5x5 census code of each pixel of a `w` x `h` luminance image (edges clamped).
fn census(image: &[f32], w: usize, h: usize) -> Vec<u32> {
    (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (x, y) = ((i % w) as i64, (i / w) as i64);
            let at = |dx: i64, dy: i64| {
                let xx = (x + dx).clamp(0, w as i64 - 1) as usize;
                let yy = (y + dy).clamp(0, h as i64 - 1) as usize;
                image[yy * w + xx]
            };
            let c = at(0, 0);
            let mut code = 0u32;
            for dy in -2..=2 {
                for dx in -2..=2 {
                    if dx != 0 || dy != 0 {
                        code = code << 1 | u32::from(at(dx, dy) < c);
                    }
                }
            }
            code
        })
        .collect()
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
        let (cl, cr) = (census(left, w, h), census(right, w, h));
        // Matching costs: pixel (x, y) at disparity d against right pixel (x - d, y); past
        // the right image's edge, the cost of its first column's match (no information).
        let cost: Vec<u8> = (0..w * h)
            .into_par_iter()
            .flat_map_iter(|i| {
                let (x, y) = (i % w, i / w);
                let (cl, cr) = (&cl, &cr);
                (0..n).map(move |d| {
                    let xr = x.saturating_sub(d);
                    (cl[i] ^ cr[y * w + xr]).count_ones() as u8
                })
            })
            .collect();
        let mut sums = vec![0u32; w * h * n];
        for &(dx, dy) in &PATHS {
            for (pixels, l) in self.paths(&cost, w, h, n, dx, dy) {
                for (k, &p) in pixels.iter().enumerate() {
                    for (s, &v) in sums[p * n..(p + 1) * n]
                        .iter_mut()
                        .zip(&l[k * n..(k + 1) * n])
                    {
                        *s += u32::from(v);
                    }
                }
            }
        }
        // Left: best d per pixel; right pixel (xr, y): best d over S(xr + d, y, d).
        let left_best: Vec<(f32, bool)> = sums
            .par_chunks(n)
            .map(|s| choose(s, self.uniqueness))
            .collect();
        let right_best: Vec<f32> = (0..w * h)
            .into_par_iter()
            .map(|i| {
                let (xr, y) = (i % w, i / w);
                let s: Vec<u32> = (0..n)
                    .map(|d| {
                        let x = xr + d;
                        if x < w {
                            sums[(y * w + x) * n + d]
                        } else {
                            u32::MAX
                        }
                    })
                    .collect();
                choose(&s, 0.0).0
            })
            .collect();
        Ok(left_right_checked(
            width,
            height,
            &left_best,
            |i| right_best[i],
            self.lr_tolerance,
        ))
    }

    /// The aggregated costs along direction `(dx, dy)`: each line of the image in that
    /// direction (in parallel), its pixels in order and their costs `L` (`n` a pixel).
    fn paths(
        &self,
        cost: &[u8],
        w: usize,
        h: usize,
        n: usize,
        dx: i32,
        dy: i32,
    ) -> Vec<(Vec<usize>, Vec<u16>)> {
        // Lines start on the edges the direction leaves from.
        let mut starts = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let (px, py) = (x as i32 - dx, y as i32 - dy);
                if px < 0 || py < 0 || px >= w as i32 || py >= h as i32 {
                    starts.push((x, y));
                }
            }
        }
        let (p1, p2) = (u32::from(self.p1), u32::from(self.p2));
        starts
            .into_par_iter()
            .map(|(x0, y0)| {
                let mut pixels = Vec::new();
                let (mut x, mut y) = (x0 as i32, y0 as i32);
                while x >= 0 && y >= 0 && x < w as i32 && y < h as i32 {
                    pixels.push(y as usize * w + x as usize);
                    (x, y) = (x + dx, y + dy);
                }
                let mut l = vec![0u16; pixels.len() * n];
                for (k, &p) in pixels.iter().enumerate() {
                    let c = &cost[p * n..(p + 1) * n];
                    if k == 0 {
                        for (o, &c) in l[..n].iter_mut().zip(c) {
                            *o = u16::from(c);
                        }
                        continue;
                    }
                    let (before, now) = l.split_at_mut(k * n);
                    let prev = &before[(k - 1) * n..];
                    let low = u32::from(*prev.iter().min().unwrap_or(&0));
                    for d in 0..n {
                        let mut best = u32::from(prev[d]);
                        if d > 0 {
                            best = best.min(u32::from(prev[d - 1]) + p1);
                        }
                        if d + 1 < n {
                            best = best.min(u32::from(prev[d + 1]) + p1);
                        }
                        best = best.min(low + p2);
                        now[d] = (u32::from(c[d]) + best - low) as u16;
                    }
                }
                (pixels, l)
            })
            .collect()
    }
}

/// The best disparity of one pixel's sums, refined by a parabola, and whether it is
/// unique (below `1 - uniqueness` times the best more than one away).
fn choose(sums: &[u32], uniqueness: f32) -> (f32, bool) {
    let Some((k, &c)) = sums
        .iter()
        .enumerate()
        .filter(|(_, s)| **s != u32::MAX)
        .min_by(|a, b| a.1.cmp(b.1).then(a.0.cmp(&b.0)))
    else {
        return (f32::INFINITY, false);
    };
    let second = sums
        .iter()
        .enumerate()
        .filter(|&(j, s)| *s != u32::MAX && j.abs_diff(k) > 1)
        .map(|(_, &s)| s)
        .min();
    let unique = second.is_none_or(|s| (c as f32) < (1.0 - uniqueness) * s as f32);
    let near = |j: Option<usize>| j.and_then(|j| sums.get(j)).filter(|s| **s != u32::MAX);
    let d = match (near(k.checked_sub(1)), near(Some(k + 1))) {
        (Some(&a), Some(&b)) => parabola(k, a as f32, c as f32, b as f32),
        _ => k as f32,
    };
    (d, unique)
}

#[cfg(test)]
mod tests;
