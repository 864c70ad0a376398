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

use clap::{Args, Parser, Subcommand};
use demos::bench::billboards as bb;
use demos::bench::budget as bbu;
use demos::bench::impostors as bi;
use demos::bench::layers as bly;
use demos::bench::lightfield as bl;
use demos::bench::morph as bm;
use demos::bench::panorama as bpn;
use demos::bench::portals as bp;
use demos::bench::raster::{self as bench, Settings};
use demos::bench::scaling;
use demos::bench::stereo as bs;
use demos::bench::sweep::{self, CsvRow};
use demos::bench::warp as bw;
use demos::chart::{self, Chart, Drawn};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

#[derive(Parser, Debug)]
#[command(version, about = "Parallax benchmark sweeps: CSV plus PNG charts")]
struct Cli {
    /// Render threads (default: one per core).
    #[arg(long, global = true)]
    threads: Option<usize>,
    #[command(subcommand)]
    sweep: Sweep,
}

#[derive(Subcommand, Debug)]
enum Sweep {
    /// Frame time against resolution and against triangle count.
    Raster(Common),
    /// Billboard frame time against count and resolution, billboard-tree error against
    /// view elevation, and billboard against mesh trees.
    Billboards(Small),
    /// Runtime impostors: frame time, refreshes and measured error against the parallax
    /// tolerance; fixed-interval refresh; predicted against measured error; octahedral.
    Impostors(Small),
    /// The city as geometry and through impostors: frame time against triangles and
    /// against pixels, with fitted lines.
    Scaling(Small),
    /// Depth images warped to moved eyes: error, holes and time against geometry.
    Warp(Small),
    /// Rooms through LDI portals, depth-image and flat portals, or as geometry: time
    /// against triangles and resolution, error along a walkthrough.
    Portals(Small),
    /// Light slabs against the geometry: error against sampling, lookup and compression;
    /// time against resolution and triangles.
    Lightfield(Small),
    /// Stereo matchers against OpenCV's StereoSGBM on rendered pairs: Middlebury error
    /// and time.
    Stereo(StereoArgs),
    /// View morphing along the path between two views, with and without the prewarp,
    /// against the geometry.
    Morph(Small),
    /// A cube-map sky seen from eyes moved away from where it was captured, against the
    /// geometry: measured and predicted error.
    Panorama(Small),
    /// Image layers against runtime impostors on the city: re-renders, error and frame
    /// time against the threshold.
    Layers(Small),
    /// The planner against single representations used everywhere: frame time and
    /// measured error over the error budget, on the city and a large world.
    Budget(BudgetArgs),
}

#[derive(Args, Debug)]
struct BudgetArgs {
    #[command(flatten)]
    run: Small,
    /// Time the cost model's experiments instead and print the fitted per-unit costs.
    #[arg(long)]
    calibrate: bool,
    /// Instead, each image representation's predicted against measured error on the
    /// objects it draws, binned by their size on screen (`budget_objects.csv`).
    #[arg(long)]
    objects: bool,
    /// Instead, the frame-scope planner at this error budget, object by object and frame
    /// by frame: representation, predicted and measured error (`budget_trace.csv`).
    #[arg(long)]
    trace: Option<f32>,
    /// Only this scene.
    #[arg(long, value_parser = ["showcase", "city", "world"])]
    scene: Option<String>,
    /// Only these methods (repeat the option; the names of the CSV's `method` column:
    /// `geometry`, `impostors`, `planner`, `planner-frame`, `layers`, or one representation
    /// run alone such as `billboards`).
    #[arg(long)]
    method: Vec<String>,
    /// The planners' relative error spread (default: the planner's own, `plan::SPREAD`;
    /// 0: the frame scope keeps the predicted mean alone). The `spread_fit` column says
    /// what spread each run's frames needed.
    #[arg(long)]
    spread: Option<f32>,
}

#[derive(Args, Debug)]
struct StereoArgs {
    #[command(flatten)]
    run: Small,
    /// Leave OpenCV out (otherwise it runs when `python3 -c "import cv2"` works; `pip
    /// install opencv-python-headless` to get it).
    #[arg(long)]
    no_opencv: bool,
}

#[derive(Args, Debug)]
struct Small {
    /// Folder for SWEEP.csv and the charts (created if missing).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// A reduced sweep (every point, few frames): about a minute at most.
    #[arg(long)]
    quick: bool,
    /// A seconds-long smoke run for tests: tiny sizes and counts (and no models).
    #[arg(long, hide = true)]
    tiny: bool,
}

#[derive(Args, Debug)]
struct Common {
    #[command(flatten)]
    run: Small,
    /// Folder of shared models (default: $PARALLAX_ASSETS, ../shared/assets beside the
    /// workspace, or /work/shared/assets).
    #[arg(long, value_name = "DIR")]
    assets: Option<PathBuf>,
    /// Skip the shared models.
    #[arg(long)]
    no_models: bool,
}

impl Small {
    /// The settings the flags ask for: tiny, quick or full.
    fn settings<P>(&self, tiny: fn() -> P, quick: fn() -> P, full: fn() -> P) -> P {
        if self.tiny {
            tiny()
        } else if self.quick {
            quick()
        } else {
            full()
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    demos::set_threads("bench", cli.threads);
    let result = match &cli.sweep {
        Sweep::Raster(c) => raster(c),
        Sweep::Billboards(c) => billboards(c),
        Sweep::Impostors(c) => impostors(c),
        Sweep::Scaling(c) => scaling_sweep(c),
        Sweep::Warp(c) => warp(c),
        Sweep::Portals(c) => portals(c),
        Sweep::Lightfield(c) => lightfield(c),
        Sweep::Stereo(c) => stereo(c),
        Sweep::Morph(c) => morph(c),
        Sweep::Panorama(c) => panorama(c),
        Sweep::Layers(c) => layers(c),
        Sweep::Budget(c) => budget(c),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("bench: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Loads the shared models (skipping, with a notice, any that fail).
fn load_models(c: &Common) -> Vec<(String, engine::Scene)> {
    let dir = match c.assets.clone().or_else(bench::default_assets_dir) {
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
    for path in bench::find_models(&dir) {
        match engine::load::model(&path) {
            Ok(loaded) => {
                let name = bench::model_name(&path);
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

/// Draws one chart, saying so when it had to go without text.
fn drawn(path: &Path, chart: &Chart) -> Result<(), String> {
    match chart::draw(path, chart) {
        Ok(Drawn::WithText) => Ok(()),
        Ok(Drawn::WithoutText) => {
            println!(
                "bench: the chart font could not be used; {} was drawn without text",
                path.display()
            );
            Ok(())
        }
        Err(e) => Err(format!("cannot draw {}: {e}", path.display())),
    }
}

/// Runs one sweep (`run`, reporting progress: index, total, what) under a progress bar,
/// prints its rows (`report`), writes `OUT/NAME.csv` and the `charts`, and says what it
/// wrote (`rows`: what its rows are, `measurements` or `rows`).
fn sweep<R: CsvRow>(
    c: &Small,
    name: &str,
    rows: &str,
    run: impl FnOnce(&mut dyn FnMut(usize, usize, &str)) -> Result<Vec<R>, String>,
    report: impl FnOnce(&[R]),
    charts: fn(&[R]) -> Vec<(&'static str, Chart)>,
) -> Result<(), String> {
    std::fs::create_dir_all(&c.out)
        .map_err(|e| format!("cannot create {}: {e}", c.out.display()))?;
    let start = Instant::now();
    let bar = ProgressBar::new(1);
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {pos}/{len} {msg}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    let measured = run(&mut |i, total, what| {
        bar.set_length(total as u64);
        bar.set_position(i as u64);
        bar.set_message(what.to_string());
    });
    bar.finish_and_clear();
    let measured = measured?;
    report(&measured);
    let csv = c.out.join(format!("{name}.csv"));
    sweep::write_csv(&csv, &measured)
        .map_err(|e| format!("cannot write {}: {e}", csv.display()))?;
    for (file, chart) in charts(&measured) {
        drawn(&c.out.join(file), &chart)?;
    }
    println!(
        "bench: {} {rows} in {:.1} s on {} threads; wrote {} and {}/{name}_*.png",
        measured.len(),
        start.elapsed().as_secs_f64(),
        rayon::current_num_threads(),
        csv.display(),
        c.out.display(),
    );
    Ok(())
}

fn raster(c: &Common) -> Result<(), String> {
    let settings = c
        .run
        .settings(Settings::tiny, Settings::quick, Settings::full);
    let models = if settings.models && !c.no_models {
        load_models(c)
    } else {
        Vec::new()
    };
    let run = |progress: &mut dyn FnMut(usize, usize, &str)| {
        Ok(bench::raster(&settings, &models, |i, total, step| {
            let (w, h) = step.size;
            progress(i, total, &format!("{} {} {w}x{h}", step.series, step.mesh));
        }))
    };
    let report = |rows: &[bench::Row]| {
        for r in rows {
            println!(
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
            );
        }
    };
    let (name, rows, charts) = ("raster", "measurements", bench::charts);
    sweep(&c.run, name, rows, run, report, charts)
}

fn billboards(c: &Small) -> Result<(), String> {
    let settings = c.settings(bb::Settings::tiny, bb::Settings::quick, bb::Settings::full);
    let report = |rows: &[bb::Row]| {
        for r in rows {
            let what = format!("{:<16} {:<13} {:>9}", r.series, r.param, r.value);
            match (&r.times, &r.error) {
                (Some(t), _) => println!(
                    "{what} {:>4}x{:<4} {:>9} tris  build {:>8.3} ms  render {:>8.3} ms  total {:>8.3} ms ({} frames)",
                    r.width, r.height, r.triangles, t.build.median_ms, t.render.median_ms, t.total.median_ms, t.total.frames
                ),
                (None, Some(e)) => println!(
                    "{what} {:>4}x{:<4} PSNR {:>6.2} dB  MAE {:>6.2}  max {:>3}  over {:>5.1}%  coverage {:>5.1}%",
                    r.width,
                    r.height,
                    e.psnr_db,
                    e.mean_abs,
                    e.max_abs,
                    e.frac_over * 100.0,
                    e.coverage_mismatch * 100.0
                ),
                (None, None) => println!("{what} (nothing measured)"),
            }
        }
    };
    let run = |progress: &mut dyn FnMut(usize, usize, &str)| Ok(bb::run(&settings, progress));
    let (name, rows, charts) = ("billboards", "measurements", bb::charts);
    sweep(c, name, rows, run, report, charts)
}

fn scaling_sweep(c: &Small) -> Result<(), String> {
    let settings = c.settings(
        scaling::Settings::tiny,
        scaling::Settings::quick,
        scaling::Settings::full,
    );
    let report = |rows: &[scaling::Row]| {
        for r in rows {
            let what = format!(
                "{:<14} {:<9} {:>9} tris {:>4}x{:<4}",
                r.series, r.mode, r.triangles, r.width, r.height
            );
            match (&r.timing, &r.fit) {
                (Some(t), _) => println!(
                    "{what} median {:>9.3} ms  p90 {:>9.3}  update {:>6.3}  render {:>9.3}  ({} frames; {} with refreshes, median {:.3} ms)  set up {:>8}  shaded {:>9}",
                    t.steady.median_ms,
                    t.steady.p90_ms,
                    t.update.median_ms,
                    t.render.median_ms,
                    t.steady.frames,
                    t.refresh.frames,
                    t.refresh.median_ms,
                    r.stats.triangles_set_up,
                    r.stats.fragments_shaded
                ),
                (None, Some(f)) => println!(
                    "{what} fit: {:.4} ms + {:.6} ns per {}, R^2 {:.4}",
                    f.intercept,
                    f.slope * 1e6,
                    if r.series == "triangles_fit" { "triangle" } else { "pixel" },
                    f.r2
                ),
                (None, None) => println!("{what} (nothing measured)"),
            }
        }
        type Pick = fn(&scaling::Timing) -> f64;
        let parts: [(&str, Pick); 3] = [
            ("frame", |t| t.steady.median_ms),
            ("update", |t| t.update.median_ms),
            ("draw list + render", |t| t.render.median_ms),
        ];
        for (part, pick) in parts {
            if let Some((lo, hi, change)) = scaling::impostor_change(rows, 1_500_000, pick) {
                println!(
                    "bench: impostor {part} median (frames without refreshes) from {lo} to {hi} triangles: {:+.1}%",
                    change * 100.0
                );
            }
        }
    };
    let run = |progress: &mut dyn FnMut(usize, usize, &str)| Ok(scaling::run(&settings, progress));
    let (name, rows, charts) = ("scaling", "rows", scaling::charts);
    sweep(c, name, rows, run, report, charts)
}

fn impostors(c: &Small) -> Result<(), String> {
    let settings = c.settings(bi::Settings::tiny, bi::Settings::quick, bi::Settings::full);
    let report = |rows: &[bi::Row]| {
        for r in rows.iter().filter(|r| r.series != "calibration") {
            bi::print_row(r);
        }
        if let Some(s) = bi::calibration_summary(rows) {
            println!("{s}");
        }
    };
    let run = |progress: &mut dyn FnMut(usize, usize, &str)| Ok(bi::run(&settings, progress));
    let (name, rows, charts) = ("impostors", "rows", bi::charts);
    sweep(c, name, rows, run, report, charts)
}

fn warp(c: &Small) -> Result<(), String> {
    let settings = c.settings(bw::Settings::tiny, bw::Settings::quick, bw::Settings::full);
    let report = |rows: &[bw::Row]| {
        for r in rows {
            let err = r.error.map_or(String::new(), |e| {
                format!(
                    "PSNR {:>6.2} dB (seen {:>6.2})  MAE {:>5.2}  over {:>5.1}%",
                    e.psnr_capped(99.0),
                    r.psnr_seen.min(99.0),
                    e.mean_abs,
                    e.frac_over * 100.0
                )
            });
            let rate = if r.samples > 0 {
                format!(
                    "  {:.0} M samples/s",
                    r.samples as f64 / r.time.median_ms / 1e3
                )
            } else {
                String::new()
            };
            println!(
                "{:<8} {:>5} {:<8} {} ref  {:>4}x{:<4} median {:>8.3} ms  holes {:>5.2}%  {err}{rate}",
                r.series,
                r.value,
                r.method,
                r.references,
                r.width,
                r.height,
                r.time.median_ms,
                r.holes * 100.0
            );
        }
    };
    let run = |progress: &mut dyn FnMut(usize, usize, &str)| Ok(bw::run(&settings, progress));
    let (name, rows, charts) = ("warp", "points", bw::charts);
    sweep(c, name, rows, run, report, charts)
}

fn portals(c: &Small) -> Result<(), String> {
    let settings = c.settings(bp::Settings::tiny, bp::Settings::quick, bp::Settings::full);
    let report = |rows: &[bp::Row]| {
        for r in rows.iter().filter(|r| r.series != "walk") {
            let err = r.error.map_or(String::new(), |e| {
                format!(
                    "PSNR {:>6.2} dB  MAE {:>5.2}",
                    e.psnr_capped(99.0),
                    e.mean_abs
                )
            });
            println!(
                "{:<10} {:<11} {:>9} tris {:>4}x{:<4} median {:>8.3} ms  {:>8} tris in  {:>8} samples  {:>8} px  {err}",
                r.series,
                r.method,
                r.room_triangles,
                r.width,
                r.height,
                r.time.median_ms,
                r.triangles_in,
                r.samples,
                r.pixels,
            );
        }
        for m in ["geometry", "flat", "depth-image", "ldi"] {
            let walk: Vec<&bp::Row> = rows
                .iter()
                .filter(|r| r.series == "walk" && r.method == m)
                .collect();
            if walk.is_empty() {
                continue;
            }
            let n = walk.len() as f64;
            let mean_ms = walk.iter().map(|r| r.time.median_ms).sum::<f64>() / n;
            let max_ms = walk.iter().map(|r| r.time.median_ms).fold(0.0, f64::max);
            let psnr: Vec<f64> = walk
                .iter()
                .filter_map(|r| r.error.map(|e| e.psnr_capped(99.0)))
                .collect();
            let min_psnr = psnr.iter().copied().fold(f64::INFINITY, f64::min);
            let rebuilds: u64 = walk.iter().map(|r| r.rebuilds).sum();
            println!(
                "walk       {m:<11} {} frames  mean {mean_ms:>7.3} ms  max {max_ms:>7.3} ms  rebuilds {rebuilds}  lowest PSNR {}",
                walk.len(),
                if psnr.is_empty() { "-".to_string() } else { format!("{min_psnr:.2} dB") },
            );
        }
    };
    let run = |progress: &mut dyn FnMut(usize, usize, &str)| Ok(bp::run(&settings, progress));
    let (name, rows, charts) = ("portals", "points", bp::charts);
    sweep(c, name, rows, run, report, charts)
}

fn lightfield(c: &Small) -> Result<(), String> {
    let settings = c.settings(bl::Settings::tiny, bl::Settings::quick, bl::Settings::full);
    let report = |rows: &[bl::Row]| {
        for r in rows {
            let err = r.error.map_or(String::new(), |e| {
                format!(
                    "PSNR {:>6.2} dB  off {:>5.2}%",
                    e.psnr_capped(99.0),
                    e.frac_over * 100.0
                )
            });
            let size = if r.file_bytes > 0 {
                format!(
                    "  {:>6.1}:1 in memory  {:>7.1}:1 file  trained {:.1} s",
                    r.raw_bytes as f64 / r.bytes.max(1) as f64,
                    r.raw_file_bytes as f64 / r.file_bytes as f64,
                    r.quantise_s
                )
            } else {
                String::new()
            };
            println!(
                "{:<10} {:<15} {:<7} {} uv {:>2} st {:>3} K {:>5} {:<7} {:>7} tris {:>4}x{:<4} median {:>8.3} ms  {err}{size}",
                r.series,
                r.method,
                r.eye_class,
                r.eye,
                r.uv,
                r.st,
                r.codewords,
                r.tile,
                r.triangles,
                r.width,
                r.height,
                r.time.median_ms,
            );
        }
    };
    let run = |progress: &mut dyn FnMut(usize, usize, &str)| Ok(bl::run(&settings, progress));
    let (name, rows, charts) = ("lightfield", "points", bl::charts);
    sweep(c, name, rows, run, report, charts)
}

fn stereo(c: &StereoArgs) -> Result<(), String> {
    let settings = c
        .run
        .settings(bs::Settings::tiny, bs::Settings::quick, bs::Settings::full);
    let peer = bs::Peer::bundled();
    let peer = if c.no_opencv {
        None
    } else if peer.available() {
        Some(peer)
    } else {
        println!(
            "bench: OpenCV is not installed for python3 (pip install opencv-python-headless); its rows are left out"
        );
        None
    };
    let report = |rows: &[bs::Row]| {
        for r in rows {
            let (n, a) = (&r.error.nonocc, &r.error.all);
            println!(
                "{:<12} {:<15} {}x{} 0..{:<3} median {:>8.2} ms  non-occluded bad 1 {:>5.1}% bad 2 {:>5.1}% RMS {:>5.2} unknown {:>5.1}%  all bad 2 {:>5.1}%",
                r.pair,
                r.method,
                r.width,
                r.height,
                r.max_disparity,
                r.time.median_ms,
                100.0 * n.bad1,
                100.0 * n.bad2,
                n.rms,
                100.0 * n.unknown,
                100.0 * a.bad2,
            );
        }
    };
    let out = c.run.out.clone();
    let run = |progress: &mut dyn FnMut(usize, usize, &str)| {
        bs::run(&settings, &out, peer.as_ref(), progress)
    };
    sweep(&c.run, "stereo", "rows", run, report, bs::charts)
}

fn morph(c: &Small) -> Result<(), String> {
    let settings = c.settings(bm::Settings::tiny, bm::Settings::quick, bm::Settings::full);
    let report = |rows: &[bm::Row]| {
        for r in rows {
            println!(
                "{:<5} {:<13} s {:.2} {}x{} median {:>8.2} ms  PSNR {:>6.2} dB  off {:>5.1}%  covered {:>5.1}%",
                r.path,
                r.method,
                r.s,
                r.width,
                r.height,
                r.time.median_ms,
                r.error.psnr_capped(99.0),
                100.0 * r.error.frac_over,
                100.0 * r.covered,
            );
        }
    };
    let run = |progress: &mut dyn FnMut(usize, usize, &str)| bm::run(&settings, progress);
    sweep(c, "morph", "rows", run, report, bm::charts)
}

fn panorama(c: &Small) -> Result<(), String> {
    let settings = c.settings(
        bpn::Settings::tiny,
        bpn::Settings::quick,
        bpn::Settings::full,
    );
    let report = |rows: &[bpn::Row]| {
        for r in rows {
            println!(
                "moved {:>5.2} {}x{}  panorama {:>7.2} ms  geometry {:>7.2} ms  PSNR {:>6.2} dB  off {:>5.1}%  predicted {:>6.1} px",
                r.moved,
                r.width,
                r.height,
                r.panorama.median_ms,
                r.geometry.median_ms,
                r.error.psnr_capped(99.0),
                100.0 * r.error.frac_over,
                r.predicted_px,
            );
        }
    };
    let run = |progress: &mut dyn FnMut(usize, usize, &str)| Ok(bpn::run(&settings, progress));
    sweep(c, "panorama", "rows", run, report, bpn::charts)
}

fn layers(c: &Small) -> Result<(), String> {
    let settings = c.settings(
        bly::Settings::tiny,
        bly::Settings::quick,
        bly::Settings::full,
    );
    let report = |rows: &[bly::Row]| {
        for r in rows {
            println!(
                "{:<9} {:<9} {:>5} px {}x{}  refreshes {:>6.2}/frame ({:>7.1} kpx)  median {:>7.2} ms  mean abs {:>6.3}  PSNR {:>6.2} dB  off {:>5.2}%  predicted max {:>6.2} px",
                r.path,
                r.method,
                r.tolerance_px,
                r.width,
                r.height,
                r.refreshes_per_frame,
                r.capture_kpx_per_frame,
                r.time.median_ms,
                r.error.mean_abs,
                r.error.psnr_capped(99.0),
                100.0 * r.error.frac_over,
                r.predicted_px_max,
            );
        }
    };
    let run = |progress: &mut dyn FnMut(usize, usize, &str)| Ok(bly::run(&settings, progress));
    sweep(c, "layers", "rows", run, report, bly::charts)
}

fn budget(c: &BudgetArgs) -> Result<(), String> {
    if c.calibrate {
        let (size, scale, reps) = if c.run.tiny {
            ((160, 96), 0.05, 1)
        } else {
            ((640, 360), 1.0, 9)
        };
        let run = |_: &mut dyn FnMut(usize, usize, &str)| {
            let (model, rows) = bbu::calibrate(size, scale, reps);
            println!(
                "cost model: {:.1} ns per triangle, {:.2} ns per lit pixel, {:.2} ns per image pixel, {:.1} us per capture, {:.2} ns per captured texel, {:.1} us per image pass, {:.2} ns per pass pixel, {:.2} ns per sample",
                model.ns_per_triangle, model.ns_per_pixel, model.ns_per_image_pixel, model.us_per_capture, model.ns_per_capture_texel, model.us_per_pass, model.ns_per_pass_pixel, model.ns_per_sample
            );
            Ok(rows)
        };
        let report = |rows: &[bbu::Calibration]| {
            for r in rows {
                println!(
                    "{:<9} {:>9} triangles {:>9} pixels {:>9} image pixels {:>4} captures {:>3} passes {:>7} pass pixels {:>7} samples {:>8.3} ms",
                    r.experiment, r.triangles, r.pixels, r.image_pixels, r.captures, r.passes, r.pass_pixels, r.samples, r.ms
                );
            }
        };
        return sweep(&c.run, "calibrate", "rows", run, report, |_| Vec::new());
    }
    let settings = bbu::Settings {
        only: c.scene.clone(),
        methods: c.method.clone(),
        spread: c.spread,
        ..c.run.settings(
            bbu::Settings::tiny,
            bbu::Settings::quick,
            bbu::Settings::full,
        )
    };
    if let Some(b) = c.trace {
        let run = |_: &mut dyn FnMut(usize, usize, &str)| Ok(bbu::trace(&settings, b));
        let report = |rows: &[bbu::TraceRow]| {
            let mut last = None;
            for r in rows {
                if last != Some((r.scene, r.frame)) {
                    last = Some((r.scene, r.frame));
                    println!(
                        "{} frame {:>3}: measured {:>7.3} bound {:>7.3}",
                        r.scene, r.frame, r.frame_measured, r.frame_bound
                    );
                }
            }
        };
        return sweep(&c.run, "budget_trace", "rows", run, report, |_| Vec::new());
    }
    if c.objects {
        let run =
            |progress: &mut dyn FnMut(usize, usize, &str)| Ok(bbu::objects(&settings, progress));
        let report = |rows: &[bbu::ObjectRow]| {
            for r in rows {
                println!(
                    "{:<8} {:<11} side >= {:>3} px {:>7} object-frames  predicted {:>7.3}  measured {:>6.3} (p95 {:>6.3})  within prediction {:>5.1}%  overlap {:>5.2}",
                    r.scene, r.representation, r.side, r.count, r.predicted_mean, r.measured_mean, r.measured_p95, 100.0 * r.within, r.overlap
                );
            }
        };
        return sweep(&c.run, "budget_objects", "bins", run, report, |_| {
            Vec::new()
        });
    }
    let report = |rows: &[bbu::Row]| {
        for r in rows {
            println!(
                "{:<8} {:<13} {:>5} {}x{} {:>6} objects {:>9} tris  median {:>8.2} ms  measured {:>6.3} (p99 {:>6.3}, within {:>5.1}%, objects over {:>5.2}%)  predicted {:>6.3} max {:>7.3} bound {:>6.3} (spread fit {:>5.2})  geometry {:>7.1} images {:>7.1} [{}] switches {:>6.2} rebuilds {:>6.2}  {:>7.1} MB  planning {:>6.2} ms",
                r.scene,
                r.method,
                r.budget,
                r.width,
                r.height,
                r.objects,
                r.triangles,
                r.time.median_ms,
                r.measured_mean,
                r.measured_p99,
                100.0 * r.within,
                100.0 * r.objects_over,
                r.predicted_mean,
                r.predicted_max,
                r.predicted_bound,
                r.spread_fit,
                r.geometry_per_frame,
                r.images_per_frame,
                r.mix,
                r.switches_per_frame,
                r.rebuilds_per_frame,
                r.memory_mb,
                r.planning_ms,
            );
        }
    };
    let run = |progress: &mut dyn FnMut(usize, usize, &str)| Ok(bbu::run(&settings, progress));
    sweep(&c.run, "budget", "rows", run, report, bbu::charts)
}
