//! Raster stage: one triangle into one tile's working buffers.
//!
//! Coverage is exact: edge functions on fixed-point vertices, evaluated at pixel centres in
//! integers, with the top-left fill rule (a pixel centre exactly on an edge belongs to the
//! triangle only if the edge is a top or a left edge), so triangles sharing an edge cover
//! each of its pixels exactly once. The tile is walked in 8 x 8 blocks: a block wholly
//! outside an edge is skipped, a block wholly inside all three needs no per-pixel edge test,
//! and the rest are tested 8 lanes at a time. Inside a partial block the test is
//! `i * A + j * B >= T` in `i32`, where the threshold `T` comes from the exact `i64` edge
//! value at the block's first pixel, so no precision is lost.
//!
//! Covered rows are depth-tested 8 lanes at a time; a triangle's rows in a block are held
//! while their covered lanes add up to 8 at most, and held rows are shaded in one vector
//! (`Rows::pack`: each row's covered pixels in the next lanes, in order), so small
//! triangles fill more of the shader's lanes; each lane's inputs are those of its own
//! pixel, and only the texture level of detail is shared by the pack.
//!
//! Depth is reversed (greater is nearer) and tested before shading. The working buffers
//! hold linear premultiplied colour in `f32`, so blending is exact and encoding to bytes
//! happens once per pixel per frame, when the tile is resolved.
//!
//! A triangle is drawn in one of the [`Pass`]es: the one-pass path (test, shade, write), or
//! one of the three parts of the tile's visibility pre-pass (see `renderer`): opaque
//! triangles first write only depth and their id, alpha-tested ones shade as usual and
//! leave their id where they wrote, then opaque triangles shade only the pixels that kept
//! their id. The walk, the depth planes and the shading are the same in every pass, so a
//! pixel comes out as the one-pass path would have made it.

use crate::setup::Tri;
use crate::shade::{eval, FragShader, Lane, Row, LANES};
use crate::simd::{F8, I8, M8};
use crate::space::{edges_of, Edge, ONE, SMALL};
use crate::state::PixelMode;
use std::ops::Add;

use crate::stats::FrameStats;
use crate::target::TILE;
use crate::tile::{TileBuf, BLOCK, BLOCKS, BLOCK_PIXELS};

mod depth;
pub use depth::DepthToView;

/// A small triangle's coverage mask ([`Tri::cover`], bit `SMALL * j + i` for pixel `(rx + i,
/// ry + j)`) moved to the frame of the block whose corner is `(rx - sx, ry - sy)`, where
/// `|sx|, |sy| < SMALL`: bit `SMALL * j + i` is then the block's pixel `(i, j)`, and pixels
/// outside the block are dropped.
#[inline(always)]
fn block_mask(cover: u64, sx: i32, sy: i32) -> u64 {
    const ROWS: u64 = u64::MAX / 0xff; // 0x0101...01: one bit at the start of each row
    let (l, r) = (sx.max(0) as u32, (-sx).max(0) as u32);
    // Each row's bits that stay inside it, moved right by `r` or left by `l`.
    let m = ((cover >> r) & (ROWS * (0xff >> r))) << l & (ROWS * ((0xff << l) & 0xff));
    let (u, d) = (sy.max(0) as u32, (-sy).max(0) as u32);
    (m >> (SMALL as u32 * d)) << (SMALL as u32 * u)
}

/// Classifies the rectangle of pixel centres `[px0, px1] x [py0, py1]` against an edge:
/// `Some(true)` wholly inside, `Some(false)` wholly outside, `None` crossing.
#[inline]
fn classify(ed: &Edge, px0: i32, py0: i32, px1: i32, py1: i32) -> Option<bool> {
    let x = |p: i32| p as i64 * ONE + ONE / 2;
    let (xl, xh) = if ed.a >= 0 {
        (x(px0), x(px1))
    } else {
        (x(px1), x(px0))
    };
    let (yl, yh) = if ed.b >= 0 {
        (x(py0), x(py1))
    } else {
        (x(py1), x(py0))
    };
    let lo = ed.a * xl + ed.b * yl + ed.c;
    let hi = ed.a * xh + ed.b * yh + ed.c;
    if hi < ed.bias {
        Some(false)
    } else if lo >= ed.bias {
        Some(true)
    } else {
        None
    }
}

/// How a triangle is drawn: in one pass, or as a part of the tile's visibility pre-pass.
/// The ids are the triangle's place in the tile's list, never `tile::NO_ID`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pass {
    /// Depth test, shade, write (no pre-pass).
    Full,
    /// Pre-pass, opaque: depth test, then write depth and the id; nothing is shaded.
    Depth(u32),
    /// Pre-pass, alpha-tested: as [`Pass::Full`], and the lanes written take the id.
    Masked(u32),
    /// After the pre-pass, opaque: shade and write the pixels that still hold the id (the
    /// triangle is the nearest there), with no depth test and no depth update needed.
    Visible(u32),
}

/// Rasterizes `tri` into the tile whose top-left pixel is `(ox, oy)`. For walked triangles
/// the shader prepares the triangle (reads its vertices' varyings from `vary`) only once a
/// fragment survives the depth test, so hidden ones never touch their vertex data; small
/// ones prepare up front (the renderer prefetches their vertices).
#[allow(clippy::too_many_arguments)] // reason: the stage's inputs, passed through as they are
pub fn raster_tri<S: FragShader>(
    buf: &mut TileBuf,
    ox: i32,
    oy: i32,
    tri: &Tri,
    shader: &S,
    vary: &[f32],
    mode: &PixelMode,
    soft: &DepthToView,
    stats: &mut FrameStats,
    pass: Pass,
) {
    debug_assert!(
        pass == Pass::Full || !buf.vis.is_empty(),
        "a pre-pass needs the tile's ids"
    );
    let x0 = (tri.bbox[0] as i32).max(ox);
    let y0 = (tri.bbox[1] as i32).max(oy);
    let x1 = (tri.bbox[2] as i32).min(ox + TILE as i32 - 1);
    let y1 = (tri.bbox[3] as i32).min(oy + TILE as i32 - 1);
    if x0 > x1 || y0 > y1 {
        return;
    }
    let mut rows = Rows {
        ox,
        oy,
        tri,
        shader,
        vary,
        mode,
        soft,
        stats,
        pass,
    };
    match tri.vertices() {
        None => rows.small(buf, [x0, y0, x1, y1]),
        Some((x, y)) => rows.walk(buf, &edges_of(&x, &y), [x0, y0, x1, y1]),
    }
}

/// One triangle's pass over one tile: what every covered row needs.
struct Rows<'a, S: FragShader> {
    ox: i32,
    oy: i32,
    tri: &'a Tri,
    shader: &'a S,
    vary: &'a [f32],
    mode: &'a PixelMode,
    soft: &'a DepthToView,
    /// The tile's counters, counted into directly: a per-triangle copy added at the end
    /// was reloaded as one wide vector that waited on the row kernel's scalar stores.
    stats: &'a mut FrameStats,
    pass: Pass,
}

impl<S: FragShader> Rows<'_, S> {
    /// Index of the block whose top-left pixel is `(bx, by)`.
    #[inline(always)]
    fn block(&self, bx: i32, by: i32) -> usize {
        ((by - self.oy) as usize / LANES) * BLOCKS + (bx - self.ox) as usize / LANES
    }

    /// Small triangles: coverage comes from the set-up mask, moved into the frame of each
    /// block the triangle overlaps (at most 2 x 2) with a few shifts, then drawn row by
    /// non-empty row. No edge work; a block where the triangle lies wholly behind the farthest
    /// depth stored is skipped ([`Rows::hidden_small`]); the blocks' farthest depth is marked
    /// stale rather than recomputed after a write.
    #[inline]
    fn small(&mut self, buf: &mut TileBuf, [x0, y0, x1, y1]: [i32; 4]) {
        const _: () = assert!(SMALL == BLOCK, "a mask row is a block row");
        let (rx, ry) = (self.tri.bbox[0] as i32, self.tri.bbox[1] as i32);
        let cover = self.tri.cover();
        let (bx0, by0) = (x0 & !(BLOCK - 1), y0 & !(BLOCK - 1));
        let (bx1, by1) = (x1 & !(BLOCK - 1), y1 & !(BLOCK - 1));
        // The (at most 2 x 2) blocks the triangle overlaps, each with its pixels, emptied
        // where the triangle lies wholly behind the block's farthest depth.
        let mut blocks = [(0, 0, 0u64); 4];
        let mut n = 0;
        let (ys, xs) = ([by0, by1], [bx0, bx1]);
        for &by in &ys[..1 + (by1 != by0) as usize] {
            for &bx in &xs[..1 + (bx1 != bx0) as usize] {
                let mut m = block_mask(cover, rx - bx, ry - by);
                let block = self.block(bx, by);
                if m != 0 && self.hidden_small(buf, block, [bx, by], [x0, y0, x1, y1]) {
                    self.stats.blocks_hiz_rejected += 1;
                    m = 0;
                }
                if m != 0 {
                    blocks[n] = (block, bx, m);
                    n += 1;
                }
            }
        }
        if n == 0 {
            return;
        }
        // Prepared up front in one pass: a small triangle with a block left to draw almost
        // always has a visible pixel, and a known `Some` keeps the row loop free of the
        // check. The pre-pass's depth writes shade nothing, and after them a small
        // triangle is often hidden: there it is prepared once a pixel is shaded.
        let mut prepared = match self.pass {
            Pass::Full | Pass::Masked(_) => Some(self.shader.prepare(self.tri, self.vary)),
            Pass::Depth(_) | Pass::Visible(_) => None,
        };
        for &(block, bx, mut m) in &blocks[..n] {
            buf.touch(block);
            self.stats.blocks_partial += 1;
            let mut wrote = false;
            let mut held = Held::default();
            while m != 0 {
                let j = m.trailing_zeros() / SMALL as u32;
                let bits = (m >> (SMALL as u32 * j)) as u32 & ((1 << SMALL) - 1);
                m &= !(((1u64 << SMALL) - 1) << (SMALL as u32 * j));
                let r = (j as i32, bits);
                wrote |= self.feed(buf, block, bx, r, &mut held, &mut prepared);
            }
            wrote |= self.flush(buf, block, bx, &mut held, &mut prepared);
            if wrote && self.mode.writes_depth() {
                buf.mark_far_stale(block);
            }
        }
    }

    /// Whether a small triangle's part in the block at `(bx, by)` (clipped to `[x0, y0, x1,
    /// y1]`) lies wholly behind the farthest depth stored there (the walk's hierarchical
    /// test, on the triangle's bounding box within the block): then no pixel of it could
    /// pass the depth test, and the block's rows are neither tested nor shaded.
    #[inline(always)]
    fn hidden_small(
        &self,
        buf: &mut TileBuf,
        block: usize,
        [bx, by]: [i32; 2],
        [x0, y0, x1, y1]: [i32; 4],
    ) -> bool {
        if !self.mode.depth_test {
            return false;
        }
        let (z, rx, ry) = (
            &self.tri.z,
            self.tri.bbox[0] as i32,
            self.tri.bbox[1] as i32,
        );
        let (xa, xb) = (
            (x0.max(bx) - rx) as f32,
            (x1.min(bx + BLOCK - 1) - rx) as f32,
        );
        let (ya, yb) = (
            (y0.max(by) - ry) as f32,
            (y1.min(by + BLOCK - 1) - ry) as f32,
        );
        let near = z.c + (z.dx * xa).max(z.dx * xb) + (z.dy * ya).max(z.dy * yb);
        let near = near + near.abs() * 1e-5 + 1e-7;
        near <= buf.far(block)
    }

    /// Other triangles: the 8 x 8 block walk with hierarchical rejection and acceptance.
    #[inline]
    fn walk(&mut self, buf: &mut TileBuf, e: &[Edge; 3], [x0, y0, x1, y1]: [i32; 4]) {
        let tri = self.tri;
        // Whole-rectangle test first: big triangles often cover the tile's part entirely.
        // A rectangle within one block is classified by the block loop anyway.
        let mut tile_inside = [false; 3];
        if x0 >> 3 != x1 >> 3 || y0 >> 3 != y1 >> 3 {
            for i in 0..3 {
                match classify(&e[i], x0, y0, x1, y1) {
                    Some(false) => return,
                    Some(true) => tile_inside[i] = true,
                    None => {}
                }
            }
        }
        let all_inside = tile_inside.iter().all(|&b| b);
        let mut prepared = None;
        let (rx, ry) = (tri.bbox[0] as i32, tri.bbox[1] as i32);
        let mut by = y0 & !(BLOCK - 1);
        while by <= y1 {
            let mut bx = x0 & !(BLOCK - 1);
            while bx <= x1 {
                let lx0 = (x0 - bx).max(0);
                let lx1 = (x1 - bx).min(BLOCK - 1);
                let rows = (y0.max(by), y1.min(by + BLOCK - 1));
                // Classify the block against the edges not already known to contain it.
                let mut full = true;
                let mut outside = false;
                let mut thr = [i32::MIN + 1; 3];
                let mut ea = [0i32; 3];
                let mut eb = [0i32; 3];
                if !all_inside {
                    let px = bx as i64 * ONE + ONE / 2;
                    let py = by as i64 * ONE + ONE / 2;
                    for i in 0..3 {
                        if tile_inside[i] {
                            continue;
                        }
                        let ed = &e[i];
                        match classify(ed, bx + lx0, rows.0, bx + lx1, rows.1) {
                            Some(false) => {
                                outside = true;
                                break;
                            }
                            Some(true) => continue,
                            None => {}
                        }
                        full = false;
                        // i * a + j * b >= ceil((bias - v) / ONE), v = E at the block's
                        // first centre
                        let v = ed.a * px + ed.b * py + ed.c;
                        let t = -(v - ed.bias).div_euclid(ONE);
                        thr[i] = t.clamp(i32::MIN as i64 + 1, i32::MAX as i64) as i32;
                        ea[i] = ed.a as i32;
                        eb[i] = ed.b as i32;
                    }
                }
                if outside {
                    bx += BLOCK;
                    continue;
                }
                // Hierarchical depth: the nearest the triangle gets in this block, against
                // the farthest depth stored there. A small relative margin keeps the test
                // conservative under f32 rounding of the per-pixel planes.
                let block = self.block(bx, by);
                if self.mode.depth_test {
                    let z = &tri.z;
                    let near = z.c
                        + z.dx * (bx - rx) as f32
                        + z.dy * (by - ry) as f32
                        + (z.dx.max(0.0) + z.dy.max(0.0)) * (BLOCK - 1) as f32;
                    let near = near + near.abs() * 1e-5 + 1e-7;
                    if near <= buf.far(block) {
                        self.stats.blocks_hiz_rejected += 1;
                        bx += BLOCK;
                        continue;
                    }
                }
                let mut wrote = false;
                buf.touch(block);
                if full {
                    self.stats.blocks_full += 1;
                } else {
                    self.stats.blocks_partial += 1;
                }
                let range = I8::lane_range(lx0, lx1);
                let ea_l: [I8; 3] = std::array::from_fn(|i| I8::ramp_times(ea[i]));
                let mut held = Held::default();
                for y in rows.0..=rows.1 {
                    let j = y - by;
                    let cov: M8 = if full {
                        range
                    } else {
                        let inside =
                            |i: usize| ea_l[i].add(I8::splat(j * eb[i] - thr[i])).non_negative();
                        range.and(inside(0)).and(inside(1)).and(inside(2))
                    };
                    let r = (j, cov.bits());
                    wrote |= self.feed(buf, block, bx, r, &mut held, &mut prepared);
                }
                wrote |= self.flush(buf, block, bx, &mut held, &mut prepared);
                if wrote && self.mode.writes_depth() {
                    buf.update_block_far(block);
                }
                bx += BLOCK;
            }
            by += BLOCK;
        }
    }

    /// Takes row `j` of the block at `(bx, _)` with covered lanes `cov`: held with the rows
    /// before it while their covered lanes add up to 8 at most, the held rows drawn first
    /// when this one would pass 8 ([`Rows::flush`]). Which rows are packed depends on
    /// coverage only, never on depth. The caller flushes what is still held at the block's
    /// end. Returns whether depth may have changed.
    #[inline(always)]
    fn feed(
        &mut self,
        buf: &mut TileBuf,
        block: usize,
        bx: i32,
        (j, cov): (i32, u32),
        held: &mut Held,
        prepared: &mut Option<S::Prepared>,
    ) -> bool {
        if cov == 0 {
            return false;
        }
        // The pre-pass's depth part shades nothing: packing would save nothing there.
        if matches!(self.pass, Pass::Depth(_)) {
            return self.row(buf, block, bx, j, cov, prepared);
        }
        let lanes = cov.count_ones();
        let mut wrote = false;
        if held.lanes + lanes > LANES as u32 {
            wrote = self.flush(buf, block, bx, held, prepared);
        }
        held.rows[held.n] = (j, cov);
        held.n += 1;
        held.lanes += lanes;
        wrote
    }

    /// Draws the rows `held` (one alone, more as a pack) and empties it; whether depth may
    /// have changed.
    #[inline(always)]
    fn flush(
        &mut self,
        buf: &mut TileBuf,
        block: usize,
        bx: i32,
        held: &mut Held,
        prepared: &mut Option<S::Prepared>,
    ) -> bool {
        let h = std::mem::take(held);
        match h.n {
            0 => false,
            1 => self.row(buf, block, bx, h.rows[0].0, h.rows[0].1, prepared),
            n => self.pack(buf, block, bx, &h.rows[..n], prepared),
        }
    }

    /// The depth (or pre-pass id) test of row `j`'s covered lanes `cov`, plane depth `z`:
    /// the lanes that pass.
    #[inline(always)]
    fn test(&mut self, buf: &TileBuf, base: usize, z: &Lane, cov: M8) -> M8 {
        if let Pass::Visible(id) = self.pass {
            // Tested in the pre-pass already: the pixels that kept this triangle's id.
            return cov.and(I8::load_u32(&buf.vis[base..]).eq(I8::splat(id as i32)));
        }
        self.stats.fragments_tested += cov.bits().count_ones() as u64;
        let mut m = if self.mode.depth_test {
            cov.and(z.gt(F8::load(&buf.depth[base..])))
        } else {
            cov
        };
        if self.mode.peel {
            // Reversed depth: strictly behind is strictly smaller.
            m = m.and(F8::load(&buf.peel[base..]).gt(*z));
        }
        m
    }

    /// Depth-tests, shades and writes the covered lanes `cov` of row `j` of the block at
    /// `(bx, _)`, as its [`Pass`] says; whether depth may have changed.
    // Not inlined: measured, the loops around it keep their state in registers then (grid
    // 1M at 1920x1080, one thread: raster stage 62 -> 57 ms).
    #[inline(never)]
    fn row(
        &mut self,
        buf: &mut TileBuf,
        block: usize,
        bx: i32,
        j: i32,
        cov: u32,
        prepared: &mut Option<S::Prepared>,
    ) -> bool {
        let covered = cov.count_ones();
        if covered == 0 {
            return false;
        }
        let cov = M8::from_bits(cov);
        let tri = self.tri;
        let (rx, ry) = (tri.bbox[0] as i32, tri.bbox[1] as i32);
        let by = (block / BLOCKS * LANES) as i32 + self.oy;
        let row = Row::whole((bx - rx) as f32, (by + j - ry) as f32, cov.bits());
        let base = block * BLOCK_PIXELS + j as usize * LANES;
        let z = eval(&tri.z, &row);
        let m = self.test(buf, base, &z, cov);
        let passed = m.bits().count_ones();
        if passed == 0 {
            return false;
        }
        if let Pass::Depth(id) = self.pass {
            z.blend_into(m, &mut buf.depth[base..]);
            set_ids(&mut buf.vis[base..base + LANES], m.bits(), id);
            return true;
        }
        let (shader, vary) = (self.shader, self.vary);
        let prepared = prepared.get_or_insert_with(|| shader.prepare(tri, vary));
        let behind = shader.behind(prepared, tri, &row, m.bits());
        let (m, z) = match &behind {
            Some(b) => self.retest(buf, base, m.and(M8::from_bits(b.keep)), &z, b.depth),
            None => (m, z),
        };
        let passed = m.bits().count_ones();
        if passed == 0 {
            return false;
        }
        self.stats.fragments_shaded += passed as u64;
        self.stats.rows_shaded += 1;
        let mut out = [F8::splat(0.0); 4];
        match &behind {
            Some(b) => shader.shade_behind(prepared, tri, &row, m.bits(), b, &mut out),
            None => shader.shade(prepared, tri, &row, m.bits(), &mut out),
        }
        self.write(buf, base, m, &z, &out)
    }

    /// A nailboard's lanes `m` of the row at `base` (plane depth `z`, which passed the
    /// test) moved `behind` view units back: tested again at their own depth (as
    /// [`Rows::test`] does, not counted again), and that depth.
    #[inline(always)]
    fn retest(&self, buf: &TileBuf, base: usize, m: M8, z: &Lane, behind: Lane) -> (M8, Lane) {
        let z = self.soft.behind(*z, behind);
        let mut m = m;
        if self.mode.depth_test {
            m = m.and(z.gt(F8::load(&buf.depth[base..])));
        }
        if self.mode.peel {
            m = m.and(F8::load(&buf.peel[base..]).gt(z));
        }
        (m, z)
    }

    /// Rows `(j, covered lanes)` of the block at `(bx, _)`, 8 covered lanes at most in all:
    /// depth-tested row by row as [`Rows::row`] does, then shaded in one vector (each row's
    /// covered pixels in the next lanes, in order), the texture level of detail shared by
    /// the pack's covered lanes (GPUs share one per 2 x 2 quad), and written row by row.
    /// Every other input of a lane is the same as in its row alone.
    #[inline(never)]
    fn pack(
        &mut self,
        buf: &mut TileBuf,
        block: usize,
        bx: i32,
        rows: &[(i32, u32)],
        prepared: &mut Option<S::Prepared>,
    ) -> bool {
        let tri = self.tri;
        let (rx, ry) = (tri.bbox[0] as i32, tri.bbox[1] as i32);
        let by = (block / BLOCKS * LANES) as i32 + self.oy;
        let fx = (bx - rx) as f32;
        // Each row's depth, its lanes that pass, and where its pixels are in the pack: lane
        // `back[k][x]` holds pixel `x` of row `k` (the lanes of uncovered pixels are not
        // written, whatever they hold).
        let (mut xs, mut ys) = ([0.0f32; LANES], [0.0f32; LANES]);
        let mut z = [F8::splat(0.0); LANES];
        let mut passed = [0u32; LANES];
        let mut back = [[0u32; LANES]; LANES];
        // The pack's lanes whose pixels passed in their rows.
        let (mut n, mut mask) = (0, 0u32);
        for (k, &(j, cov)) in rows.iter().enumerate() {
            let fy = (by + j - ry) as f32;
            let base = block * BLOCK_PIXELS + j as usize * LANES;
            z[k] = eval(&tri.z, &Row::whole(fx, fy, cov));
            passed[k] = self.test(buf, base, &z[k], M8::from_bits(cov)).bits();
            let mut bits = cov;
            while bits != 0 {
                let x = bits.trailing_zeros() as usize;
                (xs[n], ys[n], back[k][x]) = (x as f32, fy, n as u32);
                mask |= (passed[k] >> x & 1) << n;
                n += 1;
                bits &= bits - 1;
            }
        }
        if mask == 0 {
            return false;
        }
        let row = Row {
            fx,
            ys: F8::from_array(ys),
            xs: F8::from_array(xs),
            covered: (1u32 << n) - 1,
        };
        let (shader, vary) = (self.shader, self.vary);
        let prepared = prepared.get_or_insert_with(|| shader.prepare(tri, vary));
        let behind = shader.behind(prepared, tri, &row, mask);
        let mut m = [M8::from_bits(0); LANES];
        for k in 0..rows.len() {
            m[k] = M8::from_bits(passed[k]);
        }
        if let Some(b) = &behind {
            // Each row tested again at its moved depth: the pack's lanes back in the row's
            // frame (as the depth is permuted), and the pack's lanes that still pass.
            mask = 0;
            for (k, &(j, cov)) in rows.iter().enumerate() {
                let mut keep = 0;
                for x in 0..LANES {
                    keep |= (cov >> x & b.keep >> back[k][x] & 1) << x;
                }
                let base = block * BLOCK_PIXELS + j as usize * LANES;
                let depth = b.depth.permute(back[k]);
                (m[k], z[k]) = self.retest(buf, base, m[k].and(M8::from_bits(keep)), &z[k], depth);
                let bits = m[k].bits();
                for x in 0..LANES {
                    mask |= (bits >> x & 1) << back[k][x];
                }
            }
        }
        if mask == 0 {
            return false;
        }
        self.stats.fragments_shaded += mask.count_ones() as u64;
        self.stats.rows_shaded += 1;
        self.stats.rows_paired += 1;
        let mut out = [F8::splat(0.0); 4];
        match &behind {
            Some(b) => shader.shade_behind(prepared, tri, &row, mask, b, &mut out),
            None => shader.shade(prepared, tri, &row, mask, &mut out),
        }
        let mut wrote = false;
        for (k, &(j, _)) in rows.iter().enumerate() {
            if m[k].bits() != 0 {
                let base = block * BLOCK_PIXELS + j as usize * LANES;
                let b = back[k];
                let row_out = [
                    out[0].permute(b),
                    out[1].permute(b),
                    out[2].permute(b),
                    out[3].permute(b),
                ];
                wrote |= self.write(buf, base, m[k], &z[k], &row_out);
            }
        }
        wrote
    }

    /// Writes the shaded lanes `m` of the row at `base` as the pass says; whether depth
    /// may have changed.
    #[inline(always)]
    fn write(&mut self, buf: &mut TileBuf, base: usize, m: M8, z: &Lane, out: &[Lane; 4]) -> bool {
        let written = write_row(buf, base, m, z, out, self.mode, self.soft);
        self.stats.fragments_written += written.bits().count_ones() as u64;
        match self.pass {
            Pass::Masked(id) => set_ids(&mut buf.vis[base..base + LANES], written.bits(), id),
            // The depth is the pre-pass's, unchanged.
            Pass::Visible(_) => return false,
            _ => {}
        }
        true
    }
}

/// A block's rows held to be shaded together: each row's index and covered lanes, in
/// order, `lanes` covered in all (8 at most).
#[derive(Clone, Copy, Debug, Default)]
struct Held {
    rows: [(i32, u32); LANES],
    n: usize,
    lanes: u32,
}

/// Sets the ids of the lanes in `bits` of one row.
#[inline(always)]
fn set_ids(ids: &mut [u32], bits: u32, id: u32) {
    for (l, v) in ids.iter_mut().enumerate() {
        if bits >> l & 1 != 0 {
            *v = id;
        }
    }
}

mod write;
use write::write_row;

#[cfg(test)]
mod nailboard_tests;
#[cfg(test)]
mod parallax_tests;
#[cfg(test)]
mod tests;
