//! Baked octahedral impostors as one of the planner's representations: each object baked
//! once into an atlas of views (side by side on the pool when the planner asks), its
//! error from this view predicted from the angle to the blended frames and the texel
//! density against the atlas's measured gradients (in the impostors' unit, levels), and
//! its image recomposed for the view once the frame's choices are made.
//!
//! **Prediction** ([`octahedral_error`]): two terms, each an image's neighbour difference
//! times a displacement, as the runtime impostors' and the layers' models are.
//! - *Resampling*: the composed image is resampled twice (frames into the composed
//!   texture, that onto the screen), which blurs every edge by a fraction of a texel;
//!   the geometry is drawn sharp (and aliased) at screen resolution. Minified, the
//!   image's texels are denser than pixels, and every pixel sees `texels_per_px` texels
//!   of differences; magnified, a blurred edge spreads over more pixels, but the edges
//!   are sparser by as much, so the mean error stays at about the texel's.
//! - *Parallax*: each frame is reprojected onto its own plane through the centre and
//!   seen along the view direction, so a surface `z` radii off that plane is misplaced
//!   by about `z r sin a` for a frame `a` away (the blend shows the three frames'
//!   copies by weight: `a` is the weighted angle); a perspective eye also sees the
//!   object's rim along rays up to `asin(r / d)` off the view direction that the image
//!   was composed along, [`PERSPECTIVE`] of that on average. In texels of the image,
//!   `z sin a frame_px / 2`, times the depth-weighted gradient (differences weighted by
//!   their surface's distance from the frame's plane, as the runtime impostors weight
//!   theirs).
//!
//! A bake whose subject changed ([`Subject::version`]) or moved has infinite error; one
//! never made is predicted from the mean gradients of the set's bakes so far.
//!
//! **Cost**: drawing is one quad over the object's pixels, plus three bilinear taps per
//! texel of the composed image when the view changed since it was last composed; a bake
//! is `grid^2` captures of the subject's triangles, `grid^2 frame_px^2` pixels; memory is
//! [`OctahedralImpostor::bytes`].

use super::{
    cell_uv, decode, encode, select, Blend, Layout, OctahedralImpostor, MAX_ATLAS_SIDE, MAX_GRID,
    MIN_FRAME_PX, MIN_GRID,
};
use crate::core::pick_mut;
use crate::core::FrameView;
use crate::core::Subject;
use crate::core::{image_bytes, Estimate, Representation, Sight, Work};
use crate::core::{prior, BAKE_DISTANCE};
use engine::color::Encoder;
use engine::{Camera, Draw, Encoding, Projection, Rgba, Sphere};
use glam::Vec3;
use rayon::prelude::*;

/// Within this many radii of the centre the set does not draw an object (the planner
/// draws another representation): the composed image is an orthographic view, and a
/// near perspective eye sees the object's rim far off that view.
pub(crate) const NEAR: f32 = 2.0;

/// The mean angle of a perspective eye's rays through the object's disc off the ray to
/// its centre, in units of the disc's angular radius (2/3 for a uniform disc).
pub(crate) const PERSPECTIVE: f32 = 2.0 / 3.0;

/// Texels of error the two resamplings make, per texel of gradient (counted at one texel
/// per pixel at least: magnified, the mean error stays at about the texel's). Fitted with
/// [`DISPLACEMENT`]: see there.
pub(crate) const RESAMPLING: f32 = 0.6;

/// Texels of error per texel a surface one radius off the frames' planes is misplaced
/// by, per texel of depth-weighted gradient. Fitted with [`RESAMPLING`] by
/// `plan::by_technique::octahedral::predicted_error_bounds_the_measured_on_the_calibration_run`: four subjects
/// (a tilted lit torus, a lit box, a double-sided checkered card, a torus through a box),
/// each baked with four settings (8 x 8 views of 64 pixels and 6 x 6 of 32 over the
/// sphere and 6 x 6 of 48 over the upper hemisphere, blended from three frames; 8 x 8 of
/// 48 showing the nearest frame), then drawn alone on a 320 x 192 target (0.9 radian
/// field of view) along ten directions between the baked ones and four baked ones, each
/// from 2.5, 4, 7, 12 and 24 radii (0.20 to 3.86 texels per pixel, shifts up to 18.4
/// texels): 1120 views, measured over the object's screen rectangle against its geometry.
/// The pair with the least mean prediction that keeps 95% of the measured errors at or
/// below it is 0.56 and 0.57; rounded up to 0.6 and 0.6, the prediction bounds 1076 of
/// the 1120 (96.1%), at about twice the measured error on average (21.5 against 10.9
/// levels: the scatter between subjects, a box erring most for its gradient and the
/// checkered card least, is what the 95% bound pays for). Seen along a baked direction at
/// one texel a pixel, the same subjects err 1.9 levels on average (2.8 at most);
/// halfway between two of 8 x 8 views, 11.1.
pub(crate) const DISPLACEMENT: f32 = 0.6;

/// The predicted mean absolute 8-bit error over the object's screen rectangle of an image
/// with `gradient` and `depth_gradient` levels per texel, `texels_per_px` texels per screen
/// pixel, and a surface one radius off the frames' planes misplaced by `shift` texels.
pub(crate) fn octahedral_error(
    gradient: f32,
    depth_gradient: f32,
    texels_per_px: f32,
    shift: f32,
) -> f32 {
    RESAMPLING * gradient * texels_per_px.max(1.0) + DISPLACEMENT * depth_gradient * shift
}

/// What a bake's atlas measures, in 8-bit levels per texel: the mean absolute difference
/// between horizontally and vertically neighbouring texels of the same frame over RGB of
/// the stored values (premultiplied sRGB, so a silhouette against the empty texels
/// counts), and the same with each difference weighted by how far its surface lies from
/// the frame's plane through the centre (in radii, 0 to 1; the larger of the pair's,
/// empty texels counting 0). The runtime impostors and the layers measure their images'
/// the same way, from the target a capture leaves; a bake's frames are read from its
/// atlas instead.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gradients {
    pub gradient: f32,
    pub depth_gradient: f32,
}

impl Gradients {
    /// Measures `imp`'s atlas (see the type's docs).
    pub fn measure(imp: &OctahedralImpostor) -> Gradients {
        let atlas = imp.atlas();
        let (w, h) = atlas.size();
        let (cw, ch) = atlas.cell_size();
        let (w, cw, ch) = (w as usize, cw.max(1) as usize, ch.max(1) as usize);
        let r = imp.info().bounds.radius;
        let plane = BAKE_DISTANCE * r;
        let enc = Encoder::new(Encoding::Srgb);
        let row = |y: usize, px: &mut Vec<u32>, off: &mut Vec<f32>| {
            let span = y * w..(y + 1) * w;
            px.clear();
            px.extend(
                atlas.color[span.clone()]
                    .iter()
                    .map(|c| enc.pack(c.r, c.g, c.b, c.a)),
            );
            off.clear();
            off.extend(atlas.depth[span].iter().map(|&d| {
                if d.is_finite() {
                    ((d - plane).abs() / r).min(1.0)
                } else {
                    0.0
                }
            }));
        };
        let diff = |p: u32, q: u32| {
            let (p, q) = (p.to_le_bytes(), q.to_le_bytes());
            (0..3).map(|k| u64::from(p[k].abs_diff(q[k]))).sum::<u64>()
        };
        let (mut px, mut off) = ([Vec::new(), Vec::new()], [Vec::new(), Vec::new()]);
        let (mut sum, mut weighted, mut n) = (0u64, 0f64, 0u64);
        let h = h as usize;
        if h > 0 {
            let [px0, px1] = &mut px;
            let [off0, off1] = &mut off;
            row(0, px0, off0);
            for y in 0..h {
                // Pairs within one frame: not across a cell's last row or column.
                let below = y + 1 < h && (y + 1) % ch != 0;
                if y + 1 < h {
                    row(y + 1, px1, off1);
                }
                for x in 0..w {
                    if (x + 1) % cw != 0 {
                        let d = diff(px0[x], px0[x + 1]);
                        sum += d;
                        weighted += d as f64 * f64::from(off0[x].max(off0[x + 1]));
                        n += 3;
                    }
                    if below {
                        let d = diff(px0[x], px1[x]);
                        sum += d;
                        weighted += d as f64 * f64::from(off0[x].max(off1[x]));
                        n += 3;
                    }
                }
                std::mem::swap(px0, px1);
                std::mem::swap(off0, off1);
            }
        }
        let n = n.max(1);
        Gradients {
            gradient: sum as f32 / n as f32,
            depth_gradient: (weighted / n as f64) as f32,
        }
    }
}

/// An object's bake and what the set knows of it.
#[derive(Clone, Debug)]
struct Baked {
    imp: OctahedralImpostor,
    gradients: Gradients,
    /// The view direction (quantised as the impostor's recomposition key) its image was
    /// last composed for by [`Representation::prepare`].
    shown: Option<[i16; 3]>,
}

/// The frames a bake is weighed as lasting by default: a minute at 60 frames a second.
pub(crate) const PAYBACK: f32 = 3600.0;

/// Baked octahedral impostors of the planner's objects, by object index: each baked with
/// the set's settings when the planner rebuilds it, kept until released or its subject
/// changes ([`Subject::version`]) or moves.
#[derive(Clone, Debug)]
pub struct OctahedralSet {
    /// Views per side of a new bake's grid ([`OctahedralImpostor::bake`] clamps it).
    pub grid: u32,
    /// Frame side of a new bake, pixels (clamped likewise).
    pub frame_px: u32,
    /// Which directions a new bake holds.
    pub layout: Layout,
    /// How the frames are combined, from the next frame on.
    pub blend: Blend,
    /// Within this many radii the set does not draw an object (2 after [`OctahedralSet::new`]).
    pub near: f32,
    /// Frames a bake is weighed as lasting ([`Representation::payback_frames`]; `PAYBACK`
    /// after [`OctahedralSet::new`]): it holds every direction, so it lasts until its
    /// object changes, unlike an image taken from one eye.
    pub payback_frames: f32,
    baked: Vec<Option<Baked>>,
    /// Sums of the bakes' gradients, depth-weighted gradients and their count: the prior
    /// of an object never baked.
    prior: (f64, f64, u32),
    tint: Option<Rgba>,
}

impl OctahedralSet {
    /// A set for `count` objects, none baked; `grid` x `grid` views of `frame_px` pixels
    /// over `layout`, blended from three frames.
    pub fn new(count: usize, grid: u32, frame_px: u32, layout: Layout) -> Self {
        OctahedralSet {
            grid,
            frame_px,
            layout,
            blend: Blend::Three,
            near: NEAR,
            payback_frames: PAYBACK,
            baked: vec![None; count],
            prior: (0.0, 0.0, 0),
            tint: None,
        }
    }

    /// Object `i`'s bake, if it has one.
    pub fn impostor(&self, i: usize) -> Option<&OctahedralImpostor> {
        self.baked.get(i)?.as_ref().map(|b| &b.imp)
    }

    /// What object `i`'s bake measured, if it has one.
    pub fn gradients(&self, i: usize) -> Option<Gradients> {
        self.baked.get(i)?.as_ref().map(|b| b.gradients)
    }

    /// The grid and frame side a new bake gets (clamped as the bake clamps them).
    fn sizes(&self) -> (u32, u32) {
        let n = self.grid.clamp(MIN_GRID, MAX_GRID);
        (n, self.frame_px.max(MIN_FRAME_PX).min(MAX_ATLAS_SIDE / n))
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

/// Unit direction from `centre` towards the viewer (against an orthographic camera's view
/// direction), as the impostor selects its frames by; `None` for a broken camera or an
/// eye at the centre. `eye` is the camera's.
fn toward_viewer(camera: &Camera, eye: Vec3, centre: Vec3) -> Option<Vec3> {
    let d = match camera.projection {
        Projection::Orthographic { .. } => -camera.forward(),
        Projection::Perspective { .. } | Projection::Frustum { .. } => eye - centre,
    };
    d.try_normalize()
}

/// A view direction quantised as the impostor's recomposition key is (to 1/4096).
fn key(v: Vec3) -> [i16; 3] {
    v.to_array().map(|x| (x * 4096.0).round() as i16)
}

/// `atan2(|a x b|, a . b)`: well conditioned for small angles.
fn angle(a: Vec3, b: Vec3) -> f32 {
    a.cross(b).length().atan2(a.dot(b))
}

/// The angle from the view direction `v` to the frames the impostor blends for it: their
/// weighted mean (the heaviest frame's alone with [`Blend::Nearest`]), radians.
pub(crate) fn frame_angle(layout: Layout, grid: u32, blend: Blend, v: Vec3) -> f32 {
    let n = grid.clamp(MIN_GRID, MAX_GRID);
    let (idx, w) = select(layout, n, encode(layout, v));
    let dir = |k: u32| decode(layout, cell_uv(n, k % n, k / n));
    match blend {
        Blend::Three => (0..3).map(|m| w[m] * angle(v, dir(idx[m]))).sum(),
        Blend::Nearest => {
            let m = (0..3).fold(0, |b, m| if w[m] > w[b] { m } else { b });
            angle(v, dir(idx[m]))
        }
    }
}

/// Texels per screen pixel and the shift (texels) of a surface one radius off the frames'
/// planes, for `frame_px`-texel frames of a `grid` x `grid` `layout` seen as `sight`.
pub(crate) fn view_terms(
    layout: Layout,
    grid: u32,
    frame_px: u32,
    blend: Blend,
    sight: &Sight<'_>,
    v: Vec3,
) -> (f32, f32) {
    let (r, dist) = (sight.bounds.radius, sight.distance.max(1e-6));
    let spread = (r / dist).min(1.0).asin();
    let screen = 2.0 * spread * sight.px_per_radian;
    let texels_per_px = frame_px as f32 / screen.max(1e-3);
    let a = frame_angle(layout, grid, blend, v) + PERSPECTIVE * spread;
    // In screen pixels (r sin a, at the object's distance), then texels.
    let shift_px = r * a.min(std::f32::consts::FRAC_PI_2).sin() * sight.px_per_radian / dist;
    (texels_per_px, shift_px * texels_per_px)
}

/// Bytes a bake of `grid` x `grid` frames of `px` pixels holds, as
/// [`OctahedralImpostor::bytes`] counts them (its quad and fixed-size fields left out).
pub(crate) fn bake_bytes(grid: u32, px: u32) -> usize {
    let (cells, texels) = ((grid * grid) as usize, (px * px) as usize);
    let atlas =
        cells * texels * (size_of::<engine::Premul>() + 4) + cells * size_of::<Option<Camera>>();
    // The composed texture: 4 bytes and the 8-byte linear copy per texel, with mipmaps.
    atlas + cells * 12 + image_bytes(px, px) * 3
}

/// Whether `b` is still where the bake was made, at its size.
fn same_place(b: Sphere, baked: Sphere) -> bool {
    let tol = 1e-3 * baked.radius.max(1e-6);
    b.center.distance(baked.center) <= tol && (b.radius - baked.radius).abs() <= tol
}

impl<S: Subject + Send + Sync> Representation<S> for OctahedralSet {
    fn name(&self) -> &str {
        "octahedral"
    }

    fn payback_frames(&self) -> Option<f32> {
        Some(self.payback_frames)
    }

    /// `None` within [`OctahedralSet::near`] radii, on an empty target or a broken view.
    /// A bake whose subject changed or moved has infinite error; a fresh bake would err as
    /// the current one does (the bake does not depend on the view), or with the set's
    /// prior gradients for an object never baked.
    fn estimate(&self, i: usize, subject: &S, sight: &Sight<'_>) -> Option<Estimate> {
        let slot = self.baked.get(i)?;
        let b = sight.bounds;
        if !sight.sane() || sight.within(self.near) {
            return None;
        }
        let v = toward_viewer(sight.camera, sight.eye, b.center)?;
        let (fresh_grid, fresh_px) = self.sizes();
        let predict = |layout: Layout, grid: u32, px: u32, g: Gradients| {
            let (tpp, shift) = view_terms(layout, grid, px, self.blend, sight, v);
            let e = octahedral_error(g.gradient, g.depth_gradient, tpp, shift);
            if e.is_nan() {
                f32::INFINITY
            } else {
                e
            }
        };
        let (error, rebuilt, px, memory) = match slot {
            Some(baked) => {
                let info = baked.imp.info();
                let valid = subject.version() == info.version && same_place(b, info.bounds);
                let now = predict(info.layout, info.grid, info.frame_px, baked.gradients);
                let error = if valid { now } else { f32::INFINITY };
                let rebuilt = predict(self.layout, fresh_grid, fresh_px, baked.gradients);
                (error, rebuilt, info.frame_px, baked.imp.bytes())
            }
            None => {
                let rebuilt = predict(self.layout, fresh_grid, fresh_px, self.prior());
                let memory = bake_bytes(fresh_grid, fresh_px);
                (f32::INFINITY, rebuilt, fresh_px, memory)
            }
        };
        // Recomposed (three bilinear taps per texel) when the view changed.
        let shown = slot.as_ref().and_then(|s| s.shown);
        let compose = if shown == Some(key(v)) {
            0
        } else {
            3 * u64::from(px) * u64::from(px)
        };
        let renders = u64::from(fresh_grid * fresh_grid);
        Some(Estimate {
            error,
            rebuilt,
            draw: Work {
                triangles: 2,
                image_pixels: sight.pixels as u64 + compose,
                ..Work::default()
            },
            rebuild: Work {
                triangles: renders * subject.triangle_count() as u64,
                pixels: renders * u64::from(fresh_px) * u64::from(fresh_px),
                captures: renders,
                ..Work::default()
            },
            memory,
        })
    }

    /// Bakes the objects with the set's settings, side by side on the pool (each bake
    /// renders into its own capturer, so the bakes do not depend on the thread count).
    fn rebuild(&mut self, objects: &[usize], subjects: &mut [S], view: &FrameView<'_>) -> Work {
        let (grid, px) = self.sizes();
        let (layout, lighting) = (self.layout, view.lighting);
        let n = self.baked.len().min(subjects.len());
        let wanted: Vec<usize> = objects.iter().copied().filter(|&i| i < n).collect();
        let chosen = pick_mut(subjects, wanted.iter().copied());
        let bakes: Vec<(usize, OctahedralImpostor, Gradients)> = chosen
            .into_par_iter()
            .with_max_len(1)
            .map(|s| {
                let imp = OctahedralImpostor::bake(s, lighting, grid, px, layout);
                let g = Gradients::measure(&imp);
                (s.triangle_count(), imp, g)
            })
            .collect();
        let mut work = Work::default();
        let tint = self.tint.unwrap_or(Rgba::WHITE);
        for (&i, (triangles, mut imp, gradients)) in wanted.iter().zip(bakes) {
            let renders = u64::from(imp.bake_renders());
            let side = u64::from(imp.info().frame_px);
            work += Work {
                triangles: renders * triangles as u64,
                pixels: renders * side * side,
                captures: renders,
                ..Work::default()
            };
            imp.set_blend(self.blend);
            imp.set_tint(tint);
            self.prior.0 += f64::from(gradients.gradient);
            self.prior.1 += f64::from(gradients.depth_gradient);
            self.prior.2 += 1;
            self.baked[i] = Some(Baked {
                imp,
                gradients,
                shown: None,
            });
        }
        work
    }

    /// Recomposes each drawn object's image for this view, side by side.
    fn prepare(&mut self, objects: &[usize], _subjects: &[S], view: &FrameView<'_>) {
        let (camera, blend) = (view.camera, self.blend);
        let eye = camera.eye();
        let mut drawn = pick_mut(&mut self.baked, objects.iter().copied());
        drawn.par_iter_mut().with_max_len(1).for_each(|slot| {
            if let Some(b) = slot.as_mut() {
                b.imp.set_blend(blend);
                b.imp.update(camera);
                let v = toward_viewer(camera, eye, b.imp.info().bounds.center);
                b.shown = v.map(key);
            }
        });
    }

    /// The blended quad; the subject's geometry if it has no bake (the planner chose it
    /// with nothing better: its error was predicted infinite).
    fn draw<'a>(&'a self, i: usize, subject: &'a S, _eye: Vec3, out: &mut Vec<Draw<'a>>) {
        match self.baked.get(i) {
            Some(Some(b)) => out.push(b.imp.draw()),
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
            b.imp.set_tint(tint.unwrap_or(Rgba::WHITE));
        }
    }

    fn memory(&self) -> usize {
        self.baked.iter().flatten().map(|b| b.imp.bytes()).sum()
    }
}
