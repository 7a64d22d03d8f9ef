use super::*;

/// A JPEG's start of frame alone (`marker`: SOF0 baseline, SOF2 progressive) for a
/// `w × h` image of three components, then its end: what a header read sees.
fn jpeg_header(marker: u8, w: u16, h: u16) -> Vec<u8> {
    let mut b = vec![0xFF, 0xD8, 0xFF, 0xE0, 0, 4, 0, 0, 0xFF, marker, 0, 17, 8];
    b.extend(h.to_be_bytes());
    b.extend(w.to_be_bytes());
    b.push(3);
    for id in 1..=3 {
        b.extend([id, 0x11, 0]);
    }
    b.extend([0xFF, 0xD9]);
    b
}

/// A 521-byte progressive JPEG claiming 16 384 × 10 922 took 1.06 GB to decode: refused
/// from its frame header, before anything is taken.
#[test]
fn a_large_progressive_jpeg_is_refused_from_its_header() {
    let jpeg = Some(image::ImageFormat::Jpeg);
    let mut budget = TextureBudget::default();
    let progressive = jpeg_header(0xC2, 16_384, 10_922);
    let frame = |width, height| JpegFrame {
        width,
        height,
        components: 3,
        scans: 0,
        progressive: true,
        first_scan: None,
    };
    assert_eq!(jpeg_frame(&progressive), Some(frame(16_384, 10_922)));
    // Stray bytes and a stuffed zero before the frame, which the decoder skips, hide it
    // from no one.
    for junk in [&[0x00][..], &[0xFF, 0x00], &[0x12, 0xFF, 0xFF]] {
        let mut hidden = progressive[..2].to_vec();
        hidden.extend(junk);
        hidden.extend(&progressive[2..]);
        assert_eq!(jpeg_frame(&hidden), Some(frame(16_384, 10_922)));
        let err = decode_texture_bytes(&hidden, jpeg, &mut budget).unwrap_err();
        assert!(err.contains("progressive JPEG"), "{junk:?}: {err}");
    }
    let err = decode_texture_bytes(&progressive, jpeg, &mut budget).unwrap_err();
    assert!(err.contains("progressive JPEG of 16384×10922"), "{err}");
    assert_eq!(
        budget,
        TextureBudget::default(),
        "refused before anything was taken"
    );
    // Small ones, and baseline ones of any size, go to the decoder.
    assert!(!jpeg_frame(&jpeg_header(0xC0, 16_384, 10_922))
        .unwrap()
        .holds_coefficients());
    let small = jpeg_header(0xC2, 64, 64);
    let err = decode_texture_bytes(&small, jpeg, &mut budget).unwrap_err();
    assert!(!err.contains("progressive"), "{err}");
    let baseline = encoded(image::RgbImage::new(8, 8).into(), image::ImageFormat::Jpeg);
    assert!(!jpeg_frame(&baseline).unwrap().holds_coefficients());
}

/// A JPEG that the decoder reads up to its first scan: a quantisation table, a frame of
/// `w × h` (`marker`: SOF0 baseline, SOF2 progressive) in `components` components, a DC
/// and an AC Huffman table of one code each, and a first scan holding `first` of them.
fn jpeg_to_first_scan(marker: u8, w: u16, h: u16, components: u8, first: u8) -> Vec<u8> {
    let segment = |b: &mut Vec<u8>, marker: u8, body: &[u8]| {
        b.extend([0xFF, marker]);
        b.extend((body.len() as u16 + 2).to_be_bytes());
        b.extend(body);
    };
    let mut b = vec![0xFF, 0xD8];
    segment(&mut b, 0xDB, &[[0].as_slice(), &[1; 64]].concat());
    let mut frame = vec![8];
    frame.extend(h.to_be_bytes());
    frame.extend(w.to_be_bytes());
    frame.push(components);
    for id in 1..=components {
        frame.extend([id, 0x11, 0]);
    }
    segment(&mut b, marker, &frame);
    for class in [0x00, 0x10] {
        let mut table = vec![class, 1];
        table.extend([0; 15]);
        table.push(0);
        segment(&mut b, 0xC4, &table);
    }
    let mut scan = vec![first];
    for id in 1..=first {
        scan.extend([id, 0]);
    }
    let spectrum = if marker == 0xC2 {
        [0, 0, 0]
    } else {
        [0, 63, 0]
    };
    scan.extend(spectrum);
    segment(&mut b, 0xDA, &scan);
    b.extend([0; 64]);
    b.extend([0xFF, 0xD9]);
    b
}

/// A decode's error, or what it decoded (an image's debug print is its every byte).
fn refusal(decoded: Result<DynamicImage, String>) -> String {
    decoded.map_or_else(|e| e, |i| format!("decoded {}×{}", i.width(), i.height()))
}

/// What the decoder holds besides the image it gives is asked of the allocator with it.
/// Under address-space limits a 391-byte progressive CMYK JPEG of 9 400² (its
/// coefficients 707 MB) and an 83-kB GIF whose 11 000² first frame lies on a screen of
/// 1×1 (the frame 484 MB) aborted the process: the check had counted the output alone.
#[test]
fn what_the_decoder_holds_besides_the_image_is_asked_for() {
    use crate::scene::alloc_probe::with_allocatable;
    let mut budget = TextureBudget::default();
    let cmyk = jpeg_to_first_scan(0xC2, 9_400, 9_400, 4, 1);
    let err = refusal(with_allocatable(1 << 30, || {
        decode_texture_bytes(&cmyk, Some(image::ImageFormat::Jpeg), &mut budget)
    }));
    assert!(
        err.contains("9400×9400 pixels and what the decoder holds besides them need"),
        "{err}"
    );
    let mut gif = b"GIF89a\x01\x00\x01\x00\x80\x00\x00\x00\x00\x00\xff\xff\xff".to_vec();
    gif.extend(b"\x2c\x00\x00\x00\x00\xf8\x2a\xf8\x2a\x00\x02\x02\x44\x01\x00\x3b");
    let err = refusal(with_allocatable(256 << 20, || {
        decode_texture_bytes(&gif, Some(image::ImageFormat::Gif), &mut budget)
    }));
    // The frame's RGBA and its palette indices, 11 000² × 5 bytes, and the 1×1 image.
    assert!(
        err.contains("1×1 pixels and what the decoder holds besides them need 576 MiB"),
        "{err}"
    );
    // A frame past the decoder's side limit is refused however much memory there is.
    gif[24..26].copy_from_slice(&20_000u16.to_le_bytes());
    let err = refusal(decode_texture_bytes(
        &gif,
        Some(image::ImageFormat::Gif),
        &mut budget,
    ));
    assert!(err.contains("its first frame is 20000×11000"), "{err}");
}

/// zune-jpeg holds every coefficient of a baseline JPEG whose first scan leaves
/// components to later ones, as of a progressive one: a 382-byte 12 000² one needed
/// 1.4 GB. Past 1 GiB it is refused from its headers.
#[test]
fn a_large_jpeg_in_separate_scans_is_refused_from_its_headers() {
    let mut budget = TextureBudget::default();
    let jpeg = Some(image::ImageFormat::Jpeg);
    let separate = jpeg_to_first_scan(0xC0, 12_000, 12_000, 3, 1);
    let err = refusal(decode_texture_bytes(&separate, jpeg, &mut budget));
    assert!(
        err.contains("a JPEG in separate scans of 12000×12000"),
        "{err}"
    );
    assert_eq!(budget, TextureBudget::default());
    // Interleaved, it decodes row by row, and is the decoder's to read.
    let interleaved = jpeg_to_first_scan(0xC0, 64, 64, 3, 3);
    let decoded = decode_texture_bytes(&interleaved, jpeg, &mut budget);
    assert_eq!(decoded.map(|i| i.width()), Ok(64));
}

/// `jpeg` with a segment of `marker` holding `body` after its SOI.
fn with_segment_first(jpeg: &[u8], marker: u8, body: &[u8]) -> Vec<u8> {
    let mut b = jpeg[..2].to_vec();
    b.extend([0xFF, marker]);
    b.extend((body.len() as u16 + 2).to_be_bytes());
    b.extend(body);
    b.extend(&jpeg[2..]);
    b
}

/// zune-jpeg reads every marker before the first scan as a segment with a length (`FF 01`
/// and `FF D0`–`D8` too) and skips the frames it does not decode (SOF3 and up). Walked as
/// markers without a length, a 199-byte progressive JPEG of 16 384² hid its frame behind a
/// fake 1×1 one inside such a segment, passed the coefficient check and aborted a load
/// under a 900 MB limit. Each such file is read as the decoder reads it.
#[test]
fn a_frame_behind_segments_the_decoder_skips_is_the_one_checked() {
    let jpeg = Some(image::ImageFormat::Jpeg);
    let fake_frame = [8, 0, 1, 0, 1, 1, 1, 0x11, 0];
    let in_segment = [&[0xFF, 0xC2, 0, 11][..], &fake_frame].concat();
    let hidings = [0x01, 0xD0, 0xD7, 0xD8, 0xF0]
        .map(|marker| (marker, &in_segment[..]))
        .into_iter()
        .chain([0xC3, 0xC5, 0xCA, 0xCF].map(|marker| (marker, &fake_frame[..])));
    for (marker, body) in hidings {
        let what = format!("behind FF {marker:02X}");
        // Small: the decoder decodes it, at the size the walk found.
        let mut budget = TextureBudget::default();
        let small = with_segment_first(&jpeg_to_first_scan(0xC0, 64, 48, 3, 3), marker, body);
        let f = jpeg_frame(&small).unwrap();
        assert_eq!((f.width, f.height), (64, 48), "{what}");
        let decoded = decode_texture_bytes(&small, jpeg, &mut budget);
        assert_eq!(
            decoded.map(|i| (i.width(), i.height())),
            Ok((64, 48)),
            "{what}"
        );
        // Large: refused from the frame the decoder would decode.
        let large = jpeg_to_first_scan(0xC2, 12_000, 12_000, 3, 1);
        let large = with_segment_first(&large, marker, body);
        let f = jpeg_frame(&large).unwrap();
        assert_eq!((f.width, f.height), (12_000, 12_000), "{what}");
        let err = refusal(decode_texture_bytes(&large, jpeg, &mut budget));
        assert!(
            err.contains("progressive JPEG of 12000×12000"),
            "{what}: {err}"
        );
    }
}

/// A JPEG whose headers the walk and the decoder read apart is refused, not decoded
/// unchecked.
#[test]
fn a_jpeg_read_two_ways_is_refused() {
    let frame = |width, height| JpegFrame {
        width,
        height,
        components: 3,
        scans: 0,
        progressive: false,
        first_scan: None,
    };
    assert_eq!(
        decodes_the_frame_seen(Some(&frame(64, 48)), (64, 48)),
        Ok(())
    );
    let err = decodes_the_frame_seen(Some(&frame(1, 1)), (16_384, 16_384)).unwrap_err();
    assert!(
        err.contains("a frame of 1×1 before decoding, 16384×16384 to the decoder"),
        "{err}"
    );
    let err = decodes_the_frame_seen(None, (64, 48)).unwrap_err();
    assert!(err.contains("no frame before decoding"), "{err}");
}

/// The 24 greyscale 16 384 × 10 922 progressive JPEGs of 100 scans (380 KB each) that
/// kept a load busy for 100 s: past 2³⁵ samples of scans the rest are left out before
/// they are decoded.
#[test]
fn a_scenes_progressive_jpegs_are_refused_past_their_scans_work() {
    let mut b = vec![0xFF, 0xD8, 0xFF, 0xC2, 0, 11, 8];
    b.extend(10_922u16.to_be_bytes());
    b.extend(16_384u16.to_be_bytes());
    b.extend([1, 1, 0x11, 0]);
    for _ in 0..100 {
        b.extend([0xFF, 0xDA, 0, 8, 1, 1, 0, 0, 63, 0, 0x12, 0x34]);
    }
    b.extend([0xFF, 0xD9]);
    let jpeg = Some(image::ImageFormat::Jpeg);
    let mut budget = TextureBudget::default();
    // The first takes 100 × 1.8·10⁸ of the 3.4·10¹⁰ and goes to the decoder (which finds
    // no valid data in it); the second would pass the budget.
    let err = decode_texture_bytes(&b, jpeg, &mut budget).unwrap_err();
    assert!(!err.contains("scans"), "{err}");
    let err = decode_texture_bytes(&b, jpeg, &mut budget).unwrap_err();
    assert!(err.contains("16384×10922 in 100 scans"), "{err}");
    // With fewer scans, the same frame still fits what is left.
    let few = [&b[..15 + 12 * 10], &[0xFF, 0xD9]].concat();
    let err = decode_texture_bytes(&few, jpeg, &mut budget).unwrap_err();
    assert!(!err.contains("scans"), "{err}");
}

/// `image` encoded as `format`.
fn encoded(image: DynamicImage, format: image::ImageFormat) -> Vec<u8> {
    let mut bytes = Vec::new();
    image
        .write_to(&mut std::io::Cursor::new(&mut bytes), format)
        .unwrap();
    bytes
}

/// CRC-32 as PNG chunks carry it.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// A decode that fails keeps its share of the budget taken: decoding is the work the
/// budget bounds (60 images of 16 384² that failed at their last row took 16 s).
#[test]
fn a_failed_decode_is_charged() {
    let mut truncated = encoded(image::RgbImage::new(64, 32).into(), image::ImageFormat::Png);
    truncated.truncate(truncated.len() - 20);
    let mut budget = TextureBudget::default();
    let png = Some(image::ImageFormat::Png);
    assert!(decode_texture_bytes(&truncated, png, &mut budget).is_err());
    assert_eq!(MAX_SCENE_TEXTURE_BYTES - budget.left(), 64 * 32 * 4);
    // One past the decoder's limits decodes nothing and is not charged: an RGBA PNG of
    // 11 600² claims more than MAX_DECODE_BYTES from its header.
    let mut big = encoded(image::RgbaImage::new(1, 1).into(), image::ImageFormat::Png);
    // IHDR's width and height (bytes 16..24), and its CRC (over type and data, 12..29).
    big[16..20].copy_from_slice(&11_600u32.to_be_bytes());
    big[20..24].copy_from_slice(&11_600u32.to_be_bytes());
    let crc = crc32(&big[12..29]);
    big[29..33].copy_from_slice(&crc.to_be_bytes());
    let before = budget.left();
    let err = decode_texture_bytes(&big, png, &mut budget).unwrap_err();
    assert_eq!(budget.left(), before, "{err}");
}

/// Images decode in the decoder's own format before they are scaled down: a scene's
/// decoding is bounded apart from what it keeps, and a truncated image is charged its
/// decoded bytes (three a pixel for RGB8).
#[test]
fn a_scenes_decoding_is_bounded_apart_from_what_it_keeps() {
    let mut budget = TextureBudget::default();
    // 16 RGBA16 images of 16 384 × 4 096, each kept as 4 096 × 1 024 (16 MiB).
    for _ in 0..16 {
        budget
            .take_decoding(16_384, 4_096, 16_384 * 4_096 * 8)
            .unwrap();
        budget.take(16_384, 4_096).unwrap();
    }
    let err = budget
        .take_decoding(16_384, 4_096, 16_384 * 4_096 * 8)
        .unwrap_err();
    assert!(err.contains("8 GiB they may decode to"), "{err}");
    assert_eq!(
        budget.left(),
        MAX_SCENE_TEXTURE_BYTES - (256 << 20),
        "kept: 16 × 16 MiB"
    );
    let mut truncated = encoded(image::RgbImage::new(64, 32).into(), image::ImageFormat::Png);
    truncated.truncate(truncated.len() - 20);
    let mut budget = TextureBudget::default();
    let png = Some(image::ImageFormat::Png);
    assert!(decode_texture_bytes(&truncated, png, &mut budget).is_err());
    assert_eq!(MAX_SCENE_DECODED_BYTES - budget.decoded_left, 64 * 32 * 3);
    // Past what is left, the image is refused before it is decoded and nothing is taken.
    let mut nearly = TextureBudget::with_left(MAX_SCENE_TEXTURE_BYTES);
    nearly.decoded_left = 64 * 32 * 3 - 1;
    let before = nearly;
    let err = decode_texture_bytes(&truncated, png, &mut nearly).unwrap_err();
    assert!(err.contains("decoding its 64×32 pixels"), "{err}");
    assert_eq!(nearly, before);
}

/// A GIF whose screen and only frame are `width` wide and 0 high (interlaced, so the
/// decoder runs no rows and checks nothing).
fn gif_without_rows(width: u16) -> Vec<u8> {
    let mut gif = b"GIF89a".to_vec();
    gif.extend(width.to_le_bytes());
    gif.extend(0u16.to_le_bytes());
    // A global palette of two entries, no background, square pixels.
    gif.extend([0x80, 0, 0, 0, 0, 0, 0xFF, 0xFF, 0xFF]);
    // The frame: at (0, 0), `width` × 0, interlaced; LZW of no data; the trailer.
    gif.push(0x2C);
    gif.extend([0, 0, 0, 0]);
    gif.extend(width.to_le_bytes());
    gif.extend(0u16.to_le_bytes());
    gif.extend([0x40, 0x02, 0x00, 0x3B]);
    gif
}

/// An image of no pixels is refused (it would reach the scene as a texture with nothing
/// to sample, failing the whole load, or, past the size cap, as a black stripe).
#[test]
fn an_image_without_pixels_is_refused() {
    for width in [4, 5_000] {
        let mut budget = TextureBudget::default();
        let gif = gif_without_rows(width);
        let err =
            decode_texture_bytes(&gif, Some(image::ImageFormat::Gif), &mut budget).unwrap_err();
        assert!(err.contains(&format!("{width}×0")), "{err}");
    }
}

#[test]
fn large_images_are_scaled_down_keeping_their_aspect_and_named() {
    assert_eq!(stored_size(4096, 10), (4096, 10));
    assert_eq!(stored_size(12_000, 12_000), (4096, 4096));
    assert_eq!(stored_size(16_384, 3), (4096, 1));
    assert_eq!(stored_size(5_000, 2_500), (4096, 2048));
    // An RGB image wider than the budget: scaled in RGB, stored RGBA, colour kept.
    let rgb = image::RgbImage::from_pixel(5000, 6, image::Rgb([200, 100, 50]));
    let (img, warning) = to_rgba8(DynamicImage::ImageRgb8(rgb), "wall.png");
    assert_eq!(img.dimensions(), (4096, 4));
    assert_eq!(img.get_pixel(100, 2).0, [200, 100, 50, 255]);
    let warning = warning.unwrap();
    assert!(
        warning.contains("wall.png") && warning.contains("5000×6"),
        "{warning}"
    );
    let small = image::RgbaImage::from_pixel(3, 2, image::Rgba([1, 2, 3, 4]));
    let (img, warning) = to_rgba8(DynamicImage::ImageRgba8(small.clone()), "s.png");
    assert_eq!((img, warning), (small, None));
}

#[test]
fn the_budget_takes_what_textures_are_kept_as_and_refuses_past_it() {
    let mut budget = TextureBudget::default();
    // Kept as 4096² RGBA8, whatever was decoded: 64 MiB each, 16 fit.
    for _ in 0..16 {
        assert_eq!(budget.take(12_000, 12_000), Ok(64 << 20));
    }
    assert_eq!(budget.left(), 0);
    let refusal = budget.take(1, 1).unwrap_err();
    assert!(refusal.contains("1024 MiB"), "{refusal}");
    budget.give_back(64 << 20);
    assert_eq!(budget.take(4096, 4096), Ok(64 << 20));
    // Never more than the whole, however much is given back.
    budget.give_back(u64::MAX);
    assert_eq!(budget, TextureBudget::default());
}
