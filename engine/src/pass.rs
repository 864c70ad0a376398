//! Image passes: per-pixel techniques (a 3D warp, a light-field lookup, a morph) write
//! colour and depth straight into a target, depth-tested against what the rasterizer drew,
//! without an intermediate texture and quad.
//!
//! A pass implements [`PixelPass`]: given a row span of pixels it returns a fragment (a
//! premultiplied colour and a reversed depth, the target's own conventions) or nothing for
//! each. [`run_pass`] hands the target's tiles to the thread pool, one tile per task; every
//! pixel is shaded once by a pure function of its position, so the result does not depend on
//! the thread count. Nothing is allocated: spans are at most one tile wide and live on the
//! stack. A pass whose colours are already packed bytes ([`PackedPass`], run by
//! [`run_packed_pass`]) skips the per-pixel encode when its encoding is the target's.

use crate::color::{unpack, Encoder, Encoding, Premul};
use crate::stats::FrameStats;
use crate::target::{offset_in_tile, Target, TILE, TILE_PIXELS};
use rayon::prelude::*;

/// What a pass writes at one pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fragment {
    /// Premultiplied linear colour.
    pub color: Premul,
    /// Reversed depth as the rasterizer stores it (1 near plane, 0 far plane).
    pub depth: f32,
}

/// What a [`PackedPass`] writes at one pixel: colour already packed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PackedFragment {
    /// Premultiplied bytes `r | g << 8 | b << 16 | a << 24` in the pass's
    /// [`PackedPass::encoding`].
    pub color: u32,
    /// Reversed depth as the rasterizer stores it (1 near plane, 0 far plane).
    pub depth: f32,
}

/// How a pass's fragments reach the target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PassMode {
    /// Keep only fragments nearer than the stored depth (reversed: greater).
    pub depth_test: bool,
    /// Store the fragment's depth where it is written.
    pub depth_write: bool,
    /// Composite premultiplied "over" what is there, instead of replacing it.
    pub blend: bool,
}

impl Default for PassMode {
    /// Opaque: depth-tested, depth-written, replacing.
    fn default() -> Self {
        PassMode {
            depth_test: true,
            depth_write: true,
            blend: false,
        }
    }
}

/// A per-pixel technique.
pub trait PixelPass: Sync {
    /// Fills `out[i]` with the fragment at pixel `(x0 + i, y)`, or `None` where the pass
    /// has nothing. `out` arrives filled with `None` and is at most one tile wide.
    fn shade_span(&self, x0: u32, y: u32, out: &mut [Option<Fragment>]);
}

/// A per-pixel technique whose colours are packed bytes (an image it already holds in
/// that form): stored as they are when the encodings agree and nothing is blended.
pub trait PackedPass: Sync {
    /// The encoding of the colours it gives.
    fn encoding(&self) -> Encoding;
    /// As [`PixelPass::shade_span`].
    fn shade_span(&self, x0: u32, y: u32, out: &mut [Option<PackedFragment>]);
}

/// A fragment as the tile loop stores it.
trait Stored: Copy + Send + Sync {
    fn depth(&self) -> f32;
    /// The packed colour to store where `dst` is.
    fn packed(&self, dst: u32, blend: bool, to: &Encoder, encoding: Encoding) -> u32;
}

impl Stored for Fragment {
    #[inline]
    fn depth(&self) -> f32 {
        self.depth
    }
    #[inline]
    fn packed(&self, dst: u32, blend: bool, to: &Encoder, encoding: Encoding) -> u32 {
        let c = if blend {
            over(self.color, unpack(encoding, dst))
        } else {
            self.color
        };
        to.pack(c.r, c.g, c.b, c.a)
    }
}

/// A packed fragment with the encoding of its pass.
#[derive(Clone, Copy)]
struct Encoded(PackedFragment, Encoding);

impl Stored for Encoded {
    #[inline]
    fn depth(&self) -> f32 {
        self.0.depth
    }
    #[inline]
    fn packed(&self, dst: u32, blend: bool, to: &Encoder, encoding: Encoding) -> u32 {
        let Encoded(f, from) = *self;
        if !blend && from == encoding {
            return f.color;
        }
        let frag = Fragment {
            color: unpack(from, f.color),
            depth: f.depth,
        };
        frag.packed(dst, blend, to, encoding)
    }
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

/// A pixel rectangle `[x0, x1) x [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelRect {
    /// First column inside, pixels from the left.
    pub x0: u32,
    /// First row inside, pixels from the top.
    pub y0: u32,
    /// First column past the right edge; `x1 <= x0` is empty.
    pub x1: u32,
    /// First row past the bottom edge; `y1 <= y0` is empty.
    pub y1: u32,
}

impl PixelRect {
    /// The whole of a `width` x `height` image.
    pub fn full(width: u32, height: u32) -> Self {
        PixelRect {
            x0: 0,
            y0: 0,
            x1: width,
            y1: height,
        }
    }
}

/// Runs `pass` over the pixels of `rect` (clipped to the target). Fragments with a depth
/// that is not finite or outside [0, 1] are skipped. Counts the pixels asked
/// (`fragments_tested`), given a fragment (`fragments_shaded`) and written
/// (`fragments_written`).
pub fn run_pass(
    target: &mut Target,
    rect: PixelRect,
    pass: &impl PixelPass,
    mode: PassMode,
) -> FrameStats {
    run_tiles(target, rect, mode, |x0, y, out| pass.shade_span(x0, y, out))
}

/// [`run_pass`] for a pass that gives packed colours.
pub fn run_packed_pass(
    target: &mut Target,
    rect: PixelRect,
    pass: &impl PackedPass,
    mode: PassMode,
) -> FrameStats {
    let from = pass.encoding();
    run_tiles(target, rect, mode, |x0, y, out: &mut [Option<Encoded>]| {
        let mut span = [None; TILE];
        let span = &mut span[..out.len()];
        pass.shade_span(x0, y, span);
        for (o, f) in out.iter_mut().zip(span.iter()) {
            *o = f.map(|f| Encoded(f, from));
        }
    })
}

/// The tile loop of both kinds of pass: `shade(x0, y, span)` fills a row span of one tile.
fn run_tiles<F: Stored>(
    target: &mut Target,
    rect: PixelRect,
    mode: PassMode,
    shade: impl Fn(u32, u32, &mut [Option<F>]) + Sync,
) -> FrameStats {
    let (w, h) = (target.width(), target.height());
    let (x0, y0) = (rect.x0.min(w), rect.y0.min(h));
    let (x1, y1) = (rect.x1.min(w), rect.y1.min(h));
    if x0 >= x1 || y0 >= y1 {
        return FrameStats::default();
    }
    let tiles_x = target.tiles_x() as usize;
    let encoding = target.encoding();
    let encoder = Encoder::new(encoding);
    let (colors, depths) = target.storage_mut();
    colors
        .par_chunks_mut(TILE_PIXELS)
        .zip(depths.par_chunks_mut(TILE_PIXELS))
        .enumerate()
        .with_max_len(1)
        .map(|(tile, (color, depth))| {
            let mut stats = FrameStats::default();
            let (tx, ty) = (
                (tile % tiles_x * TILE) as u32,
                (tile / tiles_x * TILE) as u32,
            );
            let (sx0, sx1) = (x0.max(tx), x1.min(tx + TILE as u32));
            let (sy0, sy1) = (y0.max(ty), y1.min(ty + TILE as u32));
            if sx0 >= sx1 || sy0 >= sy1 {
                return stats;
            }
            let mut span: [Option<F>; TILE] = [None; TILE];
            let n = (sx1 - sx0) as usize;
            for y in sy0..sy1 {
                span[..n].fill(None);
                shade(sx0, y, &mut span[..n]);
                stats.fragments_tested += n as u64;
                for (i, frag) in span[..n].iter().enumerate() {
                    let Some(f) = frag else { continue };
                    stats.fragments_shaded += 1;
                    let d = f.depth();
                    if !(d.is_finite() && (0.0..=1.0).contains(&d)) {
                        continue;
                    }
                    let at = offset_in_tile((sx0 - tx) as usize + i, (y - ty) as usize);
                    if mode.depth_test && d <= depth[at] {
                        continue;
                    }
                    color[at] = f.packed(color[at], mode.blend, &encoder, encoding);
                    if mode.depth_write {
                        depth[at] = d;
                    }
                    stats.fragments_written += 1;
                }
            }
            stats
        })
        .reduce(FrameStats::default, |mut a, b| {
            a += b;
            a
        })
}

#[cfg(test)]
mod tests;
