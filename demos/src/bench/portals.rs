//! The `bench portals` sweep: the building's rooms seen through their doorways, drawn as
//! geometry or through portals holding a flat image (a textured portal), one depth image,
//! or an LDI, against a render of the full geometry from the same eye.
//!
//! - `triangles`: a fixed eye in the hall (all three doorways in view), the rooms'
//!   furniture from a few thousand triangles to over a million; frame time (the portals'
//!   images already built: the steady frame) and error.
//! - `resolution`: the same eye and rooms at several frame sizes.
//! - `walk`: frames in order along the walkthrough (along the hall, then through the
//!   middle door): each frame's time, rebuilds included, and error.
//!
//! Every portal row records the renderer's triangles, the warped samples and the pixels
//! the portals wrote, so "cost follows pixels" can be read from counters as well as times.

mod report;

pub use report::{charts, PortalsSweep};

use crate::bench::sweep::{ticker, CsvRow, Timing as Frames};
use crate::building::Building;
use crate::timing::Summary;
use engine::{Camera, Draw, FrameOptions, FrameStats, Renderer, Rgba, Target};
use ibr::metrics::{self, Options};
use ibr::portal::{PortalConfig, PortalImage, Portals};
use ibr::subject::Subject;
use ibr::technique::{FrameLoop, FrameView, Technique};
use std::time::{Duration, Instant};

/// The methods: geometry, then the portal images.
const METHODS: [(&str, Option<PortalImage>); 4] = [
    ("geometry", None),
    ("flat", Some(PortalImage::Flat)),
    ("depth-image", Some(PortalImage::DepthImage)),
    ("ldi", Some(PortalImage::Ldi)),
];

/// What a run measures.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    pub size: (u32, u32),
    /// Triangles of furniture per room, for the `triangles` series.
    pub triangles: Vec<u32>,
    /// Per room, for the `resolution` and `walk` series.
    pub walk_triangles: u32,
    pub resolutions: Vec<(u32, u32)>,
    /// Frames along the walkthrough.
    pub walk_frames: usize,
    pub frames: Frames,
}

impl Settings {
    pub fn full() -> Settings {
        Settings {
            size: (1280, 720),
            triangles: vec![1_000, 10_000, 100_000, 400_000],
            walk_triangles: 100_000,
            resolutions: vec![(640, 360), (1280, 720), (1920, 1080)],
            walk_frames: 60,
            frames: Frames {
                warmup: 1,
                frames: 10,
                time_limit: Duration::from_millis(1500),
            },
        }
    }

    /// Every point, fewer frames.
    pub fn quick() -> Settings {
        Settings {
            walk_frames: 30,
            frames: Frames {
                warmup: 1,
                frames: 4,
                time_limit: Duration::from_millis(300),
            },
            ..Settings::full()
        }
    }

    /// Seconds: small frames, two furniture sizes.
    pub fn tiny() -> Settings {
        Settings {
            size: (128, 72),
            triangles: vec![1_000, 5_000],
            walk_triangles: 2_000,
            resolutions: vec![(96, 54), (128, 72)],
            walk_frames: 6,
            frames: Frames {
                warmup: 0,
                frames: 2,
                time_limit: Duration::ZERO,
            },
        }
    }
}

/// One measured point.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// `triangles`, `resolution` or `walk`.
    pub series: &'static str,
    /// `geometry`, `flat`, `depth-image` or `ldi`.
    pub method: &'static str,
    /// Walk: the path parameter in [0, 1]; else 0.
    pub t: f32,
    pub width: u32,
    pub height: u32,
    /// Triangles behind the doorways.
    pub room_triangles: usize,
    pub time: Summary,
    /// Against the geometry frame (geometry rows: none).
    pub error: Option<metrics::ImageError>,
    /// The renderer's triangles submitted, the portals' warped samples, pixels written,
    /// rebuilds, and portals drawn as geometry.
    pub triangles_in: u64,
    pub samples: u64,
    pub pixels: u64,
    pub rebuilds: u64,
    pub geometry_portals: u64,
}

impl Row {
    /// A point of `method` at `size` on `building`: its frame times, error, the renderer's
    /// counters and the portals' work in the last frame (none for geometry). Series and
    /// walk parameter left to the caller.
    fn measured(
        method: &'static str,
        (width, height): (u32, u32),
        building: &Building,
        times: &[Duration],
        error: Option<metrics::ImageError>,
        stats: FrameStats,
        portals: Option<&Portals>,
    ) -> Row {
        let last = portals.map(Portals::last).unwrap_or_default();
        Row {
            series: "",
            method,
            t: 0.0,
            width,
            height,
            room_triangles: building.room_triangles(),
            time: Summary::of(times),
            error,
            triangles_in: stats.triangles_in,
            samples: last.stats.samples,
            pixels: last.pixels,
            rebuilds: last.rebuilds,
            geometry_portals: last.geometry,
        }
    }
}

impl CsvRow for Row {
    const HEADER: &'static str = "series,method,t,width,height,room_triangles,frames,median_ms,min_ms,p90_ms,psnr_db,mean_abs,frac_over,triangles_in,samples,pixels,rebuilds,geometry_portals";

    fn csv(&self) -> String {
        let e = self.error;
        let f = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.4}"));
        format!(
            "{},{},{:.4},{},{},{},{},{:.4},{:.4},{:.4},{},{},{},{},{},{},{},{}",
            self.series,
            self.method,
            self.t,
            self.width,
            self.height,
            self.room_triangles,
            self.time.frames,
            self.time.median_ms,
            self.time.min_ms,
            self.time.p90_ms,
            f(e.map(|e| e.psnr_capped(99.0))),
            f(e.map(|e| e.mean_abs)),
            f(e.map(|e| e.frac_over)),
            self.triangles_in,
            self.samples,
            self.pixels,
            self.rebuilds,
            self.geometry_portals,
        )
    }
}

fn clear() -> FrameOptions {
    FrameOptions {
        clear: Some(Rgba::new(0.05, 0.05, 0.06, 1.0)),
        ..Default::default()
    }
}

/// The camera at walkthrough parameter `t`.
fn camera(t: f32, (w, h): (u32, u32)) -> Camera {
    let (eye, at) = Building::path(t);
    Camera::look_at(eye, at, glam::Vec3::Y, 60f32.to_radians(), 1.0)
        .with_aspect(w, h)
        .with_depth_range(0.05, 60.0)
}

/// Where the `triangles` and `resolution` series look from: the hall, doorways in view.
const EYE_T: f32 = 0.3;

/// One frame: the hall as geometry and either every room (`portals` None) or the
/// portals. Returns the renderer's counters.
fn frame(
    building: &Building,
    portals: Option<&mut Portals>,
    cam: &Camera,
    renderer: &mut Renderer,
    frames: &mut FrameLoop,
    target: &mut Target,
) -> FrameStats {
    let mut draws: Vec<Draw> = Vec::new();
    building.hall.draws(&mut draws);
    if portals.is_none() {
        for (_, room) in &building.rooms {
            room.draws(&mut draws);
        }
    }
    let view = FrameView {
        camera: cam,
        width: target.width(),
        height: target.height(),
        lighting: &building.lighting,
        time: 0.0,
        dt: 0.0,
    };
    match portals {
        Some(p) => {
            let mut list: [&mut dyn Technique; 1] = [p];
            frames.render(renderer, draws, &mut list, &view, target, &clear())
        }
        None => frames.render(renderer, draws, &mut [], &view, target, &clear()),
    }
}

/// The portals of `building` holding `image`.
fn portals(building: &Building, image: PortalImage) -> Portals {
    Portals::new(
        building.portals(),
        PortalConfig {
            image,
            side: 512,
            ..PortalConfig::default()
        },
    )
}

/// Runs the sweep at these settings; `progress(step, total, what)` before each point.
pub fn run(settings: &Settings, progress: &mut dyn FnMut(usize, usize, &str)) -> Vec<Row> {
    let total =
        (settings.triangles.len() + settings.resolutions.len()) * METHODS.len() + METHODS.len();
    let mut tick = ticker(total, progress);
    let mut renderer = Renderer::new();
    let mut frames = FrameLoop::new();
    let mut rows = Vec::new();
    // Still frames: `triangles` and `resolution`.
    let mut still = |series: &'static str, building: &Building, size: (u32, u32)| {
        let cam = camera(EYE_T, size);
        let mut truth = Target::new(size.0, size.1);
        frame(building, None, &cam, &mut renderer, &mut frames, &mut truth);
        let mut target = Target::new(size.0, size.1);
        let mut out = Vec::new();
        for (method, image) in METHODS {
            tick(format!(
                "{series} {} {}x{} {method}",
                building.room_triangles(),
                size.0,
                size.1
            ));
            let mut p = image.map(|i| portals(building, i));
            // Built first (untimed: until no build is under way), then timed as the
            // steady frame; the error is the last timed frame's.
            let mut draw = |p: &mut Option<Portals>, target: &mut Target| {
                frame(
                    building,
                    p.as_mut(),
                    &cam,
                    &mut renderer,
                    &mut frames,
                    target,
                )
            };
            let mut stats = draw(&mut p, &mut target);
            for _ in 0..100 {
                if p.as_ref().is_none_or(|p| p.last().stale == 0) {
                    break;
                }
                stats = draw(&mut p, &mut target);
            }
            let times = settings.frames.run(|| {
                let t = Instant::now();
                stats = draw(&mut p, &mut target);
                t.elapsed()
            });
            let error = p.as_ref().map(|_| {
                metrics::compare(&target, &truth, &Options::default()).expect("same size")
            });
            out.push(Row {
                series,
                t: 0.0,
                ..Row::measured(method, size, building, &times, error, stats, p.as_ref())
            });
        }
        out
    };
    for &n in &settings.triangles {
        let building = Building::new(n, 11);
        rows.extend(still("triangles", &building, settings.size));
    }
    let building = Building::new(settings.walk_triangles, 11);
    for &size in &settings.resolutions {
        rows.extend(still("resolution", &building, size));
    }
    // The walk: frames in order, rebuilds included.
    let (w, h) = settings.size;
    let mut truth = Target::new(w, h);
    let mut target = Target::new(w, h);
    for (method, image) in METHODS {
        tick(format!("walk {method}"));
        let mut p = image.map(|i| portals(&building, i));
        for k in 0..settings.walk_frames {
            let t = k as f32 / (settings.walk_frames.max(2) - 1) as f32;
            let cam = camera(t, settings.size);
            let start = Instant::now();
            let stats = frame(
                &building,
                p.as_mut(),
                &cam,
                &mut renderer,
                &mut frames,
                &mut target,
            );
            let time = start.elapsed();
            let error = p.as_ref().map(|_| {
                frame(
                    &building,
                    None,
                    &cam,
                    &mut renderer,
                    &mut frames,
                    &mut truth,
                );
                metrics::compare(&target, &truth, &Options::default()).expect("same size")
            });
            let (size, times) = ((w, h), [time]);
            rows.push(Row {
                series: "walk",
                t,
                ..Row::measured(method, size, &building, &times, error, stats, p.as_ref())
            });
        }
    }
    rows
}
