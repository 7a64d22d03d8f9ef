//! Outputs onto failing files: `--out`, `--stats` and `--record` (a GIF or a folder of frames)
//! pointed at a full device, a folder, a missing or impossible folder, a read-only file, or
//! one file named by two options in different spellings. Every case must exit non-zero with a
//! message naming the file (or both options), and never print the success line.

use std::path::Path;
use std::sync::OnceLock;

use proptest::prelude::*;

use super::common::checks_the_command_line_alone;
use super::common::cli::{manylight, text};
use super::config;

/// Whether this run leaves these cases to the run on the system's GL (said once).
fn not_applicable() -> bool {
    static SKIP: OnceLock<bool> = OnceLock::new();
    *SKIP.get_or_init(|| checks_the_command_line_alone("outputs onto failing files"))
}

/// An option that writes a file, and the name it gives a file of its kind.
#[derive(Clone, Copy, Debug)]
enum Output {
    Out,
    Stats,
    RecordGif,
    RecordFrames,
}

impl Output {
    fn flag(self) -> &'static str {
        match self {
            Output::Out => "--out",
            Output::Stats => "--stats",
            Output::RecordGif | Output::RecordFrames => "--record",
        }
    }

    fn file_name(self) -> &'static str {
        match self {
            Output::Out => "o.png",
            Output::Stats => "s.json",
            Output::RecordGif => "r.gif",
            Output::RecordFrames => "frames",
        }
    }
}

/// What stands where the output goes.
#[derive(Clone, Copy, Debug)]
enum Failing {
    /// `/dev/full` itself, or a link to it under the output's own name (for frames: the first
    /// frame's file).
    FullDevice,
    /// A folder (for frames: a folder where the first frame's file goes).
    Folder,
    /// Inside a folder that does not exist (frames: inside a regular file).
    MissingFolder,
    /// Inside a regular file.
    UnderAFile,
    /// A read-only file (frames: the first frame's file); root may write it anyway.
    ReadOnly,
}

/// Sets the failing target up in `dir` and returns the path to pass, and what the message must
/// name.
fn prepare(dir: &Path, output: Output, failing: Failing, direct: bool) -> (String, String) {
    let name = output.file_name();
    std::fs::write(dir.join("plain"), "x").unwrap();
    let frame = "frames/frame_00000.png";
    match (output, failing) {
        (Output::RecordFrames, Failing::FullDevice) => {
            std::fs::create_dir(dir.join("frames")).unwrap();
            std::os::unix::fs::symlink("/dev/full", dir.join(frame)).unwrap();
            ("frames".into(), frame.into())
        }
        (Output::RecordFrames, Failing::Folder) => {
            std::fs::create_dir_all(dir.join(frame)).unwrap();
            ("frames".into(), frame.into())
        }
        (Output::RecordFrames, Failing::MissingFolder | Failing::UnderAFile) => {
            ("plain/frames".into(), "plain/frames".into())
        }
        (Output::RecordFrames, Failing::ReadOnly) => {
            std::fs::create_dir(dir.join("frames")).unwrap();
            read_only(&dir.join(frame));
            ("frames".into(), frame.into())
        }
        (_, Failing::FullDevice) if direct => ("/dev/full".into(), "/dev/full".into()),
        (_, Failing::FullDevice) => {
            std::os::unix::fs::symlink("/dev/full", dir.join(name)).unwrap();
            (name.into(), name.into())
        }
        (_, Failing::Folder) => {
            std::fs::create_dir(dir.join(name)).unwrap();
            (name.into(), name.into())
        }
        (_, Failing::MissingFolder) => {
            let p = format!("missing/{name}");
            (p.clone(), p)
        }
        (_, Failing::UnderAFile) => {
            let p = format!("plain/{name}");
            (p.clone(), p)
        }
        (_, Failing::ReadOnly) => {
            read_only(&dir.join(name));
            (name.into(), name.into())
        }
    }
}

/// Creates `path` as a file without write permission.
fn read_only(path: &Path) {
    use std::os::unix::fs::PermissionsExt;
    std::fs::write(path, "old").unwrap();
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o444)).unwrap();
}

/// Whether this process may write a file without write permission (root may).
fn ignores_permissions(dir: &Path) -> bool {
    let probe = dir.join("probe");
    read_only(&probe);
    let writable = std::fs::OpenOptions::new().write(true).open(&probe).is_ok();
    std::fs::remove_file(probe).unwrap();
    writable
}

fn output() -> impl Strategy<Value = Output> {
    prop_oneof![
        Just(Output::Out),
        Just(Output::Stats),
        Just(Output::RecordGif),
        Just(Output::RecordFrames),
    ]
}

fn failing() -> impl Strategy<Value = Failing> {
    prop_oneof![
        Just(Failing::FullDevice),
        Just(Failing::Folder),
        Just(Failing::MissingFolder),
        Just(Failing::UnderAFile),
        Just(Failing::ReadOnly),
    ]
}

/// A spelling of `name` in the working folder (`sub` exists there; `link` is made a symbolic
/// link to `name` when chosen).
fn spelling() -> impl Strategy<Value = u8> {
    0u8..5
}

fn spell(dir: &Path, name: &str, how: u8) -> String {
    match how {
        0 => name.to_string(),
        1 => format!("./{name}"),
        2 => format!("sub/../{name}"),
        3 => dir.join(name).to_str().unwrap().to_string(),
        _ => {
            let link = format!("link-{name}");
            if std::fs::symlink_metadata(dir.join(&link)).is_err() {
                std::os::unix::fs::symlink(name, dir.join(&link)).unwrap();
            }
            link
        }
    }
}

/// The render every case runs: tiny, two timed frames (so a recording has frames).
const RENDER: [&str; 6] = ["--size", "16x9", "--lights", "4", "--frames", "2"];

proptest! {
    #![proptest_config(config(6))]

    #[test]
    fn an_output_onto_a_failing_file_fails_naming_it(
        output in output(),
        failing in failing(),
        direct in any::<bool>(),
    ) {
        if not_applicable() {
            return Ok(());
        }
        let dir = tempfile::tempdir().unwrap();
        let cwd = dir.path();
        if matches!(failing, Failing::ReadOnly) && ignores_permissions(cwd) {
            return Ok(());
        }
        let (path, named) = prepare(cwd, output, failing, direct);
        let mut args: Vec<&str> = RENDER.to_vec();
        args.extend([output.flag(), &path]);
        if !matches!(output, Output::Out) {
            args.extend(["--out", "ok.png"]);
        }
        let out = manylight(&args, &[], cwd);
        let msg = text(&out);
        prop_assert_eq!(out.status.code(), Some(1), "{:?}: {}", args, msg);
        prop_assert!(msg.contains(&named), "{:?}: expected `{}` in {}", args, named, msg);
        prop_assert!(!msg.contains("ms/frame") && !msg.contains("panicked"), "{:?}: {}", args, msg);
    }

    #[test]
    fn two_outputs_naming_one_file_are_refused_naming_both(
        pair in prop::sample::subsequence(vec![Output::Out, Output::Stats, Output::RecordGif], 2),
        spellings in (spelling(), spelling()),
    ) {
        if not_applicable() {
            return Ok(());
        }
        let dir = tempfile::tempdir().unwrap();
        let cwd = dir.path();
        std::fs::create_dir(cwd.join("sub")).unwrap();
        let a = spell(cwd, "same", spellings.0);
        let b = spell(cwd, "same", spellings.1);
        let mut args: Vec<&str> = RENDER.to_vec();
        args.extend([pair[0].flag(), &a, pair[1].flag(), &b]);
        let out = manylight(&args, &[], cwd);
        let msg = text(&out);
        prop_assert_eq!(out.status.code(), Some(2), "{:?}: {}", args, msg);
        prop_assert!(
            msg.contains(pair[0].flag()) && msg.contains(pair[1].flag()) && msg.contains("same file"),
            "{:?}: {}", args, msg
        );
        prop_assert!(!cwd.join("same").exists(), "{:?} wrote the file", args);
    }
}
