//! Light assignment: every light → the cells it can touch, then one compact index list.
//!
//! Per light (view space, all in `f64`):
//!
//! 1. its depth range `[d − r, d + r]` is clipped to `[near, far]` **before** anything is
//!    projected, so lights behind or around the camera never flip to the wrong side; a light
//!    whose range misses the frustum is culled;
//! 2. the clipped range gives the first and last (cascade, slice);
//! 3. per cascade, the sphere's screen extent (box projection over the cascade's depth slab,
//!    tightened by the exact tangent bounds when the sphere is in front of the eye) gives a
//!    column and row range, whose ends are then tested against the tile planes;
//! 4. spot lights are further tested cone-vs-cell (against the cell's bounding sphere).
//!
//! The radius is padded by a relative 10⁻⁴ so a fragment that float rounding puts in the
//! neighbouring cell still finds every light that reaches it: the assignment is conservative.
//!
//! Then a counting sort: counts per cell → prefix sum → one index list, lights in ascending
//! order inside each cell. Only lights that touch at least one cell are kept ("visible"), and
//! the list refers to them by their position among the visible lights.
//!
//! **Overflow policy.** A cell never holds more than `cell_cap` lights (the shader's loop bound
//! on ES 2.0 and the 8-bit count): it keeps the `cell_cap` lights with the largest
//! `max(radiance) / (1 + distance²)` to the cell centre and drops the rest. If the whole list
//! would exceed `max_indices` (what the index texture holds), the per-cell cap is lowered until
//! it fits. Nothing wraps and nothing reads out of range; every dropped light is counted in
//! [`AssignStats::overflowed_lights`], and the image degrades by exactly those lights'
//! contributions (measurable against plain forward).

use super::grid::{CellCoord, ClusterGrid, GridProjection};
use super::pack::GpuLight;

/// Limits of one assignment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AssignLimits {
    /// Most lights one cell keeps.
    pub cell_cap: u32,
    /// Most indices in total.
    pub max_indices: usize,
    /// Lights from this count up are assigned on all cores.
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

/// Relative padding of light radii (see the module docs).
const RADIUS_PAD: f64 = 1e-4;

/// Calls `emit(cell_index)` for every cell `light` may touch.
pub fn for_each_cell(
    grid: &ClusterGrid,
    light: &GpuLight,
    camera_far: f64,
    emit: &mut impl FnMut(u32),
) {
    let c = light.position.as_dvec3();
    let d = -c.z;
    let r0 = light.radius as f64;
    if r0 <= 0.0 || !c.is_finite() {
        return;
    }
    let r = r0 + RADIUS_PAD * (d.abs() + r0);
    // 1. Clip the depth range before projecting.
    let dmin = (d - r).max(grid.near);
    let dmax = (d + r).min(camera_far);
    if dmin > dmax {
        return;
    }
    let (k0, s0) = grid.view_z_to_cascade_slice(dmin);
    let (k1, s1) = grid.view_z_to_cascade_slice(dmax);
    let cone = Cone::of(light);
    // Exact tangent slopes (view x/d and y/d) of the whole sphere, when it is in front of the
    // eye; computed once per light, intersected with each cascade's box bounds below.
    let tangent = |center: f64| {
        let den = d * d - r * r;
        let root = r * (d * d + center * center - r * r).sqrt();
        ((center * d - root) / den, (center * d + root) / den)
    };
    let tangents = (d > r).then(|| (tangent(c.x), tangent(c.y)));
    for k in k0..=k1 {
        let cascade = &grid.cascades[k as usize];
        let za = if k == 0 {
            dmin
        } else {
            dmin.max(cascade.z_near)
        };
        let zb = if k as usize == grid.cascades.len() - 1 {
            dmax
        } else {
            dmax.min(cascade.z_far)
        };
        let Some((x0, x1)) = axis_range(
            grid.projection,
            c.x,
            d,
            r,
            (za, zb),
            tangents.map(|t| t.0),
            Axis::X,
            cascade.tiles_x,
        ) else {
            continue;
        };
        let Some((y0, y1)) = axis_range(
            grid.projection,
            c.y,
            d,
            r,
            (za, zb),
            tangents.map(|t| t.1),
            Axis::Y,
            cascade.tiles_y,
        ) else {
            continue;
        };
        let sa = if k == k0 { s0 } else { 0 };
        let sb = if k == k1 { s1 } else { cascade.slices - 1 };
        for s in sa..=sb {
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let cell = grid.cell_index(CellCoord {
                        cascade: k,
                        slice: s,
                        x,
                        y,
                    });
                    if let Some(cone) = &cone {
                        if !cone.may_touch(grid, cell, r) {
                            continue;
                        }
                    }
                    emit(cell);
                }
            }
        }
    }
}

#[derive(Clone, Copy)]
enum Axis {
    X,
    Y,
}

/// Column (or row) range a sphere can touch within the depth slab `[za, zb]`, or `None`.
/// `tangent` holds the sphere's exact slope range when it lies in front of the eye.
#[allow(clippy::too_many_arguments)] // one call site per axis; a struct would only rename them
fn axis_range(
    projection: GridProjection,
    center: f64,
    d: f64,
    r: f64,
    (za, zb): (f64, f64),
    tangent: Option<(f64, f64)>,
    axis: Axis,
    tiles: u32,
) -> Option<(u32, u32)> {
    let (lo, hi) = match projection {
        GridProjection::Perspective { tan_x, tan_y } => {
            let tan = match axis {
                Axis::X => tan_x,
                Axis::Y => tan_y,
            };
            // Box projection: extreme slopes of the sphere's bounding box within the slab.
            let slope = |v: f64, z: f64| if z.is_infinite() { 0.0 } else { v / z };
            let (vmin, vmax) = (center - r, center + r);
            let mut lo = slope(vmin, za).min(slope(vmin, zb));
            let mut hi = slope(vmax, za).max(slope(vmax, zb));
            if let Some((tlo, thi)) = tangent {
                lo = lo.max(tlo);
                hi = hi.min(thi);
            }
            (lo / tan, hi / tan)
        }
        GridProjection::Orthographic { half_x, half_y } => {
            let half = match axis {
                Axis::X => half_x,
                Axis::Y => half_y,
            };
            ((center - r) / half, (center + r) / half)
        }
    };
    if lo.is_nan() || hi.is_nan() || hi < -1.0 || lo > 1.0 || lo > hi {
        return None;
    }
    let to_tile = |ndc: f64| (((ndc + 1.0) * 0.5 * tiles as f64).max(0.0) as u32).min(tiles - 1);
    let (mut t0, mut t1) = (to_tile(lo), to_tile(hi));
    // Tighten the ends against the tile planes where the tangent bounds do not apply (sphere
    // reaching behind the eye; with `d > r` they are exact already, as is orthographic).
    if let (GridProjection::Perspective { tan_x, tan_y }, true) = (projection, d <= r) {
        let tan = match axis {
            Axis::X => tan_x,
            Axis::Y => tan_y,
        };
        // Signed distance of the centre to the plane through the eye at NDC `u`, positive on
        // the +u side.
        let dist = |u: f64| (center - u * tan * d) / (1.0 + u * u * tan * tan).sqrt();
        let ndc = |i: u32| -1.0 + 2.0 * i as f64 / tiles as f64;
        let touches = |i: u32| dist(ndc(i)) >= -r && dist(ndc(i + 1)) <= r;
        while t0 < t1 && !touches(t0) {
            t0 += 1;
        }
        while t1 > t0 && !touches(t1) {
            t1 -= 1;
        }
        if !touches(t0) {
            return None;
        }
    }
    Some((t0, t1))
}

/// A spot light's cone, for the cone-vs-cell test (Wronski's "cull that cone").
struct Cone {
    apex: glam::DVec3,
    axis: glam::DVec3,
    cos: f64,
    sin: f64,
}

impl Cone {
    fn of(light: &GpuLight) -> Option<Cone> {
        // cos(outer) = −offset / scale (see `Light::spot_scale_offset`): no trigonometry per
        // light. Cones of 89° and wider are not worth testing.
        if light.spot_scale == 0.0 || light.direction.length_squared() == 0.0 {
            return None;
        }
        let cos_outer = -(light.spot_offset as f64) / light.spot_scale as f64;
        // Pad the angle a little: the shader evaluates the cone edge in f32.
        let cos = cos_outer - 2e-4;
        if cos.is_nan() || cos < 0.0175 {
            return None;
        }
        Some(Cone {
            apex: light.position.as_dvec3(),
            axis: light.direction.as_dvec3().normalize(),
            cos,
            sin: (1.0 - cos * cos).max(0.0).sqrt(),
        })
    }

    /// False only when the cell's bounding sphere is certainly outside the cone of `range`.
    fn may_touch(&self, grid: &ClusterGrid, cell: u32, range: f64) -> bool {
        let [x, y, z, radius] = grid.cell_sphere(cell);
        if radius.is_infinite() {
            return true;
        }
        let v = glam::DVec3::new(x, y, z) - self.apex;
        let v_len_sq = v.length_squared();
        let v1 = v.dot(self.axis);
        let closest = self.cos * (v_len_sq - v1 * v1).max(0.0).sqrt() - v1 * self.sin;
        !(closest > radius || v1 > radius + range || v1 < -radius)
    }
}

/// Importance of a light for a cell under overflow: brighter and closer first.
fn importance(light: &GpuLight, cell_center: glam::DVec3) -> f64 {
    let d2 = light.position.as_dvec3().distance_squared(cell_center);
    light.radiance.max_element() as f64 / (1.0 + d2)
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

/// One thread's share of phase 1: its lights' cells, sorted by cell (a local counting sort).
struct Chunk {
    /// Per cell: how many of this chunk's lights touch it.
    counts: Vec<u32>,
    /// Per cell: where its run starts in `sorted`.
    offsets: Vec<u32>,
    /// Light numbers local to the chunk (0-based), grouped by cell, ascending inside a cell.
    sorted: Vec<u32>,
    /// Per light of the chunk: its position among the chunk's visible lights, or `u32::MAX`.
    local_visible: Vec<u32>,
}

/// Phase 1 for a contiguous range of lights.
fn assign_chunk(grid: &ClusterGrid, lights: &[GpuLight], camera_far: f64) -> Chunk {
    let cells = grid.total_cells as usize;
    // Typical lights touch a handful to a few dozen cells; growing from 8 per light avoids
    // most reallocation copies.
    let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(lights.len() * 8);
    let mut counts = vec![0u32; cells];
    let mut local_visible = vec![u32::MAX; lights.len()];
    let mut visible_count = 0u32;
    for (i, light) in lights.iter().enumerate() {
        let before = pairs.len();
        for_each_cell(grid, light, camera_far, &mut |cell| {
            counts[cell as usize] += 1;
            pairs.push((cell, i as u32));
        });
        if pairs.len() > before {
            local_visible[i] = visible_count;
            visible_count += 1;
        }
    }
    let mut offsets = vec![0u32; cells];
    let mut running = 0u32;
    for (o, n) in offsets.iter_mut().zip(&counts) {
        *o = running;
        running += n;
    }
    let mut cursor = offsets.clone();
    let mut sorted = vec![0u32; pairs.len()];
    for (cell, light) in pairs {
        let at = &mut cursor[cell as usize];
        sorted[*at as usize] = local_visible[light as usize];
        *at += 1;
    }
    Chunk {
        counts,
        offsets,
        sorted,
        local_visible,
    }
}

/// Runs `f` on each item, on scoped threads when there is more than one.
fn parallel_map<T: Send, R: Send>(items: Vec<T>, f: impl Fn(T) -> R + Sync) -> Vec<R> {
    if items.len() <= 1 {
        return items.into_iter().map(f).collect();
    }
    std::thread::scope(|scope| {
        let f = &f;
        let handles: Vec<_> = items
            .into_iter()
            .map(|item| scope.spawn(move || f(item)))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("assignment thread"))
            .collect()
    })
}

/// Assigns `lights` (view space) to the cells of `grid`. `camera_far` may be infinite.
pub fn assign(
    grid: &ClusterGrid,
    lights: &[GpuLight],
    camera_far: f64,
    limits: &AssignLimits,
) -> Assignment {
    let cells = grid.total_cells as usize;
    if lights.is_empty() {
        return Assignment {
            offsets: vec![0; cells],
            counts: vec![0; cells],
            stats: AssignStats {
                clusters: grid.total_cells,
                ..Default::default()
            },
            ..Default::default()
        };
    }
    // Phase 1, in parallel: each thread takes a contiguous range of lights, finds their cells
    // and sorts them by cell locally.
    let threads = if lights.len() >= limits.parallel_threshold {
        std::thread::available_parallelism()
            .map_or(1, |n| n.get())
            .min(8)
    } else {
        1
    };
    let chunk_len = lights.len().div_ceil(threads);
    let ranges: Vec<&[GpuLight]> = lights.chunks(chunk_len).collect();
    let chunks = parallel_map(ranges, |part| assign_chunk(grid, part, camera_far));
    // Visible lights are numbered chunk after chunk, so the numbering is ascending.
    let mut visible = Vec::new();
    let mut visible_base = Vec::with_capacity(chunks.len());
    for (t, chunk) in chunks.iter().enumerate() {
        visible_base.push(visible.len() as u32);
        let first = (t * chunk_len) as u32;
        visible.extend(
            chunk
                .local_visible
                .iter()
                .enumerate()
                .filter(|(_, v)| **v != u32::MAX)
                .map(|(i, _)| first + i as u32),
        );
    }
    let (mut offsets, mut counts, mut indices) = if chunks.len() == 1 {
        // One chunk is already the final list: no merge pass.
        let chunk = chunks.into_iter().next().expect("one chunk");
        (chunk.offsets, chunk.counts, chunk.sorted)
    } else {
        merge_chunks(&chunks, &visible_base, cells, threads)
    };
    let max_lights_per_cluster = counts.iter().copied().max().unwrap_or(0);
    let mut stats = AssignStats {
        clusters: grid.total_cells,
        max_lights_per_cluster,
        visible_lights: visible.len(),
        ..Default::default()
    };
    // Overflow: lower the cap until the list fits the budget, then keep the most important.
    let cap = effective_cap(&counts, limits.cell_cap, limits.max_indices);
    if max_lights_per_cluster > cap {
        let mut kept = Vec::with_capacity(indices.len().min(limits.max_indices));
        for cell in 0..cells {
            let (o, n) = (offsets[cell] as usize, counts[cell] as usize);
            let list = &mut indices[o..o + n];
            if n > cap as usize {
                let center = cell_center(grid, cell as u32);
                let key = |i: &u32| importance(&lights[visible[*i as usize] as usize], center);
                list.select_nth_unstable_by(cap as usize - 1 + usize::from(cap == 0), |a, b| {
                    key(b).total_cmp(&key(a))
                });
                let keep = &mut list[..cap as usize];
                keep.sort_unstable();
                stats.overflowed_lights += (n - cap as usize) as u64;
            }
            let keep = n.min(cap as usize);
            offsets[cell] = kept.len() as u32;
            counts[cell] = keep as u32;
            kept.extend_from_slice(&indices[o..o + keep]);
        }
        indices = kept;
    }
    let nonempty = counts.iter().filter(|&&n| n > 0).count() as u32;
    stats.nonempty_clusters = nonempty;
    stats.indices = indices.len();
    stats.avg_lights_per_nonempty = if nonempty > 0 {
        indices.len() as f64 / nonempty as f64
    } else {
        0.0
    };
    Assignment {
        visible,
        offsets,
        counts,
        indices,
        stats,
    }
}

/// Phases 2 and 3 for several chunks: global counts and offsets, then every thread fills a
/// contiguous block of cells of the final list (disjoint slices), concatenating the chunks'
/// runs for each cell.
fn merge_chunks(
    chunks: &[Chunk],
    visible_base: &[u32],
    cells: usize,
    threads: usize,
) -> (Vec<u32>, Vec<u32>, Vec<u32>) {
    let mut counts = vec![0u32; cells];
    for chunk in chunks {
        for (total, n) in counts.iter_mut().zip(&chunk.counts) {
            *total += n;
        }
    }
    let mut offsets = vec![0u32; cells];
    let mut running = 0usize;
    for (o, n) in offsets.iter_mut().zip(&counts) {
        *o = running as u32;
        running += *n as usize;
    }
    let mut indices = vec![0u32; running];
    let blocks = split_cells(&offsets, running, threads);
    let mut rest: &mut [u32] = &mut indices;
    let mut jobs = Vec::with_capacity(blocks.len());
    for &(c0, c1) in &blocks {
        let len = if c1 < cells {
            offsets[c1] as usize
        } else {
            running
        } - offsets[c0] as usize;
        let (head, tail) = rest.split_at_mut(len);
        jobs.push((c0, c1, head));
        rest = tail;
    }
    parallel_map(jobs, |(c0, c1, out)| {
        let mut at = 0;
        for cell in c0..c1 {
            for (chunk, base) in chunks.iter().zip(visible_base) {
                let (o, n) = (chunk.offsets[cell] as usize, chunk.counts[cell] as usize);
                for (dst, src) in out[at..at + n].iter_mut().zip(&chunk.sorted[o..o + n]) {
                    *dst = src + base;
                }
                at += n;
            }
        }
    });
    (offsets, counts, indices)
}

/// Splits the cells into at most `parts` contiguous, non-empty blocks with about equal numbers
/// of indices (fewer blocks when there are fewer cells).
fn split_cells(offsets: &[u32], total: usize, parts: usize) -> Vec<(usize, usize)> {
    let cells = offsets.len();
    let mut blocks = Vec::with_capacity(parts);
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
    blocks
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
