//! The warped portals' pixels kept inside their openings: holes counted and samples copied
//! row by row over each outline's span.

use super::Outline;
use crate::warp::Warped;

/// Holes of `image` (the outline's rectangle) inside `outline` (before filling), and the
/// pixels inside it.
pub(super) fn holes_inside(image: &Warped, outline: &Outline) -> (u64, u64) {
    let w = image.width() as usize;
    let [x0, y0, _, y1] = outline.bounds;
    (y0..y1)
        .map(|y| {
            let (a, b) = outline.span(y);
            let row = (y - y0) as usize * w;
            let span = row + (a - x0) as usize..row + (b - x0) as usize;
            let n = span.len() as u64;
            let holes = image.disparity[span]
                .iter()
                .filter(|&&d| d.is_nan() || d < 0.0)
                .count() as u64;
            (holes, n)
        })
        .fold((0, 0), |(h, n), (a, b)| (h + a, n + b))
}

/// Copies the pixels of `from` (the outline's rectangle) inside `outline` into `into` (the
/// frame; tinted green if asked); returns the filled pixels copied.
pub(super) fn clip_into(into: &mut Warped, from: &Warped, outline: &Outline, tint: bool) -> u64 {
    let (w, fw) = (into.width() as usize, from.width() as usize);
    let [x0, y0, _, y1] = outline.bounds;
    let mut copied = 0;
    for y in y0..y1 {
        let (a, b) = outline.span(y);
        let (i0, j0) = (y as usize * w, (y - y0) as usize * fw);
        for x in a as usize..b as usize {
            let (i, j) = (i0 + x, j0 + x - x0 as usize);
            if from.is_filled(j) {
                let c = from.color[j];
                into.color[i] = if tint { tinted(c) } else { c };
                into.disparity[i] = from.disparity[j];
                copied += 1;
            }
        }
    }
    copied
}

/// A packed colour pushed toward green.
fn tinted(c: u32) -> u32 {
    let [r, g, b, a] = c.to_le_bytes();
    u32::from_le_bytes([r / 2, g / 2 + a / 2, b / 2, a])
}
