//! Running the `manylight` binary the way a user does, for the command-line tests.

use std::path::Path;
use std::process::{Command, Output};

/// Runs `manylight ARGS` in `cwd` with extra environment.
pub fn manylight(args: &[&str], env: &[(&str, &str)], cwd: &Path) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_manylight"));
    cmd.args(args).current_dir(cwd);
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().expect("run manylight")
}

/// stdout then stderr, as text.
pub fn text(out: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// Runs `manylight ARGS`, asserting its exit status and that nothing panicked; returns the
/// output.
pub fn expect_status(args: &[&str], env: &[(&str, &str)], cwd: &Path, code: i32) -> String {
    let out = manylight(args, env, cwd);
    let msg = text(&out);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {msg}");
    assert!(!msg.contains("panicked"), "{args:?} panicked: {msg}");
    msg
}

/// [`expect_status`], and the output names `needle`.
pub fn expect_exit(
    args: &[&str],
    env: &[(&str, &str)],
    cwd: &Path,
    code: i32,
    needle: &str,
) -> String {
    let msg = expect_status(args, env, cwd, code);
    assert!(
        msg.contains(needle),
        "{args:?}: expected `{needle}` in: {msg}"
    );
    msg
}
