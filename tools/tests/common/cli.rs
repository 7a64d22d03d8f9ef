//! Running the `manylight` binary the way a user does, for the command-line tests.

use std::path::Path;
use std::process::{Child, Command, Output};
use std::time::{Duration, Instant};

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

/// Waits for `child` at most `timeout`; kills it (our own child) when it runs over. Its
/// output is read meanwhile, on threads of its own: a screenshot sent to standard output
/// is more than a pipe's buffer holds.
pub fn wait_with_timeout(mut child: Child, what: &str, timeout: Duration) -> Output {
    use std::io::Read;
    let drain = |pipe: Option<Box<dyn Read + Send>>| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            if let Some(mut pipe) = pipe {
                pipe.read_to_end(&mut bytes)
                    .expect("read the child's output");
            }
            bytes
        })
    };
    let stdout = drain(
        child
            .stdout
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let stderr = drain(
        child
            .stderr
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("try_wait") {
            break status;
        }
        if start.elapsed() > timeout {
            let _ = child.kill();
            let _ = child.wait();
            panic!(
                "{what} ran over {timeout:?}; stderr:\n{}",
                String::from_utf8_lossy(&stderr.join().expect("stderr"))
            );
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    Output {
        status,
        stdout: stdout.join().expect("stdout"),
        stderr: stderr.join().expect("stderr"),
    }
}
