//! `manylight matrix`: the ES capability matrix a team runs in CI. Every configuration is a
//! real driver restriction applied to a child process (`MESA_GLES_VERSION_OVERRIDE`,
//! `MESA_EXTENSION_OVERRIDE`), except where no driver switch exists: a fragment stage without
//! highp is played by the renderer itself (`--no-fragment-highp`, shaders compiled all
//! mediump, which llvmpipe runs in fp16). Each child renders every method and compares it
//! with the reference (plain forward, light model at the best precision the configuration
//! has) on the same configuration.
//!
//! With `--gles-lib DIR` (more than once; `system` for the system's libraries) each
//! implementation gets a row group: ES 2.0, ES 2.0 without fragment highp (with float and with
//! RGBA8 light data), ES 2.0 with RGBA8 light data (all played) and ES 3.x on it; the Mesa
//! restrictions, softpipe and OSMesa rows belong to the system's group.

mod cell;
mod child;
mod configs;
mod restriction;
mod sheet;
mod table;
#[cfg(test)]
mod tests;
mod verdict;

use std::path::{Path, PathBuf};
use std::process::Command;

use clap::Parser;
use manylight::scene;
use manylight_tools::output::{self, print_stdout, JsonOut, OutputFile};
use serde_json::{json, Value};

use child::{cell_environment, cell_row, scene_arg};
use configs::{Config, Groups, CONFIGS, DRIVER_ENV};
use sheet::sheet;
use table::markdown;

pub use cell::{run_cell, MatrixCellArgs};

/// Options of `manylight matrix`.
#[derive(Parser, Debug)]
pub struct MatrixArgs {
    /// Scene rendered in every cell.
    #[arg(long, default_value = scene::builtin::DEFAULT, value_parser = crate::SceneSpec)]
    pub scene: String,
    /// Seeded random lights.
    #[arg(long, default_value_t = 256, value_parser = crate::bench_assign::parse_light_count)]
    pub lights: usize,
    /// Thumbnail size as WIDTHxHEIGHT.
    #[arg(long, default_value = "192x108", value_parser = crate::render::parse_size)]
    pub size: (u32, u32),
    /// Write the results as JSON to this file (`-`: to stdout, and the Markdown table to
    /// stderr).
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write each cell's image and a labelled contact sheet (`matrix.png`) into this folder
    /// (without it, no image is written).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Exit with status 1 when a method differs from forward on the same configuration by
    /// more than N/255 at any pixel, fails to render, or its cell crashes. Unsupported methods
    /// and configurations the driver cannot give do not count.
    #[arg(long, value_name = "N")]
    pub max_error: Option<u8>,
}

/// `MANYLIGHT_GLES_LIB` as the matrix's one implementation when no `--gles-lib` names any, as
/// for every other command; a warning when `--gles-lib` overrides it.
fn gles_lib_from_env(gles_libs: &[PathBuf]) -> Vec<PathBuf> {
    let env = manylight::gl::gles_lib::GLES_LIB_ENV;
    let Some(folder) = std::env::var_os(env).filter(|v| !v.is_empty()) else {
        return Vec::new();
    };
    if !gles_libs.is_empty() {
        log::warn!(
            "{env}={} is not used: --gles-lib names the matrix's implementations",
            folder.to_string_lossy()
        );
        return Vec::new();
    }
    vec![PathBuf::from(folder)]
}

/// `libs` with each implementation once, in their first order (a folder by the files it
/// names, however spelled); a warning where one was given twice: its rows ran twice, and
/// `system` twice wrote both OSMesa rows' pictures under one name.
fn once_each(libs: &[PathBuf]) -> Vec<PathBuf> {
    let mut kept: Vec<PathBuf> = Vec::new();
    let mut seen = Vec::new();
    for lib in libs {
        let same = output::identity(lib);
        if seen.contains(&same) {
            log::warn!(
                "--gles-lib {} names an implementation given before: its rows run once",
                scene::shown::path(lib)
            );
        } else {
            seen.push(same);
            kept.push(lib.clone());
        }
    }
    kept
}

/// `--allow-outside-files` for a cell when the matrix was given it.
fn outside_files_flag() -> Option<&'static str> {
    crate::load_options()
        .allow_outside_files
        .then_some("--allow-outside-files")
}

/// Runs the matrix: one child process per configuration and implementation (`gles_libs`:
/// folders, `system` for the system's libraries; none: the system's alone).
pub fn run(args: &MatrixArgs, gles_libs: &[PathBuf]) -> Result<(), Box<dyn std::error::Error>> {
    let exe = std::env::current_exe()?;
    let from_env = gles_lib_from_env(gles_libs);
    let gles_libs = if gles_libs.is_empty() {
        from_env
    } else {
        once_each(gles_libs)
    };
    let gles_libs = &gles_libs[..];
    // What every cell would fail on is an error of the matrix, not a row of failures: a scene
    // that cannot be read, outputs that cannot be written.
    let (_, report) =
        scene::load_with(&args.scene, Some((args.lights, 1)), &crate::load_options())?;
    output::protect_inputs(&report.files);
    for lib in gles_libs.iter().filter(|l| *l != Path::new("system")) {
        manylight::gl::gles_lib::files_in(lib)?;
    }
    let out = args.out.as_deref();
    if let Some(out) = out {
        std::fs::create_dir_all(out)
            .map_err(|e| format!("cannot create {}: {e}", scene::shown::path(out)))?;
    }
    let json_out = args.json.as_deref().map(JsonOut::create).transpose()?;
    // `-`, or a name of standard output (`/dev/stdout`): the table then goes to stderr.
    let json_to_stdout = args.json.as_deref().is_some_and(output::names_stdout);
    let sheet_file = out
        .map(|out| OutputFile::create(&out.join("matrix.png")))
        .transpose()?;
    for var in DRIVER_ENV {
        if let Some(value) = std::env::var_os(var) {
            log::warn!(
                "{var}={} is not passed to the matrix's cells: each row sets its own restriction",
                value.to_string_lossy()
            );
        }
    }
    let size = format!("{}x{}", args.size.0, args.size.1);
    let system = [PathBuf::from("system")];
    let groups = if gles_libs.is_empty() {
        &system[..]
    } else {
        gles_libs
    };
    let mut rows = Vec::new();
    for (g, lib) in groups.iter().enumerate() {
        let lib = (lib != Path::new("system")).then_some(lib.as_path());
        rows.extend(group_rows(&exe, args, &size, out, lib, g)?);
    }
    let failures = args
        .max_error
        .map(|n| verdict::mark(&mut rows, n))
        .unwrap_or_default();
    let json = serde_json::to_string_pretty(&rows)? + "\n";
    if json_to_stdout {
        eprint!("{}", markdown(&rows));
    } else {
        print_stdout(&markdown(&rows))?;
    }
    if let Some(out) = json_out {
        out.commit(&json)?;
    }
    if let (Some(file), Some(out)) = (sheet_file, out) {
        let path = scene::shown::path(file.path());
        file.commit_png(&sheet(&rows, out))?;
        eprintln!("contact sheet: {path}");
    }
    if let Some(error) = rows
        .iter()
        .map(|r| r["error"].as_str())
        .collect::<Option<Vec<_>>>()
        .and_then(|errors| errors.first().copied())
    {
        return Err(format!("no configuration of the matrix could run: {error}").into());
    }
    if let (Some(n), false) = (args.max_error, failures.is_empty()) {
        for failure in &failures {
            eprintln!("over --max-error {n}: {failure}");
        }
        return Err(format!(
            "{} of the matrix's renders fail --max-error {n} (listed above)",
            failures.len()
        )
        .into());
    }
    Ok(())
}

/// The rows of one implementation (`lib`: its folder; `None`: the system's, with the Mesa
/// restrictions and OSMesa). `group` numbers the implementation in file names.
fn group_rows(
    exe: &Path,
    args: &MatrixArgs,
    size: &str,
    out: Option<&Path>,
    lib: Option<&Path>,
    group: usize,
) -> Result<Vec<Value>, Box<dyn std::error::Error>> {
    let label = lib.map_or_else(|| "system".to_string(), scene::shown::path);
    let mut rows = Vec::new();
    let wanted = if lib.is_none() {
        Groups::System
    } else {
        Groups::Others
    };
    for config in CONFIGS
        .iter()
        .filter(|c| c.groups == Groups::All || c.groups == wanted)
    {
        let tag = if group == 0 {
            config.slug.to_string()
        } else {
            format!("lib{group}-{}", config.slug)
        };
        let mut cmd = Command::new(exe);
        cmd.args([
            "matrix-cell",
            "--es",
            config.es,
            &scene_arg(&args.scene),
            "--size",
            config.size.unwrap_or(size),
        ])
        .args(["--lights", &args.lights.to_string(), "--tag", &tag])
        .args(config.args)
        .args(outside_files_flag());
        cell_environment(&mut cmd, out);
        for (k, v) in config.env {
            cmd.env(k, v);
        }
        match lib {
            Some(dir) => cmd.env(manylight::gl::gles_lib::GLES_LIB_ENV, dir),
            None => cmd.env_remove(manylight::gl::gles_lib::GLES_LIB_ENV),
        };
        rows.push(labelled_row(config, cell_row(&cmd.output()?), &label));
    }
    name_failed_rows(&mut rows, &label);
    if lib.is_none() {
        let mut row = osmesa_row(exe, args, size, out)?;
        row["gles_lib"] = json!(label);
        if row["implementation"].is_null() {
            row["implementation"] = json!("OSMesa");
        }
        rows.push(row);
    }
    Ok(rows)
}

/// A cell's `row` named by its configuration and implementation (`label`), and marked where
/// the configuration's driver switch did not take effect.
fn labelled_row(config: &Config, mut row: Value, label: &str) -> Value {
    let mut env: Vec<String> = config.env.iter().map(|(k, v)| format!("{k}={v}")).collect();
    restriction::check(&mut row, config.shows, &env);
    env.extend(config.args.iter().map(|a| a.to_string()));
    row["config"] = json!(config.name);
    row["gles_lib"] = json!(label);
    row["env"] = json!(env);
    row
}

/// Desktop GL through OSMesa, when built with the `osmesa` feature.
fn osmesa_row(
    exe: &Path,
    args: &MatrixArgs,
    size: &str,
    out: Option<&Path>,
) -> Result<Value, Box<dyn std::error::Error>> {
    if !cfg!(feature = "osmesa") {
        return Ok(json!({
            "config": "desktop GL (OSMesa)",
            "error": "not built: rebuild with `--features osmesa`",
            "refused": true,
            "env": [],
            "methods": [],
        }));
    }
    let mut cmd = Command::new(exe);
    cmd.args([
        "matrix-cell",
        "--es",
        "3",
        "--osmesa",
        &scene_arg(&args.scene),
        "--size",
        size,
    ])
    .args(["--lights", &args.lights.to_string(), "--tag", "osmesa"])
    .args(outside_files_flag());
    cell_environment(&mut cmd, out);
    let mut row = cell_row(&cmd.output()?);
    row["config"] = json!("desktop GL (OSMesa)");
    row["env"] = json!([]);
    Ok(row)
}

/// Names the implementation of each row of one group whose context could not be made (its
/// `implementation` null): the one its group's other EGL rows on the same driver name (not
/// OSMesa's, another library), else the group's `label`. A row whose `GALLIUM_DRIVER` picks
/// another driver (softpipe) shares no name: a failed llvmpipe row is not softpipe's, nor the
/// other way round.
fn name_failed_rows(rows: &mut [Value], label: &str) {
    let own_driver = |row: &Value| {
        let env = row["env"].as_array().into_iter().flatten();
        !env.filter_map(Value::as_str)
            .any(|e| e.starts_with("GALLIUM_DRIVER="))
    };
    let implementation = rows
        .iter()
        .filter(|r| own_driver(r))
        .find_map(|r| r["implementation"].as_str().map(String::from));
    for row in rows {
        if row["implementation"].is_null() {
            let named = implementation.as_deref().filter(|_| own_driver(row));
            row["implementation"] = json!(named.unwrap_or(label));
        }
    }
}
