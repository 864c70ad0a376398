//! Light fields as one of the planner's representations: each object baked once into six
//! light slabs on a cube around its bounding sphere ([`Slab::cube`], side by side on the
//! pool when the planner asks), its error from this view predicted from what breaks a
//! light field (the camera grid's spacing against the object's depth off the focal plane,
//! the focal plane's texel density against the screen, each times a gradient measured from
//! the baked images), and rendered each frame into the screen rectangle the chosen slab's
//! focal plane covers, then composited by a depth-tested image pass.
//!
//! **Prediction** ([`lightfield_error`]): two terms, each an image's neighbour difference
//! times a displacement, as the octahedral impostors' model is.
//! - *Texels*: the rays are looked up between the `st` samples and resampled onto the
//!   screen, blurring every edge by a fraction of a texel against the sharp geometry;
//!   minified, every pixel sees `texels_per_px` texels of differences (magnified, the
//!   edges are sparser by as much as they spread: about a texel's worth).
//! - *Ghosting*: neighbouring cameras of the `uv` grid, `spacing` apart and `gap` behind
//!   the focal plane, see a surface `z` off the focal plane at places on it `spacing z /
//!   gap` apart: blended, its copies ghost (blur) by that much; depth correction moves
//!   them together where the stored depths hold, and occlusions the cameras do not share
//!   leave the rest. In texels of the focal plane for a surface one radius off it
//!   ([`view_terms`]), times the depth-weighted gradient (differences weighted by their
//!   surfaces' distance from the focal plane, in radii).
//!
//! No slab sees the whole sphere from an eye within it or near it off the cube's axes (18
//! of the calibration run's 640 views, from 3 to 24 radii): there the set gives no
//! estimate, its failure region. A bake whose
//! subject changed ([`Subject::version`]) or moved has infinite error; one never made is
//! predicted from the mean gradients of the set's bakes so far.
//!
//! **Cost**: drawing casts a ray for each pixel of the focal plane's screen rectangle
//! within the sphere's (no ray outside the sphere's meets the object, so the render is
//! cropped to it), counted as reading [`taps`] samples each ([`Work::samples`]: a bound,
//! as a ray that meets only empty samples reads fewer; about a third of it for the
//! calibration subjects seen from near), and writes the object's pixels; a bake is
//! `6 grid^2` captures of the subject's triangles of `st^2` pixels; memory is the slabs'
//! samples and depths ([`LightField::bytes`]; the frame's image buffers aside).

use super::object::{choose_slab, drawn_rect, Composite};
use super::{Interpolation, LightField, Lookup, Slab};
use crate::core::pick_mut;
use crate::core::prior;
use crate::core::screen_rect;
use crate::core::FrameView;
use crate::core::Rect;
use crate::core::Subject;
use crate::core::{Estimate, Representation, Sight, Work};
use engine::{Camera, Draw, FrameStats, Lighting, PixelRect, Rgba, Sphere, Target};
use glam::Vec3;
use rayon::prelude::*;

/// Levels of error per level of gradient per texel of blur (counted at one texel per pixel
/// at least). Fitted with [`GHOST`]: see there.
pub(crate) const TEXEL: f32 = 1.1;

/// Levels of error per level of depth-weighted gradient per texel a surface one radius
/// off the focal plane ghosts by. Fitted with [`TEXEL`] by
/// `plan::by_technique::lightfields::predicted_error_bounds_the_measured_on_the_calibration_run`, with the
/// set's lookup (bilinear between cameras, depth-corrected): four subjects (a tilted lit
/// torus, a lit box, a double-sided checkered card, a torus through a box), each baked
/// with four settings (4 x 4 cameras of 48 samples, 8 x 8 of 32, 12 x 12 of 24 and of 64:
/// ghosting 2.5 to 14.9 texels a radius), then drawn alone on a 320 x 192 target (0.9
/// radian field of view) along eight random directions each from 3, 5, 9, 14 and 24 radii
/// (0.08 to 1.76 texels per pixel): 640 views, 18 of them in the failure region, 622
/// measured over the object's screen rectangle against its geometry. The pair with the
/// least mean prediction that keeps 95% of the measured errors at or below it is 1.05 and
/// 0.07; rounded up to 1.1 and 0.1, the prediction bounds 600 of the 622 (96.5%), at
/// about twice the measured error on average (10.2 against 5.1 levels). Depth correction
/// leaves little of the ghosting (without it, bilinear between cameras, the fit is 0.43
/// and 1.02, measuring 11.6 levels on average where this lookup measures 4.2).
pub(crate) const GHOST: f32 = 0.1;

/// The frames a bake is weighed as lasting by default: a minute at 60 frames a second.
pub(crate) const PAYBACK: f32 = 3600.0;

/// The predicted mean absolute 8-bit error over the object's screen rectangle of a light
/// field with `gradient` and `depth_gradient` levels per texel, `texels_per_px` focal-plane
/// texels per screen pixel, whose cameras ghost a surface one radius off the focal plane
/// by `shift` texels.
pub(crate) fn lightfield_error(g: Gradients, texels_per_px: f32, shift: f32) -> f32 {
    TEXEL * g.gradient * texels_per_px.max(1.0) + GHOST * g.depth_gradient * shift
}

/// Texels of `slab`'s focal plane per screen pixel, and the texels by which its
/// neighbouring cameras see a surface one radius off the focal plane apart, for the object
/// seen as `sight`.
pub(crate) fn view_terms(slab: &Slab, sight: &Sight<'_>) -> (f32, f32) {
    let texel = slab.st.edge_a.length() / slab.ns.max(1) as f32;
    let pixel = sight.distance / sight.px_per_radian.max(1e-6);
    let spacing = slab.uv.edge_a.length() / slab.nu.max(1) as f32;
    let gap = (slab.st.origin - slab.uv.origin).dot(slab.forward());
    let shift = spacing * sight.bounds.radius / gap.max(1e-6) / texel.max(1e-9);
    (pixel / texel.max(1e-9), shift)
}

/// What a slab's images measure, in 8-bit levels per texel: the mean absolute difference
/// between horizontally and vertically neighbouring samples of the same image over RGB of
/// the stored values (premultiplied sRGB, so a silhouette against empty samples counts),
/// and the same with each difference weighted by how far its surface lies from the focal
/// plane (in radii, 0 to 1; the larger of the pair's, empty samples counting 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gradients {
    /// Mean absolute neighbour difference, 8-bit levels per texel (0 to 255).
    pub gradient: f32,
    /// The same, each difference weighted by its surface's distance from the focal
    /// plane in radii (0 to 1); at most `gradient`.
    pub depth_gradient: f32,
}

impl Gradients {
    /// Measures `field`'s images, surfaces' distances in units of `radius`.
    pub fn measure(field: &LightField, radius: f32) -> Gradients {
        let s = &field.slab;
        let gap = (s.st.origin - s.uv.origin).dot(s.forward());
        let r = radius.max(1e-6);
        let off = |u, v, x, y| {
            let d = field.depth_at(u, v, x, y);
            if d.is_finite() {
                ((d - gap).abs() / r).min(1.0)
            } else {
                0.0
            }
        };
        let diff = |p: u32, q: u32| {
            let (p, q) = (p.to_le_bytes(), q.to_le_bytes());
            (0..3).map(|k| u64::from(p[k].abs_diff(q[k]))).sum::<u64>()
        };
        let (mut sum, mut weighted, mut n) = (0u64, 0f64, 0u64);
        for (u, v) in (0..s.nv).flat_map(|v| (0..s.nu).map(move |u| (u, v))) {
            for y in 0..s.nt {
                for x in 0..s.ns {
                    let (c, z) = (field.sample(u, v, x, y), off(u, v, x, y));
                    let mut pair = |x2, y2| {
                        let d = diff(c, field.sample(u, v, x2, y2));
                        sum += d;
                        weighted += d as f64 * f64::from(z.max(off(u, v, x2, y2)));
                        n += 3;
                    };
                    if x + 1 < s.ns {
                        pair(x + 1, y);
                    }
                    if y + 1 < s.nt {
                        pair(x, y + 1);
                    }
                }
            }
        }
        let n = n.max(1);
        Gradients {
            gradient: sum as f32 / n as f32,
            depth_gradient: (weighted / n as f64) as f32,
        }
    }
}

/// An object's light field and what the set knows of it.
#[derive(Debug)]
struct Baked {
    /// Six slabs ([`Slab::cube`]), their gradients, and the subject's sphere and version
    /// when baked.
    fields: Vec<LightField>,
    gradients: Vec<Gradients>,
    bounds: Sphere,
    version: u64,
    /// This frame's image (buffers kept frame to frame).
    image: Composite,
}

impl Baked {
    fn bytes(&self) -> usize {
        self.fields.iter().map(LightField::bytes).sum()
    }
}

/// Light fields of the planner's objects, by object index: each baked with the set's
/// settings when the planner rebuilds it, kept until released or its subject changes
/// ([`Subject::version`]) or moves.
#[derive(Debug)]
pub struct LightFieldSet {
    /// Cameras per side of each slab's `uv` grid (`nu = nv`).
    pub grid: u32,
    /// Samples per side of each slab's `st` images (`ns = nt`, pixels).
    pub st: u32,
    /// How rays are looked up, from the next frame on.
    pub lookup: Lookup,
    /// Frames a bake is weighed as lasting ([`Representation::payback_frames`]; `PAYBACK`
    /// after [`LightFieldSet::new`]): it holds every direction outside its failure region,
    /// so it lasts until its object changes, unlike an image taken from one eye.
    pub payback_frames: f32,
    baked: Vec<Option<Baked>>,
    /// The objects drawn this frame (given to `prepare`).
    drawn: Vec<usize>,
    /// Sums of the bakes' gradients, depth-weighted gradients and their count: the prior
    /// of an object never baked.
    prior: (f64, f64, u32),
    tint: Option<Rgba>,
}

/// Samples each ray reads with `lookup` (cameras times taps in each).
pub(crate) fn taps(lookup: Lookup) -> u64 {
    match lookup.interpolation {
        Interpolation::Nearest => 1,
        Interpolation::BilinearUv => 4,
        Interpolation::Quadrilinear => 16,
    }
}

impl LightFieldSet {
    /// A set for `count` objects, none baked; `grid` x `grid` cameras of `st` x `st`
    /// samples per slab, looked up bilinearly between the cameras with depth correction.
    pub fn new(count: usize, grid: u32, st: u32) -> Self {
        LightFieldSet {
            grid,
            st,
            lookup: Lookup {
                interpolation: Interpolation::BilinearUv,
                depth_correction: true,
            },
            payback_frames: PAYBACK,
            baked: (0..count).map(|_| None).collect(),
            drawn: Vec::new(),
            prior: (0.0, 0.0, 0),
            tint: None,
        }
    }

    /// The sample counts of a new bake's slabs.
    fn counts(&self) -> [u32; 4] {
        let (g, s) = (self.grid.max(1), self.st.max(1));
        [g, g, s, s]
    }

    /// Object `i`'s slabs, if baked.
    pub fn fields(&self, i: usize) -> Option<&[LightField]> {
        self.baked.get(i)?.as_ref().map(|b| &b.fields[..])
    }

    /// What object `i`'s slabs measured, if baked.
    pub fn gradients(&self, i: usize) -> Option<&[Gradients]> {
        self.baked.get(i)?.as_ref().map(|b| &b.gradients[..])
    }

    /// The last frame's render of object `i`: the samples read and the pixels covered
    /// (`None` when it drew nothing).
    pub fn shown(&self, i: usize) -> Option<(super::LightFieldFrame, PixelRect)> {
        let b = self.baked.get(i)?.as_ref()?;
        Some((b.image.last, b.image.rect?))
    }

    /// The gradients expected of a bake never made: the mean of the set's bakes so far.
    fn prior(&self) -> Gradients {
        let (gradient, depth_gradient) = prior(self.prior);
        Gradients {
            gradient,
            depth_gradient,
        }
    }
}

/// Bytes a bake of six slabs of `counts` holds (samples and depths, 4 bytes each).
pub(crate) fn bake_bytes(counts: [u32; 4]) -> usize {
    6 * 8 * counts.iter().map(|&n| n as usize).product::<usize>()
}

/// Whether `b` is still where the bake was made, at its size.
fn same_place(b: Sphere, baked: Sphere) -> bool {
    let tol = 1e-3 * baked.radius.max(1e-6);
    b.center.distance(baked.center) <= tol && (b.radius - baked.radius).abs() <= tol
}

/// The pixels of a `width` x `height` view the sphere `b` can cover (the planner's screen
/// rectangle of it; empty when off screen).
fn sphere_rect(camera: &Camera, b: Sphere, width: u32, height: u32) -> PixelRect {
    pixel_rect(screen_rect(camera, b.center, b.radius, width, height).unwrap_or_default())
}

/// `r` as a [`PixelRect`].
fn pixel_rect(r: Rect) -> PixelRect {
    PixelRect {
        x0: r.x,
        y0: r.y,
        x1: r.x + r.width,
        y1: r.y + r.height,
    }
}

/// Bakes `subject` into six slabs of `counts` on a cube around its sphere; `None` for a
/// sphere that is not finite and positive.
fn bake(subject: &mut impl Subject, lighting: &Lighting, counts: [u32; 4]) -> Option<Baked> {
    let bounds = subject.bounds();
    let sane = bounds.radius > 0.0 && bounds.radius.is_finite() && bounds.center.is_finite();
    if !sane {
        return None;
    }
    let slabs = Slab::cube(bounds.center, bounds.radius, counts).ok()?;
    let mut fields = Vec::with_capacity(slabs.len());
    for slab in slabs {
        // View-dependent subjects (clouds) face each slab's middle camera.
        subject.prepare(&slab.camera(slab.nu / 2, slab.nv / 2), slab.nt);
        let mut draws = Vec::new();
        subject.draws(&mut draws);
        fields.push(LightField::capture(&draws, lighting, slab));
    }
    let gradients = fields
        .iter()
        .map(|f| Gradients::measure(f, bounds.radius))
        .collect();
    let camera = slabs[0].camera(0, 0);
    Some(Baked {
        fields,
        gradients,
        bounds,
        version: subject.version(),
        image: Composite::new(camera),
    })
}

impl<S: Subject + Send + Sync> Representation<S> for LightFieldSet {
    fn name(&self) -> &str {
        "light field"
    }

    /// One image pass.
    fn least_draw(&self) -> Work {
        Work {
            passes: 1,
            ..Work::default()
        }
    }

    fn payback_frames(&self) -> Option<f32> {
        Some(self.payback_frames)
    }

    /// `None` where no slab of a cube around the object sees all of it (inside or near
    /// it), on an empty target or a broken view. A bake whose subject changed or moved has
    /// infinite error; a fresh bake would err as the current one does (the bake does not
    /// depend on the view), or with the set's prior gradients for an object never baked.
    fn estimate(&self, i: usize, subject: &S, sight: &Sight<'_>) -> Option<Estimate> {
        let slot = self.baked.get(i)?;
        let b = sight.bounds;
        if !sight.sane() {
            return None;
        }
        let counts = self.counts();
        let fresh = Slab::cube(b.center, b.radius, counts).ok()?;
        let k = choose_slab(fresh.iter(), b, sight.eye)?;
        let predict = |slab: &Slab, g: Gradients| {
            let (tpp, shift) = view_terms(slab, sight);
            let e = lightfield_error(g, tpp, shift);
            if e.is_nan() {
                f32::INFINITY
            } else {
                e
            }
        };
        let (error, rebuilt) = match slot {
            Some(baked) => {
                let valid = subject.version() == baked.version && same_place(b, baked.bounds);
                let g = baked.gradients[k];
                let now = predict(&baked.fields[k].slab, g);
                let error = if valid { now } else { f32::INFINITY };
                (error, predict(&fresh[k], g))
            }
            None => (f32::INFINITY, predict(&fresh[k], self.prior())),
        };
        let clip = pixel_rect(sight.rect().unwrap_or_default());
        let rect = drawn_rect(
            &fresh[k],
            sight.camera,
            sight.width,
            sight.height,
            Some(clip),
        );
        let area = rect.map_or(0, |r| u64::from(r.x1 - r.x0) * u64::from(r.y1 - r.y0));
        let captures = 6 * u64::from(counts[0] * counts[1]);
        Some(Estimate {
            error,
            rebuilt,
            draw: Work {
                passes: 1,
                pass_pixels: area,
                samples: area * taps(self.lookup),
                ..Work::default()
            },
            rebuild: Work {
                triangles: captures * subject.triangle_count() as u64,
                pixels: captures * u64::from(counts[2] * counts[3]),
                captures,
                ..Work::default()
            },
            // What a bake with the set's settings holds (as much as this one, if made so).
            memory: bake_bytes(counts),
        })
    }

    /// Bakes the objects with the set's settings, side by side on the pool (each capture
    /// is the same at any thread count, so the bakes are too).
    fn rebuild(&mut self, objects: &[usize], subjects: &mut [S], view: &FrameView<'_>) -> Work {
        let counts = self.counts();
        let lighting = view.lighting;
        let n = self.baked.len().min(subjects.len());
        let wanted: Vec<usize> = objects.iter().copied().filter(|&i| i < n).collect();
        let chosen = pick_mut(subjects, wanted.iter().copied());
        let bakes: Vec<(usize, Option<Baked>)> = chosen
            .into_par_iter()
            .with_max_len(1)
            .map(|s| (s.triangle_count(), bake(s, lighting, counts)))
            .collect();
        let mut work = Work::default();
        for (&i, (triangles, baked)) in wanted.iter().zip(bakes) {
            let Some(baked) = baked else { continue };
            let captures = 6 * u64::from(counts[0] * counts[1]);
            work += Work {
                triangles: captures * triangles as u64,
                pixels: captures * u64::from(counts[2] * counts[3]),
                captures,
                ..Work::default()
            };
            for g in &baked.gradients {
                self.prior.0 += f64::from(g.gradient) / 6.0;
                self.prior.1 += f64::from(g.depth_gradient) / 6.0;
            }
            self.prior.2 += 1;
            self.baked[i] = Some(baked);
        }
        work
    }

    /// Renders each drawn object's light field for this view from the slab that sees it
    /// (tinted in the debug view), one object after another (each render is shared out
    /// over the pool by rows); the others draw nothing.
    fn prepare(&mut self, objects: &[usize], _subjects: &[S], view: &FrameView<'_>) {
        for &i in &self.drawn {
            if let Some(Some(b)) = self.baked.get_mut(i) {
                b.image.clear();
            }
        }
        self.drawn.clear();
        let eye = view.camera.eye();
        for &i in objects {
            let Some(Some(b)) = self.baked.get_mut(i) else {
                continue;
            };
            let Some(k) = choose_slab(b.fields.iter().map(|f| &f.slab), b.bounds, eye) else {
                continue;
            };
            let clip = sphere_rect(view.camera, b.bounds, view.width, view.height);
            b.image
                .render(&b.fields[k], view, self.lookup, Some(clip), None);
            if let Some(tint) = self.tint {
                b.image.tint(tint);
            }
            self.drawn.push(i);
        }
    }

    /// Nothing: a light field is drawn by its pass. The subject's geometry if it has no
    /// bake (the planner chose it with nothing better: its error was predicted infinite).
    fn draw<'a>(&'a self, i: usize, subject: &'a S, _eye: Vec3, out: &mut Vec<Draw<'a>>) {
        if let Some(None) = self.baked.get(i) {
            subject.draws(out);
        }
    }

    /// Composites this frame's images, depth-tested, in object order.
    fn passes(&self, _view: &FrameView<'_>, target: &mut Target) -> FrameStats {
        let mut stats = FrameStats::default();
        for &i in &self.drawn {
            if let Some(Some(b)) = self.baked.get(i) {
                stats += b.image.pass(target);
            }
        }
        stats
    }

    fn release(&mut self, i: usize) {
        if let Some(slot) = self.baked.get_mut(i) {
            *slot = None;
        }
    }

    /// Every image takes `tint` from the next `prepare` on (as they are without).
    fn set_tint(&mut self, tint: Option<Rgba>) {
        self.tint = tint;
    }

    fn memory(&self) -> usize {
        self.baked.iter().flatten().map(Baked::bytes).sum()
    }
}
