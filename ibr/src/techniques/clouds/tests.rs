//! Cumulus shapes, the light pass against the sun's side, the phase functions against
//! their closed forms, rendering (coverage, thread-count independence, idempotent and
//! allocation-stable rebuilds) and odd input.

use super::*;
use engine::{FrameOptions, Lighting, Renderer, Target};

const SIZE: Vec3 = Vec3::new(40.0, 16.0, 24.0);

fn mean(v: impl Iterator<Item = f32>) -> f32 {
    let (s, n) = v.fold((0.0, 0), |(s, n), x| (s + x, n + 1));
    s / n.max(1) as f32
}

#[test]
fn cumulus_is_deterministic_bounded_and_flat_based() {
    let c = Vec3::new(5.0, 100.0, -3.0);
    let a = cumulus(c, SIZE, 300, 7);
    assert_eq!(a, cumulus(c, SIZE, 300, 7));
    assert_ne!(a, cumulus(c, SIZE, 300, 8));
    assert_eq!(a.len(), 300);
    assert_eq!(cumulus(c, SIZE, 17, 1).len(), 17);
    assert!(cumulus(c, SIZE, 0, 1).is_empty());
    let cloud = Cloud::new(a.clone());
    let b = cloud.bounds();
    let base = c.y - SIZE.y * 0.5;
    for p in &a {
        assert!(
            p.position.distance(b.center) + p.radius <= b.radius + 1e-3,
            "{p:?} {b:?}"
        );
        assert!(p.radius > 0.0 && (0.0..=1.0).contains(&p.density), "{p:?}");
        let q = (p.position - c).abs();
        assert!(q.cmple(SIZE * 0.5 + 1e-3).all(), "inside the box: {p:?}");
    }
    assert!(
        a.iter().all(|p| p.position.y >= base - 1e-3),
        "nothing below the base"
    );
    // A flat base: a good share of particles sit in the bottom tenth of the height.
    let low = a
        .iter()
        .filter(|p| p.position.y < base + 0.1 * SIZE.y)
        .count();
    assert!(low > a.len() / 20, "{low} in the base layer");
    // Denser toward the core: the half of the particles nearest their centroid (in box
    // units) is denser on average than the outer half.
    let mid = a.iter().map(|p| p.position).sum::<Vec3>() / a.len() as f32;
    let mut by_dist: Vec<(f32, f32)> = a
        .iter()
        .map(|p| (((p.position - mid) / SIZE).length(), p.density))
        .collect();
    by_dist.sort_by(|x, y| x.0.total_cmp(&y.0));
    let (core, rim) = by_dist.split_at(150);
    let (core, rim) = (
        mean(core.iter().map(|x| x.1)),
        mean(rim.iter().map(|x| x.1)),
    );
    assert!(core > rim + 0.02, "core {core} rim {rim}");
    assert_eq!(cloud.triangle_count(), 600);
}

/// A cloud lit by a sun whose light travels along +X (the sun is at -X).
fn lit_cloud() -> Cloud {
    let mut cloud = Cloud::cumulus(Vec3::ZERO, SIZE, 300, 3);
    cloud.relight(Vec3::X, Rgba::new(1.5, 1.5, 1.5, 1.0));
    cloud
}

/// Mean transmittance of the particles on the -X and +X sides of the cloud's middle.
fn halves(cloud: &Cloud) -> (f32, f32) {
    let t = cloud.transmittance();
    let side = |neg: bool| {
        mean(
            cloud
                .particles()
                .iter()
                .zip(t)
                .filter(|(p, _)| (p.position.x < 0.0) == neg)
                .map(|(_, &t)| t),
        )
    };
    (side(true), side(false))
}

#[test]
fn light_pass_lights_the_sun_side_and_flips_with_the_sun() {
    let mut cloud = lit_cloud();
    let (sunny, shaded) = halves(&cloud);
    assert!(
        sunny > shaded + 0.15,
        "sun side {sunny} vs far side {shaded}"
    );
    for i in 0..cloud.particles().len() {
        let l = cloud.incident(i);
        for c in [l.r, l.g, l.b] {
            assert!((0.0..=1.5 + 1e-5).contains(&c), "{l:?}");
        }
    }
    // The particle nearest the sun sees it unobstructed.
    let first = (0..300).min_by(|&a, &b| {
        cloud.particles()[a]
            .position
            .x
            .total_cmp(&cloud.particles()[b].position.x)
    });
    assert_eq!(cloud.transmittance()[first.unwrap()], 1.0);
    // Monotone-ish with depth along the sun: quartiles by depth grow darker.
    let mut by_depth: Vec<(f32, f32)> = cloud
        .particles()
        .iter()
        .zip(cloud.transmittance())
        .map(|(p, &t)| (p.position.x, t))
        .collect();
    by_depth.sort_by(|a, b| a.0.total_cmp(&b.0));
    let q: Vec<f32> = by_depth
        .chunks(75)
        .map(|c| mean(c.iter().map(|x| x.1)))
        .collect();
    for w in q.windows(2) {
        assert!(w[1] <= w[0] + 0.02, "quartiles {q:?}");
    }
    assert!(q[3] < q[0] - 0.2, "quartiles {q:?}");
    assert!(
        q[3] > 0.0,
        "forward scattering keeps the far side lit: {q:?}"
    );

    let v = cloud.version();
    cloud.relight(Vec3::NEG_X, Rgba::new(1.5, 1.5, 1.5, 1.0));
    assert_ne!(cloud.version(), v);
    let (left, right) = halves(&cloud);
    assert!(right > left + 0.15, "flipped: {left} vs {right}");
    // Same sun again: nothing recomputed, same version. A new colour only bumps the version.
    let (v, t) = (cloud.version(), cloud.transmittance().to_vec());
    cloud.relight(Vec3::NEG_X * 3.0, Rgba::new(1.5, 1.5, 1.5, 1.0));
    assert_eq!(cloud.version(), v);
    cloud.relight(Vec3::NEG_X, Rgba::new(1.0, 0.8, 0.6, 1.0));
    assert_ne!(cloud.version(), v);
    assert_eq!(cloud.transmittance(), &t[..]);
}

#[test]
fn phase_functions_match_their_closed_forms() {
    let hg = Phase::HenyeyGreenstein { g: 0.6 };
    let mixed = Phase::Mixed {
        g: 0.6,
        weight: 0.5,
    };
    assert_eq!(CloudShading::default().phase, mixed);
    // Half the lobe, half isotropic.
    assert!((mixed.eval(1.0) - 5.5).abs() < 1e-4);
    assert!((mixed.eval(-1.0) - 0.578_125).abs() < 1e-5);
    // (1 + g) / (1 - g)² forward, (1 - g) / (1 + g)² backward.
    assert!((hg.eval(1.0) - 10.0).abs() < 1e-4);
    assert!((hg.eval(-1.0) - 0.156_25).abs() < 1e-5);
    assert!((hg.eval(0.0) - 0.64 / 1.36f32.powf(1.5)).abs() < 1e-5);
    let ray = Phase::Rayleigh;
    assert_eq!(
        (ray.eval(1.0), ray.eval(0.0), ray.eval(-1.0)),
        (1.5, 0.75, 1.5)
    );
    for k in 0..=20 {
        let c = k as f32 / 10.0 - 1.0;
        assert!(
            (ray.eval(c) - ray.eval(-c)).abs() < 1e-6,
            "Rayleigh is symmetric about 90°"
        );
        if c < 1.0 {
            assert!(
                hg.eval(c + 0.1) > hg.eval(c),
                "HG grows toward forward scattering"
            );
        }
    }
    // Both average 1 over the sphere: (1/2) ∫ p(c) dc over [-1, 1].
    for p in [hg, ray, mixed, Phase::HenyeyGreenstein { g: -0.3 }] {
        let n = 20_000;
        let m = (0..n)
            .map(|i| p.eval(-1.0 + (i as f32 + 0.5) * 2.0 / n as f32))
            .sum::<f32>()
            / n as f32;
        assert!((m - 1.0).abs() < 1e-3, "{p:?} mean {m}");
    }
    assert!(
        hg.eval(f32::NAN).is_finite() && Phase::HenyeyGreenstein { g: f32::NAN }.eval(0.5) == 1.0
    );

    // On a cloud: seen looking toward the sun (backlit, the eye downstream of the light) a
    // particle is brighter than seen with the sun behind the eye; with Rayleigh, the same.
    // The difference is exactly incident * albedo * (p(0°) - p(180°)).
    let mut cloud = lit_cloud();
    for i in [0, 10, 100] {
        let (back, front) = (
            cloud.particle_color(i, Vec3::X),
            cloud.particle_color(i, Vec3::NEG_X),
        );
        let expect = cloud.incident(i).r * 0.9 * (5.5 - 0.578_125);
        assert!(
            (back.r - front.r - expect).abs() < 1e-4,
            "{back:?} vs {front:?}"
        );
        assert!(back.r > front.r, "{back:?} vs {front:?}");
        assert_eq!(back.a, cloud.particles()[i].density);
        // Sideways (90°) lies in between.
        let side = cloud.particle_color(i, Vec3::Y);
        assert!(front.r < side.r && side.r < back.r);
    }
    let i = 0;
    cloud.set_shading(CloudShading {
        phase: Phase::Rayleigh,
        ..CloudShading::default()
    });
    assert_eq!(
        cloud.particle_color(i, Vec3::X),
        cloud.particle_color(i, Vec3::NEG_X)
    );
}

fn camera(eye: Vec3) -> Camera {
    Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 0.9, 1.0)
}

fn render(cloud: &mut Cloud, cam: &Camera) -> Target {
    cloud.prepare(cam, 48);
    let mut draws = Vec::new();
    cloud.draws(&mut draws);
    let mut target = Target::new(48, 48);
    let opts = FrameOptions {
        clear: Some(Rgba::TRANSPARENT),
        ..FrameOptions::default()
    };
    Renderer::new().render(draws, cam, &Lighting::default(), &mut target, &opts);
    target
}

fn small_cloud() -> Cloud {
    let mut cloud = Cloud::cumulus(Vec3::ZERO, Vec3::new(8.0, 3.0, 5.0), 120, 11);
    cloud.relight(Vec3::new(0.5, -0.6, -0.4), Rgba::WHITE);
    cloud
}

#[test]
fn renders_a_covered_middle_on_a_clear_sky() {
    let mut cloud = small_cloud();
    let target = render(&mut cloud, &camera(Vec3::new(0.0, 1.0, 14.0)));
    let alpha = |x, y| target.color_linear(x, y).unwrap().a;
    assert!(alpha(24, 24) > 0.5, "middle covered: {}", alpha(24, 24));
    for (x, y) in [(0, 0), (47, 0), (0, 47), (47, 47), (24, 1), (24, 46)] {
        assert_eq!(alpha(x, y), 0.0, "({x}, {y}) clear");
    }
    let mut draws = Vec::new();
    cloud.draws(&mut draws);
    assert_eq!(draws.len(), 1);
    assert_eq!(draws[0].mesh.triangle_count(), cloud.triangle_count());
    assert!(draws[0].material.is_blended() && draws[0].material.depth_test);
}

#[test]
fn rendering_is_the_same_at_1_and_2_threads() {
    let image = || render(&mut small_cloud(), &camera(Vec3::new(3.0, 2.0, 12.0))).to_rgba8();
    let in_pool = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(image)
    };
    assert_eq!(in_pool(1), in_pool(2));
}

#[test]
fn rebuilds_are_idempotent_and_allocation_stable() {
    let mut cloud = small_cloud();
    let cam = camera(Vec3::new(2.0, 1.0, 12.0));
    cloud.prepare(&cam, 48);
    let first = cloud.batch().mesh().clone();
    cloud.prepare(&cam, 48);
    assert_eq!(cloud.batch().mesh(), &first);
    let caps = |c: &Cloud| {
        let m = c.batch().mesh();
        (
            m.positions.capacity(),
            m.uvs.capacity(),
            m.colors.capacity(),
            m.indices.capacity(),
        )
    };
    let warm = caps(&cloud);
    for frame in 0..20 {
        let a = frame as f32 * 0.31;
        cloud.prepare(
            &camera(Vec3::new(12.0 * a.sin(), 1.0 + a, 12.0 * a.cos())),
            48,
        );
        assert_eq!(caps(&cloud), warm, "frame {frame}");
        assert_eq!(cloud.batch().mesh().positions.len(), 4 * 120);
    }
}

#[test]
fn odd_input_does_not_panic() {
    let cam = camera(Vec3::new(0.0, 1.0, 14.0));
    // No particles.
    let mut empty = Cloud::cumulus(Vec3::ZERO, SIZE, 0, 1);
    empty.relight(Vec3::X, Rgba::WHITE);
    empty.prepare(&cam, 48);
    let mut draws = Vec::new();
    empty.draws(&mut draws);
    assert!(draws.is_empty());
    assert_eq!(empty.bounds().radius, 0.0);
    assert_eq!(empty.triangle_count(), 0);

    // Broken particles among good ones are skipped everywhere.
    let mut particles = cumulus(Vec3::ZERO, Vec3::new(8.0, 3.0, 5.0), 40, 2);
    let good = particles[0];
    particles.extend([
        CloudParticle {
            position: Vec3::NAN,
            ..good
        },
        CloudParticle {
            radius: f32::NAN,
            ..good
        },
        CloudParticle {
            radius: -1.0,
            ..good
        },
        CloudParticle {
            density: f32::INFINITY,
            ..good
        },
        CloudParticle {
            position: Vec3::splat(f32::MAX),
            ..good
        },
    ]);
    let mut cloud = Cloud::new(particles);
    cloud.relight(Vec3::new(0.3, -1.0, 0.2), Rgba::WHITE);
    assert!(cloud
        .transmittance()
        .iter()
        .all(|t| (0.0..=1.0).contains(t)));
    assert_eq!(cloud.transmittance()[40], 0.0);
    let b = cloud.bounds();
    assert!(b.center.is_finite() || b.radius == 0.0);
    let target = render(&mut cloud, &cam);
    assert!(target.color_linear(24, 24).unwrap().a.is_finite());

    // A NaN or zero sun keeps the previous direction; a NaN colour the previous colour.
    let (dir, color) = cloud.sun();
    cloud.relight(Vec3::NAN, Rgba::new(f32::NAN, 1.0, 1.0, 1.0));
    cloud.relight(Vec3::ZERO, Rgba::WHITE);
    assert_eq!(cloud.sun(), (dir, color));
    let fresh = Cloud::cumulus(Vec3::ZERO, SIZE, 10, 1);
    assert_eq!(fresh.sun().0, Vec3::NEG_Y, "straight down by default");

    // Odd shapes.
    for (c, s) in [
        (Vec3::NAN, SIZE),
        (Vec3::ZERO, Vec3::NAN),
        (Vec3::ZERO, Vec3::ZERO),
        (Vec3::ONE, -SIZE),
    ] {
        let p = cumulus(c, s, 25, 4);
        assert_eq!(p.len(), 25);
        assert!(p
            .iter()
            .all(|p| p.position.is_finite() && p.radius.is_finite()));
    }

    // Moving particles bumps the version and relights lazily.
    let v = cloud.version();
    cloud.translate(Vec3::X);
    assert_ne!(cloud.version(), v);
    let v = cloud.version();
    cloud.particles_mut()[0].position = Vec3::NAN;
    assert_ne!(cloud.version(), v);
    cloud.prepare(&cam, 48);
    assert_eq!(cloud.transmittance()[0], 0.0);
}

#[test]
fn field_scatters_disjoint_clouds_on_one_base() {
    let (lo, hi) = (Vec2::new(-200.0, -100.0), Vec2::new(200.0, 100.0));
    let field = CloudField::scatter(lo, hi, 60.0, 7, 30, 5);
    assert_eq!(field.clouds.len(), 7);
    let again = CloudField::scatter(lo, hi, 60.0, 7, 30, 5);
    for (a, b) in field.clouds.iter().zip(&again.clouds) {
        assert_eq!(a.particles(), b.particles());
    }
    let boxes: Vec<(Vec2, Vec2)> = field
        .clouds
        .iter()
        .map(|c| {
            assert_eq!(c.particles().len(), 30);
            let xz = |p: &CloudParticle| Vec2::new(p.position.x, p.position.z);
            c.particles()
                .iter()
                .fold((Vec2::INFINITY, Vec2::NEG_INFINITY), |(l, h), p| {
                    assert!(p.position.y >= 60.0 - 1e-3, "above the base");
                    (l.min(xz(p)), h.max(xz(p)))
                })
        })
        .collect();
    for (i, a) in boxes.iter().enumerate() {
        assert!(a.0.cmpge(lo - 1e-3).all() && a.1.cmple(hi + 1e-3).all());
        for b in &boxes[i + 1..] {
            let overlap = a.1.min(b.1) - a.0.max(b.0);
            assert!(overlap.x <= 0.0 || overlap.y <= 0.0, "{a:?} {b:?}");
        }
    }
    assert_eq!(field.triangle_count(), 7 * 60);
    assert!(field.bounds().radius > 50.0);
    assert!(CloudField::scatter(Vec2::NAN, hi, 60.0, 7, 30, 5)
        .clouds
        .is_empty());
    assert!(CloudField::scatter(lo, hi, 60.0, 0, 30, 5)
        .clouds
        .is_empty());
}

/// Renders `cloud`'s draws as prepared, at 96 x 96, with the renderer's low-resolution
/// scale `scale`.
fn render_scaled(cloud: &Cloud, cam: &Camera, scale: u32) -> (Target, engine::FrameStats) {
    let mut draws = Vec::new();
    cloud.draws(&mut draws);
    let mut target = Target::new(96, 96);
    let opts = FrameOptions {
        clear: Some(Rgba::new(0.3, 0.5, 0.9, 1.0)),
        ..FrameOptions::default()
    };
    let mut r = Renderer::new();
    r.set_low_res_scale(scale);
    let stats = r.render(draws, cam, &Lighting::default(), &mut target, &opts);
    (target, stats)
}

#[test]
fn fill_counts_the_pixels_the_particles_shade() {
    let mut cloud = small_cloud();
    let mut last = 0.0;
    // The particles' draw alone (not the fog's quad), its fragments against the fill.
    let particles = |cloud: &Cloud, cam: &Camera| {
        let mut target = Target::new(96, 96);
        let draw = cloud.batch().draw();
        let opts = FrameOptions::default();
        let stats = Renderer::new().render([draw], cam, &Lighting::default(), &mut target, &opts);
        stats.fragments_tested as f32
    };
    for d in [30.0, 18.0, 11.0, 6.0] {
        let cam = camera(Vec3::new(0.0, 1.0, d));
        cloud.prepare(&cam, 96);
        let ratio = cloud.fill() / particles(&cloud, &cam);
        assert!(
            (0.8..1.25).contains(&ratio),
            "at {d}: fill {} is {ratio} of the fragments",
            cloud.fill()
        );
        assert!(cloud.fill() > last, "nearer fills more");
        last = cloud.fill();
    }
    // From inside, among quads beside and behind the eye: still the fragments, not a
    // screen for every quad near the eye's plane.
    for eye in [Vec3::new(0.0, 1.0, 2.5), Vec3::new(-3.0, 0.5, 3.0)] {
        let cam = Camera::look_at(eye, eye + Vec3::new(0.3, 0.0, -1.0), Vec3::Y, 0.9, 1.0);
        cloud.prepare(&cam, 96);
        let (fill, frags) = (cloud.fill(), particles(&cloud, &cam));
        assert!(frags > 2000.0, "inside at {eye}: {frags} fragments");
        let ratio = fill / frags;
        assert!(
            (0.8..1.25).contains(&ratio),
            "inside at {eye}: fill {fill} is {ratio} of the fragments"
        );
    }
}

#[test]
fn low_res_particles_shade_a_quarter_and_look_alike() {
    let mut cloud = small_cloud();
    let cam = camera(Vec3::new(0.0, 1.0, 11.0));
    cloud.prepare(&cam, 96);
    let (full, plain) = render_scaled(&cloud, &cam, 2);
    let low_res = |cloud: &Cloud| {
        let mut draws = Vec::new();
        cloud.draws(&mut draws);
        draws.iter().map(|d| d.material.low_res).collect::<Vec<_>>()
    };
    assert!(low_res(&cloud).iter().all(|&l| !l), "off by default");
    cloud.set_low_res(true);
    assert!(low_res(&cloud).iter().all(|&l| l));
    let (low, stats) = render_scaled(&cloud, &cam, 2);
    let ratio = stats.fragments_shaded_blended as f64 / plain.fragments_shaded_blended as f64;
    assert!(
        (0.2..0.32).contains(&ratio),
        "blended fragments {ratio} of full resolution"
    );
    // Soft puffs: the composite is within a fraction of a level of the full-resolution
    // particles on average.
    let (a, b) = (full.to_rgba8(), low.to_rgba8());
    let diff: u64 = a.iter().zip(&b).map(|(x, y)| x.abs_diff(*y) as u64).sum();
    let mean = diff as f64 / a.len() as f64;
    let worst = a
        .iter()
        .zip(&b)
        .map(|(x, y)| x.abs_diff(*y))
        .max()
        .unwrap_or(0);
    // Measured: mean 0.18 levels, worst 12 (a puff's edge).
    assert!(
        mean < 0.5 && worst < 40,
        "mean difference {mean} levels, worst {worst}"
    );
}
