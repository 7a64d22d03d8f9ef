//! A PNG's colour profile (`iCCP`) taken out before it is decoded. The renderer takes every
//! texture as sRGB and never reads a profile, yet the decoder inflates one (twice: header and
//! pixels) up to its allocation limit: a 538 KB chunk inflating to 512 MiB cost a second of
//! work and half a gigabyte on a 4×4 image, and nothing else bounded it.

/// The PNG signature every file starts with.
const SIGNATURE: &[u8; 8] = b"\x89PNG\r\n\x1a\n";

/// `bytes` without their `iCCP` chunks, or `None` where there is none (or the bytes are not a
/// PNG, or its chunks run past its end: the decoder then says what is wrong).
pub(crate) fn without_colour_profile(bytes: &[u8]) -> Option<Vec<u8>> {
    let chunks = bytes.strip_prefix(SIGNATURE)?;
    let mut profiles = Vec::new();
    let mut at = 0usize;
    while at < chunks.len() {
        let header = chunks.get(at..at.checked_add(8)?)?;
        let length = u32::from_be_bytes(header[..4].try_into().ok()?) as usize;
        // Length, type, data and CRC.
        let end = at.checked_add(12)?.checked_add(length)?;
        if end > chunks.len() {
            return None;
        }
        if &header[4..8] == b"iCCP" {
            profiles.push(at..end);
        }
        at = end;
    }
    if profiles.is_empty() {
        return None;
    }
    let mut kept = Vec::with_capacity(bytes.len());
    kept.extend_from_slice(SIGNATURE);
    let mut from = 0;
    for profile in profiles {
        kept.extend_from_slice(&chunks[from..profile.start]);
        from = profile.end;
    }
    kept.extend_from_slice(&chunks[from..]);
    Some(kept)
}

#[cfg(all(test, feature = "png"))]
mod tests {
    use super::without_colour_profile;
    use image::ImageEncoder;

    /// A 3×2 PNG with `profile` as its colour profile, when given one.
    fn png(profile: Option<Vec<u8>>) -> Vec<u8> {
        let pixels: Vec<u8> = (0..3 * 2 * 4).map(|i| (i * 11) as u8).collect();
        let mut out = Vec::new();
        let mut encoder = image::codecs::png::PngEncoder::new(&mut out);
        if let Some(profile) = profile {
            encoder.set_icc_profile(profile).unwrap();
        }
        encoder
            .write_image(&pixels, 3, 2, image::ExtendedColorType::Rgba8)
            .unwrap();
        out
    }

    #[test]
    fn the_profile_is_taken_out_and_the_pixels_kept() {
        let plain = png(None);
        assert_eq!(without_colour_profile(&plain), None);
        let profiled = png(Some(vec![7; 5000]));
        assert!(profiled.windows(4).any(|w| w == b"iCCP"));
        let kept = without_colour_profile(&profiled).unwrap();
        // The same chunks as the file without a profile, each with its own checksum.
        assert_eq!(kept, plain);
        // Not a PNG, or chunks running past the end: left to the decoder.
        assert_eq!(without_colour_profile(b"GIF89a"), None);
        assert_eq!(
            without_colour_profile(&profiled[..profiled.len() - 1]),
            None
        );
    }
}
