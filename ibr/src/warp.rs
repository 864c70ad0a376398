//! The 3D warp (McMillan 97): depth images re-projected to a new camera, so a novel view
//! comes from images alone, with motion parallax.
//!
//! Pipeline, one reference at a time into one output image (a [`DepthImage`] at the target
//! camera, reused frame to frame):
//! 1. **order** ([`order`]): the reference's pixels in McMillan's occlusion-compatible
//!    order (sheets around the epipole), or any order when a depth buffer decides;
//! 2. **warp** ([`equation`]): each sample's target position and depth, incrementally
//!    along rows, and its footprint: one pixel ([`Reconstruction::Points`]) or a splat sized
//!    by the warp's local stretch and the surface's slope ([`Reconstruction::Splats`]);
//! 3. **bin**: in parallel over chunks of the order, samples are listed per band of target
//!    rows, in order;
//! 4. **write**: in parallel over bands (disjoint `&mut` rows), each band's samples are
//!    written chunk by chunk in order: painted over ([`Visibility::Ordered`]) or
//!    depth-tested ([`Visibility::DepthBuffer`]). The result is the sequential warp's,
//!    exactly, at any thread count;
//! 5. **holes** ([`holes`]): counted by kind, then filled (pull-push or from the background
//!    side) without dragging foreground colour across a depth edge.
//!
//! A reference pixel whose colour is fully transparent is empty and skipped; one with
//! colour and infinite depth is at infinity (sky): it moves with the rotation alone.
//! [`technique::WarpedView`] runs this every frame for the references nearest the eye and
//! writes the result into the frame by an image pass, depth-tested against the geometry.
//! Output pixels nothing reached are holes: transparent, depth [`EMPTY`]. Both cameras must
//! be perspective (symmetric or off-axis); otherwise nothing is warped.

pub mod equation;
pub mod holes;
pub mod ldi;
pub mod mesh;
pub mod order;
pub mod predict;
pub mod technique;

use crate::images::{DepthImage, LayeredDepthImage, EMPTY};
use engine::{Camera, Premul};
use equation::Equation;
use glam::Vec2;
use order::Run;
use rayon::prelude::*;

/// How competing samples are resolved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Visibility {
    /// McMillan's occlusion-compatible order, painting over: no depth buffer.
    Ordered,
    /// A depth buffer decides: a sample replaces what is there unless it is farther by more
    /// than the edge tolerance. Samples of one surface (within the tolerance) are resolved
    /// by the order, the later winning as in [`Visibility::Ordered`]; of two surfaces the
    /// nearer wins (the ε-z-buffer of surface splatting).
    DepthBuffer,
}

/// How a sample covers the target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reconstruction {
    /// The one pixel its centre lands in.
    Points,
    /// A rectangle the size of its warped footprint (at most `max_splat` pixels a side).
    Splats,
}

/// How the second and later references of a frame join the output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Composite {
    /// By depth: a later sample replaces a hole or a sample farther by more than the edge
    /// tolerance (an occluder only a later reference saw still shows).
    Depth,
    /// By priority: later references only fill the holes of earlier ones (the nearer
    /// reference is trusted wherever it saw something; no bleeding of a farther
    /// reference's silhouettes).
    Priority,
}

/// How to warp.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WarpOptions {
    pub visibility: Visibility,
    pub reconstruction: Reconstruction,
    pub composite: Composite,
    /// The largest splat side, pixels: stretches beyond it are left as holes.
    pub max_splat: f32,
    /// Relative depth change between neighbouring samples above which they are taken to be
    /// on different surfaces (no slope is read across it).
    pub edge: f32,
}

impl Default for WarpOptions {
    fn default() -> Self {
        WarpOptions {
            visibility: Visibility::Ordered,
            reconstruction: Reconstruction::Splats,
            composite: Composite::Depth,
            max_splat: 4.0,
            edge: 0.05,
        }
    }
}

/// The work of one warp.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WarpStats {
    /// Reference samples read (non-empty).
    pub samples: u64,
    /// Samples that landed at least partly inside the target image.
    pub warped: u64,
    /// Samples behind the target eye.
    pub behind: u64,
    /// Target pixels written (a pixel written twice counts twice).
    pub pixels_written: u64,
}

impl std::ops::AddAssign for WarpStats {
    fn add_assign(&mut self, o: Self) {
        self.samples += o.samples;
        self.warped += o.warped;
        self.behind += o.behind;
        self.pixels_written += o.pixels_written;
    }
}

/// A warped sample's target rectangle `[x0, x1) x [y0, y1)`, depth and source pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Entry {
    x0: u16,
    y0: u16,
    x1: u16,
    y1: u16,
    depth: f32,
    index: u32,
}

/// Target rows per band of the write stage.
const BAND_ROWS: u32 = 16;
/// Runs (reference rows or half-rows) per chunk of the bin stage.
const CHUNK_RUNS: usize = 16;
/// The largest target side (entries hold `u16` coordinates).
pub const MAX_SIDE: u32 = u16::MAX as u32;

/// Warps depth images to a camera: the output image and the scratch memory, reused.
#[derive(Debug)]
pub struct Warper {
    output: DepthImage,
    /// An ordered warp of a second reference goes here, then merges by depth.
    layer: DepthImage,
    has_content: bool,
    runs: Vec<Run>,
    bins: Vec<Vec<Entry>>,
}

impl Default for Warper {
    fn default() -> Self {
        Self::new()
    }
}

impl Warper {
    pub fn new() -> Self {
        let camera = Camera::look_at(glam::Vec3::Z, glam::Vec3::ZERO, glam::Vec3::Y, 1.0, 1.0);
        Warper {
            output: DepthImage::new(0, 0, camera),
            layer: DepthImage::new(0, 0, camera),
            has_content: false,
            runs: Vec::new(),
            bins: Vec::new(),
        }
    }

    /// Starts an output image of `width` x `height` (each at most [`MAX_SIDE`]) seen by
    /// `camera`, all holes.
    pub fn begin(&mut self, camera: &Camera, width: u32, height: u32) {
        let (w, h) = (width.min(MAX_SIDE), height.min(MAX_SIDE));
        reset(&mut self.output, camera, w, h);
        self.has_content = false;
    }

    /// The output so far.
    pub fn output(&self) -> &DepthImage {
        &self.output
    }

    /// The output, for hole filling.
    pub fn output_mut(&mut self) -> &mut DepthImage {
        &mut self.output
    }

    /// Warps `reference` into the output. Within one reference `options.visibility`
    /// decides; later references join by `options.composite` (add the references nearest
    /// the eye first: on a surface both saw, the earlier reference's samples stay).
    pub fn add(&mut self, reference: &DepthImage, options: &WarpOptions) -> WarpStats {
        self.add_source(reference, options)
    }

    /// Warps a layered depth image into the output (Shade et al. 98): its pixels in the
    /// occlusion-compatible order, each pixel's samples back to front, painted with "over"
    /// (translucent samples blend), so surfaces the LDI camera saw behind others fill what
    /// a single depth image would leave as disocclusions. Joins earlier references like
    /// [`Warper::add`].
    pub fn add_layered(&mut self, ldi: &LayeredDepthImage, options: &WarpOptions) -> WarpStats {
        self.add_source(ldi, options)
    }

    fn add_source<S: Source>(&mut self, source: &S, options: &WarpOptions) -> WarpStats {
        let (w2, h2) = (self.output.width(), self.output.height());
        let camera = self.output.camera;
        let (w1, h1) = source.size();
        let Some(eq) = Equation::new(source.camera(), w1, h1, &camera, w2, h2) else {
            return WarpStats::default();
        };
        let (epipole, in_front) = eq.epipole_pixel();
        order::runs(w1, h1, epipole, in_front, &mut self.runs);
        let mut stats = bin(&eq, source, options, &self.runs, &mut self.bins, w2, h2);
        // A second reference is warped apart and merged, so that where both saw one
        // surface the first (the nearer to the eye, as callers order them) is kept.
        let merge = self.has_content;
        let out = if merge {
            reset(&mut self.layer, &camera, w2, h2);
            &mut self.layer
        } else {
            &mut self.output
        };
        stats.pixels_written = write(out, source, &self.bins, options.visibility, options.edge);
        if merge {
            let edge = match options.composite {
                Composite::Depth => options.edge,
                // Nothing is "clearly nearer" by more than everything: holes only.
                Composite::Priority => 1.0,
            };
            merge_nearer(&mut self.output, &self.layer, edge);
        }
        self.has_content = true;
        stats
    }
}

/// What the warp reads: an image's samples with their camera.
trait Source: Sync {
    fn camera(&self) -> &Camera;
    fn size(&self) -> (u32, u32);
    /// Calls `f(index, colour, depth)` for each sample of pixel `(x, y)` in painting order
    /// (back to front); `index` names the sample for [`Source::color`].
    fn samples(&self, x: u32, y: u32, f: impl FnMut(u32, Premul, f32));
    fn color(&self, index: u32) -> Premul;
    /// The change of disparity per pixel in x and y at a sample (the surface's slope).
    fn slope(&self, x: u32, y: u32, z: f32, edge: f32) -> Vec2;
}

impl Source for DepthImage {
    fn camera(&self) -> &Camera {
        &self.camera
    }
    fn size(&self) -> (u32, u32) {
        (self.width(), self.height())
    }
    #[inline]
    fn samples(&self, x: u32, y: u32, mut f: impl FnMut(u32, Premul, f32)) {
        let i = y * self.width() + x;
        f(i, self.color[i as usize], self.depth[i as usize]);
    }
    #[inline]
    fn color(&self, index: u32) -> Premul {
        self.color[index as usize]
    }
    fn slope(&self, x: u32, y: u32, z: f32, edge: f32) -> Vec2 {
        Vec2::new(
            slope(self, x, y, 1, 0, z, edge),
            slope(self, x, y, 0, 1, z, edge),
        )
    }
}

impl Source for LayeredDepthImage {
    fn camera(&self) -> &Camera {
        &self.camera
    }
    fn size(&self) -> (u32, u32) {
        (self.width(), self.height())
    }
    #[inline]
    fn samples(&self, x: u32, y: u32, mut f: impl FnMut(u32, Premul, f32)) {
        let (first, run) = self.samples_at(x, y);
        for (k, s) in run.iter().enumerate().rev() {
            f(first + k as u32, s.color, s.depth);
        }
    }
    #[inline]
    fn color(&self, index: u32) -> Premul {
        self.sample(index).color
    }
    /// From the neighbouring pixels' samples of the same surface (within `edge`), as for a
    /// depth image.
    fn slope(&self, x: u32, y: u32, z: f32, edge: f32) -> Vec2 {
        if !z.is_finite() {
            return Vec2::ZERO;
        }
        let near = |nx: u32, ny: u32| {
            self.samples_at(nx, ny)
                .1
                .iter()
                .find(|s| {
                    is_filled(s.color) && s.depth.is_finite() && (s.depth - z).abs() <= edge * z
                })
                .map(|s| 1.0 / s.depth)
        };
        let axis = |dx: u32, dy: u32| {
            if let Some(ahead) = near(x + dx, y + dy) {
                return ahead - 1.0 / z;
            }
            if x >= dx && y >= dy {
                if let Some(behind) = near(x - dx, y - dy) {
                    return 1.0 / z - behind;
                }
            }
            0.0
        };
        Vec2::new(axis(1, 0), axis(0, 1))
    }
}

/// Resizes `image` to `w` x `h` for `camera` and clears it to holes, keeping its memory.
fn reset(image: &mut DepthImage, camera: &Camera, w: u32, h: u32) {
    if image.width() != w || image.height() != h {
        let mut color = std::mem::take(&mut image.color);
        let mut depth = std::mem::take(&mut image.depth);
        let n = w as usize * h as usize;
        color.resize(n, Premul::TRANSPARENT);
        depth.resize(n, EMPTY);
        *image = DepthImage::from_planes(w, h, color, depth, *camera)
            .unwrap_or_else(|| DepthImage::new(w, h, *camera));
    }
    image.camera = *camera;
    image.color.fill(Premul::TRANSPARENT);
    image.depth.fill(EMPTY);
}

/// Whether a pixel holds a sample (warped outputs: holes are fully transparent).
#[inline]
pub fn is_filled(c: Premul) -> bool {
    c.a > 0.0
}

/// Stage 3: every sample's entry, listed per (chunk, band) in order.
fn bin<S: Source>(
    eq: &Equation,
    reference: &S,
    options: &WarpOptions,
    runs: &[Run],
    bins: &mut Vec<Vec<Entry>>,
    w2: u32,
    h2: u32,
) -> WarpStats {
    let bands = h2.div_ceil(BAND_ROWS).max(1) as usize;
    let chunks = runs.len().div_ceil(CHUNK_RUNS);
    bins.resize_with(chunks * bands, Vec::new);
    bins.truncate(chunks * bands);
    bins.par_chunks_mut(bands)
        .zip(runs.par_chunks(CHUNK_RUNS))
        .map(|(bins, runs)| {
            bins.iter_mut().for_each(Vec::clear);
            let mut stats = WarpStats::default();
            for run in runs {
                for x in run.pixels() {
                    reference.samples(x, run.y, |index, c, z| {
                        let sample = Sample {
                            x,
                            y: run.y,
                            index,
                            c,
                            z,
                        };
                        let Some(e) =
                            warp_sample(eq, reference, options, sample, w2, h2, &mut stats)
                        else {
                            return;
                        };
                        let (b0, b1) = (e.y0 as u32 / BAND_ROWS, (e.y1 as u32 - 1) / BAND_ROWS);
                        for b in b0..=b1 {
                            bins[b as usize].push(e);
                        }
                    });
                }
            }
            stats
        })
        .reduce(WarpStats::default, |mut a, b| {
            a += b;
            a
        })
}

/// A sample of a source at pixel `(x, y)`.
#[derive(Clone, Copy)]
struct Sample {
    x: u32,
    y: u32,
    index: u32,
    c: Premul,
    z: f32,
}

/// Stage 2 for one sample: its entry, or `None` (empty, behind the eye, off the image).
#[inline]
fn warp_sample<S: Source>(
    eq: &Equation,
    reference: &S,
    options: &WarpOptions,
    Sample { x, y, index, c, z }: Sample,
    w2: u32,
    h2: u32,
    stats: &mut WarpStats,
) -> Option<Entry> {
    if !is_filled(c) || z.is_nan() || z <= 0.0 {
        return None;
    }
    stats.samples += 1;
    let disparity = if z.is_finite() { 1.0 / z } else { 0.0 };
    let base = eq.base(x, y);
    let Some((p, depth)) = eq.land(base, disparity) else {
        stats.behind += 1;
        return None;
    };
    let (half_x, half_y) = match options.reconstruction {
        Reconstruction::Points => (0.5, 0.5),
        Reconstruction::Splats => {
            let slope = reference.slope(x, y, z, options.edge);
            let (jx, jy) = eq.stretch(base, disparity, slope);
            let size = Vec2::new(jx.x.abs() + jy.x.abs(), jx.y.abs() + jy.y.abs());
            let size = size.clamp(Vec2::ONE, Vec2::splat(options.max_splat.max(1.0)));
            if !size.is_finite() {
                (0.5, 0.5)
            } else {
                (size.x * 0.5, size.y * 0.5)
            }
        }
    };
    // Pixels whose centres lie within the footprint; at least the one the centre is in.
    let span = |c: f32, half: f32, n: u32| -> Option<(u16, u16)> {
        let (lo, hi) = if half <= 0.5 {
            (c.floor(), c.floor() + 1.0)
        } else {
            let lo = (c - half + 0.5).floor();
            (lo, (c + half + 0.5).floor().max(lo + 1.0))
        };
        let (lo, hi) = (lo.max(0.0), hi.min(n as f32));
        (lo < hi).then_some((lo as u16, hi as u16))
    };
    let ((x0, x1), (y0, y1)) = (span(p.x, half_x, w2)?, span(p.y, half_y, h2)?);
    stats.warped += 1;
    Some(Entry {
        x0,
        y0,
        x1,
        y1,
        depth,
        index,
    })
}

/// The change of disparity per pixel step `(dx, dy)` at `(x, y)` of depth `z`: from the
/// neighbour ahead, else the one behind, when on the same surface; else zero.
fn slope(r: &DepthImage, x: u32, y: u32, dx: u32, dy: u32, z: f32, edge: f32) -> f32 {
    if !z.is_finite() {
        return 0.0;
    }
    let near = |n: Option<(Premul, f32)>| {
        n.filter(|(c, d)| is_filled(*c) && d.is_finite() && (d - z).abs() <= edge * z)
            .map(|(_, d)| 1.0 / d)
    };
    if let Some(ahead) = near(r.get(x + dx, y + dy)) {
        return ahead - 1.0 / z;
    }
    if x >= dx && y >= dy {
        if let Some(behind) = near(r.get(x - dx, y - dy)) {
            return 1.0 / z - behind;
        }
    }
    0.0
}

/// Stage 4: the bins written into `out` band by band, chunks in order. Returns the pixels
/// written.
fn write<S: Source>(
    out: &mut DepthImage,
    reference: &S,
    bins: &[Vec<Entry>],
    vis: Visibility,
    edge: f32,
) -> u64 {
    let slack = 1.0 + edge.max(0.0);
    let w = out.width() as usize;
    let bands = out.height().div_ceil(BAND_ROWS).max(1) as usize;
    let band_len = BAND_ROWS as usize * w;
    if w == 0 || bins.is_empty() {
        return 0;
    }
    let chunks = bins.len() / bands;
    out.color
        .par_chunks_mut(band_len)
        .zip(out.depth.par_chunks_mut(band_len))
        .enumerate()
        .map(|(b, (color, depth))| {
            let y_base = b * BAND_ROWS as usize;
            let rows = color.len() / w;
            let mut written = 0u64;
            for c in 0..chunks {
                for e in &bins[c * bands + b] {
                    let y0 = (e.y0 as usize).max(y_base) - y_base;
                    let y1 = (e.y1 as usize).min(y_base + rows) - y_base;
                    let sample = reference.color(e.index);
                    let opaque = sample.a >= 1.0;
                    for y in y0..y1 {
                        for k in y * w + e.x0 as usize..y * w + e.x1 as usize {
                            let pass = match vis {
                                Visibility::Ordered => true,
                                Visibility::DepthBuffer => {
                                    e.depth <= depth[k] * slack || !is_filled(color[k])
                                }
                            };
                            if pass {
                                color[k] = if opaque || vis == Visibility::DepthBuffer {
                                    sample
                                } else {
                                    over(sample, color[k])
                                };
                                depth[k] = e.depth;
                                written += 1;
                            }
                        }
                    }
                }
            }
            written
        })
        .sum()
}

/// `a` over `b`, premultiplied.
#[inline]
fn over(a: Premul, b: Premul) -> Premul {
    let k = 1.0 - a.a;
    Premul {
        r: a.r + b.r * k,
        g: a.g + b.g * k,
        b: a.b + b.b * k,
        a: a.a + b.a * k,
    }
}

/// Copies into `out` every sample of `layer` where `out` has a hole or a sample farther by
/// more than `edge` (relative).
fn merge_nearer(out: &mut DepthImage, layer: &DepthImage, edge: f32) {
    let keep = 1.0 - edge.clamp(0.0, 1.0);
    out.color
        .par_iter_mut()
        .zip(out.depth.par_iter_mut())
        .zip(layer.color.par_iter().zip(layer.depth.par_iter()))
        .for_each(|((c, d), (lc, ld))| {
            if is_filled(*lc) && (!is_filled(*c) || *ld < *d * keep) {
                *c = *lc;
                *d = *ld;
            }
        });
}

#[cfg(test)]
mod tests;
