//! The assignment by **bands** of slices (see [`super`]): each thread fills one band
//! of consecutive slices, whose cells are consecutive cell numbers, so it owns one contiguous
//! part of every output array and no thread writes where another does.

use std::time::Instant;

#[cfg(test)]
mod balance_tests;

use super::cells::{for_each_run_in, SliceWindow};
use super::index_list::{EntriesMut, LightIndex};
use crate::cluster::headroom::{clear_with_room_for, room_for, share_of, WHOLE_UP_TO};
use super::types::{Assignment, Run, Totals, PARALLEL_SECONDS};
use crate::cluster::grid::ClusterGrid;
use crate::cluster::view_light::GpuLight;

/// The bands and their buffers, kept between frames.
#[derive(Default)]
pub(super) struct Bands {
    /// Every band made so far; the first `active` are the last split's. A band left out of a
    /// split keeps its buffers for when it is needed again.
    bands: Vec<Band>,
    active: usize,
    /// Per light: its visible number (phase 2, several bands).
    numbers: Vec<u32>,
}

impl Bands {
    /// The last split's bands.
    fn active(&self) -> &[Band] {
        &self.bands[..self.active]
    }

    /// Where the last split cut the bands and what each took: what the next split follows.
    pub(super) fn split_record(&self) -> SplitRecord {
        SplitRecord {
            active: self.active,
            bands: std::array::from_fn(|b| {
                self.bands.get(b).map(|band| BandCut {
                    window: band.window,
                    first_cell: band.first_cell,
                    end_cell: band.end_cell,
                    seconds: band.seconds,
                })
            }),
        }
    }

    /// Puts back a [`SplitRecord`] (after an assignment that was not a frame's).
    pub(super) fn restore_split(&mut self, record: &SplitRecord) {
        self.active = record.active;
        for (band, kept) in self.bands.iter_mut().zip(&record.bands) {
            if let Some(cut) = *kept {
                band.window = cut.window;
                band.first_cell = cut.first_cell;
                band.end_cell = cut.end_cell;
                band.seconds = cut.seconds;
            }
        }
    }

    /// Cuts the grid's slices into at most `threads` non-empty bands of about equal work.
    ///
    /// The work is what the last assignment measured when it was to a grid of as many cells
    /// and slices in as many bands: each band's time spread evenly over its cells. So the
    /// bands follow the work from frame to frame whatever it is made of (per-light setup for
    /// many small lights, per-index scatter for a fine grid), which a fixed measure does not
    /// (a split by indices misjudges many small lights, a split by lights a fine grid).
    /// Failing that, the last assignment's indices, else cells. Only the speed depends on
    /// where the bands are cut, never the lists.
    fn split(&mut self, grid: &ClusterGrid, threads: usize, out: &Assignment) {
        let cells = grid.total_cells as usize;
        let slices = grid.slice_slabs.len() as u32;
        let threads = threads.clamp(1, slices.max(1) as usize);
        let previous = out;
        let last = &self.bands[..self.active];
        // The bands' own record of the grid they were cut for (not the last lists, which may
        // be an automatic grid candidate's since: see `Assigner::assign_candidate`).
        let timed = last.len() == threads
            && threads > 1
            && last.last().map(|b| b.end_cell) == Some(cells)
            && last.last().and_then(|b| b.window).map(|w| w.end) == Some(slices)
            && last.iter().all(|b| b.seconds > 0.0)
            // Below this, timer noise and a worker's waking outweigh the work: a split by
            // such times would jump from frame to frame (and the bands' buffers with it).
            && last.iter().map(|b| b.seconds).sum::<f64>() >= PARALLEL_SECONDS;
        let by_indices = previous.offsets.len() == cells && !previous.indices.is_empty();
        // Seconds per cell of each band's cells, from the last split.
        let density: [(usize, usize, f64); 8] = std::array::from_fn(|b| match last.get(b) {
            Some(band) if timed => (
                band.first_cell,
                band.end_cell,
                band.seconds / (band.end_cell - band.first_cell).max(1) as f64,
            ),
            _ => (0, 0, 0.0),
        });
        // The work in front of `cell`.
        let work_before = |cell: usize| -> f64 {
            if timed {
                density
                    .iter()
                    .map(|&(a, b, d)| (cell.clamp(a, b) - a) as f64 * d)
                    .sum()
            } else if cell >= cells {
                if by_indices {
                    previous.indices.len() as f64
                } else {
                    cells as f64
                }
            } else if by_indices {
                previous.offsets[cell] as f64
            } else {
                cell as f64
            }
        };
        let total = work_before(cells);
        if self.bands.len() < threads {
            self.bands.resize_with(threads, Band::default);
        }
        let (mut first, mut used) = (0u32, 0usize);
        for t in 0..threads {
            if first >= slices {
                break;
            }
            // At least one slice per band; the last band takes the rest.
            let end = if t + 1 == threads {
                slices
            } else {
                let target = total * (t + 1) as f64 / threads as f64;
                let mut end = first + 1;
                while end < slices && work_before(slice_first_cell(grid, end)) < target {
                    end += 1;
                }
                end
            };
            let band = &mut self.bands[used];
            band.window = Some(SliceWindow::of(grid, first, end));
            band.first_cell = slice_first_cell(grid, first);
            band.end_cell = slice_first_cell(grid, end);
            band.seconds = 0.0;
            used += 1;
            first = end;
        }
        self.active = used;
    }

    /// Phases 1 to 3 over at most `threads` bands (in parallel when more than one: called
    /// inside rayon's pool then), into `out`; the list's totals before any cap.
    pub(super) fn assign(
        &mut self,
        grid: &ClusterGrid,
        lights: &[GpuLight],
        camera_far: f64,
        out: &mut Assignment,
        threads: usize,
    ) -> Totals {
        // The last assignment's runs and listed lights over all bands, before the split
        // moves the bands' borders.
        let last_runs: usize = self.active().iter().map(|b| b.runs.len()).sum();
        let last_lights: usize = self.active().iter().map(|b| b.lights.len()).sum();
        self.split(grid, threads, out);
        let parallel = self.active > 1;
        // Every band, also those this split leaves out, keeps room for its share of the runs
        // (the borders move with the work), and for every light while they are few (the sum
        // of the bands' lights depends on where the borders are).
        let runs_share = share_of(last_runs, threads);
        let lights_share = share_of(last_lights, threads).max(lights.len().min(WHOLE_UP_TO));
        for band in &mut self.bands {
            band.clear_with_room(runs_share, lights_share);
        }
        let cells = grid.total_cells as usize;
        let bands = &mut self.bands[..self.active];
        // Phase 1, its difference counts straight into the counts' array, and each band's
        // counts and offsets as soon as its runs are found (phase 2 sums them in place: one
        // cold array less than a separate one, and no wait for the other bands in between).
        room_for(&mut out.counts, cells);
        room_for(&mut out.offsets, cells);
        out.counts.resize(cells, 0);
        out.offsets.resize(cells, 0);
        let (counts, offsets) = (&mut out.counts[..], &mut out.offsets[..]);
        for_band_cells(bands, counts, offsets, parallel, &|band, counts, offsets| {
            band.find_and_count(grid, lights, camera_far, counts, offsets)
        });
        // Phase 2: the visible lights and their numbers (each band looks its lights' numbers
        // up in phase 3's job), then the totals.
        number_visible(bands, lights.len(), &mut out.visible, &mut self.numbers);
        let mut totals = Totals::default();
        for band in bands.iter_mut() {
            band.base = totals.indices;
            totals.indices += band.totals.indices;
            totals.max = totals.max.max(band.totals.max);
            totals.nonempty += band.totals.nonempty;
            totals.runs += band.runs.len();
        }
        // Phase 3. Every entry is written, so the list is not cleared first: only growth is
        // zero-filled.
        // One band numbered its own lights in phase 2; several look theirs up.
        let numbers = (bands.len() > 1).then_some(&self.numbers[..]);
        match out.indices.prepare(totals.indices, out.visible.len()) {
            EntriesMut::Narrow(list) => {
                scatter_bands(bands, numbers, &mut out.offsets, list, parallel)
            }
            EntriesMut::Wide(list) => scatter_bands(bands, numbers, &mut out.offsets, list, parallel),
        }
        totals
    }
}

/// The bands' split as [`Bands::split_record`] keeps it (at most 8 bands).
#[derive(Debug, PartialEq)]
pub(super) struct SplitRecord {
    active: usize,
    bands: [Option<BandCut>; 8],
}

/// One band's part of a [`SplitRecord`]: its slices and cells, and the seconds it took.
#[derive(Clone, Copy, Debug, PartialEq)]
struct BandCut {
    window: Option<SliceWindow>,
    first_cell: usize,
    end_cell: usize,
    seconds: f64,
}

/// One band of slices and its buffers. Aligned to two cache lines: the bands sit side by side
/// in a `Vec` and their buffers' lengths change with every push, so unaligned neighbours would
/// bounce a shared cache line between the threads (false sharing doubled a phase's time).
#[derive(Default)]
#[repr(align(128))]
struct Band {
    /// The band's slices.
    window: Option<SliceWindow>,
    /// The band's cells, `first_cell..end_cell`.
    first_cell: usize,
    end_cell: usize,
    /// The runs, light after light.
    runs: Vec<Run>,
    /// Every light with a run in the band, ascending: (light, start of its runs in `runs`).
    lights: Vec<(u32, u32)>,
    /// Per entry of `lights`: the light's visible number (phase 2 with one band, else the
    /// start of phase 3).
    ids: Vec<u32>,
    /// Per entry of `lights`: its first run not yet scattered (phase 3 by blocks of cells).
    cursors: Vec<u32>,
    /// The band's [`Totals`] (phase 2).
    totals: Totals,
    /// Seconds its phases 1 to 3 took (the next split's balance).
    seconds: f64,
    /// Where the band's part of the list starts (phase 2).
    base: usize,
}

impl Band {
    /// Empties the band's runs and lights for a new assignment, with room for at least
    /// `runs` and `lights` of them (and the per-light arrays for as many lights).
    fn clear_with_room(&mut self, runs: usize, lights: usize) {
        clear_with_room_for(&mut self.runs, runs);
        clear_with_room_for(&mut self.lights, lights);
        room_for(&mut self.ids, self.lights.capacity());
        room_for(&mut self.cursors, self.lights.capacity());
    }

    /// Phase 1: the band's runs of every light, and into `deltas` (the band's cells' part of
    /// the counts) their difference counts: `+1` where a run starts and `−1` (wrapping) where
    /// it ends, so a run costs two additions whatever its length and the running sum over
    /// the cells is the number of lights touching each ([`Band::count`]).
    fn find(
        &mut self,
        grid: &ClusterGrid,
        lights: &[GpuLight],
        camera_far: f64,
        deltas: &mut [u32],
    ) {
        let window = self.window.expect("a band has a window");
        let first = self.first_cell as u32;
        deltas.fill(0);
        let cells = deltas.len() as u32;
        let runs = &mut self.runs;
        for (i, light) in lights.iter().enumerate() {
            let before = runs.len();
            for_each_run_in(grid, &window, light, camera_far, &mut |start, len| {
                let start = start - first;
                deltas[start as usize] = deltas[start as usize].wrapping_add(1);
                // A run ending at the band's last cell has no cell after it to end in.
                let end = start + len;
                if end < cells {
                    deltas[end as usize] = deltas[end as usize].wrapping_sub(1);
                }
                runs.push(Run { start, len });
            });
            if runs.len() > before {
                self.lights.push((i as u32, before as u32));
            }
        }
    }

    /// Phases 1 and 2 of the band ([`Band::find`], then [`Band::count`] on the same cells),
    /// timed for the next split.
    fn find_and_count(
        &mut self,
        grid: &ClusterGrid,
        lights: &[GpuLight],
        camera_far: f64,
        counts: &mut [u32],
        offsets: &mut [u32],
    ) {
        let started = Instant::now();
        self.find(grid, lights, camera_far, counts);
        self.count(counts, offsets);
        self.seconds = started.elapsed().as_secs_f64();
    }

    /// Phase 2: the band's difference counts in `counts` (its cells' part, from phase 1)
    /// summed into counts, where each cell's list ends in the band's part of the list into
    /// `offsets` (phase 3 moves them to where the lists start), and its totals.
    fn count(&mut self, counts: &mut [u32], offsets: &mut [u32]) {
        let mut running = 0u32;
        let mut totals = Totals::default();
        for (count, offset) in counts.iter_mut().zip(offsets) {
            running = running.wrapping_add(*count);
            let n = running;
            *count = n;
            totals.add(n);
            *offset = totals.indices as u32;
        }
        self.totals = totals;
    }

    /// Phase 3: the band's lights' visible numbers (looked up in `numbers` first, when given)
    /// written into `list` (the band's part of the index list) grouped by cell, then the
    /// band's final offsets (its own plus `base`).
    ///
    /// The offsets serve as the write cursors: they start where each cell's list ends and
    /// the runs are taken in reverse, each write one place before the last, so every cell's
    /// list comes out ascending in light order and each offset ends where its list starts
    /// (no cursor array: a fine grid's assignment runs cache-cold in a renderer).
    ///
    /// A band whose offsets and list outgrow a core's cache is scattered by blocks of cells
    /// ([`scatter_blocks`]), each block's runs over all its lights before the next block's:
    /// a cell's lists are still written in reverse light order, so the lists are the same,
    /// but each block's part of the offsets and the list stays in cache while it is written.
    fn scatter<T: LightIndex>(
        &mut self,
        numbers: Option<&[u32]>,
        offsets: &mut [u32],
        list: &mut [T],
    ) {
        let started = Instant::now();
        if let Some(numbers) = numbers {
            self.ids.clear();
            self.ids
                .extend(self.lights.iter().map(|&(light, _)| numbers[light as usize]));
        }
        let cells = offsets.len();
        let blocks = scatter_blocks(cells, list.len(), std::mem::size_of::<T>(), self.lights.len());
        #[cfg(test)]
        let blocks = FORCED_SCATTER_BLOCKS.with(|b| b.get()).map_or(blocks, |b| b.clamp(1, cells));
        if blocks == 1 {
            // One block, every run whole: no cursors into the runs, no run cut at a block's
            // end (a run's bookkeeping was most of the scatter's work on runs of one or two
            // cells).
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
        } else {
            self.scatter_by_blocks(blocks, offsets, list);
        }
        if self.first_cell != 0 {
            let base = self.base as u32;
            offsets.iter_mut().for_each(|offset| *offset += base);
        }
        self.seconds += started.elapsed().as_secs_f64();
    }

    /// [`Band::scatter`]'s writes by `blocks` blocks of cells (more than one), each block's
    /// runs of all the band's lights before the next block's.
    fn scatter_by_blocks<T: LightIndex>(&mut self, blocks: usize, offsets: &mut [u32], list: &mut [T]) {
        let cells = offsets.len();
        self.cursors.clear();
        self.cursors
            .extend(self.lights.iter().map(|&(_, start)| start));
        for block in 0..blocks {
            // In u64: cells × blocks may pass a 32-bit usize.
            let cut = |b: usize| (cells as u64 * b as u64 / blocks as u64) as u32;
            let (first, end_cell) = (cut(block), cut(block + 1));
            let mut end = self.runs.len();
            let lights = self.lights.iter().zip(&self.ids).zip(&mut self.cursors);
            for ((&(_, start), &id), cursor) in lights.rev() {
                let entry = T::from_u32(id);
                let mut k = *cursor as usize;
                for run in &self.runs[k..end] {
                    if run.start >= end_cell {
                        break;
                    }
                    let run_end = run.start + run.len;
                    let (a, b) = (run.start.max(first), run_end.min(end_cell));
                    write_entries(&mut offsets[a as usize..b as usize], list, entry);
                    if run_end > end_cell {
                        // The rest of the run is the next block's.
                        break;
                    }
                    k += 1;
                }
                *cursor = k as u32;
                end = start as usize;
            }
        }
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
    pub(super) static FORCED_SCATTER_BLOCKS: std::cell::Cell<Option<usize>> =
        const { std::cell::Cell::new(None) };
}

/// Bytes of a band's offsets and list that one block of [`Band::scatter`] writes at most:
/// about what a core's own (L2) cache holds beside the runs it reads.
const SCATTER_BLOCK_BYTES: usize = 256 << 10;

/// Fewest indices a block should give each light on average: a block costs every light a
/// look at its next run.
const SCATTER_BLOCK_MIN_PER_LIGHT: usize = 16;

/// Blocks of cells [`Band::scatter`] takes a band of `cells` cells and `entries` list
/// entries of `entry_bytes` each, with `lights` lights: enough to keep each block's offsets
/// and list within [`SCATTER_BLOCK_BYTES`], few enough that each light has about
/// [`SCATTER_BLOCK_MIN_PER_LIGHT`] indices in a block; at least one.
fn scatter_blocks(cells: usize, entries: usize, entry_bytes: usize, lights: usize) -> usize {
    let bytes = cells * std::mem::size_of::<u32>() + entries * entry_bytes;
    let by_cache = bytes.div_ceil(SCATTER_BLOCK_BYTES);
    let by_lights = entries / (lights * SCATTER_BLOCK_MIN_PER_LIGHT).max(1);
    by_cache.min(by_lights).clamp(1, cells.max(1))
}

/// The first cell of slice `g` (numbered across cascades), or the grid's cell count past the
/// last slice.
fn slice_first_cell(grid: &ClusterGrid, g: u32) -> usize {
    let mut first_slice = 0;
    for c in &grid.cascades {
        if g < first_slice + c.slices {
            return (c.first_cell + (g - first_slice) * c.tiles_x * c.tiles_y) as usize;
        }
        first_slice += c.slices;
    }
    grid.total_cells as usize
}

/// What [`for_band_cells`] runs on a band: the band, then its cells' parts of the counts and
/// the offsets.
type BandCellsFn<'a> = dyn Fn(&mut Band, &mut [u32], &mut [u32]) + Sync + 'a;

/// Runs `f` on every band with its cells' parts of `counts` and `offsets` (the grid's): phase
/// 1 and 2's counts ([`Band::find_and_count`]); the halves of the bands at once with
/// `parallel`.
fn for_band_cells(
    bands: &mut [Band],
    counts: &mut [u32],
    offsets: &mut [u32],
    parallel: bool,
    f: &BandCellsFn<'_>,
) {
    if let [band] = bands {
        let cells = band.end_cell - band.first_cell;
        f(band, &mut counts[..cells], &mut offsets[..cells]);
        return;
    }
    let (left, right) = bands.split_at_mut(bands.len() / 2);
    let split = right[0].first_cell - left[0].first_cell;
    let (counts_left, counts_right) = counts.split_at_mut(split);
    let (offsets_left, offsets_right) = offsets.split_at_mut(split);
    if parallel {
        rayon::join(
            || for_band_cells(left, counts_left, offsets_left, true, f),
            || for_band_cells(right, counts_right, offsets_right, true, f),
        );
    } else {
        for_band_cells(left, counts_left, offsets_left, false, f);
        for_band_cells(right, counts_right, offsets_right, false, f);
    }
}

/// Phase 2's numbering: the lights listed by any band, ascending, into `visible`. One band
/// numbers its own lights (its `ids`); several leave each light's number in `numbers` (one
/// entry per light), which phase 3 looks their lights up in.
fn number_visible(bands: &mut [Band], lights: usize, visible: &mut Vec<u32>, numbers: &mut Vec<u32>) {
    visible.clear();
    if let [band] = bands {
        visible.extend(band.lights.iter().map(|&(light, _)| light));
        band.ids.clear();
        band.ids.extend(0..band.lights.len() as u32);
        return;
    }
    // Mark the listed lights and number the marks in light order (a merge of the bands' lists
    // cost more: a comparison per band per light).
    numbers.clear();
    numbers.resize(lights, u32::MAX);
    for band in bands.iter() {
        for &(light, _) in &band.lights {
            numbers[light as usize] = 0;
        }
    }
    for (light, number) in numbers.iter_mut().enumerate() {
        if *number == 0 {
            *number = visible.len() as u32;
            visible.push(light as u32);
        }
    }
}

/// Phase 3 ([`Band::scatter`]) over `offsets` and the index list `list` (from the first band's
/// cell and entry on), the halves of the bands at once with `parallel`.
fn scatter_bands<T: LightIndex>(
    bands: &mut [Band],
    numbers: Option<&[u32]>,
    offsets: &mut [u32],
    list: &mut [T],
    parallel: bool,
) {
    if let [band] = bands {
        band.scatter(numbers, offsets, list);
        return;
    }
    let (left, right) = bands.split_at_mut(bands.len() / 2);
    let split = right[0].first_cell - left[0].first_cell;
    let entries = right[0].base - left[0].base;
    let (offsets_left, offsets_right) = offsets.split_at_mut(split);
    let (list_left, list_right) = list.split_at_mut(entries);
    if parallel {
        rayon::join(
            || scatter_bands(left, numbers, offsets_left, list_left, true),
            || scatter_bands(right, numbers, offsets_right, list_right, true),
        );
    } else {
        scatter_bands(left, numbers, offsets_left, list_left, false);
        scatter_bands(right, numbers, offsets_right, list_right, false);
    }
}
