//! Outputs that cannot be written: every file the command line writes (`--out`, `--stats`,
//! `--record` frames and GIF, `matrix`'s JSON and contact sheet, `bench`'s report, charts and
//! pictures, standard output) onto a full disk (`/dev/full`: ENOSPC on every write), half
//! written (a file-size limit), or named twice; and every subcommand that cannot do its job.
//! Each must end in a non-zero exit and a message naming the file (or both options), never a
//! success line. Also: options that take a signed value take a negative number as a separate
//! word (`--time -1.5`).

use crate::common;

use std::path::Path;
use std::process::{Command, Stdio};

use common::cli::{expect_exit, expect_status, manylight, text};

/// A small, quick render: a few lights, one untimed frame.
const TINY: [&str; 6] = ["--size", "16x9", "--lights", "4", "--frames", "0"];

/// `args` after [`TINY`].
fn tiny(args: &[&str]) -> Vec<String> {
    TINY.iter().chain(args).map(|s| s.to_string()).collect()
}

fn strs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

/// `manylight ARGS` fails with exit 1, names `file` and prints no success line.
fn fails_naming(args: &[&str], cwd: &Path, file: &str) -> String {
    let msg = expect_exit(args, &[], cwd, 1, file);
    assert!(!msg.contains("ms/frame"), "{args:?} claimed success: {msg}");
    msg
}

/// A `bench` of one tiny configuration: `scene` with `lights` random lights, forward on ES 3.0
/// at 16×9, its report into `out`.
fn tiny_bench(scene: &str, lights: &str, out: &str) -> Vec<String> {
    [
        "bench",
        "--scenes",
        scene,
        "--lights",
        lights,
        "--methods",
        "forward",
        "--es",
        "3",
        "--size",
        "16x9",
        "--frames",
        "1",
        "--cpu-samples",
        "1",
        "--no-knobs",
        "--animated-frames",
        "0",
        "--out",
        out,
    ]
    .map(String::from)
    .to_vec()
}

#[test]
fn every_render_output_onto_a_full_disk_fails_naming_the_file() {
    if common::checks_the_command_line_alone("outputs onto a full disk") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cwd = dir.path();
    std::os::unix::fs::symlink("/dev/full", cwd.join("full.gif")).unwrap();
    std::fs::create_dir(cwd.join("frames")).unwrap();
    std::os::unix::fs::symlink("/dev/full", cwd.join("frames/frame_00000.png")).unwrap();
    // A picture far smaller than any write buffer: only a flush finds the full disk.
    let msg = fails_naming(&strs(&tiny(&["--out", "/dev/full"])), cwd, "/dev/full");
    assert!(msg.contains("No space left on device"), "{msg}");
    let args = tiny(&["--out", "a.png", "--stats", "/dev/full"]);
    fails_naming(&strs(&args), cwd, "/dev/full");
    let args = [&TINY[..4], &["--frames", "2", "--record", "full.gif"]].concat();
    fails_naming(&args, cwd, "full.gif");
    let args = [&TINY[..4], &["--frames", "2", "--record", "frames"]].concat();
    fails_naming(&args, cwd, "frame_00000.png");
    // No frame to record is no recording, not an empty GIF.
    let msg = expect_exit(
        &strs(&tiny(&["--record", "z.gif"])),
        &[],
        cwd,
        2,
        "--frames 0",
    );
    assert!(msg.contains("--record z.gif"), "{msg}");
    assert!(!cwd.join("z.gif").exists());
}

#[test]
fn every_bench_and_matrix_output_onto_a_full_disk_fails_naming_the_file() {
    if common::checks_the_command_line_alone("bench and matrix outputs onto a full disk") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cwd = dir.path();
    let bench = tiny_bench("plane", "0", "b");
    let bench = strs(&bench);
    for file in [
        "report.json",
        "report.md",
        "error_vs_time-plane.png",
        "heatmap-plane-es3-forward.png",
        "diff-plane-es3-forward.png",
        "reference-plane-es3.png",
    ] {
        let _ = std::fs::remove_dir_all(cwd.join("b"));
        std::fs::create_dir(cwd.join("b")).unwrap();
        std::os::unix::fs::symlink("/dev/full", cwd.join("b").join(file)).unwrap();
        fails_naming(&bench, cwd, file);
    }
    // No light, the plane: each of the matrix's cells a small program to compile (a software
    // GPU's slow part), whose pictures do not matter here.
    let matrix = [
        "matrix", "--scene", "plane", "--size", "16x9", "--lights", "0",
    ];
    fails_naming(
        &[&matrix[..], &["--json", "/dev/full"]].concat(),
        cwd,
        "/dev/full",
    );
    std::fs::create_dir(cwd.join("m")).unwrap();
    std::os::unix::fs::symlink("/dev/full", cwd.join("m/matrix.png")).unwrap();
    fails_naming(&[&matrix[..], &["--out", "m"]].concat(), cwd, "matrix.png");
}

/// `render` refused an output naming a file its scene was read from; `bench` and `matrix`,
/// whose outputs' names they choose themselves, replaced them (a scene file named
/// `report.json`, a texture named as a benchmark's reference picture). Every output refuses
/// such a file, naming it, and leaves it as it was.
#[test]
fn no_output_replaces_a_file_a_scene_was_read_from() {
    if common::checks_the_command_line_alone("outputs over a scene's files") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cwd = dir.path();
    let texture = "reference-tex-es3.png";
    image::RgbaImage::from_pixel(2, 2, image::Rgba([200, 40, 40, 255]))
        .save(cwd.join(texture))
        .unwrap();
    std::fs::write(
        cwd.join("m.mtl"),
        format!("newmtl m\nKd 1 1 1\nmap_Kd {texture}\n"),
    )
    .unwrap();
    std::fs::write(
        cwd.join("tex.obj"),
        "mtllib m.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n\
         f 1/1 2/2 3/3\n",
    )
    .unwrap();
    let scene_file = br#"{"objects": [{"model": "tex.obj"}]}"#;
    std::fs::write(cwd.join("report.json"), scene_file).unwrap();
    let untouched = |file: &str| std::fs::read(cwd.join(file)).unwrap();
    let (obj, png) = (untouched("tex.obj"), untouched(texture));
    let bench = |scene| tiny_bench(scene, "2", ".");
    fails_naming(&strs(&bench("tex.obj")), cwd, texture);
    let matrix = [
        "matrix", "--scene", "tex.obj", "--size", "16x9", "--lights", "0",
    ];
    fails_naming(&[&matrix[..], &["--json", texture]].concat(), cwd, texture);
    assert_eq!(untouched(texture), png);
    assert_eq!(untouched("tex.obj"), obj);
    // A scene file named as the report.
    fails_naming(&strs(&bench("report.json")), cwd, "report.json");
    assert_eq!(untouched("report.json"), scene_file);
}

/// A benchmark stopped half-way (an error here, a signal alike) leaves its report folder as
/// the last run left it, not a mixture of two runs: its files are put in place together at
/// the end (a second run's heat maps had replaced the first's beside the first's report).
#[test]
fn a_benchmark_stopped_half_way_leaves_the_last_report_whole() {
    if common::checks_the_command_line_alone("a benchmark's report folder stopped half-way") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cwd = dir.path();
    let bench = |lights| tiny_bench("plane", lights, "b");
    expect_status(&strs(&bench("2")), &[], cwd, 0);
    let folder = || {
        let mut files: Vec<_> = (std::fs::read_dir(cwd.join("b")).unwrap())
            .map(|e| {
                let e = e.unwrap();
                (e.file_name(), std::fs::read(e.path()).unwrap_or_default())
            })
            .collect();
        files.sort();
        files
    };
    let first = folder();
    // The scene's last picture cannot be written: a folder is in its way.
    let reference = cwd.join("b").join("reference-plane-es3.png");
    std::fs::remove_file(&reference).unwrap();
    std::fs::create_dir(&reference).unwrap();
    let last_run = folder();
    fails_naming(&strs(&bench("3")), cwd, "reference-plane-es3.png");
    assert!(folder() == last_run, "the folder changed");
    std::fs::remove_dir(&reference).unwrap();
    expect_status(&strs(&bench("3")), &[], cwd, 0);
    let heatmap = |files: &[(std::ffi::OsString, Vec<u8>)]| {
        let name = std::ffi::OsStr::new("heatmap-plane-es3-forward.png");
        files.iter().find(|(n, _)| n == name).unwrap().1.clone()
    };
    assert_ne!(
        heatmap(&folder()),
        heatmap(&first),
        "the runs draw different maps"
    );
}

#[test]
fn standard_output_onto_a_full_disk_fails_but_a_closed_pipe_does_not() {
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str], stdout: Stdio| {
        Command::new(env!("CARGO_BIN_EXE_manylight"))
            .args(args)
            .current_dir(dir.path())
            .stdout(stdout)
            .output()
            .unwrap()
    };
    let full = || Stdio::from(std::fs::File::create("/dev/full").unwrap());
    let cases: [&[&str]; 4] = [
        &["--size", "16x9", "--lights", "4", "--frames", "0"],
        &["info", "--json"],
        &["info"],
        &["bench-assign", "--lights", "1", "--runs", "1"],
    ];
    for args in cases {
        let out = run(args, full());
        let msg = text(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {msg}");
        assert!(
            msg.contains("cannot write to standard output"),
            "{args:?}: {msg}"
        );
        assert!(!msg.contains("panicked"), "{args:?}: {msg}");
    }
    // Standard error onto a full disk: nothing can be said, but the exit status still tells.
    let out = Command::new(env!("CARGO_BIN_EXE_manylight"))
        .args(["--scene", "missing.obj"])
        .current_dir(dir.path())
        .stderr(full())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1), "{}", text(&out));
    // Help and the version are output too.
    for args in [["--help"], ["--version"]] {
        let out = run(&args, full());
        assert_eq!(out.status.code(), Some(1), "{args:?}: {}", text(&out));
        assert_eq!(run(&args, Stdio::null()).status.code(), Some(0), "{args:?}");
    }
    // `--stats /dev/stdout | jq`: the statistics alone into the pipe (as `--stats -`), the
    // summary line on standard error.
    let args = [
        "--size",
        "16x9",
        "--lights",
        "4",
        "--frames",
        "0",
        "--stats",
        "/dev/stdout",
    ];
    let out = run(&args, Stdio::piped());
    assert!(out.status.success(), "{}", text(&out));
    let json = serde_json::from_slice::<serde_json::Value>(&out.stdout);
    assert!(
        json.is_ok_and(|j| j["method"].is_string()),
        "{}",
        text(&out)
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("untimed frame"), "{stderr}");
    // `manylight info | head -c 1`, `manylight --out - | head -c 1`: the reader leaving ends
    // the output, not in an error (the picture's was `cannot write -: Broken pipe`, exit 1).
    let picture = [
        "--size", "16x9", "--lights", "4", "--frames", "0", "--out", "-",
    ];
    for args in [&["info"][..], &picture] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_manylight"))
            .args(args)
            .current_dir(dir.path())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
}

/// Runs `manylight ARGS` with its file size limited to `kib` KiB. SIGXFSZ keeps its default
/// action, which ends the process (with temporary files left) unless it ignores the signal
/// and takes the write's EFBIG as an error.
fn with_file_size_limit(args: &[&str], cwd: &Path, kib: u32) -> std::process::Output {
    let script = format!("ulimit -f {}; exec \"$0\" \"$@\"", kib * 2);
    Command::new("sh")
        .arg("-c")
        .arg(script)
        .arg(env!("CARGO_BIN_EXE_manylight"))
        .args(args)
        .current_dir(cwd)
        .output()
        .unwrap()
}

#[test]
fn an_output_failing_half_way_leaves_the_old_file_whole_and_no_partial_one() {
    if common::checks_the_command_line_alone("an output failing half way") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cwd = dir.path();
    std::fs::write(cwd.join("a.png"), "the old picture").unwrap();
    // `ulimit -f` counts 512-byte blocks in sh: 1 KiB, less than the picture.
    let args: Vec<String> = ["--size", "256x144", "--lights", "64", "--frames", "0"]
        .iter()
        .chain(&["--out", "a.png"])
        .map(|s| s.to_string())
        .collect();
    let out = with_file_size_limit(&strs(&args), cwd, 1);
    let msg = text(&out);
    assert_eq!(out.status.code(), Some(1), "{msg}");
    assert!(msg.contains("cannot write a.png"), "{msg}");
    assert!(msg.contains("File too large"), "{msg}");
    assert_eq!(
        std::fs::read(cwd.join("a.png")).unwrap(),
        b"the old picture"
    );
    let left: Vec<_> = std::fs::read_dir(cwd)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left, ["a.png"], "a temporary file was left");
    // Without the limit the same command replaces it with a whole picture.
    expect_status(&strs(&args), &[], cwd, 0);
    image::open(cwd.join("a.png")).expect("a whole PNG");
}

/// An output's name reaches a message with its control characters escaped: a file named
/// `x⏎error: fake` given to `--record` printed a second, made-up `error:` line.
#[test]
fn an_output_name_reaches_messages_escaped() {
    let dir = tempfile::tempdir().unwrap();
    let cwd = dir.path();
    let name = "x\nerror: fake";
    std::fs::write(cwd.join(name), "").unwrap();
    let args = [
        "--size", "16x9", "--lights", "4", "--frames", "1", "--record", name,
    ];
    let msg = expect_status(&args, &[], cwd, 1);
    assert!(msg.contains("x\\u{a}error: fake"), "{msg}");
    assert!(!msg.lines().any(|l| l.starts_with("error: fake")), "{msg}");
}

#[test]
fn two_options_naming_one_file_are_a_usage_error_naming_both() {
    if common::checks_the_command_line_alone("two options naming one file") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cwd = dir.path();
    std::fs::create_dir(cwd.join("sub")).unwrap();
    std::os::unix::fs::symlink("a.png", cwd.join("link.png")).unwrap();
    let cases: [(&[&str], &str, &str); 6] = [
        (
            &["--out", "a.png", "--stats", "./a.png"],
            "--out",
            "--stats",
        ),
        (
            &["--out", "a.png", "--stats", "sub/../a.png"],
            "--out",
            "--stats",
        ),
        (
            &["--out", "a.png", "--stats", "link.png"],
            "--out",
            "--stats",
        ),
        (
            &["--stats", "manylight.png"],
            "the default --out",
            "--stats",
        ),
        (
            &["--out", "r.gif", "--record", "./r.gif"],
            "--out",
            "--record",
        ),
        (
            &["--stats", "s.json", "--record", "s.json"],
            "--stats",
            "--record",
        ),
    ];
    for (args, a, b) in cases {
        // One timed frame, so that a recording has something to record.
        let args = [&TINY[..4], &["--frames", "1"], args].concat();
        let msg = expect_exit(&args, &[], cwd, 2, a);
        assert!(
            msg.contains(b) && msg.contains("same file"),
            "{args:?}: {msg}"
        );
    }
    // A file in the folder --record fills with frames could be a frame.
    for args in [
        ["--stats", "d/frame_00001.png", "--record", "d"],
        ["--out", "d/frame_00002.png", "--record", "./d/"],
    ] {
        let args = [&TINY[..4], &["--frames", "3"], &args[..]].concat();
        let msg = expect_exit(&args, &[], cwd, 2, args[7]);
        assert!(msg.contains("--record") && msg.contains("frames"), "{msg}");
    }
    let absolute = cwd.join("a.png");
    let args = tiny(&["--out", absolute.to_str().unwrap(), "--stats", "a.png"]);
    expect_exit(&strs(&args), &[], cwd, 2, "same file");
    let args = ["matrix", "--json", "m", "--out", "./m"];
    expect_exit(&args, &[], cwd, 2, "same file");
    let args = ["matrix", "--json", "m/matrix.png", "--out", "m"];
    expect_exit(&args, &[], cwd, 2, "same file");
    // A cell's picture (`TAG-METHOD.png`), which the matrix names itself.
    let args = ["matrix", "--json", "m/es3-forward.png", "--out", "m"];
    expect_exit(&args, &[], cwd, 2, "names a cell's picture in --out m");
    assert!(!cwd.join("a.png").exists() && !cwd.join("m").exists());
    // A device takes any number of outputs; different files are fine.
    let args = tiny(&["--out", "/dev/null", "--stats", "/dev/null"]);
    expect_status(&strs(&args), &[], cwd, 0);
    expect_status(
        &strs(&tiny(&["--out", "a.png", "--stats", "a.json"])),
        &[],
        cwd,
        0,
    );
}

#[test]
fn signed_options_take_a_negative_number_as_a_separate_word() {
    if common::checks_the_command_line_alone("negative numbers as option values") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cwd = dir.path();
    // The built-in scene's lights move: a picture at t = -1.5 s differs from one at 0.
    for (i, time) in [["--time", "-1.5"], ["--time=-1.5", ""], ["--time", "0"]]
        .iter()
        .enumerate()
    {
        let out = format!("{i}.png");
        let mut args = tiny(&["--out", &out, time[0]]);
        if !time[1].is_empty() {
            args.push(time[1].to_string());
        }
        expect_status(&strs(&args), &[], cwd, 0);
    }
    let read = |i: usize| {
        image::open(cwd.join(format!("{i}.png")))
            .unwrap()
            .to_rgba8()
    };
    assert_eq!(read(0), read(1), "`--time -1.5` and `--time=-1.5` differ");
    assert_ne!(read(0), read(2), "`--time -1.5` rendered time 0");
    for (args, needle) in [
        (&["--exposure", "-1"][..], ""),
        (&["--fps", "-3"], "not a frame rate"),
        (&["--slice-depth", "-1"], "not a slice depth"),
        (&["--time", "-inf"], "not a time"),
        (&["--time", "-2e9"], "not a time"),
    ] {
        let args = tiny(args);
        let code = if needle.is_empty() { 0 } else { 2 };
        expect_exit(&strs(&args), &[], cwd, code, needle);
    }
    // Every timed frame can be rendered alone with `--time`: the last one too.
    let timed = [
        "--size", "16x9", "--lights", "4", "--out", "t.png", "--time",
    ];
    for (args, code, needle) in [
        (&["1e9", "--frames", "2"][..], 2, "past ±1e9 s"),
        (&["-1e9", "--fps", "0.001", "--frames", "3"], 0, ""),
    ] {
        expect_exit(&[&timed[..], args].concat(), &[], cwd, code, needle);
    }
}

#[test]
fn every_subcommand_that_cannot_do_its_job_exits_non_zero_naming_why() {
    let dir = tempfile::tempdir().unwrap();
    let cwd = dir.path();
    std::fs::write(cwd.join("file"), "").unwrap();
    let cases: [&[&str]; 10] = [
        &["--scene", "missing.obj", "--size", "16x9"],
        &["render", "--scene", "missing.obj", "--size", "16x9"],
        &["info", "--scene", "missing.obj"],
        &["matrix", "--scene", "missing.obj", "--size", "16x9"],
        &[
            "bench",
            "--scenes",
            "missing.obj",
            "--size",
            "16x9",
            "--out",
            "b",
        ],
        &[
            "--method",
            "no-such-method",
            "--size",
            "16x9",
            "--lights",
            "4",
        ],
        &["bench", "--methods", "no-such-method", "--out", "b"],
        &["bench", "--out", "file/b"],
        &["matrix", "--out", "file/m", "--size", "16x9"],
        &["matrix", "--gles-lib", "/nonexistent", "--size", "16x9"],
    ];
    let needles = [
        "missing.obj",
        "missing.obj",
        "missing.obj",
        "missing.obj",
        "missing.obj",
        "no-such-method",
        "no-such-method",
        "file/b",
        "file/m",
        "/nonexistent (from --gles-lib or MANYLIGHT_GLES_LIB) is not a folder",
    ];
    for (args, needle) in cases.iter().zip(needles) {
        let out = manylight(args, &[], cwd);
        let msg = text(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {msg}");
        assert!(
            msg.contains(needle),
            "{args:?}: expected `{needle}` in {msg}"
        );
        assert!(!msg.contains("panicked"), "{args:?}: {msg}");
        // A scene no cell could read, or an implementation no cell could load, is found
        // before any cell runs.
        if args[0] == "matrix" && (needle == "missing.obj" || args[1] == "--gles-lib") {
            assert!(!msg.contains("unavailable"), "{msg}");
        }
    }
}

/// The command line points descriptor 1 at standard error for what libraries print there; an
/// output named as standard output in any spelling (`/proc/self/fd/1`, a link to
/// `/dev/stdout`) still reaches the real one, not standard error.
#[cfg(unix)]
#[test]
fn every_spelling_of_standard_output_reaches_it() {
    let dir = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink("/dev/stdout", dir.path().join("link")).unwrap();
    for name in ["/proc/self/fd/1", "/dev/fd/1", "link"] {
        let args = [
            "--size", "16x9", "--lights", "4", "--frames", "0", "--stats", name,
        ];
        let out = manylight(&args, &[], dir.path());
        assert!(out.status.success(), "{name}: {}", text(&out));
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(stdout.starts_with('{'), "{name}: stdout {stdout:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            !stderr.contains("\"method\""),
            "{name}: the stats went to stderr"
        );
    }
}

/// Starts a long recording render in `dir` with SIGINT, SIGTERM and SIGHUP at their default
/// action (whatever this test inherited: `nohup`, a shell's `cmd &`), but `ignored` ignored,
/// and returns once its temporary file exists.
fn recording(dir: &Path, ignored: Option<i32>) -> std::process::Child {
    use std::os::unix::process::CommandExt;
    let mut command = Command::new(env!("CARGO_BIN_EXE_manylight"));
    command
        .args(["--size", "32x18", "--lights", "4", "--frames", "65536"])
        .args(["--record", "r.gif"])
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    // SAFETY: `signal` is async-signal-safe, as code between fork and exec must be.
    unsafe {
        command.pre_exec(move || {
            for s in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
                let action = if Some(s) == ignored {
                    libc::SIG_IGN
                } else {
                    libc::SIG_DFL
                };
                libc::signal(s, action);
            }
            Ok(())
        });
    }
    let mut child = command.spawn().unwrap();
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
    while temporaries(dir).is_empty() {
        assert!(
            std::time::Instant::now() < deadline,
            "no temporary file appeared"
        );
        assert!(
            child.try_wait().unwrap().is_none(),
            "the render ended early"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child
}

/// The hidden temporary files in `dir`.
fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect()
}

fn send(signal: &str, child: &std::process::Child) {
    let kill = Command::new("kill")
        .args([format!("-{signal}"), child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
}

/// A render stopped by a signal (Ctrl-C, `kill`, a closed terminal) half-way through a
/// recording leaves no hidden temporary file, and still ends by that signal. It used to leave
/// `.r.gif.PID.N.tmp` beside where the GIF would go. A signal it started with ignored (`nohup`)
/// stays ignored.
#[test]
fn a_signal_half_way_through_a_recording_leaves_no_temporary_file() {
    use std::os::unix::process::ExitStatusExt;
    let dir = tempfile::tempdir().unwrap();
    for (signal, number) in [
        ("TERM", libc::SIGTERM),
        ("INT", libc::SIGINT),
        ("HUP", libc::SIGHUP),
    ] {
        let mut child = recording(dir.path(), None);
        send(signal, &child);
        let status = child.wait().unwrap();
        assert_eq!(status.signal(), Some(number), "SIG{signal}: {status:?}");
        assert_eq!(temporaries(dir.path()), Vec::<String>::new(), "SIG{signal}");
        assert!(
            !dir.path().join("r.gif").exists(),
            "SIG{signal}: a GIF was left"
        );
    }
    // Under `nohup`: SIGHUP changes nothing, SIGTERM still ends it cleanly.
    let mut child = recording(dir.path(), Some(libc::SIGHUP));
    send("HUP", &child);
    std::thread::sleep(std::time::Duration::from_millis(300));
    assert!(
        child.try_wait().unwrap().is_none(),
        "an ignored SIGHUP ended the render"
    );
    send("TERM", &child);
    assert_eq!(child.wait().unwrap().signal(), Some(libc::SIGTERM));
    assert_eq!(temporaries(dir.path()), Vec::<String>::new());
}
