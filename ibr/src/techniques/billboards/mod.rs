//! Billboards as a technique: batches of camera-facing quads (the batch and its maths are
//! `crate::core`'s, since clouds, lasers and effects build on them too) drawn through the
//! frame seam, and axial billboards baked from each object's sides as a planner
//! representation ([`BillboardSet`]).

mod bake;
#[cfg(test)]
mod compare;
mod mount;
mod nailboard;
pub(crate) mod plan;
mod technique;
mod trim;
mod views;

pub use bake::{Profile, AZIMUTHS, ELEVATIONS};
pub use plan::{BillboardSet, MAX_ELEVATION};
pub use trim::Trim;
pub use views::ViewAtlas;
