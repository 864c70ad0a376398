//! Eight-lane vectors for the raster and shade kernels (and the `ibr` warp's rows): `F8` (f32), `I8` (i32) and `M8`
//! (a lane mask), with AVX2 intrinsics when the build enables them (`.cargo/config.toml`)
//! and a plain-array fallback otherwise. Both paths compute the same IEEE operations in the
//! same order, so pixels do not depend on which one was built.
//!
//! This is the crate's only `unsafe` code (in `avx.rs`), and it is the calls of
//! register-to-register intrinsics (no pointers: `bytemuck` converts arrays to and from
//! registers), one cache hint ([`prefetch`], which takes an address but reads nothing
//! through it), the texture gathers ([`I8::gather_pairs`], [`I8::gather_u32_lanes`] and
//! their masked forms) and 16-byte loads ([`I8::load_quads`]), whose indices are clamped
//! into their table before the read. The gather replaced eight scalar loads and inserts per texture
//! tap: on this Zen 5 class machine the textured torus 100k (`engine/examples/fragbench.rs`,
//! 1280x720, one thread, peer lighting) went from a 30.9 to a 28.2 ms fastest frame, same
//! run, 60 frames (an earlier measurement on Zen 4 had found it no faster). Measured on
//! the `huge_64` scene at 1920x1080 (one thread), the auto-vectorised array version of the
//! raster kernel spent most of its time rebuilding lane masks from `[bool; 8]` and ran about
//! 2x slower than this one. A bilinear tap-set is now one 16-byte load a lane
//! ([`I8::load_quads`]: each texel stored beside the one below it) where it was four
//! gathers: on an Ice Lake host (session 32) an 8-lane gather cost about 30 cycles, and the
//! textured torus 10k (`render --obj out/scenes/tex_10k/scene.obj --shading textured
//! --peer-light -W 1280 -H 720 --threads 1 --frames 150`) took 0.885 of the user time
//! (median of 8 alternated pairs), the pixels the same.

/// Lanes per vector: 8 (one 256-bit AVX2 register of `f32` or `i32`).
pub const LANES: usize = 8;

#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
#[allow(unsafe_code)] // reason: AVX2 intrinsics; see the module doc and `avx!`
mod avx;
#[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
mod scalar;

#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
use avx as imp;
#[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
use scalar as imp;

pub use imp::{prefetch, F8, I8, M8};

impl I8 {
    /// Loads 8 lanes from the start of `s` (which must hold at least 8), as `i32` bits.
    #[inline(always)]
    pub fn load_u32(s: &[u32]) -> Self {
        let a: [u32; LANES] = s[..LANES].try_into().expect("8 lanes");
        I8::from_array(a.map(|v| v as i32))
    }
    /// Stores 8 lanes to the start of `s` (which must hold at least 8).
    #[inline(always)]
    pub fn store(self, s: &mut [i32]) {
        s[..LANES].copy_from_slice(&self.to_array());
    }
}

impl F8 {
    /// Loads 8 lanes from the start of `s` (which must hold at least 8).
    #[inline(always)]
    pub fn load(s: &[f32]) -> Self {
        let a: [f32; LANES] = s[..LANES].try_into().expect("8 lanes");
        F8::from_array(a)
    }
    /// Stores 8 lanes to the start of `s`.
    #[inline(always)]
    pub fn store(self, s: &mut [f32]) {
        s[..LANES].copy_from_slice(&self.to_array());
    }
    /// `dst[l] = if m[l] { self[l] } else { dst[l] }` with one full-width store. The old
    /// value passes through `black_box` so the compiler cannot turn load-select-store into
    /// a masked store (`vmaskmovps`), which is microcoded on AMD Zen: measured, it took a
    /// quarter of the raster time of `torus_10k` at 1920x1080.
    #[inline(always)]
    pub fn blend_into(self, m: M8, dst: &mut [f32]) {
        if m.bits() == (1 << LANES) - 1 {
            self.store(dst);
        } else {
            let old = std::hint::black_box(F8::load(dst));
            m.select(self, old).store(dst);
        }
    }
    /// Clamped to [0, 1]; NaN becomes 0.
    #[inline(always)]
    pub fn clamp01(self) -> Self {
        self.max(F8::splat(0.0)).min(F8::splat(1.0))
    }
    /// `a * b + c`, unfused (the same rounding on every path).
    #[inline(always)]
    pub fn mul_add(self, b: Self, c: Self) -> Self {
        self * b + c
    }
}

#[cfg(test)]
mod tests;
