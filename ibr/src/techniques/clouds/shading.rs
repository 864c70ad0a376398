//! Cloud shading: the phase functions, the shading constants and the light pass (the
//! sunlight reaching each particle).

use super::{finite, puff_profile, CloudParticle};
use engine::Rgba;
use glam::{Vec2, Vec3};

/// Side of the light pass's transmittance buffer, in texels.
pub const LIGHT_RES: usize = 64;

/// The scattering phase function, normalised to a mean of 1 over the sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Phase {
    /// `3/4 (1 + cos² θ)`, as Harris and Lastra use: symmetric about 90°.
    Rayleigh,
    /// `(1 - g²) / (1 + g² - 2 g cos θ)^{3/2}`; `g > 0` scatters forward (`g` clamped to
    /// ±0.95, non-finite as 0).
    HenyeyGreenstein {
        /// Asymmetry in (-1, 1): positive scatters forward, 0 is isotropic.
        g: f32,
    },
    /// `weight * HG(g) + (1 - weight)`: a forward lobe over an isotropic floor standing in
    /// for the light scattered many times, so front-lit clouds stay white (`weight` clamped
    /// to [0, 1], non-finite as 1).
    Mixed {
        /// Asymmetry of the Henyey-Greenstein lobe, as in [`Phase::HenyeyGreenstein`].
        g: f32,
        /// Share of the lobe, in [0, 1]; the rest is isotropic.
        weight: f32,
    },
}

impl Phase {
    /// The phase at `cos θ` (clamped to [-1, 1]; non-finite as 0).
    pub fn eval(self, cos_theta: f32) -> f32 {
        let c = finite(cos_theta, 0.0).clamp(-1.0, 1.0);
        match self {
            Phase::Rayleigh => 0.75 * (1.0 + c * c),
            Phase::HenyeyGreenstein { g } => {
                let g = finite(g, 0.0).clamp(-0.95, 0.95);
                (1.0 - g * g) / (1.0 + g * g - 2.0 * g * c).powf(1.5)
            }
            Phase::Mixed { g, weight } => {
                let w = finite(weight, 1.0).clamp(0.0, 1.0);
                w * Phase::HenyeyGreenstein { g }.eval(c) + (1.0 - w)
            }
        }
    }
}

/// Shading constants of a cloud.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CloudShading {
    /// Fraction of the light reaching a particle that it scatters (toward the eye).
    pub albedo: f32,
    /// Share of the light a particle removes in the light pass that it passes on forward.
    pub forward_scatter: f32,
    /// The phase function of the eye pass ([`Phase::Mixed`] by default).
    pub phase: Phase,
    /// Sky light added to every particle (straight linear; alpha unused).
    pub ambient: Rgba,
}

impl Default for CloudShading {
    fn default() -> Self {
        CloudShading {
            albedo: 0.9,
            forward_scatter: 0.5,
            phase: Phase::Mixed {
                g: 0.6,
                weight: 0.5,
            },
            ambient: Rgba::new(0.42, 0.45, 0.52, 1.0),
        }
    }
}

/// The light pass (see the module docs of [`super`]): writes into `light` the fraction of
/// sunlight travelling along `d` (unit) that reaches each particle, 0 for skipped ones.
/// `buffer` and `order` are scratch, kept by the caller so the pass does not allocate once
/// warm.
pub(super) fn light_pass(
    particles: &[CloudParticle],
    d: Vec3,
    forward_scatter: f32,
    light: &mut Vec<f32>,
    buffer: &mut Vec<f32>,
    order: &mut Vec<(f32, u32)>,
) {
    let (u, v) = d.any_orthonormal_pair();
    light.clear();
    light.resize(particles.len(), 0.0);
    order.clear();
    let (mut lo, mut hi) = (Vec2::INFINITY, Vec2::NEG_INFINITY);
    for (i, p) in particles.iter().enumerate() {
        let q = Vec2::new(p.position.dot(u), p.position.dot(v));
        let depth = p.position.dot(d);
        if p.valid() && q.is_finite() && depth.is_finite() {
            lo = lo.min(q - p.radius);
            hi = hi.max(q + p.radius);
            order.push((depth, i as u32));
        }
    }
    order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let n = LIGHT_RES;
    let texel = ((hi - lo).max_element() / n as f32).max(1e-6);
    buffer.clear();
    buffer.resize(n * n, 1.0);
    let s = finite(forward_scatter, 0.0).clamp(0.0, 1.0);
    for &(_, i) in order.iter() {
        let p = particles[i as usize];
        let c = (Vec2::new(p.position.dot(u), p.position.dot(v)) - lo) / texel;
        let r = (p.radius / texel).max(1.0);
        let span = |m: f32| {
            let a = ((m - r).floor().max(0.0) as usize).min(n - 1);
            (a, ((m + r).ceil().max(0.0) as usize).clamp(a + 1, n))
        };
        let ((x0, x1), (y0, y1)) = (span(c.x), span(c.y));
        let weight = |x: usize, y: usize| {
            puff_profile(Vec2::new(x as f32 + 0.5, y as f32 + 0.5).distance(c) / r)
        };
        let (mut sum, mut wsum) = (0.0, 0.0);
        for y in y0..y1 {
            for x in x0..x1 {
                let w = weight(x, y);
                sum += w * buffer[y * n + x];
                wsum += w;
            }
        }
        // r >= 1 texel: the nearest texel centre has weight > 0.2, so wsum > 0.
        let t = finite(sum / wsum, 1.0).clamp(0.0, 1.0);
        light[i as usize] = t;
        let density = p.density();
        for y in y0..y1 {
            for x in x0..x1 {
                let a = density * weight(x, y);
                let b = &mut buffer[y * n + x];
                *b = *b * (1.0 - a) + a * s * t;
            }
        }
    }
}
