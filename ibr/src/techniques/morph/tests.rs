//! View morphing on rendered views of textured cards, against the geometry rendered from
//! the in-between cameras.

use super::*;
use crate::core::capture_batch;
use crate::metrics::compare_seen;
use crate::stereo::scenes::{with_scene_draws, H, W};
use engine::Lighting;

/// The cards (a large slanted one, a small one in front) seen from `cameras`.
pub(super) fn views(cameras: &[Camera]) -> Vec<DepthImage> {
    with_scene_draws(|draws| capture_batch(draws, cameras, &Lighting::default(), W, H))
}

/// A camera at `eye` looking at `target`.
pub(super) fn looking(eye: Vec3, target: Vec3) -> Camera {
    Camera::look_at(eye, target, Vec3::Y, 0.8, W as f32 / H as f32).with_depth_range(0.1, 50.0)
}

/// PSNR of `image` against `truth` over the pixels both cover: where the views agree on
/// what is there, how well it is placed. (The prewarp crops what turns out of its frame,
/// measured apart by [`covered`].)
pub(super) fn psnr(image: &DepthImage, truth: &DepthImage) -> f64 {
    compare_seen(image, truth)
        .expect("same size")
        .0
        .psnr_capped(99.0)
}

/// The share of `truth`'s covered pixels `image` covers.
pub(super) fn covered(image: &DepthImage, truth: &DepthImage) -> f64 {
    compare_seen(image, truth).expect("same size").1
}

/// Two views converging on the cards from either side (turned toward each other by about
/// 9 degrees: not parallel).
pub(super) fn verged() -> (Camera, Camera) {
    let target = Vec3::new(0.0, 0.0, 0.0);
    (
        looking(Vec3::new(-0.8, 0.1, 5.0), target),
        looking(Vec3::new(0.8, -0.1, 5.0), target),
    )
}

#[test]
fn the_ends_of_the_morph_are_the_two_views() {
    let (a, b) = verged();
    let v = views(&[a, b]);
    let morph = ViewMorph::new(&v[0], &v[1], Correspondence::Depth).expect("morphable");
    let (first, _) = morph.frame(0.0);
    let (last, _) = morph.frame(1.0);
    // (Measured: 26.7 and 24.6 dB, every pixel: prewarp and postwarp each resample the
    // noise texture once.)
    for (image, view) in [(&first, &v[0]), (&last, &v[1])] {
        let (p, c) = (psnr(image, view), covered(image, view));
        eprintln!("{p:.1} dB over {:.1}% of the view", 100.0 * c);
        assert!(p > 20.0 && c > 0.8, "{p:.1} dB over {:.1}%", 100.0 * c);
    }
}

#[test]
fn the_prewarp_keeps_shape_where_a_plain_morph_does_not() {
    let (a, b) = verged();
    let v = views(&[a, b]);
    let morph = ViewMorph::new(&v[0], &v[1], Correspondence::Depth).expect("morphable");
    for s in [0.25, 0.5, 0.75] {
        let camera = morph.camera_at(s);
        let truth = views(&[camera]).remove(0);
        let (view, stats) = morph.frame(s);
        let plain = plain_morph(&v[0], &v[1], s);
        let (good, bad) = (psnr(&view, &truth), psnr(&plain, &truth));
        eprintln!(
            "s {s}: morph {good:.1} dB over {:.1}%, plain {bad:.1} dB",
            100.0 * covered(&view, &truth)
        );
        // The plain morph moves points on straight lines between two non-parallel views:
        // off where the in-between camera sees them.
        // (Measured: 23.9, 22.9 and 23.2 dB against 19.7, 18.1 and 19.6.)
        assert!(
            good > bad + 3.0,
            "s {s}: morph {good:.1} dB, plain {bad:.1} dB"
        );
        assert!(stats.from_left > 0 && stats.from_right > 0, "{stats:?}");
    }
}

#[test]
fn the_in_between_camera_interpolates_eye_and_orientation() {
    let (a, b) = verged();
    let v = views(&[a, b]);
    let morph = ViewMorph::new(&v[0], &v[1], Correspondence::Depth).expect("morphable");
    let mid = morph.camera_at(0.5);
    assert!((mid.eye() - (a.eye() + b.eye()) * 0.5).length() < 1e-4);
    // Halfway between the two view directions.
    let halfway = (a.forward() + b.forward()).normalize();
    assert!(mid.forward().dot(halfway) > 0.99999, "{:?}", mid.forward());
    for (s, c) in [(0.0, a), (1.0, b)] {
        let m = morph.camera_at(s);
        assert!((m.eye() - c.eye()).length() < 1e-4 && m.forward().dot(c.forward()) > 0.99999);
    }
}

#[test]
fn stereo_correspondences_morph_nearly_as_well_as_depth() {
    let (a, b) = verged();
    let v = views(&[a, b]);
    let truth = views(&[ViewMorph::new(&v[0], &v[1], Correspondence::Depth)
        .expect("morphable")
        .camera_at(0.5)])
    .remove(0);
    let by = |how| {
        let morph = ViewMorph::new(&v[0], &v[1], how).expect("morphable");
        psnr(&morph.frame(0.5).0, &truth)
    };
    let depth = by(Correspondence::Depth);
    // (The cards lie 45 to 76 pixels apart in the prewarped pair.)
    let stereo = by(Correspondence::Stereo { max_disparity: 96 });
    // (Measured: 17.6 dB from the matcher, 22.9 dB from depth. On this small verged pair
    // the matcher is off by more than two pixels on 20% of the left view and 14% of the
    // right one; what it leaves unknown is filled from the background side.)
    eprintln!("stereo {stereo:.1} dB, depth {depth:.1} dB");
    assert!(
        stereo > depth - 6.5 && stereo > 15.0,
        "stereo {stereo:.1} dB, depth {depth:.1} dB"
    );
}

#[test]
fn motion_toward_the_scene_is_refused() {
    // The second eye straight ahead of the first: its epipole is in the image.
    let a = looking(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
    let b = looking(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO);
    let v = views(&[a, b]);
    let err = ViewMorph::new(&v[0], &v[1], Correspondence::Depth).unwrap_err();
    assert!(
        matches!(err, MorphError::Prewarp(RectifyError::AlongTheView(_))),
        "{err}"
    );
    assert!(err.to_string().contains("epipole"), "{err}");
}

#[test]
fn a_visibility_change_is_filled_from_the_other_view_and_counted() {
    // Far apart: the small card hides different parts of the large one from each eye.
    let target = Vec3::ZERO;
    let (a, b) = (
        looking(Vec3::new(-1.5, 0.0, 5.0), target),
        looking(Vec3::new(1.5, 0.0, 5.0), target),
    );
    let v = views(&[a, b]);
    let morph = ViewMorph::new(&v[0], &v[1], Correspondence::Depth).expect("morphable");
    let (view, stats) = morph.frame(0.5);
    assert!(stats.from_right > 50, "{stats:?}");
    // Counted in the frame (not the larger prewarped pair): every pixel the view covers
    // (at least half), once.
    let total = stats.from_left + stats.from_right + stats.holes;
    let covered = view.color.iter().filter(|c| c.a >= 0.5).count() as u64;
    let any = view.color.iter().filter(|c| c.a > 0.0).count() as u64;
    let opaque = view.color.iter().filter(|c| c.a >= 0.999).count() as u64;
    eprintln!(
        "{stats:?}: {covered} covered, {any} any, {opaque} opaque, {}",
        W * H
    );
    assert!(total <= u64::from(W * H), "{stats:?}");
    assert!(
        total.abs_diff(covered) * 100 <= covered,
        "{stats:?}: {covered} covered"
    );
    for c in &view.color {
        assert!(c.r.is_finite() && c.g.is_finite() && c.b.is_finite() && c.a.is_finite());
    }
}

/// Crack pixels of `image`: empty, between two covered neighbours (left and right, or
/// above and below) of one surface (depths within 5%).
fn cracks(image: &DepthImage) -> usize {
    let (w, h) = (image.width() as i64, image.height() as i64);
    let at = |x: i64, y: i64| {
        (x >= 0 && y >= 0 && x < w && y < h)
            .then(|| image.depth[(y * w + x) as usize])
            .filter(|d| d.is_finite())
    };
    let mut n = 0;
    for y in 0..h {
        for x in 0..w {
            if at(x, y).is_some() {
                continue;
            }
            let pair = |(dx, dy): (i64, i64)| match (at(x - dx, y - dy), at(x + dx, y + dy)) {
                (Some(a), Some(b)) => (a - b).abs() <= 0.05 * a.min(b),
                _ => false,
            };
            if pair((1, 0)) || pair((0, 1)) {
                n += 1;
            }
        }
    }
    n
}

#[test]
fn a_plain_morph_that_stretches_the_image_opens_no_cracks() {
    // The second eye nearer the cards: halfway, the first view's pixels spread about a
    // third apart again, and one pixel each would leave lines of holes across the cards.
    let target = Vec3::ZERO;
    let (a, b) = (
        looking(Vec3::new(-0.8, 0.1, 5.0), target),
        looking(Vec3::new(0.5, 0.0, 3.0), target),
    );
    let v = views(&[a, b]);
    for s in [0.3, 0.5, 0.8] {
        let plain = plain_morph(&v[0], &v[1], s);
        let covered = plain.depth.iter().filter(|d| d.is_finite()).count();
        let n = cracks(&plain);
        eprintln!("s {s}: {n} crack pixels in {covered}");
        assert!(covered > (W * H / 4) as usize, "s {s}: {covered} covered");
        assert!(n * 1000 <= covered, "s {s}: {n} crack pixels in {covered}");
    }
}

/// A compact object over empty space: a textured card 2 units wide at the origin and a
/// small one half a unit in front, seen from `cameras`.
fn object_views(cameras: &[Camera]) -> Vec<DepthImage> {
    use engine::procedural::{self, XorShift};
    use engine::{Draw, Encoding, Material, Rgba, Texture};
    let mut rng = XorShift::new(5);
    let px: Vec<u8> = (0..64 * 64)
        .flat_map(|_| {
            let v = (rng.next_u64() % 256) as u8;
            [v, v, v, 255]
        })
        .collect();
    let texture = std::sync::Arc::new(Texture::from_rgba8(64, 64, &px, Encoding::Srgb).unwrap());
    let material = Material::unlit(Rgba::WHITE)
        .with_texture(texture)
        .double_sided(true);
    let (big, small) = (procedural::quad(2.0, 2.0), procedural::quad(0.8, 0.8));
    let draws = [
        Draw {
            mesh: &big,
            material: &material,
            transform: Mat4::IDENTITY,
        },
        Draw {
            mesh: &small,
            material: &material,
            transform: Mat4::from_translation(Vec3::new(0.2, 0.1, 0.5)),
        },
    ];
    capture_batch(&draws, cameras, &Lighting::default(), W, H)
}

#[test]
fn stereo_disparities_past_the_search_window_are_found_by_a_coarse_search() {
    // Far apart (as 30 degrees is for a 640-pixel view): the object lies about 85 to 95
    // pixels apart in the prewarped pair.
    let target = Vec3::ZERO;
    let (a, b) = (
        looking(Vec3::new(-1.5, 0.0, 5.0), target),
        looking(Vec3::new(1.5, 0.0, 5.0), target),
    );
    let v = object_views(&[a, b]);
    let truth = object_views(&[ViewMorph::new(&v[0], &v[1], Correspondence::Depth)
        .expect("morphable")
        .camera_at(0.5)])
    .remove(0);
    let by = |max_disparity| {
        let morph = ViewMorph::new(&v[0], &v[1], Correspondence::Stereo { max_disparity })?;
        let view = morph.frame(0.5).0;
        Ok::<_, MorphError>((psnr(&view, &truth), covered(&view, &truth)))
    };
    // A window from 0 past every disparity, against one short of the least: from 0 it
    // would match every pixel short of where it is (the object doubled); placed by the
    // coarse search it holds them all.
    let (wide, narrow) = (by(128).expect("morphable"), by(64).expect("morphable"));
    eprintln!("window 128: {wide:.1?}, window 64: {narrow:.1?} (dB, share covered)");
    assert!(
        narrow.0 > wide.0 - 1.5 && narrow.1 > wide.1 - 0.02,
        "window 64: {narrow:.1?} against {wide:.1?}"
    );
}

/// Two textured posts side by side with open sky between and around them, seen from
/// `cameras`.
fn posts_views(cameras: &[Camera]) -> Vec<DepthImage> {
    use engine::procedural;
    use engine::{Draw, Material, Rgba};
    let material = Material::unlit(Rgba::new(0.8, 0.4, 0.2, 1.0)).double_sided(true);
    let post = procedural::quad(0.6, 2.0);
    let draws: Vec<Draw<'_>> = [-1.0f32, 1.0]
        .iter()
        .map(|&x| Draw {
            mesh: &post,
            material: &material,
            transform: Mat4::from_translation(Vec3::new(x, 0.0, 0.0)),
        })
        .collect();
    capture_batch(&draws, cameras, &Lighting::default(), W, H)
}

#[test]
fn the_open_sky_between_objects_morphs_as_a_direction_not_a_smear() {
    // Before the fix, sky (empty, infinitely far) counted as unknown: the gap between the
    // posts was filled along each row from the farther post, a smear across the sky.
    let (a, b) = verged();
    let v = posts_views(&[a, b]);
    let morph = ViewMorph::new(&v[0], &v[1], Correspondence::Depth).expect("morphable");
    for s in [0.33, 0.5, 0.67] {
        let truth = posts_views(&[morph.camera_at(s)]).remove(0);
        let (view, _) = morph.frame(s);
        let sky = truth.color.iter().filter(|c| c.a <= 0.0).count();
        let smeared = (truth.color.iter().zip(&view.color))
            .filter(|(t, m)| t.a <= 0.0 && m.a >= 0.5)
            .count();
        let (p, c) = (psnr(&view, &truth), covered(&view, &truth));
        eprintln!(
            "s {s}: {smeared} of {sky} sky pixels painted; {p:.1} dB over {:.1}%",
            100.0 * c
        );
        // Only the posts' anti-aliased rims may spill (a pixel or two of each edge row).
        assert!(sky > (W * H / 2) as usize, "the posts fill the view");
        assert!(
            smeared * 100 < sky,
            "s {s}: {smeared} of {sky} sky pixels painted"
        );
        assert!(c > 0.9 && p > 20.0, "s {s}: {p:.1} dB over {c:.3}");
    }
}

/// Pixels of `view` against `truth` (the geometry from the same eye, the sky transparent)
/// that show the wrong one of surface and sky, away from the geometry's silhouettes (a
/// pixel whose 3x3 neighbourhood in `truth` is all sky, or all fully covered, where the
/// edge cannot fall a pixel either way): covered at least a quarter where the geometry
/// shows the sky (streaks, ghost edges), and less than half covered where it shows a
/// surface (sky-coloured holes and corners).
fn wrong_side(view: &DepthImage, truth: &DepthImage) -> (usize, usize) {
    let (w, h) = (truth.width() as usize, truth.height() as usize);
    let around = |x: usize, y: usize, f: &dyn Fn(f32) -> bool| {
        (y.saturating_sub(1)..(y + 2).min(h))
            .all(|ny| (x.saturating_sub(1)..(x + 2).min(w)).all(|nx| f(truth.color[ny * w + nx].a)))
    };
    let (mut streaks, mut holes) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let a = view.color[y * w + x].a;
            if a > 0.25 && around(x, y, &|t| t <= 0.0) {
                streaks += 1;
            } else if a < 0.5 && around(x, y, &|t| t >= 1.0) {
                holes += 1;
            }
        }
    }
    (streaks, holes)
}

#[test]
fn silhouettes_against_the_sky_move_with_their_surface_not_smeared_along_rows() {
    // The cards against an empty sky (a direction: at infinity): every in-between view
    // shows the sky where the geometry from its camera does and the cards where it does.
    // (The slanted card shrunk to 2.4 units, so the sky shows around both cards.)
    let (parts, mut transforms) = crate::stereo::scenes::scene_draws();
    transforms[0] *= Mat4::from_scale(Vec3::splat(0.2));
    let draws: Vec<engine::Draw<'_>> = (parts.iter().zip(&transforms))
        .map(|((mesh, material), &transform)| engine::Draw {
            mesh,
            material,
            transform,
        })
        .collect();
    let views = |cameras: &[Camera]| capture_batch(&draws, cameras, &Lighting::default(), W, H);
    let (a, b) = verged();
    let v = views(&[a, b]);
    let morph = ViewMorph::new(&v[0], &v[1], Correspondence::Depth).expect("morphable");
    for s in [0.25, 0.5, 0.75] {
        let truth = views(&[morph.camera_at(s)]).remove(0);
        let (view, _) = morph.frame(s);
        let (streaks, holes) = wrong_side(&view, &truth);
        let px = (W * H) as usize;
        eprintln!(
            "s {s}: {streaks} surface pixels in the sky, {holes} sky pixels on a surface of {px}"
        );
        assert!(
            streaks * 1000 < px && holes * 1000 < px,
            "s {s}: {streaks} streak, {holes} hole pixels"
        );
    }
}

#[test]
fn only_the_rows_the_postwarp_reads_are_morphed_and_the_view_is_the_same() {
    let (a, b) = verged();
    let v = views(&[a, b]);
    let morph = ViewMorph::new(&v[0], &v[1], Correspondence::Depth).expect("morphable");
    let rows = morph.prewarped().left.height() as usize;
    for s in [0.0, 0.3, 0.5, 1.0] {
        let (view, labels) = morph.view(s);
        // The reference: every row of the parallel view morphed, with its labels, then
        // turned.
        let mut all = DepthImage::new(0, 0, a);
        morph.parallel(s, (false, true), (&mut all, &mut Vec::new(), &mut true));
        let parallel = all.camera;
        let cols = morph.prewarped().left.width() as usize;
        let (made, morphed, ..) = forward::morph(
            &morph.pair,
            (&morph.left, &morph.right),
            [&morph.reach[0], &morph.reach[1]],
            s,
            parallel,
            (0..rows, 0..cols),
            (true, true),
            (&mut all, &mut Vec::new(), &mut true),
        );
        assert_eq!(
            morphed,
            (rows * cols) as u64,
            "s {s}: labels morph every pixel"
        );
        assert_eq!(view, morph.postwarp(&all, s), "s {s}");
        let counted = forward::Made::count(&morph.postwarp(&made.expect("labels"), s));
        assert_eq!(morph.stats(&labels), counted, "s {s}");
        assert_eq!(morph.frame(s), (view, counted), "s {s}");
        // The pair is half again as large as the view: a band of its rows and of its
        // columns is read, and only about that band is morphed (a work counter).
        let (band, across) = morph.seen(&parallel, s);
        assert!(band.len() < rows * 9 / 10, "s {s}: rows {band:?} of {rows}");
        let mut scratch = MorphScratch::default();
        morph.view_into(s, &mut scratch);
        eprintln!(
            "s {s}: {} canvas pixels morphed, rows {band:?} columns {across:?} of {cols}",
            scratch.canvas_px
        );
        assert!(scratch.canvas_px >= (band.len() * across.len()) as u64);
        assert!(scratch.canvas_px <= (band.len() * cols) as u64);
        assert_eq!(scratch.band_px, (band.len() * cols) as u64);
        if s > 0.0 && s < 1.0 {
            assert!(across.len() < cols * 9 / 10, "s {s}: {across:?} of {cols}");
        }
    }
}

#[test]
fn views_captured_wider_leave_no_edge_of_the_in_between_view_unseen() {
    // The verged pair captured a third wider (same focal length) and shown at the views'
    // own size and projection: the same in-between views, as well covered and placed as
    // the morph of the views as wide as the frame. (The cards leave little beyond the
    // frame for the wider views to add; the showcase's plaza does:
    // `the_morphs_frame_edges_show_what_the_geometry_shows` in the demos. Measured: 23.6
    // against 23.5 dB at s 0.3, coverage 1.0 against 0.998.)
    let (a, b) = verged();
    let narrow = views(&[a, b]);
    let ww = W * 4 / 3;
    let wide_cams = [a, b].map(|c| {
        let eye = c.eye();
        looking(eye, Vec3::ZERO).with_aspect(ww, H)
    });
    let wide = with_scene_draws(|d| capture_batch(d, &wide_cams, &Lighting::default(), ww, H));
    let plain = ViewMorph::new(&narrow[0], &narrow[1], Correspondence::Depth).expect("morphable");
    let shown = ViewMorph::framed(&wide[0], &wide[1], Correspondence::Depth, 1.5 * 3.0 / 4.0)
        .expect("morphable")
        .shown_as(a.projection, W, H);
    for s in [0.3, 0.7] {
        // (The same camera as the narrow morph's, but for rounding: the wide views' cameras
        // are looked at again.)
        let truth = views(&[shown.camera_at(s)]).remove(0);
        let (before, after) = (plain.view(s).0, shown.view(s).0);
        assert_eq!((after.width(), after.height()), (W, H));
        let (cb, ca) = (covered(&before, &truth), covered(&after, &truth));
        let (pb, pa) = (psnr(&before, &truth), psnr(&after, &truth));
        eprintln!("s {s}: as wide {pb:.1} dB over {cb:.4}, wider {pa:.1} dB over {ca:.4}");
        assert!(ca > 0.99 && cb > 0.99, "s {s}: {ca} against {cb}");
        assert!(pa >= pb - 0.5, "s {s}: {pa:.1} dB against {pb:.1}");
    }
}

#[test]
fn a_kept_canvas_makes_the_same_views_as_fresh_images_in_any_order() {
    // The scratch kept from frame to frame (the showcase's morph) holds the last frame's
    // canvas and view: every pixel of the next must be written again, whichever rows the
    // last frame's band covered (s out of order, back and forth).
    let (a, b) = verged();
    let v = views(&[a, b]);
    let morph = ViewMorph::new(&v[0], &v[1], Correspondence::Depth).expect("morphable");
    let mut scratch = MorphScratch::default();
    let mut last_morphed = 0;
    for s in [0.5, 0.0, 1.0, 0.3, 0.3, 0.9, 0.1] {
        let labels = morph.view_into(s, &mut scratch);
        let (fresh, fresh_labels) = morph.view(s);
        assert_eq!(scratch.view, fresh, "s {s}");
        assert_eq!(morph.stats(&labels), morph.stats(&fresh_labels), "s {s}");
        // Only what the last frame morphed outside this one's columns is cleared (session
        // 19: the columns morphed again are each written once), and the canvas is then a
        // fresh one's, pixel for pixel, outside the columns read too.
        assert!(scratch.cleared_px <= last_morphed, "s {s}");
        eprintln!(
            "s {s}: cleared {} of the last {last_morphed} px",
            scratch.cleared_px
        );
        last_morphed = scratch.canvas_px;
        let mut new = MorphScratch::default();
        morph.view_into(s, &mut new);
        assert_eq!(new.cleared_px, 0);
        assert_eq!(scratch.parallel, new.parallel, "s {s}");
    }
}

#[test]
fn sources_beyond_a_rows_reach_are_skipped_and_the_canvas_is_the_same() {
    // Each row's map looks only at the source pixels its largest disparity lets reach the
    // columns morphed; with no bound (an infinite reach: every pixel from the window to
    // the row's end, as before) the canvas is the same pixel for pixel, and no fewer
    // source pixels are looked at (a work counter).
    let (a, b) = verged();
    let v = views(&[a, b]);
    let morph = ViewMorph::new(&v[0], &v[1], Correspondence::Depth).expect("morphable");
    let (w, rows) = (
        morph.prewarped().left.width() as usize,
        morph.prewarped().left.height() as usize,
    );
    let unbounded = vec![f32::INFINITY; rows];
    let (mut bounded_px, mut unbounded_px) = (0, 0);
    for s in [0.0, 0.3, 0.5, 1.0] {
        let mut scratch = MorphScratch::default();
        morph.view_into(s, &mut scratch);
        let parallel = scratch.parallel.camera;
        let seen = morph.seen(&parallel, s);
        let mut all = DepthImage::new(0, 0, a);
        let (_, morphed, looked, _) = forward::morph(
            &morph.pair,
            (&morph.left, &morph.right),
            [&unbounded, &unbounded],
            s,
            parallel,
            seen,
            (false, true),
            (&mut all, &mut Vec::new(), &mut true),
        );
        assert_eq!(all, scratch.parallel, "s {s}");
        assert_eq!(morphed, scratch.canvas_px, "s {s}");
        eprintln!(
            "s {s}: {} source pixels looked at, {looked} unbounded, rows of {w}",
            scratch.source_px
        );
        assert!(scratch.source_px <= looked, "s {s}");
        (bounded_px, unbounded_px) = (bounded_px + scratch.source_px, unbounded_px + looked);
    }
    // This small scene's disparities span most of its rows (the showcase's skip more).
    assert!(bounded_px < unbounded_px, "{bounded_px} of {unbounded_px}");
}

#[test]
fn a_view_without_depth_has_the_same_colours_and_no_depth() {
    // The showcase shows the view's colours only: without depth the canvas and the
    // postwarp skip it, and the colours are the same pixel for pixel (the kept canvas
    // too, with and without depth in turn), every depth empty.
    let (a, b) = verged();
    let v = views(&[a, b]);
    let morph = ViewMorph::new(&v[0], &v[1], Correspondence::Depth).expect("morphable");
    let mut colour = MorphScratch {
        depth: false,
        ..MorphScratch::default()
    };
    let mut both = MorphScratch::default();
    for (k, s) in [0.0, 0.3, 0.7, 1.0, 0.5].into_iter().enumerate() {
        morph.view_into(s, &mut colour);
        morph.view_into(s, &mut both);
        assert_eq!(colour.view.color, both.view.color, "s {s}");
        assert_eq!(colour.parallel.color, both.parallel.color, "s {s}");
        assert!(
            colour.view.depth.iter().all(|&z| z == crate::core::EMPTY),
            "s {s}"
        );
        // The canvas's too (session 19: a morph without depth after one without writes no
        // depth at all, after one with depth clears them).
        assert!(
            colour
                .parallel
                .depth
                .iter()
                .all(|&z| z == crate::core::EMPTY),
            "s {s}"
        );
        assert!(both.view.depth.iter().any(|z| z.is_finite()), "s {s}");
        assert_eq!(colour.canvas_px, both.canvas_px, "s {s}");
        // Depth on again for a frame: the kept canvas's depths are a fresh one's.
        if k == 2 {
            colour.depth = true;
            morph.view_into(s, &mut colour);
            assert_eq!(colour.view, both.view, "s {s}");
            colour.depth = false;
        }
    }
}
