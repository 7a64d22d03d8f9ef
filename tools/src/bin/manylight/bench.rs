//! `manylight bench`: error against run time. Sweeps scenes × light counts × ES versions ×
//! methods, plus the knobs that trade error for time, and writes the report (see
//! `manylight_tools::report`).
//!
//! For every (scene, light count, ES version) it renders the reference once (plain forward over
//! all lights, light model at highp), the lower bound of light evaluations (lights that really
//! reach each pixel) and the f64 CPU reference at sampled pixels; then each configuration is
//! timed, counted and compared against them.

use std::path::PathBuf;
use std::time::Instant;

use clap::Parser;
use manylight::cluster::grid::{Coverage, GridConfig};
use manylight::gl::HeadlessContext;
use manylight::methods::{Support, METHODS};
use manylight::metrics::cpu_reference::{self, Encoding, ReferenceSet};
use manylight::renderer::{CountKind, LightCounts};
use manylight::scene::raycast::SceneRaycaster;
use manylight::scene::{self, shown, Scene};
use manylight::{EsVersion, RenderOptions, Renderer};
use manylight_tools::animated::AnimatedRow;
use manylight_tools::report::{self, BenchRow, Pictures, Report};

use crate::EsArg;

/// Options of `manylight bench`.
#[derive(Parser, Debug)]
pub struct BenchArgs {
    /// A small sweep: the default scene at 0, 64 and 1 024 lights on ES 2.0 and 3.0 at
    /// 320×180, one timed frame, the main knobs (one to three minutes on a 2-core machine with
    /// llvmpipe, most of it the CPU reference).
    #[arg(long)]
    pub quick: bool,
    /// Folder for report.json, report.md, the charts, heatmaps and diff images.
    #[arg(long, default_value = "bench-report")]
    pub out: PathBuf,
    /// Scenes (built-in names, .obj, .gltf/.glb or .json files), comma separated. Default: the
    /// built-ins, and the conference room when $MANYLIGHT_ASSETS has it.
    #[arg(long, value_delimiter = ',')]
    pub scenes: Vec<String>,
    /// Light counts, comma separated (default 0,8,64,256,1024,4096).
    #[arg(long, value_delimiter = ',', value_parser = crate::bench_assign::parse_light_count)]
    pub lights: Vec<usize>,
    /// Methods, comma separated (default: every method in the table).
    #[arg(long, value_delimiter = ',')]
    pub methods: Vec<String>,
    /// ES versions, comma separated (default 2,3).
    #[arg(long, value_delimiter = ',', value_enum)]
    pub es: Vec<EsArg>,
    /// Image size as WIDTHxHEIGHT (default 640x360).
    #[arg(long, value_parser = crate::render::parse_size)]
    pub size: Option<(u32, u32)>,
    /// Timed frames per configuration after a warm-up frame (default 9: their median, the
    /// row's figure, outvotes the few slow frames a pool wake-up or the first frames after a
    /// grid change make; 3 for a configuration whose first frame that built no shaders (of
    /// two untimed ones) took over 100 ms, whose
    /// frames vary little against their length: forward, tiled and deferred over hundreds of
    /// lights; 1 with `--quick`). At least 1.
    #[arg(long, value_parser = crate::render::timed_frame_count())]
    pub frames: Option<u32>,
    /// Pixels sampled for the f64 CPU reference (default 256).
    #[arg(long, default_value_t = 256)]
    pub cpu_samples: usize,
    /// Skip the knob sweeps.
    #[arg(long)]
    pub no_knobs: bool,
    /// Seed of the random lights.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Frames of the animated workload (lights and camera moving, at 30 fps of animation
    /// time; the first scene at the knobs' light count; 0 leaves it out). Default 120, 20
    /// with --quick.
    #[arg(long, value_parser = crate::render::frame_count())]
    pub animated_frames: Option<u32>,
    /// The scenes' materials: as loaded (OBJ and the built-ins Blinn-Phong, glTF
    /// metallic-roughness), or all metallic-roughness (each Blinn-Phong material a dielectric
    /// of its colour, its roughness matching its exponent): two runs give the new model's cost
    /// against the old on the same scenes.
    #[arg(long, value_enum, default_value = "as-loaded")]
    pub material_model: MaterialModelArg,
}

/// `--material-model`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum MaterialModelArg {
    /// Each material's own model.
    AsLoaded,
    /// Every material converted to metallic-roughness.
    MetallicRoughness,
}

/// Every Blinn-Phong material as a dielectric metallic-roughness one of the same colour, its
/// roughness the glTF loader's exponent match inverted (`Ns = 2/α² − 2`, `α = roughness²`).
/// Only the reflectance changes: opacity, cut-outs, sides, surface maps and depth bias stay.
fn to_metallic_roughness(scene: &mut Scene) {
    for m in &mut scene.materials {
        if !m.is_metallic_roughness() {
            m.roughness = (2.0 / (m.shading_exponent() + 2.0)).powf(0.25);
            m.model = scene::MaterialModel::MetallicRoughness;
            m.metallic = 0.0;
            // Not read by metallic-roughness: as `Material::metallic_roughness` leaves it.
            m.specular = glam::Vec3::ZERO;
        }
    }
}

/// A benchmark scene with the materials `--material-model` asks for.
fn load_bench_scene(
    spec: &str,
    lights: usize,
    args: &BenchArgs,
) -> Result<Scene, Box<dyn std::error::Error>> {
    let (mut scene, report) =
        scene::load_with(spec, Some((lights, args.seed)), &crate::load_options())?;
    manylight_tools::output::protect_inputs(&report.files);
    if args.material_model == MaterialModelArg::MetallicRoughness {
        to_metallic_roughness(&mut scene);
    }
    Ok(scene)
}

/// The sweep, with the `--quick` or full defaults filled in.
struct Plan {
    scenes: Vec<String>,
    lights: Vec<usize>,
    methods: Vec<String>,
    es: Vec<EsVersion>,
    size: (u32, u32),
    frames: Frames,
    knobs: bool,
    animated_frames: u32,
}

/// How many frames a configuration times.
#[derive(Clone, Copy, Debug)]
enum Frames {
    /// What `--frames` (or `--quick`) says.
    Fixed(u32),
    /// Nine, or three for a configuration whose first (untimed) frame took over
    /// [`SLOW_FRAME_MS`]: the median of three lets one slow pool wake-up decide a fast row's
    /// assignment time, while nine frames of every slow row make the full sweep much longer.
    Adaptive,
}

/// A first frame slower than this makes an adaptive row time three frames, not nine.
const SLOW_FRAME_MS: f64 = 100.0;

/// The frames an adaptive row times, from an untimed frame of it: three where that frame took
/// over [`SLOW_FRAME_MS`], else nine; `None` where it built shader programs, whose compiling
/// says nothing of the configuration: the next frame decides.
fn adaptive_frames(untimed: &manylight::FrameStats) -> Option<u32> {
    (untimed.programs_built == 0).then(|| frames_for(untimed.time.frame_ms))
}

/// Three frames for a configuration whose frame takes `ms` past [`SLOW_FRAME_MS`], else nine.
fn frames_for(ms: f64) -> u32 {
    if ms > SLOW_FRAME_MS {
        3
    } else {
        9
    }
}

impl Plan {
    fn from(args: &BenchArgs) -> Plan {
        let or = |given: &[String], default: Vec<String>| {
            if given.is_empty() {
                default
            } else {
                given.to_vec()
            }
        };
        let scenes = if !args.scenes.is_empty() {
            args.scenes.clone()
        } else if args.quick {
            vec![scene::builtin::DEFAULT.to_string()]
        } else {
            let mut s: Vec<String> = scene::builtin::NAMES
                .iter()
                .map(|n| n.to_string())
                .collect();
            if let Some(c) = conference() {
                s.push(c);
            }
            s
        };
        let lights = match (&args.lights[..], args.quick) {
            ([], true) => vec![0, 64, 1024],
            ([], false) => vec![0, 8, 64, 256, 1024, 4096],
            (given, _) => once("--lights", given.to_vec()),
        };
        let es = match (&args.es[..], args.quick) {
            ([], true) => vec![EsVersion::Es2, EsVersion::Es3],
            ([], false) => vec![EsVersion::Es2, EsVersion::Es3],
            (given, _) => once("--es", given.iter().map(|&e| e.into()).collect()),
        };
        let default_size = if args.quick { (320, 180) } else { (640, 360) };
        Plan {
            scenes,
            lights,
            methods: once(
                "--methods",
                or(
                    &args.methods,
                    METHODS.iter().map(|m| m.name.to_string()).collect(),
                ),
            ),
            es,
            size: args.size.unwrap_or(default_size),
            frames: match args.frames {
                Some(n) => Frames::Fixed(n),
                None if args.quick => Frames::Fixed(1),
                None => Frames::Adaptive,
            },
            knobs: !args.no_knobs,
            animated_frames: args
                .animated_frames
                .unwrap_or(if args.quick { 20 } else { 120 }),
        }
    }
}

/// The conference room of $MANYLIGHT_ASSETS, when set and present; otherwise says why the
/// row is left out.
fn conference() -> Option<String> {
    conference_in(std::env::var_os("MANYLIGHT_ASSETS"))
        .map_err(|why| eprintln!("bench: the conference-room rows are left out: {why}"))
        .ok()
}

/// The conference room's OBJ in the assets folder `assets`, as the scene name bench loads, or
/// why there is none. Scene names are UTF-8, so a folder whose path is not cannot be loaded.
fn conference_in(assets: Option<std::ffi::OsString>) -> Result<String, String> {
    const HOW: &str = "set MANYLIGHT_ASSETS to a folder with the real scenes \
        (scripts/fetch-assets; docs/assets.md)";
    let obj = assets
        .map(|dir| PathBuf::from(dir).join("conference/conference.obj"))
        .filter(|obj| obj.is_file())
        .ok_or_else(|| HOW.to_string())?;
    obj.into_os_string().into_string().map_err(|obj| {
        format!(
            "MANYLIGHT_ASSETS's {} is not UTF-8, which scene paths must be; {HOW}",
            shown::path(std::path::Path::new(&obj))
        )
    })
}

/// A knob varied from the defaults, on one method.
struct Knob {
    name: String,
    method: &'static str,
    apply: fn(&mut RenderOptions, f64),
    value: f64,
    /// Run on every scene of the plan (the grid knobs), not only the first.
    every_scene: bool,
    /// Drops lights on purpose (a cap per cell): its rows count them, so the renderer's
    /// overflow warning is silenced for it.
    drops_lights: bool,
}

fn knobs(quick: bool) -> Vec<Knob> {
    let mut k = Vec::new();
    let mut add = |name: &str, method, apply: fn(&mut RenderOptions, f64), values: &[f64]| {
        for &value in values {
            k.push(Knob {
                name: format!("{name}={value}"),
                method,
                apply,
                value,
                every_scene: name.starts_with("footprint_px")
                    || name == "coverage"
                    || name == "slice_depth"
                    || name == "assign_budget",
                drops_lights: name == "cell_cap",
            });
        }
    };
    let pick = |full: &'static [f64], q: &'static [f64]| if quick { q } else { full };
    add(
        "cutoff",
        "clustered",
        |o, v| o.light_cutoff = Some(v as f32),
        pick(&[0.001, 0.01, 0.05], &[0.01]),
    );
    add(
        "cutoff",
        "tiled",
        |o, v| o.light_cutoff = Some(v as f32),
        pick(&[0.01], &[]),
    );
    add(
        "cell_cap",
        "clustered",
        |o, v| o.measure.cell_cap = Some(v as u32),
        pick(&[64.0, 16.0], &[16.0]),
    );
    // Fixed grids against the automatic one (the default rows), on every scene.
    add(
        "footprint_px",
        "clustered",
        |o, v| o.grid = GridConfig::fixed(v),
        pick(&[8.0, 16.0, 32.0, 64.0], &[16.0, 64.0]),
    );
    // The automatic grid without its CPU budget (the frame time alone decides): what the
    // budget's share of the frame costs in frame time and buys in assignment time.
    add(
        "assign_budget",
        "clustered",
        |o, v| o.grid.mode = manylight::GridMode::Auto { assign_budget: v },
        pick(&[1.0], &[]),
    );
    // Slices half as deep as a cell is wide: on the automatic grid, and on the finest fixed
    // one (what the finest cells can get out of a grazing floor).
    add(
        "slice_depth",
        "clustered",
        |o, v| o.grid.slice_depth = v,
        pick(&[0.5], &[]),
    );
    add(
        "footprint_px=8,slice_depth",
        "clustered",
        |o, v| {
            o.grid = GridConfig {
                slice_depth: v,
                ..GridConfig::fixed(8.0)
            }
        },
        pick(&[0.5], &[]),
    );
    // The per-cascade rectangle (1 = cascade box), automatic grid: what the tight bound saves.
    add(
        "coverage",
        "clustered",
        |o, _| o.grid.measure.coverage = Coverage::CascadeBox,
        pick(&[1.0], &[]),
    );
    // 4× MSAA against none: cost against edge error (ES 3.0; skipped where unsupported).
    add(
        "msaa",
        "clustered",
        |o, v| o.samples = v as u32,
        pick(&[4.0], &[]),
    );
    add(
        "cascades",
        "clustered",
        |o, v| o.grid.cascades = v as u32,
        pick(&[4.0, 8.0, 16.0], &[4.0]),
    );
    add(
        "rgba8_lights",
        "clustered",
        |o, _| o.measure.force_rgba8_lights = true,
        &[1.0],
    );
    k
}

/// Everything one configuration is measured against.
struct Baseline {
    reference: image::RgbaImage,
    bound: LightCounts,
    cpu: ReferenceSet,
}

/// Runs the command.
pub fn run(args: &BenchArgs) -> Result<(), Box<dyn std::error::Error>> {
    let started = Instant::now();
    let plan = Plan::from(args);
    // What can be checked before any rendering is: the methods' names, the output folder.
    for method in &plan.methods {
        manylight::methods::find(method)?;
    }
    std::fs::create_dir_all(&args.out).map_err(|e| {
        format!(
            "cannot create the output folder {}: {e}",
            shown::path(&args.out)
        )
    })?;
    let probe = args.out.join(".manylight-write-test");
    std::fs::write(&probe, b"")
        .and_then(|()| std::fs::remove_file(&probe))
        .map_err(|e| format!("cannot write into {}: {e}", shown::path(&args.out)))?;
    // The whole report folder is replaced at the end or not at all: stopped half-way (an
    // error, a signal) it stays the last run's, not a mixture of two.
    let deferred = manylight_tools::output::defer_commits();
    // The report's own files, where something is in the way (a folder of that name, a file
    // that cannot be written): found after the whole sweep before.
    for name in ["report.json", "report.md"] {
        let path = args.out.join(name);
        let blocked = match std::fs::symlink_metadata(&path) {
            Ok(meta) if meta.is_dir() => Some("a folder is in the way".to_string()),
            Ok(_) => {
                (std::fs::OpenOptions::new().write(true).open(&path).err()).map(|e| e.to_string())
            }
            Err(_) => None,
        };
        if let Some(why) = blocked {
            return Err(format!("cannot write {}: {why}", shown::path(&path)).into());
        }
    }
    // Rows, pictures and chart series are named by the scene's file stem: two alike would
    // overwrite each other's pictures and merge into one series.
    let mut labels = std::collections::HashMap::new();
    for spec in &plan.scenes {
        let label = report::file_tag(&scene_name(spec));
        if let Some(first) = labels.insert(label.clone(), spec) {
            return Err(format!(
                "--scenes names `{first}` and `{spec}`, which both report as `{label}`: their \
                 rows and pictures would overwrite each other (give each its own file name)"
            )
            .into());
        }
    }
    // Every scene loads once here, so a bad one fails the sweep before its first row, not
    // after the scenes before it were measured.
    let first_count = plan.lights.first().copied().unwrap_or(0);
    for spec in &plan.scenes {
        load_bench_scene(spec, first_count, args)?;
    }
    // And each ES version's context and renderer once (a driver capped at ES 2.0 refuses an
    // ES 3.0 context, or gives a 2.0 one the renderer refuses): here, not after the ES 2.0 rows.
    for &es in &plan.es {
        let ctx = HeadlessContext::new(es)?;
        Renderer::new(ctx.load_gl()?, es)?.destroy();
    }
    let knob_list = if plan.knobs {
        knobs(args.quick)
    } else {
        Vec::new()
    };
    // The knobs run at the light count nearest 1 024: the grid knobs on every scene, the
    // others on the first. Every scene's pictures are taken there too.
    let knob_lights = plan
        .lights
        .iter()
        .copied()
        .min_by_key(|&n| n.abs_diff(1024))
        .unwrap_or(0);
    let knob_scene = plan.scenes.first().cloned().unwrap_or_default();
    let knob_runs: usize = knob_list
        .iter()
        .map(|k| if k.every_scene { plan.scenes.len() } else { 1 })
        .sum();
    let animated_runs = if plan.animated_frames > 0 {
        plan.methods.len()
    } else {
        0
    };
    let steps = plan.es.len() * plan.scenes.len() * plan.lights.len() * plan.methods.len()
        + plan.es.len() * (knob_runs + animated_runs);
    let mut progress = crate::progress::Progress::new(steps as u64);
    let mut rows = Vec::new();
    let mut animated = Vec::new();
    let mut pictures = Vec::new();
    let mut casters = std::collections::HashMap::new();
    for &es in &plan.es {
        // One context per ES version, made current for its renderer's whole life.
        let ctx = HeadlessContext::new(es)?;
        let mut renderer = Renderer::new(ctx.load_gl()?, es)?;
        warn_unsupported(&renderer, es, &plan.methods, &knob_list)?;
        for spec in &plan.scenes {
            for &count in &plan.lights {
                let scene = load_bench_scene(spec, count, args)?;
                let name = scene_name(spec);
                progress.set_message(format!("{es} {name} {count} lights: reference"));
                // The geometry, and so its ray caster, is the same at every light count.
                let caster = casters
                    .entry(spec.clone())
                    .or_insert_with(|| SceneRaycaster::new(&scene));
                let base = baseline(&mut renderer, &scene, caster, plan.size, args.cpu_samples)?;
                let base = match base {
                    Ok(base) => base,
                    // Every configuration at this count is compared with that reference.
                    Err(why) => {
                        log::warn!("{es} {name} {count} lights: skipped: {why}");
                        continue;
                    }
                };
                let measure = Measure {
                    scene: &scene,
                    name: &name,
                    base: &base,
                    size: plan.size,
                    frames: plan.frames,
                };
                let knob_workload = spec == &knob_scene && count == knob_lights;
                // The grid knobs and the pictures: every scene at the knobs' light count.
                let at_knob_lights = count == knob_lights;
                let mut pictured = Vec::new();
                for method in &plan.methods {
                    progress.set_message(format!("{es} {name} {count} lights: {method}"));
                    if let Some(m) = measure.run(&mut renderer, method, "default", |_| {})? {
                        rows.push(m.row.clone());
                        if at_knob_lights {
                            pictured.push((method.clone(), m));
                        }
                    }
                    progress.inc();
                }
                if at_knob_lights {
                    let here = knob_list.iter().filter(|k| k.every_scene || knob_workload);
                    for knob in here {
                        progress.set_message(format!("{es} {name}: {}", knob.name));
                        let level = log::max_level();
                        if knob.drops_lights {
                            log::set_max_level(level.min(log::LevelFilter::Error));
                        }
                        let m = measure.run(&mut renderer, knob.method, &knob.name, |o| {
                            (knob.apply)(o, knob.value)
                        });
                        log::set_max_level(level);
                        let m = m?;
                        rows.extend(m.map(|m| m.row));
                        progress.inc();
                    }
                }
                if at_knob_lights {
                    let workload = Workload {
                        scene: &name,
                        es,
                        lights: scene.lights.len(),
                    };
                    pictures.push(write_pictures(&workload, &pictured, &base, &args.out)?);
                }
            }
        }
        if plan.animated_frames > 0 && !knob_scene.is_empty() {
            let scene = load_bench_scene(&knob_scene, knob_lights, args)?;
            let name = scene_name(&knob_scene);
            let mut workload = AnimatedWorkload::new(scene, name, plan.size, plan.animated_frames);
            for method in &plan.methods {
                let name = &workload.name;
                progress.set_message(format!("{es} {name} animated: {method}"));
                animated.extend(workload.run(&mut renderer, method, es)?);
                progress.inc();
            }
        }
        renderer.destroy();
        drop(ctx);
    }
    progress.finish();
    let report = Report {
        // Lossy: a path need not be Unicode (`args` would panic on it).
        command: std::env::args_os()
            .map(|a| a.to_string_lossy().into_owned())
            .collect::<Vec<_>>()
            .join(" "),
        cpus: std::thread::available_parallelism().map_or(1, |n| n.get()),
        seconds: started.elapsed().as_secs_f64(),
        rows,
        animated,
        pictures,
    };
    report::write(&report, &args.out)?;
    deferred.commit()?;
    eprintln!(
        "{} configurations in {:.0} s → {}",
        report.rows.len(),
        report.seconds,
        shown::path(&args.out)
    );
    Ok(())
}

/// One warning for each method of the sweep or its knobs this context cannot run: their rows
/// are left out of the report (`Measure::run` gives `None`), which said nothing.
fn warn_unsupported(
    renderer: &Renderer,
    es: EsVersion,
    methods: &[String],
    knobs: &[Knob],
) -> Result<(), Box<dyn std::error::Error>> {
    let knob_methods = knobs.iter().map(|k| k.method);
    let mut names: Vec<&str> = methods
        .iter()
        .map(String::as_str)
        .chain(knob_methods)
        .collect();
    names.sort_unstable();
    names.dedup();
    for name in names {
        let desc = manylight::methods::find(name)?;
        if let Support::Unsupported(why) = (desc.supported)(renderer.caps()) {
            log::warn!("{es} {name}: skipped, this context cannot run it: {why}");
        }
    }
    Ok(())
}

/// `items` with each value once, in their first order; a warning where `flag` listed one
/// twice (`--methods forward,forward` measured every row twice).
fn once<T: PartialEq>(flag: &str, items: Vec<T>) -> Vec<T> {
    let given = items.len();
    let mut kept: Vec<T> = Vec::with_capacity(given);
    for item in items {
        if !kept.contains(&item) {
            kept.push(item);
        }
    }
    if kept.len() < given {
        log::warn!("{flag} lists a value more than once: each is measured once");
    }
    kept
}

fn scene_name(spec: &str) -> String {
    std::path::Path::new(spec)
        .file_stem()
        .map_or(spec.to_string(), |s| s.to_string_lossy().into_owned())
}

/// Forward's reference picture, its reaching counts and the CPU reference samples; `Ok(Err)`
/// with the reason where forward cannot draw every light here (no reference to compare with).
fn baseline(
    renderer: &mut Renderer,
    scene: &Scene,
    caster: &SceneRaycaster,
    (w, h): (u32, u32),
    cpu_samples: usize,
) -> Result<Result<Baseline, String>, Box<dyn std::error::Error>> {
    renderer.set_method_named("forward")?;
    let reference_opts = RenderOptions {
        measure: manylight::MeasureOptions {
            reference_precision: true,
            ..Default::default()
        },
        ..RenderOptions::default()
    };
    // The counts first: where they are refused, a reference would not be over every light.
    let bound = renderer.render_light_counts(scene, w, h, &reference_opts, CountKind::Reaching);
    let (bound, _) = match bound {
        Ok(counted) => counted,
        // More lights than forward's loop holds here: no reference over all of them.
        Err(manylight::Error::Limit(e)) => return Ok(Err(e)),
        Err(e) => return Err(e.into()),
    };
    let (reference, _) = renderer.render_offscreen(scene, w, h, &reference_opts)?;
    let subpixel = cpu_reference::snapping_reach(renderer.caps().subpixel_bits);
    let cpu = cpu_reference::reference_samples_with(
        caster,
        scene,
        w,
        h,
        cpu_samples,
        Encoding::Srgb,
        subpixel,
    );
    Ok(Ok(Baseline {
        reference,
        bound,
        cpu,
    }))
}

/// One configuration's row, with its image and light counts (kept for the pictures).
struct Measured {
    row: BenchRow,
    image: image::RgbaImage,
    evals: LightCounts,
}

/// What every configuration of one (scene, light count, ES version) shares.
struct Measure<'a> {
    scene: &'a Scene,
    name: &'a str,
    base: &'a Baseline,
    size: (u32, u32),
    frames: Frames,
}

impl Measure<'_> {
    /// Times, counts and compares one configuration; `None` when the method cannot run here.
    fn run(
        &self,
        renderer: &mut Renderer,
        method: &str,
        knob: &str,
        adjust: impl Fn(&mut RenderOptions),
    ) -> Result<Option<Measured>, Box<dyn std::error::Error>> {
        let desc = manylight::methods::find(method)?;
        if matches!((desc.supported)(renderer.caps()), Support::Unsupported(_)) {
            return Ok(None);
        }
        renderer.set_method_named(method)?;
        let mut opts = RenderOptions::default();
        adjust(&mut opts);
        let (w, h) = self.size;
        let rendered = match self.frames {
            Frames::Fixed(n) => Ok(n),
            // An untimed frame says how slow the configuration is: the first, or the second
            // where the first built shaders.
            Frames::Adaptive => {
                let mut untimed = || renderer.render_offscreen(self.scene, w, h, &opts);
                untimed().and_then(|(_, first)| match adaptive_frames(&first) {
                    Some(n) => Ok(n),
                    None => untimed().map(|(_, second)| frames_for(second.time.frame_ms)),
                })
            }
        }
        .and_then(|frames| {
            opts.measure.timed_frames = frames;
            renderer.render_offscreen(self.scene, w, h, &opts)
        });
        let (image, stats) = match rendered {
            Ok(r) => r,
            // A configuration past a method's limits (forward's loop bound, MSAA where the
            // context has none) is skipped.
            Err(e @ (manylight::Error::Limit(_) | manylight::Error::Msaa { .. })) => {
                log::warn!("{} {method} {knob}: skipped: {e}", self.name);
                return Ok(None);
            }
            Err(e) => return Err(e.into()),
        };
        let evals = renderer.render_light_counts(self.scene, w, h, &opts, CountKind::Evals);
        let (evals, _) = match evals {
            Ok(counted) => counted,
            // Counts this configuration cannot give exactly: skipped, as a render past a limit.
            Err(e @ manylight::Error::Limit(_)) => {
                log::warn!("{} {method} {knob}: skipped: {e}", self.name);
                return Ok(None);
            }
            Err(e) => return Err(e.into()),
        };
        let d = manylight::metrics::diff(&self.base.reference, &image);
        let cpu = cpu_reference::compare(&image, &self.base.cpu);
        let bound = self.base.bound.total();
        let row = BenchRow {
            scene: self.name.to_string(),
            method: method.to_string(),
            es: format!("{}.0", stats.context.es.major()),
            lights: self.scene.lights.len(),
            width: w,
            height: h,
            knob: knob.to_string(),
            frame_ms: stats.time.frame_ms,
            timed_frames: opts.measure.timed_frames,
            auto_choice: stats.auto_choice.clone(),
            gpu_ms: stats.time.gpu_ms,
            assign_ms: stats.time.assign_ms,
            upload_bytes: stats.memory.upload_bytes,
            draw_calls: stats.draw_calls,
            light_evals: evals.total(),
            evals_per_pixel: evals.mean(),
            max_evals: evals.max(),
            lower_bound_evals: bound,
            lower_bound_per_pixel: self.base.bound.mean(),
            evals_ratio: (bound > 0).then(|| evals.total() as f64 / bound as f64),
            max_abs_err: d.max_abs,
            rmse: d.rmse,
            psnr_db: d.psnr_db.is_finite().then_some(d.psnr_db),
            over_1: d.over_1,
            over_2: d.over_2,
            cpu_max_abs_err: (cpu.samples > 0).then_some(cpu.max_abs),
            cpu_samples: cpu.samples,
            overflowed_lights: stats.lights.overflowed,
            grid_footprint_px: stats.grid.footprint_px,
            grid_cells: stats.grid.cells,
            grid_reason: stats.grid.reason.clone(),
            renderer: stats.context.renderer.clone(),
            lp_num_threads: stats.context.lp_num_threads.clone(),
        };
        Ok(Some(Measured { row, image, evals }))
    }
}

/// Frames per second of animation time in the animated workload.
const ANIMATED_FPS: f64 = 30.0;

/// The animated workload: the scene's lights moving (the lively default where the scene has
/// no motion of its own) and the camera panning ±8° about its target every 4 s.
struct AnimatedWorkload {
    /// Posed by each method's run in turn, never copied: a copy would double the lights'
    /// memory, which the light count's memory check does not allow for.
    scene: Scene,
    /// The camera the pan swings about.
    start: scene::Camera,
    name: String,
    size: (u32, u32),
    frames: u32,
}

impl AnimatedWorkload {
    fn new(mut scene: Scene, name: String, size: (u32, u32), frames: u32) -> AnimatedWorkload {
        if !scene.is_animated() {
            if let Some(bounds) = scene.bounds() {
                let motion = scene::builtin::lively_motion(&name, &bounds);
                scene.animate_lights(0..scene.lights.len(), motion, 1);
            }
        }
        AnimatedWorkload {
            start: scene.camera,
            scene,
            name,
            size,
            frames,
        }
    }

    /// One method's row; `None` where it cannot run here.
    fn run(
        &mut self,
        renderer: &mut Renderer,
        method: &str,
        es: EsVersion,
    ) -> Result<Option<AnimatedRow>, Box<dyn std::error::Error>> {
        let desc = manylight::methods::find(method)?;
        if matches!((desc.supported)(renderer.caps()), Support::Unsupported(_)) {
            return Ok(None);
        }
        // Every frame poses the scene (its time and the camera) before it is drawn.
        let scene = &mut self.scene;
        let start = self.start;
        let mut pose = move |s: &mut Scene, t: f64| {
            s.set_time(t);
            let swing = 8f64.to_radians() * (std::f64::consts::TAU * t / 4.0).sin();
            let turn = glam::DQuat::from_rotation_y(swing);
            s.camera.position = start.target + turn * (start.position - start.target);
        };
        let timeline = crate::sequence::Timeline {
            start_s: 0.0,
            fps: ANIMATED_FPS,
            frames: self.frames,
        };
        renderer.set_method_named(method)?;
        let options = RenderOptions::default();
        let rendered = match crate::sequence::render(
            renderer,
            scene,
            self.size,
            &options,
            &timeline,
            &mut pose,
            crate::sequence::Keep::Last,
        ) {
            Ok(r) => r,
            // Past a method's limits (forward's loop bound, say): skipped, as in the sweep.
            Err(e) if matches!(e.downcast_ref(), Some(manylight::Error::Limit(_))) => {
                log::warn!("{} animated {method}: skipped: {e}", self.name);
                return Ok(None);
            }
            Err(e) => return Err(e),
        };
        let stats = rendered.stats;
        // The last frame against plain forward at the same time (scene already posed there).
        let error = if method == "forward" {
            None
        } else {
            renderer.set_method_named("forward")?;
            let (w, h) = self.size;
            let (reference, _) = renderer.render_offscreen(scene, w, h, &options)?;
            let last = rendered.last.as_ref().unwrap_or(&rendered.first);
            Some(manylight::metrics::diff(&reference, last).max_abs)
        };
        let (Some(frame_ms), Some(assign_ms), Some(upload_bytes)) = (
            stats.time.frame_ms_spread,
            stats.time.assign_ms_spread,
            stats.memory.upload_bytes_spread,
        ) else {
            return Ok(None);
        };
        Ok(Some(AnimatedRow {
            scene: self.name.clone(),
            method: method.to_string(),
            es: format!("{}.0", es.major()),
            lights: scene.lights.len(),
            width: self.size.0,
            height: self.size.1,
            frames: frame_ms.frames,
            fps: ANIMATED_FPS,
            p99_over_p50: AnimatedRow::tail_ratio(&frame_ms),
            frame_ms,
            assign_ms,
            upload_bytes,
            max_abs_err_vs_forward: error,
        }))
    }
}

/// The scene, ES version and light count a set of pictures shows.
struct Workload<'a> {
    scene: &'a str,
    es: EsVersion,
    lights: usize,
}

/// How far difference images amplify: an error of this many 8-bit steps or more gets the top
/// colour (×32).
const DIFF_FULL_SCALE: u8 = 8;

/// Heatmaps of every method and of the lower bound, each method's difference from the
/// reference, and the reference, for one scene's picture workload (its knobs' light count):
/// from the images and counts its default configurations already measured. Returns the file
/// names for the report.
fn write_pictures(
    at: &Workload,
    measured: &[(String, Measured)],
    base: &Baseline,
    out: &std::path::Path,
) -> Result<Pictures, Box<dyn std::error::Error>> {
    use manylight_tools::heatmap::{self, Scale};
    use manylight_tools::output::save_png;
    std::fs::create_dir_all(out)?;
    let (scene, es, lights) = (at.scene, format!("{}.0", at.es.major()), at.lights);
    let maps = std::iter::once(("lower-bound", &base.bound))
        .chain(measured.iter().map(|(name, m)| (name.as_str(), &m.evals)));
    // One colour scale for all the maps, so they compare at a glance. It must reach forward's
    // count (every light at every pixel) or forward's map clips to one flat colour; but on a
    // linear scale that high, the culling methods' few to few hundred evaluations would all
    // be the same dark purple. A log scale does both: forward's count is the top, and 3, 30
    // and 300 evaluations are equal steps below it.
    let scale = Scale::Log(maps.clone().map(|(_, c)| c.max()).max().unwrap_or(1));
    let mut pictures = Pictures {
        scene: scene.to_string(),
        es: es.clone(),
        lights,
        reference: report::reference_file(scene, &es),
        ..Pictures::default()
    };
    for (name, c) in maps {
        let title = format!(
            "{name}: {:.1} light evaluations per pixel ({scene}, ES {es}, {lights} lights).\n\
             Colour: evaluations at each pixel on a log scale shared by all maps of this \
             scene and ES version, up to the largest ({}), so none clips; dark grey: \
             background.",
            c.mean(),
            scale.max()
        );
        let file = report::heatmap_file(scene, &es, name);
        let map = heatmap::heatmap(&c.counts, &c.covered, c.width, c.height, scale, &title);
        save_png(&out.join(&file), &map)?;
        pictures.heatmaps.push((name.to_string(), file));
    }
    for (name, m) in measured {
        let what = format!(
            "{name} vs reference (forward, all lights, highp): {scene}, ES {es}, {lights} lights."
        );
        let file = report::diff_file(scene, &es, name);
        let diff = heatmap::diff_image(&base.reference, &m.image, DIFF_FULL_SCALE, &what);
        save_png(&out.join(&file), &diff)?;
        pictures.diffs.push((name.clone(), file));
    }
    save_png(&out.join(&pictures.reference), &base.reference)?;
    Ok(pictures)
}

#[cfg(test)]
mod tests {
    use std::os::unix::ffi::OsStrExt;

    use super::*;

    #[test]
    fn the_conference_room_is_found_or_its_absence_explained() {
        let root = tempfile::tempdir().unwrap();
        let utf8 = root.path().join("assets");
        let other = root.path().join(std::ffi::OsStr::from_bytes(b"assets\xff"));
        for dir in [&utf8, &other] {
            std::fs::create_dir_all(dir.join("conference")).unwrap();
            std::fs::write(dir.join("conference/conference.obj"), "").unwrap();
        }
        let found = conference_in(Some(utf8.clone().into())).unwrap();
        assert!(std::path::Path::new(&found).is_file(), "{found}");
        let why = conference_in(Some(other.into())).unwrap_err();
        assert!(
            why.contains("is not UTF-8") && why.contains("/assets\u{fffd}/conference/"),
            "{why}"
        );
        let why = conference_in(None).unwrap_err();
        assert!(why.contains("set MANYLIGHT_ASSETS"), "{why}");
        let why = conference_in(Some(root.path().join("none").into())).unwrap_err();
        assert!(why.contains("set MANYLIGHT_ASSETS"), "{why}");
    }

    #[test]
    fn an_adaptive_row_is_timed_by_a_frame_that_built_no_shaders() {
        let frame = |ms: f64, built: usize| {
            let mut stats = manylight::FrameStats::default();
            stats.time.frame_ms = ms;
            stats.programs_built = built;
            stats
        };
        assert_eq!(adaptive_frames(&frame(150.0, 0)), Some(3));
        assert_eq!(adaptive_frames(&frame(50.0, 0)), Some(9));
        // Compiling made it slow: the next frame decides.
        assert_eq!(adaptive_frames(&frame(150.0, 3)), None);
    }

    /// The conversion changes the reflectance alone: a decal's bias, a cut-out, a single side
    /// and its opacity stay; a metallic-roughness material is left as it was.
    #[test]
    fn converting_to_metallic_roughness_keeps_everything_but_the_reflectance() {
        use manylight::scene::{Material, MaterialModel};
        let mut scene = Scene::empty();
        let mut glossy = Material {
            depth_bias: 2.0,
            alpha: 0.5,
            alpha_cutoff: Some(0.3),
            alpha_texture: true,
            alpha_vertex: true,
            double_sided: false,
            ..Material::glossy(
                "decal",
                glam::Vec3::new(0.8, 0.2, 0.1),
                glam::Vec3::ONE,
                30.0,
            )
        };
        glossy.maps.emissive = glam::Vec3::new(0.1, 0.2, 0.3);
        scene.add_material(glossy.clone());
        let metal = Material::metallic_roughness("metal", glam::Vec3::ONE, 1.0, 0.4);
        scene.add_material(metal.clone());
        to_metallic_roughness(&mut scene);
        let converted = &scene.materials[0];
        assert_eq!(converted.model, MaterialModel::MetallicRoughness);
        assert_eq!(
            (converted.metallic, converted.diffuse),
            (0.0, glossy.diffuse)
        );
        // Ns 30 = 2/α² − 2 with α = roughness².
        let alpha = converted.roughness.powi(2);
        assert!((2.0 / (alpha * alpha) - 2.0 - 30.0).abs() < 1e-3, "{alpha}");
        let kept = |m: &Material| {
            let alpha = (m.alpha, m.alpha_cutoff, m.alpha_texture, m.alpha_vertex);
            (m.depth_bias, alpha, m.double_sided, m.maps.emissive)
        };
        assert_eq!(kept(converted), kept(&glossy));
        let reflectance = |m: &Material| (m.model, m.metallic, m.roughness);
        assert_eq!(reflectance(&scene.materials[1]), reflectance(&metal));
    }
}
