//! Rendering a light slab: each pixel's ray through the `uv` and `st` planes gives
//! continuous sample coordinates `(u, v, s, t)`; the samples around them are blended
//! (nearest, bilinear in `uv`, or quadrilinear) in the stored encoding, each camera read
//! where it saw the ray's surface point when depth correction is on ([`Lookup`]). Pixels
//! whose ray misses either rectangle, points away from the `st` plane, or finds only empty
//! samples are holes; the others take the depth of that surface point (or of the `st`
//! plane, the flat proxy).

use super::{LightField, Quantised, RawRays, Rays, Rect3, Slab};
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

/// Relative depth difference within which a camera's sample is taken to be of the same
/// surface point as the ray's.
const SAME_SURFACE: f32 = 0.05;

/// How a render looks the light field up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lookup {
    pub interpolation: Interpolation,
    /// Depth correction (Gortler et al. 96): the ray's point on the surface (at the depth
    /// the nearest camera that saw something where the ray crosses the focal plane
    /// stored) is re-projected into each camera around the ray, so every camera is read
    /// where it saw that point, not where the ray crosses the focal plane; a camera that
    /// saw something else there (occluded, or nothing) is left out and its weight goes to
    /// the others. The written depth is that point's. A ray no camera around it saw
    /// anything for is a hole. Without stored depth the focal plane serves.
    pub depth_correction: bool,
}

impl Default for Lookup {
    fn default() -> Self {
        Lookup {
            interpolation: Interpolation::Quadrilinear,
            depth_correction: true,
        }
    }
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

/// A rectangle's plane as a ray meets it: a corner, the normal, and the edges divided by
/// their squared lengths (a point's dot product with them is its fraction of each edge).
#[derive(Clone, Copy, Debug)]
struct Plane {
    origin: Vec3,
    normal: Vec3,
    a: Vec3,
    b: Vec3,
}

impl Plane {
    fn of(r: &Rect3) -> Plane {
        Plane {
            origin: r.origin,
            normal: r.edge_a.cross(r.edge_b),
            a: r.edge_a / r.edge_a.length_squared(),
            b: r.edge_b / r.edge_b.length_squared(),
        }
    }

    /// Where the line `o + tau d` crosses the plane: `tau` and the fractions of the edges;
    /// `None` when parallel or not finite.
    #[inline]
    fn cross(&self, o: Vec3, d: Vec3) -> Option<(f32, f32, f32)> {
        let along = d.dot(self.normal);
        if along == 0.0 || !along.is_finite() {
            return None;
        }
        let tau = (self.origin - o).dot(self.normal) / along;
        let p = o + d * tau - self.origin;
        let (a, b) = (p.dot(self.a), p.dot(self.b));
        (tau.is_finite() && a.is_finite() && b.is_finite()).then_some((tau, a, b))
    }
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

/// Where a render reads samples from: raw or quantised rays, the choice made once per
/// frame, not per sample.
trait Source: Sync {
    fn sample(&self, u: u32, v: u32, s: u32, t: u32) -> u32;
    fn depth(&self, u: u32, v: u32, s: u32, t: u32) -> f32;
}

struct RawSource<'a> {
    rays: &'a RawRays,
    counts: [u32; 4],
}

impl Source for RawSource<'_> {
    #[inline]
    fn sample(&self, u: u32, v: u32, s: u32, t: u32) -> u32 {
        self.rays.samples[self.rays.index(self.counts, u, v, s, t)]
    }

    #[inline]
    fn depth(&self, u: u32, v: u32, s: u32, t: u32) -> f32 {
        self.rays.depth[self.rays.index(self.counts, u, v, s, t)]
    }
}

impl Source for Quantised {
    #[inline]
    fn sample(&self, u: u32, v: u32, s: u32, t: u32) -> u32 {
        Quantised::sample(self, u, v, s, t)
    }

    #[inline]
    fn depth(&self, u: u32, v: u32, s: u32, t: u32) -> f32 {
        Quantised::depth(self, u, v, s, t)
    }
}

/// Renders `lf` as seen by `camera` into `out` (made `width` x `height`, holes where the
/// light field has no ray), from raw or quantised rays alike. Row by row on the thread
/// pool; the same pixels at any thread count.
pub fn render(
    lf: &LightField,
    camera: &Camera,
    width: u32,
    height: u32,
    lookup: Lookup,
    out: &mut Warped,
) -> LightFieldFrame {
    let lookup = Lookup {
        depth_correction: lookup.depth_correction && lf.has_depth(),
        ..lookup
    };
    match &lf.rays {
        Rays::Raw(rays) => {
            let src = RawSource {
                rays,
                counts: lf.slab.counts(),
            };
            render_from(&lf.slab, &src, camera, width, height, lookup, out)
        }
        Rays::Quantised(q) => render_from(&lf.slab, q, camera, width, height, lookup, out),
    }
}

fn render_from(
    slab: &Slab,
    src: &impl Source,
    camera: &Camera,
    width: u32,
    height: u32,
    lookup: Lookup,
    out: &mut Warped,
) -> LightFieldFrame {
    out.reset(camera, width, height);
    let w = width as usize;
    if w == 0 || height == 0 {
        return LightFieldFrame::default();
    }
    let inv = camera.gl_view_proj().inverse();
    let (uv_plane, st_plane) = (Plane::of(&slab.uv), Plane::of(&slab.st));
    // The near and far points of a pixel's ray, homogeneous, are linear in its x: a row's
    // first pixel's plus x steps.
    let step = inv.x_axis * (2.0 / width as f32);
    let forward = camera.forward();
    let toward = slab.forward();
    let coords = [slab.nu, slab.nv, slab.ns, slab.nt].map(|n| n as f32);
    // The st plane's distance from the uv plane along `toward`.
    let gap = (slab.st.origin - slab.uv.origin).dot(toward);
    let correct = lookup.depth_correction;
    out.color
        .par_chunks_mut(w)
        .zip(out.disparity.par_chunks_mut(w))
        .enumerate()
        .map(|(y, (colors, disparities))| {
            let mut frame = LightFieldFrame::default();
            let ndc_x = 1.0 / width as f32 - 1.0;
            let ndc_y = 1.0 - 2.0 * (y as f32 + 0.5) / height as f32;
            let near0 = inv * Vec4::new(ndc_x, ndc_y, -1.0, 1.0);
            let far0 = inv * Vec4::new(ndc_x, ndc_y, 1.0, 1.0);
            for x in 0..w {
                let near = near0 + step * x as f32;
                let far = far0 + step * x as f32;
                let o = near.truncate() / near.w;
                let d = far.truncate() / far.w - o;
                // Light leaves the st side toward the uv side: the eye must look across
                // the planes from the uv side.
                if d.dot(toward).is_nan() || d.dot(toward) <= 0.0 {
                    continue;
                }
                let (Some((_, a_uv, b_uv)), Some((tau, a_st, b_st))) =
                    (uv_plane.cross(o, d), st_plane.cross(o, d))
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
                // Where the ray meets the surface: the depth one of the cameras around the
                // ray (nearest first) saw where the ray crosses the focal plane.
                let near = |x: f32, n: u32| (x.round().max(0.0) as u32).min(n - 1);
                let [u, v, s, t] = at;
                let from_uv = (o - slab.uv.origin).dot(toward);
                let on_ray = |z: f32| {
                    let along = (z - from_uv) / d.dot(toward);
                    (z > 0.0 && z.is_finite() && along > 0.0).then(|| (o + d * along, z))
                };
                // The nearest camera's view of the ray, followed to a fixed point: start
                // where the ray crosses the focal plane, read the depth the camera saw
                // there, move along the ray to that depth, and again.
                let (ci, cj) = (near(u, slab.nu), near(v, slab.nv));
                let project = |x: Vec3, i: u32, j: u32| -> Option<[f32; 2]> {
                    let e = slab.uv_point(i, j);
                    let dir = x - e;
                    let p = e + dir * (gap / dir.dot(toward)) - slab.st.origin;
                    let (a, b) = (p.dot(st_plane.a), p.dot(st_plane.b));
                    let st = [a * coords[2] - 0.5, b * coords[3] - 0.5];
                    (st[0].is_finite() && st[1].is_finite()).then_some(st)
                };
                let surface = if correct {
                    let mut found = None;
                    let mut x = o + d * tau;
                    for _ in 0..4 {
                        let Some([ps, pt]) = project(x, ci, cj) else {
                            break;
                        };
                        let z = src.depth(ci, cj, near(ps, slab.ns), near(pt, slab.nt));
                        let Some((next, z)) = on_ray(z) else {
                            break;
                        };
                        found = Some((next, z));
                        x = next;
                    }
                    found
                } else {
                    None
                };
                // The st coordinates where camera `(i, j)` saw the surface point; `None`
                // when it saw something else there (nearer, or nothing): it does not see
                // the point, and is left out of the blend.
                let st_of = |i: u32, j: u32| -> Option<[f32; 2]> {
                    let Some((x, z)) = surface else {
                        return Some([s, t]);
                    };
                    let st = project(x, i, j)?;
                    let seen = src.depth(i, j, near(st[0], slab.ns), near(st[1], slab.nt));
                    ((seen - z).abs() <= SAME_SURFACE * z).then_some(st)
                };
                let (c, taps) =
                    self::lookup(slab, src, [at[0], at[1]], &st_of, lookup.interpolation);
                frame.taps += taps;
                if c[3] <= 0.0 {
                    continue;
                }
                let byte = |x: f32| (x + 0.5).clamp(0.0, 255.0) as u8;
                colors[x] = u32::from_le_bytes(c.map(byte));
                let depth = match surface {
                    Some((p, _)) => (p - o).dot(forward),
                    None => (d * tau).dot(forward),
                };
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

/// The blended stored bytes around camera coordinates `(u, v)`, each camera `(i, j)` read
/// around its own st coordinates `st_of(i, j)`, and the samples read.
#[inline]
fn lookup(
    sl: &Slab,
    src: &impl Source,
    [u, v]: [f32; 2],
    st_of: &impl Fn(u32, u32) -> Option<[f32; 2]>,
    interpolation: Interpolation,
) -> ([f32; 4], u64) {
    let nearest = |x: f32, n: u32| (x.round().max(0.0) as u32).min(n - 1);
    let bytes = |c: u32| c.to_le_bytes().map(f32::from);
    let cameras: [(u32, u32, f32); 4] = if interpolation == Interpolation::Nearest {
        let (i, j) = (nearest(u, sl.nu), nearest(v, sl.nv));
        [(i, j, 1.0), (i, j, 0.0), (i, j, 0.0), (i, j, 0.0)]
    } else {
        let (u0, u1, fu) = pair(u, sl.nu);
        let (v0, v1, fv) = pair(v, sl.nv);
        [
            (u0, v0, (1.0 - fu) * (1.0 - fv)),
            (u1, v0, fu * (1.0 - fv)),
            (u0, v1, (1.0 - fu) * fv),
            (u1, v1, fu * fv),
        ]
    };
    let (mut acc, mut total) = ([0.0f32; 4], 0.0f32);
    let mut taps = 0;
    for (i, j, wuv) in cameras {
        if wuv == 0.0 {
            continue;
        }
        let Some([s, t]) = st_of(i, j) else {
            continue;
        };
        total += wuv;
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
        for (ss, tt, wst) in st {
            let wt = wuv * wst;
            if wt == 0.0 {
                continue;
            }
            taps += 1;
            let c = bytes(src.sample(i, j, ss, tt));
            for (a, x) in acc.iter_mut().zip(c) {
                *a += x * wt;
            }
        }
    }
    // Cameras left out give their weight to the others.
    if total > 0.0 && total < 1.0 {
        acc = acc.map(|a| a / total);
    }
    (acc, taps)
}
