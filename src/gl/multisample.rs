//! A multisampled offscreen target, rendered into and then resolved into a single-sampled
//! framebuffer: the renderer's offscreen target, or the caller's (a window's back buffer).
//!
//! * ES 3.0: RGBA8 and 24-bit depth renderbuffers with N samples, resolved by a blit.
//! * ES 2.0 with `GL_EXT_multisampled_render_to_texture` (Mali, Adreno, PowerVR): an RGBA8
//!   texture attached with N samples — a tile-based GPU keeps the samples on chip and writes
//!   only their average to the texture — and a depth renderbuffer with N samples
//!   (`glRenderbufferStorageMultisampleEXT`; 24-bit with `OES_depth24`, else 16); the
//!   texture is then copied onto the destination by a full-screen triangle, which leaves the
//!   destination bound with the copy's viewport, program, texture unit 0 and depth state (the
//!   renderer restores none of those after any pass). Without the extension MSAA is
//!   unsupported there, with that reason.
#![allow(unsafe_code)]

use glow::HasContext;

use super::caps::MSAA_RENDER_TO_TEXTURE;
use super::mesh::{fullscreen_triangle, GpuMesh};
use super::program::{ProgramCache, ProgramKey, Resolver, Sampler, Uniform, UniformSet};
use super::state::RenderState;
use super::target_size::{self, TargetStorage};
use super::{Device, EsVersion, GlError};

#[cfg(test)]
mod resolve_tests;

/// A framebuffer whose colour and depth have several samples per pixel.
pub struct MultisampleTarget {
    fbo: glow::Framebuffer,
    color: Color,
    depth: glow::Renderbuffer,
    size: (u32, u32),
    /// The buffers' size: `size`, or for ES 2.0's texture on a context refusing render targets
    /// of other sizes ([`Caps::npot_targets`](super::Caps::npot_targets)) the powers of two
    /// above it, the frame in their lower-left corner.
    storage: (u32, u32),
    /// The samples asked for.
    samples: u32,
    /// The samples the implementation gave: GL rounds a count it lacks up to one it has.
    samples_drawn: u32,
    /// ES 3.0: the colour renderbuffers' format, `SRGB8_ALPHA8` for a destination that
    /// encodes sRGB (a multisampled blit needs identical formats), else `RGBA8`.
    color_format: u32,
    /// Bytes of one depth sample.
    depth_bytes: usize,
    /// ES 3.0, resolving to an origin other than (0, 0) or into another colour format: a
    /// single-sampled copy the samples are resolved into first, made when first needed (GL
    /// blits a multisampled source only onto the same rectangle of the same format).
    resolved_copy: Option<(glow::Framebuffer, glow::Renderbuffer)>,
    /// A full-screen triangle: ES 2.0's resolve draws with it (made with the target), and
    /// [`MultisampleTarget::fill`] (made when first needed).
    triangle: Option<GpuMesh>,
    destroyed: bool,
}

/// Where the colour samples live.
enum Color {
    /// ES 3.0: a multisampled renderbuffer, resolved by a blit.
    Renderbuffer(glow::Renderbuffer),
    /// ES 2.0 with `GL_EXT_multisampled_render_to_texture`: a single-sampled texture the driver
    /// averages the samples into when the framebuffer is flushed, then copied to the
    /// destination by the target's full-screen triangle (ES 2.0 has no blit).
    Texture(glow::Texture),
}

impl Color {
    /// The colour storage this context uses (its storage is allocated by the caller).
    fn new(dev: &Device) -> Result<Color, GlError> {
        if dev.es() == EsVersion::Es3 {
            Ok(Color::Renderbuffer(dev.create_renderbuffer()?))
        } else {
            Ok(Color::Texture(dev.create_texture()?))
        }
    }
}

/// Why `samples` cannot be used on this context, if it cannot (1 always can).
pub fn unsupported_reason(dev: &Device, samples: u32) -> Option<String> {
    if samples <= 1 {
        return None;
    }
    let caps = dev.caps();
    if dev.es() != EsVersion::Es3 && !caps.msaa_render_to_texture {
        return Some(format!(
            "MSAA needs OpenGL ES 3.0 multisampled renderbuffers, or on ES 2.0 {MSAA_RENDER_TO_TEXTURE}, \
             which this context does not have"
        ));
    }
    let max = caps.max_samples.max(0) as u32;
    if samples > max {
        return Some(format!(
            "{samples} samples is more than this context's GL_MAX_SAMPLES ({max})"
        ));
    }
    None
}

impl MultisampleTarget {
    /// A `width × height` target with `samples` samples per pixel (at least 2).
    pub fn new(dev: &Device, width: u32, height: u32, samples: u32) -> Result<Self, GlError> {
        Self::with_encoding(dev, width, height, samples, false)
    }

    /// [`MultisampleTarget::new`], its colour encoded as sRGB on ES 3.0 with `srgb` (to be
    /// resolved into an sRGB destination; the frame is then drawn with linear output).
    pub fn with_encoding(
        dev: &Device,
        width: u32,
        height: u32,
        samples: u32,
        srgb: bool,
    ) -> Result<Self, GlError> {
        if let Some(reason) = unsupported_reason(dev, samples) {
            return Err(GlError::Unsupported(reason));
        }
        let storage = TargetStorage {
            textures: dev.es() != EsVersion::Es3,
            renderbuffers: true,
        };
        target_size::check(dev.caps(), "an MSAA target", (width, height), storage)?;
        let gl = &dev.gl;
        let (w, h) = (width as i32, height as i32);
        // Created one by one; whatever was made is freed if a later one fails.
        let depth = dev.create_renderbuffer()?;
        let fbo = match dev.create_framebuffer() {
            Ok(fbo) => fbo,
            Err(e) => {
                dev.delete_renderbuffer(depth);
                return Err(e);
            }
        };
        let color = match Color::new(dev) {
            Ok(color) => color,
            Err(e) => {
                dev.delete_framebuffer(fbo);
                dev.delete_renderbuffer(depth);
                return Err(e);
            }
        };
        let mut target = MultisampleTarget {
            fbo,
            color,
            depth,
            size: (width, height),
            storage: match dev.es() {
                EsVersion::Es3 => (width, height),
                EsVersion::Es2 => target_size::texture_storage(dev.caps(), (width, height)),
            },
            samples,
            samples_drawn: samples,
            color_format: if srgb && dev.es() == EsVersion::Es3 {
                glow::SRGB8_ALPHA8
            } else {
                glow::RGBA8
            },
            depth_bytes: if dev.caps().own_depth_format().1 > 16 {
                4
            } else {
                2
            },
            resolved_copy: None,
            triangle: None,
            destroyed: false,
        };
        if let Color::Texture(_) = target.color {
            match GpuMesh::new(dev, &fullscreen_triangle()) {
                Ok(triangle) => target.triangle = Some(triangle),
                Err(e) => {
                    target.destroy(dev);
                    return Err(e);
                }
            }
        }
        unsafe {
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
            match &target.color {
                Color::Renderbuffer(color) => {
                    gl.bind_renderbuffer(glow::RENDERBUFFER, Some(*color));
                    gl.renderbuffer_storage_multisample(
                        glow::RENDERBUFFER,
                        samples as i32,
                        target.color_format,
                        w,
                        h,
                    );
                    gl.framebuffer_renderbuffer(
                        glow::FRAMEBUFFER,
                        glow::COLOR_ATTACHMENT0,
                        glow::RENDERBUFFER,
                        Some(*color),
                    );
                    gl.bind_renderbuffer(glow::RENDERBUFFER, Some(depth));
                    gl.renderbuffer_storage_multisample(
                        glow::RENDERBUFFER,
                        samples as i32,
                        glow::DEPTH_COMPONENT24,
                        w,
                        h,
                    );
                }
                Color::Texture(texture) => {
                    // The depth as large as the texture: ES 2.0 needs that.
                    let (sw, sh) = (target.storage.0 as i32, target.storage.1 as i32);
                    gl.bind_texture(glow::TEXTURE_2D, Some(*texture));
                    gl.tex_image_2d(
                        glow::TEXTURE_2D,
                        0,
                        glow::RGBA as i32,
                        sw,
                        sh,
                        0,
                        glow::RGBA,
                        glow::UNSIGNED_BYTE,
                        glow::PixelUnpackData::Slice(None),
                    );
                    for (name, value) in [
                        (glow::TEXTURE_MIN_FILTER, glow::NEAREST),
                        (glow::TEXTURE_MAG_FILTER, glow::NEAREST),
                        (glow::TEXTURE_WRAP_S, glow::CLAMP_TO_EDGE),
                        (glow::TEXTURE_WRAP_T, glow::CLAMP_TO_EDGE),
                    ] {
                        gl.tex_parameter_i32(glow::TEXTURE_2D, name, value as i32);
                    }
                    gl.framebuffer_texture_2d_multisample(
                        glow::FRAMEBUFFER,
                        glow::COLOR_ATTACHMENT0,
                        glow::TEXTURE_2D,
                        Some(*texture),
                        0,
                        samples as i32,
                    );
                    let storage = dev
                        .renderbuffer_storage_multisample_ext
                        .expect("loaded with the extension (see unsupported_reason)");
                    gl.bind_renderbuffer(glow::RENDERBUFFER, Some(depth));
                    // The single-sampled target's depth: the same precision with MSAA as
                    // without.
                    let (format, _) = dev.caps().own_depth_format();
                    storage(glow::RENDERBUFFER, samples as i32, format, sw, sh);
                }
            }
            gl.framebuffer_renderbuffer(
                glow::FRAMEBUFFER,
                glow::DEPTH_ATTACHMENT,
                glow::RENDERBUFFER,
                Some(depth),
            );
            // Out of memory is an error naming the size, not an incomplete framebuffer.
            let what = format!("a {width}×{height} target with {samples} samples");
            if let Err(e) = dev.check(&format!("allocating {what}")) {
                target.destroy(dev);
                return Err(e);
            }
            let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
            if status != glow::FRAMEBUFFER_COMPLETE {
                let e = dev.incomplete_framebuffer(what, status);
                target.destroy(dev);
                return Err(e);
            }
            // At least the count asked for (a driver saying less is not believed).
            let drawn = gl.get_parameter_i32(glow::SAMPLES);
            target.samples_drawn = u32::try_from(drawn).unwrap_or(0).max(samples);
        }
        if let Err(e) = dev.check("multisampled target creation") {
            target.destroy(dev);
            return Err(e);
        }
        Ok(target)
    }

    /// Size in pixels and samples per pixel asked for.
    pub fn shape(&self) -> ((u32, u32), u32) {
        (self.size, self.samples)
    }

    /// Whether the colour samples are stored sRGB-encoded (see [`Self::with_encoding`]).
    pub fn is_srgb(&self) -> bool {
        self.color_format == glow::SRGB8_ALPHA8
    }

    /// Samples per pixel the implementation gave (at least those asked for).
    pub fn samples_drawn(&self) -> u32 {
        self.samples_drawn
    }

    /// GPU memory of its buffers: 4 bytes of colour and 4 of depth per sample (2 of depth on
    /// ES 2.0 without `OES_depth24`), and on ES 2.0 the 4-byte resolved texel (on ES 3.0 the
    /// 4-byte copy, once a frame was resolved to an origin other than (0, 0)) — what an
    /// immediate-mode GPU allocates; a tile-based one keeps the samples on chip.
    pub fn gpu_bytes(&self) -> usize {
        let pixels = self.storage.0 as usize * self.storage.1 as usize;
        let per_sample = 4 + self.depth_bytes;
        let copy = if self.resolved_copy.is_some() { 4 } else { 0 };
        match self.color {
            Color::Renderbuffer(_) => pixels * (self.samples_drawn as usize * per_sample + copy),
            Color::Texture(_) => pixels * (self.samples_drawn as usize * per_sample + 4),
        }
    }

    /// Its framebuffer object.
    pub fn fbo(&self) -> glow::Framebuffer {
        self.fbo
    }

    /// Binds the target and sets the viewport to cover it.
    pub fn bind(&self, dev: &Device) {
        unsafe { dev.gl.bind_framebuffer(glow::FRAMEBUFFER, Some(self.fbo)) };
        dev.viewport(0, 0, self.size.0 as i32, self.size.1 as i32);
    }

    /// Resolves the samples into the target-sized rectangle at `origin` of the framebuffer
    /// `into` (`None`: the default one): each pixel the average of its samples. Leaves `into`
    /// bound. ES 3.0 blits: straight into `into` where `same_format` (its colour is RGBA8, or
    /// SRGB8_ALPHA8 for a target made sRGB: a multisample resolve needs identical formats) and
    /// `origin` is (0, 0), else through a single-sampled copy, whose blit converts to any
    /// normalized format (`RGB8`, `RGB565`), and through the copy too where the driver refuses
    /// the direct blit (a format it reports as RGBA8 but is not); ES 2.0 draws the averaged texture over it with a
    /// program from `programs`.
    pub fn resolve(
        &mut self,
        dev: &Device,
        programs: &mut ProgramCache,
        into: Option<glow::Framebuffer>,
        origin: [u32; 2],
        same_format: bool,
    ) -> Result<(), GlError> {
        let (w, h) = (self.size.0 as i32, self.size.1 as i32);
        let colour = glow::COLOR_BUFFER_BIT;
        match &self.color {
            Color::Renderbuffer(_) if origin == [0, 0] && same_format => {
                // The frame's own errors first: the blit's are read alone below.
                dev.check("the frame before its MSAA resolve")?;
                dev.blit(self.fbo, into, self.size, [0, 0], colour);
                // NVIDIA says 8 bits a channel for an `RGBA4` destination it stores as RGBA8,
                // then refuses the resolve because the formats asked for differ.
                match dev.check("MSAA resolve") {
                    Err(GlError::Driver { code, .. }) if code == glow::INVALID_OPERATION => {
                        self.resolve_through_copy(dev, into, origin)?
                    }
                    // Checked: nothing more to check after it.
                    other => return other,
                }
            }
            Color::Renderbuffer(_) => self.resolve_through_copy(dev, into, origin)?,
            Color::Texture(texture) => {
                // Unbinding the framebuffer is what makes the driver average the samples into
                // the texture.
                dev.bind_framebuffer(into);
                dev.viewport(origin[0] as i32, origin[1] as i32, w, h);
                let uniforms: &ResolveUniforms = full_screen(dev, programs, "msaa_resolve")?;
                unsafe {
                    dev.gl.active_texture(glow::TEXTURE0);
                    dev.gl.bind_texture(glow::TEXTURE_2D, Some(*texture));
                }
                uniforms.resolved.set(dev, 0);
                let frame_part = [
                    self.size.0 as f32 / self.storage.0 as f32,
                    self.size.1 as f32 / self.storage.1 as f32,
                ];
                uniforms.frame_part.set(dev, frame_part);
                let triangle = self.triangle.as_ref();
                triangle.expect("made with the ES 2.0 target").draw(dev);
            }
        }
        dev.check("MSAA resolve (the destination must be single-sampled and hold the frame)")
    }

    /// Draws `color` (linear: the target encodes it) over every sample of the bound target,
    /// where a sRGB one's `glClear` does not reach them all
    /// ([`Caps::clears_one_sample_of_srgb_msaa`](super::Caps::clears_one_sample_of_srgb_msaa));
    /// a no-op elsewhere. The caller's clear follows as usual. Leaves the full-screen state
    /// and the solid program bound.
    pub fn fill(
        &mut self,
        dev: &Device,
        programs: &mut ProgramCache,
        color: [f32; 4],
    ) -> Result<(), GlError> {
        if !self.is_srgb() || !dev.caps().clears_one_sample_of_srgb_msaa() {
            return Ok(());
        }
        if self.triangle.is_none() {
            self.triangle = Some(GpuMesh::new(dev, &fullscreen_triangle())?);
        }
        dev.viewport(0, 0, self.size.0 as i32, self.size.1 as i32);
        let uniforms: &SolidUniforms = full_screen(dev, programs, "solid")?;
        uniforms.color.set(dev, glam::Vec4::from_array(color));
        self.triangle.as_ref().expect("made above").draw(dev);
        dev.check("filling an sRGB MSAA target")
    }

    /// ES 3.0's resolve into another format or rectangle: the samples into the single-sampled
    /// copy, whose blit then converts to the destination's normalized format.
    fn resolve_through_copy(
        &mut self,
        dev: &Device,
        into: Option<glow::Framebuffer>,
        origin: [u32; 2],
    ) -> Result<(), GlError> {
        let copy = self.resolved_copy(dev)?;
        let colour = glow::COLOR_BUFFER_BIT;
        dev.blit(self.fbo, Some(copy), self.size, [0, 0], colour);
        dev.blit(copy, into, self.size, origin, colour);
        Ok(())
    }

    /// The single-sampled copy (made now if it is not yet): its framebuffer.
    fn resolved_copy(&mut self, dev: &Device) -> Result<glow::Framebuffer, GlError> {
        if let Some((fbo, _)) = self.resolved_copy {
            return Ok(fbo);
        }
        let colour = dev.create_renderbuffer()?;
        let fbo = match dev.create_framebuffer() {
            Ok(fbo) => fbo,
            Err(e) => {
                dev.delete_renderbuffer(colour);
                return Err(e);
            }
        };
        let (w, h) = (self.size.0 as i32, self.size.1 as i32);
        unsafe {
            dev.gl.bind_renderbuffer(glow::RENDERBUFFER, Some(colour));
            dev.gl
                .renderbuffer_storage(glow::RENDERBUFFER, self.color_format, w, h);
            dev.gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
            dev.gl.framebuffer_renderbuffer(
                glow::FRAMEBUFFER,
                glow::COLOR_ATTACHMENT0,
                glow::RENDERBUFFER,
                Some(colour),
            );
        }
        // Kept only once complete: a failed one (out of memory) is freed, and the next frame
        // tries again.
        let status = unsafe { dev.gl.check_framebuffer_status(glow::FRAMEBUFFER) };
        let complete = if status == glow::FRAMEBUFFER_COMPLETE {
            Ok(())
        } else {
            Err(dev.incomplete_framebuffer(format!("the MSAA resolve's {w}×{h} copy"), status))
        };
        let made = dev
            .check("allocating the MSAA resolve's copy")
            .and(complete);
        if let Err(e) = made {
            dev.delete_framebuffer(fbo);
            dev.delete_renderbuffer(colour);
            return Err(e);
        }
        self.resolved_copy = Some((fbo, colour));
        Ok(fbo)
    }

    /// Frees the framebuffer and its buffers.
    pub fn destroy(&mut self, dev: &Device) {
        if !self.destroyed {
            dev.delete_framebuffer(self.fbo);
            match &mut self.color {
                Color::Renderbuffer(color) => dev.delete_renderbuffer(*color),
                Color::Texture(texture) => dev.delete_texture(*texture),
            }
            dev.delete_renderbuffer(self.depth);
            if let Some((fbo, colour)) = self.resolved_copy.take() {
                dev.delete_framebuffer(fbo);
                dev.delete_renderbuffer(colour);
            }
            if let Some(mut triangle) = self.triangle.take() {
                triangle.destroy(dev);
            }
            self.destroyed = true;
        }
    }
}

/// Builds the program [`MultisampleTarget::fill`] draws an sRGB target's background with, for a
/// warm-up whose own frames draw into no sRGB target.
pub(crate) fn build_fill_program(dev: &Device, programs: &mut ProgramCache) -> Result<(), GlError> {
    full_screen::<SolidUniforms>(dev, programs, "solid").map(|_| ())
}

/// Sets the full-screen state and binds `shader`'s one variant from `programs`.
fn full_screen<'p, U: UniformSet>(
    dev: &Device,
    programs: &'p mut ProgramCache,
    shader: &'static str,
) -> Result<&'p U, GlError> {
    RenderState::FULL_SCREEN.apply(dev);
    let key = ProgramKey {
        shader,
        features: 0,
        dialect: dev.es(),
    };
    programs.bind::<U>(dev, key, Vec::new)
}

/// The solid program's colour ([`MultisampleTarget::fill`]).
struct SolidUniforms {
    color: Uniform<glam::Vec4>,
}

impl UniformSet for SolidUniforms {
    fn resolve(r: &mut Resolver<'_>) -> Self {
        SolidUniforms {
            color: r.required("u_color"),
        }
    }
}

/// The ES 2.0 resolve program's texture of averaged samples.
struct ResolveUniforms {
    resolved: Uniform<Sampler>,
    frame_part: Uniform<[f32; 2]>,
}

impl UniformSet for ResolveUniforms {
    fn resolve(r: &mut Resolver<'_>) -> Self {
        ResolveUniforms {
            resolved: r.required("u_resolved"),
            frame_part: r.required("u_framePart"),
        }
    }
}

impl Drop for MultisampleTarget {
    fn drop(&mut self) {
        if !self.destroyed && !super::left_objects::left_on_purpose() {
            log::warn!("MultisampleTarget dropped without destroy(): GL objects leaked");
        }
    }
}
