//! Times the 8-lane texture sampler alone (`Texture::sample8`, trilinear, clamped) on a
//! 3072 x 2304 straight sRGB texture with alpha (the size of the showcase's forest atlas;
//! sRGB images take the sampler's 16-bit copy): rows of 8 samples `STEP` texels apart (the level of detail `log2(STEP)`), either
//! sweeping the whole texture in order or, with a second argument, in 8 x 8 blocks at
//! scattered places (sprites spread over an atlas, the cache- and TLB-missing case). Prints
//! the best of 7 passes in ns a sample.
//!
//! With the word `bytes`, the texture is premultiplied unorm instead, the kind of the forest's
//! atlas (`ibr` billboards' `ViewAtlas`, read back from a render target) and, being opaque,
//! of the peers' textured torus: the sampler then reads the stored bytes, 4 a texel, rather
//! than the 16-bit copy.
//!
//! `cargo run --release -p engine --example texbench -- [STEP [scattered] [bytes]]` (any
//! word other than `bytes` after STEP means scattered)
use engine::simd::F8;
use engine::{Encoding, Sampler, Texture};
use std::time::Instant;

fn main() -> Result<(), String> {
    let (w, h) = (3072u32, 2304u32);
    let mut s = 0x1234_5678u32;
    let mut rgba = vec![0u8; (w * h * 4) as usize];
    for (i, p) in rgba.chunks_exact_mut(4).enumerate() {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        let x = (i as u32 % w) / 37 + (i as u32 / w) / 29;
        p.copy_from_slice(&[
            (x * 7) as u8,
            (x * 13) as u8,
            (s >> 24) as u8,
            if x.is_multiple_of(3) { 0 } else { 255 },
        ]);
    }
    let words: Vec<String> = std::env::args().skip(2).collect();
    let bytes = words.iter().any(|a| a == "bytes");
    let scattered = words.iter().any(|a| a != "bytes");
    let tex = if bytes {
        let premul = rgba
            .chunks_exact(4)
            .map(|c| {
                let a = u32::from(c[3]);
                let p = |x: u8| (u32::from(x) * a + 127) / 255;
                p(c[0]) | p(c[1]) << 8 | p(c[2]) << 16 | a << 24
            })
            .collect();
        Texture::from_packed(w, h, premul, Encoding::Unorm, true)
    } else {
        Texture::from_rgba8(w, h, &rgba, Encoding::Srgb)
    }
    .ok_or("texture size")?;
    let sampler = Sampler {
        wrap_u: engine::Wrap::Clamp,
        wrap_v: engine::Wrap::Clamp,
        filter: engine::Filter::Trilinear,
    };
    let step: f32 = match std::env::args().nth(1) {
        Some(a) => a.parse().map_err(|e| format!("STEP {a}: {e}"))?,
        None => 1.5,
    };
    if !(step.is_finite() && step > 0.0) {
        return Err(format!("STEP {step}: a positive number of texels"));
    }
    let lod = step.log2();
    let mut best = f64::MAX;
    let mut sum = 0.0f32;
    for _ in 0..7 {
        let t0 = Instant::now();
        let mut n = 0usize;
        if scattered {
            // 8x8-pixel blocks of sprites at scattered places of the atlas.
            for _ in 0..60000 {
                s ^= s << 13;
                s ^= s >> 17;
                s ^= s << 5;
                let u0 = (s % (w - 64)) as f32;
                let v0 = ((s >> 12) % (h - 64)) as f32;
                for y in 0..8 {
                    let v = F8::splat((v0 + (y as f32 + 0.5) * step) / h as f32);
                    let u = F8::from_array(std::array::from_fn(|l| {
                        (u0 + (l as f32 + 0.5) * step) / w as f32
                    }));
                    let r = tex.sample8(&sampler, u, v, lod);
                    sum += r[0].to_array()[0] + r[3].to_array()[5];
                    n += 8;
                }
            }
        } else {
            let (nx, ny) = ((w as f32 / step) as usize, (h as f32 / step) as usize);
            for y in 0..ny {
                let v = F8::splat((y as f32 + 0.5) * step / h as f32);
                for x0 in (0..nx).step_by(8) {
                    let u = F8::from_array(std::array::from_fn(|l| {
                        ((x0 + l) as f32 + 0.5) * step / w as f32
                    }));
                    let r = tex.sample8(&sampler, u, v, lod);
                    sum += r[0].to_array()[0] + r[3].to_array()[5];
                    n += 8;
                }
            }
        }
        let dt = t0.elapsed().as_secs_f64() * 1e9 / n as f64;
        best = best.min(dt);
    }
    let kind = if bytes { "bytes" } else { "16-bit" };
    println!("step {step} lod {lod:.2} {kind}: best {best:.2} ns/sample ({sum})");
    Ok(())
}
