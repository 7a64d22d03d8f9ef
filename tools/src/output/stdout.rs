//! Standard output kept for the command line's own output, and the names that reach it.

use std::fs::File;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Standard output as the process was given it, once [`keep_stdout_for_own_output`] has
/// pointed descriptor 1 at standard error.
static OWN_STDOUT: OnceLock<File> = OnceLock::new();

/// Keeps standard output for the command line's own output and sends what the libraries loaded
/// in this process print there to standard error: a driver's `printf` (Mesa's "extension …
/// cannot be disabled" under `MESA_EXTENSION_OVERRIDE`, flushed at exit) would otherwise
/// follow `info --json` or `--stats -` and break whatever parses them. Call once, before any
/// GL library is loaded; [`print_stdout`] and `/dev/stdout` as an output then reach the
/// original. Unix only; where either stream is closed nothing changes.
pub fn keep_stdout_for_own_output() {
    #[cfg(unix)]
    {
        use std::os::fd::AsFd;
        let Ok(saved) = io::stdout().as_fd().try_clone_to_owned() else {
            return;
        };
        if rustix::stdio::dup2_stdout(io::stderr().as_fd()).is_ok() {
            let _ = OWN_STDOUT.set(File::from(saved));
        }
    }
}

/// The original standard output, for a path that names it (`/dev/stdout`, `/dev/fd/1`,
/// `/proc/self/fd/1`, this process's `/proc/PID/fd/1`, or a link to one of them), once
/// descriptor 1 no longer does.
pub(super) fn own_stdout_named(path: &Path) -> Option<&'static File> {
    let own = OWN_STDOUT.get()?;
    let pid = format!("/proc/{}/fd/1", std::process::id());
    let names = [
        "/dev/stdout",
        "/dev/fd/1",
        "/proc/self/fd/1",
        "/proc/thread-self/fd/1",
        &pid,
    ];
    let mut hop = std::path::absolute(path).ok()?;
    // Each link on the way, as `follow_links` takes them (40 at most).
    for _ in 0..40 {
        if names.iter().any(|name| hop == Path::new(name)) {
            return Some(own);
        }
        let target = std::fs::read_link(&hop).ok()?;
        hop = match hop.parent() {
            Some(folder) => folder.join(target),
            None => target,
        };
    }
    None
}

/// Whether `path` names standard output: `-`, or one of the system's names for descriptor 1
/// (`/dev/stdout`, `/dev/fd/1`, `/proc/self/fd/1`, or a link to one) once
/// [`keep_stdout_for_own_output`] has run.
pub fn names_stdout(path: &Path) -> bool {
    path == Path::new("-") || own_stdout_named(path).is_some()
}

/// What standard output is redirected to, as [`identity`] spells it: `-` and `/dev/stdout`
/// named the file a shell's `> f` or `>> f` opened no more than any other name did, so an output
/// or the scene there went unnoticed (`--out - >> scene.json` replaced the scene).
pub(super) fn stdout_identity() -> PathBuf {
    #[cfg(unix)]
    {
        use std::os::fd::AsRawFd;
        let fd = OWN_STDOUT.get().map_or(1, |own| own.as_raw_fd());
        let alias = PathBuf::from(format!("/proc/self/fd/{fd}"));
        std::fs::canonicalize(&alias).unwrap_or(alias)
    }
    #[cfg(not(unix))]
    PathBuf::from("-")
}

/// Whether `path` is a stream (a device, FIFO or socket, standard output's included), which
/// two outputs may share: neither overwrites the other there.
pub fn is_stream(path: &Path) -> bool {
    let meta = if names_stdout(path) {
        stdout_file().and_then(|f| f.metadata())
    } else {
        std::fs::metadata(path)
    };
    meta.is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// Standard output as a file of its own (the original one, where descriptor 1 was redirected).
pub(super) fn stdout_file() -> io::Result<File> {
    if let Some(own) = OWN_STDOUT.get() {
        return own.try_clone();
    }
    #[cfg(unix)]
    {
        use std::os::fd::AsFd;
        io::stdout().as_fd().try_clone_to_owned().map(File::from)
    }
    #[cfg(not(unix))]
    Err(io::ErrorKind::Unsupported.into())
}

/// Writes `text` to standard output and flushes it. A closed pipe (`manylight info | head`)
/// ends the output quietly; any other error (a full disk) is returned.
pub fn print_stdout(text: &str) -> Result<(), String> {
    let written = match OWN_STDOUT.get() {
        Some(mut own) => own.write_all(text.as_bytes()).and_then(|()| own.flush()),
        None => {
            let mut out = io::stdout().lock();
            out.write_all(text.as_bytes()).and_then(|()| out.flush())
        }
    };
    match written {
        Err(e) if e.kind() != io::ErrorKind::BrokenPipe => {
            Err(format!("cannot write to standard output: {e}"))
        }
        _ => Ok(()),
    }
}
