//! The automatic grid's cost per unit ([`GridCosts`]) and its calibration from rendered frames
//! ([`FrameCost`]).
//!
//! Each figure is the median of the last [`CALIBRATION_WINDOW`] frames' nanoseconds per unit.
//! A median, not a running mean: a frame's assignment swings with the pool threads' wake-up
//! and the caches the frame before left, and the first frames after a grid change pay page
//! faults of buffers that grow; a mean of the few frames before the first calibrated choice
//! takes those for the typical frame and overpredicts the assignment.

/// Frames whose per-unit costs make a figure (the median of the last this many).
pub const CALIBRATION_WINDOW: usize = 9;

pub use crate::cluster::assign::{assign_work, INDEX_WEIGHT};

/// Cost per unit in nanoseconds: what the model multiplies its counts by.
///
/// Made by [`Default`] (the priors) or [`GridCosts::new`] (priors of one's own); its figures
/// are public to read and to set, but each is the median of the frames it last measured
/// (a private window, which equality compares too), so the next [`GridCosts::observe`] that
/// measures a figure replaces a value set by hand.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct GridCosts {
    /// One light evaluation by one fragment.
    pub shade_ns: f64,
    /// One unit of assignment work ([`assign_work`]: about one run of cells).
    pub assign_ns: f64,
    /// One byte uploaded.
    pub upload_ns: f64,
    /// Frames these figures were calibrated from (0: the priors).
    pub frames: u32,
    /// The last frames' per-unit costs: shading, assignment, upload.
    #[serde(skip)]
    windows: [Window; 3],
}

impl Default for GridCosts {
    /// The priors, medians measured with llvmpipe on a 2-core machine (courtyard, 1 024
    /// lights, 640×360, two assignment threads): a device's own frames replace them within a
    /// few frames.
    fn default() -> Self {
        GridCosts {
            shade_ns: 18.0,
            assign_ns: 21.0,
            upload_ns: 0.4,
            frames: 0,
            windows: [Window::default(); 3],
        }
    }
}

impl GridCosts {
    /// Priors of one's own (a device measured before).
    pub fn new(shade_ns: f64, assign_ns: f64, upload_ns: f64) -> Self {
        GridCosts {
            shade_ns,
            assign_ns,
            upload_ns,
            ..GridCosts::default()
        }
    }

    /// Takes one rendered frame in: `shade_ms` the time of its shading (GPU time, or wall time
    /// less the CPU work), `evals` its estimated light evaluations, `assign_ms` and `work`
    /// ([`assign_work`]) its assignment, `upload_ms` and `bytes` its uploads. Each figure
    /// becomes the median of its last [`CALIBRATION_WINDOW`] measurements; a frame with
    /// nothing to measure for a figure (no units, a time that is not a positive finite
    /// number) leaves that figure as it was.
    pub fn observe(&mut self, frame: &FrameCost) {
        let measured = [
            (frame.shade_ms, frame.evals),
            (frame.assign_ms, frame.assign_work),
            (frame.upload_ms, frame.upload_bytes),
        ];
        let figures = [&mut self.shade_ns, &mut self.assign_ns, &mut self.upload_ns];
        for ((window, figure), (ms, units)) in self.windows.iter_mut().zip(figures).zip(measured) {
            let ns = ms * 1e6 / units;
            if units > 0.0 && ms > 0.0 && ns.is_finite() {
                *figure = window.push(ns);
            }
        }
        self.frames = self.frames.saturating_add(1);
    }

    /// Takes in a shading time that arrived after its frame was observed (a GPU timer read
    /// a few frames later): `shade_ms` for `evals` light evaluations, as
    /// [`GridCosts::observe`] takes them. Counts no frame.
    pub fn observe_shading(&mut self, shade_ms: f64, evals: f64) {
        let ns = shade_ms * 1e6 / evals;
        if evals > 0.0 && shade_ms > 0.0 && ns.is_finite() {
            self.shade_ns = self.windows[0].push(ns);
        }
    }

    /// Predicted cost in milliseconds of `evals` light evaluations, `work` assignment units
    /// and `bytes` uploaded.
    pub fn predict_ms(&self, evals: f64, work: f64, bytes: f64) -> f64 {
        (self.shade_ns * evals + self.upload_ns * bytes) * 1e-6 + self.assign_ms(work)
    }

    /// Predicted assignment time in milliseconds of `work` assignment units.
    pub fn assign_ms(&self, work: f64) -> f64 {
        self.assign_ns * work * 1e-6
    }
}

/// What one frame cost, for [`GridCosts::observe`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameCost {
    /// Shading time in milliseconds.
    pub shade_ms: f64,
    /// Light evaluations (estimated from the samples).
    pub evals: f64,
    /// Assignment time in milliseconds.
    pub assign_ms: f64,
    /// The assignment's work ([`assign_work`]).
    pub assign_work: f64,
    /// Upload time in milliseconds.
    pub upload_ms: f64,
    /// Bytes uploaded.
    pub upload_bytes: f64,
}

/// The last few measurements of one figure (a ring), whose median is the figure.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Window {
    ns: [f64; CALIBRATION_WINDOW],
    len: usize,
    next: usize,
}

impl Window {
    /// Takes a finite measurement in and returns the median of the window.
    fn push(&mut self, ns: f64) -> f64 {
        self.ns[self.next] = ns;
        self.next = (self.next + 1) % CALIBRATION_WINDOW;
        self.len = (self.len + 1).min(CALIBRATION_WINDOW);
        let mut sorted = self.ns;
        let sorted = &mut sorted[..self.len];
        sorted.sort_unstable_by(f64::total_cmp);
        let mid = self.len / 2;
        if self.len % 2 == 1 {
            sorted[mid]
        } else {
            0.5 * (sorted[mid - 1] + sorted[mid])
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(shade_ms: f64, assign_ms: f64) -> FrameCost {
        FrameCost {
            shade_ms,
            evals: 1e6,
            assign_ms,
            assign_work: 1e5,
            upload_ms: 0.0,
            upload_bytes: 0.0,
        }
    }

    /// The calibration moves to what frames measure and ignores what they cannot say.
    #[test]
    fn calibration_follows_measured_frames() {
        let mut costs = GridCosts::default();
        costs.observe(&frame(10.0, 1.0));
        assert_eq!((costs.shade_ns, costs.assign_ns), (10.0, 10.0));
        assert_eq!(costs.upload_ns, GridCosts::default().upload_ns);
        for _ in 0..CALIBRATION_WINDOW {
            costs.observe(&frame(20.0, 1.0));
        }
        assert_eq!(costs.shade_ns, 20.0, "{costs:?}");
        let before = costs;
        for bad in [f64::NAN, f64::INFINITY, -1.0, 0.0] {
            costs.observe(&frame(bad, 1.0));
        }
        assert_eq!(costs.shade_ns, before.shade_ns);
        assert_eq!(costs.frames, before.frames + 4);
    }

    /// A spike (a slow wake-up, a page fault) in a few frames of the window does not move a
    /// figure; a change in most of them does.
    #[test]
    fn a_few_slow_frames_do_not_move_the_calibration() {
        let mut costs = GridCosts::default();
        for k in 0..CALIBRATION_WINDOW {
            // Every third frame's assignment takes twice as long.
            costs.observe(&frame(10.0, if k % 3 == 0 { 2.0 } else { 1.0 }));
        }
        assert_eq!(costs.assign_ns, 10.0, "{costs:?}");
        // Two frames in: the median of two is their mean.
        let mut two = GridCosts::default();
        two.observe(&frame(10.0, 1.0));
        two.observe(&frame(10.0, 3.0));
        assert_eq!(two.assign_ns, 20.0);
        // Most of the window slower: the figure follows.
        for _ in 0..CALIBRATION_WINDOW / 2 + 1 {
            costs.observe(&frame(10.0, 3.0));
        }
        assert_eq!(costs.assign_ns, 30.0, "{costs:?}");
    }
}
