//! Running one test again in a child process with a changed environment: Mesa reads its
//! overrides (`MESA_GLES_VERSION_OVERRIDE`, `MESA_EXTENSION_OVERRIDE`) once per process.

/// Runs the test named `test` of this test binary in a child process with `envs` set, and
/// fails naming `what` unless it ran and passed.
pub fn rerun_with(test: &str, envs: &[(&str, &str)], what: &str) {
    let mut command = std::process::Command::new(std::env::current_exe().unwrap());
    command.args(["--exact", test, "--test-threads=1"]);
    for (key, value) in envs {
        command.env(key, value);
    }
    let out = command.output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && stdout.contains("1 passed"),
        "{what}: {stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
