//! Stage 2 of the warp, per sample: where it lands and which target pixels its footprint
//! covers. [`Footprints`] does a whole row of a depth image at once as plain loops over
//! arrays, with no branches in the arithmetic (invalid samples are masked, not skipped), so
//! the compiler vectorises them; [`Lane::sample`] does one sample of an LDI. Both compute
//! the same values the same way.

use super::equation::Equation;
use super::{Entry, Prepared, Reconstruction, WarpOptions, WarpStats};
use glam::Vec3;

/// What warping a sample needs besides the sample.
#[derive(Clone, Copy, Debug)]
pub(super) struct Lane {
    pub(super) eq: Equation,
    splats: bool,
    max_splat: f32,
    w2: f32,
    h2: f32,
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
        let (l, in_front) = self.land(base, d, source.slope[s]);
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
/// as planes (`x0 == x1` where the pixel does not land).
#[derive(Debug, Default)]
pub(super) struct Footprints {
    x0: Vec<f32>,
    y0: Vec<f32>,
    x1: Vec<f32>,
    y1: Vec<f32>,
    disparity: Vec<f32>,
}

/// `|x|` without a branch.
#[inline(always)]
fn abs(x: f32) -> f32 {
    f32::from_bits(x.to_bits() & 0x7fff_ffff)
}

/// `x < y ? x : y` and `x > y ? x : y`, as the vector instructions compute them (NaN in
/// `x` gives `y`).
#[inline(always)]
fn min(x: f32, y: f32) -> f32 {
    if x < y {
        x
    } else {
        y
    }
}

#[inline(always)]
fn max(x: f32, y: f32) -> f32 {
    if x > y {
        x
    } else {
        y
    }
}

impl Footprints {
    /// Warps pixels `lo..hi` of row `y` of `source` (one sample per pixel): the same
    /// values [`Lane::sample`] computes, written as one branch-free loop over planes.
    pub(super) fn compute(
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
        let disparity = &source.disparity[row + lo..row + hi];
        let slope = &source.slope[row + lo..row + hi];
        for plane in [
            &mut self.x0,
            &mut self.y0,
            &mut self.x1,
            &mut self.y1,
            &mut self.disparity,
        ] {
            plane.clear();
            plane.resize(n, 0.0);
        }
        let eq = &lane.eq;
        let v = y as f32 + 0.5;
        let rb = eq.a[1] * v + eq.a[2];
        let (a0, b) = (eq.a[0], eq.b);
        let (splats, max_splat, w2, h2) = (lane.splats, lane.max_splat, lane.w2, lane.h2);
        let (x0s, y0s) = (&mut self.x0[..n], &mut self.y0[..n]);
        let (x1s, y1s) = (&mut self.x1[..n], &mut self.y1[..n]);
        let ds = &mut self.disparity[..n];
        let (mut samples, mut behind, mut warped) = (0u32, 0u32, 0u32);
        for k in 0..n {
            let u = (lo + k) as f32 + 0.5;
            let d0 = disparity[k];
            let d = max(d0, 0.0);
            let hx = a0.x * u + rb.x + b.x * d;
            let hy = a0.y * u + rb.y + b.y * d;
            let hz = a0.z * u + rb.z + b.z * d;
            let inv = 1.0 / hz;
            let (x, y) = (hx * inv, hy * inv);
            // The footprint: the columns of the warp's Jacobian (a reference pixel step in
            // x and in y along the surface), summed.
            let [sx, sy] = slope[k];
            let (dxx, dxy, dxz) = (a0.x + b.x * sx, a0.y + b.y * sx, a0.z + b.z * sx);
            let (dyx, dyy, dyz) = (
                eq.a[1].x + b.x * sy,
                eq.a[1].y + b.y * sy,
                eq.a[1].z + b.z * sy,
            );
            let size_x = abs((dxx - x * dxz) * inv) + abs((dyx - x * dyz) * inv);
            let size_y = abs((dxy - y * dxz) * inv) + abs((dyy - y * dyz) * inv);
            let size_x = min(max(size_x, 1.0), max_splat);
            let size_y = min(max(size_y, 1.0), max_splat);
            let fine = splats & (abs(size_x) < f32::INFINITY) & (abs(size_y) < f32::INFINITY);
            let half_x = if fine { size_x * 0.5 } else { 0.5 };
            let half_y = if fine { size_y * 0.5 } else { 0.5 };
            let (px, py) = (x.floor(), y.floor());
            let sx0 = (x - half_x + 0.5).floor();
            let sx1 = max((x + half_x + 0.5).floor(), sx0 + 1.0);
            let sy0 = (y - half_y + 0.5).floor();
            let sy1 = max((y + half_y + 0.5).floor(), sy0 + 1.0);
            let (rx0, rx1) = if half_x <= 0.5 {
                (px, px + 1.0)
            } else {
                (sx0, sx1)
            };
            let (ry0, ry1) = if half_y <= 0.5 {
                (py, py + 1.0)
            } else {
                (sy0, sy1)
            };
            let (rx0, rx1) = (max(rx0, 0.0), min(rx1, w2));
            let (ry0, ry1) = (max(ry0, 0.0), min(ry1, h2));
            let filled = d0 >= 0.0;
            let front = hz > 0.0;
            let finite = (abs(x) < f32::INFINITY) & (abs(y) < f32::INFINITY);
            let hit = filled & front & finite & (rx0 < rx1) & (ry0 < ry1);
            x0s[k] = if hit { rx0 } else { 0.0 };
            x1s[k] = if hit { rx1 } else { 0.0 };
            y0s[k] = ry0;
            y1s[k] = ry1;
            ds[k] = d * inv;
            samples += filled as u32;
            behind += (filled & !front) as u32;
            warped += hit as u32;
        }
        WarpStats {
            samples: samples as u64,
            warped: warped as u64,
            behind: behind as u64,
            pixels_written: 0,
        }
    }

    /// The entry of pixel `k` of the row computed last (counted from its `lo`), with
    /// colour `color`; `None` when it does not land.
    #[inline]
    pub(super) fn entry(&self, k: usize, color: u32) -> Option<Entry> {
        let (x0, x1) = (self.x0[k], self.x1[k]);
        (x0 < x1).then(|| Entry {
            x0: x0 as u16,
            y0: self.y0[k] as u16,
            x1: x1 as u16,
            y1: self.y1[k] as u16,
            disparity: self.disparity[k],
            color,
        })
    }
}
