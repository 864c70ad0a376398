//! The 3D warp (McMillan 97): depth images re-projected to a new camera, so a novel view
//! comes from images alone, with motion parallax.
//!
//! References are [`Prepared`] first (disparity, surface slope and packed colour per
//! sample, once per reference). Then, one reference at a time into one output image (a
//! [`Warped`] at the target camera: packed colour and disparity, reused frame to frame):
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
//!    exactly, at any thread count.;
//! 5. **holes** ([`holes`]): counted by kind, then filled (pull-push or from the background
//!    side) without dragging foreground colour across a depth edge.
//!
//! A reference pixel whose colour is fully transparent is empty and skipped; one with
//! colour and infinite depth is at infinity (sky, disparity 0): it moves with the rotation
//! alone. For a depth image the warp and footprint of a whole row are computed first,
//! branch-free (so the compiler vectorises them), then its samples are binned in the
//! traversal's order as 16-byte entries that carry their colour, so the write stage reads
//! nothing else.
//! [`technique::WarpedView`] runs this every frame for the references nearest the eye and
//! writes the result into the frame by an image pass, depth-tested against the geometry.
//! Output pixels nothing reached are holes: transparent, disparity [`HOLE`]. Both cameras
//! must be perspective (symmetric or off-axis); otherwise nothing is warped.

pub mod equation;
pub mod holes;
pub mod ldi;
pub mod mesh;
pub mod order;
pub mod predict;
pub mod prepared;
mod rows;
pub mod technique;
pub mod warped;

use crate::images::{DepthImage, LayeredDepthImage};
use engine::color::{unpack, Encoder};
use engine::{Camera, Premul};
use equation::Equation;
use order::Run;
pub use prepared::Prepared;
use rayon::prelude::*;
use rows::{Footprints, Lane};
pub use warped::{Warped, ENCODING, HOLE};

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

/// A warped sample's target rectangle `[x0, x1) x [y0, y1)`, disparity and colour.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Entry {
    x0: u16,
    y0: u16,
    x1: u16,
    y1: u16,
    disparity: f32,
    color: u32,
}

/// Target rows per band of the write stage.
const BAND_ROWS: u32 = 32;
/// Runs (reference rows or half-rows) per chunk of the bin stage.
const CHUNK_RUNS: usize = 16;
/// The largest target side (entries hold `u16` coordinates).
pub const MAX_SIDE: u32 = u16::MAX as u32;

/// One chunk of the bin stage: its entries per band, and its row scratch.
#[derive(Debug, Default)]
struct Chunk {
    bins: Vec<Vec<Entry>>,
    row: Footprints,
}

/// Warps depth images to a camera: the output image and the scratch memory, reused.
#[derive(Debug)]
pub struct Warper {
    output: Warped,
    /// A second reference is warped here, then merged by depth.
    layer: Warped,
    has_content: bool,
    runs: Vec<Run>,
    chunks: Vec<Chunk>,
    /// A reference prepared by [`Warper::add`] or [`Warper::add_layered`].
    scratch: Prepared,
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
            output: Warped::new(0, 0, camera),
            layer: Warped::new(0, 0, camera),
            has_content: false,
            runs: Vec::new(),
            chunks: Vec::new(),
            scratch: Prepared::default(),
        }
    }

    /// Starts an output image of `width` x `height` (each at most [`MAX_SIDE`]) seen by
    /// `camera`, all holes.
    pub fn begin(&mut self, camera: &Camera, width: u32, height: u32) {
        let (w, h) = (width.min(MAX_SIDE), height.min(MAX_SIDE));
        self.output.reset(camera, w, h);
        self.has_content = false;
    }

    /// The output so far.
    pub fn output(&self) -> &Warped {
        &self.output
    }

    /// The output, for hole filling.
    pub fn output_mut(&mut self) -> &mut Warped {
        &mut self.output
    }

    /// Warps `reference` into the output (prepared here; warping the same reference
    /// often, prepare it once and use [`Warper::add_prepared`]). Within one reference
    /// `options.visibility` decides; later references join by `options.composite` (add
    /// the references nearest the eye first: on a surface both saw, the earlier
    /// reference's samples stay).
    pub fn add(&mut self, reference: &DepthImage, options: &WarpOptions) -> WarpStats {
        let mut p = std::mem::take(&mut self.scratch);
        p.prepare_image(reference, options.edge);
        let stats = self.add_prepared(&p, options);
        self.scratch = p;
        stats
    }

    /// Warps a layered depth image into the output (Shade et al. 98): its pixels in the
    /// occlusion-compatible order, each pixel's samples back to front, painted with "over"
    /// (translucent samples blend), so surfaces the LDI camera saw behind others fill what
    /// a single depth image would leave as disocclusions. Joins earlier references like
    /// [`Warper::add`].
    pub fn add_layered(&mut self, ldi: &LayeredDepthImage, options: &WarpOptions) -> WarpStats {
        let mut p = std::mem::take(&mut self.scratch);
        p.prepare_ldi(ldi, options.edge);
        let stats = self.add_prepared(&p, options);
        self.scratch = p;
        stats
    }

    /// Warps a prepared depth image or LDI into the output, as [`Warper::add`]. Its slopes
    /// were read with the edge tolerance it was prepared with.
    pub fn add_prepared(&mut self, source: &Prepared, options: &WarpOptions) -> WarpStats {
        let (w2, h2) = (self.output.width(), self.output.height());
        let camera = self.output.camera;
        let (w1, h1) = source.size();
        let Some(eq) = Equation::new(source.camera(), w1, h1, &camera, w2, h2) else {
            return WarpStats::default();
        };
        let (epipole, in_front) = eq.epipole_pixel();
        order::runs(w1, h1, epipole, in_front, &mut self.runs);
        let lane = Lane::new(&eq, options, w2, h2);
        // A second reference is warped apart and merged, so that where both saw one
        // surface the first (the nearer to the eye, as callers order them) is kept.
        let merge = self.has_content;
        let out = if merge {
            self.layer.reset(&camera, w2, h2);
            &mut self.layer
        } else {
            &mut self.output
        };
        let mut stats = bin(&lane, source, &self.runs, &mut self.chunks, h2);
        let chunks = &self.chunks[..self.runs.len().div_ceil(CHUNK_RUNS)];
        stats.pixels_written = write(out, chunks, options.visibility, options.edge);
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

/// Whether a pixel holds a sample (warped outputs: holes are fully transparent).
#[inline]
pub fn is_filled(c: Premul) -> bool {
    c.a > 0.0
}

/// Stage 3: every sample's entry, listed per (chunk, band) in order.
fn bin(
    lane: &Lane,
    source: &Prepared,
    runs: &[Run],
    chunks: &mut Vec<Chunk>,
    h2: u32,
) -> WarpStats {
    let bands = h2.div_ceil(BAND_ROWS).max(1) as usize;
    let n = runs.len().div_ceil(CHUNK_RUNS);
    if chunks.len() < n {
        chunks.resize_with(n, Chunk::default);
    }
    let w1 = source.size().0 as usize;
    chunks[..n]
        .par_iter_mut()
        .zip(runs.par_chunks(CHUNK_RUNS))
        .map(|(chunk, runs)| {
            let Chunk { bins, row } = chunk;
            bins.resize_with(bands, Vec::new);
            bins.truncate(bands);
            bins.iter_mut().for_each(Vec::clear);
            let mut stats = WarpStats::default();
            let mut emit = |e: Entry| {
                let (b0, b1) = (e.y0 as u32 / BAND_ROWS, (e.y1 as u32 - 1) / BAND_ROWS);
                bins[b0 as usize].push(e);
                for b in b0 + 1..=b1 {
                    bins[b as usize].push(e);
                }
            };
            for run in runs {
                if source.single() {
                    // The run's pixels lie in one contiguous span of its row.
                    let (lo, hi) = run.span();
                    stats += row.compute(lane, source, run.y, lo, hi);
                    let at = |x: u32| (x - lo) as usize;
                    let base = run.y as usize * w1;
                    for x in run.pixels() {
                        if let Some(e) = row.entry(at(x), source.color[base + x as usize]) {
                            emit(e);
                        }
                    }
                } else {
                    for x in run.pixels() {
                        let p = run.y as usize * w1 + x as usize;
                        let (s0, s1) = (source.first[p], source.first[p + 1]);
                        for s in s0..s1 {
                            let base = lane.eq.base(x, run.y);
                            if let Some(e) = lane.sample(source, s as usize, base, &mut stats) {
                                emit(e);
                            }
                        }
                    }
                }
            }
            stats
        })
        .reduce(WarpStats::default, |mut a, b| {
            a += b;
            a
        })
}

/// Stage 4: the bins written into `out` band by band, chunks in order. Returns the pixels
/// written.
fn write(out: &mut Warped, chunks: &[Chunk], vis: Visibility, edge: f32) -> u64 {
    let slack = 1.0 + edge.max(0.0);
    let w = out.width() as usize;
    let band_len = BAND_ROWS as usize * w;
    if w == 0 || chunks.is_empty() {
        return 0;
    }
    let enc = Encoder::new(ENCODING);
    out.color
        .par_chunks_mut(band_len)
        .zip(out.disparity.par_chunks_mut(band_len))
        .enumerate()
        .map(|(b, (color, disparity))| {
            let y_base = b * BAND_ROWS as usize;
            let rows = color.len() / w;
            let mut written = 0u64;
            for chunk in chunks {
                for e in &chunk.bins[b] {
                    let opaque = e.color >> 24 == 0xff;
                    let (x0, x1) = (e.x0 as usize, e.x1 as usize);
                    let y0 = (e.y0 as usize).max(y_base) - y_base;
                    if opaque && vis == Visibility::Ordered && x1 == x0 + 1 && e.y1 == e.y0 + 1 {
                        // A point: one pixel, painted over.
                        let k = y0 * w + x0;
                        color[k] = e.color;
                        disparity[k] = e.disparity;
                        written += 1;
                        continue;
                    }
                    let y1 = (e.y1 as usize).min(y_base + rows) - y_base;
                    for y in y0..y1 {
                        let row = y * w + x0..y * w + x1;
                        for (c, d) in color[row.clone()].iter_mut().zip(&mut disparity[row]) {
                            // A depth buffer keeps the nearer surface: nearer, or within the
                            // edge tolerance (a hole's negative disparity always yields).
                            if vis == Visibility::DepthBuffer && e.disparity * slack < *d {
                                continue;
                            }
                            *c = if opaque || vis == Visibility::DepthBuffer {
                                e.color
                            } else {
                                over(e.color, *c, &enc)
                            };
                            *d = e.disparity;
                            written += 1;
                        }
                    }
                }
            }
            written
        })
        .sum()
}

/// Packed `a` over packed `b`, premultiplied.
#[inline]
fn over(a: u32, b: u32, enc: &Encoder) -> u32 {
    let (a, b) = (unpack(ENCODING, a), unpack(ENCODING, b));
    let k = 1.0 - a.a;
    enc.pack(a.r + b.r * k, a.g + b.g * k, a.b + b.b * k, a.a + b.a * k)
}

/// Copies into `out` every sample of `layer` where `out` has a hole or a sample farther by
/// more than `edge` (relative depth).
fn merge_nearer(out: &mut Warped, layer: &Warped, edge: f32) {
    let keep = 1.0 - edge.clamp(0.0, 1.0);
    out.color
        .par_iter_mut()
        .zip(out.disparity.par_iter_mut())
        .zip(layer.color.par_iter().zip(layer.disparity.par_iter()))
        .for_each(|((c, d), (lc, ld))| {
            // Farther by more than `edge` in depth is nearer by more than that in disparity:
            // `d_out < (1 - edge) d_layer`.
            if *ld >= 0.0 && (*d < 0.0 || *ld * keep > *d) {
                *c = *lc;
                *d = *ld;
            }
        });
}

#[cfg(test)]
mod tests;
