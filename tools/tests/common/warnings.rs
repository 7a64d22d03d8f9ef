//! The warnings a test's renderers log: a logger of the test program's own (the library logs
//! through `log`, and a warning is what a user is told), read back per thread. The library
//! logs on the thread that calls it, and each test runs on a thread of its own, so a test sees
//! its own warnings and not those of the tests running beside it in the same program.

use std::cell::Cell;
use std::sync::{Mutex, Once};
use std::thread::ThreadId;

/// Each warning with the thread that logged it.
struct Warnings(Mutex<Vec<(ThreadId, String)>>);

impl log::Log for Warnings {
    fn enabled(&self, metadata: &log::Metadata) -> bool {
        metadata.level() <= log::Level::Warn
    }

    fn log(&self, record: &log::Record) {
        if self.enabled(record.metadata()) {
            let text = record.args().to_string();
            let panics = PANIC_ON.with(|on| {
                let hit = on.get().is_some_and(|t| text.contains(t));
                if hit {
                    on.set(None);
                }
                hit
            });
            self.0
                .lock()
                .unwrap()
                .push((std::thread::current().id(), text.clone()));
            if panics {
                panic!("the game's logger panics on: {text}");
            }
        }
    }

    fn flush(&self) {}
}

static WARNINGS: Warnings = Warnings(Mutex::new(Vec::new()));

thread_local! {
    /// Text whose next warning on this thread panics (see [`panic_on_next_warning_containing`]).
    static PANIC_ON: Cell<Option<&'static str>> = const { Cell::new(None) };
}

/// Makes this thread's next warning containing `text` panic, once, as a game's own logger
/// might: for tests of what a renderer keeps when a call panics and the caller catches it.
#[allow(dead_code)] // not every test program uses it
pub fn panic_on_next_warning_containing(text: &'static str) {
    install();
    PANIC_ON.with(|on| on.set(Some(text)));
}

/// Installs the logger (once per test binary).
pub fn install() {
    static INSTALL: Once = Once::new();
    INSTALL.call_once(|| {
        log::set_logger(&WARNINGS).expect("no other logger in this test binary");
        log::set_max_level(log::LevelFilter::Warn);
    });
}

/// The warnings this thread logged so far that contain `text` (installs the logger on first
/// use).
pub fn warnings_containing(text: &str) -> Vec<String> {
    install();
    let here = std::thread::current().id();
    let logged = WARNINGS.0.lock().unwrap();
    logged
        .iter()
        .filter(|(thread, w)| *thread == here && w.contains(text))
        .map(|(_, w)| w.clone())
        .collect()
}
