//! The sweep's frames: the camera at a pose, one geometry frame, one impostor frame, and
//! the untimed impostor warm-up.

use super::Plan;
use crate::city::{City, Path};
use engine::{Camera, Draw, FrameOptions, FrameStats, Renderer, Rgba, Target};
use ibr::impostor::ImpostorSet;
use ibr::subject::Subject;
use std::time::{Duration, Instant};

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

/// One geometry frame: the ground and every building's meshes.
pub fn geometry_frame(
    renderer: &mut Renderer,
    city: &City,
    camera: &Camera,
    target: &mut Target,
) -> FrameStats {
    let mut draws: Vec<Draw> = Vec::with_capacity(city.buildings.len() + 1);
    city.ground.draws(&mut draws);
    for b in &city.buildings {
        b.draws(&mut draws);
    }
    renderer.render(draws, camera, &city.lighting, target, &clear())
}

/// One impostor frame: update the impostors for `camera`, then render the ground and
/// their draws. Returns the update's report, the counters and the update's duration.
pub fn impostor_frame(
    renderer: &mut Renderer,
    city: &mut City,
    set: &mut ImpostorSet,
    camera: &Camera,
    target: &mut Target,
) -> (ibr::impostor::Report, FrameStats, Duration) {
    let t0 = Instant::now();
    let report = set.update(&mut city.buildings, camera, target.height(), &city.lighting);
    let update = t0.elapsed();
    let mut draws: Vec<Draw> = Vec::with_capacity(city.buildings.len() + 1);
    city.ground.draws(&mut draws);
    set.draws(&city.buildings, &mut draws);
    let stats = renderer.render(draws, camera, &city.lighting, target, &clear());
    (report, stats, update)
}

/// Captures every impostor that needs it for `camera` (unlimited budget, untimed).
pub fn warm_up(city: &mut City, set: &mut ImpostorSet, camera: &Camera, height: u32) {
    let budget = set.config.budget;
    set.config.budget.refreshes = usize::MAX;
    set.config.budget.time = None;
    set.update(&mut city.buildings, camera, height, &city.lighting);
    set.config.budget = budget;
}

/// The path parameter of pose `i`.
pub fn pose(plan: &Plan, i: usize) -> f32 {
    plan.path_start + plan.path_step * i as f32
}
