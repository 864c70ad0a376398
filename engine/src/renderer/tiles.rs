//! The tile loop: every triangle binned to one tile, in the frame's draw order, into that
//! tile's memory, with or without the visibility pre-pass (off unless
//! `Renderer::set_visibility_prepass` turns it on: measured slower on the showcase's tour).
//!
//! The pre-pass, for frames whose opaque and alpha-tested draws all test and write depth
//! and come before every blended draw (what `Renderer::order_draws` makes of any frame
//! without an opaque draw lacking depth test, and without depth peeling):
//! 1. the opaque and alpha-tested triangles in order: opaque ones test and write depth and
//!    leave their place in the list as an id per pixel, unshaded; alpha-tested ones are
//!    drawn as in one pass (shaded, their alpha tested, written) and leave their id where
//!    they wrote;
//! 2. the opaque triangles again, each shading only the pixels that kept its id, then the
//!    blended triangles in order as in one pass.
//!
//! The depth test runs in the same order on the same depths as in one pass, so the id a
//! pixel keeps is that of the one-pass path's last writer there, and every colour read
//! (alpha-tested writes over opaque ones, blending over the opaque result) is the one the
//! one-pass path reads: the pixels are the same, and an opaque pixel is shaded once instead
//! of once per nearer surface drawn after it.

use super::{Kind, Layout};
use crate::front::Chunk;
use crate::light::Lighting;
use crate::material::AlphaMode;
use crate::raster::{raster_tri, DepthToView, Pass};
use crate::setup::{Tri, CLIPPED};
use crate::shade::GeneralShader;
use crate::state::DrawInfo;
use crate::stats::{DrawCost, FrameStats};
use crate::tile::TileBuf;
use glam::Vec3;
use std::time::Instant;

/// How many triangles ahead the tile loop prefetches vertex varyings.
const PREFETCH_AHEAD: usize = 4;

/// What the raster stage reads for every tile of a frame.
pub(super) struct TileFrame<'f, 'a> {
    pub(super) chunks: &'f [Chunk],
    pub(super) infos: &'f [DrawInfo<'a>],
    pub(super) vary: &'f [f32],
    pub(super) lighting: &'f Lighting,
    /// `shade::light_dirs` of `lighting`.
    pub(super) light_dirs: &'f [Vec3],
    pub(super) eye: Vec3,
    pub(super) soft: &'f DepthToView,
    /// Whether tiles draw with the visibility pre-pass (see the module doc).
    pub(super) prepass: bool,
    /// Whether each draw's cost is counted (`Renderer::set_draw_costs`).
    pub(super) costs: bool,
}

/// A worker's counters for one tile: the frame's totals, and each draw's cost when
/// counted (indexed by the draw's place in the frame's order).
pub(super) struct Counters<'c> {
    pub(super) stats: &'c mut FrameStats,
    pub(super) costs: &'c mut [DrawCost],
}

/// Whether a frame's draws, in drawing order, allow the visibility pre-pass: every opaque
/// or alpha-tested draw tests and writes depth without peeling, and none follows a blended
/// draw.
pub(super) fn prepass_allowed(infos: &[DrawInfo<'_>]) -> bool {
    let mut blended = false;
    for m in infos.iter().map(|i| &i.mode) {
        if m.alpha == AlphaMode::Blend {
            blended = true;
        } else if blended || !m.depth_test || !m.depth_write || m.peel {
            return false;
        }
    }
    true
}

impl TileFrame<'_, '_> {
    /// The varyings a triangle of `chunk` indexes.
    #[inline]
    fn varyings<'s>(&'s self, chunk: &'s Chunk, tri: &Tri) -> &'s [f32] {
        if tri.flags() & CLIPPED != 0 {
            &chunk.extra[..]
        } else {
            self.vary
        }
    }

    /// Rasterizes every triangle binned to `tile` (top-left pixel `(ox, oy)`), chunk by
    /// chunk, so in submission order.
    pub(super) fn raster(
        &self,
        buf: &mut TileBuf,
        tile: usize,
        ox: i32,
        oy: i32,
        counters: &mut Counters<'_>,
    ) {
        if !self.prepass {
            self.each(tile, |chunk, tri, _| {
                self.draw(buf, ox, oy, chunk, tri, Pass::Full, counters);
            });
            return;
        }
        buf.clear_ids();
        self.each(tile, |chunk, tri, id| {
            let pass = match self.infos[tri.draw() as usize].mode.alpha {
                AlphaMode::Opaque => Pass::Depth(id),
                AlphaMode::Blend => return,
                AlphaMode::Mask { .. } | AlphaMode::Dither => Pass::Masked(id),
            };
            self.draw(buf, ox, oy, chunk, tri, pass, counters);
        });
        self.each(tile, |chunk, tri, id| {
            let pass = match self.infos[tri.draw() as usize].mode.alpha {
                AlphaMode::Opaque => Pass::Visible(id),
                AlphaMode::Blend => Pass::Full,
                AlphaMode::Mask { .. } | AlphaMode::Dither => return,
            };
            self.draw(buf, ox, oy, chunk, tri, pass, counters);
        });
    }

    /// Calls `f` with every triangle binned to `tile` and its place in the tile's list, in
    /// order. Scattered triangles and their vertices are cache misses: two cursors run
    /// ahead of the one handed out, asking for the triangles, then for their vertices.
    #[inline(always)]
    fn each<'s>(&'s self, tile: usize, mut f: impl FnMut(&'s Chunk, &'s Tri, u32)) {
        let binned = || {
            self.chunks.iter().flat_map(move |chunk| {
                let list = chunk.bins.tile(tile);
                list.iter()
                    .filter_map(move |&k| Some((chunk, chunk.tris.get(k as usize)?)))
            })
        };
        let mut far = binned().skip(2 * PREFETCH_AHEAD);
        let mut near = binned().skip(PREFETCH_AHEAD);
        for (id, (chunk, tri)) in binned().enumerate() {
            if let Some((_, t)) = far.next() {
                crate::simd::prefetch(t);
            }
            if let Some((c, t)) = near.next() {
                if self.infos[t.draw() as usize].layout != Layout::None {
                    let src = self.varyings(c, t);
                    for o in t.vary {
                        if let Some(x) = src.get(o as usize) {
                            crate::simd::prefetch(x);
                        }
                    }
                }
            }
            f(chunk, tri, id as u32);
        }
    }

    /// Draws one triangle into the tile in `pass`, with its draw's shader, and counts its
    /// shaded fragments by kind (and by draw, when counted).
    #[allow(clippy::too_many_arguments)] // reason: the tile's state and the triangle
    #[inline(always)]
    fn draw(
        &self,
        buf: &mut TileBuf,
        ox: i32,
        oy: i32,
        chunk: &Chunk,
        tri: &Tri,
        pass: Pass,
        counters: &mut Counters<'_>,
    ) {
        let src = self.varyings(chunk, tri);
        let info = &self.infos[tri.draw() as usize];
        let (mode, soft) = (&info.mode, self.soft);
        let stats = &mut *counters.stats;
        let before = self.costs.then(|| (*stats, Instant::now()));
        let shaded = stats.fragments_shaded;
        match &info.kind {
            Kind::Const(s) => raster_tri(buf, ox, oy, tri, s, src, mode, soft, stats, pass),
            Kind::Color(s) => raster_tri(buf, ox, oy, tri, s, src, mode, soft, stats, pass),
            Kind::General => {
                let s = GeneralShader {
                    material: info.material,
                    lighting: self.lighting,
                    light_dirs: self.light_dirs,
                    eye: self.eye,
                };
                raster_tri(buf, ox, oy, tri, &s, src, mode, soft, stats, pass);
            }
        }
        let shaded = stats.fragments_shaded - shaded;
        if mode.alpha == AlphaMode::Blend {
            stats.fragments_shaded_blended += shaded;
        }
        if matches!(info.kind, Kind::General) {
            stats.fragments_shaded_general += shaded;
        }
        if let Some((b, start)) = before {
            if let Some(c) = counters.costs.get_mut(tri.draw() as usize) {
                *c += DrawCost {
                    fragments_tested: stats.fragments_tested - b.fragments_tested,
                    fragments_shaded: shaded,
                    rows_shaded: stats.rows_shaded - b.rows_shaded,
                    raster: start.elapsed(),
                };
            }
        }
    }
}

#[cfg(test)]
mod tests;
