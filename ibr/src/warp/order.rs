//! McMillan's occlusion-compatible order: a traversal of the reference image in which a
//! sample that can hide another in the target view always comes later, so painting in this
//! order needs no depth buffer.
//!
//! Samples that can land on one target pixel lie on one ray from the target eye, and so on
//! one epipolar half-line of the reference image, which starts at the epipole (the target
//! eye's image). Along it, the sample nearer the target eye lies nearer the epipole when the
//! target eye is in front of the reference camera, and farther from it when behind. So the
//! epipole's row and column split the image into up to four sheets, and each sheet is
//! walked row by row toward the epipole (eye in front) or away from it (eye behind), each
//! row likewise: two samples on one half-line are ordered in both coordinates alike.

use glam::Vec2;

/// A run of one row: pixels `x = start, start + step, ...`, `len` of them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Run {
    /// The row, from the top, pixels.
    pub y: u32,
    /// The first pixel's column.
    pub start: u32,
    /// Pixels in the run.
    pub len: u32,
    /// `1` or `-1`.
    pub step: i32,
}

impl Run {
    /// The run's pixels in order.
    pub fn pixels(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.len).map(move |i| (self.start as i64 + i as i64 * self.step as i64) as u32)
    }

    /// The run's pixels as a span `[lo, hi)` of its row, whatever its direction.
    pub fn span(&self) -> (u32, u32) {
        let lo = if self.step > 0 {
            self.start
        } else {
            (self.start + 1).saturating_sub(self.len)
        };
        (lo, lo + self.len)
    }
}

/// How many pixel centres of `0..n` lie before `e` (`(i + 0.5) < e`), clamped to `0..=n`.
fn split(e: f32, n: u32) -> u32 {
    if e.is_nan() {
        return 0;
    }
    (e - 0.5).ceil().clamp(0.0, n as f32) as u32
}

/// Writes into `out` (cleared first) the runs of a `width` x `height` image in the
/// occlusion-compatible order for an epipole at `epipole` (reference pixels), the target
/// eye `in_front` of the reference camera or not. Every pixel is in exactly one run.
pub fn runs(width: u32, height: u32, epipole: Vec2, in_front: bool, out: &mut Vec<Run>) {
    out.clear();
    let (sx, sy) = (split(epipole.x, width), split(epipole.y, height));
    // Sheets by side of the epipole: rows above it (0..sy) and below (sy..height), columns
    // left (0..sx) and right (sx..width). Toward the epipole: rows above go down, rows
    // below go up; columns left go right, columns right go left. Away: the reverse.
    let sides = |split: u32, n: u32| -> [(u32, u32, i32); 2] {
        // (first, count, step) for the near-to-start side and the far side, toward.
        [(0, split, 1), (n.saturating_sub(1), n - split, -1)]
    };
    let reverse = |(first, count, step): (u32, u32, i32)| -> (u32, u32, i32) {
        if count == 0 {
            return (first, 0, step);
        }
        let last = (first as i64 + (count as i64 - 1) * step as i64) as u32;
        (last, count, -step)
    };
    for row_side in sides(sy, height) {
        let rows = if in_front {
            row_side
        } else {
            reverse(row_side)
        };
        for i in 0..rows.1 {
            let y = (rows.0 as i64 + i as i64 * rows.2 as i64) as u32;
            for col_side in sides(sx, width) {
                let cols = if in_front {
                    col_side
                } else {
                    reverse(col_side)
                };
                if cols.1 > 0 {
                    out.push(Run {
                        y,
                        start: cols.0,
                        len: cols.1,
                        step: cols.2,
                    });
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn order(width: u32, height: u32, e: Vec2, in_front: bool) -> Vec<(u32, u32)> {
        let mut r = Vec::new();
        runs(width, height, e, in_front, &mut r);
        r.iter()
            .flat_map(|run| run.pixels().map(move |x| (x, run.y)))
            .collect()
    }

    #[test]
    fn every_pixel_once_wherever_the_epipole_is() {
        for e in [
            Vec2::new(2.5, 1.5),
            Vec2::new(-40.0, 2.0),
            Vec2::new(3.0, 99.0),
            Vec2::new(0.0, 0.0),
            Vec2::new(5.0, 4.0),
            Vec2::new(1e7, -1e7),
            Vec2::NAN,
        ] {
            for in_front in [true, false] {
                let mut seen = order(5, 4, e, in_front);
                assert_eq!(seen.len(), 20);
                seen.sort();
                seen.dedup();
                assert_eq!(seen.len(), 20, "{e} {in_front}");
            }
        }
    }

    #[test]
    fn samples_on_a_half_line_come_in_order() {
        // Pixels on one half-line from the epipole: toward it (eye in front) the one nearer
        // the epipole comes later; away from it (eye behind) earlier.
        // With the epipole on a pixel corner, these pairs of pixel centres lie on one
        // half-line from it, one in each sheet.
        let e = Vec2::new(6.0, 4.0);
        for in_front in [true, false] {
            let seq = order(13, 9, e, in_front);
            let pos = |p: (u32, u32)| seq.iter().position(|&q| q == p).unwrap();
            for (near, far) in [
                ((6, 4), (8, 6)),
                ((5, 3), (2, 0)),
                ((6, 3), (9, 0)),
                ((5, 4), (1, 8)),
            ] {
                let (dn, df) = (pos(near), pos(far));
                assert_eq!(dn > df, in_front, "{near:?} {far:?} in front {in_front}");
            }
        }
    }
}
