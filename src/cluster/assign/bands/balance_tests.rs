//! The bands' split with one slow worker: a band whose thread is slower (a phone's little
//! core) gets fewer cells in the next frames, until both bands take about as long.

use super::Bands;
use crate::cluster::assign::tests::view_grid;
use crate::cluster::assign::types::Assignment;
use crate::cluster::grid::GridConfig;

/// Per-cell time of the band each thread runs: the first thread is three times slower.
const SPEED: [f64; 2] = [3e-9, 1e-9];

#[test]
fn a_slow_worker_gets_less_work_until_both_take_about_as_long() {
    let grid = view_grid(&GridConfig::fixed(16.0));
    let cells = grid.total_cells as usize;
    // The previous frame's lists (the split reads only their length and offsets).
    let previous = Assignment {
        offsets: (0..cells as u32).collect(),
        ..Assignment::default()
    };
    let mut bands = Bands::default();
    bands.split(&grid, 2, &previous);
    let even = bands.bands[0].end_cell;
    let mut spread = f64::INFINITY;
    for _frame in 0..6 {
        // Each band's time as a thread of its speed would measure it.
        for (band, speed) in bands.bands[..bands.active].iter_mut().zip(SPEED) {
            band.seconds = (band.end_cell - band.first_cell) as f64 * speed;
        }
        let times: Vec<f64> = bands.active().iter().map(|b| b.seconds).collect();
        spread = times[0].max(times[1]) / times[0].min(times[1]);
        bands.split(&grid, 2, &previous);
    }
    let slow = bands.bands[0].end_cell - bands.bands[0].first_cell;
    assert!(
        slow < even,
        "the slow band kept {slow} cells of an even {even}"
    );
    // Bands are cut between slices: within one slice of the balance (a slice is about 4 %
    // of this grid's cells).
    let slice = (cells / grid.slice_slabs.len()) as f64;
    let tolerance = 1.0 + 2.0 * slice * SPEED[0] / (cells as f64 * 0.25 * SPEED[0]);
    assert!(
        spread <= tolerance,
        "after six frames the bands' times differ by {spread:.2}x (more than {tolerance:.2}x)"
    );
}

#[test]
fn a_candidate_assigned_in_between_leaves_the_frames_split_and_threads() {
    use crate::cluster::assign::tests::random_lights;
    use crate::cluster::assign::{AssignLimits, Assigner};
    use rand::SeedableRng;

    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let frame_grid = view_grid(&GridConfig::fixed(16.0));
    let candidate_grid = view_grid(&GridConfig::fixed(45.0));
    let lights = random_lights(&mut rand_pcg::Pcg64Mcg::seed_from_u64(5), 300, 20.0);
    let limits = AssignLimits {
        parallel_threshold: 0,
        ..AssignLimits::default()
    };
    pool.install(|| {
        let mut assigner = Assigner::new();
        for _ in 0..3 {
            assigner.assign(&frame_grid, &lights, 80.0, &limits);
        }
        let split = assigner.bands.split_record();
        let (seconds, indices) = (assigner.last_cpu_seconds, assigner.frame_indices);
        assert!(indices > 0);
        let candidate = assigner.assign_candidate(&candidate_grid, &lights, 80.0, &limits);
        assert_ne!(
            candidate.indices.len(),
            indices,
            "the candidate's lists differ"
        );
        assert_eq!(assigner.bands.split_record(), split);
        assert_eq!(
            (assigner.last_cpu_seconds, assigner.frame_indices),
            (seconds, indices)
        );
    });
}

#[test]
fn a_try_of_one_thread_leaves_the_pools_split_for_its_next_assignment() {
    use crate::cluster::assign::keep_pool_split;
    use crate::cluster::assign::tests::random_lights;
    use crate::cluster::assign::{AssignLimits, Assigner};
    use rand::SeedableRng;

    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let grid = view_grid(&GridConfig::fixed(16.0));
    let lights = random_lights(&mut rand_pcg::Pcg64Mcg::seed_from_u64(7), 300, 20.0);
    let on_pool = AssignLimits {
        parallel_threshold: 0,
        ..AssignLimits::default()
    };
    pool.install(|| {
        let mut assigner = Assigner::new();
        for _ in 0..3 {
            assigner.assign(&grid, &lights, 80.0, &on_pool);
        }
        let split = assigner.bands.split_record();
        assert_eq!(split.active, super::bands_for(2));
        let (bands, kept) = (&mut assigner.bands, &mut assigner.pool_split);
        keep_pool_split(bands, kept, 2, 1);
        let mut out = Assignment::default();
        let most_runs = super::super::most_runs_a_light(&grid);
        let tally = crate::cluster::assign::types::Tally::new(usize::MAX, most_runs);
        bands.assign(&grid, &lights, 80.0, &mut out, 1, &tally);
        assert_eq!(bands.active, 1, "one thread, one band");
        keep_pool_split(bands, kept, 1, 2);
        assert_eq!(bands.split_record(), split, "the pool's split is back");
        assert!(kept.is_none());
    });
}

#[test]
fn one_thread_and_the_pool_by_turns_give_every_frame_its_own_lists() {
    use crate::cluster::assign::tests::{assert_same_lists, random_lights};
    use crate::cluster::assign::thread_choice::ThreadChoice;
    use crate::cluster::assign::{assign, AssignLimits, Assigner, PARALLEL_INDICES};
    use rand::SeedableRng;

    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    // Fine enough that every frame lists more than PARALLEL_INDICES, so the rules ask for the
    // pool (the case the choice decides) whatever the assignments' times.
    let grid = view_grid(&GridConfig::fixed(8.0));
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(11);
    let limits = AssignLimits::default();
    // One thread on frames 3, 4, 7 (a switch, a stay, a single try), else the pool.
    let one = [
        false, false, false, true, true, false, false, true, false, false,
    ];
    pool.install(|| {
        let mut assigner = Assigner::new();
        for (frame, &one) in one.iter().enumerate() {
            let lights = random_lights(&mut rng, 400, 20.0);
            assigner.choice = ThreadChoice::kept(one);
            let got = assigner.assign(&grid, &lights, 80.0, &limits);
            let fresh = assign(&grid, &lights, 80.0, &limits);
            if frame > 0 {
                assert!(
                    fresh.indices.len() >= PARALLEL_INDICES,
                    "a frame the rules give the pool"
                );
                assert_eq!(got.stats.threads, if one { 1 } else { 2 }, "frame {frame}");
            }
            assert_same_lists(got, &fresh, &format!("frame {frame}"));
        }
    });
}

#[test]
fn switching_between_one_thread_and_the_pool_grows_no_buffer_after_each_has_run() {
    use crate::cluster::assign::tests::random_lights;
    use crate::cluster::assign::thread_choice::ThreadChoice;
    use crate::cluster::assign::{AssignLimits, Assigner};
    use rand::SeedableRng;

    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let grid = view_grid(&GridConfig::fixed(8.0));
    let lights = random_lights(&mut rand_pcg::Pcg64Mcg::seed_from_u64(13), 400, 20.0);
    let limits = AssignLimits::default();
    // Every buffer's capacity: the bands' (those a split leaves out too), the numbers, the
    // output's per-cell arrays and visible lights (the index list's length is the same in
    // either mode).
    let capacities = |a: &Assigner| -> Vec<usize> {
        let bands = a.bands.bands.iter().flat_map(|b| {
            [
                b.runs.capacity(),
                b.lights.capacity(),
                b.ids.capacity(),
                b.cursors.capacity(),
            ]
        });
        let out = &a.out;
        bands
            .chain([a.bands.numbers.capacity(), out.visible.capacity()])
            .chain([out.offsets.capacity(), out.counts.capacity()])
            .collect()
    };
    pool.install(|| {
        let mut assigner = Assigner::new();
        let mut run = |modes: &[bool]| {
            for &one in modes {
                assigner.choice = ThreadChoice::kept(one);
                assigner.assign(&grid, &lights, 80.0, &limits);
            }
            capacities(&assigner)
        };
        let warm = run(&[false, false, true, true, false]);
        let after = run(&[
            true, false, false, true, false, true, true, false, true, false,
        ]);
        assert_eq!(warm, after, "a buffer grew after the warm-up");
    });
}
