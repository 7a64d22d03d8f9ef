//! Integers past `u32`: the `gltf` crate reads indices (`"mesh": 4294967296`) and enum codes
//! (`mode`, `componentType`, `target`, sampler filters and wraps) as `value as u32`, so 2³²
//! would wrap to 0 (mesh 0, mode POINTS). Refused here first, naming the field. Only
//! `byteOffset`, `byteLength` and `count` may be larger, and the schema's numbers (a
//! translation, a factor, a camera's `zfar`: JavaScript writes `1e10` as `10000000000`);
//! `extras` and unsupported extensions are not looked into (any JSON is valid there). Walks
//! the JSON without building it.

use std::fmt;

use serde::de::{self, DeserializeSeed, IgnoredAny, MapAccess, SeqAccess, Visitor};

use super::schema_path::is_schema_name;

/// The first integer past `u32::MAX` where glTF allows none, as an error naming its field.
pub(super) fn check(json: &[u8]) -> Result<(), String> {
    let mut path = Vec::new();
    let mut found = None;
    let mut reader = serde_json::Deserializer::from_slice(json);
    let walk = Walk {
        path: &mut path,
        look: true,
        found: &mut found,
    };
    // The JSON was parsed once already: an error here can only repeat that parse's.
    let _ = walk.deserialize(&mut reader);
    match found {
        Some(field) => Err(format!(
            "{field}: a number past the largest glTF allows here ({})",
            u32::MAX
        )),
        None => Ok(()),
    }
}

/// Fields whose values may pass `u32` (the crate reads them as `u64`).
const WIDE: &[&str] = &["byteOffset", "byteLength", "count"];

/// Fields (or arrays) of numbers, not integers, in the schema and the extensions read: a
/// whole number written without a fraction is still their number.
const NUMBERS: &[&str] = &[
    "translation",
    "rotation",
    "scale",
    "matrix",
    "weights",
    "min",
    "max",
    "baseColorFactor",
    "metallicFactor",
    "roughnessFactor",
    "emissiveFactor",
    "alphaCutoff",
    "strength",
    "yfov",
    "znear",
    "zfar",
    "aspectRatio",
    "xmag",
    "ymag",
    "color",
    "intensity",
    "range",
    "innerConeAngle",
    "outerConeAngle",
];

/// Deeper than any of the schema's integers lie (`extensions.KHR_lights_punctual.lights[0]
/// .spot` is five levels): a value this deep is skipped, not walked.
const SCHEMA_DEPTH: usize = 16;

/// Extensions whose contents the loader reads (others are skipped).
const READ_EXTENSIONS: &[&str] = &["KHR_lights_punctual"];

/// One step down a JSON document: an array's element or an object's member.
enum Part {
    Index(usize),
    Key(String),
}

impl Part {
    /// The member's key, if this is one.
    fn key(&self) -> Option<&str> {
        match self {
            Part::Key(k) => Some(k),
            Part::Index(_) => None,
        }
    }
}

struct Walk<'a> {
    /// `meshes`, `[0]`, `primitives`, … down to the value being read.
    path: &'a mut Vec<Part>,
    /// False inside `extras` and unsupported extensions.
    look: bool,
    found: &'a mut Option<String>,
}

impl Walk<'_> {
    /// The path down to the value, a key the file made up shown as `…` (a message never
    /// carries the file's text).
    fn field(&self) -> String {
        let mut out = String::new();
        for part in self.path.iter() {
            match part {
                Part::Index(i) => out.push_str(&format!("[{i}]")),
                Part::Key(key) => {
                    if !out.is_empty() {
                        out.push('.');
                    }
                    out.push_str(if is_schema_name(key) { key } else { "…" });
                }
            }
        }
        out
    }

    fn child(&mut self, part: Part, look: bool) -> Walk<'_> {
        self.path.push(part);
        Walk {
            path: &mut *self.path,
            look,
            found: &mut *self.found,
        }
    }
}

impl<'de> DeserializeSeed<'de> for Walk<'_> {
    type Value = ();

    fn deserialize<D: de::Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        // Skipped at any depth, as the crate skips it; walked, serde_json would stop at 128
        // levels and leave the rest of the file unchecked.
        if self.look && self.found.is_none() && self.path.len() < SCHEMA_DEPTH {
            d.deserialize_any(self)
        } else {
            d.deserialize_ignored_any(IgnoredAny).map(|_| ())
        }
    }
}

impl<'de> Visitor<'de> for Walk<'_> {
    type Value = ();

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("any JSON value")
    }

    fn visit_u64<E>(self, v: u64) -> Result<(), E> {
        // The nearest key: an element of `translation` is one of its numbers.
        let key = self.path.iter().rev().find_map(Part::key);
        let wide = self
            .path
            .last()
            .and_then(Part::key)
            .is_some_and(|k| WIDE.contains(&k))
            || key.is_some_and(|k| NUMBERS.contains(&k));
        if v > u64::from(u32::MAX) && !wide {
            *self.found = Some(self.field());
        }
        Ok(())
    }

    fn visit_i64<E>(self, _: i64) -> Result<(), E> {
        Ok(())
    }

    fn visit_f64<E>(self, _: f64) -> Result<(), E> {
        Ok(())
    }

    fn visit_bool<E>(self, _: bool) -> Result<(), E> {
        Ok(())
    }

    fn visit_str<E>(self, _: &str) -> Result<(), E> {
        Ok(())
    }

    fn visit_unit<E>(self) -> Result<(), E> {
        Ok(())
    }

    fn visit_seq<A: SeqAccess<'de>>(mut self, mut seq: A) -> Result<(), A::Error> {
        let mut i = 0usize;
        loop {
            let look = self.look;
            let element = self.child(Part::Index(i), look);
            let more = seq.next_element_seed(element)?.is_some();
            self.path.pop();
            if !more {
                return Ok(());
            }
            i += 1;
        }
    }

    fn visit_map<A: MapAccess<'de>>(mut self, mut map: A) -> Result<(), A::Error> {
        let in_extensions = self.path.last().and_then(Part::key) == Some("extensions");
        while let Some(key) = map.next_key::<String>()? {
            let look = self.look
                && key != "extras"
                && (!in_extensions || READ_EXTENSIONS.contains(&key.as_str()));
            let value = self.child(Part::Key(key), look);
            map.next_value_seed(value)?;
            self.path.pop();
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers_past_u32_are_refused_by_field() {
        let err = check(br#"{"meshes":[{"primitives":[{"mode":4294967296}]}]}"#).unwrap_err();
        assert!(err.starts_with("meshes[0].primitives[0].mode:"), "{err}");
        let err = check(br#"{"nodes":[{"children":[1, 4294967297]}]}"#).unwrap_err();
        assert!(err.starts_with("nodes[0].children[1]:"), "{err}");
        let err =
            check(br#"{"nodes":[{"extensions":{"KHR_lights_punctual":{"light":4294967296}}}]}"#)
                .unwrap_err();
        assert!(err.contains("KHR_lights_punctual.light"), "{err}");
        assert!(check(br#"{"nodes":[{"mesh":4294967295}]}"#).is_ok());
        // A key the file made up is not shown (a message never carries the file's text).
        let err = check(br#"{"user_token_abc":[{"n":1700000000000}]}"#).unwrap_err();
        assert!(err.starts_with("…[0].…:"), "{err}");
        // Nor one written like an index.
        let err = check(br#"{"[token=abc]":5000000000}"#).unwrap_err();
        assert!(err.starts_with("…:") && !err.contains("token"), "{err}");
    }

    /// serde_json stops a walk at 128 levels, where the crate skips any depth: a deep value
    /// before a field must not leave the field unchecked.
    #[test]
    fn a_deeply_nested_value_leaves_no_field_unchecked() {
        for depth in [20, 127, 128, 5000] {
            let deep = format!("{}{}", "[".repeat(depth), "]".repeat(depth));
            let json = format!(r#"{{"made_up":{deep},"nodes":[{{"mesh":4294967296}}]}}"#);
            let err = check(json.as_bytes()).unwrap_err();
            assert!(err.starts_with("nodes[0].mesh:"), "{depth}: {err}");
            let json = format!(r#"{{"nodes":[{{"mesh":1,"extras":{deep}}}],"made_up":{deep}}}"#);
            assert!(check(json.as_bytes()).is_ok(), "{depth}");
        }
    }

    #[test]
    fn wide_fields_extras_and_other_extensions_may_hold_any_number() {
        let json = br#"{"buffers":[{"byteLength":8589934592}],
            "accessors":[{"count":8589934592,"byteOffset":8589934592}],
            "extras":{"mesh":8589934592},
            "nodes":[{"extras":[8589934592],"extensions":{"EXT_other":{"n":8589934592}}}]}"#;
        assert!(check(json).is_ok());
    }

    #[test]
    fn numbers_written_as_whole_numbers_may_pass_u32() {
        let json = br#"{"nodes":[{"translation":[5000000000,0,0],"scale":[1,1,8589934592]}],
            "cameras":[{"perspective":{"yfov":1,"znear":1,"zfar":10000000000}}],
            "accessors":[{"min":[0],"max":[5000000000]}],
            "materials":[{"emissiveFactor":[5000000000,0,0]}],
            "extensions":{"KHR_lights_punctual":{"lights":[{"type":"point",
                "intensity":5000000000,"range":5000000000}]}}}"#;
        assert_eq!(check(json), Ok(()));
        // Indices among them are still refused: a node's children, a camera's index.
        let err = check(br#"{"nodes":[{"translation":[0,0,0],"camera":4294967296}]}"#);
        assert!(err.unwrap_err().starts_with("nodes[0].camera:"));
    }
}
