//! The Middlebury stereo measures (Scharstein and Szeliski; the v3 evaluation's `bad 1.0`,
//! `bad 2.0` and `rms`) of an estimated disparity map against the ground truth, over the
//! pixels not occluded in the right image and over all pixels.
//!
//! Evaluated pixels are those whose ground truth is known (and, for the non-occluded
//! figures, that the mask marks visible). A pixel is bad at threshold `t` when its
//! estimate is off by more than `t` pixels, or unknown: an estimate that leaves a pixel
//! unknown does not escape the count. `rms` is over the evaluated pixels the estimate
//! knows; `unknown` says what share it left unknown.

use super::{Disparity, StereoError};

/// The error over one set of pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DisparityError {
    /// Pixels evaluated (ground truth known, in the set).
    pub pixels: u64,
    /// Share of them (0 to 1) off by more than 1 pixel, or unknown.
    pub bad1: f64,
    /// Share of them (0 to 1) off by more than 2 pixels, or unknown.
    pub bad2: f64,
    /// Root mean square error over the evaluated pixels the estimate knows (pixels).
    pub rms: f64,
    /// Share of the evaluated pixels the estimate left unknown.
    pub unknown: f64,
}

/// The error over the non-occluded pixels and over all pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Measured {
    /// Over the left pixels the right image also sees.
    pub nonocc: DisparityError,
    /// Over every left pixel with a known true disparity.
    pub all: DisparityError,
}

/// Measures `estimate` against `truth`; `visible` marks the pixels of the left image
/// visible in the right one (the non-occluded set; `None`: all).
pub fn measure(
    estimate: &Disparity,
    truth: &Disparity,
    visible: Option<&[bool]>,
) -> Result<Measured, StereoError> {
    if (estimate.width, estimate.height) != (truth.width, truth.height) {
        return Err(StereoError::Mismatch(
            estimate.width,
            estimate.height,
            truth.width,
            truth.height,
        ));
    }
    if let Some(v) = visible {
        if v.len() != truth.data.len() {
            return Err(StereoError::Size {
                what: "visibility mask",
                found: v.len(),
                width: truth.width,
                height: truth.height,
            });
        }
    }
    let (mut nonocc, mut all) = (Sums::default(), Sums::default());
    for (i, (&e, &t)) in estimate.data.iter().zip(&truth.data).enumerate() {
        if !t.is_finite() {
            continue;
        }
        all.add(e, t);
        if visible.is_none_or(|v| v[i]) {
            nonocc.add(e, t);
        }
    }
    Ok(Measured {
        nonocc: nonocc.error(),
        all: all.error(),
    })
}

/// Running counts over one set of pixels.
#[derive(Default)]
struct Sums {
    pixels: u64,
    bad1: u64,
    bad2: u64,
    unknown: u64,
    known: u64,
    squares: f64,
}

impl Sums {
    fn add(&mut self, estimate: f32, truth: f32) {
        self.pixels += 1;
        if !estimate.is_finite() {
            self.unknown += 1;
            self.bad1 += 1;
            self.bad2 += 1;
            return;
        }
        let off = (f64::from(estimate) - f64::from(truth)).abs();
        self.bad1 += u64::from(off > 1.0);
        self.bad2 += u64::from(off > 2.0);
        self.known += 1;
        self.squares += off * off;
    }

    fn error(&self) -> DisparityError {
        let share = |k: u64| k as f64 / self.pixels.max(1) as f64;
        DisparityError {
            pixels: self.pixels,
            bad1: share(self.bad1),
            bad2: share(self.bad2),
            rms: (self.squares / self.known.max(1) as f64).sqrt(),
            unknown: share(self.unknown),
        }
    }
}

#[cfg(test)]
mod tests;
