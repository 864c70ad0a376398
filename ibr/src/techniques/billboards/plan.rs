//! Billboards as one of the planner's representations: each object baked once from the
//! side (side by side on the pool when the planner asks) and drawn as an axial billboard,
//! one quad turning about +Y through its centre toward the eye (a tree's billboard),
//! pulled toward the eye so it depth-tests against its neighbours as the object would.
//!
//! **Prediction** ([`billboard_error`]), in the impostors' unit (levels), from what breaks
//! a billboard, each measured at bake time ([`Profile`]) or from the view:
//! - *View*: the billboard shows the baked view wherever the eye is. Its orthographic
//!   error from a grid of azimuths (the object's asymmetry about its axis: nothing for a
//!   cylinder, much for a box or a card) and elevations (the upright quad seen tilted,
//!   squashed, where the object shows its top: the classic failure from above) is measured
//!   by probe captures and interpolated at the view. Beyond the last probe elevation
//!   ([`MAX_ELEVATION`]) the error is infinite: the planner draws something else.
//! - *Perspective*: a near eye sees surfaces off the quad's plane displaced against it,
//!   by about `z sin(s) frame_px / 2` texels for a surface `z` radii off the plane and the
//!   object's angular radius `s` ([`PERSPECTIVE`] of that on average), times the image's
//!   depth-weighted gradient.
//! - *Resampling*: the image resampled onto the screen blurs its edges by a fraction of a
//!   texel where the geometry is drawn sharp: the gradient times the texels per pixel (at
//!   least one), as the octahedral impostors' model.
//!
//! A bake whose subject changed ([`Subject::version`]) or moved has infinite error; one
//! never made is predicted from the mean of the set's bakes so far ([`PRIOR`] before).
//!
//! **Cost**: drawing is one quad (2 triangles) over the object's pixels; a bake is one
//! capture of `px^2` pixels plus `AZIMUTHS x ELEVATIONS` probes of `probe_px^2`; memory is
//! the image with its mipmaps (packed and the sampler's linear copy) and the quad.

use super::bake::{bake, bake_bounds, bake_work, horizontal, Profile, ELEVATIONS};
use crate::core::pick_mut;
use crate::core::FrameView;
use crate::core::Subject;
use crate::core::{image_bytes, Estimate, Representation, Sight, Work};
use crate::core::{needed_side, pixels_per_radian, pull_near, IMAGE_DEPTH_ALPHA};
use crate::core::{push_quad, UvRect};
use engine::{BlendMode, Draw, Filter, Material, Mesh, Projection, Rgba, Sphere, Texture, Wrap};
use glam::{Mat4, Vec3};
use rayon::prelude::*;
use std::sync::Arc;

/// The largest elevation (degrees above or below the horizon) the set draws an object
/// from: its last probes'.
pub const MAX_ELEVATION: f32 = ELEVATIONS[ELEVATIONS.len() - 1];

/// Within this many radii of the centre the set does not draw an object.
pub(crate) const NEAR: f32 = 2.0;

/// The mean displacement of a near eye's view of the object against the quad, in units of
/// `sin(s) frame_px / 2` texels for a surface one radius off the quad's plane.
pub(crate) const PERSPECTIVE: f32 = 2.0 / 3.0;

/// Texels of error the resampling makes per texel of gradient. Fitted with [`VIEW`]:
/// see there.
pub(crate) const RESAMPLING: f32 = 0.5;

/// Levels of error per level of the measured view error plus the perspective term. Fitted
/// with [`RESAMPLING`] by `plan::by_technique::billboards::predicted_error_bounds_the_measured_on_the_calibration_run`:
/// five subjects (the planner tests' tilted lit torus, lit box, double-sided checkered
/// card and torus through a box, and an unlit cone tree), each baked at 64 pixels from +Z,
/// then drawn alone on a 320 x 192 target (0.9 radian field of view) along six random
/// azimuths at elevations of -20, 0, 12, 30, 45 and 65 degrees (each jittered by up to 3),
/// from 2.5, 4, 7, 12 and 24 radii (0.39 to 3.86 texels per pixel): 900 views, measured
/// over the object's screen rectangle against its geometry. The pair with the least mean
/// prediction that keeps 95% of the measured errors at or below it is 0.47 and 0.55 (the
/// measured view error is taken over the billboard's square, which the screen rectangle
/// holds with the background around the object's disc); rounded up to 0.5 and 0.6, the
/// prediction bounds 883 of the 900 views (98.1%), at 1.5 times the measured error on
/// average (36.6 against 24.0 levels). The box errs most against its prediction (164 of
/// its 180 views bounded), the cone tree least (2 to 6 levels at eye level).
pub(crate) const VIEW: f32 = 0.6;

/// The profile of an object never baked, before the set's first bake: a gradient of 4
/// levels per texel, a fifth of it depth-weighted, and a view error of 1 level at eye level
/// growing by 40 levels times the sine of the elevation. Optimistic on purpose (a
/// rotationally symmetric object's; the calibration run's subjects measure gradients of
/// 3.5 to 13 and eye-level view errors of 0 to 50): a bake is made once and then predicted
/// from what it measured, so an object is tried once; a pessimistic prior would never let
/// the planner try any.
pub(crate) const PRIOR: (f32, f32, f32, f32) = (4.0, 0.2, 1.0, 40.0);

/// The frames a bake is weighed as lasting by default: a minute at 60 frames a second.
pub(crate) const PAYBACK: f32 = 3600.0;

/// The smallest bake, pixels a side ([`BillboardSet::px`] the largest).
pub(crate) const MIN_PX: u32 = 16;

/// The predicted mean absolute 8-bit error over the object's screen rectangle of a
/// billboard with profile `p` seen from `azimuth` and `elevation` (radians) off its baked
/// view, at `texels_per_px` texels per screen pixel, surfaces one radius off its plane
/// displaced by `shift` texels.
pub(crate) fn billboard_error(
    p: &Profile,
    azimuth: f32,
    elevation: f32,
    texels_per_px: f32,
    shift: f32,
) -> f32 {
    let view = p.view_error(azimuth, elevation) + p.depth_gradient * shift;
    let e = RESAMPLING * p.gradient * texels_per_px.max(1.0) + VIEW * view;
    if e.is_nan() {
        f32::INFINITY
    } else {
        e
    }
}

/// The view of the object's centre from `sight`, against a billboard baked from the
/// horizontal `side`: azimuth and elevation (radians), texels per pixel and perspective
/// shift (texels) for a `px` image. `None` for a broken view or an eye at the centre.
#[cfg(test)]
pub(crate) fn view_terms(side: Vec3, px: u32, sight: &Sight<'_>) -> Option<(f32, f32, f32, f32)> {
    Some(Look::new(sight)?.terms(side, px))
}

/// What [`view_terms`] takes from the sight alone, worked out once for the several bakes
/// an estimate weighs.
#[derive(Clone, Copy, Debug)]
struct Look {
    /// Toward the viewer (unit), its elevation, the sphere's width on screen (pixels) and
    /// the sine of its angular radius.
    toward: Vec3,
    elevation: f32,
    screen: f32,
    sin_spread: f32,
}

impl Look {
    fn new(sight: &Sight<'_>) -> Option<Look> {
        // Toward a perspective eye, or against an orthographic camera's view direction.
        let v = match sight.camera.projection {
            Projection::Orthographic { .. } => -sight.camera.forward(),
            Projection::Perspective { .. } | Projection::Frustum { .. } => {
                sight.eye - sight.bounds.center
            }
        };
        let toward = v.try_normalize()?;
        let (r, dist) = (sight.bounds.radius, sight.distance.max(1e-6));
        let sin_spread = (r / dist).min(1.0);
        let spread = sin_spread.asin();
        Some(Look {
            toward,
            elevation: toward.y.clamp(-1.0, 1.0).asin(),
            screen: 2.0 * spread * sight.px_per_radian,
            sin_spread,
        })
    }

    /// [`view_terms`] for a `px` bake from `side`.
    fn terms(&self, side: Vec3, px: u32) -> (f32, f32, f32, f32) {
        let (v, right) = (self.toward, Vec3::Y.cross(side));
        let azimuth = v.dot(right).atan2(v.dot(side));
        let texels_per_px = px as f32 / self.screen.max(1e-3);
        let shift = PERSPECTIVE * self.sin_spread * px as f32 * 0.5;
        (azimuth, self.elevation, texels_per_px, shift)
    }
}

/// An object's bake and its quad.
#[derive(Clone, Debug)]
struct Baked {
    material: Material,
    mesh: Mesh,
    bounds: Sphere,
    version: u64,
    side: Vec3,
    px: u32,
    profile: Profile,
}

impl Baked {
    fn bytes(&self) -> usize {
        let texture = self
            .material
            .base_texture
            .as_deref()
            .map_or(0, texture_bytes);
        texture + QUAD_BYTES
    }
}

/// Bytes of a quad: four corners' position, uv and colour, six indices.
const QUAD_BYTES: usize = 4 * (12 + 8 + 16) + 6 * 4;

/// Bytes of a texture: 4 per packed texel and the sampler's 8-byte linear copy, over its
/// mip chain.
fn texture_bytes(t: &Texture) -> usize {
    t.levels().iter().map(|l| l.texels.len() * 12).sum()
}

/// Axial billboards of the planner's objects, by object index: each baked from
/// [`BillboardSet::side`] when the planner rebuilds it, kept until released or its subject
/// changes or moves.
#[derive(Clone, Debug)]
pub struct BillboardSet {
    /// Largest side of a new bake's image (each object's is twice its screen diameter when
    /// baked, from `MIN_PX` up to this), and the side of its probes, pixels.
    pub px: u32,
    /// Side of each probe image, pixels (32 after `new`).
    pub probe_px: u32,
    /// The horizontal direction a new bake is taken from (toward the viewer).
    pub side: Vec3,
    /// Within this many radii the set does not draw an object (`NEAR` after `new`).
    pub near: f32,
    /// Frames a bake is weighed as lasting (`PAYBACK` after `new`): it is made once
    /// for every view, so it lasts until its object changes, unlike an image taken from
    /// one eye.
    pub payback_frames: f32,
    baked: Vec<Option<Baked>>,
    /// Sum of the bakes' profiles and their count: the prior of an object never baked.
    sum: Option<(Profile, u32)>,
    /// [`BillboardSet::prior`], worked out when a bake is added (asked of every object
    /// never baked, every frame).
    prior: Profile,
    tint: Option<Rgba>,
}

impl BillboardSet {
    /// A set for `count` objects, none baked; images of up to `px` pixels from +Z, 32-pixel
    /// probes.
    pub fn new(count: usize, px: u32) -> Self {
        BillboardSet {
            px,
            probe_px: 32,
            side: Vec3::Z,
            near: NEAR,
            payback_frames: PAYBACK,
            baked: vec![None; count],
            sum: None,
            prior: Self::mean(None),
            tint: None,
        }
    }

    /// The side of a bake of an object with bounds `b` seen from `distance` at
    /// `px_per_radian`: twice its screen diameter (room to come twice as near) as a power
    /// of two, from [`MIN_PX`] to [`BillboardSet::px`], so distant objects hold small
    /// images.
    fn bake_px(&self, b: Sphere, distance: f32, px_per_radian: f32) -> u32 {
        let max = self.px.max(MIN_PX);
        needed_side(b.radius, distance, 2.0 * px_per_radian, MIN_PX, max)
    }

    /// What object `i`'s bake measured, if it has one.
    pub fn profile(&self, i: usize) -> Option<&Profile> {
        self.baked.get(i)?.as_ref().map(|b| &b.profile)
    }

    /// Object `i`'s image, if it has one.
    pub fn image(&self, i: usize) -> Option<&Texture> {
        self.baked
            .get(i)?
            .as_ref()?
            .material
            .base_texture
            .as_deref()
    }

    /// The profile expected of a bake never made: the mean of the set's bakes so far.
    pub fn prior(&self) -> Profile {
        self.prior
    }

    /// The mean of `sum`'s count of profiles; the fixed [`PRIOR`] without any.
    fn mean(sum: Option<(Profile, u32)>) -> Profile {
        let Some((sum, n)) = sum else {
            let (g, share, level, tilt) = PRIOR;
            return Profile::uniform(g, share, level, tilt);
        };
        let n = n.max(1) as f32;
        let mut p = sum;
        p.gradient /= n;
        p.depth_gradient /= n;
        p.cells_mut().for_each(|c| *c /= n);
        p
    }

    fn add_prior(&mut self, p: &Profile) {
        let (sum, n) = self.sum.get_or_insert((
            Profile {
                gradient: 0.0,
                depth_gradient: 0.0,
                view: Default::default(),
            },
            0,
        ));
        sum.gradient += p.gradient;
        sum.depth_gradient += p.depth_gradient;
        sum.cells_mut().zip(p.cells()).for_each(|(s, c)| *s += c);
        *n += 1;
        self.prior = Self::mean(self.sum);
    }
}

/// The material that draws a billboard's image: premultiplied, alpha-blended (writing
/// depth where more than half covered, [`IMAGE_DEPTH_ALPHA`]), unlit,
/// clamped, seen from either side, mipmapped (one image is seen at every distance).
fn material(image: Texture, tint: Rgba) -> Material {
    let mut m = Material::unlit(tint)
        .with_texture(Arc::new(image))
        .blended(BlendMode::Alpha)
        .double_sided(true);
    m.vertex_colors = false;
    m.blend_depth = Some(IMAGE_DEPTH_ALPHA);
    (m.sampler.wrap_u, m.sampler.wrap_v) = (Wrap::Clamp, Wrap::Clamp);
    m.sampler.filter = Filter::Trilinear;
    m.name = "billboard".into();
    m
}

/// The pixels the upright square of the object's sphere covers on screen: its disc's
/// square (4 / pi of it), at most the frame.
fn upright_pixels(sight: &Sight<'_>) -> f32 {
    let frame = sight.width as f32 * sight.height as f32;
    (sight.pixels * 4.0 / std::f32::consts::PI).min(frame)
}

/// Whether `b` is still where the bake was made, at its size.
fn same_place(b: Sphere, baked: Sphere) -> bool {
    let tol = 1e-3 * baked.radius.max(1e-6);
    b.center.distance(baked.center) <= tol && (b.radius - baked.radius).abs() <= tol
}

/// The corners of the upright quad of the sphere `b` turned toward `eye` about +Y
/// (bottom-left, bottom-right, top-right, top-left as seen); `None` for an eye on the
/// axis or a broken one.
fn upright(b: Sphere, eye: Vec3) -> Option<[Vec3; 4]> {
    let right = Vec3::Y.cross(eye - b.center).try_normalize()?;
    let (x, y) = (right * b.radius, Vec3::Y * b.radius);
    let c = b.center;
    Some([c - x - y, c + x - y, c + x + y, c - x + y])
}

impl<S: Subject + Send + Sync> Representation<S> for BillboardSet {
    fn name(&self) -> &str {
        "billboards"
    }

    fn payback_frames(&self) -> Option<f32> {
        Some(self.payback_frames)
    }

    /// `None` within [`BillboardSet::near`] radii, on an empty target or a broken view.
    /// A bake whose subject changed or moved has infinite error; a fresh bake would err
    /// as the current one does (it does not depend on the view), or as the set's prior
    /// says for an object never baked.
    fn estimate(&self, i: usize, subject: &S, sight: &Sight<'_>) -> Option<Estimate> {
        let slot = self.baked.get(i)?;
        let b = sight.bounds;
        if !sight.sane() || sight.within(self.near) {
            return None;
        }
        let look = Look::new(sight);
        let predict = |side: Vec3, px: u32, p: &Profile| {
            let (a, e, tpp, shift) = look?.terms(side, px);
            Some(billboard_error(p, a, e, tpp, shift))
        };
        let px = self.bake_px(b, sight.distance, sight.px_per_radian);
        let fresh = (horizontal(self.side), px);
        let (error, rebuilt, memory) = match slot {
            Some(baked) => {
                let valid = subject.version() == baked.version && same_place(b, baked.bounds);
                let now = predict(baked.side, baked.px, &baked.profile)?;
                let rebuilt = predict(fresh.0, fresh.1, &baked.profile)?;
                let error = if valid { now } else { f32::INFINITY };
                (error, rebuilt, baked.bytes())
            }
            None => {
                let rebuilt = predict(fresh.0, fresh.1, &self.prior)?;
                let memory = image_bytes(fresh.1, fresh.1) * 3 + QUAD_BYTES;
                (f32::INFINITY, rebuilt, memory)
            }
        };
        let (captures, pixels) = bake_work(self.px, self.probe_px);
        Some(Estimate {
            error,
            rebuilt,
            draw: Work {
                triangles: 2,
                // Its upright square about the disc, at most the frame.
                image_pixels: upright_pixels(sight) as u64,
                ..Work::default()
            },
            rebuild: Work {
                triangles: captures * subject.triangle_count() as u64,
                pixels,
                captures,
                ..Work::default()
            },
            memory,
        })
    }

    /// Bakes the objects from [`BillboardSet::side`], side by side on the pool (each bake
    /// with its own capturer, so the bakes do not depend on the thread count).
    fn rebuild(&mut self, objects: &[usize], subjects: &mut [S], view: &FrameView<'_>) -> Work {
        let (probe, lighting) = (self.probe_px, view.lighting);
        let side = horizontal(self.side);
        let n = self.baked.len().min(subjects.len());
        let wanted: Vec<usize> = objects.iter().copied().filter(|&i| i < n).collect();
        let (eye, ppr) = (
            view.camera.eye(),
            pixels_per_radian(view.camera, view.height),
        );
        let sizes: Vec<u32> = wanted
            .iter()
            .map(|&i| {
                let b = subjects[i].bounds();
                self.bake_px(b, eye.distance(b.center), ppr)
            })
            .collect();
        let chosen = pick_mut(subjects, wanted.iter().copied());
        let bakes: Vec<_> = chosen
            .into_par_iter()
            .zip(sizes.par_iter())
            .with_max_len(1)
            .map(|(s, &px)| (s.triangle_count(), px, bake(s, lighting, side, px, probe)))
            .collect();
        let mut work = Work::default();
        let tint = self.tint.unwrap_or(Rgba::WHITE);
        for (&i, (triangles, px, bake)) in wanted.iter().zip(bakes) {
            work += Work {
                triangles: bake.captures * triangles as u64,
                pixels: bake.pixels,
                captures: bake.captures,
                ..Work::default()
            };
            self.add_prior(&bake.profile);
            let bounds = bake_bounds(bake.bounds);
            // Reuse the old quad's memory; it faces the baked side until `prepare` turns it.
            let mut mesh = self.baked[i].take().map(|b| b.mesh).unwrap_or_default();
            mesh.clear();
            let q = upright(bounds, bounds.center + side).unwrap_or([bounds.center; 4]);
            push_quad(&mut mesh, q, UvRect::FULL, Rgba::WHITE, 1.0);
            self.baked[i] = Some(Baked {
                material: material(bake.image, tint),
                mesh,
                bounds,
                version: bake.version,
                side,
                px: px.max(4),
                profile: bake.profile,
            });
        }
        work
    }

    /// Turns each drawn object's quad toward the eye (an eye on its axis keeps the last).
    fn prepare(&mut self, objects: &[usize], _subjects: &[S], view: &FrameView<'_>) {
        let eye = view.camera.eye();
        for &i in objects {
            if let Some(Some(b)) = self.baked.get_mut(i) {
                if let Some(q) = upright(b.bounds, eye) {
                    b.mesh.positions.copy_from_slice(&q);
                }
            }
        }
    }

    /// The quad pulled toward the eye to the object's nearest corner (the same pixels,
    /// nearer in depth); the subject's geometry if it has no bake (the planner chose it
    /// with nothing better: its error was predicted infinite).
    fn draw<'a>(&'a self, i: usize, subject: &'a S, eye: Vec3, out: &mut Vec<Draw<'a>>) {
        match self.baked.get(i) {
            Some(Some(b)) => out.push(Draw {
                mesh: &b.mesh,
                material: &b.material,
                transform: if eye.is_finite() {
                    pull_near(subject, eye)
                } else {
                    Mat4::IDENTITY
                },
            }),
            _ => subject.draws(out),
        }
    }

    fn release(&mut self, i: usize) {
        if let Some(slot) = self.baked.get_mut(i) {
            *slot = None;
        }
    }

    /// Every bake's image takes `tint` (white without).
    fn set_tint(&mut self, tint: Option<Rgba>) {
        self.tint = tint;
        for b in self.baked.iter_mut().flatten() {
            b.material.base_color = tint.unwrap_or(Rgba::WHITE);
        }
    }

    fn memory(&self) -> usize {
        self.baked.iter().flatten().map(Baked::bytes).sum()
    }
}
