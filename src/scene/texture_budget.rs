//! The memory budget of diffuse textures. Decoding is bounded by `image`'s limits (sides and
//! the decoder's allocation), and a decoded image larger than [`MAX_STORED_TEXTURE_SIDE`] on a
//! side is scaled down in its own pixel format before it becomes RGBA8, the decoded copy
//! dropped then: a 12 000² RGB PNG peaks near 0.55 GB (0.43 decoded, 0.05 scaled, 0.06 RGBA)
//! and is kept as 64 MiB.

use image::DynamicImage;

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
