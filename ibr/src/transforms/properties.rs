//! Property tests of the project's own captures: any capture [`write_transforms`] writes,
//! at random poses (any rotation, translations up to 1e3, uniform scales 0.2 to 5 in the
//! view), sizes and intrinsics, reads back with the same camera and warps to the same view
//! at its own eye.
//!
//! Tolerances: depth and colour exactly (depth is `f32` in PFM, colour is made 8-bit
//! first); the view within 1e-6 of the largest entry (`f64` inverse both ways, one `f32`
//! rounding); the intrinsics within 2e-5 relative (the projection stores extents, not
//! focal lengths); the warp at its own eye >= 60 dB against the written image and the same
//! coverage.

use super::*;
use crate::metrics::{compare_rgba8, Image, Options};
use crate::warp::{WarpOptions, Warper};
use glam::{Mat4, Quat, Vec3};
use proptest::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// A fresh folder per case.
fn case_dir() -> PathBuf {
    static N: AtomicUsize = AtomicUsize::new(0);
    let n = N.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("parallax-props-{}-{n}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    dir
}

/// An opaque image of a sloped depth field with a few empty pixels.
fn image(camera: Camera, w: u32, h: u32, seed: u32, slope: (f32, f32)) -> DepthImage {
    let n = (w * h) as usize;
    let mut color = Vec::with_capacity(n);
    let mut depth = Vec::with_capacity(n);
    for i in 0..n as u32 {
        let (x, y) = (i % w, i / w);
        let t = (i.wrapping_mul(2654435761) ^ seed) as f32 / u32::MAX as f32;
        color.push(through_8_bits(
            Rgba::new(t, x as f32 / w as f32, y as f32 / h as f32, 1.0).premultiply(),
        ));
        let empty = (x * 7 + y * 3).wrapping_add(seed).is_multiple_of(11);
        depth.push(if empty {
            EMPTY
        } else {
            3.0 + slope.0 * x as f32 + slope.1 * y as f32
        });
    }
    DepthImage::from_planes(w, h, color, depth, camera).unwrap()
}

fn max_abs(m: Mat4) -> f32 {
    m.to_cols_array().iter().fold(0.0, |a, b| a.max(b.abs()))
}

fn warp_to_own_eye(image: &DepthImage) -> Vec<u8> {
    let mut warper = Warper::new();
    warper.begin(&image.camera, image.width(), image.height());
    warper.add(image, &WarpOptions::default());
    srgb8(&warper.output().to_depth_image())
}

fn round_trip(written: &DepthImage) {
    let (w, h) = (written.width(), written.height());
    let dir = case_dir();
    write_transforms(&dir, std::slice::from_ref(written)).unwrap();
    let back = read_transforms(&dir.join("transforms.json"));
    std::fs::remove_dir_all(&dir).ok();
    let back = back.unwrap();
    let read = &back[0];
    assert_eq!(read.depth, written.depth);
    assert_eq!(read.color, written.color);
    let (a, b) = (read.camera.view, written.camera.view);
    let tol = 1e-6 * max_abs(b).max(1.0);
    for (x, y) in a.to_cols_array().iter().zip(b.to_cols_array()) {
        assert!((x - y).abs() <= tol, "{a} vs {b}");
    }
    let (ka, kb) = (
        Intrinsics::of(&read.camera.projection, w, h).unwrap(),
        Intrinsics::of(&written.camera.projection, w, h).unwrap(),
    );
    for (x, y) in [
        (ka.fl_x, kb.fl_x),
        (ka.fl_y, kb.fl_y),
        (ka.cx, kb.cx),
        (ka.cy, kb.cy),
    ] {
        assert!((x - y).abs() <= 2e-5 * (1.0 + y.abs()), "{ka:?} vs {kb:?}");
    }
    let warped = warp_to_own_eye(read);
    let want = srgb8(written);
    let e = compare_rgba8(
        Image::new(w, h, &warped).unwrap(),
        Image::new(w, h, &want).unwrap(),
        &Options::default(),
    )
    .unwrap();
    assert!(e.psnr_db >= 60.0, "{e:?}");
    assert_eq!(e.coverage_mismatch, 0.0, "{e:?}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn every_capture_written_reads_back_and_warps_to_itself(
        axis in (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0),
        angle in -3.1f32..3.1,
        t in (-1e3f32..1e3, -1e3f32..1e3, -1e3f32..1e3),
        scale in 0.2f32..5.0,
        (w, h) in (6u32..=24, 4u32..=16),
        fl in (0.5f32..3.0, 0.5f32..3.0),
        centre in (0.2f32..0.8, 0.2f32..0.8),
        centred in any::<bool>(),
        seed in any::<u32>(),
        slope in (-0.05f32..0.05, -0.05f32..0.05),
    ) {
        let axis = Vec3::new(axis.0, axis.1, axis.2 + 1e-3).normalize();
        let view = Mat4::from_scale_rotation_translation(
            Vec3::splat(scale),
            Quat::from_axis_angle(axis, angle),
            Vec3::new(t.0, t.1, t.2),
        );
        let (wf, hf) = (w as f32, h as f32);
        let k = if centred {
            Intrinsics { fl_x: fl.0 * wf, fl_y: fl.0 * wf, cx: wf / 2.0, cy: hf / 2.0 }
        } else {
            Intrinsics { fl_x: fl.0 * wf, fl_y: fl.1 * wf, cx: centre.0 * wf, cy: centre.1 * hf }
        };
        let camera = Camera { view, projection: k.projection(w, h, 0.5, 50.0) };
        round_trip(&image(camera, w, h, seed, slope));
    }
}

#[test]
fn the_issue_capture_at_an_odd_pose_round_trips() {
    // `render --capture --eye=-61.70723,62.5967785,-205.712078
    // --target=0.0086,21.45,0.0072` wrote a last row 0.99999988 and was refused.
    let eye = glam::DVec3::new(-61.70723, 62.5967785, -205.712078).as_vec3();
    let target = Vec3::new(0.0086, 21.45, 0.0072);
    let camera = Camera::look_at(eye, target, Vec3::Y, 0.7, 1.5).with_depth_range(1.0, 500.0);
    let (w, h) = (24, 16);
    let written = image(camera, w, h, 7, (0.5, 0.25));
    let dir = case_dir();
    write_transforms(&dir, std::slice::from_ref(&written)).unwrap();
    let text = std::fs::read_to_string(dir.join("transforms.json")).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    let json: Value = serde_json::from_str(&text).unwrap();
    let last = &json["frames"][0]["transform_matrix"][3];
    assert_eq!(last, &json!([0.0, 0.0, 0.0, 1.0]), "{text}");
    round_trip(&written);
}
