//! What every series shares: the frame camera and clear, measuring an image against its
//! geometry, and flying a path with runtime impostors or with geometry alone.

use super::Settings;
use crate::city::{City, Path as CityPath};
use engine::{Camera, Draw, FrameOptions, Lighting, Renderer, Rgba, Sphere, Target};
use ibr::impostor::{self, Budget, Config, Impostored, Mode, Predicted, Shape, Tolerance};
use ibr::metrics::{self, ImageError, Options, Region};
use ibr::subject::Subject;
use ibr::technique::{FrameLoop, FrameView};
use std::time::Duration;

/// The path's name in rows.
pub fn path_name(p: CityPath) -> &'static str {
    match p {
        CityPath::Translate => "translate",
        CityPath::Rotate => "rotate",
        CityPath::Orbit => "orbit",
    }
}

/// The camera of frame `f` of `frames` along the first `span` of `path`.
pub fn frame_camera(
    city: &City,
    path: CityPath,
    span: f32,
    f: usize,
    frames: usize,
    size: (u32, u32),
) -> Camera {
    let t = span * f as f32 / (frames.max(2) - 1) as f32;
    let (eye, target) = city.path(path, t);
    Camera::look_at(eye, target, glam::Vec3::Y, 60f32.to_radians(), 1.0)
        .with_aspect(size.0, size.1)
        .with_depth_range(0.5, city.half_extent * 12.0)
}

/// The frame's clear: an opaque sky.
pub(super) fn frame_options() -> FrameOptions {
    FrameOptions {
        clear: Some(Rgba::new(0.55, 0.65, 0.8, 1.0)),
        ..Default::default()
    }
}

/// The error of `image` against `truth`, measured exactly as [`impostor::ImpostorSet::measure`]
/// measures an impostor: each rendered alone over a transparent clear into a `width` x
/// `height` target from `camera`, compared over the screen rectangle of the sphere
/// `bounds` ([`impostor::screen_rect`]). `None` when the sphere is off the image.
pub fn measure_draws<'a>(
    renderer: &mut Renderer,
    truth: impl IntoIterator<Item = Draw<'a>>,
    image: impl IntoIterator<Item = Draw<'a>>,
    camera: &Camera,
    (width, height): (u32, u32),
    lighting: &Lighting,
    bounds: Sphere,
) -> Option<ImageError> {
    let clear = FrameOptions {
        clear: Some(Rgba::new(0.0, 0.0, 0.0, 0.0)),
        ..Default::default()
    };
    let mut t = Target::new(width, height);
    renderer.render(truth, camera, lighting, &mut t, &clear);
    let mut i = Target::new(width, height);
    renderer.render(image, camera, lighting, &mut i, &clear);
    let rect = impostor::screen_rect(camera, bounds.center, bounds.radius, width, height)?;
    let opts = Options {
        region: Region::Rect(rect),
        ..Options::default()
    };
    metrics::compare(&t, &i, &opts).ok()
}

/// How a run decides refreshes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Policy {
    /// The set's own error-driven schedule at a tolerance (degrees), unlimited budget.
    Error(f32),
    /// Infinite tolerances; a round-robin bumps `rate` buildings' versions per frame.
    Fixed { rate: f64 },
    /// Error-driven warm-up, then a budget of 0 (calibration).
    Frozen,
}

/// The set's configuration for a tolerance (degrees; infinite: never refresh on its
/// own) with an unlimited budget. Stale images are shown however stale (no fallback to
/// geometry, no pre-warming): the sweep measures the images' own error as they age.
pub(super) fn config(degrees: f32, octaves: f32) -> Config {
    Config {
        fallback_ratio: f32::INFINITY,
        prewarm: 0.0,
        tolerance: Tolerance {
            degrees,
            pixels: None,
            levels: None,
            octaves,
        },
        budget: Budget {
            refreshes: usize::MAX,
            time: None,
        },
        ..Config::default()
    }
}

/// What one run of impostors along a path measured.
pub(super) struct RunOut {
    pub(super) times: Vec<Duration>,
    pub(super) update: Vec<Duration>,
    /// Per frame after warm-up: every measured image and its prediction.
    pub(super) measured: Vec<Vec<(usize, Predicted, ImageError)>>,
    /// Per frame after warm-up: the prediction of every drawn image.
    pub(super) predicted: Vec<Predicted>,
    pub(super) refreshes: u64,
    pub(super) new_captures: u64,
    pub(super) capture_px: u64,
    pub(super) memory: u64,
    pub(super) triangles: u64,
}

/// Flies the settings' run of runtime impostors along `path` (see [`run_impostors`]).
pub(super) fn fly(settings: &Settings, city: &City, path: CityPath, policy: Policy) -> RunOut {
    fly_shape(settings, city, path, policy, Shape::Quad)
}

/// As [`fly`], the images drawn on `shape` ([`Shape`]): a relief or a box as cutouts at
/// [`SHAPE_CUTOUT`] (as the showcase's city draws them), a quad blended.
pub(super) fn fly_shape(
    settings: &Settings,
    city: &City,
    path: CityPath,
    policy: Policy,
    shape: Shape,
) -> RunOut {
    run_impostors(
        city,
        path,
        settings.span(path),
        settings.frames,
        settings.size,
        (policy, shape),
    )
}

/// The coverage from which a relief's or a box's pixel is drawn (opaque), as the
/// showcase's city.
pub(super) const SHAPE_CUTOUT: f32 = 0.5;

/// The frame's view of `camera` for a `size` image (a static scene: no time).
pub(super) fn frame_view<'a>(
    camera: &'a Camera,
    lighting: &'a Lighting,
    size: (u32, u32),
) -> FrameView<'a> {
    FrameView {
        camera,
        width: size.0,
        height: size.1,
        lighting,
        time: 0.0,
        dt: 0.0,
    }
}

/// Flies `frames` frames of runtime impostors along the first `span` of `path`, their
/// images drawn on `shape`: the ground as scene geometry and the buildings behind one
/// [`Impostored`] technique, through the [`FrameLoop`].
pub(super) fn run_impostors(
    city: &City,
    path: CityPath,
    span: f32,
    frames: usize,
    size: (u32, u32),
    (policy, shape): (Policy, Shape),
) -> RunOut {
    let n = city.buildings.len();
    let cfg = match policy {
        Policy::Error(deg) => config(deg, 1.0),
        Policy::Fixed { .. } => config(f32::INFINITY, f32::INFINITY),
        Policy::Frozen => config(Tolerance::default().degrees, 1.0),
    };
    // The subjects are shared meshes, so the copy is cheap; versions bumped here stay here.
    let mut imp = Impostored::new("runtime impostors", cfg, city.buildings.clone());
    imp.set.shape = shape;
    if shape != Shape::Quad {
        imp.set.cutout = Some(SHAPE_CUTOUT);
    }
    let mut ground = Vec::new();
    city.ground.draws(&mut ground);
    let (mut renderer, mut frame_loop) = (Renderer::new(), FrameLoop::new());
    let mut target = Target::new(size.0, size.1);
    let opts = frame_options();
    let lighting = &city.lighting;
    let mut out = RunOut {
        times: Vec::new(),
        update: Vec::new(),
        measured: Vec::new(),
        predicted: Vec::new(),
        refreshes: 0,
        new_captures: 0,
        capture_px: 0,
        memory: 0,
        triangles: 0,
    };
    let (mut credit, mut next) = (0.0f64, 0usize);
    for f in 0..frames {
        let camera = frame_camera(city, path, span, f, frames, size);
        match policy {
            Policy::Fixed { rate } if f > 0 => {
                credit += rate;
                while credit >= 1.0 - 1e-9 && n > 0 {
                    imp.subjects[next].version += 1;
                    next = (next + 1) % n;
                    credit -= 1.0;
                }
            }
            Policy::Frozen if f == 1 => imp.set.config.budget.refreshes = 0,
            _ => {}
        }
        let had: Vec<(bool, u64)> = imp
            .set
            .impostors
            .iter()
            .map(|i| (i.capture().is_some(), i.refreshes))
            .collect();
        let view = frame_view(&camera, lighting, size);
        let stats = frame_loop.render(
            &mut renderer,
            ground.iter().copied(),
            &mut [&mut imp],
            &view,
            &mut target,
            &opts,
        );
        if f == 0 {
            continue;
        }
        out.times.push(frame_loop.times.total);
        out.update.push(frame_loop.times.prepare);
        out.refreshes += imp.report.refreshes as u64;
        let set = &mut imp.set;
        out.new_captures += set
            .impostors
            .iter()
            .zip(&had)
            .filter(|(i, h)| !h.0 && i.capture().is_some())
            .count() as u64;
        out.capture_px += set
            .impostors
            .iter()
            .zip(&had)
            .filter(|(i, h)| i.refreshes > h.1)
            .filter_map(|(i, _)| i.capture().map(|c| (c.side as u64).pow(2)))
            .sum::<u64>();
        out.triangles = stats.triangles_set_up;
        let mut frame = Vec::new();
        for i in 0..n {
            if set.impostors[i].mode != Mode::Image {
                continue;
            }
            let p = set.impostors[i].predicted;
            out.predicted.push(p);
            if let Some(e) = set.measure(i, &mut imp.subjects[i], &camera, size, lighting) {
                frame.push((i, p, e));
            }
        }
        out.measured.push(frame);
    }
    out.memory = imp.set.pool().bytes() as u64;
    out
}

/// Flies `frames` frames with every building drawn as geometry (the scene alone through
/// the [`FrameLoop`]): frame times (warm-up excluded) and the last frame's triangles.
pub(super) fn run_geometry(
    city: &City,
    path: CityPath,
    span: f32,
    frames: usize,
    size: (u32, u32),
) -> (Vec<Duration>, u64) {
    let (mut renderer, mut frame_loop) = (Renderer::new(), FrameLoop::new());
    let mut target = Target::new(size.0, size.1);
    let opts = frame_options();
    let mut scene = Vec::new();
    city.ground.draws(&mut scene);
    for b in &city.buildings {
        b.draws(&mut scene);
    }
    let mut times = Vec::new();
    let mut triangles = 0;
    for f in 0..frames {
        let camera = frame_camera(city, path, span, f, frames, size);
        let view = frame_view(&camera, &city.lighting, size);
        let stats = frame_loop.render(
            &mut renderer,
            scene.iter().copied(),
            &mut [],
            &view,
            &mut target,
            &opts,
        );
        if f > 0 {
            times.push(frame_loop.times.total);
            triangles = stats.triangles_set_up;
        }
    }
    (times, triangles)
}

#[cfg(test)]
mod tests {
    use super::*;
    use ibr::impostor::ImpostorSet;

    #[test]
    fn measure_draws_agrees_with_impostor_set_measure() {
        let mut city = City::new(2, 2, 3);
        let size = (128, 72);
        let lighting = city.lighting.clone();
        let cam0 = frame_camera(&city, CityPath::Translate, 1.0, 0, 5, size);
        let cam = frame_camera(&city, CityPath::Translate, 1.0, 2, 5, size);
        let mut renderer = Renderer::new();
        let mut checked = 0;
        for i in 0..city.buildings.len() {
            // A set of one, so its draws are this image's quad alone.
            let one = &mut city.buildings[i..i + 1];
            let mut set = ImpostorSet::new(config(0.125, 1.0), 1);
            set.update(one, &cam0, size.1, &lighting);
            set.config.budget.refreshes = 0;
            set.update(one, &cam, size.1, &lighting);
            let Some(a) = set.measure(0, &mut one[0], &cam, size, &lighting) else {
                continue;
            };
            let mut image = Vec::new();
            set.draws(one, &mut image);
            let mut truth = Vec::new();
            one[0].draws(&mut truth);
            let b = measure_draws(
                &mut renderer,
                truth,
                image,
                &cam,
                size,
                &lighting,
                one[0].bounds(),
            )
            .expect("on screen");
            assert_eq!(a, b);
            assert!(a.mean_abs > 0.0, "the eye moved: {a:?}");
            checked += 1;
        }
        assert!(checked >= 2);
    }
}
