//! Light fields saved and loaded as one versioned file (`.plf`), little-endian:
//!
//! | bytes | field |
//! |---|---|
//! | 8 | magic `PLXLF\0\0\0` |
//! | 4 | version, `1` |
//! | 4 | sample encoding: `0`, packed premultiplied sRGB RGBA8 (as [`crate::warp::ENCODING`]) |
//! | 16 | sample counts `nu`, `nv`, `ns`, `nt` (`u32`) |
//! | 72 | the `uv` then the `st` rectangle: origin, edge a, edge b (`f32` x, y, z each) |
//! | 8 | capture depth range `near`, `far` (`f32`) |
//! | 4 | payload: `0`, raw samples; `1`, raw samples then their depths |
//! | 8 | sample count (`u64`), which must be `nu nv ns nt` |
//! | 4 per sample | the samples in [`LightField::samples`] order |
//! | 4 per sample | with payload `1`: their depths (`f32`, [`LightField::depth`]) |
//!
//! Reading checks the header before allocating anything: the slab must be valid
//! ([`Slab::new`]), the count must match the sample counts, and the file must hold
//! exactly that many samples, so a bad header can neither panic nor ask for a huge
//! allocation. Every error names the file.

use super::{LightField, Rect3, Slab, SlabError};
use glam::Vec3;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

const MAGIC: &[u8; 8] = b"PLXLF\0\0\0";
const VERSION: u32 = 1;
/// Bytes before the samples.
const HEADER: usize = 8 + 4 + 4 + 16 + 72 + 8 + 4 + 8;

/// Why a light-field file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: not a light-field file (no PLXLF header)")]
    NotALightField { path: PathBuf },
    #[error("{path}: version {found} is not supported (this build reads version {VERSION})")]
    Version { path: PathBuf, found: u32 },
    #[error("{path}: unknown {what} {found}")]
    Unknown {
        path: PathBuf,
        what: &'static str,
        found: u32,
    },
    #[error("{path}: bad slab: {source}")]
    Slab { path: PathBuf, source: SlabError },
    #[error("{path}: the header counts {declared} samples, but {nu} x {nv} x {ns} x {nt} makes {expected}")]
    Count {
        path: PathBuf,
        declared: u64,
        expected: u64,
        nu: u32,
        nv: u32,
        ns: u32,
        nt: u32,
    },
    #[error("{path}: {found} bytes of samples where the header promises {expected} (truncated or trailing data)")]
    Length {
        path: PathBuf,
        expected: u64,
        found: u64,
    },
}

impl LightField {
    /// Writes the light field to `path` (see the module's layout).
    pub fn save(&self, path: &Path) -> Result<(), FileError> {
        let io = |source| FileError::Io {
            path: path.to_path_buf(),
            source,
        };
        let mut out = Vec::with_capacity(HEADER + 4 * self.samples.len());
        out.extend_from_slice(MAGIC);
        let sl = &self.slab;
        for v in [VERSION, 0, sl.nu, sl.nv, sl.ns, sl.nt] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for r in [&sl.uv, &sl.st] {
            for v in [r.origin, r.edge_a, r.edge_b] {
                for c in v.to_array() {
                    out.extend_from_slice(&c.to_le_bytes());
                }
            }
        }
        for v in [sl.near, sl.far] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        let with_depth = self.depth.len() == self.samples.len();
        out.extend_from_slice(&(with_depth as u32).to_le_bytes());
        out.extend_from_slice(&(self.samples.len() as u64).to_le_bytes());
        for s in &self.samples {
            out.extend_from_slice(&s.to_le_bytes());
        }
        if with_depth {
            for d in &self.depth {
                out.extend_from_slice(&d.to_le_bytes());
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
        let (version, encoding) = (u32_(), u32_());
        let counts = [u32_(), u32_(), u32_(), u32_()];
        let floats: Vec<f32> = (0..20).map(|_| f32::from_bits(u32_())).collect();
        let payload = u32_();
        let declared = u64::from_le_bytes(head[HEADER - 8..].try_into().unwrap_or([0; 8]));
        if version != VERSION {
            return Err(FileError::Version {
                path: p(),
                found: version,
            });
        }
        for (what, found, known) in [("sample encoding", encoding, 0), ("payload", payload, 1)] {
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
        let slab = Slab::new(rect(0), rect(9), counts, floats[18], floats[19])
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
        let per_sample = 4 * (1 + payload as u64);
        if expected.checked_mul(per_sample) != Some(found) {
            return Err(FileError::Length {
                path: p(),
                expected: expected.saturating_mul(per_sample),
                found,
            });
        }
        // The file holds exactly this many bytes: the allocation is bounded by its size.
        let mut bytes = Vec::with_capacity(found as usize);
        f.take(found).read_to_end(&mut bytes).map_err(io)?;
        if bytes.len() as u64 != found {
            return Err(FileError::Length {
                path: p(),
                expected: found,
                found: bytes.len() as u64,
            });
        }
        let words = |b: &[u8]| {
            b.chunks_exact(4)
                .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect::<Vec<u32>>()
        };
        let (colour, depth) = bytes.split_at(expected as usize * 4);
        let samples = words(colour);
        let depth = words(depth).into_iter().map(f32::from_bits).collect();
        Ok(LightField {
            slab,
            samples,
            depth,
        })
    }
}
