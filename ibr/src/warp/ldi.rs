//! Layered depth images built by warping (Shade et al. 98, the second way): several depth
//! images warped into one LDI camera, samples within a depth tolerance of one already
//! there merged into it, the rest kept, each pixel's run sorted near to far. (The first
//! way, ray penetration by depth peeling, is `capture::Capturer`'s.)

use super::equation::Equation;
use super::is_filled;
use crate::core::{DepthImage, LayeredDepthImage, LdiSample};
use engine::Camera;
use rayon::prelude::*;

/// A sample landed in the LDI: its pixel, the sample, its depth spread, its image.
type Landed = (u32, LdiSample, f32, u32);

/// Depth images landed in an LDI camera one at a time (a build spread over frames lands
/// each view as it is captured); [`LdiBuilder::merge`] makes the LDI.
#[derive(Debug)]
pub struct LdiLanding {
    camera: Camera,
    width: u32,
    height: u32,
    /// Landed samples: pixel, sample, and how far in depth it may be from one of its
    /// surface's samples at the same pixel (its depth spread over one source pixel), image.
    landed: Vec<Landed>,
    /// Images landed so far.
    images: u32,
}

impl LdiLanding {
    /// Nothing landed yet in a `width` x `height` LDI seen by `camera`.
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        LdiLanding {
            camera: *camera,
            width,
            height,
            landed: Vec::new(),
            images: 0,
        }
    }

    /// Images landed so far.
    pub fn images(&self) -> usize {
        self.images as usize
    }

    /// Lands every sample of `image` (the next image; the first is the LDI camera's own
    /// view) at the pixel its centre falls in; `tolerance` sizes its depth spread.
    pub fn add(&mut self, image: &DepthImage, tolerance: f32) {
        let k = self.images;
        self.images += 1;
        let (width, height) = (self.width, self.height);
        let Some(eq) = Equation::new(
            &image.camera,
            image.width(),
            image.height(),
            &self.camera,
            width,
            height,
        ) else {
            return;
        };
        // Rows landed side by side on the thread pool, kept in row order.
        let rows: Vec<Vec<Landed>> = (0..image.height())
            .into_par_iter()
            .map(|y| {
                let mut out = Vec::new();
                for x in 0..image.width() {
                    let i = (y * image.width() + x) as usize;
                    let (c, z) = (image.color[i], image.depth[i]);
                    if !is_filled(c) || z.is_nan() || z <= 0.0 {
                        continue;
                    }
                    let disparity = if z.is_finite() { 1.0 / z } else { 0.0 };
                    let Some((p, depth)) = eq.land(eq.base(x, y), disparity) else {
                        continue;
                    };
                    let (px, py) = (p.x.floor(), p.y.floor());
                    if px < 0.0 || py < 0.0 || px >= width as f32 || py >= height as f32 {
                        continue;
                    }
                    let pixel = py as u32 * width + px as u32;
                    let spread = spread(image, x, y, tolerance) * depth / z;
                    out.push((pixel, LdiSample { color: c, depth }, spread, k));
                }
                out
            })
            .collect();
        for r in rows {
            self.landed.extend(r);
        }
    }
}

/// Scratch memory of LDI merges, reused.
#[derive(Debug, Default)]
pub struct LdiBuilder {
    /// The landed samples grouped by pixel (in landing order within a pixel), and where
    /// each pixel's group starts.
    grouped: Vec<Landed>,
    starts: Vec<u32>,
    /// The next free place of each pixel's group while grouping.
    at: Vec<u32>,
}

impl LdiBuilder {
    /// An LDI of `width` x `height` seen by `camera` (perspective) from `images`: every
    /// sample warped (to the pixel its centre lands in), then per pixel sorted near to far
    /// and merged where within `tolerance` (relative depth) of the previous kept sample, or
    /// within either's depth spread over one pixel of its own image (a surface seen at a
    /// grazing angle changes depth fast across a pixel); of such a cluster the sample of the
    /// earliest image stays. The first image is taken as seen from the LDI camera: where
    /// it has a sample, nothing nearer is kept, so its view is the front layer. An
    /// orthographic camera gives an empty LDI. ([`LdiLanding`] and [`LdiBuilder::merge`]
    /// do the same a view at a time.)
    pub fn build(
        &mut self,
        camera: &Camera,
        width: u32,
        height: u32,
        images: &[DepthImage],
        tolerance: f32,
    ) -> LayeredDepthImage {
        let mut landing = LdiLanding::new(camera, width, height);
        for image in images {
            landing.add(image, tolerance);
        }
        self.merge(&mut landing, tolerance)
    }

    /// The LDI of the images landed in `landing` (emptied), as [`LdiBuilder::build`].
    pub fn merge(&mut self, landing: &mut LdiLanding, tolerance: f32) -> LayeredDepthImage {
        let (width, height, camera) = (landing.width, landing.height, &landing.camera);
        let landed = &mut landing.landed;
        // Grouped by pixel (a counting sort, stable), then each pixel's samples sorted by
        // depth (stable: among equal depths the earlier image's sample comes first and is
        // kept): the order of one stable sort by (pixel, depth), in linear time.
        let n = width as usize * height as usize;
        self.starts.clear();
        self.starts.resize(n + 1, 0);
        for e in landed.iter() {
            self.starts[e.0 as usize + 1] += 1;
        }
        for i in 0..n {
            self.starts[i + 1] += self.starts[i];
        }
        self.grouped.clear();
        if let Some(&first) = landed.first() {
            self.grouped.resize(landed.len(), first);
        }
        self.at.clear();
        self.at.extend_from_slice(&self.starts[..n]);
        for e in landed.iter() {
            let slot = &mut self.at[e.0 as usize];
            self.grouped[*slot as usize] = *e;
            *slot += 1;
        }
        for p in 0..n {
            let (a, b) = (self.starts[p] as usize, self.starts[p + 1] as usize);
            if b - a > 1 {
                self.grouped[a..b].sort_by(|x, y| x.1.depth.total_cmp(&y.1.depth));
            }
        }
        std::mem::swap(landed, &mut self.grouped);
        let mut offsets = Vec::with_capacity(n + 1);
        let mut samples: Vec<LdiSample> = Vec::with_capacity(landed.len());
        let mut next = 0;
        offsets.push(0);
        for pixel in 0..n as u32 {
            let start = samples.len();
            let (mut reach, mut from) = (0.0f32, 0);
            let end = self.starts[pixel as usize + 1] as usize;
            // What the first image saw here is the front: a nearer sample of another image
            // in this pixel is a silhouette of its rounding, which the LDI camera cannot see.
            let front = landed[next..end].iter().find(|e| e.3 == 0).map(|e| {
                let d = e.1.depth;
                if d.is_finite() {
                    d - (tolerance * d).max(e.2)
                } else {
                    d
                }
            });
            while next < end {
                let (_, s, spread, image) = landed[next];
                if front.is_some_and(|f| s.depth < f) {
                    next += 1;
                    continue;
                }
                let same = samples[start..].last().is_some_and(|k: &LdiSample| {
                    let gap = (s.depth - k.depth).abs();
                    s.depth == k.depth || gap <= (tolerance * k.depth).max(reach.max(spread))
                });
                if !same {
                    samples.push(s);
                    (reach, from) = (spread, image);
                } else if image < from {
                    // One surface seen by two images: the earlier image's sample stands.
                    if let Some(last) = samples.last_mut() {
                        *last = s;
                    }
                    (reach, from) = (reach.max(spread), image);
                }
                next += 1;
            }
            offsets.push(samples.len() as u32);
        }
        landed.clear();
        landing.images = 0;
        LayeredDepthImage::from_packed(width, height, offsets, samples, *camera)
            .unwrap_or_else(|| LayeredDepthImage::empty(width, height, *camera))
    }
}

#[cfg(test)]
mod tests;

/// How much the depth of `image` changes from pixel `(x, y)` to its neighbours on the same
/// surface (within 4 `tolerance` relative): the depth range one of its samples stands for.
fn spread(image: &DepthImage, x: u32, y: u32, tolerance: f32) -> f32 {
    let z = image.depth[(y * image.width() + x) as usize];
    if !z.is_finite() {
        return 0.0;
    }
    let mut most = 0.0f32;
    for (dx, dy) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)] {
        let (nx, ny) = (x as i64 + dx, y as i64 + dy);
        if let Some((c, d)) = (nx >= 0 && ny >= 0)
            .then(|| image.get(nx as u32, ny as u32))
            .flatten()
        {
            let gap = (d - z).abs();
            if is_filled(c) && d.is_finite() && gap <= 4.0 * tolerance * z {
                most = most.max(gap);
            }
        }
    }
    most
}
