//! Portals against the geometry they stand for: a wall with a doorway at z = 0 (the near
//! side is +z) and a furnished room behind it, rendered with the portal and as full
//! geometry from the same eyes.

use super::*;
use crate::core::FrameLoop;
use engine::{procedural, FrameOptions, Material, Mesh, Renderer, Rgba};
use glam::{Mat4, Vec3};
use std::sync::Arc;

const W: u32 = 160;
const H: u32 = 120;

fn lighting() -> Lighting {
    Lighting::white_sun(0.35, Vec3::new(-0.4, -1.0, -0.3))
}

fn lit(r: f32, g: f32, b: f32) -> Arc<Material> {
    Arc::new(Material::lit(Rgba::new(r, g, b, 1.0)).double_sided(true))
}

/// The doorway: 1.2 wide, 2 high, in the wall z = 0, facing +z.
fn doorway() -> Opening {
    Opening::upright(Vec3::ZERO, 1.2, 2.0, Vec3::Z)
}

/// The near wall around the doorway (three quads), facing +z.
fn near_wall() -> (Mesh, Arc<Material>) {
    let wall = procedural::doorway_wall(-4.0, 4.0, 3.0, &[(0.0, 1.2, 2.0)]);
    (wall, lit(0.8, 0.75, 0.6))
}

/// The room behind: floor, ceiling, back and side walls, boxes at several depths, and a torus of
/// about `triangles` triangles (the furniture whose count the frame must not follow).
fn room(triangles: u32) -> MeshGroup {
    let slab = |size: Vec3| Arc::new(procedural::cuboid(size));
    MeshGroup::new()
        .with(
            slab(Vec3::new(6.0, 0.1, 6.0)),
            lit(0.5, 0.45, 0.4),
            Mat4::from_translation(Vec3::new(0.0, -0.05, -3.0)),
        )
        .with(
            slab(Vec3::new(6.0, 0.1, 6.0)),
            lit(0.9, 0.9, 0.85),
            Mat4::from_translation(Vec3::new(0.0, 3.05, -3.0)),
        )
        .with(
            slab(Vec3::new(6.0, 3.0, 0.1)),
            lit(0.3, 0.5, 0.7),
            Mat4::from_translation(Vec3::new(0.0, 1.5, -6.0)),
        )
        .with(
            slab(Vec3::new(0.1, 3.0, 6.0)),
            lit(0.6, 0.6, 0.3),
            Mat4::from_translation(Vec3::new(3.0, 1.5, -3.0)),
        )
        .with(
            slab(Vec3::new(0.1, 3.0, 6.0)),
            lit(0.7, 0.4, 0.3),
            Mat4::from_translation(Vec3::new(-3.0, 1.5, -3.0)),
        )
        .with(
            slab(Vec3::new(0.6, 0.8, 0.6)),
            lit(0.9, 0.2, 0.2),
            Mat4::from_translation(Vec3::new(-0.5, 0.4, -2.0)),
        )
        .with(
            slab(Vec3::new(0.8, 1.2, 0.5)),
            lit(0.2, 0.8, 0.3),
            Mat4::from_translation(Vec3::new(0.9, 0.6, -4.0)),
        )
        .with(
            Arc::new(procedural::torus_with_triangles(triangles)),
            lit(0.9, 0.8, 0.2),
            Mat4::from_translation(Vec3::new(0.2, 1.2, -3.0)) * Mat4::from_rotation_x(0.8),
        )
}

fn camera(eye: Vec3) -> Camera {
    Camera::look_at(
        eye,
        Vec3::new(0.0, 1.0, -2.0),
        Vec3::Y,
        1.0,
        W as f32 / H as f32,
    )
    .with_depth_range(0.05, 60.0)
}

/// Portals with 256-pixel LDIs, each built within one frame (five views a frame).
fn config() -> PortalConfig {
    PortalConfig {
        side: 256,
        views_per_frame: 5,
        ..PortalConfig::default()
    }
}

/// A frame of the near wall (plus `extra` near geometry) with the portals, and its
/// renderer counters.
fn render(
    portals: &mut Portals,
    cam: &Camera,
    extra: &[(Mesh, Arc<Material>)],
) -> (Target, FrameStats) {
    let (wall, wall_mat) = near_wall();
    let mut scene = vec![Draw {
        mesh: &wall,
        material: &wall_mat,
        transform: Mat4::IDENTITY,
    }];
    for (m, mat) in extra {
        scene.push(Draw {
            mesh: m,
            material: mat,
            transform: Mat4::IDENTITY,
        });
    }
    let light = lighting();
    let view = FrameView {
        camera: cam,
        width: W,
        height: H,
        lighting: &light,
        time: 0.0,
        dt: 0.0,
    };
    let mut target = Target::new(W, H);
    let mut list: [&mut dyn Technique; 1] = [portals];
    let stats = FrameLoop::new().render(
        &mut Renderer::new(),
        scene,
        &mut list,
        &view,
        &mut target,
        &FrameOptions::default(),
    );
    (target, stats)
}

/// The same frame drawn as full geometry (the portals' reference geometry included).
fn truth(portals: &Portals, cam: &Camera, extra: &[(Mesh, Arc<Material>)]) -> Target {
    let (wall, wall_mat) = near_wall();
    let mut draws = vec![Draw {
        mesh: &wall,
        material: &wall_mat,
        transform: Mat4::IDENTITY,
    }];
    for (m, mat) in extra {
        draws.push(Draw {
            mesh: m,
            material: mat,
            transform: Mat4::IDENTITY,
        });
    }
    portals.reference(&mut draws);
    let mut target = Target::new(W, H);
    Renderer::new().render(
        draws,
        cam,
        &lighting(),
        &mut target,
        &FrameOptions::default(),
    );
    target
}

/// Of the pixels inside `outline`: the fraction whose colour differs from `b`'s by more
/// than `tol` (8-bit levels, any channel), and the mean absolute difference (levels, over
/// RGB).
fn off_inside(a: &Target, b: &Target, outline: &Outline, tol: u8) -> (f32, f32) {
    let [x0, y0, x1, y1] = outline.bounds;
    let (mut n, mut off, mut sum) = (0, 0, 0u64);
    for y in y0..y1 {
        for x in x0..x1 {
            if !outline.contains(x, y) {
                continue;
            }
            n += 1;
            let (p, q) = (a.pixel(x, y).unwrap(), b.pixel(x, y).unwrap());
            let (p, q) = (p.to_le_bytes(), q.to_le_bytes());
            if (0..3).any(|k| p[k].abs_diff(q[k]) > tol) {
                off += 1;
            }
            sum += (0..3).map(|k| p[k].abs_diff(q[k]) as u64).sum::<u64>();
        }
    }
    let n = n.max(1) as f32;
    (off as f32 / n, sum as f32 / (3.0 * n))
}

fn portals(triangles: u32) -> Portals {
    Portals::new(vec![Portal::new(doorway(), room(triangles))], config())
}

#[test]
fn through_the_doorway_the_warped_room_matches_the_geometry() {
    for eye in [Vec3::new(0.3, 1.5, 4.0), Vec3::new(-1.2, 1.2, 3.0)] {
        let mut p = portals(2_000);
        let cam = camera(eye);
        let (frame, _) = render(&mut p, &cam, &[]);
        assert_eq!(p.portals[0].mode(), PortalMode::Warped, "{eye}");
        let want = truth(&p, &cam, &[]);
        let outline = doorway().outline(&cam, W, H).unwrap();
        assert!(outline.area_px() > 1000, "{eye}: {}", outline.area_px());
        // Resampling the LDI differs from the geometry at silhouettes (a few percent of the
        // doorway's pixels, up to 60 levels each: about 3 levels of the mean).
        let (off, mae) = off_inside(&frame, &want, &outline, 24);
        assert!(
            off < 0.08 && mae < 6.0,
            "{eye}: {off} of the doorway's pixels off, {mae} levels"
        );
        // Outside the doorway the frame is the near wall's alone.
        let mut none = Portals::new(Vec::new(), config());
        let (wall_only, _) = render(&mut none, &cam, &[]);
        for y in 0..H {
            for x in 0..W {
                if !outline.contains(x, y) {
                    assert_eq!(frame.pixel(x, y), wall_only.pixel(x, y), "{eye} ({x}, {y})");
                }
            }
        }
    }
}

#[test]
fn the_frame_does_not_follow_the_triangles_behind_the_doorway() {
    let cam = camera(Vec3::new(0.3, 1.5, 4.0));
    let run = |triangles: u32| {
        let mut p = portals(triangles);
        let (_, stats) = render(&mut p, &cam, &[]);
        (stats.triangles_in, p.counters())
    };
    let (few, c_few) = run(1_000);
    let (many, c_many) = run(100_000);
    // The rasterizer is given the near wall alone either way; the warp's samples come from
    // an LDI of fixed size, whatever the furniture's triangle count.
    assert_eq!(few, many);
    let ratio = c_many.samples as f64 / c_few.samples as f64;
    assert!(
        (0.9..1.1).contains(&ratio),
        "{} against {}",
        c_many.samples,
        c_few.samples
    );
    assert_eq!(c_few.geometry, 0);
    // As geometry the same view sets up the furniture too.
    let mut g = portals(100_000);
    g.portals[0].opening = Opening::upright(Vec3::new(0.0, 0.0, 5.0), 1.2, 2.0, Vec3::Z);
    let (_, geometry) = render(&mut g, &cam, &[]);
    assert!(
        geometry.triangles_in > many + 90_000,
        "{}",
        geometry.triangles_in
    );
}

#[test]
fn near_geometry_in_front_of_the_doorway_hides_the_warped_room() {
    let cam = camera(Vec3::new(0.3, 1.5, 4.0));
    // A post in front of the doorway, on the near side.
    let post = (
        {
            let mut m = procedural::cuboid(Vec3::new(0.25, 3.0, 0.25));
            for v in &mut m.positions {
                *v += Vec3::new(0.1, 1.5, 1.0);
            }
            m
        },
        lit(0.1, 0.1, 0.9),
    );
    let extra = [post];
    let mut p = portals(2_000);
    let (frame, _) = render(&mut p, &cam, &extra);
    let want = truth(&p, &cam, &extra);
    let outline = doorway().outline(&cam, W, H).unwrap();
    let (off, mae) = off_inside(&frame, &want, &outline, 24);
    assert!(off < 0.08 && mae < 6.0, "{off} {mae}");
    // The post's pixels inside the doorway (where the truth changes with the post) show
    // the post.
    let without = truth(&p, &cam, &[]);
    let (mut post_px, mut shown) = (0, 0);
    let [x0, y0, x1, y1] = outline.bounds;
    for y in y0..y1 {
        for x in x0..x1 {
            if outline.contains(x, y) && want.pixel(x, y) != without.pixel(x, y) {
                post_px += 1;
                shown += (frame.pixel(x, y) == want.pixel(x, y)) as u32;
            }
        }
    }
    assert!(
        post_px > 50 && shown * 10 >= post_px * 9,
        "{shown} of {post_px}"
    );
}

#[test]
fn at_the_doorway_and_past_it_the_room_is_geometry_without_a_pop() {
    let mut p = portals(2_000);
    // Just outside the switch distance: warped; just inside: geometry. Both close to the
    // truth, so crossing shows no jump.
    let before = camera(Vec3::new(0.1, 1.4, 1.05));
    let (frame, _) = render(&mut p, &before, &[]);
    assert_eq!(p.portals[0].mode(), PortalMode::Warped);
    let outline = doorway().outline(&before, W, H).unwrap();
    let (off, mae) = off_inside(&frame, &truth(&p, &before, &[]), &outline, 24);
    assert!(
        off < 0.08 && mae < 6.0,
        "just before the doorway: {off} {mae}"
    );
    for eye in [
        Vec3::new(0.1, 1.4, 0.95),
        Vec3::new(0.1, 1.4, 0.0),
        Vec3::new(0.1, 1.4, -1.0),
    ] {
        let cam = camera(eye);
        let (_, stats) = render(&mut p, &cam, &[]);
        assert_eq!(p.portals[0].mode(), PortalMode::Geometry, "{eye}");
        assert!(stats.triangles_in > 2000, "{eye}: the room is drawn");
    }
}

#[test]
fn leaving_the_region_rebuilds_within_the_budget() {
    let second = Portal::new(
        Opening::upright(Vec3::new(2.5, 0.0, 0.0), 1.0, 2.0, Vec3::Z),
        room(500),
    );
    let mut p = Portals::new(vec![Portal::new(doorway(), room(500)), second], config());
    let cam = camera(Vec3::new(1.0, 1.5, 5.0));
    p.update(&cam, W, H, &lighting());
    // One rebuild a frame: the first frame builds one portal, the other shows geometry.
    assert_eq!((p.last().rebuilds, p.last().stale), (1, 1));
    assert_eq!(p.last().geometry, 1);
    p.update(&cam, W, H, &lighting());
    assert_eq!(
        (p.last().rebuilds, p.last().stale, p.last().warped),
        (1, 0, 2)
    );
    // Within reach: nothing to rebuild.
    let near = camera(Vec3::new(1.2, 1.5, 5.1));
    p.update(&near, W, H, &lighting());
    assert_eq!(p.last().rebuilds, 0);
    // Far out of the region: rebuilt, one a frame, the other warped stale meanwhile.
    let far = camera(Vec3::new(-1.0, 1.5, 3.5));
    p.update(&far, W, H, &lighting());
    assert_eq!(
        (p.last().rebuilds, p.last().stale, p.last().warped),
        (1, 1, 2)
    );
    assert_eq!(p.portals.iter().map(Portal::rebuilds).sum::<u64>(), 3);
}

#[test]
fn odd_eyes_and_sizes_give_no_nan_and_no_panic() {
    let mut p = portals(500);
    for eye in [
        Vec3::new(0.0, 1.0, 0.3001),
        Vec3::new(0.0, 1.0, 1e-6),
        Vec3::new(40.0, 1.0, 0.01),
        Vec3::new(0.0, 50.0, 2.0),
        Vec3::new(0.0, 1.0, 1e6),
    ] {
        for (w, h) in [(W, H), (1, 1), (0, 0), (3, 200)] {
            let cam = Camera::look_at(eye, Vec3::new(0.0, 1.0, -2.0), Vec3::Y, 1.0, 1.3)
                .with_depth_range(0.05, 60.0);
            p.update(&cam, w, h, &lighting());
            assert!(p.image().disparity.iter().all(|d| !d.is_nan()));
        }
    }
}

#[test]
fn the_same_pixels_at_any_thread_count() {
    let cam = camera(Vec3::new(-0.4, 1.3, 3.0));
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(|| render(&mut portals(2_000), &cam, &[]).0)
    };
    let one = run(1);
    assert!(run(2) == one && run(3) == one);
}

#[test]
fn flat_and_single_image_portals_are_right_from_their_eye_and_worse_elsewhere() {
    // Built at one eye, seen from another within the region: the LDI is nearest the
    // truth, the flat image (no parallax) farthest; from the build eye all three are close.
    let build = Vec3::new(0.3, 1.5, 4.0);
    let moved = Vec3::new(0.75, 1.5, 4.0);
    let mut errors = Vec::new();
    for image in [PortalImage::Ldi, PortalImage::DepthImage, PortalImage::Flat] {
        let mut p = Portals::new(
            vec![Portal::new(doorway(), room(2_000))],
            PortalConfig { image, ..config() },
        );
        let at_build = camera(build);
        let (frame, _) = render(&mut p, &at_build, &[]);
        let outline = doorway().outline(&at_build, W, H).unwrap();
        let (_, mae) = off_inside(&frame, &truth(&p, &at_build, &[]), &outline, 24);
        assert!(mae < 6.0, "{image:?} at its eye: {mae}");
        let cam = camera(moved);
        let (frame, _) = render(&mut p, &cam, &[]);
        assert_eq!(p.last().rebuilds, 0, "{image:?}: still within reach");
        let outline = doorway().outline(&cam, W, H).unwrap();
        errors.push(off_inside(&frame, &truth(&p, &cam, &[]), &outline, 24).1);
    }
    let [ldi, single, flat] = errors[..] else {
        unreachable!()
    };
    assert!(ldi <= single + 0.5 && single < flat, "{errors:?}");
}

#[test]
fn a_rebuild_is_spread_over_frames_and_the_old_ldi_shown_meanwhile() {
    let mut p = Portals::new(
        vec![Portal::new(doorway(), room(500))],
        PortalConfig {
            views_per_frame: 2,
            ..config()
        },
    );
    let here = camera(Vec3::new(0.3, 1.5, 4.0));
    // Five views at two a frame: geometry until the third frame, which merges the LDI.
    let mut seen = Vec::new();
    for _ in 0..3 {
        p.update(&here, W, H, &lighting());
        let f = p.last();
        assert!(f.views <= 2, "{f:?}");
        seen.push((f.views, f.rebuilds, p.portals[0].mode()));
    }
    assert_eq!(
        seen,
        [
            (2, 0, PortalMode::Geometry),
            (2, 0, PortalMode::Geometry),
            (1, 1, PortalMode::Warped)
        ]
    );
    // Far from there: the old LDI is warped while the new one is captured.
    let there = camera(Vec3::new(-1.0, 1.5, 3.0));
    for k in 0..3 {
        p.update(&there, W, H, &lighting());
        assert_eq!(p.portals[0].mode(), PortalMode::Warped, "frame {k}");
        assert_eq!(p.last().rebuilds, (k == 2) as u64, "frame {k}");
    }
    assert_eq!(p.portals[0].rebuilds(), 2);
}

#[test]
fn a_predicted_error_over_the_tolerance_rebuilds_inside_the_region() {
    // A small move inside the region: rebuilt when the tolerance is tight, kept when not;
    // the prediction grows with the move and is zero at the build eye.
    let build = camera(Vec3::new(0.3, 1.5, 4.0));
    let moved = camera(Vec3::new(0.5, 1.5, 4.0));
    for (tolerance, rebuilt) in [(0.5, true), (1000.0, false)] {
        let mut p = Portals::new(
            vec![Portal::new(doorway(), room(500))],
            PortalConfig {
                tolerance_px: tolerance,
                ..config()
            },
        );
        p.update(&build, W, H, &lighting());
        assert_eq!(p.last().rebuilds, 1);
        p.update(&build, W, H, &lighting());
        assert!(
            p.last().predicted_px < 1e-3,
            "at the build eye: {}",
            p.last().predicted_px
        );
        assert_eq!(p.last().rebuilds, 0);
        p.update(&moved, W, H, &lighting());
        assert_eq!(p.last().rebuilds == 1, rebuilt, "tolerance {tolerance}");
        if !rebuilt {
            let small = p.last().predicted_px;
            p.update(&camera(Vec3::new(0.9, 1.5, 4.0)), W, H, &lighting());
            assert!(
                small > 0.5 && p.last().predicted_px > small,
                "{small} then {}",
                p.last().predicted_px
            );
        }
    }
}

#[test]
fn a_room_entered_through_the_next_door_culls_this_one() {
    // Two doorways side by side in one wall, each with its room: walking through the
    // first, the eye passes the second's plane too, but is not in its room.
    let beside = |room: MeshGroup| {
        let shift = Mat4::from_translation(Vec3::new(7.0, 0.0, 0.0));
        let mut draws = Vec::new();
        room.draws(&mut draws);
        draws.iter().fold(MeshGroup::new(), |g, d| {
            g.with(
                Arc::new(d.mesh.clone()),
                Arc::new(d.material.clone()),
                shift * d.transform,
            )
        })
    };
    let second = Portal::new(
        Opening::upright(Vec3::new(7.0, 0.0, 0.0), 1.0, 2.0, Vec3::Z),
        beside(room(3_000)),
    );
    let mut p = Portals::new(vec![Portal::new(doorway(), room(500)), second], config());
    for z in [3.0, 1.0, 0.5, 0.0, -1.0, -2.5] {
        let cam = camera(Vec3::new(0.1, 1.4, z));
        let (_, stats) = render(&mut p, &cam, &[]);
        if z <= 0.0 {
            assert_eq!(p.portals[0].mode(), PortalMode::Geometry, "{z}");
            assert_eq!(p.portals[1].mode(), PortalMode::Culled, "{z}");
            assert!(
                stats.triangles_in < 3_000,
                "{z}: the other room is not drawn"
            );
        }
    }
    // Dropped into the second room (no history): inside its box, so geometry.
    let mut q = Portals::new(
        vec![Portal::new(
            Opening::upright(Vec3::new(7.0, 0.0, 0.0), 1.0, 2.0, Vec3::Z),
            beside(room(500)),
        )],
        config(),
    );
    render(&mut q, &camera(Vec3::new(8.0, 1.4, -2.0)), &[]);
    assert_eq!(q.portals[0].mode(), PortalMode::Geometry);
    // Past the plane beside the room, outside it: culled.
    render(&mut q, &camera(Vec3::new(0.0, 1.4, -2.0)), &[]);
    assert_eq!(q.portals[0].mode(), PortalMode::Culled);
}

#[test]
fn a_rows_span_is_the_pixels_the_outline_contains() {
    // Openings of every tilt seen from eyes all round, some near enough to be clipped by
    // the near plane: each row's span holds exactly the pixels `contains` takes.
    let mut rng = procedural::XorShift::new(5);
    let mut unit = || (rng.next_u64() % 2001) as f32 / 1000.0 - 1.0;
    let (mut rows, mut pixels) = (0, 0);
    for _ in 0..200 {
        let base = Vec3::new(unit(), unit() * 0.5, unit());
        let toward = Vec3::new(unit(), 0.0, unit() + 0.01);
        let mut opening =
            Opening::upright(base, 0.5 + unit().abs(), 0.5 + 2.0 * unit().abs(), toward);
        // A skewed corner too: still planar-ish and convex on screen.
        opening.corners[2] += Vec3::new(0.1 * unit(), 0.1 * unit(), 0.0);
        let eye = Vec3::new(3.0 * unit(), 1.0 + unit(), 3.0 * unit()) + opening.normal() * 0.3;
        let cam = Camera::look_at(eye, opening.center(), Vec3::Y, 1.0, W as f32 / H as f32);
        let Some(outline) = opening.outline(&cam, W, H) else {
            continue;
        };
        let [x0, y0, x1, y1] = outline.bounds;
        for y in y0..y1 {
            let (a, b) = outline.span(y);
            let inside: Vec<u32> = (x0..x1).filter(|&x| outline.contains(x, y)).collect();
            assert_eq!(inside, (a..b).collect::<Vec<_>>(), "row {y} of {outline:?}");
            rows += 1;
            pixels += inside.len();
        }
    }
    assert!(
        rows > 1000 && pixels > 10_000,
        "{rows} rows, {pixels} pixels"
    );
}

#[test]
fn the_opening_sees_what_lies_in_the_pyramid_through_it() {
    let door = doorway();
    let eye = Vec3::new(2.0, 1.5, 3.0);
    // Straight through the doorway from the eye, and far off to the side behind the wall.
    let through = eye + (door.center() - eye) * 2.0;
    assert!(door.sees(eye, through, 0.1));
    assert!(!door.sees(eye, Vec3::new(2.2, 1.2, -3.0), 1.3));
    // On the near side of the wall: not behind the opening.
    assert!(!door.sees(eye, Vec3::new(0.0, 1.0, 2.0), 0.5));
    // From on or past the plane everything may be seen.
    assert!(door.sees(Vec3::new(0.0, 1.0, -1.0), Vec3::new(2.2, 1.2, -3.0), 0.1));
    assert!(door.sees(eye, Vec3::NAN, 1.0));
}

#[test]
fn a_room_drawn_as_geometry_from_the_hall_sets_up_only_what_the_doorway_shows() {
    // A torus behind the wall to the right, out of sight through the doorway from an eye
    // to the right of it (which sees the room's left side).
    let hidden = 20_000;
    let behind = room(500).with(
        Arc::new(procedural::torus_with_triangles(hidden)),
        lit(0.2, 0.2, 0.9),
        Mat4::from_translation(Vec3::new(2.2, 1.2, -3.0)) * Mat4::from_scale(Vec3::splat(0.6)),
    );
    let radius = behind.parts.last().unwrap().bounds().radius;
    assert!(radius < 1.3, "the torus's sphere: {radius}");
    // No views captured: the portal has no LDI and draws its geometry.
    let cfg = PortalConfig {
        views_per_frame: 0,
        ..config()
    };
    let mut p = Portals::new(vec![Portal::new(doorway(), behind)], cfg);
    let cam = camera(Vec3::new(2.0, 1.5, 3.0));
    let (frame, stats) = render(&mut p, &cam, &[]);
    assert_eq!(p.portals[0].mode(), PortalMode::Geometry);
    let f = p.last();
    let q = &p.portals[0];
    let tris = |k: usize| (q.behind.parts[k].mesh.indices.len() / 3) as u64;
    let all: u64 = (0..q.behind.parts.len()).map(tris).sum();
    let torus = tris(q.behind.parts.len() - 1);
    // The torus (and any box or wall out of the doorway's sight) left out, and counted.
    assert_eq!(q.shown.last(), Some(&false));
    assert_eq!(
        f.hidden_parts,
        q.shown.iter().filter(|s| !**s).count() as u64
    );
    assert!(f.hidden_parts >= 1);
    let drawn: u64 = (0..q.shown.len()).filter(|&k| q.shown[k]).map(tris).sum();
    assert_eq!(f.triangles, drawn);
    assert!(drawn <= all - torus);
    assert!(
        stats.triangles_in < all - torus / 2,
        "{} triangles set up of {all}",
        stats.triangles_in
    );
    // The pixels are those of the whole room drawn: what was left out was hidden.
    let truth = truth(&p, &cam, &[]);
    let differ = (0..H)
        .flat_map(|y| (0..W).map(move |x| (x, y)))
        .filter(|&(x, y)| frame.pixel(x, y) != truth.pixel(x, y))
        .count();
    assert_eq!(differ, 0, "pixels differ from the whole room's");
}

#[test]
fn a_path_prepared_ahead_warps_every_frame_without_capturing() {
    let path: Vec<Camera> = (0..8)
        .map(|i| camera(Vec3::new(-1.5 + 0.4 * i as f32, 1.5, 4.0)))
        .collect();
    let mut p = Portals::new(vec![Portal::new(doorway(), room(500))], config());
    p.config.views_per_frame = 1;
    let built = p.prepare_path(path.iter().copied(), W, H, &lighting());
    assert!(
        built >= 1 && p.portals[0].rebuilds() == 0,
        "{built} built ahead"
    );
    // The same walk building its LDIs in its frames, each whole in the frame it starts.
    let mut live = Portals::new(vec![Portal::new(doorway(), room(500))], config());
    for cam in &path {
        let (frame, _) = render(&mut p, cam, &[]);
        let f = p.last();
        // Each frame takes the LDI built for it: no view captured, no stale image.
        assert_eq!(
            (f.views, f.rebuilds, f.stale, f.warped),
            (0, 0, 0, 1),
            "{f:?}"
        );
        // And draws what the walk building that LDI in its frame draws.
        let (want, _) = render(&mut live, cam, &[]);
        assert!(frame == want, "{cam:?}");
    }
    assert_eq!(p.portals[0].built_ahead(), built);
    assert_eq!(live.portals[0].rebuilds(), built as u64);
    // Off the path, the portal builds as before.
    let (_, _) = render(&mut p, &camera(Vec3::new(2.5, 0.6, 1.5)), &[]);
    assert_eq!(p.last().views, 1);
}
