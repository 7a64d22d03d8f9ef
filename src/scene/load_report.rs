//! What a scene load produced besides the scene: its warnings.

use super::{said, shown};

/// What a load produced besides the scene: non-fatal problems (missing textures, a missing
/// MTL, …), for the caller to show.
#[derive(Debug, Default)]
pub struct LoadReport {
    /// Human-readable warnings, also logged; from `scene::load_with`, each once.
    pub warnings: Vec<String>,
}

impl LoadReport {
    /// [`LoadReport::say`]s `msg`, its control characters escaped ([`shown::text`]).
    pub(crate) fn warn(&mut self, msg: String) {
        self.say(shown::reason(&msg));
    }

    /// Logs and keeps `msg` as it is (logged when the load ends, inside `scene::load_with`).
    pub(crate) fn say(&mut self, msg: String) {
        said::warn(&msg);
        self.warnings.push(msg);
    }
}
