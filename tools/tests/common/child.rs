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

/// Set in a child that reruns a test with RGBA8 light records: `mesa` where Mesa's override
/// took float textures away, `played` where the child's ES 2.0 renderers play a device
/// without them (`Restrictions::no_float_textures`).
const RGBA8_LIGHTS: &str = "MANYLIGHT_TEST_RGBA8_LIGHTS";

/// Whether this process is a child rerunning a test with RGBA8 light records
/// ([`rerun_with_rgba8_lights`]).
pub fn rgba8_lights() -> bool {
    std::env::var_os(RGBA8_LIGHTS).is_some()
}

/// Whether this child's ES 2.0 renderers play a device without float textures.
pub fn plays_rgba8_lights() -> bool {
    std::env::var_os(RGBA8_LIGHTS).is_some_and(|v| v == "played")
}

/// Runs `test` again in a child process whose ES 2.0 contexts have no float textures, so that
/// lights go up in RGBA8 records and [`rgba8_lights`] is true; nothing in such a child. On
/// Mesa the driver loses `GL_OES_texture_float` (`MESA_EXTENSION_OVERRIDE`); on another
/// implementation, which ignores Mesa's switches, the renderers play the loss.
pub fn rerun_with_rgba8_lights(test: &str) {
    if rgba8_lights() {
        return;
    }
    if super::renders_with_mesa() {
        let envs = [
            ("MESA_EXTENSION_OVERRIDE", "-GL_OES_texture_float"),
            (RGBA8_LIGHTS, "mesa"),
        ];
        rerun_with(test, &envs, "RGBA8 light records");
    } else {
        let envs = [(RGBA8_LIGHTS, "played")];
        rerun_with(test, &envs, "RGBA8 light records (played)");
    }
}
