//! Phase 3 of the bands (see [`super`]): a band's cells counted and its runs scattered into
//! its part of the index list, block by block of cells, each block's counts, offsets and list
//! written while they are in cache.

use super::{Band, CellsOut};
use crate::cluster::assign::index_list::{EntriesMut, LightIndex};
use crate::cluster::assign::types::{Run, Totals};
use std::time::Instant;

impl Band {
    /// Phase 3: the band's `cells` (its counts and offsets) and `list` (its part of the list)
    /// from its runs (phase 1), with its lights' visible numbers (looked up in `numbers` first,
    /// when given); the band's [`Totals`] into `self.totals`.
    ///
    /// Per block of cells: the block's parts of the runs add their difference counts into its
    /// counts (`+1` where a part starts, `−1` (wrapping) where it ends, two additions whatever
    /// its length), whose running sum is each cell's count, and where its list ends is its
    /// offset. Then the runs are taken in reverse light order, each entry written one place
    /// before the last of its cell, so every cell's list comes out ascending in light order
    /// and its offset ends where the list starts (the offsets are the write cursors: no
    /// cursor array). Last, the block's offsets get the band's base.
    ///
    /// One block while the band's offsets and list fit a core's cache; more for a larger
    /// band ([`scatter_blocks`]), so that each per-cell array is written once, in cache.
    pub(super) fn count_and_scatter(
        &mut self,
        numbers: Option<&[u32]>,
        cells: CellsOut,
        list: EntriesMut,
    ) {
        let started = Instant::now();
        if let Some(numbers) = numbers {
            self.ids.clear();
            self.ids.extend(
                self.lights
                    .iter()
                    .map(|&(light, _)| numbers[light as usize]),
            );
        }
        let (counts, offsets) = (cells.counts, cells.offsets);
        self.totals = match list {
            EntriesMut::Narrow(list) => self.count_and_scatter_at(counts, offsets, list),
            EntriesMut::Wide(list) => self.count_and_scatter_at(counts, offsets, list),
        };
        self.seconds += started.elapsed().as_secs_f64();
    }

    /// [`Band::count_and_scatter`] at the list's width: in one block or several; the totals.
    fn count_and_scatter_at<T: LightIndex>(
        &mut self,
        counts: &mut [u32],
        offsets: &mut [u32],
        list: &mut [T],
    ) -> Totals {
        let cells = offsets.len();
        let blocks = scatter_blocks(
            cells,
            list.len(),
            std::mem::size_of::<T>(),
            self.lights.len(),
        );
        #[cfg(test)]
        let blocks = FORCED_SCATTER_BLOCKS
            .with(|b| b.get())
            .map_or(blocks, |b| b.clamp(1, cells));
        let mut totals = Totals::default();
        if blocks == 1 {
            self.count_and_scatter_whole(counts, offsets, list, &mut totals);
        } else {
            self.count_and_scatter_blocks(blocks, counts, offsets, list, &mut totals);
        }
        totals
    }

    /// [`Band::count_and_scatter`] in one block: every run whole, so no cursors into the runs
    /// and no run cut at a block's end (a run's bookkeeping was most of the scatter's work on
    /// runs of one or two cells).
    fn count_and_scatter_whole<T: LightIndex>(
        &self,
        counts: &mut [u32],
        offsets: &mut [u32],
        list: &mut [T],
        totals: &mut Totals,
    ) {
        counts.fill(0);
        let cells = counts.len() as u32;
        for run in &self.runs {
            add_difference(counts, run.start, run.start + run.len, cells);
        }
        sum_counts(counts, offsets, totals);
        let mut end = self.runs.len();
        for (&(_, start), &id) in self.lights.iter().zip(&self.ids).rev() {
            let entry = T::from_u32(id);
            for run in &self.runs[start as usize..end] {
                let a = run.start as usize;
                if run.len <= 2 {
                    // Most runs of small lights: the first cell, then the last, without a
                    // branch on which (a run of one cell writes its entry twice, the second
                    // time where the first went).
                    let at = offsets[a] - 1;
                    offsets[a] = at;
                    list[at as usize] = entry;
                    let (last, step) = (a + run.len as usize - 1, run.len - 1);
                    let at = offsets[last] - step;
                    offsets[last] = at;
                    list[at as usize] = entry;
                } else {
                    write_entries(&mut offsets[a..a + run.len as usize], list, entry);
                }
            }
            end = start as usize;
        }
        add_base(offsets, self.base);
    }

    /// [`Band::count_and_scatter`] by `blocks` blocks of cells (more than one), each block's
    /// parts of the runs of all the band's lights before the next block's.
    fn count_and_scatter_blocks<T: LightIndex>(
        &mut self,
        blocks: usize,
        counts: &mut [u32],
        offsets: &mut [u32],
        list: &mut [T],
        totals: &mut Totals,
    ) {
        let cells = offsets.len();
        self.cursors.clear();
        self.cursors
            .extend(self.lights.iter().map(|&(_, start)| start));
        for block in 0..blocks {
            // In u64: cells × blocks may pass a 32-bit usize.
            let cut = |b: usize| (cells as u64 * b as u64 / blocks as u64) as u32;
            let (first, end_cell) = (cut(block), cut(block + 1));
            let block_counts = &mut counts[first as usize..end_cell as usize];
            block_counts.fill(0);
            let block_cells = end_cell - first;
            let mut end = self.runs.len();
            for (&(_, start), &cursor) in self.lights.iter().zip(&self.cursors).rev() {
                let runs = &self.runs[cursor as usize..end];
                parts_in_block(runs, first, end_cell, |a, b| {
                    add_difference(block_counts, a - first, b - first, block_cells)
                });
                end = start as usize;
            }
            let block_offsets = &mut offsets[first as usize..end_cell as usize];
            sum_counts(block_counts, block_offsets, totals);
            let mut end = self.runs.len();
            let lights = self.lights.iter().zip(&self.ids).zip(&mut self.cursors);
            for ((&(_, start), &id), cursor) in lights.rev() {
                let entry = T::from_u32(id);
                let runs = &self.runs[*cursor as usize..end];
                *cursor += parts_in_block(runs, first, end_cell, |a, b| {
                    write_entries(&mut offsets[a as usize..b as usize], list, entry)
                });
                end = start as usize;
            }
            add_base(&mut offsets[first as usize..end_cell as usize], self.base);
        }
    }
}

/// Calls `part(a, b)` with the cells `a..b` of each of `runs` (one light's, from its first
/// not yet wholly taken) that lie in the block `first..end_cell`, up to the first run that
/// starts past it; the number of runs that end within the block (the light's cursor moves on
/// by that many).
#[inline(always)]
fn parts_in_block(runs: &[Run], first: u32, end_cell: u32, mut part: impl FnMut(u32, u32)) -> u32 {
    let mut done = 0;
    for run in runs {
        if run.start >= end_cell {
            break;
        }
        let run_end = run.start + run.len;
        part(run.start.max(first), run_end.min(end_cell));
        if run_end > end_cell {
            // The rest of the run is the next block's.
            break;
        }
        done += 1;
    }
    done
}

/// The difference counts of the cells `a..b` of `counts` (of `cells` cells): `+1` at `a`,
/// `−1` (wrapping) at `b` unless the run ends at the last cell.
#[inline(always)]
fn add_difference(counts: &mut [u32], a: u32, b: u32, cells: u32) {
    counts[a as usize] = counts[a as usize].wrapping_add(1);
    if b < cells {
        counts[b as usize] = counts[b as usize].wrapping_sub(1);
    }
}

/// The difference counts in `counts` summed into counts, and where each cell's list ends (in
/// the band's part of the list, after the cells `totals` already took) into `offsets`.
#[inline(always)]
fn sum_counts(counts: &mut [u32], offsets: &mut [u32], totals: &mut Totals) {
    let mut running = 0u32;
    for (count, offset) in counts.iter_mut().zip(offsets) {
        running = running.wrapping_add(*count);
        *count = running;
        totals.add(running);
        *offset = totals.indices as u32;
    }
}

/// The band's base (where its part of the list starts) added to its offsets.
fn add_base(offsets: &mut [u32], base: usize) {
    if base != 0 {
        let base = base as u32;
        offsets.iter_mut().for_each(|offset| *offset += base);
    }
}

/// Writes `entry` into `list` once for each of `cursors` (the offsets of a run's cells), each
/// cursor moved one place back first: four cursors at once (a vector subtraction), then their
/// entries.
#[inline(always)]
fn write_entries<T: LightIndex>(cursors: &mut [u32], list: &mut [T], entry: T) {
    let mut quads = cursors.chunks_exact_mut(4);
    for quad in &mut quads {
        let q: &mut [u32; 4] = quad.try_into().expect("four cursors");
        *q = q.map(|at| at - 1);
        for &at in q.iter() {
            list[at as usize] = entry;
        }
    }
    for at in quads.into_remainder() {
        *at -= 1;
        list[*at as usize] = entry;
    }
}

#[cfg(test)]
thread_local! {
    /// Set by the tests that check that any number of scatter blocks gives the same lists.
    pub(in crate::cluster::assign) static FORCED_SCATTER_BLOCKS: std::cell::Cell<Option<usize>> =
        const { std::cell::Cell::new(None) };
}

/// Bytes of a band's offsets and list that one block of [`Band::count_and_scatter`] writes at
/// most: about what a core's own (L2) cache holds beside the runs it reads.
const SCATTER_BLOCK_BYTES: usize = 256 << 10;

/// Fewest indices a block should give each light on average: a block costs every light two
/// looks at its next run.
const SCATTER_BLOCK_MIN_PER_LIGHT: usize = 16;

/// Blocks of cells [`Band::count_and_scatter`] takes a band of `cells` cells and `entries`
/// list entries of `entry_bytes` each, with `lights` lights: enough to keep each block's
/// offsets and list within [`SCATTER_BLOCK_BYTES`], few enough that each light has about
/// [`SCATTER_BLOCK_MIN_PER_LIGHT`] indices in a block; at least one.
fn scatter_blocks(cells: usize, entries: usize, entry_bytes: usize, lights: usize) -> usize {
    let bytes = cells * std::mem::size_of::<u32>() + entries * entry_bytes;
    let by_cache = bytes.div_ceil(SCATTER_BLOCK_BYTES);
    let by_lights = entries / (lights * SCATTER_BLOCK_MIN_PER_LIGHT).max(1);
    by_cache.min(by_lights).clamp(1, cells.max(1))
}
