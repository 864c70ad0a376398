//! An image's covered part as cells of a coarse grid, and the quad's mesh over just those
//! cells: a node image of many small objects (the world's clusters) covers a few scattered
//! patches of its square, and every empty texel its one trimmed rectangle put on screen
//! was still tested and shaded. The mesh is a band of runs per row of cells, split where a
//! neighbouring band's runs end so that no edge has a vertex of its neighbour in its middle
//! (no T-junction: the shared edges rasterise watertight, as the one rectangle did).

use crate::core::Rect;
use engine::Mesh;
use glam::{Vec2, Vec3};

/// Cells a side of the grid, at most (and at most one a texel).
pub(super) const CELLS: u32 = 8;

/// Which cells of a `side` x `side` image hold a texel within one texel (the bilinear
/// fringe) of a covered one: bit `c` of `rows[r]` for cell column `c` of cell row `r`.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Cells {
    side: u32,
    n: u32,
    rows: [u32; CELLS as usize],
}

impl Cells {
    /// No cell covered, for a `side`-texel image.
    pub(super) fn new(side: u32) -> Cells {
        Cells {
            side,
            n: CELLS.min(side).max(1),
            rows: [0; CELLS as usize],
        }
    }

    /// The cell column (or row) of texel column (or row) `x`; the last cell for a texel
    /// past the side (a taller image than wide is not one of the square captures, but
    /// marks its bottom rows in the last row of cells rather than panicking).
    fn cell(&self, x: u32) -> u32 {
        let c = (u64::from(x) * u64::from(self.n)) / u64::from(self.side.max(1));
        c.min(u64::from(self.n - 1)) as u32
    }

    /// The first texel column (or row) of cell `c` (`side` for `c = n`): the cells are the
    /// texels [`Cells::cell`] maps to them, none empty as there are at most `side` cells.
    fn edge(&self, c: u32) -> u32 {
        ((u64::from(c) * u64::from(self.side)).div_ceil(u64::from(self.n))) as u32
    }

    /// Marks texel row `y`, whose texels `covered` says are covered (columns ascending),
    /// and the cells within one texel of each: a run of covered texels marks the cells
    /// from its first texel's left neighbour to its last one's right neighbour.
    pub(super) fn mark_row(&mut self, y: u32, covered: impl Iterator<Item = u32>) {
        let last = self.side.saturating_sub(1);
        let span = |(a, b): (u32, u32)| {
            let (c0, c1) = (self.cell(a.saturating_sub(1)), self.cell((b + 1).min(last)));
            (u32::MAX >> (31 - c1)) & (u32::MAX << c0)
        };
        let (mut bits, mut run) = (0u32, None);
        for x in covered {
            run = match run {
                Some((a, b)) if x == b + 1 => Some((a, x)),
                Some(r) => {
                    bits |= span(r);
                    Some((x, x))
                }
                None => Some((x, x)),
            };
        }
        bits |= run.map_or(0, span);
        if bits == 0 {
            return;
        }
        for r in [y.saturating_sub(1), y, (y + 1).min(last)] {
            let r = self.cell(r) as usize;
            self.rows[r] |= bits;
        }
    }

    /// Bands of cell rows with the same covered cells, top first: (first texel row, end
    /// texel row, cells), clipped to `rect` (rows outside it dropped).
    fn bands(&self, rect: Rect) -> Vec<(u32, u32, u32)> {
        let mut out: Vec<(u32, u32, u32)> = Vec::new();
        for r in 0..self.n {
            let (y0, y1) = (self.edge(r), self.edge(r + 1));
            let (y0, y1) = (y0.max(rect.y), y1.min(rect.y + rect.height));
            if y0 >= y1 {
                continue;
            }
            let bits = self.rows[r as usize];
            match out.last_mut() {
                Some(last) if last.2 == bits && last.1 == y0 => last.1 = y1,
                _ => out.push((y0, y1, bits)),
            }
        }
        out
    }

    /// The runs of covered cells in `bits`, as texel columns `[x0, x1)` clipped to `rect`.
    fn runs(&self, bits: u32, rect: Rect, out: &mut Vec<(u32, u32)>) {
        out.clear();
        let mut c = 0;
        while c < self.n {
            if bits & (1 << c) == 0 {
                c += 1;
                continue;
            }
            let start = c;
            while c < self.n && bits & (1 << c) != 0 {
                c += 1;
            }
            let x0 = self.edge(start).max(rect.x);
            let x1 = self.edge(c).min(rect.x + rect.width);
            if x0 < x1 {
                out.push((x0, x1));
            }
        }
    }

    /// Writes into `m` (cleared first by the caller) the mesh over the covered cells
    /// within `rect` (texels), placed by `at` (texel coordinates over `side` to a point);
    /// its share of the square.
    pub(super) fn write(&self, rect: Rect, at: impl Fn(Vec2) -> Vec3, m: &mut Mesh) -> f32 {
        let bands = self.bands(rect);
        let side = self.side.max(1) as f32;
        let mut runs: Vec<Vec<(u32, u32)>> = Vec::with_capacity(bands.len());
        for &(_, _, bits) in &bands {
            let mut r = Vec::new();
            self.runs(bits, rect, &mut r);
            runs.push(r);
        }
        let mut area = 0u64;
        let (mut top, mut bottom) = (Vec::new(), Vec::new());
        for (k, &(y0, y1, _)) in bands.iter().enumerate() {
            let above = k.checked_sub(1).map_or(&[][..], |a| &runs[a][..]);
            let below = runs.get(k + 1).map_or(&[][..], |b| &b[..]);
            for &(x0, x1) in &runs[k] {
                area += u64::from(x1 - x0) * u64::from(y1 - y0);
                // Each edge left to right, with the neighbouring band's run ends on it.
                for (edge, next) in [(&mut top, above), (&mut bottom, below)] {
                    edge.clear();
                    edge.push(x0);
                    edge.extend(splits(next, x0, x1));
                    edge.push(x1);
                }
                zip(&top, &bottom, (y0, y1), side, &at, m);
            }
        }
        area as f32 / (side * side)
    }
}

/// The ends of `runs` strictly inside `(x0, x1)`, ascending.
fn splits(runs: &[(u32, u32)], x0: u32, x1: u32) -> impl Iterator<Item = u32> + '_ {
    runs.iter()
        .flat_map(|&(a, b)| [a, b])
        .filter(move |&x| x > x0 && x < x1)
}

/// Triangulates the rectangle between texel rows `y0` (its top edge's points at columns
/// `top`) and `y1` (`bottom`), both edges left to right from the same first column to the
/// same last, into `m`: every segment of either edge is an edge of one triangle, so a
/// neighbour sharing the segment meets it vertex to vertex.
fn zip(
    top: &[u32],
    bottom: &[u32],
    (y0, y1): (u32, u32),
    side: f32,
    at: &impl Fn(Vec2) -> Vec3,
    m: &mut Mesh,
) {
    let base = m.positions.len() as u32;
    let rows = top
        .iter()
        .map(|&x| (x, y0))
        .chain(bottom.iter().map(|&x| (x, y1)));
    for (x, y) in rows {
        let uv = Vec2::new(x as f32 / side, y as f32 / side);
        m.positions.push(at(uv));
        m.uvs.push(uv);
    }
    let (t, b) = (
        |i: usize| base + i as u32,
        |j: usize| base + (top.len() + j) as u32,
    );
    let (mut i, mut j) = (0, 0);
    // Wound as [`crate::core::push_quad`] winds its quads.
    while i + 1 < top.len() || j + 1 < bottom.len() {
        if j + 1 == bottom.len() || (i + 1 < top.len() && top[i + 1] <= bottom[j + 1]) {
            m.indices.extend_from_slice(&[t(i), b(j), t(i + 1)]);
            i += 1;
        } else {
            m.indices.extend_from_slice(&[t(i), b(j), b(j + 1)]);
            j += 1;
        }
    }
}

#[cfg(test)]
mod tests;
