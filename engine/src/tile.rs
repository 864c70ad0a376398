//! Tile memory: one worker's 64 x 64 tile while the raster stage draws into it, cleared
//! lazily block by block and resolved into the target at the end.

use crate::color::{unpack, Encoder, Encoding, Premul};
use crate::shade::LANES;
use crate::simd::F8;
use crate::target::{TILE, TILE_PIXELS};

/// Block side for hierarchical rejection / acceptance (one lane row is one block row).
pub const BLOCK: i32 = LANES as i32;

/// Blocks per tile side.
pub(crate) const BLOCKS: usize = TILE / LANES;

/// Values in one block.
pub(crate) const BLOCK_PIXELS: usize = LANES * LANES;

/// The id of a pixel no triangle of the tile's visibility pre-pass has reached.
pub(crate) const NO_ID: u32 = u32::MAX;

/// One tile's working memory: linear premultiplied colour planes, reversed depth, and for
/// each 8 x 8 block the farthest depth stored in it (a one-level hierarchical Z: a triangle
/// nowhere nearer than that cannot pass the depth test anywhere in the block).
///
/// Clearing is lazy: a cleared tile only remembers the clear colour, and a block is filled
/// with it the first time a triangle reaches it (`touched`). Blocks no triangle reached are
/// resolved straight from the packed clear colour.
#[derive(Clone, Debug)]
pub struct TileBuf {
    pub color: [Vec<f32>; 4],
    pub depth: Vec<f32>,
    pub block_far: Vec<f32>,
    /// The depth a peeling frame draws strictly behind (reversed depth, tile layout);
    /// empty until a peeling frame first needs it.
    pub peel: Vec<f32>,
    /// For the visibility pre-pass: per pixel, the place in the tile's triangle list of the
    /// nearest opaque or alpha-tested triangle drawn there so far ([`NO_ID`]: none); empty
    /// until a tile first uses the pre-pass.
    pub vis: Vec<u32>,
    /// Blocks whose `block_far` may be lower than it could be (small triangles wrote there
    /// without recomputing it): still conservative, refreshed when next needed.
    far_stale: u64,
    touched: u64,
    clear: Premul,
}

impl Default for TileBuf {
    fn default() -> Self {
        TileBuf {
            color: std::array::from_fn(|_| vec![0.0; TILE_PIXELS]),
            depth: vec![0.0; TILE_PIXELS],
            block_far: vec![0.0; BLOCKS * BLOCKS],
            peel: Vec::new(),
            vis: Vec::new(),
            far_stale: 0,
            touched: 0,
            clear: Premul::TRANSPARENT,
        }
    }
}

impl TileBuf {
    /// Clears to one premultiplied colour and the far depth (lazily, see the type's doc).
    pub fn clear(&mut self, c: Premul) {
        self.clear = c;
        self.touched = 0;
        self.far_stale = 0;
        self.block_far.fill(0.0);
    }

    /// Makes block `b` hold real values before it is drawn into.
    #[inline(always)]
    pub(crate) fn touch(&mut self, b: usize) {
        if self.touched >> b & 1 == 0 {
            self.fill_block(b);
        }
    }

    /// Fills block `b` with the clear values: once per block and frame, off the hot path.
    #[cold]
    #[inline(never)]
    fn fill_block(&mut self, b: usize) {
        self.touched |= 1 << b;
        let c = self.clear;
        let r = b * BLOCK_PIXELS..(b + 1) * BLOCK_PIXELS;
        for (plane, v) in self.color.iter_mut().zip([c.r, c.g, c.b, c.a]) {
            plane[r.clone()].fill(v);
        }
        self.depth[r].fill(0.0);
    }

    /// Loads a stored tile (packed colour in `encoding`, reversed depth).
    pub fn load(&mut self, color: &[u32], depth: &[f32], encoding: Encoding) {
        for (i, px) in color.iter().enumerate() {
            let c = unpack(encoding, *px);
            self.color[0][i] = c.r;
            self.color[1][i] = c.g;
            self.color[2][i] = c.b;
            self.color[3][i] = c.a;
        }
        self.depth.copy_from_slice(depth);
        self.touched = u64::MAX;
        for b in 0..BLOCKS * BLOCKS {
            self.update_block_far(b);
        }
    }

    /// Starts a visibility pre-pass: no pixel holds a triangle's id.
    pub(crate) fn clear_ids(&mut self) {
        self.vis.clear();
        self.vis.resize(TILE_PIXELS, NO_ID);
    }

    /// Loads the depth a peeling frame draws behind (a stored tile of reversed depth).
    pub fn load_peel(&mut self, depth: &[f32]) {
        self.peel.clear();
        self.peel.extend_from_slice(depth);
    }

    /// Encodes colour into packed bytes and copies depth out.
    pub fn resolve(&self, color: &mut [u32], depth: &mut [f32], encoder: &Encoder) {
        let [r, g, b, a] = &self.color;
        let c = self.clear;
        let clear_px = encoder.pack(c.r, c.g, c.b, c.a);
        for blk in 0..BLOCKS * BLOCKS {
            let range = blk * BLOCK_PIXELS..(blk + 1) * BLOCK_PIXELS;
            if self.touched >> blk & 1 == 0 {
                color[range.clone()].fill(clear_px);
                depth[range].fill(0.0);
                continue;
            }
            for i in range.clone().step_by(LANES) {
                encoder.pack8(&r[i..], &g[i..], &b[i..], &a[i..], &mut color[i..]);
            }
            depth[range.clone()].copy_from_slice(&self.depth[range]);
        }
    }

    /// The farthest depth in `block`, refreshed first if small triangles left it stale.
    #[inline]
    pub(crate) fn far(&mut self, block: usize) -> f32 {
        if self.far_stale >> block & 1 != 0 {
            self.update_block_far(block);
        }
        self.block_far[block]
    }

    /// Notes that `block`'s farthest depth may have moved nearer without recomputing it.
    #[inline]
    pub(crate) fn mark_far_stale(&mut self, block: usize) {
        self.far_stale |= 1 << block;
    }

    /// Recomputes `block`'s farthest depth.
    pub(crate) fn update_block_far(&mut self, block: usize) {
        self.far_stale &= !(1 << block);
        let mut far = F8::splat(f32::INFINITY);
        for row in self.depth[block * BLOCK_PIXELS..(block + 1) * BLOCK_PIXELS].chunks_exact(LANES)
        {
            far = far.min(F8::load(row));
        }
        let far = far.to_array();
        self.block_far[block] = far.iter().copied().fold(f32::INFINITY, f32::min);
    }
}
