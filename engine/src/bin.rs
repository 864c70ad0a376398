//! Bin stage: sorts each chunk's set-up triangles into per-tile lists.
//!
//! Each chunk of triangles (a contiguous range in submission order) bins its own triangles
//! with a counting sort into `offsets` / `entries` (copies of the triangles): tile `t`'s triangles are
//! `entries[offsets[t]..offsets[t + 1]]`, in submission order. The rasterizer visits the
//! chunks in order, so every tile sees its triangles in submission order whatever the
//! thread count. A triangle goes to every tile its pixel bounding box touches; the
//! rasterizer rejects the tiles it does not really cover.

use crate::setup::Tri;
use crate::target::TILE_SHIFT;

/// Bins of one chunk. Buffers are reused from frame to frame.
#[derive(Clone, Debug, Default)]
pub struct Bins {
    pub offsets: Vec<u32>,
    /// Copies of the triangles, grouped by tile: the rasterizer then reads each tile's
    /// triangles from consecutive memory instead of jumping around the chunk's list (on
    /// scattered scenes such as `confetti` those jumps were cache misses costing a fifth of
    /// the frame).
    pub entries: Vec<Tri>,
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
    /// Bins `tris` for a grid of `tiles_x` x `tiles_y` tiles. Returns the entry count.
    pub fn build(&mut self, tris: &[Tri], tiles_x: usize, tiles_y: usize) -> u64 {
        let n = tiles_x * tiles_y;
        self.offsets.clear();
        self.offsets.resize(n + 1, 0);
        for t in tris {
            let (x0, y0, x1, y1) = tile_range(t);
            for ty in y0..=y1.min(tiles_y - 1) {
                for tx in x0..=x1.min(tiles_x - 1) {
                    self.offsets[ty * tiles_x + tx + 1] += 1;
                }
            }
        }
        for i in 0..n {
            self.offsets[i + 1] += self.offsets[i];
        }
        let total = self.offsets[n] as usize;
        // Every slot below `total` is written next; slots past it are stale and never read,
        // so the buffer only grows (filling it each frame cost a whole extra pass).
        if self.entries.len() < total {
            if let Some(first) = tris.first() {
                self.entries.resize(total, *first);
            }
        }
        self.cursor.clear();
        self.cursor.extend_from_slice(&self.offsets[..n]);
        for t in tris {
            let (x0, y0, x1, y1) = tile_range(t);
            for ty in y0..=y1.min(tiles_y - 1) {
                for tx in x0..=x1.min(tiles_x - 1) {
                    let c = &mut self.cursor[ty * tiles_x + tx];
                    self.entries[*c as usize] = *t;
                    *c += 1;
                }
            }
        }
        total as u64
    }

    /// The triangles binned to tile `tile`, in submission order.
    #[inline]
    pub fn tile(&self, tile: usize) -> &[Tri] {
        match (self.offsets.get(tile), self.offsets.get(tile + 1)) {
            (Some(&a), Some(&b)) => &self.entries[a as usize..b as usize],
            _ => &[],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::setup::Plane;

    fn tri(bbox: [u16; 4]) -> Tri {
        Tri {
            x: [0; 3],
            y: [0; 3],
            bbox,
            z: Plane::default(),
            iw: Plane::default(),
            l1: Plane::default(),
            l2: Plane::default(),
            draw: 0,
            prim: 0,
            vary: [0; 3],
            flags: 0,
            cover: 0,
            color: 0,
        }
    }

    #[test]
    fn triangles_land_in_every_tile_of_their_box_in_order() {
        let mut tris = [
            tri([0, 0, 10, 10]),
            tri([60, 60, 70, 70]),
            tri([100, 0, 100, 0]),
        ];
        for (i, t) in tris.iter_mut().enumerate() {
            t.prim = i as u32;
        }
        let ids = |ts: &[Tri]| ts.iter().map(|t| t.prim).collect::<Vec<_>>();
        let mut b = Bins::default();
        assert_eq!(b.build(&tris, 2, 2), 1 + 4 + 1);
        assert_eq!(ids(b.tile(0)), [0, 1]);
        assert_eq!(ids(b.tile(1)), [1, 2]);
        assert_eq!(ids(b.tile(2)), [1]);
        assert_eq!(ids(b.tile(3)), [1]);
        assert!(b.tile(9).is_empty());
    }
}
