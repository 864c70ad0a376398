//! Rectification of a converging pair, against a pair rendered rectified.

use super::*;
use crate::core::capture_batch;
use crate::stereo::measure::measure;
use crate::stereo::scenes::{camera, scene_draws, with_scene_draws, BASELINE, H, W};
use crate::stereo::{luminance, Sgm, StereoPair};
use engine::Lighting;

#[test]
fn a_converging_pair_matches_along_rows_once_rectified() {
    let left = camera();
    // The right camera a baseline to the right, turned 4 degrees toward the left one's
    // line of sight and tilted a little: its rows do not match the left one's.
    let eye = left.eye() + Vec3::X * BASELINE;
    let right = Camera::look_at(
        eye,
        Vec3::new(-0.35, 0.1, 0.0),
        Vec3::new(0.03, 1.0, 0.0),
        0.8,
        W as f32 / H as f32,
    )
    .with_depth_range(0.1, 50.0);
    let (meshes, transforms) = scene_draws();
    let draws: Vec<engine::Draw<'_>> = meshes
        .iter()
        .zip(&transforms)
        .map(|((mesh, material), &transform)| engine::Draw {
            mesh,
            material,
            transform,
        })
        .collect();
    let lighting = Lighting::default();
    let views = capture_batch(&draws, &[left, right], &lighting, W, H);
    let r = rectify(&views[0], &views[1]).expect("a sideways baseline");
    assert!((r.baseline - BASELINE).abs() < 1e-5);
    // The truth: the same scene rendered by the rectified cameras directly.
    let truth = StereoPair::render(&draws, &lighting, &r.left.camera, r.baseline, W, H);
    let est = Sgm {
        max_disparity: 32,
        ..Sgm::default()
    }
    .run(&luminance(&r.left), &luminance(&r.right), W, H)
    .expect("images of the size given");
    // Pixels both rectified views hold (the rest fell outside an original image).
    let w = W as usize;
    let held = |image: &DepthImage, i: usize| image.color[i].a > 0.99;
    let mask: Vec<bool> = (0..truth.visible.len())
        .map(|i| {
            let xr = (i % w) as f32 - truth.truth.data[i];
            truth.visible[i]
                && held(&r.left, i)
                && xr >= 0.0
                && held(&r.right, i - i % w + xr.round() as usize)
        })
        .collect();
    let m = measure(&est, &truth.truth, Some(&mask)).unwrap();
    assert!(m.nonocc.pixels > 12_000, "{m:?}");
    // (Measured: 3.1% off by more than 2 pixels.)
    assert!(m.nonocc.bad2 < 0.06, "{m:?}");
    // Matched without rectifying, the rows disagree: far worse.
    let raw = StereoPair::render(&draws, &lighting, &left, BASELINE, W, H);
    let unrectified = Sgm {
        max_disparity: 32,
        ..Sgm::default()
    }
    .run(&luminance(&views[0]), &luminance(&views[1]), W, H)
    .expect("images of the size given");
    let u = measure(&unrectified, &raw.truth, Some(&raw.visible)).unwrap();
    // (Measured: 92%.)
    assert!(u.nonocc.bad2 > 0.5, "{u:?} against {m:?}");
}

#[test]
fn pairs_that_cannot_be_rectified_say_why() {
    let cam = camera();
    let image = DepthImage::new(W, H, cam);
    assert!(matches!(
        rectify(&image, &image),
        Err(RectifyError::NoBaseline(_))
    ));
    // The right camera straight ahead of the left one: motion toward the scene.
    let ahead = Camera {
        view: Mat4::from_translation(Vec3::new(0.0, 0.0, 1.0)) * cam.view,
        projection: cam.projection,
    };
    let e = rectify(&image, &DepthImage::new(W, H, ahead)).unwrap_err();
    assert!(matches!(e, RectifyError::AlongTheView(_)), "{e}");
    let small = DepthImage::new(8, 8, cam);
    assert!(matches!(
        rectify(&image, &small),
        Err(RectifyError::Sizes(..))
    ));
}

/// What a turned view covers of the original does not depend on what the original shows:
/// an image transparent everywhere is covered whole by its own view, and a view turned 10
/// degrees about the vertical covers what the pinhole model says (each pixel's ray turned
/// by hand and projected into the original's field of view).
#[test]
fn coverage_of_the_original_counts_transparent_pixels_as_inside() {
    let (w, h, fov) = (40u32, 30u32, 0.8f32);
    let aspect = w as f32 / h as f32;
    let original = Camera::look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, fov, aspect);
    let image = DepthImage::new(w, h, original);
    assert!(image.color.iter().all(|c| c.a == 0.0), "nothing shown");
    assert!(inside_original(&image, &original, w, h).iter().all(|&i| i));
    let turn = 10f32.to_radians();
    let (s, c) = turn.sin_cos();
    let turned = Camera::look_at(Vec3::ZERO, Vec3::new(-s, 0.0, -c), Vec3::Y, fov, aspect);
    let got = inside_original(&image, &turned, w, h);
    let t = (0.5 * fov).tan();
    let (mut outside, mut disagree) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let nx = 2.0 * (x as f32 + 0.5) / w as f32 - 1.0;
            let ny = 1.0 - 2.0 * (y as f32 + 0.5) / h as f32;
            let d = Vec3::new(nx * t * aspect, ny * t, -1.0);
            // Turned about +y by `turn`: -z goes to (-sin, 0, -cos).
            let world = Vec3::new(c * d.x + s * d.z, d.y, -s * d.x + c * d.z);
            let (u, v) = (world.x / -world.z / (t * aspect), world.y / -world.z / t);
            let want = -world.z > 0.0 && u.abs() <= 1.0 && v.abs() <= 1.0;
            let edge = (u.abs() - 1.0).abs() < 1e-3 || (v.abs() - 1.0).abs() < 1e-3;
            outside += !want as u32;
            disagree += (want != got[(y * w + x) as usize] && !edge) as u32;
        }
    }
    // 10 degrees of a 0.8 x 1.33 radian view: a strip of about 8 columns.
    assert!((6 * h..=10 * h).contains(&outside), "{outside} outside");
    assert_eq!(disagree, 0);
}

/// The resample's row-stepped homography (terms linear in a pixel's column, set up once a
/// row) lands where each pixel's own ray does: the same colours and depths, to float
/// rounding, as the ray of every pixel taken through the clip-to-world matrix and
/// projected into the original (a turn about the eye both ways, and a tilt).
#[test]
fn the_row_stepped_resample_matches_each_pixels_own_ray() {
    let (w, h) = (W, H);
    let original = camera();
    let image = with_scene_draws(|draws| {
        capture_batch(draws, &[original], &Lighting::default(), w, h).remove(0)
    });
    let eye = original.eye();
    for target in [
        Vec3::new(-0.6, 0.0, 0.0),
        Vec3::new(0.5, 0.3, 0.0),
        Vec3::new(0.0, -0.2, 0.0),
    ] {
        let turned = Camera::look_at(eye, target, Vec3::Y, 0.8, w as f32 / h as f32)
            .with_depth_range(0.1, 50.0);
        let got = resample(&image, &turned, w, h);
        let to_world = turned.gl_view_proj().inverse();
        let to_old = original.gl_view_proj();
        let (mut covered, mut worst_color, mut worst_depth) = (0, 0.0f32, 0.0f32);
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                let dir = pixel_ray(&to_world, eye, (x, y), (w, h));
                let want = source(&to_old, dir, (w, h)).and_then(|(u, v)| bilinear(&image, u, v));
                let Some(want) = want else {
                    // At the image's edge a ray may fall a rounding either side.
                    continue;
                };
                covered += 1;
                let c = got.color[i];
                for (a, b) in [(c.r, want.r), (c.g, want.g), (c.b, want.b), (c.a, want.a)] {
                    worst_color = worst_color.max((a - b).abs());
                }
                let (u, v) = source(&to_old, dir, (w, h)).expect("in front");
                let (nx, ny) = (u.round() as u32, v.round() as u32);
                let z_old = image.depth[(ny.min(h - 1) * w + nx.min(w - 1)) as usize];
                if z_old.is_finite() && z_old > 0.0 {
                    let z = z_old / dir.dot(original.forward()) * dir.dot(turned.forward());
                    worst_depth = worst_depth.max((got.depth[i] - z).abs() / z);
                }
            }
        }
        assert!(covered > (w * h / 2) as usize, "{covered} pixels covered");
        assert!(worst_color < 2e-3, "colour off by {worst_color}");
        assert!(worst_depth < 1e-4, "depth off by {worst_depth} of itself");
    }
}
