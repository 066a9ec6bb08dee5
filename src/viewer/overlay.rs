//! Text drawn into the RGBA framebuffer with the 8×8 public-domain bitmap
//! font of `font8x8`, scaled 2× so it reads at 720p, on a translucent band.

use font8x8::UnicodeFonts;

pub const SCALE: usize = 2;
pub const LINE_H: usize = 8 * SCALE + 4;

/// Darkens a rectangle (for legibility) — `alpha` of the old colour is kept.
pub fn shade(buf: &mut [u8], width: usize, height: usize, x0: usize, y0: usize, w: usize, h: usize) {
    for y in y0..(y0 + h).min(height) {
        for x in x0..(x0 + w).min(width) {
            let i = (y * width + x) * 4;
            for c in &mut buf[i..i + 3] {
                *c = (*c as u16 * 2 / 5) as u8;
            }
        }
    }
}

/// Draws `text` with its top-left at (x, y); returns the width drawn.
pub fn draw_text(buf: &mut [u8], width: usize, height: usize, x: usize, y: usize, text: &str, rgb: [u8; 3]) -> usize {
    let mut cx = x;
    for ch in text.chars() {
        let glyph = font8x8::BASIC_FONTS
            .get(ch)
            .or_else(|| font8x8::LATIN_FONTS.get(ch))
            .or_else(|| font8x8::GREEK_FONTS.get(ch))
            .unwrap_or([0; 8]);
        for (gy, bits) in glyph.iter().enumerate() {
            for gx in 0..8 {
                if bits & (1 << gx) == 0 {
                    continue;
                }
                for sy in 0..SCALE {
                    for sx in 0..SCALE {
                        let (px, py) = (cx + gx * SCALE + sx, y + gy * SCALE + sy);
                        if px < width && py < height {
                            let i = (py * width + px) * 4;
                            buf[i..i + 3].copy_from_slice(&rgb);
                        }
                    }
                }
            }
        }
        cx += 8 * SCALE;
    }
    cx - x
}

/// Draws lines of text in a shaded box at the top-left corner of the
/// picture, which starts at column `x0` (right of the panel).
pub fn draw_lines(buf: &mut [u8], width: usize, height: usize, x0: usize, lines: &[String]) {
    let w = lines.iter().map(|l| l.chars().count()).max().unwrap_or(0) * 8 * SCALE + 16;
    shade(buf, width, height, x0, 0, w, lines.len() * LINE_H + 12);
    for (i, l) in lines.iter().enumerate() {
        let colour = if i == 0 { [255, 230, 120] } else { [235, 235, 235] };
        draw_text(buf, width, height, x0 + 8, 8 + i * LINE_H, l, colour);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_lights_pixels_and_stays_inside_the_buffer() {
        let (w, h) = (40, 20);
        let mut buf = vec![0u8; w * h * 4];
        let drawn = draw_text(&mut buf, w, h, 30, 10, "Hello", [255, 255, 255]);
        assert_eq!(drawn, 5 * 8 * SCALE);
        assert!(buf.contains(&255));
        let mut empty = vec![0u8; 0];
        draw_lines(&mut empty, 0, 0, 0, &["x".to_string()]);
    }
}
