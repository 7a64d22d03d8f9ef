//! Text with the font8x8 glyphs at an integer scale (plotters draws no text in this build).

use font8x8::UnicodeFonts;
use image::{Rgb, RgbImage};

/// Width in pixels of `text` drawn at `scale`.
pub(super) fn text_width(text: &str, scale: u32) -> u32 {
    text.chars().count() as u32 * 8 * scale
}

/// The largest scale up to `want` (at least 1) at which `text` fits in `room` pixels.
pub(super) fn fit_scale(text: &str, want: u32, room: u32) -> u32 {
    (1..=want.max(1))
        .rev()
        .find(|&sc| text_width(text, sc) <= room)
        .unwrap_or(1)
}

/// The 8×8 glyph for `ch`: ASCII, Latin-1 (µ, ×, °) or Greek, else `?`.
pub(super) fn glyph(ch: char) -> [u8; 8] {
    font8x8::BASIC_FONTS
        .get(ch)
        .or_else(|| font8x8::LATIN_FONTS.get(ch))
        .or_else(|| font8x8::GREEK_FONTS.get(ch))
        .or_else(|| font8x8::BASIC_FONTS.get('?'))
        .unwrap_or([0; 8])
}

/// Draws `text` with font8x8 glyphs scaled by `scale`, clipped to the image. Horizontal text
/// has its top-left corner at (x, y); `up` text is turned a quarter turn anticlockwise (it
/// reads bottom to top) with its bottom-left corner at (x, y).
pub(super) fn draw_str(
    img: &mut RgbImage,
    x: i32,
    y: i32,
    text: &str,
    scale: u32,
    color: Rgb<u8>,
    up: bool,
) {
    let sc = scale as i32;
    let (w, h) = (img.width() as i32, img.height() as i32);
    for (i, ch) in text.chars().enumerate() {
        for (row, bits) in glyph(ch).iter().enumerate() {
            for col in 0..8 {
                if bits & (1 << col) == 0 {
                    continue;
                }
                for (dx, dy) in (0..sc).flat_map(|a| (0..sc).map(move |b| (a, b))) {
                    // (gx, gy): the pixel in unrotated text coordinates.
                    let gx = (i as i32 * 8 + col) * sc + dx;
                    let gy = row as i32 * sc + dy;
                    let (px, py) = if up {
                        (x + gy, y - 1 - gx)
                    } else {
                        (x + gx, y + gy)
                    };
                    if px >= 0 && py >= 0 && px < w && py < h {
                        img.put_pixel(px as u32, py as u32, color);
                    }
                }
            }
        }
    }
}
