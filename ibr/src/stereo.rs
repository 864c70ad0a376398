//! Depth from stereo (issue 16): disparity maps in the Middlebury convention, their
//! error in the Middlebury measures ([`fn@measure`]), rectified pairs rendered with exact
//! ground truth ([`pair`]), a block matcher ([`block`]) and semi-global matching
//! ([`sgm`], coarse to fine), both with left-right checks; unknown pixels filled from the
//! background side and the left view made a depth image for the 3D warp ([`depth`]);
//! pairs from any two cameras rectified first ([`fn@rectify`]); the disparity range to search
//! from depth or a coarse search, and the share of matches at its limit ([`range`]). `bench stereo` measures them
//! against OpenCV's `StereoSGBM` on the same pairs.
//!
//! A disparity map belongs to the left image of a rectified pair: pixel `(x, y)` of the
//! left image shows the point that pixel `(x - d, y)` of the right image shows, `d` in
//! pixels (not negative). Where the disparity is unknown (occluded, mismatched, or never
//! measured) it is `f32::INFINITY`, as in Middlebury's PFM files, which is how it is read
//! and written ([`Disparity::from_float_image`], [`Disparity::to_float_image`], with
//! `engine::load::float_image` and `write_float_image`).

pub mod block;
pub mod depth;
pub mod measure;
pub mod pair;
pub mod range;
pub mod rectify;
pub mod sgm;

#[cfg(test)]
pub(crate) mod scenes;

pub use block::{luminance, luminance_rgba8, BlockMatch};
pub use measure::{measure, DisparityError, Measured};
pub use pair::StereoPair;
pub use rectify::{inside_original, rectify, rectify_with, Framing, Rectified, RectifyError};
pub use sgm::{Sgm, SgmBuffers};

use engine::load::FloatImage;

/// A left image's disparities, row-major, top row first; infinite where unknown.
#[derive(Clone, Debug, PartialEq)]
pub struct Disparity {
    /// Columns, the left image's width in pixels.
    pub width: u32,
    /// Rows, the left image's height in pixels.
    pub height: u32,
    /// `width * height` disparities in pixels, row-major from the top: left pixel
    /// `(x, y)` matches right pixel `(x - d, y)`; `f32::INFINITY` where unknown.
    pub data: Vec<f32>,
}

/// Why a disparity map or a comparison is refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum StereoError {
    /// A map or image holds a number of values other than `width * height`.
    #[error("{what}: {found} values for a {width} x {height} map")]
    Size {
        /// Which map or image, in words.
        what: &'static str,
        /// Values found.
        found: usize,
        /// The map's width, pixels.
        width: u32,
        /// The map's height, pixels.
        height: u32,
    },
    #[error("{what}: a disparity at ({x}, {y}) is {value}: disparities are finite and not negative, or infinite where unknown")]
    /// A disparity is negative, NaN or `-inf` (only `+inf` may stand for unknown).
    Value {
        /// Which map, in words.
        what: &'static str,
        /// The pixel's column.
        x: u32,
        /// The pixel's row, from the top.
        y: u32,
        /// The value found.
        value: f32,
    },
    /// Estimate and ground truth differ in size: the estimate's width and height, then
    /// the truth's.
    #[error("the estimate is {0} x {1} and the ground truth {2} x {3}")]
    Mismatch(u32, u32, u32, u32),
}

impl Disparity {
    /// A map, checked: `width * height` values, each finite and not negative, or
    /// `+infinity` (unknown).
    pub fn new(width: u32, height: u32, data: Vec<f32>) -> Result<Self, StereoError> {
        Self::checked("disparity map", width, height, data)
    }

    fn checked(
        what: &'static str,
        width: u32,
        height: u32,
        data: Vec<f32>,
    ) -> Result<Self, StereoError> {
        if data.len() as u64 != u64::from(width) * u64::from(height) {
            return Err(StereoError::Size {
                what,
                found: data.len(),
                width,
                height,
            });
        }
        if let Some(i) = data
            .iter()
            .position(|&d| !(d == f32::INFINITY || (d.is_finite() && d >= 0.0)))
        {
            let w = width.max(1) as usize;
            return Err(StereoError::Value {
                what,
                x: (i % w) as u32,
                y: (i / w) as u32,
                value: data[i],
            });
        }
        Ok(Disparity {
            width,
            height,
            data,
        })
    }

    /// A map read from a float image (a Middlebury PFM), checked as [`Disparity::new`].
    pub fn from_float_image(image: FloatImage) -> Result<Self, StereoError> {
        Self::checked("disparity image", image.width, image.height, image.data)
    }

    /// The map as a float image, to write as PFM (infinity where unknown).
    pub fn to_float_image(&self) -> FloatImage {
        FloatImage {
            width: self.width,
            height: self.height,
            data: self.data.clone(),
        }
    }

    /// Checks a matcher's inputs: two luminance images of `width x height`; `Ok(None)` when
    /// they are empty (the answer is an empty map).
    pub(crate) fn inputs(
        left: &[f32],
        right: &[f32],
        width: u32,
        height: u32,
    ) -> Result<Option<Disparity>, StereoError> {
        let n = u64::from(width) * u64::from(height);
        for (what, image) in [("left image", left), ("right image", right)] {
            if image.len() as u64 != n {
                return Err(StereoError::Size {
                    what,
                    found: image.len(),
                    width,
                    height,
                });
            }
        }
        Ok((n == 0).then(|| Disparity {
            width,
            height,
            data: Vec::new(),
        }))
    }

    /// Whether pixel `i` (row-major) has a known disparity.
    pub fn known(&self, i: usize) -> bool {
        self.data.get(i).is_some_and(|d| d.is_finite())
    }
}
