//! Colour types and transfer functions.
//!
//! Inside the engine colours are linear. [`Rgba`] is straight (not premultiplied) linear
//! colour, as materials and vertices carry it; [`Premul`] is premultiplied linear colour, as
//! the shading and blending stages carry it. The two are different types so they cannot be
//! mixed up. Bytes leave the engine either sRGB-encoded ([`Encoding::Srgb`], the default, like
//! a GPU's `SRGB8_ALPHA8` target) or as plain unorm bytes ([`Encoding::Unorm`], like `RGBA8`).

use std::sync::OnceLock;

/// Straight (non-premultiplied) linear RGBA colour.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Rgba {
    /// Red, linear; 0..1 for displayable colours (larger values are allowed and clamp on
    /// output).
    pub r: f32,
    /// Green, linear, as `r`.
    pub g: f32,
    /// Blue, linear, as `r`.
    pub b: f32,
    /// Coverage / opacity, 0 (transparent) to 1 (opaque); never gamma-encoded.
    pub a: f32,
}

/// Premultiplied linear RGBA colour: `r, g, b <= a` for well-formed values.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Premul {
    /// Red, linear, already multiplied by `a`.
    pub r: f32,
    /// Green, linear, already multiplied by `a`.
    pub g: f32,
    /// Blue, linear, already multiplied by `a`.
    pub b: f32,
    /// Coverage / opacity, 0 to 1.
    pub a: f32,
}

impl Rgba {
    /// Opaque black.
    pub const BLACK: Rgba = Rgba::new(0.0, 0.0, 0.0, 1.0);
    /// Opaque white (linear 1.0, which is also sRGB byte 255).
    pub const WHITE: Rgba = Rgba::new(1.0, 1.0, 1.0, 1.0);
    /// Transparent black, alpha 0.
    pub const TRANSPARENT: Rgba = Rgba::new(0.0, 0.0, 0.0, 0.0);

    /// A colour from straight linear components (not sRGB: use [`Rgba::from_srgb8`] for
    /// colour-picker values).
    pub const fn new(r: f32, g: f32, b: f32, a: f32) -> Self {
        Rgba { r, g, b, a }
    }

    /// An opaque colour from sRGB-encoded bytes (as colour pickers give them).
    pub fn from_srgb8(r: u8, g: u8, b: u8) -> Self {
        let lut = srgb_to_linear_lut();
        Rgba::new(lut[r as usize], lut[g as usize], lut[b as usize], 1.0)
    }

    /// The premultiplied colour: `r, g, b` multiplied by `a`.
    pub fn premultiply(self) -> Premul {
        Premul {
            r: self.r * self.a,
            g: self.g * self.a,
            b: self.b * self.a,
            a: self.a,
        }
    }

    /// `[r, g, b, a]`, straight linear.
    pub fn to_array(self) -> [f32; 4] {
        [self.r, self.g, self.b, self.a]
    }

    /// From `[r, g, b, a]`, straight linear (the inverse of [`Rgba::to_array`]).
    pub fn from_array(c: [f32; 4]) -> Self {
        Rgba::new(c[0], c[1], c[2], c[3])
    }
}

impl Premul {
    /// Transparent black: all components 0, the identity of "over" blending.
    pub const TRANSPARENT: Premul = Premul {
        r: 0.0,
        g: 0.0,
        b: 0.0,
        a: 0.0,
    };

    /// Back to straight colour; fully transparent pixels become transparent black.
    pub fn unpremultiply(self) -> Rgba {
        if self.a > 0.0 {
            let inv = 1.0 / self.a;
            Rgba::new(self.r * inv, self.g * inv, self.b * inv, self.a)
        } else {
            Rgba::TRANSPARENT
        }
    }

    /// `[r, g, b, a]`, premultiplied linear.
    pub fn to_array(self) -> [f32; 4] {
        [self.r, self.g, self.b, self.a]
    }
}

/// How linear colour becomes bytes when a render target is resolved.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Encoding {
    /// sRGB transfer function on RGB, alpha linear (a GPU's `SRGB8_ALPHA8`).
    #[default]
    Srgb,
    /// Plain unorm bytes: `round(clamp(x) * 255)` (a GPU's `RGBA8`). The `render` CLI uses
    /// it for the peer-comparison shadings so bytes match llvmpipe's.
    Unorm,
}

/// The exact sRGB decode of one channel.
pub fn srgb_to_linear(x: f32) -> f32 {
    if x <= 0.04045 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// The exact sRGB encode of one channel (input clamped to [0, 1]).
pub fn linear_to_srgb(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.003_130_8 {
        x * 12.92
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// Table: sRGB byte -> linear value.
pub fn srgb_to_linear_lut() -> &'static [f32; 256] {
    static LUT: OnceLock<[f32; 256]> = OnceLock::new();
    LUT.get_or_init(|| std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0)))
}

/// Size of the encode table: linear values are quantised to 16 bits before the lookup,
/// which keeps every byte's decode -> encode round trip exact (see the tests).
const ENCODE_BITS: u32 = 16;
const ENCODE_SIZE: usize = 1 << ENCODE_BITS;

fn encode_lut() -> &'static [u8] {
    static LUT: OnceLock<Vec<u8>> = OnceLock::new();
    LUT.get_or_init(|| {
        (0..ENCODE_SIZE)
            .map(|i| {
                let x = i as f32 / (ENCODE_SIZE - 1) as f32;
                (linear_to_srgb(x) * 255.0 + 0.5) as u8
            })
            .collect()
    })
}

/// The encode table's bytes four to a word (little-endian: byte `i` of the table is bits
/// `8 * (i % 4)..` of word `i / 4`), for [`Encoder::pack8`]'s gathers.
fn encode_words() -> &'static [u32] {
    static WORDS: OnceLock<Vec<u32>> = OnceLock::new();
    WORDS.get_or_init(|| {
        encode_lut()
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect()
    })
}

/// Encodes one linear channel to an sRGB byte (clamps; NaN gives 0).
#[inline]
pub fn encode_srgb8(x: f32) -> u8 {
    let lut = encode_lut();
    let i = (x.clamp(0.0, 1.0) * (ENCODE_SIZE - 1) as f32 + 0.5) as usize;
    lut[i.min(ENCODE_SIZE - 1)]
}

/// Encodes one linear channel to a unorm byte (clamps; NaN gives 0).
#[inline]
pub fn encode_unorm8(x: f32) -> u8 {
    (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

/// A table-driven encoder, fetched once per resolve so the hot loop holds a plain slice.
#[derive(Clone, Copy, Debug)]
pub struct Encoder {
    encoding: Encoding,
    lut: &'static [u8],
    /// `lut` four bytes to a word, for the 8-lane gathers.
    words: &'static [u32],
}

impl Encoder {
    /// An encoder producing bytes in `encoding` (builds the shared sRGB table on first use).
    pub fn new(encoding: Encoding) -> Self {
        Encoder {
            encoding,
            lut: encode_lut(),
            words: encode_words(),
        }
    }

    /// Premultiplied linear colour to packed bytes `r | g << 8 | b << 16 | a << 24`
    /// (premultiplied, in the target's encoding; alpha is always unorm).
    #[inline]
    pub fn pack(&self, r: f32, g: f32, b: f32, a: f32) -> u32 {
        let (r, g, b) = match self.encoding {
            Encoding::Srgb => {
                let m = (ENCODE_SIZE - 1) as f32;
                let idx = |x: f32| ((x.clamp(0.0, 1.0) * m + 0.5) as usize).min(ENCODE_SIZE - 1);
                (self.lut[idx(r)], self.lut[idx(g)], self.lut[idx(b)])
            }
            Encoding::Unorm => (encode_unorm8(r), encode_unorm8(g), encode_unorm8(b)),
        };
        u32::from_le_bytes([r, g, b, encode_unorm8(a)])
    }
}

impl Encoder {
    /// Packs 8 pixels at once: `out[l] = pack(r[l], g[l], b[l], a[l])`, bit for bit.
    #[inline]
    pub fn pack8(&self, r: &[f32], g: &[f32], b: &[f32], a: &[f32], out: &mut [u32]) {
        use crate::simd::{F8, I8, M8};
        let unorm = |x: &[f32]| {
            F8::load(x)
                .clamp01()
                .mul_add(F8::splat(255.0), F8::splat(0.5))
                .to_i32()
        };
        let alpha = unorm(a).shl::<24>();
        let rgb = match self.encoding {
            Encoding::Unorm => unorm(r).or(unorm(g).shl::<8>()).or(unorm(b).shl::<16>()),
            Encoding::Srgb => {
                // The table's byte for each lane: one gather of the word holding it, then
                // a shift by its place in the word (24 scalar loads before: the resolve
                // was 12% of the textured torus frame). The index is the scalar path's,
                // `as usize` then `min`, negative lanes included.
                let (m, last) = ((ENCODE_SIZE - 1) as f32, I8::splat(ENCODE_SIZE as i32 - 1));
                let words = self.words;
                let at = |x: &[f32]| {
                    let i = F8::load(x)
                        .clamp01()
                        .mul_add(F8::splat(m), F8::splat(0.5))
                        .to_i32();
                    let i = i.non_negative().select_i32(i, last).min(last);
                    let w = I8::gather_u32_lanes(words, i.shr::<2>(), M8::from_bits(0xff));
                    w.shr_by(i.and(I8::splat(3)).shl::<3>())
                        .and(I8::splat(0xff))
                };
                at(r).or(at(g).shl::<8>()).or(at(b).shl::<16>())
            }
        };
        let px = rgb.or(alpha).to_array();
        for l in 0..8 {
            out[l] = px[l] as u32;
        }
    }
}

/// Packed target bytes back to premultiplied linear colour.
#[inline]
pub fn unpack(encoding: Encoding, px: u32) -> Premul {
    let [r, g, b, a] = px.to_le_bytes();
    match encoding {
        Encoding::Srgb => {
            let lut = srgb_to_linear_lut();
            Premul {
                r: lut[r as usize],
                g: lut[g as usize],
                b: lut[b as usize],
                a: a as f32 / 255.0,
            }
        }
        Encoding::Unorm => Premul {
            r: r as f32 / 255.0,
            g: g as f32 / 255.0,
            b: b as f32 / 255.0,
            a: a as f32 / 255.0,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_srgb_byte_round_trips_through_linear() {
        let lut = srgb_to_linear_lut();
        for k in 0..=255u8 {
            assert_eq!(encode_srgb8(lut[k as usize]), k, "byte {k}");
            assert_eq!(encode_unorm8(k as f32 / 255.0), k);
        }
    }

    #[test]
    fn encode_is_monotonic_and_clamps() {
        let mut last = 0;
        for i in 0..=1000 {
            let v = encode_srgb8(i as f32 / 1000.0);
            assert!(v >= last);
            last = v;
        }
        assert_eq!(encode_srgb8(-1.0), 0);
        assert_eq!(encode_srgb8(7.0), 255);
        assert_eq!(encode_srgb8(f32::NAN), 0);
        assert_eq!(encode_unorm8(f32::NAN), 0);
    }

    #[test]
    fn encode_matches_exact_curve_within_half_a_step() {
        for i in 0..=4096 {
            let x = i as f32 / 4096.0;
            let exact = linear_to_srgb(x) * 255.0;
            assert!((encode_srgb8(x) as f32 - exact).abs() <= 0.51, "{x}");
        }
    }

    #[test]
    fn pack8_matches_pack_bit_for_bit() {
        let vals = [
            0.0,
            1e-5,
            0.003,
            0.2,
            0.5,
            0.999,
            1.0,
            3.0,
            -2.0,
            f32::NAN,
            f32::INFINITY,
        ];
        for enc in [Encoding::Srgb, Encoding::Unorm] {
            let e = Encoder::new(enc);
            for (i, &x) in vals.iter().enumerate() {
                let ch = |k: usize| vals[(i + k) % vals.len()];
                let (r, g, b, a) = ([x; 8], [ch(1); 8], [ch(2); 8], [ch(3); 8]);
                let mut out = [0u32; 8];
                e.pack8(&r, &g, &b, &a, &mut out);
                assert_eq!(out[3], e.pack(x, ch(1), ch(2), ch(3)), "{enc:?} {x}");
            }
        }
    }

    /// Every entry of the sRGB table, and the values between entries, reached by the gathers
    /// of `pack8` as by `pack`, in every lane and channel.
    #[test]
    fn pack8_matches_pack_across_the_table() {
        let e = Encoder::new(Encoding::Srgb);
        let n = ENCODE_SIZE as f32 - 1.0;
        let xs: Vec<f32> = (0..2 * ENCODE_SIZE as u32 + 16)
            .map(|i| i as f32 / (2.0 * n) - 1e-4)
            .collect();
        for w in xs.chunks_exact(8) {
            let (r, g, b) = (
                w,
                &w.iter().rev().copied().collect::<Vec<_>>()[..],
                &[w[3]; 8],
            );
            let mut out = [0u32; 8];
            e.pack8(r, g, b, w, &mut out);
            for l in 0..8 {
                assert_eq!(out[l], e.pack(r[l], g[l], b[l], w[l]), "{}", r[l]);
            }
        }
    }

    #[test]
    fn premultiply_round_trip() {
        let c = Rgba::new(0.2, 0.4, 0.8, 0.5);
        let back = c.premultiply().unpremultiply();
        assert!((back.r - c.r).abs() < 1e-6 && (back.b - c.b).abs() < 1e-6);
        assert_eq!(Premul::TRANSPARENT.unpremultiply(), Rgba::TRANSPARENT);
    }
}
