//! The raster stage's block masks, checked against their definition.

use super::*;

proptest::proptest! {
    /// Moving a mask into a block's frame keeps exactly the pixels inside the block, at
    /// their block coordinates.
    #[test]
    fn block_masks_move_pixels_into_the_block(
        cover in proptest::num::u64::ANY,
        sx in -(SMALL - 1)..SMALL,
        sy in -(SMALL - 1)..SMALL,
    ) {
        let got = block_mask(cover, sx, sy);
        for j in 0..SMALL {
            for i in 0..SMALL {
                // Block pixel (i, j) is mask pixel (i - sx, j - sy).
                let (u, v) = (i - sx, j - sy);
                let want = (0..SMALL).contains(&u)
                    && (0..SMALL).contains(&v)
                    && cover >> (SMALL * v + u) & 1 != 0;
                let bit = got >> (SMALL * j + i) & 1 != 0;
                proptest::prop_assert_eq!(bit, want, "block pixel ({}, {})", i, j);
            }
        }
    }
}
