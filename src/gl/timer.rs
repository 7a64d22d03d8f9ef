//! GPU frame timing with `GL_EXT_disjoint_timer_query` (a `TIME_ELAPSED` query around the
//! frame's GL work), where the context has it. The timer is optional: without the extension,
//! when the GPU reports a disjoint event (a clock change or a context switch invalidates the
//! figure), or when the driver refuses the query object or a query call, there is no GPU time
//! (`gpu_ms` absent) and callers fall back to wall time around `glFinish`. A refusal is a
//! warning, never a failed frame.
//!
//! The calls go through the extension's own `…EXT` entry points ([`super::ext_fns`]): on an
//! ES 2.0 context the core names (`glGenQueries`, ES 3.0 only) exist in some libraries but are
//! invalid there (ANGLE refuses to create the query), while the `EXT` names are valid on ES 2.0
//! and 3.0 alike.
//!
//! A query is only as good as the driver's: llvmpipe reports the whole frame for plain forward
//! but only part of a tiled or clustered frame (their per-frame texture uploads split
//! llvmpipe's work, and the query sees only part), so on llvmpipe the wall-clock `frame_ms` is
//! the figure to quote.
#![allow(unsafe_code)]

use std::cell::Cell;

use glow::HasContext;

use super::ext_fns::{timer_query_fns, TimerQueryFns};
use super::Device;

/// `GL_TIME_ELAPSED_EXT`.
const TIME_ELAPSED: u32 = 0x88BF;
/// `GL_GPU_DISJOINT_EXT`.
const GPU_DISJOINT: u32 = 0x8FBB;
/// `GL_QUERY_RESULT_EXT`.
const QUERY_RESULT: u32 = 0x8866;

/// One elapsed-time query, reused frame after frame.
pub struct GpuTimer {
    fns: TimerQueryFns,
    query: u32,
    /// Set when the driver refused a query call: the timer then stays off (warned once).
    failed: Cell<bool>,
    /// Between `begin` and `end`: a frame that panicked in between left the query running.
    active: Cell<bool>,
}

impl GpuTimer {
    /// A timer, or `None` when the context has no `GL_EXT_disjoint_timer_query` or cannot
    /// make the query object (warned: the frame goes on untimed).
    pub fn new(dev: &Device) -> Option<GpuTimer> {
        if !dev.caps().timer_query {
            return None;
        }
        let Some(fns) = timer_query_fns() else {
            log::warn!("GL_EXT_disjoint_timer_query is listed but its entry points are missing: no GPU time (gpu_ms absent)");
            return None;
        };
        let mut query = 0u32;
        // SAFETY: the extension's signature, one name written into `query`.
        unsafe { (fns.gen_queries)(1, &mut query) };
        let error = dev.drain_errors();
        if query == 0 || error != glow::NO_ERROR {
            log::warn!(
                "the driver could not create a timer query (GL error {error:#06x}): no GPU time (gpu_ms absent)"
            );
            if query != 0 {
                unsafe { (fns.delete_queries)(1, &query) };
            }
            return None;
        }
        Some(GpuTimer {
            fns,
            query,
            failed: Cell::new(false),
            active: Cell::new(false),
        })
    }

    /// Starts timing (clears a pending disjoint flag first, so only this frame's counts).
    pub fn begin(&self, dev: &Device) {
        if self.failed.get() {
            return;
        }
        if self.active.replace(false) {
            // Left running by a frame that panicked (and was caught): ended unread, or this
            // begin would be refused and the timer turned off.
            unsafe { (self.fns.end_query)(TIME_ELAPSED) };
            dev.drain_errors();
        }
        unsafe {
            dev.gl.get_parameter_i32(GPU_DISJOINT);
            (self.fns.begin_query)(TIME_ELAPSED, self.query);
        }
        self.active.set(self.check(dev, "glBeginQueryEXT"));
    }

    /// Stops timing and waits for the result: GPU milliseconds, or `None` when the GPU
    /// reported a disjoint event or the driver refused the query. Call after the frame's work
    /// is submitted (it waits).
    pub fn end(&self, dev: &Device) -> Option<f64> {
        if self.failed.get() {
            return None;
        }
        self.active.set(false);
        let mut ns = 0u64;
        let disjoint = unsafe {
            (self.fns.end_query)(TIME_ELAPSED);
            (self.fns.get_query_object_ui64v)(self.query, QUERY_RESULT, &mut ns);
            dev.gl.get_parameter_i32(GPU_DISJOINT) != 0
        };
        (self.check(dev, "the timer query's result") && !disjoint).then_some(ns as f64 * 1e-6)
    }

    /// False (and the timer off from now on, warned) when the last calls raised a GL error.
    /// The caller takes the frame's own errors before the query's calls (they drain the queue).
    fn check(&self, dev: &Device, what: &str) -> bool {
        let error = dev.drain_errors();
        if error == glow::NO_ERROR {
            return true;
        }
        log::warn!(
            "the driver refused {what} (GL error {error:#06x}): GPU timing off (gpu_ms absent)"
        );
        self.failed.set(true);
        false
    }

    /// Frees the query.
    pub fn destroy(self, _dev: &Device) {
        unsafe { (self.fns.delete_queries)(1, &self.query) };
    }
}
