use super::*;
use crate::core::{BillboardBatch, UvRect, View};
use engine::{Camera, FrameOptions, Lighting, Renderer, Target};
use engine::{Material, Rgba};
use glam::{Vec2, Vec3};

fn sheet(looping: bool) -> SpriteSheet {
    SpriteSheet {
        cols: 4,
        rows: 2,
        frames: 6,
        fps: 10.0,
        looping,
    }
}

#[test]
fn sheet_regions_follow_age_row_major() {
    let s = sheet(false);
    for frame in 0..6u32 {
        // The middle of each frame's display time.
        let age = (frame as f32 + 0.5) / 10.0;
        assert_eq!(s.frame(age), frame);
        let r = s.region(age);
        let (col, row) = ((frame % 4) as f32, (frame / 4) as f32);
        assert_eq!(r.min, Vec2::new(col * 0.25, row * 0.5));
        assert_eq!(r.max, Vec2::new((col + 1.0) * 0.25, (row + 1.0) * 0.5));
    }
}

#[test]
fn sheet_clamps_or_wraps_past_the_end() {
    let (hold, wrap) = (sheet(false), sheet(true));
    for age in [0.65, 1.0, 7.3, 1e9, f32::INFINITY] {
        assert_eq!(hold.frame(age), 5, "age {age}");
    }
    assert_eq!(wrap.frame(0.65), 0);
    assert_eq!(wrap.frame(0.75), 1);
    assert_eq!(wrap.frame(1.25), 0);
    assert!(wrap.frame(1e9) < 6);
    assert_eq!(wrap.frame(f32::INFINITY), 0);
    for s in [hold, wrap] {
        assert_eq!(s.frame(-1.0), 0);
        assert_eq!(s.frame(f32::NAN), 0);
    }
    let odd = SpriteSheet {
        cols: 0,
        rows: u32::MAX,
        frames: 0,
        fps: f32::NAN,
        looping: true,
    };
    assert_eq!(odd.frame(3.0), 0);
    assert!(odd.region(3.0).min.is_finite());
}

#[test]
fn sheet_cells_tile_the_texture_exactly() {
    let s = SpriteSheet {
        frames: 8,
        ..sheet(false)
    };
    let mut area = 0.0;
    let mut cells: Vec<UvRect> = Vec::new();
    for f in 0..8 {
        let r = s.region((f as f32 + 0.5) / s.fps);
        assert!(r.min.cmpge(Vec2::ZERO).all() && r.max.cmple(Vec2::ONE).all());
        area += (r.max - r.min).x * (r.max - r.min).y;
        for c in &cells {
            let overlap = (r.max.min(c.max) - r.min.max(c.min)).max(Vec2::ZERO);
            assert_eq!(overlap.x * overlap.y, 0.0);
        }
        cells.push(r);
    }
    assert!((area - 1.0).abs() < 1e-6, "{area}");
    // Shared edges are the same floats, so neighbours meet without gaps.
    assert_eq!(cells[0].max.x, cells[1].min.x);
    assert_eq!(cells[0].max.y, cells[4].min.y);
    assert_eq!(cells[3].max.x, 1.0);
    assert_eq!(cells[7].max, Vec2::ONE);
}

fn fountain() -> EmitterConfig {
    EmitterConfig {
        rate: 50.0,
        burst: 5,
        lifetime: (0.5, 1.5),
        speed: (1.0, 3.0),
        spread: 0.6,
        spawn_radius: 0.2,
        acceleration: Vec3::new(0.0, -9.8, 0.0),
        drag: 0.5,
        spin: (-2.0, 2.0),
        ..Default::default()
    }
}

fn run(seed: u64, steps: &[f32]) -> Vec<Particle> {
    let mut e = Emitter::new(fountain(), Vec3::new(1.0, 2.0, 3.0), seed);
    for &dt in steps {
        e.update(dt);
    }
    e.particles
}

#[test]
fn emitters_are_deterministic_per_seed() {
    let steps: Vec<f32> = (0..120)
        .map(|i| [1.0 / 60.0, 1.0 / 30.0, 0.007][i % 3])
        .collect();
    let a = run(42, &steps);
    assert!(a.len() > 20, "{}", a.len());
    assert_eq!(a, run(42, &steps));
    assert_ne!(a, run(43, &steps));
}

#[test]
fn rate_spawns_about_rate_times_time() {
    for (rate, dt) in [(30.0, 1.0 / 60.0), (7.0, 0.001), (100.0, 0.013)] {
        let mut e = Emitter::new(
            EmitterConfig {
                rate,
                lifetime: (10.0, 10.0),
                ..Default::default()
            },
            Vec3::ZERO,
            1,
        );
        let mut t = 0.0;
        let steps = (2.0 / dt) as usize;
        for _ in 0..steps {
            e.update(dt);
            t += dt;
        }
        let n = e.particles.len() as f32;
        assert!((n - rate * t).abs() <= 1.0, "rate {rate}: {n} in {t} s");
    }
}

#[test]
fn particles_die_after_their_lifetime() {
    let mut e = Emitter::new(
        EmitterConfig {
            rate: 0.0,
            burst: 50,
            lifetime: (0.5, 1.0),
            ..Default::default()
        },
        Vec3::ZERO,
        3,
    );
    assert_eq!(e.particles.len(), 50);
    let mut t = 0.0;
    while t < 0.45 {
        e.update(0.01);
        t += 0.01;
    }
    assert_eq!(e.particles.len(), 50);
    while t < 1.01 {
        e.update(0.01);
        t += 0.01;
        assert!(e.particles.iter().all(|p| p.age < p.lifetime));
    }
    assert!(e.particles.is_empty());
    assert!(e.is_finished());
}

#[test]
fn max_particles_caps_the_count() {
    let config = EmitterConfig {
        rate: 1e6,
        burst: u32::MAX,
        lifetime: (100.0, 100.0),
        max_particles: 300,
        ..Default::default()
    };
    let mut e = Emitter::new(config, Vec3::ZERO, 9);
    assert_eq!(e.particles.len(), 300);
    for _ in 0..10 {
        e.update(0.1);
        e.burst(1000);
    }
    assert_eq!(e.particles.len(), 300);
    let huge = EmitterConfig {
        max_particles: u32::MAX,
        ..config
    };
    let mut e = Emitter::new(huge, Vec3::ZERO, 9);
    e.update(1.0);
    assert_eq!(e.particles.len(), MAX_PARTICLES as usize);
}

#[test]
fn odd_steps_are_harmless() {
    let mut e = Emitter::new(fountain(), Vec3::ZERO, 5);
    let before = e.particles.clone();
    for dt in [0.0, -1.0, f32::NAN, -f32::INFINITY] {
        e.update(dt);
    }
    assert_eq!(e.particles, before, "ignored steps change nothing");
    for dt in [
        f32::INFINITY,
        1e30,
        f32::MAX,
        0.016,
        1e-30,
        f32::MIN_POSITIVE,
    ] {
        e.update(dt);
        assert!(e.particles.len() <= 1024);
        for p in &e.particles {
            assert!(p.position.is_finite() && p.velocity.is_finite(), "{p:?}");
            assert!(p.rotation.is_finite() && p.age.is_finite());
        }
    }
    // Odd configurations: NaN everywhere, zero rate, zero lifetime.
    let nan = EmitterConfig {
        rate: f32::NAN,
        burst: 10,
        lifetime: (f32::NAN, 1.0),
        speed: (f32::INFINITY, f32::NAN),
        direction: Vec3::ZERO,
        spread: f32::NAN,
        spawn_radius: f32::NAN,
        acceleration: Vec3::splat(f32::NAN),
        drag: f32::NAN,
        size: (f32::NAN, 1.0),
        spin: (f32::NEG_INFINITY, 0.0),
        ..Default::default()
    };
    let mut e = Emitter::new(nan, Vec3::ZERO, 0);
    let mut batch = BillboardBatch::new(Material::unlit(Rgba::WHITE));
    for _ in 0..10 {
        e.update(0.016);
        e.emit(&mut batch);
    }
    assert!(e.particles.iter().all(|p| p.position.is_finite()));
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 1.0, 1.0);
    batch.build(&View::new(&camera, 32));
    assert!(batch.mesh().positions.iter().all(|p| p.is_finite()));
    let zero = EmitterConfig {
        rate: 0.0,
        lifetime: (0.0, 0.0),
        burst: 10,
        ..Default::default()
    };
    let mut e = Emitter::new(zero, Vec3::ZERO, 0);
    e.update(0.1);
    assert!(e.particles.is_empty() && e.is_finished());
}

fn camera() -> Camera {
    Camera::look_at(
        Vec3::new(0.0, 1.0, 12.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::Y,
        0.9,
        1.0,
    )
}

#[test]
fn steady_state_does_not_allocate() {
    let mut fx = Effects::new(1);
    fx.add_smoke(Vec3::ZERO);
    fx.add_sparks(Vec3::new(2.0, 0.0, 0.0));
    let view = View::new(&camera(), 64);
    let capacities = |fx: &Effects| {
        let mut caps = Vec::new();
        for (_, e) in fx.iter() {
            caps.extend(e.emitters.iter().map(|(_, e)| e.particles.capacity()));
        }
        for b in &fx.batches {
            let m = b.mesh();
            caps.extend([
                b.items.capacity(),
                m.positions.capacity(),
                m.uvs.capacity(),
                m.colors.capacity(),
                m.indices.capacity(),
            ]);
        }
        caps
    };
    for _ in 0..1200 {
        fx.update(1.0 / 60.0);
        fx.build(&view);
    }
    let warm = capacities(&fx);
    for _ in 0..1200 {
        fx.update(1.0 / 60.0);
        assert!(fx.build(&view) > 0);
        assert_eq!(capacities(&fx), warm);
    }
    assert_eq!(fx.len(), 2);
}

#[test]
fn finished_effects_are_dropped_and_stop_works() {
    let mut fx = Effects::new(2);
    let boom = fx.spawn_explosion(Vec3::ZERO);
    let smoke = fx.add_smoke(Vec3::ONE);
    assert!(fx.particle_count() > 40);
    for _ in 0..60 {
        fx.update(0.1);
    }
    assert!(fx.get_mut(boom).is_none(), "explosion is over after 6 s");
    fx.get_mut(smoke).expect("smoke runs until stopped").stop();
    for _ in 0..60 {
        fx.update(0.1);
    }
    assert!(fx.is_empty());
}

/// Renders `fx` at the given ages (seconds since spawning) and returns the images.
fn render_explosion(ages: &[f32]) -> Vec<Vec<u8>> {
    let mut fx = Effects::new(5);
    fx.spawn_explosion(Vec3::ZERO);
    let camera = camera();
    let view = View::new(&camera, 64);
    let mut renderer = Renderer::new();
    let mut target = Target::new(64, 64);
    let (mut t, dt) = (0.0f32, 1.0 / 60.0);
    let mut images = Vec::new();
    for &age in ages {
        while t + dt * 0.5 < age {
            fx.update(dt);
            t += dt;
        }
        fx.build(&view);
        renderer.render(
            fx.draws(),
            &camera,
            &Lighting::default(),
            &mut target,
            &FrameOptions::default(),
        );
        images.push(target.to_rgba8());
    }
    images
}

fn lit_near_centre(img: &[u8]) -> usize {
    let mut n = 0;
    for y in 24..40 {
        for x in 24..40 {
            let i = (y * 64 + x) * 4;
            if img[i..i + 3].iter().any(|&c| c > 8) {
                n += 1;
            }
        }
    }
    n
}

#[test]
fn explosion_renders_then_disappears() {
    let images = render_explosion(&[0.1, 0.5, 1.5, 6.0]);
    for img in &images[..3] {
        assert!(lit_near_centre(img) > 64, "{}", lit_near_centre(img));
    }
    let black = images[3].chunks_exact(4).all(|p| p == [0, 0, 0, 255]);
    assert!(black, "nothing left after the effect's lifetime");
}

fn explosion_hash() -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for img in render_explosion(&[0.05, 0.3, 0.8, 2.0]) {
        for b in img {
            h = (h ^ b as u64).wrapping_mul(0x100_0000_01b3);
        }
    }
    h
}

/// The explosion renders to the same pixels in 1- and 2-thread pools.
#[test]
fn rendering_is_the_same_at_1_and_2_threads() {
    let in_pool = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(explosion_hash)
    };
    assert_eq!(in_pool(1), in_pool(2));
}

/// Mean alpha-weighted luminance (sRGB bytes) and mean alpha of frame `f` of the sheet.
fn frame_stats(tex: &engine::Texture, cell: u32, f: u32) -> (f32, f32) {
    let level = &tex.levels()[0];
    let (x0, y0) = ((f % 4) * cell, (f / 4) * cell);
    let (mut lum, mut alpha) = (0.0, 0.0);
    for y in y0..y0 + cell {
        for x in x0..x0 + cell {
            let [r, g, b, a] = level.texels[(y * level.width + x) as usize].to_le_bytes();
            let a = a as f32 / 255.0;
            lum += (0.2126 * r as f32 + 0.7152 * g as f32 + 0.0722 * b as f32) * a;
            alpha += a;
        }
    }
    (lum / alpha.max(1e-6), alpha / (cell * cell) as f32)
}

#[test]
fn explosion_frames_cool_and_fade_with_clear_borders() {
    let cell = 64;
    let tex = explosion_sheet(cell, 4, 4, 7);
    assert_eq!((tex.width(), tex.height()), (256, 256));
    let stats: Vec<(f32, f32)> = (0..16).map(|f| frame_stats(&tex, cell, f)).collect();
    let mean = |r: std::ops::Range<usize>| {
        let n = r.len() as f32;
        stats[r].iter().map(|s| s.0).sum::<f32>() / n
    };
    let (early, late) = (mean(0..4), mean(12..16));
    assert!(early > 1.5 * late, "early {early}, late {late}");
    // The first frame's core is white-yellow hot.
    let level = &tex.levels()[0];
    let centre = |f: u32| level.texels[((f / 4 * 64 + 32) * 256 + f % 4 * 64 + 32) as usize];
    let [r0, g0, ..] = centre(0).to_le_bytes();
    assert!(r0 > 200 && g0 > 150, "hot core {r0} {g0}");
    let peak = stats.iter().map(|s| s.1).fold(0.0, f32::max);
    assert!(stats[15].1 < 0.6 * peak, "fades out: {stats:?}");
    for i in 0..256 {
        for j in [0, 63, 64, 127, 128, 191, 192, 255] {
            for (x, y) in [(i, j), (j, i)] {
                let a = level.texels[(y * 256 + x) as usize] >> 24;
                assert_eq!(a, 0, "alpha at ({x}, {y})");
            }
        }
    }
}

#[test]
fn smoke_and_spark_textures_have_soft_edges() {
    for tex in [smoke_puff(64, 3), spark(32)] {
        let l = &tex.levels()[0];
        let (w, h) = (l.width, l.height);
        for i in 0..w {
            for (x, y) in [(i, 0), (i, h - 1), (0, i), (w - 1, i)] {
                assert_eq!(l.texels[(y * w + x) as usize] >> 24, 0);
            }
        }
        let mid = l.texels[(h / 2 * w + w / 2) as usize] >> 24;
        assert!(mid > 100, "{mid}");
    }
}
