//! Light fields saved and loaded as one versioned file (`.plf`), little-endian:
//!
//! | bytes | field |
//! |---|---|
//! | 8 | magic `PLXLF\0\0\0` |
//! | 4 | version, `2` (version `1` files, which have no planes at infinity, are read too) |
//! | 4 | flags: bits 0-7 the sample encoding, `0`, packed premultiplied sRGB RGBA8 (as [`crate::warp::ENCODING`]); bit 8 the `uv` plane, bit 9 the `st` plane at infinity ([`Slab::infinite`]; version 2) |
//! | 16 | sample counts `nu`, `nv`, `ns`, `nt` (`u32`) |
//! | 72 | the `uv` then the `st` rectangle: origin, edge a, edge b (`f32` x, y, z each; directions for a plane at infinity) |
//! | 8 | capture depth range `near`, `far` (`f32`) |
//! | 4 | payload: `0`, raw samples; `1`, raw samples then their depths; `2`, quantised |
//! | 8 | sample count (`u64`), which must be `nu nv ns nt` |
//!
//! Raw payloads (`0`, `1`) follow with
//!
//! | bytes | field |
//! |---|---|
//! | 4 per sample | the samples in [`RawRays::samples`] order |
//! | 4 per sample | with payload `1`: their depths (`f32`, [`RawRays::depth`]) |
//!
//! and the quantised payload (`2`, [`Quantised`]) with
//!
//! | bytes | field |
//! |---|---|
//! | 16 | tile dimensions in `u`, `v`, `s`, `t` (`u32`, powers of two) |
//! | 4 | codewords `K` (1 to 65,536) |
//! | 4 | depth kept: `0` or `1` |
//! | 8 | length of the rest (`u64`) |
//! | rest | one zstd frame holding the codebook's `K L` packed colours (`u32`, `L` samples a tile), with depth kept their `K L` depths (`f32`), then one `u16` index per tile |
//!
//! Reading checks the header before allocating anything: the slab must be valid
//! ([`Slab::new`]), the count must match the sample counts, and the file must hold
//! exactly that many samples (raw), or a frame that decompresses to exactly the bytes the
//! header implies (quantised; decompression stops there, so memory follows the data, not
//! the header), so a bad header can neither panic nor ask for a huge allocation; every
//! index must name a codeword. Every error names the file.

use super::{LightField, Quantised, RawRays, Rays, Rect3, Slab, SlabError, TileShape, VqError};
use glam::Vec3;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

const MAGIC: &[u8; 8] = b"PLXLF\0\0\0";
const VERSION: u32 = 2;
/// Flag bits of the planes at infinity, `uv` and `st`.
const INFINITE: [u32; 2] = [1 << 8, 1 << 9];
/// Bytes before the samples.
const HEADER: usize = 8 + 4 + 4 + 16 + 72 + 8 + 4 + 8;

/// Why a light-field file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    /// The file could not be opened, read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The file does not start with the `PLXLF` magic.
    #[error("{path}: not a light-field file (no PLXLF header)")]
    NotALightField {
        /// The file.
        path: PathBuf,
    },
    /// The file's version is not one this build reads (1 or 2).
    #[error("{path}: version {found} is not supported (this build reads version {VERSION})")]
    Version {
        /// The file.
        path: PathBuf,
        /// The version the header gives.
        found: u32,
    },
    /// A header field holds a value with no meaning (an encoding, a payload kind, a flag).
    #[error("{path}: unknown {what} {found}")]
    Unknown {
        /// The file.
        path: PathBuf,
        /// Which field, in words.
        what: &'static str,
        /// The value found.
        found: u32,
    },
    /// The header's planes, counts or depth range make no valid [`Slab`].
    #[error("{path}: bad slab: {source}")]
    Slab {
        /// The file.
        path: PathBuf,
        /// Why the slab is invalid.
        source: SlabError,
    },
    /// The header's sample count is not `nu nv ns nt`.
    #[error("{path}: the header counts {declared} samples, but {nu} x {nv} x {ns} x {nt} makes {expected}")]
    Count {
        /// The file.
        path: PathBuf,
        /// The sample count the header gives.
        declared: u64,
        /// `nu nv ns nt`, the count it should give.
        expected: u64,
        /// The header's `uv` samples along `edge_a`.
        nu: u32,
        /// The header's `uv` samples along `edge_b`.
        nv: u32,
        /// The header's `st` samples along `edge_a` (image width, pixels).
        ns: u32,
        /// The header's `st` samples along `edge_b` (image height, pixels).
        nt: u32,
    },
    /// The quantised payload's tile shape, codebook or indices are inconsistent.
    #[error("{path}: bad quantised light field: {source}")]
    Quantised {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        source: VqError,
    },
    /// The quantised payload's zstd frame does not decompress.
    #[error("{path}: the compressed samples are corrupt: {message}")]
    Corrupt {
        /// The file.
        path: PathBuf,
        /// The decompressor's message.
        message: String,
    },
    /// The file (or the decompressed payload) holds more or fewer bytes than its header
    /// implies.
    #[error("{path}: {found} bytes of samples where the header promises {expected} (truncated or trailing data)")]
    Length {
        /// The file.
        path: PathBuf,
        /// Bytes the header implies.
        expected: u64,
        /// Bytes found.
        found: u64,
    },
}

/// Bytes of the quantised payload's own header.
const VQ_HEADER: usize = 16 + 4 + 4 + 8;
/// zstd's level for the quantised payload (indices and codebook compress well; higher
/// levels gain little for much longer saves).
const ZSTD_LEVEL: i32 = 19;

fn put(out: &mut Vec<u8>, words: impl IntoIterator<Item = u32>) {
    for w in words {
        out.extend_from_slice(&w.to_le_bytes());
    }
}

fn words(b: &[u8]) -> impl Iterator<Item = u32> + '_ {
    b.chunks_exact(4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

impl LightField {
    /// Writes the light field to `path` (see the module's layout): raw rays as they are,
    /// quantised ones as codebook and indices through zstd.
    pub fn save(&self, path: &Path) -> Result<(), FileError> {
        let io = |source| FileError::Io {
            path: path.to_path_buf(),
            source,
        };
        let sl = &self.slab;
        let payload = match &self.rays {
            Rays::Raw(r) => u32::from(r.has_depth()),
            Rays::Quantised(_) => 2,
        };
        let mut out = Vec::with_capacity(HEADER);
        out.extend_from_slice(MAGIC);
        let flags = (0..2)
            .filter(|&k| sl.infinite[k])
            .fold(0, |f, k| f | INFINITE[k]);
        put(&mut out, [VERSION, flags, sl.nu, sl.nv, sl.ns, sl.nt]);
        for r in [&sl.uv, &sl.st] {
            for v in [r.origin, r.edge_a, r.edge_b] {
                put(&mut out, v.to_array().map(f32::to_bits));
            }
        }
        put(&mut out, [sl.near.to_bits(), sl.far.to_bits(), payload]);
        out.extend_from_slice(&(sl.len() as u64).to_le_bytes());
        match &self.rays {
            Rays::Raw(r) => {
                out.reserve(4 * (r.samples.len() + r.depth.len()));
                put(&mut out, r.samples.iter().copied());
                if r.has_depth() {
                    put(&mut out, r.depth.iter().map(|d| d.to_bits()));
                }
            }
            Rays::Quantised(q) => {
                put(&mut out, q.tile.dims());
                put(
                    &mut out,
                    [q.codewords() as u32, u32::from(!q.depths.is_empty())],
                );
                let mut plain = Vec::with_capacity(q.bytes());
                put(&mut plain, q.colors.iter().copied());
                put(&mut plain, q.depths.iter().map(|d| d.to_bits()));
                for i in &q.indices {
                    plain.extend_from_slice(&i.to_le_bytes());
                }
                let packed = zstd::bulk::compress(&plain, ZSTD_LEVEL).map_err(io)?;
                out.extend_from_slice(&(packed.len() as u64).to_le_bytes());
                out.extend_from_slice(&packed);
            }
        }
        let mut f = std::fs::File::create(path).map_err(io)?;
        f.write_all(&out).map_err(io)
    }

    /// Reads a light field written by [`LightField::save`].
    pub fn load(path: &Path) -> Result<LightField, FileError> {
        let p = || path.to_path_buf();
        let io = |source| FileError::Io { path: p(), source };
        let mut f = std::fs::File::open(path).map_err(io)?;
        let size = f.metadata().map_err(io)?.len();
        let mut head = [0u8; HEADER];
        if size < HEADER as u64 {
            // Too short for a header: a truncated file or something else.
            let mut start = Vec::new();
            f.read_to_end(&mut start).map_err(io)?;
            return Err(if start.starts_with(MAGIC) {
                FileError::Length {
                    path: p(),
                    expected: HEADER as u64,
                    found: size,
                }
            } else {
                FileError::NotALightField { path: p() }
            });
        }
        f.read_exact(&mut head).map_err(io)?;
        if &head[..8] != MAGIC {
            return Err(FileError::NotALightField { path: p() });
        }
        let mut at = 8;
        let mut u32_ = || {
            let v = u32::from_le_bytes(head[at..at + 4].try_into().unwrap_or([0; 4]));
            at += 4;
            v
        };
        let (version, flags) = (u32_(), u32_());
        let counts = [u32_(), u32_(), u32_(), u32_()];
        let floats: Vec<f32> = (0..20).map(|_| f32::from_bits(u32_())).collect();
        let payload = u32_();
        let declared = u64::from_le_bytes(head[HEADER - 8..].try_into().unwrap_or([0; 8]));
        if version != VERSION && version != 1 {
            return Err(FileError::Version {
                path: p(),
                found: version,
            });
        }
        let (encoding, planes) = (flags & 0xff, flags >> 8);
        let known_planes = if version == 1 { 0 } else { 3 };
        let infinite = INFINITE.map(|bit| flags & bit != 0);
        for (what, found, known) in [
            ("sample encoding", encoding, 0),
            ("planes-at-infinity flags", planes, known_planes),
            ("payload", payload, 2),
        ] {
            if found > known {
                return Err(FileError::Unknown {
                    path: p(),
                    what,
                    found,
                });
            }
        }
        let v = |k: usize| Vec3::new(floats[k], floats[k + 1], floats[k + 2]);
        let rect = |k: usize| Rect3 {
            origin: v(k),
            edge_a: v(k + 3),
            edge_b: v(k + 6),
        };
        let slab = Slab::with_infinite(rect(0), rect(9), counts, floats[18], floats[19], infinite)
            .map_err(|source| FileError::Slab { path: p(), source })?;
        let [nu, nv, ns, nt] = counts;
        // Saturating: four large counts overflow even 64 bits.
        let expected = counts
            .iter()
            .try_fold(1u64, |p, &n| p.checked_mul(n as u64))
            .unwrap_or(u64::MAX);
        if declared != expected {
            return Err(FileError::Count {
                path: p(),
                declared,
                expected,
                nu,
                nv,
                ns,
                nt,
            });
        }
        let found = size - HEADER as u64;
        let rays = if payload == 2 {
            Rays::Quantised(read_quantised(&mut f, found, counts, path)?)
        } else {
            let per_sample = 4 * (1 + payload as u64);
            if expected.checked_mul(per_sample) != Some(found) {
                return Err(FileError::Length {
                    path: p(),
                    expected: expected.saturating_mul(per_sample),
                    found,
                });
            }
            // The file holds exactly this many bytes: the allocation is bounded by its
            // size.
            let bytes = read_exactly(&mut f, found, path)?;
            let (colour, depth) = bytes.split_at(expected as usize * 4);
            Rays::Raw(RawRays::new(
                words(colour).collect(),
                words(depth).map(f32::from_bits).collect(),
            ))
        };
        Ok(LightField { slab, rays })
    }
}

/// The next `n` bytes of `f`, `n` no more than the file holds.
fn read_exactly(f: &mut impl Read, n: u64, path: &Path) -> Result<Vec<u8>, FileError> {
    let mut bytes = Vec::with_capacity(n as usize);
    f.take(n)
        .read_to_end(&mut bytes)
        .map_err(|source| FileError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    if bytes.len() as u64 != n {
        return Err(FileError::Length {
            path: path.to_path_buf(),
            expected: n,
            found: bytes.len() as u64,
        });
    }
    Ok(bytes)
}

/// The quantised payload: `rest` bytes after the common header.
fn read_quantised(
    f: &mut impl Read,
    rest: u64,
    counts: [u32; 4],
    path: &Path,
) -> Result<Quantised, FileError> {
    let p = || path.to_path_buf();
    if rest < VQ_HEADER as u64 {
        return Err(FileError::Length {
            path: p(),
            expected: VQ_HEADER as u64,
            found: rest,
        });
    }
    let head = read_exactly(f, VQ_HEADER as u64, path)?;
    let w: Vec<u32> = words(&head[..24]).collect();
    let bad = |source| FileError::Quantised { path: p(), source };
    let tile = TileShape::new([w[0], w[1], w[2], w[3]]).map_err(bad)?;
    let (k, with_depth) = (w[4], w[5]);
    if !(1..=1 << 16).contains(&k) {
        return Err(bad(VqError::Codewords(k)));
    }
    if with_depth > 1 {
        return Err(FileError::Unknown {
            path: p(),
            what: "depth flag",
            found: with_depth,
        });
    }
    let packed = u64::from_le_bytes(head[24..].try_into().unwrap_or([0; 8]));
    if packed != rest - VQ_HEADER as u64 {
        return Err(FileError::Length {
            path: p(),
            expected: packed,
            found: rest - VQ_HEADER as u64,
        });
    }
    let tiles = tile.tiles(counts);
    let book = k as u64 * tile.len() as u64;
    let n_tiles = tiles.iter().map(|&t| t as u64).product::<u64>();
    let plain = 4 * book * (1 + u64::from(with_depth)) + 2 * n_tiles;
    let corrupt = |message: String| FileError::Corrupt { path: p(), message };
    let decoder =
        zstd::stream::read::Decoder::new(f.take(packed)).map_err(|e| corrupt(e.to_string()))?;
    // Reading stops one byte past what the header implies: memory follows the data.
    let mut bytes = Vec::new();
    decoder
        .take(plain.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| corrupt(e.to_string()))?;
    if bytes.len() as u64 != plain {
        return Err(corrupt(format!(
            "{} bytes where the header implies {plain}",
            bytes.len()
        )));
    }
    let (colors, rest) = bytes.split_at(4 * book as usize);
    let (depths, indices) = rest.split_at(4 * book as usize * with_depth as usize);
    Quantised::new(
        tile,
        tiles,
        words(colors).collect(),
        words(depths).map(f32::from_bits).collect(),
        indices
            .chunks_exact(2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]))
            .collect(),
    )
    .map_err(bad)
}
