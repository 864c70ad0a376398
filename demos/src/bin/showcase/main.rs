//! The showcase: a built-in game-like scene (terrain, lit and textured objects, alpha-tested
//! fence, blended glass, trees, a house, a sun and point lights) drawn by the CPU rasterizer.
//!
//! With a display it opens a window (`minifb`) with a fly camera: WASD move, mouse drag or
//! arrow keys look, Q / E down / up, Shift faster, B enters the building and V the views
//! moment (below), I toggles the debug view (cloud impostors tinted by predicted error,
//! the city's buildings coloured by how the planner draws them: geometry flat white,
//! impostors green, image layers blue), Esc quits; the frame time, the clouds' impostor
//! readout (refreshes this frame, images, geometry fallbacks, largest predicted error) and
//! the city planner's (buildings drawn as geometry, impostors and layers, rebuilds,
//! switches, largest predicted error against the budget) are shown in the title and in the
//! corner of the image. Without a display (no `DISPLAY` / `WAYLAND_DISPLAY`, or the window
//! cannot be opened), or with `--headless`, it renders a deterministic camera path to
//! `DIR/frame_0000.png ...` and prints frame-time, impostor and planner statistics and the
//! last frame's counters.
//!
//! The tour then enters a building (`demos::showcase::building`): a hall whose three
//! furnished rooms are seen through LDI portals as the camera walks along it and through
//! the middle door, with the portals' readout (warped and geometry portals, samples, holes,
//! pixels, rebuilds). Headless, its frames follow the outdoor ones (`building_0000.png`
//! ..., `--building-frames`); in the window B switches between the outdoor scene and the
//! building. `--building` shows only the building; `--debug-portals` (or I in the
//! building) tints warped pixels green.
//!
//! Last comes the views moment (`demos::showcase::views`): a layered background of image
//! layers warped instead of re-rendered, a panorama sky re-captured as the
//! eye walks away from it, and two views of the plaza morphed into each other, each with
//! its error against the geometry; headless after the building (`views_0000.png` ...,
//! `--views-frames`), V in the window, `--views` alone.
//!
//! Then the world moment (`demos::showcase::world`): a fly-over of a world of thousands
//! of objects drawn per node of a hierarchy (a node's objects as one image, or its
//! children), with the planner's readout (nodes opened, images, objects as geometry,
//! predicted error, planning and frame time); headless after the views (`world_0000.png`
//! ..., `--world-frames`), O in the window, `--world` alone.

mod window;

use clap::Parser;
use demos::showcase::attractions::Meter;
use demos::showcase::building::BuildingTour;
use demos::showcase::ibr_layer::DrawGroups;
use demos::showcase::summary::{self as report, PartTimes};
use demos::showcase::views::{Stages, ViewsTour};
use demos::showcase::world::WorldTour;
use demos::showcase::{self, Showcase, SKY};
use demos::timing::{Summary, Usage};
use engine::{FrameOptions, FrameStats, Renderer, Target};
use ibr::subject::Subject;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::{Duration, Instant};

#[derive(Parser, Debug)]
#[command(
    version,
    about = "Parallax showcase: a CPU-rasterized game scene (window or headless)"
)]
struct Args {
    /// Render a camera path to PNG files in DIR instead of opening a window.
    #[arg(long, value_name = "DIR", num_args = 0..=1, default_missing_value = "out/showcase")]
    headless: Option<PathBuf>,
    /// Frames to render in headless mode.
    #[arg(long, default_value_t = 120)]
    frames: usize,
    /// Image width (headless default 640, window default 960).
    #[arg(short = 'W', long)]
    width: Option<u32>,
    /// Image height (headless default 360, window default 540).
    #[arg(short = 'H', long)]
    height: Option<u32>,
    /// Render threads (default: one per core).
    #[arg(long)]
    threads: Option<usize>,
    /// Headless: time the frames but do not write PNG files.
    #[arg(long)]
    no_save: bool,
    /// Start with the debug view: cloud impostors tinted by their predicted error (green
    /// 0, yellow at the tolerance, red at twice it), buildings by their representation
    /// (geometry white, impostors green, layers blue). The I key toggles it in the window.
    #[arg(long)]
    debug_impostors: bool,
    /// Only the building tour: rooms seen through LDI portals, walked past and into (the
    /// window starts in it).
    #[arg(long)]
    building: bool,
    /// Headless: frames of the building walkthrough after the outdoor tour (default: half
    /// of --frames, at least one; 0 skips it).
    #[arg(long, value_name = "N")]
    building_frames: Option<usize>,
    /// With --building: start with warped pixels tinted green (I toggles in the window).
    #[arg(long)]
    debug_portals: bool,
    /// Only the views moment: a layered background, a panorama sky and a view morph, each
    /// measured against the
    /// geometry (the window starts in it).
    #[arg(long, conflicts_with = "building")]
    views: bool,
    /// Headless: frames of the views moment after the building (default: a tenth of
    /// --frames, at least three; 0 skips it).
    #[arg(long, value_name = "N")]
    views_frames: Option<usize>,
    /// Only the world moment: a fly-over of thousands of objects drawn per node of a
    /// hierarchy, with the planner's readout (the window starts in it).
    #[arg(long, conflicts_with_all = ["building", "views"])]
    world: bool,
    /// Headless: frames of the world moment after the views (default: a twentieth of
    /// --frames, at least three; 0 skips it).
    #[arg(long, value_name = "N")]
    world_frames: Option<usize>,
    /// Headless: count the tour's draws by group (forest, terrain, city, statue, clouds,
    /// effects, other: fragments, rows, raster time) into `DIR/tour_draws.csv` (off by
    /// default: the counting reads the clock twice per triangle and tile).
    #[arg(long)]
    draw_costs: bool,
}

fn main() -> ExitCode {
    let args = Args::parse();
    demos::set_threads("showcase", args.threads);
    let has_display = ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()));
    let result = match (&args.headless, has_display) {
        (Some(dir), _) => headless(&args, dir),
        (None, false) => {
            eprintln!("showcase: no display found (DISPLAY / WAYLAND_DISPLAY unset); rendering headless to out/showcase");
            headless(&args, Path::new("out/showcase"))
        }
        (None, true) => match window::window(&args) {
            Ok(()) => Ok(()),
            Err(window::WindowError::Open(e)) => {
                eprintln!(
                    "showcase: cannot open a window ({e}); rendering headless to out/showcase"
                );
                headless(&args, Path::new("out/showcase"))
            }
            Err(window::WindowError::Update(e)) => Err(format!("window update failed: {e}")),
        },
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("showcase: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Writes `contents` to `dir/name`, creating `dir` first; the path written, or a message
/// naming what could not be created or written.
fn write_into(dir: &Path, name: &str, contents: &str) -> Result<PathBuf, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let path = dir.join(name);
    std::fs::write(&path, contents).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    Ok(path)
}

/// Renders the outdoor camera path, the building walkthrough, the views and the world
/// moment (or, with `--building`, `--views` or `--world`, that part alone).
fn headless(args: &Args, dir: &Path) -> Result<(), String> {
    if !args.no_save {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    }
    let n = args.frames.max(1);
    let mut meter = Meter::new();
    let mut parts: [PartTimes; report::PARTS.len()] = Default::default();
    if args.building {
        parts[1] = building_headless(args, dir, n, &mut meter)?;
    } else if args.views {
        parts[2] = views_headless(args, dir, n, Showcase::new(), &mut meter)?;
    } else if args.world {
        parts[3] = world_headless(args, dir, n)?;
    } else {
        let show;
        (show, parts[0]) = outdoor_headless(args, dir, n, &mut meter)?;
        match args.building_frames.unwrap_or((n / 2).max(1)) {
            0 => {}
            frames => parts[1] = building_headless(args, dir, frames, &mut meter)?,
        }
        match args.views_frames.unwrap_or((n / 10).max(3)) {
            0 => {}
            frames => parts[2] = views_headless(args, dir, frames, show, &mut meter)?,
        }
        match args.world_frames.unwrap_or((n / 20).max(3)) {
            0 => {}
            frames => parts[3] = world_headless(args, dir, frames)?,
        }
    }
    write_summary(dir, parts, &meter)
}

/// Prints the summary (each part's frame times, each attraction's figures) and writes it
/// to `DIR/summary.json` (also with `--no-save`).
fn write_summary(
    dir: &Path,
    parts: [PartTimes; report::PARTS.len()],
    meter: &Meter,
) -> Result<(), String> {
    let summary = report::Summary {
        parts,
        attractions: meter.figures(),
    };
    println!("summary (frame times exclude the attractions' reference renders):");
    for line in summary.lines() {
        println!("  {line}");
    }
    let path = write_into(dir, "summary.json", &summary.json())?;
    println!("wrote {}", path.display());
    Ok(())
}

/// Prints the tour's impostor and city statistics, and (unless `--no-save`) writes their
/// chart over the tour.
fn print_impostors(show: &Showcase, args: &Args, times: &[Duration], dir: &Path) {
    let imp = show.ibr.impostors.run_stats();
    println!(
        "impostors: {} clouds; planner: {} buildings as {}{}",
        show.ibr.impostors.clouds.clouds.len(),
        show.ibr.impostors.city.objects.len(),
        show.ibr.impostors.city.names().join(", "),
        if args.debug_impostors {
            format!(
                " (debug view: cloud images tinted by predicted error; {})",
                show.ibr.impostors.legend()
            )
        } else {
            String::new()
        }
    );
    println!(
        "  refreshes: total {}, mean {:.2} per frame, peak {} (the clouds' and the city's \
         rebuilds); {} wanted but left for later",
        imp.refreshes,
        imp.mean_refreshes(),
        imp.peak_refreshes,
        imp.stale
    );
    println!(
        "  predicted error ratio (1 = tolerance or budget) of the images shown: max {:.3}, \
         mean {:.3}",
        imp.max_ratio,
        imp.mean_ratio()
    );
    let pct = |k: usize| 100.0 * k as f64 / imp.frames.max(1) as f64;
    println!(
        "  frames showing an image over its tolerance: {} ({:.1}%), over twice it: {} \
         ({:.1}%); stale cloud images drawn as geometry instead: {}; pre-warmed refreshes: {}",
        imp.frames_over,
        pct(imp.frames_over),
        imp.frames_over_twice,
        pct(imp.frames_over_twice),
        imp.stale_fallbacks,
        imp.prewarmed
    );
    let [g, i, l] = imp.city_frames;
    println!(
        "  city: {} rebuilds, {} switches; building-frames as geometry {g}, impostors {i}, \
         layers {l}; {} over the error budget; largest predicted error {:.2} levels \
         (budget {:.1})",
        imp.city_rebuilds,
        imp.city_switches,
        imp.city_over_budget,
        imp.city_max_error,
        show.ibr.impostors.city.config.budgets.error
    );
    if !args.no_save {
        let path = dir.join("impostor_error.png");
        match showcase::impostors::tour_chart(imp, times, &path) {
            Ok(()) => println!(
                "  chart of error, refreshes and frame time over the tour: {}",
                path.display()
            ),
            Err(e) => eprintln!("  could not write {}: {e}", path.display()),
        }
    }
}

/// Renders the outdoor camera path, `n` frames; writes PNGs unless `--no-save`; prints
/// statistics. Returns the scene, for the views moment.
fn outdoor_headless(
    args: &Args,
    dir: &Path,
    n: usize,
    meter: &mut Meter,
) -> Result<(Showcase, PartTimes), String> {
    let (w, h) = (args.width.unwrap_or(640), args.height.unwrap_or(360));
    let mut show = Showcase::new();
    show.ibr.impostors.set_debug(args.debug_impostors);
    let mut renderer = Renderer::new();
    let mut target = Target::new(w, h);
    let opts = FrameOptions {
        clear: Some(SKY),
        ..Default::default()
    };
    println!(
        "showcase: {} triangles in {} draws (+ {} in clouds and buildings behind images), \
         {n} frames at {w}x{h} on {} threads",
        show.scene.triangle_count(),
        show.scene.instances.len(),
        show.ibr.impostors.triangle_count(),
        rayon::current_num_threads()
    );
    // The path is known: its first frame is prepared at loading, untimed.
    let (eye, look) = show.path(0, n);
    let first = showcase::camera(eye, look, w, h);
    let loading = Instant::now();
    let prepared = show.prepare(&mut renderer, &first, &mut target, &opts);
    println!(
        "prepared at loading: {} frames from the first frame's eye, {} impostor refreshes, \
         {:.1} ms (not in the tour's times or counts)",
        prepared.frames,
        prepared.refreshes,
        loading.elapsed().as_secs_f64() * 1e3
    );
    let mut times = Vec::with_capacity(n);
    let mut stats = FrameStats::default();
    let mut sum = FrameStats::default();
    let mut breakdown = report::Breakdown::new(&TOUR_COLUMNS);
    let mut counters = String::from(COUNTER_COLUMNS);
    show.count_draws(&mut renderer, args.draw_costs);
    let mut draws = DrawGroups::csv_header();
    for i in 0..n {
        show.animate(i as f32 / 30.0);
        let (eye, look) = show.path(i, n);
        let camera = showcase::camera(eye, look, w, h);
        let start = Instant::now();
        stats = show.render(&mut renderer, &camera, &mut target, &opts);
        sum += stats;
        times.push(start.elapsed());
        breakdown.push(start.elapsed(), &tour_row(show.ibr.frame_loop()));
        counters.push_str(&counter_row(i, &show, (w, h)));
        if let Some(g) = show.draw_groups() {
            draws.push_str(&g.csv_row(i));
        }
        meter.tour(&show, &camera, w, h);
        let statue = &mut show.ibr.statue;
        statue.error = meter.last_of("statue");
        statue.errors.extend(statue.error);
        if !args.no_save {
            save_png(
                &dir.join(format!("frame_{i:04}.png")),
                &target.to_rgba8(),
                (w, h),
            )?;
        }
    }
    let summary = Summary::of(&times);
    println!("frame time: {summary}");
    println!(
        "  median {:.2} ms  min {:.2} ms  p90 {:.2} ms  ({:.1} fps at the median)",
        summary.median_ms,
        summary.min_ms,
        summary.p90_ms,
        1e3 / summary.median_ms.max(1e-9)
    );
    println!("where the tour's time went (technique prepares, frame-loop steps, engine stages of the main pass):");
    for line in breakdown.lines() {
        println!("  {line}");
    }
    write_into(dir, "tour_times.csv", &breakdown.csv())?;
    write_into(dir, "tour_counters.csv", &counters)?;
    if let Some(g) = show.draw_groups() {
        println!("the tour's mean frame by group of draws (tour_draws.csv):");
        g.lines().iter().for_each(|l| println!("  {l}"));
        write_into(dir, "tour_draws.csv", &draws)?;
    }
    print_impostors(&show, args, &times, dir);
    let last = show.ibr.impostors.readout();
    println!("  last frame: {}", last.line());
    println!("  last frame: {}", last.city.line());
    print_statue(&show, n);
    println!("last frame: {stats:#?}");
    print_fragments("the tour", &sum, n, (w, h));
    if !args.no_save {
        println!("wrote {n} frames to {}/frame_0000.png ...", dir.display());
    }
    Ok((show, PartTimes::of(&times)))
}

/// Prints the fragments of `sum`, counted over `n` frames of `w x h`, per pixel per frame.
fn print_fragments(what: &str, sum: &FrameStats, n: usize, (w, h): (u32, u32)) {
    let per_px = |x: u64| x as f64 / (n.max(1) as f64 * w as f64 * h as f64);
    println!(
        "fragments per pixel over {what}: tested {:.2}, shaded {:.2} (blended {:.2}, \
         textured or lit {:.2}), written {:.2}",
        per_px(sum.fragments_tested),
        per_px(sum.fragments_shaded),
        per_px(sum.fragments_shaded_blended),
        per_px(sum.fragments_shaded_general),
        per_px(sum.fragments_written)
    );
}

/// The columns of the tour's time breakdown: each technique's `prepare` (in the layer's
/// order), the frame loop's other steps, and the engine's stages of the main pass (raster
/// and resolve summed over the workers).
const TOUR_COLUMNS: [&str; 15] = [
    "forest",
    "lasers",
    "effects",
    "impostors",
    "statue",
    "flare",
    "render",
    "passes",
    "observe",
    "overlay",
    "vertex",
    "front",
    "tiles",
    "raster_sum",
    "resolve_sum",
];

/// The header of `DIR/tour_counters.csv`: each tour frame's work by stage, counted (the
/// clouds' refreshes, texels captured and fragments their captures shaded, the city's rebuilds, the light-field statue's
/// rays, samples read and pixels written, the flare's sprites, the pixels their squares
/// cover on screen and the pixels within their shapes' reach, which the flare blends; the
/// forest's sprites and the triangles of their reliefs).
const COUNTER_COLUMNS: &str = "frame,cloud_refreshes,cloud_texels,cloud_fragments,city_rebuilds,\
statue_rays,statue_taps,statue_pixels,flare_sprites,flare_pixels,flare_reach,\
forest_sprites,forest_triangles\n";

/// Frame `i`'s row of [`COUNTER_COLUMNS`].
fn counter_row(i: usize, show: &Showcase, (w, h): (u32, u32)) -> String {
    let imp = show.ibr.impostors.readout();
    let lf = show.ibr.statue.object.last();
    let flare = show.ibr.flare();
    let (sprites, triangles) = show.ibr.forest_work();
    format!(
        "{i},{},{},{},{},{},{},{},{},{},{},{sprites},{triangles}\n",
        imp.clouds.refreshes,
        imp.clouds.capture_texels,
        imp.clouds.capture_fragments,
        imp.city.rebuilds,
        lf.rays,
        lf.taps,
        lf.pixels,
        flare.quad_count(),
        flare.sprite_pixels(w, h),
        flare.reach_pixels(w, h)
    )
}

/// One tour frame's row of [`TOUR_COLUMNS`].
fn tour_row(f: &ibr::technique::FrameLoop) -> Vec<Duration> {
    let (t, s) = (f.times, f.stages);
    let mut row = f.prepares.clone();
    row.resize(6, Duration::ZERO);
    row.extend([t.render, t.passes, t.observe, t.overlay]);
    row.extend([s.vertex, s.front, s.tiles, s.raster, s.resolve]);
    row
}

/// The light-field statue's readout over the tour.
fn print_statue(show: &Showcase, n: usize) {
    let s = &show.ibr.statue;
    let slabs = &s.object.slabs;
    let [nu, nv, ns, nt] = slabs.first().map_or([0; 4], |f| f.slab.counts());
    println!(
        "light-field statue: {} slabs of {nu}x{nv}x{ns}x{nt}, captured in {:.2} s and {}",
        slabs.len(),
        s.capture.as_secs_f64(),
        s.storage()
    );
    println!(
        "  memory {:.2} MB held, {:.1} MB raw: {:.0}:1",
        s.bytes() as f64 / 1e6,
        s.raw_bytes as f64 / 1e6,
        s.ratio()
    );
    let psnr: Vec<f64> = s.errors.iter().map(|e| e.psnr_capped(99.0)).collect();
    let mean = psnr.iter().sum::<f64>() / psnr.len().max(1) as f64;
    let min = psnr.iter().copied().fold(f64::INFINITY, f64::min);
    println!(
        "  drawn from the light field in {} of {n} frames; error against its geometry there: \
         PSNR mean {mean:.1} dB, worst {min:.1} dB",
        psnr.len()
    );
    println!("  last frame: {}", s.line());
}

/// The building tour along its walkthrough, `n` frames; writes PNGs unless `--no-save`;
/// prints the frame times and the portals' work.
fn building_headless(
    args: &Args,
    dir: &Path,
    n: usize,
    meter: &mut Meter,
) -> Result<PartTimes, String> {
    let (w, h) = (args.width.unwrap_or(640), args.height.unwrap_or(360));
    let mut tour = BuildingTour::new();
    tour.portals.debug_tint = args.debug_portals;
    let mut renderer = Renderer::new();
    let mut target = Target::new(w, h);
    println!(
        "building: a hall of {} triangles, {} triangles behind its {} doorways, \
         {n} frames at {w}x{h} on {} threads",
        tour.building.hall.triangle_count(),
        tour.building.room_triangles(),
        tour.building.rooms.len(),
        rayon::current_num_threads()
    );
    let mut times = Vec::with_capacity(n);
    let (mut warped, mut geometry, mut rebuilds, mut samples, mut holes) = (0, 0, 0, 0, 0);
    let (mut room_tris, mut hidden) = (0, 0);
    let mut sum = FrameStats::default();
    for i in 0..n {
        let camera = BuildingTour::camera(i, n, w, h);
        let start = Instant::now();
        tour.render(&mut renderer, &camera, &mut target);
        times.push(start.elapsed());
        sum += renderer.stats();
        meter.building(&tour, &camera, w, h);
        let f = tour.last();
        (warped, geometry, rebuilds) = (
            warped + f.warped,
            geometry + f.geometry,
            rebuilds + f.rebuilds,
        );
        (samples, holes) = (samples + f.stats.samples, holes + f.holes);
        (room_tris, hidden) = (room_tris + f.triangles, hidden + f.hidden_parts);
        if !args.no_save {
            let path = dir.join(format!("building_{i:04}.png"));
            save_png(&path, &target.to_rgba8(), (w, h))?;
        }
    }
    let summary = Summary::of(&times);
    println!("building frame time: {summary}");
    println!(
        "portals over the tour: {warped} warped and {geometry} drawn as geometry (portal-frames), \
         {rebuilds} LDI rebuilds, {samples} samples warped, {holes} holes before filling{}",
        if args.debug_portals {
            " (warped pixels tinted green)"
        } else {
            ""
        }
    );
    println!(
        "  rooms drawn as geometry: {room_tris} triangles over the walk ({hidden} parts out of \
         their doorway's sight left out); triangles set up a frame: {:.0}",
        sum.triangles_in as f64 / n.max(1) as f64
    );
    println!("  last frame: {}", tour.readout());
    print_fragments("the walk's last render of each frame", &sum, n, (w, h));
    if !args.no_save {
        println!(
            "wrote {n} frames to {}/building_0000.png ...",
            dir.display()
        );
    }
    Ok(PartTimes::of(&times))
}

/// The views moment over `show`'s scene (posed at time 0), `n` frames; writes PNGs unless
/// `--no-save`; prints each frame's readout and a summary per part.
fn views_headless(
    args: &Args,
    dir: &Path,
    n: usize,
    mut show: Showcase,
    meter: &mut Meter,
) -> Result<PartTimes, String> {
    let (w, h) = (args.width.unwrap_or(640), args.height.unwrap_or(360));
    show.animate(0.0);
    let mut tour = ViewsTour::new(show.scene, w, h);
    println!(
        "views: a layered background, a panorama sky and a view morph of the plaza, {n} frames at {w}x{h} on {} \
         threads",
        rayon::current_num_threads()
    );
    // Built ahead, as a scene is loaded: no frame of the moment builds a part.
    let start = Instant::now();
    tour.prepare()?;
    println!(
        "  its parts built ahead in {:.1} ms",
        start.elapsed().as_secs_f64() * 1e3
    );
    let mut times = Vec::with_capacity(n);
    // The stages, then the CPU time of all threads showing the frame and of this thread alone
    // (what it did itself, the pool's work not: the frame's serial part), measuring left out.
    let columns: Vec<&str> = (Stages::COLUMNS.iter().copied())
        .chain(["cpu", "cpu_caller"])
        .collect();
    let mut breakdown = report::Breakdown::new(&columns);
    let mut faults = Vec::with_capacity(n);
    for i in 0..n {
        let used = Usage::now();
        let start = Instant::now();
        let frame = tour.render(i, n)?;
        // The geometry each frame is measured against is not part of showing it.
        let time = start.elapsed().saturating_sub(frame.measure);
        let shown = Usage::now().since(used);
        let cpu = shown.cpu.saturating_sub(frame.measure_usage.cpu);
        let caller = (shown.caller_cpu).saturating_sub(frame.measure_usage.caller_cpu);
        faults.push(shown.faults.saturating_sub(frame.measure_usage.faults));
        times.push(time);
        let mut row = frame.stages.row(frame.measure).to_vec();
        row.extend([cpu, caller]);
        breakdown.push(time, &row);
        if !args.no_save {
            let path = dir.join(format!("views_{i:04}.png"));
            save_png(&path, &frame.rgba, (frame.width, frame.height))?;
        }
        meter.views_tour(&tour);
        println!(
            "  {i:4}: {:6.1} ms  ({:.1} ms CPU, {:.1} on this thread, {} page faults)  {}",
            time.as_secs_f64() * 1e3,
            cpu.as_secs_f64() * 1e3,
            caller.as_secs_f64() * 1e3,
            faults[i],
            tour.readout()
        );
    }
    let summary = Summary::of(&times);
    println!(
        "views frame time (captures included, the geometry it is measured against not): {summary}"
    );
    for line in tour.summary() {
        println!("  {line}");
    }
    println!("where the views' time went (readout: its reference renders, not in the frame time):");
    for line in breakdown.lines() {
        println!("  {line}");
    }
    println!(
        "  page faults showing the frames (measuring left out): {} in all, at most {} a frame",
        faults.iter().sum::<u64>(),
        faults.iter().max().unwrap_or(&0)
    );
    write_into(dir, "views_times.csv", &breakdown.csv())?;
    if !args.no_save {
        println!("wrote {n} frames to {}/views_0000.png ...", dir.display());
    }
    Ok(PartTimes::of(&times))
}

/// The world moment's fly-over, `n` frames; writes PNGs unless `--no-save`; prints each
/// frame's planner readout.
fn world_headless(args: &Args, dir: &Path, n: usize) -> Result<PartTimes, String> {
    let (w, h) = (args.width.unwrap_or(640), args.height.unwrap_or(360));
    let mut tour = WorldTour::new();
    let mut renderer = Renderer::new();
    let mut target = Target::new(w, h);
    println!(
        "world: {} objects, {} triangles, drawn per node of a hierarchy; {n} frames at \
         {w}x{h} on {} threads",
        tour.world.objects.len(),
        tour.world.triangle_count(),
        rayon::current_num_threads()
    );
    // Loaded before the fly-over, as a level: the first frame is an ordinary one.
    let loading = Instant::now();
    let frames = tour.load(&mut renderer, w, h);
    let ms = loading.elapsed().as_secs_f64() * 1e3;
    println!("world: loaded in {frames} frames, {ms:.0} ms (before the fly-over)");
    let mut times = Vec::with_capacity(n);
    let mut errors = Vec::with_capacity(n);
    for i in 0..n {
        let camera = tour.camera(i, w, h);
        tour.render(&mut renderer, &camera, &mut target);
        times.push(tour.last_time);
        // Measured against all the geometry after the frame's time was taken.
        errors.push(tour.measure(&mut renderer, &camera, &target).mean_abs);
        let c = tour.coverage(&camera);
        println!(
            "  {i:4}: {}  ({} of {} in view drawn once)",
            tour.readout(),
            c.once,
            c.in_view
        );
        if !args.no_save {
            let path = dir.join(format!("world_{i:04}.png"));
            let mut rgba = target.to_rgba8();
            tour.annotate(&mut rgba, w, h);
            save_png(&path, &rgba, (w, h))?;
        }
    }
    println!("world frame time: {}", Summary::of(&times));
    if !args.no_save {
        println!("wrote {n} frames to {}/world_0000.png ...", dir.display());
    }
    let mean = errors.iter().sum::<f64>() / errors.len().max(1) as f64;
    let worst = errors.iter().copied().fold(0.0, f64::max);
    Ok(PartTimes {
        error: (!errors.is_empty()).then_some([mean, worst]),
        ..PartTimes::of(&times)
    })
}

/// Writes an RGBA8 image.
fn save_png(path: &Path, rgba: &[u8], (w, h): (u32, u32)) -> Result<(), String> {
    image::save_buffer(path, rgba, w, h, image::ColorType::Rgba8)
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}
