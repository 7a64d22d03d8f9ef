//! Files a test writes and loads as a user's: the glTF tests load with the file's own lights
//! only (no random ones) and without the hint that a file has none.

use std::path::{Path, PathBuf};

use manylight::scene::{self, LoadReport, Scene, SceneError};

/// Writes `bytes` to `dir/name`; the path written.
pub fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// Loads a scene or model file with its own lights only.
pub fn load(path: &Path) -> Result<(Scene, LoadReport), SceneError> {
    // No random lights: the file's own only.
    without_no_lights_hint(scene::load(path.to_str().unwrap(), Some((0, 1))))
}

/// As [`load`], reading files outside the model's folder only when `allow` is given.
pub fn load_with(path: &Path, allow: bool) -> Result<(Scene, LoadReport), SceneError> {
    let mut options = manylight::LoadOptions::default();
    options.allow_outside_files = allow;
    without_no_lights_hint(scene::load_with(
        path.to_str().unwrap(),
        Some((0, 1)),
        &options,
    ))
}

/// A load's result less the hint that a file has no lights (gltf_manners.rs checks it).
fn without_no_lights_hint(
    loaded: Result<(Scene, LoadReport), SceneError>,
) -> Result<(Scene, LoadReport), SceneError> {
    loaded.map(|(scene, mut report)| {
        report.warnings.retain(|w| !w.starts_with("no lights in "));
        (scene, report)
    })
}
