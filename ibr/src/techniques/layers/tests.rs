//! Image layers against the geometry they stand for: exact where an affine warp is exact,
//! their geometric error against its analytic value, the shared scheduler's budget, and
//! the cases where the method breaks (edge-on, behind the eye, turned past the image).

use super::*;
use crate::core::MeshGroup;
use crate::metrics::{self, Options};
use engine::{procedural, FrameOptions, Renderer, Rgba, Target, Texture};
use glam::Vec3;
use std::sync::Arc;

const W: u32 = 128;
const H: u32 = 96;

fn lighting() -> Lighting {
    Lighting::white_sun(0.3, Vec3::new(-0.3, -1.0, -0.4))
}

fn camera(eye: Vec3, target: Vec3) -> Camera {
    Camera::look_at(eye, target, Vec3::Y, 0.9, W as f32 / H as f32).with_depth_range(0.05, 100.0)
}

/// A checkered card `size` units wide facing +z at `at` (flat: its box has no depth).
fn card(at: Vec3, size: f32) -> MeshGroup {
    let texture = Texture::checker(
        64,
        8,
        Rgba::new(0.9, 0.8, 0.2, 1.0),
        Rgba::new(0.1, 0.2, 0.6, 1.0),
    );
    let material = Material::unlit(Rgba::WHITE).with_texture(Arc::new(texture));
    MeshGroup::new().with(
        Arc::new(procedural::quad(size, size)),
        Arc::new(material),
        Mat4::from_translation(at),
    )
}

/// A lit box `size` across at `at`.
fn cube(at: Vec3, size: Vec3) -> MeshGroup {
    MeshGroup::new().with(
        Arc::new(procedural::cuboid(size)),
        Arc::new(Material::lit(Rgba::new(0.8, 0.4, 0.2, 1.0))),
        Mat4::from_translation(at),
    )
}

/// The frame of `draws` over a transparent clear.
fn render(draws: Vec<Draw<'_>>, camera: &Camera) -> Target {
    let mut target = Target::new(W, H);
    let opts = FrameOptions {
        clear: Some(Rgba::TRANSPARENT),
        ..FrameOptions::default()
    };
    Renderer::new().render(draws, camera, &lighting(), &mut target, &opts);
    target
}

/// The layers' frame against the subjects' geometry from `camera`.
fn error(set: &LayerSet, subjects: &[MeshGroup], camera: &Camera) -> metrics::ImageError {
    let mut draws = Vec::new();
    set.draws(subjects, &mut draws);
    let image = render(draws, camera);
    let mut truth = Vec::new();
    subjects.iter().for_each(|s| s.draws(&mut truth));
    let truth = render(truth, camera);
    metrics::compare(&truth, &image, &Options::default()).expect("same size")
}

fn update(set: &mut LayerSet, subjects: &mut [MeshGroup], camera: &Camera) -> Report {
    set.update(subjects, camera, (W, H), &lighting())
}

#[test]
fn a_fresh_layer_is_the_geometry() {
    let mut subjects = [cube(Vec3::ZERO, Vec3::new(1.0, 0.8, 0.6))];
    let mut set = LayerSet::new(Config::default(), 1);
    let cam = camera(Vec3::new(0.7, 0.9, 3.5), Vec3::ZERO);
    let r = update(&mut set, &mut subjects, &cam);
    assert_eq!((r.refreshes, r.images, r.geometry), (1, 1, 0), "{r:?}");
    assert_eq!(set.layers[0].predicted.pixels, 0.0);
    // Rendered at the screen's resolution on its pixel grid: texel centres on pixel
    // centres, so the warp copies texels (the blend of a premultiplied texel over nothing
    // is the texel).
    let e = error(&set, &subjects, &cam);
    assert!(e.mean_abs < 0.5 && e.psnr_db > 40.0, "{e:?}");
}

#[test]
fn a_card_facing_the_screen_stays_exact_as_the_eye_slides_beside_it() {
    // Points on a plane parallel to the image plane move by one translation and scale when
    // the eye moves: the affine map is the true warp, whatever the distance moved.
    let mut subjects = [card(Vec3::ZERO, 1.2)];
    let mut set = LayerSet::new(Config::default(), 1);
    let eye = Vec3::new(0.0, 0.0, 3.0);
    update(&mut set, &mut subjects, &camera(eye, eye - Vec3::Z));
    for dx in [0.2f32, 0.5, -0.6] {
        let eye = eye + Vec3::new(dx, 0.3 * dx, 0.0);
        let cam = camera(eye, eye - Vec3::Z);
        let r = update(&mut set, &mut subjects, &cam);
        assert_eq!((r.refreshes, r.images), (0, 1), "{r:?}");
        assert!(set.layers[0].predicted.pixels < 0.01, "{:?}", set.layers[0]);
        let e = error(&set, &subjects, &cam);
        // Resampling between texels: the checker's edges blur by up to a pixel.
        assert!(
            e.mean_abs < 6.0 && e.coverage_mismatch < 0.01,
            "dx {dx}: {e:?}"
        );
    }
}

#[test]
fn the_geometric_error_follows_the_parallax_of_the_box_depth() {
    // A box from 0.5 in front of z = 0 to 0.5 behind it, seen from 4 units away: moving the
    // eye sideways by `d` shifts its front and back faces apart by f d (1/3.5 - 1/4.5) pixels
    // (f the focal length in pixels). The best affine map splits that difference: its
    // error is between a quarter of it and all of it.
    let mut subjects = [cube(Vec3::ZERO, Vec3::new(1.0, 1.0, 1.0))];
    let cfg = Config {
        tolerance_px: f32::INFINITY,
        octaves: f32::INFINITY,
        ..Config::default()
    };
    let mut set = LayerSet::new(cfg, 1);
    let eye = Vec3::new(0.0, 0.0, 4.0);
    update(&mut set, &mut subjects, &camera(eye, eye - Vec3::Z));
    let focal = 0.5 * H as f32 / (0.45f32).tan();
    let mut last = 0.0;
    for d in [0.1f32, 0.2, 0.4] {
        let eye = eye + Vec3::X * d;
        let r = update(&mut set, &mut subjects, &camera(eye, eye - Vec3::Z));
        assert_eq!(r.refreshes, 0);
        let got = set.layers[0].predicted.pixels;
        let parallax = focal * d * (1.0 / 3.5 - 1.0 / 4.5);
        assert!(
            got > 0.25 * parallax && got < parallax,
            "d {d}: {got} vs {parallax}"
        );
        assert!(got > last, "grows with the motion");
        last = got;
    }
}

#[test]
fn a_perspective_warp_follows_a_turn_of_the_view_exactly() {
    // Turning in place moves every point by one homography, whatever its depth: the
    // perspective warp stays exact where the affine one errs.
    let mut subjects = [cube(Vec3::new(1.2, 0.3, -4.0), Vec3::new(1.0, 1.5, 2.0))];
    let eye = Vec3::new(0.0, 0.5, 0.0);
    let look = |yaw: f32| camera(eye, eye + Vec3::new(yaw.sin(), 0.0, -yaw.cos()));
    let never = Config {
        tolerance_px: f32::INFINITY,
        octaves: f32::INFINITY,
        ..Config::default()
    };
    let mut affine = LayerSet::new(never, 1);
    let mut persp = LayerSet::new(
        Config {
            perspective: true,
            ..never
        },
        1,
    );
    for set in [&mut affine, &mut persp] {
        update(set, &mut subjects, &look(0.0));
    }
    for yaw in [0.15f32, 0.3] {
        let cam = look(yaw);
        update(&mut affine, &mut subjects, &cam);
        let r = update(&mut persp, &mut subjects, &cam);
        assert_eq!(r.refreshes, 0);
        let (a, p) = (affine.layers[0].predicted, persp.layers[0].predicted);
        assert!(a.pixels > 0.7, "yaw {yaw}: affine {a:?}");
        assert!(p.pixels < 0.05, "yaw {yaw}: perspective {p:?}");
        let (ea, ep) = (
            error(&affine, &subjects, &cam),
            error(&persp, &subjects, &cam),
        );
        assert!(
            ep.mean_abs < ea.mean_abs && ep.mean_abs < 1.0,
            "yaw {yaw}: {ep:?} {ea:?}"
        );
    }
}

#[test]
fn a_layer_is_re_rendered_past_its_tolerance_and_then_exact_again() {
    let mut subjects = [cube(Vec3::ZERO, Vec3::new(1.0, 1.0, 1.0))];
    let mut set = LayerSet::new(Config::default(), 1);
    let mut eye = Vec3::new(0.0, 0.3, 4.0);
    let mut refreshes = 0;
    for _ in 0..40 {
        eye += Vec3::X * 0.02;
        let r = update(&mut set, &mut subjects, &camera(eye, Vec3::ZERO));
        refreshes += r.refreshes;
        // Refreshed in the frame it passed the tolerance: never drawn over it.
        assert_eq!(r.over_tolerance, 0, "{r:?}");
        assert!(set.layers[0].predicted.pixels < 1.0);
    }
    assert!((2..40).contains(&refreshes), "{refreshes} refreshes");
}

#[test]
fn moving_nearer_passes_the_sampling_tolerance() {
    let mut subjects = [card(Vec3::ZERO, 1.0)];
    let cfg = Config {
        tolerance_px: f32::INFINITY,
        ..Config::default()
    };
    let mut set = LayerSet::new(cfg, 1);
    let cam = |z: f32| camera(Vec3::new(0.0, 0.0, z), Vec3::ZERO);
    update(&mut set, &mut subjects, &cam(6.0));
    // 6 -> 4.5 magnifies by 4/3: 0.415 octaves, under 0.5.
    let r = update(&mut set, &mut subjects, &cam(4.5));
    assert_eq!(r.refreshes, 0);
    assert!(
        (set.layers[0].predicted.octaves - 0.415).abs() < 0.02,
        "{:?}",
        set.layers[0]
    );
    // 6 -> 4 magnifies by 1.5: 0.585 octaves.
    let r = update(&mut set, &mut subjects, &cam(4.0));
    assert_eq!(r.refreshes, 1, "{r:?}");
}

#[test]
fn the_budget_goes_to_the_largest_errors_and_stale_images_fall_back_to_geometry() {
    let at = [-2.0f32, 0.0, 2.0];
    let mut subjects: Vec<MeshGroup> = at
        .iter()
        .map(|&x| cube(Vec3::new(x, 0.0, -(x + 2.0)), Vec3::ONE))
        .collect();
    let cfg = Config {
        budget: Budget::count(1),
        ..Config::default()
    };
    let mut set = LayerSet::new(cfg, 3);
    let eye = Vec3::new(0.0, 0.5, 6.0);
    let mut firsts = Vec::new();
    for _ in 0..3 {
        let r = update(
            &mut set,
            &mut subjects,
            &camera(eye, Vec3::new(0.0, 0.0, -2.0)),
        );
        assert_eq!(r.refreshes, 1, "one per frame");
        firsts.push(r);
    }
    assert_eq!(firsts[0].geometry, 2, "no image yet: geometry");
    assert_eq!(firsts[2].images, 3);
    // A large move: every layer invalid; the worst (nearest: most parallax) is refreshed
    // and the others, far past the fallback ratio, drawn as geometry.
    let far = eye + Vec3::new(2.5, 0.0, 0.0);
    let r = update(
        &mut set,
        &mut subjects,
        &camera(far, Vec3::new(0.0, 0.0, -2.0)),
    );
    assert_eq!(r.refreshes, 1, "{r:?}");
    assert_eq!(r.stale, 2, "{r:?}");
    assert_eq!(r.stale_fallbacks + r.over_tolerance, 2, "{r:?}");
    assert_eq!(set.layers[0].refreshes, 2, "the nearest goes first");
    assert_eq!(set.layers[2].refreshes, 1, "the farthest waits");
    // What is drawn is never an image past the fallback ratio.
    for l in &set.layers {
        assert!(l.mode != Mode::Image || l.predicted.ratio <= 2.0, "{l:?}");
    }
}

#[test]
fn an_edge_on_card_and_a_corner_behind_the_eye_do_not_break_it() {
    let mut subjects = [card(Vec3::ZERO, 1.0)];
    let mut set = LayerSet::new(Config::default(), 1);
    // Seen exactly edge-on: its corners lie on one line on screen.
    let side = camera(Vec3::new(3.0, 0.0, 0.0), Vec3::ZERO);
    let r = update(&mut set, &mut subjects, &side);
    assert!(r.refreshes <= 1 && r.images + r.geometry == 1, "{r:?}");
    let l = &set.layers[0];
    assert!(l.warp.h.is_finite(), "{l:?}");
    assert!(!l.predicted.pixels.is_nan() && !l.predicted.ratio.is_nan());
    // Turning away from edge-on opens the card: a new image.
    let turned = camera(Vec3::new(2.6, 0.0, 1.5), Vec3::ZERO);
    let r = update(&mut set, &mut subjects, &turned);
    assert_eq!(r.refreshes, 1, "{r:?}");
    let e = error(&set, &subjects, &turned);
    assert!(e.mean_abs < 2.0, "{e:?}");
    // The eye inside the card's box (a corner behind the near plane): geometry.
    let inside = camera(Vec3::new(0.3, 0.0, 0.0), Vec3::new(0.3, 0.0, -1.0));
    let r = update(&mut set, &mut subjects, &inside);
    assert_eq!(set.layers[0].mode, Mode::Geometry(Why::Behind), "{r:?}");
    // Wholly behind the eye: not drawn at all.
    let away = camera(Vec3::new(0.0, 0.0, 2.0), Vec3::new(0.0, 0.0, 5.0));
    let r = update(&mut set, &mut subjects, &away);
    assert_eq!((set.layers[0].mode, r.culled), (Mode::Culled, 1), "{r:?}");
}

#[test]
fn turning_past_the_edge_of_a_cropped_image_re_renders_it() {
    // A wall reaching past the view on both sides (its ends 125 pixels from the centre of
    // a 128-pixel view): its image stops at the margin, 96 pixels out; turning further
    // shows wall the image lacks.
    let mut subjects = [cube(Vec3::new(0.0, 0.0, -4.0), Vec3::new(10.0, 2.0, 0.2))];
    let cfg = Config {
        tolerance_px: f32::INFINITY,
        octaves: f32::INFINITY,
        ..Config::default()
    };
    let mut set = LayerSet::new(cfg, 1);
    let eye = Vec3::new(0.0, 0.0, 0.0);
    update(
        &mut set,
        &mut subjects,
        &camera(eye, Vec3::new(0.0, 0.0, -1.0)),
    );
    let (w, _) = set.layers[0].image_size().expect("an image");
    assert!(
        w <= (W as f32 * 1.5) as u32 + 1,
        "cropped at the margin: {w}"
    );
    let r = update(
        &mut set,
        &mut subjects,
        &camera(eye, Vec3::new(0.01, 0.0, -1.0)),
    );
    assert_eq!(r.refreshes, 0, "a small turn stays within the margin");
    let r = update(
        &mut set,
        &mut subjects,
        &camera(eye, Vec3::new(0.4, 0.0, -1.0)),
    );
    assert_eq!(r.refreshes, 1, "{r:?}");
    assert!(set.layers[0].predicted.covered);
}

#[test]
fn the_same_pixels_on_one_thread_and_on_two() {
    let frames = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a pool");
        pool.install(|| {
            let mut subjects: Vec<MeshGroup> = (0..4)
                .map(|k| {
                    cube(
                        Vec3::new(k as f32 - 1.5, 0.0, -(k as f32)),
                        Vec3::splat(0.8),
                    )
                })
                .collect();
            let mut set = LayerSet::new(Config::default(), subjects.len());
            let mut out = Vec::new();
            for f in 0..4 {
                let cam = camera(
                    Vec3::new(0.1 * f as f32, 1.0, 5.0),
                    Vec3::new(0.0, 0.0, -1.5),
                );
                update(&mut set, &mut subjects, &cam);
                let mut draws = Vec::new();
                set.draws(&subjects, &mut draws);
                out.push(render(draws, &cam).to_rgba8());
            }
            out
        })
    };
    assert_eq!(frames(1), frames(2));
}

#[test]
fn a_ground_cut_by_depth_keeps_every_triangle_in_one_slab() {
    let ground = MeshGroup::new().with(
        Arc::new(procedural::plane(20.0, 20.0, 16, 16)),
        Arc::new(Material::lit(Rgba::WHITE)),
        Mat4::IDENTITY,
    );
    let slabs = split_by_depth(&ground, Vec3::NEG_Z, 4);
    assert_eq!(slabs.len(), 4);
    let total: usize = slabs.iter().map(|s| s.triangle_count()).sum();
    assert_eq!(total, ground.triangle_count());
    for (k, s) in slabs.iter().enumerate() {
        // Slab k holds centroids with -z in [-10 + 5k, -10 + 5(k+1)]: its box reaches at
        // most one grid cell (1.25) beyond.
        let c = s.corners();
        let (lo, hi) = (-c[4].z, -c[0].z);
        let (a, b) = (-10.0 + 5.0 * k as f32, -5.0 + 5.0 * k as f32);
        assert!(lo >= a - 1.3 && hi <= b + 1.3, "slab {k}: {lo}..{hi}");
        for p in &s.parts {
            p.mesh.validate().expect("valid");
        }
    }
    assert!(split_by_depth(&MeshGroup::new(), Vec3::Z, 3).is_empty());
}

#[test]
fn an_empty_target_and_a_broken_subject_do_not_panic() {
    let mut broken = cube(Vec3::ZERO, Vec3::ONE);
    broken.parts[0].transform = Mat4::from_translation(Vec3::NAN);
    let mut subjects = [cube(Vec3::ZERO, Vec3::ONE), broken, MeshGroup::new()];
    let mut set = LayerSet::new(Config::default(), 3);
    let cam = camera(Vec3::new(0.0, 0.5, 4.0), Vec3::ZERO);
    let r = set.update(&mut subjects, &cam, (0, 0), &lighting());
    assert_eq!(r.images, 0, "{r:?}");
    for _ in 0..2 {
        let r = update(&mut set, &mut subjects, &cam);
        assert!(r.max_px.is_finite(), "{r:?}");
        for l in &set.layers {
            assert!(!l.predicted.ratio.is_nan(), "{l:?}");
        }
    }
    let mut draws = Vec::new();
    set.draws(&subjects, &mut draws);
    let frame = render(draws, &cam);
    assert_eq!(frame.width(), W);
}
