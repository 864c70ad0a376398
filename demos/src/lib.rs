//! Shared code of the Parallax binaries: the showcase scene and fly camera
//! ([`showcase`]), frame-time statistics ([`timing`]), a tiny bitmap font for on-screen
//! readouts ([`font`]), and the benchmark sweeps and charts behind the `bench` CLI
//! ([`bench`], [`chart`]). Binaries stay thin; what they do is here, where tests reach it.

pub mod bench;
pub mod chart;
pub mod font;
pub mod showcase;
pub mod timing;
