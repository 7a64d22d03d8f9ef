//! Textures: data textures (light records, later cluster grids and index lists) read texel by
//! texel, and image textures (diffuse maps) sampled with filtering.
#![allow(unsafe_code)]

use glow::HasContext;

use super::{Device, EsVersion, GlError};
use crate::scene::texture::{Filter, Sampling, Wrap};

/// Texel format of a data texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DataFormat {
    /// Four f32 channels (ES 3.0 `RGBA32F`, ES 2.0 `RGBA` + `FLOAT` with `OES_texture_float`).
    Rgba32F,
    /// Four bytes.
    Rgba8,
    /// Two u32 channels (ES 3.0 only, read with `texelFetch` from a `usampler2D`).
    Rg32Ui,
    /// One u16 channel (ES 3.0 only).
    R16Ui,
    /// One u32 channel (ES 3.0 only): the cluster grid, a list start a cell.
    R32Ui,
    /// Four u16 channels (ES 3.0 only): the index list, four light numbers a texel.
    Rgba16Ui,
}

impl DataFormat {
    /// Bytes per texel.
    pub fn bytes_per_texel(self) -> usize {
        match self {
            DataFormat::Rgba32F => 16,
            DataFormat::Rgba8 => 4,
            DataFormat::Rg32Ui => 8,
            DataFormat::R16Ui => 2,
            DataFormat::R32Ui => 4,
            DataFormat::Rgba16Ui => 8,
        }
    }

    /// (internal format, format, type) for `glTexImage2D` on the given feature level.
    fn gl_formats(self, es: EsVersion) -> (u32, u32, u32) {
        match (self, es) {
            (DataFormat::Rgba32F, EsVersion::Es3) => (glow::RGBA32F, glow::RGBA, glow::FLOAT),
            (DataFormat::Rgba32F, EsVersion::Es2) => (glow::RGBA, glow::RGBA, glow::FLOAT),
            (DataFormat::Rgba8, EsVersion::Es3) => (glow::RGBA8, glow::RGBA, glow::UNSIGNED_BYTE),
            (DataFormat::Rgba8, EsVersion::Es2) => (glow::RGBA, glow::RGBA, glow::UNSIGNED_BYTE),
            (DataFormat::Rg32Ui, _) => (glow::RG32UI, glow::RG_INTEGER, glow::UNSIGNED_INT),
            (DataFormat::R16Ui, _) => (glow::R16UI, glow::RED_INTEGER, glow::UNSIGNED_SHORT),
            (DataFormat::R32Ui, _) => (glow::R32UI, glow::RED_INTEGER, glow::UNSIGNED_INT),
            (DataFormat::Rgba16Ui, _) => (glow::RGBA16UI, glow::RGBA_INTEGER, glow::UNSIGNED_SHORT),
        }
    }
}

/// A NEAREST, CLAMP_TO_EDGE texture of raw records.
pub struct DataTexture {
    raw: glow::Texture,
    format: DataFormat,
    size: (u32, u32),
    /// Rows the last upload needed: its height's next power of two.
    rows_needed: u32,
    /// Frames in a row whose records filled at most a quarter of its rows, uploaded or drawn
    /// again (see [`SHRINK_AFTER`] and [`DataTexture::note_still_frame`]).
    small_frames: super::shrink::SmallFrames,
    destroyed: bool,
}

pub use super::shrink::SHRINK_AFTER;

/// NEAREST filtering and CLAMP_TO_EDGE on the bound 2D texture: what data textures and render
/// targets read texel by texel need.
pub(crate) fn set_nearest_clamp(gl: &glow::Context) {
    set_sampling(gl, glow::NEAREST, glow::CLAMP_TO_EDGE, glow::NEAREST);
}

/// `sampling`'s parameters on the bound 2D texture (one with mipmaps).
fn set_image_sampling(gl: &glow::Context, sampling: &Sampling) {
    let wrap = |w: Wrap| match w {
        Wrap::Repeat => glow::REPEAT,
        Wrap::ClampToEdge => glow::CLAMP_TO_EDGE,
        Wrap::MirroredRepeat => glow::MIRRORED_REPEAT,
    } as i32;
    let magnify = match sampling.magnify {
        Filter::Nearest => glow::NEAREST,
        Filter::Linear => glow::LINEAR,
    };
    let minify = match (sampling.minify, sampling.mipmap) {
        (Filter::Nearest, None) => glow::NEAREST,
        (Filter::Linear, None) => glow::LINEAR,
        (Filter::Nearest, Some(Filter::Nearest)) => glow::NEAREST_MIPMAP_NEAREST,
        (Filter::Linear, Some(Filter::Nearest)) => glow::LINEAR_MIPMAP_NEAREST,
        (Filter::Nearest, Some(Filter::Linear)) => glow::NEAREST_MIPMAP_LINEAR,
        (Filter::Linear, Some(Filter::Linear)) => glow::LINEAR_MIPMAP_LINEAR,
    };
    unsafe {
        gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_MAG_FILTER, magnify as i32);
        gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_MIN_FILTER, minify as i32);
        gl.tex_parameter_i32(
            glow::TEXTURE_2D,
            glow::TEXTURE_WRAP_S,
            wrap(sampling.wrap_u),
        );
        gl.tex_parameter_i32(
            glow::TEXTURE_2D,
            glow::TEXTURE_WRAP_T,
            wrap(sampling.wrap_v),
        );
    }
}

fn set_sampling(gl: &glow::Context, filter: u32, wrap: u32, min_filter: u32) {
    unsafe {
        gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_MAG_FILTER, filter as i32);
        gl.tex_parameter_i32(
            glow::TEXTURE_2D,
            glow::TEXTURE_MIN_FILTER,
            min_filter as i32,
        );
        gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_WRAP_S, wrap as i32);
        gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_WRAP_T, wrap as i32);
    }
}

impl DataTexture {
    /// Creates an empty data texture; storage is allocated by the first upload.
    pub fn new(dev: &Device, format: DataFormat) -> Result<DataTexture, GlError> {
        if format == DataFormat::Rgba32F && !dev.caps().float_textures {
            return Err(GlError::Unsupported(
                "float data textures need ES 3.0 or GL_OES_texture_float".into(),
            ));
        }
        let integer = matches!(
            format,
            DataFormat::Rg32Ui | DataFormat::R16Ui | DataFormat::R32Ui | DataFormat::Rgba16Ui
        );
        if integer && dev.es() != EsVersion::Es3 {
            return Err(GlError::Unsupported("integer textures need ES 3.0".into()));
        }
        let raw = dev.create_texture()?;
        unsafe { dev.gl.bind_texture(glow::TEXTURE_2D, Some(raw)) };
        set_nearest_clamp(&dev.gl);
        Ok(DataTexture {
            raw,
            format,
            size: (0, 0),
            rows_needed: 0,
            small_frames: Default::default(),
            destroyed: false,
        })
    }

    /// Uploads `bytes`, whole texels row after row from the top, into a texture `width`
    /// texels wide with at least `height` rows: the rows they fill, then the part of the next
    /// row they reach (the rest of it is not sent). Storage grows to the next power of two of
    /// rows, and shrinks to it only after [`SHRINK_AFTER`] frames in a row that fill a quarter
    /// of it at most, so a list that changes length every frame does not reallocate every
    /// frame; shaders address rows with the allocated height ([`DataTexture::size`]).
    pub fn upload(
        &mut self,
        dev: &Device,
        width: u32,
        height: u32,
        bytes: &[u8],
    ) -> Result<(), GlError> {
        let texel = self.format.bytes_per_texel();
        let row = width as usize * texel;
        if !bytes.len().is_multiple_of(texel) || bytes.len() > row * height as usize {
            return Err(GlError::Unsupported(format!(
                "data texture upload of {} bytes into {width}×{height} texels of {texel} bytes",
                bytes.len()
            )));
        }
        let max = dev.caps().max_texture_size as u32;
        if width > max || height > max {
            return Err(GlError::Unsupported(format!(
                "data texture {width}×{height} exceeds GL_MAX_TEXTURE_SIZE {max}"
            )));
        }
        let gl = &dev.gl;
        let (internal, format, ty) = self.format.gl_formats(dev.es());
        let full_rows = bytes.len().checked_div(row).unwrap_or(0);
        let rest = bytes.len() - full_rows * row;
        let needed = height.next_power_of_two();
        self.rows_needed = needed;
        let shrink = (self.small_frames).note(needed as usize, self.size.1 as usize);
        let allocate = self.size.0 != width || self.size.1 < height || shrink;
        unsafe {
            gl.bind_texture(glow::TEXTURE_2D, Some(self.raw));
            gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 1);
            if allocate {
                let kept = if shrink { 0 } else { self.size.1 };
                self.small_frames.reset();
                let rows = needed.max(kept).min(max);
                gl.tex_image_2d(
                    glow::TEXTURE_2D,
                    0,
                    internal as i32,
                    width as i32,
                    rows as i32,
                    0,
                    format,
                    ty,
                    glow::PixelUnpackData::Slice(None),
                );
                self.size = (width, rows);
            }
            let sub_image = |y: usize, w: usize, h: usize, part: &[u8]| {
                gl.tex_sub_image_2d(
                    glow::TEXTURE_2D,
                    0,
                    0,
                    y as i32,
                    w as i32,
                    h as i32,
                    format,
                    ty,
                    glow::PixelUnpackData::Slice(Some(part)),
                )
            };
            if full_rows > 0 {
                sub_image(0, width as usize, full_rows, &bytes[..full_rows * row]);
            }
            if rest > 0 {
                sub_image(full_rows, rest / texel, 1, &bytes[full_rows * row..]);
            }
        }
        if !allocate {
            // Writing into storage it has: its errors are the frame's check's (a failed frame
            // leaves nothing to draw again: the renderer's next frame uploads anew).
            return Ok(());
        }
        let uploaded = dev.check("data texture upload");
        if uploaded.is_err() {
            // The allocation may have failed: the next upload allocates again.
            self.size = (0, 0);
        }
        uploaded
    }

    /// Counts a frame that draws with the last upload's records, as an upload counts: true once
    /// they have filled a quarter of its rows at most for [`SHRINK_AFTER`] frames, when
    /// uploading them again allocates it at their size. A still scene after a burst of lights
    /// uploads nothing, and kept the burst's rows for good.
    pub fn note_still_frame(&mut self) -> bool {
        (self.small_frames).note(self.rows_needed as usize, self.size.1 as usize)
    }

    /// Binds to texture unit `unit`.
    pub fn bind(&self, dev: &Device, unit: u32) {
        unsafe {
            dev.gl.active_texture(glow::TEXTURE0 + unit);
            dev.gl.bind_texture(glow::TEXTURE_2D, Some(self.raw));
        }
        dev.count_state_call(|c| c.data_textures_bound += 1);
    }

    /// Allocated size in texels.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// GPU bytes held.
    pub fn gpu_bytes(&self) -> usize {
        self.size.0 as usize * self.size.1 as usize * self.format.bytes_per_texel()
    }

    /// Frees the texture.
    pub fn destroy(&mut self, dev: &Device) {
        if !self.destroyed {
            dev.delete_texture(self.raw);
            self.destroyed = true;
        }
    }
}

impl Drop for DataTexture {
    fn drop(&mut self) {
        if !self.destroyed && !super::left_objects::left_on_purpose() {
            log::warn!("DataTexture dropped without destroy(): GL texture leaked");
        }
    }
}

/// Whether colour textures are sRGB textures, decoded by the sampler (the ES 3.0 level and
/// desktop GL), rather than by the shader after filtering (ES 2.0): what the uploads and the
/// shaders' `SRGB_TEXTURES` both follow.
pub fn hardware_srgb(caps: &super::Caps) -> bool {
    caps.es == EsVersion::Es3
}

/// The size an image of `size` is uploaded at: each side within `max` (the context's
/// `GL_MAX_TEXTURE_SIZE`), and with `power_of_two` (ES 2.0 without `GL_OES_texture_npot`,
/// which allows neither mipmaps nor `REPEAT` on other sizes, and OBJ texture coordinates tile)
/// the largest power of two not above that. Images are only ever scaled down: rounding up made a 12 000² PNG a 16 384² texture,
/// minutes of resizing and 4.7 GB.
pub fn upload_size((w, h): (u32, u32), max: u32, power_of_two: bool) -> (u32, u32) {
    let fit = |side: u32| {
        let side = side.clamp(1, max.max(1));
        if power_of_two {
            1 << (31 - side.leading_zeros())
        } else {
            side
        }
    };
    (fit(w), fit(h))
}

/// An RGBA8 image texture, read as each bind's [`Sampling`] says, with mipmaps only once a
/// sampling reads them (an image sampled only without, as pixel art, UI atlases and light
/// maps are, has none: a third less memory). A colour one
/// (sRGB-encoded) is an `SRGB8_ALPHA8` texture at the ES 3.0 level, so texels are decoded
/// before they are filtered (glTF 2.0 §3.9.2; filtering encoded values darkens fine
/// high-contrast detail); ES 2.0 has no sRGB textures in core (`GL_EXT_sRGB` cannot make their
/// mipmaps), so there the shader decodes the filtered value (`SRGB_TEXTURES` off).
pub struct ImageTexture {
    raw: glow::Texture,
    destroyed: bool,
    /// Bytes of its base level.
    base_bytes: usize,
    /// Its mipmaps are made (about a third more than the base level).
    mipmapped: std::cell::Cell<bool>,
    /// The sampling its parameters are set for (ES 2.0 has no sampler objects: each bind
    /// sets the parameters a texture's [`Sampling`] asks, where they differ).
    sampling: std::cell::Cell<Sampling>,
}

impl ImageTexture {
    /// Uploads an image, downscaled where it is larger than the context's texture limit and,
    /// on ES 2.0 without `GL_OES_texture_npot`, to a power of two (see [`upload_size`]);
    /// `srgb` for colour (see above), with its mipmaps made where `mipmaps`.
    pub fn new(
        dev: &Device,
        image: &image::RgbaImage,
        srgb: bool,
        mipmaps: bool,
    ) -> Result<ImageTexture, GlError> {
        let max = dev.caps().max_texture_size.max(1) as u32;
        let (w, h) = image.dimensions();
        let (pw, ph) = upload_size((w, h), max, !dev.caps().npot_textures);
        let resized;
        let img = if (pw, ph) != (w, h) {
            // Area averaging (upload sizes only ever shrink) without `resize`'s full-width f32
            // copy.
            resized = image::imageops::thumbnail(image, pw, ph);
            &resized
        } else {
            image
        };
        let gl = &dev.gl;
        let raw = dev.create_texture()?;
        unsafe {
            gl.bind_texture(glow::TEXTURE_2D, Some(raw));
            gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 1);
            let internal = if srgb && hardware_srgb(dev.caps()) {
                glow::SRGB8_ALPHA8
            } else {
                glow::RGBA
            };
            gl.tex_image_2d(
                glow::TEXTURE_2D,
                0,
                internal as i32,
                pw as i32,
                ph as i32,
                0,
                glow::RGBA,
                glow::UNSIGNED_BYTE,
                glow::PixelUnpackData::Slice(Some(img.as_raw())),
            );
            if mipmaps {
                gl.generate_mipmap(glow::TEXTURE_2D);
            }
        }
        // Complete as it is: without mipmaps, a sampling that reads none.
        let sampling = Sampling {
            mipmap: Sampling::default().mipmap.filter(|_| mipmaps),
            ..Sampling::default()
        };
        set_image_sampling(gl, &sampling);
        if let Err(e) = dev.check(&format!("uploading a {pw}×{ph} image texture")) {
            dev.delete_texture(raw);
            return Err(e);
        }
        Ok(ImageTexture {
            raw,
            destroyed: false,
            base_bytes: pw as usize * ph as usize * 4,
            mipmapped: std::cell::Cell::new(mipmaps),
            sampling: std::cell::Cell::new(sampling),
        })
    }

    /// GPU bytes of its texels, mipmaps included once made.
    pub fn gpu_bytes(&self) -> usize {
        let base = self.base_bytes;
        base + if self.mipmapped.get() { base / 3 } else { 0 }
    }

    /// Makes its mipmaps, unless made: the GPU bytes that adds. Binds it to the active unit.
    pub fn make_mipmaps(&self, dev: &Device) -> usize {
        if self.mipmapped.replace(true) {
            return 0;
        }
        unsafe {
            dev.gl.bind_texture(glow::TEXTURE_2D, Some(self.raw));
            dev.gl.generate_mipmap(glow::TEXTURE_2D);
        }
        self.base_bytes / 3
    }

    /// Binds to texture unit `unit`, read as `sampling` says (its mipmaps made first where
    /// that reads them and no upload has).
    pub fn bind(&self, dev: &Device, unit: u32, sampling: &Sampling) {
        unsafe {
            dev.gl.active_texture(glow::TEXTURE0 + unit);
            dev.gl.bind_texture(glow::TEXTURE_2D, Some(self.raw));
        }
        if sampling.mipmap.is_some() && !self.mipmapped.replace(true) {
            unsafe { dev.gl.generate_mipmap(glow::TEXTURE_2D) };
        }
        if self.sampling.get() != *sampling {
            set_image_sampling(&dev.gl, sampling);
            self.sampling.set(*sampling);
        }
    }

    /// Frees the texture.
    pub fn destroy(&mut self, dev: &Device) {
        if !self.destroyed {
            dev.delete_texture(self.raw);
            self.destroyed = true;
        }
    }
}

impl Drop for ImageTexture {
    fn drop(&mut self) {
        if !self.destroyed && !super::left_objects::left_on_purpose() {
            log::warn!("ImageTexture dropped without destroy(): GL texture leaked");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::upload_size;

    #[test]
    fn images_are_scaled_down_never_up() {
        // ES 2.0: the largest power of two not above the side, within the limit.
        assert_eq!(upload_size((12_000, 12_000), 16_384, true), (8_192, 8_192));
        assert_eq!(upload_size((1_000, 513), 16_384, true), (512, 512));
        assert_eq!(upload_size((256, 64), 16_384, true), (256, 64));
        assert_eq!(upload_size((5_000, 3), 2_048, true), (2_048, 2));
        // ES 3.0: any size within the limit.
        assert_eq!(upload_size((12_000, 700), 16_384, false), (12_000, 700));
        assert_eq!(upload_size((40_000, 700), 16_384, false), (16_384, 700));
        assert_eq!(upload_size((0, 1), 4_096, false), (1, 1));
    }
}
