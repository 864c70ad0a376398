//! The view morph without cameras (Seitz and Dyer 96, from point correspondences): the
//! prewarp from the pairs' fundamental matrix by Hartley's projective rectification, the
//! row-wise morph of the private `morph::forward` module on the stereo matcher's correspondences, and a
//! postwarp interpolating the inverses of the two prewarps.
//!
//! The prewarp of `a`: its centre moved to the origin, turned (less than a quarter turn,
//! so the image stays upright) until its epipole lies on the x axis at `(f, 0)`, then
//! `G = [1 0 0; 0 1 0; -1/f 0 1]` sending that point to infinity along x: epipolar lines
//! become rows. The prewarp of `b` keeps the rows of `a` (its y and w rows are those of
//! `H_a [e_a]_x F^T`, which sends each point of `b` onto its epipolar line in `a`) and
//! chooses its x row in least squares to bring the pairs' x coordinates as close as it
//! can to theirs in `a`, then shifts it so every pair's disparity is positive.
//!
//! The first image is taken to be the left one (the second eye to the right of the first
//! as the first looks); that decides which side of a fold is nearer. Without cameras the
//! frames have no depth ([`crate::core::EMPTY`]) and keep the images' own cameras.

use super::fundamental::{from_rows, Fundamental};
use super::{forward, stereo, MorphError, ViewMorph};
use crate::core::DepthImage;
use crate::stereo::rectify::bilinear;
use crate::stereo::{Rectified, RectifyError};
use engine::Camera;
use glam::{DMat3, DVec2, DVec3, Vec2};

/// The epipole must lie this many half-diagonals from the image's centre or farther: nearer,
/// the prewarp stretches the side toward it more than threefold (and in the image, it
/// cannot make rows at all).
const EPIPOLE_CLEARANCE: f64 = 1.5;

/// The prewarped frame against the images: half again as large, as the camera path's.
const FRAME_SCALE: f64 = 1.5;

/// Homographies sending two images' pixels to parallel views: a pair's points on one row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Prewarp {
    /// From the pixels of `a` (homogeneous, `(x, y, 1)`) to the prewarped frame's, and
    /// from those of `b`.
    pub a: DMat3,
    /// From the pixels of `b` (homogeneous) to the prewarped frame's.
    pub b: DMat3,
    /// The prewarped frame's width, pixels.
    pub width: u32,
    /// The prewarped frame's height, pixels.
    pub height: u32,
    /// The smallest and largest disparity (`x` in `a` less `x` in `b`, prewarped pixels)
    /// of the pairs it was made from.
    pub disparities: (f64, f64),
}

impl Prewarp {
    /// The prewarp of two `width` x `height` images with fundamental matrix `f`, fitted to
    /// `pairs`. Refused when an epipole is in or near its image.
    pub fn new(
        f: &Fundamental,
        pairs: &[(Vec2, Vec2)],
        (width, height): (u32, u32),
    ) -> Result<Self, MorphError> {
        let size = DVec2::new(f64::from(width), f64::from(height));
        let ha = to_infinity(f.epipole_a(), size, "first")?;
        // Only checked: b's prewarp is matched to a's.
        to_infinity(f.epipole_b(), size, "second")?;
        let hom = |v: Vec2| v.as_dvec2().extend(1.0);
        let dehom = |p: DVec3| p.truncate() / p.z;
        // Rows 2 and 3 of H_a M with M = [e_a]_x F^T (Hartley and Zisserman's matching
        // transform, with the views' roles swapped): b's points on a's rows.
        let m = cross_matrix(f.epipole_a()) * f.matrix().transpose();
        let hm = ha * m;
        let (ry, mut rw) = (hm.row(1), hm.row(2));
        let centre = (size * 0.5).extend(1.0);
        let wc = rw.dot(centre);
        if wc.is_nan() || wc.abs() <= 1e-12 {
            return Err(MorphError::Pairs(
                "the second image's prewarp sends its centre to infinity",
            ));
        }
        rw /= wc;
        let ry = ry / wc;
        // The x row in least squares: h . x_b / w = x in a's prewarp.
        let mut normal = DMat3::ZERO;
        let mut rhs = DVec3::ZERO;
        for &(pa, pb) in pairs {
            let xb = hom(pb) / rw.dot(hom(pb));
            let target = dehom(ha * hom(pa)).x;
            normal += outer(xb, xb);
            rhs += xb * target;
        }
        let scale = normal
            .to_cols_array()
            .iter()
            .fold(0f64, |m, v| m.max(v.abs()));
        let det = normal.determinant();
        if det.is_nan() || det.abs() <= 1e-12 * scale.powi(3) {
            return Err(MorphError::Pairs(
                "the pairs do not fix the second image's columns",
            ));
        }
        let hx = normal.inverse() * rhs;
        let mut hb = from_rows(&[hx.x, hx.y, hx.z, ry.x, ry.y, ry.z, rw.x, rw.y, rw.z]);
        // Every pair's disparity positive, with room for points behind the farthest.
        let disparity =
            |hb: &DMat3, (pa, pb): (Vec2, Vec2)| dehom(ha * hom(pa)).x - dehom(*hb * hom(pb)).x;
        let (lo, hi) = range(pairs.iter().map(|&p| disparity(&hb, p)));
        let margin = 4.0 + 0.1 * (hi - lo);
        hb = translation(DVec2::new(lo - margin, 0.0)) * hb;
        // One frame for both: the prewarped corners fitted into it, no larger than they
        // are at a's centre.
        let corners = [
            DVec2::ZERO,
            DVec2::new(size.x, 0.0),
            DVec2::new(0.0, size.y),
            size,
        ];
        let mut min = DVec2::splat(f64::INFINITY);
        let mut max = DVec2::splat(f64::NEG_INFINITY);
        for h in [&ha, &hb] {
            for c in corners {
                let p = *h * c.extend(1.0);
                if p.z.is_nan() || p.z <= 0.0 {
                    return Err(MorphError::Pairs("an image's corner turns to infinity"));
                }
                let p = dehom(p);
                (min, max) = (min.min(p), max.max(p));
            }
        }
        let (w2, h2) = (size * FRAME_SCALE).round().into();
        let k = (w2 / (max.x - min.x)).min(h2 / (max.y - min.y)).min(1.0);
        if !(k > 1e-3 && k.is_finite()) {
            return Err(MorphError::Pairs("the prewarped images are unbounded"));
        }
        let fit = DMat3::from_cols(
            DVec3::new(k, 0.0, 0.0),
            DVec3::new(0.0, k, 0.0),
            (DVec2::new(w2, h2) * 0.5 - (min + max) * 0.5 * k).extend(1.0),
        );
        let (a, b) = (fit * ha, fit * hb);
        let (lo, hi) = range(
            pairs
                .iter()
                .map(|&(pa, pb)| dehom(a * hom(pa)).x - dehom(b * hom(pb)).x),
        );
        Ok(Prewarp {
            a,
            b,
            width: w2 as u32,
            height: h2 as u32,
            disparities: (lo, hi),
        })
    }

    /// Where pixel `p` of `a` lands in the prewarped frame.
    pub fn map_a(&self, p: Vec2) -> Vec2 {
        apply(&self.a, p.as_dvec2()).as_vec2()
    }

    /// Where pixel `p` of `b` lands in the prewarped frame.
    pub fn map_b(&self, p: Vec2) -> Vec2 {
        apply(&self.b, p.as_dvec2()).as_vec2()
    }

    /// `image` prewarped by `h` (one of the two), colour only.
    fn warp(&self, image: &DepthImage, h: &DMat3) -> DepthImage {
        let back = h.inverse();
        let mut out = DepthImage::new(self.width, self.height, image.camera);
        sample(&mut out, image, &back);
        out
    }
}

/// The postwarp of a morph from point pairs: the inverses of the two prewarps, scaled to
/// agree at a point both images see, interpolated linearly (Seitz and Dyer's postwarp
/// without cameras).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Postwarp {
    a: DMat3,
    b: DMat3,
}

impl Postwarp {
    /// The in-between view of size `w` x `h` from the morphed parallel view `parallel`, a
    /// fraction `s` of the way: `H_s^-1 = (1 - s) H_a^-1 + s H_b^-1`.
    pub(super) fn apply(
        &self,
        parallel: &DepthImage,
        s: f32,
        camera: Camera,
        w: u32,
        h: u32,
    ) -> DepthImage {
        let s = f64::from(s);
        let inverse = self.a * (1.0 - s) + self.b * s;
        let mut out = DepthImage::new(w, h, camera);
        let det = inverse.determinant();
        if det.is_finite() && det.abs() > 1e-300 {
            sample(&mut out, parallel, &inverse.inverse());
        }
        out
    }
}

impl ViewMorph {
    /// The view morph from two images of one size and point pairs between them (`(in a,
    /// in b)`, pixels, at least 8 spread over the scene, not all on one plane), without
    /// their cameras: the fundamental matrix of the pairs, the prewarp it gives
    /// ([`Prewarp`]), dense correspondences from the stereo matcher up to `max_disparity`
    /// pixels, and a postwarp interpolating the prewarps. `a` is the left view. The images'
    /// cameras and depth are not used.
    pub fn from_points(
        a: &DepthImage,
        b: &DepthImage,
        pairs: &[(Vec2, Vec2)],
        max_disparity: u32,
    ) -> Result<Self, MorphError> {
        let (w, h) = (a.width(), a.height());
        if (w, h) != (b.width(), b.height()) {
            return Err(RectifyError::Sizes(w, h, b.width(), b.height()).into());
        }
        let f = Fundamental::from_points(pairs)?;
        let prewarp = Prewarp::new(&f, pairs, (w, h))?;
        let needed = prewarp.disparities.1.ceil() as u32 + 1;
        if needed > max_disparity {
            return Err(MorphError::DisparityRange {
                needed,
                max: max_disparity,
            });
        }
        let pair = Rectified {
            left: prewarp.warp(a, &prewarp.a),
            right: prewarp.warp(b, &prewarp.b),
            // Unknown without cameras.
            baseline: 0.0,
        };
        let (left, right) = stereo(&pair, max_disparity)?;
        // The two inverses agree in scale where the pairs are, on average.
        let mean = |h: &DMat3, of: fn(&(Vec2, Vec2)) -> Vec2| {
            pairs
                .iter()
                .map(|p| apply(h, of(p).as_dvec2()))
                .sum::<DVec2>()
                / pairs.len() as f64
        };
        let middle = ((mean(&prewarp.a, |p| p.0) + mean(&prewarp.b, |p| p.1)) * 0.5).extend(1.0);
        let unit = |h: &DMat3| {
            let inverse = h.inverse();
            let w = (inverse * middle).z;
            if w.abs() > 1e-12 && w.is_finite() {
                Ok(inverse * (1.0 / w))
            } else {
                Err(MorphError::Pairs("the pairs' centre turns to infinity"))
            }
        };
        let postwarp = Postwarp {
            a: unit(&prewarp.a)?,
            b: unit(&prewarp.b)?,
        };
        Ok(ViewMorph {
            width: w,
            height: h,
            from: a.camera,
            to: b.camera,
            pair,
            reach: [forward::row_reach(&left), forward::row_reach(&right)],
            left,
            right,
            postwarp: Some(postwarp),
        })
    }
}

/// The homography `G R T` of an image of `size` sending its epipole `e` to infinity along
/// x; refused when `e` is within [`EPIPOLE_CLEARANCE`] half-diagonals of the centre.
fn to_infinity(e: DVec3, size: DVec2, image: &'static str) -> Result<DMat3, MorphError> {
    let centre = size * 0.5;
    let t = translation(-centre);
    let mut p = t * e;
    // As a line direction: a quarter turn at most, the image stays upright.
    if p.x < 0.0 {
        p = -p;
    }
    let rho = p.truncate().length();
    let half_diagonal = size.length() * 0.5;
    if rho.is_nan() || rho <= EPIPOLE_CLEARANCE * half_diagonal * p.z.abs() {
        let at = if e.z.abs() > 1e-300 {
            e.truncate() / e.z
        } else {
            DVec2::splat(f64::INFINITY)
        };
        return Err(MorphError::EpipoleInImage {
            image,
            x: at.x,
            y: at.y,
        });
    }
    let (c, s) = (p.x / rho, p.y / rho);
    let r = from_rows(&[c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0]);
    let g = from_rows(&[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, -p.z / rho, 0.0, 1.0]);
    Ok(g * r * t)
}

/// `out`'s colour looked up in `image` through `back` (from `out`'s pixels to `image`'s),
/// bilinearly; transparent where it leaves `image` or crosses infinity.
fn sample(out: &mut DepthImage, image: &DepthImage, back: &DMat3) {
    let w = out.width() as usize;
    for (i, c) in out.color.iter_mut().enumerate() {
        let q = DVec3::new((i % w) as f64 + 0.5, (i / w) as f64 + 0.5, 1.0);
        let p = *back * q;
        if p.z.is_nan() || p.z <= 0.0 {
            continue;
        }
        let (u, v) = (p.x / p.z - 0.5, p.y / p.z - 0.5);
        if let Some(color) = bilinear(image, u as f32, v as f32) {
            *c = color;
        }
    }
}

/// `h` applied to the point `p`.
fn apply(h: &DMat3, p: DVec2) -> DVec2 {
    let q = *h * p.extend(1.0);
    q.truncate() / q.z
}

fn translation(by: DVec2) -> DMat3 {
    DMat3::from_cols(DVec3::X, DVec3::Y, by.extend(1.0))
}

/// `[e]_x`: `[e]_x v = e x v`.
fn cross_matrix(e: DVec3) -> DMat3 {
    from_rows(&[0.0, -e.z, e.y, e.z, 0.0, -e.x, -e.y, e.x, 0.0])
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// The smallest and largest of `values`.
fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    })
}

#[cfg(test)]
mod tests;
