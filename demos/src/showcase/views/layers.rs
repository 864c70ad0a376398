//! The views moment's layered background (Lengyel and Snyder's image layers,
//! [`ibr::layers`]): every object of the scene farther than [`NEAR`] from the plaza's centre
//! becomes an image layer (one per tree, rock or prop), warped by the perspective map fitted
//! to its box corners and re-rendered only when that errs by more than
//! [`LAYERS_TOLERANCE_PX`]; the plaza, what stands on it and the terrain stay geometry. The
//! eye strolls across the plaza and turns, and every frame is measured against a render of
//! all the geometry from the same eye.
//!
//! The terrain is what every layer stands on. Layers are composited back to front, each at
//! one depth, so a layer of ground would have to be both behind the trees on it and in
//! front of the trees beyond its crest; cut by depth range ([`ibr::layers::split_by_depth`])
//! it still is. Drawn as geometry, it hides each layer exactly where it should.

use super::{in_view, triangles, world_spheres, Frame, Stages};
use crate::showcase;
use crate::timing::Usage;
use engine::{Camera, FrameOptions, Lighting, Renderer, Scene, Sphere, Target};
use glam::Vec3;
use ibr::layers::{self, Layered};
use ibr::metrics::{self, ImageError, Options};
use ibr::schedule::Budget;
use ibr::subject::{MeshGroup, Subject};
use ibr::technique::{FrameLoop, FrameView};
use std::time::{Duration, Instant};

/// Objects whose bounding sphere's centre lies farther than this from the plaza's centre
/// (horizontally) are layers.
pub const NEAR: f32 = 10.0;
/// Objects with a larger bounding radius (the terrain) stay geometry.
pub const LARGE: f32 = 20.0;
/// A layer is re-rendered past this much geometric error (pixels).
pub const LAYERS_TOLERANCE_PX: f32 = 1.0;
/// Most layers re-rendered a frame.
pub const LAYERS_BUDGET: usize = 16;

/// What the layered background showed in one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LayersFrame {
    /// Layers drawn as images, and as geometry (no image yet, or a corner behind the eye).
    pub images: usize,
    pub geometry: usize,
    /// Layers re-rendered this frame.
    pub refreshes: usize,
    /// The largest predicted geometric error of a drawn layer, pixels.
    pub max_px: f32,
    /// The frame against a render of all the geometry from the same eye.
    pub error: Option<ImageError>,
    /// The near scene's triangles drawn (of the draws whose bounding sphere the view
    /// reaches), of all of its triangles (a work counter).
    pub near_triangles: usize,
    pub triangles: usize,
}

impl LayersFrame {
    /// The readout line (upper case, for the bitmap font).
    pub fn line(&self) -> String {
        let error = self.error.map_or(String::from("-"), |e| {
            format!(
                "{:.1} DB, {:.1}% WRONG",
                e.psnr_capped(super::PSNR_CAP),
                100.0 * e.frac_over
            )
        });
        format!(
            "LAYERED BACKGROUND  {} IMAGES  {} GEOMETRY  {} RE-RENDERED  WORST {:.2} PX (TOL {})  \
             NEAR {:.1}K OF {:.1}K TRIANGLES  {error}",
            self.images,
            self.geometry,
            self.refreshes,
            self.max_px,
            LAYERS_TOLERANCE_PX,
            self.near_triangles as f64 * 1e-3,
            self.triangles as f64 * 1e-3
        )
    }
}

/// The layers, the near scene drawn as geometry, and the targets each frame reuses.
#[derive(Debug)]
pub(super) struct LayersPart {
    pub(super) layers: Layered<MeshGroup>,
    pub(super) near: Vec<MeshGroup>,
    /// The near scene's draws' bounding spheres ([`world_spheres`]), made once.
    spheres: Vec<Sphere>,
    renderer: Renderer,
    frames: FrameLoop,
    image: Target,
    truth: Target,
}

impl LayersPart {
    /// The far objects of `scene` as layers for a `width` x `height` view.
    pub(super) fn new(scene: &Scene, width: u32, height: u32) -> LayersPart {
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
            tolerance_px: LAYERS_TOLERANCE_PX,
            perspective: true,
            budget: Budget::count(LAYERS_BUDGET),
            // A layer past its tolerance that the budget did not reach this frame is drawn
            // as geometry, not as an image up to twice the tolerance wrong (the default):
            // the stroll's steps put most layers past a pixel every frame, so every image
            // drawn is within the tolerance.
            fallback_ratio: 1.0,
            ..layers::Config::default()
        };
        let mut draws = Vec::new();
        near.iter().for_each(|g| g.draws(&mut draws));
        let spheres = world_spheres(&draws);
        let mut part = LayersPart {
            layers: Layered::new("layered background", cfg, far),
            near,
            spheres,
            renderer: Renderer::new(),
            frames: FrameLoop::new(),
            image: Target::new(width, height),
            truth: Target::new(width, height),
        };
        part.render_first_images(&scene.lighting);
        part
    }

    /// Renders the image of every layer the stroll's first view reaches, with no cap: the
    /// burst of the first frame, which no per-frame budget holds, done as loading. Later
    /// frames re-render only the layers whose predicted error passes the tolerance.
    fn render_first_images(&mut self, lighting: &Lighting) {
        let camera = self.camera(0.0);
        let size = (self.image.width(), self.image.height());
        let set = &mut self.layers.set;
        let budget = set.config.budget;
        set.config.budget = Budget::count(set.layers.len());
        set.update(&mut self.layers.subjects, &camera, size, lighting);
        set.config.budget = budget;
    }

    /// The camera a fraction `t` along the stroll: 6 units across the plaza looking out
    /// over the terrain, turning 40 degrees.
    pub(super) fn camera(&self, t: f32) -> Camera {
        let eye = Vec3::new(-3.0 + 6.0 * t, 2.2 + 0.4 * t, 5.0);
        let yaw = (t - 0.5) * 0.7;
        let dir = Vec3::new(yaw.sin(), -0.12, -yaw.cos());
        let (w, h) = (self.image.width(), self.image.height());
        showcase::camera(eye, eye + dir, w, h)
    }

    /// The frame a fraction `t` along the stroll (the near scene as geometry, the far one
    /// as layers) into `out`, measured against all the geometry.
    /// The last frame's geometry, as the frame's RGBA8 (for its flicker).
    pub(super) fn truth_rgba(&self) -> Vec<u8> {
        self.truth.to_rgba8()
    }

    pub(super) fn frame(&mut self, scene: &Scene, t: f32, out: &mut Frame) -> LayersFrame {
        let camera = self.camera(t);
        let (w, h) = (self.image.width(), self.image.height());
        let lighting = &scene.lighting;
        let opts = FrameOptions {
            clear: Some(showcase::SKY),
            ..FrameOptions::default()
        };
        let mut all = Vec::new();
        self.near.iter().for_each(|g| g.draws(&mut all));
        if self.spheres.len() != all.len() {
            self.spheres = world_spheres(&all);
        }
        // Only the draws the view reaches: the same pixels, fewer triangles set up.
        let mut near = Vec::with_capacity(all.len());
        in_view(&all, &self.spheres, &camera, &mut near);
        let near_triangles = triangles(&near);
        let view = FrameView::still(&camera, w, h, lighting);
        let layers = &mut self.layers;
        self.frames.render(
            &mut self.renderer,
            near,
            &mut [layers],
            &view,
            &mut self.image,
            &opts,
        );
        let r = self.layers.report;
        let encode = Instant::now();
        self.image.write_rgba8(&mut out.rgba);
        let t = self.frames.times;
        let stages = Stages {
            layers: t.prepare,
            geometry: t.total.saturating_sub(t.prepare),
            over_sky: encode.elapsed(),
            ..Stages::default()
        };
        (out.width, out.height) = (w, h);
        (out.measure, out.measure_usage) = (Duration::ZERO, Usage::default());
        out.stages = stages;
        let measure = Instant::now();
        let used = Usage::now();
        self.renderer
            .render(scene.draws(), &camera, lighting, &mut self.truth, &opts);
        let error = metrics::compare(&self.truth, &self.image, &Options::default()).ok();
        // Both reads of the usage inside the measure's time, which the frame leaves out.
        out.measure_usage = Usage::now().since(used);
        out.measure = measure.elapsed();
        LayersFrame {
            images: r.images,
            geometry: r.geometry,
            refreshes: r.refreshes,
            max_px: r.max_px,
            error,
            near_triangles,
            triangles: triangles(&all),
        }
    }
}
