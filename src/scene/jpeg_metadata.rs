//! A JPEG's metadata segments taken out before it is decoded: EXIF and XMP (`APP1`), ICC
//! profiles and multi-picture data (`APP2`) and IPTC (`APP13`), none of which the renderer
//! reads. The decoder copies each and reassembles extended XMP after every marker while
//! any is pending, sorting and comparing all its pieces each time: a load's time grew with
//! the square of such a file's size.

use super::jpeg_frame::segments;

/// `APP1`, `APP2` and `APP13`.
const METADATA: [u8; 3] = [0xE1, 0xE2, 0xED];

/// `bytes` without the metadata segments before its first scan; `Ok(None)` where it has none
/// (or the bytes are not a JPEG). An error where the copy cannot be allocated.
pub(crate) fn without_metadata(bytes: &[u8]) -> Result<Option<Vec<u8>>, String> {
    if !bytes.starts_with(&[0xFF, 0xD8]) {
        return Ok(None);
    }
    let len = bytes.len();
    // Walked twice rather than kept: a file of tiny segments holds millions.
    let metadata = || {
        segments(bytes)
            .take_while(|s| s.marker != 0xDA)
            .filter(move |s| METADATA.contains(&s.marker) && s.end <= len)
    };
    if metadata().next().is_none() {
        return Ok(None);
    }
    let mut kept = super::alloc_probe::room_for_copy(bytes.len())?;
    let mut from = 0;
    for segment in metadata() {
        kept.extend_from_slice(&bytes[from..segment.at]);
        from = segment.end;
    }
    kept.extend_from_slice(&bytes[from..]);
    Ok(Some(kept))
}

#[cfg(all(test, feature = "jpeg"))]
mod tests {
    use super::without_metadata;

    /// A segment of `marker` holding `body`.
    fn segment(marker: u8, body: &[u8]) -> Vec<u8> {
        let mut s = vec![0xFF, marker];
        s.extend((body.len() as u16 + 2).to_be_bytes());
        s.extend(body);
        s
    }

    fn rgb_jpeg() -> Vec<u8> {
        let pixels =
            image::RgbImage::from_fn(16, 8, |x, y| image::Rgb([x as u8 * 15, 90, y as u8 * 30]));
        let mut out = std::io::Cursor::new(Vec::new());
        image::DynamicImage::from(pixels)
            .write_to(&mut out, image::ImageFormat::Jpeg)
            .unwrap();
        out.into_inner()
    }

    #[test]
    fn metadata_segments_are_taken_out_and_the_pixels_kept() {
        let plain = rgb_jpeg();
        assert_eq!(without_metadata(&plain), Ok(None));
        let mut extended_xmp = b"http://ns.adobe.com/xmp/extension/\0".to_vec();
        extended_xmp.extend([b'0'; 32]);
        extended_xmp.extend([0xFF, 0xFF, 0xFF, 0xFF, 0, 0, 0, 0]);
        let metadata = [
            segment(0xE1, b"Exif\0\0MM\0*"),
            segment(0xE1, &extended_xmp),
            segment(0xE2, b"ICC_PROFILE\0\x01\x01profile"),
            segment(0xED, b"Photoshop 3.0\0"),
        ]
        .concat();
        // After SOI, and again just before the frame.
        let frame = crate::scene::jpeg_frame::segments(&plain)
            .find(|s| s.marker == 0xC0)
            .unwrap()
            .at;
        let dressed = [
            &plain[..2],
            &metadata,
            &plain[2..frame],
            &metadata,
            &plain[frame..],
        ]
        .concat();
        let kept = without_metadata(&dressed).unwrap().unwrap();
        assert_eq!(kept, plain);
        // Not a JPEG: left alone.
        assert_eq!(without_metadata(b"GIF89a"), Ok(None));
        // A copy that cannot be allocated is an error, not an abort.
        let refused =
            crate::scene::alloc_probe::with_allocatable(16, || without_metadata(&dressed));
        assert!(refused
            .unwrap_err()
            .contains("without its metadata cannot be allocated"));
    }
}
