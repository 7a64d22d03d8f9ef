//! Stage grid: the cell grid the frame assigns to (tiles, the fixed grid or the automatic
//! one), rebuilt only when what it depends on changed, and why it is what it is. Also where
//! the automatic grid is told what the frame's CPU side cost.

use std::fmt::Write as _;

use super::assign::Assigned;
use super::upload::Uploaded;
use super::{CulledForward, Culling};
use crate::cluster::assign::AssignLimits;
use crate::cluster::auto_grid::{assign_work, FrameCost};
use crate::cluster::grid::{ClusterGrid, GridConfig, GridProjection};
use crate::cluster::pack::GridEncoding;
use crate::methods::grid_choice::{self, AutoGrid};
use crate::methods::FrameContext;

/// What the grid depends on; it is rebuilt only when this changes.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct GridKey {
    size: (u32, u32),
    projection: GridProjection,
    near: u64,
    far: u64,
    pub(super) config: GridConfig,
}

impl CulledForward {
    /// Rebuilds the grid when the viewport, projection or grid settings changed (the
    /// automatic grid's included).
    pub(super) fn update_grid(
        &mut self,
        ctx: &FrameContext,
        limits: &AssignLimits,
        encoding: GridEncoding,
    ) {
        let projection = GridProjection::from_matrix(&ctx.projection.as_dmat4());
        let config = match self.culling {
            Culling::Clustered if self.automatic(ctx) => {
                let choice = self.auto.config(
                    ctx,
                    projection,
                    limits,
                    encoding,
                    self.assign.candidates_assigner(),
                );
                let config = choice.config.clone();
                if self.auto.measured_candidates() {
                    self.assign.holds_candidates();
                }
                config
            }
            Culling::Clustered => ctx.options.grid.clone(),
            // Tiled shares the clustered grid's coverage setting (to measure it).
            Culling::Tiled => GridConfig {
                measure: ctx.options.grid.measure,
                ..GridConfig::tiles(ctx.options.tile_px)
            },
        };
        let key = GridKey {
            size: ctx.viewport,
            projection,
            near: ctx.near.to_bits(),
            far: ctx.content_far.to_bits(),
            config: config.clone(),
        };
        if self.grid.as_ref().map(|(k, _)| k) != Some(&key) {
            self.grid_generation += 1;
            let (w, h) = ctx.viewport;
            match &mut self.grid {
                // In place: a moving camera changes the depth range, and so the grid, every
                // frame.
                Some((old_key, grid)) => {
                    grid.rebuild(w, h, projection, ctx.near, ctx.content_far, &config);
                    *old_key = key;
                }
                None => {
                    let grid =
                        ClusterGrid::new(w, h, projection, ctx.near, ctx.content_far, &config);
                    self.grid = Some((key, grid));
                }
            }
        }
    }

    /// Writes why a tiled or fixed grid is what it is into `self.reason` (the automatic grid
    /// says it in [`AutoGrid::reason`]).
    pub(super) fn write_grid_reason(&mut self, ctx: &FrameContext) {
        self.reason.clear();
        match self.culling {
            Culling::Tiled => {
                let _ = write!(self.reason, "tiled: tile_px = {}", ctx.options.tile_px);
            }
            Culling::Clustered if self.automatic(ctx) => {}
            Culling::Clustered => {
                grid_choice::write_fixed_reason(&mut self.reason, &ctx.options.grid)
            }
        }
    }
}

/// Tells the automatic grid what this frame's assignment and uploads cost (its shading time
/// follows in [`AutoGrid::observe`]).
pub(super) fn record_cost(
    auto: &mut AutoGrid,
    grid: &ClusterGrid,
    assigned: &Assigned,
    uploaded: &Uploaded,
) {
    let assignment = assigned.assignment;
    // Reused lists cost no CPU work: such a frame calibrates the shading alone.
    let work = match assigned.reused {
        true => 0.0,
        false => assign_work(
            assignment.stats.runs,
            assignment.indices.len(),
            grid.total_cells,
        ),
    };
    auto.record(
        grid,
        &assignment.counts,
        FrameCost {
            assign_ms: assigned.ms,
            assign_work: work,
            upload_ms: uploaded.ms,
            upload_bytes: uploaded.bytes as f64,
            ..FrameCost::default()
        },
    );
}
