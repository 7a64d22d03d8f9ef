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
}
