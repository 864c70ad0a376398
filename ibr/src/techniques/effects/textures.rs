//! The effects' textures, generated at start-up from value noise: an explosion sprite sheet,
//! a smoke puff and a spark. Straight alpha; every image fades to zero alpha well inside its
//! (cell) border, so quads, bilinear taps and mip levels show no hard edges.

use engine::color::encode_srgb8;
use engine::procedural::value_noise;
use engine::{Encoding, Texture};
use glam::Vec2;

fn smoothstep(lo: f32, hi: f32, x: f32) -> f32 {
    let t = ((x - lo) / (hi - lo)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Three octaves of value noise, in [0, 1].
fn fbm(p: Vec2, seed: u64) -> f32 {
    let mut sum = 0.0;
    let mut amp = 0.5;
    let mut freq = 1.0;
    for octave in 0..3u64 {
        sum += amp * value_noise(p.x * freq, p.y * freq, seed.wrapping_add(octave));
        amp *= 0.5;
        freq *= 2.0;
    }
    sum / 0.875
}

/// Fades alpha to zero between radius 0.85 and 0.95 (half-size units), so a cell's
/// outermost pixels (radius >= 0.98 for 64-pixel cells) are fully transparent.
fn rim(r: f32) -> f32 {
    1.0 - smoothstep(0.85, 0.95, r)
}

/// Offset of pixel `(x, y)` of a `size` square from its centre, in half-size units.
fn centred(x: u32, y: u32, size: u32) -> Vec2 {
    let half = size as f32 * 0.5;
    Vec2::new(x as f32 + 0.5 - half, y as f32 + 0.5 - half) / half
}

/// Fire colour (linear) for a heat in [0, 1]: smoke, dark red, orange, yellow, white-yellow.
fn fire_ramp(heat: f32) -> [f32; 3] {
    const STOPS: [[f32; 3]; 5] = [
        [0.05, 0.045, 0.04],
        [0.35, 0.05, 0.01],
        [1.0, 0.25, 0.03],
        [1.0, 0.65, 0.15],
        [1.0, 0.95, 0.75],
    ];
    let x = heat.clamp(0.0, 1.0) * (STOPS.len() - 1) as f32;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let t = x - i as f32;
    std::array::from_fn(|c| STOPS[i][c] + (STOPS[i + 1][c] - STOPS[i][c]) * t)
}

/// One explosion frame at time `t` in [0, 1]: straight linear colour and alpha of the pixel
/// at `p` (half-size units from the cell centre).
fn fireball(p: Vec2, t: f32, seed: u64) -> ([f32; 3], f32) {
    let r = p.length();
    // The ball grows quickly, then slows; its turbulence grows with it and drifts upward.
    let radius = 0.35 + 0.5 * t.sqrt();
    let q = p / radius * 2.2 + Vec2::new(0.7 * t, 1.6 * t);
    let warp = Vec2::new(
        fbm(q + Vec2::splat(5.2), seed),
        fbm(q + Vec2::splat(9.7), seed),
    );
    let n = fbm(q + (warp - 0.5) * 1.6, seed);
    let edge = radius * (0.7 + 0.6 * n);
    let mut density = 1.0 - smoothstep(edge * 0.7, edge, r);
    // Late frames break up into wisps.
    density *= 1.0 + t * (n * 1.2 - 0.6);
    let core = (1.0 - r / radius).clamp(0.0, 1.0);
    let heat = 0.9 - 1.6 * t + 0.6 * core + 0.5 * (n - 0.5);
    let alpha = density.clamp(0.0, 1.0)
        * (0.8 + 0.2 * heat.clamp(0.0, 1.0))
        * (1.0 - 0.6 * smoothstep(0.6, 1.0, t))
        * rim(r);
    (fire_ramp(heat), alpha)
}

/// The explosion sprite sheet: `cols` x `rows` frames of `cell` x `cell` pixels, row-major,
/// of a noisy fireball that expands, cools from a white-yellow core through orange and red
/// to dark smoke, and fades out. sRGB-encoded, straight alpha.
pub fn explosion_sheet(cell: u32, cols: u32, rows: u32, seed: u64) -> Texture {
    let (cell, cols, rows) = (cell.clamp(4, 1024), cols.clamp(1, 16), rows.clamp(1, 16));
    let frames = cols * rows;
    let (w, h) = (cell * cols, cell * rows);
    let mut rgba = vec![0u8; w as usize * h as usize * 4];
    for frame in 0..frames {
        let t = if frames > 1 {
            frame as f32 / (frames - 1) as f32
        } else {
            0.0
        };
        let (x0, y0) = ((frame % cols) * cell, (frame / cols) * cell);
        for y in 0..cell {
            for x in 0..cell {
                let (c, a) = fireball(centred(x, y, cell), t, seed);
                let i = (((y0 + y) * w + x0 + x) * 4) as usize;
                rgba[i..i + 4].copy_from_slice(&[
                    encode_srgb8(c[0]),
                    encode_srgb8(c[1]),
                    encode_srgb8(c[2]),
                    (a.clamp(0.0, 1.0) * 255.0).round() as u8,
                ]);
            }
        }
    }
    Texture::from_rgba8(w, h, &rgba, Encoding::Srgb).expect("size is valid")
}

/// A soft, noisy grey smoke puff, lighter on top (the particle's tint colours it).
/// sRGB-encoded, straight alpha.
pub fn smoke_puff(size: u32, seed: u64) -> Texture {
    let size = size.clamp(4, 1024);
    let mut rgba = Vec::with_capacity(size as usize * size as usize * 4);
    for y in 0..size {
        for x in 0..size {
            let p = centred(x, y, size);
            let r = p.length();
            let n = fbm(p * 2.5, seed);
            let detail = fbm(p * 6.0 + Vec2::splat(3.1), seed ^ 0x5eed);
            let edge = 0.6 + 0.35 * n;
            let a = (1.0 - smoothstep(edge * 0.25, edge, r)) * (0.55 + 0.45 * detail) * rim(r);
            // Image y grows downward: p.y < 0 is the top of the puff.
            let grey = (0.7 + 0.25 * detail - 0.15 * p.y).clamp(0.0, 1.0);
            let g = encode_srgb8(grey);
            rgba.extend_from_slice(&[g, g, g, (a.clamp(0.0, 1.0) * 255.0).round() as u8]);
        }
    }
    Texture::from_rgba8(size, size, &rgba, Encoding::Srgb).expect("size is valid")
}

/// A spark: a white glow with a small hard core, zero at the edge. Stretched along a
/// particle's velocity it becomes a streak. Unorm (white), straight alpha.
pub fn spark(size: u32) -> Texture {
    crate::core::sprites::radial(size.clamp(4, 1024), |r| {
        ((-r * r * 30.0).exp() + 0.3 * (-r * r * 6.0).exp()) * rim(r)
    })
}
