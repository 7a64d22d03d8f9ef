//! What a progressive JPEG's segment headers say, read before it is decoded: its frame (the
//! coefficients it holds) and its scans (each one walks every block of its components).

/// A progressive JPEG's first start-of-frame segment and the scans that follow it.
#[derive(Debug, PartialEq)]
pub(crate) struct JpegFrame {
    pub width: u32,
    pub height: u32,
    pub components: u8,
    /// Start-of-scan segments after the frame.
    pub scans: u32,
}

impl JpegFrame {
    /// The decoder's work for its scans: component samples times scans (each scan is taken
    /// to cover every component, as a DC scan does).
    pub fn scan_work(&self) -> u64 {
        let samples = u64::from(self.width) * u64::from(self.height) * u64::from(self.components);
        samples.saturating_mul(u64::from(self.scans))
    }
}

/// The frame of progressive JPEG `bytes` (SOF2, SOF6, SOF10, SOF14) with the scans after it;
/// `None` for any other JPEG. Reads the segment headers only, within the bytes, skipping what
/// the decoder skips between segments (stray bytes, `FF 00`, fill, restart markers), so
/// entropy-coded data hides no marker from it.
pub(crate) fn progressive_jpeg_frame(bytes: &[u8]) -> Option<JpegFrame> {
    let mut frame: Option<JpegFrame> = None;
    let mut at = 2; // past SOI
    while at + 2 <= bytes.len() {
        if bytes[at] != 0xFF {
            at += 1;
            continue;
        }
        let marker = bytes[at + 1];
        match marker {
            // Fill bytes before a marker, and a stuffed zero.
            0xFF => at += 1,
            0x00 => at += 2,
            // End of image.
            0xD9 => break,
            // Markers without a length.
            0x01 | 0xD0..=0xD8 => at += 2,
            _ => {
                let Some(length) = bytes.get(at + 2..at + 4) else {
                    break;
                };
                let length = usize::from(u16::from_be_bytes([length[0], length[1]]));
                match (marker, &mut frame) {
                    (0xC2 | 0xC6 | 0xCA | 0xCE, None) => {
                        // Length (2), precision (1), height (2), width (2), components (1).
                        let header = bytes.get(at + 5..at + 10)?;
                        frame = Some(JpegFrame {
                            height: u16::from_be_bytes([header[0], header[1]]).into(),
                            width: u16::from_be_bytes([header[2], header[3]]).into(),
                            components: header[4],
                            scans: 0,
                        });
                    }
                    (0xC0 | 0xC1 | 0xC3 | 0xC5 | 0xC7 | 0xC9 | 0xCB | 0xCD | 0xCF, None) => {
                        return None
                    }
                    (0xDA, Some(f)) => f.scans = f.scans.saturating_add(1),
                    _ => {}
                }
                at += 2 + length;
            }
        }
    }
    frame
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A progressive frame of `w × h` with one component, then `scans` scans of `data` each.
    fn progressive(w: u16, h: u16, scans: usize, data: &[u8]) -> Vec<u8> {
        let mut b = vec![0xFF, 0xD8, 0xFF, 0xC2, 0, 11, 8];
        b.extend(h.to_be_bytes());
        b.extend(w.to_be_bytes());
        b.extend([1, 1, 0x11, 0]);
        for _ in 0..scans {
            b.extend([0xFF, 0xDA, 0, 8, 1, 1, 0, 0, 63, 0]);
            b.extend(data);
        }
        b.extend([0xFF, 0xD9]);
        b
    }

    #[test]
    fn every_scan_after_the_frame_is_counted_through_its_entropy_data() {
        // Plain bytes, stuffed zeros, restart markers and fill inside a scan's data.
        let data = [0x12, 0xFF, 0x00, 0x34, 0xFF, 0xD3, 0xFF, 0xFF, 0x00, 0x56];
        for scans in [0, 1, 10, 100] {
            let f = progressive_jpeg_frame(&progressive(64, 32, scans, &data)).unwrap();
            assert_eq!((f.width, f.height, f.components), (64, 32, 1));
            assert_eq!(f.scans, scans as u32);
            assert_eq!(f.scan_work(), 64 * 32 * scans as u64);
        }
        // A baseline frame is not read further.
        let mut baseline = progressive(64, 32, 3, &data);
        baseline[3] = 0xC0;
        assert_eq!(progressive_jpeg_frame(&baseline), None);
        // A file cut inside a segment's length ends the count there.
        let whole = progressive(64, 32, 2, &data);
        let cut = &whole[..whole.len() - data.len() - 2 - 10 + 3];
        assert_eq!(progressive_jpeg_frame(cut).unwrap().scans, 1);
    }
}
