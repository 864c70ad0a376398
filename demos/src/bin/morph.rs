//! `morph`: in-between views of two photographs and their cameras by view morphing (Seitz
//! and Dyer 96: prewarp to parallel views, morph along rows, postwarp to the in-between
//! camera). Reads the two views from a `transforms.json` capture; correspondences come
//! from its depth maps or, for photographs without depth, from the stereo matcher.
//!
//! ```sh
//! render --obj model.obj --capture cap --views 2 --spread 20 --eye 0,1,4 --target 0,1,0
//! morph --capture cap/transforms.json --frames 8 --out frames
//! morph --capture cap/transforms.json --t 0.5 --correspondence stereo --out mid
//! ```
//!
//! Writes `morph_NNNN.png` (and with `--plain` the morph without prewarp, `plain_NNNN.png`,
//! to compare) and prints each frame's parameter and what it is made of. Errors are one
//! line on stderr, `morph: error: ...`, and exit code 1; the singular case, the second eye
//! straight ahead of the first, is such an error. The flags follow the tools' shared
//! vocabulary (`demos::cli`): `--out` is the folder; the size is the capture's.

use clap::{Parser, ValueEnum};
use engine::load;
use ibr::images::transforms::{read_photos, srgb8};
use ibr::morph::{plain_morph, Correspondence, ViewMorph};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum CorrespondenceArg {
    /// The capture's depth maps.
    Depth,
    /// Semi-global matching on the prewarped pair (no depth needed).
    Stereo,
}

/// Make in-between views of two captured views by view morphing (prewarp, morph, postwarp).
#[derive(Debug, Parser)]
#[command(name = "morph", version, allow_negative_numbers = true)]
struct Args {
    /// A capture's transforms.json (or the folder holding it); depth maps are optional
    /// with `--correspondence stereo`.
    #[arg(long, value_name = "FILE")]
    capture: PathBuf,
    /// The frame of the capture to start from.
    #[arg(long, default_value_t = 0)]
    from: usize,
    /// The frame to end at.
    #[arg(long, default_value_t = 1)]
    to: usize,
    /// One in-between view, this fraction of the way (0 to 1).
    #[arg(long, value_name = "T", conflicts_with = "frames")]
    t: Option<f32>,
    /// This many views from the first to the second, ends included.
    #[arg(long, value_name = "N", default_value_t = 5)]
    frames: usize,
    #[arg(long, value_enum, default_value = "depth")]
    correspondence: CorrespondenceArg,
    /// Disparities searched with `--correspondence stereo`, in pixels of the prewarped
    /// pair (half again the images' size).
    #[arg(long, default_value_t = 128)]
    max_disparity: u32,
    /// Also write the morph without prewarp (plain_NNNN.png), which needs depth.
    #[arg(long)]
    plain: bool,
    /// The folder to write to (created if missing).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

fn main() -> ExitCode {
    match run(Args::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("morph: error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(a: Args) -> Result<(), String> {
    let json = if a.capture.is_dir() {
        a.capture.join("transforms.json")
    } else {
        a.capture.clone()
    };
    let views = read_photos(&json).map_err(|e| e.to_string())?;
    let pick = |i: usize| {
        views.get(i).ok_or_else(|| {
            format!(
                "{} has {} frames; there is no frame {i}",
                json.display(),
                views.len()
            )
        })
    };
    let (first, second) = (pick(a.from)?, pick(a.to)?);
    let how = match a.correspondence {
        CorrespondenceArg::Depth => Correspondence::Depth,
        CorrespondenceArg::Stereo => Correspondence::Stereo {
            max_disparity: a.max_disparity.max(1),
        },
    };
    if a.plain && (first.covered() == 0 || second.covered() == 0) {
        return Err("--plain needs depth maps in the capture".into());
    }
    let morph = ViewMorph::new(first, second, how).map_err(|e| e.to_string())?;
    std::fs::create_dir_all(&a.out)
        .map_err(|e| format!("cannot create {}: {e}", a.out.display()))?;
    let ts: Vec<f32> = match a.t {
        Some(t) if (0.0..=1.0).contains(&t) => vec![t],
        Some(t) => return Err(format!("--t {t}: the parameter runs from 0 to 1")),
        None => {
            let n = a.frames.max(2);
            (0..n).map(|i| i as f32 / (n - 1) as f32).collect()
        }
    };
    let (w, h) = (first.width(), first.height());
    for (k, &t) in ts.iter().enumerate() {
        let (view, stats) = morph.frame(t);
        let png = a.out.join(format!("morph_{k:04}.png"));
        load::write_png_rgba8(&png, w, h, &srgb8(&view)).map_err(|e| e.to_string())?;
        let mut line = format!(
            "morph: t {t:.3}: {} ({} pixels of the {w}x{h} frame from the first view, {} from the second only, {} filled)",
            png.display(),
            stats.from_left,
            stats.from_right,
            stats.holes
        );
        if a.plain {
            let plain = a.out.join(format!("plain_{k:04}.png"));
            let image = plain_morph(first, second, t);
            load::write_png_rgba8(&plain, w, h, &srgb8(&image)).map_err(|e| e.to_string())?;
            line += &format!("; {}", plain.display());
        }
        println!("{line}");
    }
    Ok(())
}
