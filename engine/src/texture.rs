//! Textures and sampling: mip chains of RGBA8 texels, wrap modes, nearest / bilinear /
//! trilinear filtering.
//!
//! Texels are stored as bytes in an [`Encoding`] (sRGB for colour images, unorm for data
//! and for render-target read-backs in that encoding) and decoded to linear on every tap.
//! Filtering always happens on premultiplied linear colour, so transparent texels do not
//! bleed their colour; `premultiplied` says whether the stored bytes already are.
//! Sampling is pure and cannot fail: odd coordinates (NaN, huge) sample texel 0.

use crate::color::{srgb_to_linear_lut, unpack, Encoding, Premul, Rgba};
use std::sync::OnceLock;

/// How texture coordinates outside [0, 1] are folded back.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Wrap {
    #[default]
    Repeat,
    Clamp,
    Mirror,
}

/// Texture filtering.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Filter {
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
    pub wrap_u: Wrap,
    pub wrap_v: Wrap,
    pub filter: Filter,
}

/// One mip level: `width * height` packed texels, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct MipLevel {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<u32>,
}

/// An immutable texture with its mip chain (level 0 is the full image).
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    levels: Vec<MipLevel>,
    encoding: Encoding,
    premultiplied: bool,
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
        };
        t.build_mips();
        t
    }

    /// Box-filtered mip chain, averaged as premultiplied linear colour.
    fn build_mips(&mut self) {
        let enc = crate::color::Encoder::new(self.encoding);
        while let Some(prev) = self.levels.last() {
            if prev.width == 1 && prev.height == 1 {
                break;
            }
            let (w, h) = ((prev.width / 2).max(1), (prev.height / 2).max(1));
            let mut texels = Vec::with_capacity((w * h) as usize);
            for y in 0..h {
                for x in 0..w {
                    let mut acc = [0.0f32; 4];
                    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        let sx = (2 * x + dx).min(prev.width - 1);
                        let sy = (2 * y + dy).min(prev.height - 1);
                        let c = self.decode(prev.texels[(sy * prev.width + sx) as usize]);
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
                    let c = if self.premultiplied {
                        c.to_array()
                    } else {
                        c.unpremultiply().to_array()
                    };
                    texels.push(enc.pack(c[0], c[1], c[2], c[3]));
                }
            }
            self.levels.push(MipLevel {
                width: w,
                height: h,
                texels,
            });
        }
    }

    pub fn width(&self) -> u32 {
        self.levels[0].width
    }

    pub fn height(&self) -> u32 {
        self.levels[0].height
    }

    pub fn levels(&self) -> &[MipLevel] {
        &self.levels
    }

    pub fn encoding(&self) -> Encoding {
        self.encoding
    }

    /// One stored texel as premultiplied linear colour.
    #[inline]
    pub fn decode(&self, px: u32) -> Premul {
        if self.premultiplied {
            return unpack(self.encoding, px);
        }
        let lut = match self.encoding {
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
                let max = (self.levels.len() - 1) as f32;
                let lod = if lod.is_finite() {
                    lod.clamp(0.0, max)
                } else {
                    0.0
                };
                let l0 = lod.floor();
                let t = lod - l0;
                let a = self.bilinear(s, l0 as usize, u, v);
                if t <= 0.0 {
                    return a;
                }
                let b = self.bilinear(s, l0 as usize + 1, u, v);
                Premul {
                    r: a.r + (b.r - a.r) * t,
                    g: a.g + (b.g - a.g) * t,
                    b: a.b + (b.b - a.b) * t,
                    a: a.a + (b.a - a.a) * t,
                }
            }
        }
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

/// `floor` to a texel index; NaN and huge values give 0 so they cannot overflow.
#[inline]
fn texel_floor(x: f32) -> i64 {
    if x.is_finite() && x.abs() < 1e9 {
        x.floor() as i64
    } else {
        0
    }
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
