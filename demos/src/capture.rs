//! Captures from the command line: a scene rendered from a row of cameras and written as a
//! `transforms.json` capture (PNG colour, PFM depth along the optical axis), which the
//! `warp` command and other tools read.

use engine::{Camera, FrameOptions, Renderer, Scene, Target};
use glam::{Quat, Vec3};
use ibr::images::{transforms, DepthImage};
use std::path::Path;

/// `views` eyes on a horizontal arc around `target` through `eye` (about `up`), spread
/// evenly over `spread_deg` degrees centred on `eye`; just `eye` for one view.
pub fn arc(eye: Vec3, target: Vec3, up: Vec3, views: usize, spread_deg: f32) -> Vec<Vec3> {
    let axis = up.normalize_or(Vec3::Y);
    (0..views.max(1))
        .map(|i| {
            let t = if views <= 1 {
                0.0
            } else {
                i as f32 / (views - 1) as f32 - 0.5
            };
            let turn = Quat::from_axis_angle(axis, (t * spread_deg).to_radians());
            target + turn * (eye - target)
        })
        .collect()
}

/// Renders `scene` from each camera at `width` x `height` and writes the capture into
/// `dir`. Returns the frames written.
pub fn write(
    dir: &Path,
    scene: &Scene,
    cameras: &[Camera],
    width: u32,
    height: u32,
    opts: &FrameOptions,
) -> Result<usize, String> {
    let mut renderer = Renderer::new();
    let mut target = Target::new(width, height);
    let images: Vec<DepthImage> = cameras
        .iter()
        .map(|camera| {
            renderer.render_scene(scene, camera, &mut target, opts);
            DepthImage::from_target(&target, camera)
        })
        .collect();
    transforms::write_transforms(dir, &images).map_err(|e| e.to_string())?;
    Ok(images.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_arc_keeps_its_distance_and_centres_on_the_eye() {
        let (eye, target) = (Vec3::new(0.0, 1.0, 5.0), Vec3::new(0.0, 1.0, 0.0));
        let eyes = arc(eye, target, Vec3::Y, 5, 40.0);
        assert_eq!(eyes.len(), 5);
        assert!((eyes[2] - eye).length() < 1e-5);
        for e in &eyes {
            assert!(((*e - target).length() - 5.0).abs() < 1e-4);
            assert!((e.y - 1.0).abs() < 1e-5);
        }
        let turn = (eyes[4] - target)
            .angle_between(eyes[0] - target)
            .to_degrees();
        assert!((turn - 40.0).abs() < 1e-3, "{turn}");
        assert_eq!(arc(eye, target, Vec3::Y, 1, 40.0), vec![eye]);
    }
}
