//! View morphing (Seitz and Dyer, SIGGRAPH 96): in-between views from two images and
//! their cameras, shape preserving, in three steps.
//! 1. **prewarp**: both images turned to parallel views, x along the baseline
//!    ([`crate::stereo::rectify`]; the same homographies);
//! 2. **morph** ([`forward`]): between parallel views a point moves along its row, in
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
pub mod fundamental;
pub mod uncalibrated;

use crate::images::DepthImage;
use crate::stereo::rectify::resample;
use crate::stereo::rectify::{rectify_with, Framing};
use crate::stereo::{luminance, Disparity, Rectified, RectifyError, Sgm};
use engine::color::Premul;
use engine::Camera;
use glam::{Mat3, Mat4, Quat, Vec3, Vec4};

/// Where the morph's dense correspondences come from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Correspondence {
    /// The images' depth (rendered, or from a depth camera).
    Depth,
    /// Semi-global matching on the prewarped pair, up to this many pixels of disparity.
    Stereo { max_disparity: u32 },
}

/// Why two views cannot be morphed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MorphError {
    #[error("cannot prewarp the views to parallel ones: {0}")]
    Prewarp(#[from] RectifyError),
    #[error("the images have no depth to take correspondences from (use the stereo matcher)")]
    NoDepth,
    #[error("the stereo matcher failed: {0}")]
    Stereo(String),
    #[error("cannot estimate the fundamental matrix from the point pairs: {0}")]
    Fundamental(#[from] fundamental::FundamentalError),
    #[error(
        "the epipole of the {image} image is at ({x:.0}, {y:.0}) pixels, in or near the image: the eyes move toward the scene and rows cannot be made to match (move the cameras sideways)"
    )]
    EpipoleInImage { image: &'static str, x: f64, y: f64 },
    #[error("the point pairs lie up to {needed} pixels apart in the prewarped pair, past the matcher's {max}")]
    DisparityRange { needed: u32, max: u32 },
    #[error("cannot prewarp from the point pairs: {0}")]
    Pairs(&'static str),
}

/// What a morphed frame holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MorphStats {
    /// Pixels of the parallel in-between view mapped from the left image, and from the
    /// right image only (holes the left left, filled from the other image).
    pub from_left: u64,
    pub from_right: u64,
    /// Pixels neither image mapped to; those between two mapped pixels of their row are
    /// filled from the farther side.
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
    /// For a morph from point pairs: the postwarp's two ends, in place of the cameras.
    postwarp: Option<uncalibrated::Postwarp>,
}

impl ViewMorph {
    /// Prewarps `a` and `b` (one size, cameras apart across the view) and finds their
    /// correspondences.
    pub fn new(a: &DepthImage, b: &DepthImage, how: Correspondence) -> Result<Self, MorphError> {
        // Halfway between the views' directions, half again as large: a view turned to it
        // keeps most of what it sees.
        let framing = Framing {
            between: true,
            scale: 1.5,
        };
        let pair = rectify_with(a, b, &framing)?;
        let (w, h) = (pair.left.width(), pair.left.height());
        let focal = pair.left.camera.projection.gl_matrix().x_axis.x * 0.5 * w as f32;
        let (left, right) = match how {
            Correspondence::Depth => {
                if a.covered() == 0 && b.covered() == 0 {
                    return Err(MorphError::NoDepth);
                }
                let of = |image: &DepthImage| {
                    let data = image
                        .depth
                        .iter()
                        .zip(&image.color)
                        .map(|(&z, c)| {
                            if c.a <= 0.0 {
                                // Outside what the view saw: unknown.
                                f32::INFINITY
                            } else if z.is_finite() && z > 0.0 {
                                focal * pair.baseline / z
                            } else {
                                // Sky: at infinity, the same in both views.
                                0.0
                            }
                        })
                        .collect();
                    Disparity::new(w, h, data).expect("finite and positive, or infinite")
                };
                (of(&pair.left), of(&pair.right))
            }
            Correspondence::Stereo { max_disparity } => stereo(&pair, max_disparity)?,
        };
        Ok(ViewMorph {
            width: a.width(),
            height: a.height(),
            from: a.camera,
            to: b.camera,
            pair,
            left,
            right,
            postwarp: None,
        })
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
    /// pairs its depth is unknown: [`crate::images::EMPTY`].)
    pub fn frame(&self, s: f32) -> (DepthImage, MorphStats) {
        let s = s.clamp(0.0, 1.0);
        let p = &self.pair;
        let eye = p.left.camera.eye().lerp(p.right.camera.eye(), s);
        let parallel = Camera {
            view: moved_view(&p.left.camera, eye),
            projection: p.left.camera.projection,
        };
        let (image, stats) = forward::morph(p, &self.left, &self.right, s, parallel);
        let (w, h) = (self.width, self.height);
        let camera = self.camera_at(s);
        match &self.postwarp {
            Some(postwarp) => (postwarp.apply(&image, s, camera, w, h), stats),
            None => (resample(&image, &camera, w, h), stats),
        }
    }
}

/// The dense correspondences of a prewarped pair by semi-global matching, up to
/// `max_disparity` pixels: the left view's disparities and the right's (the mirrored pair
/// matched the same way), unknowns filled from the background side, infinite where the
/// prewarped view saw nothing. Shared by the morph from points ([`uncalibrated`]).
fn stereo(pair: &Rectified, max_disparity: u32) -> Result<(Disparity, Disparity), MorphError> {
    let (w, h) = (pair.left.width(), pair.left.height());
    let sgm = Sgm {
        max_disparity,
        ..Sgm::default()
    };
    let (l, r) = (luminance(&pair.left), luminance(&pair.right));
    let run = |l: &[f32], r: &[f32]| {
        sgm.run(l, r, w, h)
            .map_err(|e| MorphError::Stereo(e.to_string()))
    };
    // The right view's disparities: the mirrored pair matched the same way.
    let flip = |v: &[f32]| -> Vec<f32> {
        v.chunks(w as usize)
            .flat_map(|row| row.iter().rev().copied())
            .collect()
    };
    let mut left = run(&l, &r)?;
    let mirrored = run(&flip(&r), &flip(&l))?;
    let mut right = Disparity::new(w, h, flip(&mirrored.data)).expect("a matcher's disparities");
    // What the checks left unknown (occlusions, mismatches) taken from the
    // background side, where a disocclusion's pixels lie.
    for (map, image) in [(&mut left, &pair.left), (&mut right, &pair.right)] {
        map.fill_from_background();
        // Unknown where the prewarped view saw nothing.
        for (d, c) in map.data.iter_mut().zip(&image.color) {
            if c.a <= 0.0 {
                *d = f32::INFINITY;
            }
        }
    }
    Ok((left, right))
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

/// The morph without the prewarp, for comparison: each pixel of `a` with depth moved on
/// the straight line from where `a` sees its point to where `b` does, a fraction `s` of
/// the way, nearer points painted last; colours from `a` alone. Not shape preserving
/// unless the views are parallel. Unfilled pixels are transparent.
pub fn plain_morph(a: &DepthImage, b: &DepthImage, s: f32) -> DepthImage {
    let (w, h) = (a.width(), a.height());
    let camera = between(&a.camera, &b.camera, s);
    let mut out = DepthImage::new(w, h, camera);
    let to_b = b.camera.gl_view_proj();
    let pixel = |c: Vec4| {
        (
            (c.x / c.w + 1.0) * 0.5 * w as f32,
            (1.0 - c.y / c.w) * 0.5 * h as f32,
        )
    };
    for y in 0..h {
        for x in 0..w {
            let (Some(point), Some((color, z))) = (a.world_point(x, y), a.get(x, y)) else {
                continue;
            };
            let c = to_b * point.extend(1.0);
            if c.w <= 0.0 {
                continue;
            }
            let (bx, by) = pixel(c);
            let (px, py) = (
                (x as f32 + 0.5) * (1.0 - s) + bx * s,
                (y as f32 + 0.5) * (1.0 - s) + by * s,
            );
            if !(px >= 0.0 && py >= 0.0 && px < w as f32 && py < h as f32) {
                continue;
            }
            let zb = c.w;
            let depth = z * (1.0 - s) + zb * s;
            let (tx, ty) = (px as u32, py as u32);
            if out.get(tx, ty).is_some_and(|(_, d)| d <= depth) {
                continue;
            }
            out.set(tx, ty, color, depth);
        }
    }
    out
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
