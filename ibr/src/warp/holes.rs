//! Holes in a warped image: counted by kind, and filled without dragging foreground colour
//! across a depth edge, nor past the warped surfaces' footprint.
//!
//! - An **unseen** pixel is no hole: nothing landed there and its ray stays in space the
//!   references saw empty, or saw not at all (the background beyond their coverage;
//!   [`seen`]). It stays empty (alpha 0, infinite depth), is counted apart, and no fill
//!   writes it.
//! - A **crack** is a hole between samples of one surface (foreshortening, rounding): within
//!   [`CRACK_REACH`] pixels on two opposite sides there are samples of similar depth.
//! - A **disocclusion** is any other hole: a surface no reference saw, beside a depth edge
//!   or where the references end.
//!
//! Filling ([`Fill`]): pull-push (Gortler et al. 96) with the weights normalised as Kraus
//! 2009 does (sums of weighted colour and weight, weight capped at one per cell), where a
//! coarse cell keeps only its **farthest** samples (within the edge tolerance of the
//! farthest), so a disocclusion is filled from the background; or the background side
//! directly: the farthest of the nearest samples left, right, up and down. Filled pixels
//! take the depth of what filled them, so depth tests against geometry still work.
//!
//! Depth is read as the warp stores it, as disparity: "farther than `d` by more than a
//! relative `edge`" is `δ (1 - edge) > δ'`-style comparisons, exact equivalents of the depth
//! ones. Pull-push (`pull_push`) averages the stored bytes (sRGB-encoded, premultiplied)
//! and runs row by row on the thread pool; the pixels it gives do not depend on the thread
//! count.

mod background;
mod pull_push;
pub mod seen;

use super::on_pool;
use super::warped::{Warped, HOLE};
use rayon::prelude::*;

/// How far (pixels) a crack's two sides may be apart.
pub const CRACK_REACH: u32 = 2;

/// Holes by kind, and the empty pixels apart.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct HoleStats {
    /// Holes with samples of similar depth within [`CRACK_REACH`] pixels on two opposite
    /// sides (one surface torn by foreshortening or rounding), in pixels.
    pub cracks: u64,
    /// Every other hole (a surface no reference saw, beside a depth edge or where the
    /// references end), in pixels.
    pub disocclusions: u64,
    /// Pixels nothing landed on that no reference saw anything at (not holes: left empty).
    pub unseen: u64,
}

impl HoleStats {
    /// The holes (cracks and disocclusions; unseen pixels are not holes).
    pub fn total(&self) -> u64 {
        self.cracks + self.disocclusions
    }
}

/// How holes are filled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fill {
    /// Left as holes.
    None,
    /// Depth-aware pull-push.
    PullPush,
    /// The background side: the farthest of the nearest samples in the four directions.
    Background,
}

/// Whether two disparities are of one surface: depths within a relative `edge` of each
/// other (`|z_a - z_b| <= edge min(z)` is `|δ_a - δ_b| <= edge min(δ)`).
#[inline]
fn similar(a: f32, b: f32, edge: f32) -> bool {
    a == b || (a - b).abs() <= edge * a.min(b)
}

/// Counts the holes of a warped image by kind; `edge` is the relative depth difference
/// that separates surfaces. Every pixel nothing landed on is a hole.
pub fn classify(image: &Warped, edge: f32) -> HoleStats {
    classify_seen(image, edge, &[])
}

/// [`classify`], with the pixels `unseen` marks ([`seen::mark_unseen`]; empty: none)
/// counted apart as [`HoleStats::unseen`].
pub fn classify_seen(image: &Warped, edge: f32, unseen: &[bool]) -> HoleStats {
    let (w, h) = (image.width(), image.height());
    let sample = |x: i64, y: i64| -> Option<f32> {
        if x < 0 || y < 0 || x >= w as i64 || y >= h as i64 {
            return None;
        }
        let d = image.disparity[(y as u32 * w + x as u32) as usize];
        (d >= 0.0).then_some(d)
    };
    // The nearest sample within reach from (x, y) along (dx, dy).
    let seek = |x: u32, y: u32, dx: i64, dy: i64| {
        (1..=CRACK_REACH as i64).find_map(|s| sample(x as i64 + dx * s, y as i64 + dy * s))
    };
    (0..h)
        .into_par_iter()
        .map(|y| {
            let mut stats = HoleStats::default();
            for x in 0..w {
                let i = (y * w + x) as usize;
                if image.disparity[i] >= 0.0 {
                    continue;
                }
                if unseen.get(i) == Some(&true) {
                    stats.unseen += 1;
                    continue;
                }
                let pair = |d: (i64, i64)| match (seek(x, y, d.0, d.1), seek(x, y, -d.0, -d.1)) {
                    (Some(a), Some(b)) => similar(a, b, edge),
                    _ => false,
                };
                if pair((1, 0)) || pair((0, 1)) || pair((1, 1)) || pair((1, -1)) {
                    stats.cracks += 1;
                } else {
                    stats.disocclusions += 1;
                }
            }
            stats
        })
        .reduce(HoleStats::default, |a, b| HoleStats {
            cracks: a.cracks + b.cracks,
            disocclusions: a.disocclusions + b.disocclusions,
            unseen: a.unseen + b.unseen,
        })
}

/// What a fill did: the holes it filled and those it left (none to fill them from, or
/// [`Fill::None`]; unseen pixels too), so that the filled image's samples are known
/// without a count.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Filled {
    /// Hole pixels given a colour and depth.
    pub filled: u64,
    /// Pixels left empty: holes with nothing to fill them from, every hole under
    /// [`Fill::None`], and unseen pixels.
    pub left: u64,
}

/// Scratch memory of the fill, reused frame to frame.
#[derive(Debug, Default)]
pub struct Filler {
    /// Levels 1, 2, ... of the pyramid (level 0 is the image).
    levels: Vec<pull_push::Level>,
    /// The background fill's planes.
    background: background::Background,
}

impl Filler {
    /// Fills the holes of `image` by `fill`; `edge` is the relative depth difference that
    /// separates surfaces.
    pub fn fill(&mut self, image: &mut Warped, fill: Fill, edge: f32) -> Filled {
        let (filled, holes) = match fill {
            Fill::None => (0, image.disparity.len() as u64 - image.filled()),
            Fill::PullPush => on_pool(|| pull_push::fill(image, &mut self.levels, edge)),
            Fill::Background => on_pool(|| self.background.fill(image)),
        };
        Filled {
            filled,
            left: holes - filled,
        }
    }

    /// [`Filler::fill`], leaving the pixels `unseen` marks ([`seen::mark_unseen`]; empty:
    /// none) empty: the fill reads the image's samples as before and writes only holes.
    pub fn fill_seen(
        &mut self,
        image: &mut Warped,
        fill: Fill,
        edge: f32,
        unseen: &[bool],
    ) -> Filled {
        let mut done = self.fill(image, fill, edge);
        if fill == Fill::None || unseen.is_empty() {
            return done;
        }
        let w = image.width().max(1) as usize;
        let cleared: u64 = on_pool(|| {
            image
                .color
                .par_chunks_mut(w)
                .zip(image.disparity.par_chunks_mut(w))
                .zip(unseen.par_chunks(w))
                .map(|((color, disparity), unseen)| {
                    let mut n = 0u64;
                    for ((c, d), &u) in color.iter_mut().zip(disparity).zip(unseen) {
                        if u && *d >= 0.0 {
                            (*c, *d) = (0, HOLE);
                            n += 1;
                        }
                    }
                    n
                })
                .sum()
        });
        done.filled -= cleared;
        done.left += cleared;
        done
    }
}
