use super::*;
use crate::warp::holes::classify;
use crate::warp::tests::{boxes, camera, cast, mismatch, reference, H, W};
use crate::warp::{WarpOptions, Warper};
use engine::{Premul, Rgba};
use glam::Vec3;

/// The home view plus views from the left and right: what an LDI at home is built from.
fn views() -> Vec<DepthImage> {
    let at = Vec3::new(0.0, 0.0, -4.0);
    vec![
        reference(),
        cast(&camera(Vec3::new(-0.9, 0.0, 2.0), at), W, H, &boxes()),
        cast(&camera(Vec3::new(0.9, 0.0, 2.0), at), W, H, &boxes()),
    ]
}

#[test]
fn warped_views_give_layers_behind_the_boxes() {
    let home = reference();
    let ldi = LdiBuilder::default().build(&home.camera, W, H, &views(), 0.03);
    // The front layer is the home view itself.
    let front = ldi.layer(0);
    let (off, _) = mismatch(&front, &home, 0.02);
    assert!(off < 0.01, "{off}");
    // Behind the near box (red at depth 4 along the axis from z = 2), the side views saw the
    // wall: pixels there hold two or more samples, the second farther than the box.
    let mut layered = 0;
    for y in 0..H {
        for x in 0..W {
            let run = ldi.samples(x, y);
            if run
                .first()
                .is_some_and(|s| s.color.r > 0.5 && (s.depth - 4.0).abs() < 0.1)
                && run.len() >= 2
            {
                layered += 1;
                assert!(run[1].depth > run[0].depth * 1.03, "{run:?}");
                assert!(run.windows(2).all(|w| w[0].depth < w[1].depth));
            }
        }
    }
    assert!(layered > 50, "{layered} box pixels with something behind");
    assert!(ldi.depth_complexity() >= 2);
}

#[test]
fn a_warped_ldi_fills_what_one_depth_image_leaves_open() {
    let home = reference();
    let ldi = LdiBuilder::default().build(&home.camera, W, H, &views(), 0.03);
    let target = camera(Vec3::new(0.7, 0.1, 1.8), Vec3::new(0.3, 0.0, -4.0));
    let truth = cast(&target, W, H, &boxes());
    let opts = WarpOptions::default();
    let mut one = Warper::new();
    one.begin(&target, W, H);
    one.add(&home, &opts);
    let mut layered = Warper::new();
    layered.begin(&target, W, H);
    let stats = layered.add_layered(&ldi, &opts);
    assert_eq!(stats.samples, ldi.sample_count() as u64);
    let (h1, h2) = (
        classify(one.output(), 0.05),
        classify(layered.output(), 0.05),
    );
    assert!(
        h2.disocclusions * 2 < h1.disocclusions,
        "LDI {h2:?} against one image {h1:?}"
    );
    let (off, both) = mismatch(&layered.output().to_depth_image(), &truth, 0.08);
    assert!(both > (W * H) as usize / 2 && off < 0.04, "{off} of {both}");
}

#[test]
fn samples_of_a_pixel_paint_back_to_front_with_over() {
    // One pixel, a translucent red sample in front of an opaque blue one: warped to its own
    // camera the pixel is red over blue, whatever order the layers were stored in.
    let cam = camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0));
    let red = Rgba::new(1.0, 0.0, 0.0, 0.5).premultiply();
    let blue = Rgba::new(0.0, 0.0, 1.0, 1.0).premultiply();
    let mut offsets = vec![0u32; (W * H + 1) as usize];
    let i = ((H / 2) * W + W / 2) as usize;
    for o in &mut offsets[i + 1..] {
        *o = 2;
    }
    let samples = vec![
        LdiSample {
            color: red,
            depth: 2.0,
        },
        LdiSample {
            color: blue,
            depth: 5.0,
        },
    ];
    let ldi = LayeredDepthImage::from_packed(W, H, offsets, samples, cam).unwrap();
    let mut warper = Warper::new();
    warper.begin(&cam, W, H);
    warper.add_layered(&ldi, &WarpOptions::default());
    let got = warper.output().color_linear(i);
    let want = Premul {
        r: 0.5,
        g: 0.0,
        b: 0.5,
        a: 1.0,
    };
    assert!(
        // Colours are stored as 8-bit sRGB: within a step of the exact answer.
        (got.r - want.r).abs() < 4e-3 && (got.b - want.b).abs() < 4e-3 && got.a == 1.0,
        "{got:?}"
    );
    let depth = warper.output().depth(i);
    assert!(
        (depth - 2.0).abs() < 1e-5,
        "the front sample's depth: {depth}"
    );
}

#[test]
fn packed_layers_are_checked() {
    let cam = camera(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0));
    let s = LdiSample {
        color: Premul::TRANSPARENT,
        depth: 1.0,
    };
    assert!(LayeredDepthImage::from_packed(1, 1, vec![0, 1], vec![s], cam).is_some());
    assert!(LayeredDepthImage::from_packed(1, 1, vec![0, 2], vec![s], cam).is_none());
    assert!(LayeredDepthImage::from_packed(2, 1, vec![0, 1], vec![s], cam).is_none());
    assert!(LayeredDepthImage::from_packed(2, 1, vec![1, 0, 1], vec![s], cam).is_none());
    assert!(LayeredDepthImage::from_packed(2, 1, vec![0, 1, 0], vec![s], cam).is_none());
}
