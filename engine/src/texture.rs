//! Textures and sampling: mip chains of RGBA8 texels, wrap modes, nearest / bilinear /
//! trilinear filtering.
//!
//! Texels are stored as bytes in an [`Encoding`] (sRGB for colour images, unorm for data
//! and for render-target read-backs in that encoding) and decoded to linear on every tap.
//! Filtering always happens on premultiplied linear colour, so transparent texels do not
//! bleed their colour; `premultiplied` says whether the stored bytes already are.
//! Sampling is pure and cannot fail: odd coordinates (NaN, huge) sample texel 0.

use crate::color::{srgb_to_linear_lut, unpack, Encoding, Premul, Rgba};
use crate::simd::{F8, I8};
use std::sync::OnceLock;

/// How texture coordinates outside [0, 1] are folded back.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Wrap {
    /// Tiles the image: coordinate `u + 1` samples what `u` does (OpenGL `GL_REPEAT`).
    #[default]
    Repeat,
    /// Repeats the edge texels outward (`GL_CLAMP_TO_EDGE`).
    Clamp,
    /// Tiles the image flipped every other time, so edges meet seamlessly
    /// (`GL_MIRRORED_REPEAT`).
    Mirror,
}

/// Texture filtering.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Filter {
    /// The texel containing the sample point, on the finest level only (no mipmaps).
    Nearest,
    /// Bilinear on the finest level only.
    Bilinear,
    /// Bilinear on the two nearest mip levels, blended by the level of detail.
    #[default]
    Trilinear,
}

/// How a material samples its texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Sampler {
    /// Wrap along u (the texture's x, to the right).
    pub wrap_u: Wrap,
    /// Wrap along v (the texture's y, downward: v = 0 is the top row).
    pub wrap_v: Wrap,
    /// Filter for magnification and minification alike.
    pub filter: Filter,
}

/// One mip level: `width * height` packed texels, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct MipLevel {
    /// Width in texels, >= 1.
    pub width: u32,
    /// Height in texels, >= 1.
    pub height: u32,
    /// Packed bytes `r | g << 8 | b << 16 | a << 24` in the texture's [`Encoding`],
    /// premultiplied when [`Texture`] says so; `width * height` of them.
    pub texels: Vec<u32>,
}

/// An immutable texture with its mip chain (level 0 is the full image).
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    levels: Vec<MipLevel>,
    encoding: Encoding,
    premultiplied: bool,
    /// Every level decoded for the 8-lane sampler ([`Texture::sample8`]).
    linear: Vec<LinearLevel>,
}

/// One level as premultiplied linear colour in 16-bit channels, one `u64` a texel
/// (`r | g << 16 | b << 32 | a << 48`): a bilinear tap is one 8-byte load per lane and a
/// few shifts, with no table lookups. 16 bits hold every 8-bit sRGB value to within 1e-5.
#[derive(Clone, Debug, PartialEq, Default)]
struct LinearLevel {
    rgba: Vec<u64>,
}

/// The largest texture side accepted; larger images are refused by the loaders.
pub const MAX_TEXTURE_SIZE: u32 = 16384;

fn unorm_lut() -> &'static [f32; 256] {
    static LUT: OnceLock<[f32; 256]> = OnceLock::new();
    LUT.get_or_init(|| std::array::from_fn(|i| i as f32 / 255.0))
}

impl Texture {
    /// A texture from straight (non-premultiplied) RGBA8 bytes, row-major, top row first.
    /// Returns `None` when the sizes disagree or a side is 0 or over [`MAX_TEXTURE_SIZE`].
    pub fn from_rgba8(width: u32, height: u32, rgba: &[u8], encoding: Encoding) -> Option<Self> {
        if width == 0 || height == 0 || width > MAX_TEXTURE_SIZE || height > MAX_TEXTURE_SIZE {
            return None;
        }
        if rgba.len() != width as usize * height as usize * 4 {
            return None;
        }
        let texels = rgba
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        Some(Self::from_level(
            MipLevel {
                width,
                height,
                texels,
            },
            encoding,
            false,
        ))
    }

    /// A texture from packed texels (as a render target stores them: premultiplied).
    pub fn from_packed(
        width: u32,
        height: u32,
        texels: Vec<u32>,
        encoding: Encoding,
        premultiplied: bool,
    ) -> Option<Self> {
        if width == 0 || height == 0 || texels.len() != width as usize * height as usize {
            return None;
        }
        Some(Self::from_level(
            MipLevel {
                width,
                height,
                texels,
            },
            encoding,
            premultiplied,
        ))
    }

    /// A 1x1 texture of one colour (the placeholder for a missing image).
    pub fn solid(c: Rgba) -> Self {
        let px = crate::color::Encoder::new(Encoding::Srgb).pack(c.r, c.g, c.b, c.a);
        // `pack` treats its input as premultiplied; a straight colour of alpha a is stored
        // straight here, so pack the unscaled channels.
        Self::from_packed(1, 1, vec![px], Encoding::Srgb, false).expect("1x1 is valid")
    }

    /// A two-colour checkerboard of `cells` x `cells` squares (procedural test pattern).
    pub fn checker(size: u32, cells: u32, a: Rgba, b: Rgba) -> Self {
        let enc = crate::color::Encoder::new(Encoding::Srgb);
        let (pa, pb) = (enc.pack(a.r, a.g, a.b, a.a), enc.pack(b.r, b.g, b.b, b.a));
        let size = size.max(1);
        let cell = (size / cells.max(1)).max(1);
        let texels = (0..size * size)
            .map(|i| {
                let (x, y) = (i % size / cell, i / size / cell);
                if (x + y) % 2 == 0 {
                    pa
                } else {
                    pb
                }
            })
            .collect();
        Self::from_packed(size, size, texels, Encoding::Srgb, false).expect("valid size")
    }

    fn from_level(level: MipLevel, encoding: Encoding, premultiplied: bool) -> Self {
        let mut t = Texture {
            levels: vec![level],
            encoding,
            premultiplied,
            linear: Vec::new(),
        };
        t.rebuild();
        t
    }

    /// Replaces the image with `width` x `height` texels written by `fill` (row-major, top
    /// row first, packed in `encoding`, premultiplied or straight), then rebuilds the mip
    /// chain, all in the texture's own memory: refilling a texture with an image of the
    /// same size allocates nothing. Returns `false`, leaving the texture as it was, for a
    /// side of 0 or over [`MAX_TEXTURE_SIZE`].
    pub fn refill(
        &mut self,
        width: u32,
        height: u32,
        encoding: Encoding,
        premultiplied: bool,
        fill: impl FnOnce(&mut [u32]),
    ) -> bool {
        if width == 0 || height == 0 || width > MAX_TEXTURE_SIZE || height > MAX_TEXTURE_SIZE {
            return false;
        }
        self.encoding = encoding;
        self.premultiplied = premultiplied;
        let l = &mut self.levels[0];
        l.width = width;
        l.height = height;
        l.texels.resize(width as usize * height as usize, 0);
        fill(&mut l.texels);
        self.rebuild();
        true
    }

    /// Recomputes the box-filtered mip chain (averaged as premultiplied linear colour) and
    /// the 16-bit linear copy from level 0, reusing the existing levels' memory.
    fn rebuild(&mut self) {
        let (encoding, premultiplied) = (self.encoding, self.premultiplied);
        let enc = crate::color::Encoder::new(encoding);
        let mut k = 1;
        loop {
            let (pw, ph) = (self.levels[k - 1].width, self.levels[k - 1].height);
            if pw == 1 && ph == 1 {
                break;
            }
            let (w, h) = ((pw / 2).max(1), (ph / 2).max(1));
            if self.levels.len() == k {
                self.levels.push(MipLevel {
                    width: w,
                    height: h,
                    texels: Vec::new(),
                });
            }
            let (done, rest) = self.levels.split_at_mut(k);
            let (prev, cur) = (&done[k - 1], &mut rest[0]);
            cur.width = w;
            cur.height = h;
            cur.texels.clear();
            for y in 0..h {
                for x in 0..w {
                    let mut acc = [0.0f32; 4];
                    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        let sx = (2 * x + dx).min(pw - 1);
                        let sy = (2 * y + dy).min(ph - 1);
                        let c = decode(
                            encoding,
                            premultiplied,
                            prev.texels[(sy * pw + sx) as usize],
                        );
                        acc[0] += c.r;
                        acc[1] += c.g;
                        acc[2] += c.b;
                        acc[3] += c.a;
                    }
                    let c = Premul {
                        r: acc[0] * 0.25,
                        g: acc[1] * 0.25,
                        b: acc[2] * 0.25,
                        a: acc[3] * 0.25,
                    };
                    let c = if premultiplied {
                        c.to_array()
                    } else {
                        c.unpremultiply().to_array()
                    };
                    cur.texels.push(enc.pack(c[0], c[1], c[2], c[3]));
                }
            }
            k += 1;
        }
        self.levels.truncate(k);
        self.linear.resize_with(k, LinearLevel::default);
        let q = |x: f32| (x.clamp(0.0, 1.0) * 65535.0).round() as u64;
        for (lin, level) in self.linear.iter_mut().zip(&self.levels) {
            lin.rgba.clear();
            for &px in &level.texels {
                let c = decode(encoding, premultiplied, px);
                let (r, g, b, a) = (q(c.r), q(c.g), q(c.b), q(c.a));
                lin.rgba.push(r | g << 16 | b << 32 | a << 48);
            }
        }
    }

    /// Width of level 0 in texels.
    pub fn width(&self) -> u32 {
        self.levels[0].width
    }

    /// Height of level 0 in texels.
    pub fn height(&self) -> u32 {
        self.levels[0].height
    }

    /// The mip chain, level 0 (full size) first, each level half the previous per side
    /// (rounded down, at least 1), box-filtered, down to 1 x 1.
    pub fn levels(&self) -> &[MipLevel] {
        &self.levels
    }

    /// How the stored bytes encode linear colour.
    pub fn encoding(&self) -> Encoding {
        self.encoding
    }

    /// One stored texel as premultiplied linear colour.
    #[inline]
    pub fn decode(&self, px: u32) -> Premul {
        decode(self.encoding, self.premultiplied, px)
    }

    /// Texel `(x, y)` of level `level`, premultiplied linear (coordinates clamped).
    pub fn texel(&self, level: usize, x: u32, y: u32) -> Premul {
        let l = &self.levels[level.min(self.levels.len() - 1)];
        let (x, y) = (x.min(l.width - 1), y.min(l.height - 1));
        self.decode(l.texels[(y * l.width + x) as usize])
    }

    /// Samples at `(u, v)` with a level of detail `lod` (log2 of texels per pixel, from
    /// the rasterizer's derivatives). Returns premultiplied linear colour.
    #[inline]
    pub fn sample(&self, s: &Sampler, u: f32, v: f32, lod: f32) -> Premul {
        match s.filter {
            Filter::Nearest => self.nearest(s, 0, u, v),
            Filter::Bilinear => self.bilinear(s, 0, u, v),
            Filter::Trilinear => {
                let (l0, t) = self.mip_levels(lod);
                let a = self.bilinear(s, l0, u, v);
                if t <= 0.0 {
                    return a;
                }
                let b = self.bilinear(s, l0 + 1, u, v);
                Premul {
                    r: a.r + (b.r - a.r) * t,
                    g: a.g + (b.g - a.g) * t,
                    b: a.b + (b.b - a.b) * t,
                    a: a.a + (b.a - a.a) * t,
                }
            }
        }
    }

    /// The finer of the two mip levels a trilinear lookup at `lod` blends, and the weight
    /// of the coarser one (`lod` clamped to the chain; non-finite means level 0).
    fn mip_levels(&self, lod: f32) -> (usize, f32) {
        let max = (self.levels.len() - 1) as f32;
        let lod = if lod.is_finite() {
            lod.clamp(0.0, max)
        } else {
            0.0
        };
        let l0 = lod.floor();
        (l0 as usize, lod - l0)
    }

    /// Samples 8 points `(u, v)` with one level of detail for all of them (as GPUs share
    /// one per 2x2 quad). Returns premultiplied linear `[r, g, b, a]`; the same filtering
    /// as [`Texture::sample`], from the 16-bit linear copy of the texels.
    #[inline]
    pub fn sample8(&self, s: &Sampler, u: F8, v: F8, lod: f32) -> [F8; 4] {
        match s.filter {
            Filter::Nearest => self.nearest8(s, u, v),
            Filter::Bilinear => self.bilinear8(s, 0, u, v),
            Filter::Trilinear => {
                let (l0, t) = self.mip_levels(lod);
                let a = self.bilinear8(s, l0, u, v);
                if t <= 0.0 {
                    return a;
                }
                let b = self.bilinear8(s, l0 + 1, u, v);
                let t = F8::splat(t);
                std::array::from_fn(|c| (b[c] - a[c]).mul_add(t, a[c]))
            }
        }
    }

    fn nearest8(&self, s: &Sampler, u: F8, v: F8) -> [F8; 4] {
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
        let idx = y.mul_lo(I8::splat(l.width as i32)) + x;
        let one = F8::splat(1.0);
        self.taps(
            0,
            [idx; 4],
            [one, F8::splat(0.0), F8::splat(0.0), F8::splat(0.0)],
        )
    }

    #[inline]
    fn bilinear8(&self, s: &Sampler, level: usize, u: F8, v: F8) -> [F8; 4] {
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
        let w = I8::splat(l.width as i32);
        let ya = wrap8(y0, l.height, s.wrap_v).mul_lo(w);
        let yb = wrap8(y0 + one, l.height, s.wrap_v).mul_lo(w);
        let (sx, sy) = (one - tx, one - ty);
        self.taps(
            level,
            [ya + xa, ya + xb, yb + xa, yb + xb],
            [sx * sy, tx * sy, sx * ty, tx * ty],
        )
    }

    /// The weighted sum of four taps of `level` at row-major indices `idx`.
    #[inline(always)]
    fn taps(&self, level: usize, idx: [I8; 4], w: [F8; 4]) -> [F8; 4] {
        let lin = &self.linear[level];
        let low = I8::splat(0xffff);
        let scale = F8::splat(1.0 / 65535.0);
        let mut acc = [F8::splat(0.0); 4];
        for k in 0..4 {
            let (rg, ba) = I8::gather_pairs(&lin.rgba, idx[k]);
            let wk = w[k] * scale;
            acc[0] = rg.and(low).to_f32().mul_add(wk, acc[0]);
            acc[1] = rg.shr::<16>().to_f32().mul_add(wk, acc[1]);
            acc[2] = ba.and(low).to_f32().mul_add(wk, acc[2]);
            acc[3] = ba.shr::<16>().to_f32().mul_add(wk, acc[3]);
        }
        acc
    }

    fn nearest(&self, s: &Sampler, level: usize, u: f32, v: f32) -> Premul {
        let l = &self.levels[level];
        let x = wrap(texel_floor(u * l.width as f32), l.width, s.wrap_u);
        let y = wrap(texel_floor(v * l.height as f32), l.height, s.wrap_v);
        self.decode(l.texels[(y * l.width + x) as usize])
    }

    #[inline]
    fn bilinear(&self, s: &Sampler, level: usize, u: f32, v: f32) -> Premul {
        let l = &self.levels[level.min(self.levels.len() - 1)];
        let fx = u * l.width as f32 - 0.5;
        let fy = v * l.height as f32 - 0.5;
        let (x0, y0) = (texel_floor(fx), texel_floor(fy));
        let (tx, ty) = if fx.is_finite() && fy.is_finite() && fx.abs() < 1e9 && fy.abs() < 1e9 {
            (fx - x0 as f32, fy - y0 as f32)
        } else {
            (0.0, 0.0)
        };
        let xa = wrap(x0, l.width, s.wrap_u);
        let xb = wrap(x0 + 1, l.width, s.wrap_u);
        let ya = wrap(y0, l.height, s.wrap_v) * l.width;
        let yb = wrap(y0 + 1, l.height, s.wrap_v) * l.width;
        let t = &l.texels;
        let px = [
            t[(ya + xa) as usize],
            t[(ya + xb) as usize],
            t[(yb + xa) as usize],
            t[(yb + xb) as usize],
        ];
        let w = [
            (1.0 - tx) * (1.0 - ty),
            tx * (1.0 - ty),
            (1.0 - tx) * ty,
            tx * ty,
        ];
        // One table fetch per sample, not per tap; straight texels are premultiplied per tap
        // so transparent texels do not bleed their colour.
        let lut = match self.encoding {
            Encoding::Srgb => srgb_to_linear_lut(),
            Encoding::Unorm => unorm_lut(),
        };
        let mut acc = [0.0f32; 4];
        for k in 0..4 {
            let [r, g, b, a] = px[k].to_le_bytes();
            let a = a as f32 * (1.0 / 255.0);
            let (m, wa) = if self.premultiplied {
                (w[k], w[k])
            } else {
                (w[k] * a, w[k])
            };
            acc[0] += lut[r as usize] * m;
            acc[1] += lut[g as usize] * m;
            acc[2] += lut[b as usize] * m;
            acc[3] += a * wa;
        }
        Premul {
            r: acc[0],
            g: acc[1],
            b: acc[2],
            a: acc[3],
        }
    }
}

/// A packed texel as premultiplied linear colour.
#[inline]
fn decode(encoding: Encoding, premultiplied: bool, px: u32) -> Premul {
    if premultiplied {
        return unpack(encoding, px);
    }
    let lut = match encoding {
        Encoding::Srgb => srgb_to_linear_lut(),
        Encoding::Unorm => unorm_lut(),
    };
    let [r, g, b, a] = px.to_le_bytes();
    let a = a as f32 * (1.0 / 255.0);
    Premul {
        r: lut[r as usize] * a,
        g: lut[g as usize] * a,
        b: lut[b as usize] * a,
        a,
    }
}

/// `floor` to a texel index; NaN and huge values give 0 so they cannot overflow.
#[inline]
fn texel_floor(x: f32) -> i64 {
    if x.is_finite() && x.abs() < 1e9 {
        x.floor() as i64
    } else {
        0
    }
}

/// NaN and huge coordinates (beyond any texture) become 0, as in [`texel_floor`].
#[inline(always)]
fn finite_or_zero(x: F8) -> F8 {
    x.within(1e9).select(x, F8::splat(0.0))
}

/// [`wrap`] for 8 integer-valued lanes; the result is clamped into `0..size` whatever
/// rounding did to huge inputs.
#[inline(always)]
fn wrap8(i: F8, size: u32, mode: Wrap) -> I8 {
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

#[inline]
fn wrap(i: i64, size: u32, mode: Wrap) -> u32 {
    let n = size as i64;
    // In range is the common case; powers of two need a mask, not a division.
    if (0..n).contains(&i) {
        return i as u32;
    }
    (match mode {
        Wrap::Repeat if size.is_power_of_two() => i & (n - 1),
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::Clamp => i.clamp(0, n - 1),
        Wrap::Mirror => {
            let m = i.rem_euclid(2 * n);
            if m >= n {
                2 * n - 1 - m
            } else {
                m
            }
        }
    }) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_by_two() -> Texture {
        // red, green / blue, white (sRGB bytes)
        let px = [
            255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255,
        ];
        Texture::from_rgba8(2, 2, &px, Encoding::Srgb).unwrap()
    }

    #[test]
    fn wrap_modes() {
        assert_eq!(wrap(-1, 4, Wrap::Repeat), 3);
        assert_eq!(wrap(5, 4, Wrap::Repeat), 1);
        assert_eq!(wrap(-1, 4, Wrap::Clamp), 0);
        assert_eq!(wrap(9, 4, Wrap::Clamp), 3);
        assert_eq!(wrap(4, 4, Wrap::Mirror), 3);
        assert_eq!(wrap(-1, 4, Wrap::Mirror), 0);
        assert_eq!(wrap(7, 4, Wrap::Mirror), 0);
    }

    #[test]
    fn bilinear_at_texel_centres_returns_texels() {
        let t = two_by_two();
        let s = Sampler {
            filter: Filter::Bilinear,
            ..Default::default()
        };
        let c = t.sample(&s, 0.25, 0.25, 0.0);
        assert!((c.r - 1.0).abs() < 1e-6 && c.g.abs() < 1e-6);
        let c = t.sample(&s, 0.75, 0.75, 0.0);
        assert!((c.g - 1.0).abs() < 1e-6 && (c.b - 1.0).abs() < 1e-6);
        // halfway between red and green: the linear average
        let c = t.sample(&s, 0.5, 0.25, 0.0);
        assert!((c.r - 0.5).abs() < 1e-6 && (c.g - 0.5).abs() < 1e-6);
    }

    #[test]
    fn mip_chain_averages_in_linear() {
        let t = two_by_two();
        assert_eq!(t.levels().len(), 2);
        let c = t.texel(1, 0, 0);
        // (1 + 0 + 0 + 1) / 4 = 0.5 linear red, re-encoded to a byte and decoded back
        assert!((c.r - 0.5).abs() < 0.01, "{c:?}");
        let s = Sampler::default();
        let far = t.sample(&s, 0.3, 0.3, 5.0);
        assert!((far.r - c.r).abs() < 1e-6);
    }

    #[test]
    fn transparent_texels_do_not_bleed() {
        let px = [255, 0, 0, 255, 0, 255, 0, 0];
        let t = Texture::from_rgba8(2, 1, &px, Encoding::Srgb).unwrap();
        let s = Sampler {
            filter: Filter::Bilinear,
            wrap_u: Wrap::Clamp,
            ..Default::default()
        };
        let c = t.sample(&s, 0.5, 0.5, 0.0);
        assert!(c.g.abs() < 1e-6 && (c.a - 0.5).abs() < 1e-6 && (c.r - 0.5).abs() < 1e-6);
    }

    /// The 8-lane sampler filters like the scalar one (to the 16-bit linear copy's
    /// precision) for every filter, wrap mode, encoding and alpha storage, odd coordinates
    /// included.
    #[test]
    fn eight_lanes_match_the_scalar_sampler() {
        let mut rng = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 40) as f32 / (1u64 << 24) as f32
        };
        let bytes: Vec<u8> = (0..13 * 7 * 4)
            .map(|i| ((i * 97 + i / 5 * 31) % 256) as u8)
            .collect();
        let textures = [
            Texture::from_rgba8(13, 7, &bytes, Encoding::Srgb).unwrap(),
            Texture::from_rgba8(13, 7, &bytes, Encoding::Unorm).unwrap(),
            Texture::checker(16, 4, Rgba::WHITE, Rgba::new(0.2, 0.5, 0.9, 0.4)),
            Texture::from_packed(
                4,
                2,
                bytes[..8]
                    .iter()
                    .map(|&b| u32::from(b) * 0x0101_0101)
                    .collect(),
                Encoding::Srgb,
                true,
            )
            .unwrap(),
        ];
        let odd = [
            f32::NAN,
            1e30,
            -1e12,
            f32::INFINITY,
            -0.0,
            1.0,
            3.999_99,
            -7.25,
        ];
        for t in &textures {
            for filter in [Filter::Nearest, Filter::Bilinear, Filter::Trilinear] {
                for wrap in [Wrap::Repeat, Wrap::Clamp, Wrap::Mirror] {
                    let s = Sampler {
                        filter,
                        wrap_u: wrap,
                        wrap_v: wrap,
                    };
                    for round in 0..40 {
                        let lod = next() * 4.0 - 0.5;
                        let (u, v): ([f32; 8], [f32; 8]) = if round == 0 {
                            (odd, std::array::from_fn(|l| odd[7 - l]))
                        } else {
                            (
                                std::array::from_fn(|_| next() * 6.0 - 3.0),
                                std::array::from_fn(|_| next() * 6.0 - 3.0),
                            )
                        };
                        let got = t.sample8(&s, F8::from_array(u), F8::from_array(v), lod);
                        for l in 0..8 {
                            if !(u[l].abs() < 1e6 && v[l].abs() < 1e6) {
                                // Either coordinate odd: any finite colour in range will do.
                                assert!(got.iter().all(|c| (0.0..=1.0).contains(&c.to_array()[l])));
                                continue;
                            }
                            let want = t.sample(&s, u[l], v[l], lod).to_array();
                            for c in 0..4 {
                                let g = got[c].to_array()[l];
                                assert!(
                                    (g - want[c]).abs() < 2e-4,
                                    "{filter:?} {wrap:?} ({}, {}) lod {lod}: {g} vs {}",
                                    u[l],
                                    v[l],
                                    want[c]
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn refilling_matches_a_new_texture_and_reuses_memory() {
        let bytes: Vec<u32> = (0..12 * 5)
            .map(|i| 0x80c0_4020u32.wrapping_mul(i + 1))
            .collect();
        let fresh = Texture::from_packed(12, 5, bytes.clone(), Encoding::Srgb, true).unwrap();
        let mut t = Texture::checker(12, 3, Rgba::WHITE, Rgba::BLACK);
        assert!(t.refill(12, 5, Encoding::Srgb, true, |out| out
            .copy_from_slice(&bytes)));
        assert_eq!(t, fresh);
        let ptrs: Vec<*const u32> = t.levels.iter().map(|l| l.texels.as_ptr()).collect();
        assert!(t.refill(12, 5, Encoding::Srgb, true, |out| out.fill(7)));
        let again: Vec<*const u32> = t.levels.iter().map(|l| l.texels.as_ptr()).collect();
        assert_eq!(ptrs, again, "same size: same memory");
        assert!(!t.refill(0, 5, Encoding::Srgb, true, |_| {}));
        assert_eq!(t.width(), 12, "a refused refill changes nothing");
        // Shrinking drops levels; growing adds them.
        assert!(t.refill(2, 2, Encoding::Unorm, false, |out| out.fill(u32::MAX)));
        assert_eq!(t.levels().len(), 2);
        assert!(t.refill(16, 16, Encoding::Unorm, false, |out| out.fill(u32::MAX)));
        assert_eq!(t.levels().len(), 5);
    }

    #[test]
    fn odd_coordinates_do_not_panic() {
        let t = Texture::checker(8, 2, Rgba::WHITE, Rgba::BLACK);
        for s in [Filter::Nearest, Filter::Bilinear, Filter::Trilinear] {
            let smp = Sampler {
                filter: s,
                wrap_u: Wrap::Mirror,
                wrap_v: Wrap::Clamp,
            };
            for (u, v) in [(f32::NAN, 0.0), (1e30, -1e30), (f32::INFINITY, 0.5)] {
                let c = t.sample(&smp, u, v, f32::NAN);
                assert!(c.r.is_finite());
            }
        }
        assert!(Texture::from_rgba8(0, 4, &[], Encoding::Srgb).is_none());
        assert!(Texture::from_rgba8(2, 2, &[0; 15], Encoding::Srgb).is_none());
    }
}
