//! `stereo`: depth from a stereo pair (`ibr::stereo`), rectified already or rectified from
//! its cameras.
//!
//! ```sh
//! stereo --left left.png --right right.png --max-disparity 64 --out out/stereo
//! stereo --left l.png --right r.png --method block --fill --focal-px 700 --baseline 0.2 --out out/s
//! stereo --cameras pair/transforms.json --out out/s
//! warp --capture out/s/transforms.json --eye 0,0,4 --target 0,0,0 --png view.png
//! ```
//!
//! Matches the left image against the right one along rows by semi-global matching
//! (default) or a block matcher, keeps matches that pass the uniqueness and left-right
//! checks, and writes `disparity.pfm` (the Middlebury convention: pixels, infinity where
//! unknown) and `disparity.png` (colour-mapped, unknown black, with a colour key below the
//! map: a bar over the searched range with tick values in pixels of disparity).
//!
//! The disparities searched are `0..N`: `--max-disparity N` when given, else from the
//! capture's depth maps when `--cameras` has them (the nearest point's disparity after
//! rectification, with a margin), else from a coarse search of the pair shrunk to about
//! 128 pixels across (`ibr::stereo::range`). When more than 5% of the matches sit at the
//! range's limit (the map's matches at its last disparity, or the coarse search's at it or
//! beyond, which a range given or chosen by the coarse search is checked against: the
//! scene comes nearer than the range reaches), one warning line goes to stderr.
//!
//! A pixel with alpha 0 shows nothing (nothing was seen there): its disparity is unknown,
//! as is that of a pixel matched to one, and `--fill` (unknown pixels filled from the
//! background side, along rows) paints neither them nor across them. The pair comes in
//! one of two forms:
//!
//! - `--left` and `--right`: two images of one size, already rectified (the right camera
//!   the left one moved along its x axis). Given the focal length in pixels and the
//!   baseline (`--focal-px`, `--baseline`) it also writes `depth.pfm` (distance along the
//!   optical axis) and the left view as a depth image with its camera: a one-frame
//!   `transforms.json` capture (`images/0000.png`, `depth/0000.pfm`; the left camera at the
//!   origin looking down -z, square pixels, the principal point in the middle).
//! - `--cameras FILE`: a `transforms.json` capture (NeRF / instant-ngp convention:
//!   camera-to-world matrices, OpenGL axes; depth maps optional, used for the range) of exactly two
//!   frames, the left view then the right, of one size, with any poses but one whose
//!   baseline runs along the view. The pair is rectified from its cameras
//!   (`ibr::stereo::rectify`: both views turned about their eyes to the left view's
//!   direction made square to the baseline, x along it) and matched; every output is in the rectified left
//!   view's frame, whose size is the images'. The focal length and the baseline come from
//!   the cameras, so `--focal-px` and `--baseline` are refused; `depth.pfm` and the
//!   one-frame capture are always written, the capture's camera the rectified left camera
//!   where it stands in the scene, so `warp --capture DIR/transforms.json` makes new views
//!   in the scene's own coordinates. Rectified left pixels with no source pixel (outside
//!   the original left image; transparent in `images/0000.png`), and those matched to a
//!   right pixel with none, are unknown, and stay so with `--fill`. The share of each
//!   rectified view inside its original is printed (whatever the original shows there).
//!
//! Errors are one line on stderr, `stereo: error: ...`, and exit code 1 (a capture without
//! two frames, views of different sizes, cameras that cannot be rectified among them).

use clap::{ArgGroup, Parser, ValueEnum};
use demos::bench::stereo::key;
use engine::load::{self, write_float_image, FloatImage};
use engine::{Camera, Premul};
use ibr::images::transforms::{read_photos, write_transforms, Intrinsics};
use ibr::stereo::range::{self, MAX_RANGE};
use ibr::stereo::{
    inside_original, luminance, luminance_rgba8, rectify, BlockMatch, Disparity, Sgm,
};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Method {
    Sgm,
    Block,
}

#[derive(Debug, Parser)]
#[command(
    version,
    about = "stereo: depth from a stereo pair, rectified images or two views with their cameras"
)]
#[command(group(ArgGroup::new("pair").required(true).args(["left", "cameras"])))]
struct Args {
    /// The left image (PNG or any format the `image` crate reads) of a rectified pair.
    #[arg(long, value_name = "FILE", requires = "right")]
    left: Option<PathBuf>,
    /// The right image, the same size.
    #[arg(long, value_name = "FILE", requires = "left")]
    right: Option<PathBuf>,
    /// Instead of --left and --right: a transforms.json capture (or the folder holding it)
    /// of two views, left then right, with their cameras; the pair is rectified first.
    #[arg(
        long,
        value_name = "FILE",
        conflicts_with_all = ["left", "right", "focal_px", "baseline"]
    )]
    cameras: Option<PathBuf>,
    /// Disparities 0 to N - 1 are searched [default: from the capture's depth, else a
    /// coarse search].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1024))]
    max_disparity: Option<u32>,
    #[arg(long, value_enum, default_value_t = Method::Sgm)]
    method: Method,
    /// Fill unknown pixels from the background side (never where the view saw nothing).
    #[arg(long)]
    fill: bool,
    /// Focal length in pixels (along x), for depth.pfm (with --left and --right).
    #[arg(long, value_name = "PIXELS", requires = "baseline")]
    focal_px: Option<f32>,
    /// Distance between the cameras (scene units), for depth.pfm (with --left and --right).
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

/// A rectified pair ready to match, and what makes its left view a depth image.
struct Pair {
    width: u32,
    height: u32,
    /// Luminance of the left and right images.
    left: Vec<f32>,
    right: Vec<f32>,
    /// Pixels of each image that show nothing (alpha 0: outside the original after
    /// rectification, or nothing seen there); empty when every pixel shows something.
    left_empty: Vec<bool>,
    right_empty: Vec<bool>,
    /// The left image's colour, premultiplied linear.
    colour: Vec<Premul>,
    /// The left camera, the focal length in pixels along x and the baseline, when known.
    camera: Option<(Camera, f32, f32)>,
    /// The disparities to search that the capture's depth maps give, when it has them.
    from_depth: Option<u32>,
}

/// Reads an image as RGBA8.
fn read(path: &Path) -> Result<(u32, u32, Vec<u8>), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    load::rgba8_from_bytes(&bytes, path).map_err(|e| e.to_string())
}

/// The pair of `--left` and `--right` (rectified already), with the camera that
/// `--focal-px` and `--baseline` give.
fn images(a: &Args, left: &Path, right: &Path) -> Result<Pair, String> {
    let (w, h, l) = read(left)?;
    let (rw, rh, r) = read(right)?;
    if (w, h) != (rw, rh) {
        return Err(format!(
            "{} is {w}x{h} but {} is {rw}x{rh}: a rectified pair has images of one size",
            left.display(),
            right.display()
        ));
    }
    let camera = match (a.focal_px, a.baseline) {
        (Some(f), Some(b)) => {
            if !(f > 0.0 && f.is_finite() && b > 0.0 && b.is_finite()) {
                return Err(format!(
                    "--focal-px {f} and --baseline {b} must be positive"
                ));
            }
            // The left camera from the focal length, at the origin.
            let fov_y = 2.0 * (0.5 * h as f32 / f).atan();
            let camera = Camera::look_at(
                glam::Vec3::ZERO,
                glam::Vec3::NEG_Z,
                glam::Vec3::Y,
                fov_y,
                w as f32 / h.max(1) as f32,
            )
            .with_depth_range(
                0.01 * f * b / a.max_disparity.unwrap_or(MAX_RANGE) as f32,
                1e4 * f * b,
            );
            Some((camera, f, b))
        }
        _ => None,
    };
    let colour = l
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
    Ok(Pair {
        width: w,
        height: h,
        left: luminance_rgba8(&l),
        right: luminance_rgba8(&r),
        left_empty: transparent(&l, &r),
        right_empty: transparent(&r, &l),
        colour,
        camera,
        from_depth: None,
    })
}

/// The pixels of RGBA8 `image` with alpha 0, or none when neither it nor `other` has any.
fn transparent(image: &[u8], other: &[u8]) -> Vec<bool> {
    let clear = |rgba: &[u8]| rgba.chunks_exact(4).any(|p| p[3] == 0);
    if !clear(image) && !clear(other) {
        return Vec::new();
    }
    image.chunks_exact(4).map(|p| p[3] == 0).collect()
}

/// The pair of the two views of the capture `path` (a `transforms.json` or its folder),
/// rectified from their cameras.
fn captured(path: &Path) -> Result<Pair, String> {
    let json = if path.is_dir() {
        path.join("transforms.json")
    } else {
        path.to_path_buf()
    };
    let views = read_photos(&json).map_err(|e| e.to_string())?;
    let [l, r] = views.as_slice() else {
        return Err(format!(
            "{} has {} frames: --cameras needs exactly 2, the left view then the right",
            json.display(),
            views.len()
        ));
    };
    let ((w, h), (rw, rh)) = ((l.width(), l.height()), (r.width(), r.height()));
    if (w, h) != (rw, rh) {
        return Err(format!(
            "{}: the left view is {w}x{h} but the right one {rw}x{rh}: a pair has images of one size",
            json.display()
        ));
    }
    let rect =
        rectify(l, r).map_err(|e| format!("{}: cannot rectify the pair: {e}", json.display()))?;
    let (w, h) = (rect.left.width(), rect.left.height());
    // x pixels per unit of x / z in the rectified camera's space (both share it).
    let focal = rect.left.camera.projection.gl_matrix().x_axis.x * 0.5 * w as f32;
    let empty = |colour: &[Premul]| colour.iter().map(|c| c.a <= 0.0).collect::<Vec<bool>>();
    let (left_empty, right_empty) = (empty(&rect.left.color), empty(&rect.right.color));
    // Coverage of the originals by where each ray falls, not by what it shows there.
    let (left_in, right_in) = (
        inside_original(l, &rect.left.camera, w, h),
        inside_original(r, &rect.right.camera, w, h),
    );
    println!(
        "stereo: rectified {}: baseline {:.4}, focal length {focal:.1} px, {:.1}% of the left view and {:.1}% of the right inside the originals",
        json.display(),
        rect.baseline,
        100.0 * share(&left_in, true),
        100.0 * share(&right_in, true),
    );
    let from_depth =
        range::from_depth(&[&rect.left.depth, &rect.right.depth], focal, rect.baseline);
    Ok(Pair {
        width: w,
        height: h,
        left: luminance(&rect.left),
        right: luminance(&rect.right),
        left_empty,
        right_empty,
        colour: rect.left.color,
        camera: Some((rect.left.camera, focal, rect.baseline)),
        from_depth,
    })
}

/// The share of `flags` that are `value` (0 when there are none).
fn share(flags: &[bool], value: bool) -> f64 {
    flags.iter().filter(|&&f| f == value).count() as f64 / flags.len().max(1) as f64
}

/// Makes unknown the disparities of left pixels that show nothing and of those matched to
/// right pixels that show nothing.
fn mask(d: &mut Disparity, pair: &Pair) {
    if pair.left_empty.is_empty() {
        return;
    }
    let w = pair.width as usize;
    for (i, v) in d.data.iter_mut().enumerate() {
        if pair.left_empty[i] {
            *v = f32::INFINITY;
        } else if v.is_finite() {
            let x = (i % w) as f32 - *v;
            let at = x.round();
            if at < 0.0 || pair.right_empty[i - i % w + at as usize] {
                *v = f32::INFINITY;
            }
        }
    }
}

/// `camera` with a depth range that holds `depth` (its finite values), the field of view
/// kept.
fn holding(camera: Camera, depth: &[f32], w: u32, h: u32) -> Camera {
    let (lo, hi) = depth
        .iter()
        .filter(|z| z.is_finite())
        .fold((f32::INFINITY, 0.0f32), |(lo, hi), &z| {
            (lo.min(z), hi.max(z))
        });
    let (near, far) = camera.near_far();
    if lo >= near && hi <= far {
        return camera;
    }
    let (near, far) = (near.min(0.5 * lo), far.max(2.0 * hi));
    match Intrinsics::of(&camera.projection, w, h) {
        Some(k) => Camera {
            view: camera.view,
            projection: k.projection(w, h, near, far),
        },
        None => camera,
    }
}

fn run(a: &Args) -> Result<(), String> {
    let pair = match (&a.cameras, &a.left, &a.right) {
        (Some(path), _, _) => captured(path)?,
        (None, Some(left), Some(right)) => images(a, left, right)?,
        _ => return Err("give --left and --right, or --cameras".into()),
    };
    let (w, h) = (pair.width, pair.height);
    std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
    let start = Instant::now();
    // The range, and the coarse search that checks a range given (or chose it).
    let search = || range::coarse(&pair.left, &pair.right, w, h);
    let (n, how, coarse) = match (a.max_disparity, pair.from_depth) {
        (Some(n), _) => (n, "--max-disparity", search()),
        (None, Some(n)) => (n, "from the capture's depth", None),
        (None, None) => match search() {
            Some(c) => (c.range(), "from a coarse search", Some(c)),
            None => (64, "nothing matched in a coarse search: the default", None),
        },
    };
    let mut d = match a.method {
        Method::Sgm => Sgm {
            max_disparity: n,
            ..Sgm::default()
        }
        .run(&pair.left, &pair.right, w, h),
        Method::Block => BlockMatch {
            max_disparity: n,
            ..BlockMatch::default()
        }
        .run(&pair.left, &pair.right, w, h),
    }
    .map_err(|e| e.to_string())?;
    mask(&mut d, &pair);
    let ms = start.elapsed().as_secs_f64() * 1e3;
    let known = d.data.iter().filter(|v| v.is_finite()).count();
    let seen = if pair.left_empty.is_empty() {
        String::new()
    } else {
        let inside = pair.left_empty.iter().filter(|&&e| !e).count();
        format!(
            " ({:.1}% of the {inside} the rectified left view sees)",
            100.0 * known as f64 / inside.max(1) as f64
        )
    };
    println!(
        "stereo: {w}x{h}, disparities 0 to {} ({how}), {:?}: {:.1}% of the pixels matched{seen} in {ms:.0} ms",
        n - 1,
        a.method,
        100.0 * known as f64 / d.data.len().max(1) as f64
    );
    let at_limit = range::at_limit(&d, n).max(coarse.map_or(0.0, |c| c.beyond(n)));
    if at_limit > 0.05 {
        eprintln!(
            "stereo: warning: {:.1}% of the matches sit at the limit of the disparity range (0 to {}): the scene comes nearer than the range reaches; raise --max-disparity{}",
            100.0 * at_limit,
            n - 1,
            if a.max_disparity.is_some() { " or leave it out to have it chosen" } else { "" }
        );
    }
    if a.fill {
        // Filling does not reach, nor cross, what the view does not see.
        let seen: Vec<bool> = pair.left_empty.iter().map(|&e| !e).collect();
        d.fill_within(&seen);
    }
    let write = |name: &str, image: &FloatImage| {
        let p = a.out.join(name);
        write_float_image(&p, image).map_err(|e| e.to_string())?;
        println!("stereo: wrote {}", p.display());
        Ok::<(), String>(())
    };
    write("disparity.pfm", &d.to_float_image())?;
    let png = a.out.join("disparity.png");
    let (pixels, keyed) = key::with_key(d.to_colour(n as f32), w, h, n as f32);
    load::write_png_rgba8(&png, w, keyed, &pixels).map_err(|e| e.to_string())?;
    println!("stereo: wrote {}", png.display());
    if let Some((camera, f, b)) = pair.camera {
        // The left view as a depth image: depth f b / d along the optical axis.
        let mut image = d
            .to_depth_image(&pair.colour, &camera, f, b)
            .expect("one colour a pixel");
        if a.cameras.is_some() {
            image.camera = holding(camera, &image.depth, w, h);
        }
        write(
            "depth.pfm",
            &FloatImage::new(w, h, image.depth.clone()).expect("one depth a pixel"),
        )?;
        write_transforms(&a.out, &[image]).map_err(|e| e.to_string())?;
        println!("stereo: wrote {}", a.out.join("transforms.json").display());
    }
    Ok(())
}
