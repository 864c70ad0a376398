//! Test support shared by the integration tests: the golden-image helper and asset paths.

pub mod assets;
pub mod busy;
pub mod compare;
pub mod counting;
pub mod golden;
pub mod reference;
pub mod scenes;
