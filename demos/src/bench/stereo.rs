//! The `bench stereo` sweep: the block matcher and semi-global matching against OpenCV's
//! `StereoSGBM` (run by `demos/benches/opencv_sgbm.py`, when Python has `cv2`) on the same
//! pairs, error (the Middlebury measures against exact ground truth) and time side by side.
//!
//! The pairs ([`scenes`]) are rendered by the engine: the showcase's plaza, cards at
//! several depths (occlusion edges), a slanted wall, thin bars, a wall with little texture,
//! one with a repeated pattern, and the cards seen by a verged right camera, rectified from
//! the known cameras first. Every matcher reads the same 8-bit PNGs: each pair is written
//! to `OUT/stereo/PAIR/` (`left.png`, `right.png`, `truth.pfm`), where the script also
//! writes its disparities (`opencv_sgbm.pfm`, `opencv_sgbm_hh.pfm`). [`key`] draws the
//! colour key under a colour-mapped disparity map (the `stereo` CLI's `disparity.png`).

pub mod key;
mod report;
mod scenes;

pub use report::{charts, StereoFlags, StereoSweep};
pub use scenes::{repeated_pair, scenes, Scene};

use crate::bench::sweep::{self, CsvRow, Timing};
use crate::timing::Summary;
use engine::load;
use ibr::images::transforms::srgb8;
use ibr::stereo::block::MIN_TEXTURE;
use ibr::stereo::{luminance_rgba8, measure, BlockMatch, Disparity, Measured, Sgm, SgmBuffers};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// What a sweep measures.
#[derive(Clone, Debug)]
pub struct Settings {
    pub width: u32,
    pub height: u32,
    /// Disparities searched: `0..max_disparity` (OpenCV: rounded up to a multiple of 16).
    pub max_disparity: u32,
    pub timing: Timing,
}

impl Settings {
    /// A seconds-long smoke run.
    pub fn tiny() -> Settings {
        Settings {
            width: 128,
            height: 96,
            max_disparity: 16,
            timing: Timing::once(),
        }
    }

    pub fn quick() -> Settings {
        Settings {
            width: 320,
            height: 240,
            max_disparity: 32,
            timing: Timing::new(1, 3, 2),
        }
    }

    pub fn full() -> Settings {
        Settings {
            width: 640,
            height: 480,
            max_disparity: 64,
            timing: Timing::new(1, 5, 5),
        }
    }
}

/// One matcher on one pair.
#[derive(Clone, Debug)]
pub struct Row {
    pub pair: String,
    pub method: String,
    pub width: u32,
    pub height: u32,
    pub max_disparity: u32,
    pub time: Summary,
    pub error: Measured,
}

impl CsvRow for Row {
    const HEADER: &'static str = "pair,method,width,height,max_disparity,frames,median_ms,min_ms,nonocc_bad1,nonocc_bad2,nonocc_rms,nonocc_unknown,all_bad1,all_bad2,all_rms,all_unknown";

    fn csv(&self) -> String {
        let (n, a) = (&self.error.nonocc, &self.error.all);
        format!(
            "{},{},{},{},{},{},{:.3},{:.3},{:.5},{:.5},{:.4},{:.5},{:.5},{:.5},{:.4},{:.5}",
            self.pair,
            self.method,
            self.width,
            self.height,
            self.max_disparity,
            self.time.frames,
            self.time.median_ms,
            self.time.min_ms,
            n.bad1,
            n.bad2,
            n.rms,
            n.unknown,
            a.bad1,
            a.bad2,
            a.rms,
            a.unknown,
        )
    }
}

/// Where OpenCV's script is, and whether to run it.
#[derive(Clone, Debug)]
pub struct Peer {
    pub python: String,
    pub script: PathBuf,
}

impl Peer {
    /// The script in this repository, run by `python3`.
    pub fn bundled() -> Peer {
        Peer {
            python: "python3".into(),
            script: Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/opencv_sgbm.py"),
        }
    }

    /// Whether this Python can import OpenCV.
    pub fn available(&self) -> bool {
        Command::new(&self.python)
            .args(["-c", "import cv2"])
            .output()
            .is_ok_and(|o| o.status.success())
    }
}

/// Runs the sweep: every pair written to `out/stereo/`, matched by ours and (with `peer`)
/// by OpenCV's; a row per pair and matcher.
pub fn run(
    settings: &Settings,
    out: &Path,
    peer: Option<&Peer>,
    progress: &mut dyn FnMut(usize, usize, &str),
) -> Result<Vec<Row>, String> {
    let pairs = scenes(settings.width, settings.height);
    let mut tick = sweep::ticker(pairs.len() * 3 + 1, progress);
    let mut rows = Vec::new();
    let mut dirs = Vec::new();
    for scene in &pairs {
        let dir = out.join("stereo").join(&scene.name);
        std::fs::create_dir_all(&dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        let (w, h) = (settings.width, settings.height);
        let (left, right) = (srgb8(&scene.pair.left), srgb8(&scene.pair.right));
        let write = |name: &str, rgba: &[u8]| {
            load::write_png_rgba8(&dir.join(name), w, h, rgba).map_err(|e| e.to_string())
        };
        write("left.png", &left)?;
        write("right.png", &right)?;
        load::write_float_image(&dir.join("truth.pfm"), &scene.pair.truth.to_float_image())
            .map_err(|e| e.to_string())?;
        let (l, r) = (luminance_rgba8(&left), luminance_rgba8(&right));
        // `sgm-flat`: SGM taking what its paths give flat regions (no texture check).
        for method in ["block", "sgm", "sgm-flat"] {
            tick(format!("{} {method}", scene.name));
            let mut last = None;
            // Kept between runs, as OpenCV keeps its matcher's buffer.
            let mut buffers = SgmBuffers::default();
            let times = settings.timing.run(|| {
                let t = Instant::now();
                let d = match method {
                    "block" => BlockMatch {
                        max_disparity: settings.max_disparity,
                        ..BlockMatch::default()
                    }
                    .run(&l, &r, w, h),
                    _ => Sgm {
                        max_disparity: settings.max_disparity,
                        min_texture: if method == "sgm" { MIN_TEXTURE } else { 0.0 },
                        ..Sgm::default()
                    }
                    .run_with(&mut buffers, &l, &r, w, h),
                };
                last = Some(d);
                t.elapsed()
            });
            let estimate = last
                .expect("at least one run")
                .map_err(|e| format!("{}: {e}", scene.name))?;
            rows.push(row(
                settings,
                scene,
                method,
                Summary::of(&times),
                &estimate,
            )?);
        }
        dirs.push(dir);
    }
    tick("OpenCV StereoSGBM".into());
    if let Some(peer) = peer {
        rows.extend(opencv(settings, &pairs, &dirs, peer)?);
    }
    Ok(rows)
}

/// A row: `estimate`'s error on `scene`'s pair.
fn row(
    settings: &Settings,
    scene: &Scene,
    method: &str,
    time: Summary,
    estimate: &Disparity,
) -> Result<Row, String> {
    let p = &scene.pair;
    let error = measure(estimate, &p.truth, Some(&p.visible)).map_err(|e| e.to_string())?;
    Ok(Row {
        pair: scene.name.clone(),
        method: method.into(),
        width: settings.width,
        height: settings.height,
        max_disparity: settings.max_disparity,
        time,
        error,
    })
}

/// OpenCV's rows: the script run over every pair folder, its timings read from its
/// output and its disparities from the PFM files it wrote.
fn opencv(
    settings: &Settings,
    pairs: &[Scene],
    dirs: &[PathBuf],
    peer: &Peer,
) -> Result<Vec<Row>, String> {
    let threads = rayon::current_num_threads().to_string();
    let out = Command::new(&peer.python)
        .arg(&peer.script)
        .args(["--max-disparity", &settings.max_disparity.to_string()])
        .args(["--repeats", &settings.timing.frames.max(1).to_string()])
        .args(["--threads", &threads])
        .args(dirs)
        .output()
        .map_err(|e| format!("cannot run {}: {e}", peer.python))?;
    if !out.status.success() {
        return Err(format!(
            "{} failed: {}",
            peer.script.display(),
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let mut rows = Vec::new();
    for line in String::from_utf8_lossy(&out.stdout).lines() {
        let mut words = line.split_whitespace();
        let (Some(pair), Some(mode)) = (words.next(), words.next()) else {
            continue;
        };
        let times: Vec<Duration> = words
            .map(|t| t.parse::<f64>().map(|ms| Duration::from_secs_f64(ms / 1e3)))
            .collect::<Result<_, _>>()
            .map_err(|e| format!("the script printed {line:?}: {e}"))?;
        let (Some(scene), Some(dir)) = (
            pairs.iter().position(|s| s.name == pair).map(|i| &pairs[i]),
            dirs.iter().find(|d| d.ends_with(pair)),
        ) else {
            return Err(format!("the script printed an unknown pair: {line:?}"));
        };
        let file = dir.join(format!("opencv_{mode}.pfm"));
        let image = load::float_image(&file).map_err(|e| e.to_string())?;
        let estimate =
            Disparity::from_float_image(image).map_err(|e| format!("{}: {e}", file.display()))?;
        let method = format!("opencv-{}", mode.replace('_', "-"));
        rows.push(row(
            settings,
            scene,
            &method,
            Summary::of(&times),
            &estimate,
        )?);
    }
    Ok(rows)
}
