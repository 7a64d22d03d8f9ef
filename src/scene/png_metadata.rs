//! A PNG's metadata taken out before it is decoded: its colour profile (`iCCP`) and text
//! (`tEXt`, `zTXt`, `iTXt`). The renderer takes every texture as sRGB and reads neither, yet
//! the decoder inflates a profile (twice: header and pixels) up to its allocation limit,
//! whatever the image's size, and turns Latin-1 text into UTF-8 in a string that doubles as
//! it grows.

/// The PNG signature every file starts with.
const SIGNATURE: &[u8; 8] = b"\x89PNG\r\n\x1a\n";

/// The chunks taken out.
const METADATA: [&[u8; 4]; 4] = [b"iCCP", b"tEXt", b"zTXt", b"iTXt"];

/// `bytes` without their [`METADATA`] chunks; `Ok(None)` where there is none (or the bytes
/// are not a PNG). The chunks are walked as the decoder reads them: up to `IEND`, whose
/// trailing bytes the decoder ignores and are dropped, or up to a chunk running past the end,
/// which is kept as it is for the decoder to refuse (metadata before it still taken out).
/// An error where the copy cannot be allocated.
pub(crate) fn without_metadata(bytes: &[u8]) -> Result<Option<Vec<u8>>, String> {
    let Some(chunks) = bytes.strip_prefix(SIGNATURE) else {
        return Ok(None);
    };
    // Walked twice rather than kept: a file of tiny chunks holds millions.
    let walk = || {
        let mut at = 0usize;
        let mut ended = false;
        std::iter::from_fn(move || {
            let chunk = whole_chunk(chunks, at).filter(|_| !ended)?;
            let kind = &chunks[at + 4..at + 8];
            ended = kind == b"IEND";
            at = chunk.end;
            Some((chunk, METADATA.iter().any(|m| kind == &m[..])))
        })
    };
    let mut end_of_image = chunks.len();
    let mut any = false;
    for (chunk, metadata) in walk() {
        any |= metadata;
        if &chunks[chunk.start + 4..chunk.start + 8] == b"IEND" {
            end_of_image = chunk.end;
        }
    }
    if !any {
        return Ok(None);
    }
    let mut kept = super::alloc_probe::room_for_copy(bytes.len())?;
    kept.extend_from_slice(SIGNATURE);
    let mut from = 0;
    for (chunk, _) in walk().filter(|(_, metadata)| *metadata) {
        kept.extend_from_slice(&chunks[from..chunk.start]);
        from = chunk.end;
    }
    kept.extend_from_slice(&chunks[from..end_of_image]);
    Ok(Some(kept))
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
    use super::without_metadata;
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
        assert_eq!(without_metadata(&plain), Ok(None));
        let profiled = png(Some(vec![7; 5000]));
        assert!(profiled.windows(4).any(|w| w == b"iCCP"));
        let kept = without_metadata(&profiled).unwrap().unwrap();
        // The same chunks as the file without a profile, each with its own checksum.
        assert_eq!(kept, plain);
        // Not a PNG: left to the decoder.
        assert_eq!(without_metadata(b"GIF89a"), Ok(None));
        // A copy that cannot be allocated is an error, not an abort.
        let refused =
            crate::scene::alloc_probe::with_allocatable(64, || without_metadata(&profiled));
        assert!(refused
            .unwrap_err()
            .contains("without its metadata cannot be allocated"));
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
            assert_eq!(
                without_metadata(&file).unwrap().as_deref(),
                Some(&plain[..])
            );
        }
        // A chunk running past the end after the profile: the profile goes, the rest is
        // kept as it is, for the decoder to refuse.
        let cut = &profiled[..profiled.len() - 1];
        let kept = without_metadata(cut).unwrap().unwrap();
        assert_eq!(kept, plain[..plain.len() - 1]);
        assert!(!kept.windows(4).any(|w| w == b"iCCP"));
        // A chunk whose length runs past `usize` on the way: the same.
        let mut huge = profiled[..profiled.len() - 12].to_vec();
        huge.extend_from_slice(&[0xFF, 0xFF, 0xFF, 0xFF, b'I', b'E', b'N', b'D']);
        let kept = without_metadata(&huge).unwrap().unwrap();
        assert!(!kept.windows(4).any(|w| w == b"iCCP"));
        assert!(kept.ends_with(&[0xFF, 0xFF, 0xFF, 0xFF, b'I', b'E', b'N', b'D']));
    }

    /// A chunk of `kind` holding `data`, with its checksum.
    fn chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
        let mut crc = !0u32;
        for &b in kind.iter().chain(data) {
            crc ^= u32::from(b);
            for _ in 0..8 {
                crc = (crc >> 1) ^ (0xEDB8_8320 & (crc & 1).wrapping_neg());
            }
        }
        let mut c = (data.len() as u32).to_be_bytes().to_vec();
        c.extend_from_slice(kind);
        c.extend_from_slice(data);
        c.extend_from_slice(&(!crc).to_be_bytes());
        c
    }

    /// Text is taken out with the profile: the decoder turned a 250 MiB `tEXt` chunk of
    /// Latin-1 into UTF-8 in a string that asked for 500 MiB more, and aborted a load under
    /// a memory limit the image itself was far within.
    #[test]
    fn text_chunks_are_taken_out_with_the_profile() {
        let plain = png(None);
        let header_end = 8 + 25; // signature and IHDR
        let texts = [
            chunk(b"tEXt", b"Comment\0\xe9\xe9\xe9"),
            chunk(b"zTXt", b"Comment\0\0\x78\x9c\x03\x00\x00\x00\x00\x01"),
            chunk(b"iTXt", b"Comment\0\0\0en\0\0text"),
        ]
        .concat();
        let with_text = [&plain[..header_end], &texts, &plain[header_end..]].concat();
        assert_eq!(
            without_metadata(&with_text).unwrap().as_deref(),
            Some(&plain[..])
        );
        // The decoder reads the file without them as it reads the one without text.
        let decoded = image::load_from_memory(&with_text).unwrap();
        assert_eq!(decoded, image::load_from_memory(&plain).unwrap());
    }
}
