//! The draw buffers of the framebuffer a game left bound (ES 3.0 and desktop state). The
//! renderer's shaders write one colour output, which reaches draw buffer 0 only: a game's
//! further draw buffers (a deferred or MRT target left bound) would take undefined values,
//! and an MSAA resolve would blit the frame into them too. So during a call the bound draw
//! framebuffer draws into its attachment 0 alone (the back buffer for the default one), and
//! the game's list is given back after.
#![allow(unsafe_code)]

use glow::HasContext;

/// Draw buffers saved: `GL_MAX_DRAW_BUFFERS` is 8 on common drivers, at least 4 on ES 3.0.
const MOST: usize = 16;

/// The game's draw-buffer list, where a call changed it.
pub(crate) struct HostDrawBuffers {
    buffers: [u32; MOST],
    count: usize,
}

impl HostDrawBuffers {
    /// Points the bound draw framebuffer's (`bound`) draw buffer 0 at its attachment 0
    /// (`GL_BACK` for the default framebuffer on ES; desktop GL's default one is left as it is)
    /// and the others at nothing, where they are not already; returns the game's list to give
    /// back then. `most`: `GL_MAX_DRAW_BUFFERS`.
    pub(crate) fn enter(
        gl: &glow::Context,
        desktop: bool,
        bound: Option<glow::Framebuffer>,
        most: usize,
    ) -> Option<HostDrawBuffers> {
        unsafe {
            let object = bound.is_some();
            if !object && desktop {
                return None;
            }
            let (first, count) = if object {
                (glow::COLOR_ATTACHMENT0, most.clamp(1, MOST))
            } else {
                // A default framebuffer's list is one buffer long on ES.
                (glow::BACK, 1)
            };
            let mut buffers = [glow::NONE; MOST];
            for (i, buffer) in buffers.iter_mut().enumerate().take(count) {
                *buffer = gl.get_parameter_i32(glow::DRAW_BUFFER0 + i as u32) as u32;
            }
            let wanted = |i: usize| if i == 0 { first } else { glow::NONE };
            if buffers[..count]
                .iter()
                .enumerate()
                .all(|(i, &b)| b == wanted(i))
            {
                return None;
            }
            gl.draw_buffers(&[first]);
            Some(HostDrawBuffers { buffers, count })
        }
    }

    /// Gives the game its list back, with its draw framebuffer bound again.
    pub(crate) fn leave(&self, gl: &glow::Context) {
        unsafe { gl.draw_buffers(&self.buffers[..self.count]) }
    }
}
