//! Light assignment: every light → the cells it can touch ([`super::cells`]), then one compact
//! index list by a counting sort.
//!
//! ```text
//! phase 1  per light (parallel over chunks of lights): runs of consecutive cells, and per-cell
//!          counts kept as a difference array (two additions per run)
//! phase 2  counts → prefix sums → offsets; visible lights numbered chunk after chunk
//! phase 3  one chunk: scatter its runs straight into the final list. Several: each chunk
//!          scatters into its own list (parallel over chunks), then blocks of cells gather
//!          the chunks' per-cell runs in chunk order (parallel over blocks)
//! ```
//!
//! Only lights that touch at least one cell are kept ("visible"), and the list refers to them
//! by their position among the visible lights. Lights are listed in ascending order inside each
//! cell, the order plain forward adds them in, so the per-pixel sums match forward exactly.
//!
//! An [`Assigner`] keeps its buffers between frames: after the first frame an assignment
//! reuses every large buffer (the page faults of fresh buffers were a tenth of the time).
//!
//! **Overflow policy.** A cell never holds more than `cell_cap` lights (the shader's loop bound
//! on ES 2.0 and the count field of the grid texel): it keeps the `cell_cap` lights with the
//! largest `max(radiance) / (1 + distance²)` to the cell centre (of equal ones, the earlier)
//! and drops the rest, in one selection and one pass (no sort per cell). If the whole list
//! would exceed `max_indices` (what the index texture holds), the per-cell cap is lowered to
//! the largest that fits (a binary search over the counts). Nothing wraps and nothing reads
//! out of range; every dropped light is counted in [`AssignStats::overflowed_lights`], and the
//! image degrades by exactly those lights' contributions (measurable against plain forward).

use std::cell::RefCell;

use rayon::prelude::*;

use super::cells::for_each_run;
use super::grid::{CellCoord, ClusterGrid};
use super::pack::GpuLight;

/// An assignment whose previous frame listed this many indices runs on all cores whatever its
/// light count: fine grids give each light hundreds of cells, and at about 3 ns an index such
/// a frame's work (a millisecond or more) dwarfs the tens of microseconds of waking rayon's
/// workers.
pub const PARALLEL_INDICES: usize = 1 << 17;

/// Limits of one assignment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AssignLimits {
    /// Most lights one cell keeps.
    pub cell_cap: u32,
    /// Most indices in total.
    pub max_indices: usize,
    /// Lights from this count up are assigned on all cores (rayon's pool); so is any
    /// assignment whose previous one (same [`Assigner`]) listed [`PARALLEL_INDICES`] or more,
    /// unless this is `usize::MAX` (never in parallel).
    pub parallel_threshold: usize,
}

impl Default for AssignLimits {
    fn default() -> Self {
        AssignLimits {
            cell_cap: 255,
            max_indices: 1 << 24,
            parallel_threshold: 4096,
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
    /// Light references dropped by the overflow policy.
    pub overflowed_lights: u64,
    /// Length of the index list.
    pub indices: usize,
    /// Lights that touch at least one cell.
    pub visible_lights: usize,
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
    /// Positions in `visible`, grouped by cell.
    pub indices: Vec<u32>,
    /// Figures.
    pub stats: AssignStats,
}

/// Consecutive cells one light touches.
#[derive(Clone, Copy, Debug)]
struct Run {
    start: u32,
    len: u32,
}

/// One chunk of lights: phase 1's runs and counts, phase 3's locally sorted list. Aligned to
/// two cache lines: the chunks sit side by side in a `Vec` and their buffers' lengths change
/// with every push, so unaligned neighbours would bounce a shared cache line between the
/// threads (false sharing doubled the phase's time).
#[derive(Default)]
#[repr(align(128))]
struct Chunk {
    /// Per cell (plus one): a difference array of the chunk's runs, `+1` where a run starts
    /// and `−1` where it ends, so a run costs two additions whatever its length; its running
    /// sum over cells is the number of the chunk's lights touching each cell.
    deltas: Vec<i32>,
    /// The chunk's runs, light after light.
    runs: Vec<Run>,
    /// Per light of the chunk: the end of its runs in `runs`.
    ends: Vec<u32>,
    /// Per cell (plus one): where the cell's run starts in `sorted` (phase 2).
    offsets: Vec<u32>,
    /// The chunk's lights (global visible numbers) grouped by cell (phase 3, several chunks
    /// only; a single chunk writes the final list directly).
    sorted: Vec<u32>,
    /// Phase 3's write positions, per cell.
    cursor: Vec<u32>,
}

impl Chunk {
    /// Phase 1: the runs of `lights` and their per-cell difference counts.
    fn find(&mut self, grid: &ClusterGrid, lights: &[GpuLight], camera_far: f64) {
        self.deltas.clear();
        self.deltas.resize(grid.total_cells as usize + 1, 0);
        self.runs.clear();
        self.ends.clear();
        let (deltas, runs) = (&mut self.deltas, &mut self.runs);
        for light in lights {
            for_each_run(grid, light, camera_far, &mut |start, len| {
                deltas[start as usize] += 1;
                deltas[(start + len) as usize] -= 1;
                runs.push(Run { start, len });
            });
            self.ends.push(runs.len() as u32);
        }
    }

    /// Phase 2: per-cell offsets into the chunk's own sorted list.
    fn prefix(&mut self) {
        self.offsets.clear();
        let (mut running, mut total) = (0i32, 0u32);
        for delta in &self.deltas {
            self.offsets.push(total);
            running += delta;
            total += running as u32;
        }
    }

    /// Lights of the chunk touching `cell`.
    fn count(&self, cell: usize) -> u32 {
        self.offsets[cell + 1] - self.offsets[cell]
    }

    /// Phase 2 when this is the only chunk, in one pass over the cells: the final counts and
    /// offsets into `out`, the scatter's cursor, and the list's [`Totals`].
    fn totals_into(&mut self, out: &mut Assignment) -> Totals {
        let cells = self.deltas.len() - 1;
        out.counts.resize(cells, 0);
        out.offsets.resize(cells, 0);
        self.cursor.resize(cells, 0);
        let mut running = 0i32;
        let mut totals = Totals::default();
        let columns = out
            .counts
            .iter_mut()
            .zip(&mut out.offsets)
            .zip(&mut self.cursor);
        for (((count, offset), cursor), delta) in columns.zip(&self.deltas) {
            running += delta;
            let n = running as u32;
            *count = n;
            *offset = totals.indices as u32;
            *cursor = totals.indices as u32;
            totals.add(n);
        }
        totals
    }

    /// Phase 3: writes the chunk's visible lights, numbered from `first_id`, into `out`
    /// grouped by cell, each cell's run starting where `self.cursor` says (advanced as it
    /// goes). Light order is kept, so every cell's list is ascending.
    fn scatter(&mut self, first_id: u32, out: &mut [u32]) {
        let mut id = first_id;
        let mut prev = 0usize;
        for &end in &self.ends {
            let end = end as usize;
            if end == prev {
                continue;
            }
            for run in &self.runs[prev..end] {
                let a = run.start as usize;
                for at in &mut self.cursor[a..a + run.len as usize] {
                    out[*at as usize] = id;
                    *at += 1;
                }
            }
            id += 1;
            prev = end;
        }
    }

    /// Phase 3 of one of several chunks: scatters into the chunk's own list.
    fn sort_locally(&mut self, first_id: u32, cells: usize) {
        let mut sorted = std::mem::take(&mut self.sorted);
        sorted.resize(self.offsets[cells] as usize, 0);
        self.cursor.clear();
        self.cursor.extend_from_slice(&self.offsets[..cells]);
        self.scatter(first_id, &mut sorted);
        self.sorted = sorted;
    }
}

/// Figures of the per-cell counts, gathered in the pass that makes the offsets.
#[derive(Clone, Copy, Debug, Default)]
struct Totals {
    /// Length of the index list.
    indices: usize,
    /// Largest count.
    max: u32,
    /// Cells with a light.
    nonempty: u32,
}

impl Totals {
    /// Takes one cell's count in.
    fn add(&mut self, n: u32) {
        self.indices += n as usize;
        self.max = self.max.max(n);
        self.nonempty += u32::from(n > 0);
    }

    /// The figures of `counts` (the several-chunk path, which sums counts itself).
    fn of(counts: &[u32]) -> Totals {
        let mut totals = Totals::default();
        counts.iter().for_each(|&n| totals.add(n));
        totals
    }
}

/// Light assignment with buffers kept from frame to frame. One per renderer (or per thread).
/// Once its buffers have grown to a frame's size, an assignment allocates nothing.
#[derive(Default)]
pub struct Assigner {
    chunks: Vec<Chunk>,
    out: Assignment,
    /// Per chunk: the visible number of its first visible light (phase 2).
    first_ids: Vec<u32>,
    /// Blocks of cells the several-chunk merge gathers in parallel.
    blocks: Vec<(usize, usize)>,
    /// The overflow policy's buffers.
    overflow: Overflow,
}

/// Buffers of the overflow policy, kept between frames.
#[derive(Default)]
struct Overflow {
    /// The compacted list, swapped with the assignment's (which becomes the next spare).
    kept: Vec<u32>,
    /// The overfull cells: (cell, offset, count).
    lists: Vec<(u32, usize, usize)>,
    /// What importance reads of each visible light (see [`trim_overfull_cells`]).
    packed: Vec<[f32; 4]>,
}

impl Assigner {
    /// An assigner with empty buffers (they grow on first use and are then reused).
    pub fn new() -> Assigner {
        Assigner::default()
    }

    /// The last result.
    pub fn assignment(&self) -> &Assignment {
        &self.out
    }

    /// Takes the last result out (the next call allocates its output again).
    pub fn into_assignment(self) -> Assignment {
        self.out
    }

    /// Assigns `lights` (view space) to the cells of `grid`. `camera_far` may be infinite.
    pub fn assign(
        &mut self,
        grid: &ClusterGrid,
        lights: &[GpuLight],
        camera_far: f64,
        limits: &AssignLimits,
    ) -> &Assignment {
        let cells = grid.total_cells as usize;
        let out = &mut self.out;
        out.visible.clear();
        out.stats = AssignStats {
            clusters: grid.total_cells,
            ..AssignStats::default()
        };
        if lights.is_empty() {
            out.indices.clear();
            out.offsets.clear();
            out.offsets.resize(cells, 0);
            out.counts.clear();
            out.counts.resize(cells, 0);
            return &self.out;
        }
        // Waking rayon's workers costs tens of microseconds on some machines: small light
        // counts stay on the calling thread.
        let heavy =
            out.indices.len() >= PARALLEL_INDICES && limits.parallel_threshold != usize::MAX;
        let threads = if lights.len() >= limits.parallel_threshold || heavy {
            rayon::current_num_threads().clamp(1, 8)
        } else {
            1
        };
        if threads == 1 {
            self.assign_in_chunks(grid, lights, camera_far, limits, 1);
        } else {
            // One entry into rayon's pool for all the phases: every entry from outside the
            // pool queues a job in rayon's global injector, which allocates a block of slots
            // every 63 jobs (so a parallel frame allocates once in 63 frames, not 3 times).
            rayon::scope(|_| self.assign_in_chunks(grid, lights, camera_far, limits, threads));
        }
        &self.out
    }

    /// Phases 1 to 3 and the overflow policy over `threads` chunks of lights (in parallel when
    /// more than one: called inside rayon's pool then).
    fn assign_in_chunks(
        &mut self,
        grid: &ClusterGrid,
        lights: &[GpuLight],
        camera_far: f64,
        limits: &AssignLimits,
        threads: usize,
    ) {
        let cells = grid.total_cells as usize;
        let out = &mut self.out;
        // Phase 1: runs and counts per chunk of lights.
        let chunk_len = lights.len().div_ceil(threads);
        self.chunks.resize_with(threads, Chunk::default);
        self.chunks.truncate(threads);
        if threads == 1 {
            self.chunks[0].find(grid, lights, camera_far);
        } else {
            self.chunks
                .par_iter_mut()
                .zip(lights.par_chunks(chunk_len))
                .for_each(|(chunk, part)| chunk.find(grid, part, camera_far));
        }
        // Phase 2: the visible lights (numbered chunk after chunk), then counts and offsets.
        let first_ids = &mut self.first_ids;
        first_ids.clear();
        for (t, chunk) in self.chunks.iter().enumerate() {
            first_ids.push(out.visible.len() as u32);
            let first = (t * chunk_len) as u32;
            let mut prev = 0;
            for (i, &end) in chunk.ends.iter().enumerate() {
                if end > prev {
                    out.visible.push(first + i as u32);
                }
                prev = end;
            }
        }
        let totals = if threads == 1 {
            let totals = self.chunks[0].totals_into(out);
            // Phase 3. Every entry is written, so the list is not cleared first: only growth
            // is zero-filled.
            out.indices.resize(totals.indices, 0);
            self.chunks[0].scatter(0, &mut out.indices);
            totals
        } else {
            self.chunks.iter_mut().for_each(Chunk::prefix);
            let chunks = &self.chunks;
            out.counts.clear();
            out.counts
                .extend((0..cells).map(|c| chunks.iter().map(|k| k.count(c)).sum::<u32>()));
            out.offsets.clear();
            let mut total = 0u32;
            out.offsets.extend(out.counts.iter().map(|&n| {
                let o = total;
                total += n;
                o
            }));
            out.indices.resize(total as usize, 0);
            // Phase 3: each chunk sorts its lights locally, then blocks of cells gather the
            // chunks' runs into the final list (contiguous, disjoint slices: no sharing).
            self.chunks
                .par_iter_mut()
                .zip(first_ids.par_iter())
                .for_each(|(chunk, &first_id)| chunk.sort_locally(first_id, cells));
            merge(
                &self.chunks,
                &out.offsets,
                &mut out.indices,
                threads,
                &mut self.blocks,
            );
            Totals::of(&out.counts)
        };
        // Overflow, then the figures.
        out.stats.max_lights_per_cluster = totals.max;
        out.stats.visible_lights = out.visible.len();
        let nonempty = if apply_cap(out, grid, lights, limits, &mut self.overflow) {
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
    }
}

/// Concatenates the chunks' per-cell runs into `indices`, in parallel over blocks of cells
/// with about equal numbers of indices (`blocks` is the buffer they are listed in).
fn merge(
    chunks: &[Chunk],
    offsets: &[u32],
    indices: &mut [u32],
    threads: usize,
    blocks: &mut Vec<(usize, usize)>,
) {
    split_cells_into(offsets, indices.len(), threads * 2, blocks);
    merge_blocks(chunks, offsets, blocks, indices);
}

/// Gathers the cells of `blocks` (contiguous, in cell order) into `out`, which starts at the
/// first block's first index: the two halves of the blocks in parallel (`rayon::join` keeps
/// its jobs on the stack, so no list of jobs is allocated).
fn merge_blocks(chunks: &[Chunk], offsets: &[u32], blocks: &[(usize, usize)], out: &mut [u32]) {
    match blocks {
        [] => {}
        &[(c0, c1)] => {
            let mut at = 0;
            for cell in c0..c1 {
                for chunk in chunks {
                    let (o, n) = (chunk.offsets[cell] as usize, chunk.count(cell) as usize);
                    out[at..at + n].copy_from_slice(&chunk.sorted[o..o + n]);
                    at += n;
                }
            }
        }
        _ => {
            let (left, right) = blocks.split_at(blocks.len() / 2);
            let split = (offsets[right[0].0] - offsets[left[0].0]) as usize;
            let (out_left, out_right) = out.split_at_mut(split);
            rayon::join(
                || merge_blocks(chunks, offsets, left, out_left),
                || merge_blocks(chunks, offsets, right, out_right),
            );
        }
    }
}

/// Splits the cells into at most `parts` contiguous, non-empty blocks with about equal numbers
/// of indices (fewer blocks when there are fewer cells).
#[cfg(test)]
fn split_cells(offsets: &[u32], total: usize, parts: usize) -> Vec<(usize, usize)> {
    let mut blocks = Vec::new();
    split_cells_into(offsets, total, parts, &mut blocks);
    blocks
}

/// [`split_cells`] into `blocks` (cleared first).
fn split_cells_into(offsets: &[u32], total: usize, parts: usize, blocks: &mut Vec<(usize, usize)>) {
    let cells = offsets.len();
    blocks.clear();
    let mut start = 0;
    for p in 1..parts {
        let target = (total * p / parts) as u32;
        let end = offsets.partition_point(|&o| o < target).clamp(start, cells);
        if end > start {
            blocks.push((start, end));
            start = end;
        }
    }
    if start < cells {
        blocks.push((start, cells));
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

/// Applies the overflow policy in place (see the module docs); true if it dropped any light.
fn apply_cap(
    out: &mut Assignment,
    grid: &ClusterGrid,
    lights: &[GpuLight],
    limits: &AssignLimits,
    scratch: &mut Overflow,
) -> bool {
    let max = out.stats.max_lights_per_cluster;
    if max <= limits.cell_cap && out.indices.len() <= limits.max_indices {
        return false;
    }
    let cap = effective_cap(&out.counts, limits.cell_cap, limits.max_indices);
    if max <= cap {
        return false;
    }
    trim_overfull_cells(out, grid, lights, cap, scratch);
    // Compact: every cell keeps the first `cap` entries of its list (the trim put the kept
    // lights there, in ascending order).
    let kept = &mut scratch.kept;
    kept.clear();
    kept.reserve(out.indices.len().min(limits.max_indices));
    for cell in 0..out.counts.len() {
        let (o, n) = (out.offsets[cell] as usize, out.counts[cell] as usize);
        let keep = n.min(cap as usize);
        out.stats.overflowed_lights += (n - keep) as u64;
        out.offsets[cell] = kept.len() as u32;
        out.counts[cell] = keep as u32;
        kept.extend_from_slice(&out.indices[o..o + keep]);
    }
    std::mem::swap(&mut out.indices, kept);
    true
}

thread_local! {
    /// One trimmed cell's keys and the selection's copy of them, kept per thread from cell to
    /// cell and frame to frame.
    static TRIM_KEYS: RefCell<(Vec<f64>, Vec<f64>)> = const { RefCell::new((Vec::new(), Vec::new())) };
}

/// Moves the `cap` most important lights of every cell holding more to the front of its list,
/// in ascending order (of equally important ones, the earlier). Each light's importance is computed once (the comparisons of a
/// selection would otherwise recompute it, through two random reads, several times per
/// entry: 4 M lights took 2 s), and cells are trimmed in parallel: their lists are disjoint.
fn trim_overfull_cells(
    out: &mut Assignment,
    grid: &ClusterGrid,
    lights: &[GpuLight],
    cap: u32,
    scratch: &mut Overflow,
) {
    let cap = cap as usize;
    // The overfull cells' lists (lists lie in cell order, so they are disjoint and ascending).
    let lists = &mut scratch.lists;
    lists.clear();
    for (cell, (&o, &n)) in out.offsets.iter().zip(&out.counts).enumerate() {
        if n as usize > cap {
            lists.push((cell as u32, o as usize, n as usize));
        }
    }
    // What importance reads of each visible light, packed in list-index order: one 16-byte
    // read per entry instead of two random reads into the full lights.
    let packed = &mut scratch.packed;
    packed.clear();
    packed.extend(out.visible.iter().map(|&l| {
        let light = &lights[l as usize];
        let p = light.position;
        [p.x, p.y, p.z, light.radiance.max_element()]
    }));
    let packed = &scratch.packed[..];
    let trim = |cell: u32, list: &mut [u32]| {
        if cap == 0 {
            return;
        }
        let center = cell_center(grid, cell);
        TRIM_KEYS.with_borrow_mut(|(keys, order)| {
            keys.clear();
            keys.extend(list.iter().map(|&i| {
                let [x, y, z, brightness] = packed[i as usize];
                let position = glam::DVec3::new(x as f64, y as f64, z as f64);
                brightness_over_distance(brightness, position, center)
            }));
            // The cap-th largest key is the threshold: every light above it stays, and of
            // those equal to it the earliest, until the cap is reached. One selection and one
            // pass in list order, so the kept lights stay in ascending order without a sort.
            order.clear();
            order.extend_from_slice(keys);
            let (_, &mut threshold, _) =
                order.select_nth_unstable_by(cap - 1, |a, b| b.total_cmp(a));
            let mut ties = cap
                - keys
                    .iter()
                    .filter(|k| k.total_cmp(&threshold) == std::cmp::Ordering::Greater)
                    .count();
            let mut kept = 0;
            for at in 0..list.len() {
                let keep = match keys[at].total_cmp(&threshold) {
                    std::cmp::Ordering::Greater => true,
                    std::cmp::Ordering::Equal if ties > 0 => {
                        ties -= 1;
                        true
                    }
                    _ => false,
                };
                if keep {
                    list[kept] = list[at];
                    kept += 1;
                }
            }
            debug_assert_eq!(kept, cap);
        });
    };
    let parallel = scratch.lists.iter().map(|&(_, _, n)| n).sum::<usize>() >= PARALLEL_INDICES;
    trim_lists(&scratch.lists, &mut out.indices, 0, parallel, &trim);
}

/// Entries of the index list below which [`trim_lists`] trims its lists on one thread.
const TRIM_GRAIN: usize = 1 << 14;

/// Trims the lists `lists` (cell, offset, count; in cell order) of `indices`, whose first
/// entry is list entry `base`: on the calling thread, or with `parallel` the two halves of
/// the lists at once (`rayon::join` keeps its jobs on the stack), down to [`TRIM_GRAIN`].
fn trim_lists(
    lists: &[(u32, usize, usize)],
    indices: &mut [u32],
    base: usize,
    parallel: bool,
    trim: &(dyn Fn(u32, &mut [u32]) + Sync),
) {
    let span = lists.last().map_or(0, |&(_, o, n)| o + n) - lists.first().map_or(0, |l| l.1);
    if !parallel || lists.len() < 2 || span < TRIM_GRAIN {
        for &(cell, o, n) in lists {
            trim(cell, &mut indices[o - base..o - base + n]);
        }
        return;
    }
    let (left, right) = lists.split_at(lists.len() / 2);
    let split = right[0].1 - base;
    let (head, tail) = indices.split_at_mut(split);
    rayon::join(
        || trim_lists(left, head, base, true, trim),
        || trim_lists(right, tail, base + split, true, trim),
    );
}

/// Importance of a light for a cell under overflow: brighter and closer first — its brightest
/// radiance channel over one plus its squared distance to the cell centre.
fn brightness_over_distance(
    brightness: f32,
    position: glam::DVec3,
    cell_center: glam::DVec3,
) -> f64 {
    brightness as f64 / (1.0 + position.distance_squared(cell_center))
}

fn cell_center(grid: &ClusterGrid, index: u32) -> glam::DVec3 {
    let k = grid
        .cascades
        .iter()
        .rposition(|c| c.first_cell <= index)
        .expect("cell in grid");
    let c = &grid.cascades[k];
    let local = index - c.first_cell;
    let (x, rest) = (local % c.tiles_x, local / c.tiles_x);
    let (y, slice) = (rest % c.tiles_y, rest / c.tiles_y);
    let b = grid.cell_bounds(CellCoord {
        cascade: k as u32,
        slice,
        x,
        y,
    });
    let z1 = if b.depth.1.is_finite() {
        b.depth.1
    } else {
        b.depth.0 * 2.0 + 1.0
    };
    let z = 0.5 * (b.depth.0 + z1);
    let (hx, hy) = grid.projection.half_extent(z);
    glam::DVec3::new(
        0.5 * (b.ndc_x.0 + b.ndc_x.1) * hx,
        0.5 * (b.ndc_y.0 + b.ndc_y.1) * hy,
        -z,
    )
}

#[cfg(test)]
pub(crate) fn split_cells_for_tests(
    offsets: &[u32],
    total: usize,
    parts: usize,
) -> Vec<(usize, usize)> {
    split_cells(offsets, total, parts)
}

/// The largest per-cell cap ≤ `cap` whose capped total fits `budget`.
fn effective_cap(counts: &[u32], cap: u32, budget: usize) -> u32 {
    let total = |c: u32| counts.iter().map(|&n| n.min(c) as usize).sum::<usize>();
    if total(cap) <= budget {
        return cap;
    }
    let (mut lo, mut hi) = (0u32, cap);
    while lo < hi {
        let mid = (lo + hi).div_ceil(2);
        if total(mid) <= budget {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    lo
}
