//! Rectification of a pair from known cameras (Fusiello, Trucco and Verri 2000): both
//! views turned, about their own eyes, to one orientation whose x axis runs along the
//! baseline, with the left camera's projection, so that matching points lie on the same
//! row. Each rectified image is its original resampled through the homography between
//! the two orientations (the eye does not move, so the mapping does not depend on depth).
//! The rectified left camera is a real camera: a disparity map of the rectified pair makes
//! a depth image with it ([`Disparity::to_depth_image`](super::Disparity::to_depth_image)).

use crate::core::{DepthImage, EMPTY};
use engine::color::Premul;
use engine::Camera;
use glam::{DMat4, DVec3, DVec4, Mat4, Vec3, Vec4};
use rayon::prelude::*;

/// Why a pair cannot be rectified.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RectifyError {
    /// The cameras' centres (nearly) coincide: their distance, scene units.
    #[error("the cameras are {0} apart: a pair needs a baseline")]
    NoBaseline(f32),
    #[error(
        "the baseline runs within {0:.1} degrees of the left camera's view direction: the epipole is in the image and rows cannot be made to match (move the cameras sideways)"
    )]
    /// The baseline runs (nearly) along the left camera's view: the angle between them,
    /// degrees.
    AlongTheView(f32),
    /// The images differ in size: left width and height, then right.
    #[error("the images are {0}x{1} and {2}x{3}: rectification needs one size")]
    Sizes(u32, u32, u32, u32),
}

/// A rectified pair: the two images resampled, their cameras and the baseline.
#[derive(Clone, Debug)]
pub struct Rectified {
    /// The left image resampled into the rectified left camera (rows are epipolar lines).
    pub left: DepthImage,
    /// The right image resampled into the rectified right camera, same size and
    /// orientation as `left`.
    pub right: DepthImage,
    /// Distance between the two camera centres, scene units.
    pub baseline: f32,
}

/// How the rectified views are framed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Framing {
    /// Turn to the direction halfway between the two views' (each view turns half as
    /// far) rather than to the left view's.
    pub between: bool,
    /// The rectified images' size against the originals', at the same focal length: above
    /// 1 they see more, so less of a turned view falls outside them.
    pub scale: f32,
}

impl Default for Framing {
    /// The left view's direction and size: the stereo matchers' rectification.
    fn default() -> Self {
        Framing {
            between: false,
            scale: 1.0,
        }
    }
}

/// Rectifies `left` and `right` (images with their cameras, one size). The rectified
/// orientation: x along the baseline (left eye to right eye), y as near the left camera's
/// up as that allows, the left camera's projection for both. Pixels whose ray leaves the
/// original image are transparent.
pub fn rectify(left: &DepthImage, right: &DepthImage) -> Result<Rectified, RectifyError> {
    rectify_with(left, right, &Framing::default())
}

/// [`rectify`], framed as `framing` asks: the view direction the rectified views turn to
/// (the left view's, or halfway to the right's), and their size at the left camera's
/// focal length.
pub fn rectify_with(
    left: &DepthImage,
    right: &DepthImage,
    framing: &Framing,
) -> Result<Rectified, RectifyError> {
    let (w, h) = (left.width(), left.height());
    if (w, h) != (right.width(), right.height()) {
        return Err(RectifyError::Sizes(w, h, right.width(), right.height()));
    }
    let (cl, cr) = (left.camera.eye(), right.camera.eye());
    let base = cr - cl;
    let baseline = base.length();
    if !(baseline > 1e-6 && baseline.is_finite()) {
        return Err(RectifyError::NoBaseline(baseline));
    }
    let x = base / baseline;
    let forward = left.camera.forward();
    let angle = x.dot(forward).abs().min(1.0).acos().to_degrees();
    let off_axis = 90.0 - angle;
    if off_axis > 60.0 {
        return Err(RectifyError::AlongTheView(angle));
    }
    let forward = if framing.between {
        (forward + right.camera.forward()).normalize_or(forward)
    } else {
        forward
    };
    // z backward (the camera looks down -z), y up, x along the baseline.
    let back = (-forward - x * (-forward).dot(x)).normalize();
    let y = back.cross(x);
    let scale = if framing.scale.is_finite() {
        framing.scale.clamp(1.0, 4.0)
    } else {
        1.0
    };
    let (w2, h2) = (
        (w as f32 * scale).round() as u32,
        (h as f32 * scale).round() as u32,
    );
    let projection = wider(&left.camera, h, h2, w2);
    let turn = |eye: Vec3| Camera {
        view: Mat4::from_cols(
            Vec4::new(x.x, y.x, back.x, 0.0),
            Vec4::new(x.y, y.y, back.y, 0.0),
            Vec4::new(x.z, y.z, back.z, 0.0),
            Vec4::new(-x.dot(eye), -y.dot(eye), -back.dot(eye), 1.0),
        ),
        projection,
    };
    Ok(Rectified {
        left: resample(left, &turn(cl), w2, h2),
        right: resample(right, &turn(cr), w2, h2),
        baseline,
    })
}

/// `camera`'s projection for an image of `w2` x `h2` pixels at the focal length it has
/// for one `h` pixels high: the same pixels per radian, a wider view. Itself when the
/// size is the same.
fn wider(camera: &Camera, h: u32, h2: u32, w2: u32) -> engine::Projection {
    if h2 == h {
        return camera.projection;
    }
    let m = camera.projection.gl_matrix();
    let tan_half = 1.0 / m.y_axis.y * h2 as f32 / h.max(1) as f32;
    let (near, far) = camera.near_far();
    Camera::look_at(
        Vec3::Z,
        Vec3::ZERO,
        Vec3::Y,
        2.0 * tan_half.atan(),
        w2 as f32 / h2.max(1) as f32,
    )
    .with_depth_range(near, far)
    .projection
}

/// `image` as seen by `camera` (at the same eye): each pixel's ray looked up in the
/// original, colour bilinearly, depth from the nearest pixel, measured along the new
/// camera's axis (the point stays where it is; only the axis turns), `w` x `h` pixels.
/// Pixels whose ray leaves the original are transparent, with depth
/// [`crate::core::EMPTY`]. Shared by the view morph's postwarp.
pub(crate) fn resample(image: &DepthImage, camera: &Camera, w: u32, h: u32) -> DepthImage {
    let mut out = DepthImage::new(w, h, *camera);
    resample_into(image, camera, &mut out, true);
    out
}

/// [`resample`] into `out` (its size, its camera set to `camera`; every pixel's colour
/// written, and its depth when `with_depth`): no image allocated a frame where `out` is
/// kept (the view morph's postwarp). Without
/// `with_depth` only the colours are looked up (the same colours) and no depth is written:
/// the caller keeps them [`crate::core::EMPTY`] (a kept view made without depth the frame
/// before already is; session 19: they were all written again); a view shown as colour
/// only skips each pixel's nearest depth, its two rays along the axes and a division
/// (issue 39).
///
/// A pixel's ray and where it falls in the original are a homography of its column
/// within a row ([`RowMap`]): each row sets up its linear terms once (in `f64`) and each
/// pixel evaluates them, instead of two 4x4 products and a division to world space a pixel
/// (at 1280x720, 0.92 M pixels a frame of the views moment's morph, issue 39).
pub(crate) fn resample_into(
    image: &DepthImage,
    camera: &Camera,
    out: &mut DepthImage,
    with_depth: bool,
) {
    out.camera = *camera;
    let (w, h) = (out.width(), out.height());
    let (iw, ih) = (image.width(), image.height());
    let map = RowMap::new(camera, &image.camera, (w, h), (iw, ih));
    // Row by row on the pool: each pixel is its own, so the image is the same on any
    // number of threads.
    out.color
        .par_chunks_mut(w.max(1) as usize)
        .zip(out.depth.par_chunks_mut(w.max(1) as usize))
        .enumerate()
        .for_each(|(y, (colors, depths))| {
            let row = map.row(y as u32);
            for (x, (color, depth)) in colors.iter_mut().zip(depths).enumerate() {
                *color = Premul::TRANSPARENT;
                if with_depth {
                    *depth = EMPTY;
                }
                let x = x as f64;
                let Some((u, v)) = row.source(x) else {
                    continue;
                };
                if let Some(p) = bilinear(image, u, v) {
                    *color = p;
                    if !with_depth {
                        continue;
                    }
                    // Nearest: depth does not blend across edges. `z_old` along the old
                    // axis is `t dir . old_forward` for the point `eye + t dir`.
                    let nx = u.round().clamp(0.0, iw as f32 - 1.0) as u32;
                    let ny = v.round().clamp(0.0, ih as f32 - 1.0) as u32;
                    let z_old = image.depth[(ny * iw + nx) as usize];
                    let (along_old, along_new) = row.along(x);
                    *depth = if z_old.is_finite() && z_old > 0.0 && along_old > 0.0 {
                        (z_old as f64 / along_old * along_new) as f32
                    } else {
                        z_old
                    };
                }
            }
        });
}

/// Where the pixels of a `w` x `h` view by `camera` look in an `iw` x `ih` original seen
/// by `old` from the same eye, as terms linear in a pixel's column for each row. The ray
/// through pixel `(x, y)` is `far / far.w - eye` with `far` the clip-to-world product of
/// its far-plane point, linear in `x`; scaled by `far.w` it is linear too, and so is its
/// product with the original's world-to-clip matrix (the ray as a point at infinity),
/// whose ratios are the pixel's place in the original. Signs are kept by `far.w`.
struct RowMap {
    /// The clip-to-world matrix's columns for x and for y, and the sum of its columns for
    /// z and w (the far plane, `w = 1`).
    col_x: DVec4,
    col_y: DVec4,
    rest: DVec4,
    eye: DVec3,
    to_old: DMat4,
    old_forward: DVec3,
    new_forward: DVec3,
    size: (f64, f64),
    old: (f64, f64),
}

/// One row of a [`RowMap`]: each term `a + b x` as `(a, b)`.
struct RowTerms {
    /// The ray times `far.w`, and `far.w`.
    ray: (DVec3, DVec3),
    far_w: (f64, f64),
    /// The original's clip coordinates of the ray (as a direction), times `far.w`.
    clip: (DVec4, DVec4),
    old_forward: DVec3,
    new_forward: DVec3,
    old: (f64, f64),
}

impl RowMap {
    fn new(camera: &Camera, old: &Camera, (w, h): (u32, u32), (iw, ih): (u32, u32)) -> Self {
        let to_world = camera.gl_view_proj().as_dmat4().inverse();
        RowMap {
            col_x: to_world.x_axis,
            col_y: to_world.y_axis,
            rest: to_world.z_axis + to_world.w_axis,
            eye: camera.eye().as_dvec3(),
            to_old: old.gl_view_proj().as_dmat4(),
            old_forward: old.forward().as_dvec3(),
            new_forward: camera.forward().as_dvec3(),
            size: (w as f64, h as f64),
            old: (iw as f64, ih as f64),
        }
    }

    /// Row `y`'s terms: ndc x is `2 (x + 0.5) / w - 1`, ndc y `1 - 2 (y + 0.5) / h`.
    fn row(&self, y: u32) -> RowTerms {
        let (w, h) = self.size;
        let ndc_y = 1.0 - 2.0 * (y as f64 + 0.5) / h;
        let far_a = self.col_x * (1.0 / w - 1.0) + self.col_y * ndc_y + self.rest;
        let far_b = self.col_x * (2.0 / w);
        let ray = |f: DVec4| f.truncate() - self.eye * f.w;
        let (ray_a, ray_b) = (ray(far_a), ray(far_b));
        RowTerms {
            ray: (ray_a, ray_b),
            far_w: (far_a.w, far_b.w),
            clip: (
                self.to_old * ray_a.extend(0.0),
                self.to_old * ray_b.extend(0.0),
            ),
            old_forward: self.old_forward,
            new_forward: self.new_forward,
            old: self.old,
        }
    }
}

impl RowTerms {
    /// Where column `x`'s ray falls in the original (pixel centres at integers), `None`
    /// behind it: [`source`] of the pixel's ray.
    #[inline]
    fn source(&self, x: f64) -> Option<(f32, f32)> {
        let far_w = self.far_w.0 + self.far_w.1 * x;
        let c = self.clip.0 + self.clip.1 * x;
        // The ray's clip w is `c.w / far_w`: in front when both have one sign.
        (c.w * far_w > 0.0 && far_w != 0.0).then(|| {
            let ((iw, ih), r) = (self.old, 1.0 / c.w);
            (
                ((c.x * r + 1.0) * 0.5 * iw - 0.5) as f32,
                ((1.0 - c.y * r) * 0.5 * ih - 0.5) as f32,
            )
        })
    }

    /// Column `x`'s ray along the original's axis and along the new one, both divided by
    /// the same positive factor (their ratio and signs are the ray's).
    #[inline]
    fn along(&self, x: f64) -> (f64, f64) {
        let far_w = self.far_w.0 + self.far_w.1 * x;
        let ray = (self.ray.0 + self.ray.1 * x) * far_w.signum();
        (ray.dot(self.old_forward), ray.dot(self.new_forward))
    }
}

/// Which pixels of a `w` x `h` view by `camera` (at `original`'s eye, as `resample`
/// makes) have their ray inside `original`'s image, whatever it shows there: `true`
/// inside, row-major. What the rectified view covers of the original, transparent
/// background included.
pub fn inside_original(original: &DepthImage, camera: &Camera, w: u32, h: u32) -> Vec<bool> {
    let (iw, ih) = (original.width(), original.height());
    let to_world = camera.gl_view_proj().inverse();
    let to_old = original.camera.gl_view_proj();
    let eye = camera.eye();
    let (fw, fh) = (iw as f32, ih as f32);
    let mut out = Vec::with_capacity(w as usize * h as usize);
    for y in 0..h {
        for x in 0..w {
            let dir = pixel_ray(&to_world, eye, (x, y), (w, h));
            // The bounds `bilinear` takes.
            out.push(
                source(&to_old, dir, (iw, ih))
                    .is_some_and(|(u, v)| u >= -0.5 && v >= -0.5 && u <= fw - 0.5 && v <= fh - 0.5),
            );
        }
    }
    out
}

/// Where the ray `dir` falls in the original view whose world-to-clip matrix is `to_old`
/// (pixel centres at integers, in an `iw` x `ih` image), the ray taken as a point at
/// infinity; `None` behind that view.
#[inline]
fn source(to_old: &Mat4, dir: Vec3, (iw, ih): (u32, u32)) -> Option<(f32, f32)> {
    let c = *to_old * dir.extend(0.0);
    (c.w > 0.0).then(|| {
        (
            (c.x / c.w + 1.0) * 0.5 * iw as f32 - 0.5,
            (1.0 - c.y / c.w) * 0.5 * ih as f32 - 0.5,
        )
    })
}

/// The direction (not normalised) from `eye` through the centre of pixel `(x, y)` of a
/// `w` x `h` view whose clip-to-world matrix is `to_world`.
#[inline]
pub(crate) fn pixel_ray(
    to_world: &Mat4,
    eye: Vec3,
    (x, y): (u32, u32),
    (w, h): (u32, u32),
) -> Vec3 {
    let ndc = Vec4::new(
        2.0 * (x as f32 + 0.5) / w as f32 - 1.0,
        1.0 - 2.0 * (y as f32 + 0.5) / h as f32,
        1.0,
        1.0,
    );
    let far = *to_world * ndc;
    far.truncate() / far.w - eye
}

/// `image`'s colour at `(u, v)` (pixel centres at integers), `None` outside it.
#[inline]
pub(crate) fn bilinear(image: &DepthImage, u: f32, v: f32) -> Option<Premul> {
    let (w, h) = (image.width() as f32, image.height() as f32);
    if !(u >= -0.5 && v >= -0.5 && u <= w - 0.5 && v <= h - 0.5) {
        return None;
    }
    let (u, v) = (u.clamp(0.0, w - 1.0), v.clamp(0.0, h - 1.0));
    let (x0, y0) = (u.floor() as u32, v.floor() as u32);
    let (x1, y1) = (
        (x0 + 1).min(image.width() - 1),
        (y0 + 1).min(image.height() - 1),
    );
    let (fx, fy) = (u - x0 as f32, v - y0 as f32);
    let at = |x: u32, y: u32| image.color[(y * image.width() + x) as usize];
    let mix = |a: Premul, b: Premul, t: f32| Premul {
        r: a.r + (b.r - a.r) * t,
        g: a.g + (b.g - a.g) * t,
        b: a.b + (b.b - a.b) * t,
        a: a.a + (b.a - a.a) * t,
    };
    Some(mix(
        mix(at(x0, y0), at(x1, y0), fx),
        mix(at(x0, y1), at(x1, y1), fx),
        fy,
    ))
}

#[cfg(test)]
mod tests;
