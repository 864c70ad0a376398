//! Stage 2 of the warp, per sample: where it lands and which target pixels its footprint
//! covers. [`warp_row`] does a row of a depth image, eight samples at a time in vector
//! registers ([`engine::simd`]), with no branches (invalid samples are masked, not
//! skipped), and hands the groups to the writer sixteen at a time; [`Lane::sample`] does one sample
//! of an LDI. Both compute the same values by the same formulas (products and sums fused,
//! rounded once, on both).

use super::equation::Equation;
use super::Visibility;
use super::HOLE;
use super::{Entry, Prepared, Reconstruction, WarpOptions, WarpStats};
use engine::simd::{F8, I8, LANES, M8};
use glam::Vec3;

/// Pixels `lo..hi` of a reference row and the range of their disparities: `(lo, hi, range)`.
pub(super) type Piece = (u32, u32, [f32; 2]);

/// What warping a sample needs besides the sample.
#[derive(Clone, Copy, Debug)]
pub(super) struct Lane {
    pub(super) eq: Equation,
    splats: bool,
    max_splat: f32,
    w2: f32,
    h2: f32,
    /// Whether opaque one-pixel footprints are marked as points (painted over, and target
    /// pixel indices fit an `i32`).
    points: bool,
}

/// The largest splat side in pixels whatever the options ask: finite, so a footprint's
/// half size is too, and larger than any target ([`Entry`] coordinates are 16-bit).
const MAX_SPLAT: f32 = 65536.0;

/// A sample's landing: target position, disparity and half footprint, or `None` when it
/// is behind the target eye.
#[derive(Clone, Copy, Debug)]
struct Landing {
    x: f32,
    y: f32,
    disparity: f32,
    half_x: f32,
    half_y: f32,
}

impl Lane {
    pub(super) fn new(eq: &Equation, options: &WarpOptions, w2: u32, h2: u32) -> Self {
        Lane {
            eq: *eq,
            splats: options.reconstruction == Reconstruction::Splats,
            // `max` first: a NaN option is one pixel.
            max_splat: options.max_splat.max(1.0).clamp(1.0, MAX_SPLAT),
            w2: w2 as f32,
            h2: h2 as f32,
            points: options.visibility == Visibility::Ordered
                && (w2 as u64 * h2 as u64) < i32::MAX as u64,
        }
    }

    /// `A x1` of reference pixel `(x, y)` (at its centre), as the rows compute it: row `y`'s
    /// part first, then `x`'s, fused.
    #[inline]
    pub(super) fn base(&self, x: u32, y: u32) -> Vec3 {
        let rb = self.row_base(y);
        let u = x as f32 + 0.5;
        let a0 = self.eq.a[0];
        Vec3::new(
            a0.x.mul_add(u, rb.x),
            a0.y.mul_add(u, rb.y),
            a0.z.mul_add(u, rb.z),
        )
    }

    /// `A x1` of reference row `y` at `x = 0`.
    #[inline]
    fn row_base(&self, y: u32) -> Vec3 {
        self.eq.a[1] * (y as f32 + 0.5) + self.eq.a[2]
    }

    /// The landing of a sample of disparity `d` and slope `slope` at a pixel whose `A x1`
    /// is `base`, and whether it is in front of the eye (`h.z > 0`). The formulas of
    /// [`warp_row`], lane for lane.
    #[inline(always)]
    fn land(&self, base: Vec3, d: f32, slope: [f32; 2]) -> (Landing, bool) {
        let eq = &self.eq;
        let (a0, a1, b) = (eq.a[0], eq.a[1], eq.b);
        let h = Vec3::new(
            b.x.mul_add(d, base.x),
            b.y.mul_add(d, base.y),
            b.z.mul_add(d, base.z),
        );
        let inv = 1.0 / h.z;
        let (x, y) = (h.x * inv, h.y * inv);
        let (half_x, half_y) = if self.splats {
            // The columns of the warp's Jacobian (a reference pixel step in x and in y along
            // the surface): `((a_k + b s_k) - p (a_k.z + b.z s_k)) / h.z` for target
            // coordinate `p`, summed in magnitude.
            let fnma = |a: f32, b: f32, c: f32| (-a).mul_add(b, c);
            let (px, py) = (fnma(x, b.z, b.x), fnma(y, b.z, b.y));
            let jxx = slope[0].mul_add(px, fnma(x, a0.z, a0.x));
            let jyx = slope[1].mul_add(px, fnma(x, a1.z, a1.x));
            let jxy = slope[0].mul_add(py, fnma(y, a0.z, a0.y));
            let jyy = slope[1].mul_add(py, fnma(y, a1.z, a1.y));
            let size = |a: f32, b: f32| clamp_splat((a.abs() + b.abs()) * inv, self.max_splat);
            (size(jxx, jyx) * 0.5, size(jxy, jyy) * 0.5)
        } else {
            (0.5, 0.5)
        };
        let landing = Landing {
            x,
            y,
            disparity: d * inv,
            half_x,
            half_y,
        };
        (landing, h.z > 0.0)
    }

    /// For each of up to [`LANES`] pieces of reference row `y` (pixels `lo[l]..hi[l]`, with
    /// disparities within `range[l]`), the target rows `[y0, y1)` its samples can cover;
    /// `None` when none can land on the image. Taken from the four corners of
    /// `[lo, hi) x range`: where `h.z` is positive over that rectangle the target position
    /// is a ratio of linear functions, whose extremes lie at corners. Near `h.z = 0` (or
    /// behind the eye) every row. Conservative by a pixel (plus rounding), so a sample it
    /// leaves out lands nowhere. Eight pieces at once: a frame bounds tens of thousands.
    pub(super) fn bounds(&self, y: u32, pieces: &[Piece]) -> [Option<(u32, u32)>; LANES] {
        let splat = F8::splat;
        let lane = |f: &dyn Fn(&Piece) -> f32, pad: f32| {
            F8::from_array(std::array::from_fn(|l| pieces.get(l).map_or(pad, f)))
        };
        // Absent lanes are empty pieces.
        let (lo, hi) = (lane(&|p| p.0 as f32, 0.0), lane(&|p| p.1 as f32, 0.0));
        let (r0, r1) = (lane(&|p| p.2[0], 1.0), lane(&|p| p.2[1], 0.0));
        let eq = &self.eq;
        let rb = eq.a[1] * (y as f32 + 0.5) + eq.a[2];
        let (zero, inf) = (splat(0.0), splat(f32::INFINITY));
        let ninf = splat(f32::NEG_INFINITY);
        let (mut x_lo, mut x_hi, mut y_lo, mut y_hi) = (inf, ninf, inf, ninf);
        let mut clear = M8::from_bits((1 << LANES) - 1);
        for u in [lo + splat(0.5), hi - splat(0.5)] {
            for d in [r0, r1] {
                // `a0 u + rb + b d`, as `Vec3` arithmetic rounds it.
                let h = |a: f32, r: f32, b: f32| splat(a) * u + splat(r) + splat(b) * d;
                let (hx, hy, hz) = (
                    h(eq.a[0].x, rb.x, eq.b.x),
                    h(eq.a[0].y, rb.y, eq.b.y),
                    h(eq.a[0].z, rb.z, eq.b.z),
                );
                // The size of the terms `h.z` sums: well away from zero relative to them,
                // rounding cannot move a sample's position far from these corners'.
                let scale =
                    (splat(eq.a[0].z) * u).abs() + splat(rb.z.abs()) + (splat(eq.b.z) * d).abs();
                let finite = hx.abs().lt(inf).and(hy.abs().lt(inf)).and(hz.abs().lt(inf));
                clear = clear.and(hz.gt(splat(1e-2) * scale)).and(finite);
                let (x, y) = (hx / hz, hy / hz);
                (x_lo, x_hi) = (x_lo.min(x), x_hi.max(x));
                (y_lo, y_hi) = (y_lo.min(y), y_hi.max(y));
            }
        }
        let half = splat(if self.splats {
            self.max_splat * 0.5
        } else {
            0.5
        });
        let slack = |v: F8| half + splat(0.51) + splat(1e-4) * v.abs();
        let (mx, my) = (slack(x_lo).max(slack(x_hi)), slack(y_lo).max(slack(y_hi)));
        let on_image = (x_hi + mx).ge(zero).and((x_lo - mx).lt(splat(self.w2)));
        let y0 = (y_lo - my).floor().max(zero).to_array();
        let y1 = ((y_hi + my).floor() + splat(1.0))
            .min(splat(self.h2))
            .to_array();
        let (clear, on_image) = (clear.bits(), on_image.bits());
        std::array::from_fn(|l| {
            let (lo, hi, range) = *pieces.get(l)?;
            if range[0].partial_cmp(&range[1]).is_none_or(|o| o.is_gt()) || lo >= hi {
                None
            } else if clear >> l & 1 == 0 {
                Some((0, self.h2 as u32))
            } else {
                (on_image >> l & 1 == 1 && y0[l] < y1[l]).then(|| (y0[l] as u32, y1[l] as u32))
            }
        })
    }

    /// The target rectangle of a landing, `[x0, x1) x [y0, y1)`; empty (`x0 >= x1` or
    /// `y0 >= y1`) when off the image or not finite.
    #[inline(always)]
    fn rect(&self, l: &Landing) -> [f32; 4] {
        let (x0, x1) = span(l.x, l.half_x, self.w2, self.splats);
        let (y0, y1) = span(l.y, l.half_y, self.h2, self.splats);
        [x0, y0, x1, y1]
    }

    /// Warps sample `s` of `source` at a pixel whose `A x1` is `base`: its entry, unless it
    /// is empty, behind the eye or off the image.
    #[inline]
    pub(super) fn sample(
        &self,
        source: &Prepared,
        s: usize,
        base: Vec3,
        stats: &mut WarpStats,
    ) -> Option<Entry> {
        let d = source.disparity[s];
        if d.is_nan() || d < 0.0 {
            return None;
        }
        stats.samples += 1;
        let (l, in_front) = self.land(base, d, [source.slope_x[s], source.slope_y[s]]);
        if !in_front {
            stats.behind += 1;
            return None;
        }
        let [x0, y0, x1, y1] = self.rect(&l);
        if !(x0 < x1 && y0 < y1) {
            return None;
        }
        stats.warped += 1;
        Some(Entry {
            x0: x0 as u16,
            y0: y0 as u16,
            x1: x1 as u16,
            y1: y1 as u16,
            disparity: l.disparity,
            color: source.color[s],
        })
    }
}

/// A splat's size from the Jacobian's summed column (or row) magnitude: at least one
/// pixel (a NaN too), at most `max`.
#[inline(always)]
fn clamp_splat(size: f32, max: f32) -> f32 {
    let at_least_one = if size > 1.0 { size } else { 1.0 };
    if max < at_least_one {
        max
    } else {
        at_least_one
    }
}

/// The pixels `[lo, hi)` of `0..n` whose centres lie within `half` of `c` (splats), at
/// least one; or the pixel `c` is in. Clamped to the image, so empty (`lo >= hi`) when off
/// it, and when `c` is not finite (a NaN bound compares false).
#[inline(always)]
fn span(c: f32, half: f32, n: f32, splats: bool) -> (f32, f32) {
    let (lo, hi) = if splats {
        let centre = c + 0.5;
        let lo = (centre - half).floor();
        let hi = (centre + half).floor();
        (lo, if hi > lo + 1.0 { hi } else { lo + 1.0 })
    } else {
        let lo = c.floor();
        (lo, lo + 1.0)
    };
    // As `F8::max(0, lo)` and `F8::min(n, hi)`: a NaN bound is kept.
    (if 0.0 > lo { 0.0 } else { lo }, if n < hi { n } else { hi })
}

/// Up to [`LANES`] samples of a row warped at once: each one's target rectangle
/// `[x0, x1) x [y0, y1)` (empty, all zero, where it does not land), disparity and colour.
#[derive(Clone, Copy, Debug)]
pub(super) struct Group {
    pub(super) x0: [i32; LANES],
    pub(super) y0: [i32; LANES],
    pub(super) x1: [i32; LANES],
    pub(super) y1: [i32; LANES],
    pub(super) disparity: [f32; LANES],
    pub(super) color: [u32; LANES],
    /// The target pixel (`y w + x`) of a point: an opaque sample covering one pixel, when
    /// [`Lane`] marks points; -1 for every other sample.
    pub(super) at: [i32; LANES],
    /// Lanes `0..n` hold samples.
    pub(super) n: usize,
    /// Whether all [`LANES`] are points on consecutive pixels (`at[0] + l`), which can be
    /// written as one block in any order.
    pub(super) run: bool,
    /// Whether all [`LANES`] are points, written with no branch per lane.
    pub(super) points: bool,
}

/// Groups [`warp_row`] computes before handing them on.
const BATCH: usize = 16;

impl Group {
    /// No sample.
    const EMPTY: Group = Group {
        x0: [0; LANES],
        y0: [0; LANES],
        x1: [0; LANES],
        y1: [0; LANES],
        disparity: [0.0; LANES],
        color: [0; LANES],
        at: [-1; LANES],
        n: 0,
        run: false,
        points: false,
    };
}

/// Where [`warp_row`] hands its groups. A trait rather than a closure so that the band
/// writer's `#[inline(always)]` method joins the row's loop (a closure that large was
/// called per group, measured as 14% of a 1080p warp).
pub(super) trait Emit {
    fn group(&mut self, g: &Group);
}

impl<F: FnMut(&Group)> Emit for F {
    #[inline(always)]
    fn group(&mut self, g: &Group) {
        self(g)
    }
}

/// The first `LANES` values of `s` from `k`, padded with `pad` past its end.
#[inline(always)]
fn lanes(s: &[f32], k: usize, pad: f32) -> F8 {
    if k + LANES <= s.len() {
        F8::load(&s[k..])
    } else {
        F8::from_array(std::array::from_fn(|l| {
            s.get(k + l).copied().unwrap_or(pad)
        }))
    }
}

/// Warps pixels `lo..hi` of row `y` of `source` (one sample per pixel) and hands each group
/// of [`LANES`] samples to `emit`, in the traversal's order: left to right, or right to
/// left (`reverse`: the groups from the last, whose lanes `emit` then takes last first).
/// The values [`Lane::sample`] computes, eight samples at a time, with no branches (invalid
/// samples are masked, not skipped). Returns those behind the eye and those that land
/// (`samples` is left at zero: the reference knows how many it holds).
pub(super) fn warp_row(
    lane: &Lane,
    source: &Prepared,
    y: u32,
    (lo, hi): (u32, u32),
    reverse: bool,
    emit: &mut impl Emit,
) -> WarpStats {
    if lane.splats {
        warp_row_with::<true>(lane, source, y, (lo, hi), reverse, emit)
    } else {
        warp_row_with::<false>(lane, source, y, (lo, hi), reverse, emit)
    }
}

/// The pixel rectangle `[x0, x1) x [y0, y1)` (as `(x0, x1, y0, y1)`, not yet clipped to
/// the target) that group `k`'s samples landing at `(x, y)` cover, `inv` the reciprocal of
/// their homogeneous depth: their footprint with splats, else the pixel they land in.
#[inline(always)]
fn footprint<const SPLATS: bool>(
    lane: &Lane,
    (slope_x, slope_y): (&[f32], &[f32]),
    k: usize,
    x: F8,
    y: F8,
    inv: F8,
) -> (F8, F8, F8, F8) {
    let splat = F8::splat;
    let (one, half) = (splat(1.0), splat(0.5));
    if SPLATS {
        let (a0, a1, b) = (lane.eq.a[0], lane.eq.a[1], lane.eq.b);
        let max_half = splat(lane.max_splat * 0.5);
        // The footprint: the columns of the warp's Jacobian (a reference pixel step in
        // x and in y along the surface), summed in magnitude; as `Lane::land`.
        let (sx, sy) = (lanes(slope_x, k, 0.0), lanes(slope_y, k, 0.0));
        let px = x.fnma(splat(b.z), splat(b.x));
        let py = y.fnma(splat(b.z), splat(b.y));
        let jxx = sx.fma(px, x.fnma(splat(a0.z), splat(a0.x)));
        let jyx = sy.fma(px, x.fnma(splat(a1.z), splat(a1.x)));
        let jxy = sx.fma(py, y.fnma(splat(a0.z), splat(a0.y)));
        let jyy = sy.fma(py, y.fnma(splat(a1.z), splat(a1.y)));
        // At least one pixel (a NaN too: `max` returns its second operand then), at
        // most the largest splat; `clamp_splat`'s comparisons, one instruction each.
        // Halved by a factor taken into `inv` (scaling by two rounds nothing: the same
        // values as halving the clamped size).
        let inv_half = inv * half;
        let half_size = |a: F8, b: F8| ((a.abs() + b.abs()) * inv_half).max(half).min(max_half);
        let (half_x, half_y) = (half_size(jxx, jyx), half_size(jxy, jyy));
        let (cx, cy) = (x + half, y + half);
        let (sx0, sy0) = ((cx - half_x).floor(), (cy - half_y).floor());
        let (sx1, sy1) = ((cx + half_x).floor(), (cy + half_y).floor());
        let (sx1, sy1) = (sx1.max(sx0 + one), sy1.max(sy0 + one));
        (sx0, sx1, sy0, sy1)
    } else {
        let (px, py) = (x.floor(), y.floor());
        (px, px + one, py, py + one)
    }
}

/// [`warp_row`] for splats (`SPLATS`) or points.
fn warp_row_with<const SPLATS: bool>(
    lane: &Lane,
    source: &Prepared,
    y: u32,
    (lo, hi): (u32, u32),
    reverse: bool,
    emit: &mut impl Emit,
) -> WarpStats {
    let w1 = source.size().0 as usize;
    let row = y as usize * w1;
    let (lo, hi) = (lo as usize, hi.max(lo) as usize);
    let n = hi - lo;
    let disparity = &source.disparity[row + lo..row + hi];
    let slopes = (&source.slope_x[row + lo..], &source.slope_y[row + lo..]);
    let color = &source.color[row + lo..row + hi];
    let (marks, width) = (
        if lane.points { u32::MAX } else { 0 },
        I8::splat(lane.w2 as i32),
    );
    let eq = &lane.eq;
    let rb = lane.row_base(y);
    let splat = F8::splat;
    let (a0, b) = (eq.a[0], eq.b);
    let zero = splat(0.0);
    let one = splat(1.0);
    let (w2, h2) = (splat(lane.w2), splat(lane.h2));
    let (mut behind, mut warped) = (0u32, 0u32);
    let groups = n.div_ceil(LANES);
    // A batch of groups is computed, then written: the writer's branches (a run or not, a
    // point or a splat) then neither wait on a group's long chain of vector work nor,
    // mispredicted, throw away the next group's (measured on the city frame: 7.4 ms
    // before, 7.0 after).
    let mut batch = [Group::EMPTY; BATCH];
    for first in (0..groups).step_by(BATCH) {
        let m = BATCH.min(groups - first);
        for (slot, g) in batch.iter_mut().zip(first..first + m) {
            let k = LANES * if reverse { groups - 1 - g } else { g };
            let u = F8::ramp() + splat((lo + k) as f32 + 0.5);
            let d0 = lanes(disparity, k, HOLE);
            let d = d0.max(zero);
            let bx = splat(a0.x).fma(u, splat(rb.x));
            let by = splat(a0.y).fma(u, splat(rb.y));
            let bz = splat(a0.z).fma(u, splat(rb.z));
            let hx = splat(b.x).fma(d, bx);
            let hy = splat(b.y).fma(d, by);
            let hz = splat(b.z).fma(d, bz);
            let inv = one / hz;
            let (x, y) = (hx * inv, hy * inv);
            let (rx0, rx1, ry0, ry1) = footprint::<SPLATS>(lane, slopes, k, x, y, inv);
            // A NaN bound is kept (`max` and `min` return their second operand then), and
            // compares false below.
            let (rx0, rx1) = (zero.max(rx0), w2.min(rx1));
            let (ry0, ry1) = (zero.max(ry0), h2.min(ry1));
            let filled = d0.ge(zero);
            let front = hz.gt(zero);
            let hit = filled.and(front).and(rx0.lt(rx1)).and(ry0.lt(ry1));
            // Lanes that miss hold an empty rectangle (and no out-of-range conversion).
            let ix0 = hit.select(rx0, zero).to_i32();
            let ix1 = hit.select(rx1, zero).to_i32();
            let iy0 = hit.select(ry0, zero).to_i32();
            let iy1 = hit.select(ry1, zero).to_i32();
            let c = if k + LANES <= n {
                I8::load_u32(&color[k..])
            } else {
                I8::from_array(std::array::from_fn(|l| {
                    color.get(k + l).map_or(0, |&c| c as i32)
                }))
            };
            let opaque = c.shr::<24>().eq(I8::splat(255));
            let ones = I8::splat(1);
            let point = M8::from_bits(marks)
                .and(hit)
                .and(opaque)
                .and(ix1.eq(ix0 + ones))
                .and(iy1.eq(iy0 + ones));
            let at = point.select_i32(iy0.mul_lo(width) + ix0, I8::splat(-1));
            let first = I8::splat(at.to_array()[0]);
            let full = (1 << LANES) - 1;
            let run = k + LANES <= n
                && point.bits() == full
                && at.eq(I8::ramp_times(1) + first).bits() == full;
            behind += filled.and_not(front).bits().count_ones();
            warped += hit.bits().count_ones();
            *slot = Group {
                x0: ix0.to_array(),
                y0: iy0.to_array(),
                x1: ix1.to_array(),
                y1: iy1.to_array(),
                disparity: (d * inv).to_array(),
                color: c.to_array().map(|c| c as u32),
                at: at.to_array(),
                n: LANES.min(n - k),
                run,
                points: k + LANES <= n && point.bits() == full,
            };
        }
        batch[..m].iter().for_each(|g| emit.group(g));
    }
    WarpStats {
        samples: 0,
        warped: warped as u64,
        behind: behind as u64,
        pixels_written: 0,
    }
}
