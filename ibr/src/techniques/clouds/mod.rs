//! Cloud particle systems after Harris and Lastra 2001, "Real-Time Cloud Rendering": cumulus
//! clouds of a few hundred soft particles, lit by a precomputed light pass and drawn as
//! blended billboards facing the eye (each turned toward the eye point, upright about +Y),
//! back to front, in one [`BillboardBatch`] per cloud. Facing the eye rather than the image
//! plane, a cloud looks the same whichever way the camera turns: parallel to the image
//! plane, the puffs of a cloud near the edge of a wide view covered less of the sky than
//! seen straight on, so an impostor captured straight on (toward the cloud) was up to 32
//! levels brighter than the particles at the top edge of the showcase's view.
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
//! Seen from close by or from inside (`fog`), particles near the eye fade out and the
//! opacity they lose is drawn as a fog over the view, so the inside of a cloud is a fog
//! in the cloud's colours rather than a wall of screen-filling billboards.
//!
//! Allocation-free once warm (the light pass and the batch reuse their buffers); particles
//! with non-finite fields or non-positive radii are skipped, a non-finite sun keeps the
//! previous direction (initially straight down).

mod field;
mod fog;
mod shading;
mod shape;

pub use field::CloudField;
pub use fog::{coverage, fade_scale, near_fade, screen_share, FOG_MAX, MAX_FILL, NEAR_FADE};
pub use shading::{CloudShading, Phase, LIGHT_RES};
pub use shape::{cumulus, puff_profile, puff_texture, CloudParticle, MAX_PARTICLES};

use crate::core::billboard::{corners, screen_share as billboard_share};
use crate::core::{enclose, Subject};
use crate::core::{Billboard, BillboardBatch, Facing, View};
use engine::{BlendMode, Camera, Draw, Material, Mesh, Projection, Rgba, Sphere, Texture, Wrap};
use glam::{Vec2, Vec3};
use std::sync::Arc;

/// How the puffs face (module docs): the eye point, upright about +Y.
pub(crate) const FACING: Facing = Facing::World { up: Vec3::Y };

/// `x` if finite, else `fallback`.
fn finite(x: f32, fallback: f32) -> f32 {
    if x.is_finite() {
        x
    } else {
        fallback
    }
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
    /// The fog seen from inside (one quad in front of the view, or nothing).
    fog: Mesh,
    fog_material: Material,
    buffer: Vec<f32>,
    order: Vec<(f32, u32)>,
    /// Per particle, distance in radii and share of the view (the fade's scale, `fog`).
    near: Vec<(f32, f32)>,
    /// The fade's scale of the last prepare (1: the plain near fade).
    scale: f32,
    /// Pixels the last prepare's quads fill ([`Cloud::fill`]).
    fill: f32,
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
            fog: Mesh::default(),
            fog_material: {
                let mut m = Material::unlit(Rgba::WHITE)
                    .blended(BlendMode::Alpha)
                    .double_sided(true);
                m.name = "cloud fog".into();
                m
            },
            buffer: Vec::new(),
            order: Vec::new(),
            near: Vec::new(),
            scale: 1.0,
            fill: 0.0,
        };
        cloud.light_pass();
        cloud
    }

    /// A cumulus cloud: see [`cumulus`].
    pub fn cumulus(center: Vec3, size: Vec3, count: usize, seed: u64) -> Self {
        Self::new(cumulus(center, size, count, seed))
    }

    /// The particles, world space.
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

    /// The shading constants in use.
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

    /// Pixels of the last prepared view its particle quads fill (their areas summed, each
    /// clipped to the near plane and the image): what drawing the particles shades, about.
    pub fn fill(&self) -> f32 {
        self.fill
    }

    /// Draws the particles and the fog as [`engine::Material::low_res`] (`on`) or not: at
    /// the renderer's reduced resolution, when it has one. Off by default; a caller whose
    /// clouds fill many screens of particles turns it on (the showcase: BENCHMARKS.md,
    /// session 23).
    pub fn set_low_res(&mut self, on: bool) {
        self.batch.material.low_res = on;
        self.fog_material.low_res = on;
    }

    /// The near fade's scale of the last prepare: 1 but from close by or inside, where
    /// it keeps the particles' fill within [`MAX_FILL`] screens (see `fog`).
    pub fn fade_scale(&self) -> f32 {
        self.scale
    }

    /// The batch drawn by [`Subject::draws`] (its mesh as of the last prepare).
    pub fn batch(&self) -> &BillboardBatch {
        &self.batch
    }

    fn light_pass(&mut self) {
        self.stale = false;
        shading::light_pass(
            &self.particles,
            self.sun_dir,
            self.shading.forward_scatter,
            &mut self.light,
            &mut self.buffer,
            &mut self.order,
        );
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
    /// for this view and faded near the eye, sorted back to front, and the fog of the
    /// faded particles (see `fog`).
    fn prepare(&mut self, camera: &Camera, height: u32) {
        if self.stale {
            self.light_pass();
        }
        let view = View::new(camera, height);
        let ortho = matches!(camera.projection, Projection::Orthographic { .. });
        // How far inside: 0 on the bounding sphere, 1 a mean particle radius within it.
        let valid = self.particles.iter().filter(|p| p.valid());
        let (radii, count) = valid.fold((0.0, 0usize), |(s, n), p| (s + p.radius, n + 1));
        let inside = if ortho || count == 0 {
            0.0
        } else {
            let bounds = self.bounds();
            let depth = bounds.radius - view.eye.distance(bounds.center);
            depth / (radii / count as f32)
        };
        self.scale = match camera.projection {
            Projection::Perspective { fov_y, aspect, .. } if inside > 0.0 => {
                let tan_half = (0.5 * fov_y).tan();
                self.near.clear();
                let valid = self.particles.iter().filter(|p| p.valid());
                self.near.extend(valid.map(|p| {
                    let z = (p.position - view.eye).dot(view.forward);
                    let share = screen_share(p.radius, z, tan_half, aspect);
                    (view.eye.distance(p.position) / p.radius, share)
                }));
                // Eased in over the same depth as the fog, so entering does not pop.
                let full = fade_scale(&mut self.near, MAX_FILL);
                1.0 + (full - 1.0) * inside.min(1.0)
            }
            // From outside, and for off-axis captures (impostor images): the plain fade.
            _ => 1.0,
        };
        self.batch.clear();
        let mut fog = fog::Fog::default();
        for (i, p) in self.particles.iter().enumerate().filter(|(_, p)| p.valid()) {
            let to_eye = match ortho {
                true => -view.forward,
                false => (view.eye - p.position).normalize_or_zero(),
            };
            let mut tint = self.particle_color(i, to_eye);
            if !ortho {
                let d = view.eye.distance(p.position) / p.radius;
                let fade = near_fade(d / self.scale);
                if fade < 1.0 {
                    fog.add(d, fade, tint.a, self.particle_color(i, -view.forward));
                    tint.a *= fade;
                }
                if tint.a <= 0.0 {
                    continue;
                }
            }
            let mut b = Billboard::new(p.position, FACING, Vec2::splat(2.0 * p.radius));
            // Golden-angle rotations, so neighbouring puffs do not repeat one silhouette.
            b.rotation = (i % 256) as f32 * 2.399_963;
            b.tint = tint;
            self.batch.push(b);
        }
        self.batch.build(&view);
        // The pixels the drawn quads fill, each clipped to the view (`Cloud::fill`).
        let clip_from_world = camera.clip_from_world();
        let share = |b: &Billboard| match corners(b, &view) {
            Some((c, _)) => billboard_share(&c, &clip_from_world),
            None => 0.0,
        };
        let screens: f32 = self.batch.items.iter().map(share).sum();
        // The image's width over its height, from the view's extents at unit depth.
        let [l, r, b, t] = camera.projection.extents();
        let aspect = if t > b { (r - l) / (t - b) } else { 1.0 };
        let h = height as f32;
        self.fill = finite(screens * h * h * aspect, 0.0);
        // The fog grows from nothing on the bounding sphere to full one mean particle
        // radius inside it.
        let near = camera.near_far().0;
        fog::fog_quad(&mut self.fog, &view, 1.5 * near, fog.color(inside));
    }

    fn draws<'s>(&'s self, out: &mut Vec<Draw<'s>>) {
        if !self.batch.mesh().indices.is_empty() {
            out.push(self.batch.draw());
        }
        if !self.fog.indices.is_empty() {
            out.push(Draw {
                mesh: &self.fog,
                material: &self.fog_material,
                transform: glam::Mat4::IDENTITY,
            });
        }
    }

    fn version(&self) -> u64 {
        self.version
    }

    fn triangle_count(&self) -> usize {
        2 * self.particles.len()
    }

    /// Every particle's quad is blended: their areas (side twice the radius) summed over
    /// the bounding sphere's disc.
    fn overdraw(&self) -> f32 {
        let r = self.bounds().radius;
        if r <= 0.0 || !r.is_finite() {
            return 1.0;
        }
        let valid = self.particles.iter().filter(|p| p.valid());
        let quads: f32 = valid.map(|p| 4.0 * p.radius * p.radius).sum();
        (quads / (std::f32::consts::PI * r * r)).max(1.0)
    }
}

#[cfg(test)]
mod tests;
