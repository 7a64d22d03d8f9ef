//! What a scene load produced besides the scene: its warnings and the files it read.

use super::{said, shown};

/// What a load produced besides the scene: non-fatal problems (missing textures, a missing
/// MTL, …), for the caller to show.
#[derive(Debug, Default)]
pub struct LoadReport {
    /// Human-readable warnings, also logged; from `scene::load_with`, each once.
    pub warnings: Vec<String>,
    /// Every file the load read (the scene file, models, MTL libraries, buffers, textures),
    /// each once, by its canonical path: for a caller that writes files, where writing one of
    /// these would replace the scene's own input.
    pub files: Vec<std::path::PathBuf>,
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
