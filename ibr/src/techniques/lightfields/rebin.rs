//! Sparse capture (the lumigraph's, Gortler et al. 96): photographs taken from anywhere
//! (a hand-held path, a `transforms.json` folder) rebinned into a light slab's grid.
//!
//! With depth maps and a slab with both planes finite, rebinning is depth-corrected
//! ([`reproject`]): each sample's ray is found on the surface the photographs' depth maps
//! describe and read from the photographs that see that point unoccluded, blended by
//! angular proximity; rays that meet nothing in any depth map are empty space (no halo
//! around silhouettes), and pull-push fills only the rays inside the surface's footprint
//! that no photograph sees.
//!
//! Without depth (or with a plane at infinity) each pixel of each image is a ray: where
//! it crosses the two planes gives continuous `(u, v, s, t)`, and its colour (and the
//! depth of the surface it saw) is splatted into the sixteen samples around that point
//! with quadrilinear weights. The weights are kept ([`Rebinned::weights`]). Samples no ray
//! reached are then filled by pull-push in four dimensions: the grid is halved along every
//! axis down to one sample (each coarser sample the weighted mean of its up to sixteen
//! children, weights clamped at 1), then every sample with weight below 1 is blended
//! toward its parent's value on the way back up. Pixels that saw nothing are rays too
//! (transparent, no depth): empty space is data, and only rays no photograph saw are
//! invented. Splatting blurs every ray over its neighbours' directions, so silhouettes
//! carry a halo; it is the fallback.
//!
//! Splatted photographs must look through the slab from the `uv` side (toward
//! [`Slab::forward`]) from outside the object, on the `uv` side of the `st` plane; other
//! pixels are left out.

pub mod reproject;

use super::{LightField, RawRays, Rays, Slab};
use crate::core::DepthImage;
use crate::warp::ENCODING;
use engine::color::Encoder;
use glam::Vec4;
use rayon::prelude::*;

/// A rebinned light field and how much of it the photographs saw.
#[derive(Clone, Debug)]
pub struct Rebinned {
    /// The light field, every sample filled (measured, or pulled and pushed from
    /// measured neighbours).
    pub field: LightField,
    /// Per sample (in [`RawRays::samples`] order), how much of it was measured: 1 where
    /// the photographs saw its ray's surface or saw through it (depth-corrected), the
    /// summed splat weight of the rays that reached it (splatted); 0 where pull-push
    /// invented it.
    pub weights: Vec<f32>,
    /// Photograph samples used: pixels with a surface point (depth-corrected) or rays
    /// splatted.
    pub rays: u64,
    /// Whether the photographs' depth corrected the rebinning ([`reproject`]).
    pub depth_corrected: bool,
}

impl Rebinned {
    /// The fraction of samples no ray reached (filled from coarser levels alone).
    pub fn invented(&self) -> f64 {
        let n = self.weights.len().max(1);
        self.weights.iter().filter(|&&w| w <= 0.0).count() as f64 / n as f64
    }

    /// The fraction of samples with at least half a ray's weight (mostly measured).
    pub fn confident(&self) -> f64 {
        let n = self.weights.len().max(1);
        self.weights.iter().filter(|&&w| w >= 0.5).count() as f64 / n as f64
    }
}

/// One sample's sums (splatting), then its value (after [`normalise`]).
#[derive(Clone, Copy, Debug, Default)]
struct Acc {
    color: [f32; 4],
    weight: f32,
    depth: f32,
    depth_weight: f32,
}

/// A ray's sample coordinates (centres at integers), stored colour bytes and depth along
/// the slab's forward axis (infinite when it saw nothing).
#[derive(Clone, Copy, Debug)]
struct Ray {
    at: [f32; 4],
    color: [f32; 4],
    depth: f32,
}

/// The two samples of `0..n` around `x` and the weight of the second (as rendering
/// interpolates).
fn pair(x: f32, n: u32) -> (u32, u32, f32) {
    let x = x.clamp(0.0, n as f32 - 1.0);
    let i = x.floor();
    (i as u32, (i as u32 + 1).min(n - 1), x - i)
}

/// The rays of one photograph that cross both rectangles of `slab`.
fn rays_of(slab: &Slab, image: &DepthImage) -> Vec<Ray> {
    let (w, h) = (image.width(), image.height());
    let inv = image.camera.gl_view_proj().inverse();
    let forward = slab.forward();
    let enc = Encoder::new(ENCODING);
    let counts = slab.counts().map(|n| n as f32);
    let mut out = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let ndc_x = 2.0 * (x as f32 + 0.5) / w as f32 - 1.0;
            let ndc_y = 1.0 - 2.0 * (y as f32 + 0.5) / h as f32;
            let near = inv * Vec4::new(ndc_x, ndc_y, -1.0, 1.0);
            let far = inv * Vec4::new(ndc_x, ndc_y, 1.0, 1.0);
            let o = near.truncate() / near.w;
            let d = far.truncate() / far.w - o;
            // Looking through the slab from the uv side, from the uv side of the st plane
            // (any eye is, of a plane at infinity).
            let along = d.dot(forward);
            let behind = if slab.infinite[1] {
                -1.0
            } else {
                (o - slab.st.origin).dot(forward)
            };
            if along.is_nan() || along <= 0.0 || behind.is_nan() || behind >= 0.0 {
                continue;
            }
            let (Some((_, au, bu)), Some((_, a_s, b_s))) =
                (slab.cross(0, o, d), slab.cross(1, o, d))
            else {
                continue;
            };
            let f = [au, bu, a_s, b_s];
            if f.iter().any(|a| !(0.0..=1.0).contains(a)) {
                continue;
            }
            let i = (y * w + x) as usize;
            let c = image.color[i];
            let color = enc.pack(c.r, c.g, c.b, c.a).to_le_bytes().map(f32::from);
            let depth = image
                .world_point(x, y)
                .map_or(f32::INFINITY, |p| (p - slab.uv.origin).dot(forward));
            out.push(Ray {
                at: std::array::from_fn(|k| f[k] * counts[k] - 0.5),
                color,
                depth: if depth > 0.0 { depth } else { f32::INFINITY },
            });
        }
    }
    out
}

/// Rebins `images` into `slab` (see the module docs): depth-corrected where the images
/// have depth and both planes are finite, else splatted. On the thread pool; the same
/// samples at any thread count.
pub fn rebin(slab: Slab, images: &[DepthImage]) -> Rebinned {
    if !slab.is_projective() && reproject::any_depth(images) {
        let (grid, points) = reproject::reproject(&slab, images);
        finish(slab, grid, points, true)
    } else {
        splat(slab, images)
    }
}

/// Rebins `images` into `slab` by splatting their rays (see the module docs), whatever
/// depth they have.
pub fn splat(slab: Slab, images: &[DepthImage]) -> Rebinned {
    let [nu, nv, ns, nt] = slab.counts();
    // Rays bucketed by the lower v sample they reach, in image and pixel order.
    let mut buckets: Vec<Vec<Ray>> = vec![Vec::new(); nv as usize];
    let mut count = 0u64;
    for rays in images
        .par_iter()
        .map(|im| rays_of(&slab, im))
        .collect::<Vec<_>>()
    {
        count += rays.len() as u64;
        for r in rays {
            buckets[pair(r.at[1], nv).0 as usize].push(r);
        }
    }
    // Each row of cameras (one v) takes the rays whose lower or upper v sample it is.
    let image = (nu * ns * nt) as usize;
    let mut grid = vec![Acc::default(); slab.len()];
    grid.par_chunks_mut(image).enumerate().for_each(|(j, row)| {
        let lower = j.checked_sub(1).map(|k| &buckets[k]);
        for r in lower.into_iter().flatten().chain(&buckets[j]) {
            let (v0, v1, fv) = pair(r.at[1], nv);
            let wv = if v0 as usize == j { 1.0 - fv } else { 0.0 }
                + if v1 as usize == j { fv } else { 0.0 };
            // v0 == v1 at the last row: both terms, weight 1.
            if wv <= 0.0 {
                continue;
            }
            let (u0, u1, fu) = pair(r.at[0], nu);
            let (s0, s1, fs) = pair(r.at[2], ns);
            let (t0, t1, ft) = pair(r.at[3], nt);
            for (u, wu) in [(u0, 1.0 - fu), (u1, fu)] {
                for (t, wt) in [(t0, 1.0 - ft), (t1, ft)] {
                    for (s, ws) in [(s0, 1.0 - fs), (s1, fs)] {
                        let wgt = wv * wu * wt * ws;
                        if wgt <= 0.0 {
                            continue;
                        }
                        let a = &mut row[((u * nt + t) * ns + s) as usize];
                        for (c, x) in a.color.iter_mut().zip(r.color) {
                            *c += wgt * x;
                        }
                        a.weight += wgt;
                        if r.depth.is_finite() {
                            a.depth += wgt * r.depth;
                            a.depth_weight += wgt;
                        }
                    }
                }
            }
        }
    });
    finish(slab, grid, count, false)
}

/// Sums to a light field: means, pull-push, packed samples and depths.
fn finish(slab: Slab, mut grid: Vec<Acc>, count: u64, depth_corrected: bool) -> Rebinned {
    let weights = grid.iter().map(|a| a.weight).collect();
    normalise(&mut grid);
    pull_push(&mut grid, slab.counts().map(|n| n as usize));
    let byte = |x: f32| (x + 0.5).clamp(0.0, 255.0) as u8;
    let samples = grid
        .iter()
        .map(|a| u32::from_le_bytes(a.color.map(byte)))
        .collect();
    // A slab with a plane at infinity keeps no depth.
    let depth = grid
        .iter()
        .take(if slab.is_projective() { 0 } else { grid.len() })
        .map(|a| {
            if a.depth_weight > 0.0 && a.depth > 0.0 && a.color[3] >= 0.5 {
                a.depth
            } else {
                f32::INFINITY
            }
        })
        .collect();
    Rebinned {
        field: LightField {
            slab,
            rays: Rays::Raw(RawRays::new(samples, depth)),
        },
        weights,
        rays: count,
        depth_corrected,
    }
}

/// Sums to means (weights kept).
fn normalise(grid: &mut [Acc]) {
    for a in grid {
        if a.weight > 0.0 {
            a.color = a.color.map(|c| c / a.weight);
        }
        if a.depth_weight > 0.0 {
            a.depth /= a.depth_weight;
        }
    }
}

/// Index of `(u, v, s, t)` in a grid of `dims` (`[nu, nv, ns, nt]`, light-field order).
#[inline]
fn at([nu, _, ns, nt]: [usize; 4], [u, v, s, t]: [usize; 4]) -> usize {
    ((v * nu + u) * nt + t) * ns + s
}

/// Every index of a grid of `dims`, in storage order, with its coordinates.
fn cells(dims: [usize; 4]) -> impl Iterator<Item = [usize; 4]> {
    let [nu, nv, ns, nt] = dims;
    (0..nv).flat_map(move |v| {
        (0..nu).flat_map(move |u| (0..nt).flat_map(move |t| (0..ns).map(move |s| [u, v, s, t])))
    })
}

/// Pull-push over four dimensions (see the module docs): fills samples of weight below 1
/// from coarser levels.
fn pull_push(grid: &mut [Acc], dims: [usize; 4]) {
    if dims.iter().all(|&d| d <= 1) {
        return;
    }
    let half = dims.map(|d| d.div_ceil(2));
    let mut parent = vec![Acc::default(); half.iter().product()];
    // Pull: each parent the clamped-weight mean of its children.
    for p in cells(half) {
        let mut acc = Acc::default();
        let mut children = 0.0;
        for k in 0..16 {
            let c: [usize; 4] = std::array::from_fn(|a| 2 * p[a] + (k >> a & 1));
            if (0..4).any(|a| c[a] >= dims[a]) {
                continue;
            }
            children += 1.0;
            let x = &grid[at(dims, c)];
            let w = x.weight.min(1.0);
            for (a, b) in acc.color.iter_mut().zip(x.color) {
                *a += w * b;
            }
            acc.weight += w;
            let wz = x.depth_weight.min(1.0);
            acc.depth += wz * x.depth;
            acc.depth_weight += wz;
        }
        let q = &mut parent[at(half, p)];
        if acc.weight > 0.0 {
            q.color = acc.color.map(|c| c / acc.weight);
        }
        if acc.depth_weight > 0.0 {
            q.depth = acc.depth / acc.depth_weight;
        }
        q.weight = acc.weight / children;
        q.depth_weight = acc.depth_weight / children;
    }
    pull_push(&mut parent, half);
    // Push: each sample short of full weight blended toward its parent.
    for c in cells(dims) {
        let p = parent[at(half, c.map(|x| x / 2))];
        let x = &mut grid[at(dims, c)];
        let w = x.weight.min(1.0);
        if w < 1.0 {
            for (a, b) in x.color.iter_mut().zip(p.color) {
                *a = w * *a + (1.0 - w) * b;
            }
            // The parent's weight carries how much of this is real, for the level below.
            x.weight = w + (1.0 - w) * p.weight.min(1.0);
        }
        // Depth only where there is something: empty space stays empty.
        let wz = x.depth_weight.min(1.0);
        if wz < 1.0 && p.depth_weight > 0.0 && x.color[3] >= 0.5 {
            x.depth = if wz > 0.0 {
                wz * x.depth + (1.0 - wz) * p.depth
            } else {
                p.depth
            };
            x.depth_weight = wz + (1.0 - wz) * p.depth_weight.min(1.0);
        }
    }
}
