//! What the automatic grid chooses between and by: the surface samples, a measured candidate,
//! the choice and its inputs, and the rules that rank candidates and keep the current grid.

use crate::cluster::assign::AssignLimits;
use crate::cluster::grid::{ClusterGrid, GridConfig, GridProjection};
use crate::cluster::pack::GridEncoding;
use crate::cluster::view_light::GpuLight;

/// A new grid must be predicted this much cheaper (relative) than the current one to replace it.
pub const HYSTERESIS: f64 = 0.1;

/// Footprints tried, coarse to fine: `64 / 2^(n/4)`, rounded (a half octave apart the CPU
/// budget jumped from a grid just over it to one with a third more evaluations).
pub const CANDIDATE_FOOTPRINTS: [f64; 13] = [
    64.0, 54.0, 45.0, 38.0, 32.0, 27.0, 23.0, 19.0, 16.0, 13.5, 11.0, 9.5, 8.0,
];

/// Most cells a chosen grid may have (a grid texture of 1 024 × 1 024 texels).
pub const CELL_BUDGET: u32 = 1 << 20;

/// Visible surface points of a frame, found by a coarse ray cast: where fragments will be.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SurfaceSamples {
    /// Window position (pixels, y from the bottom) and view depth of each surface hit.
    pub points: Vec<[f64; 3]>,
    /// Rays cast (hits and misses).
    pub rays: usize,
    /// Pixels of the viewport.
    pub pixels: f64,
}

impl SurfaceSamples {
    /// Estimated pixels covered by geometry.
    pub fn covered_pixels(&self) -> f64 {
        if self.rays == 0 {
            0.0
        } else {
            self.pixels * self.points.len() as f64 / self.rays as f64
        }
    }

    /// The nearest sampled surface depth, if any surface was hit.
    pub fn nearest_depth(&self) -> Option<f64> {
        self.points
            .iter()
            .map(|p| p[2])
            .filter(|d| d.is_finite() && *d > 0.0)
            .reduce(f64::min)
    }

    /// Mean light references dropped per sampled surface point with `grid`'s cut cells
    /// `overfull` (ascending, as [`Assignment`](crate::cluster::assign::Assignment) has them).
    pub fn dropped_per_pixel(&self, grid: &ClusterGrid, overfull: &[(u32, u32)]) -> f64 {
        if overfull.is_empty() {
            return 0.0;
        }
        self.mean_over_points(grid, |cell| {
            let cut = overfull.binary_search_by_key(&cell, |&(c, _)| c);
            cut.map_or(0, |i| overfull[i].1)
        })
    }

    /// Mean light evaluations per sampled surface point with `grid`'s lists `counts`.
    pub fn evals_per_pixel(&self, grid: &ClusterGrid, counts: &[u32]) -> f64 {
        self.mean_over_points(grid, |cell| counts.get(cell as usize).copied().unwrap_or(0))
    }

    /// Mean over the sampled surface points of `per_cell` of the `grid` cell each falls in (0
    /// without samples).
    fn mean_over_points(&self, grid: &ClusterGrid, per_cell: impl Fn(u32) -> u32) -> f64 {
        if self.points.is_empty() {
            return 0.0;
        }
        let total: u64 = (self.points.iter())
            .map(|&[x, y, d]| u64::from(per_cell(grid.cell_index(grid.cell_of_fragment(x, y, d)))))
            .sum();
        total as f64 / self.points.len() as f64
    }
}

/// One candidate grid as measured.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Candidate {
    /// Cell footprint in pixels.
    pub footprint_px: f64,
    /// Cells of the grid.
    pub cells: u32,
    /// Light indices of its assignment.
    pub indices: usize,
    /// Estimated light evaluations per covered pixel.
    pub evals_per_pixel: f64,
    /// Bytes its textures upload.
    pub bytes: usize,
    /// Predicted frame cost in milliseconds.
    pub predicted_ms: f64,
    /// Predicted assignment time in milliseconds (part of `predicted_ms`).
    pub assign_ms: f64,
    /// Its predicted assignment passes the CPU budget ([`GridConfig::assign_budget`]).
    pub over_budget: bool,
    /// Light references the overflow policy would drop with this grid.
    pub overflowed_lights: u64,
    /// Of those, the mean a sampled surface point misses (infinite where none could be
    /// listed): what the picture loses. A coarse grid drops fewer references than a fine one
    /// under a per-cell cap, each from more pixels.
    pub dropped_per_pixel: f64,
}

impl Candidate {
    /// What its overflow costs the picture, to compare: the references a surface point
    /// misses, then those dropped anywhere (in cells no sample fell in).
    pub fn overflow(&self) -> (f64, u64) {
        (self.dropped_per_pixel, self.overflowed_lights)
    }

    /// Whether its predicted assignment takes more than `share` of its predicted frame (never
    /// for a NaN share): the CPU budget's test.
    pub fn assigns_over(&self, share: f64) -> bool {
        self.assign_ms > share * self.predicted_ms
    }

    /// Its predicted assignment as a share of its predicted frame.
    pub fn assign_share(&self) -> f64 {
        self.assign_ms / self.predicted_ms.max(f64::MIN_POSITIVE)
    }
}

/// The grid chosen, and why.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct GridChoice {
    /// The grid's settings (fixed footprint, first split from the samples).
    pub config: GridConfig,
    /// One line: the prediction that decided it.
    pub reason: String,
    /// Every candidate measured, coarse to fine.
    pub candidates: Vec<Candidate>,
}

/// Bytes a choice's reason keeps room for: more than its longest (about 400 with realistic
/// numbers), with a prefix when the current grid is kept.
const REASON_CAPACITY: usize = 1024;

impl GridChoice {
    /// Gives the reason room for any reason (its numbers' widths vary) and the candidates room
    /// for `candidates`, so that a re-choice written into this choice allocates nothing.
    pub(crate) fn keep_room(&mut self, candidates: usize) {
        self.reason
            .reserve(REASON_CAPACITY.saturating_sub(self.reason.len()));
        self.candidates
            .reserve(candidates.saturating_sub(self.candidates.len()));
    }
}

/// What a candidate grid is built and assigned with.
pub struct ChoiceInputs<'a> {
    /// Viewport.
    pub size: (u32, u32),
    /// Projection.
    pub projection: GridProjection,
    /// Near plane and the grid's far end.
    pub near: f64,
    /// Far end of the grid (the content's).
    pub far: f64,
    /// The camera's far plane (may be infinite).
    pub camera_far: f64,
    /// The user's settings; `footprint_px` and `first_split` are what the choice sets.
    pub base: GridConfig,
    /// Lights in view space.
    pub lights: &'a [GpuLight],
    /// Assignment limits.
    pub limits: AssignLimits,
    /// How the grid and index textures store cells and indices (their bytes).
    pub encoding: GridEncoding,
}

/// The first split of a grid for these samples: a little before the nearest surface, rounded
/// down to a power of 2^(1/4) so small camera moves keep the same grid. `None` (start at the
/// near plane) without samples.
pub fn first_split(samples: &SurfaceSamples, near: f64) -> Option<f64> {
    let d = samples.nearest_depth()? * 0.8;
    let quantised = (d.log2() * 4.0).floor() / 4.0;
    let split = quantised.exp2();
    (split.is_finite() && split > near).then_some(split)
}

/// Whether candidate `a` beats `b`: a grid whose lists overflow drops lights from the image,
/// so the least overflow first, then one within the CPU budget, then the smallest prediction;
/// between two past the budget, the one nearer it (the smaller share), so that a budget no
/// grid keeps (`0`) gets the least CPU, not the most.
pub(super) fn better(a: &Candidate, b: &Candidate) -> bool {
    let key = |c: &Candidate| {
        let cost = if c.over_budget {
            c.assign_share()
        } else {
            c.predicted_ms
        };
        (c.overflow(), c.over_budget, cost)
    };
    key(a) < key(b)
}

/// Whether `new` should replace `current`: only when predicted at least [`HYSTERESIS`] cheaper
/// than the current footprint under the same measurement (or when the current one was not
/// measured this time, overflows or passes the CPU budget where the new one does not, passes
/// it further than the new one by [`HYSTERESIS`] (relative share), or its first split moved).
/// The current grid has to pass the budget by more than [`HYSTERESIS`] (relative) to be left
/// for it, and a grid left for the budget is not taken back until it is predicted clearly
/// cheaper, so a grid near the budget does not alternate with its neighbour.
pub fn should_switch(current: &GridConfig, new: &GridChoice) -> bool {
    if current.first_split != new.config.first_split {
        return true;
    }
    let measured = |f: f64| new.candidates.iter().find(|c| c.footprint_px == f);
    match (
        measured(current.footprint_px),
        measured(new.config.footprint_px),
    ) {
        (Some(now), Some(best)) => {
            // The current grid must pass the budget clearly too, or a grid whose share sits
            // at the budget would be swapped out whenever a measurement put it a hair over.
            let clearly_over = now.assigns_over(current.assign_budget() * (1.0 + HYSTERESIS));
            let same_overflow = best.overflow() == now.overflow();
            // Past the budget both: the new one must be clearly nearer it.
            let nearer_budget = now.over_budget
                && best.over_budget
                && best.assign_share() < now.assign_share() * (1.0 - HYSTERESIS);
            best.overflow() < now.overflow()
                || (same_overflow && clearly_over && !best.over_budget)
                || (same_overflow && nearer_budget)
                || best.predicted_ms < now.predicted_ms * (1.0 - HYSTERESIS)
        }
        _ => true,
    }
}
