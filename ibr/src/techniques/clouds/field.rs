//! Cloud fields: many cumulus clouds scattered over an area, sharing one puff texture.

use super::{cumulus, puff_texture, Cloud};
use crate::core::{enclose, Subject};
use engine::procedural::XorShift;
use engine::{Camera, Draw, Rgba, Sphere};
use glam::{Vec2, Vec3};
use std::sync::Arc;

/// Clouds scattered over an area, sharing one puff texture: the showcase's sky.
#[derive(Clone, Debug, Default)]
pub struct CloudField {
    /// The clouds, sharing one puff texture.
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

    /// The clouds' overdraw, each weighted by its disc, over the field's disc.
    fn overdraw(&self) -> f32 {
        let r = self.bounds().radius;
        if r <= 0.0 || !r.is_finite() {
            return 1.0;
        }
        let each = self
            .clouds
            .iter()
            .map(|c| c.overdraw() * c.bounds().radius.powi(2));
        (each.sum::<f32>() / (r * r)).max(1.0)
    }
}
