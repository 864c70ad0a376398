//! Rectified stereo pairs rendered by the engine with exact ground truth: the right camera
//! is the left one moved `baseline` along its own x axis, same image plane, so a point at
//! depth `z` (along the optical axis) has disparity `fx baseline / z` (`fx` the focal
//! length in pixels along x), and the right image shows it `d` pixels to the left.

use super::Disparity;
use crate::core::capture_batch;
use crate::core::DepthImage;
use engine::{Camera, Draw, Lighting};
use glam::Mat4;

/// Relative depth difference within which the right image is taken to see the same
/// surface point as the left.
const SAME_POINT: f32 = 0.01;

/// Two rectified views and the left one's true disparities.
#[derive(Clone, Debug)]
pub struct StereoPair {
    /// The left view, colour and depth, its camera's.
    pub left: DepthImage,
    /// The right view, same size, its camera moved `baseline` along the left's image x.
    pub right: DepthImage,
    /// The left image's disparities: infinite where it shows nothing.
    pub truth: Disparity,
    /// Left pixels whose point the right image sees too (not occluded, not out of view).
    pub visible: Vec<bool>,
    /// Focal length in pixels along x, and the baseline (scene units).
    pub focal_px: f32,
    /// Distance between the two cameras' centres, scene units: disparity is
    /// `focal_px * baseline / z`, `z` the depth along the optical axis.
    pub baseline: f32,
}

impl StereoPair {
    /// Renders `draws` under `lighting` from `left` and from `left` moved `baseline` to
    /// its right, `width` x `height` each, with the left image's true disparities.
    pub fn render(
        draws: &[Draw<'_>],
        lighting: &Lighting,
        left: &Camera,
        baseline: f32,
        width: u32,
        height: u32,
    ) -> StereoPair {
        let right = Camera {
            view: Mat4::from_translation(glam::Vec3::new(-baseline, 0.0, 0.0)) * left.view,
            projection: left.projection,
        };
        let [l, r]: [DepthImage; 2] =
            capture_batch(draws, &[*left, right], lighting, width, height)
                .try_into()
                .expect("two views");
        StereoPair::from_views(l, r, baseline)
    }

    /// A pair of views already rectified (the right camera the left one moved `baseline`
    /// along its own x axis, one size), with depth: the left one's true disparities from
    /// its depth, and which of its pixels the right one sees.
    pub fn from_views(l: DepthImage, r: DepthImage, baseline: f32) -> StereoPair {
        let (width, height) = (l.width(), l.height());
        // x pixels per unit of x / z in the camera's space.
        let focal_px = l.camera.projection.gl_matrix().x_axis.x * 0.5 * width as f32;
        let d_of = |z: f32| {
            if z.is_finite() && z > 0.0 {
                focal_px * baseline / z
            } else {
                f32::INFINITY
            }
        };
        let truth: Vec<f32> = l.depth.iter().map(|&z| d_of(z)).collect();
        let w = width as usize;
        let same_size = r.width() == width && r.height() == height;
        let visible = truth
            .iter()
            .enumerate()
            .map(|(i, &d)| {
                let (x, y) = (i % w, i / w);
                let xr = x as f32 - d;
                if !same_size || !d.is_finite() || xr < -0.5 {
                    return false;
                }
                let z = l.depth[i];
                // The right pixels around where the point lands.
                let lo = xr.floor().max(0.0) as usize;
                (lo..=(lo + 1).min(w - 1)).any(|xr| {
                    let zr = r.depth[y * w + xr];
                    (zr - z).abs() <= SAME_POINT * z
                })
            })
            .collect();
        StereoPair {
            truth: Disparity::new(width, height, truth).expect("finite, positive or infinite"),
            left: l,
            right: r,
            visible,
            focal_px,
            baseline,
        }
    }
}
