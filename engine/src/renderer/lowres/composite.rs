//! The low-resolution pass's composite: the small target upsampled over the frame, eight
//! pixels of a block row at a time (the tile's storage holds them contiguously).
//!
//! A full pixel takes the bilinear mean of its four small taps whose depth is like its own
//! ([`alike`]); where none is (a pixel beside an edge whose taps all lie over the nearer
//! side), the nearest small pixel alike in depth one further out, else the tap nearest in
//! depth ([`fallback`], one lane at a time). The result is blended over the pixel:
//! `dst = src + dst (1 - src.a)`.

use super::{LowRes, ALIKE};
use crate::color::{srgb_to_linear_lut, Encoder, Encoding};
use crate::simd::{F8, I8, M8};
use crate::target::{offset_in_tile, Target, BLOCK, TILE, TILE_PIXELS};
use rayon::prelude::*;

/// The small target as the composite reads it: row-major, premultiplied linear colour at
/// 16 bits a channel (`r | g << 16 | b << 32 | a << 48`, the textures' layout, for one
/// gather a tap) and depth as `f32` bits.
#[derive(Debug, Default)]
pub(super) struct Small {
    rgba: Vec<u64>,
    depth: Vec<u32>,
    width: usize,
    height: usize,
    /// Per full column: its taps' small columns and the second's weight, padded to a
    /// whole block past the frame's width.
    col0: Vec<i32>,
    col1: Vec<i32>,
    col_t: Vec<f32>,
    /// Per full row: its taps' small rows and the second's weight.
    rows: Vec<(u32, u32, f32)>,
    /// The sRGB decode table as `f32` bits, for gathers.
    decode: Vec<u32>,
}

/// Whether two reversed depths are alike ([`ALIKE`]).
#[inline(always)]
fn alike(a: f32, b: f32) -> bool {
    (a - b).abs() <= ALIKE * a.max(b)
}

/// [`alike`] for eight lanes.
#[inline(always)]
fn alike8(a: F8, b: F8) -> M8 {
    (a - b).abs().le(a.max(b) * F8::splat(ALIKE))
}

/// The two small taps (and the second's weight) of full column or row `x` of `n`, `small`
/// across: pixel centres matched, clamped at the edges.
fn tap(x: u32, n: u32, small: usize) -> (u32, u32, f32) {
    let last = small.saturating_sub(1);
    let f = ((x as f32 + 0.5) * small as f32 / n.max(1) as f32 - 0.5).clamp(0.0, last as f32);
    let i = f.floor();
    let a = i as u32;
    (a, (a + 1).min(last as u32), f - i)
}

/// A channel of 16 bits to `0..=1`.
const UNIT16: f32 = 1.0 / 65535.0;

impl Small {
    /// Reads `small` (its colour linear, at 16 bits) and the taps of a `w` x `h` frame.
    fn read(&mut self, small: &Target, w: u32, h: u32) {
        let (sw, sh) = (small.width() as usize, small.height() as usize);
        (self.width, self.height) = (sw, sh);
        self.rgba.resize(sw * sh, 0);
        self.depth.resize(sw * sh, 0);
        let lut = srgb_to_linear_lut();
        let encoding = small.encoding();
        let channel = |b: u32, srgb: bool| {
            let x = if srgb {
                lut[b as usize]
            } else {
                b as f32 / 255.0
            };
            (x * 65535.0 + 0.5) as u64
        };
        self.rgba
            .par_chunks_mut(sw)
            .zip(self.depth.par_chunks_mut(sw))
            .enumerate()
            .for_each(|(y, (rgba, depth))| {
                for (x, (c, d)) in rgba.iter_mut().zip(depth).enumerate() {
                    let i = small.index(x as u32, y as u32);
                    let p = small.color[i];
                    let srgb = encoding == Encoding::Srgb;
                    let [r, g, b] = [0, 8, 16].map(|s| channel(p >> s & 0xff, srgb));
                    *c = r | g << 16 | b << 32 | channel(p >> 24, false) << 48;
                    *d = small.depth[i].to_bits();
                }
            });
        let padded = (w as usize).div_ceil(BLOCK) * BLOCK;
        let cols = (0..padded as u32).map(|x| tap(x.min(w.saturating_sub(1)), w, sw));
        self.col0.clear();
        self.col1.clear();
        self.col_t.clear();
        for (a, b, t) in cols {
            self.col0.push(a as i32);
            self.col1.push(b as i32);
            self.col_t.push(t);
        }
        self.rows.clear();
        self.rows.extend((0..h).map(|y| tap(y, h, sh)));
        if self.decode.is_empty() {
            self.decode.extend(lut.iter().map(|x| x.to_bits()));
        }
    }

    /// Small pixel `i`'s colour, linear premultiplied.
    fn color(&self, i: usize) -> [f32; 4] {
        let c = self.rgba[i];
        [0, 16, 32, 48].map(|s| (c >> s & 0xffff) as f32 * UNIT16)
    }

    fn depth(&self, i: usize) -> f32 {
        f32::from_bits(self.depth[i])
    }

    /// Whether every small pixel the full pixels `from..to` tap, and those one further
    /// (which [`fallback`] may take), is clear.
    fn clear_under(&self, from: (usize, usize), to: (usize, usize)) -> bool {
        let lo = |v: i32| (v.max(1) - 1) as usize;
        let (x0, x1) = (
            lo(self.col0[from.0]),
            (self.col1[to.0 - 1] as usize + 2).min(self.width),
        );
        let (y0, y1) = (
            lo(self.rows[from.1].0 as i32),
            (self.rows[to.1 - 1].1 as usize + 2).min(self.height),
        );
        let row = |y: usize| &self.rgba[y * self.width + x0..y * self.width + x1];
        (y0..y1).all(|y| row(y).iter().all(|&c| c == 0))
    }
}

/// Blends `low`'s small target over `target`, upsampled (module docs).
pub(super) fn composite(low: &mut LowRes, target: &mut Target) {
    let (w, h) = (target.width(), target.height());
    if low.small.width() == 0 || low.small.height() == 0 || w == 0 || h == 0 {
        return;
    }
    low.read.read(&low.small, w, h);
    let small = &low.read;
    let tiles_x = target.tiles_x() as usize;
    let encoder = Encoder::new(target.encoding());
    let srgb = target.encoding() == Encoding::Srgb;
    let (colors, depths) = target.storage_mut();
    colors
        .par_chunks_mut(TILE_PIXELS)
        .zip(depths.par_chunks(TILE_PIXELS))
        .enumerate()
        .with_max_len(1)
        .for_each(|(t, (color, depth))| {
            let (ox, oy) = (t % tiles_x * TILE, t / tiles_x * TILE);
            let (x1, y1) = ((ox + TILE).min(w as usize), (oy + TILE).min(h as usize));
            if small.clear_under((ox, oy), (x1, y1)) {
                return;
            }
            for y in oy..y1 {
                for bx in (ox..x1).step_by(BLOCK) {
                    let off = offset_in_tile(bx - ox, y - oy);
                    let out = &mut color[off..off + BLOCK];
                    let inside = I8::lane_range(0, (x1 - bx) as i32 - 1);
                    let d = F8::load(&depth[off..off + BLOCK]);
                    block_row(small, (bx, y), inside, d, srgb, &encoder, out);
                }
            }
        });
}

/// One block row of eight full pixels from `(x, y)`: the lanes of `inside` blended over
/// `out`, their depths `d`.
#[inline(always)]
fn block_row(
    small: &Small,
    (x, y): (usize, usize),
    inside: M8,
    d: F8,
    srgb: bool,
    encoder: &Encoder,
    out: &mut [u32],
) {
    let (j0, j1, ty) = small.rows[y];
    let lane = |v: &[i32]| I8::from_array(v[x..x + BLOCK].try_into().expect("8 lanes"));
    let (i0, i1) = (lane(&small.col0), lane(&small.col1));
    let tx = F8::load(&small.col_t[x..x + BLOCK]);
    let (r0, r1) = (
        I8::splat((j0 as usize * small.width) as i32),
        I8::splat((j1 as usize * small.width) as i32),
    );
    let (one, zero, ty) = (F8::splat(1.0), F8::splat(0.0), F8::splat(ty));
    let (sx, sy) = (one - tx, one - ty);
    let taps = [
        (r0 + i0, sx * sy),
        (r1 + i0, sx * ty),
        (r0 + i1, tx * sy),
        (r1 + i1, tx * ty),
    ];
    let mut sum = [zero; 4];
    let mut weight = zero;
    let mut idle = M8::from_bits(0xff);
    let all = M8::from_bits(0xff);
    let low = I8::splat(0xffff);
    for (idx, wk) in taps {
        let dk = I8::gather_u32_lanes(&small.depth, idx, all).bits_to_f32();
        let same = alike8(dk, d);
        let (rg, ba) = I8::gather_pairs(&small.rgba, idx);
        let clear = rg.or(ba).eq(I8::splat(0));
        idle = idle.and(same).and(clear);
        let wk = same.select(wk, zero);
        let ch = [rg.and(low), rg.shr::<16>(), ba.and(low), ba.shr::<16>()];
        for (s, c) in sum.iter_mut().zip(ch) {
            *s = (c.to_f32() * F8::splat(UNIT16)).mul_add(wk, *s);
        }
        weight = weight + wk;
    }
    // Nothing to blend where every tap is clear and alike in depth.
    let work = inside.and_not(idle);
    if work.bits() == 0 {
        return;
    }
    let some = weight.gt(F8::splat(1e-6));
    let inv = some.select(one / weight, zero);
    let mut src = sum.map(|s| s * inv);
    let lost = work.and_not(some).bits();
    if lost != 0 {
        let mut lanes = src.map(F8::to_array);
        let dl = d.to_array();
        let (tx, i0, i1) = (tx.to_array(), i0.to_array(), i1.to_array());
        for l in (0..BLOCK).filter(|l| lost >> l & 1 == 1) {
            let at = (i0[l] as f32 + tx[l], j0 as f32 + ty.to_array()[l]);
            let idx = [j0, j1].map(|j| j as usize * small.width);
            let taps = [
                idx[0] + i0[l] as usize,
                idx[1] + i0[l] as usize,
                idx[0] + i1[l] as usize,
                idx[1] + i1[l] as usize,
            ];
            let c = fallback(small, &taps, at, dl[l]);
            for (ch, v) in lanes.iter_mut().zip(c) {
                ch[l] = v;
            }
        }
        src = lanes.map(F8::from_array);
    }
    src = src.map(|c| work.select(c, zero));
    // The pixels under it, linear: a lane blending nothing keeps its bytes (decoding and
    // encoding a byte is exact).
    let px = I8::from_array(std::array::from_fn(|l| out[l] as i32));
    let byte = I8::splat(0xff);
    let decode = |v: I8| match srgb {
        true => I8::gather_u32_lanes(&small.decode, v, all).bits_to_f32(),
        false => v.to_f32() * F8::splat(1.0 / 255.0),
    };
    let dst = [
        decode(px.and(byte)),
        decode(px.shr::<8>().and(byte)),
        decode(px.shr::<16>().and(byte)),
        px.shr::<24>().and(byte).to_f32() * F8::splat(1.0 / 255.0),
    ];
    let k = one - src[3];
    let mut lanes = [[0.0f32; BLOCK]; 4];
    for ((l, s), d) in lanes.iter_mut().zip(src).zip(dst) {
        d.mul_add(k, s).store(l);
    }
    let [r, g, b, a] = &lanes;
    encoder.pack8(r, g, b, a, out);
}

/// For a pixel of depth `d` whose `taps` are none alike in depth: the small pixel alike
/// in depth nearest to `at` (small pixel units) within one pixel around the taps, as an
/// edge's far side takes the colour beyond its mixed block; else the tap nearest in depth.
fn fallback(small: &Small, taps: &[usize; 4], at: (f32, f32), d: f32) -> [f32; 4] {
    let (x0, y0) = (at.0.floor() as i64, at.1.floor() as i64);
    let mut best: Option<(f32, usize)> = None;
    for y in y0 - 1..=y0 + 2 {
        for x in x0 - 1..=x0 + 2 {
            if x < 0 || y < 0 || x >= small.width as i64 || y >= small.height as i64 {
                continue;
            }
            let i = y as usize * small.width + x as usize;
            let dist = (x as f32 - at.0).powi(2) + (y as f32 - at.1).powi(2);
            if alike(small.depth(i), d) && best.is_none_or(|(b, _)| dist < b) {
                best = Some((dist, i));
            }
        }
    }
    let nearest = || {
        let off = |i: &&usize| (small.depth(**i) - d).abs();
        *taps
            .iter()
            .min_by(|a, b| off(a).total_cmp(&off(b)))
            .unwrap_or(&taps[0])
    };
    small.color(best.map_or_else(nearest, |(_, i)| i))
}
