//! Shared code of the Parallax binaries: the showcase scene, its image-based layer and fly
//! camera ([`showcase`], [`showcase_ibr`]), frame-time statistics ([`timing`]), a tiny
//! bitmap font for on-screen readouts ([`font`]), captures written for the `warp` command
//! ([`capture`]), the scalable city of the impostor
//! benchmarks ([`city`]), and the benchmark sweeps and charts behind the `bench` CLI
//! ([`bench`], [`bench_billboards`], [`chart`]). Binaries stay thin; what they do is here,
//! where tests reach it.

pub mod bench;
pub mod bench_billboards;
pub mod bench_budget;
pub mod bench_impostors;
pub mod bench_layers;
pub mod bench_lightfield;
pub mod bench_morph;
pub mod bench_panorama;
pub mod bench_portals;
pub mod bench_scaling;
pub mod bench_stereo;
pub mod bench_warp;
pub mod building;
pub mod capture;
pub mod chart;
pub mod city;
pub mod cli;
pub mod font;
pub mod showcase;
pub mod showcase_building;
pub mod showcase_ibr;
pub mod showcase_impostors;
pub mod showcase_lightfield;
pub mod showcase_views;
pub mod sweep;
pub mod timing;

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
