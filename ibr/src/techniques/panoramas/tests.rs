//! Panoramas of textured cards against the geometry: exact in any direction from the
//! capture point, wrong by parallax away from it, as predicted.

use super::*;
use crate::core::capture_batch;
use crate::metrics::compare_seen;
use crate::stereo::scenes::{with_scene_draws as with_draws, H, W};

const CENTRE: Vec3 = Vec3::new(0.0, 0.0, 5.0);

fn looking(eye: Vec3, dir: Vec3) -> Camera {
    Camera::look_at(eye, eye + dir, Vec3::Y, 0.8, W as f32 / H as f32).with_depth_range(0.1, 50.0)
}

/// PSNR of `image` against `truth` over the pixels both cover, and the share of `truth`'s
/// pixels `image` covers.
fn against(image: &DepthImage, truth: &DepthImage) -> (f64, f64) {
    let (e, covered) = compare_seen(image, truth).expect("same size");
    (e.psnr_capped(99.0), covered)
}

/// Focal length in pixels of the test cameras.
fn focal() -> f32 {
    looking(CENTRE, Vec3::NEG_Z).projection.gl_matrix().x_axis.x * 0.5 * W as f32
}

#[test]
fn from_its_centre_the_panorama_is_the_scene_in_any_direction() {
    with_draws(|draws| {
        let map = CubeMap::capture(draws, &Lighting::default(), CENTRE, 256, 0.1, 50.0);
        // Straight at the cards, turned left and down, and across a cube edge.
        for dir in [
            Vec3::NEG_Z,
            Vec3::new(-0.5, -0.3, -1.0),
            Vec3::new(0.9, 0.2, -1.0),
        ] {
            let camera = looking(CENTRE, dir);
            let truth = capture_batch(draws, &[camera], &Lighting::default(), W, H).remove(0);
            let (psnr, covered) = against(&map.view(&camera, W, H), &truth);
            // (Measured: 25.9, 30.2 and 25.0 dB, every pixel covered: the noise texture's
            // faces resampled once.)
            assert!(
                psnr > 22.0 && covered > 0.99,
                "{dir}: {psnr:.1} dB, {covered:.3}"
            );
        }
    });
}

#[test]
fn away_from_its_centre_the_error_grows_as_predicted() {
    with_draws(|draws| {
        let map = CubeMap::capture(draws, &Lighting::default(), CENTRE, 256, 0.1, 50.0);
        assert_eq!(map.predicted_px(CENTRE, focal()), 0.0);
        let mut last = (f64::INFINITY, 0.0f32);
        for step in [0.0f32, 0.2, 0.5, 1.0] {
            let eye = CENTRE + Vec3::new(step, 0.0, 0.0);
            let camera = looking(eye, Vec3::NEG_Z);
            let truth = capture_batch(draws, &[camera], &Lighting::default(), W, H).remove(0);
            let (psnr, _) = against(&map.view(&camera, W, H), &truth);
            let predicted = map.predicted_px(eye, focal());
            eprintln!("moved {step}: {psnr:.1} dB, predicted {predicted:.1} px");
            assert!(psnr < last.0 + 0.5 && predicted >= last.1, "moved {step}");
            last = (psnr, predicted);
        }
        // (Measured: 25.9 dB at the centre, 10.1 to 10.3 dB from 0.2 units on, predicted
        // 9.5, 23.9 and 47.7 pixels: the noise texture is wrong everywhere once moved a
        // few pixels.) A large move: the error is reported, many pixels' worth.
        assert!(last.1 > 20.0 && last.0 < 18.0, "{last:?}");
    });
}

#[test]
fn the_sky_is_captured_again_when_the_predicted_error_passes_the_tolerance() {
    with_draws(|draws| {
        let lighting = Lighting::default();
        let mut sky = Sky::new(draws, &lighting, CENTRE, 64, (0.1, 50.0), 4.0);
        let near = looking(CENTRE + Vec3::new(0.01, 0.0, 0.0), Vec3::NEG_Z);
        assert!(
            !sky.update(draws, &lighting, near.eye(), near.eye(), focal())
                .swapped
        );
        let far = looking(CENTRE + Vec3::new(0.8, 0.0, 0.0), Vec3::NEG_Z);
        assert!(sky.map.predicted_px(far.eye(), focal()) > 4.0);
        assert!(
            sky.update(draws, &lighting, far.eye(), far.eye(), focal())
                .swapped
        );
        assert_eq!(sky.captures, 2);
        assert!((sky.map.centre() - far.eye()).length() < 1e-5);
        assert_eq!(sky.map.predicted_px(far.eye(), focal()), 0.0);
    });
}

/// Many small steps that together stay under the tolerance: no re-capture at all, while
/// the predicted parallax (what the decision acts on) grows with the distance moved.
#[test]
fn moves_smaller_than_the_tolerance_never_capture_again() {
    with_draws(|draws| {
        let lighting = Lighting::default();
        let mut sky = Sky::new(draws, &lighting, CENTRE, 64, (0.1, 50.0), 4.0);
        // The move the tolerance allows: 4 px at the nearest point's distance.
        let allowed = 4.0 * sky.map.nearest() / focal();
        let mut last = 0.0;
        for k in 1..=20 {
            let eye = CENTRE + Vec3::new(0.9 * allowed * k as f32 / 20.0, 0.0, 0.0);
            let predicted = sky.map.predicted_px(eye, focal());
            assert!(predicted > last && predicted < 4.0, "step {k}: {predicted}");
            assert_eq!(
                sky.update(draws, &lighting, eye, eye, focal()),
                SkyStep::default()
            );
            last = predicted;
        }
        assert_eq!(sky.captures, 1);
        assert!((sky.map.centre() - CENTRE).length() < 1e-6);
    });
}

#[test]
fn the_panorama_fills_only_what_the_frame_left_empty() {
    with_draws(|draws| {
        let map = CubeMap::capture(draws, &Lighting::default(), CENTRE, 64, 0.1, 50.0);
        let camera = looking(CENTRE, Vec3::NEG_Z);
        let mut frame = DepthImage::new(W, H, camera);
        let mark = Premul {
            r: 1.0,
            g: 0.0,
            b: 0.0,
            a: 1.0,
        };
        frame.color[0] = mark;
        map.behind(&mut frame);
        assert_eq!(frame.color[0], mark);
        assert!(frame.color.iter().all(|c| c.a > 0.0 && c.r.is_finite()));
    });
}

#[test]
fn the_row_stepped_rays_fill_what_each_pixels_own_ray_shows() {
    // `behind` steps each row's rays along the row; `view` takes each pixel's own ray
    // (a 4x4 product and a division): the same colours but for rounding, looking at the
    // cards and turned and tilted across the seams of the faces beside them.
    with_draws(|draws| {
        let map = CubeMap::capture(draws, &Lighting::default(), CENTRE, 64, 0.1, 50.0);
        for dir in [
            Vec3::NEG_Z,
            Vec3::new(0.5, 0.2, -1.0),
            Vec3::new(-0.6, -0.3, -1.0),
        ] {
            let camera = looking(CENTRE, dir);
            let mut frame = DepthImage::new(W, H, camera);
            map.behind(&mut frame);
            let view = map.view(&camera, W, H);
            let diffs: Vec<f32> = (frame.color.iter().zip(&view.color))
                .map(|(a, b)| {
                    (a.r - b.r)
                        .abs()
                        .max((a.g - b.g).abs())
                        .max((a.b - b.b).abs())
                        .max((a.a - b.a).abs())
                })
                .collect();
            let worst = diffs.iter().copied().fold(0.0f32, f32::max);
            let off = diffs.iter().filter(|&&d| d > 1e-3).count();
            let seen = view.color.iter().filter(|c| c.a > 0.0).count();
            assert!(seen * 4 > diffs.len(), "{dir}: {seen} pixels see the scene");
            eprintln!(
                "{dir}: worst {worst}, {off} of {} pixels past 1e-3",
                diffs.len()
            );
            // A ray on a seam between faces may round onto the other face: a few pixels.
            assert!(off * 1000 <= diffs.len(), "{dir}: {off} pixels past 1e-3");
            assert!(worst < 0.05, "{dir}: {worst}");
        }
    });
}

#[test]
fn a_cylinder_turns_in_place_all_the_way_round_within_its_band() {
    with_draws(|draws| {
        let map = CubeMap::capture(draws, &Lighting::default(), CENTRE, 256, 0.1, 50.0);
        let cylinder = Cylinder::from_cube(&map, 1024, 384, 0.6);
        // All the way round: the cylinder's view is the cube's, across its seam (column 0
        // looks down -z, at the cards) and where the cube sees nothing (behind).
        for yaw in [0.0f32, 0.4, -0.4, 2.0, std::f32::consts::PI, -2.9] {
            let dir = Vec3::new(yaw.sin(), 0.0, -yaw.cos());
            let camera = looking(CENTRE, dir);
            let (view, want) = (cylinder.view(&camera, W, H), map.view(&camera, W, H));
            let seen = |i: &DepthImage| i.color.iter().filter(|c| c.a > 0.0).count();
            if seen(&want) == 0 {
                assert_eq!(seen(&view), 0, "yaw {yaw}");
                continue;
            }
            let (psnr, covered) = against(&view, &want);
            // (Measured: 34.1, 31.4 and 37.9 dB toward the cards.)
            assert!(
                psnr > 24.0 && covered > 0.99,
                "yaw {yaw}: {psnr:.1} dB, {covered:.3}"
            );
        }
        // Looking up past the band: not in the panorama, left empty rather than smeared.
        let up = cylinder.view(&looking(CENTRE, Vec3::new(0.0, 1.0, -0.1)), W, H);
        let shown = up.color.iter().filter(|c| c.a > 0.0).count();
        assert!(shown * 10 < up.color.len(), "{shown} pixels above the band");
    });
}

#[test]
fn after_a_large_translation_the_error_is_reported_not_garbage() {
    with_draws(|draws| {
        let map = CubeMap::capture(draws, &Lighting::default(), CENTRE, 64, 0.1, 50.0);
        let mut last = 0.0f32;
        // To the side, through the cards and out behind them, then far to the side.
        for eye in [
            CENTRE + Vec3::new(4.0, 0.0, 0.0),
            CENTRE + Vec3::new(0.0, 0.0, -9.0),
            CENTRE + Vec3::new(12.0, 3.0, 0.0),
        ] {
            let camera = looking(eye, Vec3::NEG_Z);
            let view = map.view(&camera, W, H);
            assert!(
                view.color
                    .iter()
                    .all(|c| c.r.is_finite() && c.a.is_finite())
                    && view.depth.iter().all(|d| !d.is_nan()),
                "{eye}: a NaN in the view"
            );
            let truth = capture_batch(draws, &[camera], &Lighting::default(), W, H).remove(0);
            // Measured where both see something; nothing in common is said so, not guessed.
            match compare_seen(&view, &truth) {
                Ok((e, _)) => assert!(!e.psnr_db.is_nan(), "{eye}: {e:?}"),
                Err(e) => assert_eq!(e, crate::metrics::MetricsError::Empty, "{eye}"),
            }
            let predicted = map.predicted_px(eye, focal());
            assert!(
                predicted.is_finite() && predicted > last.max(20.0),
                "{eye}: {predicted}"
            );
            last = predicted;
        }
        // A sky with a tolerance captures again rather than show that.
        let mut sky = Sky::new(draws, &Lighting::default(), CENTRE, 64, (0.1, 50.0), 4.0);
        let far = looking(CENTRE + Vec3::new(12.0, 3.0, 0.0), Vec3::NEG_Z);
        let step = sky.update(draws, &Lighting::default(), far.eye(), far.eye(), focal());
        let shown = faces_shown(draws, far.eye(), 0.1, 50.0);
        let rendered = shown.iter().filter(|&&s| s).count();
        assert!(step.swapped && step.faces == rendered, "{step:?}");
        assert_eq!(sky.captures, 2);
    });
}

/// The near scene trimmed to the panorama's cube: every pixel kept shows a point inside
/// it, every pixel cleared one outside (checked through `DepthImage::world_point`, the
/// unprojection the trim does not use), and both kinds occur.
#[test]
fn trimming_keeps_exactly_the_points_inside_the_cube() {
    with_draws(|draws| {
        let eye = CENTRE + Vec3::new(0.4, 0.2, 0.0);
        let camera = looking(eye, Vec3::new(0.2, -0.1, -1.0));
        let full = capture_batch(draws, &[camera], &Lighting::default(), W, H).remove(0);
        let inside = |p: Vec3| (p - CENTRE).abs().max_element();
        let mut far: Vec<f32> = (0..W * H)
            .filter_map(|i| full.world_point(i % W, i / W).map(inside))
            .collect();
        far.sort_by(f32::total_cmp);
        let half = far[far.len() / 2];
        let mut trimmed = full.clone();
        let cleared = trim_beyond(&mut trimmed, CENTRE, half);
        let (mut kept, mut gone) = (0, 0);
        for i in 0..W * H {
            let Some(p) = full.world_point(i % W, i / W) else {
                assert!(trimmed.depth[i as usize].is_infinite());
                continue;
            };
            // Half a thousandth of slack for the two unprojections' rounding.
            if trimmed.depth[i as usize].is_finite() {
                assert!(inside(p) <= half * 1.0005, "kept {p} at {}", inside(p));
                assert_eq!(trimmed.color[i as usize], full.color[i as usize]);
                kept += 1;
            } else {
                assert!(inside(p) >= half * 0.9995, "cleared {p} at {}", inside(p));
                assert_eq!(trimmed.color[i as usize], Premul::TRANSPARENT);
                gone += 1;
            }
        }
        assert_eq!(gone, cleared);
        assert!(kept > 100 && gone > 100, "{kept} kept, {gone} cleared");
    });
}

/// A [`Sky`] of the test scene and the bands round it (every face shown), capturing
/// `faces` faces an update, handed to `test` with its draws and lighting.
fn with_spread_sky(faces: usize, test: impl FnOnce(Sky, &[Draw<'_>], &Lighting)) {
    with_draws(|draws| {
        with_all_faces(draws, |draws| {
            let lighting = Lighting::default();
            let sky = Sky::new(draws, &lighting, CENTRE, 32, (0.1, 50.0), 4.0).spread(faces);
            test(sky, draws, &lighting)
        })
    })
}

/// A re-capture spread two faces an update: started where the eye will be when the held
/// panorama's parallax there passes the tolerance, two faces each update and never more,
/// the held panorama drawn until all six are there, then swapped whole; the faces equal
/// those of a capture made at once from the same point.
#[test]
fn a_spread_re_capture_takes_two_faces_an_update_and_swaps_when_complete() {
    with_spread_sky(2, |mut sky, draws, lighting| {
        assert_eq!(sky.lead(), 2);
        // Steps of a third of the tolerance (and a little): the eye `lead` steps ahead
        // passes it first at step 1, the eye itself at step 3.
        let step = sky.tolerance_px / 3.0 * sky.map.nearest() / focal();
        let at = |k: usize| CENTRE + Vec3::new(step * k as f32 * 1.01, 0.0, 0.0);
        let mut steps = Vec::new();
        let mut first = None;
        for k in 0..8 {
            let (before, pending) = (sky.map.centre(), sky.pending_faces());
            let s = sky.update(draws, lighting, at(k), at(k + sky.lead()), focal());
            assert!(s.faces <= 2, "step {k}: {s:?}");
            if s.swapped {
                assert_eq!(pending, Some(4), "step {k}");
                assert!(sky.pending_faces().is_none());
                assert!(sky.map.predicted_px(at(k), focal()) < 1e-3, "step {k}");
                first.get_or_insert_with(|| sky.map.clone());
            } else {
                assert_eq!(sky.map.centre(), before, "step {k}: drawn before complete");
            }
            steps.push(s);
        }
        let faces: Vec<usize> = steps.iter().map(|s| s.faces).collect();
        let swaps: Vec<usize> = (0..8).filter(|&k| steps[k].swapped).collect();
        // Every three steps, swapped where the held panorama passes the tolerance.
        assert_eq!(faces, [0, 2, 2, 2, 2, 2, 2, 2], "{steps:?}");
        assert_eq!(swaps, [3, 6], "{steps:?}");
        assert_eq!(sky.captures, 3);
        // The faces spread over three updates are those of one capture from there.
        let at_once = CubeMap::capture(draws, lighting, at(3), 32, 0.1, 50.0);
        let camera = looking(at(3), Vec3::new(0.3, 0.2, -1.0));
        let spread = first.expect("swapped").view(&camera, W, H);
        assert_eq!(spread.color, at_once.view(&camera, W, H).color);
        // The second re-capture drew into the first map's faces (kept as spares): the same
        // faces as fresh ones.
        let at_once = CubeMap::capture(draws, lighting, at(6), 32, 0.1, 50.0);
        assert_eq!(sky.map.faces, at_once.faces);
    });
}

/// An eye outrunning the spread (past the tolerance at once) has all the faces left
/// captured in that update rather than be drawn past its tolerance.
#[test]
fn an_eye_outrunning_the_spread_captures_what_is_left_at_once() {
    with_spread_sky(1, |mut sky, draws, lighting| {
        let allowed = sky.tolerance_px * sky.map.nearest() / focal();
        let near = CENTRE + Vec3::X * (0.5 * allowed);
        let ahead = CENTRE + Vec3::X * (1.5 * allowed);
        let s = sky.update(draws, lighting, near, ahead, focal());
        assert_eq!(
            (s.faces, s.swapped, sky.pending_faces()),
            (1, false, Some(1))
        );
        let s = sky.update(draws, lighting, ahead, ahead, focal());
        assert_eq!((s.faces, s.swapped), (5, true), "{s:?}");
        assert!(sky.map.predicted_px(ahead, focal()) < 1e-3);
        assert_eq!(sky.captures, 2);
    });
}

/// A band round `CENTRE` on the horizon (20 units away, 2 up and down), facing it: what
/// a cube map's four side faces see, its top and bottom faces not.
fn horizon_band() -> (engine::Mesh, engine::Material) {
    let mut mesh = engine::Mesh::default();
    let steps = 64u32;
    for i in 0..steps {
        let t = i as f32 / steps as f32 * std::f32::consts::TAU;
        let at = CENTRE + Vec3::new(t.sin() * 20.0, 0.0, -t.cos() * 20.0);
        mesh.positions
            .extend([at - Vec3::Y * 2.0, at + Vec3::Y * 2.0]);
        let c = engine::Rgba::new(0.2 + 0.6 * (i % 7) as f32 / 7.0, 0.5, 0.3, 1.0);
        mesh.colors.extend([c, c]);
    }
    for i in 0..steps {
        let (a, b) = (2 * i, 2 * ((i + 1) % steps));
        mesh.indices.extend([a, b, a + 1, b, b + 1, a + 1]);
    }
    mesh.compute_normals();
    (mesh, engine::Material::lit(engine::Rgba::WHITE))
}

/// `draws` with the horizon band round them, and copies of it 30 units above and below:
/// something in every face of a cube map at `CENTRE`, so all six are rendered (the policy
/// tests count six faces).
fn with_all_faces(draws: &[Draw<'_>], test: impl FnOnce(&[Draw<'_>])) {
    let (mesh, material) = horizon_band();
    let band = |y: f32| Draw {
        mesh: &mesh,
        material: &material,
        transform: Mat4::from_translation(Vec3::Y * y),
    };
    let mut all = draws.to_vec();
    all.extend([band(0.0), band(30.0), band(-30.0)]);
    assert_eq!(faces_shown(&all, CENTRE, 0.1, 50.0), [true; 6]);
    test(&all)
}

/// [`horizon_band`]'s one draw and the default lighting, handed to `test`.
fn with_band(test: impl FnOnce(&[Draw<'_>], &Lighting)) {
    let (mesh, material) = horizon_band();
    let draws = [Draw {
        mesh: &mesh,
        material: &material,
        transform: Mat4::IDENTITY,
    }];
    test(&draws, &Lighting::default());
}

#[test]
fn faces_that_can_show_nothing_are_left_empty_and_the_map_is_the_same() {
    with_band(|draws, lighting| {
        // Order +x, -x, +y, -y, +z, -z: the band is beside the centre, not above or below.
        let shown = faces_shown(draws, CENTRE, 0.1, 50.0);
        assert_eq!(shown, [true, true, false, false, true, true]);
        let map = CubeMap::capture(draws, lighting, CENTRE, 48, 0.1, 50.0);
        assert_eq!(map.faces_rendered(), 4);
        // The reference: all six faces rendered.
        let all = capture_batch(draws, &face_cameras(CENTRE, 0.1, 50.0), lighting, 48, 48);
        assert!(all[2].covered() == 0 && all[3].covered() == 0);
        assert_eq!(map.faces, all);
        assert_eq!(
            map.nearest(),
            CubeMap::from_faces(CENTRE, all).expect("six").nearest()
        );
        // Something above and below: every face is rendered.
        let up = Mat4::from_translation(Vec3::Y * 30.0);
        let tilted = [
            draws[0],
            Draw {
                transform: up,
                ..draws[0]
            },
        ];
        let below = Mat4::from_translation(Vec3::NEG_Y * 30.0);
        let tilted = [
            tilted[0],
            tilted[1],
            Draw {
                transform: below,
                ..draws[0]
            },
        ];
        assert_eq!(faces_shown(&tilted, CENTRE, 0.1, 50.0), [true; 6]);
    });
}

#[test]
fn a_spread_re_capture_renders_only_the_faces_that_show_something() {
    with_band(|draws, lighting| {
        let mut sky = Sky::new(draws, lighting, CENTRE, 48, (0.1, 50.0), 1.0).spread(2);
        // The re-capture's storage made ahead: no update allocates a face.
        sky.reserve();
        assert_eq!(sky.spare.len(), 6);
        // Four faces to render, two an update: one update after the one that starts it.
        assert_eq!(sky.lead(), 1);
        let ahead = CENTRE + Vec3::X * 5.0;
        let eye = CENTRE + Vec3::X * 0.01;
        assert!(sky.map.predicted_px(eye, 40.0) < 1.0 && sky.map.predicted_px(ahead, 40.0) > 1.0);
        let first = sky.update(draws, lighting, eye, ahead, 40.0);
        assert_eq!((first.faces, first.swapped), (2, false));
        let second = sky.update(draws, lighting, eye, ahead, 40.0);
        assert_eq!((second.faces, second.swapped), (2, true));
        assert_eq!(sky.captures, 2);
        // The same panorama as one captured there at once, all six faces rendered in full.
        let all = capture_batch(draws, &face_cameras(ahead, 0.1, 50.0), lighting, 48, 48);
        assert_eq!(sky.map.faces, all);
        // Only the band of rows round the horizon of each side face was rendered: the
        // band (2 units up and down, 20 away) spans a tenth of a face's height at its
        // centre, a seventh at its edges, and two rows spare each side.
        let rows: Vec<u32> = (0..6).map(|f| sky.map.face_rows(f).len() as u32).collect();
        assert!(rows[2] == 0 && rows[3] == 0, "{rows:?}");
        assert!(rows.iter().all(|&r| r <= 48 / 3), "{rows:?}");
        let rendered: u64 = rows.iter().map(|&r| r as u64 * 48).sum();
        assert_eq!(first.pixels + second.pixels, rendered);
        assert!(rendered * 3 < 4 * 48 * 48, "{rendered} of {}", 4 * 48 * 48);
        // Every face of the map swapped out is kept, the storage of the next re-capture's.
        assert_eq!(sky.spare.len(), 6);
    });
}

#[test]
fn lookups_past_the_bands_elevations_are_skipped_and_find_what_they_would() {
    // The horizon band leaves the top and bottom faces empty: a ray past the side faces'
    // bands' elevations finds nothing. Skipped (whole rows, or a pixel's ray), each gives
    // what the lookup gives, looking level, up, down, turned across the seams and rolled.
    with_band(|draws, lighting| {
        let map = CubeMap::capture(draws, lighting, CENTRE, 96, 0.1, 50.0);
        assert!(map.open.is_some());
        let (mut skipped, mut rows_shut, mut seen) = (0, 0, 0);
        let rolled = Camera::look_at(
            CENTRE,
            CENTRE + Vec3::NEG_Z,
            Vec3::new(0.6, 1.0, 0.0),
            0.8,
            1.5,
        );
        let cameras = [
            looking(CENTRE, Vec3::NEG_Z),
            looking(CENTRE, Vec3::new(0.7, 0.15, -1.0)),
            looking(CENTRE, Vec3::new(-1.0, -0.2, 0.9)),
            looking(CENTRE, Vec3::new(0.1, 1.0, -0.4)),
            looking(CENTRE, Vec3::new(1.0, -0.6, 1.0)),
            rolled,
        ];
        for camera in cameras {
            let behind = map.behind_view(&camera, (W, H));
            for y in 0..H {
                let row = behind.row(y);
                rows_shut += row.is_open_sky() as usize;
                for x in 0..W as usize {
                    let (c, looked) = row.at(x);
                    let truth = map.sample(row.ray.at(x)).unwrap_or(Premul::TRANSPARENT);
                    assert_eq!(c, truth, "{camera:?} ({x}, {y})");
                    skipped += !looked as usize;
                    seen += (truth.a > 0.0) as usize;
                }
            }
        }
        eprintln!("{skipped} lookups skipped ({rows_shut} rows whole), {seen} pixels see the band");
        assert!(rows_shut > 0 && skipped > 0 && seen > 0);
    });
}
