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
//! Depth is reversed (greater is nearer) and tested before shading. The working buffers
//! hold linear premultiplied colour in `f32`, so blending is exact and encoding to bytes
//! happens once per pixel per frame, when the tile is resolved.

use crate::camera::Camera;
use crate::material::{AlphaMode, BlendMode};
use crate::setup::{Tri, ONE};
use crate::shade::{eval, FragShader, Lane, Row, LANES};
use crate::stats::FrameStats;
use crate::target::{TILE, TILE_PIXELS};

/// Block side for hierarchical rejection / acceptance (one lane row is one block row).
pub const BLOCK: i32 = LANES as i32;

/// One tile's working memory: linear premultiplied colour planes and reversed depth.
#[derive(Clone, Debug)]
pub struct TileBuf {
    pub color: [Vec<f32>; 4],
    pub depth: Vec<f32>,
}

impl Default for TileBuf {
    fn default() -> Self {
        TileBuf {
            color: std::array::from_fn(|_| vec![0.0; TILE_PIXELS]),
            depth: vec![0.0; TILE_PIXELS],
        }
    }
}

/// How fragments that survive shading reach the tile.
#[derive(Clone, Copy, Debug)]
pub struct PixelMode {
    pub depth_test: bool,
    pub depth_write: bool,
    pub alpha: AlphaMode,
    pub blend: BlendMode,
    /// Soft-particle fade distance (view units); 0 = off.
    pub soft: f32,
}

/// Converts reversed depth to view distance, for soft particles.
#[derive(Clone, Copy, Debug)]
pub struct DepthToView {
    camera: Camera,
}

impl DepthToView {
    pub fn new(camera: Camera) -> Self {
        DepthToView { camera }
    }
    #[inline]
    fn view(&self, d: f32) -> f32 {
        self.camera.view_depth_from_reversed(d)
    }
}

/// Edge function `E(X, Y) = a X + b Y + c` (fixed-point X, Y), positive inside, and the
/// value it must reach: 0 on top-left edges, 1 elsewhere.
#[derive(Clone, Copy, Debug)]
struct Edge {
    a: i64,
    b: i64,
    c: i64,
    bias: i64,
}

#[inline]
fn edges(t: &Tri) -> [Edge; 3] {
    std::array::from_fn(|i| {
        let (p, q) = ([1, 2, 0][i], [2, 0, 1][i]);
        let (xa, ya, xb, yb) = (t.x[p] as i64, t.y[p] as i64, t.x[q] as i64, t.y[q] as i64);
        let a = ya - yb;
        let b = xb - xa;
        // Gradient (a, b) points inside: a > 0 is a left edge, a == 0 && b > 0 a top edge.
        let top_left = a > 0 || (a == 0 && b > 0);
        Edge {
            a,
            b,
            c: xa * yb - ya * xb,
            bias: if top_left { 0 } else { 1 },
        }
    })
}

/// Rasterizes `tri` into the tile whose top-left pixel is `(ox, oy)`.
#[allow(clippy::too_many_lines)]
pub fn raster_tri<S: FragShader>(
    buf: &mut TileBuf,
    ox: i32,
    oy: i32,
    tri: &Tri,
    shader: &S,
    prepared: &S::Prepared,
    mode: &PixelMode,
    soft: &DepthToView,
    stats: &mut FrameStats,
) {
    let x0 = (tri.bbox[0] as i32).max(ox);
    let y0 = (tri.bbox[1] as i32).max(oy);
    let x1 = (tri.bbox[2] as i32).min(ox + TILE as i32 - 1);
    let y1 = (tri.bbox[3] as i32).min(oy + TILE as i32 - 1);
    if x0 > x1 || y0 > y1 {
        return;
    }
    let e = edges(tri);
    let (rx, ry) = (tri.bbox[0] as i32, tri.bbox[1] as i32);
    let mut out: [Lane; 4] = [[0.0; LANES]; 4];
    let mut by = y0 & !(BLOCK - 1);
    while by <= y1 {
        let mut bx = x0 & !(BLOCK - 1);
        while bx <= x1 {
            // Classify the block against each edge, exactly.
            let px = bx as i64 * ONE + ONE / 2;
            let py = by as i64 * ONE + ONE / 2;
            let span = ONE * (BLOCK as i64 - 1);
            let mut full = true;
            let mut outside = false;
            let mut thr = [0i32; 3];
            let mut ea = [0i32; 3];
            let mut eb = [0i32; 3];
            for i in 0..3 {
                let ed = e[i];
                let v = ed.a * px + ed.b * py + ed.c;
                let lo = v + span * (ed.a.min(0) + ed.b.min(0));
                let hi = v + span * (ed.a.max(0) + ed.b.max(0));
                if hi < ed.bias {
                    outside = true;
                    break;
                }
                if lo < ed.bias {
                    full = false;
                }
                // i*a + j*b >= ceil((bias - v) / ONE)
                let t = -(v - ed.bias).div_euclid(ONE);
                thr[i] = t.clamp(i32::MIN as i64 + 1, i32::MAX as i64) as i32;
                ea[i] = ed.a as i32;
                eb[i] = ed.b as i32;
            }
            if outside {
                bx += BLOCK;
                continue;
            }
            if full {
                stats.blocks_full += 1;
            } else {
                stats.blocks_partial += 1;
            }
            let lx0 = (x0 - bx).max(0);
            let lx1 = (x1 - bx).min(BLOCK - 1);
            let rows = (y0.max(by), y1.min(by + BLOCK - 1));
            for y in rows.0..=rows.1 {
                let j = y - by;
                let mut m = [false; LANES];
                if full {
                    for l in 0..LANES {
                        m[l] = l as i32 >= lx0 && l as i32 <= lx1;
                    }
                } else {
                    let k: [i32; 3] = std::array::from_fn(|i| j * eb[i]);
                    for l in 0..LANES {
                        let li = l as i32;
                        m[l] = li >= lx0
                            && li <= lx1
                            && li * ea[0] + k[0] >= thr[0]
                            && li * ea[1] + k[1] >= thr[1]
                            && li * ea[2] + k[2] >= thr[2];
                    }
                }
                let covered = m.iter().filter(|&&b| b).count() as u64;
                if covered == 0 {
                    continue;
                }
                stats.fragments_tested += covered;
                let row = Row {
                    fx: (bx - rx) as f32,
                    fy: (y - ry) as f32,
                };
                let base = ((y - oy) as usize) * TILE + (bx - ox) as usize;
                let z = eval(&tri.z, &row);
                let zbuf: &mut [f32; LANES] = (&mut buf.depth[base..base + LANES])
                    .try_into()
                    .expect("8 lanes");
                if mode.depth_test {
                    for l in 0..LANES {
                        m[l] &= z[l] > zbuf[l];
                    }
                }
                let passed = m.iter().filter(|&&b| b).count() as u64;
                if passed == 0 {
                    continue;
                }
                stats.fragments_shaded += passed;
                shader.shade(prepared, tri, &row, &mut out);
                write_row(buf, base, &mut m, &z, &out, mode, soft, stats);
            }
            bx += BLOCK;
        }
        by += BLOCK;
    }
}

#[inline]
fn write_row(
    buf: &mut TileBuf,
    base: usize,
    m: &mut [bool; LANES],
    z: &Lane,
    out: &[Lane; 4],
    mode: &PixelMode,
    soft: &DepthToView,
    stats: &mut FrameStats,
) {
    let [r, g, b, a] = &mut buf.color;
    let dst: [&mut [f32]; 4] = [
        &mut r[base..base + LANES],
        &mut g[base..base + LANES],
        &mut b[base..base + LANES],
        &mut a[base..base + LANES],
    ];
    let zbuf = &mut buf.depth[base..base + LANES];
    match mode.alpha {
        AlphaMode::Opaque | AlphaMode::Mask { .. } => {
            if let AlphaMode::Mask { cutoff } = mode.alpha {
                for l in 0..LANES {
                    m[l] &= out[3][l] >= cutoff;
                }
            }
            let [dr, dg, db, da] = dst;
            for l in 0..LANES {
                if m[l] {
                    dr[l] = out[0][l];
                    dg[l] = out[1][l];
                    db[l] = out[2][l];
                    da[l] = 1.0;
                }
            }
            if mode.depth_write {
                for l in 0..LANES {
                    if m[l] {
                        zbuf[l] = z[l];
                    }
                }
            }
        }
        AlphaMode::Blend => {
            let mut alpha = out[3];
            if mode.soft > 0.0 {
                for l in 0..LANES {
                    if m[l] {
                        let gap = soft.view(zbuf[l]) - soft.view(z[l]);
                        alpha[l] *= (gap / mode.soft).clamp(0.0, 1.0);
                    }
                }
            }
            let keep = match mode.blend {
                BlendMode::Alpha => 1.0,
                BlendMode::Additive => 0.0,
            };
            let [dr, dg, db, da] = dst;
            for l in 0..LANES {
                if m[l] {
                    let sa = alpha[l].clamp(0.0, 1.0);
                    let inv = 1.0 - sa * keep;
                    dr[l] = out[0][l] * sa + dr[l] * inv;
                    dg[l] = out[1][l] * sa + dg[l] * inv;
                    db[l] = out[2][l] * sa + db[l] * inv;
                    da[l] = sa + da[l] * (1.0 - sa);
                }
            }
            if mode.depth_write {
                for l in 0..LANES {
                    if m[l] {
                        zbuf[l] = z[l];
                    }
                }
            }
        }
    }
    stats.fragments_written += m.iter().filter(|&&b| b).count() as u64;
}
