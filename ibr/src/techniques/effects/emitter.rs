//! Particle emitters: their configuration, their particles, and the deterministic,
//! allocation-free update that spawns, moves and retires them and turns them into billboards.

use super::SpriteSheet;
use crate::core::{AxialFallback, Billboard, BillboardBatch, Facing, Size, UvRect};
use engine::procedural::XorShift;
use engine::Rgba;
use glam::{Vec2, Vec3};
use std::f32::consts::{PI, TAU};

/// Hard limit on any emitter's particle count, whatever its configuration says.
pub const MAX_PARTICLES: u32 = 1 << 16;

/// Longest time step an update integrates; longer steps are shortened to this.
pub const MAX_STEP: f32 = 0.25;

/// How an emitter spawns, moves and draws its particles. Ranges are `(lo, hi)`, sampled
/// uniformly per particle; `(start, end)` pairs are interpolated linearly over its life.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmitterConfig {
    /// Particles per second while the emitter runs.
    pub rate: f32,
    /// Particles spawned at once when the emitter is made.
    pub burst: u32,
    /// Seconds the emitter spawns at `rate` (`f32::INFINITY`: until stopped).
    pub duration: f32,
    /// Seconds each particle lives.
    pub lifetime: (f32, f32),
    /// Initial speed, world units per second.
    pub speed: (f32, f32),
    /// Centre of the cone of initial directions, world space.
    pub direction: Vec3,
    /// Half angle of that cone, radians (0: a jet, PI: every direction).
    pub spread: f32,
    /// Particles start uniformly inside a ball of this radius around the emitter.
    pub spawn_radius: f32,
    /// Constant acceleration (gravity, buoyancy, wind), world units per second squared.
    pub acceleration: Vec3,
    /// Velocity decays as `exp(-drag * t)`.
    pub drag: f32,
    /// World size (side of the quad).
    pub size: (f32, f32),
    /// Straight linear tint times the texture; alpha is the opacity. Components above 1
    /// brighten additive layers.
    pub color: (Rgba, Rgba),
    /// Seconds over which a new particle's alpha rises from 0 (0: none).
    pub fade_in: f32,
    /// Angular speed about the view axis, radians per second (start angle is random).
    pub spin: (f32, f32),
    /// Animated particles: the frame comes from the particle's age. `None`: whole texture.
    pub sheet: Option<SpriteSheet>,
    /// When > 0, particles are streaks along their velocity (axial billboards) of length
    /// `size + speed * stretch`, instead of screen-facing squares.
    pub stretch: f32,
    /// Spawns beyond this many live particles are dropped (also capped by
    /// [`MAX_PARTICLES`]).
    pub max_particles: u32,
}

impl Default for EmitterConfig {
    fn default() -> Self {
        EmitterConfig {
            rate: 10.0,
            burst: 0,
            duration: f32::INFINITY,
            lifetime: (1.0, 1.0),
            speed: (1.0, 1.0),
            direction: Vec3::Y,
            spread: 0.0,
            spawn_radius: 0.0,
            acceleration: Vec3::ZERO,
            drag: 0.0,
            size: (1.0, 1.0),
            color: (Rgba::WHITE, Rgba::WHITE),
            fade_in: 0.0,
            spin: (0.0, 0.0),
            sheet: None,
            stretch: 0.0,
            max_particles: 1024,
        }
    }
}

/// One live particle (world space).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Particle {
    /// World-space position.
    pub position: Vec3,
    /// World units per second.
    pub velocity: Vec3,
    /// Seconds since it was spawned.
    pub age: f32,
    /// Seconds it lives; it is removed once `age` reaches this.
    pub lifetime: f32,
    /// Rotation of its sprite about the view axis, radians in [0, 2π).
    pub rotation: f32,
    /// Change of `rotation` per second, radians.
    pub spin: f32,
}

/// A particle source at `position`. Particles live in world space: moving the emitter
/// leaves the existing ones where they are.
#[derive(Clone, Debug)]
pub struct Emitter {
    /// What it spawns and how the particles move and look.
    pub config: EmitterConfig,
    /// World-space spawn point; moving it leaves live particles in place.
    pub position: Vec3,
    /// Live particles, oldest first.
    pub particles: Vec<Particle>,
    rng: XorShift,
    /// Fraction of a particle owed by the rate, carried to the next update.
    carry: f32,
    elapsed: f32,
    stopped: bool,
}

/// A sample of `(lo, hi)`, 0 when not finite. Always draws one number, so the stream of
/// random numbers does not depend on the values.
fn pick(rng: &mut XorShift, (lo, hi): (f32, f32)) -> f32 {
    let v = rng.range(lo, hi);
    if v.is_finite() {
        v
    } else {
        0.0
    }
}

/// A uniformly distributed unit vector within `spread` radians of `axis`.
fn cone(rng: &mut XorShift, axis: Vec3, spread: f32) -> Vec3 {
    let axis = axis.normalize_or(Vec3::Y);
    let spread = if spread.is_finite() {
        spread.clamp(0.0, PI)
    } else {
        0.0
    };
    let cos = 1.0 - rng.next_f32() * (1.0 - spread.cos());
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let (s, c) = (rng.next_f32() * TAU).sin_cos();
    let (u, v) = axis.any_orthonormal_pair();
    (u * c + v * s) * sin + axis * cos
}

fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a + (b - a) * t
}

/// Advances one particle by `dt` (semi-implicit Euler).
fn step(p: &mut Particle, c: &EmitterConfig, dt: f32) {
    p.velocity += c.acceleration * dt;
    if c.drag > 0.0 {
        p.velocity *= (-c.drag * dt).exp();
    }
    p.position += p.velocity * dt;
    p.rotation = (p.rotation + p.spin * dt).rem_euclid(TAU);
    p.age += dt;
}

fn alive(p: &Particle) -> bool {
    p.age < p.lifetime && p.position.is_finite() && p.velocity.is_finite()
}

impl Emitter {
    /// An emitter with its own random stream, after spawning `config.burst` particles.
    pub fn new(config: EmitterConfig, position: Vec3, seed: u64) -> Self {
        let mut e = Emitter {
            config,
            position,
            particles: Vec::new(),
            rng: XorShift::new(seed),
            carry: 0.0,
            elapsed: 0.0,
            stopped: false,
        };
        // At most rate * longest lifetime + 1 rate-spawned particles are alive at once.
        let longest = config.lifetime.0.max(config.lifetime.1);
        let steady = if e.rate() > 0.0 && longest.is_finite() {
            (e.rate() * longest.max(0.0))
                .ceil()
                .min(MAX_PARTICLES as f32) as usize
                + 2
        } else {
            0
        };
        e.particles
            .reserve((steady + config.burst as usize).min(e.max_particles()));
        e.burst(config.burst);
        e
    }

    fn max_particles(&self) -> usize {
        self.config.max_particles.min(MAX_PARTICLES) as usize
    }

    fn rate(&self) -> f32 {
        let r = self.config.rate;
        if r > 0.0 && r.is_finite() {
            r
        } else {
            0.0
        }
    }

    /// Spawns one particle and advances it by `age` seconds (its time since birth).
    fn spawn(&mut self, age: f32) {
        if self.particles.len() >= self.max_particles() {
            return;
        }
        let (c, rng) = (&self.config, &mut self.rng);
        let lifetime = pick(rng, c.lifetime);
        let speed = pick(rng, c.speed);
        let direction = cone(rng, c.direction, c.spread);
        let radius = if c.spawn_radius > 0.0 {
            c.spawn_radius
        } else {
            0.0
        };
        let offset = cone(rng, Vec3::Y, PI) * (radius * rng.next_f32().cbrt());
        let rotation = rng.next_f32() * TAU;
        let spin = pick(rng, c.spin);
        let mut p = Particle {
            position: self.position + offset,
            velocity: direction * speed,
            age: 0.0,
            lifetime,
            rotation,
            spin,
        };
        step(&mut p, c, age);
        if alive(&p) {
            self.particles.push(p);
        }
    }

    /// Spawns `n` particles at once (fewer if that would pass `max_particles`).
    pub fn burst(&mut self, n: u32) {
        let room = self.max_particles().saturating_sub(self.particles.len());
        for _ in 0..(n as usize).min(room) {
            self.spawn(0.0);
        }
    }

    /// Advances time by `dt` seconds: moves and ages the particles, removes dead ones, and
    /// spawns at the rate (a fractional particle is carried over; each new particle is
    /// born at its exact time within the step). Steps that are not positive are ignored;
    /// steps over [`MAX_STEP`] are shortened to it.
    pub fn update(&mut self, dt: f32) {
        if dt.is_nan() || dt <= 0.0 {
            return;
        }
        let dt = dt.min(MAX_STEP);
        let c = &self.config;
        self.particles.retain_mut(|p| {
            step(p, c, dt);
            alive(p)
        });
        let remaining = self.config.duration - self.elapsed;
        let window = if self.stopped || remaining.is_nan() || remaining <= 0.0 {
            0.0
        } else {
            remaining.min(dt)
        };
        self.elapsed += dt;
        let rate = self.rate();
        if rate > 0.0 && window > 0.0 {
            let c0 = self.carry;
            let total = c0 + rate * window;
            let whole = total.floor();
            self.carry = (total - whole).clamp(0.0, 1.0);
            let room = self.max_particles().saturating_sub(self.particles.len());
            let n = (whole as u64).min(room as u64) as u32;
            for j in 1..=n {
                // Particle j was due when the carried count reached j.
                let born = ((j as f32 - c0) / rate).clamp(0.0, dt);
                self.spawn(dt - born);
            }
        }
    }

    /// Stops spawning at the rate; live particles play out.
    pub fn stop(&mut self) {
        self.stopped = true;
    }

    /// Still spawning at the rate.
    pub fn is_spawning(&self) -> bool {
        !self.stopped && self.rate() > 0.0 && self.elapsed < self.config.duration
    }

    /// Not spawning and no live particles: it will draw nothing again.
    pub fn is_finished(&self) -> bool {
        !self.is_spawning() && self.particles.is_empty()
    }

    /// Pushes one billboard per live particle, with size, tint, rotation and sprite-sheet
    /// frame for its age.
    pub fn emit(&self, batch: &mut BillboardBatch) {
        let c = &self.config;
        for p in &self.particles {
            let t = (p.age / p.lifetime).clamp(0.0, 1.0);
            let size = lerp(c.size.0, c.size.1, t);
            let (a, b) = c.color;
            let mut tint = Rgba::new(
                lerp(a.r, b.r, t),
                lerp(a.g, b.g, t),
                lerp(a.b, b.b, t),
                lerp(a.a, b.a, t),
            );
            if c.fade_in > 0.0 {
                tint.a *= (p.age / c.fade_in).min(1.0);
            }
            let speed = p.velocity.length();
            let (facing, dims, rotation) = if c.stretch > 0.0 && speed > 1e-4 {
                let streak = Facing::Axial {
                    axis: p.velocity / speed,
                    fallback: AxialFallback {
                        fade_start: 60.0,
                        fade_end: 85.0,
                        top: None,
                    },
                };
                (streak, Vec2::new(size, size + speed * c.stretch), 0.0)
            } else {
                (Facing::Screen, Vec2::splat(size), p.rotation)
            };
            batch.push(Billboard {
                position: p.position,
                facing,
                size: Size::World(dims),
                pivot: Vec2::splat(0.5),
                rotation,
                tint,
                region: c.sheet.map_or(UvRect::FULL, |s| s.region(p.age)),
            });
        }
    }
}
