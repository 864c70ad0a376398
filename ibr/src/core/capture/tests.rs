use super::*;
use crate::core::EMPTY;
use engine::{procedural, Mesh};
use glam::{Mat4, Vec2};

const R: f32 = 1.0;
const EYE: Vec3 = Vec3::new(0.0, 0.0, 5.0);

fn sphere() -> Mesh {
    let mut m = procedural::icosphere(R, 4);
    m.colors.clear();
    m
}

fn camera() -> Camera {
    Camera::look_at(EYE, Vec3::ZERO, Vec3::Y, 0.7, 1.0).with_depth_range(0.5, 20.0)
}

fn draw<'a>(mesh: &'a Mesh, material: &'a Material) -> Draw<'a> {
    Draw {
        mesh,
        material,
        transform: Mat4::IDENTITY,
    }
}

#[test]
fn a_capture_holds_the_surface_with_its_camera() {
    let (mesh, mat) = (sphere(), Material::unlit(Rgba::new(0.2, 0.6, 0.9, 1.0)));
    let cam = camera();
    let mut cap = Capturer::new();
    let mut img = DepthImage::new(0, 0, cam);
    cap.capture(
        [draw(&mesh, &mat)],
        &cam,
        &Lighting::default(),
        64,
        64,
        &mut img,
    );
    assert_eq!((img.width(), img.height()), (64, 64));
    assert_eq!(img.camera, cam);
    // Centre pixel: the sphere's nearest point, 5 - 1 along the axis (the icosphere's
    // faces lie within 0.3% of the radius inside the sphere).
    let (_, d) = img.get(32, 32).expect("in the image");
    assert!((d - (EYE.z - R)).abs() < 0.01, "{d}");
    // Every covered pixel sees a point on the sphere; corners see nothing, transparent.
    let mut covered = 0;
    for y in 0..64 {
        for x in 0..64 {
            if let Some(p) = img.world_point(x, y) {
                assert!((p.length() - R).abs() < 0.01, "({x}, {y}): {p}");
                assert!(img.get(x, y).unwrap().0.a > 0.99);
                covered += 1;
            }
        }
    }
    assert!(covered > 500, "{covered}");
    assert_eq!(img.get(0, 0).map(|c| (c.0.a, c.1)), Some((0.0, EMPTY)));
}

#[test]
fn ids_name_the_triangle_seen() {
    let quad = |x: f32| {
        let mut m = procedural::quad(1.0, 1.0);
        m.colors.clear();
        for p in &mut m.positions {
            p.x += x;
        }
        m
    };
    let (left, right) = (quad(-0.8), quad(0.8));
    let mat = Material::unlit(Rgba::WHITE).double_sided(true);
    let cam = camera();
    let mut ids = Vec::new();
    let mut cap = Capturer::new();
    cap.capture_ids(
        [draw(&left, &mat), draw(&right, &mat)],
        &cam,
        64,
        64,
        &mut ids,
    );
    assert_eq!(ids.len(), 64 * 64);
    let at = |p: Vec3| {
        let q = cam.clip_from_world().project_point3(p);
        let px = (Vec2::new(q.x, -q.y) * 0.5 + 0.5) * 64.0;
        ids[px.y as usize * 64 + px.x as usize]
    };
    let n = left.triangle_count() as u32;
    assert!((1..=n).contains(&at(Vec3::new(-0.8, 0.1, 0.0))));
    assert!((n + 1..=2 * n).contains(&at(Vec3::new(0.8, -0.1, 0.0))));
    assert_eq!(at(Vec3::new(0.0, 0.9, 0.0)), 0, "nothing there");
}

#[test]
fn layers_hold_the_front_and_back_of_a_sphere() {
    let mesh = sphere();
    let mat = Material::unlit(Rgba::WHITE).double_sided(true);
    let cam = camera();
    let mut cap = Capturer::new();
    cap.options.cull = Cull::None;
    let ldi = cap.capture_layers(
        || [draw(&mesh, &mat)],
        &cam,
        &Lighting::default(),
        48,
        48,
        8,
    );
    assert_eq!(ldi.depth_complexity(), 2, "a ray crosses a sphere twice");
    let s = ldi.samples(24, 24);
    assert!((s[0].depth - (EYE.z - R)).abs() < 0.01, "{s:?}");
    assert!((s[1].depth - (EYE.z + R)).abs() < 0.01, "{s:?}");
    assert_eq!(ldi.samples(0, 0), &[]);
}

#[test]
fn batches_match_one_by_one_captures_at_any_thread_count() {
    let (mesh, mat) = (sphere(), Material::lit(Rgba::new(0.8, 0.7, 0.2, 1.0)));
    let draws = [draw(&mesh, &mat)];
    let cams: Vec<Camera> = (0..5)
        .map(|k| {
            let a = k as f32 * 1.3;
            Camera::look_at(
                Vec3::new(a.sin(), 0.4, a.cos()) * 4.0,
                Vec3::ZERO,
                Vec3::Y,
                0.8,
                1.0,
            )
        })
        .collect();
    let lighting = Lighting::default();
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .expect("pool")
    };
    let one = pool(1).install(|| capture_batch(&draws, &cams, &lighting, 40, 30));
    let two = pool(2).install(|| capture_batch(&draws, &cams, &lighting, 40, 30));
    assert_eq!(one, two);
    let mut cap = Capturer::new();
    for (c, img) in cams.iter().zip(&one) {
        let mut alone = DepthImage::new(0, 0, *c);
        cap.capture(draws, c, &lighting, 40, 30, &mut alone);
        assert_eq!(&alone, img);
    }
}

#[test]
fn cube_faces_cover_every_direction_once() {
    let eye = Vec3::new(1.0, 2.0, 3.0);
    let cams = cube_cameras(eye, 0.1, 10.0);
    let mut rng = procedural::XorShift::new(5);
    for _ in 0..2000 {
        let d = Vec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        );
        if d.length() < 0.1 {
            continue;
        }
        let p = eye + d.normalize() * 2.0;
        let inside = cams
            .iter()
            .filter(|c| {
                let q = c.clip_from_world() * p.extend(1.0);
                q.w > 0.0 && (q.x / q.w).abs() < 1.0 && (q.y / q.w).abs() < 1.0
            })
            .count();
        assert_eq!(inside, 1, "{d}");
    }
    // +X face: +Y world is down the image (OpenGL's cube-map convention).
    let q = cams[0]
        .clip_from_world()
        .project_point3(eye + Vec3::new(1.0, 0.5, 0.0));
    assert!(q.y < 0.0);
}
