//! A tiny built-in 3 x 5 bitmap font for text drawn straight into a `0x00RRGGBB`
//! framebuffer (the showcase's frame-time readout), so no font files are needed.
//!
//! Lower-case letters draw as upper case; characters without a glyph draw as blanks.

/// Glyph width and height in font pixels (plus one pixel of spacing between glyphs).
pub const GLYPH_W: usize = 3;
pub const GLYPH_H: usize = 5;

/// Rows top to bottom, 3 bits each (bit 2 = left column).
fn glyph(c: char) -> [u8; 5] {
    match c.to_ascii_uppercase() {
        '0' => [7, 5, 5, 5, 7],
        '1' => [2, 6, 2, 2, 7],
        '2' => [7, 1, 7, 4, 7],
        '3' => [7, 1, 7, 1, 7],
        '4' => [5, 5, 7, 1, 1],
        '5' => [7, 4, 7, 1, 7],
        '6' => [7, 4, 7, 5, 7],
        '7' => [7, 1, 1, 1, 1],
        '8' => [7, 5, 7, 5, 7],
        '9' => [7, 5, 7, 1, 7],
        'A' => [2, 5, 7, 5, 5],
        'B' => [6, 5, 6, 5, 6],
        'C' => [3, 4, 4, 4, 3],
        'D' => [6, 5, 5, 5, 6],
        'E' => [7, 4, 6, 4, 7],
        'F' => [7, 4, 6, 4, 4],
        'G' => [3, 4, 5, 5, 3],
        'H' => [5, 5, 7, 5, 5],
        'I' => [7, 2, 2, 2, 7],
        'J' => [1, 1, 1, 5, 2],
        'K' => [5, 5, 6, 5, 5],
        'L' => [4, 4, 4, 4, 7],
        'M' => [5, 7, 7, 5, 5],
        'N' => [6, 5, 5, 5, 5],
        'O' => [2, 5, 5, 5, 2],
        'P' => [6, 5, 6, 4, 4],
        'Q' => [2, 5, 5, 6, 3],
        'R' => [6, 5, 6, 5, 5],
        'S' => [3, 4, 2, 1, 6],
        'T' => [7, 2, 2, 2, 2],
        'U' => [5, 5, 5, 5, 7],
        'V' => [5, 5, 5, 5, 2],
        'W' => [5, 5, 7, 7, 5],
        'X' => [5, 5, 2, 5, 5],
        'Y' => [5, 5, 2, 2, 2],
        'Z' => [7, 1, 2, 4, 7],
        '.' => [0, 0, 0, 0, 2],
        ',' => [0, 0, 0, 2, 4],
        ':' => [0, 2, 0, 2, 0],
        '/' => [1, 1, 2, 4, 4],
        '-' => [0, 0, 7, 0, 0],
        '+' => [0, 2, 7, 2, 0],
        '=' => [0, 7, 0, 7, 0],
        '%' => [5, 1, 2, 4, 5],
        '(' => [1, 2, 2, 2, 1],
        ')' => [4, 2, 2, 2, 4],
        '|' => [2, 2, 2, 2, 2],
        _ => [0; 5],
    }
}

/// Width in framebuffer pixels of `text` drawn at `scale`.
pub fn text_width(text: &str, scale: usize) -> usize {
    let n = text.chars().count();
    (n * (GLYPH_W + 1)).saturating_sub(1) * scale
}

/// Draws `text` with its top-left corner at `(x, y)`, each font pixel `scale` x `scale`,
/// over a darkened backing box for legibility. Clipped to the buffer.
pub fn draw_text(
    buf: &mut [u32],
    width: usize,
    height: usize,
    x: usize,
    y: usize,
    scale: usize,
    text: &str,
    color: u32,
) {
    let scale = scale.max(1);
    if buf.len() < width * height {
        return;
    }
    // Backing box: halve the colour behind the text.
    let (bw, bh) = (text_width(text, scale) + 2 * scale, (GLYPH_H + 2) * scale);
    let (bx, by) = (x.saturating_sub(scale), y.saturating_sub(scale));
    for py in by..(by + bh).min(height) {
        for px in bx..(bx + bw).min(width) {
            let p = &mut buf[py * width + px];
            *p = (*p >> 1) & 0x007f_7f7f;
        }
    }
    for (k, c) in text.chars().enumerate() {
        let gx = x + k * (GLYPH_W + 1) * scale;
        for (row, bits) in glyph(c).iter().enumerate() {
            for col in 0..GLYPH_W {
                if bits & (4 >> col) == 0 {
                    continue;
                }
                for dy in 0..scale {
                    for dx in 0..scale {
                        let (px, py) = (gx + col * scale + dx, y + row * scale + dy);
                        if px < width && py < height {
                            buf[py * width + px] = color;
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_glyph_pixels_and_clips() {
        let (w, h) = (16, 8);
        let mut buf = vec![0x00ff_ffff; w * h];
        draw_text(&mut buf, w, h, 1, 1, 1, "1", 0x00ff_0000);
        // '1' top row is 010: only the middle column is set.
        assert_eq!(buf[w + 1], 0x007f_7f7f);
        assert_eq!(buf[w + 2], 0x00ff_0000);
        assert_eq!(buf[w + 3], 0x007f_7f7f);
        // Far outside: untouched, no panic.
        draw_text(&mut buf, w, h, 100, 100, 3, "MS 12.5", 0);
        assert_eq!(buf[w * h - 1], 0x00ff_ffff);
        assert_eq!(text_width("AB", 2), 14);
    }
}
