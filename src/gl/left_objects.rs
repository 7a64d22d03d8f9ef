//! GL objects left on purpose: a renderer whose context is gone (lost on Android, or no
//! longer current) cannot delete its objects, and says so once; the objects' own "dropped
//! without destroy()" warnings, meant for the renderer's bugs, would then repeat it for each.

use std::cell::Cell;

thread_local! {
    /// How many [`LeftObjects`] marks are dropping their owners' objects on this thread.
    static LEAVING: Cell<u32> = const { Cell::new(0) };
}

/// Whether GL objects dropping now on this thread were left on purpose (no warning of theirs).
pub(crate) fn left_on_purpose() -> bool {
    LEAVING.with(|n| n.get() > 0)
}

/// A mark an owner keeps as its **last** field (fields drop in declaration order): once
/// [`LeftObjects::leave`] is called, the owner's other fields drop quietly, until this one
/// drops.
#[derive(Debug, Default)]
pub(crate) struct LeftObjects {
    leaving: Cell<bool>,
}

impl LeftObjects {
    /// The owner's objects are left, not leaked by mistake.
    pub(crate) fn leave(&self) {
        if !self.leaving.replace(true) {
            LEAVING.with(|n| n.set(n.get() + 1));
        }
    }
}

impl Drop for LeftObjects {
    fn drop(&mut self) {
        if self.leaving.get() {
            LEAVING.with(|n| n.set(n.get().saturating_sub(1)));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{left_on_purpose, LeftObjects};

    #[test]
    fn only_while_a_left_mark_lives() {
        assert!(!left_on_purpose());
        let mark = LeftObjects::default();
        assert!(!left_on_purpose(), "not before leave()");
        mark.leave();
        mark.leave();
        assert!(left_on_purpose());
        drop(mark);
        assert!(!left_on_purpose(), "a second leave() counted once");
    }
}
