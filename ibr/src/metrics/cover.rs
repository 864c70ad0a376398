//! How many of a set of rectangles cover each pixel of an image: the frame error's region
//! (the pixels the visible objects' screen rectangles cover, each counted once), and how
//! crowded each rectangle is. Built from corner increments and two prefix sums, so its
//! cost is the image's pixels plus the rectangles, however large they are.

use super::Rect;

/// Per-pixel counts of the rectangles over a `width` x `height` image (row-major), its
/// memory reused from one [`RectCover::count`] to the next.
#[derive(Clone, Debug, Default)]
pub struct RectCover {
    width: usize,
    height: usize,
    counts: Vec<u32>,
    /// The corner increments, then (after [`RectCover::summed`]) the per-pixel counts'
    /// summed-area table (`(w + 1) x (h + 1)`).
    table: Vec<i64>,
    summed: bool,
    /// A row's running counts.
    above: Vec<i64>,
}

impl RectCover {
    /// Counts `rects` (each clipped to the image) over a `width` x `height` image.
    pub fn count(&mut self, width: u32, height: u32, rects: impl IntoIterator<Item = Rect>) {
        let (w, h) = (width as usize, height as usize);
        (self.width, self.height) = (w, h);
        let stride = w + 1;
        let diff = &mut self.table;
        diff.clear();
        diff.resize(stride * (h + 1), 0);
        for r in rects {
            let r = r.clip(width, height);
            if r.is_empty() {
                continue;
            }
            let (x0, y0) = (r.x as usize, r.y as usize);
            let (x1, y1) = (x0 + r.width as usize, y0 + r.height as usize);
            diff[y0 * stride + x0] += 1;
            diff[y0 * stride + x1] -= 1;
            diff[y1 * stride + x0] -= 1;
            diff[y1 * stride + x1] += 1;
        }
        // Rows' running sums, each added to the row above's: the counts.
        self.counts.clear();
        self.counts.resize(w * h, 0);
        let above = &mut self.above;
        above.clear();
        above.resize(w, 0);
        for y in 0..h {
            let mut run = 0;
            for x in 0..w {
                run += diff[y * stride + x];
                above[x] += run;
                self.counts[y * w + x] = above[x].max(0) as u32;
            }
        }
        self.summed = false;
    }

    /// Builds the counts' summed-area table for [`RectCover::sum`], in place of the corner
    /// increments (the frame's union needs only the counts).
    pub fn summed(&mut self) {
        let (w, h) = (self.width, self.height);
        let stride = w + 1;
        let table = &mut self.table;
        table.clear();
        table.resize(stride * (h + 1), 0);
        for y in 0..h {
            let mut run = 0i64;
            for x in 0..w {
                run += i64::from(self.counts[y * w + x]);
                table[(y + 1) * stride + x + 1] = table[y * stride + x + 1] + run;
            }
        }
        self.summed = true;
    }

    /// Each pixel's count, row-major.
    pub fn counts(&self) -> &[u32] {
        &self.counts
    }

    /// The pixels at least one rectangle covers.
    pub fn area(&self) -> u64 {
        self.counts.iter().filter(|&&c| c > 0).count() as u64
    }

    /// The sum of the counts over `r` (clipped to the image); 0 before
    /// [`RectCover::summed`].
    pub fn sum(&self, r: Rect) -> u64 {
        if !self.summed {
            return 0;
        }
        let r = r.clip(self.width as u32, self.height as u32);
        let stride = self.width + 1;
        let at = |x: u32, y: u32| self.table[y as usize * stride + x as usize];
        let (x1, y1) = (r.x + r.width, r.y + r.height);
        (at(x1, y1) - at(r.x, y1) - at(x1, r.y) + at(r.x, r.y)).max(0) as u64
    }
}

/// The pixels a set of rectangles covers, each counted once, over a `width` x `height`
/// image: [`RectCover::area`] without the per-pixel counts. Bands between the rectangles'
/// distinct rows, each one's covered columns counted from column increments kept up to
/// date as rectangles enter and leave, so its cost is the rectangles plus the bands times
/// the columns, less than the image's pixels (a planner weighs a frame's rectangles every
/// frame). Its memory is reused from one call to the next.
#[derive(Clone, Debug, Default)]
pub struct RectUnion {
    /// Clipped, non-empty rectangles by top row, and their (bottom row, left, right) by
    /// bottom row.
    enter: Vec<Rect>,
    leave: Vec<(u32, u32, u32)>,
    /// Band edges (rows), sorted and distinct.
    edges: Vec<u32>,
    /// Per column, the rectangles open there less those closed (`+1` at a rectangle's left
    /// column, `-1` past its right).
    columns: Vec<i32>,
}

impl RectUnion {
    /// The pixels of a `width` x `height` image that at least one of `rects` (each clipped
    /// to the image) covers.
    pub fn area(&mut self, width: u32, height: u32, rects: impl IntoIterator<Item = Rect>) -> u64 {
        self.enter.clear();
        let clipped = rects.into_iter().map(|r| r.clip(width, height));
        self.enter.extend(clipped.filter(|r| !r.is_empty()));
        if self.enter.is_empty() {
            return 0;
        }
        self.enter.sort_unstable_by_key(|r| r.y);
        self.leave.clear();
        let leave = self
            .enter
            .iter()
            .map(|r| (r.y + r.height, r.x, r.x + r.width));
        self.leave.extend(leave);
        self.leave.sort_unstable_by_key(|l| l.0);
        self.edges.clear();
        for r in &self.enter {
            self.edges.extend([r.y, r.y + r.height]);
        }
        self.edges.sort_unstable();
        self.edges.dedup();
        // The columns any rectangle reaches.
        let lo = self.enter.iter().map(|r| r.x).min().unwrap_or(0) as usize;
        let hi = self.enter.iter().map(|r| r.x + r.width).max().unwrap_or(0) as usize;
        self.columns.clear();
        self.columns.resize(width as usize + 1, 0);
        let (mut entered, mut left, mut area) = (0, 0, 0u64);
        for band in self.edges.windows(2) {
            let (top, bottom) = (band[0], band[1]);
            while left < self.leave.len() && self.leave[left].0 <= top {
                let (_, x0, x1) = self.leave[left];
                self.columns[x0 as usize] -= 1;
                self.columns[x1 as usize] += 1;
                left += 1;
            }
            while entered < self.enter.len() && self.enter[entered].y <= top {
                let r = self.enter[entered];
                self.columns[r.x as usize] += 1;
                self.columns[(r.x + r.width) as usize] -= 1;
                entered += 1;
            }
            if entered == left {
                continue;
            }
            let mut run = 0;
            let covered = self.columns[lo..hi].iter().fold(0u64, |n, &c| {
                run += c;
                n + u64::from(run > 0)
            });
            area += covered * u64::from(bottom - top);
        }
        area
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Counts by brute force.
    fn brute(w: u32, h: u32, rects: &[Rect]) -> Vec<u32> {
        let mut out = vec![0; (w * h) as usize];
        for r in rects {
            let r = r.clip(w, h);
            for y in r.y..r.y + r.height {
                for x in r.x..r.x + r.width {
                    out[(y * w + x) as usize] += 1;
                }
            }
        }
        out
    }

    #[test]
    fn counts_match_brute_force_and_sums_the_counts_over_a_rectangle() {
        let rects = [
            Rect::new(0, 0, 4, 4),
            Rect::new(3, 3, 4, 4),
            Rect::new(10, 0, 2, 5),
            Rect::new(0, 8, 16, 2),
            Rect::new(14, 7, 40, 40),
            Rect::new(5, 5, 0, 3),
        ];
        let mut c = RectCover::default();
        c.count(16, 10, rects);
        c.summed();
        let want = brute(16, 10, &rects);
        assert_eq!(c.counts(), &want[..]);
        assert_eq!(c.area(), want.iter().filter(|&&n| n > 0).count() as u64);
        // Their areas inside the image, less the pixel the first two share and the 2 x 2
        // the last two share (the empty one adds nothing).
        assert_eq!(c.area(), 16 + 16 + 10 + 32 + 6 - 1 - 4);
        for r in rects.iter().chain(&[Rect::new(0, 0, 16, 10)]) {
            let r = r.clip(16, 10);
            let mut sum = 0;
            for y in r.y..r.y + r.height {
                for x in r.x..r.x + r.width {
                    sum += u64::from(want[(y * 16 + x) as usize]);
                }
            }
            assert_eq!(c.sum(r), sum, "{r:?}");
        }
        // Reused for other rectangles on another size.
        c.count(3, 2, [Rect::new(1, 0, 5, 5)]);
        assert_eq!(c.counts(), &[0, 1, 1, 0, 1, 1]);
        c.count(0, 0, rects);
        assert_eq!(c.area(), 0);
    }

    #[test]
    fn the_union_of_rectangles_is_the_pixels_some_rectangle_covers() {
        let mut union = RectUnion::default();
        let mut cover = RectCover::default();
        // A fixed pseudo-random sequence of rectangles, some off the image or empty.
        let mut seed = 0x2545_f491_u32;
        let mut next = |n: u32| {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed % n
        };
        for (w, h, n) in [
            (16, 10, 6),
            (40, 30, 40),
            (7, 50, 3),
            (64, 64, 200),
            (5, 5, 0),
        ] {
            let rects: Vec<Rect> = (0..n)
                .map(|_| Rect::new(next(w + 8), next(h + 8), next(w / 2 + 2), next(h / 2 + 2)))
                .collect();
            cover.count(w, h, rects.iter().copied());
            let want = brute(w, h, &rects).iter().filter(|&&c| c > 0).count() as u64;
            assert_eq!(cover.area(), want);
            assert_eq!(
                union.area(w, h, rects.iter().copied()),
                want,
                "{w}x{h}, {n}"
            );
        }
        assert_eq!(union.area(0, 0, [Rect::new(0, 0, 4, 4)]), 0);
        let whole = Rect::new(0, 0, u32::MAX, u32::MAX);
        assert_eq!(union.area(640, 360, [whole, whole]), 640 * 360);
    }
}
