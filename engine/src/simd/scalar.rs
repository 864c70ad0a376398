//! The portable backend of [`super`]: plain arrays, the same IEEE operations in the same
//! order as the AVX2 one.

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
    /// [`I8::gather_pairs`] for the lanes of `keep` only; the other lanes are zero (this
    /// backend reads them and drops them).
    pub fn gather_pairs_lanes(table: &[u64], idx: I8, keep: M8) -> (I8, I8) {
        let (lo, hi) = Self::gather_pairs(table, idx);
        (
            keep.select_i32(lo, I8::splat(0)),
            keep.select_i32(hi, I8::splat(0)),
        )
    }
    /// `table[idx]` for the lanes of `keep` (each index first clamped into the table),
    /// zero in the others.
    pub fn gather_u32_lanes(table: &[u32], idx: I8, keep: M8) -> I8 {
        let Some(last) = table.len().checked_sub(1) else {
            return I8::splat(0);
        };
        let last = last.min(i32::MAX as usize) as i32;
        let i = idx.max(I8::splat(0)).min(I8::splat(last)).to_array();
        let v = I8::from_array(std::array::from_fn(|l| table[i[l] as usize] as i32));
        keep.select_i32(v, I8::splat(0))
    }
    /// `table[idx + k]` for `k` in `0..4`, as four vectors, for the lanes of `keep`, each
    /// index first clamped into `0..=len - 4` (zeros for a table under four long, and in
    /// the lanes not kept).
    pub fn load_quads(table: &[u32], idx: I8, keep: M8) -> [I8; 4] {
        let Some(last) = table.len().checked_sub(4) else {
            return [I8::splat(0); 4];
        };
        let last = last.min(i32::MAX as usize) as i32;
        let i = idx.max(I8::splat(0)).min(I8::splat(last)).to_array();
        std::array::from_fn(|k| {
            let v = I8::from_array(std::array::from_fn(|l| table[i[l] as usize + k] as i32));
            keep.select_i32(v, I8::splat(0))
        })
    }
    /// `table[idx]` for every lane, each index first clamped into the table, split into
    /// its low and high 32 bits (zeros for an empty table).
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
    /// Logical shift right of each lane by its own count in `n` (counts over 31 give 0).
    pub fn shr_by(self, n: I8) -> Self {
        I8(std::array::from_fn(|l| {
            (self.0[l] as u32).checked_shr(n.0[l] as u32).unwrap_or(0) as i32
        }))
    }
    /// The lanes' bits as `f32`s (a reinterpretation, not a conversion).
    pub fn bits_to_f32(self) -> F8 {
        F8(self.0.map(|x| f32::from_bits(x as u32)))
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
