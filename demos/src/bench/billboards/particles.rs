//! The timed frame of every timing series ([`measure`]), and the blended glow particles of
//! the `count` and `resolution` series.

use super::{Settings, Times};
use crate::timing::Summary;
use engine::procedural::XorShift;
use engine::{
    BlendMode, Camera, Draw, FrameOptions, FrameStats, Lighting, Material, Renderer, Rgba, Target,
};
use glam::{Vec2, Vec3};
use ibr::sprites;
use ibr::technique::{FrameLoop, FrameView, Technique};
use ibr::{Billboard, BillboardBatch, Facing};
use std::sync::Arc;
use std::time::Duration;

/// Times frames of `fixed` draws plus `techniques` (billboard batches, the nailboard
/// forest) rebuilt every frame for `camera` by the [`FrameLoop`] (`build` is their
/// `prepare`).
pub(super) fn measure(
    renderer: &mut Renderer,
    target: &mut Target,
    camera: &Camera,
    lighting: &Lighting,
    fixed: &[Draw],
    techniques: &mut [&mut dyn Technique],
    settings: &Settings,
) -> (Times, FrameStats) {
    let opts = FrameOptions {
        clear: Some(Rgba::new(0.05, 0.06, 0.09, 1.0)),
        ..Default::default()
    };
    let mut frame_loop = FrameLoop::new();
    let frames = settings.timing.run(|| {
        let view = FrameView {
            camera,
            width: target.width(),
            height: target.height(),
            lighting,
            time: 0.0,
            dt: 0.0,
        };
        let draws = fixed.iter().copied();
        let stats = frame_loop.render(renderer, draws, techniques, &view, target, &opts);
        let t = frame_loop.times;
        (t.prepare, t.total.saturating_sub(t.prepare), stats)
    });
    let summary = |part: fn(&(Duration, Duration, FrameStats)) -> Duration| {
        Summary::of(&frames.iter().map(part).collect::<Vec<_>>())
    };
    let times = Times {
        build: summary(|f| f.0),
        render: summary(|f| f.1),
        total: summary(|f| f.0 + f.1),
    };
    (
        times,
        frames.last().map_or_else(FrameStats::default, |f| f.2),
    )
}

/// The particle camera: at the origin looking down -Z, 60 degrees, 0.5 - 100.
pub fn particle_camera(width: u32, height: u32) -> Camera {
    Camera::look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 60f32.to_radians(), 1.0)
        .with_aspect(width, height)
        .with_depth_range(0.5, 100.0)
}

/// `n` glow particles (screen-facing, alpha-blended, warm random tints) in the box
/// x in [-12, 12], y in [-7, 7], z in [-30, -10].
pub fn particles(n: usize, seed: u64) -> BillboardBatch {
    let material = Material::unlit(Rgba::WHITE)
        .with_texture(Arc::new(sprites::glow(64)))
        .blended(BlendMode::Alpha);
    let mut batch = BillboardBatch::new(material);
    let mut rng = XorShift::new(seed);
    batch.items.reserve(n);
    for _ in 0..n {
        let p = Vec3::new(
            rng.range(-12.0, 12.0),
            rng.range(-7.0, 7.0),
            rng.range(-30.0, -10.0),
        );
        let mut b = Billboard::new(p, Facing::Screen, Vec2::splat(0.15));
        b.rotation = rng.range(0.0, std::f32::consts::TAU);
        b.tint = Rgba::new(1.0, rng.range(0.4, 0.9), rng.range(0.1, 0.4), 0.8);
        batch.push(b);
    }
    batch
}
