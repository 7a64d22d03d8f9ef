//! The shared engine of tiled and clustered forward: assign lights to a grid on the CPU every
//! frame, upload three data textures (lights, grid, indices), and shade in one geometry pass
//! where each fragment loops over its cell's lights only. A still frame (its `ListsKey` the
//! last frame's) skips stages 3 and 4 and draws with the last upload.
//!
//! A frame runs these stages in order, each in its own file:
//!
//! 1. `limits`: what the frame may hold on this context (cell cap, index list), and the grid
//!    and the visible lights checked against it;
//! 2. `grid`: the cell grid, rebuilt only when what it depends on changed (and the CPU costs
//!    the automatic grid calibrates on, recorded after the upload);
//! 3. `assign`: the lights assigned to the cells, and the overflow warning;
//! 4. `upload`: the lists packed into texels and uploaded into the texture ring;
//! 5. `bind`: the textures and uniform values every program of the frame gets;
//! 6. `draw` (here): the geometry pass, each program bound with them.
//!
//! Uploads are ring-buffered over `upload::RING` texture sets: a frame writes the set the GPU used
//! `RING` uploads ago, never one an in-flight frame may still read (drivers would otherwise stall
//! or copy on a rewrite).

mod assign;
mod bind;
mod grid;
mod limits;
mod upload;

pub use bind::ClusteredProgram;

use super::geometry;
use super::grid_choice::AutoGrid;
use super::GridReport;
use super::{FrameContext, MethodStats, ShadingMethod};
use crate::cluster::assign::{AssignLimits, Assignment};
use crate::cluster::grid::ClusterGrid;
use crate::cluster::pack::{GridEncoding, LightLayout, MAX_INDEXED_LIGHTS, RGBA8_CELL_CAP};
use crate::gl::{Device, GlError};
use crate::Error;

/// Which grid the method builds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Culling {
    /// 2D screen tiles, one slice over the whole depth range.
    Tiled,
    /// The dense cascaded cluster grid.
    Clustered,
}

/// A frame of [`CulledForward::render_unless_too_many`].
pub(crate) enum CulledFrame<'a> {
    /// Rendered, with its stats.
    Rendered(MethodStats<'a>),
    /// Not rendered: this many lights were visible, more than the index list can number.
    TooManyVisible(usize),
    /// Not rendered: the grid's cells would list at least `references` light references
    /// before the cell cap, more than an assignment builds.
    Unlisted { cells: u32, references: usize },
    /// Not rendered: a buffer the lists are built in could not grow to `bytes` (the
    /// allocator refused it).
    Unallocated(u64),
    /// Not rendered, as asked: the per-cell cap left this many light references out.
    Overflowed(u64),
}

/// What [`CulledForward::lists`] did.
struct Lists {
    /// What the lists are built from.
    key: ListsKey,
    /// The assignment's time.
    ms: f64,
    /// `None`: the last frame's lists are this frame's. Else light references the assignment
    /// dropped: overflowed, or `u64::MAX` where it could not list them.
    dropped: Option<u64>,
}

/// Tiled or clustered forward.
pub struct CulledForward {
    culling: Culling,
    /// The grid and what it was built for.
    grid: Option<(grid::GridKey, ClusterGrid)>,
    /// The automatic grid's choice and calibration (clustered, `GridMode::Auto`).
    auto: AutoGrid,
    /// Why a tiled or fixed grid is what it is (the automatic grid keeps its own reason).
    reason: String,
    /// The assignment's buffers and warning state.
    assign: assign::Assign,
    /// The packing buffers and the texture ring.
    upload: upload::Uploads,
    /// Bumped whenever the grid is rebuilt.
    grid_generation: u64,
    /// What the last uploaded lists were built from: a frame with the same draws with them.
    lists_key: Option<ListsKey>,
    /// Frames without lights in a row (see [`super::IDLE_FRAMES_KEPT`]).
    idle_frames: u32,
}

/// Everything a frame's light lists and uploaded textures are a function of: the lights (by
/// generation), the grid (likewise), the camera's far plane, the assignment's limits and the
/// light record layout. The ES version, also one, is the device's for good.
#[derive(Clone, Copy, Debug, PartialEq)]
struct ListsKey {
    lights_generation: u64,
    grid_generation: u64,
    far: u64,
    limits: AssignLimits,
    layout: LightLayout,
}

impl CulledForward {
    /// A method with no GPU resources yet (created on first render).
    pub fn new(culling: Culling) -> Self {
        CulledForward {
            culling,
            grid: None,
            auto: AutoGrid::default(),
            reason: String::new(),
            assign: assign::Assign::default(),
            upload: upload::Uploads::default(),
            grid_generation: 0,
            lists_key: None,
            idle_frames: 0,
        }
    }

    /// Renders one frame (the stages of the module docs, in order), or stops after the
    /// assignment, before any GL work, when more lights are visible than the index list can
    /// number: `auto` then renders the frame with forward.
    pub(crate) fn render_unless_too_many(
        &mut self,
        ctx: &mut FrameContext,
        refuse_overflow: bool,
    ) -> Result<CulledFrame<'_>, Error> {
        let method = self.name();
        let automatic = self.automatic(ctx);
        let grid_encoding = GridEncoding::for_es(ctx.dev.es());
        self.idle_frames = 0;

        let limits = limits::assign_limits(ctx);
        self.update_grid(ctx, &limits, grid_encoding);
        let mut lists = self.lists(ctx, &limits)?;
        if let Some(dropped) = lists.dropped.filter(|_| automatic) {
            if self.auto.outgrown(dropped) {
                self.update_grid(ctx, &limits, grid_encoding);
                lists = self.lists(ctx, &limits)?;
            }
        }
        // The assignments may have run other rayon jobs on this thread while they waited for
        // the pool: checked before the frame's first GL call goes to another job's context.
        if self.assign.ran_other_jobs() {
            ctx.dev
                .check_current()
                .map_err(|_| GlError::ContextChangedByPoolJob)?;
        }
        self.write_grid_reason(ctx);
        let (grid_key, grid) = self.grid.as_ref().expect("updated above");
        let reused = match (lists.dropped, self.assign.reuse()) {
            (None, Some(assigned)) => self.upload.still_frame(ctx.dev)?.map(|u| (assigned, u)),
            _ => None,
        };
        let (assigned, uploaded) = match reused {
            Some((assigned, uploaded)) => {
                // Checked again: `auto` refuses overflow in some frames only.
                if let Some(frame) = refused(assigned.assignment, refuse_overflow) {
                    return Ok(frame);
                }
                (assigned, uploaded)
            }
            None => {
                let assigned = self.assign.assigned(method, ctx, &limits, lists.ms);
                if let Some(frame) = refused(assigned.assignment, refuse_overflow) {
                    return Ok(frame);
                }
                let uploaded =
                    self.upload
                        .pack_and_upload(ctx, method, grid, assigned.assignment)?;
                self.lists_key = Some(lists.key);
                (assigned, uploaded)
            }
        };
        if automatic {
            grid::record_cost(&mut self.auto, grid, &assigned, &uploaded);
        }
        let bindings = bind::Bindings::new(
            &uploaded,
            grid,
            assigned.assignment,
            ctx.viewport,
            ctx.origin,
        );
        draw(ctx, &bindings)?;

        Ok(CulledFrame::Rendered(MethodStats {
            upload_bytes: uploaded.bytes,
            assign_ms: Some(assigned.ms),
            assign: Some(assigned.assignment.stats),
            lists_reused: assigned.reused,
            grid: Some(GridReport {
                footprint_px: grid_key.config.footprint_px,
                cells: grid.total_cells,
                reason: if automatic {
                    self.auto.reason()
                } else {
                    &self.reason
                },
            }),
            ..MethodStats::default()
        }))
    }

    /// The frame's light lists on the current grid: the last frame's where nothing they are
    /// built from changed, else assigned now. Borrows nothing, so that the automatic grid can
    /// choose again and the lists be assigned again where its choice no longer lists them.
    fn lists(&mut self, ctx: &FrameContext, limits: &AssignLimits) -> Result<Lists, Error> {
        let (grid_key, grid) = self.grid.as_ref().expect("updated before");
        limits::check_grid(ctx.dev, grid, &grid_key.config)?;
        let key = ListsKey {
            lights_generation: ctx.lights_generation,
            grid_generation: self.grid_generation,
            far: ctx.far.to_bits(),
            limits: *limits,
            layout: ctx.features.light_layout(),
        };
        // A still frame (nothing the lists depend on changed) draws with the last ones.
        let still = self.lists_key == Some(key)
            && self.assign.last().is_some()
            && self.upload.last_upload().is_some();
        if still {
            return Ok(Lists {
                key,
                ms: 0.0,
                dropped: None,
            });
        }
        // Cleared first: a refused frame leaves the assigner holding other lists.
        self.lists_key = None;
        let (ms, assignment) = self.assign.run(grid, ctx, limits);
        Ok(Lists {
            key,
            ms,
            dropped: Some(assignment.dropped_references()),
        })
    }

    /// Whether this frame's grid is the automatic one.
    fn automatic(&self, ctx: &FrameContext) -> bool {
        self.culling == Culling::Clustered && ctx.options.grid.is_auto()
    }
}

/// Why a frame with `assignment` is not drawn (see [`CulledFrame`]), if it is not.
fn refused(assignment: &Assignment, refuse_overflow: bool) -> Option<CulledFrame<'static>> {
    if let Some(bytes) = assignment.unallocated {
        return Some(CulledFrame::Unallocated(bytes));
    }
    if let Some(references) = assignment.unlisted {
        let cells = assignment.stats.clusters;
        return Some(CulledFrame::Unlisted { cells, references });
    }
    let visible = assignment.visible.len();
    if visible > MAX_INDEXED_LIGHTS {
        return Some(CulledFrame::TooManyVisible(visible));
    }
    let overflowed = assignment.stats.overflowed_lights;
    (refuse_overflow && overflowed > 0).then_some(CulledFrame::Overflowed(overflowed))
}

/// The geometry pass with the `clustered` shader, each program bound with the frame's
/// `bindings`.
fn draw(ctx: &mut FrameContext, bindings: &bind::Bindings) -> Result<(), Error> {
    geometry::draw_objects(
        ctx,
        "clustered",
        RGBA8_CELL_CAP,
        &mut |p: &ClusteredProgram, dev| bindings.bind(p, dev),
    )
}

impl ShadingMethod for CulledForward {
    fn name(&self) -> &'static str {
        match self.culling {
            Culling::Tiled => "tiled",
            Culling::Clustered => "clustered",
        }
    }

    /// Renders one frame; more visible lights than the index list can number is an error.
    fn render(&mut self, ctx: &mut FrameContext) -> Result<MethodStats<'_>, Error> {
        let (name, automatic) = (self.name(), self.automatic(ctx));
        match self.render_unless_too_many(ctx, false)? {
            CulledFrame::Rendered(stats) => Ok(stats),
            CulledFrame::TooManyVisible(visible) => Err(limits::too_many_visible(visible)),
            CulledFrame::Unlisted { cells, references } => Err(limits::too_many_references(
                name, cells, references, automatic,
            )),
            CulledFrame::Unallocated(bytes) => Err(limits::lists_unallocated(name, bytes)),
            CulledFrame::Overflowed(_) => unreachable!("overflow is refused only when asked"),
        }
    }

    fn observe_frame(&mut self, timing: super::FrameTiming) {
        self.auto.observe(timing);
    }

    fn light_lists(&self) -> Option<super::LightLists<'_>> {
        Some((&self.grid.as_ref()?.1, self.assign.last()?))
    }

    /// GPU bytes of all ring sets.
    fn gpu_bytes(&self) -> usize {
        self.upload.gpu_bytes()
    }

    fn fit_buffers(&mut self, in_use: bool) {
        self.assign.fit_buffers(in_use);
        self.upload.fit_buffers(in_use);
        if !in_use {
            self.lists_key = None;
        }
    }

    /// Frees the ring after `IDLE_FRAMES_KEPT` frames without lights.
    fn skip_frame(&mut self, dev: &Device) {
        if super::idle_for_long(&mut self.idle_frames) {
            self.destroy(dev);
        }
    }

    /// Frees the ring.
    fn destroy(&mut self, dev: &Device) {
        self.lists_key = None;
        self.upload.destroy(dev);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lists the allocator refused are a frame not drawn, whose error names the size; a list
    /// too long to build keeps its own reason.
    #[test]
    fn lists_the_allocator_refused_are_an_error_naming_the_size() {
        let mut a = Assignment {
            unlisted: Some(5),
            unallocated: Some(3 << 20),
            ..Assignment::default()
        };
        let Some(CulledFrame::Unallocated(bytes)) = refused(&a, false) else {
            panic!("not refused for its memory");
        };
        let text = limits::lists_unallocated("clustered", bytes).to_string();
        assert!(
            text.contains("3 MiB") && text.contains("cannot allocate"),
            "{text}"
        );
        a.unallocated = None;
        assert!(matches!(
            refused(&a, false),
            Some(CulledFrame::Unlisted { references: 5, .. })
        ));
    }
}
