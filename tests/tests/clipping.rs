//! Clipping: triangles crossing the near (and far) plane at many angles, triangles wholly
//! behind the eye, and huge triangles, against the analytic ray-cast reference (coverage
//! and depth per pixel), plus crack-free coverage of clipped meshes.

use engine::{Camera, Cull, Mesh};
use glam::{Mat4, Quat, Vec3};
use tests::compare::{check_raycast, compare_ids, render_ids, EDGE_EPS_PX};
use tests::reference::{to_f64, RayCast};
use tests::scenes::{render_counts, Lattice, Rng};

const W: u32 = 96;
const H: u32 = 64;

/// A perspective camera somewhere off-axis (not looking along a world axis).
fn camera(far: f32) -> Camera {
    Camera::look_at(
        Vec3::new(0.3, 1.2, 2.0),
        Vec3::new(-0.5, 0.4, -3.0),
        Vec3::Y,
        1.0,
        1.0,
    )
    .with_aspect(W, H)
    .with_depth_range(0.1, far)
}

/// View-space vertices (x right, y up, looking down -z), rolled by `roll` about the view
/// axis and yawed by `yaw`, to world space.
fn place(cam: &Camera, v: [Vec3; 3], roll: f32, yaw: f32) -> [Vec3; 3] {
    let world_from_view = cam.view.inverse();
    let r = Quat::from_rotation_y(yaw) * Quat::from_rotation_z(roll);
    v.map(|p| world_from_view.transform_point3(r * p))
}

/// One triangle, alone, rendered with both culling modes and compared with the ray cast.
/// A triangle with a vertex outside the depth range must be counted as clipped.
fn check_clipped(what: &str, cam: &Camera, tri: [Vec3; 3]) {
    let (near, far) = cam.near_far();
    let depth = |p: Vec3| -(cam.view.as_dmat4() * p.as_dvec3().extend(1.0)).z;
    let crosses = tri
        .iter()
        .any(|&p| depth(p) < near as f64 || depth(p) > far as f64);
    for cull in [Cull::None, Cull::Back] {
        let (_, stats) = check_raycast(&format!("{what} ({cull:?})"), &[tri], cam, W, H, cull);
        if crosses && cull == Cull::None {
            assert_eq!(stats.triangles_clipped, 1, "{what}: {stats:?}");
        }
    }
}

/// View-space triangles that cross the near plane in different ways.
const NEAR_CROSSING: [[[f32; 3]; 3]; 6] = [
    // one vertex behind the eye
    [[0.2, 0.1, 0.5], [-1.5, -1.0, -4.0], [1.2, -0.7, -2.5]],
    // two vertices behind the eye
    [[0.3, -0.2, 1.0], [-0.8, 0.4, 2.0], [0.1, -0.3, -3.0]],
    // one vertex between the eye and the near plane
    [[0.01, 0.02, -0.05], [1.0, -0.5, -2.0], [-1.0, -0.6, -2.5]],
    // one vertex exactly in the eye's plane (w = 0)
    [[0.5, 0.5, 0.0], [-1.0, -1.0, -3.0], [1.0, -1.0, -3.0]],
    // around the line of sight, from behind the eye to far ahead
    [[-5.0, -5.0, 2.0], [5.0, -5.0, 2.0], [0.0, 5.0, -10.0]],
    // nearly edge-on, grazing past the eye
    [[0.05, -0.3, 3.0], [0.0, -0.2, -6.0], [0.4, 0.6, -1.0]],
];

#[test]
fn near_plane_crossings_at_many_angles_match_the_ray_cast() {
    let cam = camera(100.0);
    for (k, v) in NEAR_CROSSING.iter().enumerate() {
        for step in 0..24 {
            let roll = step as f32 * 15f32.to_radians();
            let yaw = [0.0f32, 0.2, -0.35][step % 3];
            let tri = place(&cam, v.map(Vec3::from_array), roll, yaw);
            check_clipped(
                &format!("near-crossing #{k}, roll {step}x15deg, yaw {yaw}"),
                &cam,
                tri,
            );
        }
    }
}

#[test]
fn far_plane_crossings_match_the_ray_cast() {
    let cam = camera(20.0);
    let v = [[0.0, -1.0, -5.0], [-8.0, -3.0, -60.0], [9.0, 2.0, -45.0]].map(Vec3::from_array);
    for step in 0..12 {
        let tri = place(&cam, v, step as f32 * 30f32.to_radians(), 0.1);
        check_clipped(&format!("far-crossing roll {step}x30deg"), &cam, tri);
    }
    // Through both planes at once.
    let v = [
        [0.0, 0.0, 1.0],
        [-20.0, -10.0, -300.0],
        [20.0, -15.0, -250.0],
    ]
    .map(Vec3::from_array);
    for step in 0..12 {
        let tri = place(&cam, v, step as f32 * 30f32.to_radians(), -0.2);
        check_clipped(&format!("near+far roll {step}x30deg"), &cam, tri);
    }
}

/// View-space triangles spanning `s` units (about the view axis, or reaching past both
/// depth planes).
fn huge_cases(s: f32) -> [[Vec3; 3]; 5] {
    let v = Vec3::new;
    [
        // facing the camera, covering the whole view
        [v(-s, -s, -10.0), v(s, -s, -10.0), v(0.0, s, -10.0)],
        // a ground plane below the eye, from behind it to beyond the far plane
        [v(-s, -0.3, -s), v(s, -0.3, -s), v(0.0, -0.3, s)],
        // a long sliver across the view
        [v(-s, 0.5, -20.0), v(s, -0.6, -20.0), v(3.0, 2.0, -5.0)],
        // tilted, one corner near the line of sight, the others beyond the far plane
        [
            v(0.0, 0.0, -3.0),
            v(s, 0.3 * s, -0.5 * s),
            v(-0.4 * s, s, -0.8 * s),
        ],
        // from far behind the eye to a point ahead
        [v(-s, -1.0, s), v(s, -1.0, s), v(0.0, 2.0, -5.0)],
    ]
}

/// Huge triangles, each alone, against the ray cast; collects every failing case so one
/// run shows the whole picture.
fn check_huge(cases: &[(String, Camera, [Vec3; 3])]) {
    let mut failures = Vec::new();
    for (what, cam, tri) in cases {
        for cull in [Cull::None, Cull::Back] {
            let (target, _) = render_ids(&[*tri], cam, W, H, cull);
            let r = compare_ids(&target, &[*tri], cam, cull == Cull::Back);
            if !r.wrong_id.is_empty()
                || !r.wrong_depth.is_empty()
                || r.checked * 10 < (W * H * 9) as u64
            {
                let worst = r
                    .wrong_depth
                    .iter()
                    .map(|&(_, _, d, (lo, hi))| (lo - d as f64).max(d as f64 - hi) / hi.max(1e-30))
                    .fold(0.0, f64::max);
                failures.push(format!(
                    "{what} ({cull:?}): {} wrong ids (first {:?}), {} wrong depths (first {:?}, worst relative error {worst:.2e}), {} checked",
                    r.wrong_id.len(),
                    r.wrong_id.first(),
                    r.wrong_depth.len(),
                    r.wrong_depth.first(),
                    r.checked
                ));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} cases fail:\n{}",
        failures.len(),
        cases.len() * 2,
        failures.join("\n")
    );
}

#[test]
fn huge_triangles_match_the_ray_cast() {
    // A camera looking down -Z from the origin, and quarter turns done by swapping
    // coordinates: the huge coordinates then reach clip space with only relative `f32`
    // rounding. (A general rotation would round a 1e6 coordinate by ~0.06 units before the
    // pipeline sees it, which no `f32` pipeline can undo.)
    let cam = Camera::look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 1.0, 1.0)
        .with_aspect(W, H)
        .with_depth_range(0.1, 1000.0);
    let mut cases = Vec::new();
    for s in [1e4f32, 1e5, 1e6] {
        for (k, tri) in huge_cases(s).iter().enumerate() {
            let mut tri = *tri;
            for quarter in 0..4 {
                cases.push((
                    format!("huge #{k} at {s:e}, {quarter} quarter turns"),
                    cam,
                    tri,
                ));
                tri = tri.map(|p| Vec3::new(-p.y, p.x, p.z));
            }
        }
    }
    // Off-axis, at a scale where `f32` rounding of the rotated coordinates (~1e4 * 2^-24)
    // stays far below the edge tolerance.
    let cam = camera(1000.0);
    for (k, v) in huge_cases(1e4).iter().enumerate() {
        for step in 0..4 {
            cases.push((
                format!("huge off-axis #{k}, roll {step}x0.7"),
                cam,
                place(&cam, *v, step as f32 * 0.7, 0.05),
            ));
        }
    }
    check_huge(&cases);
}

#[test]
fn triangles_wholly_behind_the_eye_draw_nothing() {
    let cam = camera(100.0);
    let cases: [[[f32; 3]; 3]; 4] = [
        [[-1.0, -1.0, 1.0], [1.0, -1.0, 1.0], [0.0, 1.0, 1.0]],
        [[-1e5, -1e5, 5.0], [1e5, -1e5, 5.0], [0.0, 1e5, 0.5]],
        // behind the eye but spread over every side of it
        [[-3.0, 0.0, 0.01], [3.0, -3.0, 2.0], [3.0, 3.0, 0.2]],
        // touching the eye's plane from behind
        [[0.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]],
    ];
    for (k, v) in cases.iter().enumerate() {
        for step in 0..6 {
            let tri = place(&cam, v.map(Vec3::from_array), step as f32, 0.3);
            let (target, stats) = render_ids(&[tri], &cam, W, H, Cull::None);
            let drawn = (0..H)
                .flat_map(|y| (0..W).map(move |x| (x, y)))
                .filter(|&(x, y)| {
                    target.depth_reversed(x, y) != Some(0.0)
                        || target.pixel(x, y) != Some(0xff00_0000)
                })
                .count();
            assert_eq!(drawn, 0, "behind #{k} step {step}: {stats:?}");
            assert_eq!(
                stats.fragments_tested, 0,
                "behind #{k} step {step}: {stats:?}"
            );
            assert_eq!(
                stats.triangles_set_up, 0,
                "behind #{k} step {step}: {stats:?}"
            );
        }
    }
}

/// A jittered grid over the rectangle `[-half, half]^2` of the plane through `centre`
/// spanned by unit vectors `u`, `v`: only interior vertices move (within the plane), so the
/// union is exactly the rectangle.
fn plane_mesh(
    centre: Vec3,
    u: Vec3,
    v: Vec3,
    half: f32,
    cells: i32,
    seed: u64,
) -> (Mesh, [[Vec3; 3]; 2]) {
    let mut rng = Rng(seed);
    let n = cells / 2;
    let step = half as f64 / n as f64;
    let side = (2 * n + 1) as usize;
    let jit: Vec<(f64, f64)> = (0..side * side)
        .map(|_| (rng.range(-0.2, 0.2) * step, rng.range(-0.2, 0.2) * step))
        .collect();
    let diag: Vec<bool> = (0..side * side).map(|_| rng.below(2) == 0).collect();
    let at = |i: i32, j: i32| (j + n) as usize * side + (i + n) as usize;
    let lattice = Lattice {
        origin: (0.0, 0.0),
        a: (step, 0.0),
        b: (0.0, step),
        n,
        diagonal: &|i, j| diag[at(i, j)],
        flip: &|i, j| (i ^ j) & 4 == 0,
        jitter: &|i, j| {
            if i.abs() == n || j.abs() == n {
                (0.0, 0.0)
            } else {
                jit[at(i, j)]
            }
        },
    };
    let m = lattice.build(&|a, b| centre + u * a as f32 + v * b as f32);
    let c = |a: f32, b: f32| centre + u * a + v * b;
    let rect = [
        [c(-half, -half), c(half, -half), c(half, half)],
        [c(-half, -half), c(half, half), c(-half, half)],
    ];
    (m, rect)
}

/// A clipped mesh: every pixel is covered at most once, and wherever the ray cast against
/// the mesh's outline is unambiguous, exactly as often as it says (0 or 1).
fn check_clipped_mesh(what: &str, cam: &Camera, mesh: &Mesh, outline: &[[Vec3; 3]; 2]) {
    let (w, h) = (160, 120);
    let (got, stats) = render_counts(std::slice::from_ref(mesh), cam, w, h);
    assert!(
        stats.triangles_clipped > 0,
        "{what}: nothing was clipped: {stats:?}"
    );
    let rc = RayCast::new(cam, w, h);
    let o = to_f64(outline);
    let (mut doubles, mut wrong, mut ambiguous, mut covered) = (0, Vec::new(), 0, 0);
    for y in 0..h {
        for x in 0..w {
            let g = got.get(x, y);
            if g > 1 {
                doubles += 1;
            }
            let want = rc.cast_pixel(x, y, &o, false).is_some();
            if rc
                .ring(x, y, EDGE_EPS_PX, &o, false)
                .iter()
                .any(|s| s.is_some() != want)
            {
                ambiguous += 1;
                continue;
            }
            covered += want as u32;
            if g != want as u32 {
                wrong.push((x, y, g, want));
            }
        }
    }
    assert!(
        doubles == 0 && wrong.is_empty(),
        "{what}: {doubles} pixels covered twice or more; {} pixels wrong (x, y, count, covered; first 10: {:?})",
        wrong.len(),
        &wrong[..wrong.len().min(10)]
    );
    assert!(
        ambiguous * 20 < w * h,
        "{what}: {ambiguous} ambiguous pixels"
    );
    assert!(
        covered * 10 > w * h,
        "{what}: only {covered} pixels covered"
    );
}

#[test]
fn clipped_meshes_have_no_cracks() {
    // Ground planes just below the eye, reaching past the guard band and the far plane, so
    // shared edges are cut by the near, far and guard-band planes.
    for (k, (height, pitch, roll)) in [
        (0.03f32, -0.3f32, 0.0f32),
        (0.08, -0.6, 0.3),
        (0.5, -0.2, -0.5),
        (0.02, -1.2, 1.0),
    ]
    .into_iter()
    .enumerate()
    {
        let rot = Mat4::from_rotation_z(roll) * Mat4::from_rotation_x(pitch);
        let cam = Camera {
            view: rot.inverse() * Mat4::from_translation(Vec3::new(0.0, -height, 0.0)),
            ..Camera::look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 1.0, 4.0 / 3.0)
                .with_depth_range(0.1, 60.0)
        };
        let (m, outline) = plane_mesh(
            Vec3::new(0.3, 0.0, -2.0),
            Vec3::X,
            Vec3::Z,
            400.0,
            120,
            k as u64,
        );
        check_clipped_mesh(&format!("ground #{k}"), &cam, &m, &outline);
    }
    // A wall running from behind the eye to far ahead at 20 degrees to the view
    // direction, 0.025 to its right: the near plane cuts it inside the view.
    let cam = Camera::look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 1.2, 4.0 / 3.0)
        .with_depth_range(0.1, 30.0);
    let (sin, cos) = 20f32.to_radians().sin_cos();
    let u = Vec3::new(sin, 0.0, -cos);
    let (m, outline) = plane_mesh(Vec3::new(0.025, 0.0, 0.0), u, Vec3::Y, 50.0, 80, 9);
    check_clipped_mesh("wall", &cam, &m, &outline);
}
