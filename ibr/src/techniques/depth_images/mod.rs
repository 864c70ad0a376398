//! Depth images and layered depth images as a technique: the nearest references warped to
//! each frame's camera ([`WarpedView`], through the frame seam), and each object's own
//! depth image or LDI captured from the eye and warped into its screen rectangle
//! ([`DepthImageSet`], a planner representation). The warp itself is the image operation
//! in `crate::warp`.

pub(crate) mod set;
mod view;

pub use set::{Config, DepthImageSet};
pub use view::{WarpFrame, WarpedView};

#[cfg(test)]
mod seen_tests;
