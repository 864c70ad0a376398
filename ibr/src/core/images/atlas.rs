//! Atlases: a grid of equally sized depth images (cells) in one pair of planes, each cell
//! with the camera that took it, as baked impostors and sprite sheets store their views.
//! Cell `k` sits at column `k % cols`, row `k / cols`.

use super::{DepthImage, EMPTY};
use engine::color::Encoder;
use engine::{Camera, Encoding, Premul, Rgba, Texture};

/// `cols x rows` cells of `cell_w x cell_h` pixels.
#[derive(Clone, Debug, PartialEq)]
pub struct Atlas {
    cols: u32,
    rows: u32,
    cell_w: u32,
    cell_h: u32,
    /// Premultiplied linear colour of the whole atlas, row-major.
    pub color: Vec<Premul>,
    /// Distance along each cell camera's axis; [`EMPTY`] where nothing was drawn.
    pub depth: Vec<f32>,
    /// The camera of every cell (`None` until the cell is written).
    pub cameras: Vec<Option<Camera>>,
}

impl Atlas {
    /// An empty (transparent) atlas.
    pub fn new(cols: u32, rows: u32, cell_w: u32, cell_h: u32) -> Self {
        let n = (cols * cell_w) as usize * (rows * cell_h) as usize;
        Atlas {
            cols,
            rows,
            cell_w,
            cell_h,
            color: vec![Premul::TRANSPARENT; n],
            depth: vec![EMPTY; n],
            cameras: vec![None; (cols * rows) as usize],
        }
    }

    /// Width and height of the whole atlas, pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.cols * self.cell_w, self.rows * self.cell_h)
    }

    /// Cells per row and per column.
    pub fn grid(&self) -> (u32, u32) {
        (self.cols, self.rows)
    }

    /// Cell width and height, pixels.
    pub fn cell_size(&self) -> (u32, u32) {
        (self.cell_w, self.cell_h)
    }

    /// Number of cells (`cols * rows`).
    pub fn cell_count(&self) -> u32 {
        self.cols * self.rows
    }

    /// Cell `k`'s top-left pixel, `None` past the last cell.
    pub fn cell_origin(&self, k: u32) -> Option<(u32, u32)> {
        (k < self.cell_count())
            .then(|| ((k % self.cols) * self.cell_w, (k / self.cols) * self.cell_h))
    }

    /// Copies `image` into cell `k` (its top-left part if larger, the rest of the cell left
    /// as it was if smaller) with its camera. Returns false past the last cell.
    pub fn write_cell(&mut self, k: u32, image: &DepthImage) -> bool {
        let Some((ox, oy)) = self.cell_origin(k) else {
            return false;
        };
        let (w, _) = self.size();
        let cw = image.width().min(self.cell_w);
        for y in 0..image.height().min(self.cell_h) {
            let src = (y * image.width()) as usize;
            let dst = ((oy + y) * w + ox) as usize;
            self.color[dst..dst + cw as usize]
                .copy_from_slice(&image.color[src..src + cw as usize]);
            self.depth[dst..dst + cw as usize]
                .copy_from_slice(&image.depth[src..src + cw as usize]);
        }
        self.cameras[k as usize] = Some(image.camera);
        true
    }

    /// Cell `k` as a depth image of its own, `None` past the last cell or before it was
    /// written.
    pub fn cell(&self, k: u32) -> Option<DepthImage> {
        let (ox, oy) = self.cell_origin(k)?;
        let camera = self.cameras[k as usize]?;
        let (w, _) = self.size();
        let mut out = DepthImage::new(self.cell_w, self.cell_h, camera);
        for y in 0..self.cell_h {
            let src = ((oy + y) * w + ox) as usize;
            let dst = (y * self.cell_w) as usize;
            let n = self.cell_w as usize;
            out.color[dst..dst + n].copy_from_slice(&self.color[src..src + n]);
            out.depth[dst..dst + n].copy_from_slice(&self.depth[src..src + n]);
        }
        Some(out)
    }

    /// The colour as a texture for drawing: premultiplied, `encoding`, optionally mipmapped.
    pub fn to_texture(&self, encoding: Encoding, mipmaps: bool) -> Texture {
        let (w, h) = self.size();
        let enc = Encoder::new(encoding);
        let texels = self
            .color
            .iter()
            .map(|c| enc.pack(c.r, c.g, c.b, c.a))
            .collect();
        Texture::from_packed(w, h, texels, encoding, mipmaps)
            .unwrap_or_else(|| Texture::solid(Rgba::TRANSPARENT))
    }
}
