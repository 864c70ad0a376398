//! The raster's last step: a shaded row's lanes written into the tile as its pixel mode
//! says (alpha test or dither for cutouts, blending with the soft fade and the blended
//! draw's depth threshold, the depth write).

use super::{DepthToView, Lane, PixelMode, TileBuf, LANES};
use crate::material::{AlphaMode, BlendMode};
use crate::simd::{F8, M8};
use std::ops::{Mul, Sub};

/// Thresholds of the 4 x 4 Bayer matrix, `(rank + 0.5) / 16`, one row of 8 lanes per pixel
/// row mod 4 (the pattern repeated twice across the lanes).
const DITHER: [[f32; LANES]; 4] = {
    const RANK: [[u8; 4]; 4] = [[0, 8, 2, 10], [12, 4, 14, 6], [3, 11, 1, 9], [15, 7, 13, 5]];
    let mut t = [[0.0; LANES]; 4];
    let mut y = 0;
    while y < 4 {
        let mut x = 0;
        while x < LANES {
            t[y][x] = (RANK[y][x % 4] as f32 + 0.5) / 16.0;
            x += 1;
        }
        y += 1;
    }
    t
};

/// Writes the lanes of `m` that survive the alpha test; returns them.
#[inline(always)]
pub(super) fn write_row(
    buf: &mut TileBuf,
    base: usize,
    mut m: M8,
    z: &Lane,
    out: &[Lane; 4],
    mode: &PixelMode,
    soft: &DepthToView,
) -> M8 {
    let [r, g, b, a] = &mut buf.color;
    let (r, g, b, a) = (
        &mut r[base..],
        &mut g[base..],
        &mut b[base..],
        &mut a[base..],
    );
    match mode.alpha {
        AlphaMode::Opaque | AlphaMode::Mask { .. } | AlphaMode::Dither => {
            if let AlphaMode::Mask { cutoff } = mode.alpha {
                m = m.and(out[3].ge(F8::splat(cutoff)));
            }
            if mode.alpha == AlphaMode::Dither {
                // Tiles and blocks start on multiples of 8, so the pixel's y mod 4 is the
                // row in the block mod 4 and x mod 4 is the lane mod 4.
                m = m.and(out[3].gt(F8::from_array(DITHER[(base / LANES) % 4])));
            }
            out[0].blend_into(m, r);
            out[1].blend_into(m, g);
            out[2].blend_into(m, b);
            F8::splat(1.0).blend_into(m, a);
        }
        AlphaMode::Blend => {
            let mut alpha = out[3].max(F8::splat(0.0)).min(F8::splat(1.0));
            if mode.soft > 0.0 {
                let zb = F8::load(&buf.depth[base..]).to_array();
                let (zs, bits) = (z.to_array(), m.bits());
                let mut fade = [1.0f32; LANES];
                for l in 0..LANES {
                    if bits >> l & 1 != 0 {
                        let gap = soft.view(zb[l]) - soft.view(zs[l]);
                        fade[l] = (gap / mode.soft).clamp(0.0, 1.0);
                    }
                }
                alpha = alpha.mul(F8::from_array(fade));
            }
            let keep = match mode.blend {
                BlendMode::Alpha => 1.0,
                BlendMode::Additive => 0.0,
            };
            let inv = F8::splat(1.0).sub(alpha.mul(F8::splat(keep)));
            let ia = F8::splat(1.0).sub(alpha);
            for (dst, src) in [(&mut *r, out[0]), (&mut *g, out[1]), (&mut *b, out[2])] {
                let d = F8::load(dst);
                src.mul_add(alpha, d.mul(inv)).blend_into(m, dst);
            }
            let d = F8::load(a);
            d.mul_add(ia, alpha).blend_into(m, a);
            if mode.blend_depth <= 1.0 {
                let solid = m.and(alpha.ge(F8::splat(mode.blend_depth)));
                z.blend_into(solid, &mut buf.depth[base..]);
            }
        }
    }
    if mode.depth_write {
        z.blend_into(m, &mut buf.depth[base..]);
    }
    m
}
