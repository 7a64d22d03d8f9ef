//! What `--frames N --stats` reports: medians and spreads of the timed frames' times, and the
//! counters of the last timed frame.

use super::cli::stats;
use crate::common::cli::{manylight, text};

#[test]
fn timed_frames_report_their_spread() {
    let dir = tempfile::tempdir().unwrap();
    let out = manylight(
        &[
            "render", "--size", "32x18", "--lights", "64", "--frames", "12", "--stats", "s.json",
        ],
        &[],
        dir.path(),
    );
    let msg = text(&out);
    assert!(out.status.success(), "{msg}");
    assert!(msg.contains("p99"), "{msg}");
    let s = stats(&dir.path().join("s.json"));
    for key in ["frame_ms_spread", "assign_ms_spread"] {
        let spread = &s[key];
        assert_eq!(spread["frames"], 12, "{key}: {spread}");
        let at = |q: &str| spread[q].as_f64().unwrap();
        assert!(at("p50") <= at("p95") && at("p95") <= at("p99") && at("p99") <= at("max"));
    }
    assert_eq!(s["frame_ms"], s["frame_ms_spread"]["p50"]);
    // The run's programs, its untimed first frame's included, as one frame alone builds them
    // (the moving built-in's timed frames reported 0).
    let out = manylight(
        &[
            "render", "--size", "32x18", "--lights", "64", "--frames", "0", "--stats", "one.json",
        ],
        &[],
        dir.path(),
    );
    assert!(out.status.success(), "{}", text(&out));
    let one = stats(&dir.path().join("one.json"));
    assert!(one["programs_built"].as_u64().unwrap() > 0, "{one}");
    assert_eq!(s["programs_built"], one["programs_built"]);
    // Every timed frame of moving lights assigns and uploads its lists, the first too: it was
    // posed at the warm-up frame's time and redrew its lists, so at the default two frames
    // the median assignment read 0 ms and the median upload 0 bytes.
    let out = manylight(
        &["render", "--size", "32x18", "--stats", "two.json"],
        &[],
        dir.path(),
    );
    assert!(out.status.success(), "{}", text(&out));
    let two = stats(&dir.path().join("two.json"));
    let uploads = &two["upload_bytes_spread"];
    assert_eq!(uploads["frames"], 2, "{two}");
    assert!(uploads["p50"].as_f64().unwrap() > 0.0, "{uploads}");
    assert!(two["assign_ms"].as_f64().unwrap() > 0.0, "{two}");
    assert_eq!(two["lists_reused"], false, "{two}");
}

/// The counters beside the medians are the last timed frame's, at T + (N − 1) / fps: the
/// frame the times settled in (the automatic grid calibrates on the way), not the picture's.
#[test]
fn timed_frames_count_the_last_frame() {
    let dir = tempfile::tempdir().unwrap();
    let run = |frames: &str, time: &str, file: &str| {
        let args = [
            "render", "--size", "96x54", "--lights", "64", "--grid", "16", "--fps", "2",
            "--frames", frames, "--time", time, "--stats", file,
        ];
        let out = manylight(&args, &[], dir.path());
        assert!(out.status.success(), "{}", text(&out));
        stats(&dir.path().join(file))
    };
    let timed = run("4", "0", "timed.json");
    let first = run("0", "0", "first.json");
    let last = run("0", "1.5", "last.json");
    let counters = |s: &serde_json::Value| {
        [
            "visible_lights",
            "nonempty_clusters",
            "avg_lights_per_nonempty",
            "max_lights_per_cluster",
            "assign_runs",
        ]
        .map(|key| s[key].clone())
    };
    assert_eq!(counters(&timed), counters(&last), "{timed}\n{last}");
    assert_ne!(
        counters(&first),
        counters(&last),
        "the lights moved by the last frame"
    );
}

/// A still scene is the same picture at any `--time`, and times the same way: its timed frames
/// assign again, as at time 0. A `--time` used to draw it frame by frame, each reusing the last
/// frame's lists, so it reported an assignment of 0 ms.
#[test]
fn a_still_scene_times_the_same_at_any_time() {
    let dir = tempfile::tempdir().unwrap();
    let floor = "v -5 0 -5\nv -5 0 5\nv 5 0 5\nv 5 0 -5\nf 1 2 3 4\n";
    std::fs::write(dir.path().join("floor.obj"), floor).unwrap();
    let run = |time: &str, file: &str| {
        let args = [
            "render",
            "--scene",
            "floor.obj",
            "--size",
            "64x36",
            "--lights",
            "32",
            "--method",
            "clustered",
            "--frames",
            "3",
            "--time",
            time,
            "--stats",
            file,
        ];
        let out = manylight(&args, &[], dir.path());
        assert!(out.status.success(), "{}", text(&out));
        stats(&dir.path().join(file))
    };
    for time in ["0", "2.5"] {
        let s = run(time, "s.json");
        assert!(s["visible_lights"].as_u64().unwrap() > 0, "{time}: {s}");
        assert!(s["assign_ms"].as_f64().unwrap() > 0.0, "{time}: {s}");
        assert_eq!(
            s["upload_bytes_spread"],
            serde_json::Value::Null,
            "{time}: {s}"
        );
    }
}
