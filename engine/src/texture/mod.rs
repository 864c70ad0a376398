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

mod lanes;

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
    /// Every level laid out for the 8-lane sampler ([`Texture::sample8`]), 4 bytes a texel
    /// in blocks: the stored bytes themselves, or their square roots (`squared`).
    linear: Vec<LinearLevel>,
    /// Every texel of level 0 has alpha 255 (so every level's does).
    opaque: bool,
    /// How the 8-lane sampler's bytes hold premultiplied linear colour. `false`, for unorm
    /// textures: the byte over 255, the stored bytes themselves when they are premultiplied
    /// already (or opaque, where straight is premultiplied), else the stored colour times
    /// alpha rounded to a byte (within half a step, as unorm bytes are). `true`, for sRGB
    /// textures: each channel's premultiplied linear value `c` as `round(255 sqrt(c))`
    /// (alpha as stored), squared when read. Like sRGB, the square root spends the 8 bits
    /// where the eye tells levels apart; a sample is within `(sqrt(c) + 0.002) / 255` of
    /// the stored texels' exact linear value (the scalar [`Texture::sample`]'s: at most
    /// 0.64 of a step of the sRGB bytes, 0.28 on average over the 256), and a tap is 4
    /// bytes, a bilinear tap-set one 16-byte read (a 16-bit linear copy read 8 bytes a
    /// texel, one gather each).
    squared: bool,
}

/// One level laid out for the 8-lane sampler: `bytes`, 4 a texel (`r | g << 8 | b << 16 |
/// a << 24`, as [`Texture::squared`] says), in entries of two words, texel `(x, y)` and the
/// one below it `(x, y + 1)` (the last row's own again), row-major, a row of `stride`
/// entries (one more than the level's width: the last is its row's last texel again, so
/// that the entry after any texel's is in the table). A bilinear tap-set, texels `(x, y)`,
/// `(x, y + 1)`, `(x + 1, y)`, `(x + 1, y + 1)`, is then the 16 bytes of two neighbouring
/// entries, one load a lane ([`crate::simd::I8::load_quads`]) instead of four gathers;
/// the first entry starts on a 64-byte boundary. Only the addresses differ from a
/// row-major table: the same texels are read and weighed, so samples are the same bit for
/// bit.
#[derive(Clone, Debug, Default)]
struct LinearLevel {
    bytes: Vec<u32>,
    /// Entries in one row: the level's width plus one.
    stride: u32,
    /// Where the first entry starts in the table: on a 64-byte boundary.
    base: u32,
}

/// Equal when the same texels are stored, wherever the allocation put the first entry.
impl PartialEq for LinearLevel {
    fn eq(&self, o: &Self) -> bool {
        self.stride == o.stride && unpadded(&self.bytes, self.base) == unpadded(&o.bytes, o.base)
    }
}

/// The entries of a table without the alignment padding (`PAD` words, `base` before).
fn unpadded<T>(table: &[T], base: u32) -> &[T] {
    let n = table.len().saturating_sub(PAD);
    &table[(base as usize).min(table.len())..][..n]
}

/// Words added to a table so that its first entry can start on a cache line (16 of 4
/// bytes).
const PAD: usize = 15;

impl LinearLevel {
    /// The word where texel `(x, y)` is stored (the one below it follows): the scalar
    /// statement of the layout that `fill_pairs` writes and `Texture::index8` reads, held
    /// to both by the tests.
    #[cfg(test)]
    fn index(&self, x: u32, y: u32) -> usize {
        (self.base + 2 * (y * self.stride + x)) as usize
    }
}

/// A cleared `table` of `len` words plus [`PAD`], and the word at which the entries start:
/// the first on a 64-byte boundary (the address is only looked at, never made into a
/// pointer).
fn aligned(table: &mut Vec<u32>, len: usize) -> u32 {
    table.clear();
    table.resize(len + PAD, 0);
    ((64 - table.as_ptr() as usize % 64) % 64 / size_of::<u32>()) as u32
}

/// Writes `level`'s texels, each through `f` once, into the entries of `table` from word
/// `base` on (see [`LinearLevel`]): each texel and the one below it, a row of `width + 1`
/// entries, in the table's order.
fn fill_pairs(table: &mut [u32], base: u32, level: &MipLevel, f: impl Fn(u32) -> u32) {
    let (w, h) = (level.width as usize, level.height as usize);
    let (base, stride) = (base as usize, w + 1);
    // Each entry's first word, row by row; then its second, the first of the entry below.
    for (y, texels) in level.texels.chunks_exact(w).take(h).enumerate() {
        let row = &mut table[base + 2 * y * stride..][..2 * stride];
        for (entry, &px) in row.chunks_exact_mut(2).zip(texels) {
            entry[0] = f(px);
        }
        row[2 * w] = row[2 * w - 2];
    }
    for y in 0..h {
        let below = base + 2 * (y + 1).min(h - 1) * stride;
        let at = base + 2 * y * stride;
        for x in 0..stride {
            table[at + 2 * x + 1] = table[below + 2 * x];
        }
    }
}

/// The largest texture side accepted; larger images are refused by the loaders.
pub const MAX_TEXTURE_SIZE: u32 = 16384;

fn unorm_lut() -> &'static [f32; 256] {
    static LUT: OnceLock<[f32; 256]> = OnceLock::new();
    LUT.get_or_init(|| std::array::from_fn(|i| i as f32 / 255.0))
}

/// For each sRGB byte, the square root of its linear value in bytes (the 8-lane sampler's
/// `squared` table, [`Texture::squared`]).
fn srgb_roots() -> &'static [u8; 256] {
    static LUT: OnceLock<[u8; 256]> = OnceLock::new();
    LUT.get_or_init(|| {
        let lin = srgb_to_linear_lut();
        std::array::from_fn(|i| (lin[i].clamp(0.0, 1.0).sqrt() * 255.0).round() as u8)
    })
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
            opaque: false,
            squared: false,
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
    /// the 8-lane sampler's tables from level 0, reusing the existing levels' memory.
    fn rebuild(&mut self) {
        let (encoding, premultiplied) = (self.encoding, self.premultiplied);
        self.opaque = self.levels[0].texels.iter().all(|&px| px >> 24 == 0xff);
        self.squared = encoding == Encoding::Srgb;
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
        self.build_linear();
    }

    /// Every level's table for the 8-lane sampler, in pairs of rows ([`LinearLevel`]): the
    /// stored bytes, or their square roots when `squared` (see [`Texture::squared`]).
    fn build_linear(&mut self) {
        let (encoding, premultiplied, squared) = (self.encoding, self.premultiplied, self.squared);
        self.linear
            .resize_with(self.levels.len(), LinearLevel::default);
        let roots = srgb_roots();
        for (lin, level) in self.linear.iter_mut().zip(&self.levels) {
            lin.stride = level.width + 1;
            let len = 2 * lin.stride as usize * level.height as usize;
            lin.base = aligned(&mut lin.bytes, len);
            if !squared && (premultiplied || self.opaque) {
                fill_pairs(&mut lin.bytes, lin.base, level, |px| px);
            } else if !squared {
                fill_pairs(&mut lin.bytes, lin.base, level, |px| {
                    let c = decode(encoding, premultiplied, px);
                    let byte = |x: f32| (x.clamp(0.0, 1.0) * 255.0).round() as u32;
                    byte(c.r) | byte(c.g) << 8 | byte(c.b) << 16 | px & 0xff00_0000
                });
            } else if premultiplied {
                // A premultiplied sRGB byte is its channel's linear value: one table look-up.
                fill_pairs(&mut lin.bytes, lin.base, level, |px| {
                    let [r, g, b, a] = px.to_le_bytes();
                    let root = |c: u8| u32::from(roots[c as usize]);
                    root(r) | root(g) << 8 | root(b) << 16 | u32::from(a) << 24
                });
            } else {
                fill_pairs(&mut lin.bytes, lin.base, level, |px| {
                    let c = decode(encoding, premultiplied, px);
                    let root = |x: f32| (x.clamp(0.0, 1.0).sqrt() * 255.0).round() as u32;
                    root(c.r) | root(c.g) << 8 | root(c.b) << 16 | px & 0xff00_0000
                });
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

    /// Whether every texel has alpha 1: samples then have alpha 1 (to rounding) and
    /// premultiplied colour equal to straight colour, so a shader need not divide by alpha.
    pub fn is_opaque(&self) -> bool {
        self.opaque
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
mod tests;
