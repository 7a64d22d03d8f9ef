//! `manylight bench` as a script runs it: a tiny sweep writes every file of the report, with
//! the documented fields and figures that agree with what the renderer measures.

use std::process::Command;

#[test]
fn a_small_sweep_writes_the_report_charts_and_heatmaps() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_manylight"))
        .args([
            "bench",
            "--scenes",
            "plane",
            "--lights",
            "0,16",
            "--es",
            "3",
            "--size",
            "64x36",
            "--frames",
            "0",
            "--cpu-samples",
            "64",
            "--out",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    let log = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{log}");
    for file in [
        "report.json",
        "report.md",
        "error_vs_time.png",
        "evals_vs_lights.png",
        "heatmap-es3-clustered.png",
        "heatmap-es3-lower-bound.png",
        "diff-es3-clustered.png",
    ] {
        assert!(dir.path().join(file).is_file(), "{file} missing: {log}");
    }
    for chart in ["error_vs_time.png", "evals_vs_lights.png"] {
        let img = image::open(dir.path().join(chart)).unwrap();
        assert!(
            img.width() >= 640 && img.height() >= 400,
            "{chart} too small"
        );
    }
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("report.json")).unwrap())
            .unwrap();
    let rows = report["rows"].as_array().unwrap();
    // Five methods at two light counts, plus the knobs at 16 lights.
    assert!(rows.len() >= 10, "{} rows", rows.len());
    for row in rows {
        for field in [
            "scene",
            "method",
            "es",
            "lights",
            "width",
            "height",
            "frame_ms",
            "assign_ms",
            "upload_bytes",
            "light_evals",
            "max_abs_err",
            "rmse",
            "psnr_db",
            "over_1",
            "over_2",
        ] {
            assert!(row.get(field).is_some(), "{field} missing in {row}");
        }
        assert_eq!(
            (row["width"].as_u64(), row["height"].as_u64()),
            (Some(64), Some(36))
        );
        assert!(row["frame_ms"].as_f64().unwrap() > 0.0);
    }
    let row = |method: &str, lights: u64| {
        rows.iter()
            .find(|r| r["method"] == method && r["lights"] == lights && r["knob"] == "default")
            .unwrap_or_else(|| panic!("no {method} row at {lights} lights"))
    };
    // Forward evaluates every light at every covered pixel; clustered no more than forward;
    // nothing evaluates fewer than the lower bound.
    assert_eq!(row("forward", 16)["evals_per_pixel"].as_f64(), Some(16.0));
    let evals = |m: &str| row(m, 16)["light_evals"].as_u64().unwrap();
    assert!(evals("clustered") <= evals("forward"));
    for m in ["forward", "tiled", "clustered", "deferred"] {
        assert!(
            evals(m) >= row(m, 16)["lower_bound_evals"].as_u64().unwrap(),
            "{m}"
        );
    }
    // Zero lights: exactly the reference, no evaluations.
    assert_eq!(row("clustered", 0)["light_evals"].as_u64(), Some(0));
    assert_eq!(row("clustered", 0)["max_abs_err"].as_u64(), Some(0));
    let md = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
    assert!(md.contains("| method | lights | frame ms |"), "{md}");
}
