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

use clap::Parser;
use demos::font;
use demos::showcase::building::BuildingTour;
use demos::showcase::views::ViewsTour;
use demos::showcase::{self, toggled, FlyCamera, FlyInput, Showcase, TapCounter, SKY};
use demos::timing::Summary;
use engine::{FrameOptions, FrameStats, Renderer, Target};
use ibr::subject::Subject;
use minifb::{Key, MouseButton, MouseMode, Window, WindowOptions};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::{Arc, Mutex};
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
        (None, true) => match window(&args) {
            Ok(()) => Ok(()),
            Err(WindowError::Open(e)) => {
                eprintln!(
                    "showcase: cannot open a window ({e}); rendering headless to out/showcase"
                );
                headless(&args, Path::new("out/showcase"))
            }
            Err(WindowError::Update(e)) => Err(format!("window update failed: {e}")),
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

/// Renders the outdoor camera path, the building walkthrough and the views moment (or,
/// with `--building` or `--views`, that part alone).
fn headless(args: &Args, dir: &Path) -> Result<(), String> {
    if !args.no_save {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    }
    let n = args.frames.max(1);
    if args.building {
        return building_headless(args, dir, n);
    }
    if args.views {
        return views_headless(args, dir, n, Showcase::new());
    }
    let show = outdoor_headless(args, dir, n)?;
    match args.building_frames.unwrap_or((n / 2).max(1)) {
        0 => {}
        frames => building_headless(args, dir, frames)?,
    }
    match args.views_frames.unwrap_or((n / 10).max(3)) {
        0 => Ok(()),
        frames => views_headless(args, dir, frames, show),
    }
}

/// Renders the outdoor camera path, `n` frames; writes PNGs unless `--no-save`; prints
/// statistics. Returns the scene, for the views moment.
fn outdoor_headless(args: &Args, dir: &Path, n: usize) -> Result<Showcase, String> {
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
    let mut times = Vec::with_capacity(n);
    let mut stats = FrameStats::default();
    for i in 0..n {
        show.animate(i as f32 / 30.0);
        let (eye, look) = show.path(i, n);
        let camera = showcase::camera(eye, look, w, h);
        let start = Instant::now();
        stats = show.render(&mut renderer, &camera, &mut target, &opts);
        times.push(start.elapsed());
        show.ibr.statue.measure(&camera, w, h);
        if !args.no_save {
            let path = dir.join(format!("frame_{i:04}.png"));
            image::save_buffer(&path, &target.to_rgba8(), w, h, image::ColorType::Rgba8)
                .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
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
        match showcase::impostors::tour_chart(imp, &times, &path) {
            Ok(()) => println!(
                "  chart of error, refreshes and frame time over the tour: {}",
                path.display()
            ),
            Err(e) => eprintln!("  could not write {}: {e}", path.display()),
        }
    }
    let last = show.ibr.impostors.readout();
    println!("  last frame: {}", last.line());
    println!("  last frame: {}", last.city.line());
    print_statue(&show, n);
    println!("last frame: {stats:#?}");
    if !args.no_save {
        println!("wrote {n} frames to {}/frame_0000.png ...", dir.display());
    }
    Ok(show)
}

/// The light-field statue's readout over the tour.
fn print_statue(show: &Showcase, n: usize) {
    let s = &show.ibr.statue;
    let slabs = &s.object.slabs;
    let [nu, nv, ns, nt] = slabs.first().map_or([0; 4], |f| f.slab.counts());
    println!(
        "light-field statue: {} slabs of {nu}x{nv}x{ns}x{nt}, captured in {:.2} s and \
         vector-quantised ({} codewords) in {:.2} s",
        slabs.len(),
        s.capture.as_secs_f64(),
        showcase::lightfield::CODEWORDS,
        s.quantise.as_secs_f64()
    );
    println!(
        "  memory {:.2} MB held (codebooks and indices), {:.1} MB raw: {:.0}:1",
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

#[derive(Debug)]
enum WindowError {
    Open(minifb::Error),
    Update(minifb::Error),
}

/// Key events as they arrive from the window: Esc latches quitting, and taps of `I`, `B`
/// and `V` are counted, so a tap shorter than a frame (which the key state polled once a
/// frame, as `is_key_pressed` and `get_keys_pressed` read it, misses) still counts.
#[derive(Debug, Default)]
struct KeyEvents {
    quit: bool,
    debug_taps: TapCounter,
    building_taps: TapCounter,
    views_taps: TapCounter,
}

/// Taps since the last frame: of I, B and V.
#[derive(Clone, Copy, Debug)]
struct Taps {
    debug: u32,
    building: u32,
    views: u32,
}

/// What the window shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Moment {
    Outdoor,
    Building,
    Views,
}

impl Moment {
    /// After `taps`: each tap of B enters the building or leaves it for outdoors, and V
    /// likewise the views moment.
    fn after(self, taps: Taps) -> Moment {
        let mut m = self;
        for (key, moment) in [
            (taps.building, Moment::Building),
            (taps.views, Moment::Views),
        ] {
            if toggled(m == moment, key) != (m == moment) {
                m = if m == moment { Moment::Outdoor } else { moment };
            }
        }
        m
    }
}

/// The window's input callback, sharing [`KeyEvents`] with the frame loop.
#[derive(Debug)]
struct KeyLatch(Arc<Mutex<KeyEvents>>);

impl minifb::InputCallback for KeyLatch {
    fn add_char(&mut self, _: u32) {}

    fn set_key_state(&mut self, key: Key, down: bool) {
        let mut events = self.0.lock().unwrap_or_else(|e| e.into_inner());
        match key {
            Key::Escape if down => events.quit = true,
            Key::I => events.debug_taps.event(down),
            Key::B => events.building_taps.event(down),
            Key::V => events.views_taps.event(down),
            _ => {}
        }
    }
}

/// Reads the keyboard and mouse into a fly-camera input.
fn read_input(window: &Window, last_mouse: &mut Option<(f32, f32)>, dt: f32) -> FlyInput {
    let key = |k: Key| window.is_key_down(k) as i32 as f32;
    let mut input = FlyInput {
        forward: key(Key::W) - key(Key::S),
        right: key(Key::D) - key(Key::A),
        up: key(Key::E) - key(Key::Q),
        fast: window.is_key_down(Key::LeftShift) || window.is_key_down(Key::RightShift),
        ..Default::default()
    };
    let turn = 1.8 * dt;
    input.yaw = (key(Key::Left) - key(Key::Right)) * turn;
    input.pitch = (key(Key::Up) - key(Key::Down)) * turn;
    let mouse = window.get_mouse_pos(MouseMode::Pass);
    if window.get_mouse_down(MouseButton::Left) {
        if let (Some((x0, y0)), Some((x, y))) = (*last_mouse, mouse) {
            input.yaw -= (x - x0) * 0.005;
            input.pitch -= (y - y0) * 0.005;
        }
        *last_mouse = mouse;
    } else {
        *last_mouse = None;
    }
    input
}

/// Opens a resizable window `w` x `h` with the key-event latch.
fn open_window(
    title: &str,
    w: u32,
    h: u32,
) -> Result<(Window, Arc<Mutex<KeyEvents>>), WindowError> {
    let options = WindowOptions {
        resize: true,
        ..Default::default()
    };
    let mut window =
        Window::new(title, w as usize, h as usize, options).map_err(WindowError::Open)?;
    window.set_target_fps(0);
    let keys = Arc::new(Mutex::new(KeyEvents::default()));
    window.set_input_callback(Box::new(KeyLatch(keys.clone())));
    Ok((window, keys))
}

/// The taps since the last frame; `None` when the window should close.
fn poll(window: &Window, keys: &Mutex<KeyEvents>) -> Option<Taps> {
    let (quit, taps) = {
        let mut events = keys.lock().unwrap_or_else(|e| e.into_inner());
        let taps = Taps {
            debug: events.debug_taps.take(),
            building: events.building_taps.take(),
            views: events.views_taps.take(),
        };
        (events.quit, taps)
    };
    (window.is_open() && !window.is_key_down(Key::Escape) && !quit).then_some(taps)
}

/// Resizes `target` to the window's size (at least 1 x 1); returns it.
fn fit(window: &Window, target: &mut Target) -> (u32, u32) {
    let (ww, wh) = window.get_size();
    let (ww, wh) = (ww.max(1) as u32, wh.max(1) as u32);
    if (ww, wh) != (target.width(), target.height()) {
        target.resize(ww, wh);
    }
    (ww, wh)
}

/// Milliseconds of image refreshes per frame in the window: the clouds' (measured), and the
/// city's rebuilds (predicted by the planner's cost model).
const REFRESH_MS: u64 = 3;

fn window(args: &Args) -> Result<(), WindowError> {
    let (w, h) = (args.width.unwrap_or(960), args.height.unwrap_or(540));
    let (mut window, keys) = open_window("Parallax showcase", w, h)?;
    let mut show = Showcase::new();
    show.ibr.impostors.set_debug(args.debug_impostors);
    // Interactive: refreshes get a time budget per frame (what recent ones cost fits in),
    // not a fixed count; headless runs keep counts so their frames are reproducible.
    show.ibr
        .impostors
        .set_time_budget(Some(Duration::from_millis(REFRESH_MS)));
    // The building and the views moment are made when first entered (B, V).
    let mut tour: Option<BuildingTour> = None;
    let mut views: Option<ViewsTour> = None;
    let mut moment = match (args.building, args.views) {
        (true, _) => Moment::Building,
        (_, true) => Moment::Views,
        _ => Moment::Outdoor,
    };
    let mut fly = FlyCamera::default();
    let mut renderer = Renderer::new();
    let mut target = Target::new(w, h);
    let mut pixels = Vec::new();
    let opts = FrameOptions {
        clear: Some(SKY),
        ..Default::default()
    };
    let tris = show.scene.triangle_count();
    let start = Instant::now();
    let mut last = Instant::now();
    let mut last_mouse = None;
    let mut recent: Vec<Duration> = Vec::new();
    let mut shown = Summary::default();
    let mut title_at = Instant::now();
    let (mut frame_no, mut statue) = (0u64, String::new());
    while let Some(taps) = poll(&window, &keys) {
        let debug_taps = taps.debug;
        let now = Instant::now();
        let dt = (now - last).as_secs_f32().min(0.1);
        last = now;
        if moment.after(taps) != moment {
            moment = moment.after(taps);
            recent.clear();
        }
        let (ww, wh) = fit(&window, &mut target);
        let (bw, bh) = (ww as usize, wh as usize);
        let (title, readout, help);
        let mut city = String::new();
        if moment == Moment::Views {
            let tour = views.get_or_insert_with(|| ViewsTour::new(show.scene.clone(), ww, wh));
            (title, readout, help) = views_frame(tour, start, (ww, wh), &mut pixels, &mut recent);
        } else if moment == Moment::Building {
            let tour = tour.get_or_insert_with(|| {
                let mut tour = BuildingTour::new();
                tour.portals.debug_tint = args.debug_portals;
                tour
            });
            tour.portals.debug_tint = toggled(tour.portals.debug_tint, debug_taps);
            let t0 = Instant::now();
            tour.render(&mut renderer, &building_camera(start, ww, wh), &mut target);
            recent.push(t0.elapsed());
            title = "building".to_string();
            readout = tour.readout();
            help = "I TINT WARPED PIXELS  B OUTDOORS  V VIEWS  ESC QUIT";
            target.write_rgb_u32(&mut pixels);
        } else {
            let input = read_input(&window, &mut last_mouse, dt);
            fly.update(&input, dt);
            let on = show.ibr.impostors.debug();
            if toggled(on, debug_taps) != on {
                show.ibr.impostors.set_debug(!on);
            }
            show.animate(start.elapsed().as_secs_f32());
            let camera = fly.camera(ww, wh);
            let t0 = Instant::now();
            let stats = show.render(&mut renderer, &camera, &mut target, &opts);
            recent.push(t0.elapsed());
            // Measured every eighth frame: it renders the statue twice more.
            frame_no += 1;
            if frame_no % 8 == 1 {
                show.ibr.statue.measure(&camera, ww, wh);
            }
            statue = show.ibr.statue.line();
            let imp = show.ibr.impostors.readout();
            let debug = show.ibr.impostors.debug();
            title = outdoor_title(tris, &stats, &imp, debug);
            readout = format!("{}{}", imp.line(), if debug { "  DEBUG" } else { "" });
            city = imp.city.line();
            if debug {
                city = format!("{city}  {}", show.ibr.impostors.legend().to_uppercase());
            }
            help = "WASD MOVE  DRAG/ARROWS LOOK  Q/E DOWN/UP  SHIFT FAST  I DEBUG VIEW  \
                    B BUILDING  V VIEWS  ESC QUIT";
            target.write_rgb_u32(&mut pixels);
        }
        if title_at.elapsed() >= Duration::from_millis(500) && !recent.is_empty() {
            shown = Summary::of(&recent);
            recent.clear();
            title_at = Instant::now();
            window.set_title(&window_title(&shown, (ww, wh), &title));
        }
        let lines = [readout.as_str(), city.as_str(), statue.as_str()];
        let outdoor = moment == Moment::Outdoor;
        overlay(
            &mut pixels,
            (bw, bh),
            &shown,
            &lines[..if outdoor { 3 } else { 1 }],
            help,
        );
        window
            .update_with_buffer(&pixels, bw, bh)
            .map_err(WindowError::Update)?;
    }
    Ok(())
}

/// What the window's title says of an outdoor frame: its work, the impostors' and the
/// city's.
fn outdoor_title(
    tris: usize,
    stats: &FrameStats,
    imp: &showcase::impostors::Readout,
    debug: bool,
) -> String {
    let [g, i, l] = imp.city.counts;
    format!(
        "{tris} tris, {} shaded px - impostors: {} refreshed, {} images, {} geometry, \
         max error {:.2} - city: {g} geometry, {i} impostors, {l} layers{}",
        stats.fragments_shaded,
        imp.refreshes(),
        imp.images(),
        imp.geometry(),
        imp.max_ratio(),
        if debug { " (debug view)" } else { "" }
    )
}

/// The window's title: frame time, rate, size and what is shown.
fn window_title(shown: &Summary, (ww, wh): (u32, u32), title: &str) -> String {
    format!(
        "Parallax showcase - {:.1} ms ({:.0} fps) - {ww}x{wh} - {title}",
        shown.median_ms,
        1e3 / shown.median_ms.max(1e-9),
    )
}

/// One frame of the views moment, at the window's size when it was made (later sizes are
/// scaled to): the layered background, the panorama sky and the morph for 20 s each, in a
/// loop. Its title, readout and help.
fn views_frame(
    tour: &mut ViewsTour,
    start: Instant,
    (ww, wh): (u32, u32),
    pixels: &mut Vec<u32>,
    recent: &mut Vec<Duration>,
) -> (String, String, &'static str) {
    const LOOP: f32 = 60.0;
    let t = (start.elapsed().as_secs_f32() % LOOP) / LOOP;
    let steps = 10_000;
    let t0 = Instant::now();
    let readout = match tour.render((t * (steps - 1) as f32) as usize, steps) {
        Ok(frame) => {
            frame.write_rgb_u32(pixels, ww, wh);
            tour.readout()
        }
        Err(e) => {
            pixels.clear();
            pixels.resize(ww as usize * wh as usize, 0);
            e.to_uppercase()
        }
    };
    recent.push(t0.elapsed());
    let title = "views (layered background, panorama sky, view morph)".to_string();
    (title, readout, "V OUTDOORS  B BUILDING  ESC QUIT")
}

/// The building walkthrough's camera now: it plays in a loop of 30 s.
fn building_camera(start: Instant, ww: u32, wh: u32) -> engine::Camera {
    const LOOP: f32 = 30.0;
    let t = (start.elapsed().as_secs_f32() % LOOP) / LOOP;
    let steps = 10_000;
    BuildingTour::camera((t * (steps - 1) as f32) as usize, steps, ww, wh)
}

/// The on-screen text: frame time and size, the readout `lines` one under another, the
/// keys' `help` at the bottom.
fn overlay(
    pixels: &mut [u32],
    (bw, bh): (usize, usize),
    shown: &Summary,
    lines: &[&str],
    help: &str,
) {
    let text = format!(
        "{:.1} MS  {:.0} FPS  {}X{}",
        shown.median_ms,
        1e3 / shown.median_ms.max(1e-9),
        bw,
        bh
    );
    font::draw_text(pixels, bw, bh, 6, 6, 2, &text, 0x00ff_ff80);
    let colours = [0x0080_ffc0, 0x0080_ffc0, 0x00ff_c080];
    for (k, (line, colour)) in lines.iter().zip(colours).enumerate() {
        font::draw_text(pixels, bw, bh, 6, 20 + 14 * k, 2, line, colour);
    }
    let bottom = bh.saturating_sub(18);
    font::draw_text(pixels, bw, bh, 6, bottom, 2, help, 0x00e0_e0e0);
}

/// The building tour along its walkthrough, `n` frames; writes PNGs unless `--no-save`;
/// prints the frame times and the portals' work.
fn building_headless(args: &Args, dir: &Path, n: usize) -> Result<(), String> {
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
    for i in 0..n {
        let camera = BuildingTour::camera(i, n, w, h);
        let start = Instant::now();
        tour.render(&mut renderer, &camera, &mut target);
        times.push(start.elapsed());
        let f = tour.last();
        (warped, geometry, rebuilds) = (
            warped + f.warped,
            geometry + f.geometry,
            rebuilds + f.rebuilds,
        );
        (samples, holes) = (samples + f.stats.samples, holes + f.holes);
        if !args.no_save {
            let path = dir.join(format!("building_{i:04}.png"));
            image::save_buffer(&path, &target.to_rgba8(), w, h, image::ColorType::Rgba8)
                .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
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
    println!("  last frame: {}", tour.readout());
    if !args.no_save {
        println!(
            "wrote {n} frames to {}/building_0000.png ...",
            dir.display()
        );
    }
    Ok(())
}

/// The views moment over `show`'s scene (posed at time 0), `n` frames; writes PNGs unless
/// `--no-save`; prints each frame's readout and a summary per part.
fn views_headless(args: &Args, dir: &Path, n: usize, mut show: Showcase) -> Result<(), String> {
    let (w, h) = (args.width.unwrap_or(640), args.height.unwrap_or(360));
    show.animate(0.0);
    let mut tour = ViewsTour::new(show.scene, w, h);
    println!(
        "views: a layered background, a panorama sky and a view morph of the plaza, {n} frames at {w}x{h} on {} \
         threads",
        rayon::current_num_threads()
    );
    let mut times = Vec::with_capacity(n);
    for i in 0..n {
        let start = Instant::now();
        let frame = tour.render(i, n)?;
        times.push(start.elapsed());
        if !args.no_save {
            let path = dir.join(format!("views_{i:04}.png"));
            image::save_buffer(
                &path,
                &frame.rgba,
                frame.width,
                frame.height,
                image::ColorType::Rgba8,
            )
            .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        }
        println!("  {i:4}: {}", tour.readout());
    }
    let summary = Summary::of(&times);
    println!(
        "views frame time (captures and the geometry it is measured against included): {summary}"
    );
    for line in tour.summary() {
        println!("  {line}");
    }
    if !args.no_save {
        println!("wrote {n} frames to {}/views_0000.png ...", dir.display());
    }
    Ok(())
}
