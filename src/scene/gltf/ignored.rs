//! What a glTF file asks for that the loader does not do: required extensions it lacks (the
//! file is refused, by name), and features that change the picture but are ignored (one
//! warning per file and feature, by name). The supported extensions are listed once, in
//! [`SUPPORTED_EXTENSIONS`].

use crate::scene::shown;

/// Most names from the file a message lists one by one (a hostile file may list millions).
const LISTED: usize = 8;

/// Extensions the loader implements. A file *requiring* another is refused, naming it; one
/// merely *using* another gets one warning per extension that it is ignored.
pub const SUPPORTED_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_texture_transform",
    "KHR_materials_emissive_strength",
];

/// The file's `extensionsRequired` that the loader does not support, as the reason it is
/// refused (`None`: all supported).
pub(super) fn unsupported_required(root: &gltf::json::Root) -> Option<String> {
    let missing: Vec<&str> = root
        .extensions_required
        .iter()
        .map(String::as_str)
        .filter(|e| !SUPPORTED_EXTENSIONS.contains(e))
        .collect();
    if missing.is_empty() {
        return None;
    }
    Some(format!(
        "extensionsRequired lists {}, which manylight does not support (supported: {})",
        listed(&missing),
        SUPPORTED_EXTENSIONS.join(", ")
    ))
}

/// Names from the file as a message lists them: the first [`LISTED`], each as [`shown::name`]
/// shows it, then how many more.
fn listed(names: &[&str]) -> String {
    let mut list: Vec<String> = names.iter().take(LISTED).map(|n| shown::name(n)).collect();
    if names.len() > LISTED {
        list.push(format!("and {} more", names.len() - LISTED));
    }
    list.join(", ")
}

/// One warning per feature the file uses that changes its picture but is not drawn:
/// unsupported extensions it uses, skins, morph targets, animations, further scenes and
/// cameras. `camera_nodes` counts the drawn scene's nodes that place a camera.
pub(super) fn unused_features(document: &gltf::Document, camera_nodes: usize) -> Vec<String> {
    // extensionsUsed should list each name once; a file that repeats one gets one warning.
    let mut unsupported: Vec<&str> = document
        .extensions_used()
        .filter(|e| !SUPPORTED_EXTENSIONS.contains(e))
        .collect();
    unsupported.sort_unstable();
    unsupported.dedup();
    // One warning each for the first few.
    let mut out: Vec<String> = unsupported
        .iter()
        .take(LISTED)
        .map(|e| {
            let name = shown::name(e);
            format!(
                "extension {name} is not supported: ignored ({})",
                effect_of(e)
            )
        })
        .collect();
    if unsupported.len() > LISTED {
        out.push(format!(
            "{} more extensions are not supported: ignored",
            unsupported.len() - LISTED
        ));
    }
    let skins = document.skins().len();
    if skins > 0 {
        out.push(format!(
            "skins ({skins}) are not applied: skinned meshes are drawn in their bind pose"
        ));
    }
    let morphed = document
        .meshes()
        .filter(|m| m.primitives().any(|p| p.morph_targets().next().is_some()))
        .count();
    if morphed > 0 {
        out.push(format!(
            "morph targets ({morphed} meshes) are not applied: meshes are drawn without them"
        ));
    }
    let animations = document.animations().len();
    if animations > 0 {
        out.push(format!(
            "animations ({animations}) are not played: nodes are drawn at rest"
        ));
    }
    let scenes = document.scenes().len();
    if scenes > 1 {
        out.push(format!(
            "{scenes} scenes: only the default one (else the first) is drawn"
        ));
    }
    if camera_nodes > 1 {
        out.push(format!(
            "{camera_nodes} nodes place cameras: only the first (depth first) is read, the \
             others are ignored"
        ));
    }
    out
}

/// What ignoring extension `name` does to the picture, in a few words.
fn effect_of(name: &str) -> &'static str {
    if name == "KHR_draco_mesh_compression" || name.ends_with("_meshopt_compression") {
        "the uncompressed fallback data is drawn"
    } else if name.starts_with("KHR_materials_") {
        "the core material is drawn without it"
    } else if name.starts_with("KHR_texture_") || name.starts_with("EXT_texture_") {
        "textures are read as if it were absent"
    } else {
        "drawn as if it were absent"
    }
}

/// `warnings` with those that say the same of different parts of the file merged: a message
/// is its glTF path, `: `, then what it says (`meshes[3].primitives[0]: mode Points is not
/// drawn…`); the second and further with the same saying are counted on the first's line.
pub(super) fn once_per_feature(warnings: Vec<String>) -> Vec<String> {
    let mut merged: Vec<(String, usize)> = Vec::new();
    let mut index: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
    for w in warnings {
        let saying = w
            .split_once(": ")
            .map_or(w.as_str(), |(_, s)| s)
            .to_string();
        match index.get(&saying) {
            Some(&i) => merged[i].1 += 1,
            None => {
                index.insert(saying, merged.len());
                merged.push((w, 0));
            }
        }
    }
    merged
        .into_iter()
        .map(|(w, more)| match more {
            0 => w,
            n => format!("{w} (and {n} more like it)"),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_saying_of_different_parts_is_one_line() {
        let merged = once_per_feature(vec![
            "meshes[0].primitives[1]: mode Points is not drawn".into(),
            "meshes[2].primitives[0]: mode Lines is not drawn".into(),
            "meshes[4].primitives[0]: mode Points is not drawn".into(),
            "skins (1) are not applied".into(),
        ]);
        assert_eq!(
            merged,
            [
                "meshes[0].primitives[1]: mode Points is not drawn (and 1 more like it)",
                "meshes[2].primitives[0]: mode Lines is not drawn",
                "skins (1) are not applied",
            ]
        );
    }
}
