//! Image layers (Lengyel and Snyder, "Rendering with Coherent Layers", SIGGRAPH 97): each
//! subject rendered into its own image, cropped to its screen rectangle at a resolution
//! that matches its screen size, and on later frames warped by the affine map fitted to
//! its characteristic points instead of being rendered again.
//!
//! Per frame, [`LayerSet::update`] projects each subject's characteristic points (the
//! corners of its box, [`Subject::corners`]) and fits the affine map from where they lay
//! in its image to where they are now ([`Affine::fit`]), or, with [`Config::perspective`],
//! the perspective map ([`Homography::fit`], which follows a turn of the view exactly).
//! Its error, predicted without rendering:
//! - *geometric*: the largest distance, in pixels, between a point's true projection and
//!   where the fitted warp puts it (the paper's fiducial);
//! - *sampling*: how far the warp's stretch has drifted from the image's, in octaves (a
//!   magnified image blurs, a shrunk one wastes texels);
//! - *coverage*: whether the image still covers the part of the layer now on screen (an
//!   image cropped at the view's edge does not, once the view turns).
//!
//! A layer whose error passes its tolerance is re-rendered, largest error first, within the
//! per-frame budget of the impostors' scheduler ([`crate::core`], shared). A warped
//! image is drawn as a quad whose corners lie where the warp puts them, the nearest at the
//! layer's nearest depth (parallel to the screen for an affine warp; for a perspective one
//! its corners' depths follow the warp's weights, so the renderer's perspective-correct
//! interpolation is the warp), alpha-blended back to front with the frame; a layer
//! with a corner behind the near plane, no image yet, or an image too stale to show is
//! drawn as geometry. [`split_by_depth`] cuts a large object into layers by depth range.

mod fit;
mod frame;
pub(crate) mod plan;
mod split;
mod technique;

pub use fit::{project, unproject, Affine, Homography, Projector, Unprojector};
pub use split::split_by_depth;
pub use technique::Layered;

pub(crate) use frame::{bounds, clip};
use frame::{build_quad, finish, grow, job, overlaps, predict};

use crate::core::Subject;
use crate::core::{image_material, Frustum};
use crate::core::{refresh_side_by_side, Budget, Refresher, Scheduler};
use engine::{Camera, Draw, Lighting, Material, Mesh, Rgba};
use glam::{Mat4, Vec2, Vec3};
use std::sync::Mutex;
use std::time::Instant;

/// Settings of a [`LayerSet`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    /// Largest geometric error, pixels.
    pub tolerance_px: f32,
    /// Largest drift of the warp's stretch from the image's, octaves.
    pub octaves: f32,
    /// Warp by the perspective map fitted to the points when it fits them better than the
    /// affine one (Lengyel and Snyder's layers are affine).
    pub perspective: bool,
    /// Refreshes allowed per frame (a count, optionally a time), shared out largest error
    /// first.
    pub budget: Budget,
    /// Texels per screen pixel of a fresh image (1: the screen's resolution).
    pub resolution: f32,
    /// Largest side of an image, texels (a larger layer's image is shrunk to fit).
    pub max_side: u32,
    /// How far beyond the view a layer's image reaches, as a fraction of the view's size
    /// (the view can turn that far before an image cropped at its edge runs out); layers
    /// within it and outside the view are refreshed ahead of coming into view.
    pub margin: f32,
    /// An image whose error ratio is above this after the frame's refreshes is not shown:
    /// its subject is drawn as geometry. Infinity never falls back.
    pub fallback_ratio: f32,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            tolerance_px: 1.0,
            octaves: 0.5,
            perspective: false,
            budget: Budget::count(8),
            resolution: 1.0,
            max_side: 1024,
            margin: 0.25,
            fallback_ratio: 2.0,
        }
    }
}

/// How a layer's subject is drawn this frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Mode {
    /// Its warped image.
    Image,
    /// As geometry, and why.
    Geometry(Why),
    /// Not at all: outside the view.
    #[default]
    Culled,
}

/// Why a layer is drawn as geometry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Why {
    /// A characteristic point is at or behind the near plane: no affine map will do.
    Behind,
    /// It has no image yet and the budget had no room for one.
    NoImage,
    /// Its image's error is over [`Config::fallback_ratio`] times the tolerance and the
    /// budget had no room to refresh it.
    Stale,
}

/// A layer's predicted error this frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Predicted {
    /// Geometric error: the largest distance between a characteristic point's projection
    /// and its warped position, pixels.
    pub pixels: f32,
    /// Sampling error: `|log2|` of the warp's stretch over the image's, the larger of the
    /// two directions.
    pub octaves: f32,
    /// The image covers the part of the layer on screen.
    pub covered: bool,
    /// The larger error over its tolerance: invalid at 1 and above (infinite with no image,
    /// a changed subject, or a part on screen the image lacks).
    pub ratio: f32,
}

/// What a layer's image holds: where its subject's characteristic points lay in it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Image {
    texels: [Vec2; 8],
    width: u32,
    height: u32,
    /// Screen pixels per texel when it was rendered.
    pub(crate) scale: f32,
    version: u64,
    /// Sides (left, top, right, bottom) where the image was cut at the margin beyond the
    /// view, not at the layer's edge: only there can the screen come to show what it lacks.
    cut: [bool; 4],
    /// How busy the image is: the mean absolute difference between neighbouring texels,
    /// 8-bit levels per texel (RGB), as the impostors' [`crate::core::Capture::gradient`]:
    /// what turns the warp's error in pixels into an image error for the planner.
    pub(crate) gradient: f32,
}

/// One layer's state.
#[derive(Debug)]
pub struct Layer {
    pub(crate) image: Option<Image>,
    material: Material,
    quad: Mesh,
    /// This frame's warp of the image to the screen.
    pub warp: Homography,
    /// This frame's predicted error.
    pub predicted: Predicted,
    /// How its subject is drawn this frame.
    pub mode: Mode,
    /// Times rendered.
    pub refreshes: u64,
    /// The characteristic points' projections this frame, and the nearest one's depth.
    screen: [Vec2; 8],
    nearest: f32,
    /// The last fit of the image and what it was fitted from, for the planner's
    /// prediction and then its draw (behind a lock: predictions are made through `&self`).
    fitted: Mutex<Option<(frame::FitOf, (Predicted, Homography))>>,
}

impl Default for Layer {
    fn default() -> Self {
        Layer {
            image: None,
            material: image_material(1, 1, "layer"),
            quad: Mesh::default(),
            warp: Affine::scaled(1.0, Vec2::ZERO).into(),
            predicted: Predicted::default(),
            mode: Mode::Culled,
            refreshes: 0,
            screen: [Vec2::ZERO; 8],
            nearest: 0.0,
            fitted: Mutex::new(None),
        }
    }
}

impl Layer {
    /// The size of its image, if it has one.
    pub fn image_size(&self) -> Option<(u32, u32)> {
        self.image.map(|i| (i.width, i.height))
    }
}

/// What one [`LayerSet::update`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Report {
    /// Layers re-rendered this frame.
    pub refreshes: usize,
    /// Visible invalid layers left stale (over budget).
    pub stale: usize,
    /// Layers drawn as their warped image.
    pub images: usize,
    /// Layers drawn as geometry, for any [`Why`].
    pub geometry: usize,
    /// Layers outside the view, not drawn.
    pub culled: usize,
    /// Largest geometric error over the drawn images, pixels.
    pub max_px: f32,
    /// Mean geometric error over the drawn images, pixels (0 when none is drawn).
    pub mean_px: f32,
    /// Images drawn with an error ratio over 1.
    pub over_tolerance: usize,
    /// Layers drawn as geometry because their image was too stale ([`Why::Stale`]).
    pub stale_fallbacks: usize,
    /// Texels the refreshes rendered.
    pub capture_texels: u64,
    /// Triangles the refreshes rendered.
    pub capture_triangles: u64,
}

/// A refresh's own [`Refresher`], the triangles it rendered, and its image's gradient
/// (with the row scratch that measures it).
#[derive(Debug, Default)]
struct Worker {
    refresher: Refresher,
    triangles: u64,
    gradient: f32,
    rows: plan::Rows,
}

/// One refresh: which layer, which screen rectangle, at what size, cut on which sides.
#[derive(Clone, Copy, Debug)]
struct Job {
    i: usize,
    min: Vec2,
    max: Vec2,
    width: u32,
    height: u32,
    cut: [bool; 4],
}

/// Image layers for a list of subjects (one per subject, same order), drawn back to front.
#[derive(Debug)]
pub struct LayerSet {
    /// Settings; may be changed between frames.
    pub config: Config,
    /// One layer per subject, in the subjects' order.
    pub layers: Vec<Layer>,
    scheduler: Scheduler,
    workers: Vec<Worker>,
    jobs: Vec<Job>,
    /// The planner's debug tint of the layers' images ([`crate::core::Representation::set_tint`]).
    tint: Option<Rgba>,
}

impl LayerSet {
    /// A set of `count` layers, none rendered yet.
    pub fn new(config: Config, count: usize) -> Self {
        LayerSet {
            config,
            layers: (0..count).map(|_| Layer::default()).collect(),
            scheduler: Scheduler::default(),
            workers: Vec::new(),
            jobs: Vec::new(),
            tint: None,
        }
    }

    /// Predicts every layer's error for `camera` (a `width` x `height` image), re-renders
    /// the worst within the budget, and decides how each is drawn. Subjects drawn as
    /// geometry are prepared for `camera`.
    pub fn update<S: Subject + Send>(
        &mut self,
        subjects: &mut [S],
        camera: &Camera,
        (width, height): (u32, u32),
        lighting: &Lighting,
    ) -> Report {
        let cfg = self.config;
        let view = (Vec2::ZERO, Vec2::new(width as f32, height as f32));
        let grown = grow(view, cfg.margin);
        let frustum = Frustum::new(camera.clip_from_world());
        self.scheduler.clear();
        let projector = Projector::new(camera, width, height);
        for (i, (layer, s)) in self.layers.iter_mut().zip(subjects.iter()).enumerate() {
            let projected = project_corners(s.corners(), &projector);
            layer.predicted = Predicted::default();
            let Some((points, nearest)) = projected else {
                // Nothing to fit; the renderer clips the geometry, if it is in view at all.
                let b = s.bounds();
                layer.mode = if frustum.sees(b.center, b.radius) {
                    Mode::Geometry(Why::Behind)
                } else {
                    Mode::Culled
                };
                continue;
            };
            let rect = bounds(&points);
            let visible = overlaps(rect, view) && width > 0 && height > 0;
            layer.mode = Mode::Culled;
            (layer.screen, layer.nearest) = (points, nearest);
            if !overlaps(rect, grown) || width == 0 || height == 0 {
                continue;
            }
            layer.predicted = predict(layer, s.version(), clip(rect, view), &cfg);
            if visible {
                layer.mode = match layer.image {
                    Some(_) => Mode::Image,
                    None => Mode::Geometry(Why::NoImage),
                };
            }
            if layer.predicted.ratio >= 1.0 {
                self.scheduler.push(visible, layer.predicted.ratio, i);
            }
        }
        let mut report = Report::default();
        let budget = self.scheduler.rank(&cfg.budget);
        self.jobs.clear();
        for k in 0..self.scheduler.ranked().len() {
            let c = self.scheduler.ranked()[k];
            let job = (self.jobs.len() < budget && c.index < subjects.len())
                .then(|| job(c.index, &self.layers[c.index].screen, grown, &cfg))
                .flatten();
            match job {
                Some(job) => self.jobs.push(job),
                None => report.stale += c.visible as usize,
            }
        }
        let start = Instant::now();
        let (texels, triangles) = self.refresh(subjects, camera, (width, height), lighting);
        self.scheduler.measured(self.jobs.len(), start.elapsed());
        report.refreshes = self.jobs.len();
        report.capture_texels = texels;
        report.capture_triangles = triangles;
        let mut px_sum = 0.0;
        let unprojector = Unprojector::new(camera, width, height);
        for (layer, s) in self.layers.iter_mut().zip(subjects.iter_mut()) {
            if layer.mode == Mode::Image && layer.predicted.ratio > cfg.fallback_ratio {
                layer.mode = Mode::Geometry(Why::Stale);
                report.stale_fallbacks += 1;
            }
            match layer.mode {
                Mode::Image => {
                    report.images += 1;
                    report.max_px = report.max_px.max(layer.predicted.pixels);
                    report.over_tolerance += (layer.predicted.ratio > 1.0) as usize;
                    px_sum += layer.predicted.pixels;
                    build_quad(layer, &unprojector, camera.near_far().0);
                }
                Mode::Geometry(_) => {
                    report.geometry += 1;
                    s.prepare(camera, height);
                }
                Mode::Culled => report.culled += 1,
            }
        }
        report.mean_px = px_sum / report.images.max(1) as f32;
        report
    }

    /// Renders the frame's refreshes (`self.jobs`) side by side and takes their images into
    /// their layers; the texels and triangles rendered.
    fn refresh<S: Subject + Send>(
        &mut self,
        subjects: &mut [S],
        camera: &Camera,
        size: (u32, u32),
        lighting: &Lighting,
    ) -> (u64, u64) {
        self.render_jobs(subjects, camera, size, lighting);
        let (mut texels, mut triangles) = (0, 0);
        for (k, job) in self.jobs.iter().enumerate() {
            let (layer, w) = (&mut self.layers[job.i], &mut self.workers[k]);
            texels += job.width as u64 * job.height as u64;
            triangles += w.triangles;
            finish(layer, w, job, subjects[job.i].version());
        }
        (texels, triangles)
    }

    /// Renders the frame's refreshes side by side, one worker each (each writes only its
    /// own target, so the images do not depend on the thread count).
    fn render_jobs<S: Subject + Send>(
        &mut self,
        subjects: &mut [S],
        camera: &Camera,
        (width, height): (u32, u32),
        lighting: &Lighting,
    ) {
        let (jobs, workers) = (&mut self.jobs, &mut self.workers);
        refresh_side_by_side(
            jobs,
            |j| j.i,
            subjects,
            workers,
            |job, subject, w| {
                let crop = camera.crop(job.min, job.max, width, height);
                let size = (job.width, job.height);
                w.triangles = w
                    .refresher
                    .render(subject, &crop, lighting, size)
                    .triangles_set_up;
                w.gradient = plan::gradient(w.refresher.target(), &mut w.rows);
            },
        );
    }

    /// Appends this frame's draws: warped images as quads, the rest as their subjects'
    /// geometry.
    pub fn draws<'a, S: Subject>(&'a self, subjects: &'a [S], out: &mut Vec<Draw<'a>>) {
        for (layer, s) in self.layers.iter().zip(subjects) {
            match layer.mode {
                Mode::Image => out.push(Draw {
                    mesh: &layer.quad,
                    material: &layer.material,
                    transform: Mat4::IDENTITY,
                }),
                Mode::Geometry(_) => s.draws(out),
                Mode::Culled => {}
            }
        }
    }
}

/// Where `s`'s characteristic points land through `projector` (a camera's image), and
/// the nearest one's distance along the view direction; `None` when one is at or behind
/// the near plane (no warp will do).
pub(crate) fn project_corners(
    corners: [Vec3; 8],
    projector: &Projector,
) -> Option<([Vec2; 8], f32)> {
    let mut points = [Vec2::ZERO; 8];
    let mut nearest = f32::INFINITY;
    for (p, c) in points.iter_mut().zip(corners) {
        let (px, z) = projector.project(c)?;
        (*p, nearest) = (px, nearest.min(z));
    }
    Some((points, nearest))
}

#[cfg(test)]
mod tests;
