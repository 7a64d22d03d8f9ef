//! `manylight matrix` as CI runs it: real driver restrictions in child processes.

use crate::common;

use std::path::Path;
use std::process::Command;

#[test]
fn matrix_covers_es2_es2_without_float_and_es3_and_every_supported_cell_matches_forward() {
    // Its matrix renders on the system's GL whatever this run's implementation is (below).
    if common::picks_its_own_implementations("the system's matrix") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("m.json");
    let out = Command::new(env!("CARGO_BIN_EXE_manylight"))
        .args([
            "matrix",
            "--size",
            "64x36",
            "--lights",
            "64",
            "--max-error",
            "2",
        ])
        .arg("--json")
        .arg(&json)
        .arg("--out")
        .arg(dir.path())
        // The system's rows (Mesa's restrictions), also in a run on another implementation,
        // whose variable would otherwise name the matrix's one group.
        .env_remove("MANYLIGHT_GLES_LIB")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.starts_with("| implementation | configuration |"),
        "a Markdown table on stdout: {stdout}"
    );
    let rows: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let row = |name: &str| {
        rows.as_array()
            .unwrap()
            .iter()
            .find(|r| r["config"] == name)
            .unwrap_or_else(|| panic!("no row {name}"))
            .clone()
    };
    // Only Mesa reads MESA_* overrides: on another driver their rows are marked refused,
    // with the switch named, and not judged.
    let mesa = row("ES 2.0")["gl_version"]
        .as_str()
        .unwrap()
        .contains("Mesa");
    for name in [
        "ES 2.0",
        "ES 2.0 without float textures",
        "ES 2.0 driver (capped)",
        "ES 3.x as the driver gives it",
    ] {
        let r = row(name);
        let switched = name.contains("without float") || name.contains("capped");
        if switched && !mesa {
            assert_eq!(r["refused"], true, "{name}: {r}");
            let error = r["error"].as_str().unwrap_or_default();
            assert!(
                error.contains("MESA_") && error.contains("not applied"),
                "{error}"
            );
            continue;
        }
        assert!(r["error"].is_null(), "{name}: {}", r["error"]);
        for m in r["methods"].as_array().unwrap() {
            let status = m["support"]["status"].as_str().unwrap();
            if m["name"] == "deferred" && name.starts_with("ES 2.0") {
                assert_eq!(
                    status, "unsupported",
                    "{name}: deferred must be unsupported on ES 2.0"
                );
                assert!(m["support"]["reason"].as_str().unwrap().contains("ES 3.0"));
                continue;
            }
            assert_ne!(status, "unsupported", "{name} {}", m["name"]);
            assert!(
                m["max_abs"].as_u64().unwrap() <= 2,
                "{name} {}: {} / 255 from forward",
                m["name"],
                m["max_abs"]
            );
            assert!(dir.path().join(m["image"].as_str().unwrap()).is_file());
            // What auto ran, as `--stats` says it; the others say nothing of it.
            let choice = m["auto_choice"].as_str();
            if m["name"] == "auto" {
                let choice = choice.unwrap_or_else(|| panic!("{name}: auto says no choice"));
                assert!(
                    ["forward", "clustered", "deferred"].contains(&choice),
                    "{choice}"
                );
            } else {
                assert!(choice.is_none(), "{name} {}", m["name"]);
            }
        }
    }
    // A device without fragment highp: only the methods that need no highp run, forward
    // (and auto choosing it) within the fp16 guarantee of docs/precision.md: an RMSE of 2/255
    // from the highp reference. Single pixels go further (a light a few centimetres from a
    // surface lands off by fp16's position step, docs/precision.md), hence the loose
    // bound on the largest.
    // The same with its lights as RGBA8 records, decoded in fp16 (a Mali-400 has no float
    // textures either): the decoder's constants once overflowed fp16 and drew no light at all.
    for config in [
        "ES 2.0 without fragment highp (played)",
        "ES 2.0 without fragment highp or float textures (played)",
    ] {
        let mediump = row(config);
        assert!(mediump["error"].is_null(), "{}", mediump["error"]);
        assert_eq!(mediump["fragment_highp"], false);
        for m in mediump["methods"].as_array().unwrap() {
            let status = m["support"]["status"].as_str().unwrap();
            let name = m["name"].as_str().unwrap();
            match name {
                "forward" | "auto" => {
                    assert_ne!(status, "unsupported", "{config}: {name}");
                    assert!(m["max_abs"].as_u64().unwrap() <= 32, "{config}: {name}");
                    let rmse = m["rmse"].as_f64().unwrap();
                    assert!(rmse <= 2.0, "{config}: {name}: RMSE {rmse:.2} / 255");
                }
                other => assert_eq!(status, "unsupported", "{other} needs fragment highp"),
            }
        }
    }
    // The restriction is real: without float textures the context reports none.
    if mesa {
        let no_float = row("ES 2.0 without float textures");
        assert_eq!(no_float["float_textures"], false);
        // auto runs the methods it picks from, degraded as they are.
        for m in no_float["methods"].as_array().unwrap() {
            if m["name"] == "auto" {
                assert_eq!(m["support"]["status"], "fallback", "{m}");
            }
        }
        assert!(row("ES 2.0 driver (capped)")["gl_version"]
            .as_str()
            .unwrap()
            .contains("ES 2.0"));
        // The second Mesa driver really ran (GALLIUM_DRIVER is Mesa's too).
        let softpipe = row("ES 3.x on softpipe (second Mesa driver)");
        assert!(
            softpipe["renderer"]
                .as_str()
                .unwrap_or("")
                .contains("softpipe"),
            "{softpipe}"
        );
    }
    // Desktop GL through OSMesa runs the same methods (skipped where libOSMesa is missing).
    let osmesa = row("desktop GL (OSMesa)");
    match osmesa["error"].as_str() {
        Some(err) if err.contains("not available") => common::skip(&format!("OSMesa row: {err}")),
        Some(err) => panic!("OSMesa row failed: {err}"),
        None => {
            assert!(osmesa["gl_version"]
                .as_str()
                .unwrap()
                .contains("Core Profile"));
            for m in osmesa["methods"].as_array().unwrap() {
                assert_eq!(m["support"]["status"], "supported", "OSMesa {}", m["name"]);
                assert!(
                    m["max_abs"].as_u64().unwrap() <= 2,
                    "OSMesa {}: {}",
                    m["name"],
                    m["max_abs"]
                );
            }
        }
    }
    vs_forward_is_each_image_against_its_cells_forward(&rows, dir.path());
    let sheet = image::open(dir.path().join("matrix.png")).unwrap();
    assert!(
        sheet.width() > 64 * 5 && sheet.height() > 36 * 5,
        "contact sheet too small"
    );
}

/// `max_abs_vs_forward` is each method's image against its own cell's forward image, as this
/// test computes it from the images written; under `--max-error 2` every rendered method passes.
fn vs_forward_is_each_image_against_its_cells_forward(rows: &serde_json::Value, out: &Path) {
    let mut compared = 0;
    for row in rows.as_array().unwrap() {
        let methods = row["methods"].as_array().unwrap();
        let image = |m: &serde_json::Value| {
            image::open(out.join(m["image"].as_str().unwrap()))
                .unwrap()
                .to_rgba8()
        };
        let Some(forward) = methods.iter().find(|m| m["name"] == "forward") else {
            continue;
        };
        let forward = image(forward);
        for m in methods.iter().filter(|m| m["image"].is_string()) {
            let expected = manylight::metrics::diff(&forward, &image(m)).max_abs;
            assert_eq!(m["max_abs_vs_forward"], expected, "{} {m}", row["config"]);
            assert_eq!(m["pass"], expected <= 2, "{} {m}", row["config"]);
            compared += 1;
        }
    }
    // Mesa's rows give 20 or more; another driver refuses the rows of Mesa's switches, and
    // its ES 2.0, ES 3.x and no-highp rows give 13.
    assert!(compared >= 13, "only {compared} renders compared");
}

/// As a CI script runs it: `--json /dev/stdout` (as `-`) prints only JSON on stdout (the table
/// goes to stderr);
/// the caller's own Mesa switches do not reach the cells, whose rows are then what their
/// labels say (a capped caller turned the ES 3 rows into failures); and without `--out` no
/// image is written anywhere.
#[test]
fn matrix_json_on_stdout_ignores_the_callers_driver_switches_and_writes_no_images() {
    let dir = tempfile::tempdir().unwrap();
    // A scene file whose name starts with `-`: each cell gets it as one argument, not a flag.
    let scene = "-plane.json";
    let scene_text = r#"{"objects": [{"builtin": "plane"}]}"#;
    std::fs::write(dir.path().join(scene), scene_text).unwrap();
    // No light: each cell's programs are then small for a software GPU to compile, and the
    // lines naming renders over the bound are the verdict's unit tests' (matrix/verdict.rs).
    let out = Command::new(env!("CARGO_BIN_EXE_manylight"))
        .args([
            "matrix",
            "--size",
            "32x18",
            "--lights",
            "0",
            "--json",
            "/dev/stdout",
        ])
        .arg(format!("--scene={scene}"))
        .args(["--max-error", "0"])
        .env("MESA_GLES_VERSION_OVERRIDE", "2.0")
        .env("TMPDIR", dir.path())
        .current_dir(dir.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("stdout is not JSON alone ({e}): {stderr}"));
    // `--max-error 0`: the exit status says whether any render differs from its cell's
    // forward at all, and stderr names each that does.
    let mut over = 0;
    for row in rows.as_array().unwrap() {
        for m in row["methods"].as_array().unwrap() {
            match m["max_abs_vs_forward"].as_u64() {
                Some(d) if d > 0 => {
                    over += 1;
                    let line = format!(
                        "{} / {}: {d}/255 from forward",
                        row["config"].as_str().unwrap(),
                        m["name"].as_str().unwrap()
                    );
                    assert!(stderr.contains(&line), "{line} not in {stderr}");
                }
                Some(_) => assert_eq!(m["pass"], true, "{m}"),
                None => assert!(m["pass"].is_null(), "{m}"),
            }
        }
    }
    assert_eq!(out.status.success(), over == 0, "{over} over: {stderr}");
    assert!(
        stderr.contains("| implementation | configuration |"),
        "the table on stderr: {stderr}"
    );
    assert!(
        stderr.contains("MESA_GLES_VERSION_OVERRIDE=2.0 is not passed"),
        "{stderr}"
    );
    let rows = rows.as_array().unwrap();
    let es3 = rows
        .iter()
        .find(|r| r["config"] == "ES 3.x as the driver gives it")
        .unwrap();
    assert!(es3["error"].is_null(), "{es3}");
    assert_eq!(es3["es"], "3.0", "{es3}");
    for row in rows {
        assert!(row["implementation"].is_string(), "{row}");
        assert!(row["env"].is_array(), "{row}");
        for m in row["methods"].as_array().unwrap() {
            assert!(m["image"].is_null(), "an image without --out: {m}");
        }
    }
    let written: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .filter(|name| name != scene)
        .collect();
    assert!(written.is_empty(), "files written: {written:?}");
    // `-` too (no light: only where the JSON goes matters here).
    let out = Command::new(env!("CARGO_BIN_EXE_manylight"))
        .args([
            "matrix", "--scene", "plane", "--size", "16x9", "--lights", "0",
        ])
        .args(["--json", "-"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("`-`: stdout is not JSON alone ({e}): {stderr}"));
    assert!(rows.as_array().is_some_and(|r| !r.is_empty()), "{rows}");
    assert!(
        stderr.contains("| implementation | configuration |"),
        "{stderr}"
    );
}

/// A `--gles-lib` folder that cannot serve is an error of the matrix, before any cell runs.
#[test]
fn matrix_refuses_a_gles_lib_that_is_not_a_folder_before_any_cell() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nowhere");
    let out = Command::new(env!("CARGO_BIN_EXE_manylight"))
        .args(["matrix", "--gles-lib", "system", "--gles-lib"])
        .arg(&missing)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("nowhere") && stderr.contains("not a folder"),
        "{stderr}"
    );
    assert!(
        out.stdout.is_empty(),
        "no table: {}",
        String::from_utf8_lossy(&out.stdout)
    );
}

/// `manylight matrix-cell` on an ES 3.0 context, the plane at 16×9 with 4 lights, then `rest`.
fn matrix_cell(rest: &[&str]) -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_manylight"));
    cmd.args([
        "matrix-cell",
        "--es",
        "3",
        "--scene",
        "plane",
        "--size",
        "16x9",
    ])
    .args(["--lights", "4"])
    .args(rest);
    cmd
}

/// A configuration the driver cannot give is a row marked `refused`, which `--max-error` does
/// not count; any other failure of a cell is not marked, and fails the gate (the verdict's
/// unit tests). Here a driver capped at ES 2.0 asked for ES 3.0.
#[test]
fn a_cell_the_driver_cannot_give_is_marked_refused() {
    if common::other_implementation_than_mesa("MESA_GLES_VERSION_OVERRIDE") {
        return;
    }
    let out = matrix_cell(&["--tag", "t"])
        .env("MESA_GLES_VERSION_OVERRIDE", "2.0")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let row: serde_json::Value = serde_json::from_str(stdout.lines().last().unwrap_or_default())
        .unwrap_or_else(|e| panic!("no JSON row ({e}): {stdout}"));
    assert_eq!(row["refused"], true, "{row}");
    assert!(
        row["error"]
            .as_str()
            .unwrap()
            .contains("OpenGL ES 3.0 is not available"),
        "{row}"
    );
}

/// The hidden child's `--tag` starts its image files' names inside `--out`: `../x` wrote
/// outside it. A tag that is not one plain name is a usage error, and nothing is written.
#[test]
fn a_cell_tag_that_leaves_its_folder_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("mc/a")).unwrap();
    for tag in ["../../escape", "a/b", "..", ""] {
        let out = matrix_cell(&["--tag", tag, "--out", "mc/a"])
            .current_dir(dir.path())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{tag}: {stderr}");
        assert!(stderr.contains("--tag"), "{tag}: {stderr}");
    }
    let written: Vec<_> = walk(dir.path());
    assert!(written.is_empty(), "{written:?}");
}

/// Every file under `dir`.
fn walk(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        if entry.path().is_dir() {
            files.extend(walk(&entry.path()));
        } else {
            files.push(entry.path());
        }
    }
    files
}

/// One implementation named twice (`DIR`, then `DIR/.`) runs its rows once, with a warning: it
/// ran them twice, and `system` twice wrote both OSMesa rows' pictures under one name.
#[test]
fn an_implementation_named_twice_runs_once() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["libEGL.so.1", "libGLESv2.so.2"] {
        std::fs::write(dir.path().join(name), b"not a library").unwrap();
    }
    let run = |folders: &[&Path]| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_manylight"));
        cmd.arg("matrix");
        for folder in folders {
            cmd.arg("--gles-lib").arg(folder);
        }
        let out = cmd
            .args(["--size", "16x9", "--lights", "4", "--json", "-"])
            .env_remove("MANYLIGHT_GLES_LIB")
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        let rows: Vec<serde_json::Value> = serde_json::from_slice(&out.stdout)
            .unwrap_or_else(|e| panic!("no JSON ({e}): {stderr}"));
        (rows.len(), stderr)
    };
    let (once, said) = run(&[dir.path()]);
    assert!(once > 0 && !said.contains("given before"), "{said}");
    let (twice, said) = run(&[dir.path(), &dir.path().join(".")]);
    assert_eq!(twice, once, "{said}");
    assert!(
        said.contains("names an implementation given before"),
        "{said}"
    );
}

/// Libraries that cannot load are not a configuration this machine cannot give: every cell of
/// their group fails, unmarked, and `--max-error` fails on them (it passed a broken machine
/// when any failure to make a context read as a refusal). `MANYLIGHT_GLES_LIB` names the
/// group when no `--gles-lib` does, as for every other command.
#[test]
fn libraries_that_cannot_load_fail_the_gate_whether_named_by_flag_or_variable() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["libEGL.so.1", "libGLESv2.so.2"] {
        std::fs::write(dir.path().join(name), b"not a library").unwrap();
    }
    let folder = dir.path().to_str().unwrap();
    let small = [
        "--size",
        "16x9",
        "--lights",
        "4",
        "--json",
        "-",
        "--max-error",
        "2",
    ];
    let by_flag = Command::new(env!("CARGO_BIN_EXE_manylight"))
        .args(["matrix", "--gles-lib", folder])
        .args(small)
        .env_remove("MANYLIGHT_GLES_LIB")
        .output()
        .unwrap();
    let by_variable = Command::new(env!("CARGO_BIN_EXE_manylight"))
        .arg("matrix")
        .args(small)
        .env("MANYLIGHT_GLES_LIB", folder)
        .output()
        .unwrap();
    for (how, out) in [("--gles-lib", by_flag), ("MANYLIGHT_GLES_LIB", by_variable)] {
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{how}: {stderr}");
        let rows: Vec<serde_json::Value> = serde_json::from_slice(&out.stdout)
            .unwrap_or_else(|e| panic!("{how}: no JSON ({e}): {stderr}"));
        assert!(!rows.is_empty(), "{how}");
        for row in &rows {
            assert_eq!(row["gles_lib"], folder, "{how}: {row}");
            assert!(row["refused"] != true, "{how}: a refusal: {row}");
            assert!(
                row["error"]
                    .as_str()
                    .is_some_and(|e| e.contains("cannot load")),
                "{how}: {row}"
            );
        }
    }
}
