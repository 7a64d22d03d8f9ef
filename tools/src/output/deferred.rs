//! Commits held back until a command has written all its files, so that it replaces all of
//! them or none.

use std::path::PathBuf;

use super::temporaries::{discard, live_temporaries};
use super::WriteError;

thread_local! {
    /// The files this thread wrote whole and synced, as (temporary, destination), whose
    /// renames wait for [`Deferred::commit`]; `None` where its commits are not deferred.
    static DEFERRED: std::cell::RefCell<Option<Vec<(PathBuf, PathBuf)>>> =
        const { std::cell::RefCell::new(None) };
}

/// Runs `f` on this thread's deferred commits.
pub(super) fn with_deferred<T>(f: impl FnOnce(&mut Option<Vec<(PathBuf, PathBuf)>>) -> T) -> T {
    DEFERRED.with_borrow_mut(f)
}

/// Defers the renames of every file this thread commits from now on to [`Deferred::commit`],
/// so that a command writing many (a benchmark's report folder) replaces all of them or none:
/// stopped half-way by an error or a signal, its destinations stay as they were, their
/// temporary files removed.
pub fn defer_commits() -> Deferred {
    with_deferred(|d| *d = Some(Vec::new()));
    Deferred(())
}

/// Commits deferred by [`defer_commits`]; dropped without [`Deferred::commit`], their files
/// are removed and the destinations left as they were.
pub struct Deferred(());

impl Deferred {
    /// Puts every deferred file in place; the first rename that fails is an error naming its
    /// file, and the files after it are removed.
    pub fn commit(self) -> Result<(), WriteError> {
        let waiting = with_deferred(Option::take).unwrap_or_default();
        let mut live = live_temporaries();
        let mut failed = None;
        for (temp, dest) in waiting {
            if failed.is_none() {
                if let Err(source) = std::fs::rename(&temp, &dest) {
                    failed = Some(WriteError { path: dest, source });
                }
            }
            discard(&mut live, &temp);
        }
        failed.map_or(Ok(()), Err)
    }
}

impl Drop for Deferred {
    fn drop(&mut self) {
        if let Some(waiting) = with_deferred(Option::take) {
            let mut live = live_temporaries();
            for (temp, _) in waiting {
                discard(&mut live, &temp);
            }
        }
    }
}
