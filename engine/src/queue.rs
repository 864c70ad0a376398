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

use crate::shade::{Pixels, Row, LANES};
use crate::simd::{F8, I8, M8};

/// A row tested and waiting for its colour.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Waiting {
    /// Index of the row's first pixel in the tile buffers.
    pub base: usize,
    /// Lanes that passed the depth test.
    pub mask: u32,
    /// The row's interpolated depth.
    pub z: F8,
    /// Its first lane's place in the triangle's stream of queued lanes.
    start: usize,
}

/// See the module doc. The batch is built in vectors (a row's lanes packed by one permute
/// and placed by a lane-range select), so nothing is stored lane by lane and reloaded
/// whole, and a row's colours come back from the last two shaded batches in registers.
#[derive(Clone, Debug)]
pub(crate) struct Queue {
    /// Rows waiting, from `done` on; rows before `done` are written.
    pub rows: Vec<Waiting>,
    done: usize,
    /// Lanes queued since the triangle began, and batches shaded.
    queued: usize,
    batches: usize,
    /// The batch being filled: `n` lanes.
    pub n: usize,
    fx: F8,
    fy: F8,
    lane: F8,
    row: I8,
    fixed: M8,
    lod: F8,
    /// Shaded straight colours of the batch before the last, and of the last.
    prev: [F8; 4],
    last: [F8; 4],
    /// Blocks whose farthest depth is recomputed once the triangle's rows are written.
    pub far: Vec<usize>,
}

impl Default for Queue {
    fn default() -> Self {
        let zero = F8::splat(0.0);
        Queue {
            rows: Vec::new(),
            done: 0,
            queued: 0,
            batches: 0,
            n: 0,
            fx: zero,
            fy: zero,
            lane: zero,
            row: I8::splat(0),
            fixed: M8::from_bits(0),
            lod: zero,
            prev: [zero; 4],
            last: [zero; 4],
            far: Vec::new(),
        }
    }
}

/// A row's lanes, packed to the front and turned to start at the batch's fill point.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Packed {
    lane: F8,
    fx: f32,
    fy: f32,
    row: i32,
    lod: Option<f32>,
    /// Lanes still to place after the batch that filled up is shaded.
    pub rest: usize,
}

impl Queue {
    /// Queues the lanes `mask` of `row` with depth `z` and packs them into the batch
    /// from its fill point on; `lod` is the row's level of detail when it does not fit in
    /// the batch. When the batch fills up (`n == LANES`), the caller shades it and then
    /// places the rest with [`Queue::place_rest`].
    #[inline(always)]
    pub fn add(&mut self, base: usize, mask: u32, z: F8, row: &Row, lod: Option<f32>) -> Packed {
        let count = mask.count_ones() as usize;
        let tag = self.rows.len() as i32;
        self.rows.push(Waiting {
            base,
            mask,
            z,
            start: self.queued,
        });
        self.queued += count;
        let turn = TURN[self.n];
        let lane = F8::ramp()
            .permute_by(I8::from_array(PACK[mask as usize & 0xff]))
            .permute_by(I8::from_array(turn));
        let p = Packed {
            lane,
            fx: row.fx,
            fy: row.fy,
            row: tag,
            lod,
            rest: (self.n + count).saturating_sub(LANES),
        };
        let end = (self.n + count).min(LANES);
        self.place(&p, self.n, end);
        self.n = end;
        p
    }

    /// Places the lanes of `p` that did not fit, at the start of the new batch.
    #[inline(always)]
    pub fn place_rest(&mut self, p: &Packed) {
        self.place(p, 0, p.rest);
        self.n = p.rest;
    }

    #[inline(always)]
    fn place(&mut self, p: &Packed, lo: usize, hi: usize) {
        let m = I8::lane_range(lo as i32, hi as i32 - 1);
        self.fx = m.select(F8::splat(p.fx), self.fx);
        self.fy = m.select(F8::splat(p.fy), self.fy);
        self.lane = m.select(p.lane, self.lane);
        self.row = m.select_i32(I8::splat(p.row), self.row);
        if let Some(l) = p.lod {
            self.fixed = self.fixed.or(m);
            self.lod = m.select(F8::splat(l), self.lod);
        } else {
            self.fixed = self.fixed.and_not(m);
        }
    }

    /// The batch's lanes and the mask of those in use; empties the batch.
    #[inline]
    pub fn take(&mut self) -> (Pixels, u32) {
        let px = Pixels {
            fx: self.fx,
            fy: self.fy,
            lane: self.lane,
            row: self.row.to_array().map(|r| r as u32),
            fixed: self.fixed.bits(),
            lod: self.lod.to_array(),
        };
        let mask = (1u32 << self.n) - 1;
        self.n = 0;
        (px, mask)
    }

    /// Keeps the shaded colours of the batch just taken.
    #[inline]
    pub fn keep(&mut self, out: [F8; 4]) {
        self.prev = self.last;
        self.last = out;
        self.batches += 1;
    }

    /// The next waiting row and its lanes' colours (lanes not in its mask hold any of its
    /// colours), if all its lanes are shaded; marks it written.
    #[inline]
    pub fn next_ready(&mut self) -> Option<(Waiting, [F8; 4])> {
        let w = *self.rows.get(self.done)?;
        let count = w.mask.count_ones() as usize;
        let shaded = (self.batches * LANES).min(self.queued);
        if w.start + count > shaded {
            return None;
        }
        // Rows that ended in earlier batches are written, so this one starts in the batch
        // before the last or later: its lanes are lanes `off + rank` of `prev` then `last`.
        let off = w.start + LANES - (self.batches - 1) * LANES;
        let idx = I8::from_array(EXPAND[w.mask as usize & 0xff]) + I8::splat(off as i32);
        let from_last = idx.shr::<3>().eq(I8::splat(1));
        let out = std::array::from_fn(|c| {
            from_last.select(self.last[c].permute_by(idx), self.prev[c].permute_by(idx))
        });
        self.done += 1;
        Some((w, out))
    }

    /// Forgets the triangle (all its rows written).
    #[inline]
    pub fn reset(&mut self) {
        debug_assert_eq!(self.done, self.rows.len());
        self.rows.clear();
        self.done = 0;
        self.queued = 0;
        self.batches = 0;
        self.n = 0;
    }
}

/// For each 8-lane mask, lane `l`'s place among the mask's set lanes (its rank: set lanes
/// below it), so that packed values spread back to their lanes by one permute.
const EXPAND: [[i32; LANES]; 256] = {
    let mut t = [[0i32; LANES]; 256];
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

/// For each 8-lane mask, its set lanes packed to the front (the rest repeat lane 0).
const PACK: [[i32; LANES]; 256] = {
    let mut t = [[0i32; LANES]; 256];
    let mut m = 0;
    while m < 256 {
        let mut l = 0;
        let mut k = 0;
        while l < LANES {
            if m >> l & 1 != 0 {
                t[m][k] = l as i32;
                k += 1;
            }
            l += 1;
        }
        m += 1;
    }
    t
};

/// Turning packed lanes to start at lane `n`: lane `k` takes packed lane `(k - n) mod 8`.
const TURN: [[i32; LANES]; LANES] = {
    let mut t = [[0i32; LANES]; LANES];
    let mut n = 0;
    while n < LANES {
        let mut k = 0;
        while k < LANES {
            t[n][k] = ((k + LANES - n) % LANES) as i32;
            k += 1;
        }
        n += 1;
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
