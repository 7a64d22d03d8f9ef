//! What the bound framebuffer is: the checks a frame makes of a game's framebuffer before
//! drawing into it (its colour encoding and format, samples, depth bits), read once a frame.
//! The queries are drained of errors once together; where a driver refused one, they are
//! asked again (and from then on) with a drain each, the colour attachment's parameters
//! together, and one it will not answer gives `None` or the cautious answer.
#![allow(unsafe_code)]

use glow::HasContext;

use super::{Device, EsVersion};

/// What a frame needs to know of the framebuffer it draws into.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct TargetFormat {
    /// Samples per pixel (`GL_SAMPLES`: 0 for a single-sampled framebuffer, and where the
    /// driver would not say).
    pub samples: i32,
    /// A framebuffer object with nothing at `GL_COLOR_ATTACHMENT0`, where the frame goes (its
    /// shaders write one output, to draw buffer 0). False for the default framebuffer.
    pub colour_zero_empty: bool,
    /// The colour buffer encodes sRGB on write (`GL_FRAMEBUFFER_ATTACHMENT_COLOR_ENCODING`: an
    /// `SRGB8_ALPHA8` attachment, or a window surface made with an sRGB colour space). ES 3.0,
    /// and ES 2.0 with `GL_EXT_sRGB`; never on desktop GL, whose encoding the renderer's calls
    /// switch off (`GL_FRAMEBUFFER_SRGB`).
    pub srgb: bool,
    /// The colour buffer stores fixed-point values, which clamp to [0, 1]: its component type
    /// on ES 3.0 (`GL_UNSIGNED_NORMALIZED`), at most 8 red bits on ES 2.0 (whose float colour
    /// buffers have 16 or 32). Asked only where [`TargetQueries`] asks it or `rgba8`.
    pub fixed_point: bool,
    /// The colour is 8-bit normalized RGBA (`RGBA8` or `SRGB8_ALPHA8`): what an ES 3.0
    /// multisample resolve may blit into, which needs identical formats (`RGB8`, `RGB565`, a
    /// window surface without alpha, is not). Asked only where [`TargetQueries::rgba8`].
    pub rgba8: bool,
    /// Depth bits (0: no depth buffer); `None` where the driver would not say. ES 2.0 asks
    /// `GL_DEPTH_BITS`; ES 3.0 and desktop core (which dropped that query) ask the depth
    /// attachment.
    pub depth_bits: Option<i32>,
}

/// The answers of [`TargetFormat`] a frame asks for beyond the ones every frame needs.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct TargetQueries {
    pub fixed_point: bool,
    pub rgba8: bool,
}

impl Device {
    /// What `target`, the bound framebuffer (`None`: the default one), is.
    pub(crate) fn target_format(
        &self,
        target: Option<glow::Framebuffer>,
        queries: TargetQueries,
    ) -> TargetFormat {
        if !self.target_queries_refused.get() {
            let format = self.read_target_format(target, queries, false);
            if self.drain_errors() == glow::NO_ERROR {
                return format;
            }
            self.target_queries_refused.set(true);
        }
        self.read_target_format(target, queries, true)
    }

    /// [`Device::target_format`]'s queries; `drained`: each query's errors drained, and an
    /// answer a query did not give cautious.
    fn read_target_format(
        &self,
        target: Option<glow::Framebuffer>,
        queries: TargetQueries,
        drained: bool,
    ) -> TargetFormat {
        let caps = self.caps();
        let answered = || !drained || self.drain_errors() == glow::NO_ERROR;
        let int = |pname| {
            let value = unsafe { self.gl.get_parameter_i32(pname) };
            answered().then_some(value)
        };
        let es3_state = caps.context_has_es3_state();
        // The default framebuffer's attachments are no query on ES 2.0.
        let attachments = target.is_some() || es3_state;
        let mut format = TargetFormat {
            samples: int(glow::SAMPLES).unwrap_or(0),
            ..TargetFormat::default()
        };
        // The colour attachment's parameters, asked in one go: its encoding, component type
        // and sizes, as far as this frame needs them.
        let encoding = !caps.desktop && (es3_state || caps.has_extension("GL_EXT_sRGB"));
        let kind = !caps.desktop && es3_state && (queries.fixed_point || queries.rgba8);
        let sizes = kind && queries.rgba8;
        let pnames = [
            glow::FRAMEBUFFER_ATTACHMENT_COLOR_ENCODING,
            glow::FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE,
            glow::FRAMEBUFFER_ATTACHMENT_RED_SIZE,
            glow::FRAMEBUFFER_ATTACHMENT_GREEN_SIZE,
            glow::FRAMEBUFFER_ATTACHMENT_BLUE_SIZE,
            glow::FRAMEBUFFER_ATTACHMENT_ALPHA_SIZE,
        ];
        let wanted = [encoding, kind, sizes, sizes, sizes, sizes];
        if attachments && (target.is_some() || encoding || kind) {
            let colour = [glow::COLOR_ATTACHMENT0, glow::BACK];
            let values = self.bound_attachment(target, colour, &pnames, &wanted, drained);
            format.colour_zero_empty = target.is_some() && values == Some(None);
            if let Some(Some([encoding, kind, sizes @ ..])) = values {
                format.srgb = encoding == glow::SRGB as i32;
                let normalized = kind == glow::UNSIGNED_NORMALIZED as i32;
                format.fixed_point = normalized;
                format.rgba8 = queries.rgba8 && normalized && sizes == [8; 4];
            }
        }
        if !caps.desktop && !es3_state && queries.fixed_point {
            format.fixed_point = int(glow::RED_BITS).is_some_and(|bits| (1..=8).contains(&bits));
        }
        format.depth_bits = if caps.es == EsVersion::Es2 && !caps.desktop {
            int(glow::DEPTH_BITS)
        } else if attachments {
            let depth = [glow::DEPTH_ATTACHMENT, glow::DEPTH];
            let size = [glow::FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE];
            (self.bound_attachment(target, depth, &size, &[true], drained))
                .map(|bits| bits.map_or(0, |[bits]| bits))
        } else {
            None
        };
        format
    }

    /// The depth bits of the bound framebuffer ([`TargetFormat::depth_bits`]).
    #[cfg(test)]
    pub(crate) fn bound_depth_bits(&self) -> Option<i32> {
        let target = self.bound_framebuffer();
        self.target_format(target, TargetQueries::default())
            .depth_bits
    }

    /// Whether `target`, a framebuffer object, holds a colour buffer of integers (`RGBA8UI`,
    /// `RG32I`, …) at `GL_COLOR_ATTACHMENT0`: a frame's colours cannot be written there (GL
    /// leaves the values undefined). Asked where the context has the query (ES 3.0 state).
    pub(crate) fn bound_colour_holds_integers(&self, target: Option<glow::Framebuffer>) -> bool {
        if target.is_none() || !self.caps().context_has_es3_state() {
            return false;
        }
        let colour = [glow::COLOR_ATTACHMENT0, glow::BACK];
        let kind = [glow::FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE];
        let values = self.bound_attachment(target, colour, &kind, &[true], true);
        matches!(values, Some(Some([t])) if t == glow::INT as i32 || t == glow::UNSIGNED_INT as i32)
    }

    /// The `pnames` that are `wanted` of `target`'s attachment (the first of
    /// `[in_object, in_default]` for a framebuffer object, the second for the default one;
    /// those not wanted 0): `Some(None)` where nothing is attached, `None` where the driver
    /// would not say (checked only where `drained`).
    fn bound_attachment<const N: usize>(
        &self,
        target: Option<glow::Framebuffer>,
        [in_object, in_default]: [u32; 2],
        pnames: &[u32; N],
        wanted: &[bool; N],
        drained: bool,
    ) -> Option<Option<[i32; N]>> {
        let attachment = if target.is_some() {
            in_object
        } else {
            in_default
        };
        let param = |p| unsafe {
            self.gl
                .get_framebuffer_attachment_parameter_i32(glow::FRAMEBUFFER, attachment, p)
        };
        let attached = param(glow::FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE) != glow::NONE as i32;
        let mut values = [0; N];
        if attached {
            for ((value, &pname), _) in
                (values.iter_mut().zip(pnames).zip(wanted)).filter(|(_, w)| **w)
            {
                *value = param(pname);
            }
        }
        let answered = !drained || self.drain_errors() == glow::NO_ERROR;
        answered.then_some(attached.then_some(values))
    }
}
