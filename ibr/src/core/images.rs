//! Images that carry depth and the camera that took them: the data every image-based
//! technique stands on, kept apart from drawing (built and tested without the rasterizer).
//!
//! - [`DepthImage`]: premultiplied linear colour plus per-pixel depth and its [`Camera`].
//! - [`LayeredDepthImage`]: several samples per pixel along the pixel's ray, nearest first
//!   (Shade, Gortler, He and Szeliski 98), as depth peeling produces them.
//! - [`atlas::Atlas`]: a grid of equally sized cells in one depth image.
//! - [`transforms`]: depth images to and from files (`transforms.json` captures, PNG colour,
//!   PFM or OpenEXR depth).
//!
//! Conventions (ARCHITECTURE.md): pixels row-major, top row first, pixel centres at
//! `(x + 0.5, y + 0.5)`. **Depth is the distance along the camera's optical axis** (view-space
//! `-z`) in scene units, the convention of depth files (PFM); `f32::INFINITY` where nothing
//! was drawn. Colour is premultiplied linear, as everywhere in the engine.

pub(crate) mod atlas;

use engine::color::encode_srgb8;
use engine::{Camera, Premul, Target};
use glam::{Vec3, Vec4};
use rayon::prelude::*;

/// Depth of a pixel nothing was drawn into.
pub const EMPTY: f32 = f32::INFINITY;

/// A colour-plus-depth image and the camera that took it.
#[derive(Clone, Debug, PartialEq)]
pub struct DepthImage {
    width: u32,
    height: u32,
    /// Premultiplied linear colour, `width * height`, row-major.
    pub color: Vec<Premul>,
    /// Distance along the optical axis, scene units; [`EMPTY`] where nothing was drawn.
    pub depth: Vec<f32>,
    /// The camera that took the image (its view and projection give each pixel's ray).
    pub camera: Camera,
}

impl DepthImage {
    /// A transparent, empty image (every depth [`EMPTY`]).
    pub fn new(width: u32, height: u32, camera: Camera) -> Self {
        let n = width as usize * height as usize;
        DepthImage {
            width,
            height,
            color: vec![Premul::TRANSPARENT; n],
            depth: vec![EMPTY; n],
            camera,
        }
    }

    /// An image from `color` and `depth` planes (row-major, `width * height` each).
    /// `None` when a plane has another length.
    pub fn from_planes(
        width: u32,
        height: u32,
        color: Vec<Premul>,
        depth: Vec<f32>,
        camera: Camera,
    ) -> Option<Self> {
        let n = width as usize * height as usize;
        (color.len() == n && depth.len() == n).then_some(DepthImage {
            width,
            height,
            color,
            depth,
            camera,
        })
    }

    /// Reads a rendered `target` taken by `camera` (its reversed depth turned into distance
    /// along the axis) into this image, resizing it to the target. Reuses the planes.
    pub fn read_target(&mut self, target: &Target, camera: &Camera) {
        let (w, h) = (target.width(), target.height());
        let n = w as usize * h as usize;
        self.width = w;
        self.height = h;
        self.camera = *camera;
        self.color.resize(n, Premul::TRANSPARENT);
        self.depth.resize(n, EMPTY);
        // Rows on the pool, each pixel its own (the same image on any number of threads):
        // on one thread this took a third of the views moment's near-scene capture at
        // 1280x720 (issue 39, session 13).
        let row = w.max(1) as usize;
        self.color
            .par_chunks_mut(row)
            .zip(self.depth.par_chunks_mut(row))
            .enumerate()
            .for_each(|(y, (colors, depths))| {
                let y = y as u32;
                for (x, (c, d)) in (0..w).zip(colors.iter_mut().zip(depths.iter_mut())) {
                    *c = target.color_linear(x, y).unwrap_or(Premul::TRANSPARENT);
                    *d = axial_depth(camera, target.depth_reversed(x, y).unwrap_or(0.0));
                }
            });
    }

    /// A new image of a rendered `target` taken by `camera`.
    pub fn from_target(target: &Target, camera: &Camera) -> Self {
        let mut image = DepthImage::new(0, 0, *camera);
        image.read_target(target, camera);
        image
    }

    /// Width, pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height, pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Row-major index of pixel `(x, y)`, `None` outside.
    #[inline]
    pub fn index(&self, x: u32, y: u32) -> Option<usize> {
        (x < self.width && y < self.height).then(|| (y * self.width + x) as usize)
    }

    /// Colour and depth at a pixel.
    pub fn get(&self, x: u32, y: u32) -> Option<(Premul, f32)> {
        self.index(x, y).map(|i| (self.color[i], self.depth[i]))
    }

    /// Sets a pixel; ignored outside the image.
    pub fn set(&mut self, x: u32, y: u32, color: Premul, depth: f32) {
        if let Some(i) = self.index(x, y) {
            self.color[i] = color;
            self.depth[i] = depth;
        }
    }

    /// Pixels holding a surface (finite depth).
    pub fn covered(&self) -> usize {
        self.depth.iter().filter(|d| d.is_finite()).count()
    }

    /// The world point seen at the centre of pixel `(x, y)`, `None` where empty.
    pub fn world_point(&self, x: u32, y: u32) -> Option<Vec3> {
        let (_, d) = self.get(x, y)?;
        unproject(
            &self.camera,
            x as f32 + 0.5,
            y as f32 + 0.5,
            d,
            self.width,
            self.height,
        )
    }
}

/// The distance along the optical axis of a stored reversed depth; [`EMPTY`] for the cleared
/// value 0 (and anything not in (0, 1]).
pub fn axial_depth(camera: &Camera, reversed: f32) -> f32 {
    if reversed > 0.0 && reversed <= 1.0 {
        camera.view_depth_from_reversed(reversed)
    } else {
        EMPTY
    }
}

/// The world point at screen position `(sx, sy)` (pixels, y down) of a `width` x `height`
/// image, `depth` along the optical axis. `None` for an empty or non-finite depth.
pub fn unproject(
    camera: &Camera,
    sx: f32,
    sy: f32,
    depth: f32,
    width: u32,
    height: u32,
) -> Option<Vec3> {
    if !depth.is_finite() || width == 0 || height == 0 {
        return None;
    }
    let ndc_x = 2.0 * sx / width as f32 - 1.0;
    let ndc_y = 1.0 - 2.0 * sy / height as f32;
    // The pixel's ray meets the far plane (reversed NDC z = 0) at `p` in view space: scaled
    // to `depth` along the axis for a perspective camera, moved along -z for an orthographic one.
    let p = camera.projection.reversed_z_matrix().inverse() * Vec4::new(ndc_x, ndc_y, 0.0, 1.0);
    let p = p.truncate() / p.w;
    let view = if camera.projection.is_perspective() {
        p * (depth / -p.z)
    } else {
        Vec3::new(p.x, p.y, -depth)
    };
    let world = camera.view.inverse().transform_point3(view);
    world.is_finite().then_some(world)
}

/// One sample of a layered depth image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LdiSample {
    /// Premultiplied linear colour of the surface.
    pub color: Premul,
    /// Distance along the optical axis.
    pub depth: f32,
}

/// Several samples per pixel, nearest first, all seen by one camera: the k-th sample of a
/// pixel is the k-th surface along its ray (Shade et al. 98). Stored compactly: pixel `i`'s
/// samples are `samples[offsets[i]..offsets[i + 1]]`.
#[derive(Clone, Debug, PartialEq)]
pub struct LayeredDepthImage {
    width: u32,
    height: u32,
    offsets: Vec<u32>,
    samples: Vec<LdiSample>,
    /// The camera that took every layer.
    pub camera: Camera,
}

impl LayeredDepthImage {
    /// Merges depth layers taken by one camera at one size (layer k from depth peeling:
    /// the k-th surface per pixel) into one image: each pixel keeps its finite samples in
    /// increasing depth. `None` when the layers differ in size or there are none.
    pub fn from_layers(layers: &[DepthImage]) -> Option<Self> {
        let first = layers.first()?;
        let (w, h) = (first.width, first.height);
        if layers.iter().any(|l| l.width != w || l.height != h) {
            return None;
        }
        let n = w as usize * h as usize;
        let mut offsets = Vec::with_capacity(n + 1);
        let mut samples = Vec::new();
        let mut pixel = Vec::new();
        offsets.push(0);
        for i in 0..n {
            pixel.clear();
            pixel.extend(
                layers
                    .iter()
                    .filter(|l| l.depth[i].is_finite())
                    .map(|l| LdiSample {
                        color: l.color[i],
                        depth: l.depth[i],
                    }),
            );
            pixel.sort_by(|a, b| a.depth.total_cmp(&b.depth));
            samples.extend_from_slice(&pixel);
            offsets.push(samples.len() as u32);
        }
        Some(LayeredDepthImage {
            width: w,
            height: h,
            offsets,
            samples,
            camera: first.camera,
        })
    }

    /// An image with no samples.
    pub fn empty(width: u32, height: u32, camera: Camera) -> Self {
        LayeredDepthImage {
            width,
            height,
            offsets: vec![0; width as usize * height as usize + 1],
            samples: Vec::new(),
            camera,
        }
    }

    /// Width, pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height, pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The samples of pixel `(x, y)`, nearest first (empty outside the image).
    pub fn samples(&self, x: u32, y: u32) -> &[LdiSample] {
        if x >= self.width || y >= self.height {
            return &[];
        }
        let i = (y * self.width + x) as usize;
        &self.samples[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    /// The index of pixel `(x, y)`'s first sample and its samples, nearest first (empty
    /// outside the image).
    pub fn samples_at(&self, x: u32, y: u32) -> (u32, &[LdiSample]) {
        if x >= self.width || y >= self.height {
            return (0, &[]);
        }
        let i = (y * self.width + x) as usize;
        let (a, b) = (self.offsets[i], self.offsets[i + 1]);
        (a, &self.samples[a as usize..b as usize])
    }

    /// Sample `index` of the whole image (as [`LayeredDepthImage::samples_at`] numbers them).
    pub fn sample(&self, index: u32) -> LdiSample {
        self.samples[index as usize]
    }

    /// An image from its packed form: pixel `i`'s samples are `samples[offsets[i] ..
    /// offsets[i + 1]]`, nearest first. `None` unless `offsets` has `width * height + 1`
    /// entries, starts at 0, never decreases and ends at `samples.len()`.
    pub fn from_packed(
        width: u32,
        height: u32,
        offsets: Vec<u32>,
        samples: Vec<LdiSample>,
        camera: Camera,
    ) -> Option<Self> {
        let n = width as usize * height as usize;
        let ok = offsets.len() == n + 1
            && offsets[0] == 0
            && offsets.windows(2).all(|w| w[0] <= w[1])
            && offsets[n] as usize == samples.len();
        ok.then_some(LayeredDepthImage {
            width,
            height,
            offsets,
            samples,
            camera,
        })
    }

    /// Samples in the whole image.
    pub fn sample_count(&self) -> usize {
        self.samples.len()
    }

    /// The most samples any pixel has (the number of layers needed to hold them).
    pub fn depth_complexity(&self) -> usize {
        self.offsets
            .windows(2)
            .map(|w| (w[1] - w[0]) as usize)
            .max()
            .unwrap_or(0)
    }

    /// Layer `k` as a depth image: every pixel's k-th sample, empty where it has fewer.
    pub fn layer(&self, k: usize) -> DepthImage {
        let mut out = DepthImage::new(self.width, self.height, self.camera);
        for y in 0..self.height {
            for x in 0..self.width {
                if let Some(s) = self.samples(x, y).get(k) {
                    out.set(x, y, s.color, s.depth);
                }
            }
        }
        out
    }
}

/// An image's colour as the bytes of an sRGB, straight-alpha RGBA8 file (PNG).
pub fn srgb8(image: &DepthImage) -> Vec<u8> {
    image
        .color
        .iter()
        .flat_map(|c| {
            let s = c.unpremultiply();
            [
                encode_srgb8(s.r),
                encode_srgb8(s.g),
                encode_srgb8(s.b),
                (s.a.clamp(0.0, 1.0) * 255.0).round() as u8,
            ]
        })
        .collect()
}

#[cfg(test)]
mod tests;
