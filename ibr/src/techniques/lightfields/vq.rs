//! Vector quantisation of a light slab (Levoy and Hanrahan 96, section 4): the samples are
//! cut into tiles (2 x 2 x 2 x 2 in `u, v, s, t` by default), a codebook is trained on a
//! sample of the tiles by the generalised Lloyd algorithm, started by LBG splitting (one
//! codeword, each split in two and refined, until there are enough), and every tile is
//! replaced by the index of its nearest codeword. Rendering reads samples straight from
//! codebook and indices ([`Quantised::sample`]): nothing is decompressed first.
//!
//! A tile's vector holds, per sample, the four stored colour bytes and, when depth is
//! kept, a depth feature `255 zmin / z` (0 where the ray met nothing; `zmin` the nearest
//! depth captured), so the nearest surface weighs like a full colour channel and the
//! codewords keep depth fit for depth correction. The nearest codeword is found exactly,
//! fast: codewords are sorted along the codebook's principal axis and searched outward
//! from the query's projection, stopping when the projection gap alone exceeds the best
//! distance, skipping those whose length differs too much, and abandoning a distance once
//! its partial sum does.

use super::{RawRays, Slab};
use rayon::prelude::*;

/// A tile's extent in `u, v, s, t`: powers of two, at most 16 each and 256 samples in all.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileShape {
    log2: [u32; 4],
}

impl TileShape {
    /// Levoy and Hanrahan's 2 x 2 x 2 x 2.
    pub const LEVOY: TileShape = TileShape { log2: [1; 4] };

    /// A tile of `dims` samples in `u, v, s, t`.
    pub fn new(dims: [u32; 4]) -> Result<Self, VqError> {
        let ok = dims.iter().all(|&d| d.is_power_of_two() && d <= 16)
            && dims.iter().product::<u32>() <= 256;
        if !ok {
            return Err(VqError::Tile(dims));
        }
        Ok(TileShape {
            log2: dims.map(u32::trailing_zeros),
        })
    }

    /// Samples along `u, v, s, t`.
    pub fn dims(&self) -> [u32; 4] {
        self.log2.map(|l| 1 << l)
    }

    /// Samples in a tile.
    pub fn len(&self) -> usize {
        1 << self.bits()
    }

    /// Never: a tile holds at least one sample.
    pub fn is_empty(&self) -> bool {
        false
    }

    fn bits(&self) -> u32 {
        self.log2.iter().sum()
    }

    /// Tiles along each axis to cover `counts` samples.
    pub fn tiles(&self, counts: [u32; 4]) -> [u32; 4] {
        std::array::from_fn(|k| counts[k].div_ceil(1 << self.log2[k]))
    }
}

impl std::fmt::Display for TileShape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [u, v, s, t] = self.dims();
        write!(f, "{u}x{v}x{s}x{t}")
    }
}

/// How a light field is quantised.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VqSettings {
    /// The 4D tile (in `u`, `v`, `s`, `t` samples) each codeword stands for.
    pub tile: TileShape,
    /// Codewords wanted (at most 65,536: indices are 16-bit); fewer when the training
    /// tiles hold fewer distinct vectors.
    pub codewords: u32,
    /// Tiles the codebook is trained on, taken evenly through the light field.
    pub training_tiles: usize,
    /// Lloyd iterations on the final codebook (two after each split before it).
    pub iterations: u32,
}

impl Default for VqSettings {
    /// Levoy and Hanrahan's: 2x2x2x2 tiles, 16,384 codewords.
    fn default() -> Self {
        VqSettings {
            tile: TileShape::LEVOY,
            codewords: 16384,
            training_tiles: 1 << 18,
            iterations: 6,
        }
    }
}

/// Why a light field cannot be quantised as asked.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum VqError {
    #[error(
        "tile dimensions must be powers of two up to 16, at most 256 samples in all (got {0:?})"
    )]
    /// Tile dimensions (`u`, `v`, `s`, `t`) that are not powers of two up to 16, or make
    /// more than 256 samples.
    Tile([u32; 4]),
    /// A codeword count outside 1 to 65,536.
    #[error("a codebook needs 1 to 65,536 codewords (got {0})")]
    Codewords(u32),
    /// Codebook, indices and tile counts that do not fit each other: what is wrong.
    #[error("quantised data is inconsistent: {0}")]
    Inconsistent(String),
}

/// What training and encoding found.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VqReport {
    /// Codewords in the trained codebook.
    pub codewords: u32,
    /// Tiles trained on.
    pub training_tiles: usize,
    /// Tiles encoded (every tile of the light field).
    pub tiles: usize,
    /// Mean squared error per vector component over all encoded tiles (colour bytes and
    /// depth feature).
    pub mse: f64,
    /// Codeword distances computed while encoding, per tile (the search's work).
    pub distances_per_tile: f64,
}

/// A light field's samples as codebook and indices.
#[derive(Clone, Debug, PartialEq)]
pub struct Quantised {
    /// The tile shape each codeword covers.
    pub tile: TileShape,
    /// Tiles along `u, v, s, t`.
    pub tiles: [u32; 4],
    /// Codeword `k`'s samples at `k * tile.len()..`, packed colour, ordered `u` fastest
    /// within `v`, then `s` fastest within `t` (as [`RawRays`] orders a light field).
    pub colors: Vec<u32>,
    /// Their depths (as [`RawRays::depth`]); empty when not kept.
    pub depths: Vec<f32>,
    /// Tile `((tv tu_n + tu) tt_n + tt) ts_n + ts`'s codeword.
    pub indices: Vec<u16>,
}

impl Quantised {
    /// Checks parts read from elsewhere (a file): whole codewords, at most 65,536, depths
    /// for all or none, one index per tile, every index naming a codeword.
    pub fn new(
        tile: TileShape,
        tiles: [u32; 4],
        colors: Vec<u32>,
        depths: Vec<f32>,
        indices: Vec<u16>,
    ) -> Result<Self, VqError> {
        let bad = |m: String| Err(VqError::Inconsistent(m));
        let k = colors.len() / tile.len();
        if !colors.len().is_multiple_of(tile.len()) || k == 0 || k > 1 << 16 {
            return bad(format!(
                "{} codebook samples for {tile} tiles",
                colors.len()
            ));
        }
        if !depths.is_empty() && depths.len() != colors.len() {
            return bad(format!(
                "{} depths for {} samples",
                depths.len(),
                colors.len()
            ));
        }
        let n = tiles.iter().map(|&t| t as usize).product::<usize>();
        if indices.len() != n {
            return bad(format!("{} indices for {n} tiles", indices.len()));
        }
        if let Some(i) = indices.iter().find(|&&i| i as usize >= k) {
            return bad(format!("index {i} past the codebook's {k} codewords"));
        }
        Ok(Quantised {
            tile,
            tiles,
            colors,
            depths,
            indices,
        })
    }

    /// Codewords in the codebook.
    pub fn codewords(&self) -> usize {
        self.colors.len() / self.tile.len()
    }

    /// Bytes of codebook and indices, as held in memory.
    pub fn bytes(&self) -> usize {
        4 * self.colors.len() + 4 * self.depths.len() + 2 * self.indices.len()
    }

    /// Where sample `(u, v, s, t)` sits in the codebook.
    #[inline]
    fn at(&self, u: u32, v: u32, s: u32, t: u32) -> usize {
        let [lu, lv, ls, lt] = self.tile.log2;
        let [nu, _, ns, nt] = self.tiles.map(|n| n as usize);
        let tile = (((v >> lv) as usize * nu + (u >> lu) as usize) * nt + (t >> lt) as usize) * ns
            + (s >> ls) as usize;
        let low = |x: u32, l: u32| x & ((1 << l) - 1);
        let within = (((low(v, lv) << lu | low(u, lu)) << lt | low(t, lt)) << ls) | low(s, ls);
        ((self.indices[tile] as usize) << self.tile.bits()) | within as usize
    }

    /// Sample `(u, v, s, t)`'s packed colour.
    #[inline]
    pub fn sample(&self, u: u32, v: u32, s: u32, t: u32) -> u32 {
        self.colors[self.at(u, v, s, t)]
    }

    /// Sample `(u, v, s, t)`'s depth (infinite when depth is not kept).
    #[inline]
    pub fn depth(&self, u: u32, v: u32, s: u32, t: u32) -> f32 {
        self.depths
            .get(self.at(u, v, s, t))
            .copied()
            .unwrap_or(f32::INFINITY)
    }

    /// Trains a codebook on `raw`'s tiles and encodes every tile with it.
    pub fn encode(
        slab: &Slab,
        raw: &RawRays,
        settings: &VqSettings,
    ) -> Result<(Quantised, VqReport), VqError> {
        if !(1..=1 << 16).contains(&settings.codewords) {
            return Err(VqError::Codewords(settings.codewords));
        }
        let tiler = Tiler::new(slab, raw, settings.tile);
        let n = tiler.count();
        let take = settings.training_tiles.clamp(1, n);
        // Scattered through the light field, the same tiles every time: a stride would
        // alias with the tile grid (every tile in one column of the images).
        let step = scatter_step(n);
        let training: Vec<f32> = (0..take)
            .flat_map(|i| tiler.vector(((i as u128 * step as u128) % n as u128) as usize))
            .collect();
        let book = train(
            &training,
            tiler.dim,
            settings.codewords as usize,
            settings.iterations,
        );
        let search = Search::new(&book, tiler.dim);
        let coded: Vec<(u16, f32, u32)> = (0..n)
            .into_par_iter()
            .with_min_len(256)
            .map(|i| {
                let (k, d, work) = search.nearest(&tiler.vector(i));
                (k as u16, d, work)
            })
            .collect();
        let indices: Vec<u16> = coded.iter().map(|c| c.0).collect();
        let error: f64 = coded.iter().map(|c| f64::from(c.1)).sum();
        let work: f64 = coded.iter().map(|c| f64::from(c.2)).sum();
        let report = VqReport {
            codewords: (book.len() / tiler.dim) as u32,
            training_tiles: take,
            tiles: n,
            mse: error / (n * tiler.dim) as f64,
            distances_per_tile: work / n as f64,
        };
        let (colors, depths) = tiler.decode_book(&book);
        let q = Quantised::new(settings.tile, tiler.tiles, colors, depths, indices)?;
        Ok((q, report))
    }
}

/// A step coprime with `n` near `n` times the golden ratio's fractional part: `i step mod
/// n` for `i < n` visits every index once, scattered.
fn scatter_step(n: usize) -> usize {
    fn gcd(a: usize, b: usize) -> usize {
        if b == 0 {
            a
        } else {
            gcd(b, a % b)
        }
    }
    let mut step = ((n as f64 * 0.618_033_988_75) as usize).max(1);
    while gcd(step, n) != 1 {
        step += 1;
    }
    step
}

/// Cuts a light field into tile vectors and turns codewords back into samples.
struct Tiler<'a> {
    raw: &'a RawRays,
    counts: [u32; 4],
    tile: TileShape,
    tiles: [u32; 4],
    /// Components per sample: four colour bytes, and the depth feature when kept.
    channels: usize,
    dim: usize,
    /// `255 zmin`: the depth feature is this over the depth.
    depth_scale: f32,
}

impl<'a> Tiler<'a> {
    fn new(slab: &Slab, raw: &'a RawRays, tile: TileShape) -> Self {
        let counts = [slab.nu, slab.nv, slab.ns, slab.nt];
        let with_depth = raw.has_depth();
        let zmin = raw
            .depth
            .iter()
            .copied()
            .filter(|z| z.is_finite() && *z > 0.0)
            .fold(f32::INFINITY, f32::min);
        let channels = 4 + with_depth as usize;
        Tiler {
            raw,
            counts,
            tile,
            tiles: tile.tiles(counts),
            channels,
            dim: channels * tile.len(),
            depth_scale: if zmin.is_finite() { 255.0 * zmin } else { 1.0 },
        }
    }

    fn count(&self) -> usize {
        self.tiles.iter().map(|&t| t as usize).product()
    }

    /// Tile `i`'s vector; samples past the light field's edge repeat its last ones.
    fn vector(&self, i: usize) -> Vec<f32> {
        let [nu, nv, ns, nt] = self.tiles.map(|t| t as usize);
        let tile = [i / ns / nt % nu, i / ns / nt / nu % nv, i % ns, i / ns % nt];
        let [du, dv, ds, dt] = self.tile.dims();
        let mut out = Vec::with_capacity(self.dim);
        for v in 0..dv {
            for u in 0..du {
                for t in 0..dt {
                    for s in 0..ds {
                        let at = |k: usize, d: u32, o: u32| {
                            (tile[k] as u32 * d + o).min(self.counts[k] - 1)
                        };
                        let idx = self.raw.index(
                            self.counts,
                            at(0, du, u),
                            at(1, dv, v),
                            at(2, ds, s),
                            at(3, dt, t),
                        );
                        out.extend(self.raw.samples[idx].to_le_bytes().map(f32::from));
                        if self.channels == 5 {
                            let z = self.raw.depth[idx];
                            out.push(if z.is_finite() && z > 0.0 {
                                self.depth_scale / z
                            } else {
                                0.0
                            });
                        }
                    }
                }
            }
        }
        out
    }

    /// A trained codebook as packed colours and depths.
    fn decode_book(&self, book: &[f32]) -> (Vec<u32>, Vec<f32>) {
        let byte = |x: f32| (x + 0.5).clamp(0.0, 255.0) as u8;
        let colors = book
            .chunks_exact(self.channels)
            .map(|c| u32::from_le_bytes([byte(c[0]), byte(c[1]), byte(c[2]), byte(c[3])]))
            .collect();
        let depths = if self.channels == 5 {
            book.chunks_exact(5)
                .map(|c| {
                    if c[4] > 0.0 {
                        self.depth_scale / c[4]
                    } else {
                        f32::INFINITY
                    }
                })
                .collect()
        } else {
            Vec::new()
        };
        (colors, depths)
    }
}

/// The squared distance between `a` and `b`, or `None` once it passes `limit`.
#[inline]
fn distance(a: &[f32], b: &[f32], limit: f32) -> Option<f32> {
    let mut sum = 0.0;
    for (a, b) in a.chunks(16).zip(b.chunks(16)) {
        sum += a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f32>();
        if sum >= limit {
            return None;
        }
    }
    Some(sum)
}

/// Exact nearest-codeword search, ordered along the codebook's principal axis.
pub(super) struct Search {
    dim: usize,
    axis: Vec<f32>,
    /// Codewords sorted by projection: their vectors, projections, lengths and original
    /// indices.
    words: Vec<f32>,
    proj: Vec<f32>,
    norm: Vec<f32>,
    index: Vec<u32>,
}

impl Search {
    pub(super) fn new(book: &[f32], dim: usize) -> Search {
        let axis = principal_axis(book, dim);
        let dot = |v: &[f32]| v.iter().zip(&axis).map(|(a, b)| a * b).sum::<f32>();
        let mut order: Vec<(f32, u32)> = book
            .chunks_exact(dim)
            .enumerate()
            .map(|(i, w)| (dot(w), i as u32))
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let words = order
            .iter()
            .flat_map(|&(_, i)| &book[i as usize * dim..][..dim])
            .copied()
            .collect::<Vec<f32>>();
        let norm = words.chunks_exact(dim).map(length).collect();
        Search {
            dim,
            proj: order.iter().map(|o| o.0).collect(),
            index: order.iter().map(|o| o.1).collect(),
            axis,
            words,
            norm,
        }
    }

    /// The nearest codeword to `x`: its index, the squared distance, and the distances
    /// computed.
    pub(super) fn nearest(&self, x: &[f32]) -> (usize, f32, u32) {
        let p = x.iter().zip(&self.axis).map(|(a, b)| a * b).sum::<f32>();
        let nx = length(x);
        let n = self.proj.len();
        let start = self.proj.partition_point(|&q| q < p);
        let (mut best, mut best_d) = (0usize, f32::INFINITY);
        let mut work = 0;
        let (mut lo, mut hi) = (start, start);
        loop {
            let gap_lo = if lo > 0 {
                p - self.proj[lo - 1]
            } else {
                f32::INFINITY
            };
            let gap_hi = if hi < n {
                self.proj[hi] - p
            } else {
                f32::INFINITY
            };
            let gap = gap_lo.min(gap_hi);
            if gap * gap >= best_d {
                break;
            }
            let k = if gap_lo <= gap_hi {
                lo -= 1;
                lo
            } else {
                hi += 1;
                hi - 1
            };
            let dn = self.norm[k] - nx;
            if dn * dn >= best_d {
                continue;
            }
            work += 1;
            if let Some(d) = distance(x, &self.words[k * self.dim..][..self.dim], best_d) {
                if d < best_d || (d == best_d && self.index[k] < self.index[best]) {
                    best = k;
                    best_d = d;
                }
            }
        }
        (self.index[best] as usize, best_d.max(0.0), work)
    }
}

fn length(v: &[f32]) -> f32 {
    v.iter().map(|x| x * x).sum::<f32>().sqrt()
}

/// The direction of greatest spread of the vectors (power iteration on their scatter
/// about the mean; a fixed start, so the same axis every time).
fn principal_axis(vectors: &[f32], dim: usize) -> Vec<f32> {
    let n = (vectors.len() / dim).max(1);
    let mut mean = vec![0.0f64; dim];
    for v in vectors.chunks_exact(dim) {
        for (m, &x) in mean.iter_mut().zip(v) {
            *m += f64::from(x);
        }
    }
    let mean: Vec<f32> = mean.iter().map(|m| (m / n as f64) as f32).collect();
    let mut axis: Vec<f32> = (0..dim).map(|i| 1.0 + (i % 7) as f32 * 0.01).collect();
    for _ in 0..24 {
        let mut next = vec![0.0f32; dim];
        for v in vectors.chunks_exact(dim) {
            let c: f32 = v
                .iter()
                .zip(&mean)
                .zip(&axis)
                .map(|((x, m), a)| (x - m) * a)
                .sum();
            for ((o, x), m) in next.iter_mut().zip(v).zip(&mean) {
                *o += c * (x - m);
            }
        }
        let len = length(&next);
        if !(len > 0.0 && len.is_finite()) {
            break;
        }
        axis = next.iter().map(|x| x / len).collect();
    }
    let len = length(&axis);
    axis.iter().map(|x| x / len).collect()
}

/// The generalised Lloyd algorithm started by LBG splitting: a codebook of at most `k`
/// codewords for `vectors` (rows of `dim`), as rows.
fn train(vectors: &[f32], dim: usize, k: usize, iterations: u32) -> Vec<f32> {
    let n = vectors.len() / dim;
    let mut book = centroids(vectors, dim, &vec![0; n], 1).0;
    let mut assign = vec![0u32; n];
    let mut cluster_error = vec![0.0f64];
    loop {
        let have = book.len() / dim;
        let final_round = have >= k;
        let rounds = if final_round { iterations } else { 2 };
        for _ in 0..rounds {
            let search = Search::new(&book, dim);
            let found: Vec<(usize, f32, u32)> = vectors
                .par_chunks_exact(dim)
                .with_min_len(256)
                .map(|v| search.nearest(v))
                .collect();
            for (a, f) in assign.iter_mut().zip(&found) {
                *a = f.0 as u32;
            }
            let (next, errors) = centroids(vectors, dim, &assign, have);
            cluster_error = errors;
            book = next;
            reseed_empty(&mut book, vectors, dim, &assign, &found);
        }
        if final_round {
            return book;
        }
        // Split the clusters with the most error (all, while that stays within `k`);
        // clusters with none are exact and stay whole.
        let mut worst: Vec<usize> = (0..have).filter(|&c| cluster_error[c] > 0.0).collect();
        if worst.is_empty() {
            return book;
        }
        worst.sort_by(|&a, &b| {
            cluster_error[b]
                .total_cmp(&cluster_error[a])
                .then(a.cmp(&b))
        });
        worst.truncate(k - have);
        for (j, &c) in worst.iter().enumerate() {
            let word: Vec<f32> = book[c * dim..][..dim].to_vec();
            // A small fixed nudge, different per split, moves the copy off the original.
            book.extend(word.iter().enumerate().map(|(i, &x)| {
                let h = (i as u32 ^ (j as u32).wrapping_mul(0x9e37_79b9)).wrapping_mul(0x85eb_ca6b);
                x + if h >> 31 == 0 { 0.5 } else { -0.5 }
            }));
        }
    }
}

/// The mean of each cluster's vectors (codewords with none keep zero) and each cluster's
/// summed squared error about it.
fn centroids(vectors: &[f32], dim: usize, assign: &[u32], k: usize) -> (Vec<f32>, Vec<f64>) {
    let mut sums = vec![0.0f64; k * dim];
    let mut counts = vec![0u32; k];
    for (v, &a) in vectors.chunks_exact(dim).zip(assign) {
        counts[a as usize] += 1;
        for (s, &x) in sums[a as usize * dim..][..dim].iter_mut().zip(v) {
            *s += f64::from(x);
        }
    }
    let book: Vec<f32> = sums
        .chunks_exact(dim)
        .zip(&counts)
        .flat_map(|(s, &c)| s.iter().map(move |x| (x / f64::from(c.max(1))) as f32))
        .collect();
    let mut errors = vec![0.0f64; k];
    for (v, &a) in vectors.chunks_exact(dim).zip(assign) {
        let w = &book[a as usize * dim..][..dim];
        errors[a as usize] += v
            .iter()
            .zip(w)
            .map(|(x, y)| f64::from((x - y) * (x - y)))
            .sum::<f64>();
    }
    (book, errors)
}

/// Codewords no vector chose move to the vectors coded worst (each to its own).
fn reseed_empty(
    book: &mut [f32],
    vectors: &[f32],
    dim: usize,
    assign: &[u32],
    found: &[(usize, f32, u32)],
) {
    let mut used = vec![false; book.len() / dim];
    for &a in assign {
        used[a as usize] = true;
    }
    let empty: Vec<usize> = (0..used.len()).filter(|&c| !used[c]).collect();
    if empty.is_empty() {
        return;
    }
    let mut worst: Vec<usize> = (0..found.len()).filter(|&i| found[i].1 > 0.0).collect();
    worst.sort_by(|&a, &b| found[b].1.total_cmp(&found[a].1).then(a.cmp(&b)));
    for (&c, &v) in empty.iter().zip(&worst) {
        book[c * dim..][..dim].copy_from_slice(&vectors[v * dim..][..dim]);
    }
}
