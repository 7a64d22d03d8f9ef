//! The automatic grid's search over candidate footprints ([`super`]), whole in one call
//! ([`choose`]) or one candidate per frame ([`ChoiceSearch::step`]): a re-choice that measures
//! every candidate in one frame runs several assignments in it instead of one, a spike a game
//! sees as a dropped frame.

use super::choice::{better, Candidate, ChoiceInputs, GridChoice, SurfaceSamples};
use super::choice::{first_split, CANDIDATE_FOOTPRINTS, CELL_BUDGET};
use super::costs::{assign_work, GridCosts};
use crate::cluster::assign::Assigner;
use crate::cluster::grid::{ClusterGrid, GridConfig};

/// A search over the candidate footprints, coarse to fine, kept between frames (its buffers
/// and its scratch grid are reused by the next search).
#[derive(Default)]
pub struct ChoiceSearch {
    /// The first split every candidate starts from (from the samples at the start).
    split: Option<f64>,
    /// The footprints to try, coarse to fine, and the next one's position.
    footprints: Vec<f64>,
    next: usize,
    /// The candidates measured so far, and the best of them.
    candidates: Vec<Candidate>,
    best: Option<usize>,
    /// Successive candidates whose prediction rose.
    rises: u32,
    /// No candidate is left to measure.
    done: bool,
    /// The grid each candidate is built in (rebuilt in place).
    grid: Option<ClusterGrid>,
}

impl ChoiceSearch {
    /// Starts a search for these inputs and samples (dropping any search in progress).
    pub fn start(&mut self, inputs: &ChoiceInputs, samples: &SurfaceSamples) {
        self.split = first_split(samples, inputs.near);
        self.next = 0;
        self.candidates.clear();
        self.best = None;
        self.rises = 0;
        self.done = false;
        // The standard candidates, preceded by coarser powers of two where even the coarsest
        // passes the cell budget (a 16 384² target at 64 px cells has 25 M cells), so a huge
        // framebuffer still gets a grid that fits. Counted with the first split the
        // candidates are built with: a nearer split means more slices.
        self.footprints.clear();
        self.footprints.extend_from_slice(&CANDIDATE_FOOTPRINTS);
        let longest = f64::from(inputs.size.0.max(inputs.size.1));
        while self.footprints[0] < longest
            && self.build(inputs, self.footprints[0]).total_cells > CELL_BUDGET
        {
            self.footprints.insert(0, self.footprints[0] * 2.0);
        }
        self.candidates.reserve(self.footprints.len());
    }

    /// Whether a started search has candidates left to measure.
    pub fn in_progress(&self) -> bool {
        !self.done && !self.footprints.is_empty()
    }

    /// Measures the next candidate (built and assigned for real with this frame's lights);
    /// true when the search is over (then [`ChoiceSearch::finish`]).
    pub fn step(
        &mut self,
        inputs: &ChoiceInputs,
        samples: &SurfaceSamples,
        costs: &GridCosts,
        assigner: &mut Assigner,
    ) -> bool {
        let Some(&footprint_px) = self.footprints.get(self.next).filter(|_| !self.done) else {
            self.done = true;
            return true;
        };
        self.next += 1;
        let grid = self.build(inputs, footprint_px);
        if grid.total_cells > CELL_BUDGET {
            self.done = true;
            return true;
        }
        let a = assigner.assign_candidate(grid, inputs.lights, inputs.camera_far, &inputs.limits);
        let evals_per_pixel = samples.evals_per_pixel(grid, &a.counts);
        let bytes = grid.total_cells as usize * inputs.encoding.cell_bytes()
            + a.indices.len() * inputs.encoding.index_bytes();
        let work = assign_work(a.stats.runs, a.indices.len(), grid.total_cells);
        let covered = samples.covered_pixels();
        let mut candidate = Candidate {
            footprint_px,
            cells: grid.total_cells,
            indices: a.indices.len(),
            evals_per_pixel,
            bytes,
            predicted_ms: costs.predict_ms(evals_per_pixel * covered, work, bytes as f64),
            assign_ms: costs.assign_ms(work),
            over_budget: false,
            // Unlisted (too many references to build) is worse than any grid that lists, and
            // finer grids only list more.
            overflowed_lights: a.dropped_references(),
            dropped_per_pixel: match a.unlisted {
                Some(_) => f64::INFINITY,
                None => samples.dropped_per_pixel(grid, &a.overfull),
            },
        };
        let unlisted = a.unlisted.is_some();
        // A NaN budget (refused by the renderer) keeps every grid in.
        candidate.over_budget = candidate.assigns_over(inputs.base.assign_budget());
        // Past here finer grids only assign more than a coarser grid that kept within the CPU
        // budget without overflowing more than this one: they can win only by overflowing
        // less, and then the search goes on.
        let budget_passed = candidate.over_budget
            && self
                .candidates
                .iter()
                .any(|c| !c.over_budget && c.overflow() <= candidate.overflow());
        let (rising, overflow_grew) = self.candidates.last().map_or((false, false), |last| {
            (
                candidate.predicted_ms > last.predicted_ms,
                candidate.overflow() > last.overflow(),
            )
        });
        if self
            .best
            .is_none_or(|b| better(&candidate, &self.candidates[b]))
        {
            self.best = Some(self.candidates.len());
        }
        self.candidates.push(candidate);
        self.rises = if rising { self.rises + 1 } else { 0 };
        // Past here finer grids only rise further, or overflow the index list more (a per-cell
        // cap overflows less in finer cells, so overflow alone does not stop the search), or
        // pass the CPU budget (above).
        self.done = self.rises == 2
            || overflow_grew
            || budget_passed
            || unlisted
            || self.next == self.footprints.len();
        self.done
    }

    /// The choice the measured candidates make (see [`choose`]).
    pub fn finish(
        &mut self,
        inputs: &ChoiceInputs,
        samples: &SurfaceSamples,
        costs: &GridCosts,
    ) -> GridChoice {
        let mut choice = GridChoice {
            config: inputs.base.clone(),
            reason: String::new(),
            candidates: Vec::new(),
        };
        self.finish_into(inputs, samples, costs, &mut choice);
        choice
    }

    /// [`ChoiceSearch::finish`] into `out`, reusing its reason's and candidates' buffers (a
    /// re-choice then allocates nothing once they have grown).
    pub fn finish_into(
        &mut self,
        inputs: &ChoiceInputs,
        samples: &SurfaceSamples,
        costs: &GridCosts,
        out: &mut GridChoice,
    ) {
        use std::fmt::Write as _;
        self.done = true;
        let best = match self.best {
            Some(i) => self.candidates[i].clone(),
            None => Candidate {
                footprint_px: inputs.base.footprint_px,
                cells: 0,
                indices: 0,
                evals_per_pixel: 0.0,
                bytes: 0,
                predicted_ms: 0.0,
                assign_ms: 0.0,
                over_budget: false,
                overflowed_lights: 0,
                dropped_per_pixel: 0.0,
            },
        };
        out.reason.clear();
        out.candidates.clear();
        out.keep_room(self.footprints.len());
        let _ = write!(
            out.reason,
            "auto: {} px predicted {:.2} ms ({:.1} evaluations per pixel, {} cells, {} indices) \
             with costs per evaluation {:.1} ns, per assignment unit {:.1} ns, per byte {:.2} ns (",
            best.footprint_px,
            best.predicted_ms,
            best.evals_per_pixel,
            best.cells,
            best.indices,
            costs.shade_ns,
            costs.assign_ns,
            costs.upload_ns,
        );
        let _ = if costs.frames == 0 {
            write!(out.reason, "priors")
        } else {
            write!(out.reason, "calibrated over {} frames", costs.frames)
        };
        let _ = write!(out.reason, ") over {} samples", samples.points.len());
        // The budget's part: the chosen grid's assignment against it, and the finer grid it
        // turned down (predicted cheaper but over the budget), if any.
        let budget = inputs.base.assign_budget();
        let _ = write!(
            out.reason,
            "; assignment {:.2} ms, {:.1} % of the frame (budget {:.1} %)",
            best.assign_ms,
            100.0 * best.assign_share(),
            100.0 * budget
        );
        let turned_down = self.candidates.iter().find(|c| {
            c.over_budget && c.overflow() <= best.overflow() && c.predicted_ms < best.predicted_ms
        });
        if best.over_budget {
            let _ = write!(out.reason, "; no grid kept within it: the smallest share");
        } else if let Some(c) = turned_down {
            let _ = write!(
                out.reason,
                "; {} px was predicted {:.2} ms faster but assigns {:.1} %",
                c.footprint_px,
                best.predicted_ms - c.predicted_ms,
                100.0 * c.assign_share()
            );
        }
        out.config = GridConfig {
            footprint_px: best.footprint_px,
            first_split: self.split,
            ..inputs.base.clone()
        };
        out.candidates.extend_from_slice(&self.candidates);
    }

    /// The scratch grid rebuilt for `footprint_px` from the search's first split.
    fn build(&mut self, inputs: &ChoiceInputs, footprint_px: f64) -> &ClusterGrid {
        let config = GridConfig {
            footprint_px,
            first_split: self.split,
            ..inputs.base.clone()
        };
        let (w, h) = inputs.size;
        let (near, far) = (inputs.near, inputs.far);
        match &mut self.grid {
            Some(grid) => grid.rebuild(w, h, inputs.projection, near, far, &config),
            None => {
                self.grid = Some(ClusterGrid::new(
                    w,
                    h,
                    inputs.projection,
                    near,
                    far,
                    &config,
                ))
            }
        }
        self.grid.as_ref().expect("built above")
    }
}

/// Measures the candidates and picks the cheapest under `costs` (see [`super`]'s docs),
/// all in this call.
pub fn choose(
    inputs: &ChoiceInputs,
    samples: &SurfaceSamples,
    costs: &GridCosts,
    assigner: &mut Assigner,
) -> GridChoice {
    let mut search = ChoiceSearch::default();
    search.start(inputs, samples);
    while !search.step(inputs, samples, costs, assigner) {}
    search.finish(inputs, samples, costs)
}
