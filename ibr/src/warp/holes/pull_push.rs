//! Pull-push (Gortler et al. 96) over a warped image, biased to the background: the
//! pyramid, pulled eight cells at a time and pushed only where cells are empty.
//!
//! Every sample of the image weighs one, and a cell's weight is its children's summed and
//! capped at one (Kraus 2009), so every weight is zero or one: a cell is full or empty, and
//! the pyramid stores no weights (an empty cell has disparity [`HOLE`]). A cell keeps only
//! its children within the edge tolerance of the farthest (the background); push fills an
//! empty cell from the level above, bilinearly over the parent cells within the tolerance
//! of the farthest of them, so foreground colour never flows into a disocclusion.

use super::super::warped::{Warped, HOLE};
use engine::simd::{F8, I8, LANES, M8};
use rayon::prelude::*;

/// A pyramid level above the image: per cell the mean colour of the children it kept
/// (stored byte values, one plane per channel) and their mean disparity.
#[derive(Clone, Debug, Default)]
pub(super) struct Level {
    w: usize,
    h: usize,
    color: [Vec<f32>; 4],
    disparity: Vec<f32>,
}

impl Level {
    /// Makes this `w` x `h`; every cell is then written by a pull.
    fn resize(&mut self, w: usize, h: usize) {
        let n = w * h;
        (self.w, self.h) = (w, h);
        for plane in self.color.iter_mut().chain([&mut self.disparity]) {
            plane.resize(n, HOLE);
        }
    }

    fn colour(&self, i: usize) -> [f32; 4] {
        self.color.each_ref().map(|p| p[i])
    }

    /// Its rows on the thread pool: the row index, and the row of each plane (disparity,
    /// then the four channels).
    fn rows_mut(&mut self) -> impl IndexedParallelIterator<Item = (usize, [&mut [f32]; 5])> {
        let w = self.w.max(1);
        let [r, g, b, a] = &mut self.color;
        let rows = self.disparity.par_chunks_mut(w).zip(r.par_chunks_mut(w));
        let rows = rows.zip(g.par_chunks_mut(w)).zip(b.par_chunks_mut(w));
        rows.zip(a.par_chunks_mut(w))
            .map(|((((d, r), g), b), a)| [d, r, g, b, a])
            .enumerate()
    }
}

/// Fills the holes of `image` using `levels` as scratch: levels 1, 2, ... up to a single
/// cell. Returns how many it filled, and how many there were.
pub(super) fn fill(image: &mut Warped, levels: &mut Vec<Level>, edge: f32) -> (u64, u64) {
    let (w, h) = (image.width() as usize, image.height() as usize);
    if w == 0 || h == 0 || (w == 1 && h == 1) {
        return (0, image.disparity.len() as u64 - image.filled());
    }
    let keep = 1.0 - edge;
    // Pull: level 1 from the image, then halve until one cell.
    let halve = |(w, h): (usize, usize)| (w.div_ceil(2), h.div_ceil(2));
    let sizes = std::iter::successors(Some(halve((w, h))), |&(w, h)| {
        (w > 1 || h > 1).then(|| halve((w, h)))
    });
    let count = sizes.clone().count();
    if levels.len() < count {
        levels.resize_with(count, Level::default);
    }
    let levels = &mut levels[..count];
    for (level, (w, h)) in levels.iter_mut().zip(sizes) {
        level.resize(w, h);
    }
    let (color, disparity) = (&image.color, &image.disparity);
    pull(
        &mut levels[0],
        w,
        h,
        keep,
        |i| {
            // Eight pairs of pixels from `i` on: disparity and packed colour.
            let (d, c) = (F8::load(&disparity[i..]), I8::load_u32(&color[i..]));
            let (d2, c2) = (
                F8::load(&disparity[i + LANES..]),
                I8::load_u32(&color[i + LANES..]),
            );
            let ((d_even, d_odd), (c_even, c_odd)) = (d.deinterleave(d2), c.deinterleave(c2));
            (d_even, d_odd, c_even, c_odd)
        },
        |i| (disparity[i], color[i]),
    );
    for k in 1..levels.len() {
        let (fine, coarse) = levels.split_at_mut(k);
        let fine = &fine[k - 1];
        let pairs = |plane: &[f32], i: usize| {
            F8::load(&plane[i..]).deinterleave(F8::load(&plane[i + LANES..]))
        };
        pull(
            &mut coarse[0],
            fine.w,
            fine.h,
            keep,
            |i| {
                let (d_even, d_odd) = pairs(&fine.disparity, i);
                let c = fine.color.each_ref().map(|p| pairs(p, i));
                (d_even, d_odd, c.map(|c| c.0), c.map(|c| c.1))
            },
            |i| (fine.disparity[i], fine.colour(i)),
        );
    }
    // Push: each level's empty cells from the (already complete) level above; at the image
    // only its holes change.
    for k in (1..levels.len()).rev() {
        let (fine, coarse) = levels.split_at_mut(k);
        push(&mut fine[k - 1], &coarse[0], keep);
    }
    push_image(image, &levels[0], keep)
}

/// Eight cells' children in one finer row: disparities and colours of the even and the
/// odd columns.
type Pairs<C> = (F8, F8, C, C);

/// Eight cells' colours as the pull reads them: channels of a pyramid level, or the image's
/// packed bytes.
trait Colours: Copy + Send + Sync {
    /// One cell's.
    type One: Copy;
    /// An absent cell's.
    const NONE: Self::One;
    fn from_lanes(lanes: [Self::One; LANES]) -> Self;
    /// Per channel, the sum of the colours of the lanes each mask keeps, in order (the
    /// first term added to zero).
    fn sum(kids: [(M8, Self); 4]) -> [F8; 4];
}

impl Colours for [F8; 4] {
    type One = [f32; 4];
    const NONE: [f32; 4] = [0.0; 4];

    fn from_lanes(lanes: [[f32; 4]; LANES]) -> Self {
        std::array::from_fn(|c| F8::from_array(lanes.map(|v| v[c])))
    }

    #[inline(always)]
    fn sum(kids: [(M8, Self); 4]) -> [F8; 4] {
        let zero = F8::splat(0.0);
        let mut c = [zero; 4];
        for (m, kc) in kids {
            for (acc, v) in c.iter_mut().zip(kc) {
                *acc = *acc + m.select(v, zero);
            }
        }
        c
    }
}

/// Packed bytes: summed as integers, two channels to a 32-bit lane (four bytes sum to at
/// most 1020, so the halves never carry). Sums of whole numbers under 2^24 are exact in
/// `f32` too, so these are the sums of the stored values the channels' way gives.
impl Colours for I8 {
    type One = u32;
    const NONE: u32 = 0;

    fn from_lanes(lanes: [u32; LANES]) -> Self {
        I8::from_array(lanes.map(|c| c as i32))
    }

    #[inline(always)]
    fn sum(kids: [(M8, Self); 4]) -> [F8; 4] {
        let (zero, pairs) = (I8::splat(0), I8::splat(0x00ff_00ff));
        let (mut rb, mut ga) = (zero, zero);
        for (m, c) in kids {
            let c = m.select_i32(c, zero);
            rb = rb + c.and(pairs);
            ga = ga + c.shr::<8>().and(pairs);
        }
        let low = I8::splat(0xffff);
        [
            rb.and(low).to_f32(),
            ga.and(low).to_f32(),
            rb.shr::<16>().to_f32(),
            ga.shr::<16>().to_f32(),
        ]
    }
}

/// One coarser level from a `fw` x `fh` finer one: each cell the mean of its up to 2 x 2
/// children within the tolerance (`keep = 1 - edge`) of the farthest. Row by row on the
/// thread pool, eight cells at a time: `pairs(i)` reads the sixteen finer cells from `i`
/// on; `kid(i)` one (disparity, [`HOLE`] when empty, and colour), for the edges.
fn pull<C, P, K>(coarse: &mut Level, fw: usize, fh: usize, keep: f32, pairs: P, kid: K)
where
    C: Colours,
    P: Fn(usize) -> Pairs<C> + Sync,
    K: Fn(usize) -> (f32, C::One) + Sync,
{
    let w = coarse.w;
    coarse.rows_mut().for_each(|(y, [disparity, r, g, b, a])| {
        let none = C::from_lanes([C::NONE; LANES]);
        let empty = (F8::splat(HOLE), F8::splat(HOLE), none, none);
        for x in (0..w).step_by(LANES) {
            // The four children of cells x..x + 8, in the order (0, 0), (1, 0), (0, 1),
            // (1, 1); absent ones (past the finer level's edge) are empty.
            let row = |fy: usize| -> Pairs<C> {
                if fy >= fh {
                    empty
                } else if 2 * x + 2 * LANES <= fw {
                    pairs(fy * fw + 2 * x)
                } else {
                    let lanes: [[(f32, C::One); LANES]; 2] = std::array::from_fn(|dx| {
                        std::array::from_fn(|l| {
                            let fx = 2 * (x + l) + dx;
                            if fx < fw {
                                kid(fy * fw + fx)
                            } else {
                                (HOLE, C::NONE)
                            }
                        })
                    });
                    let d = |k: usize| F8::from_array(lanes[k].map(|(d, _)| d));
                    let c = |k: usize| C::from_lanes(lanes[k].map(|(_, v)| v));
                    (d(0), d(1), c(0), c(1))
                }
            };
            let (top, bottom) = (row(2 * y), row(2 * y + 1));
            let kids = [
                (top.0, top.2),
                (top.1, top.3),
                (bottom.0, bottom.2),
                (bottom.1, bottom.3),
            ];
            let (d, c) = reduce(kids, keep);
            let n = LANES.min(w - x);
            let planes = [&mut *disparity, r, g, b, a];
            for (plane, v) in planes.into_iter().zip([d, c[0], c[1], c[2], c[3]]) {
                if n == LANES {
                    v.store(&mut plane[x..]);
                } else {
                    plane[x..x + n].copy_from_slice(&v.to_array()[..n]);
                }
            }
        }
    });
}

/// Eight cells from their children: the mean of those within the tolerance of the
/// farthest, summed in the children's order; [`HOLE`] where none is full.
#[inline(always)]
fn reduce<C: Colours>(kids: [(F8, C); 4], keep: f32) -> (F8, [F8; 4]) {
    let (zero, one) = (F8::splat(0.0), F8::splat(1.0));
    let inf = F8::splat(f32::INFINITY);
    let far = kids
        .iter()
        .fold(inf, |far, (d, _)| far.min(d.ge(zero).select(*d, inf)));
    let (mut wsum, mut dsum) = (zero, zero);
    let kept = kids.map(|(d, kc)| {
        // Within `edge` of the farthest: `z >= z_far (1 - edge)`.
        let near_far = (d * F8::splat(keep)).le(far).or(d.le(far));
        let m = d.ge(zero).and(near_far);
        wsum = wsum + m.select(one, zero);
        dsum = dsum + m.select(d, zero);
        (m, kc)
    });
    let c = C::sum(kept);
    let any = wsum.gt(zero);
    let inv = one / wsum;
    let d = any.select(dsum * inv, F8::splat(HOLE));
    (d, c.map(|v| any.select(v * inv, zero)))
}

/// Fills the empty cells of `fine` from `coarse`, the level above, row by row on the
/// thread pool.
fn push(fine: &mut Level, coarse: &Level, keep: f32) {
    fine.rows_mut().for_each(|(y, [disparity, r, g, b, a])| {
        each_hole(disparity, coarse, y, keep, &mut LevelRow([r, g, b, a]));
    });
}

/// Fills the image's holes from level 1 (its samples stay as they are). Returns the pixels
/// filled.
fn push_image(image: &mut Warped, coarse: &Level, keep: f32) -> (u64, u64) {
    let w = image.width() as usize;
    image
        .color
        .par_chunks_mut(w)
        .zip(image.disparity.par_chunks_mut(w))
        .enumerate()
        .map(|(y, (color, disparity))| {
            let mut row = ImageRow { color, filled: 0 };
            let holes = each_hole(disparity, coarse, y, keep, &mut row);
            (row.filled, holes)
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
}

/// Where the push writes a row's filled holes, besides their disparity.
trait Fill {
    /// Fills hole `x` of `disparity` (the row) with colour `c` and disparity `d`.
    fn one(&mut self, disparity: &mut [f32], x: usize, c: [f32; 4], d: f32);

    /// Fills the holes `mask` sets of the eight from `x`: lane `l` from lane `l` of `c`
    /// and `d`. One by one unless the writer does better.
    #[inline(always)]
    fn group(&mut self, disparity: &mut [f32], x: usize, mask: u32, c: [F8; 4], d: F8) {
        let (d, c) = (d.to_array(), c.map(F8::to_array));
        for_each_bit(mask, |l| {
            self.one(disparity, x + l, [c[0][l], c[1][l], c[2][l], c[3][l]], d[l]);
        });
    }
}

/// Calls `f` with the index of each bit set in `mask`, lowest first.
#[inline(always)]
fn for_each_bit(mut mask: u32, mut f: impl FnMut(usize)) {
    while mask != 0 {
        let l = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        f(l);
    }
}

/// A pyramid level's row: one plane per channel.
struct LevelRow<'a>([&'a mut [f32]; 4]);

impl Fill for LevelRow<'_> {
    #[inline(always)]
    fn one(&mut self, disparity: &mut [f32], x: usize, c: [f32; 4], d: f32) {
        for (plane, v) in self.0.iter_mut().zip(c) {
            plane[x] = v;
        }
        disparity[x] = d;
    }
}

/// The image's row: packed colour; counts the holes filled.
struct ImageRow<'a> {
    color: &'a mut [u32],
    filled: u64,
}

impl Fill for ImageRow<'_> {
    #[inline(always)]
    fn one(&mut self, disparity: &mut [f32], x: usize, c: [f32; 4], d: f32) {
        let byte = |v: f32| (v + 0.5).clamp(0.0, 255.0) as u8;
        self.color[x] = u32::from_le_bytes(c.map(byte));
        disparity[x] = d;
        self.filled += 1;
    }

    /// Packs the eight colours at once, as [`ImageRow::one`] does each: `+ 0.5`, clamped
    /// (a NaN to 0: `max` returns its second operand then), truncated.
    #[inline(always)]
    fn group(&mut self, disparity: &mut [f32], x: usize, mask: u32, c: [F8; 4], d: F8) {
        let (zero, top, half) = (F8::splat(0.0), F8::splat(255.0), F8::splat(0.5));
        let [r, g, b, a] = c.map(|v| (v + half).max(zero).min(top).to_i32());
        let packed = r.or(g.shl::<8>()).or(b.shl::<16>()).or(a.shl::<24>());
        let (packed, d) = (packed.to_array(), d.to_array());
        for_each_bit(mask, |l| {
            self.color[x + l] = packed[l] as u32;
            disparity[x + l] = d[l];
        });
        self.filled += mask.count_ones() as u64;
    }
}

/// Fills each hole (negative disparity) of fine row `y` (`row`: its disparities) that its
/// parents in `coarse` can fill, in order, through `fill`. Holes are found eight at a time;
/// a group of eight away from the level's left and right edges takes its parents eight at
/// a time too ([`parents`]), the others one by one ([`parent`]), with the same values.
/// Returns the holes it found.
#[inline(always)]
fn each_hole(row: &mut [f32], coarse: &Level, y: usize, keep: f32, fill: &mut impl Fill) -> u64 {
    let zero = F8::splat(0.0);
    let mut holes = 0;
    for k in (0..row.len()).step_by(LANES) {
        let group = &row[k..row.len().min(k + LANES)];
        let mask = if group.len() == LANES {
            F8::load(group).lt(zero).bits()
        } else {
            group
                .iter()
                .enumerate()
                .fold(0, |m, (l, &d)| m | ((d < 0.0) as u32) << l)
        };
        if mask == 0 {
            continue;
        }
        holes += u64::from(mask.count_ones());
        if group.len() == LANES && k >= LANES && k / 2 - 1 + LANES <= coarse.w {
            let (d, c, some) = parents(coarse, k, y, keep);
            if mask & some != 0 {
                fill.group(row, k, mask & some, c, d);
            }
        } else {
            for_each_bit(mask, |l| {
                if let Some((c, d)) = parent(coarse, k + l, y, keep) {
                    fill.one(row, k + l, c, d);
                }
            });
        }
    }
    holes
}

/// [`parent`] for fine cells `x..x + 8` of row `y` at once (`x` a multiple of eight, at
/// least eight, and the coarse cells `x / 2 - 1 .. x / 2 + 7` inside the level): their
/// disparities, colours, and the lanes that have a parent. The same operations in the same
/// order as [`parent`], so the same values.
#[inline(always)]
fn parents(coarse: &Level, x: usize, y: usize, keep: f32) -> (F8, [F8; 4], u32) {
    let ([y0, y1], [wy0, wy1]) = taps(y, coarse.h);
    let first = x / 2 - 1;
    // Lane `l` lies between coarse cells `first + (l + 1) / 2` and the next.
    const LEFT: [u32; LANES] = [0, 1, 1, 2, 2, 3, 3, 4];
    const RIGHT: [u32; LANES] = [1, 2, 2, 3, 3, 4, 4, 5];
    // Even lanes (even fine cells) weigh their left cell a quarter, odd lanes three.
    let wl = F8::from_array(std::array::from_fn(
        |l| if l % 2 == 0 { 0.25 } else { 0.75 },
    ));
    let wr = F8::from_array(std::array::from_fn(
        |l| if l % 2 == 0 { 0.75 } else { 0.25 },
    ));
    let row = |cy: usize, plane: &[f32]| {
        let v = F8::load(&plane[cy * coarse.w + first..]);
        (v.permute(LEFT), v.permute(RIGHT))
    };
    let tap = |cy: usize| {
        let (dl, dr) = row(cy, &coarse.disparity);
        let c = coarse.color.each_ref().map(|p| row(cy, p));
        ((dl, c.map(|c| c.0)), (dr, c.map(|c| c.1)))
    };
    let ((d00, c00), (d10, c10)) = tap(y0);
    let ((d01, c01), (d11, c11)) = tap(y1);
    let (wy0, wy1) = (F8::splat(wy0), F8::splat(wy1));
    // Taps in the order (0, 0), (1, 0), (0, 1), (1, 1), as `parent` takes them.
    let taps = [
        (d00, c00, wl * wy0),
        (d10, c10, wr * wy0),
        (d01, c01, wl * wy1),
        (d11, c11, wr * wy1),
    ];
    let (zero, inf) = (F8::splat(0.0), F8::splat(f32::INFINITY));
    let far = taps
        .iter()
        .fold(inf, |far, (d, _, _)| d.ge(zero).select(far.min(*d), far));
    let (mut c, mut wsum) = ([zero; 4], zero);
    for (d, tc, wt) in taps {
        let m = d.ge(zero).and((d * F8::splat(keep)).le(far).or(d.le(far)));
        for (acc, v) in c.iter_mut().zip(tc) {
            *acc = *acc + m.select(v * wt, zero);
        }
        wsum = wsum + m.select(wt, zero);
    }
    let inv = F8::splat(1.0) / wsum;
    (far, c.map(|v| v * inv), wsum.gt(zero).bits())
}

/// The two coarse cells (clamped to `0..n`) whose centres bracket fine cell `x`'s centre
/// (`x / 2 - 1/4` in coarse cells), and their bilinear weights: a quarter and three
/// quarters, exactly.
#[inline(always)]
fn taps(x: usize, n: usize) -> ([usize; 2], [f32; 2]) {
    let c0 = (x as isize - 1) >> 1;
    let clamp = |c: isize| c.clamp(0, n as isize - 1) as usize;
    let w = if x.is_multiple_of(2) {
        [0.25, 0.75]
    } else {
        [0.75, 0.25]
    };
    ([clamp(c0), clamp(c0 + 1)], w)
}

/// The coarse level's colour and disparity under fine cell `(x, y)`: bilinear over the
/// parent cells that are full and lie within the tolerance of the farthest of them (so a
/// hole beside foreground takes the background's colour); the disparity is the farthest's.
#[inline]
fn parent(coarse: &Level, x: usize, y: usize, keep: f32) -> Option<([f32; 4], f32)> {
    let ([x0, x1], [wx0, wx1]) = taps(x, coarse.w);
    let ([y0, y1], [wy0, wy1]) = taps(y, coarse.h);
    let (r0, r1) = (y0 * coarse.w, y1 * coarse.w);
    // Taps in the order (0, 0), (1, 0), (0, 1), (1, 1).
    let index = [r0 + x0, r0 + x1, r1 + x0, r1 + x1];
    let weight = [wx0 * wy0, wx1 * wy0, wx0 * wy1, wx1 * wy1];
    let d = index.map(|i| coarse.disparity[i]);
    let far = d.iter().fold(
        f32::INFINITY,
        |far, &d| if d >= 0.0 { far.min(d) } else { far },
    );
    let (mut c, mut wsum) = ([0.0f32; 4], 0.0f32);
    for k in 0..4 {
        if d[k] < 0.0 || !(d[k] * keep <= far || d[k] == far) {
            continue;
        }
        let (i, wt) = (index[k], weight[k]);
        for (acc, plane) in c.iter_mut().zip(&coarse.color) {
            *acc += plane[i] * wt;
        }
        wsum += wt;
    }
    (wsum > 0.0).then(|| {
        let inv = 1.0 / wsum;
        (c.map(|v| v * inv), far)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use engine::Camera;
    use glam::Vec3;

    /// Pull-push by its definition, one cell at a time with weights (Gortler 96, Kraus
    /// 2009): a cell's weight is its kept children's summed and capped at one; push blends
    /// `w c + (1 - w) c_parent`. Colour planes of `[f32; 4]`, disparity, weight.
    type Slow = (usize, usize, Vec<[f32; 4]>, Vec<f32>, Vec<f32>);

    fn slow_pull(fine: &Slow, keep: f32) -> Slow {
        let (fw, fh) = (fine.0, fine.1);
        let (w, h) = (fw.div_ceil(2), fh.div_ceil(2));
        let mut out = (
            w,
            h,
            vec![[0.0; 4]; w * h],
            vec![HOLE; w * h],
            vec![0.0; w * h],
        );
        for y in 0..h {
            for x in 0..w {
                let kids: Vec<usize> = [(0, 0), (1, 0), (0, 1), (1, 1)]
                    .iter()
                    .map(|&(dx, dy)| (2 * x + dx, 2 * y + dy))
                    .filter(|&(fx, fy)| fx < fw && fy < fh)
                    .map(|(fx, fy)| fy * fw + fx)
                    .filter(|&i| fine.4[i] > 0.0)
                    .collect();
                let far = kids
                    .iter()
                    .map(|&i| fine.3[i])
                    .fold(f32::INFINITY, f32::min);
                let (mut c, mut wsum, mut dsum) = ([0.0f32; 4], 0.0f32, 0.0f32);
                for &i in &kids {
                    let d = fine.3[i];
                    if d * keep <= far || d == far {
                        let wt = fine.4[i];
                        for (acc, v) in c.iter_mut().zip(fine.2[i]) {
                            *acc += v * wt;
                        }
                        wsum += wt;
                        dsum += d * wt;
                    }
                }
                if wsum > 0.0 {
                    let (i, inv) = (y * w + x, 1.0 / wsum);
                    out.2[i] = c.map(|v| v * inv);
                    out.3[i] = dsum * inv;
                    out.4[i] = wsum.min(1.0);
                }
            }
        }
        out
    }

    fn slow_parent(coarse: &Slow, x: usize, y: usize, keep: f32) -> Option<([f32; 4], f32)> {
        let (fx, fy) = ((x as f32 + 0.5) * 0.5 - 0.5, (y as f32 + 0.5) * 0.5 - 0.5);
        let (x0, y0) = (fx.floor(), fy.floor());
        let (tx, ty) = (fx - x0, fy - y0);
        let taps: Vec<(usize, f32)> = [
            (0, 0, (1.0 - tx) * (1.0 - ty)),
            (1, 0, tx * (1.0 - ty)),
            (0, 1, (1.0 - tx) * ty),
            (1, 1, tx * ty),
        ]
        .iter()
        .map(|&(dx, dy, wt)| {
            let cx = (x0 as i64 + dx).clamp(0, coarse.0 as i64 - 1) as usize;
            let cy = (y0 as i64 + dy).clamp(0, coarse.1 as i64 - 1) as usize;
            (cy * coarse.0 + cx, wt)
        })
        .filter(|&(i, wt)| coarse.4[i] > 0.0 && wt > 0.0)
        .collect();
        let far = taps
            .iter()
            .map(|&(i, _)| coarse.3[i])
            .fold(f32::INFINITY, f32::min);
        let (mut c, mut wsum) = ([0.0f32; 4], 0.0f32);
        for &(i, wt) in &taps {
            let d = coarse.3[i];
            if d * keep <= far || d == far {
                for (acc, v) in c.iter_mut().zip(coarse.2[i]) {
                    *acc += v * wt;
                }
                wsum += wt;
            }
        }
        (wsum > 0.0).then(|| (c.map(|v| v * (1.0 / wsum)), far))
    }

    fn slow_fill(image: &mut Warped, edge: f32) {
        let keep = 1.0 - edge;
        let (w, h) = (image.width() as usize, image.height() as usize);
        let bytes = |c: u32| c.to_le_bytes().map(f32::from);
        let weight = |d: f32| if d >= 0.0 { 1.0 } else { 0.0 };
        let base: Slow = (
            w,
            h,
            image.color.iter().map(|&c| bytes(c)).collect(),
            image.disparity.clone(),
            image.disparity.iter().map(|&d| weight(d)).collect(),
        );
        let mut levels = vec![slow_pull(&base, keep)];
        while levels.last().is_some_and(|l| l.0 > 1 || l.1 > 1) {
            levels.push(slow_pull(levels.last().unwrap(), keep));
        }
        for k in (0..levels.len() - 1).rev() {
            let (fine, coarse) = levels.split_at_mut(k + 1);
            let (fine, coarse) = (&mut fine[k], &coarse[0]);
            for i in 0..fine.3.len() {
                let wt = fine.4[i];
                if wt >= 1.0 {
                    continue;
                }
                if let Some((pc, pd)) = slow_parent(coarse, i % fine.0, i / fine.0, keep) {
                    let c = fine.2[i];
                    fine.2[i] = std::array::from_fn(|k| c[k] * wt + pc[k] * (1.0 - wt));
                    if wt <= 0.0 {
                        fine.3[i] = pd;
                    }
                    fine.4[i] = 1.0;
                }
            }
        }
        for i in 0..w * h {
            if image.disparity[i] < 0.0 {
                if let Some((c, d)) = slow_parent(&levels[0], i % w, i / w, keep) {
                    let byte = |v: f32| (v + 0.5).clamp(0.0, 255.0) as u8;
                    image.color[i] = u32::from_le_bytes(c.map(byte));
                    image.disparity[i] = d;
                }
            }
        }
    }

    #[test]
    fn the_vectorised_pyramid_fills_as_the_definition_does() {
        // Odd sizes (ragged edges at every level), sizes under eight cells, and holes from
        // single pixels to wide gaps, beside near and far samples.
        let camera = Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 1.0, 1.0);
        let mut levels = Vec::new();
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        for (w, h) in [(1, 5), (3, 2), (7, 7), (37, 19), (64, 33), (130, 71)] {
            for holes in [0.05, 0.4, 0.9] {
                let mut image = Warped::new(w, h, camera);
                for (c, d) in image.color.iter_mut().zip(&mut image.disparity) {
                    let r = next();
                    let wide_gap = (r >> 20) % 97 < 9;
                    if (r % 1000) as f32 >= holes * 1000.0 && !wide_gap {
                        *c = (r >> 32) as u32 | 0xff00_0000;
                        // Two surfaces: near (disparity about 1) and far (about 0.2).
                        *d = if r >> 10 & 1 == 0 { 1.0 } else { 0.2 } + (r >> 40) as f32 * 1e-9;
                    }
                }
                let mut want = image.clone();
                slow_fill(&mut want, 0.05);
                fill(&mut image, &mut levels, 0.05);
                assert!(
                    image.color == want.color && image.disparity == want.disparity,
                    "{w}x{h}, holes {holes}"
                );
            }
        }
    }
}
