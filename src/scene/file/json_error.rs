//! A scene file's JSON error as a message shows it: the path to the value at fault, with the
//! file's own text in it (keys, unknown names, strings) cut to [`shown::MAX_SHOWN_NAME`].

use serde_path_to_error::Segment;

use crate::scene::shown;

/// The message for `e`: `path: reason`, or the reason alone at the top level.
pub(super) fn message(e: &serde_path_to_error::Error<serde_json::Error>) -> String {
    let inner = plain_types(file_text_cut(&e.inner().to_string()));
    let mut path: Vec<&Segment> = e.path().iter().collect();
    // Where the error came past a value's end (a comment before the last `}`), the path ends
    // in a segment serde could not tell: the position in the reason says where.
    while matches!(path.last(), Some(Segment::Unknown)) {
        path.pop();
    }
    // The reason names an unknown key itself: the path ends at the object holding it.
    if inner.starts_with("unknown field `") && matches!(path.last(), Some(Segment::Map { .. })) {
        path.pop();
    }
    if path.is_empty() {
        return inner;
    }
    // serde says only "trailing characters" of an array with more values than it takes.
    let inner = match inner.strip_prefix("trailing characters") {
        Some(position) => format!("too many values{position}"),
        None => inner,
    };
    format!("{}: {inner}", shown_path(&path))
}

/// `lights[0].position`, each key as [`shown::name`] quotes it.
fn shown_path(path: &[&Segment]) -> String {
    let mut out = String::new();
    for segment in path {
        let name = match segment {
            Segment::Seq { index } => {
                out.push_str(&format!("[{index}]"));
                continue;
            }
            Segment::Map { key } => shown::name(key),
            Segment::Enum { variant } => shown::name(variant),
            Segment::Unknown => "?".to_string(),
        };
        if !out.is_empty() {
            out.push('.');
        }
        out.push_str(&name);
    }
    out
}

/// serde's reason with the file's text it quotes cut: an unknown key or name
/// (`` unknown field `…`, expected … ``) and a string of the wrong type
/// (`invalid type: string "…", expected …`, the string written as Rust's `{:?}`).
fn file_text_cut(reason: &str) -> String {
    for prefix in ["unknown field `", "unknown variant `"] {
        if let Some(rest) = reason.strip_prefix(prefix) {
            // The name may hold anything; serde's expected names hold no "`, expected ".
            if let Some(end) = rest.rfind("`, expected ") {
                return format!("{prefix}{}{}", shown::name(&rest[..end]), &rest[end..]);
            }
        }
    }
    for prefix in ["invalid type: string \"", "invalid value: string \""] {
        if let Some(rest) = reason.strip_prefix(prefix) {
            if let Some(end) = debug_string_end(rest) {
                return format!("{prefix}{}{}", shown::name(&rest[..end]), &rest[end..]);
            }
        }
    }
    reason.to_string()
}

/// `reason` with the Rust number type serde names after its last "expected " (`expected
/// usize`) in plain words; the file's text quoted before it is left as it is.
fn plain_types(reason: String) -> String {
    let Some(at) = reason.rfind("expected ") else {
        return reason;
    };
    let (quoted, expected) = reason.split_at(at);
    let whole = |most: u64| format!("expected a whole number from 0 to {most}");
    let plain = [
        ("expected usize", whole(usize::MAX as u64)),
        ("expected u64", whole(u64::MAX)),
        ("expected u32", whole(u32::MAX.into())),
        ("expected f64", "expected a number".to_string()),
        ("expected f32", "expected a number".to_string()),
    ]
    .into_iter()
    .find_map(|(rust, plain)| Some(format!("{plain}{}", expected.strip_prefix(rust)?)));
    match plain {
        Some(tail) => format!("{quoted}{tail}"),
        None => reason,
    }
}

/// Where a `{:?}`-written string's closing quote lies in `s` (its text after the opening one).
fn debug_string_end(s: &str) -> Option<usize> {
    let mut escaped = false;
    for (i, c) in s.char_indices() {
        match c {
            _ if escaped => escaped = false,
            '\\' => escaped = true,
            '"' => return Some(i),
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quoted_file_text_is_cut_and_serdes_own_text_kept() {
        let long = "k".repeat(300);
        let unknown = format!("unknown field `{long}`, expected one of `a`, `b` at line 1");
        let cut = file_text_cut(&unknown);
        assert!(
            cut.starts_with(&format!("unknown field `{}…", "k".repeat(64))),
            "{cut}"
        );
        assert!(cut.ends_with("(236 characters more)`, expected one of `a`, `b` at line 1"));
        // A name holding serde's own words is cut where serde's text starts, not inside it.
        let name = format!("{}`, expected {}", "a".repeat(40), "b".repeat(40));
        let tricky = file_text_cut(&format!("unknown variant `{name}`, expected `c` at line 1"));
        assert!(
            tricky.ends_with("(28 characters more)`, expected `c` at line 1"),
            "{tricky}"
        );

        let string = format!(r#"invalid type: string "{long}\"q", expected f64 at line 1"#);
        let cut = file_text_cut(&string);
        assert!(cut.starts_with(&format!("invalid type: string \"{}…", "k".repeat(64))));
        assert!(
            cut.ends_with("(239 characters more)\", expected f64 at line 1"),
            "{cut}"
        );
        assert_eq!(debug_string_end(r#"a\\"b"#), Some(3));

        let other = "invalid type: integer `3`, expected a string at line 1 column 9";
        assert_eq!(file_text_cut(other), other);
    }
}
