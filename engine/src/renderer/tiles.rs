//! The tile loop: every triangle binned to one tile, in the frame's draw order, into that
//! tile's memory, with or without the visibility pre-pass (off unless
//! `Renderer::set_visibility_prepass` turns it on: measured slower on the showcase's tour).
//! In one pass, a cluster of triangles (`front::Cluster`) wholly behind the depth stored in
//! the tile is skipped unread.
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
use crate::front::{Chunk, Cluster};
use crate::light::Lighting;
use crate::material::AlphaMode;
use crate::raster::{raster_tri, DepthToView, Pass};
use crate::setup::{Tri, CLIPPED};
use crate::shade::GeneralShader;
use crate::state::DrawInfo;
use crate::stats::{DrawCost, FrameStats};
use crate::target::TILE;
use crate::tile::{TileBuf, BLOCK, BLOCKS};
use glam::Vec3;
use std::cmp::Ordering;
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
    /// Whether hidden clusters are skipped (`Renderer::set_cluster_occlusion`).
    pub(super) occlusion: bool,
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
    /// chunk, so in submission order. Without the pre-pass (and with `occlusion` on), a
    /// cluster of triangles lying wholly behind the depth stored in every block it
    /// overlaps is skipped whole ([`TileFrame::hidden`]).
    pub(super) fn raster(
        &self,
        buf: &mut TileBuf,
        tile: usize,
        ox: i32,
        oy: i32,
        counters: &mut Counters<'_>,
    ) {
        if !self.prepass {
            let cull = self.occlusion.then_some((ox, oy));
            let (clusters, tris) = self.each(buf, tile, cull, |buf, chunk, tri, _| {
                self.draw(buf, ox, oy, chunk, tri, Pass::Full, counters);
            });
            counters.stats.clusters_occluded += clusters;
            counters.stats.triangles_occluded += tris;
            return;
        }
        buf.clear_ids();
        self.each(buf, tile, None, |buf, chunk, tri, id| {
            let pass = match self.infos[tri.draw() as usize].mode.alpha {
                AlphaMode::Opaque => Pass::Depth(id),
                AlphaMode::Blend => return,
                AlphaMode::Mask { .. } | AlphaMode::Dither => Pass::Masked(id),
            };
            self.draw(buf, ox, oy, chunk, tri, pass, counters);
        });
        self.each(buf, tile, None, |buf, chunk, tri, id| {
            let pass = match self.infos[tri.draw() as usize].mode.alpha {
                AlphaMode::Opaque => Pass::Visible(id),
                AlphaMode::Blend => Pass::Full,
                AlphaMode::Mask { .. } | AlphaMode::Dither => return,
            };
            self.draw(buf, ox, oy, chunk, tri, pass, counters);
        });
    }

    /// Calls `f` with every triangle binned to `tile` and its place in the tile's list, in
    /// order, cluster by cluster of each chunk. With `cull` (the tile's top-left pixel), a
    /// cluster hidden in the tile is skipped, its triangles neither read nor drawn; returns
    /// how many clusters and (triangle, tile) pairs were skipped. Scattered triangles and
    /// their vertices are cache misses: two cursors run ahead of the one handed out, asking
    /// for the triangles, then for their vertices.
    #[inline(always)]
    fn each<'s>(
        &'s self,
        buf: &mut TileBuf,
        tile: usize,
        cull: Option<(i32, i32)>,
        mut f: impl FnMut(&mut TileBuf, &'s Chunk, &'s Tri, u32),
    ) -> (u64, u64) {
        let (mut id, mut skipped) = (0u32, (0u64, 0u64));
        for chunk in self.chunks {
            let list = chunk.bins.tile(tile);
            let clusters = &chunk.clusters[..];
            let (mut c, mut i) = (0usize, 0usize);
            while i < list.len() {
                // The part of the list in the cluster holding its next triangle.
                while clusters.get(c + 1).is_some_and(|n| n.first <= list[i]) {
                    c += 1;
                }
                let end = clusters.get(c + 1).map_or(u32::MAX, |n| n.first);
                let j = i + list[i..].partition_point(|&k| k < end);
                if let (Some(origin), Some(cl)) = (cull, clusters.get(c)) {
                    if self.hidden(buf, cl, origin) {
                        skipped.0 += 1;
                        skipped.1 += (j - i) as u64;
                        id += (j - i) as u32;
                        i = j;
                        continue;
                    }
                }
                for n in i..j {
                    if let Some(t) = list.get(n + 2 * PREFETCH_AHEAD) {
                        if let Some(t) = chunk.tris.get(*t as usize) {
                            crate::simd::prefetch(t);
                        }
                    }
                    if let Some(t) = list.get(n + PREFETCH_AHEAD) {
                        self.prefetch_varyings(chunk, chunk.tris.get(*t as usize));
                    }
                    if let Some(tri) = chunk.tris.get(list[n] as usize) {
                        f(buf, chunk, tri, id);
                    }
                    id += 1;
                }
                i = j;
            }
        }
        skipped
    }

    /// Asks for the vertex varyings `tri` reads.
    #[inline(always)]
    fn prefetch_varyings(&self, chunk: &Chunk, tri: Option<&Tri>) {
        let Some(t) = tri else { return };
        if self.infos[t.draw() as usize].layout != Layout::None {
            let src = self.varyings(chunk, t);
            for o in t.vary {
                if let Some(x) = src.get(o as usize) {
                    crate::simd::prefetch(x);
                }
            }
        }
    }

    /// Whether cluster `cl` lies wholly behind the depth stored in the tile with top-left
    /// pixel `(ox, oy)`: its draw tests depth, and in every 8 x 8 block its box overlaps
    /// there, its nearest depth (with the walk's safety margin) is no nearer than the
    /// block's farthest. Then none of its fragments could pass the (strict) depth test
    /// there, and as stored depth only moves nearer while the cluster is drawn, skipping
    /// it leaves every pixel as drawing it would.
    #[inline]
    fn hidden(&self, buf: &mut TileBuf, cl: &Cluster, (ox, oy): (i32, i32)) -> bool {
        if !self
            .infos
            .get(cl.draw as usize)
            .is_some_and(|i| i.mode.depth_test)
        {
            return false;
        }
        let x0 = (cl.bbox[0] as i32).max(ox) - ox;
        let y0 = (cl.bbox[1] as i32).max(oy) - oy;
        let x1 = (cl.bbox[2] as i32).min(ox + TILE as i32 - 1) - ox;
        let y1 = (cl.bbox[3] as i32).min(oy + TILE as i32 - 1) - oy;
        if x0 > x1 || y0 > y1 {
            return false;
        }
        let near = cl.near + cl.near.abs() * 1e-5 + 1e-7;
        for by in (y0 / BLOCK) as usize..=(y1 / BLOCK) as usize {
            for bx in (x0 / BLOCK) as usize..=(x1 / BLOCK) as usize {
                // Not hidden unless `near <= far` (NaN on either side: not hidden).
                let far = buf.far(by * BLOCKS + bx);
                if !matches!(
                    near.partial_cmp(&far),
                    Some(Ordering::Less | Ordering::Equal)
                ) {
                    return false;
                }
            }
        }
        true
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
