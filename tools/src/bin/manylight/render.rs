//! `manylight render`.

use std::path::PathBuf;

use clap::Parser;
use manylight::gl::HeadlessContext;
use manylight::scene::shown;
use manylight::{scene, RenderOptions, Renderer};
use manylight_tools::output::{print_stdout, JsonOut, OutputFile};

use crate::EsArg;

/// Options of `manylight render`.
#[derive(Parser, Debug)]
#[command(name = "render")]
pub struct RenderArgs {
    /// A built-in scene (courtyard, pillars, plane, bubbles), an .obj file, a .gltf/.glb file or a
    /// .json scene file.
    #[arg(long, default_value = scene::builtin::DEFAULT, value_parser = crate::SceneSpec)]
    pub scene: String,
    /// Shading method (see `manylight info` for the table). Default: clustered, or forward
    /// on a context where clustered cannot run.
    #[arg(long)]
    pub method: Option<String>,
    /// OpenGL ES version to render with.
    #[arg(long, value_enum, default_value = "3")]
    pub es: EsArg,
    /// Number of seeded random lights (for scene files: replaces their random_lights count).
    /// Default: 1024 for built-ins and OBJ files; a scene file or glTF file keeps its own lights.
    #[arg(long, value_parser = crate::bench_assign::parse_light_count)]
    pub lights: Option<usize>,
    /// Seed of the random lights (default 1). Unused, with a warning, where the scene keeps
    /// its own lights (a scene or glTF file without `--lights`).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Image size as WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Output PNG (`-`: to standard output, and the summary line to standard error). Default:
    /// manylight.png, or none with `--record` (the recording has every frame).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write frame statistics as JSON to this file (`-`: to standard output, and the summary
    /// line to standard error).
    #[arg(long)]
    pub stats: Option<PathBuf>,
    /// Write linear values (clamped, no sRGB encoding, no tone map) for checking pixels
    /// against the light model; `--exposure` still applies.
    #[arg(long, conflicts_with = "tonemap")]
    pub linear: bool,
    /// Frames timed after a warm-up frame: the median is reported, and from 10 frames also
    /// p95, p99 and the slowest (`--stats` has them from 1). In a scene whose lights move
    /// (the built-ins' do), frame k shows time `--time` + k / `--fps`.
    #[arg(long, default_value_t = 2, value_parser = frame_count())]
    pub frames: u32,
    /// Animation time of the picture written to `--out` and of the first timed frame, in
    /// seconds (0: the scene as built).
    #[arg(long, default_value_t = 0.0, value_parser = parse_time, allow_hyphen_values = true)]
    pub time: f64,
    /// Frames per second of animation time between timed frames.
    #[arg(long, default_value_t = 30.0, value_parser = parse_fps, allow_hyphen_values = true)]
    pub fps: f64,
    /// Write every timed frame: into a directory as `frame_00000.png` …, or, for a path
    /// ending in `.gif`, as one animated GIF.
    #[arg(long)]
    pub record: Option<PathBuf>,
    /// Play a device whose fragment stage has no highp (Mali-400 class; needs `--es 2`):
    /// every fragment float runs at mediump, fp16 on llvmpipe. Methods that need highp are
    /// unsupported there.
    #[arg(long)]
    pub no_fragment_highp: bool,
    /// Play a device without float textures (`GL_OES_texture_float`; needs `--es 2`): light
    /// records are packed in RGBA8, as `MESA_EXTENSION_OVERRIDE` removing them makes them.
    #[arg(long)]
    pub no_float_textures: bool,
    /// Tone map applied before the sRGB encode: `none` (the default: the light model's own
    /// values, clipped at 1), `reinhard`, `aces` or `neutral` (Khronos PBR Neutral).
    #[arg(long, value_enum, default_value_t = ToneMapArg::None)]
    pub tonemap: ToneMapArg,
    /// Samples per pixel (MSAA) of the offscreen image: 1 (none), 2, 4, 8, or another power of
    /// two up to the context's GL_MAX_SAMPLES; ES 3.0, or ES 2.0 with
    /// GL_EXT_multisampled_render_to_texture; not with deferred.
    #[arg(long, default_value_t = 1, value_parser = parse_samples)]
    pub msaa: u32,
    /// Exposure in stops (radiance × 2^EV before the tone map), within ±15.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = parse_exposure)]
    pub exposure: f32,
    /// Cell footprint of the clustered grid in pixels, or `auto` (chosen per frame from a
    /// cost model calibrated on this device; `--stats` says which and why).
    #[arg(long, default_value = "auto", value_parser = parse_grid)]
    pub grid: GridArg,
    /// Depth of a clustered grid slice relative to a cell's width, from 1/16 to 16 (1: cells
    /// about as deep as wide; 0.5 halves the slices' depth for tighter light lists on surfaces
    /// seen at a grazing angle, at twice the cells).
    #[arg(long, default_value_t = 1.0, value_parser = parse_slice_depth, allow_hyphen_values = true)]
    pub slice_depth: f64,
    /// With `--grid auto` (a fixed grid has none): the largest share of the predicted frame
    /// time the CPU light assignment may take (default 0.05: 5 %; 1 lets the frame time alone
    /// decide; where no grid keeps within it, the smallest share wins).
    #[arg(long, value_parser = parse_assign_budget, allow_hyphen_values = true)]
    pub assign_budget: Option<f64>,
}

impl RenderArgs {
    /// The frames `--time`, `--fps` and `--frames` ask for.
    pub fn timeline(&self) -> crate::sequence::Timeline {
        crate::sequence::Timeline {
            start_s: self.time,
            fps: self.fps,
            frames: self.frames,
        }
    }
}

/// `--tonemap`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ToneMapArg {
    /// No tone map: clamped at 1.
    None,
    /// `c / (1 + c)`.
    Reinhard,
    /// ACES filmic (Narkowicz's fit).
    Aces,
    /// Khronos PBR Neutral.
    Neutral,
}

impl From<ToneMapArg> for manylight::ToneMap {
    fn from(t: ToneMapArg) -> Self {
        match t {
            ToneMapArg::None => manylight::ToneMap::None,
            ToneMapArg::Reinhard => manylight::ToneMap::Reinhard,
            ToneMapArg::Aces => manylight::ToneMap::Aces,
            ToneMapArg::Neutral => manylight::ToneMap::Neutral,
        }
    }
}

/// `--grid`: `auto` or a footprint in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GridArg {
    /// The automatic grid.
    Auto,
    /// A fixed footprint.
    Fixed(f64),
}

/// Parses `--grid`.
pub fn parse_grid(s: &str) -> Result<GridArg, String> {
    if s == "auto" {
        return Ok(GridArg::Auto);
    }
    match s.parse::<f64>() {
        Ok(px) if px.is_finite() && (1.0..=4096.0).contains(&px) => Ok(GridArg::Fixed(px)),
        _ => Err(format!(
            "`{s}` is neither `auto` nor a footprint from 1 to 4096 pixels"
        )),
    }
}

/// Parses `--slice-depth`: a ratio from 1/16 to 16.
pub fn parse_slice_depth(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(r) if (1.0 / 16.0..=16.0).contains(&r) => Ok(r),
        _ => Err(format!(
            "`{s}` is not a slice depth from 0.0625 to 16 (times a cell's width)"
        )),
    }
}

/// The grid options given (`--grid` other than `auto`, `--slice-depth`, `--assign-budget`) when
/// the method drawn has no clustered grid to take them: said, not ignored in silence.
fn unused_grid_options(args: &RenderArgs, stats: &manylight::FrameStats) -> Option<String> {
    let given: Vec<&str> = [
        ("--grid", !matches!(args.grid, GridArg::Auto)),
        ("--slice-depth", args.slice_depth != 1.0),
        ("--assign-budget", args.assign_budget.is_some()),
    ]
    .into_iter()
    .filter_map(|(flag, set)| set.then_some(flag))
    .collect();
    // `auto` may draw clustered in other frames than the last.
    let drawn = &stats.method;
    if given.is_empty() || drawn == "clustered" || drawn == "auto" {
        return None;
    }
    let tiles = match stats.grid.footprint_px {
        Some(px) => format!(" (its tiles are fixed at {px} px)"),
        None => String::new(),
    };
    let they = if given.len() == 1 {
        "it changes"
    } else {
        "they change"
    };
    Some(format!(
        "{} set the clustered grid: {drawn} has none{tiles}, so {they} nothing",
        given.join(", ")
    ))
}

/// Parses a frame count (`render --frames`, `bench --frames`, `--animated-frames`): at most
/// [`manylight::MAX_TIMED_FRAMES`], whose figures a run keeps.
pub fn frame_count() -> clap::builder::RangedI64ValueParser<u32> {
    clap::value_parser!(u32).range(0..=i64::from(manylight::MAX_TIMED_FRAMES))
}

/// Parses a count of timed frames that must time something (`bench --frames`: a row's figure
/// is their median, and with none it would be one cold frame's time).
pub fn timed_frame_count() -> clap::builder::RangedI64ValueParser<u32> {
    clap::value_parser!(u32).range(1..=i64::from(manylight::MAX_TIMED_FRAMES))
}

/// Parses `--assign-budget`: a share of the frame from 0 to 1.
pub fn parse_assign_budget(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(b) if (0.0..=1.0).contains(&b) => Ok(b),
        _ => Err(format!(
            "`{s}` is not a share of the frame from 0 to 1 (0.05: 5 %)"
        )),
    }
}

/// Parses `--msaa`: a power of two, the counts implementations have (GL rounds another count
/// up to one it has).
pub fn parse_samples(s: &str) -> Result<u32, String> {
    match s.parse::<u32>() {
        Ok(n) if n.is_power_of_two() => Ok(n),
        _ => Err(format!(
            "`{s}` is not a sample count: 1 (no MSAA) or a power of two (2, 4, 8, ...)"
        )),
    }
}

/// The times a frame can show, in seconds either side of 0 (`--time`, and every timed frame's).
pub const MAX_TIME_S: f64 = 1e9;

/// Parses `--time`: finite seconds.
pub fn parse_time(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(t) if t.is_finite() && t.abs() <= MAX_TIME_S => Ok(t),
        _ => Err(format!(
            "`{s}` is not a time in seconds within ±{MAX_TIME_S:e}"
        )),
    }
}

/// Parses `--exposure`: finite stops within what the renderer takes.
pub fn parse_exposure(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(ev) if ev.is_finite() && ev.abs() <= manylight::MAX_EXPOSURE_EV => Ok(ev),
        _ => Err(format!(
            "`{s}` is not an exposure in stops within ±{}",
            manylight::MAX_EXPOSURE_EV
        )),
    }
}

/// Parses `--fps`: a positive, finite rate.
pub fn parse_fps(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(f) if f.is_finite() && (1e-3..=1e4).contains(&f) => Ok(f),
        _ => Err(format!("`{s}` is not a frame rate from 0.001 to 10000")),
    }
}

/// The picture's file when neither `--out` nor `--record` is given.
pub const DEFAULT_OUT: &str = "manylight.png";

/// Random lights for built-ins and OBJ files when `--lights` is not given.
const DEFAULT_LIGHTS: usize = 1024;
/// The random lights' seed without `--seed`.
const DEFAULT_SEED: u64 = 1;

pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X', '×'])
        .ok_or_else(|| format!("`{}` is not WIDTHxHEIGHT", shown::name(s)))?;
    let parse =
        |v: &str| (v.trim().parse::<u32>()).map_err(|e| format!("`{}`: {e}", shown::name(v)));
    let (w, h) = (parse(w)?, parse(h)?);
    if w == 0 || h == 0 {
        return Err(format!("size {w}x{h} is empty"));
    }
    Ok((w, h))
}

/// The random lights a scene gets: `count` where asked (`--lights`, which clap bounds by
/// [`MAX_LIGHTS`](manylight::scene::input::MAX_LIGHTS)), else [`DEFAULT_LIGHTS`] for built-ins
/// and OBJ files, none for a scene or glTF file (which keeps its own).
pub fn lights_for(spec: &str, count: Option<usize>, seed: u64) -> Option<(usize, u64)> {
    match (count, scene::brings_own_lights(spec)) {
        (Some(n), _) => Some((n, seed)),
        (None, true) => None,
        (None, false) => Some((DEFAULT_LIGHTS, seed)),
    }
}

/// An output naming a file the scene read (a model, a texture: `--out model.obj`) would replace
/// it: an error naming the option and the file, before anything is written. (The scene file itself is a usage
/// error before the load: `check_not_the_input`.)
pub fn check_not_read(
    outputs: &[(&str, Option<&std::path::Path>)],
    read: &[PathBuf],
) -> Result<(), String> {
    for (option, path) in outputs {
        let Some(path) = path.filter(|p| !manylight_tools::output::is_stream(p)) else {
            continue;
        };
        let id = manylight_tools::output::identity(path);
        if read.contains(&id) {
            return Err(format!(
                "{option} {} names a file the scene reads: it would be overwritten",
                shown::path(path)
            ));
        }
    }
    Ok(())
}

/// Warns where `--out` names another image format by its extension (`a.jpg`): the picture is
/// a PNG whatever the name, which was written without a word.
fn warn_not_png(path: &std::path::Path) {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    if let Some(extension) = extension.filter(|e| e != "png") {
        log::warn!(
            "--out {}: the picture is a PNG, whatever its name's .{} says",
            shown::path(path),
            shown::name(&extension)
        );
    }
}

/// Runs the command.
pub fn run(args: &RenderArgs) -> Result<(), Box<dyn std::error::Error>> {
    let lights = lights_for(&args.scene, args.lights, args.seed.unwrap_or(DEFAULT_SEED));
    if let (None, Some(seed)) = (lights, args.seed) {
        log::warn!(
            "--seed {seed} is not used: the scene keeps its own lights (a scene file's \
             random_lights their own seed); --lights N replaces them with seeded ones"
        );
    }
    // The loader logs each warning (at `warn`, shown by default): not printed again here.
    let (mut scene, report) = scene::load_with(&args.scene, lights, &crate::load_options())?;
    manylight_tools::output::protect_inputs(&report.files);
    let out = match (&args.out, &args.record) {
        (Some(path), _) => Some(path.as_path()),
        (None, None) => Some(std::path::Path::new(DEFAULT_OUT)),
        (None, Some(_)) => None,
    };
    let outputs = [("--out", out), ("--stats", args.stats.as_deref())];
    check_not_read(&outputs, &report.files)?;
    if let Some(record) = &args.record {
        if let Some(file) = crate::sequence::overwritten_input(record, args.frames, &report.files) {
            return Err(format!(
                "--record {} would overwrite {}, which the scene reads",
                shown::path(record),
                shown::path(&file)
            )
            .into());
        }
    }
    if let Some(path) = out.filter(|p| !manylight_tools::output::names_stdout(p)) {
        warn_not_png(path);
    }
    // Opened before rendering: a path that cannot be written fails now, not after the frames.
    let out_file = out.map(OutputFile::create).transpose()?;
    let stats_out = args.stats.as_deref().map(JsonOut::create).transpose()?;
    // Standard output holds the statistics or the picture alone when one of them goes there.
    let names_stdout = manylight_tools::output::names_stdout;
    let summary_to_stderr =
        args.stats.as_deref().is_some_and(names_stdout) || out.is_some_and(names_stdout);
    let es = args.es.into();
    let ctx = HeadlessContext::new(es)?;
    let restrictions = manylight::gl::Restrictions {
        no_fragment_highp: args.no_fragment_highp,
        no_float_textures: args.no_float_textures,
    };
    let mut renderer = Renderer::restricted(ctx.load_gl()?, es, &restrictions)?;
    // A fallback is logged as a warning by the renderer.
    if let Some(method) = &args.method {
        renderer.set_method_named(method)?;
    }
    let options = RenderOptions {
        linear: args.linear,
        measure: manylight::MeasureOptions {
            timed_frames: args.frames,
            ..Default::default()
        },
        tone_map: args.tonemap.into(),
        samples: args.msaa,
        exposure_ev: args.exposure,
        grid: manylight::GridConfig {
            slice_depth: args.slice_depth,
            ..match args.grid {
                GridArg::Auto => manylight::GridConfig {
                    mode: manylight::GridMode::Auto {
                        assign_budget: args
                            .assign_budget
                            .unwrap_or(manylight::cluster::grid::DEFAULT_ASSIGN_BUDGET),
                    },
                    ..manylight::GridConfig::default()
                },
                GridArg::Fixed(px) => manylight::GridConfig::fixed(px),
            }
        },
        ..RenderOptions::default()
    };
    let (width, height) = args.size;
    // A still scene is the same at every time: its timed frames are one frame timed again.
    let result = if scene.is_animated() || args.record.is_some() {
        let timeline = args.timeline();
        let size = (width, height);
        let keep = match args.record.as_deref() {
            Some(path) => crate::sequence::Keep::Record(path),
            None => crate::sequence::Keep::Stats,
        };
        let mut pose = |s: &mut scene::Scene, t| s.set_time(t);
        crate::sequence::render(
            &mut renderer,
            &mut scene,
            size,
            &options,
            &timeline,
            &mut pose,
            keep,
        )
        .map(|r| (r.first, r.stats))
    } else {
        renderer
            .render_offscreen(&scene, width, height, &options)
            .map_err(Into::into)
    };
    drop(renderer);
    let (image, stats) = result?;
    if let Some(warning) = unused_grid_options(args, &stats) {
        log::warn!("{warning}");
    }
    if let Some(warning) = crate::black_frame::warning(&image, &scene, options.exposure_ev) {
        log::warn!("{warning}");
    }
    if let Some(file) = out_file {
        file.commit_png(&image)?;
    }
    if let Some(out) = stats_out {
        out.commit(&(serde_json::to_string_pretty(&stats)? + "\n"))?;
    }
    // The slow frames too, where enough frames were timed for them to mean something.
    let mut tail = match stats.time.frame_ms_spread {
        Some(s) if s.frames >= 10 => {
            format!(" (p95 {:.1}, p99 {:.1}, max {:.1})", s.p95, s.p99, s.max)
        }
        _ => String::new(),
    };
    if scene.is_animated() {
        // Rounded as written, then `+ 0.0`: -0.0001 reads 0.000, not -0.000.
        let shown = (args.time * 1e3).round() / 1e3 + 0.0;
        tail += &format!(" · moving lights, picture at t = {shown:.3} s");
        if args.frames > 1 {
            let last = args.timeline().time_of(args.frames - 1);
            tail += &format!(", timed to t = {last:.3} s");
        }
    }
    if let Some(path) = &args.record {
        let frames = counted(args.frames.into(), "frame");
        tail += &format!(" · {frames} → {}", manylight::scene::shown::path(path));
    }
    let method = match (&stats.auto_choice, &stats.auto_reason) {
        (Some(choice), Some(reason)) => format!("{} → {choice} ({reason})", stats.method),
        _ => stats.method.clone(),
    };
    let written = out.map_or(String::new(), |p| {
        format!(" → {}", manylight::scene::shown::path(p))
    });
    // No timed frame: the one frame's time includes compiling shaders and uploading meshes.
    let time = if args.frames == 0 {
        format!(
            "one untimed frame, {:.1} ms with shaders compiled (--frames 0)",
            stats.time.frame_ms
        )
    } else {
        format!("{:.1} ms/frame", stats.time.frame_ms)
    };
    let summary = format!(
        "{} {}x{} · {method} · {} · {} on {} · {time}{tail}{written}\n",
        manylight::scene::shown::reason(&args.scene),
        width,
        height,
        counted(stats.lights.total as u64, "light"),
        stats.context.es,
        stats.context.renderer,
    );
    if summary_to_stderr {
        eprint!("{summary}");
    } else {
        print_stdout(&summary)?;
    }
    Ok(())
}

/// `n noun`, the noun in the plural but for one (`1 light`, `2 lights`).
fn counted(n: u64, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}
