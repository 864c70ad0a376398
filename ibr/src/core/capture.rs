//! The capture service: renders any set of draws from any camera offscreen (perspective,
//! off-axis, orthographic, cube faces) into colour and depth ([`DepthImage`]), optionally
//! triangle ids, or every surface along each ray ([`LayeredDepthImage`], by depth peeling).
//! Its targets and renderer are kept between captures, so capturing again at the same size
//! allocates nothing but what the caller's image needs. [`capture_batch`] spreads many
//! cameras over both cores.
//!
//! Captures clear to transparent black, so an image's alpha is the subject's coverage.

use crate::core::{DepthImage, LayeredDepthImage};
use engine::{
    Camera, Cull, Draw, Encoding, FrameOptions, FrameStats, Lighting, Material, Projection,
    Renderer, Rgba, Shading, Target,
};
use glam::Vec3;
use rayon::prelude::*;

/// A renderer and its offscreen targets, reused capture after capture.
#[derive(Debug)]
pub struct Capturer {
    renderer: Renderer,
    target: Target,
    /// The previous layer while peeling.
    behind: Target,
    /// Materials with [`Shading::FaceId`] for id captures, reused.
    id_materials: Vec<Material>,
    /// Clear colour and culling of every capture.
    pub options: FrameOptions,
}

impl Default for Capturer {
    fn default() -> Self {
        Capturer {
            renderer: Renderer::new(),
            target: Target::new(0, 0),
            behind: Target::new(0, 0),
            id_materials: Vec::new(),
            options: FrameOptions {
                clear: Some(Rgba::TRANSPARENT),
                cull: Cull::PerMaterial,
            },
        }
    }
}

/// A clone shares nothing but the options: the targets and the renderer are scratch.
impl Clone for Capturer {
    fn clone(&self) -> Self {
        Capturer {
            options: self.options,
            ..Capturer::new()
        }
    }
}

impl Capturer {
    /// A capturer with empty targets (sized at the first capture), a transparent clear colour
    /// and per-material culling.
    pub fn new() -> Self {
        Self::default()
    }

    /// Renders `draws` seen by `camera` into the capturer's `width` x `height` target in
    /// `encoding` and returns it (packed colour and reversed depth, as the engine stores
    /// them). The target is reused: read it before the next capture.
    pub fn render<'a>(
        &mut self,
        draws: impl IntoIterator<Item = Draw<'a>>,
        camera: &Camera,
        lighting: &Lighting,
        width: u32,
        height: u32,
        encoding: Encoding,
    ) -> &Target {
        fit(&mut self.target, width, height, encoding);
        let opts = self.options;
        self.renderer
            .render(draws, camera, lighting, &mut self.target, &opts);
        &self.target
    }

    /// The target of the last [`Capturer::render`] or id capture.
    pub fn target(&self) -> &Target {
        &self.target
    }

    /// The renderer's counters of the last capture (the last layer's, for layers).
    pub fn last_stats(&self) -> FrameStats {
        self.renderer.stats()
    }

    /// Captures `draws` seen by `camera` into `out` (resized to `width` x `height`): colour
    /// and depth along the optical axis, with the camera.
    pub fn capture<'a>(
        &mut self,
        draws: impl IntoIterator<Item = Draw<'a>>,
        camera: &Camera,
        lighting: &Lighting,
        width: u32,
        height: u32,
        out: &mut DepthImage,
    ) {
        let target = self.render(draws, camera, lighting, width, height, Encoding::Srgb);
        out.read_target(target, camera);
    }

    /// The triangle seen at every pixel (row-major): 0 where nothing was drawn, else the
    /// frame-wide index of the triangle plus one, counting the draws' triangles in order.
    /// Blended draws are drawn as opaque here.
    pub fn capture_ids<'a>(
        &mut self,
        draws: impl IntoIterator<Item = Draw<'a>> + Clone,
        camera: &Camera,
        width: u32,
        height: u32,
        out: &mut Vec<u32>,
    ) {
        self.id_materials.clear();
        self.id_materials
            .extend(draws.clone().into_iter().map(|d| Material {
                shading: Shading::FaceId,
                alpha_mode: engine::AlphaMode::Opaque,
                base_texture: None,
                ..d.material.clone()
            }));
        fit(&mut self.target, width, height, Encoding::Unorm);
        let id_draws = draws
            .into_iter()
            .zip(&self.id_materials)
            .map(|(d, material)| Draw { material, ..d });
        let opts = self.options;
        self.renderer.render(
            id_draws,
            camera,
            &Lighting::default(),
            &mut self.target,
            &opts,
        );
        out.clear();
        for y in 0..height {
            for x in 0..width {
                let px = self.target.pixel(x, y).unwrap_or(0);
                out.push(if px >> 24 == 0 { 0 } else { px & 0xff_ffff });
            }
        }
    }

    /// Every surface along each pixel's ray, nearest first, by depth peeling: layer 0 is an
    /// ordinary capture, layer k + 1 what lies strictly behind layer k. Stops after
    /// `max_layers` layers or at the first empty one. `draws` is called once per layer.
    pub fn capture_layers<'a, I>(
        &mut self,
        draws: impl Fn() -> I,
        camera: &Camera,
        lighting: &Lighting,
        width: u32,
        height: u32,
        max_layers: usize,
    ) -> LayeredDepthImage
    where
        I: IntoIterator<Item = Draw<'a>>,
    {
        let mut layers = Vec::new();
        fit(&mut self.target, width, height, Encoding::Srgb);
        fit(&mut self.behind, width, height, Encoding::Srgb);
        let opts = self.options;
        for k in 0..max_layers.max(1) {
            let stats = if k == 0 {
                self.renderer
                    .render(draws(), camera, lighting, &mut self.target, &opts)
            } else {
                std::mem::swap(&mut self.target, &mut self.behind);
                self.renderer.render_behind(
                    draws(),
                    camera,
                    lighting,
                    &mut self.target,
                    &opts,
                    &self.behind,
                )
            };
            if stats.fragments_written == 0 && k > 0 {
                break;
            }
            layers.push(DepthImage::from_target(&self.target, camera));
        }
        LayeredDepthImage::from_layers(&layers)
            .unwrap_or_else(|| LayeredDepthImage::empty(width, height, *camera))
    }
}

/// Gives `t` the size and encoding asked for, keeping its storage when they match.
fn fit(t: &mut Target, width: u32, height: u32, encoding: Encoding) {
    if t.width() != width || t.height() != height {
        t.resize(width, height);
    }
    t.set_encoding(encoding);
}

/// Captures the same `draws` from every camera of `cameras` at `width` x `height`, the
/// cameras shared out over the thread pool (each worker with a capturer of its own).
/// The draws must not depend on the camera (prepare view-dependent subjects per view and
/// capture them one by one instead). Same images at any thread count.
pub fn capture_batch(
    draws: &[Draw<'_>],
    cameras: &[Camera],
    lighting: &Lighting,
    width: u32,
    height: u32,
) -> Vec<DepthImage> {
    cameras
        .par_iter()
        .map_init(Capturer::new, |cap, camera| {
            let mut out = DepthImage::new(0, 0, *camera);
            cap.capture(
                draws.iter().copied(),
                camera,
                lighting,
                width,
                height,
                &mut out,
            );
            out
        })
        .collect()
}

/// The six 90-degree cameras of a cube map around `eye`, in the order +X, -X, +Y, -Y, +Z,
/// -Z (OpenGL's face order), each with the OpenGL cube-map up vector, so the six images
/// tile the sphere of directions without gaps or overlaps.
pub fn cube_cameras(eye: Vec3, near: f32, far: f32) -> [Camera; 6] {
    let faces = [
        (Vec3::X, Vec3::NEG_Y),
        (Vec3::NEG_X, Vec3::NEG_Y),
        (Vec3::Y, Vec3::Z),
        (Vec3::NEG_Y, Vec3::NEG_Z),
        (Vec3::Z, Vec3::NEG_Y),
        (Vec3::NEG_Z, Vec3::NEG_Y),
    ];
    faces.map(|(dir, up)| Camera {
        view: glam::Mat4::look_at_rh(eye, eye + dir, up),
        projection: Projection::Perspective {
            fov_y: std::f32::consts::FRAC_PI_2,
            aspect: 1.0,
            near,
            far,
        },
    })
}
#[cfg(test)]
mod tests;
