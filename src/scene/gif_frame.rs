//! A GIF's first frame as its image descriptor states it, read before it is decoded: the
//! frame may be larger than the logical screen `image` reports, and the decoder holds the
//! whole frame (five bytes a pixel) before it clips it to the screen.

/// The first image descriptor's rectangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct GifFrame {
    pub left: u32,
    pub top: u32,
    pub width: u32,
    pub height: u32,
}

impl GifFrame {
    /// Bytes the decoder allocates for this frame apart from the screen's image: none where
    /// the frame spans the screen's width from its left edge and ends within its height (it
    /// is decoded in place), else the frame's RGBA (image 0.25's `GifDecoder::read_image`)
    /// and its palette indices, a byte a pixel (gif 0.14's `read_into_buffer`).
    pub fn extra_bytes(&self, screen: (u32, u32)) -> u64 {
        let in_place = self.left == 0
            && self.width == screen.0
            && u64::from(self.top) + u64::from(self.height) <= u64::from(screen.1);
        if in_place {
            0
        } else {
            u64::from(self.width) * u64::from(self.height) * 5
        }
    }
}

/// The first frame of GIF `bytes`, or `None` where the bytes end or break off before one.
/// Walks the blocks only (the colour tables and each extension's sub-blocks are skipped by
/// their lengths), within the bytes.
pub(crate) fn first_gif_frame(bytes: &[u8]) -> Option<GifFrame> {
    let u16_at = |at: usize| -> Option<u32> {
        let b = bytes.get(at..at + 2)?;
        Some(u32::from(u16::from_le_bytes([b[0], b[1]])))
    };
    if !bytes.starts_with(b"GIF") {
        return None;
    }
    // Signature and version (6), then the logical screen descriptor (7).
    let packed = *bytes.get(10)?;
    let mut at = 13 + colour_table_bytes(packed);
    loop {
        match *bytes.get(at)? {
            0x2C => {
                return Some(GifFrame {
                    left: u16_at(at + 1)?,
                    top: u16_at(at + 3)?,
                    width: u16_at(at + 5)?,
                    height: u16_at(at + 7)?,
                })
            }
            // An extension: its label, then sub-blocks up to one of length 0.
            0x21 => {
                at += 2;
                loop {
                    let length = usize::from(*bytes.get(at)?);
                    at += 1 + length;
                    if length == 0 {
                        break;
                    }
                }
            }
            // The trailer, or what the decoder refuses.
            _ => return None,
        }
    }
}

/// Bytes of the colour table a descriptor's packed field announces (bit 7, size in bits 0-2).
fn colour_table_bytes(packed: u8) -> usize {
    if packed & 0x80 == 0 {
        0
    } else {
        3 << ((packed & 7) + 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A GIF of a `screen` logical screen with a global palette of two colours, a graphic
    /// control extension, and one frame at `rect` of no data.
    fn gif(screen: (u16, u16), rect: [u16; 4]) -> Vec<u8> {
        let mut b = b"GIF89a".to_vec();
        b.extend(screen.0.to_le_bytes());
        b.extend(screen.1.to_le_bytes());
        b.extend([0x80, 0, 0, 0, 0, 0, 0xFF, 0xFF, 0xFF]);
        b.extend([0x21, 0xF9, 4, 0, 0, 0, 0, 0]);
        b.push(0x2C);
        for v in rect {
            b.extend(v.to_le_bytes());
        }
        b.extend([0, 2, 0, 0x3B]);
        b
    }

    #[test]
    fn the_first_frame_is_read_past_palettes_and_extensions() {
        let frame = first_gif_frame(&gif((1, 1), [3, 4, 11_000, 11_000])).unwrap();
        assert_eq!(
            frame,
            GifFrame {
                left: 3,
                top: 4,
                width: 11_000,
                height: 11_000
            }
        );
        assert_eq!(frame.extra_bytes((1, 1)), 11_000 * 11_000 * 5);
        // A frame across the screen from its left edge is decoded in place.
        let rows = first_gif_frame(&gif((64, 32), [0, 8, 64, 24])).unwrap();
        assert_eq!(rows.extra_bytes((64, 32)), 0);
        assert_eq!(rows.extra_bytes((64, 31)), 64 * 24 * 5);
        // Cut anywhere before the frame's size, or not a GIF: none.
        let whole = gif((1, 1), [0, 0, 5, 5]);
        for end in 0..whole.len() - 4 {
            assert_eq!(first_gif_frame(&whole[..end]), None, "cut at {end}");
        }
        assert_eq!(first_gif_frame(b"\x89PNG\r\n\x1a\n"), None);
    }
}
