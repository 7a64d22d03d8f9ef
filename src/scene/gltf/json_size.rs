//! A bound on what parsing a glTF file's JSON builds. The loader parses it several times (the
//! crate's typed document, the node transforms in `f64`, the integers' widths, the materials'
//! texture slots), and each object or array becomes a struct or a collection of its own,
//! hundreds of bytes for the few an empty node `{}` takes in the file; and each element of an
//! array the crate keeps as JSON (an accessor's `min`, `extensionsUsed`) some 35 bytes for the
//! two of `0,`. The objects and arrays, and the elements and members, are counted first, in
//! one pass over the bytes, before anything is built.

use crate::scene::{alloc_probe, json_count};

/// Most JSON objects and arrays a glTF file's JSON may hold: about 600 MB parsed at some 600
/// bytes an empty node, where 2²² let 16 MB of `{},` take 2.5 GB. A node placing a mesh is one
/// (with a translation, a rotation, a scale and children, five): far more than the largest
/// real scenes' tens of thousands of nodes.
pub const MAX_JSON_CONTAINERS: usize = 1 << 20;

/// Most array elements and object members a glTF file's JSON may hold (counted by the commas
/// between them): a node with a matrix is some 20, so 400 000 such nodes and their accessors
/// fit, while a flat array of 10 million numbers (an accessor `min`, say, some 35 bytes each
/// parsed: 2²⁵ of them took 2.2 GB) does not.
pub const MAX_JSON_ELEMENTS: usize = 1 << 23;

/// Refuses JSON holding more than [`MAX_JSON_CONTAINERS`] objects and arrays or more than
/// [`MAX_JSON_ELEMENTS`] elements and members. Brackets and commas inside strings do not
/// count; what is not valid JSON is left for the parser to name.
pub(super) fn check(json: &[u8]) -> Result<JsonSize, String> {
    let (containers, separators) = json_count::count_containers(json);
    if containers > MAX_JSON_CONTAINERS {
        return Err(format!(
            "its JSON holds {containers} objects and arrays, more than the \
             {MAX_JSON_CONTAINERS} a glTF file may (refused before parsing)"
        ));
    }
    let elements = separators.saturating_add(containers);
    if elements > MAX_JSON_ELEMENTS {
        return Err(format!(
            "its JSON holds about {elements} array elements and object members, more than \
             the {MAX_JSON_ELEMENTS} a glTF file may (refused before parsing)"
        ));
    }
    Ok(JsonSize {
        containers,
        elements,
    })
}

/// What a glTF file's JSON holds, counted by [`check`].
#[derive(Debug)]
pub(super) struct JsonSize {
    containers: usize,
    elements: usize,
}

/// What parsing takes an object or array (all the loader's parses together: about 600 bytes
/// an empty node), with room to spare.
const PARSED_CONTAINER_BYTES: u64 = 640;

impl JsonSize {
    /// Refuses JSON whose parses this process cannot allocate now (serde aborts where an
    /// allocation fails): 3 MB of empty nodes, within the limits, takes some 600 MB.
    pub(super) fn check_memory(&self) -> Result<(), String> {
        let bytes = json_count::parse_bytes(self.containers, self.elements, PARSED_CONTAINER_BYTES);
        alloc_probe::ask(
            bytes,
            format_args!(
                "parsing its JSON ({} objects and arrays) takes",
                self.containers
            ),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_flat_array_is_refused_before_parsing() {
        // n zeros: n − 1 commas.
        let zeros = |n: usize| format!("[{}0]", "0,".repeat(n - 1));
        assert!(check(zeros(MAX_JSON_ELEMENTS - 1).as_bytes()).is_ok());
        let past = zeros(MAX_JSON_ELEMENTS + 1);
        let refusal = check(past.as_bytes()).unwrap_err();
        assert!(refusal.contains("array elements"), "{refusal}");
    }

    #[test]
    fn json_past_the_limit_is_refused_before_parsing() {
        let at_limit = format!("[{}]", vec!["{}"; MAX_JSON_CONTAINERS - 1].join(","));
        assert!(check(at_limit.as_bytes()).is_ok());
        let past = format!("[{}]", vec!["{}"; MAX_JSON_CONTAINERS].join(","));
        let refusal = check(past.as_bytes()).unwrap_err();
        assert!(
            refusal.contains(&format!("{} objects and arrays", MAX_JSON_CONTAINERS + 1)),
            "{refusal}"
        );
    }

    /// What the limits are for: the cheapest files that parse into a gigabyte or more, a
    /// few megabytes each, are refused (16 MB of empty nodes took 2.5 GB, 67 MB of an
    /// accessor's `min` 2.2 GB).
    #[test]
    fn files_that_parse_into_a_gigabyte_are_refused() {
        let nodes = format!("[{}]", vec!["{}"; 1_700_000].join(","));
        assert!(check(nodes.as_bytes()).is_err(), "1.7 M empty nodes");
        let zeros = format!("[{}0]", "0,".repeat(30_000_000));
        assert!(check(zeros.as_bytes()).is_err(), "30 M zeros");
    }
}
