//! The core every technique and the planner build on; it imports only `engine` (and std,
//! glam, rayon). View and screen maths ([`view`]), quad and billboard building
//! ([`billboard`], [`pool`]'s image materials), capture cameras fitted to a sphere
//! ([`framing`]), the frame seam and its loop ([`frame`]) with the refresh scheduler
//! ([`schedule`]), the planner's seam ([`represent`], [`cost`]), what images stand in for
//! ([`subject`]), images with depth ([`images`]), the one capture service ([`capture`]) and
//! generated sprite textures ([`sprites`]).
//!
//! Every item is re-exported here, so users name `crate::core::Item`.

pub mod billboard;
pub mod capture;
pub mod cost;
pub mod frame;
pub mod framing;
pub mod images;
pub mod intrinsics;
pub mod pool;
pub mod prior;
pub mod represent;
pub mod schedule;
pub mod sprites;
pub mod subject;
pub mod view;

pub use billboard::*;
pub use capture::*;
pub use cost::*;
pub use frame::*;
pub use framing::*;
pub use images::atlas::Atlas;
pub use images::*;
pub use intrinsics::*;
pub use pool::*;
pub use prior::*;
pub use represent::*;
pub use schedule::*;
pub use subject::*;
pub use view::*;
