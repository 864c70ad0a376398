//! The 8-lane sampler: [`Texture::sample8`] filters 8 points at once from the levels' blocked
//! tables (`LinearLevel`), with the same filtering (and the same odd-coordinate rules) as
//! the scalar [`Texture::sample`].
//!
//! Every table holds 4 bytes a texel (the stored bytes, or the square roots of their linear
//! values: `Texture::squared`), each beside the texel below it (`LinearLevel`), so where
//! every kept lane's tap-set lies inside the level (no wrapped or clamped edge) a lane's
//! four texels are one 16-byte load, and the 8 lanes' taps 8 loads instead of 4 gathers.

use super::{Filter, Sampler, Texture, Wrap};
use crate::simd::{F8, I8, M8};

impl Texture {
    /// Samples 8 points `(u, v)` with one level of detail for all of them (as GPUs share
    /// one per 2x2 quad). Returns premultiplied linear `[r, g, b, a]`; the same filtering
    /// as [`Texture::sample`], from the blocked byte tables (within the rounding
    /// [`Texture::squared`] states of it).
    #[inline]
    pub fn sample8(&self, s: &Sampler, u: F8, v: F8, lod: f32) -> [F8; 4] {
        self.sample8_lanes(s, u, v, lod, M8::from_bits(0xff))
    }

    /// [`Texture::sample8`] for the lanes set in `keep` only: the others read no texels
    /// and come back as zeros (a shader's idle lanes, whose coordinates lie outside the
    /// triangle, would otherwise load cache lines nobody uses). Kept lanes are the same
    /// as `sample8`'s.
    #[inline]
    pub fn sample8_lanes(&self, s: &Sampler, u: F8, v: F8, lod: f32, keep: M8) -> [F8; 4] {
        match s.filter {
            Filter::Nearest => self.nearest8(s, u, v, keep),
            Filter::Bilinear => self.bilinear8(s, 0, u, v, keep),
            Filter::Trilinear => {
                let (l0, t) = self.mip_levels(lod);
                let a = self.bilinear8(s, l0, u, v, keep);
                if t <= 0.0 {
                    return a;
                }
                let b = self.bilinear8(s, l0 + 1, u, v, keep);
                let t = F8::splat(t);
                std::array::from_fn(|c| (b[c] - a[c]).mul_add(t, a[c]))
            }
        }
    }

    fn nearest8(&self, s: &Sampler, u: F8, v: F8, keep: M8) -> [F8; 4] {
        let l = &self.levels[0];
        let x = wrap8(
            finite_or_zero(u * F8::splat(l.width as f32)).floor(),
            l.width,
            s.wrap_u,
        );
        let y = wrap8(
            finite_or_zero(v * F8::splat(l.height as f32)).floor(),
            l.height,
            s.wrap_v,
        );
        let idx = self.index8(0, x, y);
        let px = I8::gather_u32_lanes(&self.linear[0].bytes, idx, keep);
        self.weigh_bytes([px], [F8::splat(1.0)], keep)
    }

    /// The bilinear filter on the mip level nearest `lod` for the lanes set in `keep` (zeros
    /// elsewhere): half a trilinear read, where one value a texel is wanted rather than a
    /// colour blended across levels (a nailboard's depth offset).
    #[inline]
    pub fn bilinear8_lod(&self, s: &Sampler, lod: f32, u: F8, v: F8, keep: M8) -> [F8; 4] {
        let (l0, t) = self.mip_levels(lod);
        let level = (l0 + usize::from(t > 0.5)).min(self.levels.len() - 1);
        self.bilinear8(s, level, u, v, keep)
    }

    #[inline]
    fn bilinear8(&self, s: &Sampler, level: usize, u: F8, v: F8, keep: M8) -> [F8; 4] {
        let level = level.min(self.levels.len() - 1);
        let l = &self.levels[level];
        let half = F8::splat(0.5);
        let fx = finite_or_zero(u * F8::splat(l.width as f32) - half);
        let fy = finite_or_zero(v * F8::splat(l.height as f32) - half);
        let (x0, y0) = (fx.floor(), fy.floor());
        let (tx, ty) = (fx - x0, fy - y0);
        let one = F8::splat(1.0);
        let xa = wrap8(x0, l.width, s.wrap_u);
        let xb = wrap8(x0 + one, l.width, s.wrap_u);
        let ya = wrap8(y0, l.height, s.wrap_v);
        let yb = wrap8(y0 + one, l.height, s.wrap_v);
        let (sx, sy) = (one - tx, one - ty);
        let w = [sx * sy, tx * sy, sx * ty, tx * ty];
        let inside = xb.eq(xa + I8::splat(1)).and(yb.eq(ya + I8::splat(1)));
        if keep.and_not(inside).bits() == 0 {
            // Every kept lane's right and lower neighbours are the next column and row:
            // its four texels are the two entries at `(xa, ya)`.
            let t = &self.linear[level].bytes;
            let [p00, p01, p10, p11] = I8::load_quads(t, self.index8(level, xa, ya), keep);
            return self.weigh_bytes([p00, p10, p01, p11], w, keep);
        }
        let idx = |x: I8, y: I8| self.index8(level, x, y);
        self.taps(
            level,
            [idx(xa, ya), idx(xb, ya), idx(xa, yb), idx(xb, yb)],
            w,
            keep,
        )
    }

    /// The word of `level`'s table holding texel `(x, y)` (in range), as
    /// `LinearLevel::index` says.
    #[inline(always)]
    pub(super) fn index8(&self, level: usize, x: I8, y: I8) -> I8 {
        let lin = &self.linear[level];
        y.mul_lo(I8::splat(2 * lin.stride as i32)) + x.shl::<1>() + I8::splat(lin.base as i32)
    }

    /// The weighted sum of four taps of `level` at table indices `idx`, for the lanes
    /// of `keep` (zeros elsewhere).
    #[inline(always)]
    fn taps(&self, level: usize, idx: [I8; 4], w: [F8; 4], keep: M8) -> [F8; 4] {
        let t = &self.linear[level].bytes;
        let px = idx.map(|i| I8::gather_u32_lanes(t, i, keep));
        self.weigh_bytes(px, w, keep)
    }

    /// The weighted sum of `N` taps of a byte table, as premultiplied linear colour (the
    /// colour bytes squared when [`Texture::squared`]), for the lanes of `keep` (zeros
    /// elsewhere); an opaque texture's alpha is 1.
    #[inline(always)]
    fn weigh_bytes<const N: usize>(&self, px: [I8; N], w: [F8; N], keep: M8) -> [F8; 4] {
        let byte = I8::splat(0xff);
        let scale = F8::splat(1.0 / 255.0);
        // 1 / 255^2 itself: (1 / 255)^2 in f32 times 255^2 rounds to just above 1.
        let scale2 = F8::splat(1.0 / 65025.0);
        let mut acc = [F8::splat(0.0); 4];
        for k in 0..N {
            let wk = w[k] * scale;
            let colour = [px[k], px[k].shr::<8>(), px[k].shr::<16>()].map(|c| c.and(byte).to_f32());
            if self.squared {
                let wk2 = w[k] * scale2;
                for c in 0..3 {
                    acc[c] = (colour[c] * colour[c]).mul_add(wk2, acc[c]);
                }
            } else {
                for c in 0..3 {
                    acc[c] = colour[c].mul_add(wk, acc[c]);
                }
            }
            if !self.opaque {
                acc[3] = px[k].shr::<24>().to_f32().mul_add(wk, acc[3]);
            }
        }
        if self.opaque {
            acc[3] = keep.select(F8::splat(1.0), F8::splat(0.0));
        }
        acc
    }
}

/// NaN and huge coordinates (beyond any texture) become 0, as in the scalar `texel_floor`.
#[inline(always)]
fn finite_or_zero(x: F8) -> F8 {
    x.within(1e9).select(x, F8::splat(0.0))
}

/// The scalar `wrap` for 8 integer-valued lanes; the result is clamped into `0..size` whatever
/// rounding did to huge inputs.
#[inline(always)]
fn wrap8(i: F8, size: u32, mode: Wrap) -> I8 {
    if mode == Wrap::Repeat && size.is_power_of_two() {
        // The lanes are whole numbers within 1e9 (`finite_or_zero`, then `floor`), so they
        // convert to `i32` exactly, and a two's-complement mask is the floor modulo: the
        // same texel as the float path below, without its division.
        return i.to_i32().and(I8::splat(size as i32 - 1));
    }
    let n = size as f32;
    // x - m floor(x / m), then one correction step for the rounding of x / m.
    let modulo = |x: F8, m: f32| {
        let (zero, m) = (F8::splat(0.0), F8::splat(m));
        let r = x - (x / m).floor() * m;
        let r = r.ge(m).select(r - m, r);
        zero.gt(r).select(r + m, r)
    };
    let r = match mode {
        Wrap::Repeat => modulo(i, n),
        Wrap::Clamp => i,
        Wrap::Mirror => {
            let m = modulo(i, 2.0 * n);
            m.ge(F8::splat(n)).select(F8::splat(2.0 * n - 1.0) - m, m)
        }
    };
    r.to_i32().max(I8::splat(0)).min(I8::splat(size as i32 - 1))
}
