//! The integer types semi-global matching computes in: path costs ([`Lane`]) and a pass's
//! stored sums of four paths ([`Stored`]), each a byte while the penalties allow (twice the
//! lanes a vector, half the memory) and 16 bits beyond, with the same results.

/// How a pass stores its sums of four paths: `u8` while four times the largest census cost
/// plus P2 fits one, else `u16`.
pub(super) trait Stored: Copy + Default + Send + Sync {
    fn store(v: u16) -> Self;
    fn load(self) -> u16;
}

/// A path cost: `u8` while census costs plus P2 fit one (32 lanes to an AVX2 vector),
/// else `u16`. A path's cost at a pixel is at most its matching cost plus P2, and its
/// largest value, `NONE`, marks the padding beyond the disparity range.
pub(super) trait Lane: Copy + Ord + Default + Send + Sync + std::fmt::Debug {
    const NONE: Self;
    fn cost(c: u8) -> Self;
    /// A penalty, within range (the callers make sure it is).
    fn penalty(p: u16) -> Self;
    fn saturating_add(self, o: Self) -> Self;
    fn add(self, o: Self) -> Self;
    fn sub(self, o: Self) -> Self;
    fn wide(self) -> u16;
}

/// The lane types: the same operations on bytes and on 16 bits.
macro_rules! lane {
    ($t:ty) => {
        impl Lane for $t {
            const NONE: Self = <$t>::MAX;
            #[inline(always)]
            fn cost(c: u8) -> Self {
                <$t>::from(c)
            }
            #[inline(always)]
            fn penalty(p: u16) -> Self {
                <$t>::try_from(p).unwrap_or(<$t>::MAX)
            }
            #[inline(always)]
            fn saturating_add(self, o: Self) -> Self {
                <$t>::saturating_add(self, o)
            }
            #[inline(always)]
            fn add(self, o: Self) -> Self {
                self + o
            }
            #[inline(always)]
            fn sub(self, o: Self) -> Self {
                self - o
            }
            #[inline(always)]
            fn wide(self) -> u16 {
                u16::from(self)
            }
        }

        impl Stored for $t {
            /// (Sums of four fit by the choice of type; the most a lane holds otherwise.)
            #[inline(always)]
            fn store(v: u16) -> Self {
                <$t>::try_from(v).unwrap_or(<$t>::MAX)
            }
            #[inline(always)]
            fn load(self) -> u16 {
                u16::from(self)
            }
        }
    };
}

lane!(u8);
lane!(u16);
