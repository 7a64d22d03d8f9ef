//! The hidden child of `manylight matrix`: one configuration, every method rendered and
//! compared with the reference, one JSON row printed.

use std::path::PathBuf;

use clap::Parser;
use manylight::gl::HeadlessContext;
use manylight::methods::{Support, METHODS};
use manylight::{scene, EsVersion, RenderOptions, Renderer};
use manylight_tools::output::{self, print_stdout};
use serde_json::json;

use crate::EsArg;

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
