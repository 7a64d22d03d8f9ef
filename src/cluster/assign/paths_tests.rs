//! The assignment's paths against each other: one thread, bands of slices and chunks of
//! lights in pools of several sizes, reused buffers against fresh ones, 16- and 32-bit index
//! lists, and the figures each reports (the lists themselves are checked against brute force
//! in `tests.rs`).

use glam::{DVec3, Vec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

use super::tests::{assert_same_lists, cases, cell_lights, random_lights, view_grid};
use super::{
    assign, threads_for, AssignLimits, AssignStats, Assignment, PARALLEL_INDICES,
    PARALLEL_MIN_LIGHTS, PARALLEL_SECONDS,
};
use crate::cluster::grid::{ClusterGrid, GridConfig, GridProjection};
use crate::cluster::view_light::GpuLight;
use crate::scene::Light;

#[test]
fn parallel_and_sequential_assignment_agree() {
    let mut rng = Pcg64Mcg::seed_from_u64(3);
    let grid = view_grid(&GridConfig::default());
    let lights = random_lights(&mut rng, 5000, 40.0);
    let seq = assign(
        &grid,
        &lights,
        80.0,
        &AssignLimits {
            parallel_threshold: usize::MAX,
            ..Default::default()
        },
    );
    let par = assign(
        &grid,
        &lights,
        80.0,
        &AssignLimits {
            parallel_threshold: 1,
            ..Default::default()
        },
    );
    assert_same_lists(&par, &seq, "parallel against sequential");
    // The same figures, but the threads they ran on.
    assert_eq!(
        seq.stats,
        AssignStats {
            threads: 1,
            ..par.stats
        }
    );
    assert_eq!(seq.stats.threads, 1);
    assert_eq!(
        par.stats.threads,
        rayon::current_num_threads().clamp(1, 8),
        "the parallel path reports its threads"
    );
    check_stats(&seq, None);
    // Capped, on both paths: the figures describe the lists after the cap, the largest count
    // the lists before it.
    for parallel_threshold in [usize::MAX, 1] {
        let limits = AssignLimits {
            cell_cap: 3,
            parallel_threshold,
            ..Default::default()
        };
        let capped = assign(&grid, &lights, 80.0, &limits);
        assert!(capped.stats.overflowed_lights > 0);
        // The runs are what the lights were found to touch, before the cap.
        assert_eq!(capped.stats.runs, seq.stats.runs);
        check_stats(&capped, Some(seq.stats.max_lights_per_cluster));
    }
}

/// The figures of an assignment against counts taken from its lists here; `uncapped_max` is
/// the largest count before a cap (`None`: no cap applied).
fn check_stats(a: &Assignment, uncapped_max: Option<u32>) {
    let nonempty = a.counts.iter().filter(|&&n| n > 0).count() as u32;
    let max = a.counts.iter().copied().max().unwrap();
    assert!(nonempty > 0);
    assert_eq!(a.stats.nonempty_clusters, nonempty);
    assert_eq!(a.stats.max_lights_per_cluster, uncapped_max.unwrap_or(max));
    assert_eq!(a.stats.indices, a.indices.len());
    assert_eq!(a.stats.clusters as usize, a.counts.len());
    assert_eq!(a.stats.visible_lights, a.visible.len());
    let avg = a.indices.len() as f64 / nonempty as f64;
    assert!((a.stats.avg_lights_per_nonempty - avg).abs() < 1e-12);
    // Every visible light has a run, and every run at least one cell (before any cap).
    assert!(a.stats.runs >= a.visible.len(), "{:?}", a.stats);
    if uncapped_max.is_none() {
        assert!(a.stats.runs <= a.indices.len(), "{:?}", a.stats);
    }
}

/// Frames of one assigner over the cases, each against a fresh assigner's lists: grids of
/// `sizes`, `counts` lights, on the pool or one thread, capped or not, in turn. `after` runs
/// after each frame with the frame's number, the assigner, the fresh lists and a name.
fn frames_against_fresh(
    seed: u64,
    frames: usize,
    sizes: &[(u32, u32)],
    counts: &[usize],
    mut after: impl FnMut(usize, &mut super::Assigner, &Assignment, &str),
) {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut assigner = super::Assigner::new();
    let cases = cases();
    for (frame, case) in cases.iter().cycle().take(frames).enumerate() {
        let (w, h) = sizes[frame / 2 % sizes.len()];
        let grid = ClusterGrid::new(w, h, case.projection, case.near, case.far, &case.config);
        let n = counts[frame % counts.len()];
        let lights = random_lights(&mut rng, n, case.far.min(200.0) * 0.5);
        let limits = AssignLimits {
            cell_cap: if frame % 3 == 0 { 40 } else { u32::MAX },
            parallel_threshold: if frame % 2 == 0 { 1 } else { usize::MAX },
            ..Default::default()
        };
        let fresh = assign(&grid, &lights, case.far, &limits);
        let what = format!("{} frame {frame}, {n} lights", case.name);
        let reused = assigner.assign(&grid, &lights, case.far, &limits);
        assert_same_lists(reused, &fresh, &what);
        assert_eq!(fresh.stats, reused.stats, "{what}");
        after(frame, &mut assigner, &fresh, &what);
    }
}

/// One assigner over frames of different sizes, grids and light sets gives what fresh buffers
/// give (nothing stale survives from an earlier frame).
#[test]
fn reused_buffers_match_fresh_ones() {
    frames_against_fresh(
        11,
        12,
        &[(320, 180)],
        &[5000, 0, 700, 9000],
        |_, _, _, _| {},
    );
}

/// Buffers given back between frames (`Assigner::fit_buffers`, as after a burst of lights)
/// change no list: the last result stays (or, not kept, is empty), and the next assignment on
/// any path (one thread, bands, chunks of lights on a grid of few cells) matches a fresh
/// assigner's.
#[test]
fn fitted_buffers_match_fresh_ones() {
    let sizes = [(320, 180), (32, 18)];
    frames_against_fresh(
        12,
        16,
        &sizes,
        &[9000, 40, 0, 3000, 700],
        |frame, a, fresh, what| {
            let keep = frame % 3 != 1;
            a.fit_buffers(keep);
            let last = a.assignment();
            if keep {
                assert_same_lists(last, fresh, what);
            } else {
                assert!(last.visible.is_empty() && last.counts.is_empty(), "{what}");
            }
        },
    );
}

/// Which assignments take the pool: many lights, or a previous assignment of the same
/// assigner that listed many indices or took long (counted in CPU time, so a parallel one that
/// became fast stays parallel; a thread more per `PARALLEL_SECONDS` of it); never with
/// `parallel_threshold: usize::MAX`, at most 8 threads.
#[test]
fn heavy_assignments_take_the_pool_and_light_ones_stay_on_the_calling_thread() {
    let limits = AssignLimits::default();
    let lights = limits.parallel_threshold;
    assert_eq!(threads_for(lights, 0, 0.0, &limits, 4), 4);
    assert_eq!(threads_for(lights - 1, 0, 0.0, &limits, 4), 1);
    assert_eq!(threads_for(10, PARALLEL_INDICES, 0.0, &limits, 4), 4);
    assert_eq!(threads_for(10, PARALLEL_INDICES - 1, 0.0, &limits, 4), 1);
    // By the previous assignment's CPU time: a 1 ms assignment on one thread takes the pool,
    // the same work split over four (280 µs of CPU time in 70 µs) stays on three or four.
    let seconds = PARALLEL_SECONDS;
    assert_eq!(threads_for(1024, 0, 1e-3, &limits, 4), 4);
    assert_eq!(threads_for(1024, 0, 100.0 * seconds, &limits, 64), 8);
    assert!(threads_for(1024, 0, 4.0 * 70e-6, &limits, 4) >= 3);
    // Two threads from one such time, a third from two; under one, the calling thread.
    assert_eq!(threads_for(1024, 0, seconds, &limits, 4), 2);
    assert_eq!(threads_for(1024, 0, 1.9 * seconds, &limits, 4), 2);
    assert_eq!(threads_for(1024, 0, 2.0 * seconds, &limits, 4), 3);
    assert_eq!(threads_for(1024, 0, 2.0 * seconds, &limits, 2), 2);
    assert_eq!(threads_for(1024, 0, 2.0 * seconds, &limits, 1), 1);
    assert_eq!(threads_for(1024, 0, seconds * 0.9, &limits, 4), 1);
    assert_eq!(threads_for(1024, 0, f64::INFINITY, &limits, 4), 4);
    // Few lights that took long did so on a slow core, not for their work.
    assert_eq!(threads_for(PARALLEL_MIN_LIGHTS - 1, 0, 1.0, &limits, 4), 1);
    assert_eq!(threads_for(PARALLEL_MIN_LIGHTS, 0, 1.0, &limits, 4), 4);
    let never = AssignLimits {
        parallel_threshold: usize::MAX,
        ..limits
    };
    assert_eq!(threads_for(1 << 20, PARALLEL_INDICES, 1.0, &never, 4), 1);
    assert_eq!(threads_for(1 << 20, 0, 0.0, &limits, 64), 8);
    assert_eq!(threads_for(1 << 20, 0, 0.0, &limits, 1), 1);
}

/// An assigner measures each assignment's CPU time and takes the pool on the next frame when
/// it passed [`PARALLEL_SECONDS`] (below the light and index thresholds), reporting it in its
/// figures; the lists stay the same.
#[test]
fn a_slow_assignment_takes_the_pool_on_the_next_frame() {
    let mut rng = Pcg64Mcg::seed_from_u64(5);
    let grid = view_grid(&GridConfig::default());
    let lights = random_lights(&mut rng, 1024, 30.0);
    let limits = AssignLimits::default();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("a thread pool");
    let mut assigner = super::Assigner::new();
    let frame = |assigner: &mut super::Assigner| {
        pool.install(|| assigner.assign(&grid, &lights, 80.0, &limits).clone())
    };
    let first = frame(&mut assigner);
    assert!(first.indices.len() < PARALLEL_INDICES && lights.len() < limits.parallel_threshold);
    assert_eq!(first.stats.threads, 1, "the first frame has no measure yet");
    assert!(assigner.last_cpu_seconds > 0.0, "the assignment was timed");
    // The measure decides, whatever this machine's speed: set, as a slow frame would leave it.
    assigner.last_cpu_seconds = PARALLEL_SECONDS;
    let slow_before = frame(&mut assigner);
    assert_eq!(slow_before.stats.threads, 2);
    assigner.last_cpu_seconds = PARALLEL_SECONDS * 0.5;
    let fast_before = frame(&mut assigner);
    assert_eq!(fast_before.stats.threads, 1);
    for other in [&slow_before, &fast_before] {
        assert_eq!(first.indices, other.indices);
        assert_eq!(first.offsets, other.offsets);
        assert_eq!(first.visible, other.visible);
    }
}

#[test]
fn zero_lights_do_no_work() {
    let t = (30f64).to_radians().tan();
    let grid = ClusterGrid::new(
        64,
        64,
        GridProjection::Perspective { tan_x: t, tan_y: t },
        0.1,
        10.0,
        &GridConfig::default(),
    );
    let a = assign(&grid, &[], 10.0, &AssignLimits::default());
    assert!(a.indices.is_empty() && a.visible.is_empty());
    assert!(a.counts.iter().all(|&n| n == 0));
}

/// Many lights on a grid with fewer cells than threads' worth of blocks: the parallel fill must
/// not hand out empty or out-of-range cell blocks (a panic seen from the viewer).
#[test]
fn parallel_fill_on_a_tiny_grid() {
    let t = (30f64).to_radians().tan();
    let grid = ClusterGrid::new(
        32,
        24,
        GridProjection::Perspective { tan_x: t, tan_y: t },
        0.1,
        10.0,
        &GridConfig::default(),
    );
    assert!(grid.total_cells < 64);
    let mut rng = Pcg64Mcg::seed_from_u64(9);
    let lights = random_lights(&mut rng, 20_000, 5.0);
    let par = assign(
        &grid,
        &lights,
        10.0,
        &AssignLimits {
            parallel_threshold: 1,
            ..Default::default()
        },
    );
    let seq = assign(
        &grid,
        &lights,
        10.0,
        &AssignLimits {
            parallel_threshold: usize::MAX,
            ..Default::default()
        },
    );
    assert_eq!(par.indices, seq.indices);
    assert_eq!(par.offsets, seq.offsets);
}

/// The parallel paths (bands of slices, one per thread of the pool, or chunks of lights) give
/// what one band gives, for pools of 2 to 8 threads, and when the bands are balanced by an
/// earlier assignment to the same grid (measured times) or to another (cells).
#[test]
fn any_number_of_bands_gives_what_one_band_gives() {
    let mut rng = Pcg64Mcg::seed_from_u64(21);
    let sequential = AssignLimits {
        parallel_threshold: usize::MAX,
        cell_cap: 24,
        ..Default::default()
    };
    let parallel = AssignLimits {
        parallel_threshold: 1,
        ..sequential
    };
    for threads in [2, 3, 5, 8] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool");
        let mut assigner = super::Assigner::new();
        for case in cases() {
            let grid = ClusterGrid::new(96, 54, case.projection, case.near, case.far, &case.config);
            // Fewer lights than cells: bands; more: chunks of lights (see `Assigner::assign`).
            // Each count twice: the second split follows the first one's measured times.
            let counts = [grid.total_cells as usize / 4, grid.total_cells as usize * 2];
            let mut listed = 0;
            for count in counts.into_iter().flat_map(|n| [n, n]) {
                let lights = random_lights(&mut rng, count, case.far.min(200.0) * 0.5);
                let one = assign(&grid, &lights, case.far, &sequential);
                let bands =
                    pool.install(|| assigner.assign(&grid, &lights, case.far, &parallel).clone());
                let what = format!("{threads} threads, {}, {count} lights", case.name);
                assert_same_lists(&bands, &one, &what);
                assert_eq!(
                    one.stats,
                    AssignStats {
                        threads: 1,
                        ..bands.stats
                    },
                    "{what}"
                );
                assert_eq!(bands.stats.threads, threads, "{what}");
                listed += one.stats.indices;
            }
            assert!(listed > 0, "{}", case.name);
        }
    }
}

/// Chunks of lights when lights are few for the threads (49 lights on 8 threads make 7 chunks
/// of 7): after a frame with more lights, no chunk keeps that frame's runs.
#[test]
fn fewer_chunks_than_threads_keep_nothing_stale() {
    let t = (30f64).to_radians().tan();
    let grid = ClusterGrid::new(
        32,
        16,
        GridProjection::Perspective { tan_x: t, tan_y: t },
        0.1,
        10.0,
        &GridConfig::tiles(16.0),
    );
    assert!(
        grid.total_cells < 49,
        "{} cells: not the chunk path",
        grid.total_cells
    );
    let mut rng = Pcg64Mcg::seed_from_u64(5);
    let parallel = AssignLimits {
        parallel_threshold: 1,
        ..Default::default()
    };
    let sequential = AssignLimits {
        parallel_threshold: usize::MAX,
        ..Default::default()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(8)
        .build()
        .expect("a thread pool");
    let mut assigner = super::Assigner::new();
    for count in [400, 49, 9, 400] {
        let lights = random_lights(&mut rng, count, 5.0);
        let one = assign(&grid, &lights, 10.0, &sequential);
        let chunks = pool.install(|| assigner.assign(&grid, &lights, 10.0, &parallel).clone());
        assert_eq!(one.visible, chunks.visible, "{count} lights");
        assert_eq!(one.counts, chunks.counts, "{count} lights");
        assert_eq!(one.indices, chunks.indices, "{count} lights");
    }
}

/// Past 65 536 visible lights the list is 32-bit, on both parallel paths and one thread,
/// with and without the overflow policy trimming it, and every cell lists exactly the lights
/// whose runs cover it, ascending; at most 65 536 it is 16-bit with the same lists.
#[test]
fn past_65536_visible_lights_the_list_is_32_bit_and_the_same() {
    let t = (30f64).to_radians().tan();
    let projection = GridProjection::test_view();
    let mut rng = Pcg64Mcg::seed_from_u64(65_537);
    // Small lights spread over the view, nearly all visible.
    let lights: Vec<GpuLight> = (0..70_000)
        .map(|_| {
            let d = rng.random_range(1.0..40.0);
            let p = DVec3::new(
                rng.random_range(-0.9..0.9) * t * 16.0 / 9.0 * d,
                rng.random_range(-0.9..0.9) * t * d,
                -d,
            );
            let light = Light::point(p, rng.random_range(0.05..0.4) as f32, Vec3::ONE, 1.0);
            GpuLight::from_light(&light, &glam::DMat4::IDENTITY)
        })
        .collect();
    // A grid with more cells than lights (bands) and one with fewer (chunks of lights).
    for footprint in [8.0, 64.0] {
        let config = GridConfig::fixed(footprint);
        let grid = ClusterGrid::new(640, 360, projection, 0.1, 50.0, &config);
        let mut reference = vec![Vec::new(); grid.total_cells as usize];
        for (i, light) in lights.iter().enumerate() {
            super::cells::for_each_run(&grid, light, 50.0, &mut |start, len| {
                for cell in start..start + len {
                    reference[cell as usize].push(i as u32);
                }
            });
        }
        for (threshold, cap) in [(1, u32::MAX), (usize::MAX, u32::MAX), (1, 3)] {
            let limits = AssignLimits {
                parallel_threshold: threshold,
                cell_cap: cap,
                max_indices: usize::MAX,
                ..AssignLimits::default()
            };
            let a = assign(&grid, &lights, 50.0, &limits);
            let what = format!(
                "{footprint} px, threshold {threshold}, cap {cap}, {:?}",
                a.stats
            );
            assert!(a.visible.len() > 65_536, "{what}: {}", a.visible.len());
            assert!(
                a.indices.as_u32().is_some() && a.indices.as_u16().is_none(),
                "{what}"
            );
            for (cell, listed) in reference.iter().enumerate() {
                let got = cell_lights(&a, cell as u32);
                if cap == u32::MAX {
                    assert_eq!(&got, listed, "{what}: cell {cell}");
                } else {
                    assert_eq!(got.len(), listed.len().min(cap as usize), "{what}");
                    assert!(got.windows(2).all(|w| w[0] < w[1]), "{what}: {got:?}");
                    assert!(got.iter().all(|l| listed.contains(l)), "{what}: {got:?}");
                }
            }
        }
        // The same grid with the first 60 000 lights: 16-bit, the same lists.
        let few = &lights[..60_000];
        let limits = AssignLimits {
            cell_cap: u32::MAX,
            max_indices: usize::MAX,
            ..Default::default()
        };
        let a = assign(&grid, few, 50.0, &limits);
        assert!(
            a.indices.as_u16().is_some(),
            "{footprint} px, 60 000 lights"
        );
        for (cell, listed) in reference.iter().enumerate() {
            let expected: Vec<u32> = listed.iter().copied().filter(|&l| l < 60_000).collect();
            assert_eq!(cell_lights(&a, cell as u32), expected, "cell {cell}");
        }
    }
}

#[test]
fn split_cells_never_returns_empty_or_out_of_range_blocks() {
    for (offsets, total, parts) in [
        (vec![0u32; 12], 0usize, 4usize),
        (vec![0, 0, 0, 5], 9, 3),
        (vec![0, 100], 200, 8),
        (vec![], 0, 2),
    ] {
        let blocks = super::chunks::split_cells(&offsets, total, parts);
        let mut next = 0;
        for (a, b) in &blocks {
            assert!(a < b && *b <= offsets.len(), "{blocks:?}");
            assert_eq!(*a, next);
            next = *b;
        }
        assert_eq!(next, offsets.len());
    }
}

#[test]
fn scatter_blocks_of_any_number_give_the_same_lists() {
    use super::bands::FORCED_SCATTER_BLOCKS;
    let mut rng = Pcg64Mcg::seed_from_u64(31);
    let limits = AssignLimits {
        cell_cap: u32::MAX,
        parallel_threshold: usize::MAX,
        ..Default::default()
    };
    for case in cases() {
        let grid = ClusterGrid::new(320, 180, case.projection, case.near, case.far, &case.config);
        let lights = random_lights(&mut rng, 600, case.far.min(200.0) * 0.5);
        FORCED_SCATTER_BLOCKS.with(|b| b.set(Some(1)));
        let whole = assign(&grid, &lights, case.far, &limits);
        assert!(
            whole.indices.len() > 1000,
            "{}: too few indices to cut",
            case.name
        );
        // Block edges cut runs in two (7, 64), or nearly every run (a block a cell).
        for blocks in [2, 7, 64, grid.total_cells as usize] {
            FORCED_SCATTER_BLOCKS.with(|b| b.set(Some(blocks)));
            let cut = assign(&grid, &lights, case.far, &limits);
            assert_eq!(cut.offsets, whole.offsets, "{}, {blocks} blocks", case.name);
            assert_eq!(cut.counts, whole.counts, "{}, {blocks} blocks", case.name);
            assert_eq!(
                cut.indices.to_vec(),
                whole.indices.to_vec(),
                "{}, {blocks}",
                case.name
            );
            // The totals each block adds up (the block count changes how they are summed).
            let stats = |a: &Assignment| {
                let s = &a.stats;
                (
                    s.nonempty_clusters,
                    s.max_lights_per_cluster,
                    s.indices,
                    s.runs,
                )
            };
            assert_eq!(stats(&cut), stats(&whole), "{}, {blocks} blocks", case.name);
            // Two bands, each cut into blocks: the second band's offsets take its base.
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(2)
                .start_handler(move |_| FORCED_SCATTER_BLOCKS.with(|b| b.set(Some(blocks))))
                .build()
                .expect("a pool of two");
            let parallel = AssignLimits {
                parallel_threshold: 0,
                ..limits
            };
            let banded = pool.install(|| assign(&grid, &lights, case.far, &parallel));
            assert_eq!(banded.stats.threads, 2, "{}", case.name);
            assert_eq!(
                banded.offsets, whole.offsets,
                "{}, two bands of {blocks}",
                case.name
            );
            assert_eq!(
                banded.counts, whole.counts,
                "{}, two bands of {blocks}",
                case.name
            );
            assert_eq!(
                banded.indices.to_vec(),
                whole.indices.to_vec(),
                "{}, {blocks}",
                case.name
            );
        }
        FORCED_SCATTER_BLOCKS.with(|b| b.set(None));
    }
}

/// An assignment that enters rayon's pool from one of its workers may run other queued jobs
/// there, which the renderer checks for (a job that made another GL context current): the
/// assigner says so once, and not for one that took the pool from outside it or stayed on one
/// thread.
#[test]
fn an_assignment_says_when_it_entered_the_pool_from_a_worker() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let grid = view_grid(&GridConfig::fixed(8.0));
    let lights = random_lights(&mut Pcg64Mcg::seed_from_u64(23), 400, 20.0);
    let limits = |parallel_threshold| AssignLimits {
        parallel_threshold,
        ..AssignLimits::default()
    };
    let mut assigner = super::Assigner::new();
    let threads = pool.install(|| {
        assigner
            .assign(&grid, &lights, 80.0, &limits(0))
            .stats
            .threads
    });
    assert_eq!(threads, 2);
    assert!(assigner.take_ran_other_jobs(), "in a worker, on the pool");
    assert!(!assigner.take_ran_other_jobs(), "said once");
    pool.install(|| assigner.assign(&grid, &lights, 80.0, &limits(usize::MAX)));
    assert!(!assigner.take_ran_other_jobs(), "in a worker, one thread");
    // From outside any pool (the test's thread), on the global pool.
    assert!(rayon::current_thread_index().is_none());
    assigner.assign(&grid, &lights, 80.0, &limits(0));
    assert!(!assigner.take_ran_other_jobs(), "from outside the pool");
}
