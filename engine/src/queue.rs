//! Fragment queue: one triangle's depth-tested fragments in one tile, gathered across rows
//! so that a batched shader runs on full 8-lane batches instead of rows with few lanes set.
//!
//! The rasterizer tests depth row by row as before and queues each row that has passing
//! lanes; the passing lanes are packed into the batch being filled, and each full batch is
//! shaded at once. A row is written (alpha test, blending, depth write: `write_row` as on
//! the row path) as soon as all its lanes are shaded, so rows are written in the order they
//! were tested. Fragments of one triangle never overlap, so testing a row before an earlier
//! row is written reads the same depth as before. The queue lives in the tile's buffers and
//! keeps its memory from triangle to triangle and frame to frame.

use crate::shade::{Pixels, LANES};
use crate::simd::F8;
use crate::target::TILE_PIXELS;

/// A row tested and waiting for its colour.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Waiting {
    /// Index of the row's first pixel in the tile buffers.
    pub base: usize,
    /// Lanes that passed the depth test.
    pub mask: u32,
    /// The row's interpolated depth.
    pub z: [f32; LANES],
}

/// See the module doc.
#[derive(Clone, Debug, Default)]
pub(crate) struct Queue {
    /// Rows waiting, from `done` on; rows before `done` are written.
    pub rows: Vec<Waiting>,
    pub done: usize,
    /// Shaded straight colour of the waiting rows' lanes, one plane per channel, in row
    /// and lane order: `len` values, read up to `used`. Grown once to hold a tile's pixels
    /// (a triangle's fragments in a tile) plus a batch of slack for whole-vector stores.
    pub shaded: [Vec<f32>; 4],
    pub len: usize,
    pub used: usize,
    /// The batch being filled: `n` lanes.
    pub n: usize,
    fx: [f32; LANES],
    fy: [f32; LANES],
    lane: [f32; LANES],
    row: [u32; LANES],
    fixed: u32,
    lod: [f32; LANES],
    /// Blocks whose farthest depth is recomputed once the triangle's rows are written.
    pub far: Vec<usize>,
}

impl Queue {
    /// Adds lane `lane` of the row at `(fx, fy)`, the `row`-th queued row, to the batch;
    /// `lod` is the row's level of detail when the row is split between two batches.
    #[inline(always)]
    pub fn push(&mut self, fx: f32, fy: f32, lane: u32, row: u32, lod: Option<f32>) {
        let k = self.n;
        self.fx[k] = fx;
        self.fy[k] = fy;
        self.lane[k] = lane as f32;
        self.row[k] = row;
        if let Some(l) = lod {
            self.fixed |= 1 << k;
            self.lod[k] = l;
        }
        self.n += 1;
    }

    /// The batch's lanes, and the mask of those in use; empties the batch.
    #[inline]
    pub fn take(&mut self) -> (Pixels, u32) {
        let px = Pixels {
            fx: F8::from_array(self.fx),
            fy: F8::from_array(self.fy),
            lane: F8::from_array(self.lane),
            row: self.row,
            fixed: self.fixed,
            lod: self.lod,
        };
        let mask = (1u32 << self.n) - 1;
        self.n = 0;
        self.fixed = 0;
        (px, mask)
    }

    /// Keeps the shaded colours of the first `n` lanes of `out`.
    #[inline]
    pub fn keep(&mut self, out: &[F8; 4], n: usize) {
        for (plane, o) in self.shaded.iter_mut().zip(out) {
            if plane.len() < self.len + LANES {
                plane.resize((self.len + LANES).max(TILE_PIXELS + LANES), 0.0);
            }
            o.store(&mut plane[self.len..]);
        }
        self.len += n;
    }

    /// The next waiting row and its lanes' colours (lanes not in its mask hold any of its
    /// colours), if all its lanes are shaded; marks it written.
    #[inline]
    pub fn next_ready(&mut self) -> Option<(Waiting, [F8; 4])> {
        let w = *self.rows.get(self.done)?;
        let count = w.mask.count_ones() as usize;
        if self.len - self.used < count {
            return None;
        }
        // The row's lanes sit packed from `used`: spread them back to their places.
        let idx = EXPAND[w.mask as usize & 0xff];
        let used = self.used;
        let out = std::array::from_fn(|c| F8::load(&self.shaded[c][used..]).permute(idx));
        self.done += 1;
        self.used += count;
        if self.done == self.rows.len() {
            self.rows.clear();
            self.done = 0;
            self.len = 0;
            self.used = 0;
        }
        Some((w, out))
    }
}

/// For each 8-lane mask, lane `l`'s place among the mask's set lanes (its rank: set lanes
/// below it), so that packed values spread back to their lanes by one permute.
const EXPAND: [[u32; LANES]; 256] = {
    let mut t = [[0u32; LANES]; 256];
    let mut m = 0;
    while m < 256 {
        let mut l = 0;
        let mut rank = 0;
        while l < LANES {
            if m >> l & 1 != 0 {
                t[m][l] = rank;
                rank += 1;
            }
            l += 1;
        }
        m += 1;
    }
    t
};

#[cfg(test)]
mod tests {
    use crate::color::Encoding;
    use crate::procedural::torus_with_triangles;
    use crate::texture::{Filter, Sampler};
    use crate::{Camera, Draw, FrameOptions, Light, Lighting, Material, Renderer, Rgba};
    use crate::{Target, Texture};
    use glam::{Mat4, Vec3};
    use std::sync::Arc;

    /// A textured (trilinear, mipmapped), lit torus of 10k triangles at 1280 x 720, as in
    /// the fragment benchmark: its triangles cover a few pixels per row (3.3 lanes of 8 per
    /// row on the row path), yet the queue fills the shader's lanes: at least 7 of 8 used
    /// per run of the shader on average. (A triangle's batches are its own, so triangles of
    /// a few pixels, as at 320 x 180, leave lanes idle still.)
    #[test]
    fn textured_fragments_are_shaded_in_full_batches() {
        let n = 64;
        let px: Vec<u8> = (0..n * n)
            .flat_map(|i| {
                let on = (i % n / 8 + i / n / 8) % 2 == 0;
                if on {
                    [230, 200, 60, 255]
                } else {
                    [40, 90, 200, 255]
                }
            })
            .collect();
        let tex = Texture::from_rgba8(n as u32, n as u32, &px, Encoding::Srgb).expect("64x64");
        assert!(tex.levels().len() > 1, "mipmapped");
        let mut material = Material::lit(Rgba::WHITE).with_texture(Arc::new(tex));
        material.sampler = Sampler {
            filter: Filter::Trilinear,
            ..Default::default()
        };
        let mesh = torus_with_triangles(10_000);
        let lighting = Lighting {
            ambient: Rgba::new(0.1, 0.1, 0.1, 1.0),
            lights: vec![Light::Directional {
                direction: Vec3::new(-0.3, -1.0, -0.5),
                color: Rgba::WHITE,
            }],
        };
        let (w, h) = (1280, 720);
        let eye = Vec3::new(0.0, 1.6, 2.6);
        let camera = Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 0.9, w as f32 / h as f32);
        let mut target = Target::with_encoding(w, h, Encoding::Srgb);
        let draw = Draw {
            mesh: &mesh,
            material: &material,
            transform: Mat4::IDENTITY,
        };
        let stats = Renderer::new().render(
            [draw],
            &camera,
            &lighting,
            &mut target,
            &FrameOptions::default(),
        );
        assert!(stats.fragments_shaded > 100_000, "{stats:?}");
        assert!(
            stats.fragments_written == stats.fragments_shaded,
            "{stats:?}"
        );
        let per_run = stats.fragments_shaded as f64 / stats.rows_shaded as f64;
        assert!(per_run >= 7.0, "{per_run:.2} lanes per run: {stats:?}");
        assert!(per_run <= 8.0, "{per_run:.2} lanes per run: {stats:?}");
    }
}
