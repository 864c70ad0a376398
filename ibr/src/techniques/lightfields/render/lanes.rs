//! Eight-lane helpers of the lookup: sample indices and weights from coordinates, a
//! packed colour weighted into channel sums, lane masks tested and counted, and the row
//! window eight lanes' samples share ([`window`]).

use engine::simd::{F8, I8, LANES, M8};

/// All eight lanes set, as bits.
pub(super) const ALL: u32 = (1 << LANES) - 1;

/// Index `0..=last` of the sample nearest each coordinate (centres at integers): rounded
/// half away from zero (as `f32::round` is computed: `x + 0.49999997`, truncated), then
/// clamped (first to 0, so truncating is flooring); NaN gives 0.
#[inline(always)]
pub(super) fn nearest(x: F8, last: F8) -> I8 {
    (x + F8::splat(0.499_999_97))
        .max(F8::splat(0.0))
        .min(last)
        .to_i32()
}

/// The two samples of `0..=last` around each coordinate (centres at integers) and the
/// weight of the second; one sample, weight 0, at the ends.
#[inline(always)]
pub(super) fn pair(x: F8, last: F8, last_i: I8) -> ([I8; 2], F8) {
    let x = x.max(F8::splat(0.0)).min(last);
    // Not negative: truncating is flooring.
    let i = x.to_i32();
    let f = x - i.to_f32();
    ([i, (i + I8::splat(1)).min(last_i)], f)
}

/// Adds each lane's packed colour `c` weighted by `w` to `acc`, channel by channel.
#[inline(always)]
pub(super) fn add(acc: &mut [F8; 4], c: I8, w: F8) {
    let byte = I8::splat(0xff);
    let ch = [
        c.and(byte),
        c.shr::<8>().and(byte),
        c.shr::<16>().and(byte),
        c.shr::<24>(),
    ];
    for (a, x) in acc.iter_mut().zip(ch) {
        *a = *a + x.to_f32() * w;
    }
}

/// An `F8`'s bits as an `I8`'s.
#[inline(always)]
pub(super) fn as_i8(x: F8) -> I8 {
    I8::from_array(x.to_array().map(|f| f.to_bits() as i32))
}

/// Lanes of `m` set, counted.
#[inline(always)]
pub(super) fn count(m: M8) -> u64 {
    u64::from(m.bits().count_ones())
}

/// The value of the lanes of `x` in `m` (not empty) when they all have the same.
#[inline(always)]
pub(super) fn uniform(m: M8, x: I8) -> Option<u32> {
    let bits = m.bits();
    let v = x.to_array()[bits.trailing_zeros() as usize];
    ((x.eq(I8::splat(v)).bits() | !bits) & ALL == ALL).then_some(v as u32)
}

/// The row and first sample of an eight-sample window of a row (its first sample a
/// multiple of `align`, a power of two up to 8) holding the samples `lo[l]..=hi[l]` of row
/// `t[l]` of every lane `l` in `care` (not empty); `None` when there is none. The window
/// is guessed from the first and last lanes in `care` (the rays along a row of pixels meet
/// samples in order, one way or the other) and checked.
#[inline(always)]
pub(super) fn window(care: M8, t: I8, lo: I8, hi: I8, align: u32) -> Option<(u32, u32)> {
    let bits = care.bits();
    let (first, last) = (bits.trailing_zeros(), 31 - bits.leading_zeros());
    let (row, lo_at) = (t.to_array(), lo.to_array());
    let row = row[first as usize];
    let start = lo_at[first as usize].min(lo_at[last as usize]) & !(align as i32 - 1);
    let end = start + LANES as i32 - 1;
    let inside = t
        .eq(I8::splat(row))
        .and(lo.max(I8::splat(start)).eq(lo))
        .and(hi.min(I8::splat(end)).eq(hi));
    ((inside.bits() | !bits) & ALL == ALL).then_some((row as u32, start as u32))
}

/// Where each lane's sample `s` sits in a row window starting at `start` (lanes outside
/// it get some place).
#[inline(always)]
pub(super) fn offsets(s: I8, start: u32) -> [u32; LANES] {
    (s + I8::splat(-(start as i32)))
        .to_array()
        .map(|o| o as u32)
}
