//! The memory budget of diffuse textures. Decoding is bounded by `image`'s limits (sides and
//! the decoder's allocation), and a decoded image larger than [`MAX_STORED_TEXTURE_SIDE`] on a
//! side is scaled down in its own pixel format before it becomes RGBA8, the decoded copy
//! dropped then: a 12 000² RGB PNG peaks near 0.55 GB (0.43 decoded, 0.05 scaled, 0.06 RGBA)
//! and is kept as 64 MiB.

use image::{DynamicImage, ImageDecoder};

use super::gif_frame::first_gif_frame;
use super::jpeg_frame::{jpeg_frame, JpegFrame};

/// Largest side of a texture as the scene keeps it: 4096² RGBA8 is 64 MiB (85 with the GPU's
/// mipmaps), the largest `GL_MAX_TEXTURE_SIZE` many phones have, and more texels than a 4K
/// frame can show of one surface. Larger images are scaled down, keeping their aspect ratio.
pub const MAX_STORED_TEXTURE_SIDE: u32 = 4096;

/// Largest side decoded at all, in pixels.
pub const MAX_DECODED_SIDE: u32 = 16_384;

/// Most bytes the decoder may allocate for one image (12 000² RGB or 11 585² RGBA fit): a
/// header claiming more fails before any allocation, and the image's material keeps its flat
/// colour with a warning.
pub const MAX_DECODE_BYTES: u64 = 512 << 20;

/// The decoder limits of a texture.
pub fn limits() -> image::Limits {
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_DECODED_SIDE);
    limits.max_image_height = Some(MAX_DECODED_SIDE);
    limits.max_alloc = Some(MAX_DECODE_BYTES);
    limits
}

/// The stored size of a `w × h` image: within [`MAX_STORED_TEXTURE_SIDE`], aspect kept.
pub fn stored_size(w: u32, h: u32) -> (u32, u32) {
    let side = w.max(h);
    if side <= MAX_STORED_TEXTURE_SIDE {
        return (w, h);
    }
    let scale = |s: u32| {
        let scaled = u64::from(s) * u64::from(MAX_STORED_TEXTURE_SIDE) / u64::from(side);
        (scaled as u32).max(1)
    };
    (scale(w), scale(h))
}

/// The texture a decoded image becomes (consumed, so only one full-size copy lives), and a
/// warning naming it when it was scaled down.
pub fn to_rgba8(image: DynamicImage, name: &str) -> (image::RgbaImage, Option<String>) {
    let (w, h) = (image.width(), image.height());
    let (sw, sh) = stored_size(w, h);
    if (sw, sh) == (w, h) {
        return (image.into_rgba8(), None);
    }
    // Area averaging straight into the small image: `resize_exact` would first build a
    // full-width f32 RGBA copy (786 MB for 12 000 × 4 096).
    let scaled = image.thumbnail_exact(sw, sh);
    let warning = format!(
        "texture {name} is {w}×{h}; scaled down to {sw}×{sh} (textures are kept within \
         {MAX_STORED_TEXTURE_SIDE} pixels a side)"
    );
    (scaled.into_rgba8(), Some(warning))
}

/// Decodes an encoded texture (OBJ and glTF alike): the stated format first, the contents
/// decide otherwise; at most [`MAX_DECODED_SIDE`] pixels a side and
/// [`MAX_DECODE_BYTES`] decoded, so a header claiming
/// a giant image fails before any allocation; and only where what it is kept as fits what is
/// left of `budget` (its header says, before anything is decoded). The error completes
/// "texture NAME …".
pub(crate) fn decode_texture_bytes(
    bytes: &[u8],
    format: Option<image::ImageFormat>,
    budget: &mut TextureBudget,
) -> Result<image::DynamicImage, String> {
    let undecodable = |e: image::ImageError| undecodable(&e);
    // Metadata the renderer never reads, which the decoders copy, expand or reassemble.
    let without_metadata = match super::png_metadata::without_metadata(bytes)? {
        None => super::jpeg_metadata::without_metadata(bytes)?,
        png => png,
    };
    let bytes = without_metadata.as_deref().unwrap_or(bytes);
    let reader = || {
        let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes));
        if let Some(format) = format {
            reader.set_format(format);
        }
        let mut reader = reader
            .with_guessed_format()
            .map_err(|e| format!("could not be read ({})", e.kind()))?;
        reader.limits(limits());
        Ok::<_, String>(reader)
    };
    let first = reader()?;
    let format = first.format();
    // Bytes the decoder holds besides the image it gives: a JPEG's coefficients (here), a
    // GIF's frame decoded apart from its screen (below).
    let mut held = 0;
    let jpeg = (format == Some(image::ImageFormat::Jpeg)).then(|| jpeg_frame(bytes));
    if let Some(Some(frame)) = &jpeg {
        if frame.holds_coefficients() {
            let (w, h) = (frame.width, frame.height);
            held = frame.coefficient_bytes();
            let output = u64::from(w) * u64::from(h) * JPEG_OUTPUT_BYTES_PER_PIXEL;
            if held + output > MAX_COEFFICIENT_DECODE_BYTES {
                let kind = if frame.progressive {
                    "a progressive JPEG"
                } else {
                    "a JPEG in separate scans"
                };
                return Err(format!(
                    "could not be decoded ({kind} of {w}×{h} holds its coefficients besides \
                     its pixels to decode, past {} MiB)",
                    MAX_COEFFICIENT_DECODE_BYTES >> 20
                ));
            }
            budget.take_scans(frame)?;
        }
    }
    let decoder = first.into_decoder().map_err(undecodable)?;
    let (w, h) = decoder.dimensions();
    if let Some(seen) = &jpeg {
        decodes_the_frame_seen(seen.as_ref(), (w, h))?;
    }
    let bytes_per_pixel = decoder.color_type().bytes_per_pixel();
    drop(decoder);
    // Some decoders (GIF) give an image of no rows or columns rather than an error.
    if w == 0 || h == 0 {
        return Err(format!("could not be decoded (it has no pixels: {w}×{h})"));
    }
    // A GIF's first frame may be larger than its screen, which is all `dimensions` says: the
    // decoder holds the whole frame, and decodes every pixel of it.
    let frame = first_gif_frame(bytes).filter(|_| format == Some(image::ImageFormat::Gif));
    if let Some(f) = frame {
        if f.width.max(f.height) > MAX_DECODED_SIDE {
            return Err(format!(
                "could not be decoded (its first frame is {}×{}, past the decoder's limit of \
                 {MAX_DECODED_SIDE} pixels a side)",
                f.width, f.height
            ));
        }
        held = f.extra_bytes((w, h));
    }
    let pixels = u64::from(w) * u64::from(h) * u64::from(bytes_per_pixel);
    let decoded = pixels + held;
    // A failed decode keeps its share taken: decoding is the work the budget bounds (60
    // images of 16 384² that failed at their last row took 16 s, none of it counted). One
    // refused by the decoder's limits decoded nothing, and gives it back.
    budget.take_decoding(w, h, decoded)?;
    let taken = budget
        .take(w, h)
        .inspect_err(|_| budget.give_back_decoding(decoded))?;
    // `image` aborts the process where an allocation fails: the decode, what the decoder
    // holds besides it (a GIF's frame, a JPEG's coefficients), the scaled copy and the RGBA
    // one are asked for first.
    let (sw, sh) = stored_size(w, h);
    let kept = u64::from(sw) * u64::from(sh) * (u64::from(bytes_per_pixel) + 4);
    let needed = 2 * pixels + held + kept;
    if !super::alloc_probe::can_allocate(needed) {
        budget.give_back(taken);
        budget.give_back_decoding(decoded);
        // Named where it shows in the MiB given.
        let besides = if held >= 1 << 20 {
            " and what the decoder holds besides them"
        } else {
            ""
        };
        return Err(format!(
            "could not be decoded ({w}×{h} pixels{besides} need {} MiB to decode, which \
             cannot be allocated here)",
            needed >> 20
        ));
    }
    PIXEL_BYTES_DECODED.with(|n| n.set(n.get().saturating_add(u64::from(w) * u64::from(h) * 4)));
    reader()?.decode().map_err(|e| {
        if matches!(e, image::ImageError::Limits(_)) {
            budget.give_back(taken);
            budget.give_back_decoding(decoded);
        }
        undecodable(e)
    })
}

thread_local! {
    /// RGBA bytes of the images [`decode_texture_bytes`] set out to decode on this thread.
    static PIXEL_BYTES_DECODED: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// RGBA bytes of the images decoded on this thread so far, at their full size (a running
/// count, as [`super::input::bytes_read`]): a small file may decode to 512 MiB.
pub(crate) fn pixel_bytes_decoded() -> u64 {
    PIXEL_BYTES_DECODED.with(std::cell::Cell::get)
}

/// Bytes a JPEG decode's output holds a pixel at most (RGBA).
const JPEG_OUTPUT_BYTES_PER_PIXEL: u64 = 4;

/// Most bytes the decode of a JPEG that holds its coefficients (two bytes a component and
/// pixel: a progressive one, or one in separate scans) may hold with its output: 1 GiB, about
/// 10 400² pixels of three components (a progressive 16 384 × 10 922 one within
/// [`MAX_DECODE_BYTES`] of output took 1.06 GB). Other JPEGs decode row by row.
const MAX_COEFFICIENT_DECODE_BYTES: u64 = 2 * MAX_DECODE_BYTES;

/// The crate's feature that decodes `format`, where the build has no decoder for it (asked of
/// `image`, whose decoders another crate of the build may have turned on).
fn decoder_left_out(format: image::ImageFormat) -> Option<&'static str> {
    use image::ImageFormat::*;
    if format.reading_enabled() {
        return None;
    }
    match format {
        Png => Some("png"),
        Jpeg => Some("jpeg"),
        Tga => Some("tga"),
        Bmp => Some("bmp"),
        Gif => Some("gif"),
        _ => None,
    }
}

/// Why an image did not decode, by the kind of failure only: the decoders' own messages
/// quote the file (a PNG chunk's type, a BMP header's bytes read as a number), and no message
/// may show a file's bytes.
fn undecodable(e: &image::ImageError) -> String {
    use image::error::{ImageError, ImageFormatHint};
    let format = |hint: ImageFormatHint| match hint {
        ImageFormatHint::Exact(format) => format!("{format:?}"),
        _ => "image".to_string(),
    };
    match e {
        ImageError::Decoding(d) => format!(
            "could not be decoded (not valid {} data)",
            format(d.format_hint())
        ),
        ImageError::Limits(_) => format!(
            "could not be decoded (past the decoder's limits: {MAX_DECODED_SIDE} pixels a side, \
             {MAX_DECODE_BYTES} bytes decoded)"
        ),
        ImageError::Unsupported(u) => match u.format_hint() {
            ImageFormatHint::Exact(f) if decoder_left_out(f).is_some() => format!(
                "could not be decoded (this build of manylight has no {f:?} decoder: its `{}` \
                 feature is off)",
                decoder_left_out(f).unwrap_or_default()
            ),
            hint => format!(
                "could not be decoded ({} data with a format or feature the decoder does not \
                 support)",
                format(hint)
            ),
        },
        ImageError::IoError(io) => format!("could not be decoded (read failed: {})", io.kind()),
        ImageError::Parameter(_) | ImageError::Encoding(_) => "could not be decoded".to_string(),
    }
}

/// Most bytes the textures of one scene load keep (RGBA8, each within
/// [`MAX_STORED_TEXTURE_SIDE`]): 16 images of 4096², 256 of 1024². More than a phone's GPU
/// holds; each image is bounded on its own, and without a total, PNGs of one colour (a few
/// kilobytes each) named by many materials would take gigabytes. A texture past it is left out
/// with a warning and its material keeps its flat colour.
pub const MAX_SCENE_TEXTURE_BYTES: u64 = 1 << 30;

/// Whether the JPEG decoder, having read the headers, decodes the frame that
/// [`jpeg_frame`]'s walk of them found (`seen`) at `decoded`: the checks of what its decode
/// holds are only as good as that walk, so a file the two read apart is refused rather than
/// decoded unchecked.
fn decodes_the_frame_seen(seen: Option<&JpegFrame>, decoded: (u32, u32)) -> Result<(), String> {
    let seen_size = seen.map(|f| (f.width, f.height));
    if seen_size == Some(decoded) {
        return Ok(());
    }
    let seen = match seen_size {
        Some((w, h)) => format!("a frame of {w}×{h}"),
        None => "no frame".to_string(),
    };
    Err(format!(
        "could not be decoded (its segment headers read two ways: {seen} before decoding, \
         {}×{} to the decoder)",
        decoded.0, decoded.1
    ))
}

/// What is left of one scene load's [`MAX_SCENE_TEXTURE_BYTES`]: every texture a load keeps
/// takes its part before it is decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TextureBudget {
    left: u64,
    /// What is left of [`MAX_SCENE_JPEG_SCAN_WORK`].
    scan_work_left: u64,
    /// What is left of [`MAX_SCENE_DECODED_BYTES`].
    decoded_left: u64,
}

impl Default for TextureBudget {
    fn default() -> Self {
        TextureBudget {
            left: MAX_SCENE_TEXTURE_BYTES,
            scan_work_left: MAX_SCENE_JPEG_SCAN_WORK,
            decoded_left: MAX_SCENE_DECODED_BYTES,
        }
    }
}

/// Most bytes the images of one scene load may decode to, in the decoder's own pixel format,
/// before each is scaled down to what is kept: 8 GiB, 16 images at [`MAX_DECODE_BYTES`] (each
/// kept within 64 MiB, so the kept bytes alone allowed 16 times this work). 64 RGBA16 PNGs of
/// 16 384 × 4 096 (33 MB of files) decoded 32 GiB, a minute of a shared core, without it.
pub const MAX_SCENE_DECODED_BYTES: u64 = 8 << 30;

/// Most work the progressive JPEGs of one scene load may give the decoder, in component
/// samples times scans: each scan walks every block of its components, however few bytes it
/// has. 2³⁵ is 17 progressive RGB images of 8 192² with 10 scans (a usual progression), or
/// about 7 s of one core here; 24 greyscale images of 16 384 × 10 922 with 100 scans (9 MB of
/// files) took 100 s without it.
pub const MAX_SCENE_JPEG_SCAN_WORK: u64 = 1 << 35;

impl TextureBudget {
    /// Nothing left: what a loader holds while its budget is lent out (an interrupted load
    /// never hands back a fresh one).
    pub(crate) fn spent() -> TextureBudget {
        TextureBudget {
            left: 0,
            scan_work_left: 0,
            decoded_left: 0,
        }
    }

    /// Takes the `decoded` bytes a `w × h` image decodes to, or says why it is left out.
    fn take_decoding(&mut self, w: u32, h: u32, decoded: u64) -> Result<(), String> {
        if decoded > self.decoded_left {
            return Err(format!(
                "is left out: decoding its {w}×{h} pixels would take the scene's images past \
                 the {} GiB they may decode to before they are scaled down",
                MAX_SCENE_DECODED_BYTES >> 30
            ));
        }
        self.decoded_left -= decoded;
        Ok(())
    }

    /// Returns decoded bytes taken for an image that was not decoded after all.
    fn give_back_decoding(&mut self, decoded: u64) {
        self.decoded_left =
            (self.decoded_left.saturating_add(decoded)).min(MAX_SCENE_DECODED_BYTES);
    }

    /// Takes the decoding work of a progressive JPEG's scans, or says why it is left out.
    fn take_scans(&mut self, frame: &JpegFrame) -> Result<(), String> {
        let work = frame.scan_work();
        if work > self.scan_work_left {
            return Err(format!(
                "could not be decoded (a progressive JPEG of {}×{} in {} scans: the scene's \
                 progressive JPEGs would take the decoder past 2^35 component samples of scans)",
                frame.width, frame.height, frame.scans
            ));
        }
        self.scan_work_left -= work;
        Ok(())
    }

    /// Takes what a `w × h` image is kept as ([`stored_size`], RGBA8) and returns it, or says
    /// why the image is left out.
    pub fn take(&mut self, w: u32, h: u32) -> Result<u64, String> {
        let (sw, sh) = stored_size(w, h);
        let bytes = u64::from(sw) * u64::from(sh) * 4;
        if bytes > self.left {
            let mib = |b: u64| b.div_ceil(1 << 20);
            return Err(format!(
                "is left out: its {} MiB would take the scene's textures past the {} MiB they \
                 may keep",
                mib(bytes),
                mib(MAX_SCENE_TEXTURE_BYTES)
            ));
        }
        self.left -= bytes;
        Ok(bytes)
    }

    /// A budget of `left` bytes (tests of what is left out).
    #[cfg(test)]
    pub(crate) fn with_left(left: u64) -> TextureBudget {
        TextureBudget {
            left,
            scan_work_left: MAX_SCENE_JPEG_SCAN_WORK,
            decoded_left: MAX_SCENE_DECODED_BYTES,
        }
    }

    /// Bytes left.
    #[cfg(test)]
    pub(crate) fn left(&self) -> u64 {
        self.left
    }

    /// Returns `bytes` taken for a texture that is not kept after all.
    pub fn give_back(&mut self, bytes: u64) {
        self.left = self.left.saturating_add(bytes).min(MAX_SCENE_TEXTURE_BYTES);
    }
}

#[cfg(all(test, feature = "loaders"))]
mod tests;
