//! The automatic grid: which cell footprint a frame should use, chosen by a cost model over
//! measured candidates.
//!
//! A finer grid makes every fragment loop over fewer lights but costs more assignment (more
//! runs of cells to find, more indices and cells to count) and more bytes to upload; the best
//! footprint depends on the resolution, the lights, the view and the device. So the choice is
//! made by measuring, not by a constant:
//!
//! ```text
//! predicted frame cost(f) = shade · E(f) · P  +  assign · work(f)  +  upload · bytes(f)
//! ```
//!
//! * `E(f)`: light evaluations per covered pixel, counted exactly at [`SurfaceSamples`] (the
//!   surfaces a coarse ray cast of the frame found) in the candidate's real light lists;
//!   `P` the covered pixels.
//! * `work(f)` ([`assign_work`]: its runs of cells, and a little for its indices and cells)
//!   and `bytes(f)`: from the candidate's real assignment.
//! * `shade`, `assign`, `upload`: [`GridCosts`], nanoseconds per unit, calibrated on the running
//!   device from the frames it renders ([`GridCosts::observe`]): starting from priors measured
//!   on llvmpipe.
//!
//! Candidates run from coarse to fine (`64 / 2^(n/4)` pixels, a quarter octave apart, down to
//! 8) and stop once the prediction has risen twice in a row, a grid would pass the cell budget,
//! or a grid's predicted assignment passes the CPU budget
//! ([`GridConfig::assign_budget`](crate::cluster::grid::GridConfig::assign_budget), 5 % of the
//! predicted frame) after a coarser one kept within it. The choice is the cheapest predicted
//! frame among the grids that fit the index list, then among those within the CPU budget:
//! near the optimum the frame barely changes with the footprint while the assignment grows
//! about as its inverse square, so a finer grid there buys a fraction of a percent of frame
//! for tens of percent more CPU (measured in docs/grid.md). The choice is deterministic for
//! given samples, lights and costs. A new choice replaces the current grid only when it is
//! predicted at least [`HYSTERESIS`] cheaper (or the current one overflows or passes the CPU
//! budget where the new one does not), so a static scene never flip-flops between two
//! near-equal grids.

mod choice;
mod costs;
mod search;
#[cfg(test)]
mod tests;

pub use choice::{first_split, should_switch, Candidate, ChoiceInputs, GridChoice, SurfaceSamples};
pub use choice::{CANDIDATE_FOOTPRINTS, CELL_BUDGET, HYSTERESIS};
pub use costs::{assign_work, FrameCost, GridCosts, CALIBRATION_WINDOW, INDEX_WEIGHT};
pub use search::{choose, ChoiceSearch};
