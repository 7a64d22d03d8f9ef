//! `auto`: picks a method per frame from the context and the scene, and says which and why in
//! the frame's stats. Few lights → plain forward (one short loop beats assigning and uploading
//! a grid); many → clustered; clustered unsupported → forward. A frame with more lights visible
//! than clustered can index → deferred where it runs (ES 3.0 G-buffer, not the renderer's own
//! MSAA target): one proxy per light has no index limit, where forward's loop is capped by the
//! driver and leaves lights out. A method not in use keeps its GPU resources (clustered its
//! grid's calibration too) for [`IDLE_FRAMES_KEPT`](super::IDLE_FRAMES_KEPT) frames after its
//! last one, then frees them: a count hovering round a limit would otherwise free and make
//! them every other frame. Clustered is in use while a frame has too many visible lights for
//! it (it tries every frame); frames without lights free its textures alone, as they do when
//! it runs by itself.

use std::fmt::Write as _;

use super::culled::{CulledForward, CulledFrame, Culling};
use super::culled_support::culled_support;
use super::deferred::Deferred;
use super::forward::Forward;
use super::{idle_for_long, FrameContext, MethodDesc, MethodStats, ShadingMethod, Support};
use crate::cluster::pack::MAX_INDEXED_LIGHTS;
use crate::gl::target_size::{self, TargetStorage};
use crate::gl::{gbuffer, Device, EsVersion, GlError};
use crate::Error;

/// The table row.
pub const DESC: MethodDesc = MethodDesc {
    name: "auto",
    summary: "forward for few lights, clustered for many, deferred past clustered's index limit (the choice is in the stats)",
    min_es: EsVersion::Es2,
    required_extensions: &[],
    supported,
    multisample: true,
    create: |_| Ok(Box::new(Auto::default())),
};

/// As degraded as what it runs: forward's notes, clustered's when it can pick clustered (or
/// that it never can), and deferred's when it can pick deferred.
fn supported(caps: &crate::gl::Caps) -> Support {
    let mut notes = Vec::new();
    match super::forward::supported(caps) {
        Support::Supported => {}
        Support::Fallback(why) => notes.push(why),
        // What auto would run for a few lights cannot run.
        Support::Unsupported(why) => return Support::Unsupported(why),
    }
    match culled_support(caps) {
        Support::Supported => {}
        Support::Fallback(why) if notes.contains(&why) => {}
        Support::Fallback(why) => notes.push(why),
        Support::Unsupported(why) => {
            notes.push(format!("always forward: clustered cannot run ({why})"))
        }
    }
    if let Support::Fallback(why) = (super::deferred::DESC.supported)(caps) {
        notes.push(format!("past clustered's index limit, deferred with {why}"));
    }
    if notes.is_empty() {
        Support::Supported
    } else {
        Support::Fallback(notes.join("; "))
    }
}

/// Up to this many lights, plain forward is chosen: its loop runs every light, in view or not
/// (a frame with none in view is drawn ambient-only, whatever the method).
pub const FORWARD_UP_TO: usize = 32;

/// The methods auto may draw a frame with on a context with `caps`: forward always, clustered
/// where it runs, deferred where a G-buffer can be made and the frame is not drawn into the
/// renderer's own multisampled target (`own_msaa`; see [`deferred_refusal`]).
pub(crate) fn methods_it_may_run(caps: &crate::gl::Caps, own_msaa: bool) -> Vec<&'static str> {
    let mut names = vec![super::forward::DESC.name];
    if !matches!(culled_support(caps), Support::Unsupported(_)) {
        names.push(super::clustered::DESC.name);
    }
    if gbuffer::unsupported_reason(caps).is_none() && !own_msaa {
        names.push(super::deferred::DESC.name);
    }
    names
}

/// The adaptive method.
#[derive(Default)]
pub struct Auto {
    forward: Option<Forward>,
    clustered: Option<CulledForward>,
    /// For frames with more visible lights than clustered indexes, where deferred runs.
    deferred: Option<Deferred>,
    /// Frames in a row each method did not draw (forward, clustered, deferred); see [`rest`].
    idle: [u32; 3],
    /// Why this frame's method was chosen (rewritten every frame, its buffer kept).
    reason: String,
    /// Whether clustered runs on this context (asked once: the context does not change).
    clustered_support: Option<Support>,
    /// Whether the log has said that a frame had more visible lights than clustered indexes.
    warned_too_many: bool,
    /// The smallest frame (in pixels) whose G-buffer the driver could not allocate: deferred
    /// is not tried again at that size or larger (each try would ask for it again).
    gbuffer_refused_at: Option<(u64, String)>,
}

impl Auto {
    /// The method for this frame; the reason is left in `self.reason`.
    fn choose(&mut self, ctx: &FrameContext) -> &'static str {
        let n = ctx.lights.len();
        let reason = &mut self.reason;
        reason.clear();
        if n <= FORWARD_UP_TO {
            let _ = write!(reason, "{n} lights ≤ {FORWARD_UP_TO}: one short loop costs less than assigning and uploading a grid");
            return "forward";
        }
        let support = self
            .clustered_support
            .get_or_insert_with(|| culled_support(ctx.dev.caps()));
        match support {
            Support::Unsupported(why) => {
                let _ = write!(
                    reason,
                    "{n} lights, but clustered is unsupported here: {why}"
                );
                "forward"
            }
            _ => {
                let _ = write!(
                    reason,
                    "{n} lights > {FORWARD_UP_TO}: per-cell lists keep the loop short"
                );
                "clustered"
            }
        }
    }
}

/// Counts a frame `method` did not draw; from the
/// [`IDLE_FRAMES_KEPT`](super::IDLE_FRAMES_KEPT)th in a row on, it is freed.
fn rest<M: ShadingMethod>(method: &mut Option<M>, idle: &mut u32, dev: &Device) {
    if method.is_some() && idle_for_long(idle) {
        if let Some(mut m) = method.take() {
            m.destroy(dev);
        }
    }
}

/// Most lights a frame whose clustered cells would overflow is drawn with forward instead:
/// every pixel then loops over them all, at most twice ES 2.0's full cell (4 095). Past it the
/// frame stays clustered, under its overflow policy: a far longer loop at every pixel could
/// trip a phone's GPU watchdog.
pub const OVERFLOW_TO_FORWARD: usize = 8_192;

/// Why deferred cannot render this frame, if it cannot: no G-buffer on this context, or the
/// frame is drawn into the renderer's multisampled target, which deferred does not support.
fn deferred_refusal(ctx: &FrameContext) -> Option<String> {
    let caps = ctx.dev.caps();
    if let Some(why) = gbuffer::unsupported_reason(caps) {
        return Some(why);
    }
    // A frame within the viewport limit may still pass the G-buffer's texture size: forward
    // draws it then, rather than every such frame failing.
    let textures = TargetStorage {
        textures: true,
        renderbuffers: false,
    };
    if let Err(e) = target_size::check(caps, "a deferred G-buffer", ctx.viewport, textures) {
        return Some(e.to_string());
    }
    ctx.own_msaa
        .then(|| format!("{} MSAA samples, one G-buffer sample", ctx.options.samples))
}

/// Makes `deferred`'s G-buffer for this frame; when the driver has no memory for it, says so
/// (forward draws the frame then, rather than every such frame failing), remembering the size
/// in `refused_at` so frames as large do not ask again.
fn allocate_deferred(
    deferred: &mut Option<Deferred>,
    refused_at: &mut Option<(u64, String)>,
    ctx: &FrameContext,
) -> Result<Option<String>, Error> {
    let pixels = u64::from(ctx.viewport.0) * u64::from(ctx.viewport.1);
    if let Some((at, why)) = refused_at {
        if pixels >= *at {
            return Ok(Some(why.clone()));
        }
    }
    match deferred.get_or_insert_with(Deferred::default).prepare(ctx) {
        Ok(()) => Ok(None),
        Err(Error::Gl(GlError::OutOfMemory(e))) => {
            let (w, h) = ctx.viewport;
            let why = format!("no memory for a {w}×{h} G-buffer ({e})");
            if let Some(mut d) = deferred.take() {
                d.destroy(ctx.dev);
            }
            *refused_at = Some((pixels, why.clone()));
            Ok(Some(why))
        }
        Err(e) => Err(e),
    }
}

impl ShadingMethod for Auto {
    fn name(&self) -> &'static str {
        DESC.name
    }

    fn render(&mut self, ctx: &mut FrameContext) -> Result<MethodStats<'_>, Error> {
        let choice = self.choose(ctx);
        if choice == "clustered" {
            let clustered = self
                .clustered
                .get_or_insert_with(|| CulledForward::new(Culling::Clustered));
            // Else forward this frame; clustered keeps its resources and tries again next
            // frame (the visible lights change as they and the camera move). Cells past their
            // cap leave lights out: where forward's one loop holds every light, it draws them
            // (not deferred: its half-float accumulation, without GL_EXT_float_blend, drifts
            // under thousands of lights on one pixel).
            let forward_holds_all = ctx.lights.len()
                <= (super::forward::max_lights(ctx.dev.caps()) as usize).min(OVERFLOW_TO_FORWARD);
            let frame = clustered.render_unless_too_many(ctx, forward_holds_all)?;
            let overflowed = matches!(frame, CulledFrame::Overflowed(_));
            let too_many = match frame {
                CulledFrame::Rendered(mut stats) => {
                    let [forward_idle, clustered_idle, deferred_idle] = &mut self.idle;
                    rest(&mut self.forward, forward_idle, ctx.dev);
                    rest(&mut self.deferred, deferred_idle, ctx.dev);
                    *clustered_idle = 0;
                    stats.auto_choice = Some((choice, &self.reason));
                    return Ok(stats);
                }
                CulledFrame::TooManyVisible(visible) => format!(
                    "{visible} lights visible > {MAX_INDEXED_LIGHTS}, more than clustered can \
                     index"
                ),
                CulledFrame::Unlisted { references, .. } => {
                    format!("{references} or more light references, more than clustered lists")
                }
                CulledFrame::Unallocated(bytes) => format!(
                    "clustered's light lists need a buffer of {} MiB, more than this process \
                     can allocate now",
                    bytes.div_ceil(1 << 20)
                ),
                CulledFrame::Overflowed(references) => format!(
                    "{references} light references past clustered's per-cell cap would be \
                     left out"
                ),
            };
            let mut refusal = (!overflowed).then(|| deferred_refusal(ctx)).flatten();
            if !overflowed && refusal.is_none() {
                refusal = allocate_deferred(&mut self.deferred, &mut self.gbuffer_refused_at, ctx)?;
            }
            let instead = if overflowed || refusal.is_some() {
                "forward"
            } else {
                "deferred"
            };
            self.reason.clear();
            let _ = write!(self.reason, "{too_many}: {instead} renders this frame");
            if let Some(why) = refusal {
                let _ = write!(self.reason, " (deferred cannot: {why})");
            }
            if !self.warned_too_many {
                self.warned_too_many = true;
                log::warn!("auto: {}", self.reason);
            }
            // Clustered tried this frame: it is still in use.
            self.idle[1] = 0;
            let [forward_idle, _, deferred_idle] = &mut self.idle;
            let mut stats = if instead == "deferred" {
                rest(&mut self.forward, forward_idle, ctx.dev);
                *deferred_idle = 0;
                self.deferred
                    .get_or_insert_with(Deferred::default)
                    .render(ctx)?
            } else {
                rest(&mut self.deferred, deferred_idle, ctx.dev);
                *forward_idle = 0;
                self.forward
                    .get_or_insert_with(Forward::default)
                    .render(ctx)?
            };
            stats.auto_choice = Some((instead, &self.reason));
            return Ok(stats);
        }
        let [forward_idle, clustered_idle, deferred_idle] = &mut self.idle;
        rest(&mut self.clustered, clustered_idle, ctx.dev);
        rest(&mut self.deferred, deferred_idle, ctx.dev);
        *forward_idle = 0;
        let mut stats = self
            .forward
            .get_or_insert_with(Forward::default)
            .render(ctx)?;
        stats.auto_choice = Some((choice, &self.reason));
        Ok(stats)
    }

    /// Only the method the last frame drew with holds that frame's contents.
    fn fit_buffers(&mut self, in_use: bool) {
        let [forward_idle, clustered_idle, deferred_idle] = self.idle;
        if let Some(f) = &mut self.forward {
            f.fit_buffers(in_use && forward_idle == 0);
        }
        if let Some(c) = &mut self.clustered {
            c.fit_buffers(in_use && clustered_idle == 0);
        }
        if let Some(d) = &mut self.deferred {
            d.fit_buffers(in_use && deferred_idle == 0);
        }
    }

    /// A frame without lights: forward and deferred rest as on a frame another method drew;
    /// clustered as it does alone, freeing its textures and keeping its grid's calibration.
    fn skip_frame(&mut self, dev: &Device) {
        let [forward_idle, _, deferred_idle] = &mut self.idle;
        rest(&mut self.forward, forward_idle, dev);
        rest(&mut self.deferred, deferred_idle, dev);
        if let Some(c) = &mut self.clustered {
            c.skip_frame(dev);
        }
    }

    /// Clustered's grid takes in only its own frames' costs (it recorded them when it drew),
    /// and a GPU time read frames later by the frame it belongs to.
    fn observe_frame(&mut self, timing: super::FrameTiming) {
        if let Some(c) = &mut self.clustered {
            c.observe_frame(timing);
        }
    }

    fn gpu_bytes(&self) -> usize {
        self.forward.as_ref().map_or(0, Forward::gpu_bytes)
            + self.clustered.as_ref().map_or(0, CulledForward::gpu_bytes)
            + self.deferred.as_ref().map_or(0, Deferred::gpu_bytes)
    }

    fn destroy(&mut self, dev: &Device) {
        if let Some(mut f) = self.forward.take() {
            f.destroy(dev);
        }
        if let Some(mut c) = self.clustered.take() {
            c.destroy(dev);
        }
        if let Some(mut d) = self.deferred.take() {
            d.destroy(dev);
        }
    }
}
