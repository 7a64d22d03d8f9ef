//! [`GlStateHandling::Reset`](super::GlStateHandling::Reset): a renderer call that reads
//! nothing of the application's GL state but the framebuffer it bound. Each query waits for a
//! threaded driver's thread to catch up (Android's, ANGLE's, a browser's command buffer), and
//! saving the state is most of a frame's queries; an engine that sets its own state before
//! each of its draws has no use for it. So a call sets what the renderer depends on without
//! asking what it was, and leaves what it changed at GL's initial values.
#![allow(unsafe_code)]

use glow::HasContext;

use super::absent_attributes::ABSENT;
use super::host_attributes::LOCATIONS;
use super::host_state::{HostFeatures, OFF_INSIDE, TOGGLED};
use super::vertex_arrays::VertexArrays;

/// A call entered with [`GlStateHandling::Reset`](super::GlStateHandling::Reset): the
/// framebuffer the application had bound.
pub(crate) struct ResetEntry {
    draw_framebuffer: Option<glow::Framebuffer>,
}

impl ResetEntry {
    /// Reads the bound draw framebuffer and sets, without reading it, the state that
    /// `HostState::enter` sets (`host_state.rs` lists it) but the framebuffer's draw buffers:
    /// they are the framebuffer object's own, set only by a frame drawn into it
    /// ([`draw_into_attachment_0`]).
    pub(crate) fn enter(
        gl: &glow::Context,
        features: &HostFeatures,
        vao: Option<(glow::VertexArray, VertexArrays)>,
    ) -> Self {
        let f = features;
        unsafe {
            let binding = match f.es3 {
                true => glow::DRAW_FRAMEBUFFER_BINDING,
                false => glow::FRAMEBUFFER_BINDING,
            };
            let draw_framebuffer = gl.get_parameter_framebuffer(binding);
            if f.es3 {
                for unit in 0..f.units {
                    gl.bind_sampler(unit as u32, None);
                }
                gl.bind_buffer(glow::PIXEL_PACK_BUFFER, None);
                gl.bind_buffer(glow::PIXEL_UNPACK_BUFFER, None);
                gl.disable(glow::RASTERIZER_DISCARD);
            }
            gl.active_texture(glow::TEXTURE0);
            if f.desktop {
                gl.polygon_mode(glow::FRONT_AND_BACK, glow::FILL);
                gl.disable(glow::FRAMEBUFFER_SRGB);
                gl.disable(glow::PRIMITIVE_RESTART);
            }
            if f.fixed_index_restart {
                gl.disable(glow::PRIMITIVE_RESTART_FIXED_INDEX);
            }
            if f.sample_mask {
                gl.disable(glow::SAMPLE_MASK);
            }
            if f.sample_shading {
                gl.disable(glow::SAMPLE_SHADING);
            }
            if f.srgb_write_control {
                gl.enable(glow::FRAMEBUFFER_SRGB);
            }
            match vao {
                Some((vao, arrays)) => arrays.bind(gl, Some(vao)),
                None => no_divisors(f),
            }
            for p in f.rows() {
                gl.pixel_store_i32(p, 0);
            }
            for c in OFF_INSIDE {
                gl.disable(c);
            }
            gl.blend_equation(glow::FUNC_ADD);
            gl.front_face(glow::CCW);
            gl.depth_range(0.0, 1.0);
            gl.clear_depth(1.0);
            gl.color_mask(true, true, true, true);
            ResetEntry { draw_framebuffer }
        }
    }

    /// The framebuffer the application had bound for drawing (`None`: the default one).
    pub(crate) fn draw_framebuffer(&self) -> Option<glow::Framebuffer> {
        self.draw_framebuffer
    }

    /// Leaves what the renderer changes at GL's initial values, the application's framebuffer
    /// bound for drawing and reading. Its vertex array 0 is left as it was where the renderer
    /// drew with its own; without one, the arrays at the renderer's locations are disabled.
    pub(crate) fn leave(self, gl: &glow::Context, f: &HostFeatures, vao: Option<VertexArrays>) {
        unsafe {
            match vao {
                Some(arrays) => arrays.bind(gl, None),
                None => {
                    gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, None);
                    for location in 0..LOCATIONS as u32 {
                        gl.disable_vertex_attrib_array(location);
                    }
                }
            }
            for (location, _) in ABSENT {
                gl.vertex_attrib_4_f32(location, 0.0, 0.0, 0.0, 1.0);
            }
            gl.bind_buffer(glow::ARRAY_BUFFER, None);
            gl.use_program(None);
            for unit in (0..f.units).rev() {
                gl.active_texture(glow::TEXTURE0 + unit as u32);
                gl.bind_texture(glow::TEXTURE_2D, None);
            }
            // Its draw buffers are its own: a frame drawn into it set them
            // (`draw_into_attachment_0`), no other call.
            gl.bind_framebuffer(glow::FRAMEBUFFER, self.draw_framebuffer);
            gl.bind_renderbuffer(glow::RENDERBUFFER, None);
            for c in TOGGLED {
                gl.disable(c);
            }
            gl.blend_func(glow::ONE, glow::ZERO);
            gl.depth_func(glow::LESS);
            gl.depth_mask(true);
            // A call that failed between its depth prepass and its shading left it off.
            gl.color_mask(true, true, true, true);
            gl.cull_face(glow::BACK);
            gl.clear_color(0.0, 0.0, 0.0, 0.0);
            gl.pixel_store_i32(glow::PACK_ALIGNMENT, 4);
            gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 4);
        }
    }
}

/// Binds `target` for drawing and points its draw buffer 0 at its attachment 0 and no further
/// one (`host_draw_buffers.rs` says why), where the context has draw buffers (ES 3.0 state):
/// `GL_BACK` for ES's default framebuffer; desktop GL's default one is left as it is. For a
/// frame drawn into the application's framebuffer, whose draw buffers a reset call otherwise
/// leaves alone: they are that framebuffer object's state, not the context's.
pub(crate) fn draw_into_attachment_0(
    gl: &glow::Context,
    f: &HostFeatures,
    target: Option<glow::Framebuffer>,
) {
    if !f.es3 {
        return;
    }
    unsafe {
        gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, target);
        match (target, f.desktop) {
            (Some(_), _) => gl.draw_buffers(&[glow::COLOR_ATTACHMENT0]),
            (None, false) => gl.draw_buffers(&[glow::BACK]),
            (None, true) => {}
        }
    }
}

/// Sets the divisors of the arrays at the renderer's locations to 0, where an instanced-arrays
/// extension gives them (ES 2.0 without a vertex array of the renderer's own).
fn no_divisors(f: &HostFeatures) {
    if let Some(set) = f.divisor {
        for location in 0..LOCATIONS as u32 {
            // SAFETY: the extension's entry point, for a location below the context's 8.
            unsafe { set(location, 0) };
        }
    }
}
