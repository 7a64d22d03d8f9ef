//! One thread or the pool, by measure: where the rules of `threads_for` would wake the pool
//! for an assignment, an [`Assigner`](super::Assigner) keeps it on the calling thread when
//! that is as fast. Waking a worker costs from microseconds to milliseconds with the machine
//! and with what else runs on its cores (a game's own threads, the GL driver's), and a caller
//! outside rayon's pool waits for it (one in the pool starts at once); a worker woken for no
//! gain is a core taken from the caller's work.
//!
//! The choice keeps one mode and now and then tries the other on one assignment. Each mode is
//! judged by the fastest of its last [`WINDOW`] times per unit of work: other work on the
//! cores only ever slows a mode down, so a slow start (a driver compiling shaders on the same
//! cores in a renderer's first frames) or a slow patch is soon forgotten. While the pool is
//! kept, its workers' busy time stands for one thread's, so it is not interrupted by tries
//! (the bands report it; the chunks of lights do not, and are tried). Tries come at growing
//! intervals while they lose ([`FIRST_TRY`] to [`LAST_TRY`] assignments apart), and soon
//! again after a switch.

/// Assignments between the first try of the other mode and the previous one, and after a
/// switch.
const FIRST_TRY: u32 = 2;

/// Most assignments between two tries, reached by doubling while tries lose: so the cost of
/// trying the slower mode falls to at most 1 assignment in this many.
const LAST_TRY: u32 = 32;

/// The pool, which the rules asked for, gives way to one thread only where one thread takes at
/// most this share of the pool's time per unit of work; one thread gives way to the pool where
/// the pool is as fast. Between the two, the kept mode stays: noise does not flip it.
const ONE_THREAD_GAIN: f64 = 0.9;

/// Measurements per mode whose fastest decides.
const WINDOW: usize = 3;

/// Which mode is kept, each mode's last measured seconds per unit of work
/// ([`assign_work`](super::assign_work)), and when the other is tried next.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct ThreadChoice {
    /// One thread (else the pool).
    one: bool,
    /// One thread's measurements (or, while the pool is kept, its estimates), then the
    /// pool's.
    seconds_per_unit: [Window; 2],
    /// Whether the pool's last assignment estimated one thread's time (so the pool needs no
    /// tries of one thread).
    estimated: bool,
    /// Assignments since the last try, and between tries now.
    since_try: u32,
    interval: u32,
}

impl Default for ThreadChoice {
    /// The pool kept (the rules asked for it).
    fn default() -> Self {
        ThreadChoice {
            one: false,
            seconds_per_unit: [Window::default(); 2],
            estimated: false,
            since_try: 0,
            interval: FIRST_TRY,
        }
    }
}

impl ThreadChoice {
    /// A choice that keeps one thread (`one`) or the pool and tries nothing (for the tests
    /// that set each assignment's mode).
    #[cfg(test)]
    pub(super) fn kept(one: bool) -> ThreadChoice {
        ThreadChoice {
            one,
            interval: u32::MAX,
            ..ThreadChoice::default()
        }
    }

    /// Threads for an assignment that the rules would give the pool's `pool` (two or more):
    /// the kept mode's, or, when a try is due and the kept mode has been measured, the other's
    /// (never one thread while the pool's own assignments estimate it).
    pub(super) fn threads(&mut self, pool: usize) -> usize {
        self.since_try = self.since_try.saturating_add(1);
        let kept_measured = self.seconds_per_unit[usize::from(!self.one)].len > 0;
        let try_other =
            self.since_try >= self.interval && kept_measured && (self.one || !self.estimated);
        if try_other {
            self.since_try = 0;
        }
        if self.one != try_other {
            1
        } else {
            pool
        }
    }

    /// Takes in an assignment on `threads` threads that took `seconds` for `work` units, and
    /// keeps the mode whose best recent time is best (with [`ONE_THREAD_GAIN`]'s margin).
    /// `busy` is what the pool's workers spent working, where it is known (the bands' phases
    /// 1 and 3): about one thread's time (more where each band sets up the same lights, less
    /// by what runs outside the bands), which stands for it while the pool is kept.
    pub(super) fn measured(&mut self, threads: usize, seconds: f64, work: f64, busy: Option<f64>) {
        if !(work > 0.0 && seconds.is_finite() && seconds > 0.0) {
            return;
        }
        let one = threads == 1;
        self.seconds_per_unit[usize::from(!one)].push(seconds / work);
        if !one && !self.one {
            let busy = busy.filter(|b| b.is_finite() && *b > 0.0);
            self.estimated = busy.is_some();
            if let Some(busy) = busy {
                self.seconds_per_unit[0].push(busy / work);
            }
        }
        // The fastest of the last few: what else runs on the cores only ever slows a mode
        // down, so the fastest time is the mode's own.
        let prefer_one = match self.seconds_per_unit.map(|w| w.min()) {
            [Some(one), Some(pool)] if self.one => one < pool,
            [Some(one), Some(pool)] => one <= ONE_THREAD_GAIN * pool,
            _ => self.one,
        };
        if prefer_one != self.one {
            self.one = prefer_one;
            self.interval = FIRST_TRY;
            self.since_try = 0;
            if prefer_one {
                // From now on one thread's own times, not the pool's estimates of them.
                self.seconds_per_unit[0] = Window::default();
            }
        } else if one != self.one {
            // A try that lost: the next one later.
            self.interval = self.interval.saturating_mul(2).min(LAST_TRY);
        }
    }
}

/// The last [`WINDOW`] measurements of one mode.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Window {
    values: [f64; WINDOW],
    len: usize,
    next: usize,
}

impl Window {
    fn push(&mut self, value: f64) {
        self.values[self.next] = value;
        self.next = (self.next + 1) % WINDOW;
        self.len = (self.len + 1).min(WINDOW);
    }

    /// The smallest, if any.
    fn min(&self) -> Option<f64> {
        self.values[..self.len].iter().copied().reduce(f64::min)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs `frames` assignments whose pool would take 4 threads, one thread taking `one(i)`
    /// and the pool `pool(i)` seconds a unit in assignment `i`, the pool's workers busy for
    /// none of it known (as the chunks of lights report); the threads each took.
    fn run(
        choice: &mut ThreadChoice,
        frames: usize,
        one: impl Fn(usize) -> f64,
        pool: impl Fn(usize) -> f64,
    ) -> Vec<usize> {
        run_busy(choice, frames, one, |i| (pool(i), None))
    }

    /// [`run`] with the pool's time and its workers' busy time (as the bands report).
    fn run_busy(
        choice: &mut ThreadChoice,
        frames: usize,
        one: impl Fn(usize) -> f64,
        pool: impl Fn(usize) -> (f64, Option<f64>),
    ) -> Vec<usize> {
        (0..frames)
            .map(|i| {
                let threads = choice.threads(4);
                let (seconds, busy) = if threads == 1 {
                    (one(i), None)
                } else {
                    pool(i)
                };
                choice.measured(threads, seconds, 1.0, busy);
                threads
            })
            .collect()
    }

    fn ones(threads: &[usize]) -> usize {
        threads.iter().filter(|&&t| t == 1).count()
    }

    #[test]
    fn the_pool_stays_where_it_is_faster_and_one_thread_is_tried_ever_less_often() {
        let mut choice = ThreadChoice::default();
        let threads = run(&mut choice, 200, |_| 2e-3, |_| 1e-3);
        assert_eq!(threads[0], 4);
        assert_eq!(threads[1], 1, "one thread is tried early");
        // Tries 2, 4, 8, 16, 32, 32, ... apart: 9 in 200, none twice in a row.
        assert!((6..=9).contains(&ones(&threads)), "{threads:?}");
        assert!(threads.windows(2).all(|w| w != [1, 1]), "{threads:?}");
        assert_eq!(ones(&threads[100..164]), 2, "one try in 32 once settled");
    }

    #[test]
    fn the_kept_mode_stays_where_the_other_gains_little() {
        // One thread 5 % faster: the pool stays, one thread tried ever less often.
        let mut choice = ThreadChoice::default();
        let threads = run(&mut choice, 100, |_| 0.95e-3, |_| 1e-3);
        assert!(ones(&threads) <= 7, "{threads:?}");
        // One thread clearly faster: kept, and it stays when the pool is 5 % slower still.
        let threads = run(&mut choice, 100, |_| 0.8e-3, |_| 1e-3);
        assert!(ones(&threads[40..]) >= 57, "{threads:?}");
        let threads = run(&mut choice, 100, |_| 0.95e-3, |_| 1e-3);
        assert!(ones(&threads) >= 90, "{threads:?}");
        // The pool as fast: back to the pool at its next try.
        let threads = run(&mut choice, 100, |_| 1e-3, |_| 0.99e-3);
        assert!(ones(&threads[40..]) <= 3, "{threads:?}");
    }

    #[test]
    fn a_slow_start_of_the_pool_is_undone_at_its_next_try() {
        // As in a renderer's first frames on a 2-core host, where the driver's threads compile
        // shaders on the same cores: the pool is slow at first, then twice as fast.
        let mut choice = ThreadChoice::default();
        let threads = run(
            &mut choice,
            20,
            |_| 2e-3,
            |i| if i < 4 { 5e-3 } else { 1e-3 },
        );
        assert_eq!(
            threads[1..3],
            [1, 1],
            "one thread wins its first try: {threads:?}"
        );
        assert!(ones(&threads) <= 7, "{threads:?}");
        assert!(
            threads[8..].iter().filter(|&&t| t > 1).count() >= 10,
            "{threads:?}"
        );
    }

    #[test]
    fn a_busy_machine_keeps_one_thread_and_a_freed_one_gets_the_pool_back() {
        // The pool seven times slower while other work holds the cores (the figures of a
        // loaded 2-core host), then twice as fast once they are free.
        let mut choice = ThreadChoice::default();
        let busy = run(&mut choice, 100, |_| 0.5e-3, |_| 3.5e-3);
        assert!(ones(&busy[3..]) >= 90, "{busy:?}");
        let freed = run(&mut choice, 100, |_| 1e-3, |_| 0.5e-3);
        assert!(ones(&freed[40..]) <= 3, "{freed:?}");
    }

    #[test]
    fn a_pool_whose_workers_are_busy_longer_than_it_takes_is_never_tried_against_one_thread() {
        // Two workers busy 1.8 ms in all, done in 1 ms: the pool pays, and its own figures
        // say so, with no assignment spent on one thread.
        let mut choice = ThreadChoice::default();
        let threads = run_busy(&mut choice, 200, |_| 2e-3, |_| (1e-3, Some(1.8e-3)));
        assert_eq!(ones(&threads), 0, "{threads:?}");
    }

    #[test]
    fn a_pool_that_waits_for_its_workers_gives_way_to_one_thread_at_once() {
        // The figures of 640x360 on 64-px cells: under load the workers woke late (3.5 ms for
        // 0.5 ms of work); on a quiet 2-core host each band still looked at every light (busy
        // 0.5 ms, done in 0.6), where one thread takes 0.3 ms.
        for (pool, busy, one) in [(3.5e-3, 0.5e-3, 0.5e-3), (0.6e-3, 0.5e-3, 0.3e-3)] {
            let mut choice = ThreadChoice::default();
            let threads = run_busy(&mut choice, 200, |_| one, |_| (pool, Some(busy)));
            assert_eq!(threads[..2], [4, 1], "{threads:?}");
            // The pool tried 2, 4, 8, 16, 32, ... apart, none kept.
            assert!(200 - ones(&threads) <= 10, "{threads:?}");
        }
    }

    #[test]
    fn nothing_measured_or_nonsense_keeps_the_pool() {
        let mut choice = ThreadChoice::default();
        for _ in 0..10 {
            choice.measured(1, f64::NAN, 1.0, None);
            choice.measured(4, 1e-3, 0.0, Some(1e-3));
            choice.measured(4, f64::INFINITY, 1.0, None);
            assert_eq!(choice.threads(3), 3, "no try before the pool is measured");
        }
        assert_eq!(choice.seconds_per_unit.map(|w| w.min()), [None, None]);
        // A busy time that is no time estimates nothing: one thread is then tried.
        choice.measured(4, 1e-3, 1.0, Some(f64::NAN));
        assert_eq!(choice.seconds_per_unit[0].min(), None);
        assert_eq!(choice.threads(3), 1);
    }
}
