//! When the shell tries again after a frame, or a resume, failed, and which failures it logs:
//! a phone's app should neither end on one bad frame (winit allows one event loop a process,
//! so an ended shell could not start again until the process dies) nor spin and flood logcat
//! on one that fails every time. GL- and Android-free, so it is unit-tested on the host.

use std::time::{Duration, Instant};

/// Time between tries while the shell keeps failing.
pub const RETRY_EVERY: Duration = Duration::from_secs(1);

/// The failures in a row so far and when to try next.
#[derive(Debug, Default)]
pub struct Retry {
    /// The last failure's message, while failures go on.
    last: Option<String>,
    /// When the next try is due (`None`: none is waited for).
    next: Option<Instant>,
}

impl Retry {
    /// Something failed at `now` with `error`: the next try is due [`RETRY_EVERY`] later.
    /// True when the message is worth logging: the first of a run, or one unlike the last.
    pub fn failed(&mut self, error: &str, now: Instant) -> bool {
        self.next = Some(now + RETRY_EVERY);
        let new = self.last.as_deref() != Some(error);
        if new {
            self.last = Some(error.to_string());
        }
        new
    }

    /// Something worked: no try is waited for any more. True when it ends a run of failures.
    pub fn succeeded(&mut self) -> bool {
        self.next = None;
        self.last.take().is_some()
    }

    /// When the next try is due, if one is waited for.
    pub fn next(&self) -> Option<Instant> {
        self.next
    }

    /// A redraw ended: a frame that `drew` ends a run of failures as [`Retry::succeeded`]
    /// (true when it does); one that drew nothing (no surface yet, a zero-sized window) leaves
    /// the try waited for, such as a failed resume's, due. True when it ends a run.
    pub fn redrawn(&mut self, drew: bool) -> bool {
        drew && self.succeeded()
    }

    /// True, once, when the try waited for is due at `now`.
    pub fn due(&mut self, now: Instant) -> bool {
        match self.next {
            Some(at) if now >= at => {
                self.next = None;
                true
            }
            _ => false,
        }
    }
}

/// Time within which a context lost again counts as the same run of losses.
pub const LOSSES_APART: Duration = Duration::from_secs(10);

/// Context losses while shown: the first of a run is rebuilt at once (a power event); one
/// within [`LOSSES_APART`] of the last (a frame the GPU's watchdog resets every time) goes to
/// the retry, a second later, and is logged at the second, fourth, eighth… loss of the run.
#[derive(Debug, Default)]
pub struct Losses {
    /// When the last loss came, and how many came in a row before it (itself included).
    last: Option<(Instant, u32)>,
}

/// What the shell does about a context lost at some time.
#[derive(Debug, PartialEq, Eq)]
pub struct Loss {
    /// Rebuild the context and renderer now, rather than at the next retry.
    pub rebuild_now: bool,
    /// Say so in logcat.
    pub log: bool,
    /// Losses in this run, this one included.
    pub in_run: u32,
}

impl Losses {
    /// A context lost at `now`.
    pub fn lost(&mut self, now: Instant) -> Loss {
        let in_run = match self.last {
            Some((at, n)) if now.saturating_duration_since(at) < LOSSES_APART => n + 1,
            _ => 1,
        };
        self.last = Some((now, in_run));
        Loss {
            rebuild_now: in_run == 1,
            log: in_run.is_power_of_two(),
            in_run,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failure_repeated_is_logged_once_and_tried_again_a_second_later() {
        let start = Instant::now();
        let mut retry = Retry::default();
        assert!(!retry.due(start), "nothing to try before a failure");
        assert!(retry.failed("GL_OUT_OF_MEMORY", start));
        assert_eq!(retry.next(), Some(start + RETRY_EVERY));
        assert!(!retry.due(start + RETRY_EVERY / 2));
        assert!(retry.due(start + RETRY_EVERY));
        assert!(!retry.due(start + RETRY_EVERY), "due once");
        let later = start + RETRY_EVERY;
        assert!(
            !retry.failed("GL_OUT_OF_MEMORY", later),
            "the same again: not logged"
        );
        assert!(retry.failed("context lost", later), "another: logged");
        assert!(retry.succeeded(), "a success ends the run, and says so");
        assert_eq!(retry.next(), None);
        assert!(!retry.succeeded(), "once");
        assert!(
            retry.failed("GL_OUT_OF_MEMORY", later),
            "after a success the same failure is logged again"
        );
    }

    /// A resume that failed stays due through a redraw that drew nothing (winit sends one for
    /// Android's `onNativeWindowRedrawNeeded` after every window is made): taking that for a
    /// success left no try, and the screen black until the next pause.
    #[test]
    fn a_redraw_that_drew_nothing_leaves_a_failed_resume_due() {
        let start = Instant::now();
        let mut retry = Retry::default();
        assert!(retry.failed("cannot create the window surface: EGL_BAD_ALLOC", start));
        assert!(!retry.redrawn(false), "drew nothing: no success to log");
        assert_eq!(retry.next(), Some(start + RETRY_EVERY));
        assert!(retry.due(start + RETRY_EVERY));
        assert!(retry.redrawn(true), "a frame drawn ends the run");
        assert_eq!(retry.next(), None);
    }

    /// A loss is rebuilt at once; losses that keep coming are not (each rebuild compiles every
    /// program), and only some of them are logged.
    #[test]
    fn context_losses_in_a_row_wait_for_the_retry_and_log_less_and_less() {
        let start = Instant::now();
        let mut losses = Losses::default();
        let first = losses.lost(start);
        assert!(first.rebuild_now && first.log && first.in_run == 1);
        let mut logged = 0;
        for i in 1..100u32 {
            let loss = losses.lost(start + RETRY_EVERY * i);
            assert!(!loss.rebuild_now, "loss {}: rebuilt at once", loss.in_run);
            assert_eq!(loss.in_run, i + 1);
            logged += u32::from(loss.log);
        }
        assert_eq!(logged, 6, "the 2nd, 4th, 8th, 16th, 32nd and 64th");
        let apart = losses.lost(start + RETRY_EVERY * 99 + LOSSES_APART);
        assert_eq!(
            apart,
            Loss {
                rebuild_now: true,
                log: true,
                in_run: 1
            }
        );
    }
}
