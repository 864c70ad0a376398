//! The part of a baked view its sprite is drawn over ([`Trim`]): the rows its texels cover
//! and, at each row of the depth grid's nodes, the columns, so the clear texels of a view's
//! square (sampled, tested and discarded like any other) are not drawn; and the view's
//! depth where those nodes lie ([`surface`]).

use super::views::RELIEF;
use glam::Vec2;

/// Node rows less one: the bands of texel rows between node rows.
const BANDS: usize = RELIEF - 1;

/// A view's drawn part, in fractions of its square (0 at the top left, 1 at the bottom
/// right): rows `top` to `bottom`, and on node row `g` of the `RELIEF` x `RELIEF` grid the
/// columns `left[g]` to `right[g]`. A sprite's edges run straight between node rows, each
/// node row as wide as the covered texels (alpha above 0, grown by a texel each way for the
/// bilinear filter) of the bands on either side of it, so the trimmed grid still holds
/// every texel the whole square would draw.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trim {
    /// First row drawn.
    pub top: f32,
    /// End of the last row drawn.
    pub bottom: f32,
    /// Per node row, its first column drawn.
    pub left: [f32; RELIEF],
    /// Per node row, the end of its last column drawn.
    pub right: [f32; RELIEF],
}

impl Trim {
    /// The whole square (a view with nothing in it).
    pub const FULL: Trim = Trim {
        top: 0.0,
        bottom: 1.0,
        left: [0.0; RELIEF],
        right: [1.0; RELIEF],
    };

    /// Node (`gx`, `gy`)'s place in the square.
    pub fn node(&self, gx: usize, gy: usize) -> Vec2 {
        let s = 1.0 / BANDS as f32;
        let y = self.top + (self.bottom - self.top) * gy as f32 * s;
        let x = self.left[gy] + (self.right[gy] - self.left[gy]) * gx as f32 * s;
        Vec2::new(x, y)
    }

    /// The drawn part of a view whose alpha is `alpha` (`px` square, row-major, top row
    /// first).
    pub fn of(alpha: &[u8], px: usize) -> Trim {
        // Each texel row's covered columns (first, last), then grown a texel each way and
        // over the rows above and below.
        let span = |y: usize| {
            let row = &alpha[y * px..(y + 1) * px];
            let lo = row.iter().position(|&a| a > 0)?;
            let hi = row.iter().rposition(|&a| a > 0)?;
            Some((lo, hi))
        };
        let spans: Vec<Option<(usize, usize)>> = (0..px).map(span).collect();
        let grown: Vec<Option<(usize, usize)>> = (0..px)
            .map(|y| {
                (y.saturating_sub(1)..(y + 2).min(px))
                    .filter_map(|r| spans[r])
                    .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
                    .map(|(lo, hi)| (lo.saturating_sub(1), (hi + 1).min(px - 1)))
            })
            .collect();
        let (Some(y0), Some(y1)) = (
            grown.iter().position(Option::is_some),
            grown.iter().rposition(Option::is_some),
        ) else {
            return Trim::FULL;
        };
        let rows = (y1 + 1 - y0) as f32;
        let f = |texels: usize| texels as f32 / px as f32;
        let all = grown
            .iter()
            .flatten()
            .copied()
            .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
            .unwrap_or((0, px - 1));
        let mut trim = Trim {
            top: f(y0),
            bottom: f(y1 + 1),
            ..Trim::FULL
        };
        // Each node row starts as the span of the texel row it lies on (an empty one as a
        // point in the middle).
        let middle = 0.5 * (f(all.0) + f(all.1 + 1));
        for g in 0..RELIEF {
            let y = (y0 + (g as f32 / BANDS as f32 * rows) as usize).min(y1);
            (trim.left[g], trim.right[g]) =
                grown[y].map_or((middle, middle), |(lo, hi)| (f(lo), f(hi + 1)));
        }
        // Then each band's two edges are moved out until they hold every texel row of the
        // band (checked at the row's top and bottom: the edges are straight), each node
        // row as far out as either band needs; an edge that would leave the square is
        // the band's widest span instead.
        let (mut left, mut right) = (trim.left, trim.right);
        for b in 0..BANDS {
            let (mut out_l, mut out_r) = (0f32, 0f32);
            let (mut min_l, mut max_r) = (1f32, 0f32);
            for (y, s) in grown.iter().enumerate().take(y1 + 1).skip(y0) {
                let Some((lo, hi)) = *s else { continue };
                // The row's top and bottom in the band's units (0 and 1 its node rows).
                let t = |edge: usize| (edge - y0) as f32 / rows * BANDS as f32 - b as f32;
                let (ta, tb) = (t(y), t(y + 1));
                if tb <= 0.0 || ta >= 1.0 {
                    continue;
                }
                for t in [ta.max(0.0), tb.min(1.0)] {
                    let l = trim.left[b] + (trim.left[b + 1] - trim.left[b]) * t;
                    let r = trim.right[b] + (trim.right[b + 1] - trim.right[b]) * t;
                    out_l = out_l.max(l - f(lo));
                    out_r = out_r.max(f(hi + 1) - r);
                }
                min_l = min_l.min(f(lo));
                max_r = max_r.max(f(hi + 1));
            }
            let (mut l, mut r) = (
                [trim.left[b] - out_l, trim.left[b + 1] - out_l],
                [trim.right[b] + out_r, trim.right[b + 1] + out_r],
            );
            if l.iter().any(|&x| x < 0.0) {
                l = [min_l; 2];
            }
            if r.iter().any(|&x| x > 1.0) {
                r = [max_r; 2];
            }
            for (i, g) in [b, b + 1].into_iter().enumerate() {
                left[g] = left[g].min(l[i]);
                right[g] = right[g].max(r[i]);
            }
        }
        (trim.left, trim.right) = (left, right);
        trim
    }

    /// This trim grown by `by` (fractions of the square: a margin of screen pixels, so
    /// that an outline the bake's texels put inside a pixel's centre but the filtered
    /// coarser levels reach is still drawn), kept within the square.
    pub fn grown(&self, by: Vec2) -> Trim {
        Trim {
            top: (self.top - by.y).max(0.0),
            bottom: (self.bottom + by.y).min(1.0),
            left: self.left.map(|l| (l - by.x).max(0.0)),
            right: self.right.map(|r| (r + by.x).min(1.0)),
        }
    }
}

/// The surface of a view's depth grid over its whole square (`grid`, row-major, `RELIEF`
/// nodes a side, as [`super::ViewAtlas::depth`]) at `at` in the square, interpolated
/// bilinearly between its nodes: a trimmed sprite's nodes stand about as deep as the whole
/// square's surface where they lie. (Taking each trimmed node's nearest surface among the
/// texels nearest it instead pushed the corners, now on a crown's flank, toward the eye;
/// on the 640 x 360 tour it measured no better.)
pub(crate) fn surface(grid: &[f32; RELIEF * RELIEF], at: Vec2) -> f32 {
    let at = at.clamp(Vec2::ZERO, Vec2::ONE) * BANDS as f32;
    let (x0, y0) = (
        (at.x as usize).min(BANDS - 1),
        (at.y as usize).min(BANDS - 1),
    );
    let (tx, ty) = (at.x - x0 as f32, at.y - y0 as f32);
    let v = |x: usize, y: usize| grid[y * RELIEF + x];
    let top = v(x0, y0) + (v(x0 + 1, y0) - v(x0, y0)) * tx;
    let bottom = v(x0, y0 + 1) + (v(x0 + 1, y0 + 1) - v(x0, y0 + 1)) * tx;
    top + (bottom - top) * ty
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `px` square view holding a triangle, point up: rows 4.. of 32, row `y` covering
    /// the columns within `(y - 4) / 2` of the middle.
    fn cone(px: usize) -> Vec<u8> {
        let mut a = vec![0u8; px * px];
        for y in 4..px {
            let half = (y - 4) / 2;
            for x in px / 2 - half..=px / 2 + half {
                a[y * px + x] = 255;
            }
        }
        a
    }

    #[test]
    fn a_trim_holds_every_covered_texel_and_leaves_out_the_clear_ones() {
        let px = 32;
        let alpha = cone(px);
        let t = Trim::of(&alpha, px);
        // Rows from one above the tip's; the tip's node row narrow, the base's wide.
        assert_eq!(t.top, 3.0 / 32.0);
        assert_eq!(t.bottom, 1.0);
        assert!(
            t.right[0] - t.left[0] < 0.25 * (t.right[2] - t.left[2]),
            "{t:?}"
        );
        // Every covered texel (and its bilinear neighbours) lies inside the trimmed
        // outline; the outline is well under the square.
        let inside = |x: f32, y: f32| {
            let fy = (y - t.top) / (t.bottom - t.top) * BANDS as f32;
            if !(0.0..=BANDS as f32).contains(&fy) {
                return false;
            }
            let b = (fy as usize).min(BANDS - 1);
            let s = fy - b as f32;
            let l = t.left[b] + (t.left[b + 1] - t.left[b]) * s;
            let r = t.right[b] + (t.right[b + 1] - t.right[b]) * s;
            (l..=r).contains(&x)
        };
        let mut area = 0;
        for y in 0..px {
            for x in 0..px {
                let c = |dx: f32, dy: f32| {
                    Vec2::new(x as f32 + 0.5 + dx, y as f32 + 0.5 + dy) / px as f32
                };
                if alpha[y * px + x] > 0 {
                    for (dx, dy) in [(-0.5, -0.5), (0.5, -0.5), (-0.5, 0.5), (0.5, 0.5)] {
                        let p = c(dx, dy);
                        assert!(inside(p.x, p.y), "texel {x},{y} corner {p}: {t:?}");
                    }
                }
                let p = c(0.0, 0.0);
                area += usize::from(inside(p.x, p.y));
            }
        }
        assert!(area * 10 < px * px * 6, "{area} of {}", px * px);
        // The grid's nodes run over the trimmed part.
        assert_eq!(t.node(0, 0), Vec2::new(t.left[0], t.top));
        assert_eq!(t.node(BANDS, BANDS), Vec2::new(t.right[BANDS], t.bottom));
    }

    #[test]
    fn an_empty_view_keeps_its_whole_square() {
        assert_eq!(Trim::of(&[0; 64], 8), Trim::FULL);
        assert_eq!(Trim::FULL.grown(Vec2::splat(0.1)), Trim::FULL);
    }

    #[test]
    fn a_grown_trim_stays_in_the_square() {
        let t = Trim::of(&cone(32), 32);
        let g = t.grown(Vec2::new(0.05, 0.5));
        assert_eq!((g.top, g.bottom), (0.0, 1.0));
        for n in 0..RELIEF {
            assert!((g.left[n] - (t.left[n] - 0.05).max(0.0)).abs() < 1e-6);
            assert!((g.right[n] - (t.right[n] + 0.05).min(1.0)).abs() < 1e-6);
        }
    }

    #[test]
    fn trimmed_nodes_follow_the_whole_squares_surface() {
        // A surface rising to the right and down: a plane, so interpolation is exact.
        let plane = |p: Vec2| 0.1 + 0.2 * p.x + 0.3 * p.y;
        let mut full = [0.0; RELIEF * RELIEF];
        for (i, o) in full.iter_mut().enumerate() {
            let p = Vec2::new((i % RELIEF) as f32, (i / RELIEF) as f32) / BANDS as f32;
            *o = plane(p);
        }
        let t = Trim::of(&cone(32), 32);
        for gy in 0..RELIEF {
            for gx in 0..RELIEF {
                let (at, want) = (t.node(gx, gy), plane(t.node(gx, gy)));
                assert!((surface(&full, at) - want).abs() < 1e-5, "{gx},{gy}: {at}");
            }
        }
        // Beyond the square, its edge's; between nodes, bilinear.
        assert!((surface(&full, Vec2::new(2.0, -1.0)) - plane(Vec2::X)).abs() < 1e-5);
        let mut bump = [0.0; RELIEF * RELIEF];
        bump[RELIEF * RELIEF / 2] = 1.0;
        // The middle node's tent, a band wide each way.
        let band = 1.0 / BANDS as f32;
        let at = Vec2::splat(0.5 - 0.25 * band);
        assert!((surface(&bump, at) - 0.5625).abs() < 1e-5);
        let at = Vec2::new(0.5 - 0.75 * band, 0.5 - 0.5 * band);
        assert!((surface(&bump, at) - 0.125).abs() < 1e-5);
    }
}
