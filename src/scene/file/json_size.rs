//! A bound on what parsing a scene file's JSON builds, counted in one pass before parsing:
//! serde builds each object or array (some 220 bytes an empty one) and aborts where an
//! allocation fails.

/// Most JSON objects and arrays a scene file may hold: four for each object it may place
/// (`{"builtin": "plane", "transform": {"translate": […]}}` is three).
pub const MAX_SCENE_FILE_CONTAINERS: usize = 4 * crate::scene::MAX_SCENE_OBJECTS;

/// What parsing takes an object or array, with room to spare over what was measured
/// (docs/cli.md).
const PARSED_CONTAINER_BYTES: u64 = 256;

/// What parsing takes an array element or object member besides its container.
const PARSED_ELEMENT_BYTES: u64 = 64;

/// Refuses JSON past [`MAX_SCENE_FILE_CONTAINERS`] or whose parse this process cannot
/// allocate now (serde aborts where an allocation fails), counted before parsing.
pub(super) fn check(text: &str) -> Result<(), String> {
    let (containers, separators) = crate::scene::json_count::count_containers(text.as_bytes());
    if containers > MAX_SCENE_FILE_CONTAINERS {
        return Err(format!(
            "its JSON holds {containers} objects and arrays, more than the \
             {MAX_SCENE_FILE_CONTAINERS} a scene file may (refused before parsing)"
        ));
    }
    let bytes =
        containers as u64 * PARSED_CONTAINER_BYTES + separators as u64 * PARSED_ELEMENT_BYTES;
    if !crate::scene::alloc_probe::can_allocate(bytes) {
        return Err(format!(
            "parsing its {containers} JSON objects and arrays takes about {} MiB, more than \
             this process can allocate now",
            bytes >> 20
        ));
    }
    Ok(())
}
