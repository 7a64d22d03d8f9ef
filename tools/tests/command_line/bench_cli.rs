//! `manylight bench` as a script runs it: a tiny sweep writes every file of the report, with
//! the documented fields and figures that agree with what the renderer measures.

use std::process::Command;

use crate::common;

/// Runs `manylight bench` with `args` and the output folder; panics with its output if it
/// fails.
fn bench(args: &[&str], dir: &std::path::Path) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_manylight"))
        .arg("bench")
        .args(args)
        .arg("--out")
        .arg(dir)
        .output()
        .unwrap();
    let log = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{log}");
    log
}

#[test]
fn a_small_sweep_writes_the_report_charts_and_heatmaps() {
    let dir = tempfile::tempdir().unwrap();
    let log = bench(
        &[
            "--scenes",
            "plane",
            "--lights",
            "0,16",
            "--es",
            "3",
            "--size",
            "64x36",
            "--frames",
            "1",
            "--cpu-samples",
            "64",
            "--animated-frames",
            "6",
        ],
        dir.path(),
    );
    for file in [
        "report.json",
        "report.md",
        "error_vs_time-plane.png",
        "evals_vs_lights-plane.png",
        "heatmap-plane-es3-clustered.png",
        "heatmap-plane-es3-lower-bound.png",
        "diff-plane-es3-clustered.png",
        "reference-plane-es3.png",
    ] {
        assert!(dir.path().join(file).is_file(), "{file} missing: {log}");
    }
    // stderr is a pipe here: progress comes as plain lines, one a step, as the run goes.
    assert!(log.contains("[1/"), "no progress lines: {log}");
    assert!(log.contains("cell_cap"), "{log}");
    assert!(!log.contains("light references left out"), "{log}");
    for chart in ["error_vs_time-plane.png", "evals_vs_lights-plane.png"] {
        let img = image::open(dir.path().join(chart)).unwrap();
        assert!(
            img.width() >= 640 && img.height() >= 400,
            "{chart} too small"
        );
    }
    // The 64×36 maps are enlarged 4× to 256 pixels wide, with a legend panel under them and
    // nothing beside them (a long caption wraps rather than widening the image).
    for picture in [
        "heatmap-plane-es3-forward.png",
        "diff-plane-es3-clustered.png",
    ] {
        let img = image::open(dir.path().join(picture)).unwrap();
        assert_eq!(img.width(), 256, "{picture}");
        assert!(img.height() > 144 + 40, "{picture} has no legend");
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
        // `--frames 1`; auto says what it drew with, no other method does, nor auto a frame
        // without lights (drawn ambient-only, without a method).
        assert_eq!(row["timed_frames"].as_u64(), Some(1), "{row}");
        let auto = row["method"] == "auto" && row["lights"] != 0;
        assert_eq!(row["auto_choice"].is_string(), auto, "{row}");
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
    // The animated workload: every method, at the knobs' light count (16), with its spread
    // and, for the culled methods, an error against forward within 2/255.
    let animated = report["animated"].as_array().unwrap();
    assert_eq!(animated.len(), 5, "{animated:?}");
    for r in animated {
        assert_eq!(r["lights"], 16);
        let spread = &r["frame_ms"];
        assert_eq!(spread["frames"], 6, "{r}");
        assert!(spread["p50"].as_f64() <= spread["p99"].as_f64());
        assert!(r["p99_over_p50"].as_f64().unwrap() >= 1.0, "{r}");
        match r["max_abs_err_vs_forward"].as_u64() {
            None => assert_eq!(r["method"], "forward"),
            Some(e) => assert!(e <= 2, "{r}"),
        }
    }
    assert!(
        md.contains("## Animated workload") && md.contains("| p99/p50 |"),
        "{md}"
    );
}

#[test]
fn every_scene_gets_its_own_charts_heatmaps_and_differences() {
    let dir = tempfile::tempdir().unwrap();
    let log = bench(
        &[
            "--scenes",
            "plane,pillars",
            "--lights",
            "0,16",
            "--es",
            "3",
            "--methods",
            "forward,clustered,auto",
            "--size",
            "48x27",
            "--frames",
            "1",
            "--cpu-samples",
            "16",
        ],
        dir.path(),
    );
    let md = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
    for scene in ["plane", "pillars"] {
        let mut files = vec![
            format!("error_vs_time-{scene}.png"),
            format!("evals_vs_lights-{scene}.png"),
            format!("reference-{scene}-es3.png"),
            format!("heatmap-{scene}-es3-lower-bound.png"),
        ];
        for method in ["forward", "clustered", "auto"] {
            files.push(format!("heatmap-{scene}-es3-{method}.png"));
            files.push(format!("diff-{scene}-es3-{method}.png"));
        }
        for file in &files {
            assert!(dir.path().join(file).is_file(), "{file} missing: {log}");
            assert!(
                md.contains(&format!("]({file})")),
                "report.md misses {file}:\n{md}"
            );
        }
    }
    // Nothing is left under the old, scene-less names.
    for old in [
        "error_vs_time.png",
        "heatmap-es3-clustered.png",
        "diff-es3-clustered.png",
    ] {
        assert!(!dir.path().join(old).exists(), "{old}");
    }
    // The two scenes' pictures are different pictures.
    let read = |f: &str| std::fs::read(dir.path().join(f)).unwrap();
    assert_ne!(
        read("reference-plane-es3.png"),
        read("reference-pillars-es3.png")
    );
    assert_ne!(
        read("heatmap-plane-es3-clustered.png"),
        read("heatmap-pillars-es3-clustered.png")
    );
    // The "—" of the 0-light rows (no lower bound to divide by) is explained.
    assert!(md.contains("| — |"), "{md}");
    assert!(md.contains("A \"—\" means"), "{md}");
}

#[test]
fn knobs_a_context_cannot_run_are_skipped_not_fatal() {
    // llvmpipe's ES 2.0 has no multisampling: the msaa knob is skipped with a warning.
    let dir = tempfile::tempdir().unwrap();
    let log = bench(
        &[
            "--scenes",
            "plane",
            "--lights",
            "64",
            "--es",
            "2",
            "--size",
            "32x18",
            "--frames",
            "1",
            "--cpu-samples",
            "16",
            "--animated-frames",
            "0",
        ],
        dir.path(),
    );
    // Where ES 2.0 has GL_EXT_multisampled_render_to_texture (NVIDIA) the knob runs instead.
    let es2_msaa = {
        let mut es2 = common::Gpu::new(manylight::EsVersion::Es2);
        es2.r().caps().max_samples >= 4
    };
    assert_eq!(log.contains("msaa=4: skipped"), !es2_msaa, "{log}");
    // 64 lights overflow the cell_cap=16 knob's cap on purpose: its rows count them, and no
    // renderer warning reads like a failure.
    assert!(!log.contains("light references left out"), "{log}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("report.json")).unwrap())
            .unwrap();
    let rows = report["rows"].as_array().unwrap();
    assert_eq!(
        rows.iter().any(|r| r["knob"] == "msaa=4"),
        es2_msaa,
        "{rows:?}"
    );
    assert!(rows.iter().any(|r| r["knob"] == "cell_cap=16"), "{rows:?}");
    // Deferred needs ES 3.0: no row, and a warning says why (its rows vanished silently).
    assert!(!rows.iter().any(|r| r["method"] == "deferred"), "{rows:?}");
    assert!(log.contains("ES 2.0 deferred: skipped"), "{log}");
}

/// Two scenes whose files share a stem (`a/room.obj`, `c/room.obj`; or a built-in twice) were
/// both labelled `room`: the second's pictures overwrote the first's and the charts merged them
/// into one series. The sweep now refuses them before it measures anything.
#[test]
fn scenes_that_would_report_under_one_name_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    for sub in ["a", "c"] {
        std::fs::create_dir(dir.path().join(sub)).unwrap();
        let scene = r#"{"objects": [{"builtin": "plane"}]}"#;
        std::fs::write(dir.path().join(sub).join("room.json"), scene).unwrap();
    }
    for scenes in ["a/room.json,c/room.json", "plane,plane"] {
        let out = Command::new(env!("CARGO_BIN_EXE_manylight"))
            .args(["bench", "--scenes", scenes, "--lights", "8", "--es", "3"])
            .args(["--size", "16x9", "--no-knobs", "--animated-frames", "0"])
            .arg("--out")
            .arg(dir.path().join("report"))
            .current_dir(dir.path())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{scenes}: {stderr}");
        assert!(stderr.contains("both report as"), "{scenes}: {stderr}");
        let measured = std::fs::read_dir(dir.path().join("report"))
            .map(|files| files.count())
            .unwrap_or(0);
        assert_eq!(measured, 0, "{scenes}: files written before the refusal");
    }
}

/// A report file that cannot be written (a folder named `report.json` in the output folder)
/// ends the sweep before it measures anything: it was found once every row was measured.
#[test]
fn a_report_file_in_the_way_is_refused_before_the_sweep() {
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("report");
    std::fs::create_dir_all(report.join("report.json")).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_manylight"))
        .args(["bench", "--scenes", "plane", "--lights", "8", "--es", "3"])
        .args(["--size", "16x9", "--no-knobs", "--animated-frames", "0"])
        .arg("--out")
        .arg(&report)
        .current_dir(dir.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(
        stderr.contains("report.json") && stderr.contains("a folder is in the way"),
        "{stderr}"
    );
    // Nothing measured: only the folder in the way is there.
    assert_eq!(std::fs::read_dir(&report).unwrap().count(), 1, "{stderr}");
}

/// A report file that is a FIFO: without a reader the sweep ends at once (its check opened
/// it and waited for one forever); with a reader that stops at its first end of file, as
/// `cat` does, the reader gets the whole report (the check's open and close ended it, and the
/// report then found no reader).
#[test]
#[cfg(unix)]
fn a_report_fifo_is_refused_without_a_reader_and_reaches_one_that_waits() {
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("report");
    std::fs::create_dir_all(&report).unwrap();
    let fifo = report.join("report.json");
    let made = Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|s| s.success()) {
        eprintln!("no mkfifo here: nothing to check");
        return;
    }
    let run = || {
        let child = Command::new(env!("CARGO_BIN_EXE_manylight"))
            .args(["bench", "--scenes", "plane", "--lights", "8", "--es", "3"])
            .args(["--methods", "forward", "--size", "16x9", "--frames", "1"])
            .args(["--no-knobs", "--animated-frames", "0", "--out"])
            .arg(&report)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        common::cli::wait_with_timeout(child, "bench", std::time::Duration::from_secs(60))
    };
    let out = run();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("no process reads"), "{stderr}");
    // A reader blocked in its open until a writer comes, reading to the first end of file.
    // Whether it is in its open when the sweep starts cannot be seen from here: a sweep that
    // found none is tried again with a new reader.
    for _ in 0..20 {
        let path = fifo.clone();
        let reader = std::thread::spawn(move || std::fs::read(path).unwrap());
        std::thread::sleep(std::time::Duration::from_millis(200));
        let out = run();
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        if out.status.success() {
            let json: serde_json::Value = serde_json::from_slice(&reader.join().unwrap())
                .unwrap_or_else(|e| panic!("the reader got no report ({e}): {stderr}"));
            assert_eq!(json["rows"].as_array().map(Vec::len), Some(1), "{json}");
            return;
        }
        assert!(stderr.contains("no process reads"), "{stderr}");
        // The reader may still wait in its open: a writer's open and close lets it go.
        use std::os::unix::fs::OpenOptionsExt;
        let _ = (std::fs::OpenOptions::new().write(true))
            .custom_flags(libc::O_NONBLOCK)
            .open(&fifo);
        reader.join().unwrap();
    }
    panic!("no sweep wrote its report to a reader waiting on the FIFO");
}

/// Edge values of the sweep: `--cpu-samples 0` (no CPU reference, documented as "—") panicked
/// at its first reference; an output folder whose name is not Unicode panicked once every row
/// was measured, before the report; a light count past what forward's loop holds here (no
/// reference over every light) ended the whole sweep at its counts instead of being skipped;
/// a light count past a scene's limit, and no timed frames (a row's time would be one cold
/// frame's), are usage errors before anything runs.
#[test]
fn edge_values_of_the_sweep_are_measured_skipped_or_refused_not_fatal() {
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join(std::ffi::OsStr::from_bytes(b"r\xff"));
    let forward_max = {
        let mut es3 = common::Gpu::new(manylight::EsVersion::Es3);
        manylight::methods::forward::max_lights(es3.r().caps()) as usize
    };
    // A count past forward's loop, where one lies within the scenes' limit (NVIDIA's loop
    // holds every count a scene may have).
    let past = (forward_max < manylight::scene::input::MAX_LIGHTS).then(|| forward_max + 1);
    let lights = match past {
        Some(past) => format!("8,{past}"),
        None => "8".to_string(),
    };
    let run = Command::new(env!("CARGO_BIN_EXE_manylight"))
        .args([
            "bench", "--scenes", "plane", "--lights", &lights, "--es", "3",
        ])
        .args(["--methods", "forward", "--size", "16x9", "--frames", "1"])
        .args(["--cpu-samples", "0", "--no-knobs", "--animated-frames", "0"])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let log = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{log}");
    match past {
        Some(past) => assert!(log.contains(&format!("{past} lights: skipped")), "{log}"),
        None => eprintln!("forward holds {forward_max} lights here: no count to skip"),
    }
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let rows = report["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 1, "{rows:?}");
    assert_eq!(rows[0]["lights"], 8);
    assert_eq!(rows[0]["cpu_samples"], 0);
    assert!(rows[0]["cpu_max_abs_err"].is_null(), "{:?}", rows[0]);
    // Past the scene limit: refused as a usage error naming the flag.
    let too_many = (manylight::scene::input::MAX_LIGHTS + 1).to_string();
    let refused = Command::new(env!("CARGO_BIN_EXE_manylight"))
        .args([
            "bench",
            "--scenes",
            "plane",
            "--lights",
            &format!("8,{too_many}"),
        ])
        .arg("--out")
        .arg(dir.path().join("never"))
        .output()
        .unwrap();
    let log = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(refused.status.code(), Some(2), "{log}");
    assert!(log.contains("--lights") && log.contains(&too_many), "{log}");
    assert!(!dir.path().join("never").exists());
    let untimed = Command::new(env!("CARGO_BIN_EXE_manylight"))
        .args([
            "bench", "--scenes", "plane", "--lights", "8", "--frames", "0",
        ])
        .arg("--out")
        .arg(dir.path().join("never"))
        .output()
        .unwrap();
    let log = String::from_utf8_lossy(&untimed.stderr);
    assert_eq!(untimed.status.code(), Some(2), "{log}");
    assert!(log.contains("--frames"), "{log}");
    assert!(!dir.path().join("never").exists());
}

/// A value listed twice is measured once, with a warning (`--methods forward,forward` gave
/// every row twice).
#[test]
fn values_listed_twice_are_measured_once() {
    let dir = tempfile::tempdir().unwrap();
    let log = bench(
        &[
            "--scenes",
            "plane",
            "--lights",
            "8,8",
            "--es",
            "3,3",
            "--methods",
            "forward,forward",
            "--size",
            "32x18",
            "--frames",
            "1",
            "--cpu-samples",
            "0",
            "--animated-frames",
            "0",
            "--no-knobs",
        ],
        dir.path(),
    );
    for flag in ["--lights", "--es", "--methods"] {
        assert!(
            log.contains(&format!("{flag} lists a value more than once")),
            "{log}"
        );
    }
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("report.json")).unwrap())
            .unwrap();
    assert_eq!(report["rows"].as_array().unwrap().len(), 1, "{report}");
}
