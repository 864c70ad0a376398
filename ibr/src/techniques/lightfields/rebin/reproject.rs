//! Depth-corrected rebinning (the lumigraph's use of its approximate geometry, Gortler et
//! al. 96, with the photographs' own depth maps as that geometry): every sample of the
//! grid is a ray, from its `uv` sample through its `st` sample, and is looked up in the
//! photographs where they saw the surface the ray meets.
//!
//! For each `uv` sample (one image of the grid, in parallel):
//!
//! 1. Candidates: the [`CANDIDATES`] photographs whose eyes are nearest in angle to the
//!    sample, seen from the `st` rectangle's centre.
//! 2. Where each ray meets a surface: the candidates' depth maps as points, projected
//!    from the `uv` sample into its image (nearest point per sample, a z-buffer). A ray
//!    tries, nearest first, the front layer of its 3 x 3 neighbourhood (cracks between
//!    projected points) and its own depth.
//! 3. Each try puts a point `X` on the ray and asks every candidate what it saw there
//!    (its depth at `X`'s pixel against `X`'s depth): the surface at `X` (a colour, read
//!    bilinearly from the pixels at that depth), something behind `X` or nothing at all
//!    (so `X` is empty space: a free vote), or something in front (occluded: no vote).
//!    The votes are weighted by angular proximity as the unstructured lumigraph weights
//!    them (the [`BLEND`] nearest in angle, `(1 - a / a_next) / a`). More surface than
//!    free weight: `X` is moved once onto the nearest-angle surface photograph's depth
//!    (a fixed-point step) and its colour is their weighted blend, in linear light. More
//!    free weight: the next try; a ray some try found free and none a surface is empty.
//! 4. A ray that met no point at all, or that the photographs see through, is empty with
//!    full weight (measured empty space: no halo). A ray with a surface point that no
//!    candidate sees unoccluded keeps its depth and weight 0, and pull-push fills its
//!    colour (only such true gaps inside the surface's footprint are invented).

use super::Acc;
use crate::core::{DepthImage, EMPTY};
use crate::techniques::lightfields::Slab;
use crate::warp::ENCODING;
use engine::color::{Encoder, Premul};
use glam::{Mat4, Vec3};
use rayon::prelude::*;

/// Photographs looked at per `uv` sample.
pub const CANDIDATES: usize = 10;

/// Photographs blended per ray (the nearest in angle that see it).
pub const BLEND: usize = 4;

/// Depth agreement, a fraction of the depth (plus the local slope of the depth map).
const TOLERANCE: f32 = 0.01;

/// The most the local slope adds to the tolerance, a fraction of the depth (a larger step
/// is an edge between surfaces, not a slope).
const SLOPE_CAP: f32 = 0.03;

/// A photograph prepared: its points (pixels with depth) and projection.
struct Photo<'a> {
    image: &'a DepthImage,
    view_proj: Mat4,
    view: Mat4,
    eye: Vec3,
    points: Vec<Vec3>,
}

impl<'a> Photo<'a> {
    fn new(image: &'a DepthImage) -> Self {
        let (w, h) = (image.width(), image.height());
        let points = (0..h)
            .flat_map(|y| (0..w).filter_map(move |x| image.world_point(x, y)))
            .collect();
        Photo {
            image,
            view_proj: image.camera.gl_view_proj(),
            view: image.camera.view,
            eye: image.camera.eye(),
            points,
        }
    }

    /// Depth at pixel `(x, y)` (clamped into the image).
    fn depth(&self, x: i64, y: i64) -> f32 {
        let (w, h) = (self.image.width() as i64, self.image.height() as i64);
        let (x, y) = (x.clamp(0, w - 1), y.clamp(0, h - 1));
        self.image.depth[(y * w + x) as usize]
    }

    fn color(&self, x: i64, y: i64) -> Premul {
        let (w, h) = (self.image.width() as i64, self.image.height() as i64);
        let (x, y) = (x.clamp(0, w - 1), y.clamp(0, h - 1));
        self.image.color[(y * w + x) as usize]
    }

    /// What this photograph saw at `x`.
    fn look(&self, x: Vec3) -> Seen {
        let clip = self.view_proj * x.extend(1.0);
        if clip.w <= 0.0 {
            return Seen::Outside;
        }
        let (w, h) = (self.image.width() as f32, self.image.height() as f32);
        let sx = (clip.x / clip.w + 1.0) * 0.5 * w;
        let sy = (1.0 - clip.y / clip.w) * 0.5 * h;
        if !(sx >= 0.0 && sx < w && sy >= 0.0 && sy < h) {
            return Seen::Outside;
        }
        let dx = -(self.view * x.extend(1.0)).z;
        let (px, py) = (sx.floor() as i64, sy.floor() as i64);
        let dn = self.depth(px, py);
        if dn == EMPTY {
            return Seen::Free;
        }
        // The local slope: the largest step to a 4-neighbour with depth, capped.
        let slope = [(-1, 0), (1, 0), (0, -1), (0, 1)]
            .iter()
            .map(|&(ox, oy)| self.depth(px + ox, py + oy))
            .filter(|d| d.is_finite())
            .fold(0.0f32, |m, d| m.max((d - dn).abs()));
        let tol = TOLERANCE * dx + slope.min(SLOPE_CAP * dx);
        if dx < dn - tol {
            return Seen::Free;
        }
        if dx > dn + tol {
            return Seen::Occluded;
        }
        // Bilinear over the four pixels around, those at X's depth.
        let (fx, fy) = (sx - 0.5, sy - 0.5);
        let (x0, y0) = (fx.floor() as i64, fy.floor() as i64);
        let (ax, ay) = (fx - x0 as f32, fy - y0 as f32);
        let (mut c, mut z, mut wsum) = ([0.0f32; 4], 0.0f32, 0.0f32);
        for (ox, oy, wgt) in [
            (0, 0, (1.0 - ax) * (1.0 - ay)),
            (1, 0, ax * (1.0 - ay)),
            (0, 1, (1.0 - ax) * ay),
            (1, 1, ax * ay),
        ] {
            let d = self.depth(x0 + ox, y0 + oy);
            if wgt <= 0.0 || !d.is_finite() || (d - dx).abs() > tol {
                continue;
            }
            let p = self.color(x0 + ox, y0 + oy);
            for (a, b) in c.iter_mut().zip([p.r, p.g, p.b, p.a]) {
                *a += wgt * b;
            }
            z += wgt * d;
            wsum += wgt;
        }
        if wsum <= 0.0 {
            // The nearest pixel agreed but carries no bilinear weight: read it alone.
            let p = self.color(px, py);
            return Seen::Surface {
                color: [p.r, p.g, p.b, p.a],
                depth: dn,
                at: dx,
            };
        }
        Seen::Surface {
            color: c.map(|v| v / wsum),
            depth: z / wsum,
            at: dx,
        }
    }
}

/// What a photograph saw at a point.
#[derive(Clone, Copy, Debug)]
enum Seen {
    /// Outside its image (or behind it): no vote.
    Outside,
    /// Something in front of the point: no vote.
    Occluded,
    /// Nothing there, or something behind it: the point is empty space.
    Free,
    /// The point's surface: its colour (linear, premultiplied), the photograph's depth
    /// there and the point's depth, along its axis.
    Surface {
        color: [f32; 4],
        depth: f32,
        at: f32,
    },
}

/// The photographs' verdict on a point of a ray.
enum Verdict {
    /// Surface: the blended colour and the nearest-angle photograph that saw it, with
    /// what it saw.
    Surface([f32; 4], usize, Seen),
    Free,
    Unknown,
}

/// The photographs' weighted vote at `x` on a ray along `dir` (unit).
fn judge(photos: &[Photo<'_>], candidates: &[usize], x: Vec3, dir: Vec3) -> Verdict {
    let mut all = [(0.0f32, 0usize, Seen::Outside); CANDIDATES];
    let mut n = 0;
    for &k in candidates.iter().take(CANDIDATES) {
        let seen = photos[k].look(x);
        if matches!(seen, Seen::Outside | Seen::Occluded) {
            continue;
        }
        let to = (x - photos[k].eye).normalize_or_zero();
        all[n] = (dir.dot(to).clamp(-1.0, 1.0).acos(), k, seen);
        n += 1;
    }
    let votes = &mut all[..n];
    if votes.is_empty() {
        return Verdict::Unknown;
    }
    votes.sort_by(|a, b| a.0.total_cmp(&b.0));
    // Unstructured-lumigraph weights: the next photograph's angle is the threshold.
    let next = votes
        .get(BLEND)
        .map_or(votes.last().map_or(0.0, |v| v.0) * 1.5 + 1e-3, |v| v.0)
        .max(1e-6);
    let (mut surface, mut free, mut color) = (0.0f32, 0.0f32, [0.0f32; 4]);
    for &(angle, _, seen) in votes.iter().take(BLEND) {
        let w = (1.0 - angle / next).max(0.0) / (angle + 1e-4);
        match seen {
            Seen::Surface { color: c, .. } => {
                surface += w;
                for (a, b) in color.iter_mut().zip(c) {
                    *a += w * b;
                }
            }
            _ => free += w,
        }
    }
    if surface > free && surface > 0.0 {
        let &(_, k, seen) = votes
            .iter()
            .find(|v| matches!(v.2, Seen::Surface { .. }))
            .expect("a surface vote");
        Verdict::Surface(color.map(|c| c / surface), k, seen)
    } else if free > 0.0 {
        Verdict::Free
    } else {
        Verdict::Unknown
    }
}

/// Whether any photograph has depth (else rebinning falls back to splatting).
pub fn any_depth(images: &[DepthImage]) -> bool {
    images
        .iter()
        .any(|im| im.depth.iter().any(|d| d.is_finite()))
}

/// Rebins `images` into the grid of finite `slab` (see the module docs): per sample its
/// sums (colour as stored bytes, weight 1 where measured, 0 where invented), and the
/// photograph points used.
pub(super) fn reproject(slab: &Slab, images: &[DepthImage]) -> (Vec<Acc>, u64) {
    let photos: Vec<Photo<'_>> = images.par_iter().map(Photo::new).collect();
    let points = photos.iter().map(|p| p.points.len() as u64).sum();
    let [nu, _, ns, nt] = slab.counts().map(|n| n as usize);
    let image = ns * nt;
    let mut grid = vec![Acc::default(); slab.len()];
    grid.par_chunks_mut(image).enumerate().for_each(|(k, out)| {
        let (i, j) = ((k % nu) as u32, (k / nu) as u32);
        uv_image(slab, &photos, slab.uv_point(i, j), out);
    });
    (grid, points)
}

/// The candidates of a `uv` sample at `eye`: nearest in angle from the `st` centre.
fn candidates(slab: &Slab, photos: &[Photo<'_>], eye: Vec3) -> Vec<usize> {
    let c = slab.st.at(0.5, 0.5);
    let to = (eye - c).normalize_or_zero();
    let mut ranked: Vec<(f32, usize)> = photos
        .iter()
        .enumerate()
        .filter(|(_, p)| !p.points.is_empty())
        .map(|(k, p)| (-(p.eye - c).normalize_or_zero().dot(to), k))
        .collect();
    ranked.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    ranked.iter().take(CANDIDATES).map(|r| r.1).collect()
}

/// One `uv` sample's image of the grid: `out` (`ns * nt`, row-major).
fn uv_image(slab: &Slab, photos: &[Photo<'_>], eye: Vec3, out: &mut [Acc]) {
    let (ns, nt) = (slab.ns as usize, slab.nt as usize);
    let forward = slab.forward();
    let origin = slab.uv.origin;
    let st = slab.st;
    let normal = st.edge_a.cross(st.edge_b);
    let reach = (st.origin - eye).dot(normal);
    let (ea, eb) = (
        st.edge_a / st.edge_a.length_squared(),
        st.edge_b / st.edge_b.length_squared(),
    );
    let chosen = candidates(slab, photos, eye);
    // The z-buffer: per sample the nearest point's depth along forward from the uv plane.
    let mut zbuf = vec![f32::INFINITY; ns * nt];
    for &k in &chosen {
        for &p in &photos[k].points {
            let d = p - eye;
            let along = d.dot(normal);
            let z = (p - origin).dot(forward);
            if along == 0.0 || z <= 0.0 {
                continue;
            }
            let tau = reach / along;
            if tau <= 0.0 || !tau.is_finite() {
                continue;
            }
            let q = eye + d * tau - st.origin;
            let (a, b) = (q.dot(ea), q.dot(eb));
            if !(0.0..1.0).contains(&a) || !(0.0..1.0).contains(&b) {
                continue;
            }
            let (s, t) = ((a * ns as f32) as usize, (b * nt as f32) as usize);
            let cell = &mut zbuf[t.min(nt - 1) * ns + s.min(ns - 1)];
            *cell = cell.min(z);
        }
    }
    let enc = Encoder::new(ENCODING);
    for t in 0..nt {
        for s in 0..ns {
            // The front layer of the 3 x 3 neighbourhood: the mean of the depths near its
            // nearest.
            let around = || {
                (t.saturating_sub(1)..(t + 2).min(nt)).flat_map(move |y| {
                    (s.saturating_sub(1)..(s + 2).min(ns)).map(move |x| y * ns + x)
                })
            };
            let nearest = around().map(|i| zbuf[i]).fold(f32::INFINITY, f32::min);
            let own = zbuf[t * ns + s];
            let acc = &mut out[t * ns + s];
            // Empty space unless a try finds a surface (or cannot tell).
            acc.weight = 1.0;
            if !nearest.is_finite() {
                continue;
            }
            let (sum, n) = around()
                .map(|i| zbuf[i])
                .filter(|&z| z <= nearest * (1.0 + 3.0 * TOLERANCE))
                .fold((0.0, 0), |(a, n), z| (a + z, n + 1));
            let front = sum / n as f32;
            let target = st.at((s as f32 + 0.5) / ns as f32, (t as f32 + 0.5) / nt as f32);
            let ray = target - eye;
            let dz = ray.dot(forward);
            if dz <= 0.0 {
                continue;
            }
            let dir = ray.normalize();
            let point = |z: f32| eye + ray * ((z - (eye - origin).dot(forward)) / dz);
            let tries = if own.is_finite() && (own - front).abs() > TOLERANCE * front {
                [front.min(own), front.max(own)]
            } else {
                [front, f32::NAN]
            };
            let (mut unknown, mut free) = (None, false);
            let mut found = None;
            for z in tries.into_iter().filter(|z| !z.is_nan()) {
                match judge(photos, &chosen, point(z), dir) {
                    Verdict::Surface(first, k, Seen::Surface { depth, at, .. }) => {
                        // One fixed-point step onto that photograph's surface.
                        let x = point(z);
                        let p = &photos[k];
                        let q = p.eye + (x - p.eye) * (depth / at);
                        let z2 = (q - origin).dot(forward);
                        let z2 = if z2.is_finite() && z2 > 0.0 { z2 } else { z };
                        found = Some(match judge(photos, &chosen, point(z2), dir) {
                            Verdict::Surface(c, ..) => (c, z2),
                            _ => (first, z),
                        });
                        break;
                    }
                    Verdict::Unknown if unknown.is_none() => unknown = Some(z),
                    Verdict::Free => free = true,
                    _ => {}
                }
            }
            if let Some((c, z)) = found {
                let bytes = enc.pack(c[0], c[1], c[2], c[3]).to_le_bytes();
                acc.color = bytes.map(f32::from);
                acc.depth = z;
                acc.depth_weight = 1.0;
            } else if let (Some(z), false) = (unknown, free) {
                // A surface no candidate sees (nor sees through): its colour for
                // pull-push to invent.
                acc.weight = 0.0;
                acc.depth = z;
                acc.depth_weight = 1.0;
            }
        }
    }
}
