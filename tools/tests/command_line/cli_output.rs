//! What the command line writes and says in the cases a newcomer met: files it should not
//! write, timings that add up, messages that name the flag typed rather than a library field.

use std::path::Path;

use crate::common;

use common::cli::{expect_status, manylight, text};

/// [`expect_status`] without extra environment.
fn expect(args: &[&str], cwd: &std::path::Path, code: i32) -> String {
    expect_status(args, &[], cwd, code)
}

#[test]
fn a_file_of_another_type_is_called_unsupported_not_an_unknown_built_in() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("notes.md"), "# not a scene\n").unwrap();
    let msg = expect(&["--scene", "notes.md", "--size", "8x8"], dir.path(), 1);
    assert!(msg.contains("unsupported scene file type"), "{msg}");
    assert!(
        msg.contains("notes.md") && !msg.contains("built-in scene `"),
        "{msg}"
    );
    // A name without an extension is still looked up among the built-ins.
    let msg = expect(&["--scene", "atlantis", "--size", "8x8"], dir.path(), 1);
    assert!(msg.contains("unknown built-in scene"), "{msg}");
    // A file in the folder named like a built-in does not hide it (plain `manylight` failed
    // as an unsupported file beside one called `courtyard`).
    std::fs::write(dir.path().join("courtyard"), "notes\n").unwrap();
    let args = ["--size", "8x8", "--lights", "0", "--out", "c.png"];
    let out = manylight(&args, &[], dir.path());
    assert!(out.status.success(), "{}", text(&out));
    // Nor is writing over that file writing over the scene.
    let args = ["--size", "8x8", "--lights", "0", "--out", "courtyard"];
    let out = manylight(&args, &[], dir.path());
    assert!(out.status.success(), "{}", text(&out));
}

/// An output naming the scene file (in any spelling) would replace the scene with a picture or
/// with statistics: a usage error naming both, and the scene is left as it was.
#[test]
fn an_output_that_would_overwrite_the_scene_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    let scene = r#"{"objects": [{"builtin": "plane"}]}"#;
    std::fs::write(dir.path().join("s.json"), scene).unwrap();
    for (option, path) in [("--out", "s.json"), ("--stats", "./s.json")] {
        let args = ["--scene", "s.json", "--size", "8x8", option, path];
        let msg = expect(&args, dir.path(), 2);
        assert!(
            msg.contains(&format!("{option} {path} names the scene file")),
            "{msg}"
        );
        assert_eq!(
            std::fs::read_to_string(dir.path().join("s.json")).unwrap(),
            scene
        );
    }
    // `matrix --json` too (the matrix was renamed over the scene once its cells had run).
    let msg = expect(
        &["matrix", "--scene", "s.json", "--json", "s.json"],
        dir.path(),
        2,
    );
    assert!(msg.contains("--json s.json names the scene file"), "{msg}");
    assert_eq!(
        std::fs::read_to_string(dir.path().join("s.json")).unwrap(),
        scene
    );
}

#[test]
fn linear_output_and_a_tone_map_are_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    let msg = expect(&["--linear", "--tonemap", "reinhard"], dir.path(), 2);
    assert!(
        msg.contains("--linear") && msg.contains("--tonemap"),
        "{msg}"
    );
}

#[test]
fn an_msaa_refusal_names_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "--msaa", "64", "--size", "16x9", "--lights", "4", "--frames", "0",
    ];
    // More samples than the context has: status 3, what this context cannot do.
    let msg = expect(&args, dir.path(), 3);
    assert!(msg.contains("--msaa 64"), "{msg}");
    assert!(!msg.contains("RenderOptions"), "{msg}");
}

#[test]
fn a_frame_larger_than_the_context_allows_names_the_flag_and_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    // Past every implementation's largest viewport and texture (16 384 at most here).
    let args = ["--size", "40000x9", "--lights", "4", "--frames", "0"];
    let msg = expect(&args, dir.path(), 3);
    assert!(
        msg.contains("--size 40000x9") && msg.contains("GL_MAX_"),
        "{msg}"
    );
}

#[test]
fn a_recording_writes_no_default_picture_beside_it() {
    if common::checks_the_command_line_alone("a recording without a picture") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let base = ["--size", "16x9", "--lights", "4", "--frames", "2"];
    expect(&[&base[..], &["--record", "a.gif"]].concat(), dir.path(), 0);
    assert!(dir.path().join("a.gif").is_file());
    assert!(
        !dir.path().join("manylight.png").exists(),
        "--record wrote ./manylight.png"
    );
    // Asked for, the picture is written as well.
    let args = [&base[..], &["--record", "b.gif", "--out", "x.png"]].concat();
    expect(&args, dir.path(), 0);
    assert!(dir.path().join("x.png").is_file());
}

#[test]
fn gif_frame_delays_add_up_to_the_animation_time() {
    if common::checks_the_command_line_alone("GIF frame delays") {
        return;
    }
    use image::AnimationDecoder;
    let dir = tempfile::tempdir().unwrap();
    // 9 frames at 30 fps last 0.3 s: whole hundredths that each round 3.33 alone would make 0.27.
    let args = [
        "--size", "8x8", "--lights", "4", "--frames", "9", "--fps", "30", "--record", "a.gif",
    ];
    expect(&args, dir.path(), 0);
    let file = std::io::BufReader::new(std::fs::File::open(dir.path().join("a.gif")).unwrap());
    let frames = image::codecs::gif::GifDecoder::new(file)
        .unwrap()
        .into_frames()
        .collect_frames()
        .unwrap();
    assert_eq!(frames.len(), 9);
    let total_ms: u32 = frames
        .iter()
        .map(|f| {
            let (n, d) = f.delay().numer_denom_ms();
            n / d
        })
        .sum();
    assert_eq!(total_ms, 300, "frame delays sum to {total_ms} ms");
}

#[test]
fn the_summary_line_says_what_auto_picked_and_which_time_the_picture_shows() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "--method", "auto", "--size", "16x9", "--lights", "8", "--out", "a.png",
    ];
    let msg = expect(&args, dir.path(), 0);
    assert!(msg.contains("auto → "), "{msg}");
    let msg = expect(
        &["--size", "16x9", "--lights", "8", "--out", "b.png"],
        dir.path(),
        0,
    );
    assert!(msg.contains("picture at t = 0.000 s"), "{msg}");
    assert!(!msg.contains("t = 0.000 to"), "{msg}");
}

#[test]
fn info_shows_the_methods_before_any_extension_list() {
    let dir = tempfile::tempdir().unwrap();
    let msg = expect(&["info"], dir.path(), 0);
    let methods = msg.find("\nmethods\n").expect("a methods table");
    let extensions = msg.find("\nextensions").expect("the extension count");
    assert!(methods < extensions, "{msg}");
    assert!(!msg.contains("\n  GL_"), "extensions listed unasked: {msg}");
    let listed = expect(&["info", "--extensions"], dir.path(), 0);
    assert!(listed.contains("\n  GL_"), "{listed}");
}

#[test]
fn bench_assign_runs_what_runs_asks_and_says_how_many() {
    let dir = tempfile::tempdir().unwrap();
    let msg = expect(
        &[
            "bench-assign",
            "--lights",
            "100001",
            "--runs",
            "9",
            "--json",
        ],
        dir.path(),
        0,
    );
    let rows: serde_json::Value = serde_json::from_str(&msg[msg.find('[').unwrap()..]).unwrap();
    assert_eq!(rows[0]["runs"], 9, "{msg}");
    let msg = expect(&["bench-assign", "--lights", "8"], dir.path(), 0);
    assert!(msg.contains("median of 101 runs"), "{msg}");
}

#[test]
fn a_budget_for_a_fixed_grid_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    let msg = expect(&["--grid", "16", "--assign-budget", "0.1"], dir.path(), 2);
    assert!(
        msg.contains("--assign-budget") && msg.contains("fixed"),
        "{msg}"
    );
}

/// `--stats -` puts the statistics alone on standard output, for a pipe into a JSON reader,
/// and the summary line on standard error; it wrote a file named `-`. Without lights, the
/// summary says nothing of moving lights.
#[test]
fn stats_to_standard_output_are_json_alone() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "--size", "16x9", "--lights", "0", "--out", "a.png", "--stats", "-",
    ];
    let out = manylight(&args, &[], dir.path());
    assert!(out.status.success(), "{}", text(&out));
    let stats: serde_json::Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("standard output is not JSON ({e}): {}", text(&out)));
    assert_eq!(stats["lights"], 0, "{stats}");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("0 lights"), "{stderr}");
    assert!(!stderr.contains("moving lights"), "{stderr}");
    assert!(
        !dir.path().join("-").exists(),
        "a file named `-` was written"
    );
}

/// `--out -` puts the PNG alone on standard output (the summary line on standard error), as
/// `--stats -` does its JSON; it wrote a file named `-`. Both on standard output (either
/// spelling) is a usage error saying so, not one calling them the same file.
#[test]
fn a_picture_to_standard_output_is_the_png_alone() {
    let dir = tempfile::tempdir().unwrap();
    let out = manylight(
        &["--size", "16x9", "--lights", "4", "--out", "-"],
        &[],
        dir.path(),
    );
    assert!(out.status.success(), "{}", text(&out));
    let png = image::load_from_memory_with_format(&out.stdout, image::ImageFormat::Png)
        .unwrap_or_else(|e| panic!("standard output is not a PNG ({e}): {}", text(&out)));
    assert_eq!((png.width(), png.height()), (16, 9));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("4 lights"), "{stderr}");
    assert!(
        !dir.path().join("-").exists(),
        "a file named `-` was written"
    );
    for picture in ["-", "/dev/stdout"] {
        let args = ["--size", "16x9", "--out", picture, "--stats", "-"];
        let msg = expect(&args, dir.path(), 2);
        assert!(
            msg.contains("both name standard output"),
            "{picture}: {msg}"
        );
    }
    // Standard output is no file of a recording's folder, even the current one.
    let args = [
        "--size", "16x9", "--frames", "1", "--record", ".", "--out", "-",
    ];
    let out = manylight(&args, &[], dir.path());
    assert!(out.status.success(), "{}", text(&out));
    assert!(
        image::load_from_memory(&out.stdout).is_ok(),
        "{}",
        text(&out)
    );
    // `--stats /dev/stdout` is the JSON alone too, the summary line on standard error.
    let args = ["--size", "16x9", "--out", "p.png", "--stats", "/dev/stdout"];
    let out = manylight(&args, &[], dir.path());
    assert!(out.status.success(), "{}", text(&out));
    let json = serde_json::from_slice::<serde_json::Value>(&out.stdout);
    assert!(json.is_ok(), "{json:?}: {}", text(&out));
}

/// `--frames 0` times no frame: the summary line said "ms/frame" of the one frame it rendered,
/// shader compilation included. It now says the frame was not timed.
#[test]
fn no_timed_frames_are_not_called_a_frame_time() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "--size", "16x9", "--lights", "4", "--frames", "0", "--stats", "s.json",
    ];
    let out = manylight(&args, &[], dir.path());
    assert!(out.status.success(), "{}", text(&out));
    let summary = String::from_utf8_lossy(&out.stdout);
    assert!(
        summary.contains("one untimed frame") && !summary.contains("ms/frame"),
        "{summary}"
    );
    let stats: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("s.json")).unwrap()).unwrap();
    let spread = stats.get("frame_ms_spread");
    assert!(spread.is_some_and(serde_json::Value::is_null), "{stats}");
}

/// `--grid` and `--slice-depth` with a method that has no clustered grid changed nothing in
/// silence (tiled's tiles are fixed): now a warning names them and the method. Clustered
/// takes them without a word.
#[test]
fn grid_options_a_method_cannot_take_are_named() {
    let dir = tempfile::tempdir().unwrap();
    for (method, warned) in [("tiled", true), ("forward", true), ("clustered", false)] {
        let args = [
            "--size",
            "16x9",
            "--method",
            method,
            "--grid",
            "8",
            "--slice-depth",
            "2",
            "--out",
            "p.png",
        ];
        let out = manylight(&args, &[], dir.path());
        assert!(out.status.success(), "{}", text(&out));
        let stderr = String::from_utf8_lossy(&out.stderr);
        let said = stderr.contains("--grid, --slice-depth set the clustered grid");
        assert_eq!(said, warned, "{method}: {stderr}");
        assert_eq!(said, stderr.contains("so they change nothing"), "{stderr}");
        assert_eq!(
            stderr.contains("fixed at 32 px"),
            method == "tiled",
            "{stderr}"
        );
    }
    // One option is "it".
    let args = [
        "--size", "16x9", "--method", "forward", "--grid", "8", "--out", "p.png",
    ];
    let out = manylight(&args, &[], dir.path());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("--grid set the clustered grid: forward has none, so it changes nothing"),
        "{stderr}"
    );
}

/// Recording into a folder that holds another recording's frames left them beside the new
/// ones in silence (a longer earlier clip's tail): a warning counts them. Frames this run
/// overwrites are not counted, and an empty folder gets no warning.
#[test]
fn frames_left_from_an_earlier_recording_are_counted() {
    if common::checks_the_command_line_alone("frames left from an earlier recording") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("rec");
    std::fs::create_dir(&rec).unwrap();
    let args = [
        "--size", "16x9", "--lights", "2", "--frames", "2", "--record", "rec",
    ];
    let run = || {
        let out = manylight(&args, &[], dir.path());
        assert!(out.status.success(), "{}", text(&out));
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    assert!(!run().contains("from before"));
    // The run's own two frames now exist: still nothing to say.
    assert!(!run().contains("from before"));
    for stale in ["frame_00002.png", "frame_0001.png", "frame_00099.png"] {
        std::fs::write(rec.join(stale), b"old").unwrap();
    }
    let stderr = run();
    assert!(stderr.contains("3 frame_*.png from before"), "{stderr}");
}

/// A driver's own `printf` on standard output (Mesa's "extension … cannot be disabled" under
/// `MESA_EXTENSION_OVERRIDE`, flushed at exit) goes to standard error: `info --json` and
/// `--stats -` stay the JSON alone, as a CI script parses them.
#[test]
fn a_drivers_own_line_on_stdout_leaves_the_json_alone() {
    let dir = tempfile::tempdir().unwrap();
    let env = [(
        "MESA_EXTENSION_OVERRIDE",
        "-GL_OES_texture_float -GL_EXT_color_buffer_float",
    )];
    let info: &[&str] = &["info", "--es", "2", "--json"];
    let render: &[&str] = &[
        "--es", "2", "--size", "16x9", "--lights", "4", "--stats", "-", "--out", "p.png",
    ];
    let mut chatter = false;
    for args in [info, render] {
        let out = manylight(args, &env, dir.path());
        assert_eq!(out.status.code(), Some(0), "{args:?}: {}", text(&out));
        let parsed = serde_json::from_slice::<serde_json::Value>(&out.stdout);
        assert!(parsed.is_ok(), "{args:?}: {parsed:?} in {}", text(&out));
        chatter |= String::from_utf8_lossy(&out.stderr).contains("cannot be disabled");
    }
    if !chatter {
        eprintln!("this Mesa printed nothing for the override: the JSON was checked alone");
    }
}

/// An ES 2.0 context without 24-bit depth (`GL_OES_depth24` removed; Mesa then offers no
/// `GL_OES_packed_depth_stencil` either): the renderer's own target has 16 bits, which the
/// stats say and a warning names; with it, 24 and no warning.
#[test]
fn a_sixteen_bit_own_depth_buffer_is_said() {
    if common::other_implementation_than_mesa("MESA_EXTENSION_OVERRIDE") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "--es", "2", "--size", "16x9", "--lights", "4", "--stats", "s.json", "--out", "p.png",
    ];
    for (env, bits) in [
        (&[("MESA_EXTENSION_OVERRIDE", "-GL_OES_depth24")][..], 16),
        (&[], 24),
    ] {
        let out = manylight(&args, env, dir.path());
        assert_eq!(out.status.code(), Some(0), "{env:?}: {}", text(&out));
        let stats: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.path().join("s.json")).unwrap()).unwrap();
        assert_eq!(stats["depth_bits"], bits, "{env:?}");
        let warned = text(&out).contains("own depth buffer has 16 bits");
        assert_eq!(warned, bits == 16, "{env:?}: {}", text(&out));
    }
}

/// softpipe has ES 3.0 but one sample: `info` says that, not that MSAA needs ES 3.0.
#[test]
fn info_gives_the_real_reason_msaa_is_missing() {
    if common::other_implementation_than_mesa("GALLIUM_DRIVER=softpipe") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = manylight(&["info"], &[("GALLIUM_DRIVER", "softpipe")], dir.path());
    let shown = text(&out);
    assert_eq!(out.status.code(), Some(0), "{shown}");
    let msaa = shown.lines().find(|l| l.starts_with("MSAA")).unwrap();
    if !shown.contains("softpipe") {
        common::skip(&format!("no softpipe here: {msaa}"));
        return;
    }
    assert!(msaa.contains("GL_MAX_SAMPLES is 1"), "{msaa}");
}

/// `info` without `--es` reports what the device has: ES 2.0, with a warning, where the driver
/// gives no ES 3.0; `--es 3` still insists (status 3).
#[test]
fn info_probes_es_2_where_es_3_is_missing() {
    if common::other_implementation_than_mesa("MESA_GLES_VERSION_OVERRIDE") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let capped = [("MESA_GLES_VERSION_OVERRIDE", "2.0")];
    let out = manylight(&["info", "--json"], &capped, dir.path());
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(info["caps"]["es"], "2.0");
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("probing OpenGL ES 2.0"),
        "{}",
        text(&out)
    );
    let out = manylight(&["info", "--es", "3"], &capped, dir.path());
    assert_eq!(out.status.code(), Some(3), "{}", text(&out));
    // Uncapped, the default is ES 3.0, said without a warning.
    let out = manylight(&["info", "--json"], &[], dir.path());
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(info["caps"]["es"], "3.0");
    assert!(!text(&out).contains("probing"), "{}", text(&out));
    // A device without fragment highp is an ES 2.0 one: probed as such.
    let out = manylight(&["info", "--json", "--no-fragment-highp"], &[], dir.path());
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(info["caps"]["es"], "2.0");
}

/// An OBJ whose 300 materials each name a missing texture: 60 000 of them wrote 60 000 lines.
/// The first 50 are said, then one line of how many more, and the frame still renders.
#[test]
fn a_load_with_many_warnings_says_the_first_and_counts_the_rest() {
    let dir = tempfile::tempdir().unwrap();
    let mut obj = String::from("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
    let mut mtl = String::new();
    for i in 0..300 {
        obj += &format!("usemtl m{i}\nf 1 2 3\n");
        mtl += &format!("newmtl m{i}\nKd 0.5 0.5 0.5\nmap_Kd missing{i}.png\n");
    }
    std::fs::write(dir.path().join("m.obj"), obj).unwrap();
    std::fs::write(dir.path().join("m.mtl"), mtl).unwrap();
    let args = ["--scene", "m.obj", "--size", "16x9", "--out", "m.png"];
    let msg = expect(&args, dir.path(), 0);
    let missing = msg
        .lines()
        .filter(|l| l.contains("not found next to"))
        .count();
    assert_eq!(missing, 50, "{msg}");
    assert!(
        msg.contains("missing0.png") && !msg.contains("missing299.png"),
        "{msg}"
    );
    assert!(
        msg.contains("250 more warnings of this load are logged at the debug level"),
        "{msg}"
    );
    assert!(dir.path().join("m.png").is_file());
}

/// Runs `manylight ARGS` in `cwd` with standard output going into `stdout` (a file, as a
/// shell's `> f` or `>> f` gives it); returns the exit status and standard error.
fn into_file(args: &[&str], stdout: std::fs::File, cwd: &Path) -> (Option<i32>, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_manylight"))
        .args(args)
        .current_dir(cwd)
        .stdout(stdout)
        .output()
        .expect("run manylight");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    (out.status.code(), stderr)
}

/// Standard output redirected to a file is written where the shell left it: after what came
/// before (`{ echo header; manylight --out -; } > f`) and at the end under `>>`. It was
/// truncated first, which left a hole of NULs where "header" was, and under `>>` wiped the
/// file. And that file is the file the checks of outputs and scene see: `--out - >> s.json`
/// replaced the scene, `--out - --stats x.json > x.json` lost the picture, both exit 0.
#[test]
fn standard_output_into_a_file_is_written_after_what_it_holds_and_checked_as_that_file() {
    use std::io::Write;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.bin");
    let args = ["--size", "16x9", "--lights", "2", "--out", "-"];
    for append in [false, true] {
        std::fs::write(&path, b"header\n").unwrap();
        let mut file = std::fs::OpenOptions::new()
            .write(true)
            .append(append)
            .open(&path)
            .unwrap();
        if !append {
            // The shell's descriptor, where `echo header` left it.
            file.write_all(b"header\n").unwrap();
        }
        let (code, stderr) = into_file(&args, file, dir.path());
        assert_eq!(code, Some(0), "{stderr}");
        let written = std::fs::read(&path).unwrap();
        assert!(
            written.starts_with(b"header\n\x89PNG"),
            "append {append}: {:?}",
            &written[..written.len().min(12)]
        );
        assert!(image::load_from_memory(&written[7..]).is_ok());
    }
    for picture in ["-", "/dev/stdout"] {
        // The scene file behind standard output.
        let scene = dir.path().join("s.json");
        let text = r#"{"objects":[{"builtin":"plane"}],"random_lights":{"count":4}}"#;
        std::fs::write(&scene, text).unwrap();
        let file = std::fs::OpenOptions::new()
            .append(true)
            .open(&scene)
            .unwrap();
        let args = ["--scene", "s.json", "--size", "16x9", "--out", picture];
        let (code, stderr) = into_file(&args, file, dir.path());
        assert_eq!(code, Some(2), "{picture}: {stderr}");
        assert!(stderr.contains("names the scene file"), "{stderr}");
        assert_eq!(std::fs::read_to_string(&scene).unwrap(), text);
        // Another output's file behind standard output.
        let file = std::fs::File::create(dir.path().join("x.json")).unwrap();
        let args = ["--size", "16x9", "--out", picture, "--stats", "x.json"];
        let (code, stderr) = into_file(&args, file, dir.path());
        assert_eq!(code, Some(2), "{picture}: {stderr}");
        assert!(stderr.contains("name the same file"), "{stderr}");
    }
}

/// A file under `/dev` that is a file (`/dev/shm`'s) is replaced whole, as any other output:
/// all of `/dev` was taken as streams, so such a file was truncated and written in place, and
/// a write that failed half-way (a full disk, `ulimit -f`) left it cut short.
#[test]
fn a_file_under_dev_is_replaced_whole() {
    use std::os::unix::fs::MetadataExt;
    let shm = Path::new("/dev/shm");
    if !shm.is_dir() {
        eprintln!("no /dev/shm here: nothing to check");
        return;
    }
    let dir = tempfile::tempdir_in(shm).unwrap();
    let path = dir.path().join("keep.png");
    std::fs::write(&path, b"old").unwrap();
    let before = std::fs::metadata(&path).unwrap().ino();
    let out = manylight(
        &[
            "--size",
            "16x9",
            "--lights",
            "2",
            "--out",
            path.to_str().unwrap(),
        ],
        &[],
        dir.path(),
    );
    assert!(out.status.success(), "{}", text(&out));
    // A new file renamed over the old one, not the old one rewritten.
    assert_ne!(std::fs::metadata(&path).unwrap().ino(), before);
    assert!(image::open(&path).is_ok());
}

/// An output naming a FIFO that no process reads is an error at once: opening it waited for a
/// reader, so `--out fifo` hung before any work, saying nothing. With a reader it is written.
#[test]
#[cfg(unix)]
fn a_fifo_without_a_reader_is_an_error_not_a_wait() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("fifo");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|s| s.success()) {
        eprintln!("no mkfifo here: nothing to check");
        return;
    }
    let run = |args: &[&str]| {
        let child = std::process::Command::new(env!("CARGO_BIN_EXE_manylight"))
            .args(args)
            .current_dir(dir.path())
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let what = format!("{args:?}");
        common::cli::wait_with_timeout(child, &what, std::time::Duration::from_secs(120))
    };
    for args in [
        ["--size", "16x9", "--lights", "2", "--out", "fifo"],
        ["--size", "16x9", "--out", "a.png", "--stats", "fifo"],
    ] {
        let out = run(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(stderr.contains("no process reads"), "{stderr}");
    }
    // A reader waiting (opened without waiting for a writer, so it is there before the
    // command starts): the PNG reaches it.
    use std::io::Read;
    use std::os::unix::fs::OpenOptionsExt;
    let mut source = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(&fifo)
        .unwrap();
    let reader = std::thread::spawn(move || {
        let (mut png, mut buffer) = (Vec::new(), [0u8; 4096]);
        let start = std::time::Instant::now();
        // Until the writer has come and gone: no writer yet reads as an end too.
        while start.elapsed() < std::time::Duration::from_secs(120) {
            match source.read(&mut buffer) {
                Ok(0) if !png.is_empty() => break,
                Ok(n) => png.extend_from_slice(&buffer[..n]),
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {}
                Err(e) => panic!("reading the FIFO: {e}"),
            }
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        png
    });
    let out = run(&["--size", "16x9", "--lights", "2", "--out", "fifo"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let png = reader.join().unwrap();
    assert!(image::load_from_memory(&png).is_ok());
}

/// `--out a.jpg` writes a PNG (the only format), which it did without a word: a warning says
/// so; `.png` in any case and no extension say nothing.
#[test]
fn a_picture_named_as_another_format_is_warned_of() {
    let dir = tempfile::tempdir().unwrap();
    for (name, warned) in [("a.jpg", true), ("b.PNG", false), ("c", false)] {
        let out = manylight(
            &["--size", "16x9", "--lights", "2", "--out", name],
            &[],
            dir.path(),
        );
        assert!(out.status.success(), "{}", text(&out));
        let said = text(&out);
        assert_eq!(
            said.contains("the picture is a PNG"),
            warned,
            "{name}: {said}"
        );
        let bytes = std::fs::read(dir.path().join(name)).unwrap();
        let format = image::guess_format(&bytes).unwrap();
        assert_eq!(format, image::ImageFormat::Png, "{name}");
    }
}

/// An output naming a file the scene reads (its model, the model's MTL library, a texture) is
/// an error before anything is written: `--out q.obj` replaced the model with a picture, exit 0.
#[test]
fn an_output_naming_a_file_the_scene_reads_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let obj = "mtllib q.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n";
    std::fs::write(dir.path().join("q.obj"), obj).unwrap();
    std::fs::write(
        dir.path().join("q.mtl"),
        "newmtl m\nKd 1 1 1\nmap_Kd t.png\n",
    )
    .unwrap();
    image::RgbaImage::from_pixel(2, 2, image::Rgba([200, 100, 50, 255]))
        .save(dir.path().join("t.png"))
        .unwrap();
    let scene = r#"{"objects":[{"obj":"q.obj"}],"random_lights":{"count":4}}"#;
    std::fs::write(dir.path().join("s.json"), scene).unwrap();
    for (option, file) in [
        ("--out", "q.obj"),
        ("--stats", "q.mtl"),
        ("--out", "./t.png"),
    ] {
        let before = std::fs::read(dir.path().join(file)).unwrap();
        let args = ["--scene", "s.json", "--size", "16x9", option, file];
        let out = manylight(&args, &[], dir.path());
        let said = text(&out);
        assert_eq!(out.status.code(), Some(1), "{option} {file}: {said}");
        assert!(said.contains("names a file the scene reads"), "{said}");
        assert_eq!(
            std::fs::read(dir.path().join(file)).unwrap(),
            before,
            "{file}"
        );
    }
    // Another name is written as usual.
    let args = ["--scene", "s.json", "--size", "16x9", "--out", "p.png"];
    let out = manylight(&args, &[], dir.path());
    assert!(out.status.success(), "{}", text(&out));
}

/// `--record` is checked against the files the scene reads too: a texture that is one of the
/// frames a recording writes, or the GIF it writes, was replaced by a frame of the recording.
#[test]
fn a_recording_that_would_overwrite_a_file_the_scene_reads_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let obj = "mtllib r.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n\
               usemtl m\nf 1/1 2/2 3/3\nusemtl g\nf 1/1 3/3 2/2\n";
    std::fs::write(dir.path().join("r.obj"), obj).unwrap();
    let mtl = "newmtl m\nmap_Kd rec/frame_00001.png\nnewmtl g\nmap_Kd t.gif\n";
    std::fs::write(dir.path().join("r.mtl"), mtl).unwrap();
    std::fs::create_dir(dir.path().join("rec")).unwrap();
    let texel = image::RgbaImage::from_pixel(2, 2, image::Rgba([200, 100, 50, 255]));
    texel.save(dir.path().join("rec/frame_00001.png")).unwrap();
    texel.save(dir.path().join("t.gif")).unwrap();
    let render = |record: &str, frames: &str| {
        let args = [
            "--scene", "r.obj", "--size", "16x9", "--lights", "2", "--record", record, "--frames",
            frames,
        ];
        manylight(&args, &[], dir.path())
    };
    for (record, file) in [("rec", "rec/frame_00001.png"), ("./t.gif", "t.gif")] {
        let before = std::fs::read(dir.path().join(file)).unwrap();
        let out = render(record, "3");
        let said = text(&out);
        assert_eq!(out.status.code(), Some(1), "--record {record}: {said}");
        assert!(said.contains("which the scene reads"), "{said}");
        assert_eq!(
            std::fs::read(dir.path().join(file)).unwrap(),
            before,
            "{file}"
        );
    }
    // A frame that is a symbolic link to the texture: written through it.
    std::fs::create_dir(dir.path().join("links")).unwrap();
    std::os::unix::fs::symlink("../t.gif", dir.path().join("links/frame_00002.png")).unwrap();
    let out = render("links", "3");
    let said = text(&out);
    assert_eq!(out.status.code(), Some(1), "--record links: {said}");
    assert!(said.contains("which the scene reads"), "{said}");
    // One frame writes frame_00000.png alone, which the scene does not read.
    let out = render("rec", "1");
    assert!(out.status.success(), "{}", text(&out));
    assert!(dir.path().join("rec/frame_00000.png").is_file());
}

/// A `--scene` path that is not UTF-8 is a usage error naming `--scene` (scene paths are
/// text); it was clap's "invalid UTF-8 was detected in one or more arguments", no option named.
#[test]
#[cfg(unix)]
fn a_scene_path_that_is_not_utf8_is_named_as_the_scene() {
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().unwrap();
    let name = std::ffi::OsStr::from_bytes(b"x\xff.json");
    for subcommand in [&["render"][..], &["info"], &["view"]] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_manylight"))
            .args(subcommand)
            .arg("--scene")
            .arg(name)
            .current_dir(dir.path())
            .env_remove("DISPLAY")
            .output()
            .unwrap();
        let said = text(&out);
        assert_eq!(out.status.code(), Some(2), "{subcommand:?}: {said}");
        assert!(
            said.contains("--scene") && said.contains("not UTF-8"),
            "{subcommand:?}: {said}"
        );
    }
}
