//! References prepared for warping: what the warp reads of each sample (its disparity, the
//! slope of its surface's disparity, its colour as packed bytes) computed once when the
//! reference is made, not per frame, and laid out as planes so the warp's inner loop reads
//! 16 bytes a sample, eight samples at a time, and divides once.

use super::is_filled;
use super::warped::{ENCODING, HOLE};
use crate::core::{DepthImage, LayeredDepthImage};
use engine::color::Encoder;
use engine::{Camera, Premul};

/// A depth image or LDI as the warp reads it.
#[derive(Clone, Debug)]
pub struct Prepared {
    camera: Camera,
    width: u32,
    height: u32,
    /// Pixel `p`'s samples are `first[p]..first[p + 1]`, in painting order (back to front).
    /// Empty for a depth image: one sample per pixel, its index the pixel's.
    pub(crate) first: Vec<u32>,
    /// `1 / depth`; 0 at infinity (sky); [`HOLE`] for an empty pixel of a depth image.
    pub(crate) disparity: Vec<f32>,
    /// The change of disparity per pixel step in x on the sample's surface (zero across a
    /// depth edge), and in y.
    pub(crate) slope_x: Vec<f32>,
    pub(crate) slope_y: Vec<f32>,
    /// Premultiplied bytes in [`ENCODING`].
    pub(crate) color: Vec<u32>,
    /// The least and greatest disparity of each block of [`BLOCK`] pixels of a row (row
    /// by row, blocks left to right), over its samples; `[INFINITY, -INFINITY]` when it
    /// has none. Bounds where a block can land before it is warped.
    pub(crate) blocks: Vec<[f32; 2]>,
    /// The samples (non-empty).
    samples: u64,
    /// The edge tolerance the slopes were read with.
    edge: f32,
}

/// Pixels of a row per block of [`Prepared::blocks`].
pub(super) const BLOCK: u32 = 64;

impl Default for Prepared {
    fn default() -> Self {
        let camera = Camera::look_at(glam::Vec3::Z, glam::Vec3::ZERO, glam::Vec3::Y, 1.0, 1.0);
        Prepared {
            camera,
            width: 0,
            height: 0,
            first: Vec::new(),
            disparity: Vec::new(),
            slope_x: Vec::new(),
            slope_y: Vec::new(),
            color: Vec::new(),
            blocks: Vec::new(),
            samples: 0,
            edge: 0.0,
        }
    }
}

/// A sample's disparity, or [`HOLE`] when it is empty (no colour, depth NaN or not
/// positive).
#[inline]
fn disparity(c: Premul, z: f32) -> f32 {
    if !is_filled(c) || z.is_nan() || z <= 0.0 {
        HOLE
    } else if z.is_finite() {
        1.0 / z
    } else {
        0.0
    }
}

impl Prepared {
    /// `image` prepared, slopes read across neighbours within `edge` (relative depth).
    pub fn from_image(image: &DepthImage, edge: f32) -> Self {
        let mut p = Prepared::default();
        p.prepare_image(image, edge);
        p
    }

    /// `ldi` prepared likewise.
    pub fn from_ldi(ldi: &LayeredDepthImage, edge: f32) -> Self {
        let mut p = Prepared::default();
        p.prepare_ldi(ldi, edge);
        p
    }

    /// The camera the reference was captured with.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// The reference's width and height, pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The edge tolerance the slopes were read with.
    pub fn edge(&self) -> f32 {
        self.edge
    }

    /// The samples (non-empty).
    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// Whether each pixel has one sample (a depth image).
    pub(super) fn single(&self) -> bool {
        self.first.is_empty()
    }

    /// Re-prepares from `image`, keeping this one's memory.
    pub fn prepare_image(&mut self, image: &DepthImage, edge: f32) {
        let (w, h) = (image.width(), image.height());
        self.start(image.camera, w, h, edge);
        let enc = Encoder::new(ENCODING);
        for (c, &z) in image.color.iter().zip(&image.depth) {
            self.disparity.push(disparity(*c, z));
            self.color.push(enc.pack(c.r, c.g, c.b, c.a));
        }
        let same = |x: u32, y: u32, z: f32| -> Option<f32> {
            let (c, d) = image.get(x, y)?;
            (is_filled(c) && d.is_finite() && (d - z).abs() <= edge * z).then(|| 1.0 / d)
        };
        for y in 0..h {
            for x in 0..w {
                let z = image.depth[(y * w + x) as usize];
                self.push_slope(slope(x, y, z, |x, y| same(x, y, z)));
            }
        }
        self.bound_blocks();
    }

    /// Re-prepares from `ldi`, keeping this one's memory. Empty samples are left out.
    pub fn prepare_ldi(&mut self, ldi: &LayeredDepthImage, edge: f32) {
        let (w, h) = (ldi.width(), ldi.height());
        self.start(ldi.camera, w, h, edge);
        let enc = Encoder::new(ENCODING);
        let same = |x: u32, y: u32, z: f32| -> Option<f32> {
            if x >= w || y >= h {
                return None;
            }
            ldi.samples(x, y)
                .iter()
                .find(|s| {
                    is_filled(s.color) && s.depth.is_finite() && (s.depth - z).abs() <= edge * z
                })
                .map(|s| 1.0 / s.depth)
        };
        for y in 0..h {
            for x in 0..w {
                self.first.push(self.disparity.len() as u32);
                for s in ldi.samples(x, y).iter().rev() {
                    let d = disparity(s.color, s.depth);
                    if d == HOLE {
                        continue;
                    }
                    let c = s.color;
                    self.disparity.push(d);
                    self.color.push(enc.pack(c.r, c.g, c.b, c.a));
                    self.push_slope(slope(x, y, s.depth, |x, y| same(x, y, s.depth)));
                }
            }
        }
        self.first.push(self.disparity.len() as u32);
        self.bound_blocks();
    }

    fn push_slope(&mut self, [x, y]: [f32; 2]) {
        self.slope_x.push(x);
        self.slope_y.push(y);
    }

    /// The disparity range of block `b` of row `y`.
    pub(super) fn block(&self, y: u32, b: u32) -> [f32; 2] {
        self.blocks[(y * self.width.div_ceil(BLOCK) + b) as usize]
    }

    /// Fills [`Prepared::blocks`] from the samples.
    fn bound_blocks(&mut self) {
        let (w, h) = (self.width, self.height);
        self.blocks.clear();
        self.samples = 0;
        for y in 0..h {
            for x0 in (0..w).step_by(BLOCK as usize) {
                let (p0, p1) = (
                    (y * w + x0) as usize,
                    (y * w + (x0 + BLOCK).min(w)) as usize,
                );
                let samples = if self.single() {
                    p0..p1
                } else {
                    self.first[p0] as usize..self.first[p1] as usize
                };
                let mut range = [f32::INFINITY, f32::NEG_INFINITY];
                for &d in &self.disparity[samples] {
                    if d >= 0.0 {
                        range = [range[0].min(d), range[1].max(d)];
                        self.samples += 1;
                    }
                }
                self.blocks.push(range);
            }
        }
    }

    fn start(&mut self, camera: Camera, w: u32, h: u32, edge: f32) {
        self.camera = camera;
        self.width = w;
        self.height = h;
        self.edge = edge;
        self.first.clear();
        self.disparity.clear();
        self.slope_x.clear();
        self.slope_y.clear();
        self.color.clear();
        self.blocks.clear();
    }
}

/// The change of disparity per pixel step in x and in y at pixel `(x, y)`, a sample of
/// depth `z`: from the neighbour ahead, else the one behind, when on the same surface
/// (`same(x, y)`: the disparity there if so); else zero.
fn slope(x: u32, y: u32, z: f32, same: impl Fn(u32, u32) -> Option<f32>) -> [f32; 2] {
    if !(z.is_finite() && z > 0.0) {
        return [0.0; 2];
    }
    let axis = |dx: u32, dy: u32| {
        if let Some(ahead) = same(x + dx, y + dy) {
            return ahead - 1.0 / z;
        }
        if x >= dx && y >= dy {
            if let Some(behind) = same(x - dx, y - dy) {
                return 1.0 / z - behind;
            }
        }
        0.0
    };
    [axis(1, 0), axis(0, 1)]
}
