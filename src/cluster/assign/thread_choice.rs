//! One thread or the pool, by measure: where the rules of `threads_for` would wake the pool
//! for an assignment, an [`Assigner`](super::Assigner) keeps it on the calling thread when
//! that has been as fast. Waking a worker costs from microseconds to a millisecond, depending
//! on the machine and on what else runs on its cores. On a 2-core host whose GPU (llvmpipe)
//! shares them, one thread took 0.39 ms where two took 0.59 ms; on a 16-core host, 1.40
//! against 1.26 ms (docs/performance.md). A worker woken for no gain is also a core taken
//! from the caller's own work.

/// Every this many assignments the choice tries the mode it does not prefer, so that it
/// follows a change (the work grew, the cores got busy or free).
pub(super) const TRY_OTHER_EVERY: u32 = 30;

/// The pool is preferred when its time per unit of work is at most this share of one
/// thread's.
pub(super) const POOL_GAIN: f64 = 0.9;

/// Measurements per mode whose median decides.
const WINDOW: usize = 5;

/// The last measured seconds per unit of work ([`assign_work`](super::assign_work)) on one
/// thread and on the pool, and when the other mode was last tried.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct ThreadChoice {
    /// One thread, then the pool.
    seconds_per_unit: [Window; 2],
    /// Assignments since the mode not preferred was last tried.
    since_other: u32,
}

impl ThreadChoice {
    /// Threads for an assignment that the rules would give the pool's `pool` (two or more).
    ///
    /// Until one thread has been measured it is tried on the second such assignment (early,
    /// while a caller's buffers still grow); then the pool while it is at most
    /// [`POOL_GAIN`] of one thread's time a unit (or not yet measured), else one thread; and
    /// every [`TRY_OTHER_EVERY`] assignments the other.
    pub(super) fn threads(&mut self, pool: usize) -> usize {
        self.since_other += 1;
        let [one, many] = self.seconds_per_unit.map(|w| w.median());
        let prefer_one = match (one, many) {
            (Some(one), Some(many)) => many > POOL_GAIN * one,
            _ => false,
        };
        let due = if one.is_none() { 2 } else { TRY_OTHER_EVERY };
        let other = self.since_other >= due;
        if other {
            self.since_other = 0;
        }
        if prefer_one != other {
            1
        } else {
            pool
        }
    }

    /// Takes in an assignment on `threads` threads that took `seconds` for `work` units.
    pub(super) fn measured(&mut self, threads: usize, seconds: f64, work: f64) {
        if work > 0.0 && seconds.is_finite() && seconds > 0.0 {
            self.seconds_per_unit[usize::from(threads > 1)].push(seconds / work);
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

    /// The median (of an even count, the upper one), if any.
    fn median(&self) -> Option<f64> {
        let mut values = self.values;
        let values = &mut values[..self.len];
        values.sort_by(f64::total_cmp);
        values.get(self.len / 2).copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs `frames` assignments whose pool would take 4 threads, one thread taking `one` and
    /// the pool `pool` seconds a unit; the threads each took.
    fn run(choice: &mut ThreadChoice, frames: usize, one: f64, pool: f64) -> Vec<usize> {
        (0..frames)
            .map(|_| {
                let threads = choice.threads(4);
                choice.measured(threads, if threads == 1 { one } else { pool }, 1.0);
                threads
            })
            .collect()
    }

    #[test]
    fn the_pool_stays_where_it_is_faster_and_one_thread_is_tried_now_and_then() {
        let mut choice = ThreadChoice::default();
        let threads = run(&mut choice, 100, 2e-3, 1e-3);
        assert_eq!(threads[0], 4);
        assert_eq!(threads[1], 1, "one thread is measured early");
        let ones = threads.iter().filter(|&&t| t == 1).count();
        assert!((3..=5).contains(&ones), "one thread {ones} times in 100: {threads:?}");
    }

    #[test]
    fn one_thread_is_kept_where_the_pool_gains_too_little() {
        let mut choice = ThreadChoice::default();
        // The pool at 0.95 of one thread's time: not worth a woken worker.
        let threads = run(&mut choice, 100, 1e-3, 0.95e-3);
        let pools = threads[2..].iter().filter(|&&t| t > 1).count();
        assert!((2..=4).contains(&pools), "the pool {pools} times: {threads:?}");
        // When the pool becomes clearly faster, the next tries of it bring it back.
        let threads = run(&mut choice, 200, 1e-3, 0.5e-3);
        assert!(threads[150..].iter().filter(|&&t| t > 1).count() > 40, "{threads:?}");
    }

    #[test]
    fn nothing_measured_or_nonsense_keeps_the_pool() {
        let mut choice = ThreadChoice::default();
        choice.measured(1, f64::NAN, 1.0);
        choice.measured(1, 1e-3, 0.0);
        assert_eq!(choice.seconds_per_unit[0].median(), None);
        assert_eq!(choice.threads(3), 3);
    }
}
