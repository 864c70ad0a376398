//! Particle effects on billboards: animated sprite sheets, particle emitters, and the
//! explosion / smoke / sparks presets the showcase draws through three batches.
//!
//! An [`Emitter`] is plain data stepped by [`Emitter::update`]: deterministic for a seed and
//! a sequence of time steps, allocation-free once its particle `Vec` has reached its peak,
//! and indifferent to odd input (non-positive or NaN steps are ignored, huge ones capped,
//! particle counts capped by `max_particles`). [`Emitter::emit`] turns live particles into
//! billboards. An [`Effect`] is a few emitters, each tagged with the [`Layer`] (texture and
//! blend mode) it draws in; [`Effects`] owns the generated textures, one
//! [`BillboardBatch`](crate::core::BillboardBatch) per layer, and the running effects, and drops finished ones.

mod emitter;
mod presets;
mod sheet;
mod technique;
mod textures;

pub use emitter::{Emitter, EmitterConfig, Particle, MAX_PARTICLES, MAX_STEP};
pub use presets::{Effect, EffectId, Effects, Layer};
pub use sheet::{SpriteSheet, EXPLOSION_SHEET};
pub use textures::{explosion_sheet, smoke_puff, spark};

#[cfg(test)]
mod tests;
