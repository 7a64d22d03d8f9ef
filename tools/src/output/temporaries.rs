//! The hidden temporary files an output is written to before it replaces its destination,
//! and the list of those alive, which a signal that ends the process removes.

use std::ffi::OsString;
use std::fs::{File, OpenOptions};
use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Mutex, MutexGuard};

/// Numbers the temporary files of one process.
static TEMP_COUNTER: AtomicU32 = AtomicU32::new(0);

/// The temporary files being written now, which a signal that ends the process removes
/// (`crate::signals`). Each is listed while its file exists: created, renamed and removed with
/// the lock held, so that a signal's removal never races them.
static LIVE_TEMPORARIES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

pub(super) fn live_temporaries() -> MutexGuard<'static, Vec<PathBuf>> {
    LIVE_TEMPORARIES.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes every temporary file being written, then runs `then` with the list still locked, so
/// that no new one is made, renamed or removed meanwhile (`then` ends the process).
pub(crate) fn remove_temporaries_then(then: impl FnOnce()) {
    let mut live = live_temporaries();
    for temp in live.drain(..) {
        let _ = std::fs::remove_file(temp);
    }
    then();
}

/// Removes the temporary file `temp` where it is still there, and takes it off `live`.
pub(super) fn discard(live: &mut Vec<PathBuf>, temp: &Path) {
    let _ = std::fs::remove_file(temp);
    live.retain(|t| t != temp);
}

/// Longest file name most file systems take, in bytes (ext4's, tmpfs's, APFS's `NAME_MAX`).
pub(super) const NAME_MAX: usize = 255;

/// Creates `.NAME.PID.N.tmp` beside `dest`, new (never an existing file); `.manylight.PID.N.tmp`
/// where NAME is too long for that, so a name the file system takes is written.
pub(super) fn create_temp(dest: &Path) -> io::Result<(PathBuf, File)> {
    let name = dest
        .file_name()
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "the path names no file"))?;
    let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
    let suffix = format!(".{}.{n}.tmp", std::process::id());
    let mut temp_name = OsString::from(".");
    if 1 + name.len() + suffix.len() <= NAME_MAX {
        temp_name.push(name);
    } else {
        temp_name.push("manylight");
    }
    temp_name.push(suffix);
    let temp = dest.with_file_name(temp_name);
    let mut live = live_temporaries();
    let file = OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&temp)?;
    live.push(temp.clone());
    Ok((temp, file))
}
