//! The names of the report's files: a scene's or method's name made safe for a file name.

/// `name` (a scene or method) as it appears in file names: ASCII letters, digits, `-`, `_`
/// and `.` kept, anything else (spaces, slashes, non-ASCII) becomes `_`.
pub fn file_tag(name: &str) -> String {
    let keep = |c: char| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.');
    let tag: String = name
        .chars()
        .map(|c| if keep(c) { c } else { '_' })
        .collect();
    if tag.is_empty() {
        "scene".to_string()
    } else {
        tag
    }
}

/// "3.0" → "es3".
pub(super) fn es_tag(es: &str) -> String {
    format!("es{}", es.split('.').next().unwrap_or(es))
}

/// A chart of `scene`: `error_vs_time-<scene>.png`, say.
pub fn chart_file(chart: &str, scene: &str) -> String {
    format!("{chart}-{}.png", file_tag(scene))
}

/// The light-evaluation heatmap of `what` (a method or "lower-bound") on `scene`, ES `es`.
pub fn heatmap_file(scene: &str, es: &str, what: &str) -> String {
    format!(
        "heatmap-{}-{}-{}.png",
        file_tag(scene),
        es_tag(es),
        file_tag(what)
    )
}

/// The difference of `method` from the reference on `scene`, ES `es`.
pub fn diff_file(scene: &str, es: &str, method: &str) -> String {
    format!(
        "diff-{}-{}-{}.png",
        file_tag(scene),
        es_tag(es),
        file_tag(method)
    )
}

/// The reference image of `scene`, ES `es`.
pub fn reference_file(scene: &str, es: &str) -> String {
    format!("reference-{}-{}.png", file_tag(scene), es_tag(es))
}
