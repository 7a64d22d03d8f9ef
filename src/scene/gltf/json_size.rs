//! A bound on what parsing a glTF file's JSON builds. The loader parses it several times (the
//! crate's typed document, the node transforms in `f64`, the integers' widths, the materials'
//! texture slots), and each object or array becomes a struct or a collection of its own,
//! hundreds of bytes for the few an empty node `{}` takes in the file. The objects and arrays
//! are counted first, in one pass over the bytes, before anything is built.

/// Most JSON objects and arrays a glTF file's JSON may hold: four for each of the 2²⁰
/// primitives a file may place (a node with a translation, a rotation, a scale and children
/// is five; a primitive, its attributes and its accessors' bounds a few more).
pub const MAX_JSON_CONTAINERS: usize = 1 << 22;

/// Refuses JSON holding more than [`MAX_JSON_CONTAINERS`] objects and arrays. Brackets inside
/// strings do not count; what is not valid JSON is left for the parser to name.
pub(super) fn check(json: &[u8]) -> Result<(), String> {
    let containers = count_containers(json);
    if containers > MAX_JSON_CONTAINERS {
        return Err(format!(
            "its JSON holds {containers} objects and arrays, more than the \
             {MAX_JSON_CONTAINERS} a glTF file may (refused before parsing)"
        ));
    }
    Ok(())
}

/// The `{` and `[` outside strings.
fn count_containers(json: &[u8]) -> usize {
    let (mut count, mut in_string, mut escaped) = (0, false, false);
    for &b in json {
        if in_string {
            if escaped {
                escaped = false;
            } else if b == b'\\' {
                escaped = true;
            } else if b == b'"' {
                in_string = false;
            }
        } else if b == b'"' {
            in_string = true;
        } else if b == b'{' || b == b'[' {
            count += 1;
        }
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn objects_and_arrays_are_counted_outside_strings() {
        assert_eq!(count_containers(br#"{"a": [1, {"b": []}]}"#), 4);
        // Brackets in strings, escaped quotes and escaped backslashes.
        assert_eq!(count_containers(br#"{"n": "{[\"[{\\", "m": [}"#), 2);
        assert_eq!(count_containers(b""), 0);
    }

    #[test]
    fn json_past_the_limit_is_refused_before_parsing() {
        let at_limit = format!("[{}]", vec!["{}"; MAX_JSON_CONTAINERS - 1].join(","));
        assert_eq!(check(at_limit.as_bytes()), Ok(()));
        let past = format!("[{}]", vec!["{}"; MAX_JSON_CONTAINERS].join(","));
        let refusal = check(past.as_bytes()).unwrap_err();
        assert!(
            refusal.contains(&format!("{} objects and arrays", MAX_JSON_CONTAINERS + 1)),
            "{refusal}"
        );
    }
}
