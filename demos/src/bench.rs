//! The benchmark sweeps behind the `bench` CLI, one module per sweep, and what they share
//! ([`sweep`]: CSV rows, progress steps, the timed-frames loop).

pub mod billboards;
pub mod budget;
pub mod impostors;
pub mod layers;
pub mod lightfield;
pub mod morph;
pub mod panorama;
pub mod portals;
pub mod raster;
pub mod scaling;
pub mod stereo;
pub mod sweep;
pub mod warp;
