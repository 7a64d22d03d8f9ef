//! Phases 1 to 3 of several bands on the pool's workers, each band of a phase taken by the
//! next worker that is free (see [`assign_shared`]).

use super::{number_listed, Band, CellsOut, MAX_BANDS};
use crate::cluster::assign::index_list::EntriesMut;
use crate::cluster::assign::types::{Assignment, Tally, Totals};
use crate::cluster::grid::ClusterGrid;
use crate::cluster::view_light::GpuLight;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard};

/// Phases 1 to 3 of `bands` (two or more, at most [`MAX_BANDS`]) into `out`, on up to
/// `workers` threads of the current rayon pool.
///
/// Each worker takes the next band of phase 1 that no one has taken, until none is left;
/// whoever finishes the last one does phase 2; then each takes the next band of phase 3. So a
/// worker that wakes late (an idle core can take milliseconds to wake: a phone's sleeping
/// little core, or a virtual machine's) still takes whatever bands are left, and a worker
/// that waits for phase 2 (at most one band's time) spins instead of falling asleep, so it
/// is awake for phase 3. Which worker takes which band changes nothing in the lists: each
/// band writes its own part of every array.
pub(super) fn assign_shared(
    bands: &mut [Band],
    workers: usize,
    (grid, lights, camera_far, tally): (&ClusterGrid, &[GpuLight], f64, &Tally),
    out: &mut Assignment,
    numbers: &mut Vec<u32>,
) {
    let n = bands.len();
    assert!((2..=MAX_BANDS).contains(&n), "{n} bands");
    let mut each = bands.iter_mut();
    let found: [Mutex<Option<&mut Band>>; MAX_BANDS] =
        std::array::from_fn(|_| Mutex::new(each.next()));
    let scatters: [Mutex<Option<Scatter>>; MAX_BANDS] = std::array::from_fn(|_| Mutex::new(None));
    let between = Mutex::new(Some((out, numbers)));
    let (find_next, find_done) = (AtomicUsize::new(0), AtomicUsize::new(0));
    let (scatter_open, scatter_next) = (AtomicBool::new(false), AtomicUsize::new(0));
    let abandoned = AtomicBool::new(false);
    let work = || {
        // A worker that panics lets the others stop waiting (the panic then reaches the
        // caller through `rayon::join`), rather than leave them spinning for a phase that
        // never opens.
        let _panicking = AbandonOnPanic(&abandoned);
        while let Some(i) = claim(&find_next, n) {
            #[cfg(test)]
            tests::panic_if_asked(lights);
            let mut band = lock(&found[i]);
            band.as_mut()
                .expect("phase 1's band")
                .find(grid, lights, camera_far, tally);
            drop(band);
            if find_done.fetch_add(1, Ordering::AcqRel) + 1 == n {
                let (out, numbers) = lock(&between).take().expect("phase 2 runs once");
                let taken = found.each_ref().map(|band| lock(band).take());
                between_phases(taken, (lights.len(), tally), out, numbers, &scatters);
                scatter_open.store(true, Ordering::Release);
            }
        }
        if !wait_until(&scatter_open, &abandoned) {
            return;
        }
        while let Some(i) = claim(&scatter_next, n) {
            // None where phase 2 listed nothing (too many references).
            if let Some(scatter) = lock(&scatters[i]).take() {
                scatter.run();
            }
        }
    };
    on_workers(workers.min(n), &work);
}

/// Runs `work` once on each of up to `count` workers of the pool: this thread's first, the
/// others' as the pool's idle workers steal them (a worker that comes too late finds nothing
/// left to take; a copy no one stole runs here last and finds the same). By `rayon::join`,
/// whose jobs live on the stack: a scope's spawned jobs are allocated, one per frame.
fn on_workers(count: usize, work: &(dyn Fn() + Sync)) {
    if count <= 1 {
        work();
    } else {
        let others = count / 2;
        rayon::join(
            || on_workers(count - others, work),
            || on_workers(others, work),
        );
    }
}

/// Phase 2 (the visible lights, numbered; where each band's part of the list starts) and
/// phase 3's jobs: each band's parts of the per-cell arrays and of the list, in `scatters`.
fn between_phases<'a>(
    mut taken: [Option<&'a mut Band>; MAX_BANDS],
    (lights, tally): (usize, &Tally),
    out: &'a mut Assignment,
    numbers: &'a mut Vec<u32>,
    scatters: &[Mutex<Option<Scatter<'a>>>; MAX_BANDS],
) {
    let listed = taken.iter().flatten().map(|band| &**band);
    number_listed(listed, lights, &mut out.visible, numbers);
    let mut indices = 0;
    for band in taken.iter_mut().flatten() {
        band.base = indices;
        indices += band.indices;
    }
    let Some(mut list) = tally.list(&mut out.indices, indices, out.visible.len()) else {
        // Not listed: phase 3 finds no band to scatter.
        out.unlisted = Some(indices);
        (taken.iter_mut().flatten()).for_each(|b| b.totals = Totals::default());
        return;
    };
    // The bands cover the grid, from cell 0 to the last band's end.
    let cells = taken
        .iter()
        .flatten()
        .last()
        .map_or(0, |band| band.end_cell);
    let mut rest = CellsOut::sized(&mut out.counts, &mut out.offsets, cells);
    let numbers: &[u32] = numbers;
    for (band, slot) in taken.into_iter().flatten().zip(scatters) {
        let (cells, after) = rest.split_at(band.end_cell - band.first_cell);
        let (part, tail) = list.split_at(band.indices);
        *lock(slot) = Some(Scatter {
            band,
            cells,
            list: part,
            numbers,
        });
        (rest, list) = (after, tail);
    }
}

/// One band's phase 3 and where it writes.
struct Scatter<'a> {
    band: &'a mut Band,
    cells: CellsOut<'a>,
    list: EntriesMut<'a>,
    numbers: &'a [u32],
}

impl Scatter<'_> {
    /// The band's phase 3, with the lights' numbers from phase 2.
    fn run(self) {
        let numbers = Some(self.numbers);
        self.band.count_and_scatter(numbers, self.cells, self.list);
    }
}

/// The next of `n` jobs no one has taken, if any.
fn claim(next: &AtomicUsize, n: usize) -> Option<usize> {
    let i = next.fetch_add(1, Ordering::AcqRel);
    (i < n).then_some(i)
}

/// Waits for `flag` (true) or `abandoned` (false): spinning a while (the wait is at most one
/// band's phase 1), then giving the core to others in turn (on a busy core the band's worker
/// may need it).
fn wait_until(flag: &AtomicBool, abandoned: &AtomicBool) -> bool {
    let mut spins = 0u32;
    while !flag.load(Ordering::Acquire) {
        if abandoned.load(Ordering::Acquire) {
            return false;
        }
        if spins < 1 << 10 {
            spins += 1;
            std::hint::spin_loop();
        } else {
            std::thread::yield_now();
        }
    }
    true
}

/// Sets its flag when dropped by a panic.
struct AbandonOnPanic<'a>(&'a AtomicBool);

impl Drop for AbandonOnPanic<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.store(true, Ordering::Release);
        }
    }
}

/// `mutex` locked; a lock a panicking worker left poisoned is taken as it is (the panic
/// reaches the caller through rayon's scope).
fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    mutex
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

#[cfg(test)]
mod tests {
    use crate::cluster::assign::tests::{assert_same_lists, random_lights, view_grid};
    use crate::cluster::assign::{AssignLimits, Assigner};
    use crate::cluster::grid::GridConfig;
    use crate::cluster::view_light::GpuLight;
    use rand::SeedableRng;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::mpsc;
    use std::time::Duration;

    /// The address of the lights whose phase 1 panics (one test's own, so the tests that run
    /// beside it are not touched).
    static PANIC_ON: AtomicUsize = AtomicUsize::new(0);

    /// Panics when asked to for `lights`: the first band claimed is never found, so the
    /// other workers find theirs and wait for phase 3.
    pub(super) fn panic_if_asked(lights: &[GpuLight]) {
        let asked = PANIC_ON.load(Ordering::Acquire);
        if asked != 0 && asked == lights.as_ptr() as usize {
            PANIC_ON.store(0, Ordering::Release);
            panic!("asked to panic in phase 1");
        }
    }

    /// Keeps one of `pool`'s workers busy until the returned sender sends (or is dropped);
    /// returns once that worker is held.
    fn hold_one_worker(pool: &rayon::ThreadPool) -> mpsc::Sender<()> {
        let (go, wait) = mpsc::channel::<()>();
        let (held, is_held) = mpsc::channel::<()>();
        pool.spawn(move || {
            held.send(()).unwrap();
            let _ = wait.recv();
        });
        is_held.recv().unwrap();
        go
    }

    /// A worker that panics in phase 1 makes the assignment panic, not hang: the others stop
    /// waiting for phase 3.
    #[test]
    fn a_worker_that_panics_in_phase_1_leaves_no_one_waiting() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(4)
            .build()
            .unwrap();
        let grid = view_grid(&GridConfig::fixed(8.0));
        let lights = random_lights(&mut rand_pcg::Pcg64Mcg::seed_from_u64(19), 400, 20.0);
        let on_pool = AssignLimits {
            parallel_threshold: 0,
            ..AssignLimits::default()
        };
        let (done, result) = mpsc::channel();
        // On its own thread, so that a hang fails the test instead of stalling the suite.
        std::thread::spawn(move || {
            let mut assigner = Assigner::new();
            let threads = pool.install(|| {
                assigner
                    .assign(&grid, &lights, 80.0, &on_pool)
                    .stats
                    .threads
            });
            assert!(threads > 1, "the pool's assignment");
            PANIC_ON.store(lights.as_ptr() as usize, Ordering::Release);
            let panicked = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                pool.install(|| {
                    assigner
                        .assign(&grid, &lights, 80.0, &on_pool)
                        .stats
                        .threads
                })
            }))
            .is_err();
            let _ = done.send(panicked);
        });
        let panicked = result
            .recv_timeout(Duration::from_secs(60))
            .expect("the assignment returns (no worker left waiting)");
        assert!(panicked, "the panic reaches the caller");
    }

    /// A caller that is one of the pool's threads (`use_current_thread`, as the command line
    /// builds rayon's global pool) starts the assignment itself: with the pool's other worker
    /// held until the assignment has returned, it still returns, with one thread's lists.
    /// (From outside the pool the work would wait in rayon's queue for a worker to take it.)
    #[test]
    fn a_caller_in_the_pool_works_without_waiting_for_another_worker() {
        let (done, result) = mpsc::channel();
        // On its own thread (it becomes one of the pool's), so a hang fails the test.
        std::thread::spawn(move || {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(2)
                .use_current_thread()
                .build()
                .unwrap();
            let grid = view_grid(&GridConfig::fixed(8.0));
            let lights = random_lights(&mut rand_pcg::Pcg64Mcg::seed_from_u64(23), 400, 20.0);
            let limits = |parallel_threshold| AssignLimits {
                parallel_threshold,
                ..AssignLimits::default()
            };
            let expected = Assigner::new()
                .assign(&grid, &lights, 80.0, &limits(usize::MAX))
                .clone();
            let go = hold_one_worker(&pool);
            let mut assigner = Assigner::new();
            let got = pool.install(|| assigner.assign(&grid, &lights, 80.0, &limits(0)).clone());
            go.send(()).unwrap();
            let _ = done.send((got, expected));
        });
        let (got, expected) = result
            .recv_timeout(Duration::from_secs(60))
            .expect("the assignment returns while the other worker is held");
        assert_eq!(got.stats.threads, 2, "the pool's assignment");
        assert_same_lists(&got, &expected, "a caller in the pool");
    }

    /// With the second of two workers held elsewhere and let go at some moment of the
    /// assignment (before it, during it, after it), each frame lists what one thread lists:
    /// the first worker takes every band the second has not, and a copy of the work no one
    /// stole finds nothing left.
    #[test]
    fn a_worker_that_comes_at_any_moment_takes_what_is_left_and_the_lists_stay() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let grid = view_grid(&GridConfig::fixed(8.0));
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(17);
        let on_pool = AssignLimits {
            parallel_threshold: 0,
            ..AssignLimits::default()
        };
        let one_thread = AssignLimits {
            parallel_threshold: usize::MAX,
            ..AssignLimits::default()
        };
        let mut assigner = Assigner::new();
        let mut alone = Assigner::new();
        for (frame, late_us) in [0, 200, 500, 1000, 2000, 5000, 100_000]
            .into_iter()
            .enumerate()
        {
            let lights = random_lights(&mut rng, 400, 20.0);
            let expected = alone.assign(&grid, &lights, 80.0, &one_thread).clone();
            // Holds one worker until the timer lets it go; the other runs the assignment.
            let go = hold_one_worker(&pool);
            let timer = std::thread::spawn(move || {
                std::thread::sleep(Duration::from_micros(late_us));
                let _ = go.send(());
            });
            let got = pool.install(|| assigner.assign(&grid, &lights, 80.0, &on_pool).clone());
            timer.join().unwrap();
            assert_eq!(got.stats.threads, 2, "frame {frame}: the pool's assignment");
            assert_same_lists(&got, &expected, &format!("frame {frame}"));
        }
    }
}
