//! Stage assign: the frame's lights assigned to the grid's cells on the CPU, timed, with a
//! warning (once per method) when the overflow policy drops light references.

use std::time::Instant;

use crate::cluster::assign::{AssignLimits, Assigner, Assignment};
use crate::cluster::grid::ClusterGrid;
use crate::cluster::pack::MAX_INDEXED_LIGHTS;
use crate::methods::FrameContext;

/// The assignment's buffers, reused frame after frame, and whether overflow was warned about.
#[derive(Default)]
pub(super) struct Assign {
    assigner: Assigner,
    /// `FrameStats::overflowed_lights` counts every frame's dropped references; the log says
    /// it once.
    warned_overflow: bool,
    /// The assigner's last assignment is not a frame's: an automatic grid candidate's, or
    /// emptied (`fit_buffers`).
    holds_candidate: bool,
}

/// A frame's assignment and how long it took.
pub(super) struct Assigned<'a> {
    pub assignment: &'a Assignment,
    pub ms: f64,
    /// The last frame's assignment, kept: nothing it depends on changed (no time, no work).
    pub reused: bool,
}

impl Assign {
    /// Gives back what a burst of lights grew the assigner's buffers to; not `in_use` (the
    /// last frame drew without the method), its assignment goes too, and is no longer the
    /// last frame's to reuse.
    pub(super) fn fit_buffers(&mut self, in_use: bool) {
        self.assigner.fit_buffers(in_use);
        if !in_use {
            self.holds_candidate = true;
        }
    }

    /// Assigns `ctx.lights` to `grid`'s cells within `limits`: the time it took, and the
    /// assignment ([`Assign::assigned`] takes it as the frame's).
    pub(super) fn run(
        &mut self,
        grid: &ClusterGrid,
        ctx: &FrameContext,
        limits: &AssignLimits,
    ) -> (f64, &Assignment) {
        let started = Instant::now();
        self.holds_candidate = false;
        let assignment = self.assigner.assign(grid, ctx.lights, ctx.far, limits);
        (started.elapsed().as_secs_f64() * 1e3, assignment)
    }

    /// The last [`Assign::run`]'s assignment, which took `ms`, as the frame's, with a warning
    /// (once per method) where it drops light references.
    pub(super) fn assigned(
        &mut self,
        method: &str,
        ctx: &FrameContext,
        limits: &AssignLimits,
        ms: f64,
    ) -> Assigned<'_> {
        let assignment = self.assigner.assignment();
        let dropped = assignment.stats.overflowed_lights;
        // A frame refused for too many visible lights or references drops nothing: the
        // warning (once a renderer) is kept for one that draws.
        let drawn = assignment.visible.len() <= MAX_INDEXED_LIGHTS && assignment.unlisted.is_none();
        if dropped > 0 && drawn && !self.warned_overflow {
            self.warned_overflow = true;
            let automatic = method == "clustered" && ctx.options.grid.is_auto();
            warn_overflow(method, assignment, limits, automatic);
        }
        Assigned {
            assignment,
            ms,
            reused: false,
        }
    }

    /// The last frame's assignment as this frame's, when no automatic grid's candidate was
    /// assigned since.
    pub(super) fn reuse(&self) -> Option<Assigned<'_>> {
        Some(Assigned {
            assignment: self.last()?,
            ms: 0.0,
            reused: true,
        })
    }

    /// The last frame's assignment; `None` when an automatic grid's candidate was assigned
    /// since (a frame that failed before its own assignment).
    pub(super) fn last(&self) -> Option<&Assignment> {
        (!self.holds_candidate).then(|| self.assigner.assignment())
    }

    /// Whether an assignment since the last call ran other rayon jobs on this thread
    /// ([`Assigner::take_ran_other_jobs`]).
    pub(super) fn ran_other_jobs(&mut self) -> bool {
        self.assigner.take_ran_other_jobs()
    }

    /// The assigner, for the automatic grid's candidates: they share the frame's buffers.
    /// [`Assign::holds_candidates`] says when it assigned one.
    pub(super) fn candidates_assigner(&mut self) -> &mut Assigner {
        &mut self.assigner
    }

    /// The assigner's last assignment is an automatic grid candidate's.
    pub(super) fn holds_candidates(&mut self) {
        self.holds_candidate = true;
    }
}

/// Says once that a frame left light references out, which limit left them out, and what
/// would avoid it: other cells, unless the automatic grid (`automatic`) chose these already.
fn warn_overflow(method: &str, assignment: &Assignment, limits: &AssignLimits, automatic: bool) {
    let dropped = assignment.stats.overflowed_lights;
    let cap = match limits.cell_cap {
        u32::MAX => "no cap per cell".to_string(),
        cap => format!("a cell keeps at most {cap} lights"),
    };
    // The policy's cap is uniform: below the cell cap only where the whole list was full.
    let kept = assignment.counts.iter().copied().max().unwrap_or(0);
    let list_full = kept < limits.cell_cap;
    let remedy = match (automatic, method, list_full) {
        (true, ..) => {
            "the automatic grid chose these cells already: fewer lights over one spot, or \
             Method::Auto (which draws such a frame with forward or deferred) avoid it"
        }
        (false, "tiled", false) => "smaller tiles (RenderOptions::tile_px) avoid it",
        (false, "tiled", true) => "larger tiles (RenderOptions::tile_px) avoid it",
        (false, _, false) => {
            "smaller cells (a smaller grid.footprint_px), shallower slices (a smaller \
             grid.slice_depth) or the automatic grid avoid it"
        }
        (false, _, true) => {
            "a coarser grid (grid.footprint_px), deeper slices (grid.slice_depth) or the \
             automatic grid avoid it"
        }
    };
    let full = if list_full {
        format!("the index list was full, so every cell kept at most {kept}")
    } else {
        "cells touched more lights than a cell keeps".to_string()
    };
    log::warn!(
        "{method}: {dropped} light references left out of this frame's cell lists, so \
         the image lacks those lights where they reach ({cap}, and at most {} \
         references fit in the index list here: the index texture's capacity on this \
         context or MeasureOptions::max_indices; {full}; each cell keeps the lights that \
         matter most to it, and FrameStats::lights.overflowed counts the dropped ones every \
         frame): {remedy}",
        limits.max_indices
    );
}
