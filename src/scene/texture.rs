//! Decoded 8-bit images: what every material texture slot holds.

/// An 8-bit RGBA image: sRGB-encoded colours (base colour, emission; decoded to linear in the
/// shader) or linear data (normal, occlusion and metallic-roughness maps).
#[derive(Debug)]
pub struct Texture {
    /// Where it came from (file path or a built-in name), for messages.
    pub name: String,
    /// Pixels, row 0 at the top as image files store them.
    pub image: image::RgbaImage,
}
