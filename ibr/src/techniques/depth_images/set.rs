//! Depth images and layered depth images (LDIs) as planner representations: per object a
//! reference captured from the eye of that object alone, warped each frame (the 3D warp:
//! splats, holes filled from the background side) into the object's screen rectangle and
//! written into the frame by a depth-tested image pass; its error predicted from the
//! parallax the eye's move makes ([`super::predict::parallax_px`]) and the image's
//! gradients, in the impostors' unit (levels).

mod composite;
mod reference;

use crate::core::refresh_side_by_side;
use crate::core::Capturer;
use crate::core::FrameView;
use crate::core::Rect;
use crate::core::Subject;
use crate::core::PRIOR_GRADIENT;
use crate::core::{needed_side, pixels_per_radian, screen_rect, Capture};
use crate::core::{Estimate, Representation, Sight, Work};
use crate::warp::holes::Filler;
use crate::warp::predict::parallax_px;
use crate::warp::{ImagePass, Prepared, WarpOptions, Warped, Warper};
use composite::{fill_inside, tint, Cropped};
use engine::{
    run_packed_pass, Camera, Draw, FrameStats, PassMode, PixelRect, Rgba, Sphere, Target,
};
use glam::{Vec2, Vec3};
use reference::capture;

/// Error per level of gradient (times texels per pixel) a fresh reference makes by
/// resampling alone: the warp takes the nearest sample (splats) where the geometry samples
/// each pixel's centre. Fitted with [`DISPLACEMENT`] by
/// `plan::by_technique::depth_images::predicted_error_bounds_the_measured_on_the_calibration_run`: the four
/// calibration subjects as depth images and as three-layer LDIs from 3 to 14 radii, each
/// seen alone from 12 views (its own eye, orbits of 2 to 75 degrees, rises of 10 and 25,
/// dollies in and out), 384 views. The pair with the least summed prediction that keeps 95%
/// of the measured errors at or below it is 0.33 and 0.13; rounded up, these hold for 370
/// of the 384 (96.4%).
pub(crate) const RESAMPLING: f32 = 0.35;
/// Error per pixel of parallax spread, per level of the reference's edge gradient (times
/// texels per pixel): the colour differences across its depth edges and silhouettes,
/// where disocclusions open and silhouettes turn. Fitted with [`RESAMPLING`].
pub(crate) const DISPLACEMENT: f32 = 0.14;

/// Bytes a prepared reference holds per pixel: disparity, its two slopes and the packed
/// colour ([`Prepared`]).
const BYTES_PER_SAMPLE: usize = 16;

/// The part of a never-captured reference's square that holds samples, before one is
/// taken: a sphere's disc fills about pi / 4 of it, the subject within rather less.
const COVERAGE: f32 = 0.5;

/// Settings of a [`DepthImageSet`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    /// Layers peeled per reference: 1 makes depth images, more LDIs.
    pub layers: usize,
    /// The reference's side, pixels (its screen diameter rounded up to a power of two,
    /// clamped).
    pub min_side: u32,
    /// The largest reference side, pixels (the clamp's upper end).
    pub max_side: u32,
    /// Within this many radii of the centre the object is not drawn from a reference.
    pub transition: f32,
    /// A reference coarser than the view needs by more than this many octaves is not
    /// drawn (its splats would tear).
    pub octaves: f32,
    /// How the references are warped into the view.
    pub options: WarpOptions,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            layers: 1,
            min_side: 16,
            max_side: 256,
            transition: 2.0,
            octaves: 1.0,
            options: WarpOptions::default(),
        }
    }
}

/// One object's reference, prepared for the warp, and what its predictions need.
#[derive(Debug)]
struct Reference {
    prepared: Prepared,
    eye: Vec3,
    bounds: Sphere,
    version: u64,
    side: u32,
    range: Option<(f32, f32)>,
    /// The front layer's gradients: levels per texel, and those across depth edges.
    gradient: f32,
    edge_gradient: f32,
}

impl Reference {
    fn bytes(&self) -> usize {
        let p = &self.prepared;
        p.color.len() * BYTES_PER_SAMPLE + p.first.len() * 4 + p.blocks.len() * 8
    }
}

/// Per object: its reference, and this frame's warped rectangle (buffer reused).
#[derive(Debug)]
struct Slot {
    reference: Option<Reference>,
    out: Warped,
    rect: Option<Rect>,
}

/// One capture of a frame's rebuilds.
#[derive(Clone, Copy, Debug)]
struct Job {
    i: usize,
    camera: Camera,
    side: u32,
    eye: Vec3,
    bounds: Sphere,
    version: u64,
}

/// A rebuild's capturer (reused) and what it made.
#[derive(Debug, Default)]
struct Worker {
    capturer: Capturer,
    made: Option<Reference>,
    captures: u64,
}

/// Depth images (or LDIs) of the planner's objects.
#[derive(Debug)]
pub struct DepthImageSet {
    /// The settings every reference of the set is made and drawn with.
    pub config: Config,
    slots: Vec<Slot>,
    jobs: Vec<Job>,
    workers: Vec<Worker>,
    warper: Warper,
    filler: Filler,
    /// Scratch: which pixels of a warped rectangle were holes before filling.
    holes: Vec<bool>,
    /// The objects prepared this frame.
    drawn: Vec<usize>,
    tint: Option<Rgba>,
}

fn empty_camera() -> Camera {
    Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 1.0, 1.0)
}

impl DepthImageSet {
    /// A set for `count` objects, holding nothing yet.
    pub fn new(config: Config, count: usize) -> Self {
        let slot = || Slot {
            reference: None,
            out: Warped::new(0, 0, empty_camera()),
            rect: None,
        };
        DepthImageSet {
            config,
            slots: (0..count).map(|_| slot()).collect(),
            jobs: Vec::new(),
            workers: Vec::new(),
            warper: Warper::new(),
            filler: Filler::default(),
            holes: Vec::new(),
            drawn: Vec::new(),
            tint: None,
        }
    }

    /// The rectangle object `i` was warped into this frame and its image, if drawn.
    pub fn warped(&self, i: usize) -> Option<(Rect, &Warped)> {
        let slot = self.slots.get(i)?;
        Some((slot.rect?, &slot.out))
    }

    /// The two terms of object `i`'s predicted error seen as `sight`, without their
    /// constants (`RESAMPLING`, `DISPLACEMENT`): texels per pixel times the gradient, and
    /// times the edge gradient and the parallax spread. `None` when it holds nothing.
    pub fn error_terms(&self, i: usize, sight: &Sight<'_>) -> Option<(f32, f32)> {
        let r = self.slots.get(i)?.reference.as_ref()?;
        let screen = screen_px(sight.bounds, sight.distance, sight.px_per_radian).max(1.0);
        Some(terms(r, sight, screen))
    }

    /// Whether object `i` holds a reference.
    pub fn holds(&self, i: usize) -> bool {
        self.slots.get(i).is_some_and(|s| s.reference.is_some())
    }
}

/// The predicted error of a reference with `gradient` and `edge_gradient` (levels per
/// texel) at `texels_per_px` texels per screen pixel, warped with a parallax spread of
/// `parallax` pixels.
pub(crate) fn warp_error(
    gradient: f32,
    edge_gradient: f32,
    texels_per_px: f32,
    parallax: f32,
) -> f32 {
    texels_per_px * (RESAMPLING * gradient + DISPLACEMENT * edge_gradient * parallax)
}

/// The error terms of `r` seen as `sight` where the object is `screen` pixels across: see
/// [`DepthImageSet::error_terms`].
fn terms(r: &Reference, sight: &Sight<'_>, screen: f32) -> (f32, f32) {
    let parallax = r.range.map_or(0.0, |range| {
        parallax_px(
            range,
            r.prepared.camera(),
            sight.camera,
            sight.width,
            sight.height,
        )
    });
    let scale = r.side as f32 / screen;
    (scale * r.gradient, scale * r.edge_gradient * parallax)
}

/// A sphere's screen diameter, pixels.
fn screen_px(b: Sphere, distance: f32, px_per_radian: f32) -> f32 {
    2.0 * (b.radius / distance).min(1.0).asin() * px_per_radian
}

impl<S: Subject + Send + Sync> Representation<S> for DepthImageSet {
    fn name(&self) -> &str {
        if self.config.layers > 1 {
            "LDIs"
        } else {
            "depth images"
        }
    }

    /// `None` where no reference could draw the object: an empty target, a non-finite eye,
    /// the eye within [`Config::transition`] radii, the object off the view. What it holds
    /// errs infinitely when the subject changed or moved, when the eye is past the plane
    /// through the object's centre facing the reference eye (the reference never saw that
    /// side), or the reference is too coarse by [`Config::octaves`]; a rebuild still can.
    fn estimate(&self, i: usize, subject: &S, sight: &Sight<'_>) -> Option<Estimate> {
        let slot = self.slots.get(i)?;
        let cfg = &self.config;
        let b = sight.bounds;
        if !sight.sane() || sight.within(cfg.transition) {
            return None;
        }
        let rect = sight.rect()?;
        let ppr = sight.px_per_radian;
        let needed = needed_side(b.radius, sight.distance, ppr, cfg.min_side, cfg.max_side);
        let screen = screen_px(b, sight.distance, ppr).max(1.0);
        let layers = cfg.layers.max(1) as u64;
        let area = u64::from(needed) * u64::from(needed);
        let (error, rebuilt, samples, memory) = match &slot.reference {
            Some(r) => {
                let to_eye = sight.eye - b.center;
                let behind = to_eye.dot(r.eye - r.bounds.center) <= 0.0;
                let moved = b.center.distance(r.bounds.center) > 1e-3 * r.bounds.radius
                    || (b.radius - r.bounds.radius).abs() > 1e-3 * r.bounds.radius;
                let coarse = (needed as f32 / r.side as f32).log2() > cfg.octaves;
                let error = if subject.version() != r.version || moved || behind || coarse {
                    f32::INFINITY
                } else {
                    let (a, b) = terms(r, sight, screen);
                    let e = RESAMPLING * a + DISPLACEMENT * b;
                    if e.is_nan() {
                        f32::INFINITY
                    } else {
                        e
                    }
                };
                let rebuilt = warp_error(r.gradient, 0.0, needed as f32 / screen, 0.0);
                let held = r.prepared.size();
                let ratio = area as f64 / (u64::from(held.0) * u64::from(held.1)).max(1) as f64;
                let memory = (r.bytes() as f64 * ratio) as usize;
                (error, rebuilt, r.prepared.samples(), memory)
            }
            None => {
                let rebuilt = warp_error(PRIOR_GRADIENT, 0.0, needed as f32 / screen, 0.0);
                let samples = (area as f32 * COVERAGE) as u64 * layers;
                let first = if layers > 1 { 4 } else { 0 };
                let memory = samples as usize * BYTES_PER_SAMPLE + area as usize * first;
                (f32::INFINITY, rebuilt, samples, memory)
            }
        };
        Some(Estimate {
            error,
            rebuilt,
            draw: Work {
                passes: 1,
                pass_pixels: u64::from(rect.width) * u64::from(rect.height),
                samples,
                ..Work::default()
            },
            rebuild: Work {
                triangles: subject.triangle_count() as u64 * layers,
                pixels: area * layers,
                captures: layers,
                ..Work::default()
            },
            memory,
        })
    }

    /// Captures each object alone from the eye (its capture camera, `Capture`), peeled
    /// into [`Config::layers`], side by side on the thread pool (one capturer each, so the
    /// references do not depend on the thread count), and prepares them for the warp.
    fn rebuild(&mut self, objects: &[usize], subjects: &mut [S], view: &FrameView<'_>) -> Work {
        let cfg = self.config;
        let eye = view.camera.eye();
        let ppr = pixels_per_radian(view.camera, view.height);
        self.jobs.clear();
        for &i in objects {
            let Some(s) = subjects.get(i).filter(|_| i < self.slots.len()) else {
                continue;
            };
            let b = s.bounds();
            let dist = eye.distance(b.center);
            let side = needed_side(b.radius, dist, ppr, cfg.min_side, cfg.max_side);
            let Some(c) = Capture::new(eye, b.center, b.radius, side, s.version()) else {
                continue;
            };
            self.jobs.push(Job {
                i,
                camera: c.camera(),
                side,
                eye,
                bounds: b,
                version: c.version,
            });
        }
        let lighting = view.lighting;
        refresh_side_by_side(
            &mut self.jobs,
            |j| j.i,
            subjects,
            &mut self.workers,
            |job, subject, w| {
                let (reference, captures) = capture(job, subject, &mut w.capturer, lighting, &cfg);
                w.made = Some(reference);
                w.captures = captures;
            },
        );
        let mut work = Work::default();
        for (k, job) in self.jobs.iter().enumerate() {
            let w = &mut self.workers[k];
            let Some(made) = w.made.take() else { continue };
            let triangles = subjects.get(job.i).map_or(0, |s| s.triangle_count()) as u64;
            work.triangles += triangles * w.captures;
            work.pixels += u64::from(job.side).pow(2) * w.captures;
            work.captures += w.captures;
            self.slots[job.i].reference = Some(made);
        }
        work
    }

    /// Warps each drawn object's reference into its screen rectangle (a crop of the
    /// frame's camera), fills the holes inside what the reference saw, and tints it.
    fn prepare(&mut self, objects: &[usize], subjects: &[S], view: &FrameView<'_>) {
        // Only the slots drawn last frame hold a rectangle (a world's slots are thousands).
        for &i in &self.drawn {
            if let Some(slot) = self.slots.get_mut(i) {
                slot.rect = None;
            }
        }
        self.drawn.clear();
        let (w, h) = (view.width, view.height);
        if w == 0 || h == 0 || !view.camera.eye().is_finite() {
            return;
        }
        let options = self.config.options;
        for &i in objects {
            let (Some(s), Some(slot)) = (subjects.get(i), self.slots.get_mut(i)) else {
                continue;
            };
            let Some(r) = &slot.reference else { continue };
            let b = s.bounds();
            let Some(rect) = screen_rect(view.camera, b.center, b.radius, w, h) else {
                continue;
            };
            if rect.width == 0 || rect.height == 0 {
                continue;
            }
            let lo = Vec2::new(rect.x as f32, rect.y as f32);
            let hi = lo + Vec2::new(rect.width as f32, rect.height as f32);
            let crop = view.camera.crop(lo, hi, w, h);
            self.warper.begin(&crop, rect.width, rect.height);
            self.warper.add_prepared(&r.prepared, &options);
            let out = self.warper.output_mut();
            fill_inside(out, &mut self.filler, &mut self.holes, r, options.edge);
            if let Some(t) = self.tint {
                tint(out, t);
            }
            // The slot's buffer goes to the warper for the next object: no copy.
            std::mem::swap(out, &mut slot.out);
            slot.rect = Some(rect);
            self.drawn.push(i);
        }
    }

    /// Drawn by its image passes alone.
    fn draw<'a>(&'a self, _i: usize, _subject: &'a S, _eye: Vec3, _out: &mut Vec<Draw<'a>>) {}

    /// Each warped rectangle into the target, depth-tested, writing colour ("over", for
    /// the silhouettes' partial coverage) and depth.
    fn passes(&self, _view: &FrameView<'_>, target: &mut Target) -> FrameStats {
        let mut stats = FrameStats::default();
        let mode = PassMode {
            blend: true,
            ..PassMode::default()
        };
        for &i in &self.drawn {
            let Some((rect, image)) = self.warped(i) else {
                continue;
            };
            let pass = Cropped {
                pass: ImagePass::new(image),
                x0: rect.x,
                y0: rect.y,
            };
            let pixels = PixelRect {
                x0: rect.x,
                y0: rect.y,
                x1: rect.x + rect.width,
                y1: rect.y + rect.height,
            };
            stats += run_packed_pass(target, pixels, &pass, mode);
        }
        stats
    }

    /// A depth image stays valid over more of the eye's motion than a flat impostor: the
    /// warp moves every sample by its own depth, so only disocclusions and turning
    /// silhouettes err, not the whole image's parallax. Per pixel of parallax its error
    /// constant (`DISPLACEMENT`, 0.14, over the edge gradient: only the differences at
    /// depth edges and silhouettes) is a quarter of the impostors' (0.57, over their whole
    /// depth-weighted gradient), and parallax grows linearly with the eye's move, so a
    /// reference lasts several times the impostors' 30 frames: 90, rounded down from that
    /// ratio (a reasoned figure, not a measured one).
    /// One image pass.
    fn least_draw(&self) -> Work {
        Work {
            passes: 1,
            ..Work::default()
        }
    }

    fn payback_frames(&self) -> Option<f32> {
        Some(90.0)
    }

    fn release(&mut self, i: usize) {
        if let Some(slot) = self.slots.get_mut(i) {
            slot.reference = None;
            slot.out = Warped::new(0, 0, empty_camera());
            slot.rect = None;
        }
        self.drawn.retain(|&k| k != i);
    }

    fn memory(&self) -> usize {
        let held = self.slots.iter().filter_map(|s| s.reference.as_ref());
        held.map(Reference::bytes).sum()
    }

    fn set_tint(&mut self, tint: Option<Rgba>) {
        self.tint = tint;
    }
}
