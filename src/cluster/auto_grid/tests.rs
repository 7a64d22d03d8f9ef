//! The automatic grid's choice end to end: candidates, costs, budget, hysteresis.

use super::*;
use crate::cluster::assign::{AssignLimits, Assigner};
use crate::cluster::grid::{GridConfig, GridMode, GridProjection};
use crate::cluster::pack::GridEncoding;
use crate::cluster::view_light::GpuLight;
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

/// The choice for `lights` under the default limits and costs: what a test then tightens.
fn roomy_choice(lights: &[GpuLight], samples: &SurfaceSamples) -> GridChoice {
    choose(
        &inputs(lights),
        samples,
        &GridCosts::default(),
        &mut Assigner::new(),
    )
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
    unbudgeted.base.mode = GridMode::Auto { assign_budget: 1.0 };
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
        let budget = choice.config.assign_budget() * (1.0 + HYSTERESIS);
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
            dropped_per_pixel: 0.0,
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
    free.base.mode = GridMode::Auto { assign_budget: 1.0 };
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
    tight.base.mode = GridMode::Auto {
        assign_budget: budget,
    };
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
        mode: GridMode::Auto {
            assign_budget: budget,
        },
        ..unbounded.config.clone()
    };
    assert!(should_switch(&free_config, &bounded));
    // No candidate within a zero budget: the one nearest it, the smallest share, so a
    // tighter budget never buys a finer grid (it took the free choice's, the most CPU).
    let mut none = inputs(&lights);
    none.base.mode = GridMode::Auto { assign_budget: 0.0 };
    let zero = choose(&none, &samples, &costs, &mut Assigner::new());
    let zero_pick = chosen(&zero);
    assert!(zero.candidates.iter().all(|c| c.over_budget), "{zero:?}");
    assert!(
        zero.candidates
            .iter()
            .all(|c| share(&zero_pick) <= share(c)),
        "{zero:?}"
    );
    assert!(zero_pick.footprint_px >= pick.footprint_px, "{zero:?}");
    assert!(
        zero.reason.contains("no grid kept within it"),
        "{}",
        zero.reason
    );
    // A grid past the budget gives way to one clearly nearer it, not to one a hair nearer.
    let zero_config = |footprint_px: f64| GridConfig {
        footprint_px,
        mode: GridMode::Auto { assign_budget: 0.0 },
        ..zero.config.clone()
    };
    assert!(should_switch(&zero_config(free_pick.footprint_px), &zero));
    assert!(!should_switch(&zero_config(zero_pick.footprint_px), &zero));
}

/// Overflow outranks the budget: with a per-cell cap that coarse cells overflow, a grid
/// past the budget that drops fewer lights does not end the search, and the choice is
/// the grid that drops the fewest.
#[test]
fn overflow_outranks_the_cpu_budget() {
    let (lights, samples) = workload(600);
    let mut capped = inputs(&lights);
    capped.limits.cell_cap = 12;
    capped.base.mode = GridMode::Auto {
        assign_budget: 0.05,
    };
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
    let roomy = roomy_choice(&lights, &samples);
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

/// A candidate too fine to list (`Assignment::unlisted`: more references than
/// `max_untrimmed`) reports no overflow of its own and empty cells, which looked cheap: it
/// must lose to a coarser grid that lists, even one that overflows the index list, and the
/// search stops there (finer grids only list more).
#[test]
fn a_grid_too_fine_to_list_is_not_chosen() {
    let (lights, samples) = workload(600);
    let roomy = roomy_choice(&lights, &samples);
    let coarsest = roomy.candidates[0].indices;
    assert!(
        roomy.candidates[1].indices > coarsest,
        "{:?}",
        roomy.candidates
    );
    let mut tight = inputs(&lights);
    tight.limits.max_untrimmed = coarsest;
    // The coarsest overflows too, so overflow alone does not decide against the finer one.
    tight.limits.max_indices = coarsest / 2;
    let choice = choose(
        &tight,
        &samples,
        &GridCosts::default(),
        &mut Assigner::new(),
    );
    assert_eq!(choice.config.footprint_px, CANDIDATE_FOOTPRINTS[0]);
    assert_eq!(choice.candidates.len(), 2, "{:?}", choice.candidates);
    assert!(choice.candidates[0].overflowed_lights > 0);
}

/// Between two grids that overflow, the one whose sampled surface points miss fewer references
/// wins, though it drops more of them in all: a coarse grid's few dropped references each
/// leave a larger part of the frame.
#[test]
fn overflow_is_weighed_by_what_the_surface_misses() {
    let candidate = |footprint_px: f64, overflowed_lights: u64, dropped_per_pixel: f64| Candidate {
        footprint_px,
        cells: 100,
        indices: 100,
        evals_per_pixel: 1.0,
        bytes: 100,
        predicted_ms: 1.0,
        assign_ms: 0.01,
        over_budget: false,
        overflowed_lights,
        dropped_per_pixel,
    };
    let coarse = candidate(54.0, 71, 3.0);
    let fine = candidate(9.5, 95, 0.07);
    assert!(super::choice::better(&fine, &coarse));
    assert!(!super::choice::better(&coarse, &fine));
    // Equal on the surface: fewer references dropped anywhere wins.
    let unseen = candidate(16.0, 40, 0.07);
    assert!(super::choice::better(&unseen, &fine));
}
