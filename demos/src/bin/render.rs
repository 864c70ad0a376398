//! `render`: loads an OBJ or glTF, renders it with the peers' camera conventions, and
//! optionally times frames and writes the colour (PNG, `--out`) and depth (raw f32) images,
//! or a `transforms.json` capture of one or more views (`--capture DIR --views N`) whose
//! colour files hold the same bytes `--out` writes for the same view, in the shading's
//! encoding (unorm for `vertex`, `flat` and `faceid`, sRGB for `lit` and `textured`).
//!
//! The counterpart of `../shared/peers/llvmpipe_render.py`: same flags, same camera
//! (`look_at_rh` + `perspective_rh_gl`), same outputs (PNG with a top-left origin; depth as
//! little-endian f32 OpenGL window depth, top row first, 1.0 where nothing was drawn) and
//! the same last stdout line when timing
//! (`render NAME WxH tris=T threads=N median_ms=.. min_ms=.. p90_ms=.. frames=N`, with the
//! peer's median and `p90 = sorted[floor(0.9 (n - 1))]`). The peer's `--png` is kept as
//! a hidden alias of `--out`; the other flags follow the tools' shared vocabulary
//! (`demos::cli`), negative vectors included (`--eye -1,2,3`).
//!
//! Stderr carries the (last) frame's work counters (`render: stats: ...`, `FrameStats`)
//! and, when timing, each stage's median over the timed frames (`render: stages:
//! vertex_ms=.. front_ms=.. tiles_ms=.. raster_sum_ms=.. resolve_sum_ms=..`, `StageTimes`).
//!
//! When the model covers (almost) none of the frame, one line on stderr says so, with the
//! model's bounds and an `--eye`/`--target` that would frame it.
//!
//! Every error (unreadable model, bad flag value, unwritable output) is one line on stderr,
//! `render: error: ...`, and exit code 1 (2 for other usage errors).

use clap::error::ErrorKind;
use clap::{ArgGroup, Parser, ValueEnum};
use demos::cli::{almost_empty, format_vec3, parse_vec3};
use engine::{
    load, Camera, Cull, Encoding, FrameOptions, FrameStats, Material, Projection, Renderer, Rgba,
    Scene, Shading, StageTimes, Target,
};
use glam::{Mat4, Vec3};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum ShadingArg {
    /// Interpolated vertex colours (default colours where a mesh has none), unlit, unorm.
    Vertex,
    /// The peers' per-face rule, unorm bytes.
    Flat,
    /// RGB = triangle index + 1 (24-bit little-endian), unorm; 0 = background.
    Faceid,
    /// The loaded materials without their textures, lit, sRGB.
    Lit,
    /// The loaded materials as they are, sRGB.
    Textured,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum CullArg {
    None,
    Back,
}

/// Render one OBJ or glTF model headless: a PNG, a depth file or a capture of views.
#[derive(Debug, Parser)]
#[command(name = "render", version, allow_negative_numbers = true)]
#[command(group(ArgGroup::new("model").required(true).args(["obj", "gltf"])))]
struct Args {
    /// Wavefront OBJ file (with its MTL materials, if any).
    #[arg(long, value_name = "FILE")]
    obj: Option<PathBuf>,
    /// glTF 2.0 file (.gltf or .glb).
    #[arg(long, value_name = "FILE")]
    gltf: Option<PathBuf>,
    /// Image width in pixels.
    #[arg(short = 'W', long = "width", default_value_t = 640)]
    width: u32,
    /// Image height in pixels.
    #[arg(short = 'H', long = "height", default_value_t = 480)]
    height: u32,
    /// Camera position.
    #[arg(long, value_name = "X,Y,Z", default_value = "0,0,3", allow_hyphen_values = true, value_parser = parse_vec3)]
    eye: Vec3,
    /// Point the camera looks at.
    #[arg(long, value_name = "X,Y,Z", default_value = "0,0,0", allow_hyphen_values = true, value_parser = parse_vec3)]
    target: Vec3,
    /// Camera up direction.
    #[arg(long, value_name = "X,Y,Z", default_value = "0,1,0", allow_hyphen_values = true, value_parser = parse_vec3)]
    up: Vec3,
    /// Vertical field of view in degrees.
    #[arg(long = "fov-y", value_name = "DEG", default_value_t = 60.0)]
    fov_y: f32,
    /// Near plane distance.
    #[arg(long, default_value_t = 0.1)]
    near: f32,
    /// Far plane distance.
    #[arg(long, default_value_t = 100.0)]
    far: f32,
    /// What to draw.
    #[arg(long, value_enum, default_value_t = ShadingArg::Vertex)]
    shading: ShadingArg,
    /// Face culling (default: none for vertex/flat/faceid, per material for lit/textured).
    #[arg(long, value_enum)]
    cull: Option<CullArg>,
    /// Worker threads (default: rayon's, one per core).
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
    /// Time N frames (after the warm-up) and print the timing line.
    #[arg(long, value_name = "N")]
    frames: Option<usize>,
    /// Untimed frames before the timed ones.
    #[arg(long, value_name = "N", default_value_t = 3)]
    warmup: usize,
    /// Write the colour image as PNG (`--png` is the peer's spelling, also taken).
    #[arg(long = "out", alias = "png", value_name = "FILE")]
    out: Option<PathBuf>,
    /// Write the depth image as raw little-endian f32 (OpenGL window depth, top row first).
    #[arg(long, value_name = "FILE")]
    depth: Option<PathBuf>,
    /// Write a capture into DIR: transforms.json (camera-to-world poses, intrinsics),
    /// images/NNNN.png and depth/NNNN.pfm (distance along the optical axis), one frame per
    /// view; the `warp` command reads it.
    #[arg(long, value_name = "DIR")]
    capture: Option<PathBuf>,
    /// Views in the capture: eyes on a horizontal arc around --target through --eye.
    #[arg(long, value_name = "N", default_value_t = 1)]
    views: usize,
    /// The arc's angle, degrees, centred on --eye.
    #[arg(long, value_name = "DEG", default_value_t = 20.0)]
    spread: f32,
    /// Light as the textured llvmpipe peer (`../shared/peers/llvmpipe_textured.py`) does:
    /// grey ambient 0.2 and one white directional light of 0.8 from (0.4, 0.8, 0.45), no
    /// highlights, on the texture's bytes as stored (unorm texture and target, as the
    /// peer's GL context has no sRGB decoding), for `lit` and `textured`.
    #[arg(long)]
    peer_light: bool,
}

/// Checks what clap cannot: sizes, camera sanity, counts.
fn check(a: &Args) -> Result<(), String> {
    let max = engine::target::MAX_TARGET_SIZE;
    if a.width == 0 || a.height == 0 || a.width > max || a.height > max {
        return Err(format!(
            "image size {}x{} out of range (1..={max} per side)",
            a.width, a.height
        ));
    }
    if !(a.fov_y > 0.0 && a.fov_y < 180.0) {
        return Err(format!("--fov-y {} must be in (0, 180) degrees", a.fov_y));
    }
    if !(a.near > 0.0 && a.far > a.near && a.far.is_finite()) {
        return Err(format!(
            "need 0 < near < far (finite); got near={} far={}",
            a.near, a.far
        ));
    }
    let dir = a.target - a.eye;
    if dir.length_squared() == 0.0 {
        return Err("--eye and --target are the same point".into());
    }
    if dir.cross(a.up).length_squared() == 0.0 {
        return Err("--up is zero or parallel to the view direction".into());
    }
    if matches!(a.threads, Some(n) if n == 0 || n > 1024) {
        return Err("--threads must be in 1..=1024".into());
    }
    if a.frames == Some(0) {
        return Err("--frames must be at least 1".into());
    }
    // Fail before a long render rather than after it.
    for out in [&a.out, &a.depth].into_iter().flatten() {
        match out.parent() {
            Some(dir) if !dir.as_os_str().is_empty() && !dir.is_dir() => {
                return Err(format!(
                    "{}: cannot write: folder {} does not exist",
                    out.display(),
                    dir.display()
                ))
            }
            _ => {}
        }
    }
    Ok(())
}

/// The peers' colours for meshes without any: `(p - min) / (max - min)` per axis in f32
/// (an extent of 0 counts as 1), over `lo..hi`.
fn default_colors(positions: &[Vec3], lo: Vec3, hi: Vec3) -> Vec<Rgba> {
    let ext = hi - lo;
    let ext = Vec3::new(
        if ext.x > 0.0 { ext.x } else { 1.0 },
        if ext.y > 0.0 { ext.y } else { 1.0 },
        if ext.z > 0.0 { ext.z } else { 1.0 },
    );
    positions
        .iter()
        .map(|p| {
            let c = (*p - lo) / ext;
            Rgba::new(c.x, c.y, c.z, 1.0)
        })
        .collect()
}

/// Bounds of every `v` line of an OBJ, as the peers compute them (unreferenced vertices
/// included), or `None` if the file cannot be re-read.
fn obj_bounds(path: &Path) -> Option<(Vec3, Vec3)> {
    let text = std::fs::read_to_string(path).ok()?;
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for line in text.lines() {
        let mut w = line.split_whitespace();
        if w.next() != Some("v") {
            continue;
        }
        let xyz: Vec<f32> = w.take(3).filter_map(|t| t.parse().ok()).collect();
        if let [x, y, z] = xyz[..] {
            lo = lo.min(Vec3::new(x, y, z));
            hi = hi.max(Vec3::new(x, y, z));
        }
    }
    (lo.x <= hi.x).then_some((lo, hi))
}

/// Bounds of every mesh vertex (object space).
fn scene_bounds(scene: &Scene) -> (Vec3, Vec3) {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for p in scene.meshes.iter().flat_map(|m| &m.positions) {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    (lo, hi)
}

/// The textured peer's lighting and arithmetic: `colour = texel * (0.2 + 0.8 max(0, n .
/// l))` on the stored bytes as they are (the peer's texture and framebuffer are not sRGB),
/// so textures are re-read as unorm and the target is unorm; returns that encoding.
fn peer_light(scene: &mut Scene) -> Encoding {
    for m in &mut scene.materials {
        if let Some(t) = &m.base_texture {
            let l = &t.levels()[0];
            let unorm = engine::Texture::from_packed(
                l.width,
                l.height,
                l.texels.clone(),
                Encoding::Unorm,
                false,
            );
            m.base_texture = unorm.map(std::sync::Arc::new);
        }
    }
    scene.lighting = engine::Lighting {
        ambient: Rgba::new(0.2, 0.2, 0.2, 1.0),
        lights: vec![engine::Light::Directional {
            direction: -Vec3::new(0.4, 0.8, 0.45),
            color: Rgba::new(0.8, 0.8, 0.8, 1.0),
        }],
    };
    for m in &mut scene.materials {
        if let Shading::Lit { specular, .. } = &mut m.shading {
            *specular = 0.0;
        }
    }
    Encoding::Unorm
}

/// Rewrites the loaded scene for a shading mode; returns the target encoding.
fn prepare(scene: &mut Scene, shading: ShadingArg, bounds: (Vec3, Vec3)) -> Encoding {
    let fill_colors = |scene: &mut Scene| {
        for m in &mut scene.meshes {
            if m.colors.is_empty() {
                m.colors = default_colors(&m.positions, bounds.0, bounds.1);
            }
        }
    };
    let replace = |scene: &mut Scene, mat: Material| {
        for m in &mut scene.materials {
            *m = Material {
                name: std::mem::take(&mut m.name),
                ..mat.clone()
            };
        }
    };
    match shading {
        ShadingArg::Faceid => {
            replace(
                scene,
                Material {
                    shading: Shading::FaceId,
                    ..Material::default()
                },
            );
            Encoding::Unorm
        }
        ShadingArg::Flat => {
            fill_colors(scene);
            replace(
                scene,
                Material {
                    shading: Shading::Flat,
                    ..Material::default()
                },
            );
            Encoding::Unorm
        }
        ShadingArg::Vertex => {
            fill_colors(scene);
            replace(scene, Material::unlit(Rgba::WHITE));
            Encoding::Unorm
        }
        ShadingArg::Lit => {
            for m in &mut scene.materials {
                m.base_texture = None;
            }
            Encoding::Srgb
        }
        ShadingArg::Textured => Encoding::Srgb,
    }
}

/// Bounds of every drawn vertex in world space (instances' transforms applied); `None`
/// when nothing is drawn.
fn world_bounds(scene: &Scene) -> Option<(Vec3, Vec3)> {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for inst in &scene.instances {
        let Some(mesh) = scene.meshes.get(inst.mesh) else {
            continue;
        };
        for p in &mesh.positions {
            let w = inst.transform.transform_point3(*p);
            if w.is_finite() {
                lo = lo.min(w);
                hi = hi.max(w);
            }
        }
    }
    (lo.x <= hi.x).then_some((lo, hi))
}

/// The warning for a frame the model (almost) misses: the pixels covered (drawn colour or
/// depth), the model's world bounds and a camera that would frame them. `None` when the
/// frame is covered enough.
fn coverage_warning(a: &Args, target: &Target, scene: &Scene) -> Option<String> {
    let bytes = target.to_rgba8();
    let depth = target.depth_gl_image();
    let covered = bytes
        .chunks_exact(4)
        .zip(&depth)
        .filter(|(px, d)| **d < 1.0 || *px != [0, 0, 0, 255])
        .count();
    let total = depth.len();
    if !almost_empty(covered, total) {
        return None;
    }
    let mut line = format!(
        "the model covers {covered} of {total} pixels from --eye {} --target {}",
        format_vec3(a.eye),
        format_vec3(a.target)
    );
    if let Some((lo, hi)) = world_bounds(scene) {
        let centre = 0.5 * (lo + hi);
        let radius = (0.5 * (hi - lo).length()).max(1e-3);
        // Far enough for the bounding sphere to fit the vertical field of view, looking
        // along the current view direction.
        let dist = radius / (0.5 * a.fov_y.to_radians()).sin();
        let dir = (a.target - a.eye).normalize_or(Vec3::NEG_Z);
        line += &format!(
            "; its bounds run from {} to {} (centre {}): try --eye {} --target {}",
            format_vec3(lo),
            format_vec3(hi),
            format_vec3(centre),
            format_vec3(centre - dir * dist),
            format_vec3(centre)
        );
        if dist + radius > a.far {
            line += &format!(" --far {}", (1.5 * (dist + radius)).ceil());
        }
    } else {
        line += "; aim the camera with --eye and --target";
    }
    Some(line)
}

/// The peer's statistics: `statistics.median` and `sorted[floor(0.9 (n - 1))]`.
fn summary(times_ms: &[f64]) -> (f64, f64, f64) {
    let mut t = times_ms.to_vec();
    t.sort_by(f64::total_cmp);
    let n = t.len();
    if n == 0 {
        return (0.0, 0.0, 0.0);
    }
    let median = if n % 2 == 1 {
        t[n / 2]
    } else {
        0.5 * (t[n / 2 - 1] + t[n / 2])
    };
    (median, t[0], t[(0.9 * (n - 1) as f64) as usize])
}

/// The timed frames' stage times, each stage's median in milliseconds: the vertex, front
/// and tile stages by the wall clock, and within the tile stage the raster (clears and
/// loads included) and resolve time summed over the workers (`StageTimes`).
fn stages_line(stages: &[StageTimes]) -> String {
    let median = |f: fn(&StageTimes) -> std::time::Duration| {
        let ms: Vec<f64> = stages.iter().map(|s| f(s).as_secs_f64() * 1e3).collect();
        summary(&ms).0
    };
    format!(
        "render: stages: vertex_ms={:.3} front_ms={:.3} tiles_ms={:.3} raster_sum_ms={:.3} \
         resolve_sum_ms={:.3}",
        median(|s| s.vertex),
        median(|s| s.front),
        median(|s| s.tiles),
        median(|s| s.raster),
        median(|s| s.resolve)
    )
}

fn stats_line(s: &FrameStats) -> String {
    format!(
        "render: stats: draws={} triangles_in={} clipped={} culled={} rejected={} set_up={} \
         binned={} fragments_tested={} shaded={} written={} rows_shaded={} rows_paired={} \
         blocks_full={} blocks_partial={} blocks_hiz_rejected={}",
        s.draws,
        s.triangles_in,
        s.triangles_clipped,
        s.triangles_culled,
        s.triangles_rejected,
        s.triangles_set_up,
        s.triangles_binned,
        s.fragments_tested,
        s.fragments_shaded,
        s.fragments_written,
        s.rows_shaded,
        s.rows_paired,
        s.blocks_full,
        s.blocks_partial,
        s.blocks_hiz_rejected
    )
}

/// Loads the model at `path` and prepares it for the shading asked for; the scene, the
/// target's encoding and the model's file name (warnings and a summary on stderr).
fn load_scene(a: &Args, path: &Path, is_obj: bool) -> Result<(Scene, Encoding, String), String> {
    let t0 = Instant::now();
    let loaded = if is_obj {
        load::obj(path)
    } else {
        load::gltf(path)
    }
    .map_err(|e| e.to_string())?;
    for w in &loaded.warnings {
        eprintln!("render: warning: {w}");
    }
    let mut scene = loaded.scene;
    if scene.instances.is_empty() {
        eprintln!("render: notice: the scene has nothing to draw; the frame is the clear colour");
    }
    let bounds = if is_obj {
        obj_bounds(path).unwrap_or_else(|| scene_bounds(&scene))
    } else {
        scene_bounds(&scene)
    };
    let mut encoding = prepare(&mut scene, a.shading, bounds);
    if a.peer_light {
        encoding = peer_light(&mut scene);
    }
    let name = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    eprintln!(
        "render: loaded {name}: {} triangles, {} meshes, {} instances in {:.1} ms",
        scene.triangle_count(),
        scene.meshes.len(),
        scene.instances.len(),
        t0.elapsed().as_secs_f64() * 1e3
    );
    Ok((scene, encoding, name))
}

/// Writes what the flags ask for: the PNG, the depth file, the dataset of views.
fn write_outputs(
    a: &Args,
    target: &Target,
    scene: &Scene,
    camera: &Camera,
    encoding: Encoding,
    opts: &FrameOptions,
) -> Result<(), String> {
    if let Some(png) = &a.out {
        image::save_buffer_with_format(
            png,
            &target.to_rgba8(),
            target.width(),
            target.height(),
            image::ColorType::Rgba8,
            image::ImageFormat::Png,
        )
        .map_err(|e| format!("{}: cannot write PNG: {e}", png.display()))?;
    }
    if let Some(depth) = &a.depth {
        let bytes: Vec<u8> = target
            .depth_gl_image()
            .iter()
            .flat_map(|d| d.to_le_bytes())
            .collect();
        std::fs::write(depth, bytes)
            .map_err(|e| format!("{}: cannot write depth: {e}", depth.display()))?;
    }
    if let Some(dir) = &a.capture {
        let cameras: Vec<Camera> = demos::dataset::arc(a.eye, a.target, a.up, a.views, a.spread)
            .into_iter()
            .map(|eye| Camera {
                view: Mat4::look_at_rh(eye, a.target, a.up),
                ..*camera
            })
            .collect();
        let size = (a.width, a.height);
        let n = demos::dataset::write(dir, scene, &cameras, size, encoding, opts)?;
        eprintln!(
            "render: wrote a capture of {n} view(s) to {}",
            dir.display()
        );
    }
    Ok(())
}

fn run(a: &Args) -> Result<(), String> {
    check(a)?;
    let (path, is_obj) = match (&a.obj, &a.gltf) {
        (Some(p), _) => (p.as_path(), true),
        (None, Some(p)) => (p.as_path(), false),
        (None, None) => return Err("one of --obj or --gltf is required".into()),
    };
    let (scene, encoding, name) = load_scene(a, path, is_obj)?;

    let camera = Camera {
        view: Mat4::look_at_rh(a.eye, a.target, a.up),
        projection: Projection::Perspective {
            fov_y: a.fov_y.to_radians(),
            aspect: a.width as f32 / a.height as f32,
            near: a.near,
            far: a.far,
        },
    };
    let cull = match (a.cull, a.shading) {
        (Some(CullArg::None), _) => Cull::None,
        (Some(CullArg::Back), _) => Cull::Back,
        (None, ShadingArg::Lit | ShadingArg::Textured) => Cull::PerMaterial,
        (None, _) => Cull::None,
    };
    let opts = FrameOptions {
        clear: Some(Rgba::BLACK),
        cull,
    };
    let mut target = Target::with_encoding(a.width, a.height, encoding);

    let render = |target: &mut Target| {
        let mut renderer = Renderer::new();
        let mut times = Vec::new();
        let mut stages = Vec::new();
        let mut stats = FrameStats::default();
        match a.frames {
            None => stats = renderer.render_scene(&scene, &camera, target, &opts),
            Some(n) => {
                for _ in 0..a.warmup {
                    renderer.render_scene(&scene, &camera, target, &opts);
                }
                for _ in 0..n {
                    let t = Instant::now();
                    stats = renderer.render_scene(&scene, &camera, target, &opts);
                    times.push(t.elapsed().as_secs_f64() * 1e3);
                    stages.push(renderer.stage_times());
                }
            }
        }
        (stats, times, stages, rayon::current_num_threads())
    };
    let (stats, times, stages, threads) = match a.threads {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| format!("cannot start {n} threads: {e}"))?
            .install(|| render(&mut target)),
        None => render(&mut target),
    };
    eprintln!("{}", stats_line(&stats));
    if !stages.is_empty() {
        eprintln!("{}", stages_line(&stages));
    }

    if !scene.instances.is_empty() {
        if let Some(line) = coverage_warning(a, &target, &scene) {
            eprintln!("render: warning: {line}");
        }
    }
    write_outputs(a, &target, &scene, &camera, encoding, &opts)?;
    if a.frames.is_some() {
        let (median, min, p90) = summary(&times);
        println!(
            "render {name} {}x{} tris={} threads={threads} median_ms={median:.3} \
             min_ms={min:.3} p90_ms={p90:.3} frames={}",
            a.width,
            a.height,
            scene.triangle_count(),
            times.len()
        );
    }
    Ok(())
}

/// Reports a clap error: help and version as clap does; anything else as one line.
fn clap_error(e: clap::Error) -> ExitCode {
    if matches!(
        e.kind(),
        ErrorKind::DisplayHelp
            | ErrorKind::DisplayVersion
            | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    ) {
        e.exit();
    }
    let text = e.to_string();
    let msg: Vec<&str> = text
        .lines()
        .take_while(|l| !l.trim().is_empty())
        .map(str::trim)
        .collect();
    let msg = msg.join(" ");
    eprintln!(
        "render: error: {}",
        msg.strip_prefix("error: ").unwrap_or(&msg)
    );
    match e.kind() {
        ErrorKind::InvalidValue | ErrorKind::ValueValidation => ExitCode::from(1),
        _ => ExitCode::from(2),
    }
}

fn main() -> ExitCode {
    let args = match Args::try_parse() {
        Ok(a) => a,
        Err(e) => return clap_error(e),
    };
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(msg) => {
            eprintln!("render: error: {msg}");
            ExitCode::from(1)
        }
    }
}
