//! What a frame needs of the framebuffer the application bound ([`Renderer::render`]): complete,
//! no larger than the driver's viewport, its colour at attachment 0 and not of integers, and
//! with a depth buffer when the frame is drawn in it (an MSAA frame brings its own and only
//! resolves there); a frame reaching past its colour buffer is warned of. Forward, tiled and
//! clustered draw with the depth test there, and so does deferred for transparent objects and
//! for a frame without lights; deferred's opaque composite alone does not, but one rule for
//! every method and frame is what the README asks of a game.

use super::Renderer;
use crate::gl::bound_framebuffer::TargetFormat;
use crate::gl::GlError;
use crate::{CountKind, Error, RenderOptions};

/// Depth bits below which surfaces close in depth show through (the README's 24).
const FULL_DEPTH_BITS: i32 = 24;

impl Renderer {
    /// Refuses a frame past `GL_MAX_VIEWPORT_DIMS`, which GL would clamp: into any target.
    pub(super) fn check_viewport_limit(&self, width: u32, height: u32) -> Result<(), Error> {
        let [max_w, max_h] = self.dev.caps().max_viewport_dims;
        if (max_w > 0 && width > max_w as u32) || (max_h > 0 && height > max_h as u32) {
            return Err(GlError::TooLarge {
                what: "a frame",
                width,
                height,
                limit: "GL_MAX_VIEWPORT_DIMS",
                max_width: max_w as u32,
                max_height: max_h as u32,
            }
            .into());
        }
        Ok(())
    }

    /// Refuses the bound framebuffer `target` (of `format`) where it cannot take a
    /// `width × height` frame; warns once of a shallow depth buffer. `drawn_here`: the frame is
    /// drawn in it (no MSAA of the renderer's); then its depth bits (24 where the driver would
    /// not say).
    pub(super) fn check_bound_target(
        &mut self,
        (target, format): (Option<glow::Framebuffer>, &TargetFormat),
        (width, height): (u32, u32),
        origin: [u32; 2],
        drawn_here: bool,
    ) -> Result<Option<u32>, Error> {
        self.check_viewport_limit(width, height)?;
        // Asked again for another framebuffer, or after a failed frame: one the game made
        // incomplete since fails its draws with GL_INVALID_FRAMEBUFFER_OPERATION, and the next
        // frame names why.
        let checked = matches!(self.complete_target.take(), Some(complete) if complete == target);
        let status = match checked {
            true => glow::FRAMEBUFFER_COMPLETE,
            false => self.dev.bound_framebuffer_status(),
        };
        self.dev
            .check_status_call(status, "the bound framebuffer")?;
        if status != glow::FRAMEBUFFER_COMPLETE {
            return Err(GlError::BoundFramebuffer(format!(
                "it is incomplete ({}; on a surfaceless context, framebuffer 0 has no surface: \
                 bind a framebuffer object of your own)",
                status_name(status)
            ))
            .into());
        }
        if format.colour_zero_empty {
            return Err(GlError::BoundFramebuffer(
                "it has no colour buffer at GL_COLOR_ATTACHMENT0, the one the frame is drawn \
                 into (a colour buffer at another attachment is not): attach it there"
                    .to_string(),
            )
            .into());
        }
        if !checked && self.dev.bound_colour_holds_integers(target) {
            return Err(GlError::BoundFramebuffer(
                "its colour buffer at GL_COLOR_ATTACHMENT0 stores integers (an RGBA8UI-like \
                 format), to which a frame's colours cannot be written: attach a normalized \
                 (RGBA8, SRGB8_ALPHA8) or float one"
                    .to_string(),
            )
            .into());
        }
        self.warn_past_bound_colour(target, (width, height), origin);
        if !drawn_here {
            return Ok(None);
        }
        let bits = format.depth_bits;
        match bits {
            Some(0) => {
                return Err(GlError::BoundFramebuffer(
                    "it has no depth buffer, which the frame is drawn against: attach one \
                     (24-bit; 16-bit loses precision), or render colour with MSAA, whose \
                     target has its own (light counts and the heatmap are drawn single-sampled)"
                        .to_string(),
                )
                .into())
            }
            Some(bits) if bits < FULL_DEPTH_BITS && !self.warned_depth_bits => {
                self.warned_depth_bits = true;
                log::warn!(
                    "the bound framebuffer's depth buffer has {bits} bits: surfaces close \
                     together in depth may show the one behind (a 24-bit one does not)"
                );
            }
            _ => {}
        }
        Ok(Some(bits.map_or(FULL_DEPTH_BITS, |b| b.max(0)) as u32))
    }

    /// Warns once of a frame reaching past the bound framebuffer object's colour buffer, where
    /// GL can say its size: GL draws only the part inside, and a game that did not resize its
    /// framebuffer with the window would see a cut frame with no error. Asked again only when
    /// the framebuffer or the frame's place in it changes, not every frame.
    fn warn_past_bound_colour(
        &mut self,
        target: Option<glow::Framebuffer>,
        (width, height): (u32, u32),
        [x, y]: [u32; 2],
    ) {
        let frame = Some((target, [x, y, width, height]));
        if self.warned_past_framebuffer || self.placed_in == frame {
            return;
        }
        self.placed_in = frame;
        let Some((w, h)) = self.dev.bound_color_size(target) else {
            return;
        };
        if u64::from(x) + u64::from(width) > u64::from(w)
            || u64::from(y) + u64::from(height) > u64::from(h)
        {
            self.warned_past_framebuffer = true;
            log::warn!(
                "the {width}×{height} frame at ({x}, {y}) reaches past the bound framebuffer's \
                 {w}×{h} colour buffer: only the part inside is drawn (a framebuffer not resized \
                 with the window?)"
            );
        }
    }

    /// Warns once of HDR colour into a fixed-point framebuffer (of `format`): its unclamped
    /// radiance is clamped to [0, 1] there, with neither exposure nor tone map applied.
    pub(super) fn warn_hdr_into_fixed_point(
        &mut self,
        options: &RenderOptions,
        format: &TargetFormat,
    ) {
        if !options.hdr
            || options.count != CountKind::None
            || self.warned_hdr_fixed_point
            || !format.fixed_point
        {
            return;
        }
        self.warned_hdr_fixed_point = true;
        log::warn!(
            "RenderOptions::hdr writes unclamped linear radiance, but the bound framebuffer's \
             colour is fixed-point: every value past 1 is clamped, untoned (bind a float colour \
             buffer such as RGBA16F, or leave hdr off to get the exposed, tone-mapped image)"
        );
    }

    /// Depth bits of the renderer's own targets, a 16-bit one warned of once.
    pub(super) fn own_depth_bits(&mut self) -> u32 {
        let (_, bits) = self.dev.caps().own_depth_format();
        if bits < FULL_DEPTH_BITS as u32 && !self.warned_own_depth_bits && !self.warming_up {
            self.warned_own_depth_bits = true;
            log::warn!(
                "the renderer's own depth buffer has {bits} bits on this context (it has \
                 neither GL_OES_depth24 nor GL_OES_packed_depth_stencil): surfaces close \
                 together in depth may show the one behind, whatever the method; a near plane \
                 as far out as the scene allows narrows it (docs/precision.md)"
            );
        }
        bits
    }
}

/// `glCheckFramebufferStatus`'s answer by name.
fn status_name(status: u32) -> String {
    let name = match status {
        glow::FRAMEBUFFER_UNDEFINED => "GL_FRAMEBUFFER_UNDEFINED",
        glow::FRAMEBUFFER_INCOMPLETE_ATTACHMENT => "GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT",
        glow::FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT => {
            "GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT"
        }
        // GL_FRAMEBUFFER_INCOMPLETE_DIMENSIONS (ES 2.0), not in glow's core list.
        0x8CD9 => "GL_FRAMEBUFFER_INCOMPLETE_DIMENSIONS",
        glow::FRAMEBUFFER_UNSUPPORTED => "GL_FRAMEBUFFER_UNSUPPORTED",
        glow::FRAMEBUFFER_INCOMPLETE_MULTISAMPLE => "GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE",
        _ => return format!("status 0x{status:04x}"),
    };
    format!("{name}, 0x{status:04x}")
}
