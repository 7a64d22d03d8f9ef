//! The automatic grid: which cell footprint a frame should use, chosen by a cost model over
//! measured candidates.
//!
//! A finer grid makes every fragment loop over fewer lights but costs more assignment (more
//! runs of cells to find, more indices and cells to count) and more bytes to upload; the best footprint depends on
//! the resolution, the lights, the view and the device. So the choice is made by measuring, not
//! by a constant:
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
//! or a grid's predicted assignment passes the CPU budget ([`GridConfig::assign_budget`], 5 % of
//! the predicted frame) after a coarser one kept within it. The choice is the cheapest predicted
//! frame among the grids that fit the index list, then among those within the CPU budget:
//! near the optimum the frame barely changes with the footprint while the assignment grows
//! about as its inverse square, so a finer grid there buys a fraction of a percent of frame
//! for tens of percent more CPU (measured in docs/grid.md). The choice is deterministic for
//! given samples, lights and costs. A new choice replaces the current grid only when it is
//! predicted at least [`HYSTERESIS`] cheaper (or the current one overflows or passes the CPU
//! budget where the new one does not), so a static scene never flip-flops between two
//! near-equal grids.

mod costs;
mod search;

pub use costs::{assign_work, FrameCost, GridCosts, CALIBRATION_WINDOW, INDEX_WEIGHT};
pub use search::{choose, ChoiceSearch};

use crate::cluster::assign::AssignLimits;
use crate::cluster::grid::{ClusterGrid, GridConfig, GridProjection};
use crate::cluster::pack::GpuLight;
use crate::cluster::pack_grid::GridEncoding;

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

    /// Mean light evaluations per sampled surface point with `grid`'s lists `counts`.
    pub fn evals_per_pixel(&self, grid: &ClusterGrid, counts: &[u32]) -> f64 {
        if self.points.is_empty() {
            return 0.0;
        }
        let total: u64 = self
            .points
            .iter()
            .map(|&[x, y, d]| {
                let cell = grid.cell_index(grid.cell_of_fragment(x, y, d));
                counts.get(cell as usize).copied().unwrap_or(0) as u64
            })
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
}

impl Candidate {
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
/// so the least overflow first, then one within the CPU budget, then the smallest prediction.
pub(super) fn better(a: &Candidate, b: &Candidate) -> bool {
    (a.overflowed_lights, a.over_budget, a.predicted_ms)
        < (b.overflowed_lights, b.over_budget, b.predicted_ms)
}

/// Whether `new` should replace `current`: only when predicted at least [`HYSTERESIS`] cheaper
/// than the current footprint under the same measurement (or when the current one was not
/// measured this time, overflows or passes the CPU budget where the new one does not, or its
/// first split moved). The current grid has to pass the budget by more than [`HYSTERESIS`]
/// (relative) to be left for it, and a grid left for the budget is not taken back until it is
/// predicted clearly cheaper, so a grid near the budget does not alternate with its neighbour.
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
            let clearly_over = now.assigns_over(current.assign_budget * (1.0 + HYSTERESIS));
            best.overflowed_lights < now.overflowed_lights
                || (best.overflowed_lights == now.overflowed_lights
                    && clearly_over
                    && !best.over_budget)
                || best.predicted_ms < now.predicted_ms * (1.0 - HYSTERESIS)
        }
        _ => true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cluster::assign::Assigner;
    use crate::scene::Light;
    use glam::{DMat4, DVec3, Vec3};
    use rand::{Rng, SeedableRng};

    const SIZE: (u32, u32) = (320, 180);

    /// Lights over a floor seen from above, and surface samples on that floor.
    fn workload(lights: usize) -> (Vec<GpuLight>, SurfaceSamples) {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(3);
        let lights = (0..lights)
            .map(|_| {
                let p = DVec3::new(
                    rng.random_range(-12.0..12.0),
                    rng.random_range(-7.0..7.0),
                    -rng.random_range(6.0..30.0),
                );
                let light = Light::point(p, rng.random_range(0.5..2.5), Vec3::ONE, 1.0);
                GpuLight::from_light(&light, &DMat4::IDENTITY)
            })
            .collect();
        let mut samples = SurfaceSamples {
            rays: 0,
            pixels: (SIZE.0 * SIZE.1) as f64,
            ..SurfaceSamples::default()
        };
        for j in 0..18 {
            for i in 0..32 {
                samples.rays += 1;
                samples.points.push([
                    (i as f64 + 0.5) * 10.0,
                    (j as f64 + 0.5) * 10.0,
                    8.0 + j as f64,
                ]);
            }
        }
        (lights, samples)
    }

    fn inputs(lights: &[GpuLight]) -> ChoiceInputs<'_> {
        ChoiceInputs {
            size: SIZE,
            projection: GridProjection::test_view(),
            near: 0.1,
            far: 40.0,
            camera_far: 100.0,
            base: GridConfig::default(),
            lights,
            limits: AssignLimits {
                cell_cap: u32::MAX,
                ..AssignLimits::default()
            },
            encoding: GridEncoding::Uint,
        }
    }

    /// A framebuffer whose every standard candidate passes the cell budget still gets a grid:
    /// a coarser one.
    #[test]
    fn a_huge_framebuffer_gets_coarser_cells_than_the_standard_candidates() {
        let (lights, samples) = workload(50);
        let mut huge = inputs(&lights);
        huge.size = (16_384, 16_384);
        let choice = choose(&huge, &samples, &GridCosts::default(), &mut Assigner::new());
        let chosen = choice
            .candidates
            .iter()
            .find(|c| c.footprint_px == choice.config.footprint_px)
            .expect("the chosen footprint was measured");
        assert!(
            chosen.cells > 0 && chosen.cells <= CELL_BUDGET,
            "{chosen:?}"
        );
        assert!(
            choice.config.footprint_px > CANDIDATE_FOOTPRINTS[0],
            "{choice:?}"
        );
        // Where the standard list fits, it is the list.
        let standard = choose(
            &inputs(&lights),
            &samples,
            &GridCosts::default(),
            &mut Assigner::new(),
        );
        assert_eq!(standard.candidates[0].footprint_px, CANDIDATE_FOOTPRINTS[0]);
    }

    /// Same samples, lights and costs: the same choice, candidate for candidate.
    #[test]
    fn the_choice_is_deterministic_for_given_costs() {
        let (lights, samples) = workload(600);
        let costs = GridCosts::default();
        let a = choose(&inputs(&lights), &samples, &costs, &mut Assigner::new());
        let b = choose(&inputs(&lights), &samples, &costs, &mut Assigner::new());
        assert_eq!(a, b);
        assert!(a.candidates.len() >= 3, "{:?}", a.candidates);
    }

    /// Finer grids evaluate fewer lights and cost more assignment: cheap shading favours
    /// coarse grids, expensive shading fine ones, and without a CPU budget the choice is the
    /// candidate with the smallest prediction.
    #[test]
    fn the_choice_follows_the_costs() {
        let (lights, samples) = workload(600);
        let mut unbudgeted = inputs(&lights);
        unbudgeted.base.assign_budget = 1.0;
        let pick = |shade_ns: f64| {
            let prior = GridCosts::default();
            let costs = GridCosts::new(shade_ns, prior.assign_ns, prior.upload_ns);
            let choice = choose(&unbudgeted, &samples, &costs, &mut Assigner::new());
            assert!(choice.candidates.iter().all(|c| !c.over_budget));
            let best = choice
                .candidates
                .iter()
                .min_by(|a, b| a.predicted_ms.total_cmp(&b.predicted_ms))
                .unwrap();
            assert_eq!(best.footprint_px, choice.config.footprint_px);
            for pair in choice.candidates.windows(2) {
                assert!(pair[1].evals_per_pixel <= pair[0].evals_per_pixel * 1.01);
                assert!(pair[1].indices >= pair[0].indices);
            }
            choice.config.footprint_px
        };
        let (cheap, dear) = (pick(1e-4), pick(1000.0));
        assert_eq!(cheap, CANDIDATE_FOOTPRINTS[0]);
        assert!(dear < cheap, "{dear} px against {cheap} px");
    }

    /// A search stepped one candidate per call (as frames do) measures the same candidates and
    /// makes the same choice as one made whole; a new start drops a search in progress.
    #[test]
    fn a_search_spread_over_calls_chooses_what_one_call_does() {
        let (lights, samples) = workload(600);
        let costs = GridCosts::default();
        let whole = choose(&inputs(&lights), &samples, &costs, &mut Assigner::new());
        assert!(whole.candidates.len() >= 3, "{:?}", whole.candidates);
        let mut search = ChoiceSearch::default();
        let mut assigner = Assigner::new();
        // A search abandoned after one step leaves nothing behind.
        search.start(&inputs(&lights[..100]), &samples);
        assert!(!search.step(&inputs(&lights[..100]), &samples, &costs, &mut assigner));
        search.start(&inputs(&lights), &samples);
        let mut steps = 0;
        while search.in_progress() {
            search.step(&inputs(&lights), &samples, &costs, &mut assigner);
            steps += 1;
        }
        assert_eq!(steps, whole.candidates.len());
        assert_eq!(search.finish(&inputs(&lights), &samples, &costs), whole);
    }

    /// A new choice within the hysteresis band of the current grid does not replace it, one
    /// clearly cheaper does; so a static scene measured again keeps its grid.
    #[test]
    fn switching_needs_a_clear_gain() {
        let (lights, samples) = workload(600);
        let choice = choose(
            &inputs(&lights),
            &samples,
            &GridCosts::default(),
            &mut Assigner::new(),
        );
        assert!(!should_switch(&choice.config, &choice));
        for c in &choice.candidates {
            let current = GridConfig {
                footprint_px: c.footprint_px,
                ..choice.config.clone()
            };
            let best = choice
                .candidates
                .iter()
                .find(|b| b.footprint_px == choice.config.footprint_px)
                .unwrap();
            let budget = choice.config.assign_budget * (1.0 + HYSTERESIS);
            let clear = best.predicted_ms < c.predicted_ms * (1.0 - HYSTERESIS)
                || (c.assign_ms > budget * c.predicted_ms && !best.over_budget);
            assert_eq!(should_switch(&current, &choice), clear, "{c:?}");
        }
        // Measured again and again with costs a little off (the shading's cost moving the
        // shares, so a grid near the budget goes in and out of it), the grid changes at most
        // once and never goes back.
        let mut current = choice.config.clone();
        let mut footprints = vec![current.footprint_px];
        let mut costs = GridCosts::default();
        // Per footprint, whether it was over the budget in each measurement.
        let mut verdicts: Vec<(f64, Vec<bool>)> = Vec::new();
        for shade in [13.0, 14.5, 13.5, 14.0, 13.2, 14.8, 13.8, 14.2, 13.4] {
            costs.shade_ns = shade;
            let again = choose(&inputs(&lights), &samples, &costs, &mut Assigner::new());
            for c in &again.candidates {
                match verdicts.iter_mut().find(|(f, _)| *f == c.footprint_px) {
                    Some((_, v)) => v.push(c.over_budget),
                    None => verdicts.push((c.footprint_px, vec![c.over_budget])),
                }
            }
            if should_switch(&current, &again) {
                current = again.config.clone();
            }
            if footprints.last() != Some(&current.footprint_px) {
                footprints.push(current.footprint_px);
            }
        }
        assert!(
            verdicts
                .iter()
                .any(|(_, v)| v.contains(&true) && v.contains(&false)),
            "no grid went in and out of the budget, so this tested nothing: {verdicts:?} {:?}",
            choice
                .candidates
                .iter()
                .map(|c| (c.footprint_px, c.assign_ms / c.predicted_ms))
                .collect::<Vec<_>>()
        );
        assert!(
            footprints.len() <= 2,
            "the grid flip-flopped: {footprints:?}"
        );
    }

    /// The budget's hysteresis on hand-made figures: a current grid a little over the budget
    /// (less than [`HYSTERESIS`] past it) stays when the best grid is not clearly cheaper; one
    /// clearly over gives way to a grid within it even when that one is predicted slower.
    #[test]
    fn a_grid_just_over_the_budget_is_kept() {
        let candidate = |footprint_px: f64, predicted_ms: f64, assign_ms: f64| {
            let mut c = Candidate {
                footprint_px,
                cells: 1000,
                indices: 1000,
                evals_per_pixel: 1.0,
                bytes: 1000,
                predicted_ms,
                assign_ms,
                over_budget: false,
                overflowed_lights: 0,
            };
            c.over_budget = c.assigns_over(0.05);
            c
        };
        let choice = |current_assign_ms: f64| GridChoice {
            config: GridConfig {
                footprint_px: 13.5,
                ..GridConfig::default()
            },
            reason: String::new(),
            candidates: vec![
                candidate(13.5, 10.2, 0.45),
                candidate(11.0, 10.0, current_assign_ms),
            ],
        };
        let current = GridConfig {
            footprint_px: 11.0,
            ..GridConfig::default()
        };
        // 5.2 % of the frame: over the 5 % budget, not by 10 %.
        assert!(choice(0.52).candidates[1].over_budget);
        assert!(!should_switch(&current, &choice(0.52)));
        // 6 %: clearly over.
        assert!(should_switch(&current, &choice(0.6)));
        // Within the budget, the faster current grid stays.
        assert!(!should_switch(&current, &choice(0.4)));
    }

    /// The CPU budget: the choice is the cheapest predicted frame among the grids whose
    /// predicted assignment keeps within the budget's share of it, the search stops at the
    /// first grid past it, and a current grid past it gives way to one within it even when
    /// that one is predicted slower; the reason says what the budget turned down.
    #[test]
    fn the_cpu_budget_bounds_the_assignment() {
        let (lights, samples) = workload(600);
        // Dear shading: without a budget the finest grids win.
        let prior = GridCosts::default();
        let costs = GridCosts::new(200.0, prior.assign_ns, prior.upload_ns);
        let mut free = inputs(&lights);
        free.base.assign_budget = 1.0;
        let unbounded = choose(&free, &samples, &costs, &mut Assigner::new());
        let share = |c: &Candidate| c.assign_ms / c.predicted_ms;
        let chosen = |choice: &GridChoice| {
            choice
                .candidates
                .iter()
                .find(|c| c.footprint_px == choice.config.footprint_px)
                .unwrap()
                .clone()
        };
        let free_pick = chosen(&unbounded);
        assert!(share(&free_pick) > 0.0, "{free_pick:?}");
        // A budget between the coarsest grid's share and the free choice's.
        let coarsest = share(&unbounded.candidates[0]);
        assert!(coarsest < share(&free_pick), "{unbounded:?}");
        let budget = 0.5 * (coarsest + share(&free_pick));
        let mut tight = inputs(&lights);
        tight.base.assign_budget = budget;
        let bounded = choose(&tight, &samples, &costs, &mut Assigner::new());
        let pick = chosen(&bounded);
        assert!(!pick.over_budget && share(&pick) <= budget, "{bounded:?}");
        assert!(pick.footprint_px > free_pick.footprint_px, "{bounded:?}");
        let within = bounded.candidates.iter().filter(|c| !c.over_budget);
        let cheapest = within
            .min_by(|a, b| a.predicted_ms.total_cmp(&b.predicted_ms))
            .unwrap();
        assert_eq!(cheapest.footprint_px, pick.footprint_px);
        // Every candidate flagged as the budget says, and none measured past the first over.
        for (k, c) in bounded.candidates.iter().enumerate() {
            assert_eq!(c.over_budget, share(c) > budget, "{c:?}");
            if c.over_budget {
                assert_eq!(k, bounded.candidates.len() - 1, "{bounded:?}");
            }
        }
        assert!(bounded.reason.contains("but assigns"), "{}", bounded.reason);
        // The grid the free choice would keep is over the budget: the bounded choice replaces
        // it although it is predicted slower; the other way the hysteresis decides.
        let free_config = GridConfig {
            assign_budget: budget,
            ..unbounded.config.clone()
        };
        assert!(should_switch(&free_config, &bounded));
        // No candidate within a zero budget: the cheapest prediction, as without one.
        let mut none = inputs(&lights);
        none.base.assign_budget = 0.0;
        let zero = choose(&none, &samples, &costs, &mut Assigner::new());
        assert_eq!(zero.config.footprint_px, free_pick.footprint_px);
    }

    /// Overflow outranks the budget: with a per-cell cap that coarse cells overflow, a grid
    /// past the budget that drops fewer lights does not end the search, and the choice is
    /// the grid that drops the fewest.
    #[test]
    fn overflow_outranks_the_cpu_budget() {
        let (lights, samples) = workload(600);
        let mut capped = inputs(&lights);
        capped.limits.cell_cap = 12;
        capped.base.assign_budget = 0.05;
        let choice = choose(
            &capped,
            &samples,
            &GridCosts::default(),
            &mut Assigner::new(),
        );
        let c = &choice.candidates;
        let first_over = c
            .iter()
            .position(|c| c.over_budget)
            .expect("a grid past the 5 % budget");
        let least_within = c[..first_over]
            .iter()
            .map(|c| c.overflowed_lights)
            .min()
            .expect("a coarse grid within 5 %");
        assert!(
            c[first_over].overflowed_lights < least_within,
            "this workload must overflow less past the budget: {c:?}"
        );
        assert!(
            c.len() > first_over + 1,
            "the search stopped at the budget: {c:?}"
        );
        let fewest = c.iter().map(|c| c.overflowed_lights).min().unwrap();
        let chosen = c
            .iter()
            .find(|c| c.footprint_px == choice.config.footprint_px)
            .unwrap();
        assert_eq!(chosen.overflowed_lights, fewest, "{c:?}");
    }

    /// A grid whose lists would not fit loses to one that fits, however cheap it looks.
    #[test]
    fn a_grid_that_overflows_is_not_chosen() {
        let (lights, samples) = workload(600);
        let roomy = choose(
            &inputs(&lights),
            &samples,
            &GridCosts::default(),
            &mut Assigner::new(),
        );
        let coarsest = roomy.candidates[0].indices;
        let mut tight = inputs(&lights);
        tight.limits.max_indices = coarsest + 1;
        let mut costs = GridCosts::default();
        costs.shade_ns = 1000.0;
        let choice = choose(&tight, &samples, &costs, &mut Assigner::new());
        assert_eq!(choice.config.footprint_px, CANDIDATE_FOOTPRINTS[0]);
        assert!(choice.candidates.len() >= 2, "a finer grid was measured");
        assert!(choice.candidates[1].overflowed_lights > 0);
    }

    /// The grid starts a little before the nearest surface, on a coarse ladder of depths, and
    /// never before the near plane.
    #[test]
    fn the_first_split_comes_from_the_nearest_surface() {
        let (_, samples) = workload(1);
        let split = first_split(&samples, 0.1).unwrap();
        assert!(split <= 8.0 * 0.8 && split > 8.0 * 0.8 / 2f64.powf(0.25));
        let mut moved = samples.clone();
        moved.points[0][2] = 8.05;
        assert_eq!(
            first_split(&moved, 0.1),
            Some(split),
            "a small move keeps it"
        );
        assert_eq!(first_split(&samples, 10.0), None);
        assert_eq!(first_split(&SurfaceSamples::default(), 0.1), None);
    }
}
