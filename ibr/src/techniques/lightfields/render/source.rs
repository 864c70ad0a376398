//! Where a render reads samples from: raw or quantised rays, the choice made once per
//! frame (the kernels monomorphise). A camera's image is found once per batch of rays
//! ([`Source::image`]), then read either eight samples of one row at a time (the rays of
//! neighbouring pixels read neighbouring samples) or one sample at a time.

use super::super::{Quantised, RawRays, Slab};
use engine::simd::{F8, LANES};

/// Samples by camera: [`Source::image`] finds camera `(u, v)`'s image, the other methods
/// read it (indices within the slab's counts).
pub(super) trait Source: Sync {
    /// Where one camera's image is.
    type Image: Copy + Default;

    fn image(&self, u: u32, v: u32) -> Self::Image;

    /// Packed colour of sample `(s, t)`.
    fn sample(&self, image: Self::Image, s: u32, t: u32) -> u32;

    /// Depth of sample `(s, t)`; called only when depth is kept.
    fn depth(&self, image: Self::Image, s: u32, t: u32) -> f32;

    /// The nearest and farthest finite depth of any sample (`None`: no sample met a
    /// surface, or depth is not kept).
    fn depth_range(&self) -> Option<(f32, f32)>;

    /// What the first sample of a row window ([`Source::sample_row`]) must be a multiple
    /// of: a power of two, at most 8.
    fn align(&self) -> u32;

    /// Samples `(start + l, t)`, lane `l`, packed colours as bits of `f32`s, `start` a
    /// multiple of [`Source::align`]; `None` when they reach past the stored samples
    /// (those past the row's end are not to be used).
    fn sample_row(&self, image: Self::Image, t: u32, start: u32) -> Option<F8>;

    /// Depths of samples `(start + l, t)`, as [`Source::sample_row`].
    fn depth_row(&self, image: Self::Image, t: u32, start: u32) -> Option<F8>;

    /// [`Source::sample_row`] of two rows.
    #[inline(always)]
    fn sample_rows(&self, image: Self::Image, [t0, t1]: [u32; 2], start: u32) -> Option<[F8; 2]> {
        Some([
            self.sample_row(image, t0, start)?,
            self.sample_row(image, t1, start)?,
        ])
    }
}

/// Eight lanes from `s`, if it holds them.
#[inline(always)]
fn lanes<T: Copy>(s: &[T], start: usize) -> Option<[T; LANES]> {
    s.get(start..start + LANES)?.try_into().ok()
}

/// Raw rays: an image is where its samples start.
pub(super) struct RawSource<'a> {
    samples: &'a [u32],
    depth: &'a [f32],
    nu: usize,
    ns: usize,
    image_len: usize,
    range: Option<(f32, f32)>,
}

impl<'a> RawSource<'a> {
    pub(super) fn new(slab: &Slab, rays: &'a RawRays) -> Self {
        RawSource {
            samples: &rays.samples,
            depth: &rays.depth,
            range: rays.depth_range(),
            nu: slab.nu as usize,
            ns: slab.ns as usize,
            image_len: slab.ns as usize * slab.nt as usize,
        }
    }
}

impl Source for RawSource<'_> {
    type Image = usize;

    fn depth_range(&self) -> Option<(f32, f32)> {
        self.range
    }

    #[inline(always)]
    fn align(&self) -> u32 {
        1
    }

    #[inline(always)]
    fn image(&self, u: u32, v: u32) -> usize {
        (v as usize * self.nu + u as usize) * self.image_len
    }

    #[inline(always)]
    fn sample(&self, image: usize, s: u32, t: u32) -> u32 {
        self.samples[image + t as usize * self.ns + s as usize]
    }

    #[inline(always)]
    fn depth(&self, image: usize, s: u32, t: u32) -> f32 {
        self.depth[image + t as usize * self.ns + s as usize]
    }

    #[inline(always)]
    fn sample_row(&self, image: usize, t: u32, start: u32) -> Option<F8> {
        let at = image + t as usize * self.ns + start as usize;
        Some(F8::from_array(lanes(self.samples, at)?.map(f32::from_bits)))
    }

    #[inline(always)]
    fn depth_row(&self, image: usize, t: u32, start: u32) -> Option<F8> {
        let at = image + t as usize * self.ns + start as usize;
        Some(F8::from_array(lanes(self.depth, at)?))
    }
}

/// Quantised rays read in place ([`Quantised::sample`]): an image is the first of its
/// tiles and its `(u, v)` place within a tile, as bits of a sample's place in a codeword.
pub(super) struct CodeSource<'a> {
    q: &'a Quantised,
    /// `log2` of the tile's extent along `u, v, s, t`.
    log2: [u32; 4],
    /// Tiles along `u` and `s`, and in one `(u, v)` image's worth.
    tiles_u: usize,
    tiles_s: usize,
    image_tiles: usize,
    /// Samples in a tile, `log2`.
    bits: u32,
    /// Samples a row of tiles spans along `s`.
    row_span: u32,
    /// Samples along `s` a row window reads from one tile: the tile's extent, at most 8.
    run: usize,
    /// The codebook's depth range (found each frame: a codebook is small).
    range: Option<(f32, f32)>,
}

/// A camera's image in quantised rays: its first tile and its `(u, v)` place within a
/// tile, as bits of a sample's place in a codeword.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct CodeImage {
    tiles: usize,
    within: usize,
}

impl<'a> CodeSource<'a> {
    pub(super) fn new(q: &'a Quantised) -> Self {
        let log2 = q.tile.dims().map(u32::trailing_zeros);
        let [tu, _, ts, tt] = q.tiles.map(|n| n as usize);
        CodeSource {
            q,
            log2,
            tiles_u: tu,
            tiles_s: ts,
            image_tiles: ts * tt,
            bits: log2.iter().sum(),
            row_span: q.tiles[2] << log2[2],
            run: 1 << log2[2].min(3),
            range: super::super::depth_range(&q.depths),
        }
    }

    /// Where sample `(s, t)` of `image` sits in the codebook.
    #[inline(always)]
    fn at(&self, image: CodeImage, s: u32, t: u32) -> usize {
        let [_, _, ls, lt] = self.log2;
        let tile = image.tiles + (t >> lt) as usize * self.tiles_s + (s >> ls) as usize;
        let low = |x: u32, b: u32| x & ((1 << b) - 1);
        let within = (low(t, lt) << ls | low(s, ls)) as usize;
        ((self.q.indices[tile] as usize) << self.bits) | image.within | within
    }

    /// Samples `(start + l, t)` of `image` from `data` (colours or depths), `start` a
    /// multiple of the tile's extent along `s` (of 8 when that is more): whole runs of a
    /// tile's row, each read from its codeword. `None` past the tiles or the data.
    #[inline(always)]
    fn row<T: Copy + Default>(
        &self,
        data: &[T],
        image: CodeImage,
        t: u32,
        start: u32,
    ) -> Option<[T; LANES]> {
        if start + LANES as u32 > self.row_span {
            return None;
        }
        let [_, _, ls, lt] = self.log2;
        let low = |x: u32, b: u32| x & ((1 << b) - 1);
        let tiles = image.tiles + (t >> lt) as usize * self.tiles_s + (start >> ls) as usize;
        let within = image.within | (low(t, lt) << ls | low(start, ls)) as usize;
        match self.run {
            1 => self.runs::<1, T>(data, tiles, within),
            2 => self.runs::<2, T>(data, tiles, within),
            4 => self.runs::<4, T>(data, tiles, within),
            _ => self.runs::<8, T>(data, tiles, within),
        }
    }

    /// Eight samples as `LANES / RUN` runs of `RUN` from as many tiles from `tiles` on,
    /// each at `within` in its codeword.
    #[inline(always)]
    fn runs<const RUN: usize, T: Copy + Default>(
        &self,
        data: &[T],
        tiles: usize,
        within: usize,
    ) -> Option<[T; LANES]> {
        let mut out = [T::default(); LANES];
        let codes = self.q.indices.get(tiles..tiles + LANES / RUN)?;
        for (run, &code) in out.chunks_exact_mut(RUN).zip(codes) {
            let at = ((code as usize) << self.bits) | within;
            run.copy_from_slice(data.get(at..at + RUN)?);
        }
        Some(out)
    }

    /// [`CodeSource::runs`] of two rows of the same tiles, at `within[0]` and
    /// `within[1]` in their codewords: the codewords read once.
    #[inline(always)]
    fn runs2<const RUN: usize, T: Copy + Default>(
        &self,
        data: &[T],
        tiles: usize,
        within: [usize; 2],
    ) -> Option<[[T; LANES]; 2]> {
        let mut out = [[T::default(); LANES]; 2];
        let codes = self.q.indices.get(tiles..tiles + LANES / RUN)?;
        let [out0, out1] = &mut out;
        for ((r0, r1), &code) in out0
            .chunks_exact_mut(RUN)
            .zip(out1.chunks_exact_mut(RUN))
            .zip(codes)
        {
            let at = (code as usize) << self.bits;
            r0.copy_from_slice(data.get(at | within[0]..(at | within[0]) + RUN)?);
            r1.copy_from_slice(data.get(at | within[1]..(at | within[1]) + RUN)?);
        }
        Some(out)
    }
}

impl Source for CodeSource<'_> {
    fn depth_range(&self) -> Option<(f32, f32)> {
        self.range
    }

    type Image = CodeImage;

    #[inline(always)]
    fn align(&self) -> u32 {
        self.run as u32
    }

    #[inline(always)]
    fn image(&self, u: u32, v: u32) -> CodeImage {
        let [lu, lv, ls, lt] = self.log2;
        let low = |x: u32, b: u32| x & ((1 << b) - 1);
        CodeImage {
            tiles: ((v >> lv) as usize * self.tiles_u + (u >> lu) as usize) * self.image_tiles,
            within: ((low(v, lv) << lu | low(u, lu)) as usize) << (lt + ls),
        }
    }

    #[inline(always)]
    fn sample(&self, image: CodeImage, s: u32, t: u32) -> u32 {
        self.q.colors[self.at(image, s, t)]
    }

    #[inline(always)]
    fn depth(&self, image: CodeImage, s: u32, t: u32) -> f32 {
        self.q
            .depths
            .get(self.at(image, s, t))
            .copied()
            .unwrap_or(f32::INFINITY)
    }

    #[inline(always)]
    fn sample_row(&self, image: CodeImage, t: u32, start: u32) -> Option<F8> {
        let row = self.row(&self.q.colors, image, t, start)?;
        Some(F8::from_array(row.map(f32::from_bits)))
    }

    #[inline(always)]
    fn depth_row(&self, image: CodeImage, t: u32, start: u32) -> Option<F8> {
        Some(F8::from_array(self.row(&self.q.depths, image, t, start)?))
    }

    /// Two rows in the same tiles (one row of tiles) read each codeword once.
    #[inline(always)]
    fn sample_rows(&self, image: CodeImage, [t0, t1]: [u32; 2], start: u32) -> Option<[F8; 2]> {
        let [_, _, ls, lt] = self.log2;
        if t0 >> lt != t1 >> lt || start + LANES as u32 > self.row_span {
            return Some([
                self.sample_row(image, t0, start)?,
                self.sample_row(image, t1, start)?,
            ]);
        }
        let low = |x: u32, b: u32| x & ((1 << b) - 1);
        let tiles = image.tiles + (t0 >> lt) as usize * self.tiles_s + (start >> ls) as usize;
        let within = [t0, t1].map(|t| image.within | (low(t, lt) << ls | low(start, ls)) as usize);
        let colors = &self.q.colors;
        let rows = match self.run {
            1 => self.runs2::<1, u32>(colors, tiles, within),
            2 => self.runs2::<2, u32>(colors, tiles, within),
            4 => self.runs2::<4, u32>(colors, tiles, within),
            _ => self.runs2::<8, u32>(colors, tiles, within),
        }?;
        Some(rows.map(|r| F8::from_array(r.map(f32::from_bits))))
    }
}
