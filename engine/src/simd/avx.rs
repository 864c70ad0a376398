//! The AVX2 backend of [`super`]: one register per vector, intrinsics only.

use super::LANES;
use std::arch::x86_64::*;

/// Calls AVX/AVX2 intrinsics.
macro_rules! avx {
    ($e:expr) => {
        // SAFETY: this module is compiled only when `target_feature = "avx2"` is enabled
        // for the whole build (see the `cfg` on `mod avx` in `simd/mod.rs`), so every AVX/AVX2 instruction the
        // intrinsic emits exists on the machine running it. The intrinsics used here
        // take and return registers only; none dereferences a pointer (the one gather,
        // in `I8::gather_pairs`, says why its reads stay inside its table).
        unsafe { $e }
    };
}

/// Asks the cache for `x`, to be read soon: one line every 64 bytes from its start. The
/// extra line an unaligned value can reach into is not asked for; measured, doing so
/// cost more on torus and grid 1M than it saved on confetti (1920x1080, one thread).
#[inline(always)]
pub fn prefetch<T>(x: &T) {
    let first = (x as *const T).cast::<i8>();
    for line in (0..size_of::<T>().max(1)).step_by(64) {
        // SAFETY: `prefetcht0` only hints the cache: it never faults and reads nothing
        // into the program; the addresses lie within `x`, a live reference.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(first.wrapping_add(line)) }
    }
}

/// Eight `f32` lanes in one AVX register.
#[derive(Clone, Copy, Debug)]
pub struct F8(__m256);
/// Eight `i32` lanes in one AVX2 register.
#[derive(Clone, Copy, Debug)]
pub struct I8(__m256i);
/// A mask of eight lanes (each all ones or all zeros), made by comparisons and read by
/// `select`.
#[derive(Clone, Copy, Debug)]
pub struct M8(__m256);

impl F8 {
    /// Every lane `x`.
    #[inline(always)]
    pub fn splat(x: f32) -> Self {
        avx!(F8(_mm256_set1_ps(x)))
    }
    /// Lane `l` is `a[l]`.
    #[inline(always)]
    pub fn from_array(a: [f32; LANES]) -> Self {
        F8(bytemuck::cast(a))
    }
    /// The lanes, lane 0 first.
    #[inline(always)]
    pub fn to_array(self) -> [f32; LANES] {
        bytemuck::cast(self.0)
    }
    /// `[0, 1, ..., 7]`.
    #[inline(always)]
    pub fn ramp() -> Self {
        avx!(F8(_mm256_setr_ps(0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0)))
    }
    /// Lane-wise minimum; where a lane of either is NaN, the lane of `o` (as `vminps`).
    #[inline(always)]
    pub fn min(self, o: Self) -> Self {
        avx!(F8(_mm256_min_ps(self.0, o.0)))
    }
    /// Lane-wise maximum; where a lane of either is NaN, the lane of `o` (as `vmaxps`).
    #[inline(always)]
    pub fn max(self, o: Self) -> Self {
        avx!(F8(_mm256_max_ps(self.0, o.0)))
    }
    /// Lanes where `self > o` (unset where either is NaN).
    #[inline(always)]
    pub fn gt(self, o: Self) -> M8 {
        avx!(M8(_mm256_cmp_ps::<_CMP_GT_OQ>(self.0, o.0)))
    }
    /// Lane-wise square root, correctly rounded (NaN for negative lanes).
    #[inline(always)]
    pub fn sqrt(self) -> Self {
        avx!(F8(_mm256_sqrt_ps(self.0)))
    }
    /// Truncating conversion (in range for the callers: values in [0, 2^31)).
    #[inline(always)]
    pub fn to_i32(self) -> I8 {
        avx!(I8(_mm256_cvttps_epi32(self.0)))
    }
    /// Lanes where `self >= o` (unset where either is NaN).
    #[inline(always)]
    pub fn ge(self, o: Self) -> M8 {
        avx!(M8(_mm256_cmp_ps::<_CMP_GE_OQ>(self.0, o.0)))
    }
    /// Lane-wise rounding toward negative infinity.
    #[inline(always)]
    pub fn floor(self) -> Self {
        avx!(F8(_mm256_floor_ps(self.0)))
    }
    /// Lanes that are not NaN and whose magnitude is below `limit`.
    #[inline(always)]
    pub fn within(self, limit: f32) -> M8 {
        let abs = avx!(_mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0));
        avx!(M8(_mm256_cmp_ps::<_CMP_LT_OQ>(abs, _mm256_set1_ps(limit))))
    }
    /// Lanes 0, 2, .. 14 and lanes 1, 3, .. 15 of the sixteen lanes of `self` then `o`.
    #[inline(always)]
    pub fn deinterleave(self, o: Self) -> (Self, Self) {
        let even = avx!(_mm256_shuffle_ps::<0b10_00_10_00>(self.0, o.0));
        let odd = avx!(_mm256_shuffle_ps::<0b11_01_11_01>(self.0, o.0));
        // Each is [0 2 | 8 10 | 4 6 | 12 14] in 64-bit pairs: swap the middle two.
        let fix = |v: __m256| {
            let pairs = avx!(_mm256_permute4x64_pd::<0b11_01_10_00>(_mm256_castps_pd(v)));
            avx!(_mm256_castpd_ps(pairs))
        };
        (F8(fix(even)), F8(fix(odd)))
    }
    /// Lane `l` is lane `idx[l]` (of `0..8`) of `self`.
    #[inline(always)]
    pub fn permute(self, idx: [u32; LANES]) -> Self {
        let i: __m256i = bytemuck::cast(idx);
        avx!(F8(_mm256_permutevar8x32_ps(self.0, i)))
    }
    /// The sign bit cleared.
    #[inline(always)]
    pub fn abs(self) -> Self {
        avx!(F8(_mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0)))
    }
    /// `self * b + c`, rounded once (FMA); the fallback's `f32::mul_add` rounds the same.
    #[cfg(target_feature = "fma")]
    #[inline(always)]
    pub fn fma(self, b: Self, c: Self) -> Self {
        avx!(F8(_mm256_fmadd_ps(self.0, b.0, c.0)))
    }
    /// `c - self * b`, rounded once.
    #[cfg(target_feature = "fma")]
    #[inline(always)]
    pub fn fnma(self, b: Self, c: Self) -> Self {
        avx!(F8(_mm256_fnmadd_ps(self.0, b.0, c.0)))
    }
    /// `self * b + c`, rounded once (FMA).
    #[cfg(not(target_feature = "fma"))]
    #[inline(always)]
    pub fn fma(self, b: Self, c: Self) -> Self {
        let (a, b, c) = (self.to_array(), b.to_array(), c.to_array());
        F8::from_array(std::array::from_fn(|l| a[l].mul_add(b[l], c[l])))
    }
    /// `c - self * b`, rounded once.
    #[cfg(not(target_feature = "fma"))]
    #[inline(always)]
    pub fn fnma(self, b: Self, c: Self) -> Self {
        let (a, b, c) = (self.to_array(), b.to_array(), c.to_array());
        F8::from_array(std::array::from_fn(|l| (-a[l]).mul_add(b[l], c[l])))
    }
    /// Lanes where `self < o` (unset where either is NaN).
    #[inline(always)]
    pub fn lt(self, o: Self) -> M8 {
        avx!(M8(_mm256_cmp_ps::<_CMP_LT_OQ>(self.0, o.0)))
    }
    /// Lanes where `self <= o` (unset where either is NaN).
    #[inline(always)]
    pub fn le(self, o: Self) -> M8 {
        avx!(M8(_mm256_cmp_ps::<_CMP_LE_OQ>(self.0, o.0)))
    }
}

impl I8 {
    /// [`I8::gather_pairs`] for the lanes of `keep` only; the other lanes read nothing and
    /// are zero.
    #[inline(always)]
    pub fn gather_pairs_lanes(table: &[u64], idx: I8, keep: M8) -> (I8, I8) {
        if keep.bits() == 0xff {
            return Self::gather_pairs(table, idx);
        }
        let Some(last) = table.len().checked_sub(1) else {
            return (I8::splat(0), I8::splat(0));
        };
        let last = last.min(i32::MAX as usize) as i32;
        let i = idx.max(I8::splat(0)).min(I8::splat(last)).0;
        // SAFETY: as in `gather_pairs`: every index was clamped into `0..=last`, so each
        // 8-byte read a kept lane makes lies inside `table`; masked-off lanes read nothing.
        unsafe { gather_u64_masked::<8>(table.as_ptr().cast::<i64>(), i, keep) }
    }
    /// `table[idx]` for the lanes of `keep` (each index first clamped into the table),
    /// zero in the others, which read nothing. One AVX2 gather of eight 32-bit texels.
    #[inline(always)]
    pub fn gather_u32_lanes(table: &[u32], idx: I8, keep: M8) -> I8 {
        let Some(last) = table.len().checked_sub(1) else {
            return I8::splat(0);
        };
        let last = last.min(i32::MAX as usize) as i32;
        let i = idx.max(I8::splat(0)).min(I8::splat(last)).0;
        let base = table.as_ptr().cast::<i32>();
        let m = avx!(_mm256_castps_si256(keep.0));
        let zero = avx!(_mm256_setzero_si256());
        // SAFETY: every index was clamped into `0..=last`, so each 4-byte read a kept lane
        // makes lies inside `table`, a live slice of `u32`s; masked-off lanes read nothing.
        I8(unsafe { _mm256_mask_i32gather_epi32::<4>(zero, base, i, m) })
    }
    /// `table[idx + k]` for `k` in `0..4`, as four vectors (the `k`-th holds each lane's
    /// `k`-th word), for the lanes of `keep`, each index first clamped into `0..=len - 4`
    /// (zeros for a table under four long, and in the lanes not kept, which read where the
    /// first kept lane does, so they load no cache line of their own). A texel's bilinear
    /// tap-set stored as 4 neighbouring words is one 16-byte load a lane and a transpose:
    /// no gather (AVX2 gathers cost about 30 cycles each on the Ice Lake hosts this has
    /// run on).
    #[inline(always)]
    pub fn load_quads(table: &[u32], idx: I8, keep: M8) -> [I8; 4] {
        let Some(last) = table.len().checked_sub(4) else {
            return [I8::splat(0); 4];
        };
        let last = last.min(i32::MAX as usize) as i32;
        let i = kept_or_first(idx.max(I8::splat(0)).min(I8::splat(last)).0, keep);
        let at = |l: usize| -> __m128i {
            // SAFETY: every index was clamped into `0..=len - 4`, so the 16 bytes from
            // word `i[l]` on lie inside `table`, a live slice of `u32`s; `loadu` takes
            // any alignment.
            unsafe { _mm_loadu_si128(table.as_ptr().add(i[l] as usize).cast()) }
        };
        // Lanes `l` and `l + 4` in one register's halves, then a 4 x 4 transpose per half.
        // (Written out: `[0, 1, 2, 3].map(..)` was left a call, its indices passed through
        // memory.)
        let (c0, c1) = avx!((
            _mm256_set_m128i(at(4), at(0)),
            _mm256_set_m128i(at(5), at(1))
        ));
        let (c2, c3) = avx!((
            _mm256_set_m128i(at(6), at(2)),
            _mm256_set_m128i(at(7), at(3))
        ));
        let (t0, t1) = avx!((_mm256_unpacklo_epi32(c0, c1), _mm256_unpacklo_epi32(c2, c3)));
        let (t2, t3) = avx!((_mm256_unpackhi_epi32(c0, c1), _mm256_unpackhi_epi32(c2, c3)));
        let m = avx!(_mm256_castps_si256(keep.0));
        let kept = |v: __m256i| I8(avx!(_mm256_and_si256(v, m)));
        [
            kept(avx!(_mm256_unpacklo_epi64(t0, t1))),
            kept(avx!(_mm256_unpackhi_epi64(t0, t1))),
            kept(avx!(_mm256_unpacklo_epi64(t2, t3))),
            kept(avx!(_mm256_unpackhi_epi64(t2, t3))),
        ]
    }
    /// `table[idx]` for every lane, each index first clamped into the table, split into
    /// its low and high 32 bits (zeros for an empty table). Two AVX2 gathers of four
    /// 64-bit texels.
    #[inline(always)]
    pub fn gather_pairs(table: &[u64], idx: I8) -> (I8, I8) {
        let Some(last) = table.len().checked_sub(1) else {
            return (I8::splat(0), I8::splat(0));
        };
        let last = last.min(i32::MAX as usize) as i32;
        let i = idx.max(I8::splat(0)).min(I8::splat(last)).0;
        let base = table.as_ptr().cast::<i64>();
        let (lo4, hi4) = avx!((_mm256_castsi256_si128(i), _mm256_extracti128_si256::<1>(i)));
        // SAFETY: every index was clamped into `0..=last` above, so each 8-byte read
        // (index times 8 from `base`) lies inside `table`, a live slice of `u64`s; AVX2
        // is enabled for the whole build (see `avx!`).
        let (a, b) = unsafe {
            (
                _mm256_i32gather_epi64::<8>(base, lo4),
                _mm256_i32gather_epi64::<8>(base, hi4),
            )
        };
        // Lanes of `a` as i32: low 0, high 0, low 1, high 1, ...; likewise `b` for 4..8.
        I8(a).deinterleave(I8(b))
    }
    /// Every lane `x`.
    #[inline(always)]
    pub fn splat(x: i32) -> Self {
        avx!(I8(_mm256_set1_epi32(x)))
    }
    /// Lane `l` is `l * k`.
    #[inline(always)]
    pub fn ramp_times(k: i32) -> Self {
        avx!(I8(_mm256_mullo_epi32(
            _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7),
            _mm256_set1_epi32(k)
        )))
    }
    /// Bitwise or.
    #[inline(always)]
    pub fn or(self, o: Self) -> Self {
        avx!(I8(_mm256_or_si256(self.0, o.0)))
    }
    /// Lane-wise shift left by `N` bits.
    #[inline(always)]
    pub fn shl<const N: i32>(self) -> Self {
        avx!(I8(_mm256_slli_epi32::<N>(self.0)))
    }
    /// The lanes, lane 0 first.
    #[inline(always)]
    pub fn to_array(self) -> [i32; LANES] {
        bytemuck::cast(self.0)
    }
    /// Lane `l` is `a[l]`.
    #[inline(always)]
    pub fn from_array(a: [i32; LANES]) -> Self {
        I8(bytemuck::cast(a))
    }
    /// Lanes where `self == o`.
    #[inline(always)]
    pub fn eq(self, o: Self) -> M8 {
        avx!(M8(_mm256_castsi256_ps(_mm256_cmpeq_epi32(self.0, o.0))))
    }
    /// Lanes where `self >= 0`.
    #[inline(always)]
    pub fn non_negative(self) -> M8 {
        avx!(M8(_mm256_castsi256_ps(_mm256_cmpgt_epi32(
            self.0,
            _mm256_set1_epi32(-1)
        ))))
    }
    /// Lanes `l` with `lo <= l <= hi`.
    #[inline(always)]
    pub fn lane_range(lo: i32, hi: i32) -> M8 {
        let l = avx!(_mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
        let a = avx!(_mm256_cmpgt_epi32(l, _mm256_set1_epi32(lo - 1)));
        let b = avx!(_mm256_cmpgt_epi32(_mm256_set1_epi32(hi + 1), l));
        avx!(M8(_mm256_castsi256_ps(_mm256_and_si256(a, b))))
    }
    /// Lane-wise signed minimum.
    #[inline(always)]
    pub fn min(self, o: Self) -> Self {
        avx!(I8(_mm256_min_epi32(self.0, o.0)))
    }
    /// Lane-wise signed maximum.
    #[inline(always)]
    pub fn max(self, o: Self) -> Self {
        avx!(I8(_mm256_max_epi32(self.0, o.0)))
    }
    /// Low 32 bits of the lane products.
    #[inline(always)]
    pub fn mul_lo(self, o: Self) -> Self {
        avx!(I8(_mm256_mullo_epi32(self.0, o.0)))
    }
    /// Bitwise and.
    #[inline(always)]
    pub fn and(self, o: Self) -> Self {
        avx!(I8(_mm256_and_si256(self.0, o.0)))
    }
    /// Logical shift right.
    #[inline(always)]
    pub fn shr<const N: i32>(self) -> Self {
        avx!(I8(_mm256_srli_epi32::<N>(self.0)))
    }
    /// Logical shift right of each lane by its own count in `n` (counts over 31 give 0).
    #[inline(always)]
    pub fn shr_by(self, n: I8) -> Self {
        avx!(I8(_mm256_srlv_epi32(self.0, n.0)))
    }
    /// The lanes' bits as `f32`s (a reinterpretation, not a conversion).
    #[inline(always)]
    pub fn bits_to_f32(self) -> F8 {
        F8(bytemuck::cast(self.0))
    }
    /// Lane-wise conversion to `f32`, rounded to nearest.
    #[inline(always)]
    pub fn to_f32(self) -> F8 {
        avx!(F8(_mm256_cvtepi32_ps(self.0)))
    }
    /// As [`F8::deinterleave`].
    #[inline(always)]
    pub fn deinterleave(self, o: Self) -> (Self, Self) {
        let f = |v: __m256i| F8(avx!(_mm256_castsi256_ps(v)));
        let (even, odd) = f(self.0).deinterleave(f(o.0));
        let i = |v: F8| I8(avx!(_mm256_castps_si256(v.0)));
        (i(even), i(odd))
    }
}

impl std::ops::Add for F8 {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        avx!(F8(_mm256_add_ps(self.0, o.0)))
    }
}

impl std::ops::Sub for F8 {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        avx!(F8(_mm256_sub_ps(self.0, o.0)))
    }
}

impl std::ops::Mul for F8 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        avx!(F8(_mm256_mul_ps(self.0, o.0)))
    }
}

impl std::ops::Div for F8 {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        avx!(F8(_mm256_div_ps(self.0, o.0)))
    }
}

impl std::ops::Add for I8 {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        avx!(I8(_mm256_add_epi32(self.0, o.0)))
    }
}

impl M8 {
    /// Lane `l` set where bit `l` of `bits` is.
    #[inline(always)]
    pub fn from_bits(bits: u32) -> Self {
        let k = avx!(_mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128));
        let b = avx!(_mm256_and_si256(_mm256_set1_epi32(bits as i32), k));
        avx!(M8(_mm256_castsi256_ps(_mm256_cmpeq_epi32(b, k))))
    }
    /// Lanes set in both.
    #[inline(always)]
    pub fn and(self, o: Self) -> Self {
        avx!(M8(_mm256_and_ps(self.0, o.0)))
    }
    /// Lanes set in `self` and not in `o`.
    #[inline(always)]
    pub fn and_not(self, o: Self) -> Self {
        avx!(M8(_mm256_andnot_ps(o.0, self.0)))
    }
    /// Lanes set in either.
    #[inline(always)]
    pub fn or(self, o: Self) -> Self {
        avx!(M8(_mm256_or_ps(self.0, o.0)))
    }
    /// One bit per lane.
    #[inline(always)]
    pub fn bits(self) -> u32 {
        avx!(_mm256_movemask_ps(self.0) as u32)
    }
    /// `if lane { a } else { b }`.
    #[inline(always)]
    pub fn select(self, a: F8, b: F8) -> F8 {
        avx!(F8(_mm256_blendv_ps(b.0, a.0, self.0)))
    }
    /// `if lane { a } else { b }`, of integers.
    #[inline(always)]
    pub fn select_i32(self, a: I8, b: I8) -> I8 {
        let m = avx!(_mm256_castps_si256(self.0));
        avx!(I8(_mm256_blendv_epi8(b.0, a.0, m)))
    }
}

/// Eight 8-byte reads, at `base` plus `S` times each lane's index in bytes, for the lanes
/// of `keep` (zero in the others, which read nothing): two masked AVX2 gathers of four,
/// deinterleaved into the reads' low and high 32 bits.
///
/// # Safety
/// Every kept lane's 8 bytes at `base + S * index` must lie inside one live allocation.
#[inline(always)]
unsafe fn gather_u64_masked<const S: i32>(base: *const i64, i: __m256i, keep: M8) -> (I8, I8) {
    let m = avx!(_mm256_castps_si256(keep.0));
    let (lo4, hi4) = avx!((_mm256_castsi256_si128(i), _mm256_extracti128_si256::<1>(i)));
    // Each 32-bit lane mask widened (sign-extended) to the 64-bit lane it guards.
    let (mlo, mhi) = avx!((
        _mm256_cvtepi32_epi64(_mm256_castsi256_si128(m)),
        _mm256_cvtepi32_epi64(_mm256_extracti128_si256::<1>(m)),
    ));
    let zero = avx!(_mm256_setzero_si256());
    // SAFETY: the caller promises every kept lane's read lies inside a live allocation;
    // masked-off lanes read nothing.
    let (a, b) = unsafe {
        (
            _mm256_mask_i32gather_epi64::<S>(zero, base, lo4, mlo),
            _mm256_mask_i32gather_epi64::<S>(zero, base, hi4, mhi),
        )
    };
    I8(a).deinterleave(I8(b))
}

/// The index lanes `i`, each lane not in `keep` replaced by the first kept lane's index
/// (left as they are when no lane is kept).
#[inline(always)]
fn kept_or_first(i: __m256i, keep: M8) -> [i32; LANES] {
    let a: [i32; LANES] = bytemuck::cast(i);
    let k = keep.bits();
    let first = a[k.trailing_zeros() as usize & (LANES - 1)];
    let pick = |l: usize| if k >> l & 1 != 0 { a[l] } else { first };
    [
        pick(0),
        pick(1),
        pick(2),
        pick(3),
        pick(4),
        pick(5),
        pick(6),
        pick(7),
    ]
}
