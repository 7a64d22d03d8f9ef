//! The assignment by **bands** of slices (see [`super`]): each band is consecutive slices,
//! whose cells are consecutive cell numbers, so it owns one contiguous part of every output
//! array and no thread writes where another does. On several threads there are two bands a
//! worker, each taken by the next worker free (`shared.rs`).

use std::time::Instant;

#[cfg(test)]
mod balance_tests;
mod scatter;
mod shared;
#[cfg(test)]
pub(super) use scatter::FORCED_SCATTER_BLOCKS;

use super::cells::{for_each_run_in, SliceWindow};
use super::types::{Assignment, Run, Tally, Totals, PARALLEL_SECONDS};
use crate::cluster::grid::ClusterGrid;
use crate::cluster::headroom::{clear_with_room_for, room_for, share_of, WHOLE_UP_TO};
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
    /// Gives back what a burst of lights grew the bands' buffers to (each frame fills them
    /// afresh).
    pub(super) fn fit(&mut self) {
        use crate::cluster::headroom::fit_empty;
        fit_empty(&mut self.numbers);
        for band in &mut self.bands {
            fit_empty(&mut band.runs);
            fit_empty(&mut band.lights);
            fit_empty(&mut band.ids);
            fit_empty(&mut band.cursors);
        }
    }

    /// The last split's bands.
    fn active(&self) -> &[Band] {
        &self.bands[..self.active]
    }

    /// Frees the runs a refused assignment found ([`Assignment::unlisted`]): up to the bound's
    /// worth, which the next assignment would otherwise keep room for in every band.
    pub(super) fn release_runs(&mut self) {
        for band in &mut self.bands {
            band.runs = Vec::new();
        }
    }

    /// Seconds the last split's bands spent in their phases 1 and 3, all together: the
    /// threads' work, without their waiting.
    pub(super) fn busy_seconds(&self) -> f64 {
        self.active().iter().map(|band| band.seconds).sum()
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

    /// Cuts the grid's slices into at most `count` non-empty bands of about equal work.
    ///
    /// The work is what the last assignment measured when it was to a grid of as many cells
    /// and slices in as many bands: each band's time spread evenly over its cells. So the
    /// bands follow the work from frame to frame whatever it is made of (per-light setup for
    /// many small lights, per-index scatter for a fine grid), which a fixed measure does not
    /// (a split by indices misjudges many small lights, a split by lights a fine grid).
    /// Failing that, the last assignment's indices, else cells. Only the speed depends on
    /// where the bands are cut, never the lists.
    fn split(&mut self, grid: &ClusterGrid, count: usize, out: &Assignment) {
        let cells = grid.total_cells as usize;
        let slices = grid.slice_slabs.len() as u32;
        let count = count.clamp(1, slices.max(1) as usize);
        let previous = out;
        let last = &self.bands[..self.active];
        // The bands' own record of the grid they were cut for (not the last lists, which may
        // be an automatic grid candidate's since: see `Assigner::assign_candidate`).
        let timed = last.len() == count
            && count > 1
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
        if self.bands.len() < count {
            self.bands.resize_with(count, Band::default);
        }
        let (mut first, mut used) = (0u32, 0usize);
        for t in 0..count {
            if first >= slices {
                break;
            }
            // At least one slice per band; the last band takes the rest.
            let end = if t + 1 == count {
                slices
            } else {
                let target = total * (t + 1) as f64 / count as f64;
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

    /// Phases 1 to 3 over [`bands_for`] `threads` bands (shared among `threads` workers when
    /// more than one: called inside rayon's pool then), into `out`; the list's totals before
    /// any cap.
    pub(super) fn assign(
        &mut self,
        grid: &ClusterGrid,
        lights: &[GpuLight],
        camera_far: f64,
        out: &mut Assignment,
        threads: usize,
        tally: &Tally,
    ) -> Totals {
        // The last assignment's runs and listed lights over all bands, before the split
        // moves the bands' borders.
        let last_runs: usize = self.active().iter().map(|b| b.runs.len()).sum();
        let last_lights: usize = self.active().iter().map(|b| b.lights.len()).sum();
        let wanted = bands_for(threads);
        self.split(grid, wanted, out);
        // Every band, also those this split leaves out, keeps room for its share of the runs
        // (the borders move with the work), and for every light while they are few (the sum
        // of the bands' lights depends on where the borders are).
        let runs_share = share_of(last_runs, wanted);
        let lights_share = share_of(last_lights, wanted).max(lights.len().min(WHOLE_UP_TO));
        for band in &mut self.bands {
            band.clear_with_room(runs_share, lights_share);
        }
        let bands = &mut self.bands[..self.active];
        if let [band] = bands {
            band.assign_alone(grid, lights, camera_far, out, tally);
        } else {
            let numbers = &mut self.numbers;
            let work = (grid, lights, camera_far, tally);
            shared::assign_shared(bands, threads, work, out, numbers);
        }
        let mut totals = Totals::default();
        for band in self.active() {
            totals.indices += band.totals.indices;
            totals.max = totals.max.max(band.totals.max);
            totals.nonempty += band.totals.nonempty;
            totals.runs += band.runs.len();
        }
        totals
    }
}

/// Most bands a split makes (and a [`SplitRecord`] keeps).
const MAX_BANDS: usize = 8;

/// Bands a split for `threads` workers makes: two a worker (so a worker that wakes late still
/// finds a band to take, see [`shared::assign_shared`]), at most [`MAX_BANDS`]; one for one.
fn bands_for(threads: usize) -> usize {
    if threads > 1 {
        (2 * threads).min(MAX_BANDS)
    } else {
        1
    }
}

/// The bands' split as [`Bands::split_record`] keeps it.
#[derive(Debug, PartialEq)]
pub(super) struct SplitRecord {
    active: usize,
    bands: [Option<BandCut>; MAX_BANDS],
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
    /// Indices the band's runs give (phase 1).
    indices: usize,
    /// The band's [`Totals`] (phase 3).
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

    /// Phase 1: the band's runs of every light, the lights that have any, and the number of
    /// indices they give (so the bands' parts of the list are known before phase 3), timed
    /// for the next split.
    fn find(&mut self, grid: &ClusterGrid, lights: &[GpuLight], camera_far: f64, tally: &Tally) {
        let started = Instant::now();
        let window = self.window.expect("a band has a window");
        let first = self.first_cell as u32;
        let runs = &mut self.runs;
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
            // Taking `first` by value and summing the indices after: the closure lives on the
            // stack (the refinement takes it), so each value it reaches by reference costs a
            // load per run, and a sum it keeps a load and a store.
            let to = &mut *runs;
            let mut emit = move |start: u32, len| {
                to.push(Run {
                    start: start - first,
                    len,
                })
            };
            for_each_run_in(grid, &window, light, camera_far, &mut emit);
            debug_assert!(
                runs.len() - before <= tally.most_runs,
                "a light's runs past the bound"
            );
            if runs.len() > before {
                self.lights.push((i as u32, before as u32));
                listed += runs[before..]
                    .iter()
                    .map(|run| run.len as usize)
                    .sum::<usize>();
                // Past the bound the list is refused anyway: the runs would go on taking
                // memory (and past 2³² be misnumbered). And the next light's runs need room.
                let within = listed <= tally.limit && tally.keeps_within(listed, &mut added);
                if !within || !tally.room_for_runs(runs) {
                    break;
                }
            }
        }
        self.indices = listed;
        self.seconds = started.elapsed().as_secs_f64();
    }

    /// Phases 1 to 3 of the only band (the whole grid, one thread) into `out`: it numbers its
    /// own lights in phase 2 (its `ids`).
    fn assign_alone(
        &mut self,
        grid: &ClusterGrid,
        lights: &[GpuLight],
        camera_far: f64,
        out: &mut Assignment,
        tally: &Tally,
    ) {
        self.find(grid, lights, camera_far, tally);
        out.visible.clear();
        out.visible
            .extend(self.lights.iter().map(|&(light, _)| light));
        let Some(list) = tally.list(&mut out.indices, self.indices, out.visible.len()) else {
            out.unlisted = Some(self.indices);
            self.totals = Totals::default();
            return;
        };
        self.ids.clear();
        self.ids.extend(0..self.lights.len() as u32);
        self.base = 0;
        let cells = CellsOut::sized(&mut out.counts, &mut out.offsets, self.end_cell);
        self.count_and_scatter(None, cells, list);
    }
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

/// Phase 2's numbering with several bands: the lights listed by any of `bands`, ascending,
/// into `visible`, and each light's number in `numbers` (one entry per light), which phase 3
/// looks the bands' lights up in.
fn number_listed<'a>(
    bands: impl Iterator<Item = &'a Band>,
    lights: usize,
    visible: &mut Vec<u32>,
    numbers: &mut Vec<u32>,
) {
    visible.clear();
    // Mark the listed lights and number the marks in light order (a merge of the bands' lists
    // cost more: a comparison per band per light).
    numbers.clear();
    numbers.resize(lights, u32::MAX);
    for band in bands {
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

/// The per-cell outputs of phase 3: from the first band's cell on.
struct CellsOut<'a> {
    counts: &'a mut [u32],
    offsets: &'a mut [u32],
}

impl<'a> CellsOut<'a> {
    /// `counts` and `offsets` sized to the grid's `cells` cells. Phase 3 writes every offset
    /// and clears the counts block by block, so the resizing only zero-fills growth.
    fn sized(counts: &'a mut Vec<u32>, offsets: &'a mut Vec<u32>, cells: usize) -> Self {
        room_for(counts, cells);
        room_for(offsets, cells);
        counts.resize(cells, 0);
        offsets.resize(cells, 0);
        CellsOut { counts, offsets }
    }

    /// The first `cells` cells, and the rest.
    fn split_at(self, cells: usize) -> (CellsOut<'a>, CellsOut<'a>) {
        let (counts_left, counts_right) = self.counts.split_at_mut(cells);
        let (offsets_left, offsets_right) = self.offsets.split_at_mut(cells);
        (
            CellsOut {
                counts: counts_left,
                offsets: offsets_left,
            },
            CellsOut {
                counts: counts_right,
                offsets: offsets_right,
            },
        )
    }
}
