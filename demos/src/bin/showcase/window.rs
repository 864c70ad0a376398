//! The showcase's window: the fly camera outdoors, and the moments (the building tour, the
//! views, the world) each entered and left by its key ([`Moment::KEYED`]), each frame
//! timed, with its readout drawn over it.

use super::Args;
use demos::font;
use demos::showcase::attractions::Meter;
use demos::showcase::building::BuildingTour;
use demos::showcase::views::ViewsTour;
use demos::showcase::world::WorldTour;
use demos::showcase::{self, toggled, FlyCamera, FlyInput, Showcase, TapCounter, SKY};
use demos::timing::Summary;
use engine::{FrameOptions, FrameStats, Renderer, Target};
use minifb::{Key, MouseButton, MouseMode, Window, WindowOptions};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Why the window failed: opening it (the showcase then renders headless) or updating it.
#[derive(Debug)]
pub(super) enum WindowError {
    Open(minifb::Error),
    Update(minifb::Error),
}

/// Key events as they arrive from the window: Esc latches quitting, and taps of `I` and
/// of each moment's key are counted, so a tap shorter than a frame (which the key state
/// polled once a frame, as `is_key_pressed` and `get_keys_pressed` read it, misses) still
/// counts.
#[derive(Debug, Default)]
struct KeyEvents {
    quit: bool,
    debug_taps: TapCounter,
    moment_taps: [TapCounter; Moment::KEYED.len()],
}

/// Taps since the last frame: of I, and of each moment's key ([`Moment::KEYED`]).
#[derive(Clone, Copy, Debug)]
struct Taps {
    debug: u32,
    moments: [u32; Moment::KEYED.len()],
}

/// What the window shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Moment {
    Outdoor,
    Building,
    Views,
    World,
}

impl Moment {
    /// The moments besides outdoors and the key that enters and leaves each.
    const KEYED: [(Moment, Key); 3] = [
        (Moment::Building, Key::B),
        (Moment::Views, Key::V),
        (Moment::World, Key::O),
    ];

    /// The moment the window starts in: the one the flags name, else outdoors.
    fn first(args: &Args) -> Moment {
        match (args.building, args.views, args.world) {
            (true, _, _) => Moment::Building,
            (_, true, _) => Moment::Views,
            (_, _, true) => Moment::World,
            _ => Moment::Outdoor,
        }
    }

    /// The part of the showcase this moment is, as `summary.json` names it.
    fn part(self) -> &'static str {
        match self {
            Moment::Outdoor => "tour",
            Moment::Building => "building",
            Moment::Views => "views",
            Moment::World => "world",
        }
    }

    /// The lines of readout it shows under the frame time (the world's three: as one
    /// line it runs past the window's right edge at 960 pixels).
    fn readout_lines(self) -> usize {
        match self {
            Moment::Outdoor | Moment::World => 3,
            Moment::Building | Moment::Views => 1,
        }
    }

    /// After `taps`: each tap of a moment's key enters that moment or leaves it for
    /// outdoors.
    fn after(self, taps: Taps) -> Moment {
        let mut m = self;
        for (&(moment, _), &key) in Moment::KEYED.iter().zip(&taps.moments) {
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
            key => {
                let keyed = Moment::KEYED.iter().position(|&(_, k)| k == key);
                if let Some(k) = keyed {
                    events.moment_taps[k].event(down);
                }
            }
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
            moments: std::array::from_fn(|k| events.moment_taps[k].take()),
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

pub(super) fn window(args: &Args) -> Result<(), WindowError> {
    let (w, h) = (args.width.unwrap_or(960), args.height.unwrap_or(540));
    let (mut window, keys) = open_window("Parallax showcase", w, h)?;
    let mut show = Showcase::new();
    show.ibr.impostors.set_debug(args.debug_impostors);
    // Interactive: refreshes get a time budget per frame (what recent ones cost fits in),
    // not a fixed count; headless runs keep counts so their frames are reproducible.
    show.ibr
        .impostors
        .set_time_budget(Some(Duration::from_millis(REFRESH_MS)));
    // The moments are made when first entered (B, V, O).
    let (mut tour, mut views): (Option<BuildingTour>, Option<ViewsTour>) = (None, None);
    let mut world: Option<WorldTour> = None;
    let mut moment = Moment::first(args);
    let mut fly = FlyCamera::default();
    let mut renderer = Renderer::new();
    let mut target = Target::new(w, h);
    let mut pixels = Vec::new();
    let opts = FrameOptions {
        clear: Some(SKY),
        ..Default::default()
    };
    show.prepare(&mut renderer, &fly.camera(w, h), &mut target, &opts); // at loading
    let tris = show.scene.triangle_count();
    let (start, mut last) = (Instant::now(), Instant::now());
    let mut last_mouse = None;
    let mut recent: Vec<Duration> = Vec::new();
    let mut shown = Summary::default();
    let mut title_at = Instant::now();
    let (mut frame_no, mut statue) = (0u64, String::new());
    // Each attraction measured against its geometry every eighth frame of its part (the
    // flicker pairs are eight frames apart here).
    let mut meter = Meter::new();
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
            meter.views_tour(tour);
        } else if moment == Moment::World {
            let tour = world.get_or_insert_with(|| WorldTour::loaded(&mut renderer, ww, wh));
            (title, _, help) = world_frame(tour, &mut renderer, &mut target, start);
            [readout, city, statue] = tour.readout_lines();
            recent.push(tour.last_time);
            target.write_rgb_u32(&mut pixels);
        } else if moment == Moment::Building {
            let tour = tour.get_or_insert_with(|| {
                let mut tour = BuildingTour::new();
                tour.portals.debug_tint = args.debug_portals;
                tour
            });
            tour.portals.debug_tint = toggled(tour.portals.debug_tint, debug_taps);
            let camera = building_camera(start, ww, wh);
            recent.push(timed(|| tour.render(&mut renderer, &camera, &mut target)));
            frame_no += 1;
            if frame_no % 8 == 1 {
                meter.building(tour, &camera, ww, wh);
            }
            (title, readout) = ("building".to_string(), tour.readout());
            help = "I TINT WARPED PIXELS  B OUTDOORS  V VIEWS  O WORLD  ESC QUIT";
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
            let mut stats = FrameStats::default();
            recent.push(timed(|| {
                stats = show.render(&mut renderer, &camera, &mut target, &opts);
            }));
            // Measured every eighth frame: it renders each attraction twice more.
            frame_no += 1;
            if frame_no % 8 == 1 {
                meter.tour(&show, &camera, ww, wh);
                show.ibr.statue.error = meter.last_of("statue");
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
                    B BUILDING  V VIEWS  O WORLD  ESC QUIT";
            target.write_rgb_u32(&mut pixels);
        }
        if title_at.elapsed() >= Duration::from_millis(500) && !recent.is_empty() {
            shown = Summary::of(&recent);
            recent.clear();
            title_at = Instant::now();
            window.set_title(&window_title(&shown, (ww, wh), &title));
        }
        let lines = [readout.as_str(), city.as_str(), statue.as_str()];
        let n = moment.readout_lines();
        overlay(&mut pixels, (bw, bh), &shown, &lines[..n], help);
        attraction_lines(&mut pixels, (bw, bh), &meter.part_lines(moment.part()));
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
    (title, readout, "V OUTDOORS  B BUILDING  O WORLD  ESC QUIT")
}

/// The building walkthrough's camera now: it plays in a loop of 30 s.
fn building_camera(start: Instant, ww: u32, wh: u32) -> engine::Camera {
    const LOOP: f32 = 30.0;
    let t = (start.elapsed().as_secs_f32() % LOOP) / LOOP;
    let steps = 10_000;
    BuildingTour::camera((t * (steps - 1) as f32) as usize, steps, ww, wh)
}

/// How long `f` takes.
fn timed<T>(f: impl FnOnce() -> T) -> Duration {
    let t0 = Instant::now();
    f();
    t0.elapsed()
}

/// One frame of the world moment: its fly-over plays in a loop of 40 s. Its title,
/// readout and help.
fn world_frame(
    tour: &mut WorldTour,
    renderer: &mut Renderer,
    target: &mut Target,
    start: Instant,
) -> (String, String, &'static str) {
    const LOOP: f32 = 40.0;
    let t = (start.elapsed().as_secs_f32() % LOOP) / LOOP;
    let camera = tour.camera_at(t, target.width(), target.height());
    tour.render(renderer, &camera, target);
    let title = "world (planned per node)".to_string();
    (
        title,
        tour.readout(),
        "O OUTDOORS  B BUILDING  V VIEWS  ESC QUIT",
    )
}

/// The part's attractions' figures so far (PSNR against geometry, flicker), one small line
/// each above the keys' help.
fn attraction_lines(pixels: &mut [u32], (bw, bh): (usize, usize), lines: &[String]) {
    let top = bh.saturating_sub(30 + 10 * lines.len());
    for (k, line) in lines.iter().enumerate() {
        font::draw_text(pixels, bw, bh, 6, top + 10 * k, 1, line, 0x00c0_ffc0);
    }
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
