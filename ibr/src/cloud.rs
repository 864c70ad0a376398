//! Cloud particle systems after Harris and Lastra 2001, "Real-Time Cloud Rendering": cumulus
//! clouds of a few hundred soft particles, lit by a precomputed light pass and drawn as
//! blended screen-facing billboards, back to front, in one [`BillboardBatch`] per cloud.
//!
//! Shading has the paper's two passes:
//!
//! 1. **Light pass** ([`Cloud::relight`], rerun only when the sun's direction changes or the
//!    particles move). Particles are sorted by distance toward the sun, nearest first, and
//!    splatted in that order into a [`LIGHT_RES`]² transmittance buffer in the sun's
//!    orthographic view of the cloud. Each particle first reads the buffer over its
//!    footprint (weighted by the puff profile): that fraction `I_k` of the sunlight is its
//!    incident light. It then attenuates the buffer by its opacity `a(x)` (profile times
//!    density) but passes a share `s` of what it removes on forward:
//!    `T <- T (1 - a) + a s I_k`. This is the paper's multiple forward scattering
//!    approximation `I_{k+1} = g_k + T_k I_k` with `g_k = a s I_k`, `s` standing for the
//!    albedo times the forward lobe of the phase function ([`CloudShading::forward_scatter`]),
//!    so the far side of a cloud is dimmed, never black. `T` stays in [0, 1].
//! 2. **Eye pass** ([`Subject::prepare`]): a particle's straight colour is
//!    `I_k * sun * albedo * phase(cos θ) + ambient` and its alpha its density, `θ` the
//!    scattering angle between the sunlight's direction of travel and the direction from
//!    the particle to the eye.
//!
//! The phase function defaults to [`Phase::Mixed`]: half Henyey-Greenstein with `g = 0.6`
//! (a forward peak: a backlit cloud brightens toward the sun, the silver lining), half
//! isotropic, standing in for the higher orders of scattering that keep a front-lit cumulus
//! white (pure HG at 0.6 scatters back only 0.16 and paints it grey). The paper's Rayleigh
//! `3/4 (1 + cos² θ)` is [`Phase::Rayleigh`]; symmetric about 90°, it has no silver lining.
//! All are normalised to a mean of 1 over the sphere, so tints above 1 are allowed.
//!
//! Allocation-free once warm (the light pass and the batch reuse their buffers); particles
//! with non-finite fields or non-positive radii are skipped, a non-finite sun keeps the
//! previous direction (initially straight down).

use crate::billboard::{Billboard, BillboardBatch, Facing, View};
use crate::subject::{enclose, Subject};
use engine::procedural::{value_noise, XorShift};
use engine::{
    BlendMode, Camera, Draw, Encoding, Material, Projection, Rgba, Sphere, Texture, Wrap,
};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::sync::Arc;

/// Side of the light pass's transmittance buffer, in texels.
pub const LIGHT_RES: usize = 64;
/// Most particles [`cumulus`] makes.
pub const MAX_PARTICLES: usize = 1 << 16;

/// One cloud particle (world space).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CloudParticle {
    pub position: Vec3,
    pub radius: f32,
    /// Peak opacity at the centre, in [0, 1].
    pub density: f32,
}

impl CloudParticle {
    fn valid(&self) -> bool {
        self.position.is_finite() && self.radius.is_finite() && self.radius > 0.0
    }
    fn density(&self) -> f32 {
        finite(self.density, 0.0).clamp(0.0, 1.0)
    }
}

/// The scattering phase function, normalised to a mean of 1 over the sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Phase {
    /// `3/4 (1 + cos² θ)`, as Harris and Lastra use: symmetric about 90°.
    Rayleigh,
    /// `(1 - g²) / (1 + g² - 2 g cos θ)^{3/2}`; `g > 0` scatters forward (`g` clamped to
    /// ±0.95, non-finite as 0).
    HenyeyGreenstein { g: f32 },
    /// `weight * HG(g) + (1 - weight)`: a forward lobe over an isotropic floor standing in
    /// for the light scattered many times, so front-lit clouds stay white (`weight` clamped
    /// to [0, 1], non-finite as 1).
    Mixed { g: f32, weight: f32 },
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

/// `x` if finite, else `fallback`.
fn finite(x: f32, fallback: f32) -> f32 {
    if x.is_finite() {
        x
    } else {
        fallback
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

/// A cloud: particles, their light, and the batch that draws them. See the module docs.
#[derive(Clone, Debug)]
pub struct Cloud {
    particles: Vec<CloudParticle>,
    /// Per particle: the fraction of sunlight reaching it (the light pass's `I_k`).
    light: Vec<f32>,
    shading: CloudShading,
    /// Direction the sunlight travels (unit), as `Light::Directional::direction`.
    sun_dir: Vec3,
    sun_color: Rgba,
    stale: bool,
    version: u64,
    batch: BillboardBatch,
    buffer: Vec<f32>,
    order: Vec<(f32, u32)>,
}

impl Cloud {
    /// A cloud of `particles` with its own generated puff texture, lit by a white sun
    /// straight overhead.
    pub fn new(particles: Vec<CloudParticle>) -> Self {
        Self::with_texture(particles, Arc::new(puff_texture(64, 0)))
    }

    /// A cloud drawing its particles with `texture` (shared between the clouds of a field).
    pub fn with_texture(particles: Vec<CloudParticle>, texture: Arc<Texture>) -> Self {
        let mut material = Material::unlit(Rgba::WHITE)
            .with_texture(texture)
            .blended(BlendMode::Alpha);
        material.name = "cloud".into();
        (material.sampler.wrap_u, material.sampler.wrap_v) = (Wrap::Clamp, Wrap::Clamp);
        let mut cloud = Cloud {
            particles,
            light: Vec::new(),
            shading: CloudShading::default(),
            sun_dir: Vec3::NEG_Y,
            sun_color: Rgba::WHITE,
            stale: true,
            version: 0,
            batch: BillboardBatch::new(material),
            buffer: Vec::new(),
            order: Vec::new(),
        };
        cloud.light_pass();
        cloud
    }

    /// A cumulus cloud: see [`cumulus`].
    pub fn cumulus(center: Vec3, size: Vec3, count: usize, seed: u64) -> Self {
        Self::new(cumulus(center, size, count, seed))
    }

    pub fn particles(&self) -> &[CloudParticle] {
        &self.particles
    }

    /// The particles, for moving them: bumps the version, and the light pass reruns at
    /// the next [`Cloud::relight`] or [`Subject::prepare`].
    pub fn particles_mut(&mut self) -> &mut [CloudParticle] {
        self.stale = true;
        self.version += 1;
        &mut self.particles
    }

    /// Moves every particle by `offset` (wind drift). A directional light's pass does not
    /// change under translation, so it is not rerun.
    pub fn translate(&mut self, offset: Vec3) {
        if offset.is_finite() && offset != Vec3::ZERO {
            self.particles.iter_mut().for_each(|p| p.position += offset);
            self.version += 1;
        }
    }

    pub fn shading(&self) -> CloudShading {
        self.shading
    }

    /// Replaces the shading constants; reruns the light pass if `forward_scatter` changed.
    pub fn set_shading(&mut self, shading: CloudShading) {
        if shading != self.shading {
            self.stale |= shading.forward_scatter != self.shading.forward_scatter;
            self.shading = shading;
            self.version += 1;
        }
    }

    /// Soft particles: fade where the cloud meets opaque geometry (view units; 0 off).
    pub fn set_soft_distance(&mut self, distance: f32) {
        self.batch.material.soft_distance = finite(distance, 0.0).max(0.0);
        self.version += 1;
    }

    /// The sunlight's direction of travel (unit) and colour.
    pub fn sun(&self) -> (Vec3, Rgba) {
        (self.sun_dir, self.sun_color)
    }

    /// Sets the sun (`sun_dir`: the direction its light travels, as for
    /// `Light::Directional`). Reruns the light pass only if the direction changed (or the
    /// particles moved); a zero or non-finite direction keeps the previous one.
    pub fn relight(&mut self, sun_dir: Vec3, sun_color: Rgba) {
        let dir = sun_dir.try_normalize().unwrap_or(self.sun_dir);
        let ok = sun_color.to_array().iter().all(|c| c.is_finite());
        let color = if ok { sun_color } else { self.sun_color };
        if dir != self.sun_dir || self.stale {
            self.sun_dir = dir;
            self.light_pass();
            self.version += 1;
        }
        if color != self.sun_color {
            self.sun_color = color;
            self.version += 1;
        }
    }

    /// Fraction of the sunlight reaching each particle, from the last light pass (0 for
    /// skipped particles).
    pub fn transmittance(&self) -> &[f32] {
        &self.light
    }

    /// The sunlight reaching particle `i` (transmittance times the sun's colour).
    pub fn incident(&self, i: usize) -> Rgba {
        let (t, s) = (self.light.get(i).copied().unwrap_or(0.0), self.sun_color);
        Rgba::new(s.r * t, s.g * t, s.b * t, 1.0)
    }

    /// Particle `i`'s straight colour seen along `to_eye` (unit, from the particle toward
    /// the eye): `incident * albedo * phase + ambient`, alpha the density.
    pub fn particle_color(&self, i: usize, to_eye: Vec3) -> Rgba {
        let density = self.particles.get(i).map_or(0.0, CloudParticle::density);
        let sh = &self.shading;
        let t = self.light.get(i).copied().unwrap_or(0.0);
        let k = finite(t * sh.albedo * sh.phase.eval(self.sun_dir.dot(to_eye)), 0.0).max(0.0);
        let rgb = |c: Rgba| Vec3::new(c.r, c.g, c.b);
        let c = (rgb(self.sun_color) * k + rgb(sh.ambient)).clamp(Vec3::ZERO, Vec3::splat(64.0));
        let c = if c.is_finite() { c } else { Vec3::ZERO };
        Rgba::new(c.x, c.y, c.z, density)
    }

    /// The batch drawn by [`Subject::draws`] (its mesh as of the last prepare).
    pub fn batch(&self) -> &BillboardBatch {
        &self.batch
    }

    fn light_pass(&mut self) {
        self.stale = false;
        let d = self.sun_dir;
        let (particles, light) = (&self.particles, &mut self.light);
        let (buffer, order) = (&mut self.buffer, &mut self.order);
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
        let s = finite(self.shading.forward_scatter, 0.0).clamp(0.0, 1.0);
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
}

impl Subject for Cloud {
    /// A sphere around every (valid) particle's sphere.
    fn bounds(&self) -> Sphere {
        enclose(self.particles.iter().filter(|p| p.valid()).map(|p| Sphere {
            center: p.position,
            radius: p.radius,
        }))
    }

    /// Reruns a stale light pass, then writes one screen-facing quad per particle, tinted
    /// for this view, sorted back to front.
    fn prepare(&mut self, camera: &Camera, height: u32) {
        if self.stale {
            self.light_pass();
        }
        let view = View::new(camera, height);
        let ortho = matches!(camera.projection, Projection::Orthographic { .. });
        self.batch.clear();
        for (i, p) in self.particles.iter().enumerate().filter(|(_, p)| p.valid()) {
            let to_eye = match ortho {
                true => -view.forward,
                false => (view.eye - p.position).normalize_or_zero(),
            };
            let mut b = Billboard::new(p.position, Facing::Screen, Vec2::splat(2.0 * p.radius));
            // Golden-angle rotations, so neighbouring puffs do not repeat one silhouette.
            b.rotation = (i % 256) as f32 * 2.399_963;
            b.tint = self.particle_color(i, to_eye);
            self.batch.push(b);
        }
        self.batch.build(&view);
    }

    fn draws<'s>(&'s self, out: &mut Vec<Draw<'s>>) {
        if !self.batch.mesh().indices.is_empty() {
            out.push(self.batch.draw());
        }
    }

    fn version(&self) -> u64 {
        self.version
    }

    fn triangle_count(&self) -> usize {
        2 * self.particles.len()
    }
}

/// Clouds scattered over an area, sharing one puff texture: the showcase's sky.
#[derive(Clone, Debug, Default)]
pub struct CloudField {
    pub clouds: Vec<Cloud>,
}

impl CloudField {
    /// `count` (at most 4096) cumulus clouds of `particles` particles each over the
    /// rectangle `min..max` of the XZ plane, their flat bases at height `base`. The area is
    /// cut into a grid of about `count` cells; clouds go to randomly chosen cells, sized
    /// to and jittered within them, so they never overlap. Deterministic by `seed`; empty
    /// for a non-finite area or height.
    pub fn scatter(
        min: Vec2,
        max: Vec2,
        base: f32,
        count: usize,
        particles: usize,
        seed: u64,
    ) -> Self {
        let (lo, hi) = (min.min(max), min.max(max));
        let count = count.min(4096);
        if !(min.is_finite() && max.is_finite() && base.is_finite()) || count == 0 {
            return Self::default();
        }
        let area = (hi - lo).max(Vec2::splat(1e-3));
        let cols = ((count as f32 * area.x / area.y).sqrt().ceil() as usize).clamp(1, count);
        let rows = count.div_ceil(cols);
        let cell = area / Vec2::new(cols as f32, rows as f32);
        let mut rng = XorShift::new(seed);
        let mut cells: Vec<usize> = (0..cols * rows).collect();
        for i in (1..cells.len()).rev() {
            cells.swap(i, (rng.next_u64() % (i as u64 + 1)) as usize);
        }
        let texture = Arc::new(puff_texture(64, seed));
        let clouds = cells[..count]
            .iter()
            .map(|&c| {
                let w = cell.x * rng.range(0.55, 0.85);
                let size = Vec3::new(w, w * rng.range(0.3, 0.45), cell.y * rng.range(0.45, 0.7));
                let corner = lo + Vec2::new((c % cols) as f32, (c / cols) as f32) * cell;
                let slack = (cell - Vec2::new(size.x, size.z)) * 0.5;
                let jitter = Vec2::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
                let xz = corner + cell * 0.5 + slack * jitter;
                let center = Vec3::new(xz.x, base + size.y * 0.5, xz.y);
                let shape = cumulus(center, size, particles, rng.next_u64());
                Cloud::with_texture(shape, texture.clone())
            })
            .collect();
        CloudField { clouds }
    }

    /// Relights every cloud (see [`Cloud::relight`]).
    pub fn relight(&mut self, sun_dir: Vec3, sun_color: Rgba) {
        for c in &mut self.clouds {
            c.relight(sun_dir, sun_color);
        }
    }
}

impl Subject for CloudField {
    fn bounds(&self) -> Sphere {
        let spheres = self.clouds.iter().map(Subject::bounds);
        enclose(spheres.filter(|s| s.radius > 0.0))
    }

    fn prepare(&mut self, camera: &Camera, height: u32) {
        for c in &mut self.clouds {
            c.prepare(camera, height);
        }
    }

    fn draws<'s>(&'s self, out: &mut Vec<Draw<'s>>) {
        self.clouds.iter().for_each(|c| c.draws(out));
    }

    fn version(&self) -> u64 {
        self.clouds.iter().fold(0, |v, c| v.wrapping_add(c.version))
    }

    fn triangle_count(&self) -> usize {
        self.clouds.iter().map(Subject::triangle_count).sum()
    }
}

#[cfg(test)]
mod tests;
