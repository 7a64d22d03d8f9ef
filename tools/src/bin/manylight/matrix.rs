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

mod restriction;
mod verdict;

use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Output};

use clap::Parser;
use manylight::gl::HeadlessContext;
use manylight::methods::{Support, METHODS};
use manylight::{scene, EsVersion, RenderOptions, Renderer};
use manylight_tools::output::{self, print_stdout, JsonOut, OutputFile};
use serde_json::{json, Value};

use crate::EsArg;
use restriction::Shows;

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

/// The driver switches the configurations set: cleared in every cell first, so a row is
/// the restriction its label names and no other the caller's environment carried.
const DRIVER_ENV: [&str; 3] = [
    "MESA_GLES_VERSION_OVERRIDE",
    "MESA_EXTENSION_OVERRIDE",
    "GALLIUM_DRIVER",
];

/// One configuration: a name, the ES version asked for, and the environment that restricts
/// the driver.
struct Config {
    name: &'static str,
    slug: &'static str,
    es: &'static str,
    env: &'static [(&'static str, &'static str)],
    /// Extra arguments of the child (restrictions the renderer plays itself).
    args: &'static [&'static str],
    /// Image size instead of the matrix's (a slow driver renders a smaller image).
    size: Option<&'static str>,
    /// Which row groups have it.
    groups: Groups,
    /// What its context shows when `env` took effect.
    shows: Shows,
}

/// The row groups a configuration belongs to.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Groups {
    /// Every implementation's.
    All,
    /// The system's alone: a Mesa switch (environment override, second driver).
    System,
    /// The other implementations': a restriction the renderer plays where no Mesa switch exists.
    Others,
}

const CONFIGS: &[Config] = &[
    Config {
        name: "ES 2.0",
        slug: "es2",
        es: "2",
        env: &[],
        args: &[],
        groups: Groups::All,
        size: None,
        shows: Shows::Nothing,
    },
    Config {
        name: "ES 2.0 without fragment highp (played)",
        slug: "es2-mediump",
        es: "2",
        env: &[],
        args: &["--no-fragment-highp"],
        groups: Groups::All,
        size: None,
        shows: Shows::Nothing,
    },
    Config {
        // A Mali-400's pair: its lights as 16-bit RGBA8 records decoded in fp16.
        name: "ES 2.0 without fragment highp or float textures (played)",
        slug: "es2-mediump-rgba8",
        es: "2",
        env: &[],
        args: &["--no-fragment-highp", "--no-float-textures"],
        groups: Groups::All,
        size: None,
        shows: Shows::Nothing,
    },
    Config {
        name: "ES 2.0 with RGBA8 light data (played)",
        slug: "es2-rgba8",
        es: "2",
        env: &[],
        args: &["--no-float-textures"],
        groups: Groups::Others,
        size: None,
        shows: Shows::Nothing,
    },
    Config {
        name: "ES 2.0 without float textures",
        slug: "es2-nofloat",
        es: "2",
        env: &[(
            "MESA_EXTENSION_OVERRIDE",
            "-GL_OES_texture_float -GL_OES_texture_half_float",
        )],
        args: &[],
        groups: Groups::System,
        size: None,
        shows: Shows::NoFloatTextures,
    },
    Config {
        name: "ES 2.0 driver (capped)",
        slug: "es2-capped",
        es: "2",
        env: &[("MESA_GLES_VERSION_OVERRIDE", "2.0")],
        args: &[],
        groups: Groups::System,
        size: None,
        shows: Shows::GlVersion("OpenGL ES 2.0"),
    },
    Config {
        name: "ES 3.0 driver (capped)",
        slug: "es3-capped",
        es: "3",
        env: &[("MESA_GLES_VERSION_OVERRIDE", "3.0")],
        args: &[],
        groups: Groups::System,
        size: None,
        shows: Shows::GlVersion("OpenGL ES 3.0"),
    },
    Config {
        name: "ES 3.x as the driver gives it",
        slug: "es3",
        es: "3",
        env: &[],
        args: &[],
        groups: Groups::All,
        size: None,
        shows: Shows::Nothing,
    },
    // A second Mesa rasterizer (mediump at fp32, no LLVM): slow, so a small image. Where it
    // and llvmpipe differ, it is on triangle edges only (tests/second_driver.rs).
    Config {
        name: "ES 3.x on softpipe (second Mesa driver)",
        slug: "es3-softpipe",
        es: "3",
        env: &[("GALLIUM_DRIVER", "softpipe")],
        args: &[],
        groups: Groups::System,
        size: Some("96x54"),
        shows: Shows::Renderer("softpipe"),
    },
];

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
        &from_env[..]
    } else {
        gles_libs
    };
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

/// What every cell's child gets: no driver switch from the caller ([`DRIVER_ENV`]), and the
/// folder for its images, if any.
fn cell_environment(cmd: &mut Command, out: Option<&Path>) {
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
fn scene_arg(scene: &str) -> String {
    format!("--scene={scene}")
}

/// A cell's row: the last line of its output that is a JSON object (a driver may print lines
/// of its own there, as Mesa's "extension … cannot be disabled"), else why it has none.
fn cell_row(output: &Output) -> Value {
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
fn cell_error(stderr: &[u8], status: ExitStatus) -> String {
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

/// A row's implementation (its folder where the context could not say) and configuration.
/// Each row's implementation as the table and sheet show it, and its configuration: the
/// implementation's family, with the `--gles-lib` it came from where another row's
/// implementation of the same family came from elsewhere (two Mesa builds).
fn row_labels(rows: &[Value]) -> Vec<(String, &str)> {
    let family = |row: &Value| {
        row["implementation"]
            .as_str()
            .or(row["gles_lib"].as_str())
            .unwrap_or("?")
            .to_string()
    };
    let lib = |row: &Value| row["gles_lib"].as_str().unwrap_or("?").to_string();
    rows.iter()
        .map(|row| {
            let shared = rows
                .iter()
                .any(|other| family(other) == family(row) && lib(other) != lib(row));
            let implementation = if shared {
                format!("{} ({})", family(row), lib(row))
            } else {
                family(row)
            };
            (implementation, row["config"].as_str().unwrap_or("?"))
        })
        .collect()
}

/// What a row with an `error` is: a configuration this machine cannot give, or a failure.
fn row_failure(row: &Value) -> &'static str {
    if row["refused"] == true {
        "unavailable"
    } else {
        "failed"
    }
}

fn markdown(rows: &[Value]) -> String {
    let mut s = String::from("| implementation | configuration | context | method | support | max abs vs forward | max abs vs reference | pixels > 2/255 | frame ms |\n|---|---|---|---|---|---|---|---|---|\n");
    for (row, (implementation, config)) in rows.iter().zip(row_labels(rows)) {
        let config = &format!("{implementation} | {config}");
        if let Some(err) = row["error"].as_str() {
            let what = row_failure(row);
            s += &format!("| {config} | — | — | {what}: {err} | | | | |\n");
            continue;
        }
        let context = match row["max_samples"].as_i64() {
            Some(n) if n > 1 => format!(
                "{}, MSAA up to {n}×",
                row["gl_version"].as_str().unwrap_or("?")
            ),
            _ => format!("{}, no MSAA", row["gl_version"].as_str().unwrap_or("?")),
        };
        for m in row["methods"].as_array().into_iter().flatten() {
            let status = m["support"]["status"].as_str().unwrap_or("?");
            let support = match (m["error"].as_str(), m["support"]["reason"].as_str()) {
                (Some(e), _) => format!("error: {e}"),
                (None, Some(r)) => format!("{status}: {r}"),
                (None, None) => status.to_string(),
            };
            let num = |k: &str, digits: usize| {
                m[k].as_f64()
                    .map_or(String::new(), |v| format!("{v:.digits$}"))
            };
            let name = m["name"].as_str().unwrap_or("?");
            let method = match m["auto_choice"].as_str() {
                Some(choice) => format!("{name} → {choice}"),
                None => name.to_string(),
            };
            s += &format!(
                "| {config} | {context} | {method} | {support} | {} | {} | {} | {} |\n",
                num("max_abs_vs_forward", 0),
                num("max_abs", 0),
                m["over_2"]
                    .as_f64()
                    .map_or(String::new(), |v| format!("{:.3} %", v * 100.0)),
                num("frame_ms", 1),
            );
        }
    }
    s
}

/// Longest side of a contact sheet's thumbnail: the sheet holds every cell's at once, so full
/// pictures would make its memory grow with the frame's size.
const THUMB_MAX: u32 = 512;

/// The picture in `file`, scaled down to fit [`THUMB_MAX`] (one full picture decoded at a time).
fn thumbnail(file: &Path) -> Option<image::RgbaImage> {
    let picture = image::open(file).ok()?;
    let fits = picture.width().max(picture.height()) <= THUMB_MAX;
    Some(
        if fits {
            picture
        } else {
            picture.thumbnail(THUMB_MAX, THUMB_MAX)
        }
        .to_rgba8(),
    )
}

fn sheet(rows: &[Value], out: &Path) -> image::RgbaImage {
    let mut cells = Vec::new();
    for (row, (implementation, config)) in rows.iter().zip(row_labels(rows)) {
        let config = format!("{implementation}: {config}");
        if row["error"].is_string() {
            cells.push((vec![config, row_failure(row).to_string()], None));
            continue;
        }
        for m in row["methods"].as_array().into_iter().flatten() {
            let name = m["name"].as_str().unwrap_or("?");
            let thumb = m["image"].as_str().and_then(|f| thumbnail(&out.join(f)));
            let detail = match (m["support"]["status"].as_str(), m["max_abs"].as_f64()) {
                _ if m["error"].is_string() => "error".to_string(),
                (Some("unsupported"), _) => "unsupported".to_string(),
                (Some(status), Some(err)) => format!("{status}, max err {err:.0}/255"),
                (status, _) => status.unwrap_or("?").to_string(),
            };
            cells.push((vec![config.clone(), format!("{name}: {detail}")], thumb));
        }
    }
    manylight_tools::sheet::contact_sheet(&cells, METHODS.len())
}

/// `--tag` of the hidden child: letters, digits, `-`, `_` and `.` only, not starting with `.`,
/// so `TAG-METHOD.png` is a file inside `--out`.
fn parse_tag(s: &str) -> Result<String, String> {
    let fits = |c: char| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.');
    if s.is_empty() || s.starts_with('.') || !s.chars().all(fits) {
        return Err("a tag is letters, digits, `-`, `_` and `.`, not starting with `.`".into());
    }
    Ok(s.to_string())
}

/// Options of the hidden per-configuration child.
#[derive(Parser, Debug)]
pub struct MatrixCellArgs {
    #[arg(long, value_enum)]
    es: EsArg,
    #[arg(long)]
    scene: String,
    #[arg(long, value_parser = crate::render::parse_size)]
    size: (u32, u32),
    #[arg(long)]
    lights: usize,
    /// Starts each image's file name: one name, no folder, so the image stays inside `--out`.
    #[arg(long, value_parser = parse_tag)]
    tag: String,
    /// The folder for the cell's images (none written without it).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Desktop GL through OSMesa instead of EGL (needs the `osmesa` feature).
    #[arg(long)]
    osmesa: bool,
    /// Play a device without fragment highp.
    #[arg(long)]
    no_fragment_highp: bool,
    /// Play a device without float textures: light records packed in RGBA8.
    #[arg(long)]
    no_float_textures: bool,
}

/// The context a matrix cell renders with (kept alive for the renderer's life).
enum CellContext {
    Egl(Box<HeadlessContext>),
    #[cfg(feature = "osmesa")]
    OsMesa(manylight::gl::osmesa::OsMesaContext),
}

impl CellContext {
    fn new(es: EsVersion, osmesa: bool) -> Result<CellContext, Box<dyn std::error::Error>> {
        if osmesa {
            #[cfg(feature = "osmesa")]
            return Ok(CellContext::OsMesa(
                manylight::gl::osmesa::OsMesaContext::new()?,
            ));
            #[cfg(not(feature = "osmesa"))]
            return Err("this build has no OSMesa support (cargo feature `osmesa`)".into());
        }
        Ok(CellContext::Egl(Box::new(HeadlessContext::new(es)?)))
    }

    fn load_gl(&self) -> Result<glow::Context, manylight::GlError> {
        match self {
            CellContext::Egl(c) => c.load_gl(),
            #[cfg(feature = "osmesa")]
            CellContext::OsMesa(c) => Ok(c.load_gl()),
        }
    }
}

/// The row of a configuration this machine cannot give (its context could not be made, or
/// is another version): printed as the cell's result, marked `refused`, so the matrix lists
/// it without counting it as a failure.
fn print_refusal(e: &dyn std::error::Error) -> Result<(), Box<dyn std::error::Error>> {
    let row = json!({"error": e.to_string(), "refused": true, "methods": []});
    print_stdout(&format!("{row}\n"))?;
    Ok(())
}

/// Renders every method in this (restricted) process and prints one JSON row.
pub fn run_cell(args: &MatrixCellArgs) -> Result<(), Box<dyn std::error::Error>> {
    let es: EsVersion = args.es.into();
    let (scene, report) =
        scene::load_with(&args.scene, Some((args.lights, 1)), &crate::load_options())?;
    output::protect_inputs(&report.files);
    let (w, h) = args.size;
    let opts = RenderOptions {
        measure: manylight::MeasureOptions {
            timed_frames: 3,
            ..Default::default()
        },
        ..RenderOptions::default()
    };
    // The reference comes from an unrestricted renderer of its own (made, used and dropped
    // before the cell's context, since creating a context makes it current): under a played
    // restriction the driver underneath is unrestricted, so the row shows what it costs.
    let reference = {
        let ctx = match CellContext::new(es, args.osmesa) {
            Ok(ctx) => ctx,
            Err(e) if args.osmesa || crate::version_unavailable(&*e) => return print_refusal(&*e),
            // A driver that cannot start, a library that cannot load: the cell fails.
            Err(e) => return Err(e),
        };
        let mut full = match Renderer::new(ctx.load_gl()?, es) {
            Err(e) if crate::version_unavailable(&e) => return print_refusal(&e),
            made => made?,
        };
        full.set_method_named("forward")?;
        let reference_opts = RenderOptions {
            measure: manylight::MeasureOptions {
                reference_precision: true,
                ..Default::default()
            },
            ..RenderOptions::default()
        };
        let result = full.render_offscreen(&scene, w, h, &reference_opts);
        full.destroy();
        result?.0
    };
    let ctx = CellContext::new(es, args.osmesa)?;
    let restrictions = manylight::gl::Restrictions {
        no_fragment_highp: args.no_fragment_highp,
        no_float_textures: args.no_float_textures,
    };
    let mut renderer = match Renderer::restricted(ctx.load_gl()?, es, &restrictions) {
        Err(e) if crate::version_unavailable(&e) => return print_refusal(&e),
        made => made?,
    };
    let mut methods = Vec::new();
    let mut images = Vec::new();
    for m in METHODS {
        let support = (m.supported)(renderer.caps());
        let mut entry = json!({"name": m.name, "support": support});
        if matches!(support, Support::Unsupported(_)) {
            methods.push(entry);
            continue;
        }
        // One method failing is its entry's error; the others are still measured.
        let rendered = renderer
            .set_method_named(m.name)
            .and_then(|_| renderer.render_offscreen(&scene, w, h, &opts));
        match rendered {
            Ok((img, stats)) => {
                let d = manylight::metrics::diff(&reference, &img);
                entry["max_abs"] = json!(d.max_abs);
                entry["rmse"] = json!(d.rmse);
                entry["over_2"] = json!(d.over_2);
                entry["frame_ms"] = json!(stats.time.frame_ms);
                entry["light_encoding"] = json!(stats.lights.encoding);
                if stats.auto_choice.is_some() {
                    entry["auto_choice"] = json!(stats.auto_choice);
                    entry["auto_reason"] = json!(stats.auto_reason);
                }
                if let Some(out) = &args.out {
                    let file = format!("{}-{}.png", args.tag, m.name);
                    output::save_png(&out.join(&file), &img)?;
                    entry["image"] = json!(file);
                }
                images.push((methods.len(), img));
            }
            Err(e) => entry["error"] = json!(e.to_string()),
        }
        methods.push(entry);
    }
    // Each method against forward on this very configuration: what a method must equal.
    if let Some((_, forward)) = images
        .iter()
        .find(|(i, _)| methods[*i]["name"] == "forward")
    {
        for (i, img) in &images {
            methods[*i]["max_abs_vs_forward"] =
                json!(manylight::metrics::diff(forward, img).max_abs);
        }
    }
    let caps = renderer.caps().clone();
    renderer.destroy();
    let row = json!({
        "es": caps.es,
        "gl_version": caps.gl_version,
        "renderer": caps.renderer,
        "implementation": caps.implementation(),
        "float_textures": caps.float_textures,
        "fragment_highp": caps.fragment_has_highp(),
        "max_samples": caps.max_samples,
        "methods": methods,
    });
    print_stdout(&format!("{row}\n"))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::{cell_error, cell_row, markdown, name_failed_rows, sheet, THUMB_MAX};
    use super::{labelled_row, CONFIGS};
    use serde_json::json;

    /// The system's libraries need not be Mesa (a device farm's driver): there every row of a
    /// Mesa switch is unavailable, not a pass of the unrestricted driver under its name, and
    /// every other row stays as its cell made it.
    #[test]
    fn every_mesa_switch_row_on_another_implementation_is_unavailable() {
        let swiftshader = json!({"implementation": "SwiftShader", "float_textures": true,
            "gl_version": "OpenGL ES 3.2 SwiftShader", "renderer": "Google SwiftShader",
            "methods": [{"name": "forward", "max_abs_vs_forward": 0}]});
        for config in CONFIGS {
            let row = labelled_row(config, swiftshader.clone(), "system");
            if config.env.is_empty() {
                assert!(row["error"].is_null(), "{}: {row}", config.name);
                assert_eq!(row["methods"], swiftshader["methods"], "{}", config.name);
            } else {
                assert_eq!(row["refused"], true, "{}: {row}", config.name);
                assert_eq!(row["methods"], json!([]), "{}", config.name);
                assert!(row["error"].as_str().unwrap().contains("not applied"));
            }
        }
    }

    /// A row whose context failed (an llvmpipe row at a size it cannot take) is named after
    /// its group's rows on the same driver, never after softpipe's, which succeeded.
    #[test]
    fn a_failed_row_takes_its_own_drivers_name() {
        let softpipe = json!({"implementation": "Mesa softpipe", "config": "ES 3.x on softpipe",
            "env": ["GALLIUM_DRIVER=softpipe"]});
        let failed = json!({"implementation": null, "config": "ES 3.0", "env": []});
        let mut rows = [softpipe.clone(), failed.clone()];
        name_failed_rows(&mut rows, "system");
        assert_eq!(rows[1]["implementation"], "system");
        let llvmpipe = json!({"implementation": "Mesa llvmpipe", "config": "ES 2.0", "env": []});
        let mut rows = [softpipe, llvmpipe.clone(), failed];
        name_failed_rows(&mut rows, "system");
        assert_eq!(rows[2]["implementation"], "Mesa llvmpipe");
        assert_eq!(rows[0]["implementation"], "Mesa softpipe");
        // Nor the other way round: a failed softpipe row is not llvmpipe's.
        let failed_softpipe = json!({"implementation": null, "config": "ES 3.x on softpipe",
            "env": ["GALLIUM_DRIVER=softpipe"]});
        let mut rows = [llvmpipe, failed_softpipe];
        name_failed_rows(&mut rows, "system");
        assert_eq!(rows[1]["implementation"], "system");
    }

    /// Large pictures go on the sheet scaled down to fit [`THUMB_MAX`], their shape kept; small
    /// ones as they are.
    #[test]
    fn the_sheet_holds_large_pictures_as_thumbnails() {
        let dir = tempfile::tempdir().unwrap();
        let picture = image::RgbaImage::from_pixel(2048, 1152, image::Rgba([200, 0, 0, 255]));
        picture.save(dir.path().join("big.png")).unwrap();
        let small = image::RgbaImage::from_pixel(64, 36, image::Rgba([0, 200, 0, 255]));
        small.save(dir.path().join("small.png")).unwrap();
        let rows = [
            json!({"implementation": "Mesa llvmpipe", "config": "ES 3.0",
            "methods": [{"name": "forward", "image": "big.png"},
                        {"name": "clustered", "image": "small.png"}]}),
        ];
        let sheet = sheet(&rows, dir.path());
        assert!(sheet.height() < THUMB_MAX + 100, "{:?}", sheet.dimensions());
        let red = |p: &&image::Rgba<u8>| p.0 == [200, 0, 0, 255];
        let green = |p: &&image::Rgba<u8>| p.0 == [0, 200, 0, 255];
        assert_eq!(sheet.pixels().filter(red).count(), 512 * 288);
        assert_eq!(sheet.pixels().filter(green).count(), 64 * 36);
    }

    /// Two implementations of one family (two Mesa builds) are told apart by their folders;
    /// auto's row says what it ran.
    #[test]
    fn the_table_tells_same_family_implementations_apart_and_says_what_auto_ran() {
        let row = |lib: &str| {
            json!({"implementation": "Mesa llvmpipe", "gles_lib": lib, "config": "ES 3.0",
                "gl_version": "3.2", "max_samples": 4,
                "methods": [{"name": "auto", "support": {"status": "supported"},
                    "auto_choice": "forward", "max_abs_vs_forward": 0}]})
        };
        let table = markdown(&[row("system"), row("/opt/mesa")]);
        assert!(table.contains("| Mesa llvmpipe (system) |"), "{table}");
        assert!(table.contains("| Mesa llvmpipe (/opt/mesa) |"), "{table}");
        assert!(table.contains("| auto → forward |"), "{table}");
        let alone = markdown(&[row("system")]);
        assert!(alone.contains("| Mesa llvmpipe | ES 3.0 |"), "{alone}");
    }
    use std::os::unix::process::ExitStatusExt;
    use std::process::{ExitStatus, Output};

    #[test]
    fn a_cell_error_is_one_line_without_the_warnings_before_it() {
        let stderr = b"[WARN  manylight::renderer] fragment mediump\nerror: lights[0]: too far\n";
        let failed = ExitStatus::from_raw(1 << 8);
        assert_eq!(cell_error(stderr, failed), "lights[0]: too far");
        assert_eq!(
            cell_error(b"[WARN  x] slow\nthread panicked\nboom\n\n", failed),
            "the cell stopped (exit status: 1); its last line: boom"
        );
        assert_eq!(
            cell_error(b"", ExitStatus::from_raw(0)),
            "the cell printed no result"
        );
    }

    /// A driver's own line on stdout (Mesa's, under `MESA_EXTENSION_OVERRIDE`) does not hide
    /// the row printed before it.
    #[test]
    fn a_cells_row_is_its_last_json_line_whatever_follows() {
        let output = Output {
            status: ExitStatus::from_raw(0),
            stdout: b"{\"es\":\"2\",\"methods\":[]}\nWarning: extension 'X' cannot be disabled\n"
                .to_vec(),
            stderr: Vec::new(),
        };
        let row = cell_row(&output);
        assert_eq!(row["es"], "2", "{row}");
        assert!(row["error"].is_null(), "{row}");
        let failed = Output {
            status: ExitStatus::from_raw(1 << 8),
            ..output
        };
        assert!(cell_row(&failed)["error"].is_string());
    }
}
