//! GPU frame timing with `GL_EXT_disjoint_timer_query` (a `TIME_ELAPSED` query around the
//! frame's GL work), where the context has it. Without the extension, or when the GPU reports a
//! disjoint event (a clock change or a context switch invalidates the figure), there is no GPU
//! time and callers fall back to wall time around `glFinish`.
//!
//! A query is only as good as the driver's: llvmpipe reports the whole frame for plain forward
//! but a few milliseconds for tiled and clustered frames that take 75 ms by the wall clock
//! (their per-frame texture uploads split llvmpipe's work, and the query sees only part), so
//! on llvmpipe the wall-clock `frame_ms` is the figure to quote.
#![allow(unsafe_code)]

use glow::HasContext;

use super::{Device, GlError};

/// `GL_TIME_ELAPSED_EXT`.
const TIME_ELAPSED: u32 = 0x88BF;
/// `GL_GPU_DISJOINT_EXT`.
const GPU_DISJOINT: u32 = 0x8FBB;

/// One elapsed-time query, reused frame after frame.
pub struct GpuTimer {
    query: glow::Query,
}

impl GpuTimer {
    /// A timer, or `None` when the context has no `GL_EXT_disjoint_timer_query`.
    pub fn new(dev: &Device) -> Result<Option<GpuTimer>, GlError> {
        if !dev.caps().timer_query {
            return Ok(None);
        }
        let query = unsafe { dev.gl.create_query() }.map_err(GlError::Create)?;
        Ok(Some(GpuTimer { query }))
    }

    /// Starts timing (clears a pending disjoint flag first, so only this frame's counts).
    pub fn begin(&self, dev: &Device) {
        unsafe {
            dev.gl.get_parameter_i32(GPU_DISJOINT);
            dev.gl.begin_query(TIME_ELAPSED, self.query);
        }
    }

    /// Stops timing and waits for the result: GPU milliseconds, or `None` when the GPU
    /// reported a disjoint event. Call after the frame's work is submitted (it waits).
    pub fn end(&self, dev: &Device) -> Option<f64> {
        unsafe {
            dev.gl.end_query(TIME_ELAPSED);
            let ns = dev
                .gl
                .get_query_parameter_u64(self.query, glow::QUERY_RESULT);
            let disjoint = dev.gl.get_parameter_i32(GPU_DISJOINT) != 0;
            (!disjoint).then_some(ns as f64 * 1e-6)
        }
    }

    /// Frees the query.
    pub fn destroy(self, dev: &Device) {
        unsafe { dev.gl.delete_query(self.query) };
    }
}
