//! Billboard orientation against the analytic expectation, sizes, pivots, the axial
//! fallback over the top, and batch ordering and memory reuse.

use super::*;
use engine::{AlphaMode, BlendMode};

const EPS: f32 = 1e-4;

fn camera(eye: Vec3, target: Vec3) -> Camera {
    Camera::look_at(eye, target, Vec3::Y, 1.0, 1.5)
}

/// Eyes all around a billboard at `P`, at many azimuths and elevations (never straight
/// above or below, where "up" is undefined for a look-at camera).
fn eyes() -> Vec<Vec3> {
    let mut v = Vec::new();
    for a in 0..12 {
        for e in [-70.0f32, -30.0, -5.0, 0.0, 10.0, 45.0, 80.0] {
            let (az, el) = ((a as f32 * 30.0 + 7.0).to_radians(), e.to_radians());
            let dir = Vec3::new(el.cos() * az.cos(), el.sin(), el.cos() * az.sin());
            v.push(P + dir * (3.0 + a as f32));
        }
    }
    v
}

const P: Vec3 = Vec3::new(1.0, 0.5, -2.0);

fn assert_orthonormal(b: &Basis) {
    for (x, y) in [(b.right, b.up), (b.up, b.normal), (b.normal, b.right)] {
        assert!(x.dot(y).abs() < EPS, "{b:?}");
    }
    for v in [b.right, b.up, b.normal] {
        assert!((v.length() - 1.0).abs() < EPS, "{b:?}");
    }
    // Counter-clockwise as seen from the normal side: right x up = normal.
    assert!(b.right.cross(b.up).distance(b.normal) < EPS, "{b:?}");
}

#[test]
fn screen_billboards_are_parallel_to_the_image_plane() {
    for eye in eyes() {
        // Look somewhere other than the billboard: a screen billboard ignores its position.
        let cam = camera(eye, P + Vec3::new(0.3, 0.1, 0.0));
        let view = View::new(&cam, 100);
        let b = orient(Facing::Screen, &view, P);
        assert_orthonormal(&b);
        let v = cam.view;
        // In view space the quad's axes are exactly +X and +Y, its normal +Z.
        assert!(v.transform_vector3(b.right).distance(Vec3::X) < EPS);
        assert!(v.transform_vector3(b.up).distance(Vec3::Y) < EPS);
        assert!(v.transform_vector3(b.normal).distance(Vec3::Z) < EPS);
        assert_eq!(b.fade, 1.0);
    }
}

#[test]
fn world_billboards_face_the_eye_and_stay_upright() {
    for eye in eyes() {
        let cam = camera(eye, Vec3::ZERO);
        let b = orient(Facing::World { up: Vec3::Y }, &View::new(&cam, 100), P);
        assert_orthonormal(&b);
        assert!(
            b.normal.distance((eye - P).normalize()) < EPS,
            "faces the eye"
        );
        assert!(b.right.y.abs() < EPS, "right stays horizontal");
        assert!(b.up.y > 0.0, "up keeps its sign");
        // Among unit vectors perpendicular to the normal, `up` is the closest to +Y.
        let best = (Vec3::Y - b.normal * b.normal.y).normalize();
        assert!(b.up.distance(best) < EPS);
    }
}

#[test]
fn axial_billboards_turn_only_about_their_axis() {
    let axis = Vec3::new(0.2, 1.0, -0.1).normalize();
    let facing = Facing::Axial {
        axis,
        fallback: AxialFallback::default(),
    };
    for eye in eyes() {
        let cam = camera(eye, Vec3::ZERO);
        let b = orient(facing, &View::new(&cam, 100), P);
        assert_orthonormal(&b);
        assert!(b.up.distance(axis) < EPS, "up is the axis");
        let to_eye = (eye - P).normalize();
        let flat = (to_eye - axis * to_eye.dot(axis)).normalize();
        assert!(b.normal.distance(flat) < EPS, "faces the eye's projection");
        let elevation = to_eye.dot(axis).abs().asin().to_degrees();
        let expect = if elevation <= 55.0 {
            1.0
        } else if elevation >= 75.0 {
            0.0
        } else {
            b.fade
        };
        assert_eq!(b.fade, expect, "elevation {elevation}");
        assert!((0.0..=1.0).contains(&b.fade));
    }
}

#[test]
fn axial_fade_is_monotonic_and_the_quad_vanishes_over_the_top() {
    let mut last = 1.0;
    for i in 0..=90 {
        let e = (i as f32).to_radians();
        let eye = P + Vec3::new(e.cos(), e.sin(), 0.0) * 5.0;
        let view = View::new(&camera(eye, P + Vec3::new(0.0, 0.0, 0.01)), 100);
        let b = orient(Facing::UPRIGHT, &view, P);
        assert!(
            b.fade <= last + 1e-6 && b.fade.is_finite(),
            "at {i} degrees"
        );
        last = b.fade;
        let bb = Billboard::new(P, Facing::UPRIGHT, Vec2::ONE);
        assert_eq!(corners(&bb, &view).is_none(), i >= 75, "at {i} degrees");
    }
}

/// The over-the-top path: the eye passes straight over an axial billboard. Its corners
/// stay finite, and while it is visible they move by a bounded amount from step to step
/// (no flip, no jitter); the top sprite fades in as the upright quad fades out, one of the
/// two always fully opaque.
#[test]
fn over_the_top_path_has_no_nan_flip_or_jitter() {
    let top = UvRect::cell(2, 1, 1);
    let facing = Facing::Axial {
        axis: Vec3::Y,
        fallback: AxialFallback {
            top: Some(top),
            ..Default::default()
        },
    };
    let b = Billboard {
        pivot: Vec2::new(0.5, 0.0),
        ..Billboard::new(P, facing, Vec2::new(1.0, 2.0))
    };
    let mut prev: Option<[Vec3; 4]> = None;
    let n = 720;
    for i in 0..=n {
        // From the west at ground level, over the top, down to the east.
        let a = std::f32::consts::PI * i as f32 / n as f32;
        let eye = P + Vec3::new(-a.cos(), a.sin(), 0.02) * 6.0 + Vec3::Y * 0.3;
        let view = View::new(&camera(eye, P), 64);
        let mut batch = BillboardBatch::new(Material::default());
        batch.push(b);
        batch.build(&view);
        let mesh = batch.mesh();
        assert!(mesh.positions.iter().all(|p| p.is_finite()), "step {i}");
        assert!(mesh.colors.iter().all(|c| (0.0..=1.0).contains(&c.a)));
        let upright = corners(&b, &view);
        // Upright and top overlap: one of them is always drawn at full opacity.
        let opaque = mesh
            .colors
            .iter()
            .step_by(4)
            .map(|c| c.a)
            .fold(0.0, f32::max);
        assert!(
            (opaque - 1.0).abs() < 1e-6,
            "one quad fully opaque at step {i}: {opaque}"
        );
        if let (Some((q, _)), Some(p)) = (upright, prev) {
            let moved = q
                .iter()
                .zip(p)
                .map(|(a, b)| a.distance(b))
                .fold(0.0, f32::max);
            // One step is 0.25 degrees of a 6-unit orbit; the quad (2 units tall) turns
            // with the eye, so its corners move by a small fraction of its size.
            assert!(moved < 0.05, "step {i}: corners jumped by {moved}");
        }
        prev = upright.map(|(q, _)| q);
    }
}

#[test]
fn pivot_and_rotation_place_the_corners() {
    let cam = camera(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
    let view = View::new(&cam, 100);
    let mut b = Billboard::new(P, Facing::Screen, Vec2::new(2.0, 1.0));
    b.pivot = Vec2::new(0.5, 0.0);
    let (q, _) = corners(&b, &view).unwrap();
    assert!(
        ((q[0] + q[1]) * 0.5).distance(P) < EPS,
        "bottom centre at P"
    );
    assert!((q[1] - q[0]).distance(Vec3::X * 2.0) < EPS);
    assert!((q[3] - q[0]).distance(Vec3::Y) < EPS);
    b.pivot = Vec2::splat(0.5);
    b.rotation = std::f32::consts::FRAC_PI_2;
    let (q, _) = corners(&b, &view).unwrap();
    // Turned a quarter counter-clockwise: the width now runs up the screen.
    assert!((q[1] - q[0]).distance(Vec3::Y * 2.0) < EPS, "{q:?}");
    assert!(((q[0] + q[2]) * 0.5).distance(P) < EPS);
}

#[test]
fn pixel_sized_billboards_keep_their_screen_size_at_any_distance() {
    let (w, h) = (320u32, 200u32);
    for dist in [1.0f32, 4.0, 30.0, 90.0] {
        let cam = camera(Vec3::new(0.0, 0.0, dist), Vec3::ZERO).with_aspect(w, h);
        let view = View::new(&cam, h);
        let mut b = Billboard::new(Vec3::new(0.2, -0.1, 0.0), Facing::Screen, Vec2::ONE);
        b.size = Size::Pixels(Vec2::new(24.0, 10.0));
        let (q, _) = corners(&b, &view).unwrap();
        let to_px = |p: Vec3| {
            let c = cam.clip_from_world() * p.extend(1.0);
            Vec2::new(
                (c.x / c.w * 0.5 + 0.5) * w as f32,
                (0.5 - c.y / c.w * 0.5) * h as f32,
            )
        };
        let width = to_px(q[1]).distance(to_px(q[0]));
        let height = to_px(q[3]).distance(to_px(q[0]));
        assert!(
            (width - 24.0).abs() < 0.01 && (height - 10.0).abs() < 0.01,
            "{width} {height} at {dist}"
        );
    }
    // Behind the eye there is no pixel size: nothing is drawn.
    let cam = camera(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
    let mut b = Billboard::new(Vec3::new(0.0, 0.0, 9.0), Facing::Screen, Vec2::ONE);
    b.size = Size::Pixels(Vec2::splat(8.0));
    assert!(corners(&b, &View::new(&cam, 100)).is_none());
}

#[test]
fn cells_tile_the_texture() {
    let r = UvRect::cell(4, 2, 5);
    assert_eq!(r.min, Vec2::new(0.25, 0.5));
    assert_eq!(r.max, Vec2::new(0.5, 1.0));
    assert_eq!(UvRect::cell(4, 2, 8), UvRect::cell(4, 2, 0), "wraps");
    assert_eq!(
        UvRect::cell(0, 0, 3),
        UvRect::FULL,
        "empty grids are one cell"
    );
}

fn scattered(n: usize) -> Vec<Billboard> {
    let mut rng = engine::procedural::XorShift::new(3);
    (0..n)
        .map(|_| {
            let p = Vec3::new(
                rng.range(-5.0, 5.0),
                rng.range(-5.0, 5.0),
                rng.range(-20.0, 0.0),
            );
            Billboard::new(p, Facing::Screen, Vec2::ONE)
        })
        .collect()
}

#[test]
fn blended_batches_write_far_to_near_and_opaque_ones_in_order() {
    let cam = camera(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
    let view = View::new(&cam, 100);
    let items = scattered(200);
    for (material, sorted) in [
        (Material::default().blended(BlendMode::Alpha), true),
        (
            Material {
                alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
                ..Default::default()
            },
            false,
        ),
    ] {
        let mut batch = BillboardBatch::new(material);
        batch.items = items.clone();
        assert_eq!(batch.build(&view), 200);
        let depths: Vec<f32> = batch
            .mesh()
            .positions
            .chunks_exact(4)
            .map(|q| view.depth((q[0] + q[2]) * 0.5))
            .collect();
        if sorted {
            assert!(depths.windows(2).all(|w| w[0] >= w[1] - EPS), "far to near");
        } else {
            let expect: Vec<f32> = items.iter().map(|b| view.depth(b.position)).collect();
            for (d, e) in depths.iter().zip(&expect) {
                assert!((d - e).abs() < EPS, "insertion order kept");
            }
        }
    }
}

#[test]
fn rebuilding_a_warm_batch_does_not_grow_its_buffers() {
    let mut batch = BillboardBatch::new(Material::default().blended(BlendMode::Additive));
    batch.items = scattered(500);
    let caps = |b: &BillboardBatch| {
        let m = b.mesh();
        (
            m.positions.capacity(),
            m.uvs.capacity(),
            m.colors.capacity(),
            m.indices.capacity(),
        )
    };
    batch.build(&View::new(
        &camera(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO),
        100,
    ));
    let warm = caps(&batch);
    for i in 0..50 {
        let eye = Vec3::new((i as f32 * 0.3).sin() * 4.0, 1.0, 5.0);
        batch.build(&View::new(&camera(eye, Vec3::ZERO), 100));
        assert_eq!(caps(&batch), warm, "frame {i}");
    }
}

#[test]
fn odd_billboards_are_skipped_not_drawn_broken() {
    let view = View::new(&camera(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO), 100);
    let mut batch = BillboardBatch::new(Material::default().blended(BlendMode::Alpha));
    batch.push(Billboard::new(Vec3::NAN, Facing::Screen, Vec2::ONE));
    batch.push(Billboard::new(
        Vec3::ZERO,
        Facing::Screen,
        Vec2::splat(f32::INFINITY),
    ));
    batch.push(Billboard::new(
        Vec3::new(0.0, 0.0, 5.0),
        Facing::UPRIGHT,
        Vec2::ONE,
    ));
    batch.push(Billboard::new(
        Vec3::ZERO,
        Facing::World { up: Vec3::ZERO },
        Vec2::ONE,
    ));
    batch.build(&view);
    assert!(batch.mesh().positions.iter().all(|p| p.is_finite()));
    assert!(batch.mesh().validate().is_ok());
}
