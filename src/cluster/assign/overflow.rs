//! The assignment's overflow policy (see [`super`]'s docs): a cell never lists more
//! than the cap, keeping its most important lights, and the whole list fits the index texture.

use std::cell::RefCell;

use super::index_list::{EntriesMut, IndexList, LightIndex};
use super::types::{AssignLimits, Assignment, PARALLEL_INDICES};
use crate::cluster::grid::{CellCoord, ClusterGrid};
use crate::cluster::view_light::GpuLight;

/// Buffers of the overflow policy, kept between frames.
#[derive(Default)]
pub(super) struct Overflow {
    /// The compacted list, swapped with the assignment's (which becomes the next spare).
    kept: IndexList,
    /// The overfull cells: (cell, offset, count).
    lists: Vec<(u32, usize, usize)>,
    /// What importance reads of each visible light (see [`trim_overfull_cells`]).
    packed: Vec<[f32; 4]>,
}

impl Overflow {
    /// Gives back what a burst of lights grew the policy's buffers to.
    pub(super) fn fit(&mut self) {
        self.kept.fit_keeping(false);
        crate::cluster::headroom::fit_empty(&mut self.lists);
        crate::cluster::headroom::fit_empty(&mut self.packed);
    }
}

/// Applies the overflow policy in place (see the module docs); true if it dropped any light.
/// Where the trimmed list cannot be allocated, nothing is listed (`out.unallocated`).
pub(super) fn apply_cap(
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
    let parts = limits.max_threads.clamp(1, super::MAX_ASSIGN_THREADS);
    trim_overfull_cells(out, grid, lights, cap, parts, scratch);
    // Compact: every cell keeps the first `cap` entries of its list (the trim put the kept
    // lights there, in ascending order).
    let total: usize = out.counts.iter().map(|&n| n.min(cap) as usize).sum();
    let (offsets, counts) = (&mut out.offsets, &mut out.counts);
    let overfull = &mut out.overfull;
    let kept = match scratch.kept.prepare(total, out.visible.len()) {
        Ok(kept) => kept,
        // Nothing listed, as for a list too long to build.
        Err(bytes) => {
            out.unallocated = Some(bytes);
            out.unlisted = Some(out.indices.len());
            return false;
        }
    };
    let dropped = match (kept, out.indices.as_u16(), out.indices.as_u32()) {
        (EntriesMut::Narrow(kept), Some(list), _) => {
            compact(list, kept, offsets, counts, cap, overfull)
        }
        (EntriesMut::Wide(kept), _, Some(list)) => {
            compact(list, kept, offsets, counts, cap, overfull)
        }
        _ => unreachable!("a list's width follows its visible lights, the same for both"),
    };
    out.stats.overflowed_lights += dropped;
    std::mem::swap(&mut out.indices, &mut scratch.kept);
    true
}

/// Copies the first `cap` entries of every cell's list of `list` into `kept` (as long as
/// their sum), moving `offsets` and `counts` with them, and notes each cut cell in
/// `overfull`; the entries dropped.
fn compact<T: LightIndex>(
    list: &[T],
    kept: &mut [T],
    offsets: &mut [u32],
    counts: &mut [u32],
    cap: u32,
    overfull: &mut Vec<(u32, u32)>,
) -> u64 {
    let (mut at, mut dropped) = (0, 0);
    for (cell, (offset, count)) in offsets.iter_mut().zip(counts.iter_mut()).enumerate() {
        let (o, n) = (*offset as usize, *count as usize);
        let keep = n.min(cap as usize);
        if n > keep {
            overfull.push((cell as u32, (n - keep) as u32));
        }
        dropped += (n - keep) as u64;
        kept[at..at + keep].copy_from_slice(&list[o..o + keep]);
        *offset = at as u32;
        *count = keep as u32;
        at += keep;
    }
    dropped
}

thread_local! {
    /// One trimmed cell's keys and the selection's copy of them, kept per thread from cell to
    /// cell and frame to frame.
    static TRIM_KEYS: RefCell<(Vec<f64>, Vec<f64>)> = const { RefCell::new((Vec::new(), Vec::new())) };
}

/// Moves the `cap` most important lights of every cell holding more to the front of its list,
/// in ascending order (of equally important ones, the earlier). Each light's importance is
/// computed once (the comparisons of a selection would otherwise recompute it, through two
/// random reads, several times per entry), and cells are trimmed in parallel: their lists are
/// disjoint.
fn trim_overfull_cells(
    out: &mut Assignment,
    grid: &ClusterGrid,
    lights: &[GpuLight],
    cap: u32,
    parts: usize,
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
    let many = scratch.lists.iter().map(|&(_, _, n)| n).sum::<usize>() >= PARALLEL_INDICES;
    let parts = if many { parts } else { 1 };
    let lists = &scratch.lists[..];
    match out.indices.entries_mut() {
        EntriesMut::Narrow(list) => trim_lists(lists, list, 0, parts, &|cell, list| {
            trim_cell(grid, packed, cap, cell, list)
        }),
        EntriesMut::Wide(list) => trim_lists(lists, list, 0, parts, &|cell, list| {
            trim_cell(grid, packed, cap, cell, list)
        }),
    }
}

/// Moves the `cap` most important of `list`'s lights (cell `cell`'s; `packed` is what
/// importance reads of each visible light) to its front, in ascending order.
fn trim_cell<T: LightIndex>(
    grid: &ClusterGrid,
    packed: &[[f32; 4]],
    cap: usize,
    cell: u32,
    list: &mut [T],
) {
    if cap == 0 {
        return;
    }
    let center = cell_center(grid, cell);
    TRIM_KEYS.with_borrow_mut(|(keys, order)| {
        keys.clear();
        keys.extend(list.iter().map(|&i| {
            let [x, y, z, brightness] = packed[i.to_usize()];
            let position = glam::DVec3::new(x as f64, y as f64, z as f64);
            brightness_over_distance(brightness, position, center)
        }));
        // The cap-th largest key is the threshold: every light above it stays, and of
        // those equal to it the earliest, until the cap is reached. One selection and one
        // pass in list order, so the kept lights stay in ascending order without a sort.
        order.clear();
        order.extend_from_slice(keys);
        let (_, &mut threshold, _) = order.select_nth_unstable_by(cap - 1, |a, b| b.total_cmp(a));
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
}

/// Entries of the index list below which [`trim_lists`] trims its lists on one thread.
const TRIM_GRAIN: usize = 1 << 14;

/// Trims the lists `lists` (cell, offset, count; in cell order) of `indices`, whose first
/// entry is list entry `base`: on the calling thread, or, for `parts` above 1, the two halves
/// of the lists at once (`rayon::join` keeps its jobs on the stack), each with half the
/// parts, so at most `parts` at once; down to [`TRIM_GRAIN`].
fn trim_lists<T: LightIndex>(
    lists: &[(u32, usize, usize)],
    indices: &mut [T],
    base: usize,
    parts: usize,
    trim: &(dyn Fn(u32, &mut [T]) + Sync),
) {
    let span = lists.last().map_or(0, |&(_, o, n)| o + n) - lists.first().map_or(0, |l| l.1);
    if parts < 2 || lists.len() < 2 || span < TRIM_GRAIN {
        for &(cell, o, n) in lists {
            trim(cell, &mut indices[o - base..o - base + n]);
        }
        return;
    }
    let (left, right) = lists.split_at(lists.len() / 2);
    let split = right[0].1 - base;
    let (head, tail) = indices.split_at_mut(split);
    rayon::join(
        || trim_lists(left, head, base, parts - parts / 2, trim),
        || trim_lists(right, tail, base + split, parts / 2, trim),
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
