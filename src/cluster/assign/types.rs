//! The types the assignment's parts share (its limits, result and figures; the runs and totals
//! of bands and chunks), below them all so no part imports the module that calls it.

use super::index_list::{EntriesMut, IndexList};
use crate::cluster::headroom::try_room_for;

/// Most light references an assignment lists before the overflow policy trims them: a grid
/// whose cells and overlapping lights would give more is not listed (see
/// [`Assignment::unlisted`]). 2²⁶ entries, what an index texture of 16 384 rows holds, take
/// 128 or 256 MiB, and their runs at most 512 MiB; a list past 2³² entries would not even be
/// numbered by the 32-bit offsets.
pub const MAX_UNTRIMMED_INDICES: usize = 1 << 26;

/// The references the phase-1 workers of one assignment found, all together: each adds its
/// own every [`TALLY_STEP`] references, so past [`MAX_UNTRIMMED_INDICES`] every worker stops
/// soon after (the runs found meanwhile stay within the bound plus a step a worker). The
/// bound is [`AssignLimits::max_untrimmed`].
pub(super) struct Tally {
    total: std::sync::atomic::AtomicUsize,
    /// The bound ([`AssignLimits::max_untrimmed`]).
    pub(super) limit: usize,
    /// Most runs one light gives on this grid (a row of one slice holds at most one): a
    /// worker keeps room for as many before each light ([`Tally::room_for_runs`]), so that no
    /// push of a light's runs grows its buffer (which would abort where memory runs out).
    pub(super) most_runs: usize,
    /// Bytes a worker's buffer could not grow to (0: none): the lists are not built
    /// ([`Assignment::unallocated`]).
    refused: std::sync::atomic::AtomicU64,
}

/// References a worker finds between two additions to the [`Tally`].
const TALLY_STEP: usize = 1 << 18;

impl Tally {
    /// A tally against `limit`, for lights of at most `most_runs` runs each.
    pub(super) fn new(limit: usize, most_runs: usize) -> Tally {
        Tally {
            total: std::sync::atomic::AtomicUsize::new(0),
            limit,
            most_runs,
            refused: std::sync::atomic::AtomicU64::new(0),
        }
    }

    /// Makes room in `runs` for one more light's, asking the allocator; false (and said) where
    /// it refuses.
    #[inline(always)]
    pub(super) fn room_for_runs(&self, runs: &mut Vec<Run>) -> bool {
        match crate::cluster::headroom::try_room_for_more(runs, self.most_runs) {
            Ok(()) => true,
            Err(bytes) => {
                self.refuse(bytes);
                false
            }
        }
    }

    /// `indices` made a list of `len` entries for `visible` lights, to be written; `None` where
    /// none is built: past the bound, after a refusal, or refused now (and said).
    pub(super) fn list<'a>(
        &self,
        indices: &'a mut IndexList,
        len: usize,
        visible: usize,
    ) -> Option<EntriesMut<'a>> {
        if len > self.limit || self.refused().is_some() {
            return None;
        }
        indices
            .prepare(len, visible)
            .map_err(|bytes| self.refuse(bytes))
            .ok()
    }

    /// Says that a buffer of the assignment could not grow to `bytes`.
    pub(super) fn refuse(&self, bytes: u64) {
        (self.refused).fetch_max(bytes.max(1), std::sync::atomic::Ordering::Relaxed);
    }

    /// The most bytes a buffer of the assignment could not grow to, if any could not.
    pub(super) fn refused(&self) -> Option<u64> {
        let bytes = self.refused.load(std::sync::atomic::Ordering::Relaxed);
        (bytes > 0).then_some(bytes)
    }

    /// A worker's running count `listed`, of which `added` were added already: adds the rest
    /// once it makes a step; false once the assignment's total is past the bound.
    #[inline]
    pub(super) fn keeps_within(&self, listed: usize, added: &mut usize) -> bool {
        if listed - *added < TALLY_STEP {
            return true;
        }
        let step = listed - *added;
        *added = listed;
        let total = self
            .total
            .fetch_add(step, std::sync::atomic::Ordering::Relaxed);
        total + step <= self.limit
    }
}

/// Most threads one assignment takes (see [`AssignLimits::max_threads`]): its bands and
/// chunks are cut for at most this many.
pub const MAX_ASSIGN_THREADS: usize = 8;

/// An assignment whose previous frame listed this many indices runs on all cores whatever its
/// light count: fine grids give each light hundreds of cells, and scattering that many indices
/// outweighs the cost of waking rayon's workers.
pub const PARALLEL_INDICES: usize = 1 << 17;

/// An assignment whose previous one (same [`Assigner`](super::Assigner)) took this much CPU
/// time (its wall time times its threads) or more runs on two threads, and on one more for
/// every further `PARALLEL_SECONDS` (up to the pool, at most 8), from [`PARALLEL_MIN_LIGHTS`]
/// lights up: waking a pool's worker costs tens of microseconds, which half of this repays.
/// Counting the threads' time, not the wall time, keeps a parallel assignment parallel when
/// it becomes fast.
pub const PARALLEL_SECONDS: f64 = 100e-6;

/// Fewest lights the [`PARALLEL_SECONDS`] rule takes to the pool: below, an assignment that
/// took long did so on a slow or busy core, not for its work.
pub const PARALLEL_MIN_LIGHTS: usize = 256;

/// Most cells an assignment takes: its per-cell arrays (difference counts, counts, offsets,
/// cursors; each chunk of lights has its own) hold 16 bytes a cell or more, 1 GiB and up
/// here. Four times what the grid textures address (2²⁴ cells, which the renderer refuses past
/// by name), so a CPU-only caller has room; a larger grid (up to 2³², which raised `max_tiles`
/// and a large frame can make) gets no cells (see
/// [`Assigner::assign`](super::Assigner::assign)).
pub const MAX_ASSIGN_CELLS: u32 = 1 << 26;

/// What an index or a cell weighs against a run in [`assign_work`].
pub const INDEX_WEIGHT: f64 = 1.0 / 64.0;

/// An assignment's work in units of one run: each run of consecutive cells a light touches
/// (a row of a slice: its chord, its columns, the cone's test, the run and its two
/// difference counts), plus [`INDEX_WEIGHT`] for each index scattered and each cell counted.
///
/// The automatic grid predicts an assignment's time from it, and an
/// [`Assigner`](super::Assigner) compares one thread with the pool by it. Fitted to the
/// renderer's assignments on the courtyard over footprints 64 to 8 px: the time follows the
/// runs, while indices and cells add little, so a calibration at one grid predicts the others.
/// The small weight keeps grids of very long runs (huge lights) from looking free.
pub fn assign_work(runs: usize, indices: usize, cells: u32) -> f64 {
    runs as f64 + INDEX_WEIGHT * (indices as f64 + f64::from(cells))
}

/// Limits of one assignment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AssignLimits {
    /// Most lights one cell keeps.
    pub cell_cap: u32,
    /// Most indices in total.
    pub max_indices: usize,
    /// Lights from this count up are assigned on all cores (rayon's pool, at most 8); so is
    /// any assignment whose previous one (same [`Assigner`](super::Assigner)) listed
    /// [`PARALLEL_INDICES`] or more, and one that took [`PARALLEL_SECONDS`] of CPU time or
    /// more (from [`PARALLEL_MIN_LIGHTS`] lights) on a thread per such time and one, unless
    /// this is `usize::MAX` (never in parallel). Those two by the previous assignment only
    /// while the pool measures as fast: an [`Assigner`](super::Assigner) keeps one thread
    /// where one thread takes at most 0.9× the pool's time per unit of work (the pool's own
    /// estimate of it: what its workers spent working; tries of the other mode now and then).
    /// From this count of lights up the pool always runs.
    pub parallel_threshold: usize,
    /// Most references listed before the overflow policy: past it nothing is listed
    /// ([`Assignment::unlisted`]); [`MAX_UNTRIMMED_INDICES`] by default.
    pub max_untrimmed: usize,
    /// Most threads, the caller included (at most [`MAX_ASSIGN_THREADS`](super::MAX_ASSIGN_THREADS)
    /// are used); 1 never enters rayon, not even to learn the pool's size.
    pub max_threads: usize,
}

impl Default for AssignLimits {
    fn default() -> Self {
        AssignLimits {
            cell_cap: 255,
            max_indices: 1 << 24,
            parallel_threshold: 4096,
            max_threads: super::MAX_ASSIGN_THREADS,
            max_untrimmed: MAX_UNTRIMMED_INDICES,
        }
    }
}

/// Figures of one assignment.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct AssignStats {
    /// Cells in the grid.
    pub clusters: u32,
    /// Cells with at least one light.
    pub nonempty_clusters: u32,
    /// Mean lights per non-empty cell (after the cap).
    pub avg_lights_per_nonempty: f64,
    /// Most lights any cell touched (before the cap).
    pub max_lights_per_cluster: u32,
    /// Light references dropped by the overflow policy; on a grid of more than
    /// `MAX_ASSIGN_CELLS` (2²⁶) cells, which gets none, every light once. (A frame's total, with
    /// forward's, is in its `lights` figures.)
    #[serde(skip)]
    pub overflowed_lights: u64,
    /// Length of the index list.
    #[serde(skip)]
    pub indices: usize,
    /// Lights that touch at least one cell (a frame reports them with its `lights` figures).
    #[serde(skip)]
    pub visible_lights: usize,
    /// Runs of consecutive cells the lights were found to touch (before the cap): the
    /// per-run part of the assignment's work, beside the per-index and per-cell parts.
    #[serde(rename = "assign_runs")]
    pub runs: usize,
    /// Threads the assignment ran on (1 unless it took rayon's pool).
    #[serde(rename = "assign_threads")]
    pub threads: usize,
}

/// The result: per-cell offset and count into `indices`, and the visible lights.
#[derive(Clone, Debug, Default)]
pub struct Assignment {
    /// Original indices of the lights that touch at least one cell, ascending.
    pub visible: Vec<u32>,
    /// Per cell: first position in `indices`.
    pub offsets: Vec<u32>,
    /// Per cell: number of lights (≤ the cap).
    pub counts: Vec<u32>,
    /// Positions in `visible`, grouped by cell (16-bit while they fit).
    pub indices: IndexList,
    /// Figures.
    pub stats: AssignStats,
    /// `Some(n)`: the cells' lists would hold at least `n` references before the overflow
    /// policy, more than [`AssignLimits::max_untrimmed`], so none were listed (every cell is empty;
    /// the lights found visible, which may stop short of all of them, count as overflowed).
    pub unlisted: Option<usize>,
    /// `Some(bytes)`: a buffer the lists are built in could not grow to `bytes`, more than the
    /// allocator gave (an address-space limit, a 32-bit process); nothing was listed, as for
    /// [`Assignment::unlisted`], which is `Some` too (`offsets` and `counts` may then be empty:
    /// where even they cannot be allocated).
    pub unallocated: Option<u64>,
    /// The cells the overflow policy cut, ascending, with the references each lost (empty
    /// without overflow): where in the picture the dropped lights are missing.
    pub(crate) overfull: Vec<(u32, u32)>,
}

impl Assignment {
    /// Gives back what a burst of lights grew the lists to ([`fit`](crate::cluster::headroom::fit)),
    /// keeping them, or (not `keep`) emptying them first.
    pub(crate) fn fit(&mut self, keep: bool) {
        use crate::cluster::headroom::fit_keeping;
        fit_keeping(&mut self.visible, keep);
        fit_keeping(&mut self.offsets, keep);
        fit_keeping(&mut self.counts, keep);
        fit_keeping(&mut self.overfull, keep);
        self.indices.fit_keeping(keep);
    }

    /// Light references these lists leave out: those the overflow policy dropped, or
    /// `u64::MAX` where none could be listed ([`Assignment::unlisted`]), worse than any lists.
    pub(crate) fn dropped_references(&self) -> u64 {
        match self.unlisted {
            Some(_) => u64::MAX,
            None => self.stats.overflowed_lights,
        }
    }

    /// No lists: every one of `cells` cells empty (offsets and counts 0), no indices; where
    /// the allocator refuses even the per-cell arrays, none (nothing is listed either way).
    pub(super) fn empty_lists(&mut self, cells: usize) {
        self.indices.clear();
        for per_cell in [&mut self.offsets, &mut self.counts] {
            per_cell.clear();
            if try_room_for(per_cell, cells).is_ok() {
                per_cell.resize(cells, 0);
            }
        }
    }
}

/// Consecutive cells one light touches (numbered from its band's first cell in a band).
#[derive(Clone, Copy, Debug)]
pub(super) struct Run {
    pub(super) start: u32,
    pub(super) len: u32,
}

/// Figures of the per-cell counts, gathered in the pass that makes the offsets.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Totals {
    /// Length of the index list.
    pub(super) indices: usize,
    /// Largest count.
    pub(super) max: u32,
    /// Cells with a light.
    pub(super) nonempty: u32,
    /// Runs of consecutive cells found (before any cap).
    pub(super) runs: usize,
}

impl Totals {
    /// Takes one cell's count in.
    #[inline(always)]
    pub(super) fn add(&mut self, n: u32) {
        self.indices += n as usize;
        self.max = self.max.max(n);
        self.nonempty += u32::from(n > 0);
    }

    /// The figures of `counts` (after the overflow policy changed them).
    pub(super) fn of(counts: &[u32]) -> Totals {
        let mut totals = Totals::default();
        counts.iter().for_each(|&n| totals.add(n));
        totals
    }
}
