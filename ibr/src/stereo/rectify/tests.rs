//! Rectification of a converging pair, against a pair rendered rectified.

use super::*;
use crate::capture::capture_batch;
use crate::stereo::measure::measure;
use crate::stereo::scenes::{camera, scene_draws, BASELINE, H, W};
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
