//! Bin stage: sorts each chunk's set-up triangles into per-tile lists.
//!
//! Each chunk of triangles (a contiguous range in submission order) bins its own triangles
//! with a counting sort into `offsets` / `entries` (indices into the chunk's list): tile
//! `t`'s triangles are `entries[offsets[t]..offsets[t + 1]]`, in submission order. The rasterizer visits the
//! chunks in order, so every tile sees its triangles in submission order whatever the
//! thread count. A triangle goes to every tile its pixel bounding box touches; the
//! rasterizer rejects the tiles it does not really cover.

use crate::setup::Tri;
use crate::target::TILE_SHIFT;

/// Bins of one chunk. Buffers are reused from frame to frame.
#[derive(Clone, Debug, Default)]
pub struct Bins {
    pub offsets: Vec<u32>,
    tiles_x: usize,
    tiles_y: usize,
    /// Indices into the chunk's triangle list, grouped by tile. (Copies of the triangles
    /// read faster on scattered scenes such as `confetti`, but cost a second write and read
    /// of every triangle; the rasterizer prefetches the triangles ahead instead.)
    pub entries: Vec<u32>,
    cursor: Vec<u32>,
}

#[inline]
fn tile_range(t: &Tri) -> (usize, usize, usize, usize) {
    (
        (t.bbox[0] >> TILE_SHIFT) as usize,
        (t.bbox[1] >> TILE_SHIFT) as usize,
        (t.bbox[2] >> TILE_SHIFT) as usize,
        (t.bbox[3] >> TILE_SHIFT) as usize,
    )
}

impl Bins {
    /// Starts a frame on a grid of `tiles_x` x `tiles_y` tiles.
    pub fn begin(&mut self, tiles_x: usize, tiles_y: usize) {
        (self.tiles_x, self.tiles_y) = (tiles_x, tiles_y);
        self.offsets.clear();
        self.offsets.resize(tiles_x * tiles_y + 1, 0);
    }

    /// Counts a triangle that will be in [`Bins::build`]'s list. Setup calls it as it makes
    /// each triangle, while its box is at hand, so binning needs one pass over the list,
    /// not two.
    #[inline]
    pub fn count(&mut self, t: &Tri) {
        if self.tiles_x == 0 || self.tiles_y == 0 {
            return;
        }
        let (x0, y0, x1, y1) = tile_range(t);
        if x0 == x1 && y0 == y1 {
            if let Some(c) = self.offsets.get_mut(y0 * self.tiles_x + x0 + 1) {
                *c += 1;
            }
            return;
        }
        for ty in y0..=y1.min(self.tiles_y - 1) {
            for tx in x0..=x1.min(self.tiles_x - 1) {
                self.offsets[ty * self.tiles_x + tx + 1] += 1;
            }
        }
    }

    /// Bins `tris`, each of which was counted since [`Bins::begin`]. Returns the entry count.
    pub fn build(&mut self, tris: &[Tri]) -> u64 {
        let (tiles_x, tiles_y) = (self.tiles_x, self.tiles_y);
        let n = tiles_x * tiles_y;
        if n == 0 {
            return 0;
        }
        for i in 0..n {
            self.offsets[i + 1] += self.offsets[i];
        }
        let total = self.offsets[n] as usize;
        // Every slot below `total` is written next; slots past it are stale and never read,
        // so the buffer only grows (filling it each frame cost a whole extra pass).
        if self.entries.len() < total {
            self.entries.resize(total, 0);
        }
        self.cursor.clear();
        self.cursor.extend_from_slice(&self.offsets[..n]);
        for (i, t) in tris.iter().enumerate() {
            let (x0, y0, x1, y1) = tile_range(t);
            for ty in y0..=y1.min(tiles_y - 1) {
                for tx in x0..=x1.min(tiles_x - 1) {
                    let c = &mut self.cursor[ty * tiles_x + tx];
                    self.entries[*c as usize] = i as u32;
                    *c += 1;
                }
            }
        }
        total as u64
    }

    /// Indices (into the list given to [`Bins::build`]) of the triangles binned to tile
    /// `tile`, in submission order.
    #[inline]
    pub fn tile(&self, tile: usize) -> &[u32] {
        match (self.offsets.get(tile), self.offsets.get(tile + 1)) {
            (Some(&a), Some(&b)) => &self.entries[a as usize..b as usize],
            _ => &[],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn triangles_land_in_every_tile_of_their_box_in_order() {
        let tris = [
            Tri::with_box([0, 0, 10, 10], 0),
            Tri::with_box([60, 60, 70, 70], 1),
            Tri::with_box([100, 0, 100, 0], 2),
        ];
        let ids = |ts: &[u32]| {
            ts.iter()
                .map(|&i| tris[i as usize].vary[0])
                .collect::<Vec<_>>()
        };
        let mut b = Bins::default();
        b.begin(2, 2);
        for t in &tris {
            b.count(t);
        }
        assert_eq!(b.build(&tris), 1 + 4 + 1);
        assert_eq!(ids(b.tile(0)), [0, 1]);
        assert_eq!(ids(b.tile(1)), [1, 2]);
        assert_eq!(ids(b.tile(2)), [1]);
        assert_eq!(ids(b.tile(3)), [1]);
        assert!(b.tile(9).is_empty());
    }
}
