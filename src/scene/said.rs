//! A load's warnings, logged once each when the load ends: also when it fails, where the
//! warnings before the error explain it, and once however often a model named again in a
//! scene file is read.

use std::cell::RefCell;
use std::collections::HashSet;

thread_local! {
    /// The warnings held back by the [`once_each`] running on this thread, if any.
    static HELD: RefCell<Option<Vec<String>>> = const { RefCell::new(None) };
}

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
            let mut seen = HashSet::new();
            for msg in held.unwrap_or_default() {
                if seen.insert(msg.clone()) {
                    warn(&msg);
                }
            }
        }
    }
    let _release = Release(HELD.with(|h| h.borrow_mut().replace(Vec::new())));
    load()
}

#[cfg(test)]
mod tests {
    use super::*;

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
