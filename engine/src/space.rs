//! The pipeline's coordinate spaces and the exact maths that crosses them: clip-space
//! planes and outcodes (with the guard band), the viewport transform onto the snapped
//! fixed-point screen grid, and the integer edge functions that decide coverage. Every stage
//! builds on this module; it depends on none of them.
//!
//! Screen space: x right, y down, pixel centres at `(x + 0.5, y + 0.5)`, vertices snapped to
//! `1 / 2^SUBPIXEL_BITS` pixel.

use crate::simd::{I8, LANES};
use glam::{DVec4, Vec4};

/// Sub-pixel precision of snapped vertices.
pub const SUBPIXEL_BITS: u32 = 8;
/// One pixel in fixed-point units.
pub const ONE: i64 = 1 << SUBPIXEL_BITS;
/// Guard band: how far (pixels) outside the target a vertex may lie before x/y clipping.
pub const GUARD_PX: f32 = 8192.0;

/// Triangles whose vertices span less than `SMALL` pixels each way (so at most `SMALL` x
/// `SMALL` pixel centres) carry their coverage as a mask ([`Tri::cover`]).
pub const SMALL: i32 = 8;

/// The planes, as bits of an outcode.
pub(crate) const NEAR: u8 = 1;
pub(crate) const FAR: u8 = 2;
pub(crate) const LEFT: u8 = 4;
pub(crate) const RIGHT: u8 = 8;
pub(crate) const BOTTOM: u8 = 16;
pub(crate) const TOP: u8 = 32;

/// Guard band in NDC units per axis (`gx`, `gy`): clip-space `|x| <= gx * w`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuardBand {
    pub gx: f32,
    pub gy: f32,
}

#[inline]
pub(crate) fn distance(p: Vec4, plane: u8, g: GuardBand) -> f32 {
    distance64(p.as_dvec4(), plane, g) as f32
}

/// The signed distance in f64: differences of f32 values are exact there, which matters
/// for huge triangles whose w spans millions while the cut lands near w = near.
#[inline]
pub(crate) fn distance64(p: DVec4, plane: u8, g: GuardBand) -> f64 {
    match plane {
        NEAR => p.w - p.z,
        FAR => p.z,
        LEFT => p.x + g.gx as f64 * p.w,
        RIGHT => g.gx as f64 * p.w - p.x,
        BOTTOM => p.y + g.gy as f64 * p.w,
        _ => g.gy as f64 * p.w - p.y,
    }
}

/// Bits of the planes a clip-space position is outside of.
#[inline]
pub fn outcode(p: Vec4, g: GuardBand) -> u8 {
    let mut code = 0;
    for plane in [NEAR, FAR, LEFT, RIGHT, BOTTOM, TOP] {
        // `!(d >= 0)` also flags NaN distances
        if distance(p, plane, g) < 0.0 {
            code |= plane;
        }
    }
    code
}

/// A vertex after the perspective divide: snapped position (coverage), exact position,
/// depth and 1/w in f64 (interpolation planes).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ScreenVert {
    pub x: i32,
    pub y: i32,
    pub fx: f64,
    pub fy: f64,
    pub z: f64,
    pub iw: f64,
}

/// The target's size as the setup stage needs it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Viewport {
    pub width: u32,
    pub height: u32,
}

impl Viewport {
    /// Perspective divide, viewport transform and snap. `None` for non-finite input.
    #[inline]
    pub fn to_screen(self, p: Vec4) -> Option<ScreenVert> {
        let p = p.as_dvec4();
        let iw = 1.0 / p.w;
        let sx = (p.x * iw * 0.5 + 0.5) * self.width as f64;
        let sy = (0.5 - p.y * iw * 0.5) * self.height as f64;
        let z = p.z * iw;
        if !(sx.is_finite() && sy.is_finite() && z.is_finite() && iw.is_finite()) {
            return None;
        }
        let lim = (crate::target::MAX_TARGET_SIZE as f64 + GUARD_PX as f64 * 2.0) * ONE as f64;
        let snap = |v: f64| (v * ONE as f64).round().clamp(-lim, lim) as i32;
        Some(ScreenVert {
            x: snap(sx),
            y: snap(sy),
            fx: sx,
            fy: sy,
            z: z.clamp(0.0, 1.0),
            iw,
        })
    }

    /// The guard band in NDC units.
    pub fn guard(&self) -> GuardBand {
        GuardBand {
            gx: 1.0 + 2.0 * GUARD_PX / self.width.max(1) as f32,
            gy: 1.0 + 2.0 * GUARD_PX / self.height.max(1) as f32,
        }
    }
}

/// Edge function `E(X, Y) = a X + b Y + c` (fixed-point X, Y), positive inside, and the
/// value it must reach: 0 on top-left edges, 1 elsewhere.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Edge {
    pub(crate) a: i64,
    pub(crate) b: i64,
    pub(crate) c: i64,
    pub(crate) bias: i64,
}

#[inline]
pub(crate) fn edges_of(x: &[i32; 3], y: &[i32; 3]) -> [Edge; 3] {
    std::array::from_fn(|i| {
        let (p, q) = ([1, 2, 0][i], [2, 0, 1][i]);
        let (xa, ya, xb, yb) = (x[p] as i64, y[p] as i64, x[q] as i64, y[q] as i64);
        let a = ya - yb;
        let b = xb - xa;
        // Gradient (a, b) points inside: a > 0 is a left edge, a == 0 && b > 0 a top edge.
        let top_left = a > 0 || (a == 0 && b > 0);
        Edge {
            a,
            b,
            c: xa * yb - ya * xb,
            bias: if top_left { 0 } else { 1 },
        }
    })
}

/// Coverage mask of a small triangle (fixed-point vertices, positive winding, spanning
/// less than `SMALL` pixels each way) over the pixel rectangle `[px0, py0, px1, py1]`
/// (inclusive, at most `SMALL` x `SMALL`): bit `SMALL * j + i` for pixel `(px0 + i, py0 +
/// j)`, by exactly the rule the edge walk applies. Setup stores it in `Tri::cover`.
///
/// Within that span every edge value fits `i32` exactly: `|a|, |b| < SMALL * ONE` and the
/// first centre lies inside the vertices' box, so `|E| < 2 * (2 * SMALL * ONE)^2`.
#[inline]
pub(crate) fn small_cover(x: &[i32; 3], y: &[i32; 3], [px0, py0, px1, py1]: [i64; 4]) -> u64 {
    const _: () = assert!(SMALL as usize == LANES, "one mask row per 8-lane vector");
    let e = edges_of(x, y);
    let (cx, cy) = (px0 * ONE + ONE / 2, py0 * ONE + ONE / 2);
    // Each edge's values along the first row, and its step from row to row.
    let mut value = [I8::splat(0); 3];
    let mut step = [I8::splat(0); 3];
    for (k, ed) in e.iter().enumerate() {
        let v = (ed.a * cx + ed.b * cy + ed.c - ed.bias) as i32;
        value[k] = I8::splat(v) + I8::ramp_times((ed.a * ONE) as i32);
        step[k] = I8::splat((ed.b * ONE) as i32);
    }
    let lanes = I8::lane_range(0, (px1 - px0) as i32);
    let mut mask = 0u64;
    for j in 0..=(py1 - py0) as u32 {
        let m = lanes
            .and(value[0].non_negative())
            .and(value[1].non_negative())
            .and(value[2].non_negative());
        mask |= (m.bits() as u64) << (SMALL as u32 * j);
        for k in 0..3 {
            value[k] = value[k] + step[k];
        }
    }
    mask
}
