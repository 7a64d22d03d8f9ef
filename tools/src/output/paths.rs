//! What an output path names: one spelling of its file, whether a scene was read from it,
//! descriptor aliases, symbolic links, and FIFOs without a reader.

use std::fs::{File, OpenOptions};
use std::io;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

use super::stdout::{names_stdout, stdout_identity};

/// The files the process's scenes were read from, by [`identity`]: no output replaces one.
pub(super) fn inputs() -> MutexGuard<'static, Vec<PathBuf>> {
    static INPUTS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
    INPUTS.lock().unwrap_or_else(|e| e.into_inner())
}

/// Keeps every output of this process off `files`, which a scene was read from
/// (`LoadReport::files`): [`OutputFile::create`](super::OutputFile::create) refuses them,
/// naming the file, so an output that a subcommand names itself (a benchmark's heat map, a
/// matrix cell's picture) cannot replace a model or texture of the same name.
pub fn protect_inputs(files: &[PathBuf]) {
    let mut inputs = inputs();
    for file in files {
        let id = identity(file);
        if !inputs.contains(&id) {
            inputs.push(id);
        }
    }
}

/// `path` opened for writing, without waiting for a reader: opening a FIFO that no process
/// reads blocked until one came, so `--out fifo` hung before any work, saying nothing. Such a
/// FIFO is an error now; one with a reader is opened again as usual (blocking writes).
pub(super) fn open_without_waiting(path: &Path) -> io::Result<File> {
    let file = open_without_waiting_once(path)?;
    if file.metadata()?.is_file() {
        return Ok(file);
    }
    // A FIFO with a reader, or a device (a terminal's writes must not fail for want of
    // room): opened again as usual, so that writes wait rather than fail.
    OpenOptions::new().write(true).open(path)
}

/// `path` opened for writing without blocking (and without becoming the controlling
/// terminal); a FIFO without a reader is an error saying so.
fn open_without_waiting_once(path: &Path) -> io::Result<File> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
        let probe = OpenOptions::new()
            .write(true)
            .custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY)
            .open(path);
        match probe {
            Err(e)
                if e.raw_os_error() == Some(libc::ENXIO)
                    && std::fs::metadata(path).is_ok_and(|m| m.file_type().is_fifo()) =>
            {
                Err(io::Error::other(
                    "a FIFO that no process reads: start its reader first",
                ))
            }
            probe => probe,
        }
    }
    #[cfg(not(unix))]
    OpenOptions::new().write(true).open(path)
}

/// Whether `path`, which exists, may be written later, found without waiting and without
/// ending a FIFO's reader: a FIFO that has one is kept open by the returned file (its reader
/// would see its end when this check's open closed), to be dropped once the real write is
/// done; one without a reader is an error now.
pub fn check_writable_later(path: &Path) -> io::Result<Option<File>> {
    let file = open_without_waiting_once(path)?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if file.metadata()?.file_type().is_fifo() {
            return Ok(Some(file));
        }
    }
    Ok(None)
}

/// Whether `path` is one of the system's names for an open descriptor (`/dev/stdout`,
/// `/dev/fd/N`, `/proc/self/fd/N`): written in place, whatever it points at. Other files under
/// `/dev` (`/dev/shm`'s) are files like any other, replaced whole; all of `/dev` was taken as
/// a stream, and a file there was truncated before a write that then failed.
pub(super) fn is_descriptor_alias(path: &Path) -> bool {
    let mut parts = path.components().map(|c| c.as_os_str());
    let mut next = || parts.next().and_then(|p| p.to_str());
    matches!(
        (next(), next(), next(), next()),
        (
            Some("/"),
            Some("dev"),
            Some("stdout" | "stderr" | "stdin"),
            None
        ) | (Some("/"), Some("dev"), Some("fd"), Some(_))
            | (Some("/"), Some("proc"), Some(_), Some("fd"))
    )
}

/// `path` with symbolic links followed to the last one's target, which need not exist (at most
/// 40 links, the system's own limit; past it, the last path reached).
pub(super) fn follow_links(path: &Path) -> PathBuf {
    let mut path = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::read_link(&path) {
            Ok(target) => {
                path = match path.parent() {
                    Some(folder) => folder.join(target),
                    None => target,
                }
            }
            Err(_) => break,
        }
    }
    path
}

/// The file `path` names, spelled one way: symbolic links resolved, `.` and `..` gone, made
/// absolute; for a file that does not exist yet, its folder resolved. Two outputs with the same
/// identity would overwrite each other.
pub fn identity(path: &Path) -> PathBuf {
    if names_stdout(path) {
        return stdout_identity();
    }
    if let Ok(p) = std::fs::canonicalize(path) {
        return p;
    }
    let path = follow_links(path);
    let absolute = std::path::absolute(&path).unwrap_or(path);
    match (absolute.parent(), absolute.file_name()) {
        (Some(parent), Some(name)) => std::fs::canonicalize(parent)
            .unwrap_or_else(|_| parent.to_path_buf())
            .join(name),
        _ => absolute,
    }
}
