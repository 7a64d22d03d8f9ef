//! The assignment by **chunks** of lights (see [`super`]): each thread finds and sorts
//! the runs of its own lights, then blocks of cells gather the chunks' per-cell runs in chunk
//! order. Several threads only; one thread takes a single band (`bands.rs`).

use rayon::prelude::*;

use super::cells::for_each_run;
use super::index_list::{EntriesMut, IndexList, LightIndex};
use super::types::{Assignment, Run, Tally, Totals};
use crate::cluster::grid::ClusterGrid;
use crate::cluster::headroom::{clear_with_room_for, room_for, share_of, zeroed_with_room};
use crate::cluster::view_light::GpuLight;

/// The chunks and their buffers, kept between frames.
#[derive(Default)]
pub(super) struct Chunks {
    chunks: Vec<Chunk>,
    /// Per chunk: the visible number of its first visible light (phase 2).
    first_ids: Vec<u32>,
    /// Blocks of cells the merge gathers in parallel.
    blocks: Vec<(usize, usize)>,
}

impl Chunks {
    /// Gives back what a burst of lights grew the chunks' buffers to (each frame fills them
    /// afresh).
    pub(super) fn fit(&mut self) {
        use crate::cluster::headroom::fit_empty;
        for chunk in &mut self.chunks {
            fit_empty(&mut chunk.deltas);
            fit_empty(&mut chunk.runs);
            fit_empty(&mut chunk.ends);
            fit_empty(&mut chunk.visible);
            fit_empty(&mut chunk.offsets);
            fit_empty(&mut chunk.cursor);
            chunk.sorted.fit_keeping(false);
        }
    }

    /// Frees the runs a refused assignment found (see [`Bands::release_runs`](super::bands)).
    pub(super) fn release_runs(&mut self) {
        for chunk in &mut self.chunks {
            chunk.runs = Vec::new();
        }
    }

    /// Phases 1 to 3 over `threads` (at least two) chunks of lights, in parallel (called
    /// inside rayon's pool), into `out`; the list's totals before any cap.
    pub(super) fn assign(
        &mut self,
        grid: &ClusterGrid,
        lights: &[GpuLight],
        camera_far: f64,
        out: &mut Assignment,
        threads: usize,
        tally: &Tally,
    ) -> Totals {
        let cells = grid.total_cells as usize;
        // Phase 1: runs and counts per chunk of lights.
        let chunk_len = lights.len().div_ceil(threads);
        // Fewer chunks than threads when lights are few (49 lights in chunks of 7 make 7, not
        // 8): a chunk past the last would keep an earlier frame's runs.
        let chunks = lights.len().div_ceil(chunk_len);
        // Each chunk keeps room for its share (`share_of`) of the last assignment's runs,
        // visible lights and entries: which chunk's lights are in view changes with the camera
        // and the lights, and a chunk would otherwise grow at each new peak of its own.
        let last_runs: usize = self.chunks.iter().map(|k| k.runs.len()).sum();
        let last_visible: usize = self.chunks.iter().map(|k| k.visible.len()).sum();
        let last_sorted: usize = self.chunks.iter().map(|k| k.sorted.len()).sum();
        let share = |total: usize| share_of(total, chunks);
        let shares = (share(last_runs), share(last_visible));
        let sorted_share = share(last_sorted);
        self.chunks.resize_with(chunks, Chunk::default);
        self.chunks.truncate(chunks);
        self.chunks
            .par_iter_mut()
            .zip(lights.par_chunks(chunk_len))
            .for_each(|(chunk, part)| {
                chunk.find(grid, part, camera_far, shares, tally);
                // Offsets are 32-bit: only for a list that is built.
                if chunk.listed <= tally.limit {
                    chunk.prefix();
                }
            });
        // Phase 2: the visible lights (numbered chunk after chunk: each chunk listed its own
        // in phase 1, so this is a copy, not a pass over every light), then counts and
        // offsets.
        let first_ids = &mut self.first_ids;
        first_ids.clear();
        for (t, chunk) in self.chunks.iter().enumerate() {
            first_ids.push(out.visible.len() as u32);
            let first = (t * chunk_len) as u32;
            out.visible.extend(chunk.visible.iter().map(|&i| first + i));
        }
        let listed = (self.chunks.iter()).fold(0usize, |n, k| n.saturating_add(k.listed));
        if listed > tally.limit || tally.refused().is_some() {
            out.unlisted = Some(listed);
            return Totals::default();
        }
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
        // Phase 3: each chunk sorts its lights locally, then blocks of cells gather the
        // chunks' runs into the final list (contiguous, disjoint slices: no sharing).
        let visible = out.visible.len();
        self.chunks
            .par_iter_mut()
            .zip(first_ids.par_iter())
            .for_each(|(chunk, &first_id)| {
                if let Err(bytes) = chunk.sort_locally(first_id, cells, visible, sorted_share) {
                    tally.refuse(bytes);
                }
            });
        let (chunks, blocks) = (&self.chunks, &mut self.blocks);
        // A chunk's own list refused above lists nothing either.
        match tally.list(&mut out.indices, total as usize, out.visible.len()) {
            Some(EntriesMut::Narrow(list)) => merge(chunks, &out.offsets, list, threads, blocks),
            Some(EntriesMut::Wide(list)) => merge(chunks, &out.offsets, list, threads, blocks),
            None => {
                out.unlisted = Some(listed);
                return Totals::default();
            }
        }
        Totals {
            runs: self.chunks.iter().map(|c| c.runs.len()).sum(),
            ..Totals::of(&out.counts)
        }
    }
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
    /// The entries its runs list (phase 1; past the [`Tally`]'s limit, at least that).
    listed: usize,
    /// The chunk's lights with a run (positions in the chunk), ascending.
    visible: Vec<u32>,
    /// Per cell (plus one): where the cell's run starts in `sorted` (phase 2).
    offsets: Vec<u32>,
    /// The chunk's lights (global visible numbers) grouped by cell (phase 3), at the final
    /// list's width, so the merge copies slices (and the scatter writes half the bytes while
    /// the visible lights fit 16 bits), and one spare entry.
    sorted: IndexList,
    /// Phase 3's write positions, per cell, and the spare entry's.
    cursor: Vec<u32>,
}

impl Chunk {
    /// Phase 1: the runs of `lights` and their per-cell difference counts. `shares`: the
    /// runs and visible lights the chunk keeps room for at least.
    fn find(
        &mut self,
        grid: &ClusterGrid,
        lights: &[GpuLight],
        camera_far: f64,
        (runs_share, visible_share): (usize, usize),
        tally: &Tally,
    ) {
        zeroed_with_room(&mut self.deltas, grid.total_cells as usize + 1);
        clear_with_room_for(&mut self.runs, runs_share);
        self.ends.clear();
        clear_with_room_for(&mut self.visible, visible_share);
        let (deltas, runs) = (&mut self.deltas[..], &mut self.runs);
        let (mut listed, mut added) = (0usize, 0usize);
        // Room for a light's runs before it, kept after each light that took some: no push
        // below grows the buffer.
        let lights = if tally.room_for_runs(runs) {
            lights
        } else {
            &[]
        };
        for (i, light) in lights.iter().enumerate() {
            let before = runs.len();
            // The callback lives on the stack (the refinement takes it out of line): it holds
            // the difference counts as a slice, not through their `Vec`, one load less a run.
            let (deltas, to) = (&mut *deltas, &mut *runs);
            let mut emit = move |start: u32, len: u32| {
                deltas[start as usize] += 1;
                deltas[(start + len) as usize] -= 1;
                to.push(Run { start, len });
            };
            for_each_run(grid, light, camera_far, &mut emit);
            debug_assert!(
                runs.len() - before <= tally.most_runs,
                "a light's runs past the bound"
            );
            self.ends.push(runs.len() as u32);
            if runs.len() > before {
                self.visible.push(i as u32);
                listed += runs[before..]
                    .iter()
                    .map(|run| run.len as usize)
                    .sum::<usize>();
                if !tally.room_for_runs(runs) {
                    break;
                }
            }
            // As a band's phase 1: past this the list is refused, so stop taking memory.
            if listed > tally.limit || !tally.keeps_within(listed, &mut added) {
                break;
            }
        }
        self.listed = listed;
    }

    /// Phase 2: per-cell offsets into the chunk's own sorted list.
    fn prefix(&mut self) {
        room_for(&mut self.offsets, self.deltas.len());
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

    /// Phase 3: writes the chunk's visible lights, numbered from `first_id`, into `out`
    /// grouped by cell, each cell's run starting where `self.cursor` says (advanced as it
    /// goes). Light order is kept, so every cell's list is ascending.
    ///
    /// `self.cursor` has one entry past the cells, pointing at a spare last entry of `out`:
    /// a run of one or two cells (most runs with many small lights) writes two entries,
    /// the second into the spare one when the run has one cell, instead of looping — how
    /// many cells a run has is what a branch predictor cannot learn.
    fn scatter<T: LightIndex>(&mut self, first_id: u32, out: &mut [T]) {
        let spare = self.cursor.len() - 1;
        let mut id = first_id;
        let mut prev = 0usize;
        for &end in &self.ends {
            let end = end as usize;
            if end == prev {
                continue;
            }
            let entry = T::from_u32(id);
            for run in &self.runs[prev..end] {
                let a = run.start as usize;
                if run.len <= 2 {
                    let at = self.cursor[a];
                    out[at as usize] = entry;
                    self.cursor[a] = at + 1;
                    let two = run.len == 2;
                    let cell = if two { a + 1 } else { spare };
                    let at = self.cursor[cell];
                    out[at as usize] = entry;
                    self.cursor[cell] = at + u32::from(two);
                } else {
                    for at in &mut self.cursor[a..a + run.len as usize] {
                        out[*at as usize] = entry;
                        *at += 1;
                    }
                }
            }
            id += 1;
            prev = end;
        }
    }

    /// Phase 3 of one of several chunks: scatters into the chunk's own list, at the width of
    /// a list of `visible` lights, with one spare entry at its end (see [`Chunk::scatter`]),
    /// keeping room for `share` entries (its share of the last assignment's). The bytes its
    /// list could not grow to, if the allocator refused them.
    fn sort_locally(
        &mut self,
        first_id: u32,
        cells: usize,
        visible: usize,
        share: usize,
    ) -> Result<(), u64> {
        let mut sorted = std::mem::take(&mut self.sorted);
        let len = self.offsets[cells];
        room_for(&mut self.cursor, cells + 1);
        self.cursor.clear();
        self.cursor.extend_from_slice(&self.offsets[..cells]);
        self.cursor.push(len);
        let prepared = sorted.prepare_with_room(len as usize + 1, share, visible);
        let result = prepared.map(|list| match list {
            EntriesMut::Narrow(list) => self.scatter(first_id, list),
            EntriesMut::Wide(list) => self.scatter(first_id, list),
        });
        self.sorted = sorted;
        result
    }
}

/// Concatenates the chunks' per-cell runs into `indices`, in parallel over blocks of cells
/// with about equal numbers of indices (`blocks` is the buffer they are listed in).
fn merge<T: LightIndex>(
    chunks: &[Chunk],
    offsets: &[u32],
    indices: &mut [T],
    threads: usize,
    blocks: &mut Vec<(usize, usize)>,
) {
    split_cells_into(offsets, indices.len(), threads * 2, blocks);
    merge_blocks(chunks, offsets, blocks, indices, threads);
}

/// Gathers the cells of `blocks` (contiguous, in cell order) into `out`, which starts at the
/// first block's first index: the two halves of the blocks in parallel, each with half of
/// `threads`, so at most `threads` at once (`rayon::join` keeps its jobs on the stack, so no
/// list of jobs is allocated); with one thread, block after block.
fn merge_blocks<T: LightIndex>(
    chunks: &[Chunk],
    offsets: &[u32],
    blocks: &[(usize, usize)],
    out: &mut [T],
    threads: usize,
) {
    if threads < 2 || blocks.len() < 2 {
        let mut at = 0;
        for &(c0, c1) in blocks {
            for cell in c0..c1 {
                for chunk in chunks {
                    let (o, n) = (chunk.offsets[cell] as usize, chunk.count(cell) as usize);
                    out[at..at + n].copy_from_slice(&T::entries(&chunk.sorted)[o..o + n]);
                    at += n;
                }
            }
        }
        return;
    }
    let (left, right) = blocks.split_at(blocks.len() / 2);
    let split = (offsets[right[0].0] - offsets[left[0].0]) as usize;
    let (out_left, out_right) = out.split_at_mut(split);
    let half = threads / 2;
    rayon::join(
        || merge_blocks(chunks, offsets, left, out_left, threads - half),
        || merge_blocks(chunks, offsets, right, out_right, half),
    );
}

/// Splits the cells into at most `parts` contiguous, non-empty blocks with about equal numbers
/// of indices (fewer blocks when there are fewer cells).
#[cfg(test)]
pub(super) fn split_cells(offsets: &[u32], total: usize, parts: usize) -> Vec<(usize, usize)> {
    let mut blocks = Vec::new();
    split_cells_into(offsets, total, parts, &mut blocks);
    blocks
}

/// `split_cells` (the tests' version) into `blocks` (cleared first).
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
