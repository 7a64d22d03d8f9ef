//! Light assignment: every light → the cells it can touch ([`cells`]), then one compact
//! index list by a counting sort.
//!
//! The work is shared in one of two ways ([`Assigner::assign`] picks):
//!
//! * **Bands of slices** (`bands.rs`; one band on a single thread, and on several
//!   when the grid has at least as many cells as there are lights): two bands of consecutive
//!   slices a thread, balanced by the previous frame's measured times, each taken by the next
//!   thread free; a band's cells are consecutive cell numbers, so each band owns one
//!   contiguous part of every output array and no thread writes where another does.
//! * **Chunks of lights** (`chunks.rs`; more lights than cells): each thread
//!   finds and sorts its own lights' runs, then blocks of cells gather the chunks' runs.
//!
//! ```text
//! phase 1  per band (or chunk of lights): every light's runs of consecutive cells
//!          (chunks: and per-cell counts kept as a difference array, two additions per run)
//! phase 2  the visible lights (a light is visible if any band listed it), numbered in light
//!          order; where each band's part of the list starts (chunks: counts → offsets)
//! phase 3  bands, block by block of cells: a block's counts from the difference counts of
//!          its parts of the runs, its offsets, and its runs scattered into the list while
//!          the block is in cache (so two threads meet twice a frame, and each per-cell array
//!          is written once); chunks: runs scattered into their own lists, then merged cell
//!          by cell
//! ```
//!
//! Why two: a fine grid gives each light hundreds of cells, and merging chunks cell by cell
//! (with a second copy of the list) is a large share of the work, which bands do not pay; with
//! many small lights each light's setup dominates, every band would look at every light, and
//! chunks of lights share that work evenly.
//!
//! An [`Assigner`] keeps its buffers between frames: after the first frame an assignment
//! reuses every large buffer, so it pays no page faults of fresh buffers.
//!
//! **Overflow policy** (`overflow.rs`). A cell never holds more than `cell_cap` lights
//! (in the renderer, the ES 2.0 shader's constant loop bound; on ES 3.0 only the index list
//! bounds a cell): it keeps the `cell_cap` lights with the largest
//! `max(radiance) / (1 + distance²)` to the cell centre (of equal ones, the earlier) and drops
//! the rest, in one selection and one pass (no sort per cell). If the whole list would exceed
//! `max_indices` (what the index texture holds), the per-cell cap is lowered to the largest
//! that fits (a binary search over the counts). Nothing wraps and nothing reads out of range;
//! every dropped light is counted in [`AssignStats::overflowed_lights`], and the image degrades
//! by exactly those lights' contributions (measurable against plain forward).

pub(super) mod bands;
pub mod cells;
mod chunks;
mod cone;
pub mod index_list;
mod overflow;
#[cfg(test)]
mod paths_tests;
mod rows;
mod simd;
#[cfg(test)]
mod tests;
mod thread_choice;
mod types;
#[cfg(test)]
mod unlisted_tests;

pub use types::{
    assign_work, AssignLimits, AssignStats, Assignment, INDEX_WEIGHT, MAX_ASSIGN_CELLS,
    MAX_ASSIGN_THREADS, MAX_UNTRIMMED_INDICES, PARALLEL_INDICES, PARALLEL_MIN_LIGHTS,
    PARALLEL_SECONDS,
};

use crate::cluster::grid::ClusterGrid;
use crate::cluster::view_light::GpuLight;
use bands::Bands;
use chunks::Chunks;
use overflow::{apply_cap, Overflow};
use thread_choice::ThreadChoice;
use types::Totals;

/// Light assignment with buffers kept from frame to frame. One per renderer (or per thread).
/// Once its buffers have grown to a frame's size, an assignment allocates nothing.
#[derive(Default)]
pub struct Assigner {
    bands: Bands,
    chunks: Chunks,
    out: Assignment,
    /// The overflow policy's buffers.
    overflow: Overflow,
    /// Whether a grid past [`MAX_ASSIGN_CELLS`] was warned of (once per assigner).
    warned_oversize: bool,
    /// CPU seconds the last assignment took: its wall time times its threads.
    last_cpu_seconds: f64,
    /// Indices the last assignment listed (the lists may be a candidate's since).
    frame_indices: usize,
    /// One thread or the pool, by measure, where the rules would take the pool.
    choice: ThreadChoice,
    /// Threads the last assignment took.
    last_threads: usize,
    /// The bands' split of the last assignment on the pool, kept while one thread runs.
    pool_split: Option<bands::SplitRecord>,
    /// An assignment entered rayon's pool from one of its workers since the last
    /// [`Assigner::take_ran_other_jobs`].
    may_have_run_other_jobs: bool,
}

/// What the next frame's assignment follows from the last frame's (its threads and the bands'
/// split), kept aside while an automatic grid candidate is assigned in between.
struct FrameRecord {
    cpu_seconds: f64,
    indices: usize,
    split: bands::SplitRecord,
    choice: ThreadChoice,
    threads: usize,
}

impl Assigner {
    /// An assigner with empty buffers (they grow on first use and are then reused).
    pub fn new() -> Assigner {
        Assigner::default()
    }

    /// Gives back what a burst of lights grew the buffers to (the renderer calls it once frames
    /// have needed a quarter at most for `SHRINK_AFTER` frames in a row, as it does its GPU
    /// stores): the last result is kept with room for its size, or (not `keep_result`)
    /// emptied; the scratch is emptied.
    pub fn fit_buffers(&mut self, keep_result: bool) {
        self.bands.fit();
        self.chunks.fit();
        self.out.fit(keep_result);
        self.overflow.fit();
    }

    /// Whether an assignment since the last call entered rayon's pool from one of its
    /// workers, which runs other queued jobs while it waits (a job that makes its own GL
    /// context current leaves the caller's frame without its own).
    pub fn take_ran_other_jobs(&mut self) -> bool {
        std::mem::take(&mut self.may_have_run_other_jobs)
    }

    /// The last result.
    pub fn assignment(&self) -> &Assignment {
        &self.out
    }

    /// [`Assigner::assign`] for a grid that is not the frame's (the automatic grid's
    /// candidates, measured with the frame's assigner so that the grid it adopts already fits
    /// its buffers): the next frame still takes its threads and its bands' split from the
    /// last frame's assignment, not from this one.
    pub fn assign_candidate(
        &mut self,
        grid: &ClusterGrid,
        lights: &[GpuLight],
        camera_far: f64,
        limits: &AssignLimits,
    ) -> &Assignment {
        let frame = FrameRecord {
            cpu_seconds: self.last_cpu_seconds,
            indices: self.frame_indices,
            split: self.bands.split_record(),
            choice: self.choice,
            threads: self.last_threads,
        };
        self.assign(grid, lights, camera_far, limits);
        self.last_cpu_seconds = frame.cpu_seconds;
        self.frame_indices = frame.indices;
        self.bands.restore_split(&frame.split);
        self.choice = frame.choice;
        self.last_threads = frame.threads;
        &self.out
    }

    /// The result of an assignment that lists nothing ([`Assignment::unlisted`]): empty
    /// cells, every visible light overflowed, the runs found given back.
    fn nothing_listed(&mut self, cells: usize, threads: usize) -> &Assignment {
        self.bands.release_runs();
        self.chunks.release_runs();
        let out = &mut self.out;
        out.empty_lists(cells);
        out.stats.visible_lights = out.visible.len();
        out.stats.overflowed_lights = out.visible.len() as u64;
        out.stats.threads = threads;
        &self.out
    }

    /// Takes the last result out (the next call allocates its output again).
    pub fn into_assignment(self) -> Assignment {
        self.out
    }

    /// Assigns `lights` (view space) to the cells of `grid`. `camera_far` may be infinite.
    ///
    /// A grid of more than [`MAX_ASSIGN_CELLS`] cells is not assigned: its per-cell arrays
    /// would take gigabytes. The result then has no offsets, counts or indices,
    /// [`AssignStats::overflowed_lights`] counts every light once, and the first such call of
    /// this assigner logs a warning. Lists that would hold more than `limits.max_untrimmed`
    /// ([`MAX_UNTRIMMED_INDICES`] by default) references before the overflow policy are not
    /// built either: [`Assignment::unlisted`]
    /// says so (the renderer refuses such a frame), every cell is empty and every visible
    /// light counts as overflowed.
    ///
    /// Inside a renderer call on a driver whose calls take turns (llvmpipe), the turn is let go
    /// meanwhile: the pool's workers may be waiting for it in renderer calls of their own.
    pub fn assign(
        &mut self,
        grid: &ClusterGrid,
        lights: &[GpuLight],
        camera_far: f64,
        limits: &AssignLimits,
    ) -> &Assignment {
        crate::gl::driver_turns::let_go_while(move || {
            self.assign_holding_no_turn(grid, lights, camera_far, limits)
        })
    }

    fn assign_holding_no_turn(
        &mut self,
        grid: &ClusterGrid,
        lights: &[GpuLight],
        camera_far: f64,
        limits: &AssignLimits,
    ) -> &Assignment {
        let cells = grid.total_cells as usize;
        let out = &mut self.out;
        out.visible.clear();
        out.unlisted = None;
        out.unallocated = None;
        out.overfull.clear();
        out.stats = AssignStats {
            clusters: grid.total_cells,
            threads: 1,
            ..AssignStats::default()
        };
        // Zero until this assignment's is known (the early returns below leave it so).
        let last_cpu_seconds = std::mem::take(&mut self.last_cpu_seconds);
        let last_indices = std::mem::take(&mut self.frame_indices);
        if grid.total_cells > MAX_ASSIGN_CELLS {
            if !self.warned_oversize {
                self.warned_oversize = true;
                log::warn!(
                    "light assignment: a grid of {} cells is more than the {MAX_ASSIGN_CELLS} an \
                     assignment takes; it gets no cell lists, and all {} lights count as \
                     overflowed (a larger grid.footprint_px or a lower grid.max_tiles avoid it)",
                    grid.total_cells,
                    lights.len()
                );
            }
            out.indices.clear();
            out.offsets.clear();
            out.counts.clear();
            out.stats.overflowed_lights = lights.len() as u64;
            return &self.out;
        }
        if lights.is_empty() {
            out.empty_lists(cells);
            return &self.out;
        }
        let started = std::time::Instant::now();
        // Asking rayon for its pool's size would build the global pool: not where the caller
        // keeps the assignment on its own thread.
        let pool = match limits.max_threads {
            0 | 1 => 1,
            most => rayon::current_num_threads().min(most),
        };
        let rule = threads_for(lights.len(), last_indices, last_cpu_seconds, limits, pool);
        // Lights past the caller's threshold take the pool; the rules' other reasons are
        // weighed against one thread by measure.
        let chosen = rule > 1 && lights.len() < limits.parallel_threshold;
        let threads = if chosen {
            self.choice.threads(rule)
        } else {
            rule
        };
        keep_pool_split(
            &mut self.bands,
            &mut self.pool_split,
            self.last_threads,
            threads,
        );
        self.last_threads = threads;
        self.may_have_run_other_jobs |= threads > 1 && rayon::current_thread_index().is_some();
        let tally = types::Tally::new(limits.max_untrimmed, most_runs_a_light(grid));
        let by_bands = threads == 1 || cells >= lights.len();
        let totals = if threads == 1 {
            self.bands.assign(grid, lights, camera_far, out, 1, &tally)
        } else {
            // One entry into rayon's pool for all the phases: every entry from outside the
            // pool queues a job in rayon's global injector, which allocates a block of slots
            // every 63 jobs (so a parallel frame allocates once in 63 frames, not 3 times).
            let (bands, chunks) = (&mut self.bands, &mut self.chunks);
            rayon::scope(|_| {
                if by_bands {
                    bands.assign(grid, lights, camera_far, out, threads, &tally)
                } else {
                    chunks.assign(grid, lights, camera_far, out, threads, &tally)
                }
            })
        };
        out.unallocated = tally.refused();
        if out.unlisted.is_some() {
            return self.nothing_listed(cells, threads);
        }
        // Overflow, then the figures.
        out.stats.max_lights_per_cluster = totals.max;
        out.stats.runs = totals.runs;
        out.stats.visible_lights = out.visible.len();
        let capped = apply_cap(out, grid, lights, limits, &mut self.overflow);
        if out.unallocated.is_some() {
            return self.nothing_listed(cells, threads);
        }
        let nonempty = if capped {
            Totals::of(&out.counts).nonempty
        } else {
            totals.nonempty
        };
        out.stats.nonempty_clusters = nonempty;
        out.stats.indices = out.indices.len();
        out.stats.avg_lights_per_nonempty = if nonempty > 0 {
            out.indices.len() as f64 / nonempty as f64
        } else {
            0.0
        };
        out.stats.threads = threads;
        self.frame_indices = out.indices.len();
        let seconds = started.elapsed().as_secs_f64();
        self.last_cpu_seconds = seconds * threads as f64;
        if chosen {
            let work = assign_work(out.stats.runs, out.indices.len(), grid.total_cells);
            // The bands time their own work; the chunks of lights do not.
            let busy = by_bands.then(|| self.bands.busy_seconds());
            self.choice.measured(threads, seconds, work, busy);
        }
        &self.out
    }
}

/// Most runs one light gives on `grid`: one per row of each slice at most (a light's cells in
/// a row are contiguous), over every cascade it may span.
fn most_runs_a_light(grid: &ClusterGrid) -> usize {
    (grid.cascades.iter())
        .map(|c| c.tiles_y as usize * c.slices as usize)
        .sum()
}

/// Keeps the bands' split of the pool aside while one thread runs (`last` threads ran the
/// last assignment, `threads` run this one), and puts it back for the pool's next assignment,
/// so that a try of one thread costs the pool no balance.
fn keep_pool_split(
    bands: &mut Bands,
    pool_split: &mut Option<bands::SplitRecord>,
    last: usize,
    threads: usize,
) {
    if threads == 1 && last > 1 {
        *pool_split = Some(bands.split_record());
    } else if threads > 1 && last == 1 {
        if let Some(split) = pool_split.take() {
            bands.restore_split(&split);
        }
    }
}

/// Threads an assignment of `lights` takes from a pool of `pool` (at most 8), given its
/// previous one's index count and CPU seconds: the pool's when the lights reach
/// `limits.parallel_threshold` or the previous assignment listed [`PARALLEL_INDICES`]; from
/// [`PARALLEL_MIN_LIGHTS`] lights, one more than the whole [`PARALLEL_SECONDS`] in the
/// previous one's CPU time (so two from one up), each worker getting enough work to repay its
/// waking (tens of microseconds on some machines); else one, on the calling thread. Never more
/// than one with `limits.parallel_threshold` at `usize::MAX`. Where the pool comes from the
/// previous assignment (its indices or its time), [`Assigner::assign`] then keeps the work on
/// one thread where one thread measures at most 0.9× the pool's time ([`ThreadChoice`]).
fn threads_for(
    lights: usize,
    last_indices: usize,
    last_cpu_seconds: f64,
    limits: &AssignLimits,
    pool: usize,
) -> usize {
    let most = pool.clamp(1, MAX_ASSIGN_THREADS);
    if limits.parallel_threshold == usize::MAX {
        1
    } else if lights >= limits.parallel_threshold || last_indices >= PARALLEL_INDICES {
        most
    } else if lights >= PARALLEL_MIN_LIGHTS && last_cpu_seconds >= PARALLEL_SECONDS {
        // `as` saturates: any time past 2⁶⁴ shares is the whole pool.
        ((last_cpu_seconds / PARALLEL_SECONDS) as usize)
            .saturating_add(1)
            .min(most)
    } else {
        1
    }
}

/// Assigns `lights` (view space) to the cells of `grid` with fresh buffers (see [`Assigner`]
/// for the per-frame path). `camera_far` may be infinite.
pub fn assign(
    grid: &ClusterGrid,
    lights: &[GpuLight],
    camera_far: f64,
    limits: &AssignLimits,
) -> Assignment {
    let mut assigner = Assigner::new();
    assigner.assign(grid, lights, camera_far, limits);
    assigner.into_assignment()
}
