//! The effect presets (explosion, smoke, sparks), the layers they draw in, and [`Effects`],
//! which owns the textures, the three batches and the running effects.

use super::{explosion_sheet, smoke_puff, spark, Emitter, EmitterConfig, EXPLOSION_SHEET};
use crate::core::{BillboardBatch, View};
use engine::procedural::XorShift;
use engine::{BlendMode, Draw, Material, Rgba, Sampler, Wrap};
use glam::Vec3;
use std::f32::consts::PI;
use std::sync::Arc;

/// Which batch (texture and blend mode) an emitter draws in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layer {
    /// The explosion sprite sheet, alpha blended.
    Fire,
    /// Smoke puffs, alpha blended, soft against opaque surfaces.
    Smoke,
    /// Sparks, additive.
    Sparks,
}

/// A few emitters that make one effect.
#[derive(Clone, Debug)]
pub struct Effect {
    /// The effect's emitters, each with the batch it draws in.
    pub emitters: Vec<(Layer, Emitter)>,
}

impl Effect {
    /// A one-shot explosion: a burst of animated fireballs, fast sparks falling under
    /// gravity, and smoke that keeps rising for a while. Finished after about 4 seconds.
    pub fn explosion(position: Vec3, seed: u64) -> Effect {
        let fire = EmitterConfig {
            rate: 0.0,
            burst: 10,
            lifetime: (0.9, 1.2),
            speed: (0.5, 2.0),
            spread: PI,
            spawn_radius: 0.3,
            acceleration: Vec3::new(0.0, 0.8, 0.0),
            drag: 2.0,
            size: (2.0, 4.2),
            color: (Rgba::WHITE, Rgba::new(1.0, 1.0, 1.0, 0.0)),
            spin: (-1.0, 1.0),
            sheet: Some(EXPLOSION_SHEET),
            max_particles: 64,
            ..Default::default()
        };
        let smoke = EmitterConfig {
            rate: 14.0,
            burst: 4,
            duration: 1.2,
            lifetime: (1.8, 2.8),
            speed: (0.3, 1.0),
            spread: 0.8,
            spawn_radius: 0.6,
            acceleration: Vec3::new(0.0, 0.6, 0.0),
            drag: 0.8,
            size: (1.2, 3.5),
            color: (
                Rgba::new(0.12, 0.11, 0.1, 0.75),
                Rgba::new(0.3, 0.3, 0.3, 0.0),
            ),
            fade_in: 0.3,
            spin: (-0.5, 0.5),
            max_particles: 64,
            ..Default::default()
        };
        let sparks = EmitterConfig {
            rate: 0.0,
            burst: 40,
            ..spark_config()
        };
        Effect {
            emitters: vec![
                (Layer::Smoke, Emitter::new(smoke, position, seed ^ 0x51)),
                (Layer::Fire, Emitter::new(fire, position, seed ^ 0xf1)),
                (Layer::Sparks, Emitter::new(sparks, position, seed ^ 0x5a)),
            ],
        }
    }

    /// A continuous column of rising grey puffs, until stopped.
    pub fn smoke(position: Vec3, seed: u64) -> Effect {
        let smoke = EmitterConfig {
            rate: 6.0,
            lifetime: (3.0, 4.5),
            speed: (0.4, 0.8),
            spread: 0.35,
            spawn_radius: 0.2,
            acceleration: Vec3::new(0.15, 0.3, 0.0),
            drag: 0.5,
            size: (0.8, 3.0),
            color: (
                Rgba::new(0.55, 0.55, 0.55, 0.55),
                Rgba::new(0.7, 0.7, 0.7, 0.0),
            ),
            fade_in: 0.4,
            spin: (-0.4, 0.4),
            max_particles: 128,
            ..Default::default()
        };
        Effect {
            emitters: vec![(Layer::Smoke, Emitter::new(smoke, position, seed))],
        }
    }

    /// A continuous fountain of hot additive streaks falling under gravity, until stopped.
    pub fn sparks(position: Vec3, seed: u64) -> Effect {
        let sparks = EmitterConfig {
            rate: 60.0,
            speed: (4.0, 7.0),
            spread: 0.5,
            ..spark_config()
        };
        Effect {
            emitters: vec![(Layer::Sparks, Emitter::new(sparks, position, seed))],
        }
    }

    /// Advances every emitter by `dt` seconds.
    pub fn update(&mut self, dt: f32) {
        for (_, e) in &mut self.emitters {
            e.update(dt);
        }
    }

    /// Stops every emitter spawning; the effect finishes when its particles die.
    pub fn stop(&mut self) {
        for (_, e) in &mut self.emitters {
            e.stop();
        }
    }

    /// Moves every emitter (live particles stay where they are).
    pub fn set_position(&mut self, position: Vec3) {
        for (_, e) in &mut self.emitters {
            e.position = position;
        }
    }

    /// Whether every emitter has stopped spawning and has no live particle left.
    pub fn is_finished(&self) -> bool {
        self.emitters.iter().all(|(_, e)| e.is_finished())
    }

    /// Live particles over all emitters.
    pub fn particle_count(&self) -> usize {
        self.emitters.iter().map(|(_, e)| e.particles.len()).sum()
    }
}

/// Sparks: small, very bright (additive) orange streaks under gravity.
fn spark_config() -> EmitterConfig {
    EmitterConfig {
        lifetime: (0.4, 0.9),
        speed: (6.0, 12.0),
        spread: PI,
        acceleration: Vec3::new(0.0, -9.8, 0.0),
        drag: 1.0,
        size: (0.12, 0.05),
        color: (
            Rgba::new(4.0, 2.2, 0.8, 1.0),
            Rgba::new(1.5, 0.3, 0.05, 0.0),
        ),
        stretch: 0.04,
        max_particles: 512,
        ..Default::default()
    }
}

/// A handle to an effect added to [`Effects`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct EffectId(pub u64);

/// Running effects and the three batches they draw through.
///
/// Per frame: [`Effects::update`], then [`Effects::build`] with the camera's view, then
/// hand [`Effects::draws`] to the renderer with the frame's other draws.
#[derive(Clone, Debug)]
pub struct Effects {
    effects: Vec<(EffectId, Effect)>,
    /// Indexed by [`Layer`]: fire, smoke, sparks.
    pub(super) batches: [BillboardBatch; 3],
    rng: XorShift,
    next_id: u64,
}

impl Effects {
    /// Generates the textures; `seed` drives the seeds of the effects spawned later.
    pub fn new(seed: u64) -> Self {
        let material = |name: &str, texture: engine::Texture, blend: BlendMode, soft: f32| {
            let mut m = Material::unlit(Rgba::WHITE)
                .with_texture(Arc::new(texture))
                .blended(blend);
            m.name = name.into();
            m.soft_distance = soft;
            m.sampler = Sampler {
                wrap_u: Wrap::Clamp,
                wrap_v: Wrap::Clamp,
                ..Sampler::default()
            };
            BillboardBatch::new(m)
        };
        let sheet = &EXPLOSION_SHEET;
        Effects {
            effects: Vec::new(),
            batches: [
                material(
                    "effects-fire",
                    explosion_sheet(64, sheet.cols, sheet.rows, 7),
                    BlendMode::Alpha,
                    0.3,
                ),
                material("effects-smoke", smoke_puff(64, 11), BlendMode::Alpha, 0.5),
                material("effects-sparks", spark(32), BlendMode::Additive, 0.0),
            ],
            rng: XorShift::new(seed),
            next_id: 0,
        }
    }

    /// Adds an effect; it is dropped once finished.
    pub fn add(&mut self, effect: Effect) -> EffectId {
        let id = EffectId(self.next_id);
        self.next_id += 1;
        self.effects.push((id, effect));
        id
    }

    /// Adds [`Effect::explosion`] with the next seed.
    pub fn spawn_explosion(&mut self, position: Vec3) -> EffectId {
        let seed = self.rng.next_u64();
        self.add(Effect::explosion(position, seed))
    }

    /// Adds [`Effect::smoke`] with the next seed.
    pub fn add_smoke(&mut self, position: Vec3) -> EffectId {
        let seed = self.rng.next_u64();
        self.add(Effect::smoke(position, seed))
    }

    /// Adds [`Effect::sparks`] with the next seed.
    pub fn add_sparks(&mut self, position: Vec3) -> EffectId {
        let seed = self.rng.next_u64();
        self.add(Effect::sparks(position, seed))
    }

    /// The running effect `id` (`None` once finished and dropped).
    pub fn get_mut(&mut self, id: EffectId) -> Option<&mut Effect> {
        self.effects
            .iter_mut()
            .find(|(i, _)| *i == id)
            .map(|(_, e)| e)
    }

    /// The running effects, oldest first.
    pub fn iter(&self) -> impl Iterator<Item = (EffectId, &Effect)> {
        self.effects.iter().map(|(i, e)| (*i, e))
    }

    /// Number of running effects.
    pub fn len(&self) -> usize {
        self.effects.len()
    }

    /// Whether no effect is running.
    pub fn is_empty(&self) -> bool {
        self.effects.is_empty()
    }

    /// Live particles over all running effects.
    pub fn particle_count(&self) -> usize {
        self.effects.iter().map(|(_, e)| e.particle_count()).sum()
    }

    /// Advances every effect by `dt` seconds and drops the finished ones.
    pub fn update(&mut self, dt: f32) {
        for (_, e) in &mut self.effects {
            e.update(dt);
        }
        self.effects.retain(|(_, e)| !e.is_finished());
    }

    /// Writes the batches' meshes for `view`. Returns the number of quads.
    pub fn build(&mut self, view: &View) -> usize {
        for b in &mut self.batches {
            b.clear();
        }
        for (_, effect) in &self.effects {
            for (layer, e) in &effect.emitters {
                e.emit(&mut self.batches[*layer as usize]);
            }
        }
        self.batches.iter_mut().map(|b| b.build(view)).sum()
    }

    /// The batch of `layer` (its material and last mesh).
    pub fn batch(&self, layer: Layer) -> &BillboardBatch {
        &self.batches[layer as usize]
    }

    /// The three draws (smoke, fire, sparks); empty batches draw nothing.
    pub fn draws(&self) -> [Draw<'_>; 3] {
        [Layer::Smoke, Layer::Fire, Layer::Sparks].map(|l| self.batch(l).draw())
    }
}

impl Default for Effects {
    fn default() -> Self {
        Self::new(0)
    }
}
