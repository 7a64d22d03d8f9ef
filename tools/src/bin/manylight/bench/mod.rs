//! `manylight bench`: error against run time. Sweeps scenes × light counts × ES versions ×
//! methods, plus the knobs that trade error for time, and writes the report (see
//! `manylight_tools::report`).
//!
//! For every (scene, light count, ES version) it renders the reference once (plain forward over
//! all lights, light model at highp), the lower bound of light evaluations (lights that really
//! reach each pixel) and the f64 CPU reference at sampled pixels; then each configuration is
//! timed, counted and compared against them.

mod animated;
mod knobs;
mod materials;
mod measure;
mod pictures;
mod plan;
mod preflight;

use std::path::PathBuf;
use std::time::Instant;

use clap::Parser;
use manylight::gl::HeadlessContext;
use manylight::methods::Support;
use manylight::scene::raycast::SceneRaycaster;
use manylight::scene::{self, shown, Scene};
use manylight::{EsVersion, Renderer};
use manylight_tools::report::{self, Report};

use crate::EsArg;
use animated::AnimatedWorkload;
use knobs::{knobs, Knob};
use materials::to_metallic_roughness;
use measure::{baseline, Measure};
use pictures::{write_pictures, Workload};
use plan::{scene_name, Plan};
use preflight::check_before_rendering;

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

/// Runs the command.
pub fn run(args: &BenchArgs) -> Result<(), Box<dyn std::error::Error>> {
    let started = Instant::now();
    let plan = Plan::from(args);
    let _fifos_held_until_written = check_before_rendering(args, &plan)?;
    // The whole report folder is replaced at the end or not at all: stopped half-way (an
    // error, a signal) it stays the last run's, not a mixture of two.
    let deferred = manylight_tools::output::defer_commits();
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
