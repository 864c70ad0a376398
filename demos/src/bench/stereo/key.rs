//! The colour key under a colour-mapped disparity map (`ibr::stereo::Disparity::to_colour`):
//! a strip below the map holding a bar of the ramp from disparity 0 (left) to the range's
//! top (right), tick marks, and their values in pixels of disparity in the built-in font.

use crate::font::{draw_text, text_width, GLYPH_H};
use ibr::stereo::depth::ramp;

/// The strip's height, in font pixels of `scale` (a 6-pixel bar, ticks, a line of text).
const STRIP: usize = 18;

/// The font scale for a map `w` pixels wide.
fn scale(w: u32) -> usize {
    if w >= 480 {
        2
    } else {
        1
    }
}

/// The bar's first column and width in a map `w` pixels wide: a margin each side.
pub fn bar(w: u32) -> (usize, usize) {
    let m = 4 * scale(w);
    (m, (w as usize).saturating_sub(2 * m))
}

/// The strip's rows that hold the bar: `[from, to)` below the map's `h` rows.
pub fn bar_rows(w: u32, h: u32) -> (usize, usize) {
    let s = scale(w);
    (h as usize + 2 * s, h as usize + 8 * s)
}

/// `rgba` (the map's `w` x `h` RGBA8 pixels, colour-mapped over `0..max`) with the key
/// below it, and the new height.
pub fn with_key(rgba: Vec<u8>, w: u32, h: u32, max: f32) -> (Vec<u8>, u32) {
    let s = scale(w);
    let (wu, rows) = (w as usize, STRIP * s);
    let height = h as usize + rows;
    let mut strip = vec![0u32; wu * rows];
    let (x0, bw) = bar(w);
    let (b0, b1) = (2 * s, 8 * s);
    for x in 0..bw {
        let [r, g, b] = ramp(x as f32 / (bw.max(2) - 1) as f32);
        let c = u32::from(r) << 16 | u32::from(g) << 8 | u32::from(b);
        for y in b0..b1 {
            strip[y * wu + x0 + x] = c;
        }
    }
    // Ticks: steps of 1, 2 or 5 times a power of ten, as many as the labels' room allows
    // (at most six).
    let label_w = text_width(&format!("{}", max.ceil() as u32), s) + 4 * s;
    let room = (bw / label_w.max(1)).clamp(1, 6) as f32;
    let mut step = 1.0f32;
    'find: for p in 0..7 {
        for m in [1.0, 2.0, 5.0] {
            step = m * 10f32.powi(p);
            if max / step + 1.0 <= room {
                break 'find;
            }
        }
    }
    let mut v = 0.0f32;
    while bw > 1 && v <= max + 1e-3 {
        let x = x0 + ((v / max.max(f32::MIN_POSITIVE)) * (bw - 1) as f32).round() as usize;
        for y in b1..b1 + 2 * s {
            for dx in 0..s {
                if let Some(p) = strip.get_mut(y * wu + x + dx) {
                    *p = 0x00ff_ffff;
                }
            }
        }
        let text = format!("{}", v.round() as u32);
        let tw = text_width(&text, s);
        let tx = x.saturating_sub(tw / 2).min(wu.saturating_sub(tw));
        let ty = b1 + 3 * s;
        if ty + GLYPH_H * s <= rows {
            draw_text(&mut strip, wu, rows, tx, ty, s, &text, 0x00ff_ffff);
        }
        v += step;
    }
    let mut out = rgba;
    out.reserve(wu * rows * 4);
    for p in strip {
        out.extend_from_slice(&[(p >> 16) as u8, (p >> 8) as u8, p as u8, 255]);
    }
    debug_assert_eq!(out.len(), wu * height * 4);
    (out, height as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bar runs from the ramp's colour at 0 (blue) to its colour at the top (red),
    /// red never falling and blue never rising along it; the map above is untouched, and
    /// tick values are drawn below the bar.
    #[test]
    fn the_bar_follows_the_colour_map_and_carries_values() {
        let (w, h) = (120u32, 10u32);
        let map: Vec<u8> = (0..w * h).flat_map(|i| [i as u8, 1, 2, 255]).collect();
        let (out, height) = with_key(map.clone(), w, h, 40.0);
        assert_eq!(height as usize, h as usize + STRIP);
        assert_eq!(out.len(), (w * height * 4) as usize);
        assert_eq!(&out[..map.len()], &map[..]);
        let px = |x: usize, y: usize| {
            let i = (y * w as usize + x) * 4;
            [out[i], out[i + 1], out[i + 2]]
        };
        let (x0, bw) = bar(w);
        let (r0, r1) = bar_rows(w, h);
        let y = (r0 + r1) / 2;
        let row: Vec<[u8; 3]> = (x0..x0 + bw).map(|x| px(x, y)).collect();
        assert_eq!(row[0], ramp(0.0));
        assert_eq!(row[bw - 1], ramp(1.0));
        assert!(
            row[0][2] == 255 && row[0][0] == 0,
            "blue at 0: {:?}",
            row[0]
        );
        assert!(
            row[bw - 1][0] == 255 && row[bw - 1][2] == 0,
            "red at the top"
        );
        for pair in row.windows(2) {
            assert!(
                pair[1][0] >= pair[0][0] && pair[1][2] <= pair[0][2],
                "{pair:?}"
            );
        }
        // Outside the bar's columns the bar rows are black.
        assert_eq!(px(0, y), [0, 0, 0]);
        // White text below the bar: tick labels.
        let text = (r1 + 3..height as usize)
            .flat_map(|y| (0..w as usize).map(move |x| (x, y)))
            .filter(|&(x, y)| px(x, y) == [255, 255, 255])
            .count();
        assert!(text > 20, "{text} white pixels of labels");
    }
}
