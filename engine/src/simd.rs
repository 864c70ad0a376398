//! Eight-lane vectors for the raster and shade kernels (and the `ibr` warp's rows): `F8` (f32), `I8` (i32) and `M8`
//! (a lane mask), with AVX2 intrinsics when the build enables them (`.cargo/config.toml`)
//! and a plain-array fallback otherwise. Both paths compute the same IEEE operations in the
//! same order, so pixels do not depend on which one was built.
//!
//! This is the crate's only `unsafe` code, and it is only the calls of register-to-register
//! intrinsics (no pointers: `bytemuck` converts arrays to and from registers) and one cache
//! hint ([`prefetch`], which takes an address but reads nothing through it). Table
//! lookups ([`I8::gather_pairs`]) are plain loads: an AVX2 gather measured no faster for
//! texture taps (10k blended particles, and the impostor city, at 1280x720, one thread, Zen 4). Measured on
//! the `huge_64` scene at 1920x1080 (one thread), the auto-vectorised array version of the
//! raster kernel spent most of its time rebuilding lane masks from `[bool; 8]` and ran about
//! 2x slower than this one.

/// Lanes per vector: 8 (one 256-bit AVX2 register of `f32` or `i32`).
pub const LANES: usize = 8;

#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
#[allow(unsafe_code)] // reason: AVX2 intrinsics; see the module doc and `avx!`
mod imp {
    use super::LANES;
    use std::arch::x86_64::*;

    /// Calls AVX/AVX2 intrinsics.
    macro_rules! avx {
        ($e:expr) => {
            // SAFETY: this module is compiled only when `target_feature = "avx2"` is enabled
            // for the whole build (see the `cfg` above), so every AVX/AVX2 instruction the
            // intrinsic emits exists on the machine running it. The intrinsics used here
            // take and return registers only; none dereferences a pointer.
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
}

#[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
mod imp {
    use super::LANES;
    type A = [f32; LANES];

    /// Without AVX2 the build targets no particular CPU: no cache hint.
    pub fn prefetch<T>(_: &T) {}

    /// Eight `f32` lanes.
    #[derive(Clone, Copy, Debug)]
    pub struct F8(A);
    /// Eight `i32` lanes.
    #[derive(Clone, Copy, Debug)]
    pub struct I8([i32; LANES]);
    /// A mask of eight lanes, made by comparisons and read by `select`.
    #[derive(Clone, Copy, Debug)]
    pub struct M8([bool; LANES]);

    fn map(a: A, b: A, f: impl Fn(f32, f32) -> f32) -> A {
        std::array::from_fn(|l| f(a[l], b[l]))
    }

    impl F8 {
        /// Every lane `x`.
        pub fn splat(x: f32) -> Self {
            F8([x; LANES])
        }
        /// Lane `l` is `a[l]`.
        pub fn from_array(a: A) -> Self {
            F8(a)
        }
        /// The lanes, lane 0 first.
        pub fn to_array(self) -> A {
            self.0
        }
        /// `[0, 1, ..., 7]`.
        pub fn ramp() -> Self {
            F8(std::array::from_fn(|l| l as f32))
        }
        // Same NaN behaviour as minps/maxps: the second operand wins.
        /// Lane-wise minimum; where a lane of either is NaN, the lane of `o` (as `vminps`).
        pub fn min(self, o: Self) -> Self {
            F8(map(self.0, o.0, |a, b| if a < b { a } else { b }))
        }
        /// Lane-wise maximum; where a lane of either is NaN, the lane of `o` (as `vmaxps`).
        pub fn max(self, o: Self) -> Self {
            F8(map(self.0, o.0, |a, b| if a > b { a } else { b }))
        }
        /// Lanes where `self > o` (unset where either is NaN).
        pub fn gt(self, o: Self) -> M8 {
            M8(std::array::from_fn(|l| self.0[l] > o.0[l]))
        }
        /// Truncating conversion (in range for the callers: values in [0, 2^31)).
        pub fn to_i32(self) -> I8 {
            I8(std::array::from_fn(|l| self.0[l] as i32))
        }
        /// Lane-wise square root, correctly rounded (NaN for negative lanes).
        pub fn sqrt(self) -> Self {
            F8(self.0.map(f32::sqrt))
        }
        /// Lanes where `self >= o` (unset where either is NaN).
        pub fn ge(self, o: Self) -> M8 {
            M8(std::array::from_fn(|l| self.0[l] >= o.0[l]))
        }
        /// Lane-wise rounding toward negative infinity.
        pub fn floor(self) -> Self {
            F8(self.0.map(f32::floor))
        }
        /// Lanes that are not NaN and whose magnitude is below `limit`.
        pub fn within(self, limit: f32) -> M8 {
            M8(std::array::from_fn(|l| self.0[l].abs() < limit))
        }
        /// The sign bit cleared.
        pub fn abs(self) -> Self {
            F8(self.0.map(f32::abs))
        }
        /// `self * b + c`, rounded once (FMA).
        pub fn fma(self, b: Self, c: Self) -> Self {
            F8(std::array::from_fn(|l| self.0[l].mul_add(b.0[l], c.0[l])))
        }
        /// `c - self * b`, rounded once.
        pub fn fnma(self, b: Self, c: Self) -> Self {
            F8(std::array::from_fn(|l| {
                (-self.0[l]).mul_add(b.0[l], c.0[l])
            }))
        }
        /// Lane `l` is lane `idx[l]` (of `0..8`) of `self`.
        pub fn permute(self, idx: [u32; LANES]) -> Self {
            F8(idx.map(|i| self.0[i as usize % LANES]))
        }
        /// Lanes 0, 2, .. 14 and lanes 1, 3, .. 15 of the sixteen lanes of `self` then `o`.
        pub fn deinterleave(self, o: Self) -> (Self, Self) {
            let at = |i: usize| if i < LANES { self.0[i] } else { o.0[i - LANES] };
            (
                F8(std::array::from_fn(|l| at(2 * l))),
                F8(std::array::from_fn(|l| at(2 * l + 1))),
            )
        }
        /// Lanes where `self < o` (unset where either is NaN).
        pub fn lt(self, o: Self) -> M8 {
            M8(std::array::from_fn(|l| self.0[l] < o.0[l]))
        }
        /// Lanes where `self <= o` (unset where either is NaN).
        pub fn le(self, o: Self) -> M8 {
            M8(std::array::from_fn(|l| self.0[l] <= o.0[l]))
        }
    }

    impl I8 {
        /// Every lane `x`.
        pub fn splat(x: i32) -> Self {
            I8([x; LANES])
        }
        /// Lane `l` is `l * k`.
        pub fn ramp_times(k: i32) -> Self {
            I8(std::array::from_fn(|l| l as i32 * k))
        }
        /// Bitwise or.
        pub fn or(self, o: Self) -> Self {
            I8(std::array::from_fn(|l| self.0[l] | o.0[l]))
        }
        /// Lane-wise shift left by `N` bits.
        pub fn shl<const N: i32>(self) -> Self {
            I8(std::array::from_fn(|l| self.0[l] << N))
        }
        /// The lanes, lane 0 first.
        pub fn to_array(self) -> [i32; LANES] {
            self.0
        }
        /// Lane `l` is `a[l]`.
        pub fn from_array(a: [i32; LANES]) -> Self {
            I8(a)
        }
        /// Lanes where `self == o`.
        pub fn eq(self, o: Self) -> M8 {
            M8(std::array::from_fn(|l| self.0[l] == o.0[l]))
        }
        /// Lanes where `self >= 0`.
        pub fn non_negative(self) -> M8 {
            M8(std::array::from_fn(|l| self.0[l] >= 0))
        }
        /// Lanes `l` with `lo <= l <= hi`.
        pub fn lane_range(lo: i32, hi: i32) -> M8 {
            M8(std::array::from_fn(|l| l as i32 >= lo && l as i32 <= hi))
        }
        /// Lane-wise signed minimum.
        pub fn min(self, o: Self) -> Self {
            I8(std::array::from_fn(|l| self.0[l].min(o.0[l])))
        }
        /// Lane-wise signed maximum.
        pub fn max(self, o: Self) -> Self {
            I8(std::array::from_fn(|l| self.0[l].max(o.0[l])))
        }
        /// Low 32 bits of the lane products.
        pub fn mul_lo(self, o: Self) -> Self {
            I8(std::array::from_fn(|l| self.0[l].wrapping_mul(o.0[l])))
        }
        /// Bitwise and.
        pub fn and(self, o: Self) -> Self {
            I8(std::array::from_fn(|l| self.0[l] & o.0[l]))
        }
        /// Logical shift right.
        pub fn shr<const N: i32>(self) -> Self {
            I8(std::array::from_fn(|l| ((self.0[l] as u32) >> N) as i32))
        }
        /// Lane-wise conversion to `f32`, rounded to nearest.
        pub fn to_f32(self) -> F8 {
            F8(std::array::from_fn(|l| self.0[l] as f32))
        }
        /// As [`F8::deinterleave`].
        pub fn deinterleave(self, o: Self) -> (Self, Self) {
            let at = |i: usize| if i < LANES { self.0[i] } else { o.0[i - LANES] };
            (
                I8(std::array::from_fn(|l| at(2 * l))),
                I8(std::array::from_fn(|l| at(2 * l + 1))),
            )
        }
    }

    impl std::ops::Add for F8 {
        type Output = Self;
        fn add(self, o: Self) -> Self {
            F8(map(self.0, o.0, |a, b| a + b))
        }
    }

    impl std::ops::Sub for F8 {
        type Output = Self;
        fn sub(self, o: Self) -> Self {
            F8(map(self.0, o.0, |a, b| a - b))
        }
    }

    impl std::ops::Mul for F8 {
        type Output = Self;
        fn mul(self, o: Self) -> Self {
            F8(map(self.0, o.0, |a, b| a * b))
        }
    }

    impl std::ops::Div for F8 {
        type Output = Self;
        fn div(self, o: Self) -> Self {
            F8(map(self.0, o.0, |a, b| a / b))
        }
    }

    impl std::ops::Add for I8 {
        type Output = Self;
        fn add(self, o: Self) -> Self {
            I8(std::array::from_fn(|l| self.0[l] + o.0[l]))
        }
    }

    impl M8 {
        /// Lane `l` set where bit `l` of `bits` is.
        pub fn from_bits(bits: u32) -> Self {
            M8(std::array::from_fn(|l| bits >> l & 1 != 0))
        }
        /// Lanes set in both.
        pub fn and(self, o: Self) -> Self {
            M8(std::array::from_fn(|l| self.0[l] && o.0[l]))
        }
        /// Lanes set in `self` and not in `o`.
        pub fn and_not(self, o: Self) -> Self {
            M8(std::array::from_fn(|l| self.0[l] && !o.0[l]))
        }
        /// Lanes set in either.
        pub fn or(self, o: Self) -> Self {
            M8(std::array::from_fn(|l| self.0[l] || o.0[l]))
        }
        /// One bit per lane: bit `l` is lane `l`.
        pub fn bits(self) -> u32 {
            (0..LANES).fold(0, |b, l| b | (self.0[l] as u32) << l)
        }
        /// `if lane { a } else { b }`.
        pub fn select(self, a: F8, b: F8) -> F8 {
            F8(std::array::from_fn(
                |l| if self.0[l] { a.0[l] } else { b.0[l] },
            ))
        }
        /// `if lane { a } else { b }`, of integers.
        pub fn select_i32(self, a: I8, b: I8) -> I8 {
            I8(std::array::from_fn(
                |l| if self.0[l] { a.0[l] } else { b.0[l] },
            ))
        }
    }
}

pub use imp::{prefetch, F8, I8, M8};

impl I8 {
    /// `table[idx]` for every lane, each index first clamped into the table, split into
    /// its low and high 32 bits (zeros for an empty table).
    #[inline(always)]
    pub fn gather_pairs(table: &[u64], idx: I8) -> (I8, I8) {
        let Some(last) = table.len().checked_sub(1) else {
            return (I8::splat(0), I8::splat(0));
        };
        let last = last.min(i32::MAX as usize) as i32;
        let i = idx.max(I8::splat(0)).min(I8::splat(last)).to_array();
        let v: [u64; LANES] = std::array::from_fn(|l| table[i[l] as usize]);
        (
            I8::from_array(v.map(|x| x as u32 as i32)),
            I8::from_array(v.map(|x| (x >> 32) as u32 as i32)),
        )
    }
}

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
mod tests {
    use super::*;

    #[test]
    fn lanes_behave() {
        let a = F8::from_array([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]);
        let b = F8::splat(3.5);
        assert_eq!(a.gt(b).bits(), 0b1111_0000);
        assert_eq!(a.ge(F8::splat(3.0)).bits(), 0b1111_1000);
        assert_eq!(
            a.gt(b).select(a, b).to_array(),
            [3.5, 3.5, 3.5, 3.5, 4.0, 5.0, 6.0, 7.0]
        );
        assert_eq!(I8::lane_range(2, 4).bits(), 0b0001_1100);
        assert_eq!(M8::from_bits(0b1010_0110).bits(), 0b1010_0110);
        assert_eq!(
            (I8::ramp_times(-3) + I8::splat(6)).non_negative().bits(),
            0b0000_0111
        );
        assert_eq!(F8::ramp().to_array()[7], 7.0);
        let c = F8::from_array([-1.0, -0.0, 2.0, f32::NAN, 3.5, -3.5, 0.0, 7.0]);
        assert_eq!(c.abs().to_array()[..3], [1.0, 0.0, 2.0]);
        assert_eq!(c.lt(b).bits(), 0b0110_0111);
        assert_eq!(c.le(b).bits(), 0b0111_0111);
        assert_eq!(c.lt(b).and_not(c.le(F8::splat(0.0))).bits(), 0b0000_0100);
        assert_eq!(c.gt(b).or(c.le(F8::splat(0.0))).bits(), 0b1110_0011);
        assert_eq!(
            F8::ramp().permute([7, 0, 1, 1, 2, 2, 3, 7]).to_array(),
            [7.0, 0.0, 1.0, 1.0, 2.0, 2.0, 3.0, 7.0]
        );
        let hi = F8::ramp() + F8::splat(8.0);
        let (even, odd) = F8::ramp().deinterleave(hi);
        assert_eq!(even.to_array(), [0.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0]);
        assert_eq!(odd.to_array(), [1.0, 3.0, 5.0, 7.0, 9.0, 11.0, 13.0, 15.0]);
        let (even, odd) = I8::ramp_times(1).deinterleave(I8::ramp_times(1) + I8::splat(8));
        assert_eq!(even.to_array(), [0, 2, 4, 6, 8, 10, 12, 14]);
        assert_eq!(odd.to_array(), [1, 3, 5, 7, 9, 11, 13, 15]);
        assert_eq!(
            M8::from_bits(0b0101)
                .select_i32(I8::splat(7), I8::splat(-1))
                .to_array()[..4],
            [7, -1, 7, -1]
        );
        assert_eq!(
            I8::ramp_times(2)
                .eq(I8::from_array([0, 2, 5, 6, 0, 0, 12, 14]))
                .bits(),
            0b1100_1011
        );
        let words = [0xff00_0001u32, 2, 3, 4, 5, 6, 7, 8];
        assert_eq!(I8::load_u32(&words).shr::<24>().to_array()[0], 0xff);
        let packed = F8::from_array([0.0, 0.5, 1.0, 2.0, -1.0, f32::NAN, 0.25, 0.75]).clamp01();
        assert_eq!(packed.to_array()[3], 1.0);
        assert_eq!(packed.to_array()[5], 0.0);
        assert_eq!(
            I8::splat(3).shl::<8>().or(I8::splat(1)).to_array()[0],
            0x301
        );
        let table = [10u64 | 20 << 32, 11 | 21 << 32, 12 | 22 << 32];
        let idx = I8::from_array([-5, 0, 1, 2, 3, i32::MAX, i32::MIN, 1]);
        let (lo, hi) = I8::gather_pairs(&table, idx);
        assert_eq!(lo.to_array(), [10, 10, 11, 12, 12, 12, 10, 11]);
        assert_eq!(hi.to_array(), [20, 20, 21, 22, 22, 22, 20, 21]);
        assert_eq!(I8::gather_pairs(&[], idx).0.to_array(), [0; 8]);
        // Fused: rounded once, so (1 + e)(1 - e) - 1 keeps the -e^2 an unfused product loses.
        let e = F8::splat(f32::EPSILON);
        let (p, q) = (F8::splat(1.0) + e, F8::splat(1.0) - e);
        assert_eq!(
            p.fma(q, F8::splat(-1.0)).to_array()[0],
            -f32::EPSILON * f32::EPSILON
        );
        assert_eq!(
            p.fnma(q, F8::splat(1.0)).to_array()[0],
            f32::EPSILON * f32::EPSILON
        );
        assert_eq!((p * q + F8::splat(-1.0)).to_array()[0], 0.0);
        let mut s = [0.0; 9];
        a.store(&mut s);
        assert_eq!(F8::load(&s).to_array(), a.to_array());
    }
}
