//! Sampling against hand-worked values and the 8-lane sampler against the scalar one.

use super::*;
use crate::simd::F8;

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

/// The 8-lane sampler filters like the scalar one (to its byte tables'
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
        opaque_unorm(13, 7),
        Texture::from_packed(13, 7, premultiplied_bytes(13 * 7), Encoding::Unorm, true).unwrap(),
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
                    // Some lanes only: the kept ones unchanged, the others zero.
                    let keep = (round as u32 * 37 + 11) & 0xff;
                    let part = t.sample8_lanes(
                        &s,
                        F8::from_array(u),
                        F8::from_array(v),
                        lod,
                        crate::simd::M8::from_bits(keep),
                    );
                    for l in 0..8 {
                        for c in 0..4 {
                            let want = if keep >> l & 1 != 0 {
                                got[c].to_array()[l]
                            } else {
                                0.0
                            };
                            assert_eq!(part[c].to_array()[l].to_bits(), want.to_bits());
                        }
                    }
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
                                (g - want[c]).abs() <= rounding(t, c, want[c]),
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
    assert!(t.is_opaque(), "alpha 255 everywhere");
    assert!(t.refill(16, 16, Encoding::Unorm, false, |out| {
        out.fill(u32::MAX);
        out[37] = 0x00ff_ffff;
    }));
    assert!(!t.is_opaque(), "one clear texel");
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

/// An opaque unorm texture of odd size with texels that differ everywhere.
fn opaque_unorm(w: u32, h: u32) -> Texture {
    let texels = (0..w * h)
        .map(|i| (i.wrapping_mul(2_654_435_761u32.wrapping_mul(i + 1)) & 0x00ff_ffff) | 0xff00_0000)
        .collect();
    Texture::from_packed(w, h, texels, Encoding::Unorm, false).unwrap()
}

/// `n` premultiplied texels: every channel at most the texel's alpha.
fn premultiplied_bytes(n: u32) -> Vec<u32> {
    (0..n)
        .map(|i| {
            let a = (i * 37 + 20) % 256;
            let c = |k: u32| (i * k + 3) % (a + 1);
            c(11) | c(29) << 8 | c(53) << 16 | a << 24
        })
        .collect()
}

/// How far the 8-lane sampler may be from the scalar one in channel `c` (3 is alpha) of a
/// sample whose exact value is `want`: float rounding, plus, for the square-rooted tables
/// ([`Texture::squared`]), each root's rounding to a byte: a root off by at most half a
/// step, `0.5 / 255`, squares to at most `(sqrt(l) + 0.25 / 255) / 255` off a texel of
/// value `l`, and a weighted mean of texels stays below the same of the mean (the square
/// root is concave). A straight unorm texture with alpha is premultiplied into bytes,
/// within half a step.
fn rounding(t: &Texture, c: usize, want: f32) -> f32 {
    if t.squared && c < 3 {
        (want.max(0.0).sqrt() + 0.5 / 255.0) / 255.0 + 1e-5
    } else if !(t.premultiplied || t.opaque) && c < 3 {
        0.5 / 255.0 + 1e-5
    } else {
        1e-5
    }
}

/// The byte sampler against the scalar one (which reads the stored texels through the
/// encoding's table, the independent path), for stored bytes (unorm, premultiplied or
/// opaque), square-rooted ones (premultiplied sRGB, straight sRGB with alpha) and
/// premultiplied ones (straight unorm with alpha): at and between every texel of every level of odd sizes (13 x 7 down to 1 x 1),
/// across the edges, the blocks' seams (where a row's two taps are not read in one
/// gather) and a period beyond, in every wrap mode, bilinear and trilinear, all lanes and
/// some (the others zero).
#[test]
fn byte_taps_match_the_scalar_sampler() {
    let straight: Vec<u8> = premultiplied_bytes(13 * 7)
        .iter()
        .flat_map(|px| px.wrapping_mul(2_654_435_761).to_le_bytes())
        .collect();
    let textures = [
        opaque_unorm(13, 7),
        Texture::from_packed(13, 7, premultiplied_bytes(13 * 7), Encoding::Unorm, true).unwrap(),
        opaque_unorm(5, 1),
        Texture::from_packed(13, 7, premultiplied_bytes(13 * 7), Encoding::Srgb, true).unwrap(),
        Texture::from_rgba8(13, 7, &straight, Encoding::Srgb).unwrap(),
        Texture::from_rgba8(13, 7, &straight, Encoding::Unorm).unwrap(),
    ];
    for (n, t) in textures.iter().enumerate() {
        assert_eq!(t.squared, (3..5).contains(&n), "texture {n}");
        for (level, l) in t.levels().iter().enumerate() {
            let (w, h) = (l.width as f32, l.height as f32);
            // Texel centres and corners from one texel before the level to one after, then
            // a whole period further out.
            let xs: Vec<f32> = (-2..=2 * l.width as i32 + 2)
                .map(|k| k as f32 * 0.5 / w)
                .chain([1.0 + 0.25 / w, -1.0 - 0.75 / w])
                .collect();
            let ys: Vec<f32> = (-2..=2 * l.height as i32 + 2)
                .map(|k| k as f32 * 0.5 / h)
                .chain([2.0 + 0.5 / h])
                .collect();
            for filter in [Filter::Bilinear, Filter::Trilinear] {
                for (wrap_u, wrap_v) in [
                    (Wrap::Repeat, Wrap::Repeat),
                    (Wrap::Clamp, Wrap::Clamp),
                    (Wrap::Mirror, Wrap::Mirror),
                    (Wrap::Repeat, Wrap::Clamp),
                ] {
                    let s = Sampler {
                        filter,
                        wrap_u,
                        wrap_v,
                    };
                    for &y in &ys {
                        for (n, xs8) in xs.chunks(8).enumerate() {
                            let u: [f32; 8] = std::array::from_fn(|k| xs8[k % xs8.len()]);
                            let keep = [0xff, 0x5a, 0x81][n % 3];
                            let mask = crate::simd::M8::from_bits(keep);
                            for lod in [level as f32, level as f32 + 0.5] {
                                let got =
                                    t.sample8_lanes(&s, F8::from_array(u), F8::splat(y), lod, mask);
                                for k in 0..8 {
                                    let want = t.sample(&s, u[k], y, lod).to_array();
                                    for c in 0..4 {
                                        let g = got[c].to_array()[k];
                                        if keep >> k & 1 == 0 {
                                            assert_eq!(g, 0.0);
                                            continue;
                                        }
                                        assert!(
                                            (g - want[c]).abs() <= rounding(t, c, want[c]),
                                            "{filter:?} {wrap_u:?}/{wrap_v:?} level {level} \
                                             ({}, {y}) lod {lod} channel {c}: {g} vs {}",
                                            u[k],
                                            want[c]
                                        );
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn pair_tables_hold_every_texel_and_the_one_below() {
    // Odd sizes, a row, a column, a power of two; straight sRGB with
    // alpha and premultiplied sRGB (square roots), straight unorm (premultiplied into
    // bytes), premultiplied and opaque unorm (the stored bytes).
    let sizes = [(13, 7), (1, 9), (17, 1), (16, 16), (5, 6)];
    for (w, h) in sizes {
        let bytes: Vec<u8> = (0..w * h * 4)
            .map(|i| ((i * 97 + i / 5 * 31) % 256) as u8)
            .collect();
        let packed: Vec<u32> = bytes
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        let textures = [
            Texture::from_rgba8(w, h, &bytes, Encoding::Srgb).unwrap(),
            Texture::from_packed(w, h, packed, Encoding::Srgb, true).unwrap(),
            Texture::from_rgba8(w, h, &bytes, Encoding::Unorm).unwrap(),
            Texture::from_packed(w, h, premultiplied_bytes(w * h), Encoding::Unorm, true).unwrap(),
            opaque_unorm(w, h),
        ];
        for t in &textures {
            let root = |x: f32| (x.clamp(0.0, 1.0).sqrt() * 255.0).round() as u32;
            let byte = |x: f32| (x.clamp(0.0, 1.0) * 255.0).round() as u32;
            for (k, (lin, l)) in t.linear.iter().zip(t.levels()).enumerate() {
                let first = lin.bytes.as_ptr().wrapping_add(lin.base as usize) as usize;
                assert_eq!(first % 64, 0, "entries start on a cache line");
                let mut seen = vec![false; lin.bytes.len()];
                let want = |x: u32, y: u32| {
                    let stored = l.texels[(y * l.width + x) as usize];
                    let c = t.texel(k, x, y);
                    if t.squared {
                        root(c.r) | root(c.g) << 8 | root(c.b) << 16 | stored & 0xff00_0000
                    } else if t.premultiplied || t.opaque {
                        stored
                    } else {
                        byte(c.r) | byte(c.g) << 8 | byte(c.b) << 16 | stored & 0xff00_0000
                    }
                };
                for y in 0..l.height {
                    // One entry past the row: its last texel again.
                    for x in 0..=l.width {
                        let i = lin.index(x, y);
                        let (xs, below) = (x.min(l.width - 1), (y + 1).min(l.height - 1));
                        let at = format!("{w}x{h} level {k} ({x}, {y})");
                        assert_eq!(lin.bytes[i], want(xs, y), "{at}");
                        assert_eq!(lin.bytes[i + 1], want(xs, below), "{at}, below");
                        assert!(!seen[i] && !seen[i + 1], "two entries at {i}");
                        (seen[i], seen[i + 1]) = (true, true);
                    }
                }
                // The 8-lane index (what the loads read) is the scalar one.
                for y in 0..l.height {
                    for x0 in (0..l.width).step_by(8) {
                        let xs: [i32; 8] =
                            std::array::from_fn(|j| (x0 + j as u32).min(l.width - 1) as i32);
                        let got = t
                            .index8(
                                k,
                                crate::simd::I8::from_array(xs),
                                crate::simd::I8::splat(y as i32),
                            )
                            .to_array();
                        for j in 0..8 {
                            assert_eq!(got[j] as usize, lin.index(xs[j] as u32, y));
                        }
                    }
                }
            }
        }
    }
}
