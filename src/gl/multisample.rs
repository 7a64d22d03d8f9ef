//! A multisampled offscreen target (ES 3.0: RGBA8 and depth renderbuffers with N samples),
//! rendered into and then resolved by a blit into a single-sampled framebuffer: the
//! renderer's offscreen target, or the caller's (a window's back buffer).
//! ES 2.0 core has no multisampled renderbuffers; its extensions for it are not used yet, so
//! MSAA is unsupported there with that reason.
#![allow(unsafe_code)]

use glow::HasContext;

use super::{Device, EsVersion, GlError};

/// A framebuffer of multisampled colour and depth renderbuffers.
pub struct MultisampleTarget {
    fbo: glow::Framebuffer,
    color: glow::Renderbuffer,
    depth: glow::Renderbuffer,
    size: (u32, u32),
    samples: u32,
    destroyed: bool,
}

/// Why `samples` cannot be used on this context, if it cannot (1 always can).
pub fn unsupported_reason(dev: &Device, samples: u32) -> Option<String> {
    if samples <= 1 {
        return None;
    }
    if dev.es() != EsVersion::Es3 {
        return Some(
            "MSAA needs OpenGL ES 3.0 multisampled renderbuffers (ES 2.0's \
             EXT_multisampled_render_to_texture is not used yet)"
                .into(),
        );
    }
    let max = dev.caps().max_samples.max(0) as u32;
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
        if let Some(reason) = unsupported_reason(dev, samples) {
            return Err(GlError::Unsupported(reason));
        }
        let gl = &dev.gl;
        let (w, h) = (width as i32, height as i32);
        let color = dev.create_renderbuffer()?;
        let depth = dev.create_renderbuffer()?;
        let fbo = dev.create_framebuffer()?;
        let mut target = MultisampleTarget {
            fbo,
            color,
            depth,
            size: (width, height),
            samples,
            destroyed: false,
        };
        unsafe {
            gl.bind_renderbuffer(glow::RENDERBUFFER, Some(color));
            gl.renderbuffer_storage_multisample(
                glow::RENDERBUFFER,
                samples as i32,
                glow::RGBA8,
                w,
                h,
            );
            gl.bind_renderbuffer(glow::RENDERBUFFER, Some(depth));
            gl.renderbuffer_storage_multisample(
                glow::RENDERBUFFER,
                samples as i32,
                glow::DEPTH_COMPONENT24,
                w,
                h,
            );
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
            gl.framebuffer_renderbuffer(
                glow::FRAMEBUFFER,
                glow::COLOR_ATTACHMENT0,
                glow::RENDERBUFFER,
                Some(color),
            );
            gl.framebuffer_renderbuffer(
                glow::FRAMEBUFFER,
                glow::DEPTH_ATTACHMENT,
                glow::RENDERBUFFER,
                Some(depth),
            );
            let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
            if status != glow::FRAMEBUFFER_COMPLETE {
                target.destroy(dev);
                return Err(GlError::FramebufferIncomplete(status));
            }
        }
        if let Err(e) = dev.check("multisampled target creation") {
            target.destroy(dev);
            return Err(e);
        }
        Ok(target)
    }

    /// Size in pixels and samples per pixel.
    pub fn shape(&self) -> ((u32, u32), u32) {
        (self.size, self.samples)
    }

    /// GPU memory of its buffers: 4 bytes of colour and 4 of depth per sample.
    pub fn gpu_bytes(&self) -> usize {
        self.size.0 as usize * self.size.1 as usize * self.samples as usize * 8
    }

    /// Binds the target and sets the viewport to cover it.
    pub fn bind(&self, dev: &Device) {
        unsafe { dev.gl.bind_framebuffer(glow::FRAMEBUFFER, Some(self.fbo)) };
        dev.viewport(0, 0, self.size.0 as i32, self.size.1 as i32);
    }

    /// Resolves the samples into the framebuffer `into` (`None`: the default one) of the same
    /// size: each pixel the average of its samples. Leaves `into` bound. The destination's
    /// colour format must be RGBA8, as ES 3.0's multisample resolve needs identical formats.
    pub fn resolve(&self, dev: &Device, into: Option<glow::Framebuffer>) -> Result<(), GlError> {
        let (w, h) = (self.size.0 as i32, self.size.1 as i32);
        unsafe {
            dev.gl
                .bind_framebuffer(glow::READ_FRAMEBUFFER, Some(self.fbo));
            dev.gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, into);
            dev.gl.blit_framebuffer(
                0,
                0,
                w,
                h,
                0,
                0,
                w,
                h,
                glow::COLOR_BUFFER_BIT,
                glow::NEAREST,
            );
        }
        dev.bind_framebuffer(into);
        dev.check("MSAA resolve (the destination must be RGBA8 and the same size)")
    }

    /// Frees the framebuffer and its renderbuffers.
    pub fn destroy(&mut self, dev: &Device) {
        if !self.destroyed {
            dev.delete_framebuffer(self.fbo);
            dev.delete_renderbuffer(self.color);
            dev.delete_renderbuffer(self.depth);
            self.destroyed = true;
        }
    }
}

impl Drop for MultisampleTarget {
    fn drop(&mut self) {
        if !self.destroyed {
            log::warn!("MultisampleTarget dropped without destroy(): GL objects leaked");
        }
    }
}
