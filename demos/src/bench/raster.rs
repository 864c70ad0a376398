//! Benchmark sweeps behind the `bench` CLI: what is measured, how, and the CSV it becomes.
//!
//! A measurement renders one scene from one camera into one target size: `warmup` frames
//! first (caches, scratch buffers), then up to `frames` timed frames of
//! `Renderer::render_scene` alone (`std::time::Instant`), stopping early once the time
//! time limit is spent but never before [`MIN_FRAMES`]. Procedural scenes reproduce the peers'
//! set-up (`shared/peers/make_scenes.py`: torus of major radius 0.95 and minor 0.38 tilted by
//! (-55, 20) degrees, eye (0, 0, 3), 60 degree field of view) with a lit, vertex-coloured
//! material; shared models are framed by their bounding sphere and keep their own
//! materials.

use crate::bench::sweep::{CsvRow, Timing};
use crate::bench::{Progress, RunFlags, Sweep};
use crate::chart::{Chart, LineAndDots, Point};
use crate::timing::Summary;
use engine::procedural;
use engine::{Camera, FrameOptions, FrameStats, Material, Renderer, Rgba, Scene, Target};
use glam::{Mat4, Vec3};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

pub use crate::bench::sweep::MIN_FRAMES;

/// How much a sweep measures.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Target sizes of the resolution series (torus of `fixed_triangles`).
    pub resolutions: Vec<(u32, u32)>,
    pub fixed_triangles: u32,
    /// Torus sizes of the triangle series (at `fixed_resolution`).
    pub triangle_counts: Vec<u32>,
    pub fixed_resolution: (u32, u32),
    /// Whether to render the shared models (when their folder exists).
    pub models: bool,
    /// How each measurement times its frames.
    pub timing: Timing,
}

impl Settings {
    /// The full sweep.
    pub fn full() -> Settings {
        Settings {
            resolutions: vec![
                (320, 240),
                (640, 480),
                (1280, 720),
                (1920, 1080),
                (2560, 1440),
                (3840, 2160),
            ],
            fixed_triangles: 100_000,
            triangle_counts: vec![1_000, 10_000, 100_000, 1_000_000, 2_000_000],
            fixed_resolution: (1280, 720),
            models: true,
            timing: Timing::new(3, 31, 3),
        }
    }

    /// Every point of the full sweep with few frames: about a minute at most.
    pub fn quick() -> Settings {
        Settings {
            timing: Timing {
                warmup: 1,
                frames: 9,
                time_limit: Duration::from_millis(1200),
            },
            ..Settings::full()
        }
    }

    /// A seconds-long smoke run (tests): two small sizes, two small meshes, no models.
    pub fn tiny() -> Settings {
        Settings {
            resolutions: vec![(160, 120), (320, 240)],
            fixed_triangles: 10_000,
            triangle_counts: vec![1_000, 10_000],
            fixed_resolution: (320, 240),
            models: false,
            timing: Timing {
                warmup: 0,
                frames: 2,
                time_limit: Duration::from_millis(200),
            },
        }
    }
}

/// One measurement: a CSV row.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// `resolution`, `triangles` or `model`.
    pub series: String,
    pub mesh: String,
    pub triangles: u64,
    pub width: u32,
    pub height: u32,
    pub threads: usize,
    pub time: Summary,
    pub stats: FrameStats,
}

impl CsvRow for Row {
    const HEADER: &'static str = "series,mesh,triangles,width,height,threads,median_ms,min_ms,p90_ms,mean_ms,frames,triangles_set_up,fragments_shaded";

    fn csv(&self) -> String {
        format!(
            "{},{},{},{},{},{},{:.4},{:.4},{:.4},{:.4},{},{},{}",
            self.series,
            self.mesh.replace(',', "_"),
            self.triangles,
            self.width,
            self.height,
            self.threads,
            self.time.median_ms,
            self.time.min_ms,
            self.time.p90_ms,
            self.time.mean_ms,
            self.time.frames,
            self.stats.triangles_set_up,
            self.stats.fragments_shaded
        )
    }
}

/// The sweep's charts: file name and chart.
pub fn charts(rows: &[Row]) -> Vec<(&'static str, Chart)> {
    vec![
        ("raster_resolution.png", resolution_chart(rows)),
        ("raster_triangles.png", triangles_chart(rows)),
    ]
}

/// Median frame time against megapixels for the `resolution` rows.
pub fn resolution_chart(rows: &[Row]) -> Chart {
    let line: Vec<Point> = rows
        .iter()
        .filter(|r| r.series == "resolution")
        .map(|r| Point {
            x: r.width as f64 * r.height as f64 / 1e6,
            y: r.time.median_ms,
            label: format!("{}x{}", r.width, r.height),
        })
        .collect();
    let mesh = rows
        .iter()
        .find(|r| r.series == "resolution")
        .map_or(String::new(), |r| r.mesh.clone());
    Chart::LineAndDots(LineAndDots {
        title: format!("Frame time vs resolution ({mesh})"),
        x_desc: "megapixels",
        y_desc: "median frame time (ms)",
        line_name: mesh,
        line,
        dots_name: "",
        dots: Vec::new(),
        log_x: false,
        log_y: false,
    })
}

/// Median frame time against triangle count: the torus series as a line, the shared
/// models as labelled dots.
pub fn triangles_chart(rows: &[Row]) -> Chart {
    let points = |series: &str| -> Vec<Point> {
        rows.iter()
            .filter(|r| r.series == series)
            .map(|r| Point {
                x: r.triangles.max(1) as f64,
                y: r.time.median_ms,
                label: r.mesh.clone(),
            })
            .collect()
    };
    let size = rows
        .iter()
        .find(|r| r.series == "triangles")
        .map_or(String::new(), |r| format!(" at {}x{}", r.width, r.height));
    Chart::LineAndDots(LineAndDots {
        title: format!("Frame time vs triangles{size}"),
        x_desc: "triangles",
        y_desc: "median frame time (ms)",
        line_name: "procedural torus".into(),
        line: points("triangles"),
        dots_name: "shared models",
        dots: points("model"),
        log_x: true,
        log_y: true,
    })
}

/// Short names for triangle counts: 1k, 100k, 2M.
pub fn count_name(n: u64) -> String {
    if n >= 1_000_000 && n.is_multiple_of(1_000_000) {
        format!("{}M", n / 1_000_000)
    } else if n >= 1_000 && n.is_multiple_of(1_000) {
        format!("{}k", n / 1_000)
    } else {
        n.to_string()
    }
}

/// The peers' tilted torus of `n` triangles, lit, with colours from its normals.
pub fn torus_scene(n: u32) -> Scene {
    let mut s = Scene::default();
    let tilt =
        Mat4::from_rotation_y(20f32.to_radians()) * Mat4::from_rotation_x(-55f32.to_radians());
    s.add(
        procedural::torus_with_triangles(n),
        Material::lit(Rgba::WHITE),
        tilt,
    );
    s
}

/// The peers' default camera: eye (0, 0, 3) looking at the origin, 60 degrees, 0.1 - 100.
pub fn peer_camera(width: u32, height: u32) -> Camera {
    Camera::look_at(
        Vec3::new(0.0, 0.0, 3.0),
        Vec3::ZERO,
        Vec3::Y,
        60f32.to_radians(),
        1.0,
    )
    .with_aspect(width, height)
    .with_depth_range(0.1, 100.0)
}

/// A camera that frames a scene's bounding sphere from the front, a little above.
pub fn framing_camera(scene: &Scene, width: u32, height: u32) -> Camera {
    let s = scene.bounding_sphere();
    let r = s.radius.max(1e-3);
    let fov = 50f32.to_radians();
    let aspect = width.max(1) as f32 / height.max(1) as f32;
    let half = (fov * 0.5).tan().min((fov * 0.5).tan() * aspect).atan();
    let dist = r / half.sin() * 1.05;
    let eye = s.center + Vec3::new(0.35, 0.3, 1.0).normalize() * dist;
    Camera::look_at(eye, s.center, Vec3::Y, fov, aspect)
        .with_depth_range((dist - 1.5 * r).max(dist * 1e-3), dist + 1.5 * r)
}

/// Times one scene from one camera at one size.
pub fn measure(
    renderer: &mut Renderer,
    scene: &Scene,
    camera: &Camera,
    (width, height): (u32, u32),
    settings: &Settings,
) -> (Summary, FrameStats) {
    let mut target = Target::new(width, height);
    let opts = FrameOptions {
        clear: Some(Rgba::new(0.1, 0.1, 0.12, 1.0)),
        ..Default::default()
    };
    let frames = settings.timing.run(|| {
        let t0 = Instant::now();
        let stats = renderer.render_scene(scene, camera, &mut target, &opts);
        (t0.elapsed(), stats)
    });
    let times: Vec<Duration> = frames.iter().map(|f| f.0).collect();
    let stats = frames.last().map_or_else(FrameStats::default, |f| f.1);
    (Summary::of(&times), stats)
}

/// The shared models folder: `$PARALLAX_ASSETS`, else `shared/assets` beside the
/// workspace, else `/work/shared/assets`; `None` when none exists.
pub fn default_assets_dir() -> Option<PathBuf> {
    let mut candidates = Vec::new();
    if let Some(p) = std::env::var_os("PARALLAX_ASSETS") {
        candidates.push(PathBuf::from(p));
    }
    let ws = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    candidates.push(ws.join("../shared/assets"));
    candidates.push(PathBuf::from("/work/shared/assets"));
    candidates.into_iter().find(|p| p.is_dir())
}

/// Model files under `dir` (`.obj`, `.gltf`, `.glb`), one per model name (a `.glb` is
/// preferred over a `.gltf` over an `.obj` of the same name), sorted by name.
pub fn find_models(dir: &Path) -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        let mut entries: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                walk(&p, out);
            } else if rank(&p).is_some() {
                out.push(p);
            }
        }
    }
    fn rank(p: &Path) -> Option<u8> {
        match p.extension()?.to_str()?.to_ascii_lowercase().as_str() {
            "glb" => Some(0),
            "gltf" => Some(1),
            "obj" => Some(2),
            _ => None,
        }
    }
    let mut all = Vec::new();
    walk(dir, &mut all);
    let mut best: std::collections::BTreeMap<String, PathBuf> = Default::default();
    for p in all {
        let name = model_name(&p);
        let better = best.get(&name).is_none_or(|q| rank(&p) < rank(q));
        if better {
            best.insert(name, p);
        }
    }
    best.into_values().collect()
}

/// A model's name: its file stem.
pub fn model_name(p: &Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// What a sweep is about to do, for progress reporting.
#[derive(Clone, Debug)]
pub struct Step {
    pub series: &'static str,
    pub mesh: String,
    pub size: (u32, u32),
}

/// The resolution and triangle-count series, then the given models; `progress` is called
/// before each measurement with its 0-based index and the total.
pub fn raster(
    settings: &Settings,
    models: &[(String, Scene)],
    mut progress: impl FnMut(usize, usize, &Step),
) -> Vec<Row> {
    let total = settings.resolutions.len()
        + settings.triangle_counts.len()
        + if settings.models { models.len() } else { 0 };
    let mut rows = Vec::with_capacity(total);
    let mut renderer = Renderer::new();
    let threads = rayon::current_num_threads();
    let mut run = |rows: &mut Vec<Row>, step: Step, scene: &Scene, camera: &Camera| {
        progress(rows.len(), total, &step);
        let (time, stats) = measure(&mut renderer, scene, camera, step.size, settings);
        rows.push(Row {
            series: step.series.to_string(),
            mesh: step.mesh,
            triangles: scene.triangle_count() as u64,
            width: step.size.0,
            height: step.size.1,
            threads,
            time,
            stats,
        });
    };
    let fixed = torus_scene(settings.fixed_triangles);
    let fixed_name = format!("torus_{}", count_name(fixed.triangle_count() as u64));
    for &(w, h) in &settings.resolutions {
        let step = Step {
            series: "resolution",
            mesh: fixed_name.clone(),
            size: (w, h),
        };
        run(&mut rows, step, &fixed, &peer_camera(w, h));
    }
    drop(fixed);
    let (w, h) = settings.fixed_resolution;
    for &n in &settings.triangle_counts {
        let scene = torus_scene(n);
        let step = Step {
            series: "triangles",
            mesh: format!("torus_{}", count_name(scene.triangle_count() as u64)),
            size: (w, h),
        };
        run(&mut rows, step, &scene, &peer_camera(w, h));
    }
    if settings.models {
        for (name, scene) in models {
            let step = Step {
                series: "model",
                mesh: name.clone(),
                size: (w, h),
            };
            run(&mut rows, step, scene, &framing_camera(scene, w, h));
        }
    }
    rows
}

/// The `raster` sweep's flags.
#[derive(clap::Args, Clone, Debug)]
pub struct RasterFlags {
    #[command(flatten)]
    pub run: RunFlags,
    /// Folder of shared models (default: $PARALLAX_ASSETS, ../shared/assets beside the
    /// workspace, or /work/shared/assets).
    #[arg(long, value_name = "DIR")]
    pub assets: Option<PathBuf>,
    /// Skip the shared models.
    #[arg(long)]
    pub no_models: bool,
}

impl AsRef<RunFlags> for RasterFlags {
    fn as_ref(&self) -> &RunFlags {
        &self.run
    }
}

/// The `raster` sweep: frame time against resolution and against triangle count.
#[derive(Clone, Copy, Debug)]
pub struct RasterSweep;

impl Sweep for RasterSweep {
    const NAME: &'static str = "raster";
    const ABOUT: &'static str = "Frame time against resolution and against triangle count";
    const ROWS: &'static str = "measurements";
    type Flags = RasterFlags;
    /// The settings and the shared models loaded.
    type Settings = (Settings, Vec<(String, Scene)>);
    type Row = Row;

    fn settings(&self, flags: &RasterFlags) -> Result<Self::Settings, String> {
        let settings = flags
            .run
            .pick(Settings::tiny, Settings::quick, Settings::full);
        let models = if settings.models && !flags.no_models {
            load_models(flags.assets.clone())
        } else {
            Vec::new()
        };
        Ok((settings, models))
    }

    fn rows(
        &self,
        (settings, models): &Self::Settings,
        _: &RasterFlags,
        progress: Progress,
    ) -> Result<Vec<Row>, String> {
        Ok(raster(settings, models, |i, total, step| {
            let (w, h) = step.size;
            progress(i, total, &format!("{} {} {w}x{h}", step.series, step.mesh));
        }))
    }

    fn line(&self, r: &Row) -> Option<String> {
        Some(format!(
            "{:<10} {:<22} {:>9} tris {:>4}x{:<4} median {:>9.3} ms  min {:>9.3}  p90 {:>9.3}  ({} frames)",
            r.series,
            r.mesh,
            r.triangles,
            r.width,
            r.height,
            r.time.median_ms,
            r.time.min_ms,
            r.time.p90_ms,
            r.time.frames
        ))
    }

    fn charts(&self, rows: &[Row]) -> Vec<(&'static str, Chart)> {
        charts(rows)
    }
}

/// Loads the shared models from `assets` or the default folder (skipping, with a notice,
/// any that fail), fewest triangles first.
fn load_models(assets: Option<PathBuf>) -> Vec<(String, Scene)> {
    let dir = match assets.or_else(default_assets_dir) {
        Some(d) if d.is_dir() => d,
        Some(d) => {
            println!(
                "bench: no shared models: {} is not a folder; skipping them",
                d.display()
            );
            return Vec::new();
        }
        None => {
            println!("bench: no shared models folder found (set --assets or PARALLAX_ASSETS); skipping them");
            return Vec::new();
        }
    };
    let mut out = Vec::new();
    for path in find_models(&dir) {
        match engine::load::model(&path) {
            Ok(loaded) => {
                let name = model_name(&path);
                println!(
                    "bench: loaded {name} ({} triangles{})",
                    loaded.scene.triangle_count(),
                    if loaded.warnings.is_empty() {
                        String::new()
                    } else {
                        format!(", {} warnings", loaded.warnings.len())
                    }
                );
                out.push((name, loaded.scene));
            }
            Err(e) => println!("bench: skipping {}: {e}", path.display()),
        }
    }
    out.sort_by_key(|(_, s)| s.triangle_count());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_row_matches_header() {
        let row = Row {
            series: "triangles".into(),
            mesh: "torus_1k".into(),
            triangles: 1000,
            width: 320,
            height: 240,
            threads: 2,
            time: Summary::default(),
            stats: FrameStats::default(),
        };
        assert_eq!(row.csv().split(',').count(), Row::HEADER.split(',').count());
        assert_eq!(count_name(2_000_000), "2M");
        assert_eq!(count_name(10_000), "10k");
        assert_eq!(count_name(1234), "1234");
    }

    #[test]
    fn tiny_sweep_measures_every_point_and_draws_the_torus() {
        let settings = Settings::tiny();
        let mut seen = 0;
        let rows = raster(&settings, &[], |i, total, _| {
            assert_eq!(i, seen);
            assert_eq!(total, 4);
            seen += 1;
        });
        assert_eq!(rows.len(), 4);
        for r in &rows {
            assert!(r.time.frames >= MIN_FRAMES);
            assert!(r.stats.fragments_shaded > 0, "{r:?}");
            assert!(r.time.median_ms > 0.0);
        }
        assert_eq!(rows[2].triangles, 1_000);
        assert_eq!(rows[3].triangles, 10_000);
    }

    #[test]
    fn framing_camera_sees_the_whole_scene() {
        let mut s = Scene::default();
        s.add(
            procedural::uv_sphere(5.0, 8, 16),
            Material::unlit(Rgba::WHITE),
            Mat4::from_translation(Vec3::new(100.0, 0.0, 0.0)),
        );
        let cam = framing_camera(&s, 64, 48);
        let mut t = Target::new(64, 48);
        let stats = Renderer::new().render_scene(&s, &cam, &mut t, &FrameOptions::default());
        assert!(stats.fragments_shaded > 200);
        // Nothing touches the border: the sphere is entirely in view.
        for x in 0..64 {
            assert_eq!(t.pixel(x, 0), Some(0xff00_0000));
            assert_eq!(t.pixel(x, 47), Some(0xff00_0000));
        }
    }
}
