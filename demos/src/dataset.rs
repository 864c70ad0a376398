//! Datasets of views from the command line (`render --capture DIR`): a scene rendered from
//! a row of cameras and written as a `transforms.json` dataset (PNG colour, PFM depth along
//! the optical axis), which the `warp` command and other tools read. (In `ibr` and the rest
//! of demos, capturing means rendering an image representation: `ibr::capture`.)
//!
//! The colour files hold the bytes the render target holds, in the target's encoding:
//! sRGB for lit and textured shadings, unorm for the data-like shadings (flat and vertex
//! colours, face ids), exactly as `render --png` writes the same view. Readers take a PNG
//! as sRGB, so the images kept in memory ([`frames`]) are those bytes decoded as sRGB: what
//! reading the dataset back gives, and what [`transforms::srgb8`] turns back into the same
//! bytes.

use engine::color::srgb_to_linear_lut;
use engine::{Camera, Encoding, FrameOptions, Renderer, Rgba, Scene, Target};
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

/// The frames of a dataset: `scene` rendered from each camera at `width` x `height` into
/// a target of `encoding`, each image's colour the target's bytes read as sRGB (the
/// module doc), its depth the distance along the optical axis.
pub fn frames(
    scene: &Scene,
    cameras: &[Camera],
    width: u32,
    height: u32,
    encoding: Encoding,
    opts: &FrameOptions,
) -> Vec<DepthImage> {
    let mut renderer = Renderer::new();
    let mut target = Target::with_encoding(width, height, encoding);
    cameras
        .iter()
        .map(|camera| {
            renderer.render_scene(scene, camera, &mut target, opts);
            let mut image = DepthImage::from_target(&target, camera);
            image.color = as_srgb(&target.to_rgba8());
            image
        })
        .collect()
}

/// Straight RGBA8 bytes as premultiplied linear colour, the bytes read as sRGB.
fn as_srgb(bytes: &[u8]) -> Vec<engine::Premul> {
    let lut = srgb_to_linear_lut();
    bytes
        .chunks_exact(4)
        .map(|p| {
            let a = f32::from(p[3]) / 255.0;
            Rgba::new(
                lut[p[0] as usize],
                lut[p[1] as usize],
                lut[p[2] as usize],
                a,
            )
            .premultiply()
        })
        .collect()
}

/// Renders `scene` from each camera at `width` x `height` into a target of `encoding`
/// (the shading's) and writes the dataset into `dir`. Returns the frames written.
pub fn write(
    dir: &Path,
    scene: &Scene,
    cameras: &[Camera],
    (width, height): (u32, u32),
    encoding: Encoding,
    opts: &FrameOptions,
) -> Result<usize, String> {
    let images = frames(scene, cameras, width, height, encoding, opts);
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

    /// What the capture's PNG holds is the target's bytes, for every byte value and both
    /// encodings: opaque pixels exactly, as the transforms writer encodes them.
    #[test]
    fn a_frame_writes_back_the_targets_bytes() {
        use engine::Shading;
        let cameras = [Camera::look_at(
            Vec3::new(0.0, 0.0, 3.0),
            Vec3::ZERO,
            Vec3::Y,
            1.0,
            1.0,
        )];
        // Every byte through the writer's encode: the sRGB read is undone exactly.
        let all: Vec<u8> = (0..=255u8).flat_map(|b| [b, 255 - b, b / 2, 255]).collect();
        let image =
            DepthImage::from_planes(256, 1, as_srgb(&all), vec![1.0; 256], cameras[0]).unwrap();
        assert_eq!(transforms::srgb8(&image), all);
        // A face-id render: triangle 1 is byte 1 in the file, not its sRGB encoding.
        let mut scene = Scene::default();
        scene.meshes.push(engine::procedural::quad(2.0, 2.0));
        scene.materials.push(engine::Material {
            shading: Shading::FaceId,
            ..engine::Material::default()
        });
        scene.instances.push(engine::Instance {
            mesh: 0,
            material: 0,
            transform: glam::Mat4::IDENTITY,
        });
        let opts = FrameOptions {
            clear: Some(Rgba::BLACK),
            ..FrameOptions::default()
        };
        for encoding in [Encoding::Unorm, Encoding::Srgb] {
            let images = frames(&scene, &cameras, 16, 16, encoding, &opts);
            let bytes = transforms::srgb8(&images[0]);
            if encoding == Encoding::Unorm {
                // Triangle 1 or 2 (the pixel is near the diagonal), never its sRGB form.
                let centre = (8 * 16 + 8) * 4;
                let id = &bytes[centre..centre + 4];
                assert!(matches!(id, [1 | 2, 0, 0, 255]), "{id:?}");
            }
            let mut target = Target::with_encoding(16, 16, encoding);
            Renderer::new().render_scene(&scene, &cameras[0], &mut target, &opts);
            assert_eq!(bytes, target.to_rgba8(), "{encoding:?}");
        }
    }
}
