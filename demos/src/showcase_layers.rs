//! The showcase's layered background (Lengyel and Snyder's image layers, [`ibr::layers`]):
//! every object of the scene farther than [`NEAR`] from the plaza's centre becomes an image
//! layer (one per tree, rock or prop), re-rendered only when its warp errs by more than the
//! tolerance; the plaza, what stands on it and the terrain stay geometry. The eye strolls
//! across the plaza and turns, and every frame is measured against a render of all the
//! geometry from the same eye, for the readout.
//!
//! The terrain is what every layer stands on. Layers are composited back to front, each at
//! one depth, so a layer of ground would have to be both behind the trees on it and in
//! front of the trees beyond its crest; cut by depth range ([`ibr::layers::split_by_depth`])
//! it still is. Drawn as geometry, it hides each layer exactly where it should.

use crate::showcase::{self, Showcase};
use engine::{Camera, FrameOptions, FrameStats, Renderer, Target};
use glam::Vec3;
use ibr::layers::{self, Layered};
use ibr::metrics::{self, ImageError, Options};
use ibr::schedule::Budget;
use ibr::subject::{MeshGroup, Subject};
use ibr::technique::{FrameLoop, FrameView};

/// Objects whose bounding sphere's centre lies farther than this from the plaza's centre
/// (horizontally) are layers.
pub const NEAR: f32 = 10.0;
/// Objects with a larger bounding radius (the terrain) stay geometry.
pub const LARGE: f32 = 20.0;

/// The layered background, the geometry it stands for, and its measurements.
#[derive(Debug)]
pub struct LayeredBackground {
    /// The far scene as layers.
    pub layers: Layered<MeshGroup>,
    /// The near scene, drawn as geometry.
    pub near: Vec<MeshGroup>,
    renderer: Renderer,
    frames: FrameLoop,
    truth: Target,
    /// Re-renders since the start.
    pub refreshes: u64,
}

/// What a frame of the layered background did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Readout {
    pub images: usize,
    pub geometry: usize,
    pub refreshes: usize,
    /// The largest predicted geometric error of a drawn layer, pixels.
    pub max_px: f32,
    /// The frame against a render of all the geometry from the same eye.
    pub error: Option<ImageError>,
}

impl Readout {
    /// One line for the window and the console.
    pub fn line(&self) -> String {
        let error = self.error.map_or(String::from("-"), |e| {
            format!(
                "{:.1} dB, {:.1}% off",
                e.psnr_capped(99.0),
                100.0 * e.frac_over
            )
        });
        format!(
            "layers: {} images, {} geometry, {} re-rendered, worst {:.2} px; frame vs geometry {error}",
            self.images, self.geometry, self.refreshes, self.max_px
        )
    }
}

impl LayeredBackground {
    /// The showcase's far scene as layers at `tolerance_px` of geometric error, re-rendering
    /// at most `budget` layers a frame (perspective warps, so turning costs nothing).
    pub fn new(show: &Showcase, tolerance_px: f32, budget: usize) -> Self {
        let scene = &show.scene;
        let (mut far, mut near) = (Vec::new(), Vec::new());
        for i in 0..scene.instances.len() {
            let group = MeshGroup::from_scene(scene, [i]);
            let b = group.bounds();
            if b.radius <= LARGE && b.center.x.hypot(b.center.z) > NEAR {
                far.push(group);
            } else {
                near.push(group);
            }
        }
        let cfg = layers::Config {
            tolerance_px,
            perspective: true,
            budget: Budget::count(budget),
            ..layers::Config::default()
        };
        LayeredBackground {
            layers: Layered::new("layered background", cfg, far),
            near,
            renderer: Renderer::new(),
            frames: FrameLoop::new(),
            truth: Target::new(0, 0),
            refreshes: 0,
        }
    }

    /// The moment's camera at frame `i` of `n` for a `width` x `height` image: the eye
    /// strolls 6 units across the plaza looking out over the terrain, turning 40 degrees.
    pub fn camera(i: usize, n: usize, width: u32, height: u32) -> Camera {
        let t = i as f32 / (n.max(2) - 1) as f32;
        let eye = Vec3::new(-3.0 + 6.0 * t, 2.2 + 0.4 * t, 5.0);
        let yaw = (t - 0.5) * 0.7;
        let dir = Vec3::new(yaw.sin(), -0.12, -yaw.cos());
        showcase::camera(eye, eye + dir, width, height)
    }

    /// Renders one frame from `camera` into `target` (the near scene as geometry, the far
    /// one as layers), then measures it against all the geometry.
    pub fn frame(&mut self, show: &Showcase, camera: &Camera, target: &mut Target) -> Readout {
        let (w, h) = (target.width(), target.height());
        let lighting = &show.scene.lighting;
        let opts = FrameOptions {
            clear: Some(showcase::SKY),
            ..FrameOptions::default()
        };
        let mut near = Vec::new();
        self.near.iter().for_each(|g| g.draws(&mut near));
        let view = FrameView::still(camera, w, h, lighting);
        let layers = &mut self.layers;
        self.frames.render(
            &mut self.renderer,
            near,
            &mut [layers],
            &view,
            target,
            &opts,
        );
        let r = self.layers.report;
        self.refreshes += r.refreshes as u64;
        if (self.truth.width(), self.truth.height()) != (w, h) {
            self.truth = Target::new(w, h);
        }
        let _: FrameStats =
            self.renderer
                .render(show.scene.draws(), camera, lighting, &mut self.truth, &opts);
        Readout {
            images: r.images,
            geometry: r.geometry,
            refreshes: r.refreshes,
            max_px: r.max_px,
            error: metrics::compare(&self.truth, target, &Options::default()).ok(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_far_scene_is_layers_and_the_frame_stays_near_the_geometry() {
        let show = Showcase::new();
        let mut bg = LayeredBackground::new(&show, 1.0, 64);
        assert!(
            bg.layers.subjects.len() > 40,
            "{}",
            bg.layers.subjects.len()
        );
        let total: usize = bg
            .layers
            .subjects
            .iter()
            .chain(&bg.near)
            .map(|g| g.triangle_count())
            .sum();
        let scene: usize = show.scene.draws().map(|d| d.mesh.triangle_count()).sum();
        assert_eq!(
            total, scene,
            "every triangle in one layer or in the near scene"
        );
        let (w, h) = (160, 96);
        let mut target = Target::new(w, h);
        // The first 8 of the moment's 40 frames.
        let mut readouts = Vec::new();
        for i in 0..8 {
            let camera = LayeredBackground::camera(i, 40, w, h);
            readouts.push(bg.frame(&show, &camera, &mut target));
        }
        // Every layer is taken in the first frame; later frames warp most of them.
        assert!(readouts[0].refreshes > 20, "{:?}", readouts[0]);
        let later: usize = readouts[1..].iter().map(|r| r.refreshes).sum();
        assert!(later < readouts[0].refreshes, "{readouts:?}");
        for r in &readouts {
            assert!(r.max_px <= 1.0 + 1e-3, "{r:?}");
            let e = r.error.expect("same size");
            assert!(e.psnr_db > 25.0 && e.frac_over < 0.05, "{}", r.line());
        }
    }
}
