//! Render targets: colour and depth stored tile by tile, so that each raster worker owns one
//! tile's memory outright (`&mut` slices handed to rayon, no sharing).
//!
//! Layout: the target is cut into `TILE` x `TILE` tiles, row-major over tiles; inside a
//! tile, pixels are stored in 8 x 8 blocks ([`offset_in_tile`]); edge tiles are padded to
//! full size. Colour is
//! premultiplied RGBA8 in the target's [`Encoding`]; depth is the pipeline's reversed depth
//! (1 = near plane, 0 = far plane and the cleared value). Readers convert to row-major images,
//! OpenGL window depth, or a [`Texture`] for image-based rendering.

use crate::color::{unpack, Encoder, Encoding, Premul, Rgba};
use crate::texture::Texture;

/// Tile side in pixels (a power of two). 64 x 64 tiles keep a worker's colour and depth
/// scratch (80 KiB) in L2 while giving enough tiles to balance two or more cores.
pub const TILE: usize = 64;
/// `log2(TILE)`.
pub const TILE_SHIFT: u32 = 6;
/// Pixels in one tile.
pub const TILE_PIXELS: usize = TILE * TILE;
/// Side of the blocks a tile is stored in.
pub const BLOCK: usize = 8;

/// Where pixel `(x, y)` of a tile is stored: 8 x 8 blocks, row-major over blocks, each
/// block row-major inside. A block (the rasterizer's unit) is then 64 contiguous values.
#[inline]
pub fn offset_in_tile(x: usize, y: usize) -> usize {
    ((y / BLOCK) * (TILE / BLOCK) + x / BLOCK) * BLOCK * BLOCK + (y % BLOCK) * BLOCK + x % BLOCK
}

/// Copies one run of a row of the tiled storage (`Target::row_runs`): a whole block's row
/// as a fixed-size copy the compiler inlines. Copied with the run's length, every 8 values
/// were a `memmove` call costing more than the copy (3.9% of the 720p tour's samples,
/// chiefly the attractions' meter reading each frame).
#[inline(always)]
fn copy_run<T: Copy>(dst: &mut [T], src: &[T]) {
    if let (Ok(d), Ok(s)) = (
        <&mut [T; BLOCK]>::try_from(&mut *dst),
        <&[T; BLOCK]>::try_from(src),
    ) {
        *d = *s;
        return;
    }
    dst.copy_from_slice(src);
}

/// Largest target side; larger requests are clamped to it.
pub const MAX_TARGET_SIZE: u32 = 16384;

/// A colour + depth render target of any size, including 0 x 0.
#[derive(Clone, Debug, PartialEq)]
pub struct Target {
    width: u32,
    height: u32,
    tiles_x: u32,
    tiles_y: u32,
    encoding: Encoding,
    pub(crate) color: Vec<u32>,
    pub(crate) depth: Vec<f32>,
}

impl Default for Target {
    /// A 0 x 0 target.
    fn default() -> Self {
        Target::new(0, 0)
    }
}

impl Target {
    /// A cleared (transparent black, far depth) sRGB target. Sides are clamped to
    /// [`MAX_TARGET_SIZE`].
    pub fn new(width: u32, height: u32) -> Self {
        Self::with_encoding(width, height, Encoding::Srgb)
    }

    /// A cleared target whose colour bytes are in `encoding` ([`Encoding::Unorm`] for data
    /// or byte-exact comparisons). Sides are clamped to [`MAX_TARGET_SIZE`].
    pub fn with_encoding(width: u32, height: u32, encoding: Encoding) -> Self {
        let mut t = Target {
            width: 0,
            height: 0,
            tiles_x: 0,
            tiles_y: 0,
            encoding,
            color: Vec::new(),
            depth: Vec::new(),
        };
        t.resize(width, height);
        t
    }

    /// Changes the size (contents become cleared); keeps the allocation when it can.
    pub fn resize(&mut self, width: u32, height: u32) {
        let (width, height) = (width.min(MAX_TARGET_SIZE), height.min(MAX_TARGET_SIZE));
        self.width = width;
        self.height = height;
        self.tiles_x = width.div_ceil(TILE as u32);
        self.tiles_y = height.div_ceil(TILE as u32);
        let n = self.tile_count() * TILE_PIXELS;
        self.color.clear();
        self.color.resize(n, 0);
        self.depth.clear();
        self.depth.resize(n, 0.0);
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// How the stored colour bytes encode linear colour.
    pub fn encoding(&self) -> Encoding {
        self.encoding
    }

    /// Changes how later frames encode colour. The stored bytes are not converted: what is
    /// already there is read back in the new encoding.
    pub fn set_encoding(&mut self, encoding: Encoding) {
        self.encoding = encoding;
    }

    /// Tiles per row: `ceil(width / TILE)`.
    pub fn tiles_x(&self) -> u32 {
        self.tiles_x
    }

    /// Rows of tiles: `ceil(height / TILE)`.
    pub fn tiles_y(&self) -> u32 {
        self.tiles_y
    }

    /// Number of tiles, `tiles_x * tiles_y` (0 for an empty target).
    pub fn tile_count(&self) -> usize {
        self.tiles_x as usize * self.tiles_y as usize
    }

    /// Clears colour and depth now (the renderer clears as part of a frame instead).
    pub fn clear(&mut self, color: Rgba) {
        let c = color.premultiply();
        let px = Encoder::new(self.encoding).pack(c.r, c.g, c.b, c.a);
        self.color.fill(px);
        self.depth.fill(0.0);
    }

    #[inline]
    pub(crate) fn index(&self, x: u32, y: u32) -> usize {
        let tile = (y as usize >> TILE_SHIFT) * self.tiles_x as usize + (x as usize >> TILE_SHIFT);
        tile * TILE_PIXELS + offset_in_tile(x as usize & (TILE - 1), y as usize & (TILE - 1))
    }

    /// Packed premultiplied bytes `r | g << 8 | b << 16 | a << 24` at a pixel, or `None`
    /// outside the target.
    pub fn pixel(&self, x: u32, y: u32) -> Option<u32> {
        (x < self.width && y < self.height).then(|| self.color[self.index(x, y)])
    }

    /// Where row `y` (inside the target) lies in the tiled storage: `(x, at, n)` for each
    /// run of `n` contiguous values starting at index `at`, pixel `x` first (a block's row,
    /// 8 values at most), left to right.
    fn row_runs(&self, y: u32) -> impl Iterator<Item = (usize, usize, usize)> {
        let w = self.width as usize;
        let tile_row = (y as usize >> TILE_SHIFT) * self.tiles_x as usize;
        let inner = offset_in_tile(0, y as usize & (TILE - 1));
        (0..w).step_by(BLOCK).map(move |x0| {
            let tile = tile_row + (x0 >> TILE_SHIFT);
            let at = tile * TILE_PIXELS + inner + ((x0 & (TILE - 1)) / BLOCK) * BLOCK * BLOCK;
            (x0, at, BLOCK.min(w - x0))
        })
    }

    /// Row `y`'s packed colours and reversed depths, left to right, into `color` and
    /// `depth` (cleared first; left empty for a row outside the target). Copies runs of
    /// the tiled storage ([`copy_run`]), not a tile lookup per pixel.
    pub fn read_row(&self, y: u32, color: &mut Vec<u32>, depth: &mut Vec<f32>) {
        color.clear();
        depth.clear();
        if y >= self.height {
            return;
        }
        color.resize(self.width as usize, 0);
        depth.resize(self.width as usize, 0.0);
        for (x0, at, n) in self.row_runs(y) {
            copy_run(&mut color[x0..x0 + n], &self.color[at..at + n]);
            copy_run(&mut depth[x0..x0 + n], &self.depth[at..at + n]);
        }
    }

    /// Premultiplied linear colour at a pixel.
    pub fn color_linear(&self, x: u32, y: u32) -> Option<Premul> {
        self.pixel(x, y).map(|p| unpack(self.encoding, p))
    }

    /// Reversed depth at a pixel (1 = near plane, 0 = far / nothing drawn).
    pub fn depth_reversed(&self, x: u32, y: u32) -> Option<f32> {
        (x < self.width && y < self.height).then(|| self.depth[self.index(x, y)])
    }

    /// OpenGL window depth at a pixel (0 = near plane, 1 = far / nothing drawn).
    pub fn depth_gl(&self, x: u32, y: u32) -> Option<f32> {
        self.depth_reversed(x, y)
            .map(crate::camera::gl_window_depth)
    }

    /// Row-major copy of the stored bytes (premultiplied RGBA8), top row first.
    pub fn to_rgba8_premultiplied(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.width as usize * self.height as usize * 4);
        for y in 0..self.height {
            for (_, at, n) in self.row_runs(y) {
                out.extend(self.color[at..at + n].iter().flat_map(|p| p.to_le_bytes()));
            }
        }
        out
    }

    /// Row-major straight-alpha RGBA8 in the target's encoding, as image files want it.
    pub fn to_rgba8(&self) -> Vec<u8> {
        let mut out = Vec::new();
        self.write_rgba8(&mut out);
        out
    }

    /// [`Target::to_rgba8`]'s bytes into `out` (resized; its memory kept from call to
    /// call), rows on the pool, each pixel its own (the same bytes at any thread count): a
    /// pixel neither empty nor opaque unpremultiplied and packed again, the others as
    /// stored. The views moment's layers frame made a fresh 3.7 MB vector on one thread
    /// here every frame at 1280x720 (session 21).
    pub fn write_rgba8(&self, out: &mut Vec<u8>) {
        use rayon::prelude::*;
        let w = self.width as usize;
        // Every byte is written below: no clearing.
        out.resize(w * self.height as usize * 4, 0);
        if w == 0 {
            return;
        }
        let enc = Encoder::new(self.encoding);
        out.par_chunks_mut(w * 4).enumerate().for_each(|(y, row)| {
            for (x, at, n) in self.row_runs(y as u32) {
                let bytes = row[4 * x..4 * (x + n)].chunks_exact_mut(4);
                for (px, &p) in bytes.zip(&self.color[at..at + n]) {
                    let a = p >> 24;
                    let word = if a != 0 && a != 255 {
                        let s = unpack(self.encoding, p).unpremultiply();
                        enc.pack(s.r, s.g, s.b, s.a)
                    } else {
                        p
                    };
                    px.copy_from_slice(&word.to_le_bytes());
                }
            }
        });
    }

    /// Writes `0x00RRGGBB` words (a window's framebuffer format), row-major.
    pub fn write_rgb_u32(&self, out: &mut Vec<u32>) {
        out.clear();
        for y in 0..self.height {
            for x in 0..self.width {
                let [r, g, b, _] = self.color[self.index(x, y)].to_le_bytes();
                out.push((r as u32) << 16 | (g as u32) << 8 | b as u32);
            }
        }
    }

    /// Row-major OpenGL window depth (`0.5 * ndc_z + 0.5`; 1.0 where nothing was drawn).
    pub fn depth_gl_image(&self) -> Vec<f32> {
        let mut out = Vec::with_capacity(self.width as usize * self.height as usize);
        for y in 0..self.height {
            for x in 0..self.width {
                out.push(crate::camera::gl_window_depth(self.depth[self.index(x, y)]));
            }
        }
        out
    }

    /// The colour as a texture (premultiplied, same encoding); `None` for a 0-sized target.
    pub fn to_texture(&self) -> Option<Texture> {
        let mut texels = Vec::with_capacity(self.width as usize * self.height as usize);
        for y in 0..self.height {
            for x in 0..self.width {
                texels.push(self.color[self.index(x, y)]);
            }
        }
        Texture::from_packed(self.width, self.height, texels, self.encoding, true)
    }

    /// Copies the colour into `tex` (premultiplied, same encoding) in `tex`'s own memory
    /// (see [`Texture::refill`]); `false` for a 0-sized target.
    pub fn copy_to_texture(&self, tex: &mut Texture) -> bool {
        let w = self.width as usize;
        tex.refill(self.width, self.height, self.encoding, true, |out| {
            for (y, row) in out.chunks_exact_mut(w.max(1)).enumerate() {
                for (x, at, n) in self.row_runs(y as u32) {
                    copy_run(&mut row[x..x + n], &self.color[at..at + n]);
                }
            }
        })
    }

    /// The tile-major depth storage, for the renderer to read a peel depth from.
    pub(crate) fn depth_storage(&self) -> &[f32] {
        &self.depth
    }

    /// The tile-major colour and depth storage, for the renderer to split into tiles.
    pub(crate) fn storage_mut(&mut self) -> (&mut [u32], &mut [f32]) {
        (&mut self.color, &mut self.depth)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_sized_targets_are_fine() {
        let t = Target::new(0, 0);
        assert_eq!(t.tile_count(), 0);
        assert!(t.pixel(0, 0).is_none());
        assert!(t.to_rgba8().is_empty());
        assert!(t.to_texture().is_none());
    }

    #[test]
    fn copy_to_texture_matches_to_texture() {
        let mut t = Target::new(70, 9);
        for (i, px) in t.color.iter_mut().enumerate() {
            *px = (i as u32).wrapping_mul(0x9e37_79b9);
        }
        let mut tex = Texture::solid(Rgba::WHITE);
        assert!(t.copy_to_texture(&mut tex));
        assert_eq!(Some(tex), t.to_texture());
        assert!(!Target::new(0, 3).copy_to_texture(&mut Texture::solid(Rgba::WHITE)));
    }

    #[test]
    fn index_is_a_bijection_onto_tile_memory() {
        let t = Target::new(130, 70);
        let mut seen = vec![false; t.color.len()];
        for y in 0..70 {
            for x in 0..130 {
                let i = t.index(x, y);
                assert!(!seen[i]);
                seen[i] = true;
            }
        }
        assert_eq!(t.tiles_x(), 3);
        assert_eq!(t.tiles_y(), 2);
    }

    #[test]
    fn rows_read_as_pixel_by_pixel() {
        let mut t = Target::new(141, 70);
        for (i, (px, d)) in t.color.iter_mut().zip(&mut t.depth).enumerate() {
            *px = (i as u32).wrapping_mul(0x9e37_79b9);
            *d = i as f32;
        }
        let (mut c, mut d) = (Vec::new(), Vec::new());
        let mut bytes = Vec::new();
        for y in 0..70 {
            t.read_row(y, &mut c, &mut d);
            let px: Vec<u32> = (0..141).map(|x| t.pixel(x, y).unwrap()).collect();
            let depth: Vec<f32> = (0..141).map(|x| t.depth_reversed(x, y).unwrap()).collect();
            assert_eq!((&c, &d), (&px, &depth), "row {y}");
            bytes.extend(px.iter().flat_map(|p| p.to_le_bytes()));
        }
        assert_eq!(t.to_rgba8_premultiplied(), bytes);
        t.read_row(70, &mut c, &mut d);
        assert!(c.is_empty() && d.is_empty());
    }

    #[test]
    fn clear_and_read_back() {
        let mut t = Target::with_encoding(3, 2, Encoding::Unorm);
        t.clear(Rgba::new(1.0, 0.5, 0.0, 1.0));
        assert_eq!(&t.to_rgba8()[..4], &[255, 128, 0, 255]);
        assert_eq!(t.depth_gl(2, 1), Some(1.0));
        t.resize(100_000, 1);
        assert_eq!(t.width(), MAX_TARGET_SIZE);
    }
}
