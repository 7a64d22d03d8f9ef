//! Every method against plain forward on the other GLES implementations a phone or browser
//! ships (docs/drivers.md): SwiftShader and ANGLE, fetched by `scripts/fetch-gles` into the
//! folder `MANYLIGHT_GLES_DIR` names. Each case runs `manylight matrix-cell` in a child
//! process with `MANYLIGHT_GLES_LIB` pointing at one implementation (one implementation per
//! process), ANGLE under `xvfb-run` (it needs an X display). Without the variable at build
//! time these tests are listed as ignored with the command that fetches the libraries. In a
//! run of the suite on another implementation (`MANYLIGHT_GLES_LIB` set) they do nothing:
//! their children would do the same work as in the run on the system's GL; there one test
//! checks instead that the run renders with the implementation its folder holds. Where the
//! whole suite runs on each implementation as well (`.ci/run` says so with
//! `MANYLIGHT_SUITE_ON_EACH_GLES`), the comparisons of every method with forward leave it to
//! those runs.
#![cfg_attr(not(manylight_gles), allow(dead_code, unused_imports))]

use std::path::PathBuf;
use std::process::Command;

use serde_json::Value;

mod common;

const BIN: &str = env!("CARGO_BIN_EXE_manylight");

fn gles_dir() -> PathBuf {
    let dir = std::env::var_os("MANYLIGHT_GLES_DIR")
        .map(PathBuf::from)
        .expect("MANYLIGHT_GLES_DIR is not set (scripts/fetch-gles prints the line that sets it)");
    assert!(
        dir.join("swiftshader").is_dir() && dir.join("angle").is_dir(),
        "MANYLIGHT_GLES_DIR names {}, which lacks swiftshader/ or angle/ (scripts/fetch-gles makes them)",
        dir.display()
    );
    dir
}

/// Whether this is the suite's run on another implementation, where these tests do nothing
/// (see the top).
fn in_another_implementations_run() -> bool {
    common::picks_its_own_implementations("tools/tests/gles_implementations.rs")
}

/// Whether the whole suite also runs on each implementation, as `.ci/run` says with
/// `MANYLIGHT_SUITE_ON_EACH_GLES`: those runs check what [`methods_equal_forward`]'s few scenes
/// would (every method against forward, on every scene the suite draws). True after saying so
/// on stderr.
fn the_suite_runs_on_each_implementation(what: &str) -> bool {
    let set = std::env::var_os("MANYLIGHT_SUITE_ON_EACH_GLES").is_some_and(|v| !v.is_empty());
    if set {
        eprintln!(
            "NOT APPLICABLE: {what}: MANYLIGHT_SUITE_ON_EACH_GLES says the whole suite runs on \
             each implementation of MANYLIGHT_GLES_DIR, which holds every method to forward there"
        );
    }
    set
}

/// One matrix cell on implementation `name` (a folder of `MANYLIGHT_GLES_DIR`).
fn cell(name: &str, es: &str, scene: &str, extra: &[&str]) -> Value {
    let out = tempfile::tempdir().expect("temp dir");
    let mut cmd = if name == "angle" {
        let mut c = Command::new("xvfb-run");
        c.args(["-a", BIN]);
        c
    } else {
        Command::new(BIN)
    };
    cmd.env("MANYLIGHT_GLES_LIB", gles_dir().join(name))
        .args([
            "matrix-cell",
            "--es",
            es,
            "--scene",
            scene,
            "--size",
            "160x90",
        ])
        .args(["--lights", "256", "--tag", "t", "--out"])
        .arg(out.path())
        .args(extra);
    let output = cmd.output().expect("run manylight matrix-cell");
    assert!(
        output.status.success(),
        "{name} ES {es} {scene}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    let text = String::from_utf8_lossy(&output.stdout);
    let line = text.lines().last().unwrap_or_default();
    serde_json::from_str(line).unwrap_or_else(|e| panic!("{name}: not a JSON row ({e}): {text}"))
}

/// Every method the implementation supports within 2/255 of forward at every pixel (the bar the
/// Mesa suites hold them to; the floor is 0.1 % of pixels over it), on every built-in
/// scene (the transparent bubbles among them), ES 2.0 and 3.0 taking two scenes each; and the
/// row really came from that implementation. Each cell is a process of its own, whose shaders a
/// software implementation compiles anew: the suite's own run on each implementation holds
/// the methods to forward on the scenes and ES versions this leaves out (`culled_vs_forward`,
/// `deferred`, `stability`).
fn methods_equal_forward(name: &str, family: &str) {
    for (es, scenes) in [("2", ["courtyard", "bubbles"]), ("3", ["pillars", "plane"])] {
        for scene in scenes {
            let row = cell(name, es, scene, &[]);
            assert_eq!(row["implementation"], family, "{name}: {row}");
            let mut rendered = 0;
            for m in row["methods"].as_array().expect("methods") {
                let method = m["name"].as_str().unwrap();
                if m["support"]["status"] == "unsupported" {
                    continue;
                }
                rendered += 1;
                let (max_abs, over) = (
                    m["max_abs"].as_f64().unwrap(),
                    m["over_2"].as_f64().unwrap(),
                );
                assert!(
                    max_abs <= 2.0,
                    "{name} ES {es} {scene} {method}: max {max_abs}/255, {:.3} % of pixels over 2/255",
                    over * 100.0
                );
            }
            assert!(
                rendered >= 4,
                "{name} ES {es}: only {rendered} methods rendered: {row}"
            );
        }
    }
}

#[test]
#[cfg_attr(
    not(manylight_gles),
    ignore = "needs SwiftShader and ANGLE: scripts/fetch-gles, then set MANYLIGHT_GLES_DIR"
)]
fn every_method_equals_forward_on_swiftshader() {
    if in_another_implementations_run() || the_suite_runs_on_each_implementation("SwiftShader") {
        return;
    }
    methods_equal_forward("swiftshader", "SwiftShader");
}

#[test]
#[cfg_attr(
    not(manylight_gles),
    ignore = "needs SwiftShader and ANGLE: scripts/fetch-gles, then set MANYLIGHT_GLES_DIR"
)]
fn every_method_equals_forward_on_angle() {
    if in_another_implementations_run() || the_suite_runs_on_each_implementation("ANGLE") {
        return;
    }
    methods_equal_forward("angle", "ANGLE");
}

/// `info` names the implementation and the files it loaded from the folder given.
#[test]
#[cfg_attr(
    not(manylight_gles),
    ignore = "needs SwiftShader and ANGLE: scripts/fetch-gles, then set MANYLIGHT_GLES_DIR"
)]
fn info_names_the_chosen_implementation_and_its_files() {
    if in_another_implementations_run() {
        return;
    }
    let dir = gles_dir().join("swiftshader");
    let out = Command::new(BIN)
        .args(["info", "--es", "3", "--gles-lib"])
        .arg(&dir)
        .env_remove("MANYLIGHT_GLES_LIB")
        .output()
        .expect("run manylight info");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("implementation     SwiftShader (--gles-lib"),
        "{text}"
    );
    assert!(
        text.contains(&format!("{}/libGLESv2.so", dir.display())),
        "{text}"
    );
}

/// `matrix --gles-lib system --gles-lib DIR` adds a row group for the folder's implementation
/// (the implementation-neutral configurations), after the system's.
#[test]
#[cfg_attr(
    not(manylight_gles),
    ignore = "needs SwiftShader and ANGLE: scripts/fetch-gles, then set MANYLIGHT_GLES_DIR"
)]
fn matrix_adds_a_row_group_per_implementation() {
    if in_another_implementations_run() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("m.json");
    let swiftshader = gles_dir().join("swiftshader");
    let out = Command::new(BIN)
        .args([
            "matrix",
            "--size",
            "64x36",
            "--lights",
            "64",
            // Its pictures do not matter here, and SwiftShader compiles the plane's programs
            // in a third of the courtyard's time.
            "--scene",
            "plane",
            "--gles-lib",
            "system",
        ])
        .arg("--gles-lib")
        .arg(&swiftshader)
        .arg("--json")
        .arg(&json)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: Vec<Value> = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let group: Vec<&Value> = rows
        .iter()
        .filter(|r| r["gles_lib"] == swiftshader.display().to_string())
        .collect();
    let configs: Vec<&str> = group
        .iter()
        .map(|r| r["config"].as_str().unwrap())
        .collect();
    assert_eq!(
        configs,
        [
            "ES 2.0",
            "ES 2.0 without fragment highp (played)",
            "ES 2.0 without fragment highp or float textures (played)",
            "ES 2.0 with RGBA8 light data (played)",
            "ES 3.x as the driver gives it"
        ]
    );
    assert!(
        group.iter().all(|r| r["implementation"] == "SwiftShader"),
        "{group:?}"
    );
    // The played restriction is real: its lights went through the RGBA8 records.
    let played = group[3]["methods"].as_array().unwrap();
    assert!(
        played
            .iter()
            .filter(|m| m["support"]["status"] != "unsupported")
            .all(|m| m["light_encoding"] == "rgba8"),
        "{played:?}"
    );
    assert!(rows
        .iter()
        .any(|r| r["gles_lib"] == "system" && r["config"] == "desktop GL (OSMesa)"));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("| SwiftShader | ES 3.x as the driver gives it |"),
        "{stdout}"
    );
}

/// ANGLE's EGL on Linux has no surfaceless platform and needs an X display: without one it
/// failed with a bare "eglInitialize failed". The error now says what is missing and how to
/// run it (or, should a later ANGLE run without a display, `info` succeeds).
#[test]
#[cfg_attr(
    not(manylight_gles),
    ignore = "needs SwiftShader and ANGLE: scripts/fetch-gles, then set MANYLIGHT_GLES_DIR"
)]
fn angle_without_a_display_says_how_to_run_it() {
    if in_another_implementations_run() {
        return;
    }
    let out = Command::new(BIN)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env("MANYLIGHT_GLES_LIB", gles_dir().join("angle"))
        .args(["info", "--es", "2"])
        .output()
        .expect("run manylight info");
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        assert!(
            stderr.contains("needs a display server") && stderr.contains("xvfb-run -a"),
            "{stderr}"
        );
    }
}

/// In the suite's run on another implementation: what renders is what the folder holds
/// (`scripts/fetch-gles` names them `swiftshader` and `angle`), not the system's GL or the
/// other one, so that run tests what it says. A folder of another name is not checked.
#[test]
#[cfg_attr(
    not(manylight_gles),
    ignore = "needs SwiftShader and ANGLE: scripts/fetch-gles, then set MANYLIGHT_GLES_DIR"
)]
fn a_run_on_another_implementation_renders_with_the_one_its_folder_holds() {
    let Some(folder) = manylight::gl::gles_lib::chosen_folder() else {
        eprintln!("NOT APPLICABLE: this run renders with the system's GL (no MANYLIGHT_GLES_LIB)");
        return;
    };
    let expected = match folder.file_name().and_then(|n| n.to_str()) {
        Some("swiftshader") => "SwiftShader",
        Some("angle") => "ANGLE",
        _ => {
            eprintln!(
                "NOT CHECKED: {} is not a folder scripts/fetch-gles names",
                folder.display()
            );
            return;
        }
    };
    for es in [manylight::EsVersion::Es2, manylight::EsVersion::Es3] {
        let mut gpu = common::Gpu::new(es);
        let caps = gpu.r().caps();
        assert_eq!(
            caps.implementation(),
            expected,
            "{es} from {}: GL_RENDERER {}",
            folder.display(),
            caps.renderer
        );
    }
}

/// Choosing a GLES folder in code (`select_gles_library`): a folder that is not one is refused
/// at once, naming where it was chosen (it was accepted, and the first context blamed the
/// command line or the variable); after a first load that failed, choosing another says that
/// it failed, not that "the system's" implementation is loaded. In a child process, whose
/// `MANYLIGHT_GLES_LIB` names no folder: a process loads its implementation once.
#[test]
fn choosing_a_gles_folder_in_code_says_what_went_wrong() {
    const CHILD: &str = "MANYLIGHT_TEST_GLES_CHOICE_CHILD";
    if std::env::var_os(CHILD).is_none() {
        if in_another_implementations_run() {
            return;
        }
        common::child::rerun_with(
            "choosing_a_gles_folder_in_code_says_what_went_wrong",
            &[(CHILD, "1"), ("MANYLIGHT_GLES_LIB", "/nonexistent")],
            "the child choosing folders",
        );
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let err = manylight::select_gles_library(&dir.path().join("nowhere")).unwrap_err();
    let err = err.to_string();
    assert!(
        err.contains("is not a folder") && err.contains("select_gles_library"),
        "{err}"
    );
    let first = match manylight::HeadlessContext::new(manylight::EsVersion::Es3) {
        Ok(_) => panic!("a context from /nonexistent"),
        Err(e) => e.to_string(),
    };
    assert!(
        first.contains("/nonexistent") && first.contains("MANYLIGHT_GLES_LIB"),
        "{first}"
    );
    let err = manylight::select_gles_library(dir.path())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("failed already") && !err.contains("the system's"),
        "{err}"
    );
}
