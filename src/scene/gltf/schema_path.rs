//! Where a glTF document does not fit the schema, as a field path (`nodes[0].rotation`),
//! found by parsing it again through `serde_path_to_error`. Only the schema's own names are
//! shown: a key the file made up (an attribute's, an extension's) is shown as `…`, so no
//! message carries the file's bytes.

use serde_path_to_error::Segment;

/// The path of the first value that does not fit glTF's schema; `None` where the document
/// fits (or is not JSON at all).
pub(super) fn misfit(json: &[u8]) -> Option<String> {
    let mut reader = serde_json::Deserializer::from_slice(json);
    let err = serde_path_to_error::deserialize::<_, gltf::json::Root>(&mut reader).err()?;
    let mut out = String::new();
    for segment in err.path().iter() {
        match segment {
            Segment::Seq { index } => out.push_str(&format!("[{index}]")),
            Segment::Map { key } | Segment::Enum { variant: key } => {
                if !out.is_empty() {
                    out.push('.');
                }
                out.push_str(if is_schema_name(key) { key } else { "…" });
            }
            Segment::Unknown => out.push_str(".…"),
        }
    }
    Some(if out.is_empty() {
        "the document".to_string()
    } else {
        out
    })
}

/// A path the `gltf` crate's validation wrote (`….attributes["NAME"]`) with a key the file
/// made up (not [`is_schema_name`]) and all after it shown as `[…]`: the key is the file's
/// text, written unescaped, so nothing after its start can be trusted to end it.
pub(super) fn without_made_up_keys(path: &str) -> String {
    let mut out = String::new();
    let mut rest = path;
    while let Some(start) = rest.find("[\"") {
        out.push_str(&rest[..start]);
        let after = &rest[start + 2..];
        match after
            .find("\"]")
            .map(|end| (&after[..end], &after[end + 2..]))
        {
            Some((key, next)) if is_schema_name(key) => {
                out.push_str(&format!("[\"{key}\"]"));
                rest = next;
            }
            _ => {
                out.push_str("[…]");
                return out;
            }
        }
    }
    out.push_str(rest);
    out
}

/// Property names of the glTF 2.0 schema and of the extensions the loader reads, and the
/// attribute semantics.
pub(super) fn is_schema_name(key: &str) -> bool {
    const NAMES: &[&str] = &[
        "accessors",
        "alphaCutoff",
        "alphaMode",
        "animations",
        "aspectRatio",
        "asset",
        "attributes",
        "baseColorFactor",
        "baseColorTexture",
        "buffer",
        "bufferView",
        "bufferViews",
        "buffers",
        "byteLength",
        "byteOffset",
        "byteStride",
        "camera",
        "cameras",
        "channels",
        "children",
        "color",
        "componentType",
        "copyright",
        "count",
        "doubleSided",
        "emissiveFactor",
        "emissiveStrength",
        "emissiveTexture",
        "extensions",
        "extensionsRequired",
        "extensionsUsed",
        "extras",
        "generator",
        "images",
        "index",
        "indices",
        "innerConeAngle",
        "input",
        "intensity",
        "interpolation",
        "inverseBindMatrices",
        "joints",
        "light",
        "lights",
        "magFilter",
        "material",
        "materials",
        "matrix",
        "max",
        "mesh",
        "meshes",
        "metallicFactor",
        "metallicRoughnessTexture",
        "mimeType",
        "min",
        "minFilter",
        "minVersion",
        "mode",
        "name",
        "node",
        "nodes",
        "normalTexture",
        "normalized",
        "occlusionTexture",
        "offset",
        "orthographic",
        "outerConeAngle",
        "output",
        "path",
        "pbrMetallicRoughness",
        "perspective",
        "primitives",
        "range",
        "rotation",
        "roughnessFactor",
        "sampler",
        "samplers",
        "scale",
        "scene",
        "scenes",
        "skeleton",
        "skin",
        "skins",
        "source",
        "sparse",
        "spot",
        "strength",
        "target",
        "targets",
        "texCoord",
        "textures",
        "translation",
        "type",
        "uri",
        "values",
        "version",
        "weights",
        "wrapS",
        "wrapT",
        "xmag",
        "ymag",
        "yfov",
        "zfar",
        "znear",
        "KHR_lights_punctual",
        "KHR_texture_transform",
        "KHR_materials_emissive_strength",
    ];
    const SEMANTICS: &[&str] = &["POSITION", "NORMAL", "TANGENT"];
    const NUMBERED: &[&str] = &["TEXCOORD_", "COLOR_", "JOINTS_", "WEIGHTS_"];
    NAMES.contains(&key)
        || SEMANTICS.contains(&key)
        || NUMBERED.iter().any(|prefix| {
            key.strip_prefix(prefix).is_some_and(|n| {
                !n.is_empty() && n.len() <= 3 && n.bytes().all(|b| b.is_ascii_digit())
            })
        })
}

#[cfg(test)]
mod tests {
    use super::{misfit, without_made_up_keys};

    #[test]
    fn validation_paths_hide_keys_the_file_made_and_what_follows() {
        assert_eq!(
            without_made_up_keys(r#"meshes[0].primitives[1].attributes["SECRET"].x"#),
            "meshes[0].primitives[1].attributes[…]"
        );
        assert_eq!(
            without_made_up_keys(r#"a["POSITION"].b["x\"]y"]"#),
            r#"a["POSITION"].b[…]"#
        );
        assert_eq!(without_made_up_keys("nodes[2].mesh"), "nodes[2].mesh");
    }

    #[test]
    fn the_path_names_schema_fields_and_hides_names_the_file_made() {
        let doc = |rest: &str| format!(r#"{{"asset": {{"version": "2.0"}}, {rest}}}"#);
        let rotation = doc(r#""nodes": [{}, {"rotation": [0, 0, 0, 1, 5]}]"#);
        assert_eq!(
            misfit(rotation.as_bytes()).as_deref(),
            Some("nodes[1].rotation")
        );
        let made_up = doc(
            r#""meshes": [{"primitives": [{"attributes": {"SECRET_NAME": "x", "POSITION": 0}}]}]"#,
        );
        let path = misfit(made_up.as_bytes()).unwrap();
        assert!(
            path.starts_with("meshes[0].primitives[0].attributes"),
            "{path}"
        );
        assert!(!path.contains("SECRET"), "{path}");
        assert_eq!(misfit(doc(r#""nodes": []"#).as_bytes()), None);
    }
}
