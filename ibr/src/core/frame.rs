//! The technique interface: one shape for every image-based technique's frame, and the one
//! frame loop ([`FrameLoop::render`]) that drives a list of them beside a scene's geometry.
//!
//! A frame, for techniques `t`:
//! 1. `t.prepare(view)`: update for this camera and time (rebuild meshes, refresh images);
//! 2. `t.draws(out)`: the draws it adds to the frame; the scene's and all techniques' draws
//!    are rendered together (opaque, then blended back to front);
//! 3. `t.passes(view, target)`: per-pixel image passes over the rendered frame;
//! 4. `t.observe(seen)`: read the finished frame (a lens flare measures its light's
//!    visibility in it), then `t.resolve(view, value)` takes what it observed, and
//!    `t.counters()` reports the frame's work;
//! 5. `t.overlay(out)`: draws rendered over the finished frame (a second render pass, run
//!    only when some technique gives draws), then `t.overlay_pass(view, target)`: image
//!    passes over it (the flare's sprites, blended over the pixels they reach).
//!
//! Each technique reports its work as [`Counters`], and names the geometry it stands for
//! ([`Technique::reference`]) so its error can be measured against a render of that geometry.
//! Techniques are passed as a slice of `&mut dyn Technique`, so their owners keep typed
//! access to them between frames.

use crate::core::{Capturer, View};
use engine::{
    Camera, Draw, FrameOptions, FrameStats, Lighting, Mesh, Renderer, StageTimes, Target,
};
use std::ops::AddAssign;
use std::time::{Duration, Instant};

/// What a technique prepares for: the camera, the target's size, the lighting and the time.
#[derive(Clone, Copy, Debug)]
pub struct FrameView<'a> {
    /// The frame's camera.
    pub camera: &'a Camera,
    /// Width of the target, pixels.
    pub width: u32,
    /// Height of the target, pixels.
    pub height: u32,
    /// The frame's lighting.
    pub lighting: &'a Lighting,
    /// Seconds since the start.
    pub time: f32,
    /// Seconds since the previous frame (0 on the first, or when time went backwards).
    pub dt: f32,
}

impl<'a> FrameView<'a> {
    /// A view at time zero (a still frame).
    pub fn still(camera: &'a Camera, width: u32, height: u32, lighting: &'a Lighting) -> Self {
        FrameView {
            camera,
            width,
            height,
            lighting,
            time: 0.0,
            dt: 0.0,
        }
    }

    /// The billboard view for this camera and height.
    pub fn billboard_view(&self) -> View {
        View::new(self.camera, self.height)
    }
}

/// Work a technique did for one frame (integer sums, so totals are the same whatever the
/// order they are added in).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// Quads (sprites, impostor images) it drew.
    pub quads: u64,
    /// Images it shows in place of geometry.
    pub images: u64,
    /// Images it re-rendered this frame.
    pub refreshes: u64,
    /// Subjects it drew as their own geometry (fallbacks).
    pub geometry: u64,
    /// Pixels it shaded in image passes.
    pub pixels: u64,
    /// Image samples it warped (3D warps).
    pub samples: u64,
    /// Holes left in its warped images before filling.
    pub holes: u64,
}

impl AddAssign for Counters {
    fn add_assign(&mut self, o: Counters) {
        self.quads += o.quads;
        self.images += o.images;
        self.refreshes += o.refreshes;
        self.geometry += o.geometry;
        self.pixels += o.pixels;
        self.samples += o.samples;
        self.holes += o.holes;
    }
}

/// The finished frame, as a technique observing it sees it.
#[derive(Debug)]
pub struct Observed<'s, 'a> {
    /// The finished frame (colour and depth after every pass).
    pub target: &'s Target,
    /// The camera it was rendered with.
    pub camera: &'s Camera,
    /// The lighting it was rendered with.
    pub lighting: &'s Lighting,
    /// Every draw the frame rendered.
    pub draws: &'s [Draw<'a>],
    /// Offscreen captures an observer may make (the loop's own, reused).
    pub capturer: &'s mut Capturer,
}

/// One image-based technique in a frame (see the module docs for the order of calls).
pub trait Technique {
    /// A short name for readouts, CSV rows and charts.
    fn name(&self) -> &str;
    /// Updates for this view and time.
    fn prepare(&mut self, view: &FrameView<'_>);
    /// Appends the draws it adds to the frame (after `prepare`).
    fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>);
    /// Runs its per-pixel image passes over the rendered frame.
    fn passes(&self, _view: &FrameView<'_>, _target: &mut Target) -> FrameStats {
        FrameStats::default()
    }
    /// Reads the finished frame; what it returns goes to `resolve`.
    fn observe(&self, _seen: &mut Observed<'_, '_>) -> Option<f32> {
        None
    }
    /// Takes what `observe` returned.
    fn resolve(&mut self, _view: &FrameView<'_>, _observed: Option<f32>) {}
    /// Appends draws rendered over the finished frame (no clear).
    fn overlay<'a>(&'a self, _out: &mut Vec<Draw<'a>>) {}
    /// Runs its image passes over the finished frame, after the overlay draws.
    fn overlay_pass(&self, _view: &FrameView<'_>, _target: &mut Target) -> FrameStats {
        FrameStats::default()
    }
    /// The work of the last frame.
    fn counters(&self) -> Counters {
        Counters::default()
    }
    /// Appends the geometry it stands for, to render the ground truth its error is measured
    /// against (nothing for techniques that are their own truth).
    fn reference<'a>(&'a self, _out: &mut Vec<Draw<'a>>) {}
}

/// An emptied draw list with another lifetime, keeping its allocation (draws of every
/// lifetime have one layout, so the in-place collect reuses the buffer).
pub fn recycle<'b>(mut v: Vec<Draw<'_>>) -> Vec<Draw<'b>> {
    v.clear();
    v.into_iter().map(|_| unreachable!("empty")).collect()
}

/// Where the last frame's time went, for benchmarks (tests check work counters instead:
/// wall-clock time is noise on a shared machine).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameTimes {
    /// In the techniques' `prepare` (impostor refreshes, billboard rebuilds).
    pub prepare: Duration,
    /// The renderer's main pass over the scene's and the techniques' draws.
    pub render: Duration,
    /// The techniques' image passes.
    pub passes: Duration,
    /// Observing and resolving (the flare's occlusion capture).
    pub observe: Duration,
    /// The overlay draws' pass and the overlay image passes (flare sprites).
    pub overlay: Duration,
    /// The whole frame, `prepare` included.
    pub total: Duration,
}

/// The frame loop's memory, kept between frames: draw lists, observations and the
/// observers' capturer.
///
/// # Example
///
/// One frame of a billboard batch (a technique) into a 32 x 32 target: a white,
/// screen-facing unit square 3 units in front of the eye, over the black clear colour.
///
/// ```
/// use engine::{Camera, FrameOptions, Lighting, Material, Renderer, Rgba, Target};
/// use glam::{Vec2, Vec3};
/// use ibr::billboard::{Billboard, BillboardBatch, Facing};
/// use ibr::technique::{FrameLoop, FrameView, Technique};
///
/// let mut trees = BillboardBatch::new(Material::unlit(Rgba::WHITE));
/// trees.push(Billboard::new(Vec3::ZERO, Facing::Screen, Vec2::ONE));
///
/// let camera = Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 0.8, 1.0);
/// let lighting = Lighting::default();
/// let view = FrameView::still(&camera, 32, 32, &lighting);
/// let (mut renderer, mut target) = (Renderer::new(), Target::new(32, 32));
/// let mut frames = FrameLoop::new();
/// let scene = std::iter::empty(); // the scene's own draws would go here
/// let techniques: &mut [&mut dyn Technique] = &mut [&mut trees];
/// frames.render(&mut renderer, scene, techniques, &view, &mut target, &FrameOptions::default());
///
/// assert_eq!(frames.counters[0].quads, 1);
/// // Packed premultiplied RGBA: the billboard at the centre, the clear colour in a corner.
/// assert_eq!(target.pixel(16, 16), Some(0xFFFF_FFFF));
/// assert_eq!(target.pixel(0, 0), Some(0xFF00_0000));
/// ```
#[derive(Debug, Default)]
pub struct FrameLoop {
    draws: Vec<Draw<'static>>,
    observed: Vec<Option<f32>>,
    capturer: Capturer,
    /// The techniques' counters of the last frame, in list order.
    pub counters: Vec<Counters>,
    /// The last frame's times.
    pub times: FrameTimes,
    /// The last frame's time in each technique's `prepare`, in list order.
    pub prepares: Vec<Duration>,
    /// The engine's stage times of the last frame's main pass.
    pub stages: StageTimes,
}

impl FrameLoop {
    /// A loop with no frame rendered yet; its draw lists and capturer are reused frame to
    /// frame.
    pub fn new() -> Self {
        Self::default()
    }

    /// Renders one frame of `scene` draws with `techniques` (see the module docs). Returns
    /// the renderer's counters over every pass.
    pub fn render<'s>(
        &mut self,
        renderer: &mut Renderer,
        scene: impl IntoIterator<Item = Draw<'s>>,
        techniques: &mut [&mut dyn Technique],
        view: &FrameView<'_>,
        target: &mut Target,
        opts: &FrameOptions,
    ) -> FrameStats {
        let start = Instant::now();
        self.prepares.clear();
        for t in techniques.iter_mut() {
            let t0 = Instant::now();
            t.prepare(view);
            self.prepares.push(t0.elapsed());
        }
        let prepared = Instant::now();
        let mut draws = recycle(std::mem::take(&mut self.draws));
        for d in scene {
            // One by one: each scene draw shortens to the techniques' borrow.
            draws.push(d);
        }
        for t in techniques.iter() {
            t.draws(&mut draws);
        }
        let mut stats = renderer.render(
            draws.iter().copied(),
            view.camera,
            view.lighting,
            target,
            opts,
        );
        let rendered = Instant::now();
        self.stages = renderer.stage_times();
        for t in techniques.iter() {
            stats += t.passes(view, target);
        }
        let passed = Instant::now();
        self.observed.clear();
        {
            let mut seen = Observed {
                target,
                camera: view.camera,
                lighting: view.lighting,
                draws: &draws,
                capturer: &mut self.capturer,
            };
            for t in techniques.iter() {
                self.observed.push(t.observe(&mut seen));
            }
        }
        let mut over = recycle(draws);
        self.counters.clear();
        for (t, o) in techniques.iter_mut().zip(&self.observed) {
            t.resolve(view, *o);
            self.counters.push(t.counters());
        }
        let observed = Instant::now();
        for t in techniques.iter() {
            t.overlay(&mut over);
        }
        if !over.is_empty() {
            let opts = FrameOptions {
                clear: None,
                ..*opts
            };
            stats += renderer.render(
                over.iter().copied(),
                view.camera,
                view.lighting,
                target,
                &opts,
            );
        }
        self.draws = recycle(over);
        for t in techniques.iter() {
            stats += t.overlay_pass(view, target);
        }
        let end = Instant::now();
        self.times = FrameTimes {
            prepare: prepared - start,
            render: rendered - prepared,
            passes: passed - rendered,
            observe: observed - passed,
            overlay: end - observed,
            total: end - start,
        };
        stats
    }
}

/// Several techniques of one kind as one (a forest of batches): each step forwards to every
/// member in order and counters add up. Members' observations are not forwarded.
impl<T: Technique> Technique for Vec<T> {
    fn name(&self) -> &str {
        self.first().map_or("none", |t| t.name())
    }
    fn prepare(&mut self, view: &FrameView<'_>) {
        self.iter_mut().for_each(|t| t.prepare(view));
    }
    fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        self.iter().for_each(|t| t.draws(out));
    }
    fn passes(&self, view: &FrameView<'_>, target: &mut Target) -> FrameStats {
        let mut stats = FrameStats::default();
        for t in self {
            stats += t.passes(view, target);
        }
        stats
    }
    fn overlay<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        self.iter().for_each(|t| t.overlay(out));
    }
    fn overlay_pass(&self, view: &FrameView<'_>, target: &mut Target) -> FrameStats {
        let mut stats = FrameStats::default();
        for t in self {
            stats += t.overlay_pass(view, target);
        }
        stats
    }
    fn counters(&self) -> Counters {
        let mut c = Counters::default();
        for t in self {
            c += t.counters();
        }
        c
    }
    fn reference<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        self.iter().for_each(|t| t.reference(out));
    }
}

/// The quads of a mesh of quads (four vertices each).
pub fn quads(mesh: &Mesh) -> u64 {
    (mesh.positions.len() / 4) as u64
}

#[cfg(test)]
mod tests;
