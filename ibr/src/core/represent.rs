//! The per-object face of the technique interface: what the planner asks of every
//! representation of an object (its predicted error and cost from this view, what a rebuild
//! would cost and give, the memory it holds), and geometry, the representation every other
//! one is measured against.

use super::cost::Work;
use crate::core::FrameView;
use crate::core::Rect;
use crate::core::RectProjector;
use crate::core::Subject;
use engine::{Camera, Draw, FrameStats, Rgba, Sphere, Target};
use glam::Vec3;

/// How one object is seen this frame: what every representation's prediction starts from.
#[derive(Clone, Copy, Debug)]
pub struct Sight<'a> {
    /// The frame's camera.
    pub camera: &'a Camera,
    /// The camera's eye, world space.
    pub eye: Vec3,
    /// The target's width, pixels.
    pub width: u32,
    /// The target's height, pixels.
    pub height: u32,
    /// Pixels per radian at the image centre.
    pub px_per_radian: f32,
    /// The object's bounding sphere, world space.
    pub bounds: Sphere,
    /// The eye's distance from the centre of `bounds`, world units.
    pub distance: f32,
    /// Pixels its bounding sphere covers on screen (the disc, at most the whole target):
    /// what its geometry's fragments cost, and the pixels its error is weighed over. An
    /// image prices its draw by its own quad instead (trimmed to what it holds).
    pub pixels: f32,
    /// Screen rectangles under the camera (its matrices taken once per frame, not per
    /// object): [`Sight::rect`].
    pub project: RectProjector,
    /// The subject's corners ([`Subject::corners`]) where the planner worked them out
    /// once for every representation that needs them; `None`: ask the subject
    /// ([`Sight::corners_of`]).
    pub corners: Option<[Vec3; 8]>,
}

impl<'a> Sight<'a> {
    /// How an object with bounding sphere `bounds` is seen by `camera` in a `width` x
    /// `height` target (the planner's own, for callers that estimate outside it).
    pub fn new(camera: &'a Camera, width: u32, height: u32, bounds: Sphere) -> Sight<'a> {
        let px_per_radian = crate::core::pixels_per_radian(camera, height);
        Sight {
            camera,
            eye: camera.eye(),
            width,
            height,
            px_per_radian,
            bounds,
            distance: 0.0,
            pixels: 0.0,
            project: RectProjector::new(camera, width, height),
            corners: None,
        }
        .at(bounds)
    }

    /// The same camera and target seeing an object with bounding sphere `bounds` (what
    /// depends on the camera alone is not worked out again).
    pub fn at(&self, bounds: Sphere) -> Sight<'a> {
        let (eye, px_per_radian) = (self.eye, self.px_per_radian);
        let (camera, width, height, project) = (self.camera, self.width, self.height, self.project);
        let distance = eye.distance(bounds.center);
        let frame_px = width as f32 * height as f32;
        let pixels = if distance > bounds.radius {
            let r_px = (bounds.radius / distance).asin() * px_per_radian;
            (std::f32::consts::PI * r_px * r_px).min(frame_px)
        } else {
            frame_px
        };
        Sight {
            camera,
            eye,
            width,
            height,
            px_per_radian,
            bounds,
            distance,
            pixels,
            project,
            corners: None,
        }
    }

    /// The same, with the subject's corners worked out ([`Sight::corners`]).
    pub fn with_corners(self, corners: [Vec3; 8]) -> Sight<'a> {
        Sight {
            corners: Some(corners),
            ..self
        }
    }

    /// `subject`'s corners: those worked out already, else its own.
    pub fn corners_of<S: Subject + ?Sized>(&self, subject: &S) -> [Vec3; 8] {
        self.corners.unwrap_or_else(|| subject.corners())
    }

    /// The object's screen rectangle ([`crate::core::screen_rect`]; `None` when wholly
    /// behind the eye).
    pub fn rect(&self) -> Option<Rect> {
        self.project.rect(self.bounds.center, self.bounds.radius)
    }

    /// Whether there is anything to predict: a target with pixels, a finite eye and a
    /// bounding sphere of finite centre and positive, finite radius.
    pub fn sane(&self) -> bool {
        let b = self.bounds;
        let sphere = b.radius > 0.0 && b.radius.is_finite() && b.center.is_finite();
        self.width > 0 && self.height > 0 && sphere && self.eye.is_finite()
    }

    /// Whether the eye is within `k` radii of the centre (images of the object break down).
    pub fn within(&self, k: f32) -> bool {
        self.distance.partial_cmp(&(self.bounds.radius * k)) != Some(std::cmp::Ordering::Greater)
    }
}

/// What one representation predicts for one object from this view, without rendering.
///
/// Errors are in the impostors' calibrated unit: the mean absolute 8-bit error (over RGB)
/// the representation makes over the object's screen rectangle against its geometry
/// (the runtime impostors' `Predicted::levels`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// Drawn now from what it holds; infinite when it holds nothing to draw.
    pub error: f32,
    /// Drawn right after a rebuild this frame; infinite when it cannot be rebuilt.
    pub rebuilt: f32,
    /// The work of drawing it this frame.
    pub draw: Work,
    /// The work of a rebuild (zero when it needs none).
    pub rebuild: Work,
    /// Bytes it holds for the object after a rebuild (images, samples).
    pub memory: usize,
}

impl Estimate {
    /// An image's estimate: one quad of `pixels` on screen to draw, and to rebuild, a
    /// capture of `triangles` into `texels` (width, height) held with its mipmaps.
    pub fn image(
        error: f32,
        rebuilt: f32,
        pixels: f32,
        triangles: usize,
        texels: (u32, u32),
    ) -> Estimate {
        let area = u64::from(texels.0) * u64::from(texels.1);
        Estimate {
            error: if error.is_nan() { f32::INFINITY } else { error },
            rebuilt,
            draw: Work {
                triangles: 2,
                image_pixels: pixels as u64,
                ..Work::default()
            },
            rebuild: Work {
                triangles: triangles as u64,
                pixels: area,
                captures: 1,
                ..Work::default()
            },
            memory: image_bytes(texels.0, texels.1),
        }
    }
}

/// Bytes of a `width` x `height` RGBA8 image with its mipmaps.
pub fn image_bytes(width: u32, height: u32) -> usize {
    width as usize * height as usize * 4 * 4 / 3
}

/// One way of drawing objects: geometry, or an image-based technique's per-object images.
/// The planner asks each for an [`Estimate`] per visible object per frame, chooses, asks
/// for the chosen rebuilds in one call (so they can run side by side), then for the draws.
/// Indices are the planner's object numbering; a representation keeps whatever per-object
/// state it needs.
pub trait Representation<S>: Send + Sync {
    /// A short name for readouts, CSV rows and charts.
    fn name(&self) -> &str;
    /// Its prediction for object `i` seen as `sight`; `None` when it cannot draw it from
    /// here at all (an image seen from inside its object).
    fn estimate(&self, i: usize, subject: &S, sight: &Sight<'_>) -> Option<Estimate>;
    /// Rebuilds its data for `objects` (ascending) from this view. Returns the work done.
    fn rebuild(&mut self, objects: &[usize], subjects: &mut [S], view: &FrameView<'_>) -> Work;
    /// Called once per frame after the rebuilds, with the objects (ascending, possibly
    /// none) this representation draws this frame, before any [`Representation::draw`]:
    /// for what drawing needs from this view (a layer's warp fitted to it). By default
    /// nothing.
    fn prepare(&mut self, _objects: &[usize], _subjects: &[S], _view: &FrameView<'_>) {}
    /// Appends the draws that show object `i` this frame (after `rebuild` and `prepare`).
    /// A representation drawn by image passes alone appends nothing here.
    fn draw<'a>(&'a self, i: usize, subject: &'a S, eye: Vec3, out: &mut Vec<Draw<'a>>);
    /// Runs its per-pixel image passes over the rendered frame for the objects it draws
    /// this frame (those [`Representation::prepare`] was given), writing colour and depth
    /// depth-tested against what is there. Returns their work. By default nothing.
    fn passes(&self, _view: &FrameView<'_>, _target: &mut Target) -> FrameStats {
        FrameStats::default()
    }
    /// Whether its draws are the subject's own (prepared for the camera first, as
    /// [`Subject::prepare`] asks).
    fn draws_subject(&self) -> bool {
        false
    }
    /// Frames a rebuild of its data lasts, for weighing a rebuild that only saves time
    /// (`None`: the planner's `super::Config::payback_frames`). A view-independent bake
    /// lasts until its object changes; an image taken from one eye only until the eye moves.
    fn payback_frames(&self) -> Option<f32> {
        None
    }
    /// A bound below the work of drawing any object this way (zero, the default: none
    /// known). The planner does not ask for an estimate where an exact option (error 0,
    /// the object's geometry) draws for no more than this bound: this representation
    /// could never be chosen there. An image pass costs at least its setup.
    fn least_draw(&self) -> Work {
        Work::default()
    }
    /// Frees what it holds for object `i` (long unused).
    fn release(&mut self, _i: usize) {}
    /// Bytes it holds over every object. The planner asks again only after it rebuilt or
    /// released: what it holds changes there alone.
    fn memory(&self) -> usize {
        0
    }
    /// Multiplies its images by `tint` from now on (`None`: drawn as they are), for a
    /// debug view that tells representations apart (`super::Planner::set_tints`). By
    /// default nothing (geometry is given a flat material by the planner instead).
    fn set_tint(&mut self, _tint: Option<Rgba>) {}
}

/// The object's own triangles: exact (error 0), costing its triangles and its fragments
/// ([`Subject::overdraw`] per pixel of its disc) every frame.
#[derive(Clone, Copy, Debug, Default)]
pub struct Geometry;

impl<S: Subject + Send + Sync> Representation<S> for Geometry {
    fn name(&self) -> &str {
        "geometry"
    }
    fn estimate(&self, _i: usize, subject: &S, sight: &Sight<'_>) -> Option<Estimate> {
        // Its fragments: over its box's screen rectangle when that is smaller than the
        // sphere's disc (a tall building's is).
        let footprint = sight.project.points_area(&sight.corners_of(subject));
        let pixels = footprint.map_or(sight.pixels, |a| a.min(sight.pixels));
        let draw = Work {
            triangles: subject.triangle_count() as u64,
            pixels: (pixels * subject.overdraw()) as u64,
            ..Work::default()
        };
        Some(Estimate {
            error: 0.0,
            rebuilt: 0.0,
            draw,
            rebuild: Work::default(),
            memory: 0,
        })
    }
    fn rebuild(&mut self, _: &[usize], _: &mut [S], _: &FrameView<'_>) -> Work {
        Work::default()
    }
    fn draws_subject(&self) -> bool {
        true
    }
    fn draw<'a>(&'a self, _i: usize, subject: &'a S, _eye: Vec3, out: &mut Vec<Draw<'a>>) {
        subject.draws(out);
    }
}

/// How far the eye may move, as a fraction of its distance from an object, before every
/// representation is asked for the object's prediction again (the planner's `Config::reask`):
/// a representation's promise must hold over that much movement.
pub const REASK_MOVE: f32 = 0.05;
