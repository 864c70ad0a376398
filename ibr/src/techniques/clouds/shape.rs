//! Cumulus shapes: the particle type, the cumulus generator and the puff's opacity profile
//! and texture.

use super::finite;
use engine::procedural::{value_noise, XorShift};
use engine::{Encoding, Texture};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Most particles [`cumulus`] makes.
pub const MAX_PARTICLES: usize = 1 << 16;

/// One cloud particle (world space).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CloudParticle {
    /// Centre of the puff, world space.
    pub position: Vec3,
    /// Radius of the puff in world units: its screen-facing quad is twice this on a side.
    pub radius: f32,
    /// Peak opacity at the centre, in [0, 1].
    pub density: f32,
}

impl CloudParticle {
    pub(super) fn valid(&self) -> bool {
        self.position.is_finite() && self.radius.is_finite() && self.radius > 0.0
    }
    pub(super) fn density(&self) -> f32 {
        finite(self.density, 0.0).clamp(0.0, 1.0)
    }
}

fn smoothstep(lo: f32, hi: f32, x: f32) -> f32 {
    let t = ((x - lo) / (hi - lo)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// A particle's opacity profile at `r` radii from its centre: Gaussian-ish, 0 from `r = 1`.
pub fn puff_profile(r: f32) -> f32 {
    (-3.0 * r * r).exp() * (1.0 - smoothstep(0.7, 1.0, r))
}

/// The cloud-puff texture: a white, noisy soft disc (alpha [`puff_profile`] with a
/// value-noise edge and texture), zero alpha at and beyond the mid-edges. Unorm, straight.
pub fn puff_texture(size: u32, seed: u64) -> Texture {
    let size = size.clamp(4, 1024);
    let half = size as f32 * 0.5;
    let mut rgba = Vec::with_capacity(size as usize * size as usize * 4);
    for y in 0..size {
        for x in 0..size {
            let p = Vec2::new(x as f32 + 0.5 - half, y as f32 + 0.5 - half) / half;
            let noise = |f: f32, s: u64| value_noise(p.x * f + 7.3, p.y * f + 3.1, seed ^ s);
            let edge = 0.8 + 0.2 * noise(3.0, 1);
            let a = puff_profile(p.length() / edge) * (0.7 + 0.3 * noise(7.0, 2));
            let a = a * (1.0 - smoothstep(0.9, 0.98, p.length()));
            rgba.extend_from_slice(&[255, 255, 255, (a.clamp(0.0, 1.0) * 255.0).round() as u8]);
        }
    }
    Texture::from_rgba8(size, size, &rgba, Encoding::Unorm).expect("size is valid")
}

/// A cumulus cloud's particles: `count` (at most [`MAX_PARTICLES`]) particles in the box
/// of `size` around `center`, deterministic by `seed`. A row of 3 to 5 overlapping
/// ellipsoidal blobs, tallest in the middle, with smaller turrets on top, denser and with
/// larger particles toward each blob's core; particle centres below the base (the bottom
/// of the box) are folded into a thin layer just above it, giving a flat base.
pub fn cumulus(center: Vec3, size: Vec3, count: usize, seed: u64) -> Vec<CloudParticle> {
    let count = count.min(MAX_PARTICLES);
    let center = if center.is_finite() {
        center
    } else {
        Vec3::ZERO
    };
    let size = if size.is_finite() {
        size.abs()
    } else {
        Vec3::ONE
    }
    .max(Vec3::splat(1e-3));
    let half = size * 0.5;
    let mut rng = XorShift::new(seed);
    // Blobs in box units ([-1, 1]³, base at y = -1): (centre, semi-axes), sized so that
    // bumps (up to 1.15 semi-axes) stay inside the box.
    let mut blobs = [(Vec3::ZERO, Vec3::ONE); 9];
    let main = 3 + (rng.next_u64() % 3) as usize;
    for (i, blob) in blobs.iter_mut().take(main).enumerate() {
        let t = i as f32 / (main - 1) as f32 * 2.0 - 1.0;
        let ry = 1.25 * (1.0 - 0.5 * t.abs() * rng.range(0.6, 1.0));
        let radii = Vec3::new(rng.range(0.3, 0.4), ry, rng.range(0.45, 0.6));
        let (x, z) = (t * rng.range(0.4, 0.5), rng.range(-0.25, 0.25));
        *blob = (Vec3::new(x, -1.0 + 0.4 * ry, z), radii);
    }
    let turrets = 2 + (rng.next_u64() % 3) as usize;
    for k in 0..turrets {
        let (c, r) = blobs[(rng.next_u64() % main as u64) as usize];
        let (x, z) = (rng.range(-0.5, 0.5), rng.range(-0.4, 0.4));
        blobs[main + k] = (c + Vec3::new(x, 0.6, z) * r, r * 0.4);
    }
    let blobs = &blobs[..main + turrets];
    let volume = |r: Vec3| r.x * r.y * r.z;
    let total: f32 = blobs.iter().map(|b| volume(b.1)).sum();
    let world_volume = total * 4.0 / 3.0 * PI * half.x * half.y * half.z * 0.6;
    let r0 = (1.3 * (world_volume / count.max(1) as f32).cbrt()).min(0.3 * size.max_element());
    let mut out = Vec::with_capacity(count);
    for _ in 0..count {
        let mut pick = rng.next_f32() * total;
        let &(c, radii) = blobs
            .iter()
            .find(|b| {
                pick -= volume(b.1);
                pick < 0.0
            })
            .unwrap_or(&blobs[0]);
        let mut s = Vec3::ZERO;
        for _ in 0..16 {
            s = Vec3::from_array(std::array::from_fn(|_| rng.range(-1.0, 1.0)));
            if s.length_squared() <= 1.0 {
                break;
            }
        }
        let rho = s.length().min(1.0);
        // Pull samples toward the core (radius rho^1.5) and bump the surface with noise.
        let bump = 0.85 + 0.3 * value_noise(s.x * 2.5 + s.y * 1.7, s.z * 2.5 - s.y * 2.3, seed);
        let mut q = c + s * rho.sqrt() * bump * radii;
        if q.y < -1.0 {
            q.y = -1.0 + (-1.0 - q.y) * 0.25;
        }
        let q = q.clamp(Vec3::NEG_ONE, Vec3::ONE);
        out.push(CloudParticle {
            position: center + q * half,
            radius: r0 * rng.range(0.75, 1.25) * (1.25 - 0.5 * rho),
            density: ((0.6 - 0.3 * rho) * rng.range(0.8, 1.2)).clamp(0.05, 1.0),
        });
    }
    out
}
