//! Depth: visibility resolved per pixel against the analytic ray cast, stored depth against
//! the analytic depth of the visible surface, and the precision reversed depth buys far
//! from the eye.

use engine::{Camera, Cull};
use glam::{Quat, Vec3};
use tests::compare::{check_raycast, Report};
use tests::scenes::pixel_camera;

const W: u32 = 128;
const H: u32 = 96;

fn camera() -> Camera {
    Camera::look_at(
        Vec3::new(0.4, 0.3, 1.0),
        Vec3::new(0.0, 0.0, -4.0),
        Vec3::Y,
        0.9,
        1.0,
    )
    .with_aspect(W, H)
    .with_depth_range(0.1, 100.0)
}

/// Renders `tris` (each its own draw) in the given order and in reverse, and checks both
/// against the ray cast: which triangle each pixel shows, and its depth.
fn check_depth_order(what: &str, tris: &[[Vec3; 3]], cam: &Camera) -> Report {
    let rev: Vec<[Vec3; 3]> = tris.iter().rev().copied().collect();
    let (fwd, _) = check_raycast(
        &format!("{what}, submitted in order"),
        tris,
        cam,
        W,
        H,
        Cull::None,
    );
    let (bwd, _) = check_raycast(
        &format!("{what}, submitted reversed"),
        &rev,
        cam,
        W,
        H,
        Cull::None,
    );
    assert_eq!(fwd.covered, bwd.covered, "{what}");
    fwd
}

/// `tris` turned by `angle` about the axis from the eye through `pivot`.
fn rolled(tris: &[[Vec3; 3]], cam: &Camera, pivot: Vec3, angle: f32) -> Vec<[Vec3; 3]> {
    let eye = cam.eye();
    let q = Quat::from_axis_angle((pivot - eye).normalize(), angle);
    tris.iter()
        .map(|t| t.map(|p| pivot + q * (p - pivot)))
        .collect()
}

#[test]
fn interpenetrating_triangles_resolve_per_pixel() {
    let cam = camera();
    let v = Vec3::new;
    // Two triangles tilted opposite ways, crossing along a line.
    let pair = [
        [v(-2.0, -1.5, -3.0), v(2.0, -1.5, -5.0), v(0.0, 2.0, -4.0)],
        [v(-2.0, 1.5, -5.0), v(2.0, 1.5, -3.0), v(0.0, -2.0, -4.0)],
    ];
    // Three triangles overlapping cyclically (each above the next): no draw order alone
    // can resolve them, only per-pixel depth.
    let cycle = [
        [v(-2.0, -0.2, -3.0), v(2.0, 0.6, -5.0), v(-2.0, 0.6, -3.0)],
        [v(0.6, -2.0, -3.0), v(-1.2, 2.0, -5.0), v(1.4, -2.0, -3.0)],
        [v(1.6, 1.8, -3.0), v(-1.6, -1.6, -5.0), v(-0.6, -1.9, -3.0)],
    ];
    for k in 0..8 {
        let a = k as f32 * 0.4;
        let r = check_depth_order(
            &format!("pair, roll {a}"),
            &rolled(&pair, &cam, v(0.0, 0.0, -4.0), a),
            &cam,
        );
        assert!(r.covered > (W * H / 8) as u64);
        check_depth_order(
            &format!("cycle, roll {a}"),
            &rolled(&cycle, &cam, v(0.0, 0.0, -4.0), a),
            &cam,
        );
    }
}

#[test]
fn nearly_coplanar_far_surfaces_resolve_with_reversed_depth() {
    // Two tilted quads 60..95 units away, 0.002 apart along their normal. In OpenGL's
    // window depth stored as f32 (1 - near/dist, close to 1) they would be the same number
    // (checked below); in reversed depth (near/dist, close to 0) they are hundreds of
    // ulps apart, so the nearer one must win at every pixel whatever the draw order.
    let cam = Camera::look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 0.8, 1.0)
        .with_aspect(W, H)
        .with_depth_range(0.1, 100.0);
    let normal = Vec3::new(0.25, 0.15, 1.0).normalize();
    let centre = Vec3::new(0.0, 0.0, -77.0);
    let u = normal.cross(Vec3::Y).normalize() * 150.0;
    let w = normal.cross(u).normalize() * 150.0;
    let quad = |offset: f32| {
        let c = centre + normal * offset;
        [
            [c - u - w, c + u - w, c + u + w],
            [c - u - w, c + u + w, c - u + w],
        ]
    };
    const GAP: f32 = 0.002;
    let (far, near) = (quad(0.0), quad(GAP));
    let tris = [far[0], far[1], near[0], near[1]];
    let r = check_depth_order("quads 0.002 apart", &tris, &cam);
    // All of the view is covered (the quads reach past it), and only the near quad shows.
    assert!(r.covered * 10 > (W * H * 9) as u64);

    // The same separation in f32 OpenGL window depth at the view centre is below one ulp.
    let gl = |dist: f32| {
        let clip = cam.gl_view_proj() * Vec3::new(0.0, 0.0, -dist).extend(1.0);
        0.5 * clip.z / clip.w + 0.5
    };
    // Along the view axis the far quad is 77 away and the near one GAP / normal.z nearer.
    let (d_far, d_near) = (77.0, 77.0 - GAP / normal.z);
    assert!(
        (gl(d_far) - gl(d_near)).abs() <= f32::EPSILON,
        "{} vs {}",
        gl(d_far),
        gl(d_near)
    );
}

#[test]
fn orthographic_depth_is_affine_in_distance() {
    // Tilted triangles under an orthographic camera: depth is linear in view distance.
    let cam = pixel_camera(W, H);
    let v = Vec3::new;
    let tris = [
        [
            v(5.0, -5.0, -1.0),
            v(120.0, -20.0, -9.0),
            v(30.0, -90.0, -4.0),
        ],
        [
            v(100.0, -3.0, -8.5),
            v(126.0, -94.0, -0.6),
            v(10.0, -60.0, -5.0),
        ],
    ];
    let r = check_depth_order("orthographic pair", &tris, &cam);
    assert!(r.covered > (W * H / 4) as u64);
}

#[test]
fn pixel_ray_agrees_with_the_reference_ray() {
    let cam = camera();
    let rc = tests::reference::RayCast::new(&cam, W, H);
    for (x, y) in [
        (0.5f32, 0.5f32),
        (64.0, 48.0),
        (127.5, 95.5),
        (10.25, 80.75),
    ] {
        let (origin, dir) = cam.pixel_ray(x, y, W, H);
        let (a, b) = rc.segment(x as f64, y as f64);
        let want = (b - a).normalize();
        let angle = dir.as_dvec3().normalize().dot(want).clamp(-1.0, 1.0).acos();
        assert!(angle < 1e-5, "({x}, {y}): direction off by {angle} rad");
        assert!(
            (origin.as_dvec3() - a).length() < 1e-5,
            "({x}, {y}): origin {origin} vs {a}"
        );
        // The origin lies on the near plane, where reversed depth is 1 and GL depth 0.
        assert!((rc.view_distance(a) - rc.near).abs() < 1e-6 * rc.near);
    }
}

#[test]
fn many_overlapping_triangles_resolve_per_pixel() {
    // Random tilted triangles stacked in depth: each pixel must show the nearest one and
    // store its depth, however many nearer or farther ones were drawn before or after
    // (this also exercises any per-block depth bounds the rasterizer keeps).
    let cam = camera();
    let mut rng = tests::scenes::Rng(77);
    let mut r = |a: f64, b: f64| rng.range(a, b) as f32;
    let tris: Vec<[Vec3; 3]> = (0..60)
        .map(|_| {
            let c = Vec3::new(r(-1.5, 1.5), r(-1.2, 1.2), r(-7.0, -2.0));
            [0, 1, 2].map(|_| c + Vec3::new(r(-1.5, 1.5), r(-1.5, 1.5), r(-1.0, 1.0)))
        })
        .collect();
    let r = check_depth_order("60 random triangles", &tris, &cam);
    assert!(r.covered > (W * H / 2) as u64);
}

/// A triangle textured with a checker whose odd cells are transparent, alpha-tested, in
/// front of an opaque one drawn after it: through the holes the far triangle must show
/// (discarded fragments write no depth), elsewhere the near one.
fn check_alpha_mask_holes(order_near_first: bool) {
    use engine::{AlphaMode, Encoding, Filter, Material, Rgba, Sampler, Scene, Texture, Wrap};
    use std::sync::Arc;
    use tests::compare::EDGE_EPS_PX;
    use tests::reference::{intersect, RayCast};

    let cam = camera();
    let v = Vec3::new;
    let near = [v(-2.5, -2.0, -3.0), v(2.5, -2.0, -3.5), v(0.0, 2.5, -3.2)];
    let far = [v(-3.0, -3.0, -6.0), v(3.0, -3.0, -6.0), v(0.0, 3.0, -5.0)];
    // uv = world (x, y) / 2, so a cell (1/8 of the texture) is 0.25 world units.
    let uv = |p: Vec3| glam::Vec2::new(p.x / 2.0, p.y / 2.0);
    let mut near_mesh = tests::scenes::soup(&[near]);
    near_mesh.uvs = near.iter().map(|&p| uv(p)).collect();
    let holes = Texture::checker(64, 8, Rgba::WHITE, Rgba::new(1.0, 1.0, 1.0, 0.0));
    let masked = Material {
        alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
        sampler: Sampler {
            filter: Filter::Nearest,
            wrap_u: Wrap::Repeat,
            wrap_v: Wrap::Repeat,
        },
        ..Material::unlit(Rgba::new(1.0, 0.0, 0.0, 1.0))
            .with_texture(Arc::new(holes))
            .double_sided(true)
    };
    let opaque = Material::unlit(Rgba::new(0.0, 0.0, 1.0, 1.0)).double_sided(true);
    let mut scene = Scene::default();
    let far_mesh = tests::scenes::soup(&[far]);
    if order_near_first {
        scene.add(near_mesh, masked, glam::Mat4::IDENTITY);
        scene.add(far_mesh, opaque, glam::Mat4::IDENTITY);
    } else {
        scene.add(far_mesh, opaque, glam::Mat4::IDENTITY);
        scene.add(near_mesh, masked, glam::Mat4::IDENTITY);
    }
    let (target, _) = tests::scenes::render(&scene, &cam, W, H, Encoding::Unorm, Cull::None);

    // Reference: 0 = nothing, 1 = the near triangle's solid cell, 2 = the far triangle.
    let rc = RayCast::new(&cam, W, H);
    let (n64, f64_) = (near.map(|p| p.as_dvec3()), far.map(|p| p.as_dvec3()));
    let see = |sx: f64, sy: f64| -> u8 {
        let (a, b) = rc.segment(sx, sy);
        let hit = |t: [glam::DVec3; 3]| intersect(a, b - a, t).filter(|s| (0.0..=1.0).contains(s));
        if let Some(s) = hit(n64) {
            let p = a + (b - a) * s;
            let (cu, cv) = (
                (p.x / 2.0 * 8.0).floor() as i64,
                (p.y / 2.0 * 8.0).floor() as i64,
            );
            if (cu + cv).rem_euclid(2) == 0 {
                return 1;
            }
        }
        if hit(f64_).is_some() {
            2
        } else {
            0
        }
    };
    let (mut wrong, mut holes_seen) = (Vec::new(), 0);
    for y in 0..H {
        for x in 0..W {
            let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
            let want = see(cx, cy);
            let ambiguous = (0..8).any(|k| {
                let a = k as f64 * std::f64::consts::FRAC_PI_4;
                see(cx + EDGE_EPS_PX * a.cos(), cy + EDGE_EPS_PX * a.sin()) != want
            });
            if ambiguous {
                continue;
            }
            let [r, _, b, _] = target.pixel(x, y).expect("inside").to_le_bytes();
            let got = match (r, b) {
                (0, 0) => 0,
                (255, 0) => 1,
                (0, 255) => 2,
                _ => 9,
            };
            if got != want {
                wrong.push((x, y, got, want));
            }
            // A hole: the far triangle seen where the near one is in front of it.
            if want == 2 && rc.cast(cx, cy, &[n64], false).is_some() {
                holes_seen += 1;
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "near first {order_near_first}: {} wrong pixels (x, y, engine, reference; first 10: {:?})",
        wrong.len(),
        &wrong[..wrong.len().min(10)]
    );
    assert!(holes_seen > 500, "only {holes_seen} hole pixels");
}

#[test]
fn alpha_masked_holes_show_what_is_behind() {
    check_alpha_mask_holes(true);
    check_alpha_mask_holes(false);
}
