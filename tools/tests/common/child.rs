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

/// Set in a child that reruns a test with RGBA8 light records.
const RGBA8_LIGHTS: &str = "MANYLIGHT_TEST_RGBA8_LIGHTS";

/// Whether this process is a child rerunning a test with RGBA8 light records
/// ([`rerun_with_rgba8_lights`]).
pub fn rgba8_lights() -> bool {
    std::env::var_os(RGBA8_LIGHTS).is_some()
}

/// Runs `test` again in a child process whose Mesa has no `GL_OES_texture_float` (an ES 2.0
/// context at most, whose lights go up in RGBA8 records), where [`rgba8_lights`] is true;
/// nothing in such a child, or on another implementation than Mesa.
pub fn rerun_with_rgba8_lights(test: &str) {
    if rgba8_lights() || super::other_implementation_than_mesa("MESA_EXTENSION_OVERRIDE") {
        return;
    }
    rerun_with(
        test,
        &[
            ("MESA_EXTENSION_OVERRIDE", "-GL_OES_texture_float"),
            (RGBA8_LIGHTS, "1"),
        ],
        "RGBA8 light records",
    );
}
