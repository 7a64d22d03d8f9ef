//! The `manylight` command line: `render` (the default), `info`, `bench`, `bench-assign`,
//! `matrix`, `view`.

/// `std::eprintln!` for this binary and its modules, except that a standard error that cannot
/// be written (`2>/dev/full`) is ignored instead of panicking: there is nowhere left to say so,
/// and the exit status still tells.
macro_rules! eprintln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

mod bench;
mod bench_assign;
mod black_frame;
mod info;
mod matrix;
mod progress;
mod render;
mod sequence;
mod thread_pool;
#[cfg(feature = "window")]
mod view;

use std::path::Path;
use std::process::ExitCode;

use clap::error::ErrorKind;
use clap::{CommandFactory, FromArgMatches, Parser, Subcommand, ValueEnum};
use manylight::scene::shown;
use manylight::{EsVersion, LoadOptions};
use manylight_tools::output;

/// How every subcommand loads its scene (set once from the command line).
static LOAD_OPTIONS: std::sync::OnceLock<LoadOptions> = std::sync::OnceLock::new();

/// The scene-loading options the command line asked for.
pub fn load_options() -> LoadOptions {
    LOAD_OPTIONS.get().copied().unwrap_or_default()
}

/// Thousands of dynamic lights on OpenGL ES 2.0 / 3.0, rendered headless through EGL.
#[derive(Parser)]
#[command(
    name = "manylight",
    version,
    // Not the package's description, which names `view` also where the build leaves it out.
    about = "Thousands of dynamic lights on OpenGL ES 2.0 and 3.0: render scenes, probe \
             contexts, compare methods and time them",
    args_conflicts_with_subcommands = true
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Folder of the OpenGL ES implementation to render with (its libEGL.so[.1] and
    /// libGLESv2.so[.2]: SwiftShader, ANGLE, a device's driver) instead of the system's; the
    /// same as MANYLIGHT_GLES_LIB (docs/drivers.md). Only `matrix` takes it more than once,
    /// and there `system` names the system's libraries. Not for `view`, whose window's GL comes
    /// from glutin.
    #[arg(long, global = true, value_name = "DIR")]
    gles_lib: Vec<std::path::PathBuf>,
    /// Let a model's references (glTF buffer and image URIs, OBJ mtllib and texture paths)
    /// name files outside the model's folder (`../x`, absolute paths, links leading out).
    /// Refused by default: an untrusted model must not read your files. Only for models you
    /// trust.
    #[arg(long, global = true)]
    allow_outside_files: bool,
    /// With no subcommand, `render`'s options apply: `manylight --lights 64` renders.
    #[command(flatten)]
    render: render::RenderArgs,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene to a PNG (the default when no subcommand is given).
    Render(render::RenderArgs),
    /// Print the capabilities of an ES 2.0 or 3.0 context.
    Info(info::InfoArgs),
    /// Error against run time: sweep methods, light counts, scenes, ES versions and knobs,
    /// and write a report with tables, charts and light-evaluation heatmaps.
    Bench(bench::BenchArgs),
    /// Time CPU light assignment alone on the default view.
    BenchAssign(bench_assign::BenchAssignArgs),
    /// The ES capability matrix: every method under real driver restrictions.
    Matrix(matrix::MatrixArgs),
    /// One configuration of the matrix (run by `matrix` in a restricted child process).
    #[command(hide = true)]
    MatrixCell(matrix::MatrixCellArgs),
    /// Open an interactive window (fly camera, method and light-count keys).
    #[cfg(feature = "window")]
    View(view::ViewArgs),
    /// In a build without the `window` feature: says how to get the viewer.
    #[cfg(not(feature = "window"))]
    #[command(hide = true)]
    View {
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        _args: Vec<String>,
    },
}

/// `--es 2` or `--es 3`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum EsArg {
    /// OpenGL ES 2.0 (GLSL ES 1.00).
    #[value(name = "2")]
    Two,
    /// OpenGL ES 3.0 (GLSL ES 3.00).
    #[value(name = "3")]
    Three,
}

impl From<EsArg> for EsVersion {
    fn from(e: EsArg) -> Self {
        match e {
            EsArg::Two => EsVersion::Es2,
            EsArg::Three => EsVersion::Es3,
        }
    }
}

/// Usage errors clap's attributes cannot express, reported the way clap reports its own
/// (exit status 2).
fn check_usage(cli: &Cli, subcommand: Option<&str>) {
    let render = match &cli.command {
        None => Some(&cli.render),
        Some(Command::Render(a)) => Some(a),
        _ => None,
    };
    // (--no-fragment-highp, --no-float-textures, --es)
    let es2_devices = match &cli.command {
        Some(Command::Info(a)) => {
            a.es.map(|es| (a.no_fragment_highp, a.no_float_textures, es))
        }
        _ => render.map(|a| (a.no_fragment_highp, a.no_float_textures, a.es)),
    };
    match es2_devices {
        Some((true, _, EsArg::Three)) => usage_error(
            subcommand,
            ErrorKind::ArgumentConflict,
            "--no-fragment-highp plays an OpenGL ES 2.0 device (ES 3.0 requires fragment \
                 highp): add `--es 2`",
        ),
        Some((_, true, EsArg::Three)) => usage_error(
            subcommand,
            ErrorKind::ArgumentConflict,
            "--no-float-textures plays an OpenGL ES 2.0 device (ES 3.0 has float textures in \
                 core): add `--es 2`",
        ),
        _ => {}
    }
    if let Some(a) = render.filter(|a| a.assign_budget.is_some()) {
        if let render::GridArg::Fixed(_) = a.grid {
            usage_error(
                subcommand,
                ErrorKind::ArgumentConflict,
                "--assign-budget is the automatic grid's CPU budget: a fixed --grid has none",
            );
        }
    }
    if let Some(record) = render.and_then(|a| a.record.as_deref().filter(|_| a.frames == 0)) {
        usage_error(
            subcommand,
            ErrorKind::ArgumentConflict,
            format!(
                "--record {} writes the timed frames, and --frames 0 times none",
                shown::path(record)
            ),
        );
    }
    if render.is_some_and(|a| a.record.as_deref() == Some(Path::new("-"))) {
        usage_error(
            subcommand,
            ErrorKind::ValueValidation,
            "--record -: a recording is a folder of PNG frames or a .gif file, not standard \
             output",
        );
    }
    if let Some(a) = render.filter(|a| a.frames > 1) {
        // Each frame can be rendered alone with `--time`: the last one too.
        let last = a.timeline().time_of(a.frames - 1);
        if last.abs() > render::MAX_TIME_S {
            usage_error(
                subcommand,
                ErrorKind::ValueValidation,
                format!(
                    "--frames {} at --fps {} from --time {} end at {last:e} s, past ±{:e} s, \
                     the times a frame can show",
                    a.frames,
                    a.fps,
                    a.time,
                    render::MAX_TIME_S
                ),
            );
        }
    }
    if let Some(a) = render {
        let out = match (&a.out, &a.record) {
            (Some(out), _) => Some(("--out", out.as_path())),
            (None, None) => Some(("the default --out", Path::new(render::DEFAULT_OUT))),
            (None, Some(_)) => None,
        };
        let stats = a.stats.as_deref().map(|p| ("--stats", p));
        let record = a.record.as_deref().map(|p| ("--record", p));
        check_distinct_outputs(subcommand, &[out, stats, record]);
        check_not_the_input(subcommand, &[out, stats], &a.scene);
        if let Some(folder) = a.record.as_deref().filter(|p| !sequence::records_gif(p)) {
            check_outside_folder(subcommand, &[out, stats], ("--record", folder));
        }
    }
    if let Some(Command::BenchAssign(a)) = &cli.command {
        if a.threads.len() > bench_assign::MAX_POOLS {
            usage_error(
                subcommand,
                ErrorKind::ValueValidation,
                format!(
                    "--threads lists {} pools; at most {} (each pool's threads exist at once)",
                    a.threads.len(),
                    bench_assign::MAX_POOLS
                ),
            );
        }
        check_list_length(subcommand, "--lights", a.lights.len());
    }
    if let Some(Command::Bench(a)) = &cli.command {
        check_list_length(subcommand, "--scenes", a.scenes.len());
        check_list_length(subcommand, "--lights", a.lights.len());
        check_list_length(subcommand, "--methods", a.methods.len());
        check_list_length(subcommand, "--es", a.es.len());
    }
    if let Some(Command::Matrix(a)) = &cli.command {
        // `--json -` is stdout, no file.
        let json = a
            .json
            .as_deref()
            .filter(|p| *p != Path::new("-"))
            .map(|p| ("--json", p));
        let sheet = a.out.as_ref().map(|p| p.join("matrix.png"));
        check_distinct_outputs(subcommand, &[json, a.out.as_deref().map(|p| ("--out", p))]);
        check_distinct_outputs(subcommand, &[json, sheet.as_deref().map(|p| ("--out", p))]);
        check_not_the_input(
            subcommand,
            &[json, sheet.as_deref().map(|p| ("--out", p))],
            &a.scene,
        );
        if let (Some((_, json)), Some(out)) = (json, a.out.as_deref()) {
            check_not_a_cell_picture(subcommand, json, out);
        }
    }
    #[cfg(feature = "window")]
    if let Some(Command::View(a)) = &cli.command {
        let screenshot = a.screenshot.as_deref().map(|p| ("--screenshot", p));
        check_not_the_input(subcommand, &[screenshot], &a.scene);
    }
    #[cfg(feature = "window")]
    if !cli.gles_lib.is_empty() && matches!(cli.command, Some(Command::View(_))) {
        usage_error(
            subcommand,
            ErrorKind::ArgumentConflict,
            "--gles-lib does not reach `view`: its window comes from glutin, which loads the \
                 system's libEGL.so.1 (point LD_LIBRARY_PATH at the folder instead)",
        );
    }
    if cli.gles_lib.len() > 1 && !matches!(cli.command, Some(Command::Matrix(_))) {
        usage_error(
            subcommand,
            ErrorKind::ArgumentConflict,
            "--gles-lib names one implementation here; only `matrix` compares several",
        );
    }
    #[cfg(not(feature = "window"))]
    if let Some(Command::View { .. }) = cli.command {
        usage_error(
            subcommand,
            ErrorKind::InvalidSubcommand,
            "`view` needs the `window` feature, which this build left out: \
                 cargo run --release --features window -- view",
        );
    }
}

/// Most values a list option of `bench` or `bench-assign` takes: each is a run of its own (a
/// sweep's scenes are all loaded at its start), so a list as long as a command line holds would
/// take days, or the memory of a hundred thousand scenes.
const MAX_LIST_VALUES: usize = 64;

/// A usage error (exit status 2), the usage line of `subcommand` (or the top level's) under
/// the message.
fn usage_error(subcommand: Option<&str>, kind: ErrorKind, message: impl std::fmt::Display) -> ! {
    // Built, so that a subcommand's usage line names it.
    let mut cli = Cli::command();
    cli.build();
    match subcommand.and_then(|name| cli.find_subcommand_mut(name)) {
        Some(sub) => sub.error(kind, message).exit(),
        None => cli.error(kind, message).exit(),
    }
}

/// `option` of `subcommand` lists at most [`MAX_LIST_VALUES`] values (over all its uses).
fn check_list_length(subcommand: Option<&str>, option: &str, len: usize) {
    if len > MAX_LIST_VALUES {
        usage_error(
            subcommand,
            ErrorKind::ValueValidation,
            format!("{option} lists {len} values; at most {MAX_LIST_VALUES}"),
        );
    }
}

/// `--scene`'s value as text: a built-in's name or a path the loaders take as UTF-8. A path
/// that is not UTF-8 is a usage error naming the option (clap's own names none).
#[derive(Clone)]
struct SceneSpec;

impl clap::builder::TypedValueParser for SceneSpec {
    type Value = String;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<String, clap::Error> {
        value.to_str().map(str::to_owned).ok_or_else(|| {
            let option = arg.map_or("--scene".to_string(), ToString::to_string);
            let shown = shown::path(Path::new(value));
            clap::Error::raw(
                ErrorKind::InvalidValue,
                format!(
                    "{option} {shown}: the path is not UTF-8, which scene paths must be (rename \
                     the file or its folder)\n"
                ),
            )
            .with_cmd(cmd)
        })
    }
}

/// Two options naming one file (through any spelling or symbolic link), or both standard output,
/// would overwrite each other's output: a usage error naming both. A device or FIFO
/// (`/dev/null`) other than standard output may take both.
fn check_distinct_outputs(subcommand: Option<&str>, outputs: &[Option<(&str, &Path)>]) {
    let to_stdout: Vec<_> = (outputs.iter().flatten())
        .filter(|(_, path)| output::names_stdout(path))
        .collect();
    if let [(a, a_path), (b, b_path), ..] = to_stdout[..] {
        usage_error(
            subcommand,
            ErrorKind::ArgumentConflict,
            format!(
                "{a} {} and {b} {} both name standard output: one would run into the other",
                shown::path(a_path),
                shown::path(b_path)
            ),
        );
    }
    let named: Vec<_> = outputs
        .iter()
        .flatten()
        .filter(|(_, path)| !output::is_stream(path))
        .map(|&(option, path)| (option, path, output::identity(path)))
        .collect();
    for (i, (a, a_path, a_id)) in named.iter().enumerate() {
        if let Some((b, b_path, _)) = named[i + 1..].iter().find(|(_, _, id)| id == a_id) {
            usage_error(
                subcommand,
                ErrorKind::ArgumentConflict,
                format!(
                    "{a} {} and {b} {} name the same file: one would overwrite the other",
                    shown::path(a_path),
                    shown::path(b_path)
                ),
            );
        }
    }
}

/// `matrix --json` naming a picture its `--out` folder gets, one per cell (`TAG-METHOD.png`),
/// would be replaced by it or replace it: a usage error naming both.
fn check_not_a_cell_picture(subcommand: Option<&str>, json: &Path, out: &Path) {
    // A bare name's folder is the current one.
    let folder = (json.parent())
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let in_out = output::identity(folder) == output::identity(out);
    let name = json.file_name().map(|n| n.to_string_lossy());
    let cell = name.is_some_and(|n| {
        manylight::methods::METHODS
            .iter()
            .any(|m| n.ends_with(&format!("-{}.png", m.name)))
    });
    if in_out && cell {
        usage_error(
            subcommand,
            ErrorKind::ArgumentConflict,
            format!(
                "--json {} names a cell's picture in --out {}: one would overwrite the other",
                shown::path(json),
                shown::path(out)
            ),
        );
    }
}

/// An output naming the scene file itself (through any spelling or link) would replace it with
/// a picture or statistics: a usage error naming both.
fn check_not_the_input(subcommand: Option<&str>, outputs: &[Option<(&str, &Path)>], spec: &str) {
    // A built-in's name is the built-in, even beside a file of that name.
    let scene = Path::new(spec);
    if manylight::BUILTIN_SCENES.contains(&spec) || !scene.is_file() {
        return;
    }
    let scene_id = output::identity(scene);
    if let Some((option, path)) = outputs
        .iter()
        .flatten()
        .find(|(_, path)| output::identity(path) == scene_id)
    {
        usage_error(
            subcommand,
            ErrorKind::ArgumentConflict,
            format!(
                "{option} {} names the scene file --scene {}: it would be overwritten",
                shown::path(path),
                shown::path(scene)
            ),
        );
    }
}

/// A file inside the folder `--record` fills with frames could be one of them: a usage error
/// naming both options.
fn check_outside_folder(
    subcommand: Option<&str>,
    outputs: &[Option<(&str, &Path)>],
    (folder_option, folder): (&str, &Path),
) {
    let folder_id = output::identity(folder);
    // Standard output (`-`, `/dev/stdout`) is no file of the folder's.
    let files = outputs
        .iter()
        .flatten()
        .filter(|(_, p)| !output::names_stdout(p));
    for &(option, path) in files {
        if output::identity(path).parent() == Some(folder_id.as_path()) {
            usage_error(
                subcommand,
                ErrorKind::ArgumentConflict,
                format!(
                    "{option} {} lies in the folder {folder_option} {} fills with frames: \
                         a frame could overwrite it",
                    shown::path(path),
                    shown::path(folder)
                ),
            );
        }
    }
}

/// The exit status of a request this context cannot do (docs/cli.md, "Exit codes"), so that a
/// capability script tells what a device cannot do from a failure without reading stderr.
const CANNOT_ON_THIS_CONTEXT: u8 = 3;

/// Whether `e` says the context cannot do what was asked: its ES version, the method, MSAA, a
/// frame larger than it allows.
fn cannot_on_this_context(e: &(dyn std::error::Error + 'static)) -> bool {
    matches!(
        e.downcast_ref::<manylight::Error>(),
        Some(
            manylight::Error::UnsupportedMethod { .. }
                | manylight::Error::Msaa { .. }
                | manylight::Error::Gl(manylight::GlError::TooLarge { .. })
        )
    ) || version_unavailable(e)
}

/// Whether `e` (a library or GL error) says the driver gives no context of the version asked,
/// as opposed to one that could not start at all.
pub(crate) fn version_unavailable(e: &(dyn std::error::Error + 'static)) -> bool {
    let gl = match e.downcast_ref::<manylight::Error>() {
        Some(manylight::Error::Gl(gl)) => Some(gl),
        _ => e.downcast_ref::<manylight::GlError>(),
    };
    matches!(gl, Some(manylight::GlError::VersionUnavailable { .. }))
}

/// Every option that takes a value reads a negative number as one: `--lights -1` is then
/// refused as a bad value of `--lights`, not as an unexpected argument `-1`; an option of one
/// value that is not text or a path (a number, a size, a list) takes anything after it
/// (`--lights -inf`, `--size -64x36`: not the flags `-i`, `-6`, …).
fn negative_values(command: clap::Command) -> clap::Command {
    use std::any::TypeId;
    let texts = [
        TypeId::of::<String>(),
        TypeId::of::<std::path::PathBuf>(),
        TypeId::of::<std::ffi::OsString>(),
    ];
    command
        .mut_args(|a| {
            let takes = a.get_action().takes_values();
            let option = a.get_long().is_some() || a.get_short().is_some();
            let one_value = a
                .get_num_args()
                .is_none_or(|n| n.min_values() == 1 && n.max_values() == 1);
            let text = texts.iter().any(|t| a.get_value_parser().type_id() == *t);
            a.allow_negative_numbers(takes)
                .allow_hyphen_values(takes && option && one_value && !text)
        })
        .mut_subcommands(negative_values)
}

fn main() -> ExitCode {
    manylight_tools::signals::remove_temporaries_on_signals();
    // env_logger's own layout, each message with its control characters escaped but its line
    // ends (a model's names reach warnings, and a terminal acts on escape sequences).
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn"))
        .format(|buf, record| {
            use std::io::Write as _;
            let message = record.args().to_string();
            writeln!(
                buf,
                "[{:<5} {}] {}",
                record.level(),
                record.target(),
                shown::lines(&message)
            )
        })
        .init();
    let parsed = negative_values(Cli::command())
        .try_get_matches()
        .and_then(|m| {
            Ok((
                Cli::from_arg_matches(&m)?,
                m.subcommand_name().map(str::to_owned),
            ))
        });
    let (cli, subcommand) = parsed.unwrap_or_else(|e| {
        // As clap's own `exit`, but help or a version that cannot be written is a failure too.
        let code = if e
            .print()
            .and_then(|()| std::io::Write::flush(&mut std::io::stdout()))
            .is_err()
        {
            1
        } else {
            e.exit_code()
        };
        std::process::exit(code)
    });
    // Before the usage checks: they ask whether an output names standard output.
    output::keep_stdout_for_own_output();
    check_usage(&cli, subcommand.as_deref());
    let mut options = LoadOptions::default();
    options.allow_outside_files = cli.allow_outside_files;
    let _ = LOAD_OPTIONS.set(options);
    thread_pool::join_rayon_pool();
    if !matches!(cli.command, Some(Command::Matrix(_))) {
        if let Some(dir) = cli.gles_lib.first() {
            if let Err(e) = manylight::gl::gles_lib::select(dir) {
                eprintln!("error: {e}");
                return ExitCode::FAILURE;
            }
        }
    }
    let result = match cli.command {
        None => render::run(&cli.render),
        Some(Command::Render(args)) => render::run(&args),
        Some(Command::Info(args)) => info::run(&args),
        Some(Command::Bench(args)) => bench::run(&args),
        Some(Command::BenchAssign(args)) => bench_assign::run(&args),
        Some(Command::Matrix(args)) => matrix::run(&args, &cli.gles_lib),
        Some(Command::MatrixCell(args)) => matrix::run_cell(&args),
        #[cfg(feature = "window")]
        Some(Command::View(args)) => view::run(&args),
        #[cfg(not(feature = "window"))]
        Some(Command::View { .. }) => unreachable!("check_usage refuses `view` in this build"),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // The library names its option; the user typed the flag.
            match e.downcast_ref::<manylight::Error>() {
                Some(manylight::Error::Msaa { samples, reason }) => {
                    eprintln!("error: --msaa {samples}: {reason}")
                }
                Some(manylight::Error::Gl(
                    too_large @ manylight::GlError::TooLarge { width, height, .. },
                )) => eprintln!("error: --size {width}x{height}: {too_large}"),
                // Line ends kept: a shader's compile error lists its source.
                _ => eprintln!("error: {}", shown::lines(&e.to_string())),
            }
            if cannot_on_this_context(&*e) {
                ExitCode::from(CANNOT_ON_THIS_CONTEXT)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}
