//! Laser quads against the dual-billboard construction, end-on and degenerate beams, and
//! the glow seen when looking down the beam.

use super::*;
use engine::{Camera, Draw, FrameOptions, Lighting, Material, Renderer, Target};
use glam::Mat4;

const EPS: f32 = 1e-4;

fn laser() -> Laser {
    Laser {
        a: Vec3::new(-2.0, 0.5, -1.0),
        b: Vec3::new(3.0, 1.0, -4.0),
        width: 0.2,
        color: Rgba::new(1.0, 0.2, 0.1, 1.0),
        intensity: 2.0,
    }
}

fn normal(q: &[Vec3; 4]) -> Vec3 {
    (q[1] - q[0]).cross(q[3] - q[0]).normalize()
}

#[test]
fn quads_contain_the_axis_and_the_first_faces_the_viewer() {
    let l = laser();
    let d = (l.b - l.a).normalize();
    let mut rng = engine::procedural::XorShift::new(9);
    for _ in 0..200 {
        let eye = Vec3::new(
            rng.range(-9.0, 9.0),
            rng.range(-9.0, 9.0),
            rng.range(-9.0, 9.0),
        );
        let (q, fade) = beam_quads(&l, eye, Vec3::Y, Vec3::X).unwrap();
        for quad in &q {
            // Both quads contain the beam axis: their centre lines are A..B.
            assert!(((quad[0] + quad[1]) * 0.5).distance(l.a) < EPS);
            assert!(((quad[2] + quad[3]) * 0.5).distance(l.b) < EPS);
            assert!(
                (quad[1].distance(quad[0]) - l.width).abs() < EPS,
                "full width"
            );
            assert!(normal(quad).dot(d).abs() < EPS, "axis lies in the quad");
        }
        // Quad 1's normal is the view vector projected perpendicular to the axis.
        let t = (eye - l.a).dot(d).clamp(0.0, l.a.distance(l.b));
        let v = eye - (l.a + d * t);
        let perp = (v - d * v.dot(d)).normalize();
        assert!(
            normal(&q[0]).dot(perp).abs() > 1.0 - EPS,
            "quad 1 faces the viewer"
        );
        assert!(
            normal(&q[1]).dot(normal(&q[0])).abs() < EPS,
            "quad 2 at 90 degrees"
        );
        let sin = (1.0 - v.normalize().dot(d).powi(2)).max(0.0).sqrt();
        let degrees = sin.asin().to_degrees();
        if degrees >= END_ON_DEGREES {
            assert_eq!(fade, 1.0, "full strength away from the axis");
        } else {
            assert!((0.0..1.0).contains(&fade), "fading near the axis");
        }
    }
}

#[test]
fn end_on_beams_stay_finite_full_size_quads() {
    let l = laser();
    let d = (l.b - l.a).normalize();
    for eye in [l.b + d * 4.0, l.a - d * 0.5, l.a, (l.a + l.b) * 0.5] {
        let (q, fade) = beam_quads(&l, eye, Vec3::Y, Vec3::X).unwrap();
        assert!(fade < 1e-5, "seen exactly along the axis: {fade}");
        for quad in &q {
            assert!(quad.iter().all(|p| p.is_finite()));
            let area = (quad[1] - quad[0]).cross(quad[3] - quad[0]).length();
            assert!(
                (area - l.width * l.a.distance(l.b)).abs() < 1e-3,
                "not degenerate"
            );
        }
    }
    // The camera up along the axis too: the fallback still finds a direction.
    let vertical = Laser {
        a: Vec3::ZERO,
        b: Vec3::Y,
        ..laser()
    };
    let (q, _) = beam_quads(&vertical, Vec3::Y * 5.0, Vec3::Y, Vec3::X).unwrap();
    assert!(q.iter().flatten().all(|p| p.is_finite()));
}

#[test]
fn zero_length_or_broken_beams_draw_only_caps() {
    let view = View::new(
        &Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 1.0, 1.0),
        64,
    );
    let mut batch = LaserBatch::new();
    batch.lasers = vec![
        Laser {
            b: laser().a,
            ..laser()
        },
        Laser {
            a: Vec3::NAN,
            ..laser()
        },
        Laser {
            width: f32::INFINITY,
            ..laser()
        },
    ];
    assert_eq!(batch.build(&view), 0);
    assert!(batch.cap_mesh().positions.iter().all(|p| p.is_finite()));
    assert!(batch.cap_mesh().validate().is_ok());
}

/// Looking straight down a beam, the image centre glows in the beam's colour; from the
/// side, the beam crosses the image. Both are symmetric, additive and finite.
#[test]
fn a_beam_glows_end_on_and_from_the_side() {
    let l = Laser {
        a: Vec3::new(0.0, 0.0, -2.0),
        b: Vec3::new(0.0, 0.0, -12.0),
        width: 0.3,
        color: Rgba::new(0.1, 1.0, 0.2, 1.0),
        intensity: 1.5,
    };
    let mut batch = LaserBatch::new();
    batch.lasers.push(l);
    let mut renderer = Renderer::new();
    let mut target = Target::new(48, 48);
    let black = FrameOptions {
        clear: Some(Rgba::new(0.0, 0.0, 0.0, 1.0)),
        ..Default::default()
    };
    let mut render = |cam: Camera, target: &mut Target| {
        batch.build(&View::new(&cam, 48));
        renderer.render(batch.draws(), &cam, &Lighting::default(), target, &black);
    };
    render(
        Camera::look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 1.0, 1.0),
        &mut target,
    );
    let c = target.color_linear(24, 24).unwrap();
    assert!(
        c.g > 0.5 && c.g > 2.0 * c.r && c.g > 2.0 * c.b,
        "green glow: {c:?}"
    );
    let corner = target.color_linear(1, 1).unwrap();
    assert!(corner.g < 0.05, "glow is local: {corner:?}");

    render(
        Camera::look_at(
            Vec3::new(8.0, 0.0, -7.0),
            Vec3::new(0.0, 0.0, -7.0),
            Vec3::Y,
            1.0,
            1.0,
        ),
        &mut target,
    );
    // From the side the beam is a horizontal line through the middle row.
    let mid: f32 = (4..44)
        .map(|x| target.color_linear(x, 24).unwrap().g)
        .sum::<f32>()
        / 40.0;
    let off: f32 = (4..44)
        .map(|x| target.color_linear(x, 6).unwrap().g)
        .sum::<f32>()
        / 40.0;
    assert!(mid > 0.3 && off < 0.02, "beam row {mid}, away {off}");
}

/// A cap's sprite lies in front of the whole sphere of [`CAP_CLEARANCE`] cap radii around
/// its end (so a housing or target within it cannot hide it), at the same place and size
/// on screen as a sprite at the end itself.
#[test]
fn caps_sit_in_front_of_their_glow_sphere_at_the_same_place_on_screen() {
    let l = laser();
    let radius = 0.5 * l.width * CAP_SCALE * CAP_CLEARANCE;
    let mut rng = engine::procedural::XorShift::new(5);
    let mut batch = LaserBatch::new();
    batch.lasers.push(l);
    for _ in 0..100 {
        let eye = Vec3::new(
            rng.range(-9.0, 9.0),
            rng.range(-9.0, 9.0),
            rng.range(-9.0, 9.0),
        );
        let look = (l.a + l.b) * 0.5 + Vec3::new(rng.range(-1.0, 1.0), 0.0, 0.0);
        if eye.distance(l.a).min(eye.distance(l.b)) < 2.0 * radius + 0.1 {
            continue;
        }
        let view = View::new(&Camera::look_at(eye, look, Vec3::Y, 1.0, 1.0), 64);
        batch.build(&view);
        let caps = &batch.cap_mesh().positions;
        assert_eq!(caps.len(), 8);
        let screen = |p: Vec3| {
            let d = view.depth(p);
            Vec2::new((p - eye).dot(view.right), (p - eye).dot(view.up)) / d
        };
        for quad in caps.chunks(4) {
            // Blended billboards are sorted back to front: find the quad's end on screen.
            let mid = quad.iter().copied().sum::<Vec3>() * 0.25;
            let end = [l.a, l.b]
                .into_iter()
                .min_by(|x, y| {
                    screen(*x)
                        .distance(screen(mid))
                        .total_cmp(&screen(*y).distance(screen(mid)))
                })
                .unwrap();
            if view.depth(end) <= 2.0 * radius {
                continue;
            }
            for p in quad {
                let d = view.depth(*p);
                assert!(
                    d <= view.depth(end) - radius + 1e-3,
                    "in front of the sphere"
                );
                assert!(d > 0.0, "in front of the eye");
            }
            let q: Vec<Vec2> = quad.iter().map(|p| screen(*p)).collect();
            let centre = (q[0] + q[1] + q[2] + q[3]) * 0.25;
            assert!(centre.distance(screen(end)) < 1e-4, "same place on screen");
            let side = q[0].distance(q[1]).max(q[0].distance(q[3]));
            let expected = l.width * CAP_SCALE / view.depth(end);
            assert!(
                (side - expected).abs() < 1e-3 * expected.max(1.0),
                "same size"
            );
        }
    }
}

/// The showcase's case: a beam from an emitter inside an opaque turret head (radius 0.45
/// around the emitter point) to 0.6 short of the centre of another such head, seen 0, 2
/// and 4 degrees off its axis from behind either head. The beam quads fade out end-on and
/// the nearer head hides the beam itself; the caps must still light pixels (the old caps,
/// 2.5 widths across at the end points, sat inside or behind the heads: nothing lit from
/// behind either head at any of the three angles).
#[test]
fn an_end_on_beam_shows_past_the_turret_heads() {
    let a = Vec3::new(0.0, 0.0, 0.0);
    let b = Vec3::new(0.0, 0.0, -20.0);
    let l = Laser {
        a,
        b: b - (b - a).normalize() * 0.6,
        width: 0.35,
        color: Rgba::new(1.0, 0.25, 0.15, 1.0),
        intensity: 1.2,
    };
    let mut head = engine::procedural::uv_sphere(0.45, 10, 20);
    head.colors.clear();
    let black = Material::unlit(Rgba::new(0.0, 0.0, 0.0, 1.0));
    let mut batch = LaserBatch::new();
    batch.lasers.push(l);
    let mut renderer = Renderer::new();
    let size = 96;
    let mut target = Target::new(size, size);
    let opts = FrameOptions {
        clear: Some(Rgba::new(0.0, 0.0, 0.0, 1.0)),
        ..Default::default()
    };
    let (mut counts, mut low) = (Vec::new(), false);
    for degrees in [0.0f32, 2.0, 4.0] {
        let off = Vec3::X * degrees.to_radians().sin() + Vec3::Z * degrees.to_radians().cos();
        // Behind the emitter's head looking down the beam, and behind the far head looking
        // back at the emitter.
        for (eye, look, seen) in [
            (a + off * 6.0, b, "behind the emitter"),
            (b - off * 6.0, a, "behind the far head"),
        ] {
            let cam = Camera::look_at(eye, look, Vec3::Y, 1.0, 1.0);
            batch.build(&View::new(&cam, size));
            let [beam, caps] = batch.draws();
            let housing = |at: Vec3| Draw {
                mesh: &head,
                material: &black,
                transform: Mat4::from_translation(at),
            };
            let draws = [housing(a), housing(b), beam, caps];
            renderer.render(draws, &cam, &Lighting::default(), &mut target, &opts);
            let mut lit = 0;
            for y in 0..size {
                for x in 0..size {
                    lit += (target.color_linear(x, y).unwrap().r > 0.1) as u32;
                }
            }
            counts.push(format!("{degrees} degrees {seen}: {lit}"));
            low |= lit < 20;
        }
    }
    println!("pixels lit: {counts:?}");
    assert!(!low, "pixels lit: {counts:?}");
}
