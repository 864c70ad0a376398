//! The sweep's frames, each through the [`FrameLoop`]: the camera at a pose, one geometry
//! frame, one impostor frame, and the untimed impostor warm-up.

use super::Settings;
use crate::city::{City, Path};
use engine::{Camera, Draw, FrameOptions, FrameStats, Lighting, Renderer, Rgba, Target};
use ibr::impostor::{Budget, Config, Impostored, Report};
use ibr::subject::{MeshGroup, Subject};
use ibr::technique::{FrameLoop, FrameView, Technique};

/// The sweep's camera at `t` along `path` for a `width` x `height` image.
pub fn camera(city: &City, path: Path, t: f32, (width, height): (u32, u32)) -> Camera {
    let (eye, target) = city.path(path, t);
    Camera::look_at(eye, target, glam::Vec3::Y, 50f32.to_radians(), 1.0)
        .with_aspect(width, height)
        .with_depth_range(0.5, city.half_extent * 8.0)
}

/// The frame's clear colour: a pale sky.
fn clear() -> FrameOptions {
    FrameOptions {
        clear: Some(Rgba::new(0.55, 0.65, 0.8, 1.0)),
        ..Default::default()
    }
}

/// The frame's view of `camera` for `target` (a static scene: no time).
fn view<'a>(camera: &'a Camera, lighting: &'a Lighting, target: &Target) -> FrameView<'a> {
    FrameView {
        camera,
        width: target.width(),
        height: target.height(),
        lighting,
        time: 0.0,
        dt: 0.0,
    }
}

/// One geometry frame: the ground and every building's meshes as the scene, no technique.
pub fn geometry_frame(
    renderer: &mut Renderer,
    frame_loop: &mut FrameLoop,
    city: &City,
    camera: &Camera,
    target: &mut Target,
) -> FrameStats {
    let mut draws: Vec<Draw> = Vec::with_capacity(city.buildings.len() + 1);
    city.ground.draws(&mut draws);
    for b in &city.buildings {
        b.draws(&mut draws);
    }
    let view = view(camera, &city.lighting, target);
    frame_loop.render(renderer, draws, &mut [], &view, target, &clear())
}

/// One impostor frame: the ground as the scene and the buildings behind `impostors`
/// (updated for `camera`, then drawn). Returns the update's report and the counters; the
/// loop's [`FrameLoop::times`] has the frame's and the update's durations.
pub fn impostor_frame(
    renderer: &mut Renderer,
    frame_loop: &mut FrameLoop,
    city: &City,
    impostors: &mut Impostored<MeshGroup>,
    camera: &Camera,
    target: &mut Target,
) -> (Report, FrameStats) {
    let mut ground: Vec<Draw> = Vec::with_capacity(1);
    city.ground.draws(&mut ground);
    let view = view(camera, &city.lighting, target);
    let stats = frame_loop.render(renderer, ground, &mut [impostors], &view, target, &clear());
    (impostors.report, stats)
}

/// The city's buildings behind a fresh impostor set configured by `config`, with every
/// impostor that needs it captured for `camera` (unlimited budget, untimed).
pub fn warm_up(
    city: &City,
    config: Config,
    camera: &Camera,
    target: &Target,
) -> Impostored<MeshGroup> {
    let mut impostors = Impostored::new("impostors", config, city.buildings.clone());
    impostors.set.config.budget = Budget {
        refreshes: usize::MAX,
        time: None,
    };
    impostors.prepare(&view(camera, &city.lighting, target));
    impostors.set.config.budget = config.budget;
    impostors
}

/// The path parameter of pose `i`.
pub fn pose(settings: &Settings, i: usize) -> f32 {
    settings.path_start + settings.path_step * i as f32
}
