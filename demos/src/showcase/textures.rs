//! The showcase's generated textures: the wooden crate and the alpha-tested fence lattice.

use engine::procedural;
use engine::{Encoding, Texture};
use std::sync::Arc;

/// Builds a texture from a per-texel function returning straight sRGB bytes.
fn texture(size: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> Arc<Texture> {
    let mut bytes = Vec::with_capacity((size * size * 4) as usize);
    for y in 0..size {
        for x in 0..size {
            bytes.extend_from_slice(&f(x, y));
        }
    }
    Arc::new(Texture::from_rgba8(size, size, &bytes, Encoding::Srgb).expect("valid size"))
}

/// Wooden crate: planks with grain, a darker frame and diagonal brace.
pub fn crate_texture() -> Arc<Texture> {
    const N: u32 = 128;
    texture(N, |x, y| {
        let (u, v) = (x as f32 / N as f32, y as f32 / N as f32);
        let grain = procedural::value_noise(u * 3.0, v * 40.0, 11);
        let plank = ((v * 4.0).fract() < 0.04) as u8 as f32;
        let frame = !(0.1..=0.9).contains(&u) || !(0.1..=0.9).contains(&v);
        let brace = ((u - v).abs() < 0.07) && !frame;
        let mut c = [
            168.0 + 40.0 * grain,
            118.0 + 30.0 * grain,
            66.0 + 16.0 * grain,
        ];
        if frame || brace {
            c = [c[0] * 0.72, c[1] * 0.7, c[2] * 0.66];
        }
        if plank > 0.0 && !frame {
            c = [c[0] * 0.5, c[1] * 0.5, c[2] * 0.5];
        }
        [c[0] as u8, c[1] as u8, c[2] as u8, 255]
    })
}

/// Fence panel: a diagonal lattice inside a frame; the holes are transparent (alpha 0).
pub fn lattice_texture() -> Arc<Texture> {
    const N: u32 = 128;
    texture(N, |x, y| {
        let (u, v) = (x as f32 / N as f32, y as f32 / N as f32);
        let frame = !(0.06..=0.94).contains(&u) || !(0.08..=0.92).contains(&v);
        let d1 = ((u + v) * 5.0).fract();
        let d2 = ((u - v + 4.0) * 5.0).fract();
        let bar = d1 < 0.16 || d2 < 0.16;
        if frame || bar {
            let shade = 0.85 + 0.15 * procedural::value_noise(u * 20.0, v * 20.0, 3);
            let s = |c: f32| (c * shade) as u8;
            [s(205.0), s(200.0), s(185.0), 255]
        } else {
            [0, 0, 0, 0]
        }
    })
}
