//! The planner with each technique's representation among its choices: each one's
//! predicted error against the error measured on a calibration run, and what the planner
//! promises with it (the contract every representation keeps is checked once for all in
//! `plan::catalog_tests`).

mod billboards;
mod clouds;
mod depth_images;
mod layers;
mod lightfields;
mod octahedral;
