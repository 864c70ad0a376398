//! Rendering a light slab: each pixel's ray through the `uv` and `st` planes gives
//! continuous sample coordinates `(u, v, s, t)`; the samples around them are blended
//! (nearest, bilinear in `uv`, or quadrilinear) in the stored encoding, each camera read
//! where it saw the ray's surface point when depth correction is on ([`Lookup`]). Pixels
//! whose ray misses either rectangle, points away from the `st` plane, or finds only empty
//! samples are holes; the others take the depth of that surface point (or of the `st`
//! plane, the flat proxy).
//!
//! How: blocks of rows on the thread pool; in each row only the run of pixels whose rays
//! cross the slab (`run`), eight rays at a time (`rays`), looked up as one ray would be
//! in 8-lane arithmetic (`kernel`; depth correction's geometry in `surface`, lane
//! helpers in `lanes`) from raw or quantised samples (`source`). Without depth
//! correction a pixel is bit for bit what one ray at a time in scalar `f32` gives; with
//! it, up to rounding (the projections are rearranged).

mod kernel;
mod lanes;
mod rays;
mod source;
mod surface;

use super::{LightField, Rays, Slab};
use crate::warp::Warped;
use engine::simd::LANES;
use engine::Camera;
use kernel::Kernel;
use rayon::prelude::*;
use source::{CodeSource, RawSource, Source};

/// How the samples around a ray are combined.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// The nearest sample (one tap).
    Nearest,
    /// Bilinear over the four nearest cameras, nearest in `st` (four taps).
    BilinearUv,
    /// Bilinear in both planes (sixteen taps).
    Quadrilinear,
}

/// Relative depth difference within which a camera's sample is taken to be of the same
/// surface point as the ray's.
const SAME_SURFACE: f32 = 0.05;

/// How a render looks the light field up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Lookup {
    /// How many samples around the ray are blended: one, four (bilinear in `uv`) or
    /// sixteen (quadrilinear).
    pub interpolation: Interpolation,
    /// Depth correction (Gortler et al. 96): the ray's point on the surface (found by
    /// marching along the ray through the nearest camera's stored depths, and the other
    /// cameras' around the ray where that finds nothing) is re-projected into each camera
    /// around the ray, so every camera is read where it saw that point, not where the ray
    /// crosses the focal plane; a camera that saw something else there (occluded, or
    /// nothing) is left out and its weight goes to the others. The written depth is that
    /// point's. A ray along which no camera finds a surface is blended uncorrected where
    /// every camera around it sees something at the focal plane (an edge between
    /// samples), else a hole. Without stored depth the focal plane serves.
    pub depth_correction: bool,
}

impl Default for Lookup {
    fn default() -> Self {
        Lookup {
            interpolation: Interpolation::Quadrilinear,
            depth_correction: true,
        }
    }
}

/// The work of one render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LightFieldFrame {
    /// Pixels whose ray crossed both rectangles.
    pub rays: u64,
    /// Samples read.
    pub taps: u64,
    /// Pixels written (rays that found a non-empty sample).
    pub pixels: u64,
}

impl std::ops::AddAssign for LightFieldFrame {
    fn add_assign(&mut self, o: Self) {
        self.rays += o.rays;
        self.taps += o.taps;
        self.pixels += o.pixels;
    }
}

/// Renders `lf` as seen by `camera` into `out` (made `width` x `height`, holes where the
/// light field has no ray), from raw or quantised rays alike. Blocks of rows on the
/// thread pool; the same pixels at any thread count.
pub fn render(
    lf: &LightField,
    camera: &Camera,
    width: u32,
    height: u32,
    lookup: Lookup,
    out: &mut Warped,
) -> LightFieldFrame {
    render_within(lf, camera, width, height, lookup, None, out)
}

/// [`render`], looking up only the rays of each row's batches that overlap its span
/// `spans[y]` (pixels `x0..x1`; none when empty) if given: a caller that keeps only those
/// pixels (the outline from geometry, [`super::outline`]) leaves the rest holes. The
/// batches looked up are looked up as [`render`] does, so those pixels are the same.
pub(crate) fn render_within(
    lf: &LightField,
    camera: &Camera,
    width: u32,
    height: u32,
    lookup: Lookup,
    spans: Option<&[(u32, u32)]>,
    out: &mut Warped,
) -> LightFieldFrame {
    let lookup = Lookup {
        depth_correction: lookup.depth_correction && lf.has_depth(),
        ..lookup
    };
    match &lf.rays {
        Rays::Raw(rays) => {
            let src = RawSource::new(&lf.slab, rays);
            render_from(&lf.slab, &src, (camera, width, height), lookup, spans, out)
        }
        Rays::Quantised(q) => {
            let src = CodeSource::new(q);
            render_from(&lf.slab, &src, (camera, width, height), lookup, spans, out)
        }
    }
}

fn render_from(
    slab: &Slab,
    src: &impl Source,
    (camera, width, height): (&Camera, u32, u32),
    lookup: Lookup,
    spans: Option<&[(u32, u32)]>,
    out: &mut Warped,
) -> LightFieldFrame {
    out.reset(camera, width, height);
    let w = width as usize;
    if w == 0 || height == 0 {
        return LightFieldFrame::default();
    }
    let rays = rays::Rays::new(slab, camera, width, height, lookup.depth_correction);
    let kernel = Kernel::new(slab, src, lookup);
    match lookup.interpolation {
        Interpolation::Nearest => render_rows::<1, 1>(&rays, &kernel, w, spans, out),
        Interpolation::BilinearUv => render_rows::<4, 1>(&rays, &kernel, w, spans, out),
        Interpolation::Quadrilinear => render_rows::<4, 4>(&rays, &kernel, w, spans, out),
    }
}

/// Renders the rows of `out` (`w` wide), blocks of them on the thread pool, each ray
/// read from `CAMERAS` cameras, `TAPS` samples each ([`Kernel::shade`]), within each
/// row's span if `spans` are given ([`render_within`]).
fn render_rows<const CAMERAS: usize, const TAPS: usize>(
    rays: &rays::Rays,
    kernel: &Kernel<'_, impl Source>,
    w: usize,
    spans: Option<&[(u32, u32)]>,
    out: &mut Warped,
) -> LightFieldFrame {
    let block = w * BLOCK_ROWS;
    out.color
        .par_chunks_mut(block)
        .zip(out.disparity.par_chunks_mut(block))
        .enumerate()
        .map(|(b, (colors, disparities))| {
            let mut frame = LightFieldFrame::default();
            let mut guess = None;
            for (r, (colors, disparities)) in colors
                .chunks_mut(w)
                .zip(disparities.chunks_mut(w))
                .enumerate()
            {
                let y = b * BLOCK_ROWS + r;
                // Past the spans' end a row has none.
                let span =
                    spans.map(|s| s.get(y).map_or((0, 0), |&(a, b)| (a as usize, b as usize)));
                if span.is_some_and(|(a, b)| a >= b) {
                    continue;
                }
                guess = render_row::<CAMERAS, TAPS>(
                    rays,
                    kernel,
                    (y, span),
                    guess,
                    colors,
                    disparities,
                    &mut frame,
                );
            }
            frame
        })
        .reduce(LightFieldFrame::default, |mut a, b| {
            a += b;
            a
        })
}

/// Rows a task renders one after another, each looking for its rays that cross the slab
/// where the row before found them.
const BLOCK_ROWS: usize = 8;

/// Renders row `y`, eight pixels at a time, two batches of eight at a time where it can
/// (their depth correction's dependent reads interleave), only the batches overlapping
/// `span` (pixels `x0..x1`, not empty) if given, and returns its run of batches whose
/// rays cross the slab (`run`; `guess`, the row before's, is where it looks).
fn render_row<const CAMERAS: usize, const TAPS: usize>(
    rays: &rays::Rays,
    kernel: &Kernel<'_, impl Source>,
    (y, span): (usize, Option<(usize, usize)>),
    guess: Option<(usize, usize)>,
    colors: &mut [u32],
    disparities: &mut [f32],
    frame: &mut LightFieldFrame,
) -> Option<(usize, usize)> {
    let ends = rays.row(y);
    let w = colors.len();
    // Lanes past the row's end are not hits.
    let within = |x0: usize| (1u32 << (w - x0).min(LANES)) - 1;
    let found = run(w.div_ceil(LANES), guess, |k| {
        rays.hits(ends, k * LANES) & within(k * LANES)
    })?;
    let (lo, hi) = match span {
        Some((x0, x1)) => (found.0.max(x0 / LANES), found.1.min((x1 - 1) / LANES)),
        None => found,
    };
    let mut k = lo;
    while k <= hi {
        let x0 = k * LANES;
        let (a, hits_a) = rays.batch(ends, x0);
        let hits_a = hits_a & within(x0);
        let na = (w - x0).min(LANES);
        if k < hi {
            let (b, hits_b) = rays.batch(ends, x0 + LANES);
            let hits_b = hits_b & within(x0 + LANES);
            let nb = (w - x0 - LANES).min(LANES);
            if hits_a != 0 && hits_b != 0 {
                let (ca, cb) = colors[x0..x0 + na + nb].split_at_mut(na);
                let (da, db) = disparities[x0..x0 + na + nb].split_at_mut(na);
                *frame += kernel.shade::<CAMERAS, TAPS, 2>(
                    [&a, &b],
                    [hits_a, hits_b],
                    [(ca, da), (cb, db)],
                );
                k += 2;
                continue;
            }
        }
        if hits_a != 0 {
            let out = (&mut colors[x0..x0 + na], &mut disparities[x0..x0 + na]);
            *frame += kernel.shade::<CAMERAS, TAPS, 1>([&a], [hits_a], [out]);
        }
        k += 1;
    }
    Some(found)
}

/// The run `lo..=hi` of a row's `n` batches whose rays cross the slab (`hits(k)`, batch
/// `k`'s hits, not 0), if any. A row's rays lie in a plane through the eye (parallel in
/// it, for an orthographic camera); of those looking across the planes from the `uv`
/// side, the ones that cross a convex polygon, or meet a plane beyond their start, are a
/// run of pixels, and so is the intersection of such runs. So the run is found from one
/// batch in it by its ends: the middle of `guess` (the row before's run) if in it, the
/// guess's ends then moved to the run's; else the first batch that hits, along the row,
/// the run's last found by bisection.
fn run(
    n: usize,
    guess: Option<(usize, usize)>,
    hits: impl Fn(usize) -> u32,
) -> Option<(usize, usize)> {
    let hit = |k: usize| hits(k) != 0;
    if let Some((lo, hi)) = guess {
        if hit((lo + hi) / 2) {
            let lo = if hit(lo) {
                (0..lo).rev().take_while(|&k| hit(k)).last().unwrap_or(lo)
            } else {
                (lo + 1..).find(|&k| hit(k)).unwrap_or(lo)
            };
            let hi = if hit(hi) {
                (hi + 1..n).take_while(|&k| hit(k)).last().unwrap_or(hi)
            } else {
                (0..hi).rev().find(|&k| hit(k)).unwrap_or(hi)
            };
            return Some((lo, hi));
        }
    }
    let lo = (0..n).find(|&k| hit(k))?;
    // hit(a), and not hit(b) (or b past the end).
    let (mut a, mut b) = (lo, n);
    while b - a > 1 {
        let m = (a + b) / 2;
        if hit(m) {
            a = m;
        } else {
            b = m;
        }
    }
    Some((lo, a))
}
