//! Decoded 8-bit images and how they are read: what every material texture slot holds.

use std::sync::Arc;

/// An 8-bit RGBA image: sRGB-encoded colours (base colour, emission; decoded to linear in the
/// shader) or linear data (normal, occlusion and metallic-roughness maps), and how it is
/// sampled.
#[derive(Debug)]
pub struct Texture {
    /// Where it came from (file path or a built-in name), for messages.
    pub name: String,
    /// Pixels, row 0 at the top as image files store them. Shared by the textures that read
    /// one image with different [`Sampling`]s (uploaded once).
    pub image: Arc<image::RgbaImage>,
    /// How it is read between and beyond its texels (glTF's sampler; for OBJ the default, or
    /// clamped by `map_Kd -clamp on`).
    /// A draw binds each image once: a material whose slots read one image through
    /// different samplings reads it through one of them (the glTF loader makes them agree,
    /// with a warning).
    pub sampling: Sampling,
}

impl Texture {
    /// A texture of `image` with the default [`Sampling`]. A side past the context's
    /// `GL_MAX_TEXTURE_SIZE` is scaled down to it at upload, with a warning (once a renderer;
    /// a loaded file's images are kept within 4 096 a side already).
    pub fn new(name: impl Into<String>, image: image::RgbaImage) -> Texture {
        Texture {
            name: name.into(),
            image: Arc::new(image),
            sampling: Sampling::default(),
        }
    }

    /// The same image (shared, not copied) read through `sampling`.
    pub fn with_sampling(&self, sampling: Sampling) -> Texture {
        Texture {
            name: self.name.clone(),
            image: self.image.clone(),
            sampling,
        }
    }
}

/// How a texture is read: its wrapping beyond [0, 1] along each axis and its filtering
/// (glTF 2.0 §5.26, the GL parameters of the same names). The default repeats, filters
/// linearly and blends the two nearest mipmap levels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Sampling {
    /// Along u (`wrapS`).
    pub wrap_u: Wrap,
    /// Along v (`wrapT`).
    pub wrap_v: Wrap,
    /// Magnified (`magFilter`).
    pub magnify: Filter,
    /// Minified, within a mipmap level (`minFilter`'s first word).
    pub minify: Filter,
    /// Between mipmap levels when minified, or `None` for the full-size level alone
    /// (`minFilter` `NEAREST` or `LINEAR`).
    pub mipmap: Option<Filter>,
}

impl Default for Sampling {
    fn default() -> Self {
        Sampling {
            wrap_u: Wrap::Repeat,
            wrap_v: Wrap::Repeat,
            magnify: Filter::Linear,
            minify: Filter::Linear,
            mipmap: Some(Filter::Linear),
        }
    }
}

/// What a texture coordinate beyond [0, 1] reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Wrap {
    /// The image again (`REPEAT`).
    Repeat,
    /// The edge texel (`CLAMP_TO_EDGE`).
    ClampToEdge,
    /// The image again, every other copy mirrored (`MIRRORED_REPEAT`).
    MirroredRepeat,
}

/// Filtering between texels (or mipmap levels).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Filter {
    /// The nearest one.
    Nearest,
    /// A linear blend of the nearest ones.
    Linear,
}
