//! A load's warnings, logged once each when the load ends: also when it fails, where the
//! warnings before the error explain it, and once however often a model named again in a
//! scene file is read. At most [`MOST_SHOWN`] distinct ones a load are logged as warnings, so
//! a model with thousands of faults cannot flood the log; the rest go to the debug level, and
//! one line says how many.

use std::cell::RefCell;
use std::collections::HashSet;

thread_local! {
    /// The warnings held back by the [`once_each`] running on this thread, if any.
    static HELD: RefCell<Option<Vec<String>>> = const { RefCell::new(None) };
}

/// Most distinct warnings one load logs at the warning level.
pub(crate) const MOST_SHOWN: usize = 50;

/// Logs `msg` now, or when the load [`once_each`] runs on this thread ends.
pub(crate) fn warn(msg: &str) {
    let held = HELD.with(|h| h.borrow_mut().as_mut().map(|v| v.push(msg.to_string())));
    if held.is_none() {
        log::warn!("{msg}");
    }
}

/// Runs `load` with the warnings it says ([`warn`]) held back, then logs each distinct one
/// once, in the order first said, however `load` ends (an error, or a panic unwinding).
pub(crate) fn once_each<T>(load: impl FnOnce() -> T) -> T {
    /// Puts back the holder that was there before and logs what was held.
    struct Release(Option<Vec<String>>);
    impl Drop for Release {
        fn drop(&mut self) {
            let held = HELD.with(|h| std::mem::replace(&mut *h.borrow_mut(), self.0.take()));
            // An inner load's warnings go to the load around it, which shows or hides them.
            let outermost = HELD.with(|h| h.borrow().is_none());
            let most = if outermost { MOST_SHOWN } else { usize::MAX };
            let (shown, hidden) = distinct(held.unwrap_or_default(), most);
            shown.iter().for_each(|msg| warn(msg));
            hidden.iter().for_each(|msg| log::debug!("{msg}"));
            if !hidden.is_empty() {
                log::warn!(
                    "{} more warnings of this load are logged at the debug level only \
                     (RUST_LOG=debug shows them)",
                    hidden.len()
                );
            }
        }
    }
    let _release = Release(HELD.with(|h| h.borrow_mut().replace(Vec::new())));
    load()
}

/// `warnings` without repeats, in the order first said: the first `most`, and the rest.
fn distinct(warnings: Vec<String>, most: usize) -> (Vec<String>, Vec<String>) {
    let mut seen = HashSet::new();
    let mut unique: Vec<String> = warnings
        .into_iter()
        .filter(|w| seen.insert(w.clone()))
        .collect();
    let rest = unique.split_off(most.min(unique.len()));
    (unique, rest)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn past_the_most_shown_distinct_warnings_the_rest_are_kept_apart_in_order() {
        let said: Vec<String> = (0..MOST_SHOWN + 10)
            .flat_map(|i| [format!("texture {i} not found"), "repeated".to_string()])
            .collect();
        let (shown, hidden) = distinct(said, MOST_SHOWN);
        assert_eq!(shown.len(), MOST_SHOWN);
        assert_eq!(shown[..2], ["texture 0 not found", "repeated"]);
        assert_eq!(hidden.len(), 11, "{hidden:?}");
        assert_eq!(hidden[0], format!("texture {} not found", MOST_SHOWN - 1));
        let (all, none) = distinct(vec!["a".into(), "a".into()], MOST_SHOWN);
        assert_eq!((all, none.len()), (vec!["a".to_string()], 0));
    }

    fn held() -> Option<Vec<String>> {
        HELD.with(|h| h.borrow().clone())
    }

    /// An inner load releases its warnings to the outer holder: once each, in order, also
    /// when it fails.
    #[test]
    fn held_warnings_are_released_once_each_also_on_an_error() {
        once_each(|| {
            let failed: Result<(), &str> = once_each(|| {
                warn("a");
                warn("b");
                warn("a");
                Err("failed")
            });
            assert!(failed.is_err());
            assert_eq!(held(), Some(vec!["a".to_string(), "b".to_string()]));
        });
        assert_eq!(held(), None, "nothing held once every load ended");
    }
}
