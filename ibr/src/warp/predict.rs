//! The warp's error predicted without rendering, like the impostors': how far apart, in
//! target pixels, two samples of one reference pixel's neighbourhood can move, which is the
//! widest a disocclusion can open.
//!
//! A point at depth `z` seen from an eye moved by `t` (in the target's view space) shifts
//! in the image by about `f |t_xy| / z` (sideways) plus `r |t_z| / z` (toward or away, `r`
//! pixels from the image centre). Over the depths a reference holds, `z_near..z_far`, the
//! spread of those shifts is `(f |t_xy| + r |t_z|) (1 / z_near - 1 / z_far)`: zero for a pure
//! rotation or a flat scene, growing linearly with the move.

use super::is_filled;
use crate::core::DepthImage;
use crate::core::Intrinsics;
use engine::Camera;

/// A reference's depth range: the 2nd and 98th percentiles of its finite depths (a few
/// stray samples do not decide it), from a sample of up to 4096 pixels. `None` when it has
/// no finite depth.
pub fn depth_range(reference: &DepthImage) -> Option<(f32, f32)> {
    let step = (reference.depth.len() / 4096).max(1);
    let mut d: Vec<f32> = reference
        .depth
        .iter()
        .zip(&reference.color)
        .step_by(step)
        .filter(|(d, c)| d.is_finite() && **d > 0.0 && is_filled(**c))
        .map(|(d, _)| *d)
        .collect();
    if d.is_empty() {
        return None;
    }
    d.sort_by(f32::total_cmp);
    let at = |q: f32| d[((d.len() - 1) as f32 * q).round() as usize];
    Some((at(0.02), at(0.98)))
}

/// The predicted parallax spread, target pixels, of warping a reference with depth range
/// `range` and camera `from` to `camera` at `width` x `height`. Zero for an orthographic
/// target (no warp is made to it).
pub fn parallax_px(
    range: (f32, f32),
    from: &Camera,
    camera: &Camera,
    width: u32,
    height: u32,
) -> f32 {
    let Some(k) = Intrinsics::of(&camera.projection, width, height) else {
        return 0.0;
    };
    let (near, far) = range;
    if near.is_nan() || near <= 0.0 {
        return 0.0;
    }
    let inv = 1.0 / near - if far.is_finite() { 1.0 / far } else { 0.0 };
    let t = camera.view.transform_point3(from.eye()); // the reference eye in target view space
    let f = k.fl_x.max(k.fl_y);
    let r = 0.5 * ((width as f32).powi(2) + (height as f32).powi(2)).sqrt();
    ((f * t.truncate().length() + r * t.z.abs()) * inv).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::warp::holes::classify;
    use crate::warp::tests::{camera, reference, H, W};
    use crate::warp::{Reconstruction, WarpOptions, Warper};
    use glam::Vec3;

    #[test]
    fn no_move_no_parallax_and_it_grows_with_the_move() {
        let r = reference();
        let range = depth_range(&r).unwrap();
        // The floor near the camera to the wall behind (8 units along the axis).
        assert!(range.0 > 2.0 && range.1 <= 8.5, "{range:?}");
        let at = Vec3::new(0.0, 0.0, -4.0);
        // A pure rotation.
        let turned = camera(r.camera.eye(), Vec3::new(1.0, 0.5, -4.0));
        assert!(parallax_px(range, &r.camera, &turned, W, H) < 1e-3);
        let p = |dx: f32| parallax_px(range, &r.camera, &camera(Vec3::new(dx, 0.0, 2.0), at), W, H);
        let (a, b) = (p(0.2), p(0.4));
        assert!(a > 1.0 && (b / a - 2.0).abs() < 0.15, "{a} {b}");
    }

    #[test]
    fn the_prediction_bounds_the_widest_disocclusion() {
        let r = reference();
        let range = depth_range(&r).unwrap();
        let opts = WarpOptions {
            reconstruction: Reconstruction::Splats,
            ..WarpOptions::default()
        };
        for dx in [0.2f32, 0.4, 0.8] {
            let target = camera(Vec3::new(dx, 0.0, 2.0), Vec3::new(dx, 0.0, -4.0));
            let mut warper = Warper::new();
            warper.begin(&target, W, H);
            warper.add(&r, &opts);
            let out = warper.output();
            // The widest run of holes along a row, away from the image's edges (which the
            // reference never saw).
            let mut widest = 0;
            for y in 0..H {
                let mut run = 0;
                for x in 0..W {
                    if out.is_filled((y * W + x) as usize) {
                        // A run that started at the left edge is not between samples.
                        if run < x {
                            widest = widest.max(run);
                        }
                        run = 0;
                    } else {
                        run += 1;
                    }
                }
            }
            let predicted = parallax_px(range, &r.camera, &target, W, H);
            assert!(classify(out, 0.05).disocclusions > 0, "{dx}");
            assert!(
                widest as f32 <= predicted + 2.0,
                "{dx}: a hole {widest} px wide against {predicted:.1} predicted"
            );
        }
    }
}
