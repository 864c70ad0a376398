//! The techniques, one folder each. A technique imports `crate::core`, `engine` and the
//! image operations (`crate::warp`, `crate::stereo`, `crate::metrics`, `crate::transforms`),
//! never a sibling technique.

pub mod billboards;
pub mod clouds;
pub mod depth_images;
pub mod effects;
pub mod flare;
pub mod impostors;
pub mod lasers;
pub mod layers;
pub mod lightfields;
pub mod morph;
pub mod octahedral;
pub mod panoramas;
pub mod portals;
