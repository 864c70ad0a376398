//! Shared code of the Parallax binaries: the showcase scene, its image-based layer, its
//! moments and fly camera ([`showcase`]), frame-time statistics ([`timing`]), a tiny
//! bitmap font for on-screen readouts ([`font`]), datasets of views written for the
//! `warp` command ([`dataset`]), the scalable city of the impostor benchmarks ([`city`]),
//! the building of the portal walkthrough ([`building`]), the world of many objects and its
//! per-node planner ([`world`]), the benchmark sweeps behind the
//! `bench` CLI ([`bench`]) and the charts they draw ([`chart`]). Binaries stay thin; what they do is
//! here, where tests reach it.
//!
//! The top-level modules form layers without a circle: [`world`] uses [`city`];
//! [`showcase`] uses [`chart`], [`city`], [`building`] and [`world`]; [`bench`] uses those, [`font`], [`timing`] and
//! [`showcase`]'s scene; the others are leaves, and nothing here uses [`bench`].

pub mod bench;
pub mod building;
pub mod chart;
pub mod city;
pub mod cli;
pub mod dataset;
pub mod font;
pub mod showcase;
pub mod timing;
pub mod world;

/// Sets the global rayon pool to `threads` workers (when given); a failure is reported on
/// stderr as `PROGRAM: ...` and the default pool is kept.
pub fn set_threads(program: &str, threads: Option<usize>) {
    if let Some(n) = threads {
        if let Err(e) = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
        {
            eprintln!("{program}: cannot set {n} threads: {e}");
        }
    }
}
