//! Image layers as one of the planner's representations: each object's screen-aligned
//! image, its error from this view predicted from the warp's geometric error and the
//! image's gradient (in the impostors' unit, levels), re-rendered when the planner asks,
//! and its warp fitted to the view once the frame's choices are made.

use super::frame::{bounds, build_quad, clip, fit_once, grow, job, predict, FitOf};
use super::{project_corners, LayerSet, Mode, Projector, Unprojector, Why};
use crate::core::image_material;
use crate::core::FrameView;
use crate::core::Subject;
use crate::core::PRIOR_GRADIENT;
use crate::core::{image_bytes, Estimate, Representation, Sight, Work};
use engine::{Draw, Rgba, Target};
use glam::{Mat4, Vec2, Vec3};
use rayon::prelude::*;
use std::sync::PoisonError;

/// The error a warped image makes with no geometric error at all, in units of its
/// gradient: resampling. A fresh image lies on the pixel grid (texel centres on pixel
/// centres) and is exact, but once the view moves the warp puts its texels between
/// pixels, and bilinear filtering blurs every edge by up to half a texel each way (the
/// mean of two neighbours differs from either by half their difference). Fitted with
/// [`DISPLACEMENT`]: see there.
pub(crate) const RESAMPLING: f32 = 0.55;

/// Texels of error per pixel of the warp's geometric error. The geometric error is the
/// largest over the box's corners; the surfaces lie inside the box, so the mean
/// displacement over the layer is at most that (up to 1 texel per pixel, if every surface
/// were at a worst corner), and an edge's error stops growing once it has moved past its
/// neighbour. Fitted with [`RESAMPLING`] by
/// `plan::by_technique::layers::predicted_error_bounds_the_measured_on_the_calibration_run`: twelve layers
/// (tori, boxes, checkered cards; 320 x 192), each drawn alone from 11 views along five
/// paths away from where it was rendered (slide, rise, orbit, dolly, turn; up to 5.1 pixels
/// and 0.46 octaves), 659 images. The pair with the least mean prediction that keeps 95%
/// of their measured errors (over the object's rectangle and over the layer's own, the
/// larger) at or below it is 0.09 and 0.50; rounded up (a variant of the scene with three
/// cards facing away, nine layers, needed 0.12 and 0.54), these hold for 98.5% of them
/// (99.8% over the object's rectangle).
pub(crate) const DISPLACEMENT: f32 = 0.12;

/// The predicted image error of a layer whose image has `gradient` levels per texel and
/// `texels_per_px` texels per screen pixel, warped with a geometric error of `pixels`:
/// mean absolute 8-bit error over its screen rectangle.
pub(crate) fn layer_error(gradient: f32, texels_per_px: f32, pixels: f32) -> f32 {
    gradient * texels_per_px * (RESAMPLING + DISPLACEMENT * pixels)
}

impl<S: Subject + Send + Sync> Representation<S> for LayerSet {
    fn name(&self) -> &str {
        "layers"
    }

    /// `None` with a characteristic point at or behind the near plane (the layer set draws
    /// geometry there). An image whose subject changed, that lacks part of the layer now on
    /// screen (cut at the view's margin), or whose stretch has drifted past
    /// [`super::Config::octaves`] has infinite error.
    fn estimate(&self, i: usize, subject: &S, sight: &Sight<'_>) -> Option<Estimate> {
        let layer = self.layers.get(i)?;
        let cfg = &self.config;
        let (w, h) = (sight.width, sight.height);
        if w == 0 || h == 0 {
            return None;
        }
        let (points, _) = project_corners(
            sight.corners_of(subject),
            &Projector::new(sight.camera, w, h),
        )?;
        let view = (Vec2::ZERO, Vec2::new(w as f32, h as f32));
        let fresh = job(i, &points, grow(view, cfg.margin), cfg);
        // What a draw shades: the warped image's quad, about the box's screen rectangle
        // within the view.
        let (lo, hi) = clip(bounds(&points), view);
        let pixels = (hi - lo).max(Vec2::ZERO).element_product();
        let (error, gradient) = match &layer.image {
            Some(image) => {
                let version = subject.version();
                let on_screen = clip(bounds(&points), view);
                let mut last = layer.fitted.lock().unwrap_or_else(PoisonError::into_inner);
                let of = FitOf {
                    image: *image,
                    screen: points,
                    version,
                    on_screen,
                    cfg: *cfg,
                };
                let (p, _) = fit_once(&mut last, of);
                let valid = version == image.version
                    && p.covered
                    && p.octaves <= cfg.octaves
                    && p.pixels.is_finite();
                let error = if valid {
                    layer_error(image.gradient, 1.0 / image.scale.max(1e-6), p.pixels)
                } else {
                    f32::INFINITY
                };
                (error, image.gradient)
            }
            None => (f32::INFINITY, PRIOR_GRADIENT),
        };
        let (rebuilt, texels) = match fresh {
            Some(j) => {
                let texels_per_px = j.width as f32 / (j.max.x - j.min.x).max(1.0);
                let error = layer_error(gradient, texels_per_px, 0.0);
                (error, (j.width, j.height))
            }
            None => (f32::INFINITY, (0, 0)),
        };
        let triangles = subject.triangle_count();
        Some(Estimate::image(error, rebuilt, pixels, triangles, texels))
    }

    /// Re-renders the objects' images for this view, side by side (as
    /// [`LayerSet::update`] does its own refreshes).
    fn rebuild(&mut self, objects: &[usize], subjects: &mut [S], view: &FrameView<'_>) -> Work {
        let cfg = self.config;
        let (w, h) = (view.width, view.height);
        let grown = grow((Vec2::ZERO, Vec2::new(w as f32, h as f32)), cfg.margin);
        let projector = Projector::new(view.camera, w, h);
        self.jobs.clear();
        for &i in objects {
            let (Some(s), Some(layer)) = (subjects.get(i), self.layers.get_mut(i)) else {
                continue;
            };
            let Some((points, nearest)) = project_corners(s.corners(), &projector) else {
                continue;
            };
            (layer.screen, layer.nearest) = (points, nearest);
            self.jobs.extend(job(i, &points, grown, &cfg));
        }
        let (texels, triangles) = self.refresh(subjects, view.camera, (w, h), view.lighting);
        Work {
            triangles,
            pixels: texels,
            captures: self.jobs.len() as u64,
            ..Work::default()
        }
    }

    /// Fits each drawn layer's warp to this view and builds its quad; the others are not
    /// drawn by the planner this frame ([`Mode::Culled`]).
    fn prepare(&mut self, objects: &[usize], subjects: &[S], view: &FrameView<'_>) {
        let cfg = self.config;
        let (w, h) = (view.width, view.height);
        let on_view = (Vec2::ZERO, Vec2::new(w as f32, h as f32));
        let (projector, unprojector) = (
            Projector::new(view.camera, w, h),
            Unprojector::new(view.camera, w, h),
        );
        let near = view.camera.near_far().0;
        // Each layer on its own (side by side: the same at any thread count).
        let layers = self.layers.par_iter_mut().enumerate();
        layers.for_each(|(i, layer)| {
            layer.mode = Mode::Culled;
            let Some(s) = subjects
                .get(i)
                .filter(|_| objects.binary_search(&i).is_ok())
            else {
                return;
            };
            let Some((points, nearest)) = project_corners(s.corners(), &projector) else {
                layer.mode = Mode::Geometry(Why::Behind);
                return;
            };
            (layer.screen, layer.nearest) = (points, nearest);
            layer.predicted = predict(layer, s.version(), clip(bounds(&points), on_view), &cfg);
            layer.quad.clear();
            if layer.image.is_some() {
                build_quad(layer, &unprojector, near);
            }
            layer.mode = if layer.quad.indices.is_empty() {
                Mode::Geometry(Why::NoImage)
            } else {
                Mode::Image
            };
        });
    }

    /// The warped image's quad; the subject's geometry if the layer has none to draw (the
    /// planner chose it with nothing better: its error was predicted infinite).
    fn draw<'a>(&'a self, i: usize, subject: &'a S, _eye: Vec3, out: &mut Vec<Draw<'a>>) {
        match self.layers.get(i) {
            Some(layer) if layer.mode == Mode::Image => out.push(Draw {
                mesh: &layer.quad,
                material: &layer.material,
                transform: Mat4::IDENTITY,
            }),
            _ => subject.draws(out),
        }
    }

    fn release(&mut self, i: usize) {
        if let Some(layer) = self.layers.get_mut(i) {
            layer.image = None;
            layer.material = image_material(1, 1, "layer");
            layer.material.base_color = self.tint.unwrap_or(Rgba::WHITE);
            layer.quad.clear();
            layer.mode = Mode::Culled;
        }
    }

    /// Every layer's material takes `tint` (white without).
    fn set_tint(&mut self, tint: Option<Rgba>) {
        self.tint = tint;
        for layer in &mut self.layers {
            layer.material.base_color = tint.unwrap_or(Rgba::WHITE);
        }
    }

    fn memory(&self) -> usize {
        let images = self.layers.iter().filter_map(|l| l.image.as_ref());
        images.map(|im| image_bytes(im.width, im.height)).sum()
    }
}

/// Two rows of an image's stored pixels and one of its depths, reused by [`gradient`].
#[derive(Debug, Default)]
pub(super) struct Rows {
    px: [Vec<u32>; 2],
    depth: Vec<f32>,
}

/// The mean absolute difference between horizontally and vertically neighbouring texels of
/// `t`, over RGB of the stored 8-bit values (premultiplied, so a layer's silhouette against
/// its empty texels counts): levels per texel, as the impostors measure theirs.
pub(super) fn gradient(t: &Target, rows: &mut Rows) -> f32 {
    let (w, h) = (t.width() as usize, t.height());
    let diff = |p: u32, q: u32| {
        let (p, q) = (p.to_le_bytes(), q.to_le_bytes());
        (0..3).map(|k| u64::from(p[k].abs_diff(q[k]))).sum::<u64>()
    };
    let (mut sum, mut n) = (0u64, 0u64);
    let [above, below] = &mut rows.px;
    if h > 0 {
        t.read_row(0, above, &mut rows.depth);
    }
    for y in 0..h {
        let next = y + 1 < h;
        if next {
            t.read_row(y + 1, below, &mut rows.depth);
        }
        for x in 0..w {
            if x + 1 < w {
                sum += diff(above[x], above[x + 1]);
                n += 3;
            }
            if next {
                sum += diff(above[x], below[x]);
                n += 3;
            }
        }
        std::mem::swap(above, below);
    }
    sum as f32 / n.max(1) as f32
}
