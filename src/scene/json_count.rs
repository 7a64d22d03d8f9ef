//! What parsing JSON builds, counted in one pass over its bytes before anything is built: each
//! object or array becomes a struct or a collection of its own, hundreds of bytes for the two
//! an empty `{}` takes in the file.

/// What parsing takes an array element or object member besides its container, with room to
/// spare (docs/cli.md).
const PARSED_ELEMENT_BYTES: u64 = 64;

/// Bytes a parse of `containers` objects and arrays and `elements` elements and members takes,
/// at `container_bytes` a container (what the format's parses build for each).
pub(crate) fn parse_bytes(containers: usize, elements: usize, container_bytes: u64) -> u64 {
    containers as u64 * container_bytes + elements as u64 * PARSED_ELEMENT_BYTES
}

/// The `{` and `[`, and the `,`, outside strings.
pub(crate) fn count_containers(json: &[u8]) -> (usize, usize) {
    let mut commas = 0;
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
        } else if b == b',' {
            commas += 1;
        }
    }
    (count, commas)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn objects_and_arrays_are_counted_outside_strings() {
        assert_eq!(count_containers(br#"{"a": [1, {"b": []}]}"#), (4, 1));
        // Brackets and commas in strings, escaped quotes and escaped backslashes.
        assert_eq!(count_containers(br#"{"n": "{[\",[{\\", "m": [}"#), (2, 1));
        assert_eq!(count_containers(b""), (0, 0));
    }
}
