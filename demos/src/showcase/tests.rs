//! Tests of the showcase scene, its animation, the fly camera and the headless path.

use super::*;
use engine::{AlphaMode, Light, Material};
use glam::{Vec2, Vec3};

#[test]
fn scene_is_valid_and_has_every_feature() {
    let show = Showcase::new();
    let s = &show.scene;
    validate(s).unwrap();
    assert!(s.draws().count() == s.instances.len());
    let mats: Vec<&Material> = s.draws().map(|d| d.material).collect();
    assert!(mats
        .iter()
        .any(|m| matches!(m.alpha_mode, AlphaMode::Mask { .. })));
    assert!(mats.iter().any(|m| m.alpha_mode == AlphaMode::Blend));
    assert!(mats.iter().any(|m| m.base_texture.is_some()));
    assert!(s
        .draws()
        .any(|d| d.material.vertex_colors && !d.mesh.colors.is_empty()));
    assert!(s
        .lighting
        .lights
        .iter()
        .any(|l| matches!(l, Light::Point { .. })));
    assert!(s
        .lighting
        .lights
        .iter()
        .any(|l| matches!(l, Light::Directional { .. })));
}

#[test]
fn animation_moves_the_lamp_and_is_deterministic() {
    let mut a = Showcase::new();
    let mut b = Showcase::new();
    a.animate(1.5);
    b.animate(1.5);
    assert_eq!(a.scene, b.scene);
    let before = a.scene.lighting.clone();
    a.animate(2.5);
    assert_ne!(before, a.scene.lighting);
}

#[test]
fn fly_camera_moves_where_it_looks() {
    let mut c = FlyCamera::looking_at(Vec3::ZERO, Vec3::new(0.0, 0.0, -5.0));
    assert!((c.forward() - Vec3::NEG_Z).length() < 1e-5);
    c.update(
        &FlyInput {
            forward: 1.0,
            ..Default::default()
        },
        0.5,
    );
    assert!((c.position - Vec3::new(0.0, 0.0, -3.0)).length() < 1e-4);
    c.update(
        &FlyInput {
            right: 1.0,
            up: 1.0,
            ..Default::default()
        },
        1.0 / 6.0,
    );
    assert!((c.position - Vec3::new(1.0, 1.0, -3.0)).length() < 1e-4);
    let looking = FlyCamera::looking_at(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0));
    assert!((looking.forward() - Vec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-5);
    c.update(
        &FlyInput {
            pitch: 10.0,
            ..Default::default()
        },
        0.0,
    );
    assert!(c.pitch <= 1.5);
}

/// The whole headless path, sampled 20 times as densely as the default 120 frames: the eye
/// stays above the ground around it by a margin, out of the turrets, the trees and the
/// city's buildings, and the view never dives steeper than the path's limit (the old
/// frame 43 looked straight down from a target sweeping under the eye).
#[test]
fn path_stays_clear_of_the_ground_and_obstacles() {
    use crate::showcase::path::MAX_PITCH;
    use ibr::subject::Subject;
    let show = Showcase::new();
    let trees: Vec<Vec3> = show.ibr.tree_positions().collect();
    let buildings: Vec<_> = show
        .ibr
        .impostors
        .city
        .objects
        .iter()
        .map(|b| b.bounds())
        .collect();
    let n = 2400;
    let mut lowest = f32::INFINITY;
    for i in 0..n {
        let (eye, target) = show.path(i, n);
        let dir = (target - eye).normalize();
        assert!(eye.is_finite() && dir.is_finite(), "sample {i}");
        // Ground: over a disc of radius 1.5 around the eye.
        let mut ground = f32::NEG_INFINITY;
        for r in [0.0, 0.5, 1.0, 1.5] {
            for k in 0..16 {
                let (s, c) = (k as f32 * std::f32::consts::TAU / 16.0).sin_cos();
                ground = ground.max(show.terrain.height_at(eye.x + r * c, eye.z + r * s));
            }
        }
        lowest = lowest.min(eye.y - ground);
        assert!(
            eye.y > ground + 2.0,
            "sample {i}: eye {eye} over ground {ground}"
        );
        assert!(
            dir.y >= -MAX_PITCH.sin() - 1e-4,
            "sample {i}: looks down at {:.1} degrees",
            dir.y.asin().to_degrees()
        );
        // Turrets: a pylon of radius 0.35 up to the head, a head of radius 0.45.
        for t in show.ibr.turrets {
            let across = Vec2::new(eye.x - t.x, eye.z - t.z).length();
            assert!(eye.distance(t) > 1.0, "sample {i}: in turret head {t}");
            assert!(
                across > 1.0 || eye.y > t.y + 0.5,
                "sample {i}: in pylon {t}"
            );
        }
        // Trees (3.5 to 7.5 tall): not within a trunk's reach below their tops.
        for t in &trees {
            let across = Vec2::new(eye.x - t.x, eye.z - t.z).length();
            assert!(across > 1.0 || eye.y > t.y + 7.5, "sample {i}: in tree {t}");
        }
        for b in &buildings {
            assert!(
                eye.distance(b.center) > b.radius,
                "sample {i}: in building {b:?}"
            );
        }
        let statue = show.ibr.statue.object.bounds;
        assert!(
            eye.distance(statue.center) > statue.radius,
            "sample {i}: in the statue"
        );
    }
    println!("lowest eye over the ground within 1.5: {lowest:.2}");
}

/// A tap shorter than a frame (press and release between two frames) still toggles; a held
/// key's auto-repeated presses count once; two taps in one frame cancel out.
#[test]
fn key_taps_toggle_once_per_press_from_events() {
    let mut taps = TapCounter::default();
    // Press and release between two frames: the key is up again when the frame looks.
    taps.event(true);
    taps.event(false);
    let n = taps.take();
    assert_eq!(n, 1);
    assert!(toggled(false, n));
    assert_eq!(taps.take(), 0, "taken once");
    assert!(!toggled(false, 0));
    // Held over several frames with auto-repeat: one tap, on the first frame.
    taps.event(true);
    assert_eq!(taps.take(), 1);
    taps.event(true);
    taps.event(true);
    assert_eq!(taps.take(), 0);
    taps.event(false);
    assert_eq!(taps.take(), 0);
    // Two quick taps within one frame: toggled twice, back where it was.
    for down in [true, false, true, false] {
        taps.event(down);
    }
    let n = taps.take();
    assert_eq!(n, 2);
    assert!(toggled(true, n));
}

#[test]
fn every_attraction_shows_a_catalogued_technique_and_every_catalogued_one_is_shown() {
    use crate::showcase::attractions::ATTRACTIONS;
    for a in ATTRACTIONS {
        let entry = ibr::catalog().iter().find(|e| e.attraction == Some(a.name));
        assert!(entry.is_some(), "{}: no catalogue entry shows it", a.name);
    }
    for e in ibr::catalog() {
        if let Some(name) = e.attraction {
            let shown = ATTRACTIONS.iter().any(|a| a.name == name);
            assert!(shown, "{}: no showcase attraction {name}", e.name);
        }
    }
}

/// Frame options the tour renders with: the target cleared to the sky.
fn sky_clear() -> FrameOptions {
    FrameOptions {
        clear: Some(SKY),
        ..Default::default()
    }
}

/// The tour's first frame prepared at loading ([`Showcase::prepare`]): the clouds' and the
/// city's first captures are done there, budgets lifted, so frame 0 itself refreshes no
/// impostor (without it, frame 0 takes the first captures its budgets allow); the run's
/// counters count the tour's frames only.
#[test]
fn the_first_frame_prepared_at_loading_leaves_frame_0_no_captures() {
    let (w, h, n) = (320, 180, 120);
    let opts = sky_clear();
    let first = |prepare: bool| {
        let mut show = Showcase::new();
        let mut renderer = Renderer::new();
        let mut target = Target::new(w, h);
        show.animate(0.0);
        let (eye, look) = show.path(0, n);
        let cam = camera(eye, look, w, h);
        let prepared = prepare.then(|| show.prepare(&mut renderer, &cam, &mut target, &opts));
        show.render(&mut renderer, &cam, &mut target, &opts);
        let imp = &show.ibr.impostors;
        (prepared, imp.readout().refreshes(), imp.run_stats().frames)
    };
    let (none, cold, _) = first(false);
    let (prepared, warm, frames) = first(true);
    let prepared = prepared.expect("prepared");
    eprintln!("frame 0: {cold} refreshes cold; prepared {prepared:?}, then {warm}");
    assert!(none.is_none() && cold > 0);
    assert!(prepared.refreshes >= cold, "{prepared:?}");
    assert!(prepared.frames < PREPARE_FRAMES, "{prepared:?}");
    assert_eq!(warm, 0);
    assert_eq!(frames, 1, "the run counts the tour's frames only");
}

/// The attraction meter's per-frame buffers are kept frame to frame: once every attraction
/// it measures has been measured (and the frame after, whose scratch is traded with the
/// tracks' last renders), measuring more frames of the same size holds the same bytes.
/// Until session 17 each measured attraction allocated its renders, a copy of them and
/// both targets' bytes again for the PSNR, every frame (55% of the 640x360 tour's minor
/// page faults, `perf record -e page-faults`).
#[test]
fn the_attraction_meter_keeps_its_buffers_frame_to_frame() {
    use crate::showcase::attractions::Meter;
    let (w, h, n) = (320, 180, 120);
    let opts = sky_clear();
    let mut show = Showcase::new();
    let mut renderer = Renderer::new();
    let mut target = Target::new(w, h);
    let mut meter = Meter::new();
    let (mut held, mut started) = (Vec::new(), Vec::new());
    for i in 22..32 {
        show.animate(i as f32 / 30.0);
        let (eye, look) = show.path(i, n);
        let cam = camera(eye, look, w, h);
        show.render(&mut renderer, &cam, &mut target, &opts);
        meter.tour(&show, &cam, w, h);
        held.push(meter.held());
        started.push(meter.tracks.iter().filter(|t| t.frames > 0).count());
    }
    let all = *started.last().unwrap();
    let first = started.iter().position(|&s| s == all).unwrap();
    eprintln!("tracks started {started:?}, bytes held {held:?}");
    assert!(all >= 2, "{started:?}");
    assert!(first + 3 < held.len(), "{started:?}");
    assert!(
        held[first + 1..].iter().all(|&b| b == held[first + 1]),
        "{held:?}"
    );
    assert!(
        held[first + 1] >= all * w as usize * h as usize * 9,
        "{held:?}"
    );
}

/// `--draw-costs`: each frame's draws grouped (forest, terrain, city, statue, clouds,
/// effects, other) account for every fragment the frame counted, tested, shaded, blended
/// and in rows (the engine's per-draw costs plus the statue's and the flare's image
/// passes), and counting changes no pixel.
#[test]
fn the_draw_groups_sum_to_the_frames_counters_and_change_no_pixel() {
    use crate::showcase::ibr_layer::GROUPS;
    let (w, h, n) = (160, 90, 120);
    let opts = sky_clear();
    let mut counted = (Showcase::new(), Renderer::new(), Target::new(w, h));
    let mut plain = (Showcase::new(), Renderer::new(), Target::new(w, h));
    counted.0.count_draws(&mut counted.1, true);
    let mut shaded = [0u64; GROUPS.len()];
    for i in [0, 20, 25, 40, 60, 75, 100] {
        let (eye, look) = counted.0.path(i, n);
        let cam = camera(eye, look, w, h);
        let (show, renderer, target) = &mut counted;
        show.animate(i as f32 / 30.0);
        let stats = show.render(renderer, &cam, target, &opts);
        let g = show.draw_groups().expect("counted");
        assert_eq!(g.error, None, "frame {i}");
        let t = g.total();
        assert_eq!(t.draws as usize, renderer.draw_costs().len(), "frame {i}");
        assert_eq!(t.fragments_tested, stats.fragments_tested, "frame {i}");
        assert_eq!(t.fragments_shaded, stats.fragments_shaded, "frame {i}");
        assert_eq!(
            t.fragments_blended, stats.fragments_shaded_blended,
            "frame {i}"
        );
        assert_eq!(t.rows_shaded, stats.rows_shaded, "frame {i}");
        for (s, c) in shaded.iter_mut().zip(&g.groups) {
            *s += c.fragments_shaded;
        }
        let (show, renderer, target) = &mut plain;
        show.animate(i as f32 / 30.0);
        show.render(renderer, &cam, target, &opts);
        assert!(show.draw_groups().is_none() && renderer.draw_costs().is_empty());
        assert_eq!(counted.2.to_rgba8(), target.to_rgba8(), "frame {i}");
    }
    eprintln!(
        "fragments shaded by group: {:?}",
        GROUPS.iter().zip(&shaded).collect::<Vec<_>>()
    );
    for g in ["forest_sprites", "terrain", "clouds", "effects", "other"] {
        let k = GROUPS.iter().position(|&x| x == g).unwrap();
        assert!(shaded[k] > 0, "{g}: {shaded:?}");
    }
}
