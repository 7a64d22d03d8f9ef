//! A bound on what parsing a scene file's JSON builds, counted in one pass before parsing:
//! serde builds each object or array (some 220 bytes an empty one) and aborts where an
//! allocation fails.

use crate::scene::{alloc_probe, json_count};

/// Most JSON objects and arrays a scene file may hold: four for each object it may place
/// (`{"builtin": "plane", "transform": {"translate": […]}}` is three).
pub const MAX_SCENE_FILE_CONTAINERS: usize = 4 * crate::scene::MAX_SCENE_OBJECTS;

/// What parsing takes an object or array, with room to spare over what was measured
/// (docs/cli.md).
const PARSED_CONTAINER_BYTES: u64 = 256;

/// Refuses JSON past [`MAX_SCENE_FILE_CONTAINERS`] or whose parse this process cannot
/// allocate now (serde aborts where an allocation fails), counted before parsing.
pub(super) fn check(text: &str) -> Result<(), String> {
    let (containers, separators) = json_count::count_containers(text.as_bytes());
    if containers > MAX_SCENE_FILE_CONTAINERS {
        return Err(format!(
            "its JSON holds {containers} objects and arrays, more than the \
             {MAX_SCENE_FILE_CONTAINERS} a scene file may (refused before parsing)"
        ));
    }
    let bytes = json_count::parse_bytes(containers, separators, PARSED_CONTAINER_BYTES);
    alloc_probe::ask(
        bytes,
        format_args!("parsing its {containers} JSON objects and arrays takes"),
    )
}
