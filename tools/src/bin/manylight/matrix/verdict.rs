//! `matrix --max-error N`: which of the matrix's renders fail it. A method fails when it
//! differs from forward in its own cell by more than N/255 or errs; a cell fails when its child
//! did (an error, a panic, a signal, no row) for any reason but the configuration being
//! unavailable here (`"refused"`: no context of that version, no OSMesa). An unsupported
//! method, or a refused configuration, is what that device can do, not a failure.

use serde_json::{json, Value};

/// Marks every rendered method with `"pass"` (and a failed cell with `"pass": false`) and
/// returns one line per failure, naming its implementation, configuration and method.
pub fn mark(rows: &mut [Value], max_error: u8) -> Vec<String> {
    let mut failures = Vec::new();
    let places: Vec<String> = super::table::row_labels(rows)
        .into_iter()
        .map(|(implementation, config)| format!("{implementation} / {config}"))
        .collect();
    for (row, place) in rows.iter_mut().zip(places) {
        if let Some(error) = row["error"].as_str() {
            if row["refused"] != true {
                failures.push(format!("{place}: the cell failed: {error}"));
                row["pass"] = json!(false);
            }
            continue;
        }
        for m in row["methods"].as_array_mut().into_iter().flatten() {
            let name = m["name"].as_str().unwrap_or("?").to_string();
            let failure = match (m["error"].as_str(), m["max_abs_vs_forward"].as_u64()) {
                (Some(e), _) => Some(format!("{place} / {name}: error: {e}")),
                (None, Some(d)) if d > u64::from(max_error) => {
                    Some(format!("{place} / {name}: {d}/255 from forward"))
                }
                (None, Some(_)) => None,
                // Unsupported, or no forward to compare with (its own error is listed).
                (None, None) => continue,
            };
            m["pass"] = json!(failure.is_none());
            failures.extend(failure);
        }
    }
    failures
}

#[cfg(test)]
mod tests {
    use super::mark;
    use serde_json::json;

    fn rows() -> Vec<serde_json::Value> {
        vec![
            json!({"implementation": "Mesa", "config": "ES 2.0", "methods": [
                {"name": "forward", "max_abs_vs_forward": 0},
                {"name": "tiled", "max_abs_vs_forward": 3},
                {"name": "clustered", "max_abs_vs_forward": 2},
                {"name": "deferred", "support": {"status": "unsupported"}},
                {"name": "auto", "error": "shader failed"},
            ]}),
            json!({"implementation": "ANGLE", "config": "ES 3.x", "error": "boom",
                   "methods": []}),
            json!({"implementation": "Mesa", "config": "ES 3.0 driver (capped)",
                   "error": "no ES 3.0", "refused": true, "methods": []}),
        ]
    }

    #[test]
    fn over_the_bound_an_error_and_a_failed_cell_fail_and_nothing_else_does() {
        let mut rows = rows();
        let failures = mark(&mut rows, 2);
        assert_eq!(
            failures,
            [
                "Mesa / ES 2.0 / tiled: 3/255 from forward",
                "Mesa / ES 2.0 / auto: error: shader failed",
                "ANGLE / ES 3.x: the cell failed: boom",
            ]
        );
        let methods = &rows[0]["methods"];
        assert_eq!(methods[0]["pass"], true);
        assert_eq!(methods[1]["pass"], false);
        assert_eq!(methods[2]["pass"], true);
        assert!(
            methods[3]["pass"].is_null(),
            "an unsupported method is not judged"
        );
        assert_eq!(methods[4]["pass"], false);
        assert_eq!(rows[1]["pass"], false);
        assert!(
            rows[2]["pass"].is_null(),
            "a refused configuration is not judged"
        );
    }

    #[test]
    fn a_looser_bound_passes_the_difference() {
        let mut rows = rows();
        let failures = mark(&mut rows, 3);
        assert_eq!(failures.len(), 2, "{failures:?}");
        assert_eq!(rows[0]["methods"][1]["pass"], true);
    }
}
