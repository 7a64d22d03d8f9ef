//! What a JPEG's segment headers say, read before it is decoded: its frame, and where the
//! decoder holds every coefficient besides the pixels, its scans (each one walks every block
//! of its components).

/// The start-of-frame segment the decoder decodes, and the scans after it.
#[derive(Debug, PartialEq)]
pub(crate) struct JpegFrame {
    pub width: u32,
    pub height: u32,
    pub components: u8,
    /// Start-of-scan segments after the frame; counted on only where the decoder holds the
    /// coefficients ([`JpegFrame::holds_coefficients`]).
    pub scans: u32,
    /// Progressive (SOF2).
    pub progressive: bool,
    /// Components of the first scan, where one was seen.
    pub first_scan: Option<u8>,
}

impl JpegFrame {
    /// Whether the decoder holds all its coefficients before it makes pixels: a progressive
    /// frame, or a sequential one whose first scan holds fewer components than the frame
    /// (zune-jpeg then keeps every component's coefficients). A sequential frame with no
    /// scan was not seen to hold anything.
    pub fn holds_coefficients(&self) -> bool {
        self.progressive || self.first_scan.is_some_and(|n| n < self.components)
    }

    /// The decoder's work for its scans: component samples times scans (each scan is taken
    /// to cover every component, as a DC scan does).
    pub fn scan_work(&self) -> u64 {
        let samples = u64::from(self.width) * u64::from(self.height) * u64::from(self.components);
        samples.saturating_mul(u64::from(self.scans))
    }

    /// Bytes of the coefficients the decoder holds: two a component and pixel (the blocks'
    /// padding past the edges left out, within 0.6 % from 4 096 pixels a side).
    pub fn coefficient_bytes(&self) -> u64 {
        2 * u64::from(self.components) * u64::from(self.width) * u64::from(self.height)
    }
}

/// One marker segment with a length: its marker, where its `FF` lies, and where it ends
/// (`at + 2 +` its length; past the bytes where they are cut).
pub(crate) struct Segment {
    pub marker: u8,
    pub at: usize,
    pub end: usize,
}

/// A JPEG's marker segments with a length, as zune-jpeg (the `image` crate's JPEG decoder)
/// walks them, so that no segment hides another from one of the two: stray bytes, `FF 00`
/// and fill between segments skipped; before the first scan every marker read as a segment
/// with a length, as the decoder reads it; after it, restart markers skipped, having none.
/// Ends at `EOI` or where a length is cut.
pub(crate) fn segments(bytes: &[u8]) -> impl Iterator<Item = Segment> + '_ {
    let mut at = 2; // past SOI
    let mut scanning = false;
    std::iter::from_fn(move || {
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
                0xD9 => return None,
                // Restart markers, inside a scan's entropy-coded data.
                0xD0..=0xD7 if scanning => at += 2,
                _ => {
                    let length = bytes.get(at + 2..at + 4)?;
                    let length = usize::from(u16::from_be_bytes([length[0], length[1]]));
                    let segment = Segment {
                        marker,
                        at,
                        end: at + 2 + length,
                    };
                    scanning |= marker == 0xDA;
                    at = segment.end;
                    return Some(segment);
                }
            }
        }
        None
    })
}

/// The frame a JPEG's decoder decodes, with its scans where it holds their coefficients;
/// `None` where the bytes hold no frame. Reads the segment headers only ([`segments`]), and
/// knows the frames the decoder knows (SOF0–2; it skips the others as unknown segments).
pub(crate) fn jpeg_frame(bytes: &[u8]) -> Option<JpegFrame> {
    let mut frame: Option<JpegFrame> = None;
    for Segment { marker, at, .. } in segments(bytes) {
        match (marker, &mut frame) {
            (0xC0..=0xC2, None) => {
                // Length (2), precision (1), height (2), width (2), components (1).
                let header = bytes.get(at + 5..at + 10)?;
                frame = Some(JpegFrame {
                    height: u16::from_be_bytes([header[0], header[1]]).into(),
                    width: u16::from_be_bytes([header[2], header[3]]).into(),
                    components: header[4],
                    scans: 0,
                    progressive: marker == 0xC2,
                    first_scan: None,
                });
            }
            (0xDA, Some(f)) => {
                f.scans = f.scans.saturating_add(1);
                let Some(&in_scan) = bytes.get(at + 4) else {
                    break;
                };
                f.first_scan.get_or_insert(in_scan);
                // A frame that makes pixels as its scans come is not read further.
                if !f.holds_coefficients() {
                    break;
                }
            }
            _ => {}
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
            let f = jpeg_frame(&progressive(64, 32, scans, &data)).unwrap();
            assert_eq!((f.width, f.height, f.components), (64, 32, 1));
            assert_eq!(f.scans, scans as u32);
            assert_eq!(f.scan_work(), 64 * 32 * scans as u64);
        }
        // A baseline frame whose first scan holds its one component is not read further.
        let mut baseline = progressive(64, 32, 3, &data);
        baseline[3] = 0xC0;
        let f = jpeg_frame(&baseline).unwrap();
        assert_eq!(
            (f.scans, f.first_scan, f.holds_coefficients()),
            (1, Some(1), false)
        );
        // A file cut inside a segment's length ends the count there.
        let whole = progressive(64, 32, 2, &data);
        let cut = &whole[..whole.len() - data.len() - 2 - 10 + 3];
        assert_eq!(jpeg_frame(cut).unwrap().scans, 1);
    }

    /// A baseline frame of three components whose first scan holds `first` of them.
    fn baseline_in_scans(w: u16, h: u16, first: u8) -> Vec<u8> {
        let mut b = vec![0xFF, 0xD8, 0xFF, 0xC0, 0, 17, 8];
        b.extend(h.to_be_bytes());
        b.extend(w.to_be_bytes());
        b.push(3);
        for id in 1..=3 {
            b.extend([id, 0x11, 0]);
        }
        b.extend([0xFF, 0xDA, 0, 6 + 2 * first, first]);
        for id in 1..=first {
            b.extend([id, 0]);
        }
        b.extend([0, 63, 0, 0x12, 0x34, 0xFF, 0xD9]);
        b
    }

    /// zune-jpeg holds every component's coefficients (two bytes a sample) for a baseline
    /// JPEG whose first scan leaves components to later ones: a 382-byte 12 000² one
    /// aborted a load under a memory limit that the check of its pixels had passed.
    #[test]
    fn a_baseline_frame_in_separate_scans_holds_its_coefficients() {
        let f = jpeg_frame(&baseline_in_scans(12_000, 12_000, 1)).unwrap();
        assert_eq!(
            (f.width, f.height, f.components, f.scans),
            (12_000, 12_000, 3, 1)
        );
        assert!(!f.progressive && f.holds_coefficients());
        assert_eq!(f.coefficient_bytes(), 2 * 3 * 12_000 * 12_000);
        assert!(!jpeg_frame(&baseline_in_scans(64, 64, 3))
            .unwrap()
            .holds_coefficients());
        let two = jpeg_frame(&baseline_in_scans(33, 1, 2)).unwrap();
        assert_eq!((two.scans, two.coefficient_bytes()), (1, 2 * 3 * 33));
    }
}
