//! The warnings a test binary's renderers log: a logger of its own (the library logs through
//! `log`, and a warning is what a user is told).

use std::sync::{Mutex, Once};

struct Warnings(Mutex<Vec<String>>);

impl log::Log for Warnings {
    fn enabled(&self, metadata: &log::Metadata) -> bool {
        metadata.level() <= log::Level::Warn
    }

    fn log(&self, record: &log::Record) {
        if self.enabled(record.metadata()) {
            self.0.lock().unwrap().push(record.args().to_string());
        }
    }

    fn flush(&self) {}
}

static WARNINGS: Warnings = Warnings(Mutex::new(Vec::new()));

/// Installs the logger (once per test binary).
pub fn install() {
    static INSTALL: Once = Once::new();
    INSTALL.call_once(|| {
        log::set_logger(&WARNINGS).expect("no other logger in this test binary");
        log::set_max_level(log::LevelFilter::Warn);
    });
}

/// The warnings logged so far that contain `text` (installs the logger on first use).
pub fn warnings_containing(text: &str) -> Vec<String> {
    install();
    let logged = WARNINGS.0.lock().unwrap();
    logged
        .iter()
        .filter(|w| w.contains(text))
        .cloned()
        .collect()
}
