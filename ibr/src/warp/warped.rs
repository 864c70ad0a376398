//! The warp's output: an image at the target camera holding, per pixel, a packed colour and
//! a disparity, 8 bytes a pixel, in the form the frame's target stores colour (so the
//! image pass copies bytes) and with the depth the warp computes without a divide.

use crate::core::{DepthImage, EMPTY};
use engine::color::unpack;
use engine::{Camera, Encoding, Premul};
use rayon::prelude::*;

/// The encoding of warped colours (and of prepared references): the engine's default
/// target encoding.
pub const ENCODING: Encoding = Encoding::Srgb;

/// The disparity of a hole (nothing landed there). Any negative disparity is a hole.
pub const HOLE: f32 = -1.0;

/// A warped image: colour and disparity per pixel, row-major, and the camera it is seen by.
#[derive(Clone, Debug, PartialEq)]
pub struct Warped {
    width: u32,
    height: u32,
    /// Premultiplied bytes `r | g << 8 | b << 16 | a << 24` in [`ENCODING`]; 0 in holes.
    pub color: Vec<u32>,
    /// `1 / depth` along the camera's axis, 0 at infinity (sky), [`HOLE`] where nothing is.
    pub disparity: Vec<f32>,
    /// The camera the image is seen from: the view warped to.
    pub camera: Camera,
}

impl Warped {
    /// An image of holes.
    pub fn new(width: u32, height: u32, camera: Camera) -> Self {
        let n = width as usize * height as usize;
        Warped {
            width,
            height,
            color: vec![0; n],
            disparity: vec![HOLE; n],
            camera,
        }
    }

    /// Makes this `w` x `h` at `camera`, all holes, keeping its memory.
    pub fn reset(&mut self, camera: &Camera, w: u32, h: u32) {
        let n = w as usize * h as usize;
        self.width = w;
        self.height = h;
        self.camera = *camera;
        self.color.resize(n, 0);
        self.disparity.resize(n, HOLE);
        // Cleared on the thread pool: a 1080p image is 16 MB.
        const CHUNK: usize = 1 << 16;
        self.color.par_chunks_mut(CHUNK).for_each(|c| c.fill(0));
        self.disparity
            .par_chunks_mut(CHUNK)
            .for_each(|d| d.fill(HOLE));
    }

    /// Makes the pixels of `[x0, y0, x1, y1]` (clamped to the image) holes: the only ones
    /// to clear when nothing else was written since the last clear.
    pub fn clear_rect(&mut self, [x0, y0, x1, y1]: [u32; 4]) {
        let w = self.width as usize;
        let (x0, x1) = (x0.min(self.width) as usize, x1.min(self.width) as usize);
        for y in y0.min(self.height) as usize..y1.min(self.height) as usize {
            let row = y * w + x0..y * w + x1.max(x0);
            self.color[row.clone()].fill(0);
            self.disparity[row].fill(HOLE);
        }
    }

    /// Columns, pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Rows, pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Whether pixel `i` (row-major) holds a sample.
    #[inline]
    pub fn is_filled(&self, i: usize) -> bool {
        self.disparity[i] >= 0.0
    }

    /// Depth along the axis at pixel `i`: infinity for sky, [`EMPTY`] in a hole.
    pub fn depth(&self, i: usize) -> f32 {
        let d = self.disparity[i];
        if d > 0.0 {
            1.0 / d
        } else {
            EMPTY
        }
    }

    /// Premultiplied linear colour at pixel `i` (transparent in a hole).
    pub fn color_linear(&self, i: usize) -> Premul {
        if self.is_filled(i) {
            unpack(ENCODING, self.color[i])
        } else {
            Premul::TRANSPARENT
        }
    }

    /// Filled pixels (counted on the thread pool: a 1080p image is 2 M pixels).
    pub fn filled(&self) -> u64 {
        self.disparity
            .par_chunks(1 << 16)
            .map(|c| c.iter().filter(|d| **d >= 0.0).count() as u64)
            .sum()
    }

    /// As a depth image (linear colour and depth), for files and comparisons.
    pub fn to_depth_image(&self) -> DepthImage {
        let n = self.disparity.len();
        let color = (0..n).map(|i| self.color_linear(i)).collect();
        let depth = (0..n).map(|i| self.depth(i)).collect();
        DepthImage::from_planes(self.width, self.height, color, depth, self.camera)
            .expect("planes of the image's own size")
    }
}
