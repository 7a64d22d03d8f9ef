//! What the bound framebuffer is: the checks a frame makes of a game's framebuffer before
//! drawing into it (its colour encoding and format, samples, depth bits). Each query's error is
//! drained, and a driver that will not say gives `None` or the cautious answer.
#![allow(unsafe_code)]

use glow::HasContext;

use super::{Device, EsVersion};

impl Device {
    /// Whether the bound framebuffer's colour buffer encodes sRGB on write
    /// (`GL_FRAMEBUFFER_ATTACHMENT_COLOR_ENCODING`: an `SRGB8_ALPHA8` attachment, or a window
    /// surface made with an sRGB colour space). ES 3.0, and ES 2.0 with `GL_EXT_sRGB`; never
    /// on desktop GL, whose encoding the renderer's calls switch off (`GL_FRAMEBUFFER_SRGB`).
    pub(crate) fn bound_color_is_srgb(&self) -> bool {
        let caps = self.caps();
        if caps.desktop || !(caps.context_has_es3_state() || caps.has_extension("GL_EXT_sRGB")) {
            return false;
        }
        let colour = [glow::COLOR_ATTACHMENT0, glow::BACK];
        let encoding = self.bound_attachment(colour, glow::FRAMEBUFFER_ATTACHMENT_COLOR_ENCODING);
        encoding == Some(Some(glow::SRGB as i32))
    }

    /// Whether the bound framebuffer object has nothing at `GL_COLOR_ATTACHMENT0`, where the
    /// frame goes (its shaders write one output, to draw buffer 0). False for the default
    /// framebuffer and where the driver would not say.
    pub(crate) fn bound_colour_zero_is_empty(&self) -> bool {
        if self.bound_framebuffer().is_none() {
            return false;
        }
        let colour = [glow::COLOR_ATTACHMENT0, glow::BACK];
        self.bound_attachment(colour, glow::FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE) == Some(None)
    }

    /// Whether the bound framebuffer's colour buffer stores fixed-point values, which clamp to
    /// [0, 1]: its component type on ES 3.0 (`GL_UNSIGNED_NORMALIZED`), at most 8 red bits on
    /// ES 2.0 (whose float colour buffers have 16 or 32). False on desktop GL and where the
    /// driver would not say.
    pub(crate) fn bound_color_is_fixed_point(&self) -> bool {
        let caps = self.caps();
        if caps.desktop {
            return false;
        }
        if caps.context_has_es3_state() {
            let colour = [glow::COLOR_ATTACHMENT0, glow::BACK];
            let kind = self.bound_attachment(colour, glow::FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE);
            return kind == Some(Some(glow::UNSIGNED_NORMALIZED as i32));
        }
        let bits = unsafe { self.gl.get_parameter_i32(glow::RED_BITS) };
        self.drain_errors() == glow::NO_ERROR && (1..=8).contains(&bits)
    }

    /// Samples per pixel of the bound framebuffer (`GL_SAMPLES`: 0 for a single-sampled
    /// one, and where the driver would not say).
    pub(crate) fn bound_samples(&self) -> i32 {
        let samples = unsafe { self.gl.get_parameter_i32(glow::SAMPLES) };
        if self.drain_errors() == glow::NO_ERROR {
            samples
        } else {
            0
        }
    }

    /// Whether the bound framebuffer's colour is 8-bit normalized RGBA (`RGBA8` or
    /// `SRGB8_ALPHA8`): what an ES 3.0 multisample resolve may blit into, which needs identical
    /// formats. False where it is not (`RGB8`, `RGB565`: a window surface without alpha) and
    /// where the driver would not say.
    pub(crate) fn bound_color_is_rgba8(&self) -> bool {
        if self.caps().desktop || !self.caps().context_has_es3_state() {
            return false;
        }
        let colour = [glow::COLOR_ATTACHMENT0, glow::BACK];
        let sizes = [
            glow::FRAMEBUFFER_ATTACHMENT_RED_SIZE,
            glow::FRAMEBUFFER_ATTACHMENT_GREEN_SIZE,
            glow::FRAMEBUFFER_ATTACHMENT_BLUE_SIZE,
            glow::FRAMEBUFFER_ATTACHMENT_ALPHA_SIZE,
        ];
        let normalized = self.bound_attachment(colour, glow::FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE)
            == Some(Some(glow::UNSIGNED_NORMALIZED as i32));
        normalized
            && sizes
                .iter()
                .all(|&size| self.bound_attachment(colour, size) == Some(Some(8)))
    }

    /// The depth bits of the bound framebuffer (0: no depth buffer); `None` where the driver
    /// would not say. ES 2.0 asks `GL_DEPTH_BITS`; ES 3.0 and desktop core (which dropped that
    /// query) ask the depth attachment.
    pub(crate) fn bound_depth_bits(&self) -> Option<i32> {
        if self.caps().es == EsVersion::Es2 && !self.caps().desktop {
            let bits = unsafe { self.gl.get_parameter_i32(glow::DEPTH_BITS) };
            return (self.drain_errors() == glow::NO_ERROR).then_some(bits);
        }
        let depth = [glow::DEPTH_ATTACHMENT, glow::DEPTH];
        self.bound_attachment(depth, glow::FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE)
            .map(|bits| bits.unwrap_or(0))
    }

    /// `pname` of the bound framebuffer's attachment (the first of `[in_object, in_default]`
    /// for a framebuffer object, the second for the default one): `Some(None)` where nothing
    /// is attached, `None` where the driver would not say (a surfaceless default framebuffer,
    /// ES 2.0's default one), its error drained.
    fn bound_attachment(
        &self,
        [in_object, in_default]: [u32; 2],
        pname: u32,
    ) -> Option<Option<i32>> {
        let attachment = if self.bound_framebuffer().is_some() {
            in_object
        } else {
            in_default
        };
        let param = |p| unsafe {
            self.gl
                .get_framebuffer_attachment_parameter_i32(glow::FRAMEBUFFER, attachment, p)
        };
        let attached = param(glow::FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE) != glow::NONE as i32;
        let value = attached.then(|| param(pname));
        (self.drain_errors() == glow::NO_ERROR).then_some(value)
    }
}
