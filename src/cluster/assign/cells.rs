//! Which cells one light can touch: the per-light half of the assignment (`assign` does the
//! sorting). All in view space and `f64`.
//!
//! 1. A light wholly outside one of the frustum's side planes touches nothing. Otherwise its
//!    depth range `[d − r, d + r]` is clipped to `[near, far]` **before** anything
//!    is projected, so lights behind or around the camera never flip to the wrong side; a light
//!    whose range misses the frustum touches nothing.
//! 2. The clipped range gives the first and last (cascade, slice).
//! 3. Per cascade, the sphere's screen extent (box projection over the cascade's depth slab,
//!    tightened by the exact tangent bounds when the sphere is in front of the eye) bounds the
//!    columns and rows, whose ends are then tested against the tile planes. Inside that
//!    rectangle, per slice, the sphere is cut to its largest cross-section over the slice's
//!    depths (radius `ρ`), and per row of cells to that cross-section's chord where the row's
//!    band comes nearest (half-width `√(ρ² − δ²)`): each row gets the columns that chord can
//!    reach ([`Coverage::SliceRows`]), four rows at a time (`rows.rs`). The rectangle alone is
//!    [`Coverage::CascadeBox`].
//! 4. Spot lights start from the bounding sphere of their cone's reach instead of their whole
//!    sphere, and each row's columns are then cut to those whose cells' bounding spheres the
//!    cone may touch, solved per row in closed form (`cone.rs`; four rows at a time,
//!    `cone/lanes.rs`); a rectangle of at most 2 × 2 cells per slice is kept whole.
//!
//! The cells come out as **runs**: a run is consecutive columns of one row of one slice, which
//! are consecutive cell numbers. Emitting runs instead of single cells lets the counting sort
//! touch its per-cell counters in tight loops and keeps the per-cell cost to a few instructions.
//!
//! The radius is padded by a relative 10⁻⁴ so a fragment that float rounding puts in the
//! neighbouring cell still finds every light that reaches it: the assignment is conservative.

use super::cone::{Cone, ConeSlice};
use super::rows::{RowChords, ROW_LANES};
use crate::cluster::grid::{CascadeConstants, ClusterGrid, Coverage, GridProjection};
use crate::cluster::min_max::MinMax;
use crate::cluster::view_light::GpuLight;

/// Relative padding of light radii (see the module docs).
const RADIUS_PAD: f64 = 1e-4;

/// A slice whose cross-section spans fewer columns than this plus one emits its rows without
/// a chord each (see [`ScreenExtent::for_each_row_run`]).
const ROW_CHORD_MIN_COLUMNS: u32 = 3;

/// A band of consecutive slices (numbered across cascades, `first..end`), the part of the grid
/// one thread of the assignment fills, and the view depths a light must reach to touch it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SliceWindow {
    /// First slice.
    pub first: u32,
    /// One past the last slice.
    pub end: u32,
    /// A light whose depth range misses `[near, far]` touches none of the band's cells
    /// (conservative: widened beyond the slices' own widened bounds; unbounded at the grid's
    /// two ends, which take every depth in front of and behind it).
    near: f64,
    far: f64,
}

impl SliceWindow {
    /// Every slice of any grid: no depth bound, and an end past any grid's last slice (a
    /// constant, so a light's runs over the whole grid pay nothing for the window).
    pub const ALL: SliceWindow = SliceWindow {
        first: 0,
        end: u32::MAX,
        near: f64::NEG_INFINITY,
        far: f64::INFINITY,
    };

    /// Slices `first..end` of `grid` (`first < end ≤` its slice count).
    pub fn of(grid: &ClusterGrid, first: u32, end: u32) -> SliceWindow {
        let slabs = &grid.slice_slabs;
        let near = if first == 0 {
            f64::NEG_INFINITY
        } else {
            slabs[first as usize][0] * (1.0 - WINDOW_MARGIN)
        };
        let far = if end as usize >= slabs.len() {
            f64::INFINITY
        } else {
            slabs[end as usize - 1][1] * (1.0 + WINDOW_MARGIN)
        };
        SliceWindow {
            first,
            end,
            near,
            far,
        }
    }
}

/// Relative widening of a [`SliceWindow`]'s depth bounds: its depth test only skips lights
/// early, the slice numbers decide, so it may be generous.
const WINDOW_MARGIN: f64 = 1e-3;

/// Calls `emit(first_cell, cells)` for every run of consecutive cells `light` may touch, in
/// ascending cell order.
pub fn for_each_run(
    grid: &ClusterGrid,
    light: &GpuLight,
    camera_far: f64,
    emit: &mut impl FnMut(u32, u32),
) {
    for_each_run_in(grid, &SliceWindow::ALL, light, camera_far, emit)
}

/// [`for_each_run`] restricted to the cells of `window`'s slices: exactly the runs
/// [`for_each_run`] emits there.
#[inline(always)]
pub(crate) fn for_each_run_in(
    grid: &ClusterGrid,
    window: &SliceWindow,
    light: &GpuLight,
    camera_far: f64,
    emit: &mut impl FnMut(u32, u32),
) {
    let p = light.position.as_dvec3();
    let r0 = light.cull_radius as f64;
    if r0.is_nan() || r0 <= 0.0 || !p.is_finite() {
        return;
    }
    let range = r0 + RADIUS_PAD * (p.z.abs() + r0);
    // A spot's cone bound (below) lies within √2 · range of the light: 2 · range bounds it.
    let reach = if light.spot_scale == 0.0 {
        range
    } else {
        2.0 * range
    };
    if -p.z + reach < window.near || -p.z - reach > window.far {
        return;
    }
    let cone = Cone::of(light, range);
    // The sphere every cell test starts from: the light's, or the tighter bound of a spot's
    // cone.
    let (c, r) = cone.as_ref().map_or((p, range), |cone| cone.bound);
    // 1. Cull against the frustum's sides, then clip the depth range before projecting.
    if grid.sphere_outside_sides(c, r) {
        return;
    }
    let d = -c.z;
    // The planes first (`MinMax`): never NaN, where a hostile spot's bound may be.
    let dmin = grid.near.at_least(d - r);
    let dmax = camera_far.at_most(d + r);
    if dmin > dmax {
        return;
    }
    let ((k0, s0), (k1, s1)) = grid.depth_range_to_slices(dmin, dmax);
    let extent = ScreenExtent::new(grid, c, r, dmin, dmax);
    let light = LightBounds {
        grid,
        window,
        extent: &extent,
        cone: &cone,
    };
    if k0 == k1 {
        // The common case, apart from the loop: nothing is needed after the cascade's runs,
        // so the compiler keeps the light's bounds in registers rather than on the stack
        // across the refinement's call.
        light.cascade_runs(k0, s0, s1, false, emit);
        return;
    }
    // Exclusive ranges in the loops below: inclusive ones cost a flag check per step.
    for k in k0..k1 + 1 {
        let sa = if k == k0 { s0 } else { 0 };
        let sb = if k == k1 {
            s1
        } else {
            grid.cascades[k as usize].slices - 1
        };
        if !light.cascade_runs(k, sa, sb, true, emit) {
            // The window ends before this cascade (and every later one).
            break;
        }
    }
}

/// What a light's cells in each cascade are cut from: its screen extent and cone, the grid and
/// the window's slices.
struct LightBounds<'a> {
    grid: &'a ClusterGrid,
    window: &'a SliceWindow,
    extent: &'a ScreenExtent,
    cone: &'a Option<Cone>,
}

impl LightBounds<'_> {
    /// Emits the light's runs in slices `sa..=sb` of cascade `k` (numbered within it), cut to
    /// the window's; with `slab`, the light's depth range spans several cascades and this
    /// cascade's slab tightens the tangent bounds. False when the window ends before the
    /// cascade.
    #[inline(always)]
    fn cascade_runs(
        &self,
        k: u32,
        sa: u32,
        sb: u32,
        slab: bool,
        emit: &mut impl FnMut(u32, u32),
    ) -> bool {
        let (grid, window, extent) = (self.grid, self.window, self.extent);
        let cascade = &grid.cascades[k as usize];
        let constants = &grid.cascade_constants[k as usize];
        // The light's slices of this cascade, cut to the window's (numbered within the
        // cascade, inclusive).
        let sa = sa.max(window.first.saturating_sub(constants.first_slice));
        let Some(last) = window.end.checked_sub(constants.first_slice + 1) else {
            return false;
        };
        let sb = sb.min(last);
        if sa > sb {
            return true;
        }
        // The whole sphere's tangent bounds are exact on their own when the depth range
        // lies in one cascade (the common case); otherwise each cascade's slab tightens them.
        // Every slice and row below stays inside these ranges, so the refinement can only
        // remove cells.
        let Some(columns) = extent.tile_range(constants, slab, 0, cascade.tiles_x) else {
            return true;
        };
        let Some(rows) = extent.tile_range(constants, slab, 1, cascade.tiles_y) else {
            return true;
        };
        let slice_cells = cascade.tiles_x * cascade.tiles_y;
        let slice_start = cascade.first_cell + sa * slice_cells;
        // A rectangle of at most 2 × 2 cells per slice has little to trim (a corner cell at
        // most) and the per-row arithmetic, or a spot's cone test, would cost more than the
        // cells it saves (a spot's bounding sphere already fits its cone).
        let small = columns.1 - columns.0 < 2 && rows.1 - rows.0 < 2;
        if small && small_path_enabled() {
            // The common case of many small lights, kept to the plain loops: with the
            // refinement's code in the same loop the compiler spills registers and calls per
            // row.
            let width = columns.1 - columns.0 + 1;
            let mut run = slice_start + rows.0 * cascade.tiles_x + columns.0;
            let two_rows = rows.1 > rows.0;
            for _ in sa..sb + 1 {
                emit(run, width);
                if two_rows {
                    emit(run + cascade.tiles_x, width);
                }
                run += slice_cells;
            }
            return true;
        }
        let tiles = CascadeTiles {
            grid,
            constants,
            tiles_x: cascade.tiles_x,
            tiles_y: cascade.tiles_y,
            columns,
            rows,
        };
        refine_slices(extent, &tiles, self.cone, k, sa..sb + 1, small, emit);
        true
    }
}

/// The cells of slices `slices` of cascade `k` (numbered within it) for a light wider than
/// 2 × 2 cells there (or, in the tests, a small one with `small`):
/// the per-slice refinement of [`Coverage::SliceRows`], or the cascade's rectangle.
///
/// Kept out of line: inlined, its state crowded the small lights' path (the common case of
/// many lights) out of the registers, and every light paid for the spills.
#[inline(never)]
fn refine_slices(
    extent: &ScreenExtent,
    tiles: &CascadeTiles,
    cone: &Option<Cone>,
    k: u32,
    slices: std::ops::Range<u32>,
    small: bool,
    emit: &mut impl FnMut(u32, u32),
) {
    let grid = tiles.grid;
    let constants = tiles.constants;
    let (columns, rows) = (tiles.columns, tiles.rows);
    let slice_cells = tiles.tiles_x * tiles.tiles_y;
    let mut slice_start = grid.cascades[k as usize].first_cell + slices.start * slice_cells;
    // A small rectangle reaches this loop only in the tests that check the plain loops
    // above against it (the whole rectangle, no cone): outside tests `small` is false here.
    let coverage = if small {
        Coverage::CascadeBox
    } else {
        grid.coverage
    };
    for s in slices {
        // A spot's cone against the slice's cells, worked out once per slice.
        let cone = match cone {
            Some(cone) if !small => {
                let g = constants.first_slice + s;
                Some(cone.slice(&grid.slice_cells(k, g, columns, rows)))
            }
            _ => None,
        };
        match coverage {
            Coverage::SliceRows => {
                let slab = grid.slice_slabs[(constants.first_slice + s) as usize];
                let row_start = |row: u32| slice_start + row * tiles.tiles_x;
                // Two callers, so that a point light's rows take no cone's test.
                let emit_run = &mut |row, x0, x1| emit(row_start(row) + x0, x1 - x0 + 1);
                match &cone {
                    None => extent.for_each_row_run(tiles, slab, &WholeRows, emit_run),
                    Some(cone) => extent.for_each_row_run(tiles, slab, cone, emit_run),
                }
            }
            Coverage::CascadeBox => {
                for row in rows.0..rows.1 + 1 {
                    let row_start = slice_start + row * tiles.tiles_x;
                    emit_row(emit, &cone, row_start, row, columns.0, columns.1);
                }
            }
        }
        slice_start += slice_cells;
    }
}

/// Emits the run of columns `x0..=x1` of the row starting at cell `row_start`, cut to a spot's
/// cone when there is one. A function, not a closure: the compiler left the closure out of
/// line, a call per row.
#[inline(always)]
fn emit_row(
    emit: &mut impl FnMut(u32, u32),
    cone: &Option<ConeSlice>,
    row_start: u32,
    row: u32,
    x0: u32,
    x1: u32,
) {
    let (x0, x1) = match cone {
        None => (x0, x1),
        Some(cone) => match cone.columns(row, x0, x1) {
            Some(span) => span,
            None => return,
        },
    };
    emit(row_start + x0, x1 - x0 + 1)
}

/// What a slice's rows are cut to past their chords: nothing more (a point light's,
/// [`WholeRows`]) or a spot's cone ([`ConeSlice`]).
trait RowTrim {
    /// Row `row`'s columns within `x0..=x1`, or `None`.
    fn one(&self, row: u32, x0: u32, x1: u32) -> Option<(u32, u32)>;
    /// Rows `row .. row + ROW_LANES`, each within its span, `x0 > x1` for none.
    fn rows(&self, row: u32, spans: [(u32, u32); ROW_LANES]) -> [(u32, u32); ROW_LANES];
}

/// A point light's rows: their chords' columns.
struct WholeRows;

impl RowTrim for WholeRows {
    #[inline(always)]
    fn one(&self, _: u32, x0: u32, x1: u32) -> Option<(u32, u32)> {
        Some((x0, x1))
    }

    #[inline(always)]
    fn rows(&self, _: u32, spans: [(u32, u32); ROW_LANES]) -> [(u32, u32); ROW_LANES] {
        spans
    }
}

impl RowTrim for ConeSlice<'_> {
    #[inline(always)]
    fn one(&self, row: u32, x0: u32, x1: u32) -> Option<(u32, u32)> {
        self.columns(row, x0, x1)
    }

    #[inline(always)]
    fn rows(&self, row: u32, spans: [(u32, u32); ROW_LANES]) -> [(u32, u32); ROW_LANES] {
        self.columns_of_rows(row, spans)
    }
}

#[cfg(test)]
thread_local! {
    /// Set by the tests that compare the small-light loops with the general slice loop.
    pub(crate) static SMALL_PATH_OFF: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Whether lights of at most 2 × 2 cells a cascade take their own plain loops (always,
/// outside tests).
#[inline(always)]
fn small_path_enabled() -> bool {
    #[cfg(test)]
    return !SMALL_PATH_OFF.with(|off| off.get());
    #[cfg(not(test))]
    true
}

/// One cascade's tiling as the per-slice refinement sees it, with the column and row ranges
/// the whole cascade's bound allows.
struct CascadeTiles<'a> {
    grid: &'a ClusterGrid,
    constants: &'a CascadeConstants,
    tiles_x: u32,
    tiles_y: u32,
    columns: (u32, u32),
    rows: (u32, u32),
}

/// Largest reciprocal depth used: `1 / f64::MIN_POSITIVE`, so a slab at the eye gives huge
/// slopes rather than `0 · ∞ = NaN`.
const MAX_INV_DEPTH: f64 = 1.0 / f64::MIN_POSITIVE;

/// Extreme view-space slopes of the extent `[low, high]` over the depths whose reciprocals
/// are `inv_a` and `inv_b` (the box projection: the extremes lie at the slab's ends).
#[inline(always)]
fn box_slopes(low: f64, high: f64, inv_a: f64, inv_b: f64) -> (f64, f64) {
    (
        (low * inv_a).min(low * inv_b),
        (high * inv_a).max(high * inv_b),
    )
}

/// [`box_slopes`] for finite `inv_a ≥ inv_b ≥ 0` (a slice's slab, see
/// `ScreenExtent::for_each_row_run`), by comparison and select: a product with `inv_a` is NaN
/// only when the one with `inv_b` is too (a NaN extent, or an infinite one and both zero).
#[inline(always)]
fn slab_slopes(low: f64, high: f64, inv_a: f64, inv_b: f64) -> (f64, f64) {
    (
        (low * inv_a).at_most(low * inv_b),
        (high * inv_a).at_least(high * inv_b),
    )
}

/// Tile range `[t0, t1]` of `count` tiles (`half` = count / 2) covering the NDC range
/// `[lo, hi]`, or `None` when it misses the screen (or is NaN).
#[inline(always)]
fn ndc_to_tiles(lo: f64, hi: f64, half: f64, count: u32) -> Option<(u32, u32)> {
    // `&`, not `&&`: one branch instead of three.
    if !((lo <= hi) & (hi >= -1.0) & (lo <= 1.0)) {
        return None;
    }
    // `as u32` saturates: negative coordinates give tile 0.
    let to_tile = |ndc: f64| (((ndc + 1.0) * half) as u32).min(count - 1);
    Some((to_tile(lo), to_tile(hi)))
}

/// The per-slice, per-row refinement (Persson's "practical clustered", Bevy's assigner):
/// inside a slice's depth slab the sphere is no wider than its largest cross-section there,
/// and inside one row's band no wider than that cross-section's chord at the band's nearest
/// point.
impl ScreenExtent {
    /// Calls `emit(row, first_column, last_column)` for every row of the cascade whose cells
    /// in the depth slab `[z0, z1]` the sphere may reach, with the columns it may reach there
    /// and `trim` keeps (a spot's cone).
    ///
    /// In the slab (clipped to the sphere's depth range, `za ≤ z ≤ zb`) the sphere's points
    /// lie within `ρ` of its axis, `ρ` the radius of its cross-section at the depth of the
    /// slab nearest the centre. A row is the band of view `y` between `t0·z` and `t1·z`
    /// (perspective; `t0` and `t1` in orthographic); over the slab the band comes no closer to
    /// the centre than `δ`, a lower bound of the distance taken over the slab's two ends, so
    /// inside the row the sphere's points lie within `√(ρ² − δ²)` of the centre in `x`. Each
    /// extent becomes a tile range by the box projection over `[za, zb]`.
    #[inline(always)]
    fn for_each_row_run(
        &self,
        tiles: &CascadeTiles,
        [z0, z1, inv_z0, inv_z1]: [f64; 4],
        trim: &impl RowTrim,
        emit: &mut impl FnMut(u32, u32, u32),
    ) {
        let (dmin, dmax) = self.depth;
        // The slab's bounds and reciprocals are never NaN, so they go first (`MinMax`); the
        // light's may be (a hostile spot's axis) and go second.
        let za = z0.at_least(dmin);
        // Never below `za`: the slice came from the widened depth range, so the slab meets it
        // up to rounding.
        let zb = z1.at_most(dmax).at_least(za);
        // Their reciprocals without a division: `1/max(a, b) = min(1/a, 1/b)`.
        let inv_a = inv_z0.at_most(self.inv_depth.0).at_most(MAX_INV_DEPTH);
        let inv_b = inv_z1.at_least(self.inv_depth.1).at_most(inv_a);
        // The centre's depth clamped into the slab, less the depth: NaN for a NaN depth on
        // either architecture's `MinMax` (as with `f64::clamp`).
        let nearest = self.d.at_least(za).at_most(zb) - self.d;
        // 0 first: a NaN difference gives 0, as `f64::max` did.
        let rho_sq = 0.0_f64.at_least(self.r * self.r - nearest * nearest);
        let rho = rho_sq.sqrt();
        let constants = tiles.constants;
        let [cx, cy] = self.center;
        let Some((y0, y1)) = self.tiles_of(tiles, 1, cy - rho, cy + rho, inv_a, inv_b) else {
            return;
        };
        let (y0, y1) = (y0.max(tiles.rows.0), y1.min(tiles.rows.1));
        if y0 > y1 {
            return;
        }
        // The cross-section's own columns bound every row's chord.
        let Some((x0, x1)) = self.tiles_of(tiles, 0, cx - rho, cx + rho, inv_a, inv_b) else {
            return;
        };
        let columns = (x0.max(tiles.columns.0), x1.min(tiles.columns.1));
        if columns.0 > columns.1 {
            return;
        }
        if columns.1 - columns.0 < ROW_CHORD_MIN_COLUMNS {
            // Too narrow for a chord to trim more than a corner cell: the per-row arithmetic
            // would cost more than the cells it saves.
            for row in y0..y1 + 1 {
                if let Some((x0, x1)) = trim.one(row, columns.0, columns.1) {
                    emit(row, x0, x1);
                }
            }
            return;
        }
        // Four rows at a time (`rows.rs`), the last fewer than four one at a time (the lanes
        // of a slice of few rows would cost more than they save), each emitted in order.
        let chords = RowChords {
            perspective: self.perspective,
            za,
            zb,
            inv_a,
            inv_b,
            cx,
            cy,
            rho_sq,
            extent_y: constants.extent[1],
            step_y: constants.tile_step[1],
            scale_x: tiles.grid.ndc_scale[0],
            half_tiles_x: constants.half_tiles[0],
            last_column: tiles.tiles_x - 1,
            columns,
        };
        let mut row = y0;
        while y1 - row + 1 >= ROW_LANES as u32 {
            for (i, &(x0, x1)) in trim.rows(row, chords.columns(row)).iter().enumerate() {
                if x0 <= x1 {
                    emit(row + i as u32, x0, x1);
                }
            }
            row += ROW_LANES as u32;
            if row > y1 {
                return;
            }
        }
        for row in row..y1 + 1 {
            let (x0, x1) = chords.one(row);
            if x0 > x1 {
                continue;
            }
            if let Some((x0, x1)) = trim.one(row, x0, x1) {
                emit(row, x0, x1);
            }
        }
    }

    /// Tile range along `axis` of the view-space extent `[low, high]` over the depths with
    /// reciprocals `inv_a` ≥ `inv_b` (box projection), or `None` when it misses the screen.
    #[inline(always)]
    fn tiles_of(
        &self,
        tiles: &CascadeTiles,
        axis: usize,
        low: f64,
        high: f64,
        inv_a: f64,
        inv_b: f64,
    ) -> Option<(u32, u32)> {
        let scale = tiles.grid.ndc_scale[axis];
        let (lo, hi) = if self.perspective {
            slab_slopes(low, high, inv_a, inv_b)
        } else {
            (low, high)
        };
        let count = if axis == 0 {
            tiles.tiles_x
        } else {
            tiles.tiles_y
        };
        ndc_to_tiles(
            lo * scale,
            hi * scale,
            tiles.constants.half_tiles[axis],
            count,
        )
    }
}

/// Where on screen the sphere a light's cells are tested against can be, computed once per
/// light and narrowed per cascade: view-space bounds pre-multiplied by the grid's NDC scale.
struct ScreenExtent {
    perspective: bool,
    /// Per axis: `(centre − r) · scale` and `(centre + r) · scale` (perspective: to be divided
    /// by a depth, orthographic: NDC already).
    low: [f64; 2],
    high: [f64; 2],
    /// Per axis: the exact NDC bounds of the sphere's tangent planes, when it lies in front
    /// of the eye (perspective only).
    tangents: Option<[(f64, f64); 2]>,
    /// The clipped depth range `dmin`, `dmax`, and their reciprocals (0 for an infinite end).
    depth: (f64, f64),
    inv_depth: (f64, f64),
    /// Centre (view x, y), depth and radius, for the plane tests of a sphere around the eye.
    center: [f64; 2],
    d: f64,
    r: f64,
}

impl ScreenExtent {
    fn new(grid: &ClusterGrid, c: glam::DVec3, r: f64, dmin: f64, dmax: f64) -> ScreenExtent {
        let perspective = matches!(grid.projection, GridProjection::Perspective { .. });
        let d = -c.z;
        let scale = grid.ndc_scale;
        // Exact tangent slopes (view x/d and y/d) of the sphere, when it is in front of the
        // eye.
        let tangents = (perspective && d > r).then(|| {
            let inv_den = 1.0 / (d * d - r * r);
            let tangent = |center: f64, scale: f64| {
                let root = r * (d * d + center * center - r * r).sqrt();
                let k = scale * inv_den;
                ((center * d - root) * k, (center * d + root) * k)
            };
            [tangent(c.x, scale[0]), tangent(c.y, scale[1])]
        });
        ScreenExtent {
            perspective,
            low: [(c.x - r) * scale[0], (c.y - r) * scale[1]],
            high: [(c.x + r) * scale[0], (c.y + r) * scale[1]],
            tangents,
            depth: (dmin, dmax),
            inv_depth: (1.0 / dmin, 1.0 / dmax),
            center: [c.x, c.y],
            d,
            r,
        }
    }

    /// Column (`axis` 0) or row (`axis` 1) range of the cascade with `constants` and `tiles`
    /// columns or rows the sphere can touch, or `None`. With `slab`, the box projection over
    /// the cascade's part of the depth range narrows the tangent bounds.
    #[inline(always)]
    fn tile_range(
        &self,
        constants: &CascadeConstants,
        slab: bool,
        axis: usize,
        tiles: u32,
    ) -> Option<(u32, u32)> {
        let (lo, hi) = match (self.perspective, self.tangents) {
            (false, _) => (self.low[axis], self.high[axis]),
            (true, Some(tangents)) if !slab => tangents[axis],
            (true, tangents) => {
                // Box projection: extreme slopes of the sphere's bounding box within the
                // cascade's slab [max(dmin, z_near), min(dmax, z_far)].
                let inv_za = self.inv_depth.0.min(constants.inv_near);
                let inv_zb = self.inv_depth.1.max(constants.inv_far);
                let (lo, hi) = box_slopes(self.low[axis], self.high[axis], inv_za, inv_zb);
                match tangents {
                    Some(t) => (lo.max(t[axis].0), hi.min(t[axis].1)),
                    None => (lo, hi),
                }
            }
        };
        let (t0, t1) = ndc_to_tiles(lo, hi, constants.half_tiles[axis], tiles)?;
        if self.perspective && self.tangents.is_none() {
            // A sphere reaching behind the eye: its box bounds are loose, tighten the ends.
            return self.tighten_around_eye(constants, axis, t0, t1);
        }
        Some((t0, t1))
    }

    /// Narrows `[t0, t1]` to the columns or rows whose planes through the eye the sphere
    /// touches, for a sphere reaching behind the eye; `None` when it touches none.
    fn tighten_around_eye(
        &self,
        constants: &CascadeConstants,
        axis: usize,
        mut t0: u32,
        mut t1: u32,
    ) -> Option<(u32, u32)> {
        let (center, d, r) = (self.center[axis], self.d, self.r);
        // The plane through the eye at NDC `u` has the normal (1, −s) (in the axis and depth
        // coordinates) with `s = u · tan`; the centre's signed distance to it, positive on the
        // +u side, is `(center − s·d) / √(1 + s²)`. Compared with ±r squared, so no root.
        // Per plane `i` (slope `s`): `a = centre − s·d` and whether |a| ≤ r·√(1 + s²).
        let plane = |i: u32| {
            let s = constants.tile_edge(axis, i);
            let a = center - s * d;
            (a, a * a <= r * r * (1.0 + s * s))
        };
        let touches = |i: u32| {
            let ((low, low_within), (high, high_within)) = (plane(i), plane(i + 1));
            (low >= 0.0 || low_within) && (high <= 0.0 || high_within)
        };
        while t0 < t1 && !touches(t0) {
            t0 += 1;
        }
        while t1 > t0 && !touches(t1) {
            t1 -= 1;
        }
        touches(t0).then_some((t0, t1))
    }
}
