//! `warp`: makes a new view from depth images alone (McMillan's 3D warp): reads references
//! from a `transforms.json` capture (or one colour image, one depth map and its camera
//! given by flags), warps the nearest to a target camera, fills the holes, and writes the
//! view as PNG, with optionally its depth (PFM or OpenEXR) and a mask of the holes before
//! filling (PNG, white where a hole was, grey where nothing landed and no reference saw
//! anything). A hole is a pixel the new view should see but no reference sample covers;
//! pixels no reference saw anything at (the background beyond their coverage) are not
//! holes: they stay empty (alpha 0, depth inf), are counted apart ("unseen"), and no fill
//! paints them (`ibr::warp::holes::seen`).
//!
//! ```sh
//! render --gltf model.glb --capture cap --views 5 --eye 0,1,4 --target 0,1,0
//! warp --capture cap/transforms.json --eye -0.5,1.2,3.5 --target 0,1,0 --out view.png
//! ```
//!
//! The flags follow the tools' shared vocabulary (`demos::cli`: `-W/-H`, `--eye/--target/
//! --up`, `--out`; `--png` is kept as a hidden alias), negative vectors included. When the
//! warped references cover (almost) none of the view, one line on stderr says so. Errors
//! are one line on stderr, `warp: error: ...`, and exit code 1.

use clap::{Parser, ValueEnum};
use demos::cli::{almost_empty, format_vec3, parse_vec3};
use engine::{load, Camera, Projection};
use glam::{Mat4, Vec3};
use ibr::depth_images::WarpedView;
use ibr::images::transforms::{read_depth_image, read_transforms, srgb8};
use ibr::images::DepthImage;
use ibr::warp::holes::{Fill, Filler};
use ibr::warp::{Reconstruction, Visibility};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum ReconArg {
    /// One pixel per sample.
    Points,
    /// Splats sized by the warp's local stretch.
    Splats,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum VisArg {
    /// McMillan's occlusion-compatible order, no depth buffer.
    Ordered,
    /// A depth buffer.
    Depth,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum FillArg {
    None,
    PullPush,
    Background,
}

/// Make a new view from depth images alone: warp a capture's nearest views to a new camera.
#[derive(Debug, Parser)]
#[command(name = "warp", version, allow_negative_numbers = true)]
struct Args {
    /// A capture's transforms.json (or the folder holding it).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["colour", "depth"])]
    capture: Option<PathBuf>,
    /// One reference's colour image (PNG or JPEG), with --depth and --ref-* for its camera.
    #[arg(long, value_name = "FILE", requires = "depth")]
    colour: Option<PathBuf>,
    /// One reference's depth map (PFM or EXR, distance along the optical axis).
    #[arg(long, value_name = "FILE", requires = "colour")]
    depth: Option<PathBuf>,
    /// The reference camera's position (with --colour).
    #[arg(long, value_name = "X,Y,Z", default_value = "0,0,3", allow_hyphen_values = true, value_parser = parse_vec3)]
    ref_eye: Vec3,
    /// The point the reference camera looks at.
    #[arg(long, value_name = "X,Y,Z", default_value = "0,0,0", allow_hyphen_values = true, value_parser = parse_vec3)]
    ref_target: Vec3,
    /// The reference camera's vertical field of view, degrees.
    #[arg(long, value_name = "DEG", default_value_t = 60.0)]
    ref_fov_y: f32,
    /// Target camera position.
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = parse_vec3)]
    eye: Vec3,
    /// Point the target camera looks at.
    #[arg(long, value_name = "X,Y,Z", default_value = "0,0,0", allow_hyphen_values = true, value_parser = parse_vec3)]
    target: Vec3,
    /// Up direction of both cameras.
    #[arg(long, value_name = "X,Y,Z", default_value = "0,1,0", allow_hyphen_values = true, value_parser = parse_vec3)]
    up: Vec3,
    /// Target vertical field of view, degrees.
    #[arg(long = "fov-y", value_name = "DEG", default_value_t = 60.0)]
    fov_y: f32,
    /// Output width (default: the first reference's).
    #[arg(short = 'W', long)]
    width: Option<u32>,
    /// Output height (default: the first reference's).
    #[arg(short = 'H', long)]
    height: Option<u32>,
    #[arg(long, default_value_t = 0.1)]
    near: f32,
    #[arg(long, default_value_t = 100.0)]
    far: f32,
    /// References warped: the nearest to the target eye.
    #[arg(long, value_name = "N", default_value_t = 2)]
    nearest: usize,
    #[arg(long, value_enum, default_value_t = ReconArg::Splats)]
    reconstruction: ReconArg,
    #[arg(long, value_enum, default_value_t = VisArg::Ordered)]
    visibility: VisArg,
    #[arg(long, value_enum, default_value_t = FillArg::PullPush)]
    fill: FillArg,
    /// The warped view, PNG.
    #[arg(long = "out", alias = "png", value_name = "FILE")]
    out: PathBuf,
    /// Its depth along the target's optical axis (.pfm or .exr); inf where nothing.
    #[arg(long, value_name = "FILE")]
    depth_out: Option<PathBuf>,
    /// A mask of the holes before filling (PNG, white = hole).
    #[arg(long, value_name = "FILE")]
    holes: Option<PathBuf>,
}

fn perspective(
    eye: Vec3,
    at: Vec3,
    up: Vec3,
    fov_y: f32,
    w: u32,
    h: u32,
    near: f32,
    far: f32,
) -> Camera {
    Camera {
        view: Mat4::look_at_rh(eye, at, up),
        projection: Projection::Perspective {
            fov_y: fov_y.to_radians(),
            aspect: w as f32 / h as f32,
            near,
            far,
        },
    }
}

/// The mean of the references' eyes, for the warning when the view misses them.
fn refs_centre(refs: &[DepthImage]) -> Vec3 {
    let sum: Vec3 = refs
        .iter()
        .map(|r| r.camera.view.inverse().w_axis.truncate())
        .sum();
    sum / refs.len().max(1) as f32
}

fn references(a: &Args) -> Result<Vec<DepthImage>, String> {
    if let Some(capture) = &a.capture {
        let file = if capture.is_dir() {
            capture.join("transforms.json")
        } else {
            capture.clone()
        };
        return read_transforms(&file).map_err(|e| e.to_string());
    }
    let (Some(colour), Some(depth)) = (&a.colour, &a.depth) else {
        return Err("give --capture FILE, or --colour FILE --depth FILE".into());
    };
    // The camera's aspect comes from the image, read first.
    let camera = |w, h| {
        perspective(
            a.ref_eye,
            a.ref_target,
            a.up,
            a.ref_fov_y,
            w,
            h,
            a.near,
            a.far,
        )
    };
    let mut image = read_depth_image(colour, depth, camera(1, 1)).map_err(|e| e.to_string())?;
    image.camera = camera(image.width(), image.height());
    Ok(vec![image])
}

fn run(a: &Args) -> Result<(), String> {
    if !(a.fov_y > 0.0 && a.fov_y < 180.0 && a.ref_fov_y > 0.0 && a.ref_fov_y < 180.0) {
        return Err("fields of view must be between 0 and 180 degrees".into());
    }
    if !(a.near > 0.0 && a.far > a.near) {
        return Err(format!(
            "need 0 < --near < --far, got {} and {}",
            a.near, a.far
        ));
    }
    let refs = references(a)?;
    let (w, h) = (
        a.width.unwrap_or(refs[0].width()),
        a.height.unwrap_or(refs[0].height()),
    );
    if w == 0 || h == 0 || w > ibr::warp::MAX_SIDE || h > ibr::warp::MAX_SIDE {
        return Err(format!(
            "output size {w} x {h}: sides must be 1..={}",
            ibr::warp::MAX_SIDE
        ));
    }
    let camera = perspective(a.eye, a.target, a.up, a.fov_y, w, h, a.near, a.far);
    let n = refs.len();
    let ref_eyes = refs_centre(&refs);
    let mut view = WarpedView::new("warp", refs);
    view.nearest = a.nearest.max(1);
    view.fill = Fill::None;
    view.options.reconstruction = match a.reconstruction {
        ReconArg::Points => Reconstruction::Points,
        ReconArg::Splats => Reconstruction::Splats,
    };
    view.options.visibility = match a.visibility {
        VisArg::Ordered => Visibility::Ordered,
        VisArg::Depth => Visibility::DepthBuffer,
    };
    let t = Instant::now();
    let frame = view.warp_to(&camera, w, h);
    let mut image = view.image().clone();
    let fill = match a.fill {
        FillArg::None => Fill::None,
        FillArg::PullPush => Fill::PullPush,
        FillArg::Background => Fill::Background,
    };
    let filled = Filler::default()
        .fill_seen(&mut image, fill, view.options.edge, view.unseen())
        .filled;
    let ms = t.elapsed().as_secs_f64() * 1e3;
    if let Some(path) = &a.holes {
        let unseen = view.unseen();
        let mask: Vec<u8> = (view.image().disparity.iter().enumerate())
            .flat_map(|(i, d)| match (*d >= 0.0, unseen.get(i) == Some(&true)) {
                (true, _) => [0, 0, 0, 255],
                (false, true) => [128, 128, 128, 255],
                (false, false) => [255; 4],
            })
            .collect();
        load::write_png_rgba8(path, w, h, &mask).map_err(|e| e.to_string())?;
    }
    let image = image.to_depth_image();
    load::write_png_rgba8(&a.out, w, h, &srgb8(&image)).map_err(|e| e.to_string())?;
    if let Some(path) = &a.depth_out {
        let depth = load::FloatImage::new(w, h, image.depth.clone()).ok_or("depth plane size")?;
        load::write_float_image(path, &depth).map_err(|e| e.to_string())?;
    }
    let s = frame.stats;
    eprintln!(
        "warp: {} of {n} reference(s), {} samples, {} landed, {} behind the eye; holes: {} cracks, {} disocclusions; {filled} filled; {} unseen (no reference saw anything: left empty); {w}x{h} in {ms:.1} ms",
        frame.references, s.samples, s.warped, s.behind, frame.holes.cracks, frame.holes.disocclusions, frame.holes.unseen
    );
    let landed = view.image().disparity.iter().filter(|d| **d >= 0.0).count();
    if almost_empty(landed, view.image().disparity.len()) {
        eprintln!(
            "warp: warning: the references cover {landed} of {} pixels of the view from --eye {} --target {}; they were taken from around {}: aim --eye/--target at what they see",
            w as usize * h as usize,
            format_vec3(a.eye),
            format_vec3(a.target),
            format_vec3(ref_eyes)
        );
    }
    Ok(())
}

fn main() -> ExitCode {
    let args = match Args::try_parse() {
        Ok(a) => a,
        Err(e) => {
            let code = e.exit_code();
            let _ = e.print();
            return ExitCode::from(code as u8);
        }
    };
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("warp: error: {e}");
            ExitCode::from(1)
        }
    }
}
