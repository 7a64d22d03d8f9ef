//! Offscreen render targets: an RGBA8 colour texture (renderable in ES 2.0 core, unlike RGBA8
//! renderbuffers) or an RGBA16F one (to see NaN and Inf, which an 8-bit target hides), and a
//! depth renderbuffer (24-bit where available: tiny near planes need it).
#![allow(unsafe_code)]

use glow::HasContext;

use super::target_size::{self, TargetStorage};
use super::{Device, EsVersion, GlError};

/// An offscreen framebuffer of a fixed size.
pub struct OffscreenTarget {
    fbo: glow::Framebuffer,
    color: glow::Texture,
    depth: glow::Renderbuffer,
    width: u32,
    height: u32,
    format: ColorFormat,
    destroyed: bool,
}

/// Colour buffer format of an offscreen target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorFormat {
    /// 8 bits per channel (what a window shows).
    Rgba8,
    /// Half floats: keeps values above 1, NaN and Inf (needs `GL_EXT_color_buffer_float` or
    /// `GL_EXT_color_buffer_half_float`).
    Rgba16F,
}

impl ColorFormat {
    /// Whether the context can render to this format.
    pub fn supported(self, dev: &Device) -> bool {
        match self {
            ColorFormat::Rgba8 => true,
            ColorFormat::Rgba16F => dev.caps().hdr_output(),
        }
    }
}

impl OffscreenTarget {
    /// Creates a `width × height` target.
    pub fn new(dev: &Device, width: u32, height: u32) -> Result<OffscreenTarget, GlError> {
        Self::with_format(dev, width, height, ColorFormat::Rgba8)
    }

    /// Creates a `width × height` target with the given colour format.
    pub fn with_format(
        dev: &Device,
        width: u32,
        height: u32,
        format: ColorFormat,
    ) -> Result<OffscreenTarget, GlError> {
        if !format.supported(dev) {
            return Err(GlError::Unsupported(format!(
                "{format:?} render targets are not supported on this context"
            )));
        }
        let storage = TargetStorage {
            textures: true,
            renderbuffers: true,
        };
        target_size::check(dev.caps(), "a render target", (width, height), storage)?;
        // The frame is drawn and read in the lower-left corner of the storage.
        let (storage_width, storage_height) =
            target_size::texture_storage(dev.caps(), (width, height));
        let gl = &dev.gl;
        unsafe {
            let color = dev.create_texture()?;
            gl.bind_texture(glow::TEXTURE_2D, Some(color));
            let (internal, ty) = match (format, dev.es()) {
                (ColorFormat::Rgba8, EsVersion::Es3) => (glow::RGBA8, glow::UNSIGNED_BYTE),
                (ColorFormat::Rgba8, EsVersion::Es2) => (glow::RGBA, glow::UNSIGNED_BYTE),
                (ColorFormat::Rgba16F, EsVersion::Es3) => (glow::RGBA16F, glow::HALF_FLOAT),
                (ColorFormat::Rgba16F, EsVersion::Es2) => (glow::RGBA, HALF_FLOAT_OES),
            };
            gl.tex_image_2d(
                glow::TEXTURE_2D,
                0,
                internal as i32,
                storage_width as i32,
                storage_height as i32,
                0,
                glow::RGBA,
                ty,
                glow::PixelUnpackData::Slice(None),
            );
            super::texture::set_nearest_clamp(gl);
            let depth = match dev.create_renderbuffer() {
                Ok(depth) => depth,
                Err(e) => {
                    dev.delete_texture(color);
                    return Err(e);
                }
            };
            gl.bind_renderbuffer(glow::RENDERBUFFER, Some(depth));
            let (depth_format, _) = dev.caps().own_depth_format();
            gl.renderbuffer_storage(
                glow::RENDERBUFFER,
                depth_format,
                storage_width as i32,
                storage_height as i32,
            );
            // Out of memory here is an error naming the size, not an incomplete framebuffer.
            let fbo = dev
                .check(&format!("allocating a {width}×{height} {format:?} target"))
                .and_then(|()| dev.create_framebuffer());
            let fbo = match fbo {
                Ok(fbo) => fbo,
                Err(e) => {
                    dev.delete_texture(color);
                    dev.delete_renderbuffer(depth);
                    return Err(e);
                }
            };
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
            gl.framebuffer_texture_2d(
                glow::FRAMEBUFFER,
                glow::COLOR_ATTACHMENT0,
                glow::TEXTURE_2D,
                Some(color),
                0,
            );
            gl.framebuffer_renderbuffer(
                glow::FRAMEBUFFER,
                glow::DEPTH_ATTACHMENT,
                glow::RENDERBUFFER,
                Some(depth),
            );
            let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
            let mut target = OffscreenTarget {
                fbo,
                color,
                depth,
                width,
                height,
                format,
                destroyed: false,
            };
            if status != glow::FRAMEBUFFER_COMPLETE {
                let e = dev
                    .incomplete_framebuffer(format!("a {width}×{height} offscreen target"), status);
                target.destroy(dev);
                return Err(e);
            }
            if let Err(e) = dev.check("offscreen target creation") {
                target.destroy(dev);
                return Err(e);
            }
            Ok(target)
        }
    }

    /// Binds the target and sets the viewport to cover it.
    pub fn bind(&self, dev: &Device) {
        unsafe { dev.gl.bind_framebuffer(glow::FRAMEBUFFER, Some(self.fbo)) };
        dev.viewport(0, 0, self.width as i32, self.height as i32);
    }

    /// The framebuffer object (to resolve a multisampled target into).
    pub fn framebuffer(&self) -> glow::Framebuffer {
        self.fbo
    }

    /// Size in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Colour format.
    pub fn format(&self) -> ColorFormat {
        self.format
    }

    /// Reads a float colour buffer as f32 RGBA, top row first. ES 3.0 reads floats as
    /// `RGBA`/`FLOAT`; an ES 2.0 context may take only its own read format (Mesa's: half
    /// floats), which its `GL_IMPLEMENTATION_COLOR_READ_*` name.
    pub fn read_rgba_f32(&self, dev: &Device) -> Result<Vec<[f32; 4]>, GlError> {
        unsafe { dev.gl.bind_framebuffer(glow::FRAMEBUFFER, Some(self.fbo)) };
        let Some(kind) = half_float_read_type(dev) else {
            return self.read_pixels(
                dev,
                glow::FLOAT,
                1,
                ("float read-back", "glReadPixels (float)"),
            );
        };
        let halves: Vec<[u16; 4]> = self.read_pixels(
            dev,
            kind,
            1,
            ("half-float read-back", "glReadPixels (half float)"),
        )?;
        let mut texels: Vec<[f32; 4]> =
            super::alloc::zeroed(self.width, self.height, 1, "float read-back")?;
        for (texel, half) in texels.iter_mut().zip(&halves) {
            *texel = half.map(|bits| half::f16::from_bits(bits).to_f32());
        }
        Ok(texels)
    }

    /// Reads the colour buffer, top row first (as image files store it).
    pub fn read_rgba8(&self, dev: &Device) -> Result<image::RgbaImage, GlError> {
        unsafe { dev.gl.bind_framebuffer(glow::FRAMEBUFFER, Some(self.fbo)) };
        let pixels =
            self.read_pixels(dev, glow::UNSIGNED_BYTE, 4, ("read-back", "glReadPixels"))?;
        Ok(image::RgbaImage::from_raw(self.width, self.height, pixels).expect("size matches"))
    }

    /// The bound framebuffer's `RGBA` pixels of type `kind`, `per_pixel` `T`s each, top row
    /// first; `what` names the buffer and the call in errors.
    fn read_pixels<T: bytemuck::Pod>(
        &self,
        dev: &Device,
        kind: u32,
        per_pixel: usize,
        (buffer, call): (&str, &str),
    ) -> Result<Vec<T>, GlError> {
        let mut pixels: Vec<T> = super::alloc::zeroed(self.width, self.height, per_pixel, buffer)?;
        unsafe {
            // Rows are whole pixels: no padding whatever `T`.
            dev.gl
                .pixel_store_i32(glow::PACK_ALIGNMENT, std::mem::align_of::<T>() as i32);
            dev.gl.read_pixels(
                0,
                0,
                self.width as i32,
                self.height as i32,
                glow::RGBA,
                kind,
                glow::PixelPackData::Slice(Some(bytemuck::cast_slice_mut(&mut pixels))),
            );
        }
        dev.check(call)?;
        super::alloc::flip_rows(&mut pixels, self.width as usize * per_pixel);
        Ok(pixels)
    }

    /// Frees the framebuffer and its attachments.
    pub fn destroy(&mut self, dev: &Device) {
        if !self.destroyed {
            dev.delete_framebuffer(self.fbo);
            dev.delete_texture(self.color);
            dev.delete_renderbuffer(self.depth);
            self.destroyed = true;
        }
    }
}

impl Drop for OffscreenTarget {
    fn drop(&mut self) {
        if !self.destroyed && !super::left_objects::left_on_purpose() {
            log::warn!("OffscreenTarget dropped without destroy(): GL objects leaked");
        }
    }
}

/// `GL_HALF_FLOAT_OES`: ES 2.0's `OES_texture_half_float` type (ES 3.0's `HALF_FLOAT` has
/// another value).
const HALF_FLOAT_OES: u32 = 0x8D61;

/// On an ES 2.0 renderer, the half-float type of the bound framebuffer's own read format when
/// that is `RGBA` half floats, which the context accepts where it may refuse `RGBA`/`FLOAT`.
fn half_float_read_type(dev: &Device) -> Option<u32> {
    if dev.es() != EsVersion::Es2 {
        return None;
    }
    let (format, kind) = unsafe {
        (
            dev.gl
                .get_parameter_i32(glow::IMPLEMENTATION_COLOR_READ_FORMAT) as u32,
            dev.gl
                .get_parameter_i32(glow::IMPLEMENTATION_COLOR_READ_TYPE) as u32,
        )
    };
    (format == glow::RGBA && matches!(kind, HALF_FLOAT_OES | glow::HALF_FLOAT)).then_some(kind)
}

#[cfg(test)]
mod tests {
    use super::OffscreenTarget;
    use crate::gl::context::context_or_skip;
    use crate::gl::{Device, EsVersion};

    /// Without `GL_OES_depth24` the renderer's own target takes the 24 depth bits of a packed
    /// depth and stencil format where the context has one, and 16 only where it has neither.
    #[test]
    fn the_own_target_keeps_24_depth_bits_through_packed_depth_stencil() {
        let Some(ctx) = context_or_skip(EsVersion::Es2) else {
            return;
        };
        let mut dev = Device::new(ctx.load_gl().unwrap(), EsVersion::Es2).unwrap();
        // Each format only where the context has it (ANGLE's ES 2.0 context has the packed
        // one and not `GL_OES_depth24`, and refuses what it lacks, as it should).
        let here = (dev.caps().depth24, dev.caps().packed_depth_stencil);
        let cases = [(false, true, 24), (false, false, 16), (true, false, 24)];
        for (depth24, packed, bits) in cases {
            if (depth24 && !here.0) || (packed && !here.1) {
                eprintln!("depth24 {depth24}, packed {packed}: not on this context");
                continue;
            }
            dev.caps_mut().depth24 = depth24;
            dev.caps_mut().packed_depth_stencil = packed;
            assert_eq!(dev.caps().own_depth_format().1, bits);
            let mut target = OffscreenTarget::new(&dev, 8, 8).unwrap();
            target.bind(&dev);
            assert_eq!(
                dev.bound_depth_bits(),
                Some(bits as i32),
                "depth24 {depth24}, packed {packed}"
            );
            dev.check("the target").unwrap();
            target.destroy(&dev);
        }
    }
}
