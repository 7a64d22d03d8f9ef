//! Contact sheets: thumbnails in a grid, each labelled underneath with an 8×8 bitmap font, so
//! a person can look at a whole capability matrix at once.

use font8x8::UnicodeFonts;
use image::{Rgba, RgbaImage};

/// Pixels between and around thumbnails.
const MARGIN: u32 = 6;
/// Height of one label line.
const LINE: u32 = 10;

/// Draws `text` at (x, y) in `color`, clipped to the image; unknown characters print as `?`.
pub fn draw_text(img: &mut RgbaImage, x: u32, y: u32, text: &str, color: Rgba<u8>) {
    for (i, ch) in text.chars().enumerate() {
        let glyph = font8x8::BASIC_FONTS
            .get(ch)
            .or_else(|| font8x8::BASIC_FONTS.get('?'))
            .unwrap_or([0; 8]);
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8u32 {
                if bits & (1 << col) != 0 {
                    let (px, py) = (x + i as u32 * 8 + col, y + row as u32);
                    if px < img.width() && py < img.height() {
                        img.put_pixel(px, py, color);
                    }
                }
            }
        }
    }
}

/// Lays out `cells` (label lines, thumbnail) in rows of `columns`. Thumbnails may differ in
/// size; each cell is as large as the largest. Missing thumbnails (`None`) leave a dark box.
pub fn contact_sheet(cells: &[(Vec<String>, Option<RgbaImage>)], columns: usize) -> RgbaImage {
    let columns = columns.max(1);
    let thumb_w = cells
        .iter()
        .filter_map(|(_, t)| t.as_ref())
        .map(|t| t.width())
        .max()
        .unwrap_or(64);
    let thumb_h = cells
        .iter()
        .filter_map(|(_, t)| t.as_ref())
        .map(|t| t.height())
        .max()
        .unwrap_or(36);
    let lines = cells.iter().map(|(l, _)| l.len()).max().unwrap_or(0) as u32;
    let label_chars = cells
        .iter()
        .flat_map(|(l, _)| l.iter())
        .map(|s| s.chars().count())
        .max()
        .unwrap_or(0) as u32;
    let cell_w = thumb_w.max(label_chars * 8) + MARGIN;
    let cell_h = thumb_h + lines * LINE + MARGIN;
    let rows = cells.len().div_ceil(columns) as u32;
    let mut sheet = RgbaImage::from_pixel(
        columns as u32 * cell_w + MARGIN,
        rows * cell_h + MARGIN,
        Rgba([24, 24, 28, 255]),
    );
    for (i, (labels, thumb)) in cells.iter().enumerate() {
        let x0 = MARGIN + (i % columns) as u32 * cell_w;
        let y0 = MARGIN + (i / columns) as u32 * cell_h;
        match thumb {
            Some(t) => image::imageops::overlay(&mut sheet, t, x0 as i64, y0 as i64),
            None => {
                for y in y0..y0 + thumb_h {
                    for x in x0..x0 + thumb_w {
                        sheet.put_pixel(x, y, Rgba([60, 20, 20, 255]));
                    }
                }
            }
        }
        for (l, text) in labels.iter().enumerate() {
            draw_text(
                &mut sheet,
                x0,
                y0 + thumb_h + 1 + l as u32 * LINE,
                text,
                Rgba([230, 230, 230, 255]),
            );
        }
    }
    sheet
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sheet_places_thumbnails_and_labels() {
        let red = RgbaImage::from_pixel(20, 10, Rgba([255, 0, 0, 255]));
        let cells = vec![
            (vec!["A".to_string()], Some(red.clone())),
            (vec!["B".to_string(), "second".to_string()], None),
            (vec!["C".to_string()], Some(red)),
        ];
        let sheet = contact_sheet(&cells, 2);
        // The widest label ("second", 6 characters) is wider than the 20-pixel thumbnail.
        let cell_w = 6 * 8 + MARGIN;
        assert_eq!(sheet.width(), 2 * cell_w + MARGIN);
        assert_eq!(sheet.height(), 2 * (10 + 2 * LINE + MARGIN) + MARGIN);
        assert_eq!(sheet.get_pixel(MARGIN, MARGIN), &Rgba([255, 0, 0, 255]));
        // Some label pixels are lit under the first thumbnail.
        let lit = (0..8)
            .flat_map(|dy| (0..8).map(move |dx| (dx, dy)))
            .any(|(dx, dy)| sheet.get_pixel(MARGIN + dx, MARGIN + 11 + dy)[0] > 200);
        assert!(lit, "label not drawn");
    }
}
