//! Stage 2 of the warp, per sample: where it lands and which target pixels its footprint
//! covers. [`Footprints`] does a whole row of a depth image at once, eight samples at a time
//! in vector registers ([`engine::simd`]), with no branches (invalid samples are masked,
//! not skipped); [`Lane::sample`] does one sample of an LDI. Both compute the same values
//! by the same formulas.

use super::equation::Equation;
use super::Visibility;
use super::HOLE;
use super::{Entry, Prepared, Reconstruction, WarpOptions, WarpStats};
use engine::simd::{F8, I8, LANES, M8};
use glam::Vec3;

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
            max_splat: options.max_splat.max(1.0),
            w2: w2 as f32,
            h2: h2 as f32,
            points: options.visibility == Visibility::Ordered
                && (w2 as u64 * h2 as u64) < i32::MAX as u64,
        }
    }

    /// The landing of a sample of disparity `d` and slope `slope` at a pixel whose `A x1`
    /// is `base`, and whether it is in front of the eye (`h.z > 0`).
    #[inline(always)]
    fn land(&self, base: Vec3, d: f32, slope: [f32; 2]) -> (Landing, bool) {
        let eq = &self.eq;
        let h = base + eq.b * d;
        let inv = 1.0 / h.z;
        let (x, y) = (h.x * inv, h.y * inv);
        let (half_x, half_y) = if self.splats {
            // The columns of the warp's Jacobian: how a reference pixel step in x and in y
            // (along the surface) moves in the target.
            let column = |dh: Vec3| ((dh.x - x * dh.z) * inv, (dh.y - y * dh.z) * inv);
            let jx = column(eq.a[0] + eq.b * slope[0]);
            let jy = column(eq.a[1] + eq.b * slope[1]);
            let sx = (jx.0.abs() + jy.0.abs()).clamp(1.0, self.max_splat);
            let sy = (jx.1.abs() + jy.1.abs()).clamp(1.0, self.max_splat);
            let fine = sx.is_finite() && sy.is_finite();
            (
                if fine { sx * 0.5 } else { 0.5 },
                if fine { sy * 0.5 } else { 0.5 },
            )
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

    /// The target rows `[y0, y1)` that samples of reference row `y`, pixels `lo..hi`, with
    /// disparities within `range` can cover; `None` when none can land on the image. Taken
    /// from the four corners of `[lo, hi) x range`: where `h.z` is positive over that
    /// rectangle the target position is a ratio of linear functions, whose extremes lie at
    /// corners. Near `h.z = 0` (or behind the eye) every row. Conservative by a pixel
    /// (plus rounding), so a sample it leaves out lands nowhere.
    pub(super) fn bound(&self, y: u32, lo: u32, hi: u32, range: [f32; 2]) -> Option<(u32, u32)> {
        if range[0].partial_cmp(&range[1]).is_none_or(|o| o.is_gt()) || lo >= hi {
            return None;
        }
        let eq = &self.eq;
        let rb = eq.a[1] * (y as f32 + 0.5) + eq.a[2];
        let every = Some((0, self.h2 as u32));
        let (mut x_lo, mut x_hi) = (f32::INFINITY, f32::NEG_INFINITY);
        let (mut y_lo, mut y_hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for u in [lo as f32 + 0.5, hi as f32 - 0.5] {
            for d in range {
                let h = eq.a[0] * u + rb + eq.b * d;
                // The size of the terms `h.z` sums: well away from zero relative to them,
                // rounding cannot move a sample's position far from these corners'.
                let scale = (eq.a[0].z * u).abs() + rb.z.abs() + (eq.b.z * d).abs();
                let clear = h.z.partial_cmp(&(1e-2 * scale)).is_some_and(|o| o.is_gt());
                if !clear || !h.is_finite() {
                    return every;
                }
                let (x, y) = (h.x / h.z, h.y / h.z);
                (x_lo, x_hi) = (x_lo.min(x), x_hi.max(x));
                (y_lo, y_hi) = (y_lo.min(y), y_hi.max(y));
            }
        }
        let half = if self.splats {
            self.max_splat * 0.5
        } else {
            0.5
        };
        let slack = |v: f32| half + 0.51 + 1e-4 * v.abs();
        let (mx, my) = (slack(x_lo).max(slack(x_hi)), slack(y_lo).max(slack(y_hi)));
        if !(x_hi + mx >= 0.0 && x_lo - mx < self.w2) {
            return None;
        }
        let y0 = (y_lo - my).floor().max(0.0);
        let y1 = ((y_hi + my).floor() + 1.0).min(self.h2);
        (y0 < y1).then_some((y0 as u32, y1 as u32))
    }

    /// The target rectangle of a landing, `[x0, x1) x [y0, y1)`; empty (`x0 == x1`) when
    /// off the image or not finite.
    #[inline(always)]
    fn rect(&self, l: &Landing) -> [f32; 4] {
        let (x0, x1) = span(l.x, l.half_x, self.w2);
        let (y0, y1) = span(l.y, l.half_y, self.h2);
        let inside = x0 < x1 && y0 < y1 && l.x.is_finite() && l.y.is_finite();
        if inside {
            [x0, y0, x1, y1]
        } else {
            [0.0; 4]
        }
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
        if x0 >= x1 {
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

/// The pixels `[lo, hi)` of `0..n` whose centres lie within `half` of `c`; at least the one
/// `c` is in. Empty when off the image.
#[inline(always)]
fn span(c: f32, half: f32, n: f32) -> (f32, f32) {
    let point = c.floor();
    let lo = (c - half + 0.5).floor();
    let hi = (c + half + 0.5).floor().max(lo + 1.0);
    let (lo, hi) = if half <= 0.5 {
        (point, point + 1.0)
    } else {
        (lo, hi)
    };
    (lo.max(0.0), hi.min(n))
}

/// A row of a depth image warped at once: each pixel's target rectangle and disparity,
/// as planes (`x0 == x1` where the pixel does not land), padded to whole groups of
/// [`LANES`].
#[derive(Debug, Default)]
pub(super) struct Footprints {
    x0: Vec<i32>,
    y0: Vec<i32>,
    x1: Vec<i32>,
    y1: Vec<i32>,
    disparity: Vec<f32>,
    /// The target pixel (`y w + x`) of a point: an opaque sample covering one pixel, when
    /// [`Lane`] marks points; -1 for every other sample.
    index: Vec<i32>,
    /// Per whole group of [`LANES`] samples: whether all are points on consecutive pixels
    /// (`index[8 g] + l` for lane `l`), which can be written as one block in any order.
    runs: Vec<bool>,
    /// The pixels of the row computed last.
    n: usize,
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

impl Footprints {
    /// Warps pixels `lo..hi` of row `y` of `source` (one sample per pixel): the values
    /// [`Lane::sample`] computes, eight samples at a time, with no branches (invalid
    /// samples are masked, not skipped). Counts those behind the eye and those that land;
    /// `samples` is left at zero (the reference knows how many it holds).
    pub(super) fn compute(
        &mut self,
        lane: &Lane,
        source: &Prepared,
        y: u32,
        lo: u32,
        hi: u32,
    ) -> WarpStats {
        if lane.splats {
            self.compute_with::<true>(lane, source, y, lo, hi)
        } else {
            self.compute_with::<false>(lane, source, y, lo, hi)
        }
    }

    /// [`Footprints::compute`] for splats (`SPLATS`) or points.
    fn compute_with<const SPLATS: bool>(
        &mut self,
        lane: &Lane,
        source: &Prepared,
        y: u32,
        lo: u32,
        hi: u32,
    ) -> WarpStats {
        let w1 = source.size().0 as usize;
        let row = y as usize * w1;
        let (lo, hi) = (lo as usize, hi as usize);
        let n = hi - lo;
        let padded = n.div_ceil(LANES) * LANES;
        for plane in [
            &mut self.x0,
            &mut self.y0,
            &mut self.x1,
            &mut self.y1,
            &mut self.index,
        ] {
            plane.resize(padded.max(plane.len()), 0);
        }
        self.disparity.resize(padded.max(self.disparity.len()), 0.0);
        self.runs.clear();
        self.n = n;
        let disparity = &source.disparity[row + lo..row + hi];
        let (slope_x, slope_y) = (&source.slope_x[row + lo..], &source.slope_y[row + lo..]);
        let color = &source.color[row + lo..row + hi];
        let (marks, width) = (
            if lane.points { u32::MAX } else { 0 },
            I8::splat(lane.w2 as i32),
        );
        let eq = &lane.eq;
        let v = y as f32 + 0.5;
        let rb = eq.a[1] * v + eq.a[2];
        let splat = F8::splat;
        let (a0, a1, b) = (eq.a[0], eq.a[1], eq.b);
        let zero = splat(0.0);
        let (one, half) = (splat(1.0), splat(0.5));
        let (max_splat, w2, h2) = (splat(lane.max_splat), splat(lane.w2), splat(lane.h2));
        let (finite_clamp, inf) = (lane.max_splat.is_finite(), f32::INFINITY);
        let (mut behind, mut warped) = (0u32, 0u32);
        for k in (0..n).step_by(LANES) {
            let u = F8::ramp() + splat((lo + k) as f32 + 0.5);
            let d0 = lanes(disparity, k, HOLE);
            let d = d0.max(zero);
            let hx = splat(a0.x) * u + splat(rb.x) + splat(b.x) * d;
            let hy = splat(a0.y) * u + splat(rb.y) + splat(b.y) * d;
            let hz = splat(a0.z) * u + splat(rb.z) + splat(b.z) * d;
            let inv = one / hz;
            let (x, y) = (hx * inv, hy * inv);
            let (rx0, rx1, ry0, ry1) = if SPLATS {
                // The footprint: the columns of the warp's Jacobian (a reference pixel step
                // in x and in y along the surface), summed.
                let (sx, sy) = (lanes(slope_x, k, 0.0), lanes(slope_y, k, 0.0));
                let dxx = splat(a0.x) + splat(b.x) * sx;
                let dxy = splat(a0.y) + splat(b.y) * sx;
                let dxz = splat(a0.z) + splat(b.z) * sx;
                let dyx = splat(a1.x) + splat(b.x) * sy;
                let dyy = splat(a1.y) + splat(b.y) * sy;
                let dyz = splat(a1.z) + splat(b.z) * sy;
                let size_x = ((dxx - x * dxz) * inv).abs() + ((dyx - x * dyz) * inv).abs();
                let size_y = ((dxy - y * dxz) * inv).abs() + ((dyy - y * dyz) * inv).abs();
                let size_x = size_x.max(one).min(max_splat);
                let size_y = size_y.max(one).min(max_splat);
                // Clamped to a finite largest splat, sizes are finite (a NaN clamps to 1).
                let fine = if finite_clamp {
                    M8::from_bits(u32::MAX)
                } else {
                    size_x.within(inf).and(size_y.within(inf))
                };
                let half_x = fine.select(size_x * half, half);
                let half_y = fine.select(size_y * half, half);
                let (px, py) = (x.floor(), y.floor());
                let sx0 = (x - half_x + half).floor();
                let sx1 = (x + half_x + half).floor().max(sx0 + one);
                let sy0 = (y - half_y + half).floor();
                let sy1 = (y + half_y + half).floor().max(sy0 + one);
                let (point_x, point_y) = (half_x.le(half), half_y.le(half));
                (
                    point_x.select(px, sx0),
                    point_x.select(px + one, sx1),
                    point_y.select(py, sy0),
                    point_y.select(py + one, sy1),
                )
            } else {
                let (px, py) = (x.floor(), y.floor());
                (px, px + one, py, py + one)
            };
            let (rx0, rx1) = (rx0.max(zero), rx1.min(w2));
            let (ry0, ry1) = (ry0.max(zero), ry1.min(h2));
            let filled = d0.ge(zero);
            let front = hz.gt(zero);
            let finite = x.within(inf).and(y.within(inf));
            let hit = filled
                .and(front)
                .and(finite)
                .and(rx0.lt(rx1))
                .and(ry0.lt(ry1));
            // Lanes that miss hold an empty rectangle (and no out-of-range conversion).
            hit.select(rx0, zero).to_i32().store(&mut self.x0[k..]);
            hit.select(rx1, zero).to_i32().store(&mut self.x1[k..]);
            hit.select(ry0, zero).to_i32().store(&mut self.y0[k..]);
            hit.select(ry1, zero).to_i32().store(&mut self.y1[k..]);
            (d * inv).store(&mut self.disparity[k..]);
            let c = if k + LANES <= n {
                I8::load_u32(&color[k..])
            } else {
                I8::from_array(std::array::from_fn(|l| {
                    color.get(k + l).map_or(0, |&c| c as i32)
                }))
            };
            let opaque = c.shr::<24>().to_f32().ge(splat(255.0));
            let point = M8::from_bits(marks)
                .and(hit)
                .and(opaque)
                .and((rx1 - rx0).le(one))
                .and((ry1 - ry0).le(one));
            let at = hit.select(ry0, zero).to_i32().mul_lo(width) + hit.select(rx0, zero).to_i32();
            let at = point.select_i32(at, I8::splat(-1));
            at.store(&mut self.index[k..]);
            let first = I8::splat(at.to_array()[0]);
            let run = point.bits() == (1 << LANES) - 1
                && at.eq(I8::ramp_times(1) + first).bits() == (1 << LANES) - 1;
            self.runs.push(run && k + LANES <= n);
            behind += filled.and_not(front).bits().count_ones();
            warped += hit.bits().count_ones();
        }
        WarpStats {
            samples: 0,
            warped: warped as u64,
            behind: behind as u64,
            pixels_written: 0,
        }
    }

    /// The pixels of the row computed last.
    pub(super) fn len(&self) -> usize {
        self.n
    }

    /// The row computed last: target rectangles as planes `x0`, `y0`, `x1`, `y1` (`x0 ==
    /// x1` where a pixel does not land), and disparities.
    pub(super) fn planes(&self) -> ([&[i32]; 4], &[f32]) {
        let n = self.n;
        (
            [&self.x0[..n], &self.y0[..n], &self.x1[..n], &self.y1[..n]],
            &self.disparity[..n],
        )
    }

    /// The points' target pixels of the row computed last (-1 where not a point).
    pub(super) fn points(&self) -> &[i32] {
        &self.index[..self.n]
    }

    /// Per group of [`LANES`] samples of the row computed last (the last group, if
    /// partial, included): whether it is a run of points on consecutive pixels.
    pub(super) fn runs(&self) -> &[bool] {
        &self.runs
    }
}
