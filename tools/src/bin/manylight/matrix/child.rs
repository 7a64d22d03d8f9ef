//! A cell's child process: its environment and arguments, and what its output says.

use std::path::Path;
use std::process::{Command, ExitStatus, Output};

use serde_json::{json, Value};

use super::configs::DRIVER_ENV;

/// What every cell's child gets: no driver switch from the caller ([`DRIVER_ENV`]), and the
/// folder for its images, if any.
pub(super) fn cell_environment(cmd: &mut Command, out: Option<&Path>) {
    for var in DRIVER_ENV {
        cmd.env_remove(var);
    }
    if let Some(out) = out {
        // One argument: a folder named `-x` is no flag.
        let mut arg = std::ffi::OsString::from("--out=");
        arg.push(out);
        cmd.arg(arg);
    }
}

/// `--scene=NAME` as one argument: a file named `-x.json` is no flag.
pub(super) fn scene_arg(scene: &str) -> String {
    format!("--scene={scene}")
}

/// A cell's row: the last line of its output that is a JSON object (a driver may print lines
/// of its own there, as Mesa's "extension … cannot be disabled"), else why it has none.
pub(super) fn cell_row(output: &Output) -> Value {
    let stdout = String::from_utf8_lossy(&output.stdout);
    let row = stdout.lines().rev().find_map(|l| {
        serde_json::from_str::<Value>(l)
            .ok()
            .filter(Value::is_object)
    });
    match row {
        Some(row) if output.status.success() => row,
        _ => json!({
            "error": cell_error(&output.stderr, output.status),
            "methods": [],
        }),
    }
}

/// Why a cell failed, on one line for its table cell: the child's `error:` lines, without the
/// warnings logged before them; else how it ended, with its last line.
pub(super) fn cell_error(stderr: &[u8], status: ExitStatus) -> String {
    let text = String::from_utf8_lossy(stderr);
    let errors: Vec<&str> = text
        .lines()
        .filter_map(|l| l.strip_prefix("error: "))
        .map(str::trim)
        .collect();
    if !errors.is_empty() {
        return errors.join("; ");
    }
    let ended = if status.success() {
        "the cell printed no result".to_string()
    } else {
        format!("the cell stopped ({status})")
    };
    match text.lines().rev().map(str::trim).find(|l| !l.is_empty()) {
        Some(last) => format!("{ended}; its last line: {last}"),
        None => ended,
    }
}
