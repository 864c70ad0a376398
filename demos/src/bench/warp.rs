//! The `bench warp` sweep: depth images of the city warped to eyes moved away from where
//! they were captured, against a render of the geometry from the same eye.
//!
//! References are captured around a home eye looking at the city's centre: one (the home
//! eye), two (left and right of it) or four (also above and below), each at the sweep's
//! frame size. Each target eye is the home eye moved sideways (`distance`, a fraction of the
//! city's half width) or orbited about the centre (`angle`, degrees). For every method
//! (references x points or splats, later references composited by depth or only into
//! holes; holes filled by pull-push, or from the background side for `splats-background`;
//! and one LDI built from the home view and the four around it, filled by pull-push) a
//! point records the error
//! against the geometry frame (PSNR over the frame and over the pixels the references saw
//! before filling, mean error, fraction over the threshold), the holes, and the times of
//! the warp frame and the geometry frame. A `speed` series times one reference warped with
//! splats and filled each way at 1920x1080 (smaller in quick and tiny runs).

mod report;

pub use report::{charts, WarpSweep};

use crate::bench::sweep::{ticker, CsvRow, Timing as Frames};
use crate::city::City;
use crate::showcase::{self, Showcase};
use crate::timing::Summary;
use engine::{Camera, Draw, FrameOptions, Renderer, Rgba, Target};
use glam::{Mat4, Quat, Vec3};
use ibr::depth_images::WarpedView;
use ibr::images::DepthImage;
use ibr::metrics::{self, Options, Region};
use ibr::subject::Subject;
use ibr::technique::{FrameLoop, FrameView, Technique};
use ibr::warp::holes::Fill;
use ibr::warp::ldi::LdiBuilder;
use ibr::warp::mesh::{depth_mesh, depth_mesh_material};
use ibr::warp::{Composite, Reconstruction, Visibility};
use std::time::{Duration, Instant};

/// The warp methods: (name, reconstruction, how references composite, how holes are
/// filled).
const METHODS: [(&str, Reconstruction, Composite, Fill); 4] = [
    (
        "points",
        Reconstruction::Points,
        Composite::Depth,
        Fill::PullPush,
    ),
    (
        "splats",
        Reconstruction::Splats,
        Composite::Depth,
        Fill::PullPush,
    ),
    (
        "splats-priority",
        Reconstruction::Splats,
        Composite::Priority,
        Fill::PullPush,
    ),
    (
        "splats-background",
        Reconstruction::Splats,
        Composite::Depth,
        Fill::Background,
    ),
];

/// What a run measures.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    pub size: (u32, u32),
    /// Triangles of the city (its buildings are split to reach them).
    pub triangles: usize,
    /// Sideways moves, fractions of the city's half width.
    pub distances: Vec<f32>,
    /// Orbits about the centre, degrees.
    pub angles: Vec<f32>,
    /// Reference counts to compare.
    pub references: Vec<usize>,
    /// The `speed` series' frame size.
    pub speed_size: (u32, u32),
    pub frames: Frames,
}

impl Settings {
    pub fn full() -> Settings {
        Settings {
            size: (640, 360),
            triangles: 500_000,
            distances: vec![0.0, 0.05, 0.1, 0.2, 0.4, 0.8],
            angles: vec![0.0, 2.0, 5.0, 10.0, 20.0, 40.0],
            references: vec![1, 2, 4],
            speed_size: (1920, 1080),
            frames: Frames {
                warmup: 2,
                frames: 15,
                time_limit: Duration::from_millis(1500),
            },
        }
    }

    /// Every point, fewer frames.
    pub fn quick() -> Settings {
        Settings {
            frames: Frames {
                warmup: 1,
                frames: 5,
                time_limit: Duration::from_millis(400),
            },
            ..Settings::full()
        }
    }

    /// Seconds: a small frame, two moves each way.
    pub fn tiny() -> Settings {
        Settings {
            size: (96, 54),
            triangles: 5_000,
            distances: vec![0.0, 0.2],
            angles: vec![5.0],
            references: vec![1, 2],
            speed_size: (160, 90),
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
    /// `distance`, `angle` or `speed`.
    pub series: &'static str,
    /// The move: fraction of the half width, or degrees.
    pub value: f32,
    /// `geometry`, or `points` / `splats` / `splats-priority` / `splats-background` for a
    /// warp of the nearest
    /// references, or `ldi`: one layered depth image at the home eye built from five views
    /// (references: 5), splatted; or `mesh`: the home view as a mesh broken at depth edges,
    /// drawn by the rasterizer (references: 1).
    pub method: &'static str,
    pub references: usize,
    pub width: u32,
    pub height: u32,
    pub triangles: usize,
    pub time: Summary,
    /// Error against the geometry frame (geometry rows: none).
    pub error: Option<metrics::ImageError>,
    /// PSNR over the pixels the references saw (before filling).
    pub psnr_seen: f64,
    /// Holes before filling, as a fraction of the frame, and by kind.
    pub holes: f64,
    pub cracks: u64,
    pub disocclusions: u64,
    /// Reference samples warped per frame.
    pub samples: u64,
    /// The predicted parallax spread of the nearest reference (pixels).
    pub predicted_px: f32,
}

impl Row {
    /// A timed point with nothing else measured yet: no error, no holes, no samples.
    fn timed(
        method: &'static str,
        (width, height): (u32, u32),
        city: &City,
        times: &[Duration],
    ) -> Row {
        Row {
            series: "",
            value: 0.0,
            method,
            references: 0,
            width,
            height,
            triangles: city.triangle_count(),
            time: Summary::of(times),
            error: None,
            psnr_seen: f64::NAN,
            holes: 0.0,
            cracks: 0,
            disocclusions: 0,
            samples: 0,
            predicted_px: 0.0,
        }
    }
}

impl CsvRow for Row {
    const HEADER: &'static str = "series,value,method,references,width,height,triangles,frames,median_ms,min_ms,p90_ms,psnr_db,psnr_seen_db,mean_abs,frac_over,holes,cracks,disocclusions,samples,msamples_per_s,predicted_px";

    fn csv(&self) -> String {
        let e = self.error;
        let f = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.4}"));
        let rate = (self.samples > 0 && self.time.median_ms > 0.0)
            .then(|| self.samples as f64 / self.time.median_ms / 1e3);
        format!(
            "{},{},{},{},{},{},{},{},{:.4},{:.4},{:.4},{},{},{},{},{:.5},{},{},{},{},{:.3}",
            self.series,
            self.value,
            self.method,
            self.references,
            self.width,
            self.height,
            self.triangles,
            self.time.frames,
            self.time.median_ms,
            self.time.min_ms,
            self.time.p90_ms,
            f(e.map(|e| e.psnr_capped(99.0))),
            f((self.error.is_some()).then_some(self.psnr_seen.min(99.0))),
            f(e.map(|e| e.mean_abs)),
            f(e.map(|e| e.frac_over)),
            self.holes,
            self.cracks,
            self.disocclusions,
            self.samples,
            f(rate),
            self.predicted_px,
        )
    }
}

fn clear() -> FrameOptions {
    FrameOptions {
        clear: Some(Rgba::new(0.55, 0.65, 0.8, 1.0)),
        ..Default::default()
    }
}

/// The home eye and the point every camera looks at.
fn home(city: &City) -> (Vec3, Vec3) {
    let e = city.half_extent;
    (Vec3::new(0.0, e * 0.6, e * 1.6), Vec3::new(0.0, 2.0, 0.0))
}

fn camera(eye: Vec3, at: Vec3, (w, h): (u32, u32), city: &City) -> Camera {
    Camera::look_at(eye, at, Vec3::Y, 50f32.to_radians(), 1.0)
        .with_aspect(w, h)
        .with_depth_range(0.5, city.half_extent * 8.0)
}

/// The frame view of `camera` over the city at `size` (a still scene: no time).
fn still_view<'a>(
    camera: &'a Camera,
    city: &'a City,
    (width, height): (u32, u32),
) -> FrameView<'a> {
    FrameView {
        camera,
        width,
        height,
        lighting: &city.lighting,
        time: 0.0,
        dt: 0.0,
    }
}

/// Renders the city's geometry from `camera` into `target`.
fn geometry(
    renderer: &mut Renderer,
    frame: &mut FrameLoop,
    city: &City,
    camera: &Camera,
    target: &mut Target,
) {
    let mut draws: Vec<Draw> = Vec::with_capacity(city.buildings.len() + 1);
    city.ground.draws(&mut draws);
    for b in &city.buildings {
        b.draws(&mut draws);
    }
    let view = still_view(camera, city, (target.width(), target.height()));
    frame.render(renderer, draws, &mut [], &view, target, &clear());
}

/// The reference eyes: home, then left and right, then above and below.
fn reference_eyes(city: &City, n: usize) -> Vec<Vec3> {
    let (eye, _) = home(city);
    let s = city.half_extent * 0.2;
    let all = [
        eye,
        eye - Vec3::X * s,
        eye + Vec3::X * s,
        eye + Vec3::Y * s,
        eye - Vec3::Y * s,
    ];
    match n {
        1 => vec![all[0]],
        2 => vec![all[1], all[2]],
        _ => all[1..5].to_vec(),
    }
}

/// A target eye for a series' move.
fn target_eye(city: &City, series: &str, value: f32) -> Vec3 {
    let (eye, at) = home(city);
    match series {
        "angle" => at + Quat::from_rotation_y(value.to_radians()) * (eye - at),
        _ => eye + Vec3::X * value * city.half_extent,
    }
}

/// What the warps start from: the depth images of each reference count as a warped view,
/// the LDI at the home eye, and the home view as a mesh with its material.
struct References {
    views: Vec<(usize, WarpedView)>,
    ldi: WarpedView,
    mesh: engine::Mesh,
    material: engine::Material,
}

/// Renders the references of `settings` around the city's home eye looking at `at`.
fn references(
    city: &City,
    at: Vec3,
    settings: &Settings,
    renderer: &mut Renderer,
    frame: &mut FrameLoop,
    target: &mut Target,
) -> References {
    let capture =
        |renderer: &mut Renderer, frame: &mut FrameLoop, target: &mut Target, n: usize| {
            reference_eyes(city, n)
                .into_iter()
                .map(|eye| {
                    let cam = camera(eye, at, settings.size, city);
                    geometry(renderer, frame, city, &cam, target);
                    DepthImage::from_target(target, &cam)
                })
                .collect::<Vec<_>>()
        };
    let views: Vec<(usize, WarpedView)> = settings
        .references
        .iter()
        .map(|&n| {
            let refs = capture(renderer, frame, target, n);
            let mut v = WarpedView::new(format!("warp {n}"), refs);
            v.nearest = n;
            (n, v)
        })
        .collect();
    // An LDI at the home eye from the home view and the four around it (the home view
    // first, so it is the front layer).
    let ldi = {
        let (eye, _) = home(city);
        let home_cam = camera(eye, at, settings.size, city);
        let mut images = capture(renderer, frame, target, 1);
        images.extend(capture(renderer, frame, target, 4));
        let ldi =
            LdiBuilder::default().build(&home_cam, settings.size.0, settings.size.1, &images, 0.02);
        let mut v = WarpedView::new("ldi", Vec::new());
        v.layered.push(ldi);
        v.nearest = 0;
        v
    };
    // The home view as a mesh (the third reconstruction), drawn by the rasterizer.
    let (mesh, material) = {
        let image = &capture(renderer, frame, target, 1)[0];
        let (mut mesh, mut index) = (engine::Mesh::default(), Vec::new());
        depth_mesh(image, 0.05, &mut mesh, &mut index);
        (mesh, depth_mesh_material())
    };
    References {
        views,
        ldi,
        mesh,
        material,
    }
}

/// Runs the sweep at these settings; `progress(step, total, what)` before each point.
pub fn run(settings: &Settings, progress: &mut dyn FnMut(usize, usize, &str)) -> Vec<Row> {
    let city = City::with_triangles(4, settings.triangles, 7);
    let (_, at) = home(&city);
    let mut renderer = Renderer::new();
    let mut frame = FrameLoop::new();
    let mut target = Target::new(settings.size.0, settings.size.1);
    let moves: Vec<(&'static str, f32)> = settings
        .distances
        .iter()
        .map(|&d| ("distance", d))
        .chain(settings.angles.iter().map(|&a| ("angle", a)))
        .collect();
    let per_move = 3 + settings.references.len() * METHODS.len();
    let mut tick = ticker(moves.len() * per_move + 1, progress);
    let mut rows = Vec::new();
    let References {
        mut views,
        ldi: mut ldi_view,
        mesh: home_mesh,
        material: mesh_material,
    } = references(&city, at, settings, &mut renderer, &mut frame, &mut target);
    let (w, h) = settings.size;
    let mut truth = Target::new(w, h);
    for &(series, value) in &moves {
        let cam = camera(target_eye(&city, series, value), at, settings.size, &city);
        tick(format!("{series} {value} geometry"));
        let times = settings.frames.run(|| {
            let t = Instant::now();
            geometry(&mut renderer, &mut frame, &city, &cam, &mut truth);
            t.elapsed()
        });
        rows.push(Row {
            series,
            value,
            psnr_seen: f64::INFINITY,
            ..Row::timed("geometry", settings.size, &city, &times)
        });
        for (n, view) in views.iter_mut() {
            for (method, rec, composite, fill) in METHODS {
                if *n == 1 && composite == Composite::Priority {
                    continue;
                }
                tick(format!("{series} {value} {n} refs {method}"));
                view.options.reconstruction = rec;
                view.options.composite = composite;
                view.options.visibility = Visibility::Ordered;
                let row = measure(
                    view,
                    fill,
                    &cam,
                    &city,
                    &truth,
                    &mut frame,
                    &mut renderer,
                    &mut target,
                    settings,
                );
                rows.push(Row {
                    series,
                    value,
                    method,
                    references: *n,
                    ..row
                });
            }
        }
        tick(format!("{series} {value} mesh"));
        rows.push(Row {
            series,
            value,
            ..mesh_point(
                &home_mesh,
                &mesh_material,
                &cam,
                &city,
                &truth,
                &mut frame,
                &mut renderer,
                &mut target,
                settings,
            )
        });
        tick(format!("{series} {value} ldi"));
        ldi_view.options.reconstruction = Reconstruction::Splats;
        let row = measure(
            &mut ldi_view,
            Fill::PullPush,
            &cam,
            &city,
            &truth,
            &mut frame,
            &mut renderer,
            &mut target,
            settings,
        );
        rows.push(Row {
            series,
            value,
            method: "ldi",
            references: 5,
            ..row
        });
    }
    tick("speed".into());
    rows.extend(speed(settings, &city, &mut renderer, &mut frame));
    rows
}

/// One warp point, holes filled by `fill`: counted and compared once (untimed), then timed
/// without the hole count.
fn measure(
    view: &mut WarpedView,
    fill: Fill,
    cam: &Camera,
    city: &City,
    truth: &Target,
    frame: &mut FrameLoop,
    renderer: &mut Renderer,
    target: &mut Target,
    settings: &Settings,
) -> Row {
    let (w, h) = settings.size;
    let frame_view = still_view(cam, city, (w, h));
    // Counted: the holes before filling, and the pixels the references saw.
    view.fill = Fill::None;
    view.count_holes = true;
    let counted = view.warp_to(cam, w, h);
    let seen: Vec<bool> = view.image().disparity.iter().map(|d| *d >= 0.0).collect();
    view.fill = fill;
    view.count_holes = false;
    let mut list: [&mut dyn Technique; 1] = [view];
    let times = settings.frames.run(|| {
        let t = Instant::now();
        frame.render(renderer, [], &mut list, &frame_view, target, &clear());
        t.elapsed()
    });
    let error = metrics::compare(target, truth, &Options::default()).ok();
    let seen_err = metrics::compare(
        target,
        truth,
        &Options {
            region: Region::Mask(&seen),
            ..Options::default()
        },
    )
    .ok();
    let pixels = (w as u64 * h as u64).max(1);
    Row {
        error,
        psnr_seen: seen_err.map_or(f64::NAN, |e| e.psnr_db),
        holes: counted.holes.total() as f64 / pixels as f64,
        cracks: counted.holes.cracks,
        disocclusions: counted.holes.disocclusions,
        samples: counted.stats.samples,
        predicted_px: counted.predicted_px,
        ..Row::timed("", settings.size, city, &times)
    }
}

/// The home view's depth mesh drawn from `cam` (no holes are filled: where the mesh
/// broke, the sky shows), timed and compared like a warp.
fn mesh_point(
    mesh: &engine::Mesh,
    material: &engine::Material,
    cam: &Camera,
    city: &City,
    truth: &Target,
    frame: &mut FrameLoop,
    renderer: &mut Renderer,
    target: &mut Target,
    settings: &Settings,
) -> Row {
    let (w, h) = settings.size;
    let view = still_view(cam, city, (w, h));
    let draw = Draw {
        mesh,
        material,
        transform: Mat4::IDENTITY,
    };
    let times = settings.frames.run(|| {
        let t = Instant::now();
        frame.render(renderer, [draw], &mut [], &view, target, &clear());
        t.elapsed()
    });
    Row {
        references: 1,
        error: metrics::compare(target, truth, &Options::default()).ok(),
        samples: mesh.positions.len() as u64,
        ..Row::timed("mesh", (w, h), city, &times)
    }
}

/// One reference warped with splats at the speed size, holes filled by pull-push
/// (`splats`) and from the background side (`splats-background`), each timed as the warp
/// alone (no geometry in the frame, no hole count).
fn speed(
    settings: &Settings,
    city: &City,
    renderer: &mut Renderer,
    frame: &mut FrameLoop,
) -> Vec<Row> {
    let (w, h) = settings.speed_size;
    let (reference, moved) = city_reference(city, renderer, frame, (w, h));
    let mut view = WarpedView::new("speed", vec![reference]);
    view.nearest = 1;
    view.count_holes = false;
    [
        ("splats", Fill::PullPush),
        ("splats-background", Fill::Background),
    ]
    .into_iter()
    .map(|(method, fill)| {
        view.fill = fill;
        let times = settings.frames.run(|| {
            let t = Instant::now();
            view.warp_to(&moved, w, h);
            t.elapsed()
        });
        Row {
            series: "speed",
            value: 0.05,
            references: 1,
            samples: view.last().stats.samples,
            predicted_px: view.last().predicted_px,
            ..Row::timed(method, (w, h), city, &times)
        }
    })
    .collect()
}

/// The `speed` series' frame: the city seen from the home eye at `w` x `h` as a depth
/// image, and the home eye moved 0.05 of the city's half width sideways.
pub fn city_reference(
    city: &City,
    renderer: &mut Renderer,
    frame: &mut FrameLoop,
    (w, h): (u32, u32),
) -> (DepthImage, Camera) {
    let (eye, at) = home(city);
    let mut target = Target::new(w, h);
    let cam = camera(eye, at, (w, h), city);
    geometry(renderer, frame, city, &cam, &mut target);
    let moved = camera(target_eye(city, "distance", 0.05), at, (w, h), city);
    (DepthImage::from_target(&target, &cam), moved)
}

/// The criterion warp bench's frame (`benches/warp.rs`, `examples/warp_phases.rs`): the
/// showcase's first tour view rendered at `width` x `height` as a depth image, and its
/// camera moved `sideways` to the left.
pub fn showcase_reference(width: u32, height: u32, sideways: f32) -> (DepthImage, Camera) {
    let show = Showcase::new();
    let (eye, target) = show.path(0, 60);
    let camera = showcase::camera(eye, target, width, height);
    let mut frame = Target::new(width, height);
    let opts = FrameOptions {
        clear: Some(Rgba::new(0.55, 0.65, 0.8, 1.0)),
        ..Default::default()
    };
    Renderer::new().render_scene(&show.scene, &camera, &mut frame, &opts);
    let reference = DepthImage::from_target(&frame, &camera);
    let mut moved = camera;
    moved.view *= Mat4::from_translation(Vec3::new(-sideways, 0.0, 0.0));
    (reference, moved)
}
