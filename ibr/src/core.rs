//! The core every technique and the planner build on; it imports only `engine` (and std,
//! glam, rayon). View and screen maths ([`view`]), quad and billboard building
//! ([`billboard`], [`pool`]'s image materials), capture cameras fitted to a sphere
//! ([`framing`]), the frame seam and its loop ([`frame`]) with the refresh scheduler
//! ([`schedule`]), the planner's seam ([`represent`], [`cost`]), what images stand in for
//! ([`subject`]), images with depth ([`images`]), the one capture service ([`capture`]) and
//! generated sprite textures ([`sprites`]).
//!
//! Every item is re-exported here, so users name `crate::core::Item`.

pub(crate) mod billboard;
pub(crate) mod capture;
pub(crate) mod cost;
pub(crate) mod frame;
pub(crate) mod framing;
pub(crate) mod images;
pub(crate) mod intrinsics;
pub(crate) mod pool;
pub(crate) mod prior;
pub(crate) mod represent;
pub(crate) mod schedule;
pub(crate) mod sprites;
pub(crate) mod subject;
pub(crate) mod view;

pub use billboard::*;
pub use capture::*;
pub use cost::*;
pub use frame::*;
pub(crate) use framing::*;
pub(crate) use images::atlas::Atlas;
pub use images::*;
pub use intrinsics::*;
pub use pool::*;
pub(crate) use prior::*;
pub use represent::*;
pub use schedule::*;
pub use subject::*;
pub use view::*;
