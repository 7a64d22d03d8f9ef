//! GPU frame timing with `GL_EXT_disjoint_timer_query` (a `TIME_ELAPSED` query around the
//! frame's GL work), where the context has it: read at once by a frame that waits for the GPU
//! anyway, and a few frames later, when finished, by one that does not (a game's). The timer
//! is optional: without the extension, when the GPU reports a disjoint event (a clock change
//! or a context switch invalidates the figure), or when the driver refuses the query object or
//! a query call, there is no GPU time (`gpu_ms` absent) and callers fall back to wall time
//! around `glFinish`. A refusal is a warning, never a failed frame.
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

/// Queries in the ring: a frame that does not wait reads its result up to this many frames
/// later (a GPU runs two or three frames behind the CPU at most).
pub const RING: usize = 4;

/// `GL_QUERY_RESULT_AVAILABLE_EXT`.
const QUERY_RESULT_AVAILABLE: u32 = 0x8867;

/// `GL_CURRENT_QUERY_EXT`.
const CURRENT_QUERY: u32 = 0x8865;

/// A ring of elapsed-time queries, reused frame after frame. A frame that waits for the GPU
/// reads its own query at once; one that does not leaves it in flight and reads the finished
/// ones later, without stalling ([`GpuTimer::poll`]).
pub struct GpuTimer {
    fns: TimerQueryFns,
    queries: [u32; RING],
    /// The frame each query times, while its result is unread (`None`: free).
    in_flight: [Cell<Option<u64>>; RING],
    /// The query between `begin` and `end`: a frame that panicked in between left it running.
    running: Cell<Option<usize>>,
    /// Set when the driver refused a query call: the timer then stays off (warned once).
    failed: Cell<bool>,
    /// The application was found timing its own work around a frame: each begin asks first
    /// whether its query runs (else beginning ours raises a GL error the game would see), until
    /// a frame finds none.
    application_times: Cell<bool>,
}

impl GpuTimer {
    /// A timer, or `None` when the context has no `GL_EXT_disjoint_timer_query` or cannot
    /// make the query objects (warned: the frame goes on untimed).
    pub fn new(dev: &Device) -> Option<GpuTimer> {
        if !dev.caps().timer_query {
            return None;
        }
        let Some(fns) = timer_query_fns() else {
            log::warn!("GL_EXT_disjoint_timer_query is listed but its entry points are missing: no GPU time (gpu_ms absent)");
            return None;
        };
        let mut queries = [0u32; RING];
        // SAFETY: the extension's signature, RING names written into `queries`.
        unsafe { (fns.gen_queries)(RING as i32, queries.as_mut_ptr()) };
        let error = dev.drain_errors();
        if queries.contains(&0) || error != glow::NO_ERROR {
            log::warn!(
                "the driver could not create timer queries (GL error {error:#06x}): no GPU time (gpu_ms absent)"
            );
            for query in queries.iter().filter(|&&q| q != 0) {
                unsafe { (fns.delete_queries)(1, query) };
            }
            return None;
        }
        Some(GpuTimer {
            fns,
            queries,
            in_flight: Default::default(),
            running: Cell::new(None),
            failed: Cell::new(false),
            application_times: Cell::new(false),
        })
    }

    /// Starts timing frame `serial` on a free query. Where every query is still in flight, a
    /// frame that `wait`s for the GPU first waits for the oldest one's result (it waits for
    /// all that frame's work anyway); one that does not goes untimed.
    pub fn begin(&self, dev: &Device, serial: u64, wait: bool) {
        if self.failed.get() {
            return;
        }
        self.end_running(dev);
        if self.application_times.get() {
            let running = self.application_query(dev);
            self.application_times.set(running != Some(false));
            if running != Some(false) {
                return;
            }
        }
        let free = self.in_flight.iter().position(|f| f.get().is_none());
        let oldest = || (0..RING).min_by_key(|&slot| self.in_flight[slot].get());
        let Some(slot) = free.or_else(|| oldest().filter(|_| wait)) else {
            return;
        };
        if self.in_flight[slot].take().is_some() {
            // The result, waited for and dropped: a newer frame's is the one reported.
            self.result(slot, QUERY_RESULT);
        }
        unsafe { (self.fns.begin_query)(TIME_ELAPSED, self.queries[slot]) };
        let error = dev.drain_errors();
        if error == glow::NO_ERROR {
            self.running.set(Some(slot));
            self.in_flight[slot].set(Some(serial));
            return;
        }
        // An application timing its own work around the frame has a query running: one
        // elapsed-time query at a time, so this frame goes untimed. Asked only once a begin
        // failed, not every frame, and before each begin from then on.
        match self.application_query(dev) {
            Some(true) => self.application_times.set(true),
            _ => self.refused(error, "glBeginQueryEXT"),
        }
    }

    /// Whether the application has an elapsed-time query running (`None`: the driver would not
    /// say).
    fn application_query(&self, dev: &Device) -> Option<bool> {
        let mut current = 0;
        unsafe { (self.fns.get_queryiv)(TIME_ELAPSED, CURRENT_QUERY, &mut current) };
        (dev.drain_errors() == glow::NO_ERROR).then_some(current != 0)
    }

    /// Ends, unread, a query left running by a frame that panicked between `begin` and `end`
    /// (else this timer's next begin, and the application's own queries, would be refused).
    pub fn end_running(&self, dev: &Device) {
        if let Some(slot) = self.running.take() {
            unsafe { (self.fns.end_query)(TIME_ELAPSED) };
            dev.drain_errors();
            self.in_flight[slot].set(None);
        }
    }

    /// Stops timing. `wait`: reads the result now, waiting for it (call after the frame's
    /// work is submitted): GPU milliseconds, or `None` when the GPU reported a disjoint event
    /// or the driver refused the query. Otherwise the query stays in flight for
    /// [`GpuTimer::poll`], which checks this call's errors too (call it next), and this
    /// returns `None`.
    pub fn end(&self, dev: &Device, wait: bool) -> Option<f64> {
        let slot = self.running.take()?;
        if self.failed.get() {
            return None;
        }
        unsafe { (self.fns.end_query)(TIME_ELAPSED) };
        if !wait {
            // Its error is checked by the `poll` that follows.
            return None;
        }
        self.in_flight[slot].set(None);
        let ns = self.result(slot, QUERY_RESULT);
        let valid = self.check(dev, "the timer query's result") && !self.take_disjoint(dev);
        valid.then_some(ns as f64 * 1e-6)
    }

    /// The newest finished frame whose query was left in flight: its serial and GPU
    /// milliseconds, read without waiting; `None` while none has finished, and when the GPU
    /// reported a disjoint event (every result in flight is then dropped).
    pub fn poll(&self, dev: &Device) -> Option<(u64, f64)> {
        if self.failed.get() {
            return None;
        }
        // The frame the query in `slot` times, while its result is unread and it has ended.
        let waiting =
            |slot: usize| (self.in_flight[slot].get()).filter(|_| self.running.get() != Some(slot));
        // Oldest first, up to the first without its result: GPUs finish frames in order (and
        // a later one's result is read by a later poll), and each ask is a round trip on a
        // threaded driver.
        let mut slots: [usize; RING] = std::array::from_fn(|slot| slot);
        slots.sort_by_key(|&slot| waiting(slot).unwrap_or(u64::MAX));
        // Nothing to read, and no call since the last check: no round trip.
        waiting(slots[0])?;
        let mut newest: Option<(u64, f64)> = None;
        for slot in slots {
            let Some(serial) = waiting(slot) else { break };
            if self.result(slot, QUERY_RESULT_AVAILABLE) == 0 {
                break;
            }
            self.in_flight[slot].set(None);
            let ms = self.result(slot, QUERY_RESULT) as f64 * 1e-6;
            newest = Some((serial, ms));
        }
        if !self.check(dev, "the timer query's result") || self.take_disjoint(dev) {
            return None;
        }
        newest
    }

    /// `pname` of query `slot`.
    fn result(&self, slot: usize, pname: u32) -> u64 {
        let mut value = 0u64;
        unsafe { (self.fns.get_query_object_ui64v)(self.queries[slot], pname, &mut value) };
        value
    }

    /// Reads (and so clears) the disjoint flag, once a frame after its query ended; when it was
    /// set, every result in flight is unreliable and dropped (an event between two frames
    /// drops the later one's too: a sample fewer, never a wrong one).
    fn take_disjoint(&self, dev: &Device) -> bool {
        let disjoint = unsafe { dev.gl.get_parameter_i32(GPU_DISJOINT) } != 0;
        if disjoint {
            for flight in &self.in_flight {
                flight.set(None);
            }
        }
        disjoint
    }

    /// False (and the timer off from now on, warned) when the last calls raised a GL error.
    /// The caller takes the frame's own errors before the query's calls (they drain the queue).
    fn check(&self, dev: &Device, what: &str) -> bool {
        let error = dev.drain_errors();
        if error == glow::NO_ERROR {
            return true;
        }
        self.refused(error, what);
        false
    }

    /// Turns the timer off, warned, after the driver refused `what` with `error`.
    fn refused(&self, error: u32, what: &str) {
        log::warn!(
            "the driver refused {what} (GL error {error:#06x}): GPU timing off (gpu_ms absent)"
        );
        self.failed.set(true);
    }

    /// Frees the queries.
    pub fn destroy(self, _dev: &Device) {
        unsafe { (self.fns.delete_queries)(RING as i32, self.queries.as_ptr()) };
    }
}
