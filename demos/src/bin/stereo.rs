//! `stereo`: depth from a rectified stereo pair (`ibr::stereo`).
//!
//! ```sh
//! stereo --left left.png --right right.png --max-disparity 64 --out out/stereo
//! stereo --left l.png --right r.png --method block --fill --focal-px 700 --baseline 0.2 --out out/s
//! ```
//!
//! Matches the left image against the right one along rows (the pair must be rectified:
//! the right camera the left one moved along its x axis) by semi-global matching (default)
//! or a block matcher, keeps matches that pass the uniqueness and left-right checks, and
//! writes `disparity.pfm` (the Middlebury convention: pixels, infinity where unknown),
//! `disparity.png` (colour-mapped, unknown black) and, given the focal length in pixels and
//! the baseline, `depth.pfm` (distance along the optical axis) and the left view as a
//! depth image with its camera: a one-frame `transforms.json` capture (`images/0000.png`,
//! `depth/0000.pfm`; the left camera at the origin looking down -z, square pixels, the
//! principal point in the middle), which `warp --capture DIR/transforms.json` turns into
//! new views. `--fill` fills unknown pixels from the background side first. Errors are one
//! line on stderr and exit code 1.

use clap::{Parser, ValueEnum};
use engine::load::{self, write_float_image, FloatImage};
use ibr::stereo::{luminance_rgba8, BlockMatch, Sgm};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Method {
    Sgm,
    Block,
}

#[derive(Debug, Parser)]
#[command(version, about = "Depth from a rectified stereo pair")]
struct Args {
    /// The left image (PNG or any format the `image` crate reads).
    #[arg(long, value_name = "FILE")]
    left: PathBuf,
    /// The right image, the same size.
    #[arg(long, value_name = "FILE")]
    right: PathBuf,
    /// Disparities 0 to N - 1 are searched.
    #[arg(long, value_name = "N", default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=1024))]
    max_disparity: u32,
    #[arg(long, value_enum, default_value_t = Method::Sgm)]
    method: Method,
    /// Fill unknown pixels from the background side.
    #[arg(long)]
    fill: bool,
    /// Focal length in pixels (along x), for depth.pfm.
    #[arg(long, value_name = "PIXELS", requires = "baseline")]
    focal_px: Option<f32>,
    /// Distance between the cameras (scene units), for depth.pfm.
    #[arg(long, value_name = "UNITS", requires = "focal_px")]
    baseline: Option<f32>,
    /// The folder to write to.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

fn main() -> ExitCode {
    match run(&Args::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("stereo: error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Reads an image as RGBA8.
fn read(path: &Path) -> Result<(u32, u32, Vec<u8>), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    load::rgba8_from_bytes(&bytes, path).map_err(|e| e.to_string())
}

fn run(a: &Args) -> Result<(), String> {
    let (w, h, left) = read(&a.left)?;
    let (rw, rh, right) = read(&a.right)?;
    if (w, h) != (rw, rh) {
        return Err(format!(
            "{} is {w}x{h} but {} is {rw}x{rh}: a rectified pair has images of one size",
            a.left.display(),
            a.right.display()
        ));
    }
    if let (Some(f), Some(b)) = (a.focal_px, a.baseline) {
        if !(f > 0.0 && f.is_finite() && b > 0.0 && b.is_finite()) {
            return Err(format!(
                "--focal-px {f} and --baseline {b} must be positive"
            ));
        }
    }
    std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
    let (l, r) = (luminance_rgba8(&left), luminance_rgba8(&right));
    let start = Instant::now();
    let mut d = match a.method {
        Method::Sgm => Sgm {
            max_disparity: a.max_disparity,
            ..Sgm::default()
        }
        .run(&l, &r, w, h),
        Method::Block => BlockMatch {
            max_disparity: a.max_disparity,
            ..BlockMatch::default()
        }
        .run(&l, &r, w, h),
    }
    .map_err(|e| e.to_string())?;
    let ms = start.elapsed().as_secs_f64() * 1e3;
    let known = d.data.iter().filter(|v| v.is_finite()).count();
    println!(
        "stereo: {w}x{h}, disparities 0 to {}, {:?}: {:.1}% of the pixels matched in {ms:.0} ms",
        a.max_disparity - 1,
        a.method,
        100.0 * known as f64 / d.data.len().max(1) as f64
    );
    if a.fill {
        d.fill_from_background();
    }
    let write = |name: &str, image: &FloatImage| {
        let p = a.out.join(name);
        write_float_image(&p, image).map_err(|e| e.to_string())?;
        println!("stereo: wrote {}", p.display());
        Ok::<(), String>(())
    };
    write("disparity.pfm", &d.to_float_image())?;
    let png = a.out.join("disparity.png");
    load::write_png_rgba8(&png, w, h, &d.to_colour(a.max_disparity as f32))
        .map_err(|e| e.to_string())?;
    println!("stereo: wrote {}", png.display());
    if let (Some(f), Some(b)) = (a.focal_px, a.baseline) {
        let depth: Vec<f32> = d
            .data
            .iter()
            .map(|&v| {
                if v.is_finite() && v > 0.0 {
                    f * b / v
                } else {
                    f32::INFINITY
                }
            })
            .collect();
        write(
            "depth.pfm",
            &FloatImage::new(w, h, depth).expect("one depth a pixel"),
        )?;
        // The left view as a depth image: its camera from the focal length.
        let fov_y = 2.0 * (0.5 * h as f32 / f).atan();
        let camera = engine::Camera::look_at(
            glam::Vec3::ZERO,
            glam::Vec3::NEG_Z,
            glam::Vec3::Y,
            fov_y,
            w as f32 / h.max(1) as f32,
        )
        .with_depth_range(0.01 * f * b / a.max_disparity as f32, 1e4 * f * b);
        let color: Vec<engine::Premul> = left
            .chunks_exact(4)
            .map(|p| {
                let c = engine::Rgba::from_srgb8(p[0], p[1], p[2]);
                engine::Rgba {
                    a: f32::from(p[3]) / 255.0,
                    ..c
                }
                .premultiply()
            })
            .collect();
        let image = d
            .to_depth_image(&color, &camera, f, b)
            .expect("one colour a pixel");
        ibr::images::transforms::write_transforms(&a.out, &[image]).map_err(|e| e.to_string())?;
        println!("stereo: wrote {}", a.out.join("transforms.json").display());
    }
    Ok(())
}
