//! View morphing (Seitz and Dyer, SIGGRAPH 96): in-between views from two images and
//! their cameras, shape preserving, in three steps.
//! 1. **prewarp**: both images turned to parallel views, x along the baseline
//!    ([`fn@crate::stereo::rectify`]; the same homographies);
//! 2. **morph** (the private `forward` module): between parallel views a point moves along its row, in
//!    proportion to its disparity, so the view from the eye a fraction `s` along the
//!    baseline puts left pixel `x` at `x - s d`; both images are mapped there (the left by
//!    its disparities, the right by its own), folds resolved by disparity (nearer wins),
//!    colours cross-dissolved where both see the point, holes filled from the other image;
//! 3. **postwarp**: the parallel in-between view turned to the in-between camera, whose
//!    eye is interpolated along the baseline and whose orientation is interpolated between
//!    the two (spherically), as the lectures describe.
//!
//! Correspondences come from the images' depth ([`Correspondence::Depth`]) or from the
//! stereo matcher on the prewarped pair ([`Correspondence::Stereo`]). The singular case,
//! the baseline along the view (an epipole inside the image: motion toward the scene), is
//! refused with the rectifier's error, not morphed into garbage.
//!
//! Without cameras ([`ViewMorph::from_points`], [`uncalibrated`]) the prewarp comes from
//! point pairs: their fundamental matrix by the normalised eight-point algorithm
//! ([`fundamental`]), homographies sending both epipoles to infinity along x (Hartley's
//! projective rectification), and the postwarp interpolates the two prewarps' inverses.
//!
//! [`plain_morph`] is the morph without the prewarp: points moved along straight lines
//! between their positions in the two images, which is not shape preserving when the
//! views are not parallel; it is here to be measured against.

mod forward;
pub use forward::MorphScratch;
mod plain;
pub use plain::plain_morph;
pub mod fundamental;
pub mod uncalibrated;

use crate::core::DepthImage;
use crate::stereo::rectify::{pixel_ray, resample, resample_into};
use crate::stereo::rectify::{rectify_with, Framing};
use crate::stereo::{luminance, Disparity, Rectified, RectifyError, Sgm};
use engine::color::Premul;
use engine::{Camera, Projection};
use glam::{Mat3, Mat4, Quat, Vec3, Vec4};
use std::ops::Range;
use std::time::Instant;

/// Where the morph's dense correspondences come from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Correspondence {
    /// The images' depth (rendered, or from a depth camera).
    Depth,
    /// Semi-global matching on the prewarped pair, up to this many pixels of disparity.
    Stereo {
        /// The largest disparity searched, in pixels of the prewarped pair.
        max_disparity: u32,
    },
}

/// Why two views cannot be morphed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MorphError {
    /// The views cannot be rectified to parallel ones (no baseline, or moving along the
    /// view).
    #[error("cannot prewarp the views to parallel ones: {0}")]
    Prewarp(#[from] RectifyError),
    #[error("the images have no depth to take correspondences from (use the stereo matcher)")]
    /// Depth correspondence was asked for, but neither image holds a surface (finite
    /// depth).
    NoDepth,
    /// The stereo matcher refused the pair: its message.
    #[error("the stereo matcher failed: {0}")]
    Stereo(String),
    /// The point pairs give no fundamental matrix (uncalibrated morphs).
    #[error("cannot estimate the fundamental matrix from the point pairs: {0}")]
    Fundamental(#[from] fundamental::FundamentalError),
    #[error(
        "the epipole of the {image} image is at ({x:.0}, {y:.0}) pixels, in or near the image: the eyes move toward the scene and rows cannot be made to match (move the cameras sideways)"
    )]
    /// An epipole lies in or near an image, so no homography can make its rows match
    /// (the eyes move toward the scene).
    EpipoleInImage {
        /// Which image, `"first"` or `"second"`.
        image: &'static str,
        /// The epipole's x, in that image's pixels.
        x: f64,
        /// The epipole's y, in that image's pixels.
        y: f64,
    },
    /// The point pairs' disparities exceed what the stereo matcher searches.
    #[error("the point pairs lie up to {needed} pixels apart in the prewarped pair, past the matcher's {max}")]
    DisparityRange {
        /// The largest disparity of the pairs, prewarped pixels.
        needed: u32,
        /// The matcher's `max_disparity`.
        max: u32,
    },
    /// The point pairs cannot make a prewarp: why.
    #[error("cannot prewarp from the point pairs: {0}")]
    Pairs(&'static str),
}

/// What a morphed frame holds, in pixels of the frame (the output, not the larger
/// prewarped pair): each covered pixel counted once, by what most of it came from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MorphStats {
    /// Pixels mapped from the left image, and from the right image only (holes the left
    /// left, filled from the other image).
    pub from_left: u64,
    /// Pixels mapped from the right image only (where the left image left holes).
    pub from_right: u64,
    /// Pixels neither image mapped to, between two mapped pixels of their row in the
    /// parallel view (filled from the farther side), or past the last mapped pixel of a row
    /// that shows a surface (filled from it: the corners neither view saw).
    pub holes: u64,
}

/// Two views prewarped to parallel ones, with their disparities: ready to morph.
#[derive(Clone, Debug)]
pub struct ViewMorph {
    /// The views' size (the prewarped pair is larger).
    width: u32,
    height: u32,
    from: Camera,
    to: Camera,
    pair: Rectified,
    /// The prewarped left and right views' disparities (pixels, infinity where unknown).
    left: Disparity,
    right: Disparity,
    /// The largest disparity of each of their rows ([`forward::row_reach`]).
    reach: [Vec<f32>; 2],
    /// For a morph from point pairs: the postwarp's two ends, in place of the cameras.
    postwarp: Option<uncalibrated::Postwarp>,
}

impl ViewMorph {
    /// Prewarps `a` and `b` (one size, cameras apart across the view) and finds their
    /// correspondences. The prewarped pair is half again as large as the views: a view
    /// turned to it keeps most of what it sees.
    pub fn new(a: &DepthImage, b: &DepthImage, how: Correspondence) -> Result<Self, MorphError> {
        Self::framed(a, b, how, 1.5)
    }

    /// [`ViewMorph::new`] with the prewarped pair `scale` times the views' size (at their
    /// focal length, clamped to 1 to 4): views captured wider than the in-between views
    /// shown ([`ViewMorph::shown_as`]) need less.
    pub fn framed(
        a: &DepthImage,
        b: &DepthImage,
        how: Correspondence,
        scale: f32,
    ) -> Result<Self, MorphError> {
        // Halfway between the views' directions.
        let framing = Framing {
            between: true,
            scale,
        };
        let pair = rectify_with(a, b, &framing)?;
        let (w, h) = (pair.left.width(), pair.left.height());
        let focal = pair.left.camera.projection.gl_matrix().x_axis.x * 0.5 * w as f32;
        let (left, right) = match how {
            Correspondence::Depth => {
                if a.covered() == 0 && b.covered() == 0 {
                    return Err(MorphError::NoDepth);
                }
                let of = |image: &DepthImage, original: &Camera| {
                    let saw = seen_directions(image, original);
                    let depth = surface_depth(image);
                    let data = (depth.iter().zip(&image.color).zip(saw))
                        .map(|((&z, c), saw)| {
                            if z.is_finite() && z > 0.0 {
                                focal * pair.baseline / z
                            } else if c.a > 0.0 || saw {
                                // Sky, and what lies past the far plane: seen, empty, at
                                // infinity, the same in both views (a direction, moved by
                                // the postwarp's turn only, never filled along its row).
                                0.0
                            } else {
                                // Outside what the view saw: unknown.
                                f32::INFINITY
                            }
                        })
                        .collect();
                    Disparity::new(w, h, data).expect("finite and positive, or infinite")
                };
                (of(&pair.left, &a.camera), of(&pair.right, &b.camera))
            }
            Correspondence::Stereo { max_disparity } => stereo(&pair, max_disparity)?,
        };
        Ok(ViewMorph {
            width: a.width(),
            height: a.height(),
            from: a.camera,
            to: b.camera,
            pair,
            reach: [forward::row_reach(&left), forward::row_reach(&right)],
            left,
            right,
            postwarp: None,
        })
    }

    /// The same morph showing its in-between views through `projection` at `width` x
    /// `height` instead of the first view's projection and size (eyes and turns as before).
    /// Views captured wider than the views shown (same focal length, centred) leave no
    /// corner of a turned in-between view that neither saw: beside the frame's edge, a
    /// surface beyond both views' frames was filled along its row from whatever the row's
    /// first mapped pixel showed (a rock, a house's side), a streak (issue 39).
    pub fn shown_as(mut self, projection: Projection, width: u32, height: u32) -> Self {
        self.from.projection = projection;
        self.to.projection = projection;
        (self.width, self.height) = (width, height);
        self
    }

    /// The prewarped pair. (From point pairs its cameras are the first image's, standing
    /// in, and its baseline 0: unknown.)
    pub fn prewarped(&self) -> &Rectified {
        &self.pair
    }

    /// The in-between camera a fraction `s` of the way (0: the first view, 1: the second):
    /// its eye on the line between the two, its orientation interpolated spherically, the
    /// first view's projection. For a morph from point pairs, the images' own cameras,
    /// which the morph did not use.
    pub fn camera_at(&self, s: f32) -> Camera {
        between(&self.from, &self.to, s)
    }

    /// The in-between view a fraction `s` of the way, and what it is made of. (From point
    /// pairs its depth is unknown: [`crate::core::EMPTY`].)
    pub fn frame(&self, s: f32) -> (DepthImage, MorphStats) {
        let mut image = DepthImage::new(0, 0, self.from);
        let (made, ..) = self.parallel(s, (true, true), (&mut image, &mut Vec::new(), &mut true));
        let view = self.postwarp(&image, s);
        let made = made.expect("labels asked for");
        (view, forward::Made::count(&self.postwarp(&made, s)))
    }

    /// The in-between view a fraction `s` of the way, and what [`ViewMorph::stats`] needs
    /// to count what it is made of. Showing the view needs only the first: the labels are
    /// made (a second morph of the pair) and postwarped when counted.
    pub fn view(&self, s: f32) -> (DepthImage, Labels) {
        let mut scratch = MorphScratch::default();
        let labels = self.view_into(s, &mut scratch);
        (scratch.view, labels)
    }

    /// [`ViewMorph::view`] into `scratch` (the view in [`MorphScratch::view`]): a morph
    /// shown frame after frame keeps its canvas and its view instead of allocating them
    /// every frame (at 1280x720 a 2-million-pixel canvas, 40 MB, and the view, 18 MB).
    /// The same pixels as [`ViewMorph::view`] (its colours only, every depth empty, when
    /// [`MorphScratch::depth`] is off).
    pub fn view_into(&self, s: f32, scratch: &mut MorphScratch) -> Labels {
        let s = s.clamp(0.0, 1.0);
        let start = Instant::now();
        let canvas = (
            &mut scratch.parallel,
            &mut scratch.written,
            &mut scratch.canvas_depth_empty,
        );
        let (_, morphed, band, looked, cleared) = self.parallel(s, (false, scratch.depth), canvas);
        (scratch.canvas_px, scratch.band_px) = (morphed, band);
        (scratch.source_px, scratch.cleared_px) = (looked, cleared);
        let postwarp = Instant::now();
        scratch.canvas_time = postwarp - start;
        let camera = self.camera_at(s);
        match &self.postwarp {
            Some(_) => {
                scratch.view = self.postwarp(&scratch.parallel, s);
                scratch.view_depth_empty = false;
            }
            None => {
                if (scratch.view.width(), scratch.view.height()) != (self.width, self.height) {
                    scratch.view = DepthImage::new(self.width, self.height, camera);
                    scratch.view_depth_empty = true;
                }
                // A view made without depth writes none: the kept view's depths are made
                // empty once, when the view before it had depths (session 19: every
                // depth was written empty each frame, 3.7 MB at 1280x720).
                if !scratch.depth && !scratch.view_depth_empty {
                    scratch.view.depth.fill(crate::core::EMPTY);
                }
                scratch.view_depth_empty = !scratch.depth;
                let view = &mut scratch.view;
                resample_into(&scratch.parallel, &camera, view, scratch.depth);
            }
        }
        scratch.postwarp_time = postwarp.elapsed();
        Labels { s }
    }

    /// What the view of `labels` is made of: the labels morphed and carried by the same
    /// postwarp as the view, then counted.
    pub fn stats(&self, labels: &Labels) -> MorphStats {
        let mut image = DepthImage::new(0, 0, self.from);
        let canvas = (&mut image, &mut Vec::new(), &mut true);
        let (made, ..) = self.parallel(labels.s, (true, true), canvas);
        let made = made.expect("labels asked for");
        forward::Made::count(&self.postwarp(&made, labels.s))
    }

    /// The parallel in-between view a fraction `s` of the way (the rows and columns the
    /// postwarp reads) into `out`, with its labels when `labels` is set (every column
    /// then) and its depths when `depth` is, the canvas pixels morphed, and the pixels of
    /// the rows the postwarp reads (what was morphed before the columns were cut: a work
    /// counter's reference), the source pixels looked at and the canvas pixels cleared
    /// ([`forward::morph`]'s counters).
    fn parallel(
        &self,
        s: f32,
        (labels, depth): (bool, bool),
        out: (&mut DepthImage, &mut Vec<Range<usize>>, &mut bool),
    ) -> (Option<DepthImage>, u64, u64, u64, u64) {
        let s = s.clamp(0.0, 1.0);
        let p = &self.pair;
        let eye = p.left.camera.eye().lerp(p.right.camera.eye(), s);
        let parallel = Camera {
            view: moved_view(&p.left.camera, eye),
            projection: p.left.camera.projection,
        };
        let seen = self.seen(&parallel, s);
        let band = (seen.0.len() * p.left.width() as usize) as u64;
        let reach = [self.reach[0].as_slice(), self.reach[1].as_slice()];
        let (made, morphed, looked, cleared) = forward::morph(
            p,
            (&self.left, &self.right),
            reach,
            s,
            parallel,
            seen,
            (labels, depth),
            out,
        );
        (made, morphed, band, looked, cleared)
    }

    /// The rows and the columns of the parallel in-between view (seen by `parallel`) that
    /// the postwarp to the in-between camera reads: the prewarped pair is larger than the
    /// view, and the turned view reads a band of its rows and of its columns, so the
    /// pixels outside it are not morphed (the view is the same pixel for pixel; each row is
    /// morphed on its own, its columns as [`forward::morph`] keeps them). The band is the
    /// span of the view's four corners seen by `parallel` (a turn about the eye maps the
    /// view's rectangle to a quadrilateral, whose pixels lie between its corners'), with two
    /// pixels to spare for the bilinear lookup. Every pixel when a corner lies behind
    /// `parallel` or the postwarp is not a turn (a morph from point pairs).
    fn seen(&self, parallel: &Camera, s: f32) -> (Range<usize>, Range<usize>) {
        let (pw, ph) = (
            self.pair.left.width() as usize,
            self.pair.left.height() as usize,
        );
        let all = (0..ph, 0..pw);
        if self.postwarp.is_some() {
            return all;
        }
        let to_world = self.camera_at(s).gl_view_proj().inverse();
        let to_parallel = parallel.gl_view_proj();
        let eye = parallel.eye();
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        let (mut left, mut right) = (f32::INFINITY, f32::NEG_INFINITY);
        for (x, y) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
            let far = to_world * Vec4::new(x, y, 1.0, 1.0);
            let dir = far.truncate() / far.w - eye;
            let c = to_parallel * dir.extend(0.0);
            if !(far.w.is_finite() && far.w != 0.0 && c.w > 0.0) {
                return all;
            }
            // Pixel rows and columns, centres at integers, as the postwarp's lookup counts
            // them.
            let v = (1.0 - c.y / c.w) * 0.5 * ph as f32 - 0.5;
            let u = (c.x / c.w + 1.0) * 0.5 * pw as f32 - 0.5;
            (lo, hi) = (lo.min(v), hi.max(v));
            (left, right) = (left.min(u), right.max(u));
        }
        if !(lo.is_finite() && hi.is_finite() && left.is_finite() && right.is_finite()) {
            return all;
        }
        let span = |lo: f32, hi: f32, n: usize| {
            let lo = (lo.floor() - 2.0).clamp(0.0, n as f32) as usize;
            let hi = (hi.ceil() + 3.0).clamp(0.0, n as f32) as usize;
            lo..hi.max(lo)
        };
        (span(lo, hi, ph), span(left, right, pw))
    }

    /// The parallel in-between `image` (a fraction `s` of the way) turned to the
    /// in-between camera.
    fn postwarp(&self, image: &DepthImage, s: f32) -> DepthImage {
        let (w, h) = (self.width, self.height);
        let camera = self.camera_at(s);
        match &self.postwarp {
            Some(postwarp) => postwarp.apply(image, s, camera, w, h),
            None => resample(image, &camera, w, h),
        }
    }
}

/// Which in-between view [`ViewMorph::view`] made, for [`ViewMorph::stats`] to count what
/// each of its pixels is made of (from the left view, the right, or filled).
#[derive(Clone, Debug)]
pub struct Labels {
    s: f32,
}

/// The depth of each pixel of `image` (a prewarped view) that shows a surface, infinite
/// elsewhere. A pixel on a silhouette against the sky has its colour blended from both
/// (the prewarp's bilinear colour) but the depth of the nearest source pixel, often the
/// sky's: taken as a direction it was moved as the sky is, leaving a faint copy of the
/// surface's edge where the surface is not, and a disocclusion beside it was filled with
/// that faint colour, a streak along the row (issue 39). Such a pixel (covered, no depth)
/// takes the depth of the nearest surface among its eight neighbours; covered pixels with
/// no surface around them stay at infinity.
fn surface_depth(image: &DepthImage) -> Vec<f32> {
    let (w, h) = (image.width() as usize, image.height() as usize);
    let depth = &image.depth;
    let surface = |z: f32| z.is_finite() && z > 0.0;
    (0..w * h)
        .map(|i| {
            let z = depth[i];
            if surface(z) || image.color[i].a <= 0.0 {
                return if surface(z) { z } else { f32::INFINITY };
            }
            let (x, y) = (i % w, i / w);
            let mut nearest = f32::INFINITY;
            for ny in y.saturating_sub(1)..(y + 2).min(h) {
                for nx in x.saturating_sub(1)..(x + 2).min(w) {
                    let n = depth[ny * w + nx];
                    if surface(n) && n < nearest {
                        nearest = n;
                    }
                }
            }
            nearest
        })
        .collect()
}

/// Whether each pixel of `image` (a prewarped view) looks in a direction `original` (the
/// view it was resampled from) saw: inside its frustum, taken as a direction (at
/// infinity). Tells the sky and what lies past the far plane (empty, but seen) from what
/// the view never saw (empty, unknown).
fn seen_directions(image: &DepthImage, original: &Camera) -> Vec<bool> {
    let (w, h) = (image.width(), image.height());
    let to_world = image.camera.gl_view_proj().inverse();
    let eye = image.camera.eye();
    let to_clip = original.gl_view_proj();
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|p| {
            let c = to_clip * pixel_ray(&to_world, eye, p, (w, h)).extend(0.0);
            c.w > 0.0 && c.x.abs() <= c.w && c.y.abs() <= c.w
        })
        .collect()
}

/// The dense correspondences of a prewarped pair by semi-global matching, over a window
/// of `max_disparity` pixels: the left view's disparities and the right's (the mirrored
/// pair matched the same way), unknowns filled from the background side, infinite where
/// the prewarped view saw nothing. Where the window lies comes from [`disparity_window`]:
/// `0..max_disparity` unless the pair's disparities reach past it (views far apart, as
/// 30 degrees at 640 pixels), when the right image is shifted by the least disparity
/// found, so a match is never sought short of where it is (which doubled the model).
/// (Disparities spanning more than the window cannot all be found; the window then starts
/// at 0, as without the search.)
/// Shared by the morph from points ([`uncalibrated`]).
fn stereo(pair: &Rectified, max_disparity: u32) -> Result<(Disparity, Disparity), MorphError> {
    let (w, h) = (pair.left.width(), pair.left.height());
    let sgm = Sgm {
        max_disparity,
        ..Sgm::default()
    };
    let (l, r) = (luminance(&pair.left), luminance(&pair.right));
    let seen: Vec<bool> = pair.left.color.iter().map(|c| c.a > 0.0).collect();
    let lo = disparity_window(&l, &r, &seen, (w, h), max_disparity)?;
    let run = |l: &[f32], r: &[f32]| {
        let mut d = sgm
            .run(l, r, w, h)
            .map_err(|e| MorphError::Stereo(e.to_string()))?;
        for v in &mut d.data {
            *v += lo as f32;
        }
        Ok::<_, MorphError>(d)
    };
    // The right view's disparities: the mirrored pair matched the same way.
    let flip = |v: &[f32]| -> Vec<f32> {
        v.chunks(w as usize)
            .flat_map(|row| row.iter().rev().copied())
            .collect()
    };
    let mut left = run(&l, &shift(&r, w, lo))?;
    let mirrored = run(&flip(&r), &shift(&flip(&l), w, lo))?;
    let mut right = Disparity::new(w, h, flip(&mirrored.data)).expect("a matcher's disparities");
    // What the checks left unknown (occlusions, mismatches) taken from the
    // background side, where a disocclusion's pixels lie.
    for (map, image) in [(&mut left, &pair.left), (&mut right, &pair.right)] {
        map.fill_from_background();
        fill_columns(map);
        // Unknown where the prewarped view saw nothing.
        for (d, c) in map.data.iter_mut().zip(&image.color) {
            if c.a <= 0.0 {
                *d = f32::INFINITY;
            }
        }
    }
    Ok((left, right))
}

/// Fills what a row fill left unknown (rows with no match at all: a textureless sky or
/// backdrop above or below the model) from the nearest known pixels of its column above
/// and below, the farther of the two (the background side). Without it those rows stayed
/// empty: a band of nothing across the morph where the views saw sky.
fn fill_columns(map: &mut Disparity) {
    let (w, h) = (map.width as usize, map.height as usize);
    for x in 0..w {
        let mut above: Option<f32> = None;
        let mut pending = Vec::new();
        for y in 0..h {
            let d = map.data[y * w + x];
            if d.is_finite() {
                for &p in &pending {
                    map.data[p] = above.map_or(d, |a| a.min(d));
                }
                pending.clear();
                above = Some(d);
            } else {
                pending.push(y * w + x);
            }
        }
        if let Some(a) = above {
            for &p in &pending {
                map.data[p] = a;
            }
        }
    }
}

/// The rows of `image` (`w` wide) moved right by `by` pixels, black coming in at the left:
/// a left pixel `x` that matches `x - d` in `image` matches `x - (d - by)` in this.
fn shift(image: &[f32], w: u32, by: u32) -> Vec<f32> {
    let (w, by) = (w as usize, (by as usize).min(w as usize));
    if by == 0 {
        return image.to_vec();
    }
    image
        .chunks(w)
        .flat_map(|row| std::iter::repeat_n(0.0, by).chain(row[..w - by].iter().copied()))
        .collect()
}

/// The pair's reduction for the coarse search: each side divided by this.
const COARSE: u32 = 4;

/// Where a window of `max` disparities must start for the pair `l`, `r` (luminance, `w` x
/// `h`; `seen`: the left view's pixels that show something): 0 when a coarse search (the
/// pair reduced [`COARSE`] times, matched over its whole width) finds its disparities
/// (1st to 99th percentile over the blocks the left view sees whole, give or take two
/// coarse pixels) inside `0..max` or spanning more than `max` (then the window cannot
/// hold them wherever it lies); their least otherwise.
fn disparity_window(
    l: &[f32],
    r: &[f32],
    seen: &[bool],
    (w, h): (u32, u32),
    max: u32,
) -> Result<u32, MorphError> {
    let (cw, ch) = (w / COARSE, h / COARSE);
    if cw < 8 || ch < 8 {
        return Ok(0);
    }
    let k = COARSE as usize;
    // The pixels of coarse block `i`.
    let block = move |i: usize| {
        let (x, y) = (i % cw as usize * k, i / cw as usize * k);
        (0..k).flat_map(move |dy| (0..k).map(move |dx| (y + dy) * w as usize + x + dx))
    };
    let reduce = |v: &[f32]| -> Vec<f32> {
        (0..(cw * ch) as usize)
            .map(|i| block(i).map(|p| v[p]).sum::<f32>() / (k * k) as f32)
            .collect()
    };
    let coarse = Sgm {
        max_disparity: cw,
        prior: 0,
        ..Sgm::default()
    };
    let Ok(found) = coarse.run(&reduce(l), &reduce(r), cw, ch) else {
        return Ok(0);
    };
    let mut d: Vec<f32> = (found.data.into_iter().enumerate())
        .filter(|&(i, d)| d.is_finite() && block(i).all(|p| seen[p]))
        .map(|(_, d)| d)
        .collect();
    if d.len() < 16 {
        return Ok(0);
    }
    d.sort_by(f32::total_cmp);
    let at = |q: f32| d[((d.len() - 1) as f32 * q) as usize] * COARSE as f32;
    let margin = 2.0 * COARSE as f32;
    let lo = (at(0.01) - margin).max(0.0).floor() as u32;
    let hi = (at(0.99) + margin).ceil() as u32;
    if hi <= max {
        return Ok(0);
    }
    if hi - lo > max {
        // Wider than the window: searched from 0 as before (what lies past it is matched
        // short of where it is); a wider window is the cure.
        return Ok(0);
    }
    Ok(lo)
}

/// `camera`'s view with its eye moved to `eye` (same orientation).
fn moved_view(camera: &Camera, eye: Vec3) -> Mat4 {
    let mut view = camera.view;
    let r = Mat3::from_mat4(view);
    view.w_axis = (-(r * eye)).extend(1.0);
    view
}

/// The camera a fraction `s` of the way from `a` to `b`: eye linearly, orientation by
/// spherical interpolation, `a`'s projection.
pub fn between(a: &Camera, b: &Camera, s: f32) -> Camera {
    let rotation = |c: &Camera| Quat::from_mat3(&Mat3::from_mat4(c.view)).normalize();
    let r = rotation(a).slerp(rotation(b), s);
    let eye = a.eye().lerp(b.eye(), s);
    let m = Mat3::from_quat(r);
    let t = -(m * eye);
    Camera {
        view: Mat4::from_cols(
            m.x_axis.extend(0.0),
            m.y_axis.extend(0.0),
            m.z_axis.extend(0.0),
            Vec4::new(t.x, t.y, t.z, 1.0),
        ),
        projection: a.projection,
    }
}

/// `a` over nothing: premultiplied colour scaled by `k`.
fn scaled(c: Premul, k: f32) -> Premul {
    Premul {
        r: c.r * k,
        g: c.g * k,
        b: c.b * k,
        a: c.a * k,
    }
}

/// The sum of two premultiplied colours.
fn sum(a: Premul, b: Premul) -> Premul {
    Premul {
        r: a.r + b.r,
        g: a.g + b.g,
        b: a.b + b.b,
        a: a.a + b.a,
    }
}

#[cfg(test)]
mod tests;
