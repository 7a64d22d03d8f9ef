//! The matrix's Markdown table: a row per configuration, a column per method.

use serde_json::Value;

/// Each row's implementation as the table and sheet show it, and its configuration: the
/// implementation's family, with the `--gles-lib` it came from where another row's
/// implementation of the same family came from elsewhere (two Mesa builds).
pub(super) fn row_labels(rows: &[Value]) -> Vec<(String, &str)> {
    let family = |row: &Value| {
        row["implementation"]
            .as_str()
            .or(row["gles_lib"].as_str())
            .unwrap_or("?")
            .to_string()
    };
    let lib = |row: &Value| row["gles_lib"].as_str().unwrap_or("?").to_string();
    rows.iter()
        .map(|row| {
            let shared = rows
                .iter()
                .any(|other| family(other) == family(row) && lib(other) != lib(row));
            let implementation = if shared {
                format!("{} ({})", family(row), lib(row))
            } else {
                family(row)
            };
            (implementation, row["config"].as_str().unwrap_or("?"))
        })
        .collect()
}

/// What a row with an `error` is: a configuration this machine cannot give, or a failure.
pub(super) fn row_failure(row: &Value) -> &'static str {
    if row["refused"] == true {
        "unavailable"
    } else {
        "failed"
    }
}

/// The rows as a Markdown table, a line per (configuration, method); a failed or refused
/// configuration takes one line saying why.
pub(super) fn markdown(rows: &[Value]) -> String {
    let mut s = String::from(concat!(
        "| implementation | configuration | context | method | support | max abs vs forward ",
        "| max abs vs reference | pixels > 2/255 | frame ms |\n",
        "|---|---|---|---|---|---|---|---|---|\n"
    ));
    for (row, (implementation, config)) in rows.iter().zip(row_labels(rows)) {
        let config = &format!("{implementation} | {config}");
        if let Some(err) = row["error"].as_str() {
            let what = row_failure(row);
            s += &format!("| {config} | — | — | {what}: {err} | | | | |\n");
            continue;
        }
        let context = match row["max_samples"].as_i64() {
            Some(n) if n > 1 => format!(
                "{}, MSAA up to {n}×",
                row["gl_version"].as_str().unwrap_or("?")
            ),
            _ => format!("{}, no MSAA", row["gl_version"].as_str().unwrap_or("?")),
        };
        for m in row["methods"].as_array().into_iter().flatten() {
            let status = m["support"]["status"].as_str().unwrap_or("?");
            let support = match (m["error"].as_str(), m["support"]["reason"].as_str()) {
                (Some(e), _) => format!("error: {e}"),
                (None, Some(r)) => format!("{status}: {r}"),
                (None, None) => status.to_string(),
            };
            let num = |k: &str, digits: usize| {
                m[k].as_f64()
                    .map_or(String::new(), |v| format!("{v:.digits$}"))
            };
            let name = m["name"].as_str().unwrap_or("?");
            let method = match m["auto_choice"].as_str() {
                Some(choice) => format!("{name} → {choice}"),
                None => name.to_string(),
            };
            s += &format!(
                "| {config} | {context} | {method} | {support} | {} | {} | {} | {} |\n",
                num("max_abs_vs_forward", 0),
                num("max_abs", 0),
                m["over_2"]
                    .as_f64()
                    .map_or(String::new(), |v| format!("{:.3} %", v * 100.0)),
                num("frame_ms", 1),
            );
        }
    }
    s
}
