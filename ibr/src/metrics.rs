//! Image error of a render against a ground-truth render of the same size: PSNR, mean and
//! largest error, the share of visibly wrong pixels, and where the two disagree on coverage.
//!
//! What is compared: the colour each image stores, as 8-bit values in [0, 255] per RGB
//! channel. For an engine [`Target`] that is [`Target::to_rgba8_premultiplied`]: premultiplied
//! by alpha and in the target's encoding (sRGB for [`Target::new`]), i.e. the image
//! composited over black. For opaque pixels these are the plain 8-bit sRGB colours an image
//! file would hold; for partly transparent ones a missing faint fringe counts as a faint
//! error, not as a full colour difference. Alpha itself only decides coverage.
//!
//! - `mse` is the mean of the squared channel differences over the RGB channels of the
//!   compared pixels, and `psnr_db = 10 log10(255^2 / mse)`: `f64::INFINITY` when the
//!   images are identical there (see [`ImageError::psnr_capped`] for charts and tables).
//!   A constant error of `k` levels on every channel gives `20 log10(255 / k)`.
//! - `mean_abs` is the mean absolute channel difference (levels), `max_abs` the largest.
//! - `frac_over` is the fraction of compared pixels whose largest channel difference
//!   exceeds [`Options::threshold`] levels.
//! - `coverage_mismatch` is the fraction of compared pixels covered in exactly one image,
//!   where "covered" is [`Coverage::Alpha`] (stored alpha above 0: render with a
//!   transparent clear colour) or [`Coverage::Background`] (RGB differs from a known
//!   background colour: opaque clears).
//!
//! The comparison can be restricted to a rectangle or a mask ([`Region`]), e.g. the
//! [`covered_rect`] of both images so an empty background does not dilute the error.
//! Nothing here renders: the functions read images and are exact integer sums up to the
//! final divisions, so their answers can be checked by hand.

pub use crate::core::Rect;
use crate::core::{srgb8, DepthImage};
use engine::Target;
use std::fmt;

mod cover;
pub use cover::{RectCover, RectUnion};

/// Default [`Options::threshold`]: an error of more than 8 levels (about 3%) is visible.
pub const DEFAULT_THRESHOLD: u8 = 8;

/// When a pixel counts as covered (drawn on).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Coverage {
    /// Stored alpha above 0 (images rendered over a transparent clear colour).
    #[default]
    Alpha,
    /// RGB differs from this background colour (8-bit values as compared).
    Background([u8; 3]),
}

/// Which pixels are compared.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Region<'a> {
    /// Every pixel.
    #[default]
    All,
    /// The pixels of a rectangle (clipped to the image).
    Rect(Rect),
    /// The pixels whose entry is `true`: one entry per pixel, row-major, top row first.
    Mask(&'a [bool]),
}

/// How to compare.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options<'a> {
    /// A pixel is "over" when its largest channel difference exceeds this many levels.
    pub threshold: u8,
    /// Which pixels count as covered (for [`ImageError::coverage_mismatch`]).
    pub coverage: Coverage,
    /// Which pixels are compared.
    pub region: Region<'a>,
}

impl Default for Options<'_> {
    fn default() -> Self {
        Options {
            threshold: DEFAULT_THRESHOLD,
            coverage: Coverage::Alpha,
            region: Region::All,
        }
    }
}

/// The error of one image against another over the compared pixels (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageError {
    /// `10 log10(255^2 / mse)`; `f64::INFINITY` when `mse` is 0.
    pub psnr_db: f64,
    /// Mean squared channel difference (levels squared).
    pub mse: f64,
    /// Mean absolute channel difference (levels).
    pub mean_abs: f64,
    /// Largest channel difference (levels).
    pub max_abs: u8,
    /// Fraction of pixels whose largest channel difference exceeds the threshold.
    pub frac_over: f64,
    /// Fraction of pixels covered in exactly one of the two images.
    pub coverage_mismatch: f64,
    /// Pixels compared.
    pub pixels: u64,
}

impl ImageError {
    /// PSNR no higher than `cap_db` (finite for tables and charts when images match).
    pub fn psnr_capped(&self, cap_db: f64) -> f64 {
        self.psnr_db.min(cap_db)
    }

    /// The error over the union of several comparisons' pixels, as if they were one image
    /// (means weighted by pixel count, PSNR from the pooled `mse`, the largest `max_abs`):
    /// e.g. one figure for several views of an object. `None` when there are no pixels.
    pub fn pooled<'a>(errors: impl IntoIterator<Item = &'a ImageError>) -> Option<ImageError> {
        let (mut pixels, mut mse, mut mae, mut over, mut cov) = (0u64, 0.0, 0.0, 0.0, 0.0);
        let mut max_abs = 0u8;
        for e in errors {
            let n = e.pixels as f64;
            pixels += e.pixels;
            mse += e.mse * n;
            mae += e.mean_abs * n;
            over += e.frac_over * n;
            cov += e.coverage_mismatch * n;
            max_abs = max_abs.max(e.max_abs);
        }
        if pixels == 0 {
            return None;
        }
        let n = pixels as f64;
        let mse = mse / n;
        Some(ImageError {
            psnr_db: psnr(mse),
            mse,
            mean_abs: mae / n,
            max_abs,
            frac_over: over / n,
            coverage_mismatch: cov / n,
            pixels,
        })
    }
}

/// `10 log10(255^2 / mse)`, infinite for a zero `mse`.
fn psnr(mse: f64) -> f64 {
    if mse <= 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0f64 * 255.0 / mse).log10()
    }
}

/// Why two images could not be compared.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MetricsError {
    /// The images differ in size.
    SizeMismatch {
        /// Width and height of the first image, pixels.
        a: (u32, u32),
        /// Width and height of the second image, pixels.
        b: (u32, u32),
    },
    /// A raw image's byte count is not `width * height * 4`.
    BufferLength {
        /// Width the image claims, pixels.
        width: u32,
        /// Height the image claims, pixels.
        height: u32,
        /// Bytes it holds.
        len: usize,
    },
    /// A mask's length is not the image's pixel count.
    MaskLength {
        /// The image's pixel count.
        expected: usize,
        /// The mask's entry count.
        len: usize,
    },
    /// No pixel to compare (an empty image, rectangle or mask).
    Empty,
}

impl fmt::Display for MetricsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MetricsError::SizeMismatch { a, b } => write!(
                f,
                "images differ in size: {}x{} against {}x{}",
                a.0, a.1, b.0, b.1
            ),
            MetricsError::BufferLength { width, height, len } => write!(
                f,
                "a {width}x{height} RGBA8 image needs {} bytes, got {len}",
                *width as usize * *height as usize * 4
            ),
            MetricsError::MaskLength { expected, len } => {
                write!(f, "the mask has {len} entries for {expected} pixels")
            }
            MetricsError::Empty => write!(f, "no pixel to compare"),
        }
    }
}

impl std::error::Error for MetricsError {}

/// A borrowed row-major RGBA8 image, top row first (premultiplied, as targets store it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Image<'a> {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// `width * height` RGBA8 pixels, 4 bytes each (premultiplied, as stored; sRGB or linear as
    /// the target's encoding).
    pub rgba: &'a [u8],
}

impl<'a> Image<'a> {
    /// Checks that `rgba` holds `width * height` pixels.
    pub fn new(width: u32, height: u32, rgba: &'a [u8]) -> Result<Self, MetricsError> {
        if rgba.len() != width as usize * height as usize * 4 {
            return Err(MetricsError::BufferLength {
                width,
                height,
                len: rgba.len(),
            });
        }
        Ok(Image {
            width,
            height,
            rgba,
        })
    }

    fn px(&self, x: u32, y: u32) -> [u8; 4] {
        let i = (y as usize * self.width as usize + x as usize) * 4;
        [
            self.rgba[i],
            self.rgba[i + 1],
            self.rgba[i + 2],
            self.rgba[i + 3],
        ]
    }
}

fn covered(c: Coverage, p: [u8; 4]) -> bool {
    match c {
        Coverage::Alpha => p[3] > 0,
        Coverage::Background(bg) => p[..3] != bg,
    }
}

/// The error of `a` against `b` (the reference): two targets of the same size.
pub fn compare(a: &Target, b: &Target, opts: &Options) -> Result<ImageError, MetricsError> {
    if (a.width(), a.height()) != (b.width(), b.height()) {
        return Err(MetricsError::SizeMismatch {
            a: (a.width(), a.height()),
            b: (b.width(), b.height()),
        });
    }
    let (pa, pb) = (a.to_rgba8_premultiplied(), b.to_rgba8_premultiplied());
    compare_rgba8(
        Image::new(a.width(), a.height(), &pa)?,
        Image::new(b.width(), b.height(), &pb)?,
        opts,
    )
}

/// The error of `a` against `b` (the reference) over the smallest rectangle holding what
/// either covers (alpha above 0: render both over a transparent clear colour), so an empty
/// background does not dilute it; the other options default.
pub fn compare_covered(a: &Target, b: &Target) -> Result<ImageError, MetricsError> {
    let area = [a, b]
        .iter()
        .filter_map(|t| covered_rect(t, Coverage::Alpha))
        .fold(Rect::default(), Rect::union);
    let opts = Options {
        region: Region::Rect(area),
        ..Options::default()
    };
    compare(a, b, &opts)
}

/// The error of depth image `view` against `truth` (as 8-bit sRGB) over the pixels both
/// cover (alpha above 0): where they agree something is there, how well it is drawn. And
/// the share of `truth`'s covered pixels `view` covers, which that error leaves out.
pub fn compare_seen(
    view: &DepthImage,
    truth: &DepthImage,
) -> Result<(ImageError, f64), MetricsError> {
    let both: Vec<bool> = view
        .color
        .iter()
        .zip(&truth.color)
        .map(|(v, t)| v.a > 0.0 && t.a > 0.0)
        .collect();
    let (a, b) = (srgb8(view), srgb8(truth));
    let options = Options {
        region: Region::Mask(&both),
        ..Options::default()
    };
    let error = compare_rgba8(
        Image::new(view.width(), view.height(), &a)?,
        Image::new(truth.width(), truth.height(), &b)?,
        &options,
    )?;
    let seen = truth.color.iter().filter(|c| c.a > 0.0).count();
    let covered = both.iter().filter(|b| **b).count() as f64 / seen.max(1) as f64;
    Ok((error, covered))
}

/// The error of raw image `a` against `b` (the reference).
pub fn compare_rgba8(a: Image, b: Image, opts: &Options) -> Result<ImageError, MetricsError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(MetricsError::SizeMismatch {
            a: (a.width, a.height),
            b: (b.width, b.height),
        });
    }
    let (w, h) = (a.width, a.height);
    let full = Rect::new(0, 0, w, h);
    let (rect, mask) = match opts.region {
        Region::All => (full, None),
        Region::Rect(r) => (r.clip(w, h), None),
        Region::Mask(m) => {
            let expected = w as usize * h as usize;
            if m.len() != expected {
                return Err(MetricsError::MaskLength {
                    expected,
                    len: m.len(),
                });
            }
            (full, Some(m))
        }
    };
    let (mut pixels, mut sq, mut abs, mut over, mut mismatch) = (0u64, 0u64, 0u64, 0u64, 0u64);
    let mut max_abs = 0u8;
    for y in rect.y..rect.y + rect.height {
        for x in rect.x..rect.x + rect.width {
            if mask.is_some_and(|m| !m[y as usize * w as usize + x as usize]) {
                continue;
            }
            let (p, q) = (a.px(x, y), b.px(x, y));
            let mut worst = 0u8;
            for c in 0..3 {
                let d = p[c].abs_diff(q[c]);
                worst = worst.max(d);
                abs += d as u64;
                sq += d as u64 * d as u64;
            }
            max_abs = max_abs.max(worst);
            over += (worst > opts.threshold) as u64;
            mismatch += (covered(opts.coverage, p) != covered(opts.coverage, q)) as u64;
            pixels += 1;
        }
    }
    if pixels == 0 {
        return Err(MetricsError::Empty);
    }
    let n = pixels as f64;
    let mse = sq as f64 / (3.0 * n);
    Ok(ImageError {
        psnr_db: if sq == 0 { f64::INFINITY } else { psnr(mse) },
        mse,
        mean_abs: abs as f64 / (3.0 * n),
        max_abs,
        frac_over: over as f64 / n,
        coverage_mismatch: mismatch as f64 / n,
        pixels,
    })
}

/// The bounding rectangle of a target's covered pixels (`None` when nothing is covered).
pub fn covered_rect(t: &Target, coverage: Coverage) -> Option<Rect> {
    let px = t.to_rgba8_premultiplied();
    covered_rect_rgba8(
        Image::new(t.width(), t.height(), &px).expect("a target's own size"),
        coverage,
    )
}

/// The bounding rectangle of a raw image's covered pixels (`None` when nothing is covered).
pub fn covered_rect_rgba8(image: Image, coverage: Coverage) -> Option<Rect> {
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for y in 0..image.height {
        for x in 0..image.width {
            if covered(coverage, image.px(x, y)) {
                x0 = x0.min(x);
                y0 = y0.min(y);
                x1 = x1.max(x + 1);
                y1 = y1.max(y + 1);
            }
        }
    }
    (x1 > x0).then(|| Rect::new(x0, y0, x1 - x0, y1 - y0))
}

#[cfg(test)]
mod tests;
