//! The G-buffer and light accumulation buffer of traditional deferred shading (ES 3.0).
//!
//! ```text
//! attachment        format     bytes  contents
//! colour 0 albedo   RGBA16F      8    linear albedo (Kd × decoded texture); a: the surface
//!                                     point's window y offset from the pixel centre
//! colour 1 normal   RGBA32F     16    view-space normal (of the side seen) in
//!                                     octahedral form (xy), view depth (z), window x offset
//! colour 2 specular RGBA16F      8    Ks, Blinn-Phong exponent (metallic, roughness, −1 for a
//!                                     metallic-roughness material); none in a scene without
//!                                     either kind of material
//! depth             DEPTH24      4    for the geometry pass's depth test
//! accumulation      RGBA32F     16    Σ light radiance (additive blending; RGBA16F, 8 bytes,
//!                                     where GL_EXT_float_blend is missing), started by the
//!                                     geometry pass (colour 3) with the surface's emission,
//!                                     and its ambient occlusion in alpha
//!                              ----
//!                               52 bytes per pixel (1280×720: 47.9 MB), 44 with RGBA16F;
//!                               8 fewer without the specular target
//! ```
//!
//! The accumulation buffer is 32-bit where float blending allows: hundreds of small
//! contributions summed in fp16 drift by several 8-bit steps (measured in the stability tests).
//!
//! Float formats everywhere so the G-buffer loses almost nothing against forward: the normal
//! and depth are exact f32, albedo and specular keep 11 significant bits. The surface point is
//! the one forward shades (its interpolated position, kept as depth and window offset), not the
//! point on the pixel centre's ray: an implementation that snaps vertices to 1/16 pixel
//! (SwiftShader) puts them up to a few hundredths of a pixel apart, enough to change a pixel
//! near a light by 11/255. Rendering to float textures needs `GL_EXT_color_buffer_float`.
#![allow(unsafe_code)]

use glow::HasContext;

use super::target_size::{self, TargetStorage};
use super::{Caps, Device, EsVersion, GlError};

/// The normal buffer's view depth where no surface was drawn (below `noSurface`'s −10²⁹).
const NO_SURFACE_DEPTH: f32 = -1.0e30;

/// Bytes of GPU memory per pixel on this context, with or without the specular target (see
/// the module docs).
pub fn bytes_per_pixel(caps: &Caps, specular: bool) -> usize {
    let accumulation = if half_float_accumulation(caps) { 8 } else { 16 };
    let specular = if specular { 8 } else { 0 };
    8 + 16 + specular + 4 + accumulation
}

/// Why deferred cannot run on this context, if it cannot.
pub fn unsupported_reason(dev_caps: &Caps) -> Option<String> {
    if dev_caps.es != EsVersion::Es3 {
        return Some(if dev_caps.has_extension("GL_EXT_draw_buffers") {
            "needs OpenGL ES 3.0 (GL_EXT_draw_buffers exists, but float G-buffers and texelFetch do not on ES 2.0)".into()
        } else {
            "needs OpenGL ES 3.0 multiple render targets (ES 2.0 has one colour attachment)".into()
        });
    }
    if !dev_caps.has_extension("GL_EXT_color_buffer_float") {
        return Some("needs GL_EXT_color_buffer_float to render the float G-buffer".into());
    }
    if dev_caps.max_draw_buffers < 4 || dev_caps.max_color_attachments < 4 {
        return Some(format!(
            "needs 4 draw buffers, the context has {}",
            dev_caps.max_draw_buffers
        ));
    }
    None
}

/// G-buffer plus accumulation buffer of one size.
pub struct GBuffer {
    geometry_fbo: glow::Framebuffer,
    accum_fbo: glow::Framebuffer,
    /// albedo, normal+depth, specular (where the scene has such materials), accumulation
    color: [Option<glow::Texture>; 4],
    depth: glow::Texture,
    size: (u32, u32),
    bytes_per_pixel: usize,
    destroyed: bool,
}

fn texture(dev: &Device, w: u32, h: u32, internal: u32) -> Result<glow::Texture, GlError> {
    let t = dev.create_texture()?;
    let gl = &dev.gl;
    unsafe {
        gl.bind_texture(glow::TEXTURE_2D, Some(t));
        gl.tex_storage_2d(glow::TEXTURE_2D, 1, internal, w as i32, h as i32);
        super::texture::set_nearest_clamp(gl);
    }
    Ok(t)
}

/// The light accumulation is RGBA16F: the context cannot blend into 32-bit floats
/// (`GL_EXT_float_blend`).
pub fn half_float_accumulation(caps: &Caps) -> bool {
    !caps.has_extension("GL_EXT_float_blend")
}

#[cfg(test)]
thread_local! {
    /// Makes the next [`GBuffer::new`] on this thread fail as out of memory (tests of what
    /// a driver that has none does).
    pub(crate) static REFUSE_NEXT: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Most lights a half-float accumulation counts exactly at a pixel (fp16 holds every integer
/// up to 2¹¹; 2 048 + 1 rounds back to 2 048).
pub const HALF_FLOAT_EXACT_COUNT: usize = 2_048;

impl GBuffer {
    /// Allocates the buffers for a `width × height` viewport, with the specular target when
    /// `specular` (a scene with specular or metallic-roughness materials).
    pub fn new(dev: &Device, width: u32, height: u32, specular: bool) -> Result<GBuffer, GlError> {
        if let Some(reason) = unsupported_reason(dev.caps()) {
            return Err(GlError::Unsupported(reason));
        }
        #[cfg(test)]
        if REFUSE_NEXT.with(|r| r.replace(false)) {
            return Err(GlError::OutOfMemory("refused by a test".into()));
        }
        let (w, h) = (width, height);
        let storage = TargetStorage {
            textures: true,
            renderbuffers: false,
        };
        target_size::check(dev.caps(), "a deferred G-buffer", (w, h), storage)?;
        let albedo = texture(dev, w, h, glow::RGBA16F)?;
        let normal = texture(dev, w, h, glow::RGBA32F)?;
        let specular = match specular {
            true => Some(texture(dev, w, h, glow::RGBA16F)?),
            false => None,
        };
        let accum_format = if half_float_accumulation(dev.caps()) {
            glow::RGBA16F
        } else {
            glow::RGBA32F
        };
        let accum = texture(dev, w, h, accum_format)?;
        let depth = texture(dev, w, h, glow::DEPTH_COMPONENT24)?;
        let geometry_fbo = dev.create_framebuffer()?;
        let accum_fbo = dev.create_framebuffer()?;
        let gb = GBuffer {
            geometry_fbo,
            accum_fbo,
            color: [Some(albedo), Some(normal), specular, Some(accum)],
            depth,
            size: (w, h),
            bytes_per_pixel: bytes_per_pixel(dev.caps(), specular.is_some()),
            destroyed: false,
        };
        // Out of memory is an error naming the size, not an incomplete framebuffer.
        if let Err(e) = dev.check(&format!("allocating a {w}×{h} G-buffer")) {
            let mut gb = gb;
            gb.destroy(dev);
            return Err(e);
        }
        let gl = &dev.gl;
        unsafe {
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(geometry_fbo));
            // The accumulation buffer too: the geometry pass starts it (emission, occlusion).
            for (i, t) in gb.color.iter().enumerate() {
                gl.framebuffer_texture_2d(
                    glow::FRAMEBUFFER,
                    glow::COLOR_ATTACHMENT0 + i as u32,
                    glow::TEXTURE_2D,
                    *t,
                    0,
                );
            }
            gl.framebuffer_texture_2d(
                glow::FRAMEBUFFER,
                glow::DEPTH_ATTACHMENT,
                glow::TEXTURE_2D,
                Some(depth),
                0,
            );
            // Without the specular target its output goes nowhere (the shader writes it all
            // the same: locations are fixed).
            let specular = match gb.color[2] {
                Some(_) => glow::COLOR_ATTACHMENT2,
                None => glow::NONE,
            };
            gl.draw_buffers(&[
                glow::COLOR_ATTACHMENT0,
                glow::COLOR_ATTACHMENT1,
                specular,
                glow::COLOR_ATTACHMENT3,
            ]);
            let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(accum_fbo));
            gl.framebuffer_texture_2d(
                glow::FRAMEBUFFER,
                glow::COLOR_ATTACHMENT0,
                glow::TEXTURE_2D,
                Some(accum),
                0,
            );
            // The geometry pass's depth, tested (never written) by the light volumes.
            gl.framebuffer_texture_2d(
                glow::FRAMEBUFFER,
                glow::DEPTH_ATTACHMENT,
                glow::TEXTURE_2D,
                Some(depth),
                0,
            );
            let accum_status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
            for s in [status, accum_status] {
                if s != glow::FRAMEBUFFER_COMPLETE {
                    let e = dev.incomplete_framebuffer(format!("a {width}×{height} G-buffer"), s);
                    let mut gb = gb;
                    gb.destroy(dev);
                    return Err(e);
                }
            }
        }
        if let Err(e) = dev.check("G-buffer creation") {
            let mut gb = gb;
            gb.destroy(dev);
            return Err(e);
        }
        Ok(gb)
    }

    /// Size in pixels.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// Whether it has the specular target.
    pub fn has_specular(&self) -> bool {
        self.color[2].is_some()
    }

    /// GPU bytes held.
    pub fn gpu_bytes(&self) -> usize {
        self.size.0 as usize * self.size.1 as usize * self.bytes_per_pixel
    }

    /// Binds the G-buffer for the geometry pass and clears it: a view depth of −10³⁰ in the
    /// normal buffer marks uncovered pixels (`noSurface` in `deferred_common.glsl`). Not 0: an
    /// orthographic camera with near 0 draws surfaces at and just behind the eye plane, which
    /// must not read as background.
    pub fn begin_geometry(&self, dev: &Device) {
        let gl = &dev.gl;
        unsafe {
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(self.geometry_fbo));
        }
        dev.viewport(0, 0, self.size.0 as i32, self.size.1 as i32);
        dev.clear([0.0; 4]);
        unsafe { gl.clear_buffer_f32_slice(glow::COLOR, 1, &[0.0, 0.0, NO_SURFACE_DEPTH, 0.0]) };
    }

    /// Binds the accumulation buffer as the geometry pass left it (each surface's emission,
    /// and its occlusion in alpha; 0 elsewhere), with the geometry pass's depth attached (kept) for the
    /// light volumes' depth test.
    pub fn begin_accumulation(&self, dev: &Device) {
        unsafe {
            dev.gl
                .bind_framebuffer(glow::FRAMEBUFFER, Some(self.accum_fbo));
        }
        dev.viewport(0, 0, self.size.0 as i32, self.size.1 as i32);
    }

    /// Binds the geometry pass's depth texture to `unit`, for the composite pass to write into
    /// the target's own depth buffer (whatever its format) with `gl_FragDepth`.
    pub fn bind_depth_texture(&self, dev: &Device, unit: u32) {
        unsafe {
            dev.gl.active_texture(glow::TEXTURE0 + unit);
            dev.gl.bind_texture(glow::TEXTURE_2D, Some(self.depth));
        }
    }

    /// Binds albedo, normal+depth, specular (none without the target) and accumulation to
    /// units `first..first + 4`.
    pub fn bind_textures(&self, dev: &Device, first: u32) {
        for (i, t) in self.color.iter().enumerate() {
            unsafe {
                dev.gl.active_texture(glow::TEXTURE0 + first + i as u32);
                dev.gl.bind_texture(glow::TEXTURE_2D, *t);
            }
        }
    }

    /// Frees everything.
    pub fn destroy(&mut self, dev: &Device) {
        if !self.destroyed {
            dev.delete_framebuffer(self.geometry_fbo);
            dev.delete_framebuffer(self.accum_fbo);
            for t in self.color.into_iter().flatten() {
                dev.delete_texture(t);
            }
            dev.delete_texture(self.depth);
            self.destroyed = true;
        }
    }
}

impl Drop for GBuffer {
    fn drop(&mut self) {
        if !self.destroyed && !super::left_objects::left_on_purpose() {
            log::warn!("GBuffer dropped without destroy(): GL objects leaked");
        }
    }
}
