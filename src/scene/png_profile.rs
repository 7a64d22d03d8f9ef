//! A PNG's colour profile (`iCCP`) taken out before it is decoded. The renderer takes every
//! texture as sRGB and never reads a profile, yet the decoder inflates one (twice: header and
//! pixels) up to its allocation limit: a 538 KB chunk inflating to 512 MiB cost a second of
//! work and half a gigabyte on a 4×4 image, and nothing else bounded it.

/// The PNG signature every file starts with.
const SIGNATURE: &[u8; 8] = b"\x89PNG\r\n\x1a\n";

/// `bytes` without their `iCCP` chunks, or `None` where there is none (or the bytes are not a
/// PNG). The chunks are walked as the decoder reads them: up to `IEND`, whose trailing bytes
/// the decoder ignores and are dropped, or up to a chunk running past the end, which is kept
/// as it is for the decoder to refuse (a profile before it is still taken out).
pub(crate) fn without_colour_profile(bytes: &[u8]) -> Option<Vec<u8>> {
    let chunks = bytes.strip_prefix(SIGNATURE)?;
    let mut profiles = Vec::new();
    let mut at = 0usize;
    let mut end_of_image = chunks.len();
    while let Some(chunk) = whole_chunk(chunks, at) {
        let kind = &chunks[at + 4..at + 8];
        if kind == b"iCCP" {
            profiles.push(at..chunk.end);
        }
        at = chunk.end;
        if kind == b"IEND" {
            end_of_image = at;
            break;
        }
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
    kept.extend_from_slice(&chunks[from..end_of_image]);
    Some(kept)
}

/// The bytes of the chunk starting at `at` (length, type, data and CRC), where all of them
/// lie within `chunks`.
fn whole_chunk(chunks: &[u8], at: usize) -> Option<std::ops::Range<usize>> {
    let header = chunks.get(at..at.checked_add(8)?)?;
    let length = u32::from_be_bytes(header[..4].try_into().ok()?) as usize;
    let end = at.checked_add(12)?.checked_add(length)?;
    (end <= chunks.len()).then_some(at..end)
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
        // Not a PNG: left to the decoder.
        assert_eq!(without_colour_profile(b"GIF89a"), None);
    }

    /// The decoder reads a profile wherever its walk of the chunks reaches it, so the walk
    /// here must reach it too: a single byte after `IEND`, which the decoder ignores, made
    /// the whole file "not a PNG" here and its 500 MiB profile was inflated.
    #[test]
    fn a_profile_is_taken_out_whatever_follows_the_last_whole_chunk() {
        let plain = png(None);
        let profiled = png(Some(vec![7; 5000]));
        // Bytes after IEND: dropped with the profile.
        for trailing in [&b"\0"[..], b"garbage after the image", &profiled[..]] {
            let mut file = profiled.clone();
            file.extend_from_slice(trailing);
            assert_eq!(without_colour_profile(&file).as_deref(), Some(&plain[..]));
        }
        // A chunk running past the end after the profile: the profile goes, the rest is
        // kept as it is, for the decoder to refuse.
        let cut = &profiled[..profiled.len() - 1];
        let kept = without_colour_profile(cut).unwrap();
        assert_eq!(kept, plain[..plain.len() - 1]);
        assert!(!kept.windows(4).any(|w| w == b"iCCP"));
        // A chunk whose length runs past `usize` on the way: the same.
        let mut huge = profiled[..profiled.len() - 12].to_vec();
        huge.extend_from_slice(&[0xFF, 0xFF, 0xFF, 0xFF, b'I', b'E', b'N', b'D']);
        let kept = without_colour_profile(&huge).unwrap();
        assert!(!kept.windows(4).any(|w| w == b"iCCP"));
        assert!(kept.ends_with(&[0xFF, 0xFF, 0xFF, 0xFF, b'I', b'E', b'N', b'D']));
    }
}
