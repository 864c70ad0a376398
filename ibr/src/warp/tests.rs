//! The warp against an analytic ray caster: scenes of rectangles facing the camera, a
//! floor and a wall, whose depth images are exact, so a warped view can be compared with
//! the image the target camera really sees.

use super::holes::{classify, Fill, Filler};
use super::*;
use crate::core::unproject;
use engine::Rgba;
use glam::{Vec2, Vec3};

/// A rectangle in the plane `z = z`, facing +z.
#[derive(Clone, Copy)]
pub(super) struct Rect {
    z: f32,
    min: Vec2,
    max: Vec2,
    red: bool,
}

/// Smooth colour of a world point: a red box or a blue-green wall/floor, shaded by position
/// so a misplaced sample shows.
fn shade(p: Vec3, red: bool) -> Premul {
    let t = |v: f32| 0.5 + 0.5 * (v * 0.7).sin();
    if red {
        Rgba::new(0.9, 0.1 * t(p.x), 0.1 * t(p.y), 1.0).premultiply()
    } else {
        Rgba::new(
            0.05,
            0.3 + 0.5 * t(p.x + p.z),
            0.3 + 0.5 * t(p.y - p.z),
            1.0,
        )
        .premultiply()
    }
}

/// The wall at z = -6, the floor at y = -1.5 and the rectangles, as the camera sees them.
pub(super) fn cast(camera: &Camera, w: u32, h: u32, rects: &[Rect]) -> DepthImage {
    let eye = camera.eye();
    let mut image = DepthImage::new(w, h, *camera);
    for y in 0..h {
        for x in 0..w {
            // A point at axial depth 1: the ray's parameter is then the axial depth.
            let p1 = unproject(camera, x as f32 + 0.5, y as f32 + 0.5, 1.0, w, h).unwrap();
            let dir = p1 - eye;
            let mut best: Option<(f32, bool)> = None;
            let mut hit = |t: f32, red: bool| {
                if t > 1e-4 && best.is_none_or(|(b, _)| t < b) {
                    best = Some((t, red));
                }
            };
            for r in rects {
                let t = (r.z - eye.z) / dir.z;
                let p = eye + dir * t;
                if p.x >= r.min.x && p.x <= r.max.x && p.y >= r.min.y && p.y <= r.max.y {
                    hit(t, r.red);
                }
            }
            hit((-6.0 - eye.z) / dir.z, false);
            hit((-1.5 - eye.y) / dir.y, false);
            if let Some((t, red)) = best {
                image.set(x, y, shade(eye + dir * t, red), t);
            }
        }
    }
    image
}

pub(super) fn boxes() -> Vec<Rect> {
    vec![
        Rect {
            z: -2.0,
            min: Vec2::new(-0.6, -0.5),
            max: Vec2::new(0.4, 0.6),
            red: true,
        },
        Rect {
            z: -3.5,
            min: Vec2::new(0.8, -1.0),
            max: Vec2::new(1.8, 0.2),
            red: true,
        },
    ]
}

pub(super) fn camera(eye: Vec3, at: Vec3) -> Camera {
    Camera::look_at(eye, at, Vec3::Y, 1.0, 4.0 / 3.0).with_depth_range(0.1, 50.0)
}

pub(super) const W: u32 = 96;
pub(super) const H: u32 = 72;

pub(super) fn reference() -> DepthImage {
    cast(
        &camera(Vec3::new(0.0, 0.0, 2.0), Vec3::new(0.0, 0.0, -4.0)),
        W,
        H,
        &boxes(),
    )
}

fn warp(reference: &DepthImage, target: &Camera, options: WarpOptions) -> (Warped, WarpStats) {
    let mut warper = Warper::new();
    warper.begin(target, W, H);
    let stats = warper.add(reference, &options);
    (warper.output().clone(), stats)
}

/// `image` with its colours as the warp stores them (packed bytes, read back).
pub(super) fn quantised(image: &DepthImage) -> DepthImage {
    let enc = Encoder::new(ENCODING);
    let mut q = image.clone();
    for c in &mut q.color {
        *c = unpack(ENCODING, enc.pack(c.r, c.g, c.b, c.a));
    }
    q
}

fn options(visibility: Visibility, reconstruction: Reconstruction) -> WarpOptions {
    WarpOptions {
        visibility,
        reconstruction,
        ..WarpOptions::default()
    }
}

const ALL: [(Visibility, Reconstruction); 4] = [
    (Visibility::Ordered, Reconstruction::Points),
    (Visibility::Ordered, Reconstruction::Splats),
    (Visibility::DepthBuffer, Reconstruction::Points),
    (Visibility::DepthBuffer, Reconstruction::Splats),
];

#[test]
fn warping_to_the_reference_camera_gives_the_reference_back() {
    let r = reference();
    for (v, rec) in ALL {
        let (out, stats) = warp(&r, &r.camera, options(v, rec));
        let out = out.to_depth_image();
        assert_eq!(out.color, quantised(&r).color, "{v:?} {rec:?}");
        for (a, b) in out.depth.iter().zip(&r.depth) {
            assert!((a - b).abs() <= 1e-4 * b, "{a} vs {b}");
        }
        assert_eq!(stats.samples, (W * H) as u64);
        assert_eq!(stats.pixels_written, (W * H) as u64, "{v:?} {rec:?}");
    }
}

/// Fraction of pixels filled in both where the colours differ by more than `tol`.
pub(super) fn mismatch(a: &DepthImage, b: &DepthImage, tol: f32) -> (f32, usize) {
    let mut both = 0;
    let mut off = 0;
    for (ca, cb) in a.color.iter().zip(&b.color) {
        if is_filled(*ca) && is_filled(*cb) {
            both += 1;
            let d = (ca.r - cb.r)
                .abs()
                .max((ca.g - cb.g).abs())
                .max((ca.b - cb.b).abs());
            if d > tol {
                off += 1;
            }
        }
    }
    (off as f32 / both.max(1) as f32, both)
}

#[test]
fn a_warped_view_matches_what_the_target_camera_sees() {
    let r = reference();
    for eye in [
        Vec3::new(0.5, 0.2, 2.2),
        Vec3::new(-0.4, 0.4, 1.0),
        Vec3::new(0.3, -0.2, 3.0),
    ] {
        let target = camera(eye, Vec3::new(0.2, 0.0, -4.0));
        let truth = cast(&target, W, H, &boxes());
        for (v, rec) in ALL {
            let (out, _) = warp(&r, &target, options(v, rec));
            let (off, both) = mismatch(&out.to_depth_image(), &truth, 0.08);
            assert!(both > (W * H) as usize / 2, "{eye} {v:?} {rec:?}: {both}");
            assert!(
                off < 0.03,
                "{eye} {v:?} {rec:?}: {off} of {both} pixels off"
            );
        }
    }
}

#[test]
fn ordered_and_depth_buffered_warps_agree_wherever_the_epipole_is() {
    let r = reference();
    // (eye, name, pixels that may differ, of which of two surfaces), for points and splats.
    let eyes = [
        // In front of the reference: epipole inside the image.
        (Vec3::new(0.2, 0.1, 1.0), "inside", [(0, 0), (40, 0)]),
        // Behind the reference camera: traversed away from the epipole.
        (Vec3::new(0.3, 0.2, 3.5), "behind", [(0, 0), (0, 0)]),
        // Beside it, seen at the image's left border.
        (border_eye(&r), "border", [(0, 0), (40, 0)]),
        // Sideways in the reference's image plane: epipole at infinity. Rows of the
        // reference then map to tilted rows of the target, and point samples of two
        // surfaces from neighbouring rows can round into one pixel at a silhouette,
        // where the order keeps the later and the depth buffer the nearer.
        (Vec3::new(1.5, 0.0, 2.0), "infinity", [(60, 6), (90, 6)]),
    ];
    for (eye, name, limits) in eyes {
        let target = camera(eye, Vec3::new(0.0, 0.0, -4.0));
        for (rec, (most, surfaces)) in [Reconstruction::Points, Reconstruction::Splats]
            .into_iter()
            .zip(limits)
        {
            let (a, _) = warp(&r, &target, options(Visibility::Ordered, rec));
            let (b, _) = warp(&r, &target, options(Visibility::DepthBuffer, rec));
            let (a, b) = (a.to_depth_image(), b.to_depth_image());
            let (mut differ, mut two) = (0, 0);
            for (ca, cb) in a.color.iter().zip(&b.color) {
                if ca != cb {
                    differ += 1;
                    // Red box against blue-green wall: two surfaces.
                    if (ca.r - cb.r).abs() > 0.5 {
                        two += 1;
                    }
                }
            }
            assert!(
                differ <= most && two <= surfaces,
                "{name} {rec:?}: {differ} pixels differ (at most {most}), {two} of two surfaces (at most {surfaces})"
            );
        }
    }
}

/// An eye whose image in the reference lies on the left border (x = 0), beside it.
fn border_eye(r: &DepthImage) -> Vec3 {
    let (o, dir) = r.camera.pixel_ray(0.0, H as f32 / 2.0, W, H);
    o + dir * 0.8
}

#[test]
fn the_same_pixels_at_any_thread_count() {
    let r = reference();
    let target = camera(Vec3::new(0.6, 0.3, 1.5), Vec3::new(0.0, 0.0, -4.0));
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| ALL.map(|(v, rec)| warp(&r, &target, options(v, rec)).0))
    };
    let one = run(1);
    for n in [2, 3, 5] {
        assert!(run(n) == one, "{n} threads");
    }
}

#[test]
fn a_rotation_leaves_no_holes_inside_what_the_reference_saw() {
    let r = reference();
    let eye = r.camera.eye();
    let target = camera(eye, Vec3::new(1.2, 0.5, -4.0));
    let (out, _) = warp(
        &r,
        &target,
        options(Visibility::Ordered, Reconstruction::Splats),
    );
    let inv = r.camera.clip_from_world();
    let mut holes = 0;
    for y in 0..H {
        for x in 0..W {
            // Where this target pixel's ray meets the reference image.
            let p = unproject(&target, x as f32 + 0.5, y as f32 + 0.5, 5.0, W, H).unwrap();
            let c = inv * p.extend(1.0);
            let (u, v) = (
                (c.x / c.w + 1.0) * 0.5 * W as f32,
                (1.0 - c.y / c.w) * 0.5 * H as f32,
            );
            let inside = u > 1.0 && v > 1.0 && u < W as f32 - 1.0 && v < H as f32 - 1.0;
            if inside && !out.is_filled((y * W + x) as usize) {
                holes += 1;
            }
        }
    }
    assert_eq!(holes, 0);
}

#[test]
fn samples_at_infinity_move_with_the_rotation_alone() {
    // A sky of colour at infinite depth: translating the eye moves none of it.
    let cam = camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0));
    let mut sky = DepthImage::new(W, H, cam);
    for y in 0..H {
        for x in 0..W {
            let c = Rgba::new(x as f32 / W as f32, y as f32 / H as f32, 0.5, 1.0).premultiply();
            sky.set(x, y, c, f32::INFINITY);
        }
    }
    let moved = camera(Vec3::new(3.0, 1.0, -2.0), Vec3::new(3.0, 1.0, -3.0));
    for (v, rec) in ALL {
        let (out, _) = warp(&sky, &moved, options(v, rec));
        let out = out.to_depth_image();
        assert_eq!(out.color, quantised(&sky).color, "{v:?} {rec:?}");
        assert!(out.depth.iter().all(|d| d.is_infinite()));
    }
}

#[test]
fn an_eye_behind_the_reference_or_far_away_never_gives_nan() {
    let r = reference();
    for eye in [
        Vec3::new(0.0, 0.0, 9.0),
        Vec3::new(0.0, 0.0, -9.0),
        Vec3::new(40.0, 30.0, 2.0),
        Vec3::new(0.0, 0.0, -2.0),
    ] {
        for look in [Vec3::new(0.0, 0.0, -4.0), Vec3::new(0.0, 0.0, 40.0)] {
            let target = camera(eye, look);
            for (v, rec) in ALL {
                let (out, stats) = warp(&r, &target, options(v, rec));
                assert!(out.disparity.iter().all(|d| !d.is_nan()));
                let out = out.to_depth_image();
                assert!(out
                    .color
                    .iter()
                    .all(|c| c.to_array().iter().all(|x| x.is_finite())));
                assert!(out.depth.iter().all(|d| !d.is_nan() && *d > 0.0));
                assert_eq!(stats.samples, (W * H) as u64);
            }
        }
    }
    // A reference with NaN, zero and negative depths: those samples are skipped.
    let mut bad = r.clone();
    bad.depth[0] = f32::NAN;
    bad.depth[1] = 0.0;
    bad.depth[2] = -1.0;
    let (_, stats) = warp(&bad, &r.camera, WarpOptions::default());
    assert_eq!(stats.samples, (W * H) as u64 - 3);
}

#[test]
fn disocclusions_are_counted_and_filled_from_the_background() {
    let r = reference();
    // Stepping sideways uncovers wall beside the near box.
    let target = camera(Vec3::new(0.9, 0.0, 2.0), Vec3::new(0.6, 0.0, -4.0));
    for fill in [Fill::Background, Fill::PullPush] {
        let mut warper = Warper::new();
        warper.begin(&target, W, H);
        warper.add(&r, &options(Visibility::Ordered, Reconstruction::Splats));
        let before = warper.output().clone();
        let holes = classify(&before, 0.05);
        assert!(holes.disocclusions > 20, "{holes:?}");
        let filled = Filler::default().fill(warper.output_mut(), fill, 0.05);
        let after = warper.output();
        // What it says it left is what it left.
        let n = after.disparity.len() as u64;
        assert_eq!(filled.left, n - after.filled(), "{fill:?}");
        let filled = filled.filled;
        assert!(
            filled >= holes.total() - holes.total() / 10,
            "{fill:?}: {filled} of {holes:?}"
        );
        // Every filled pixel of a disocclusion beside the box shows wall, not box: the
        // box's red never spreads into the hole.
        let truth = cast(&target, W, H, &boxes());
        let mut checked = 0;
        for i in 0..after.color.len() {
            if before.is_filled(i) || !after.is_filled(i) {
                continue;
            }
            let wall = truth.color[i].r < 0.5;
            if wall {
                checked += 1;
                assert!(
                    after.color_linear(i).r < 0.3,
                    "{fill:?}: pixel {i} filled with foreground {:?}",
                    after.color_linear(i)
                );
                assert!(
                    after.depth(i) > 2.5,
                    "{fill:?}: pixel {i} given depth {}",
                    after.depth(i)
                );
            }
        }
        assert!(checked > 20, "{fill:?}: {checked}");
    }
}

#[test]
fn two_references_fill_each_others_disocclusions() {
    let left = cast(
        &camera(Vec3::new(-0.8, 0.0, 2.0), Vec3::new(0.0, 0.0, -4.0)),
        W,
        H,
        &boxes(),
    );
    let right = cast(
        &camera(Vec3::new(0.8, 0.0, 2.0), Vec3::new(0.0, 0.0, -4.0)),
        W,
        H,
        &boxes(),
    );
    let target = camera(Vec3::new(0.0, 0.1, 2.0), Vec3::new(0.0, 0.0, -4.0));
    let truth = cast(&target, W, H, &boxes());
    for v in [Visibility::Ordered, Visibility::DepthBuffer] {
        let opts = options(v, Reconstruction::Splats);
        let mut one = Warper::new();
        one.begin(&target, W, H);
        one.add(&left, &opts);
        let single = classify(one.output(), 0.05).total();
        let mut two = Warper::new();
        two.begin(&target, W, H);
        two.add(&left, &opts);
        two.add(&right, &opts);
        let double = classify(two.output(), 0.05).total();
        assert!(
            double * 4 < single.max(1),
            "{v:?}: {double} holes with two, {single} with one"
        );
        let (off, _) = mismatch(&two.output().to_depth_image(), &truth, 0.08);
        assert!(off < 0.03, "{v:?}: {off}");
    }
}

#[test]
fn magnification_cracks_points_and_splats_close_them() {
    // Walking toward the scene spreads samples apart: points leave cracks between samples
    // of one surface; splats sized by the warp's stretch close them.
    let r = reference();
    let target = camera(Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 0.0, -4.0));
    let (points, _) = warp(
        &r,
        &target,
        options(Visibility::Ordered, Reconstruction::Points),
    );
    let (splats, _) = warp(
        &r,
        &target,
        options(Visibility::Ordered, Reconstruction::Splats),
    );
    let (p, s) = (classify(&points, 0.05), classify(&splats, 0.05));
    assert!(p.cracks > 500, "{p:?}");
    assert!(p.cracks > p.disocclusions, "{p:?}");
    assert!(s.cracks * 20 < p.cracks, "{s:?} against {p:?}");
}

#[test]
fn by_priority_a_reference_at_the_eye_is_shown_as_it_is_and_by_depth_nearly() {
    // The reference taken from the target eye, added first, then one from elsewhere: by
    // priority the second only fills holes (there are none), so the view is the first
    // exactly; by depth the second's samples replace only clearly farther ones, which on
    // an exact view happens only where its splats spill over silhouettes.
    let here = camera(Vec3::new(0.3, 0.1, 2.0), Vec3::new(0.0, 0.0, -4.0));
    let exact = cast(&here, W, H, &boxes());
    let other = cast(
        &camera(Vec3::new(-0.6, 0.3, 2.4), Vec3::new(0.0, 0.0, -4.0)),
        W,
        H,
        &boxes(),
    );
    for (composite, most) in [(Composite::Priority, 0), (Composite::Depth, W * H / 20)] {
        let opts = WarpOptions {
            composite,
            ..WarpOptions::default()
        };
        let mut warper = Warper::new();
        warper.begin(&here, W, H);
        warper.add(&exact, &opts);
        warper.add(&other, &opts);
        let differ = warper
            .output()
            .to_depth_image()
            .color
            .iter()
            .zip(&quantised(&exact).color)
            .filter(|(a, b)| a != b)
            .count();
        assert!(
            differ <= most as usize,
            "{composite:?}: {differ} pixels differ"
        );
    }
}

mod sequential;
