//! The benchmark CLI: `bench SWEEP --out DIR [--quick]` runs one sweep, writes
//! `DIR/SWEEP.csv` (a header row, one row per measurement) and `DIR/SWEEP_*.png` charts.
//!
//! Sweeps:
//! - `raster`: frame time against resolution (torus 100k, 320x240 to 3840x2160) and
//!   against triangle count (torus 1k to 2M, and the shared models when their folder
//!   exists) at 1280x720.
//! - `billboards`: particle frame time against billboard count and resolution (build and
//!   render timed apart), billboard-tree error against view elevation (PSNR, mean error),
//!   and frame time of billboard trees against mesh trees as the forest grows
//!   (`demos::bench::billboards`).
//! - `impostors`: runtime impostors on the city: frame time, refreshes per frame and
//!   measured error against the parallax tolerance on translation-only and rotation-only
//!   paths; error-driven against fixed-interval refresh at equal refresh counts; predicted
//!   against measured error; runtime against baked octahedral impostors against geometry
//!   (`demos::bench::impostors`).
//! - `scaling`: the city at 1k to 2M triangles and at 320x180 to 3840x2160, drawn as
//!   geometry and through runtime impostors: frame time against triangles and against
//!   pixels, with fitted lines (`demos::bench::scaling`).
//! - `warp`: depth images of the city warped to moved eyes (sideways, orbiting) with one,
//!   two and four references, points and splats: error and holes against the move, error
//!   against time beside the geometry frame, and the warp's speed at 1920x1080
//!   (`demos::bench::warp`).
//! - `portals`: the building's rooms through their doorways as geometry, a flat image, one
//!   depth image or an LDI: frame time against the triangles behind the doorways and
//!   against resolution, error and time along a walkthrough (`demos::bench::portals`).
//! - `lightfield`: a torus as light slabs against its geometry: error against `uv`
//!   density, `st` resolution and lookup (nearest to quadrilinear, depth correction), eyes
//!   between and away from the capture cameras; codebook size and tile shape against
//!   compression and error; frame time against resolution and the object's triangles
//!   (`demos::bench::lightfield`).
//! - `stereo`: the block matcher and semi-global matching against OpenCV's `StereoSGBM`
//!   (five and eight paths; `demos/benches/opencv_sgbm.py`, when Python has `cv2`) on
//!   rendered pairs with exact ground truth (the plaza, cards, a slanted wall, thin bars,
//!   little texture, a repeated pattern, an unrectified pair): the Middlebury measures
//!   and time side by side (`demos::bench::stereo`).
//! - `morph`: view morphing between two views of the plaza (near and wide apart), with the
//!   prewarp (correspondences from depth and from the stereo matcher) and the plain morph
//!   without it: error against the geometry from each in-between camera, and time
//!   (`demos::bench::morph`).
//! - `layers`: image layers against runtime impostors on the city, one threshold in pixels
//!   for both: re-renders per frame, error against the geometry and frame time on the
//!   translation and rotation paths (`demos::bench::layers`).
//! - `panorama`: the showcase's far scene as a cube-map sky, seen from eyes moved away
//!   from its capture point: error against the geometry, the predicted parallax, time
//!   (`demos::bench::panorama`).
//! - `budget`: the planner (each object's representation chosen per frame under an error
//!   budget) against geometry and runtime impostors used everywhere, on the city and a large
//!   world: frame time and measured error over the budgets (`demos::bench::budget`);
//!   `--calibrate` times the planner's cost model's experiments and prints its fit.

use clap::{value_parser, Arg, Command};
use demos::bench;
use std::process::ExitCode;

/// The command line: `--threads` and one subcommand per sweep of [`bench::sweeps`].
fn cli() -> Command {
    let sweeps = bench::sweeps();
    Command::new("bench")
        .version(env!("CARGO_PKG_VERSION"))
        .about("Parallax benchmark sweeps: CSV plus PNG charts")
        .arg(
            Arg::new("threads")
                .long("threads")
                .value_name("THREADS")
                .global(true)
                .value_parser(value_parser!(usize))
                .help("Render threads (default: one per core)"),
        )
        .subcommand_required(true)
        .arg_required_else_help(true)
        .subcommands(sweeps.iter().map(|s| s.command()))
}

fn main() -> ExitCode {
    let matches = cli().get_matches();
    demos::set_threads("bench", matches.get_one::<usize>("threads").copied());
    let Some((name, flags)) = matches.subcommand() else {
        unreachable!("clap requires a subcommand");
    };
    let sweeps = bench::sweeps();
    let result = match sweeps.iter().find(|s| s.name() == name) {
        Some(sweep) => sweep.run(flags),
        None => Err(format!("no sweep named {name}")),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("bench: {e}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The command line is well formed (clap's own checks) and lists every sweep once.
    #[test]
    fn every_sweep_is_a_subcommand() {
        cli().debug_assert();
        let names: Vec<&str> = bench::sweeps().iter().map(|s| s.name()).collect();
        let mut unique = names.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), names.len(), "{names:?}");
        for name in names {
            assert!(cli().find_subcommand(name).is_some(), "{name}");
        }
    }
}
