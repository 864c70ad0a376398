//! The morph between two parallel views, row by row: each image's pixels moved along
//! their row by their disparity to the in-between eye, neighbours on one surface (within a
//! pixel of disparity) joined so no crack opens, folds resolved by disparity, colours
//! cross-dissolved where the other image sees the same point, and what neither image
//! reaches filled from the farther side of the row (at the row's ends, from the surface
//! beside it).

use super::{scaled, sum, MorphStats};
use crate::core::{DepthImage, EMPTY};
use crate::stereo::{Disparity, Rectified};
use engine::color::Premul;
use engine::Camera;
use rayon::prelude::*;
use std::ops::Range;
use std::time::Duration;

/// Disparities within this many pixels are one surface.
const SAME: f32 = 1.0;

/// One source image of the morph, as a row reads it.
struct Source<'a> {
    color: &'a [Premul],
    disparity: &'a [f32],
    /// The other image, and its disparities: for the cross-dissolve.
    other: &'a [Premul],
    other_disparity: &'a [f32],
    /// Where a pixel of disparity `d` at `x + 0.5` lands: `x + 0.5 + shift d`.
    shift: f32,
    /// Where the other image sees it: `x + 0.5 + other_shift d`.
    other_shift: f32,
    /// The weight of this image's colour in the dissolve.
    weight: f32,
}

/// A row of the in-between view: colour, disparity (negative: empty) and whether it came
/// from the second image. The last two are a worker's buffers, kept from row to row: only
/// the columns a row's maps look at are set empty first (the maps, the fill and the depths
/// read no others; a row mapped out to its ends is set empty whole).
struct Row<'a> {
    color: &'a mut [Premul],
    disparity: &'a mut [f32],
    from_right: &'a mut [bool],
}

impl<'a> Source<'a> {
    /// The left and the right image's rows (colours and disparities) as sources of the
    /// view a fraction `s` from the left: left pixel x lands at x - s d, right pixel x at
    /// x + (1 - s) d.
    fn pair(
        (lrow, ld): (&'a [Premul], &'a [f32]),
        (rrow, rd): (&'a [Premul], &'a [f32]),
        s: f32,
    ) -> (Self, Self) {
        let from_left = Source {
            color: lrow,
            disparity: ld,
            other: rrow,
            other_disparity: rd,
            shift: -s,
            other_shift: -1.0,
            weight: 1.0 - s,
        };
        let from_right = Source {
            color: rrow,
            disparity: rd,
            other: lrow,
            other_disparity: ld,
            shift: 1.0 - s,
            other_shift: 1.0,
            weight: s,
        };
        (from_left, from_right)
    }

    /// Maps this image's row into `row`, the pixels in `window` only: `first` paints every
    /// pixel nearer than what is there; the second image (`!first`) only pixels left empty
    /// or nearer by more than a pixel of disparity. Each pixel of `window` is painted as
    /// the whole row's map paints it (the same sources, in the same order); the sources
    /// that cannot reach it are skipped (a pixel moved left by `shift <= 0` lands before
    /// `x + 2`, one moved right at or after `x`), and so are those that would have to move
    /// farther than the row's largest disparity `reach` takes them: a pixel moves by
    /// `|shift| d <= |shift| reach`, and its span ends within two pixels of where it
    /// lands. Returns the source pixels looked at (a work counter).
    fn map(&self, row: &mut Row, first: bool, window: Range<usize>, reach: f32) -> usize {
        let w = self.color.len();
        let at = |x: usize, d: f32| x as f32 + 0.5 + self.shift * d;
        // Three pixels to spare past the farthest move (rounding of the positions).
        let moved = (self.shift.abs() * reach).ceil().min(w as f32) as usize + 3;
        let sources = if self.shift <= 0.0 {
            window.start.saturating_sub(2)..(window.end + moved).min(w)
        } else {
            window.start.saturating_sub(moved)..window.end.min(w)
        };
        let looked = sources.len();
        let (first_px, end_px) = (window.start as f32, window.end as f32);
        for x in sources {
            let d = self.disparity[x];
            if !d.is_finite() {
                continue;
            }
            let from = at(x, d);
            // Joined to the next pixel when on the same surface and not folded over it.
            let to = match self.disparity.get(x + 1) {
                Some(&d1) if d1.is_finite() && (d1 - d).abs() <= SAME && at(x + 1, d1) > from => {
                    at(x + 1, d1)
                }
                _ => from.floor() + 1.0,
            };
            let (lo, hi) = (from.floor().max(first_px), to.floor().min(end_px));
            if lo >= hi {
                continue;
            }
            // Dissolved once, when the first pixel is painted: the second image paints
            // only what the first left empty or hid, and most of its pixels paint none.
            let mut color = None;
            for t in lo as usize..hi as usize {
                let there = row.disparity[t];
                let paint = if first {
                    there < 0.0 || d > there
                } else {
                    there < 0.0 || d > there + SAME
                };
                if paint {
                    row.color[t] = *color.get_or_insert_with(|| self.dissolved(x, d));
                    row.disparity[t] = d;
                    row.from_right[t] = !first;
                }
            }
        }
        looked
    }

    /// Pixel `x`'s colour, dissolved with the other image's where it sees the same point.
    fn dissolved(&self, x: usize, d: f32) -> Premul {
        let c = self.color[x];
        let ox = x as f32 + 0.5 + self.other_shift * d;
        let seen = (ox >= 0.0 && (ox as usize) < self.other.len())
            .then_some(ox as usize)
            .filter(|&o| (self.other_disparity[o] - d).abs() <= SAME);
        match seen {
            Some(o) => sum(
                scaled(c, self.weight),
                scaled(self.other[o], 1.0 - self.weight),
            ),
            None => c,
        }
    }
}

/// What a pixel of the parallel in-between view is made of, as one-hot colours so the
/// postwarp carries it to the output as it carries the view ([`Made::count`]): red from
/// the left image, green from the right only, blue filled, each as opaque as the pixel;
/// transparent where nothing.
pub(super) struct Made;

impl Made {
    const LEFT: Premul = Premul {
        r: 1.0,
        g: 0.0,
        b: 0.0,
        a: 1.0,
    };
    const RIGHT: Premul = Premul {
        r: 0.0,
        g: 1.0,
        b: 0.0,
        a: 1.0,
    };
    const FILLED: Premul = Premul {
        r: 0.0,
        g: 0.0,
        b: 1.0,
        a: 1.0,
    };

    /// Labels the pixels of `row` mapped from an image by that image.
    fn mapped(made: &mut [Premul], row: &Row) {
        for (t, &d) in row.disparity.iter().enumerate() {
            if d >= 0.0 {
                made[t] = if row.from_right[t] {
                    Made::RIGHT
                } else {
                    Made::LEFT
                };
            }
        }
    }

    /// Labels the pixels of `row` filled since [`Made::mapped`] as filled, and every label
    /// as opaque as its pixel, so the postwarp covers the same pixels with both.
    fn filled(made: &mut [Premul], row: &Row) {
        for (t, &d) in row.disparity.iter().enumerate() {
            if d >= 0.0 && made[t].a <= 0.0 {
                made[t] = Made::FILLED;
            }
            made[t] = scaled(made[t], row.color[t].a);
        }
    }

    /// The counts of a resampled image of these labels: each pixel at least half covered
    /// counted by its largest share. Pixels nothing reached count nowhere.
    pub(super) fn count(labels: &DepthImage) -> MorphStats {
        let mut stats = MorphStats::default();
        for c in &labels.color {
            if c.a < 0.5 {
                continue;
            }
            if c.r >= c.g && c.r >= c.b {
                stats.from_left += 1;
            } else if c.g >= c.b {
                stats.from_right += 1;
            } else {
                stats.holes += 1;
            }
        }
        stats
    }
}

/// The largest finite disparity of each row of `d` (0 where there is none): how far a
/// pixel of that row can move, so [`Source::map`] skips the pixels that cannot reach the
/// columns it paints. Made once for a morph's pair, not a frame.
pub(super) fn row_reach(d: &Disparity) -> Vec<f32> {
    let w = d.width.max(1) as usize;
    d.data
        .chunks(w)
        .map(|row| (row.iter().filter(|v| v.is_finite())).fold(0.0f32, |m, &v| m.max(v.abs())))
        .collect()
}

/// Columns morphed beyond each side of the columns asked for, a 64th of the canvas's
/// width and two more: a run of empty pixels that reaches into the columns asked for is
/// filled from its ends, which must lie within the columns morphed, or the row is morphed
/// again out to its end on that side ([`crosses`]). (A hole is as wide as a difference of disparities, which
/// grows with the canvas's width.)
fn margin(w: usize) -> usize {
    2 + w / 64
}

/// The parallel in-between view a fraction `s` from the left view of `pair` to its right,
/// seen by `camera` (its depth from the disparities), and what each pixel is made of
/// ([`Made`]) when `labels` is set (counting is a figure: showing the view skips it): the
/// rows in `rows` only (each row is morphed on its own), the others left empty; of those
/// rows, the pixels in `cols` as the whole row's morph makes them (the columns about
/// them, [`margin`] to each side, morphed; out to the row's end where a hole runs past
/// those),
/// the others left empty or holding what is not read (every column with `labels`). Into
/// `out`, kept from frame to frame (made the pair's size when it is not; every pixel
/// written): the canvas, twice the frame's pixels, is not allocated again each frame.
/// `written` holds, per row, the columns the last morph into `out` may have written
/// (the rest of the row is empty): only those are cleared, and it is set to this morph's
/// (at 1280x720 about 1.1 M of the canvas's 2.0 M pixels a frame, all cleared before).
/// `reach` is [`row_reach`] of `left` and of `right`. Without `with_depth` the canvas's
/// depths are left empty (its colours are the same): a view shown as colour only needs none.
/// `depth_empty` says whether every depth of `out` is empty (made so, or by a morph without
/// depth): then a morph without depth writes none (session 19: it cleared the last
/// morph's columns' depths, 5.4 MB at 1280x720); it is set for the next morph.
/// A pixel of a row's columns is written once (session 19): painted, filled, or made
/// transparent after the fill where neither reached it; only the last morph's columns
/// outside this one's are cleared first (until then every column the last morph wrote was
/// cleared, then most were painted again: 22 MB a frame at 1280x720).
/// Returns the labels, the canvas pixels morphed, the source pixels the maps looked at and
/// the canvas pixels cleared before the maps (work counters).
#[allow(clippy::too_many_arguments)]
pub(super) fn morph(
    pair: &Rectified,
    (left, right): (&Disparity, &Disparity),
    reach: [&[f32]; 2],
    s: f32,
    camera: Camera,
    (rows, cols): (Range<usize>, Range<usize>),
    (labels, with_depth): (bool, bool),
    (out, written, depth_empty): (&mut DepthImage, &mut Vec<Range<usize>>, &mut bool),
) -> (Option<DepthImage>, u64, u64, u64) {
    let (w, h) = (pair.left.width() as usize, pair.left.height() as usize);
    if (out.width() as usize, out.height() as usize) != (w, h) || written.len() != h {
        *out = DepthImage::new(w as u32, h as u32, camera);
        written.clear();
        written.resize(h, 0..0);
        *depth_empty = true;
    }
    // Depths to clear or write: none when they are all empty and none are made.
    let depths = with_depth || !*depth_empty;
    *depth_empty = !with_depth;
    out.camera = camera;
    let mut made = labels.then(|| DepthImage::new(w as u32, h as u32, camera));
    if w == 0 || h == 0 {
        return (made, 0, 0, 0);
    }
    let cols = if labels {
        0..w
    } else {
        cols.start.min(w)..cols.end.min(w)
    };
    let window = cols.start.saturating_sub(margin(w))..(cols.end + margin(w)).min(w);
    let mut made_rows: Vec<Option<&mut [Premul]>> = match made.as_mut() {
        Some(m) => m.color.chunks_mut(w).map(Some).collect(),
        None => (0..h).map(|_| None).collect(),
    };
    // Disparity to depth: d = f b / z for the pair's baseline.
    let focal = camera.projection.gl_matrix().x_axis.x * 0.5 * w as f32;
    let depth_of = |d: f32| focal * pair.baseline / d;
    let (lc, rc) = (&pair.left.color, &pair.right.color);
    let (morphed, looked, cleared) = out
        .color
        .par_chunks_mut(w)
        .zip(out.depth.par_chunks_mut(w))
        .zip(made_rows.par_iter_mut())
        .zip(written.par_iter_mut())
        .enumerate()
        .map_init(
            || (vec![-1.0f32; w], vec![false; w]),
            |(disparity, from_right), (y, (((color, depth), made), written))| {
                // The last morph's columns outside this one's window (the window's own
                // are each written below); all of them in a row not morphed now.
                let keep = if rows.contains(&y) {
                    window.clone()
                } else {
                    0..0
                };
                let cleared = clear_outside((color, depth, depths), written, &keep);
                *written = 0..0;
                if !rows.contains(&y) {
                    return (0, 0, cleared);
                }
                let span = y * w..(y + 1) * w;
                let (ld, rd) = (&left.data[span.clone()], &right.data[span.clone()]);
                let (lrow, rrow) = (&lc[span.clone()], &rc[span]);
                disparity[window.clone()].fill(-1.0);
                from_right[window.clone()].fill(false);
                let mut row = Row {
                    color,
                    disparity,
                    from_right,
                };
                let (from_left, from_right) = Source::pair((lrow, ld), (rrow, rd), s);
                let (lr, rr) = (reach[0][y], reach[1][y]);
                let mut looked = from_left.map(&mut row, true, window.clone(), lr)
                    + from_right.map(&mut row, false, window.clone(), rr);
                let window = match crosses(row.disparity, &window, &cols) {
                    Some(wider) => {
                        // The whole row: what the first map wrote is cleared too.
                        row.color.fill(Premul::TRANSPARENT);
                        row.disparity.fill(-1.0);
                        row.from_right.fill(false);
                        looked += from_left.map(&mut row, true, wider.clone(), lr)
                            + from_right.map(&mut row, false, wider.clone(), rr);
                        wider
                    }
                    None => window.clone(),
                };
                // Each map paints within its window; the fill and the depths below too.
                *written = window.clone();
                if let Some(made) = made.as_deref_mut() {
                    Made::mapped(made, &row);
                }
                fill_from_farther(&mut row, window.clone());
                clear_unreached(&mut row, window.clone());
                if let Some(made) = made.as_deref_mut() {
                    Made::filled(made, &row);
                }
                if depths {
                    let depth_of = |d: f32| (with_depth && d > 0.0).then(|| depth_of(d));
                    write_depths(
                        &mut depth[window.clone()],
                        &row.disparity[window.clone()],
                        depth_of,
                    );
                }
                (window.len() as u64, looked as u64, cleared)
            },
        )
        .reduce(|| (0, 0, 0), |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2));
    (made, morphed, looked, cleared)
}

/// Clears a canvas row's pixels (`color`, and `depth` when `depths`) of the last morph's
/// columns `written` outside `keep` (the columns this morph writes); returns how many.
fn clear_outside(
    (color, depth, depths): (&mut [Premul], &mut [f32], bool),
    written: &Range<usize>,
    keep: &Range<usize>,
) -> u64 {
    let mut cleared = 0;
    for span in outside(written, keep) {
        cleared += span.len() as u64;
        color[span.clone()].fill(Premul::TRANSPARENT);
        if depths {
            depth[span].fill(EMPTY);
        }
    }
    cleared
}

/// The pixels of `row` in `window` that neither image nor the fill reached made
/// transparent: their colour is a frame before's ([`morph`] writes each pixel once).
fn clear_unreached(row: &mut Row, window: Range<usize>) {
    let colors = row.color[window.clone()].iter_mut();
    for (c, &d) in colors.zip(&row.disparity[window]) {
        if d < 0.0 {
            *c = Premul::TRANSPARENT;
        }
    }
}

/// Each depth of `depth` from its pixel's disparity (`depth_of`, `None`: empty).
fn write_depths(depth: &mut [f32], disparity: &[f32], depth_of: impl Fn(f32) -> Option<f32>) {
    for (z, &d) in depth.iter_mut().zip(disparity) {
        *z = depth_of(d).unwrap_or(EMPTY);
    }
}

/// The parts of `span` outside `keep` (before it and after it).
fn outside(span: &Range<usize>, keep: &Range<usize>) -> [Range<usize>; 2] {
    if keep.is_empty() {
        return [span.clone(), 0..0];
    }
    [
        span.start..span.end.min(keep.start).max(span.start),
        span.start.max(keep.end)..span.end.max(span.start.max(keep.end)),
    ]
}

/// Whether a run of empty pixels of a row mapped over `window` (its `disparity`, negative:
/// empty) reaches both into `cols` and to an end of `window` short of the row's end: then
/// where it ends, which its fill is taken from, is not known within `window`. If so, the
/// window to map instead: `window` carried to the row's end on each such side (the pixels
/// on the other side are as before, so it needs no second look).
fn crosses(disparity: &[f32], window: &Range<usize>, cols: &Range<usize>) -> Option<Range<usize>> {
    let w = disparity.len();
    let empty = |t: usize| disparity[t] < 0.0;
    if window.is_empty() {
        return (!cols.is_empty()).then_some(0..w);
    }
    let open_before = window.start > 0 && empty(window.start) && {
        let end = window.clone().find(|&t| !empty(t)).unwrap_or(window.end);
        end > cols.start
    };
    let open_after = window.end < w && empty(window.end - 1) && {
        let start = window
            .clone()
            .rev()
            .find(|&t| !empty(t))
            .map_or(window.start, |t| t + 1);
        start < cols.end
    };
    (open_before || open_after).then(|| {
        let start = if open_before { 0 } else { window.start };
        let end = if open_after { w } else { window.end };
        start..end
    })
}

/// Fills each run of empty pixels of `row` between two mapped ones from the farther
/// (smaller disparity) of the two: the background side, so a disocclusion does not take
/// the colour of the surface in front. A run at either end of the row, which neither view
/// saw (the corners a turned in-between view shows beyond both frames), is filled from the
/// one mapped pixel beside it when that shows a surface (the ground), so the corner is not
/// left to the sky colour where the scene shows ground; beside the sky, or in a row with
/// nothing mapped, it stays empty. The pixels in `span` only, its ends taken as the row's.
fn fill_from_farther(row: &mut Row, span: Range<usize>) {
    let w = span.end.min(row.disparity.len());
    let mut x = span.start;
    while x < w {
        if row.disparity[x] >= 0.0 {
            x += 1;
            continue;
        }
        let start = x;
        while x < w && row.disparity[x] < 0.0 {
            x += 1;
        }
        let f = match (
            (start > span.start).then(|| start - 1),
            (x < w).then_some(x),
        ) {
            (Some(a), Some(b)) => {
                if row.disparity[a] <= row.disparity[b] {
                    a
                } else {
                    b
                }
            }
            (Some(f), None) | (None, Some(f)) => {
                // The row's end: only from a surface.
                if row.disparity[f] <= 0.0 || row.color[f].a < 0.5 {
                    continue;
                }
                f
            }
            (None, None) => continue,
        };
        let (c, d) = (row.color[f], row.disparity[f]);
        for t in start..x {
            row.color[t] = c;
            row.disparity[t] = d;
        }
    }
}

/// The images a morph shown frame after frame keeps ([`ViewMorph::view_into`]): the
/// parallel in-between canvas and the view turned from it.
#[derive(Clone, Debug)]
pub struct MorphScratch {
    pub(super) parallel: DepthImage,
    /// The last in-between view made.
    pub view: DepthImage,
    /// Pixels of the parallel canvas the last view morphed (a work counter: the rows and
    /// columns the postwarp reads, with a margin, of a canvas about twice the view's).
    pub canvas_px: u64,
    /// Pixels of the canvas's rows the postwarp reads, every column (what the morph took
    /// before it cut the columns): `canvas_px` against it is the share saved.
    pub band_px: u64,
    /// Pixels of the two prewarped views the morph's row maps looked at (a work counter:
    /// those that cannot move into the columns morphed are skipped).
    pub source_px: u64,
    /// Per row of `parallel`, the columns the last morph wrote ([`morph`]'s `written`).
    pub(super) written: Vec<Range<usize>>,
    /// Pixels of the canvas cleared for the last view (a work counter): what the view
    /// before it morphed outside the columns this one morphs (which are each written once:
    /// session 19); until session 15 all the canvas's pixels were cleared, until session 19
    /// all those the view before morphed.
    pub cleared_px: u64,
    /// The last view's time in the morph to the parallel canvas (a figure for the
    /// showcase's per-stage times).
    pub canvas_time: Duration,
    /// The last view's time in the postwarp from the canvas to the view.
    pub postwarp_time: Duration,
    /// Whether the view (and the canvas) carry depth; `true` unless set. Without it every
    /// depth of [`MorphScratch::view`] is [`crate::core::EMPTY`] and its colours are the
    /// same: a view shown as colour only (the showcase's) skips a nearest-depth lookup and
    /// two divisions a pixel.
    pub depth: bool,
    /// Whether every depth of the canvas, and of the view, is empty (made so, or made
    /// without depth since): then a view without depth writes none ([`morph`]).
    pub(super) canvas_depth_empty: bool,
    pub(super) view_depth_empty: bool,
}

impl Default for MorphScratch {
    fn default() -> Self {
        let camera = Camera::look_at(glam::Vec3::ZERO, glam::Vec3::NEG_Z, glam::Vec3::Y, 1.0, 1.0);
        let empty = DepthImage::new(0, 0, camera);
        MorphScratch {
            parallel: empty.clone(),
            view: empty,
            canvas_px: 0,
            band_px: 0,
            source_px: 0,
            written: Vec::new(),
            cleared_px: 0,
            canvas_time: Duration::ZERO,
            postwarp_time: Duration::ZERO,
            depth: true,
            canvas_depth_empty: true,
            view_depth_empty: true,
        }
    }
}
