//! Rendering a light slab: each pixel's ray through the `uv` and `st` planes gives
//! continuous sample coordinates `(u, v, s, t)`; the samples around them are blended
//! (nearest, bilinear in `uv`, or quadrilinear) in the stored encoding. Pixels whose ray
//! misses either rectangle, points away from the `st` plane, or finds only empty samples
//! are holes; the others take the depth of the `st` plane along the ray (the flat proxy).

use super::{LightField, Rect3};
use crate::warp::Warped;
use engine::Camera;
use glam::{Vec3, Vec4};
use rayon::prelude::*;

/// How the samples around a ray are combined.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// The nearest sample (one tap).
    Nearest,
    /// Bilinear over the four nearest cameras, nearest in `st` (four taps).
    BilinearUv,
    /// Bilinear in both planes (sixteen taps).
    Quadrilinear,
}

/// The work of one render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LightFieldFrame {
    /// Pixels whose ray crossed both rectangles.
    pub rays: u64,
    /// Samples read.
    pub taps: u64,
    /// Pixels written (rays that found a non-empty sample).
    pub pixels: u64,
}

impl std::ops::AddAssign for LightFieldFrame {
    fn add_assign(&mut self, o: Self) {
        self.rays += o.rays;
        self.taps += o.taps;
        self.pixels += o.pixels;
    }
}

/// Where a line crosses a rectangle's plane: the ray parameter and the fractions of its
/// edges; `None` when parallel.
#[inline]
fn cross(r: &Rect3, o: Vec3, d: Vec3) -> Option<(f32, f32, f32)> {
    let n = r.edge_a.cross(r.edge_b);
    let along = d.dot(n);
    if along == 0.0 || !along.is_finite() {
        return None;
    }
    let tau = (r.origin - o).dot(n) / along;
    let p = o + d * tau - r.origin;
    let a = p.dot(r.edge_a) / r.edge_a.length_squared();
    let b = p.dot(r.edge_b) / r.edge_b.length_squared();
    (tau.is_finite() && a.is_finite() && b.is_finite()).then_some((tau, a, b))
}

/// The two samples of `0..n` around coordinate `x` (sample centres at integers) and the
/// weight of the second; one sample, weight 0, at the ends.
#[inline]
fn pair(x: f32, n: u32) -> (u32, u32, f32) {
    let last = n as f32 - 1.0;
    let x = x.clamp(0.0, last);
    let i = x.floor();
    let f = x - i;
    let i = i as u32;
    (i, (i + 1).min(n - 1), f)
}

/// Renders `lf` as seen by `camera` into `out` (made `width` x `height`, holes where the
/// light field has no ray). Row by row on the thread pool; the same pixels at any thread
/// count.
pub fn render(
    lf: &LightField,
    camera: &Camera,
    width: u32,
    height: u32,
    interpolation: Interpolation,
    out: &mut Warped,
) -> LightFieldFrame {
    out.reset(camera, width, height);
    let w = width as usize;
    if w == 0 || height == 0 {
        return LightFieldFrame::default();
    }
    let inv = camera.gl_view_proj().inverse();
    let forward = camera.forward();
    let slab = &lf.slab;
    let toward = slab.forward();
    let coords = [slab.nu, slab.nv, slab.ns, slab.nt].map(|n| n as f32);
    out.color
        .par_chunks_mut(w)
        .zip(out.disparity.par_chunks_mut(w))
        .enumerate()
        .map(|(y, (colors, disparities))| {
            let mut frame = LightFieldFrame::default();
            for x in 0..w {
                let ndc_x = 2.0 * (x as f32 + 0.5) / width as f32 - 1.0;
                let ndc_y = 1.0 - 2.0 * (y as f32 + 0.5) / height as f32;
                let near = inv * Vec4::new(ndc_x, ndc_y, -1.0, 1.0);
                let far = inv * Vec4::new(ndc_x, ndc_y, 1.0, 1.0);
                let o = near.truncate() / near.w;
                let d = far.truncate() / far.w - o;
                // Light leaves the st side toward the uv side: the eye must look across
                // the planes from the uv side.
                if d.dot(toward).is_nan() || d.dot(toward) <= 0.0 {
                    continue;
                }
                let (Some((_, a_uv, b_uv)), Some((tau, a_st, b_st))) =
                    (cross(&slab.uv, o, d), cross(&slab.st, o, d))
                else {
                    continue;
                };
                let inside = |a: f32| (0.0..=1.0).contains(&a);
                if tau <= 0.0 || !(inside(a_uv) && inside(b_uv) && inside(a_st) && inside(b_st)) {
                    continue;
                }
                frame.rays += 1;
                // Sample coordinates: centres at integers.
                let f = [a_uv, b_uv, a_st, b_st];
                let at: [f32; 4] = std::array::from_fn(|k| f[k] * coords[k] - 0.5);
                let (c, taps) = lookup(lf, at, interpolation);
                frame.taps += taps;
                if c[3] <= 0.0 {
                    continue;
                }
                let byte = |x: f32| (x + 0.5).clamp(0.0, 255.0) as u8;
                colors[x] = u32::from_le_bytes(c.map(byte));
                let depth = (d * tau).dot(forward);
                disparities[x] = if depth > 0.0 { 1.0 / depth } else { 0.0 };
                frame.pixels += 1;
            }
            frame
        })
        .reduce(LightFieldFrame::default, |mut a, b| {
            a += b;
            a
        })
}

/// The blended stored bytes around `(u, v, s, t)`, and the samples read.
#[inline]
fn lookup(
    lf: &LightField,
    [u, v, s, t]: [f32; 4],
    interpolation: Interpolation,
) -> ([f32; 4], u64) {
    let sl = &lf.slab;
    let nearest = |x: f32, n: u32| (x.round().max(0.0) as u32).min(n - 1);
    let bytes = |c: u32| c.to_le_bytes().map(f32::from);
    match interpolation {
        Interpolation::Nearest => {
            let c = lf.sample(
                nearest(u, sl.nu),
                nearest(v, sl.nv),
                nearest(s, sl.ns),
                nearest(t, sl.nt),
            );
            (bytes(c), 1)
        }
        Interpolation::BilinearUv | Interpolation::Quadrilinear => {
            let (u0, u1, fu) = pair(u, sl.nu);
            let (v0, v1, fv) = pair(v, sl.nv);
            let st: [(u32, u32, f32); 4] = if interpolation == Interpolation::Quadrilinear {
                let (s0, s1, fs) = pair(s, sl.ns);
                let (t0, t1, ft) = pair(t, sl.nt);
                [
                    (s0, t0, (1.0 - fs) * (1.0 - ft)),
                    (s1, t0, fs * (1.0 - ft)),
                    (s0, t1, (1.0 - fs) * ft),
                    (s1, t1, fs * ft),
                ]
            } else {
                let (s, t) = (nearest(s, sl.ns), nearest(t, sl.nt));
                [(s, t, 1.0), (s, t, 0.0), (s, t, 0.0), (s, t, 0.0)]
            };
            let mut acc = [0.0f32; 4];
            let mut taps = 0;
            for (uu, vv, wuv) in [
                (u0, v0, (1.0 - fu) * (1.0 - fv)),
                (u1, v0, fu * (1.0 - fv)),
                (u0, v1, (1.0 - fu) * fv),
                (u1, v1, fu * fv),
            ] {
                for &(ss, tt, wst) in &st {
                    let wt = wuv * wst;
                    if wt == 0.0 {
                        continue;
                    }
                    taps += 1;
                    let c = bytes(lf.sample(uu, vv, ss, tt));
                    for (a, x) in acc.iter_mut().zip(c) {
                        *a += x * wt;
                    }
                }
            }
            (acc, taps)
        }
    }
}
