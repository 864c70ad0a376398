//! `lightfield`: light slabs from the command line (`ibr::lightfield`).
//!
//! ```sh
//! lightfield capture --obj model.obj --out model.plf --uv 32 --st 256
//! lightfield capture --transforms cap/transforms.json --out cap.plf --uv 16 --st 128
//! lightfield capture --obj model.obj --out ortho.plf --infinite uv
//! lightfield compress model.plf --out model_vq.plf --codewords 16384 --tile 2x2x2x2
//! lightfield render model_vq.plf --out view.png --eye -0.1,0.2,3 -W 1280 -H 720
//! lightfield info model_vq.plf
//! ```
//!
//! `capture` renders a model (OBJ or glTF) through a slab fitted around it, its cameras
//! looking along `--look` (dense capture, with a progress bar), or rebins the
//! photographs of a `transforms.json` capture into one (sparse capture, depth-corrected by
//! the depth maps: each ray read where the photographs saw its surface, rays that meet
//! nothing left empty, pull-push filling only what no photograph saw, and how much was
//! invented printed). `compress` vector-
//! quantises a light field (then zstd, in the file). `render` draws views of a light-field
//! file to PNG: one from `--eye`, or `--frames N` along a sweep across the camera plane.
//! Files are `.plf` (see `ibr::lightfield::file`). Errors are one line on stderr,
//! `lightfield: error: ...`, and exit code 1; a view in which the light field covers no
//! pixel is written but warned about (`lightfield: warning: ...`). Vector flags take
//! negative numbers as they are (`--eye -1,2,3`).

use clap::{Args, Parser, Subcommand, ValueEnum};
use demos::cli::parse_vec3;
use engine::{load, Camera, FrameOptions, Renderer, Rgba, Target};
use glam::Vec3;
use ibr::images::transforms::read_transforms;
use ibr::lightfield::{
    rebin, Interpolation, LightField, LightFieldObject, Lookup, Rays, Slab, TileShape, VqSettings,
};
use ibr::technique::{FrameLoop, FrameView, Technique};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

#[derive(Debug, Parser)]
#[command(
    name = "lightfield",
    version,
    about = "Light fields: capture light slabs from a model or a capture folder, compress them, and render views of them to PNG",
    long_about = None
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Capture a model (dense) or rebin a transforms.json capture (sparse) into a file.
    Capture(CaptureArgs),
    /// Vector-quantise a light field (codebook and indices, then zstd in the file).
    Compress(CompressArgs),
    /// Render views of a light field to PNG.
    Render(RenderArgs),
    /// Print a light field's slab, storage and size.
    Info {
        /// The light-field file.
        file: PathBuf,
    },
}

#[derive(Debug, Args)]
struct CaptureArgs {
    /// An OBJ model.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["gltf", "transforms"])]
    obj: Option<PathBuf>,
    /// A glTF model (.gltf or .glb).
    #[arg(long, value_name = "FILE", conflicts_with = "transforms")]
    gltf: Option<PathBuf>,
    /// A capture's transforms.json (or its folder), with depth maps: rebinned.
    #[arg(long, value_name = "FILE")]
    transforms: Option<PathBuf>,
    /// The light-field file to write.
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
    /// Camera-plane samples per side.
    #[arg(long, default_value_t = 32)]
    uv: u32,
    /// Focal-plane samples per side.
    #[arg(long, default_value_t = 256)]
    st: u32,
    /// The direction the capture cameras look (models; a sparse capture uses its
    /// photographs' mean direction).
    #[arg(long, value_name = "X,Y,Z", default_value = "0,0,-1", value_parser = parse_vec3, allow_hyphen_values = true)]
    look: Vec3,
    /// Up in the capture images.
    #[arg(long, value_name = "X,Y,Z", default_value = "0,1,0", value_parser = parse_vec3, allow_hyphen_values = true)]
    up: Vec3,
    /// Aperture prefiltering (models): each camera's image the mean of N x N views over
    /// its cell of the camera plane (1: none).
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=8))]
    aperture: u32,
    /// Put a plane at infinity (as `.lid` slabs may): `uv`, parallel-projection cameras
    /// looking along the directions from the camera plane to the focal plane's centre;
    /// `st`, pinhole cameras seeing what lies infinitely far in the focal plane's
    /// directions (an environment). Such slabs keep no depth.
    #[arg(long, value_name = "PLANE")]
    infinite: Option<PlaneArg>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum PlaneArg {
    Uv,
    St,
}

/// `slab` with the plane `--infinite` names moved to infinity.
fn place(slab: Slab, infinite: Option<PlaneArg>) -> Result<Slab, String> {
    match infinite {
        None => Ok(slab),
        Some(PlaneArg::Uv) => slab.with_uv_at_infinity(),
        Some(PlaneArg::St) => slab.with_st_at_infinity(),
    }
    .map_err(|e| format!("cannot move the plane to infinity: {e}"))
}

#[derive(Debug, Args)]
struct CompressArgs {
    /// The light-field file to compress.
    file: PathBuf,
    /// The compressed file to write.
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
    /// Codewords (1 to 65536).
    #[arg(long, default_value_t = 16384)]
    codewords: u32,
    /// Tile shape in u, v, s, t (powers of two).
    #[arg(long, default_value = "2x2x2x2", value_parser = parse_tile)]
    tile: TileShape,
    /// Tiles the codebook is trained on.
    #[arg(long, default_value_t = 1 << 18)]
    training: usize,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum InterpArg {
    Nearest,
    BilinearUv,
    Quadrilinear,
}

#[derive(Debug, Args)]
struct RenderArgs {
    /// The light-field file.
    file: PathBuf,
    /// The PNG to write (with --frames, a folder for NNNN.png); `--png` is the old spelling.
    #[arg(long = "out", alias = "png", value_name = "PATH")]
    out: PathBuf,
    /// Eye position (default: the middle of the camera plane).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    eye: Option<Vec3>,
    /// Point looked at (default: the middle of the focal plane).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    target: Option<Vec3>,
    /// Up direction.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    up: Option<Vec3>,
    /// Vertical field of view, degrees.
    #[arg(long, default_value_t = 40.0)]
    fov_y: f32,
    /// Image width in pixels.
    #[arg(short = 'W', long = "width", default_value_t = 1280, value_parser = clap::value_parser!(u32).range(1..=16384))]
    width: u32,
    /// Image height in pixels.
    #[arg(short = 'H', long = "height", default_value_t = 720, value_parser = clap::value_parser!(u32).range(1..=16384))]
    height: u32,
    /// The frame size as WIDTHxHEIGHT (the older spelling of -W and -H).
    #[arg(long, hide = true, value_parser = parse_size, conflicts_with_all = ["width", "height"])]
    size: Option<(u32, u32)>,
    #[arg(long, value_enum, default_value_t = InterpArg::Quadrilinear)]
    interpolation: InterpArg,
    /// Look samples up where the ray's plane crossings are, without depth correction.
    #[arg(long)]
    no_depth_correction: bool,
    /// Frames along a sweep across the camera plane (left to right), into the --out
    /// folder.
    #[arg(long)]
    frames: Option<u32>,
}

/// The most samples a capture may ask for (16 GiB of colour and depth).
const MAX_SAMPLES: u64 = 1 << 31;

fn parse_tile(s: &str) -> Result<TileShape, String> {
    let dims: Vec<u32> = s
        .split('x')
        .map(|p| p.trim().parse::<u32>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("expected UxVxSxT: {e}"))?;
    let dims: [u32; 4] = dims
        .try_into()
        .map_err(|_| format!("expected four sizes UxVxSxT, got {s:?}"))?;
    TileShape::new(dims).map_err(|e| e.to_string())
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once('x')
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, got {s:?}"))?;
    let n = |v: &str| v.trim().parse::<u32>().map_err(|e| format!("{v:?}: {e}"));
    let (w, h) = (n(w)?, n(h)?);
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(format!("a size from 1x1 to 16384x16384, got {s:?}"));
    }
    Ok((w, h))
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Capture(a) => capture(a),
        Command::Compress(a) => compress(a),
        Command::Render(a) => render(a),
        Command::Info { file } => info(file),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("lightfield: error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn bar(len: u64, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {pos}/{len} {msg}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_message(what.to_string());
    bar
}

fn capture(a: &CaptureArgs) -> Result<(), String> {
    let start = Instant::now();
    let counts = [a.uv, a.uv, a.st, a.st];
    // Checked before anything is allocated: a light field is held in memory whole.
    let samples = (u64::from(a.uv) * u64::from(a.st)).pow(2);
    if samples == 0 || samples > MAX_SAMPLES {
        return Err(format!(
            "--uv {} and --st {} make {samples} samples; a light field holds 1 to {MAX_SAMPLES} (8 bytes each with depth)",
            a.uv, a.st
        ));
    }
    let field = if let Some(t) = &a.transforms {
        let t = if t.is_dir() {
            t.join("transforms.json")
        } else {
            t.clone()
        };
        let images = read_transforms(&t).map_err(|e| e.to_string())?;
        // The object: the points the photographs saw; the look: their mean direction.
        let points: Vec<Vec3> = images
            .iter()
            .flat_map(|im| {
                (0..im.height())
                    .flat_map(move |y| (0..im.width()).filter_map(move |x| im.world_point(x, y)))
            })
            .collect();
        if points.is_empty() {
            return Err(format!("{}: the depth maps see nothing", t.display()));
        }
        let (lo, hi) = points
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), p| {
                (l.min(*p), h.max(*p))
            });
        let look = images.iter().map(|im| im.camera.forward()).sum::<Vec3>();
        let slab = Slab::facing(
            (lo + hi) * 0.5,
            (hi - lo).length() * 0.5,
            look,
            a.up,
            counts,
        )
        .map_err(|e| format!("cannot fit a slab to the photographs: {e}"))?;
        let r = rebin(place(slab, a.infinite)?, &images);
        let how = if r.depth_corrected {
            "surface points of"
        } else {
            "rays of (no depth: splatted)"
        };
        println!(
            "lightfield: rebinned {} {how} {} photographs: {:.1}% of the samples measured, {:.1}% invented by pull-push",
            r.rays,
            images.len(),
            r.confident() * 100.0,
            r.invented() * 100.0
        );
        r.field
    } else {
        let (path, loaded) = match (&a.obj, &a.gltf) {
            (Some(p), _) => (p, load::obj(p)),
            (None, Some(p)) => (p, load::gltf(p)),
            (None, None) => return Err("one of --obj, --gltf or --transforms is required".into()),
        };
        let loaded = loaded.map_err(|e| e.to_string())?;
        for w in &loaded.warnings {
            eprintln!("lightfield: warning: {w}");
        }
        let scene = loaded.scene;
        let draws: Vec<_> = scene.draws().collect();
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for d in &draws {
            for p in &d.mesh.positions {
                let w = d.transform.transform_point3(*p);
                lo = lo.min(w);
                hi = hi.max(w);
            }
        }
        if lo.x.is_nan() || lo.x > hi.x {
            return Err(format!(
                "{}: the model has nothing to capture",
                path.display()
            ));
        }
        let slab = Slab::facing(
            (lo + hi) * 0.5,
            (hi - lo).length() * 0.5,
            a.look,
            a.up,
            counts,
        )
        .map_err(|e| format!("cannot fit a slab to the model: {e}"))?;
        let slab = place(slab, a.infinite)?;
        let bar = bar(u64::from(a.uv * a.uv), "views");
        let lf = LightField::capture_prefiltered(
            &draws,
            &scene.lighting,
            slab,
            a.aperture,
            &mut |done, _| bar.set_position(done as u64),
        );
        bar.finish_and_clear();
        lf
    };
    field.save(&a.out).map_err(|e| e.to_string())?;
    println!(
        "lightfield: wrote {} ({} samples, {:.1} MB) in {:.1} s",
        a.out.display(),
        field.slab.len(),
        file_len(&a.out) as f64 / 1e6,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

fn file_len(p: &Path) -> u64 {
    std::fs::metadata(p).map_or(0, |m| m.len())
}

fn compress(a: &CompressArgs) -> Result<(), String> {
    let lf = LightField::load(&a.file).map_err(|e| e.to_string())?;
    if let Rays::Quantised(q) = &lf.rays {
        return Err(format!(
            "{}: already compressed ({} codewords of {} tiles); compress the raw light field it was made from",
            a.file.display(),
            q.codewords(),
            q.tile
        ));
    }
    let settings = VqSettings {
        tile: a.tile,
        codewords: a.codewords,
        training_tiles: a.training,
        ..VqSettings::default()
    };
    let start = Instant::now();
    let (q, report) = lf.quantise(&settings).map_err(|e| e.to_string())?;
    let trained = start.elapsed().as_secs_f64();
    q.save(&a.out).map_err(|e| e.to_string())?;
    println!(
        "lightfield: {} codewords of {} tiles trained on {} tiles and {} tiles encoded in {trained:.1} s (mean squared error {:.2})",
        report.codewords, a.tile, report.training_tiles, report.tiles, report.mse
    );
    println!(
        "lightfield: {:.1} MB in memory -> {:.2} MB ({:.1}:1); file {:.2} MB -> {:.3} MB ({:.1}:1): {}",
        lf.bytes() as f64 / 1e6,
        q.bytes() as f64 / 1e6,
        lf.bytes() as f64 / q.bytes() as f64,
        file_len(&a.file) as f64 / 1e6,
        file_len(&a.out) as f64 / 1e6,
        file_len(&a.file) as f64 / file_len(&a.out).max(1) as f64,
        a.out.display()
    );
    Ok(())
}

fn render(a: &RenderArgs) -> Result<(), String> {
    let lf = LightField::load(&a.file).map_err(|e| e.to_string())?;
    let slab = lf.slab;
    let middle = slab.viewpoint(0.5, 0.5);
    let up = a.up.unwrap_or(-slab.st.edge_b.normalize());
    let (w, h) = a.size.unwrap_or((a.width, a.height));
    let mut object = LightFieldObject::new("light field", lf);
    object.lookup = Lookup {
        interpolation: match a.interpolation {
            InterpArg::Nearest => Interpolation::Nearest,
            InterpArg::BilinearUv => Interpolation::BilinearUv,
            InterpArg::Quadrilinear => Interpolation::Quadrilinear,
        },
        depth_correction: !a.no_depth_correction,
    };
    let eyes: Vec<(PathBuf, Vec3)> = match a.frames {
        None => vec![(a.out.clone(), a.eye.unwrap_or(middle))],
        Some(n) => {
            std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
            (0..n.max(1))
                .map(|k| {
                    let f = (k as f32 + 0.5) / n.max(1) as f32;
                    (a.out.join(format!("{k:04}.png")), slab.viewpoint(f, 0.5))
                })
                .collect()
        }
    };
    let (mut renderer, mut frames) = (Renderer::new(), FrameLoop::new());
    let mut out = Target::new(w, h);
    let opts = FrameOptions {
        clear: Some(Rgba::new(0.05, 0.05, 0.06, 1.0)),
        ..Default::default()
    };
    let lighting = engine::Lighting::default();
    for (path, eye) in eyes {
        let target = a.target.unwrap_or(slab.look_target(eye));
        let camera = Camera::look_at(eye, target, up, a.fov_y.to_radians(), 1.0)
            .with_aspect(w, h)
            .with_depth_range(0.01 * slab.near, 4.0 * slab.far);
        let view = FrameView::still(&camera, w, h, &lighting);
        let t = Instant::now();
        let mut list: [&mut dyn Technique; 1] = [&mut object];
        frames.render(&mut renderer, [], &mut list, &view, &mut out, &opts);
        let ms = t.elapsed().as_secs_f64() * 1e3;
        image::save_buffer_with_format(
            &path,
            &out.to_rgba8(),
            w,
            h,
            image::ColorType::Rgba8,
            image::ImageFormat::Png,
        )
        .map_err(|e| format!("{}: cannot write PNG: {e}", path.display()))?;
        let last = object.last();
        println!(
            "lightfield: {} from {eye}: {} rays, {} samples read, {} pixels in {ms:.1} ms",
            path.display(),
            last.rays,
            last.taps,
            last.pixels
        );
        if last.pixels == 0 {
            eprintln!(
                "lightfield: warning: {}: the light field covers no pixel from {eye} looking at {target} (the view crosses none of its rays, or they are all empty); the PNG holds only the background",
                path.display()
            );
        }
    }
    Ok(())
}

fn info(file: &Path) -> Result<(), String> {
    let lf = LightField::load(file).map_err(|e| e.to_string())?;
    let s = lf.slab;
    println!(
        "{}: {} x {} (uv) by {} x {} (st), {} samples",
        file.display(),
        s.nu,
        s.nv,
        s.ns,
        s.nt,
        s.len()
    );
    let at = |k: usize| {
        if s.infinite[k] {
            " at infinity (directions)"
        } else {
            ""
        }
    };
    println!(
        "  uv plane{}: corner {} edges {} {}",
        at(0),
        s.uv.origin,
        s.uv.edge_a,
        s.uv.edge_b
    );
    println!(
        "  st plane{}: corner {} edges {} {}",
        at(1),
        s.st.origin,
        s.st.edge_a,
        s.st.edge_b
    );
    println!(
        "  depth range {} to {}, depth kept: {}",
        s.near,
        s.far,
        lf.has_depth()
    );
    match &lf.rays {
        Rays::Raw(_) => println!("  raw samples: {:.1} MB in memory", lf.bytes() as f64 / 1e6),
        Rays::Quantised(q) => println!(
            "  quantised: {} codewords of {} tiles, {} indices, {:.2} MB in memory",
            q.codewords(),
            q.tile,
            q.indices.len(),
            lf.bytes() as f64 / 1e6
        ),
    }
    println!("  file: {:.3} MB", file_len(file) as f64 / 1e6);
    Ok(())
}
