//! Signals that end the command line (SIGINT, SIGTERM, SIGHUP: Ctrl-C, `kill`, a closed
//! terminal) first remove the temporary output files being written (`output`), then end the
//! process by the signal's default action, with the same exit status: a `--record` stopped
//! half-way leaves no `.NAME.PID.N.tmp` behind. A file size limit's signal is ignored.

/// Starts the thread that watches the signals. A signal the process started with ignored
/// (`nohup` ignores SIGHUP, a shell's `cmd &` SIGINT) stays ignored. SIGXFSZ, which a write
/// past `ulimit -f` raises and which would end the process leaving its temporary files, is
/// ignored: the write fails with `EFBIG` instead, an error naming the file.
#[cfg(unix)]
pub fn remove_temporaries_on_signals() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    // SAFETY: setting a signal's action to `SIG_IGN` installs no handler, and nothing else in
    // the process sets SIGXFSZ's.
    unsafe { libc::signal(libc::SIGXFSZ, libc::SIG_IGN) };
    let watched: Vec<i32> = [SIGINT, SIGTERM, SIGHUP]
        .into_iter()
        .filter(|&s| !is_ignored(s))
        .collect();
    // Registered on the thread: if it cannot start, the signals keep their default action.
    let watch = move || {
        let Ok(mut signals) = signal_hook::iterator::Signals::new(&watched) else {
            return;
        };
        if let Some(signal) = signals.forever().next() {
            crate::output::remove_temporaries_then(|| {
                let _ = signal_hook::low_level::emulate_default_handler(signal);
            });
        }
    };
    let _ = std::thread::Builder::new()
        .name("signals".into())
        .spawn(watch);
}

/// Whether `signal`'s action is to be ignored (`SIG_IGN`).
#[cfg(unix)]
fn is_ignored(signal: i32) -> bool {
    let mut current = std::mem::MaybeUninit::<libc::sigaction>::zeroed();
    // SAFETY: with a null new action `sigaction` only writes the current one into `current`,
    // a properly sized and aligned `struct sigaction`; it is read only when the call succeeded.
    let read = unsafe { libc::sigaction(signal, std::ptr::null(), current.as_mut_ptr()) } == 0;
    // SAFETY: zero-initialised, and filled in by the successful call.
    read && unsafe { current.assume_init() }.sa_sigaction == libc::SIG_IGN
}

/// Elsewhere a signal ends the process as it always did.
#[cfg(not(unix))]
pub fn remove_temporaries_on_signals() {}
