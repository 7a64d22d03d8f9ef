//! A glow context plus its capabilities, and the frame-level calls every pass needs.
#![allow(unsafe_code)]

use glow::HasContext;

use super::{Caps, EsVersion, GlError, Restrictions};

/// The GL context the renderer draws with. Created from a glow context the caller owns (a
/// game's, or [`super::HeadlessContext::load_gl`]) and the ES level to restrict itself to.
pub struct Device {
    pub(crate) gl: glow::Context,
    caps: Caps,
    live: std::cell::Cell<LiveObjects>,
    /// `glRenderbufferStorageMultisampleEXT`, on ES 2.0 with
    /// `GL_EXT_multisampled_render_to_texture` (see [`super::ext_fns`]).
    pub(crate) renderbuffer_storage_multisample_ext:
        Option<super::ext_fns::RenderbufferStorageMultisampleExt>,
}

/// GL objects currently alive, as counted by the renderer's own create/delete calls: what
/// tests use to check that switching methods frees the previous method's resources.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct LiveObjects {
    /// Textures.
    pub textures: i64,
    /// Buffers.
    pub buffers: i64,
    /// Framebuffers.
    pub framebuffers: i64,
    /// Renderbuffers.
    pub renderbuffers: i64,
    /// Programs.
    pub programs: i64,
}

macro_rules! tracked {
    ($create:ident, $delete:ident, $ty:ty, $field:ident) => {
        pub(crate) fn $create(&self) -> Result<$ty, GlError> {
            let object = unsafe { self.gl.$create() }.map_err(creation_failed)?;
            self.count(|l| l.$field += 1);
            Ok(object)
        }

        pub(crate) fn $delete(&self, object: $ty) {
            unsafe { self.gl.$delete(object) };
            self.count(|l| l.$field -= 1);
        }
    };
}

/// A creation error, or the usual cause when EGL says no context is current here: the context
/// (a `HeadlessContext`, say) was dropped, or another made current, while the renderer lived.
fn creation_failed(reason: String) -> GlError {
    if super::gles_lib::no_current_context() {
        GlError::NotCurrent
    } else {
        GlError::Create(reason)
    }
}

impl Device {
    /// Wraps a current glow context and probes its capabilities.
    pub fn new(gl: glow::Context, es: EsVersion) -> Result<Device, GlError> {
        Device::restricted(gl, es, &Restrictions::default())
    }

    /// [`Device::new`] playing a weaker device (see [`Restrictions`]).
    pub fn restricted(
        gl: glow::Context,
        es: EsVersion,
        restrictions: &Restrictions,
    ) -> Result<Device, GlError> {
        let mut caps = Caps::probe(&gl, es)?;
        caps.restrict(restrictions)?;
        if caps.desktop {
            // A core profile draws nothing without a bound vertex array object; ES needs none.
            unsafe {
                let vao = gl.create_vertex_array().map_err(GlError::Create)?;
                gl.bind_vertex_array(Some(vao));
            }
        }
        let renderbuffer_storage_multisample_ext = if caps.msaa_render_to_texture {
            let f = super::ext_fns::renderbuffer_storage_multisample_ext();
            if f.is_none() {
                log::warn!(
                    "GL_EXT_multisampled_render_to_texture is listed but \
                     glRenderbufferStorageMultisampleEXT could not be loaded through EGL: \
                     no MSAA on this context"
                );
                caps.msaa_render_to_texture = false;
                caps.max_samples = 0;
            }
            f
        } else {
            None
        };
        Ok(Device {
            gl,
            caps,
            live: std::cell::Cell::new(LiveObjects::default()),
            renderbuffer_storage_multisample_ext,
        })
    }

    /// GL objects alive now (created and not yet deleted by this crate).
    pub fn live_objects(&self) -> LiveObjects {
        self.live.get()
    }

    /// Counts `n` programs built by another device on this context as this one's (a negative
    /// `n`: handed to another), for `Renderer::adopt_programs` (with `lab`).
    pub(crate) fn count_handed_programs(&self, n: i64) {
        self.count(|l| l.programs += n);
    }

    fn count(&self, f: impl FnOnce(&mut LiveObjects)) {
        let mut l = self.live.get();
        f(&mut l);
        self.live.set(l);
    }

    tracked!(create_texture, delete_texture, glow::Texture, textures);
    tracked!(create_buffer, delete_buffer, glow::Buffer, buffers);
    tracked!(
        create_framebuffer,
        delete_framebuffer,
        glow::Framebuffer,
        framebuffers
    );
    tracked!(
        create_renderbuffer,
        delete_renderbuffer,
        glow::Renderbuffer,
        renderbuffers
    );
    tracked!(create_program, delete_program, glow::Program, programs);

    /// The probed capabilities.
    pub fn caps(&self) -> &Caps {
        &self.caps
    }

    /// The feature level in use.
    pub fn es(&self) -> EsVersion {
        self.caps.es
    }

    /// Sets the viewport.
    pub fn viewport(&self, x: i32, y: i32, width: i32, height: i32) {
        unsafe { self.gl.viewport(x, y, width, height) }
    }

    /// Clears colour and depth of the bound framebuffer.
    pub fn clear(&self, color: [f32; 4]) {
        unsafe {
            self.gl.color_mask(true, true, true, true);
            self.gl.depth_mask(true);
            self.gl.clear_color(color[0], color[1], color[2], color[3]);
            self.gl.clear_depth_f32(1.0);
            self.gl
                .clear(glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT);
        }
    }

    /// Clears only the colour of the bound framebuffer (its depth, if any, is kept).
    pub fn clear_color_only(&self, color: [f32; 4]) {
        unsafe {
            self.gl.color_mask(true, true, true, true);
            self.gl.clear_color(color[0], color[1], color[2], color[3]);
            self.gl.clear(glow::COLOR_BUFFER_BIT);
        }
    }

    /// Blocks until the GPU has finished all submitted work (wall-clock frame timing).
    pub fn finish(&self) {
        unsafe { self.gl.finish() }
    }

    /// The framebuffer bound now (`None`: the default one, a window's back buffer).
    pub fn bound_framebuffer(&self) -> Option<glow::Framebuffer> {
        unsafe { self.gl.get_parameter_framebuffer(glow::FRAMEBUFFER_BINDING) }
    }

    /// Binds `fbo` (`None`: the default framebuffer).
    pub fn bind_framebuffer(&self, fbo: Option<glow::Framebuffer>) {
        unsafe { self.gl.bind_framebuffer(glow::FRAMEBUFFER, fbo) }
    }

    /// Copies the buffers of `mask` (`glow::COLOR_BUFFER_BIT`, `DEPTH_BUFFER_BIT`) of the
    /// framebuffer `from` into `into` (`None`: the default one), both `size` pixels, nearest
    /// (ES 3.0: a multisampled source is resolved); leaves `into` bound.
    pub fn blit(
        &self,
        from: glow::Framebuffer,
        into: Option<glow::Framebuffer>,
        (width, height): (u32, u32),
        mask: u32,
    ) {
        let (w, h) = (width as i32, height as i32);
        unsafe {
            self.gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(from));
            self.gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, into);
            self.gl
                .blit_framebuffer(0, 0, w, h, 0, 0, w, h, mask, glow::NEAREST);
        }
        self.bind_framebuffer(into);
    }

    /// Binds the default framebuffer (a window's back buffer).
    pub fn bind_default_framebuffer(&self) {
        unsafe { self.gl.bind_framebuffer(glow::FRAMEBUFFER, None) }
    }

    /// Returns the first pending GL error as [`GlError::Driver`], draining the queue.
    pub fn check(&self, what: &str) -> Result<(), GlError> {
        let code = unsafe { self.gl.get_error() };
        if code == glow::NO_ERROR {
            return Ok(());
        }
        unsafe { while self.gl.get_error() != glow::NO_ERROR {} }
        if code == glow::OUT_OF_MEMORY {
            return Err(GlError::OutOfMemory(format!(
                "the driver reported GL_OUT_OF_MEMORY after {what}"
            )));
        }
        Err(GlError::Driver {
            what: what.to_string(),
            name: error_name(code),
            code,
        })
    }
}

/// Debug builds check `glGetError` after the wrapped step and panic with its decoded name;
/// release builds compile it out (one check per frame still runs via [`Device::check`]).
macro_rules! gl_check {
    ($device:expr, $what:expr) => {
        #[cfg(debug_assertions)]
        if let Err(e) = $device.check($what) {
            panic!("{e}");
        }
    };
}
pub(crate) use gl_check;

/// Name of a `glGetError` code.
pub fn error_name(code: u32) -> &'static str {
    match code {
        glow::INVALID_ENUM => "GL_INVALID_ENUM",
        glow::INVALID_VALUE => "GL_INVALID_VALUE",
        glow::INVALID_OPERATION => "GL_INVALID_OPERATION",
        glow::INVALID_FRAMEBUFFER_OPERATION => "GL_INVALID_FRAMEBUFFER_OPERATION",
        glow::OUT_OF_MEMORY => "GL_OUT_OF_MEMORY",
        _ => "unknown GL error",
    }
}
