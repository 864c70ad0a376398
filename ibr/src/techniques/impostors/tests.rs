//! Impostor captures against geometry, the error predictors against their analytic values,
//! and the scheduler's budget, priorities, fallbacks and texture pool.

use super::*;
use crate::core::MeshGroup;
use crate::core::{needed_side, screen_rect, Capture};
use engine::{procedural, Material};
use glam::Vec3;
use std::sync::Arc;

const W: u32 = 96;
const H: u32 = 72;

fn lighting() -> Lighting {
    Lighting::white_sun(0.3, Vec3::new(-0.3, -1.0, -0.4))
}

/// A lit torus standing at `at`, about 1 unit across.
fn torus(at: Vec3) -> MeshGroup {
    MeshGroup::new().with(
        Arc::new(procedural::torus(0.4, 0.15, 32, 16)),
        Arc::new(Material::lit(Rgba::new(0.8, 0.4, 0.2, 1.0))),
        Mat4::from_translation(at) * Mat4::from_rotation_x(1.0),
    )
}

fn camera(eye: Vec3, target: Vec3) -> Camera {
    Camera::look_at(eye, target, Vec3::Y, 0.9, W as f32 / H as f32).with_depth_range(0.05, 100.0)
}

fn set(n: usize, refreshes: usize) -> ImpostorSet {
    let mut cfg = Config::default();
    cfg.budget.refreshes = refreshes;
    ImpostorSet::new(cfg, n)
}

#[test]
fn an_image_seen_from_its_capture_eye_matches_the_geometry() {
    let mut subjects = [torus(Vec3::ZERO)];
    let mut imps = set(1, 1);
    let cam = camera(Vec3::new(0.5, 0.8, 4.0), Vec3::ZERO);
    let r = imps.update(&mut subjects, &cam, H, &lighting());
    assert_eq!((r.refreshes, r.images), (1, 1));
    let err = imps
        .measure(0, &mut subjects[0], &cam, (W, H), &lighting())
        .expect("drawn as an image");
    // Resampling the image costs a little at the silhouette (a 28-pixel torus here: its
    // outline is a tenth of its pixels); inside it the picture is the same.
    assert!(err.psnr_db > 25.0 && err.mean_abs < 4.0, "{err:?}");
    assert!(err.coverage_mismatch < 0.05, "{err:?}");
}

#[test]
fn parallax_is_zero_at_the_capture_eye_and_ignores_rotation() {
    let mut subjects = [torus(Vec3::ZERO)];
    let mut imps = set(1, 1);
    let eye = Vec3::new(0.0, 0.5, 5.0);
    imps.update(&mut subjects, &camera(eye, Vec3::ZERO), H, &lighting());
    // Turning the camera in place (the subject still in view) predicts no error.
    for look in [Vec3::new(0.3, 0.0, 0.0), Vec3::new(-0.4, 0.2, 0.0)] {
        let r = imps.update(&mut subjects, &camera(eye, look), H, &lighting());
        assert_eq!(r.refreshes, 0);
        let p = imps.impostors[0].predicted;
        assert!(p.degrees < 1e-3 && p.ratio < 1.0, "{p:?}");
    }
}

#[test]
fn parallax_matches_the_angle_between_the_stored_points() {
    let mut subjects = [torus(Vec3::ZERO)];
    let mut imps = set(1, 1);
    let eye = Vec3::new(0.0, 0.0, 5.0);
    imps.update(&mut subjects, &camera(eye, Vec3::ZERO), H, &lighting());
    imps.config.budget.refreshes = 0;
    let c = *imps.impostors[0].capture().unwrap();
    let mut last = 0.0;
    for step in 1..8 {
        let moved = eye + Vec3::X * (0.05 * step as f32);
        imps.update(&mut subjects, &camera(moved, Vec3::ZERO), H, &lighting());
        let p = imps.impostors[0].predicted;
        // In f64: acos of a dot product this close to 1 is too coarse in f32.
        let (a, b) = ((c.near - moved).as_dvec3(), (c.far - moved).as_dvec3());
        let expect = a.angle_between(b).to_degrees() as f32;
        assert!(
            (p.degrees - expect).abs() < 2e-3 * expect,
            "{} vs {expect}",
            p.degrees
        );
        assert!(p.degrees > last, "grows with the translation");
        last = p.degrees;
        let px = p.degrees.to_radians() * H as f32 * 0.5 / (0.45f32).tan();
        assert!((p.pixels - px).abs() < 1e-3 * px);
        assert_eq!(
            p.ratio >= 1.0,
            p.degrees >= 0.125,
            "default tolerance 0.125 degrees"
        );
    }
    // In pixels instead of degrees.
    imps.config.tolerance.pixels = Some(1000.0);
    imps.update(
        &mut subjects,
        &camera(eye + Vec3::X, Vec3::ZERO),
        H,
        &lighting(),
    );
    assert!(imps.impostors[0].predicted.ratio < 1.0);
}

#[test]
fn resolution_error_counts_octaves_of_the_needed_side() {
    // A sphere of radius 1 at distance d covers 2 * (H/2) / tan(fov/2) / d pixels.
    let ppr = H as f32 * 0.5 / 0.45f32.tan();
    for d in [2.0f32, 5.0, 11.0, 40.0] {
        let px = 2.0 * ppr / d;
        let side = needed_side(1.0, d, ppr, 1, 4096);
        assert!(side.is_power_of_two() && side as f32 >= px && (side as f32) < 2.0 * px);
    }
    assert_eq!(needed_side(1.0, 1e-9, ppr, 16, 512), 512);
    assert_eq!(needed_side(1.0, 1e9, ppr, 16, 512), 16);
    assert_eq!(needed_side(f32::NAN, 1.0, ppr, 16, 512), 512);

    let mut subjects = [torus(Vec3::ZERO)];
    let mut imps = set(1, 1);
    imps.update(
        &mut subjects,
        &camera(Vec3::new(0.0, 0.0, 8.0), Vec3::ZERO),
        H,
        &lighting(),
    );
    let side = imps.impostors[0].capture().unwrap().side;
    // Coming four times closer along the capture ray: no parallax, two octaves.
    imps.config.budget.refreshes = 0;
    imps.update(
        &mut subjects,
        &camera(Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO),
        H,
        &lighting(),
    );
    let p = imps.impostors[0].predicted;
    assert!(p.degrees < 1e-3);
    assert_eq!(p.needed_side, (side * 4).min(512));
    assert!((p.octaves - 2.0).abs() < 1e-6 && p.ratio >= 1.0);
}

/// With a side step the image is as wide as the subject's disc on screen (the angle its
/// bounding sphere subtends, taken here from the camera's field of view) rounded up to the
/// step, not to the power of two; coming closer along the capture ray (no parallax) until
/// the disc is wider than the image makes it invalid, and its refresh is wider again.
#[test]
fn a_side_step_sizes_images_to_their_disc_and_refreshes_them_when_outgrown() {
    let mut subjects = [torus(Vec3::ZERO)];
    let mut imps = set(1, 1);
    imps.side_step = Some(16);
    let b = subjects[0].bounds();
    let (radius, ppr) = (b.radius, H as f32 * 0.5 / 0.45f32.tan());
    let disc = |d: f32| 2.0 * (radius / d).asin() * ppr;
    let at = |d: f32| camera(b.center + Vec3::new(0.0, 0.0, d), b.center);
    // Distances at which the disc is 40 and 52 px wide (images of 48 and 64 texels).
    let (d0, d1) = (radius / (20.0 / ppr).sin(), radius / (26.0 / ppr).sin());
    imps.update(&mut subjects, &at(d0), H, &lighting());
    let side = imps.impostors[0].capture().unwrap().side;
    assert_eq!(side % 16, 0);
    assert!(
        side as f32 >= disc(d0) && (side as f32) < disc(d0) + 16.0,
        "{side}"
    );
    assert!(
        !side.is_power_of_two() && disc(d1) > side as f32,
        "{side} {}",
        disc(d1)
    );
    // A little nearer, the disc still within the image: no refresh.
    let r = imps.update(&mut subjects, &at(d0 * 0.98), H, &lighting());
    assert!(disc(d0 * 0.98) <= side as f32);
    assert_eq!(r.refreshes, 0);
    // Nearer still the disc outgrows the image: invalid, whatever the parallax (none).
    imps.config.budget.refreshes = 0;
    let r = imps.update(&mut subjects, &at(d1), H, &lighting());
    let p = imps.impostors[0].predicted;
    assert!(p.degrees < 1e-3 && p.ratio.is_infinite(), "{p:?}");
    assert_eq!(r.stale, 1);
    imps.config.budget.refreshes = 1;
    let r = imps.update(&mut subjects, &at(d1), H, &lighting());
    assert_eq!(r.refreshes, 1);
    let wider = imps.impostors[0].capture().unwrap().side;
    assert!(
        wider as f32 >= disc(d1) && wider.is_multiple_of(16) && wider > side,
        "{wider}"
    );
    // Without the step, the same subject takes the power of two at or above its disc.
    let mut pow2 = set(1, 1);
    pow2.update(&mut subjects, &at(d0), H, &lighting());
    assert!(pow2.impostors[0].capture().unwrap().side.is_power_of_two());
}

/// Five subjects in a row; the eye slides sideways so parallax differs per subject.
fn row() -> Vec<MeshGroup> {
    (0..5)
        .map(|k| torus(Vec3::new(k as f32 * 1.5 - 3.0, 0.0, -(k as f32) * 2.0)))
        .collect()
}

#[test]
fn the_budget_refreshes_the_largest_errors_first() {
    let mut subjects = row();
    let mut imps = set(5, 2);
    let eye = Vec3::new(0.0, 1.0, 6.0);
    let look = Vec3::new(0.0, 0.0, -4.0);
    // Two per frame: all five captured after three frames, the first two on frame one.
    let firsts: Vec<usize> = (0..3)
        .map(|_| {
            imps.update(&mut subjects, &camera(eye, look), H, &lighting())
                .refreshes
        })
        .collect();
    assert_eq!(firsts, [2, 2, 1]);
    assert!(imps.impostors.iter().all(|i| i.capture().is_some()));
    // Move: every impostor is invalid; the two with the largest predicted error go first.
    let moved = eye + Vec3::new(1.5, 0.5, 0.0);
    imps.config.budget.refreshes = 0;
    imps.update(&mut subjects, &camera(moved, look), H, &lighting());
    let mut ratios: Vec<(f32, usize)> = imps
        .impostors
        .iter()
        .enumerate()
        .map(|(i, imp)| (imp.predicted.ratio, i))
        .collect();
    assert!(ratios.iter().all(|r| r.0 >= 1.0), "{ratios:?}");
    ratios.sort_by(|a, b| b.0.total_cmp(&a.0));
    imps.config.budget.refreshes = 2;
    let before: Vec<u64> = imps.impostors.iter().map(|i| i.refreshes).collect();
    let r = imps.update(&mut subjects, &camera(moved, look), H, &lighting());
    assert_eq!((r.refreshes, r.stale), (2, 3));
    let refreshed: Vec<usize> = (0..5)
        .filter(|&i| imps.impostors[i].refreshes > before[i])
        .collect();
    let mut worst = vec![ratios[0].1, ratios[1].1];
    worst.sort();
    assert_eq!(refreshed, worst);
    // Stale impostors still draw their old image, or their geometry when the image is
    // over twice the tolerance: no subject goes missing, no badly stale image is shown.
    assert_eq!(r.images + r.geometry, 5);
    for imp in &imps.impostors {
        match imp.mode {
            Mode::Image => assert!(imp.predicted.ratio <= 2.0, "{:?}", imp.predicted),
            Mode::Geometry(f) => {
                assert_eq!(f, Fallback::Stale);
                assert!(imp.predicted.ratio > 2.0);
            }
            Mode::Culled => panic!("all five are in view"),
        }
    }
    assert_eq!(r.stale_fallbacks, r.geometry);
    assert_eq!(
        r.over_tolerance,
        r.images - 2,
        "all but the two refreshed are over"
    );
}

#[test]
fn a_badly_stale_image_is_never_shown_and_comes_back_once_refreshed() {
    let mut subjects = [torus(Vec3::ZERO)];
    let mut imps = set(1, 1);
    let look = Vec3::ZERO;
    let eye = Vec3::new(0.0, 0.3, 4.0);
    imps.update(&mut subjects, &camera(eye, look), H, &lighting());
    imps.config.budget.refreshes = 0;
    // Walk around the subject without refreshing: the image is shown while its predicted
    // error is at most twice the tolerance, the geometry after that.
    let mut seen = Vec::new();
    for a in 0..40 {
        let e = Mat4::from_rotation_y((a as f32 * 0.05).to_radians()).transform_point3(eye);
        let r = imps.update(&mut subjects, &camera(e, look), H, &lighting());
        let imp = &imps.impostors[0];
        match imp.mode {
            Mode::Image => assert!(imp.predicted.ratio <= 2.0),
            Mode::Geometry(Fallback::Stale) => assert!(imp.predicted.ratio > 2.0),
            m => panic!("{m:?}"),
        }
        assert_eq!(r.stale_fallbacks, (imp.mode != Mode::Image) as usize);
        seen.push(imp.mode);
    }
    assert_eq!(seen[0], Mode::Image);
    assert_eq!(
        seen[39],
        Mode::Geometry(Fallback::Stale),
        "walked far enough"
    );
    // With budget again, it is refreshed and shown as an image.
    imps.config.budget.refreshes = 1;
    let e = Mat4::from_rotation_y(2.0f32.to_radians()).transform_point3(eye);
    let r = imps.update(&mut subjects, &camera(e, look), H, &lighting());
    assert_eq!((r.refreshes, r.images, r.stale_fallbacks), (1, 1, 0));
}

#[test]
fn subjects_about_to_come_into_view_are_prewarmed_after_the_visible_ones() {
    // One torus in view, one just beyond the right edge, one far outside.
    let look = Vec3::new(0.0, 0.0, -4.0);
    let cam = camera(Vec3::new(0.0, 0.0, 6.0), look);
    let edge = {
        // Just past the right edge at the subjects' depth: about 1.1 half-widths out.
        let p = cam
            .clip_from_world()
            .inverse()
            .project_point3(Vec3::new(1.15, 0.0, 0.99));
        let dir = (p - cam.eye()).normalize();
        cam.eye() + dir * 10.0
    };
    let mut subjects = [torus(look), torus(edge), torus(Vec3::new(60.0, 0.0, -4.0))];
    let mut imps = set(3, 1);
    let r = imps.update(&mut subjects, &cam, H, &lighting());
    assert_eq!((r.refreshes, r.prewarmed, r.images, r.culled), (1, 0, 1, 2));
    assert_eq!(imps.impostors[0].refreshes, 1, "the visible one first");
    imps.config.budget.refreshes = 3;
    let r = imps.update(&mut subjects, &cam, H, &lighting());
    assert_eq!((r.refreshes, r.prewarmed, r.culled), (1, 1, 2), "{r:?}");
    assert_eq!(imps.impostors[1].refreshes, 1, "pre-warmed, still culled");
    assert_eq!(imps.impostors[1].mode, Mode::Culled);
    assert_eq!(imps.impostors[2].refreshes, 0, "too far outside");
}

#[test]
fn inside_the_sphere_the_subject_is_geometry_and_near_it_refreshes_every_frame() {
    let mut subjects = [torus(Vec3::ZERO)];
    let mut imps = set(1, 4);
    let r = subjects[0].bounds().radius;
    // In the transition band (1 to 1.25 radii) every frame refreshes, even standing still.
    let eye = Vec3::new(0.0, 0.0, r * 1.15);
    for _ in 0..3 {
        let rep = imps.update(&mut subjects, &camera(eye, Vec3::ZERO), H, &lighting());
        assert_eq!((rep.refreshes, rep.images), (1, 1));
    }
    let rep = imps.update(
        &mut subjects,
        &camera(Vec3::new(0.0, 0.0, r * 0.9), Vec3::ZERO),
        H,
        &lighting(),
    );
    assert_eq!(imps.impostors[0].mode, Mode::Geometry(Fallback::Inside));
    assert_eq!((rep.refreshes, rep.geometry), (0, 1));
    let mut draws = Vec::new();
    imps.draws(&subjects, &mut draws);
    assert_eq!(draws.len(), 1, "the torus itself");
    assert!(std::ptr::eq(draws[0].mesh, &*subjects[0].parts[0].mesh));
}

#[test]
fn an_exhausted_pool_falls_back_to_geometry_never_to_nothing() {
    let mut subjects = row();
    let cfg = Config {
        pool_slots: 2,
        ..Config::default()
    };
    let mut imps = ImpostorSet::new(cfg, 5);
    let cam = camera(Vec3::new(0.0, 1.0, 6.0), Vec3::new(0.0, 0.0, -4.0));
    let r = imps.update(&mut subjects, &cam, H, &lighting());
    assert_eq!((r.refreshes, r.images, r.geometry, r.culled), (2, 2, 3, 0));
    assert_eq!((r.pool_used, r.pool_size), (2, 2));
    let mut draws = Vec::new();
    imps.draws(&subjects, &mut draws);
    assert_eq!(draws.len(), 5, "two images and three tori");
}

#[test]
fn culled_impostors_give_their_textures_back() {
    let mut subjects = row();
    let cfg = Config {
        release_after: 3,
        ..Config::default()
    };
    let mut imps = ImpostorSet::new(cfg, 5);
    let look = Vec3::new(0.0, 0.0, -4.0);
    let eye = Vec3::new(0.0, 1.0, 6.0);
    imps.update(&mut subjects, &camera(eye, look), H, &lighting());
    assert_eq!(imps.pool().usage(), (5, 5));
    // Look away: everything is culled; after `release_after` frames the pool is free.
    let away = camera(eye, eye + Vec3::Z);
    for frame in 0..5 {
        let r = imps.update(&mut subjects, &away, H, &lighting());
        assert_eq!(r.culled, 5);
        assert_eq!(r.pool_used, if frame < 3 { 5 } else { 0 }, "frame {frame}");
    }
    // Looking back recaptures into the same textures: the pool does not grow.
    imps.update(&mut subjects, &camera(eye, look), H, &lighting());
    assert_eq!(imps.pool().usage(), (5, 5));
}

#[test]
fn a_changed_subject_is_recaptured() {
    let mut subjects = [torus(Vec3::ZERO)];
    let mut imps = set(1, 1);
    let cam = camera(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
    imps.update(&mut subjects, &cam, H, &lighting());
    assert_eq!(
        imps.update(&mut subjects, &cam, H, &lighting()).refreshes,
        0
    );
    subjects[0].version += 1;
    assert_eq!(
        imps.update(&mut subjects, &cam, H, &lighting()).refreshes,
        1
    );
    // Moving it (without a version bump) is noticed through its bounds.
    subjects[0].parts[0].transform = Mat4::from_translation(Vec3::X * 0.2);
    assert_eq!(
        imps.update(&mut subjects, &cam, H, &lighting()).refreshes,
        1
    );
}

/// Without refreshes, the measured error grows as the eye moves away from the capture
/// eye, and so does the predicted error.
#[test]
fn measured_error_grows_with_predicted_error() {
    let mut subjects = [torus(Vec3::ZERO)];
    let mut imps = set(1, 1);
    let eye = Vec3::new(0.0, 0.3, 4.0);
    imps.update(&mut subjects, &camera(eye, Vec3::ZERO), H, &lighting());
    imps.config.budget.refreshes = 0;
    // Keep showing the stale image however stale, to measure it.
    imps.config.fallback_ratio = f32::INFINITY;
    let mut rows = Vec::new();
    for a in [0.0f32, 4.0, 12.0, 30.0] {
        let e = Mat4::from_rotation_y(a.to_radians()).transform_point3(eye);
        let cam = camera(e, Vec3::ZERO);
        imps.update(&mut subjects, &cam, H, &lighting());
        let m = imps
            .measure(0, &mut subjects[0], &cam, (W, H), &lighting())
            .unwrap();
        rows.push((imps.impostors[0].predicted.degrees, m.mean_abs));
    }
    for w in rows.windows(2) {
        assert!(w[1].0 > w[0].0 && w[1].1 > w[0].1, "{rows:?}");
    }
}

#[test]
fn odd_cameras_and_subjects_do_not_break_the_set() {
    let mut subjects = [
        torus(Vec3::ZERO),
        MeshGroup::new(),
        torus(Vec3::splat(f32::NAN)),
    ];
    let mut imps = set(3, 3);
    for cam in [
        camera(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO),
        camera(Vec3::splat(f32::NAN), Vec3::ZERO),
        camera(Vec3::ZERO, Vec3::Z),
    ] {
        let r = imps.update(&mut subjects, &cam, H, &lighting());
        assert!(r.max_ratio.is_finite() || r.images == 0);
        let mut draws = Vec::new();
        imps.draws(&subjects, &mut draws);
        for d in draws {
            assert!(
                d.mesh.positions.iter().all(|p| p.is_finite())
                    || d.mesh.positions.is_empty()
                    || std::ptr::eq(d.mesh, &*subjects[2].parts[0].mesh)
            );
        }
    }
    let _ = imps.update(
        &mut subjects,
        &camera(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO),
        0,
        &lighting(),
    );
}

#[test]
fn screen_rect_is_none_behind_the_eye_and_whole_around_it() {
    let cam = Camera::look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 1.0, 1.0);
    let rect = |z: f32| screen_rect(&cam, Vec3::new(0.0, 0.0, z), 1.0, 64, 64);
    let ahead = rect(-5.0).expect("ahead");
    assert!(ahead.width > 0 && ahead.width < 64, "{ahead:?}");
    assert_eq!(rect(5.0), None, "wholly behind");
    assert_eq!(rect(1.0), None, "touching the eye's plane from behind");
    assert_eq!(
        rect(0.5).map(|r| (r.width, r.height)),
        Some((64, 64)),
        "around the eye"
    );
}

/// A refresh's single read of its image finds the same covered bounds as
/// `metrics::covered_rect` and the same gradients as the definition applied texel by texel
/// (every right and lower neighbour pair, RGB of the stored bytes; weighted by the nearer
/// surface's distance from the quad's plane in radii, capped at 1).
#[test]
fn a_refresh_measures_its_image_as_the_definitions_say() {
    let subject = torus(Vec3::new(0.1, 0.0, 0.0));
    let b = subject.bounds();
    // 100 texels: two tiles across, a partial 8-texel block at the edge.
    let capture = Capture::new(Vec3::new(0.4, 1.5, 3.0), b.center, b.radius, 100, 0).unwrap();
    let camera = capture.camera();
    let mut draws = Vec::new();
    subject.draws(&mut draws);
    let mut cap = crate::core::Capturer::new();
    let lit = lighting();
    let t = cap.render(draws, &camera, &lit, 100, 100, engine::Encoding::Srgb);
    let got = refresh::measure(t, &capture, &mut Default::default());
    assert_eq!(
        got.covered,
        metrics::covered_rect(t, metrics::Coverage::Alpha)
    );
    let plane = capture.eye.distance(capture.center);
    let off = |x: u32, y: u32| {
        let d = t.depth_reversed(x, y).unwrap();
        if d > 0.0 {
            ((camera.view_depth_from_reversed(d) - plane).abs() / capture.radius).min(1.0) as f64
        } else {
            0.0
        }
    };
    let rgb = |x: u32, y: u32| t.pixel(x, y).unwrap().to_le_bytes();
    let (mut sum, mut weighted, mut n) = (0.0f64, 0.0f64, 0.0f64);
    for y in 0..100 {
        for x in 0..100 {
            for (qx, qy) in [(x + 1, y), (x, y + 1)] {
                if qx < 100 && qy < 100 {
                    let (p, q) = (rgb(x, y), rgb(qx, qy));
                    let d: f64 = (0..3).map(|k| p[k].abs_diff(q[k]) as f64).sum();
                    sum += d;
                    weighted += d * off(x, y).max(off(qx, qy));
                    n += 3.0;
                }
            }
        }
    }
    assert!(
        got.gradient > 1.0,
        "a lit torus has edges: {}",
        got.gradient
    );
    assert!((got.gradient as f64 - sum / n).abs() < 1e-4 * (sum / n));
    assert!((got.depth_gradient as f64 - weighted / n).abs() < 1e-4 * (weighted / n).max(1e-3));
}

#[test]
fn a_texel_budget_spreads_refreshes_over_frames_by_their_area() {
    let mut subjects = row();
    let mut imps = set(5, 5);
    let look = Vec3::new(0.0, 0.0, -4.0);
    // Each frame the eye jumps a unit sideways: every image is invalid every frame.
    let eye = |k: usize| Vec3::new((k % 2) as f32 * 1.5, 1.0, 6.0);
    imps.update(&mut subjects, &camera(eye(1), look), H, &lighting());
    let sides: Vec<u64> = imps
        .impostors
        .iter()
        .map(|i| u64::from(i.predicted.needed_side))
        .collect();
    let largest = sides.iter().max().copied().unwrap_or(0);
    let budget = largest * largest / 2;
    imps.texel_budget = Some(budget);
    let (mut spent, mut refreshes, mut idle) = (0u64, 0usize, 0usize);
    for k in 0..12 {
        let before: Vec<u64> = imps.impostors.iter().map(|i| i.refreshes).collect();
        let r = imps.update(&mut subjects, &camera(eye(k), look), H, &lighting());
        // What the report counts is the areas of the images taken this frame.
        let areas: u64 = imps
            .impostors
            .iter()
            .zip(&before)
            .filter(|(i, &b)| i.refreshes > b)
            .filter_map(|(i, _)| i.capture())
            .map(|c| u64::from(c.side).pow(2))
            .sum();
        assert_eq!(r.capture_texels, areas, "frame {k}");
        spent += r.capture_texels;
        refreshes += r.refreshes;
        idle += (r.refreshes == 0) as usize;
        // Never more than the frames so far have earned (no subject is near enough for the
        // every-frame refreshes, which may borrow).
        assert!(
            spent <= budget * (k as u64 + 1),
            "frame {k}: {spent} > {budget} x {}",
            k + 1
        );
        assert_eq!(r.images + r.geometry, 5, "every subject drawn somehow");
    }
    // The budget is spent, not hoarded: within a capture of what 12 frames earned, and
    // frames without a refresh between those with one.
    assert!(
        spent + largest * largest > budget * 12,
        "{spent} of {}",
        budget * 12
    );
    assert!(
        refreshes >= 6 && idle >= 2,
        "{refreshes} refreshes, {idle} idle frames"
    );
}

mod density;
mod shape;
