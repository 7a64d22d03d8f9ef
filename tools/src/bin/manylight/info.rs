//! `manylight info`.

use clap::Parser;
use manylight::gl::{Caps, HeadlessContext};
use manylight::methods::{ShaderFeatures, Support, METHODS};
use manylight::EsVersion;
use manylight::Renderer;
use manylight_tools::output::print_stdout;

use crate::EsArg;

/// Options of `manylight info`.
#[derive(Parser, Debug)]
pub struct InfoArgs {
    /// OpenGL ES version of the context to probe (default: 3 where the driver gives it, else 2
    /// with a warning; 2 with `--no-fragment-highp` or `--no-float-textures`).
    #[arg(long, value_enum)]
    pub es: Option<EsArg>,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Also render this scene (built-in, .obj, .gltf/.glb or .json) once with every supported
    /// method and report the shader variants built (features, source size) and each method's
    /// GPU memory.
    #[arg(long, value_parser = crate::SceneSpec)]
    pub scene: Option<String>,
    /// Play a device whose fragment stage has no highp (needs `--es 2`; see `render`).
    #[arg(long)]
    pub no_fragment_highp: bool,
    /// Play a device without float textures (needs `--es 2`; see `render`).
    #[arg(long)]
    pub no_float_textures: bool,
    /// List every extension of the context (the text output gives only their number).
    #[arg(long)]
    pub extensions: bool,
}

/// Renders `spec` with every supported method at a small size; returns per-method GPU bytes,
/// the scene's features and every variant built.
fn scene_report(
    renderer: &mut Renderer,
    spec: &str,
) -> Result<serde_json::Value, Box<dyn std::error::Error>> {
    // The lights `render` gives it by default (seed 1): a glTF or scene file its own.
    let lights = crate::render::lights_for(spec, None, 1);
    let (scene, _) = manylight::scene::load_with(spec, lights, &crate::load_options())?;
    let mut methods = Vec::new();
    let mut features = None;
    let mut first_error = None;
    for m in METHODS {
        if matches!((m.supported)(renderer.caps()), Support::Unsupported(_)) {
            continue;
        }
        renderer.set_method_named(m.name)?;
        // A method past its limits with this scene (tiled and clustered over 65 536 visible
        // lights) is reported as such; the others still are.
        match renderer.render_offscreen(&scene, 64, 36, &manylight::RenderOptions::default()) {
            Ok((_, stats)) => {
                features = Some(stats.scene_features);
                methods.push(serde_json::json!({
                    "method": m.name, "gpu_bytes": stats.memory.method_gpu_bytes
                }));
            }
            Err(e) => {
                methods.push(serde_json::json!({"method": m.name, "error": e.to_string()}));
                first_error.get_or_insert(e);
            }
        }
    }
    if let (None, Some(e)) = (&features, first_error) {
        return Err(e.into());
    }
    let variants: Vec<_> = renderer
        .program_report()
        .into_iter()
        .map(|p| {
            serde_json::json!({
                "shader": p.shader,
                "features": ShaderFeatures(p.features).names(),
                "source_bytes": p.source_bytes,
            })
        })
        .collect();
    Ok(
        serde_json::json!({"scene": spec, "features": features, "methods": methods, "variants": variants}),
    )
}

/// Runs the command.
pub fn run(args: &InfoArgs) -> Result<(), Box<dyn std::error::Error>> {
    let restrictions = manylight::gl::Restrictions {
        no_fragment_highp: args.no_fragment_highp,
        no_float_textures: args.no_float_textures,
    };
    let probe = |es: EsVersion| -> Result<_, Box<dyn std::error::Error>> {
        let ctx = HeadlessContext::new(es)?;
        let renderer = Renderer::restricted(ctx.load_gl()?, es, &restrictions)?;
        Ok((ctx, renderer))
    };
    let (ctx, mut renderer) = match args.es {
        Some(es) => probe(es.into())?,
        None if args.no_fragment_highp || args.no_float_textures => probe(EsVersion::Es2)?,
        // A capability probe reports what the device has: ES 2.0 where ES 3.0 is missing.
        None => match probe(EsVersion::Es3) {
            Err(e) if crate::version_unavailable(e.as_ref()) => {
                log::warn!("{e}: probing OpenGL ES 2.0 (`--es 3` insists on 3.0)");
                probe(EsVersion::Es2)?
            }
            probed => probed?,
        },
    };
    let report = args
        .scene
        .as_deref()
        .map(|s| scene_report(&mut renderer, s))
        .transpose();
    let caps = renderer.caps().clone();
    let fp16 = renderer.mediump_is_fp16();
    renderer.destroy();
    let fp16 = fp16?;
    let report = report?;
    let methods: Vec<_> = METHODS
        .iter()
        .map(|m| (m.name, (m.supported)(&caps)))
        .collect();
    if args.json {
        let value = serde_json::json!({
            "egl": ctx.info(),
            "library_files": manylight::gl::gles_lib::loaded_files(),
            "implementation": caps.implementation(),
            "caps": caps,
            "capacities": manylight::methods::capacity::capacities(&caps),
            "mediump_is_fp16": fp16,
            "assign_pool": {
                "threads": rayon::current_num_threads(),
                "most_an_assignment_takes": assignment_threads(),
                "caller_in_pool": caller_in_pool(),
            },
            "scene": report,
            "methods": methods.iter().map(|(name, s)| serde_json::json!({"name": name, "support": s})).collect::<Vec<_>>(),
        });
        print_stdout(&(serde_json::to_string_pretty(&value)? + "\n"))?;
    } else {
        let mut text = format_text(&caps, ctx.info(), &methods, args.extensions);
        text.push_str(&format!(
            "mediump runs as      {}\n",
            if fp16 {
                "fp16 (measured)"
            } else {
                "fp32 (measured)"
            }
        ));
        text.push_str(&format!(
            "light assignment     up to {} CPU threads (of rayon's pool of {}{})\n",
            assignment_threads(),
            rayon::current_num_threads(),
            if caller_in_pool() {
                ", this thread one of them"
            } else {
                "; this thread waits for them"
            }
        ));
        if let Some(r) = &report {
            text.push_str(&format_scene_report(r));
        }
        print_stdout(&text)?;
    }
    Ok(())
}

/// Whether this thread, which renders and so assigns the lights, is one of rayon's pool: then a
/// parallel assignment starts on it at once (`thread_pool::join_rayon_pool`, called by `main`).
fn caller_in_pool() -> bool {
    rayon::current_thread_index().is_some()
}

/// `writeln!` into a String (cannot fail).
macro_rules! w {
    ($out:expr, $($arg:tt)*) => {{
        use std::fmt::Write as _;
        let _ = writeln!($out, $($arg)*);
    }};
}

fn format_text(
    caps: &Caps,
    egl: &manylight::gl::context::EglInfo,
    methods: &[(&str, Support)],
    list_extensions: bool,
) -> String {
    let mut out = String::new();
    w!(
        out,
        "feature level      {} (context {})",
        caps.es,
        caps.context_version
    );
    w!(out, "GL_VERSION         {}", caps.gl_version);
    w!(out, "GLSL               {}", caps.glsl_version);
    w!(out, "GL_RENDERER        {}", caps.renderer);
    w!(out, "GL_VENDOR          {}", caps.vendor);
    w!(
        out,
        "implementation     {} ({})",
        caps.implementation(),
        egl.gles_lib.as_ref().map_or_else(
            || "the system's libEGL.so.1".to_string(),
            |d| format!("--gles-lib {}", manylight::scene::shown::path(d))
        )
    );
    // Read here, not at every context's creation: only `info` shows them.
    for f in &manylight::gl::gles_lib::loaded_files() {
        w!(out, "  {}", manylight::scene::shown::path(f));
    }
    w!(
        out,
        "EGL                {} ({}, {} platform, {})",
        egl.egl_version,
        egl.egl_vendor,
        egl.platform,
        if egl.surfaceless_context {
            "surfaceless context"
        } else {
            "1x1 pbuffer"
        }
    );
    w!(out, "max texture size   {}", caps.max_texture_size);
    w!(out, "max renderbuffer   {}", caps.max_renderbuffer_size);
    let [vw, vh] = caps.max_viewport_dims;
    w!(out, "max viewport       {vw}×{vh}");
    w!(
        out,
        "frag uniform vecs  {}",
        caps.max_fragment_uniform_vectors
    );
    w!(out, "texture units      {}", caps.max_texture_image_units);
    w!(
        out,
        "draw buffers       {} (colour attachments {})",
        caps.max_draw_buffers,
        caps.max_color_attachments
    );
    if caps.max_samples > 1 {
        w!(
            out,
            "MSAA               up to {}× (--msaa)",
            caps.max_samples
        );
    } else if caps.es == EsVersion::Es3 || caps.msaa_render_to_texture {
        // The way to multisample is there, but not the samples (softpipe).
        w!(
            out,
            "MSAA               unsupported here (GL_MAX_SAMPLES is {})",
            caps.max_samples
        );
    } else {
        w!(
            out,
            "MSAA               unsupported here (needs ES 3.0, or GL_EXT_multisampled_render_to_texture on ES 2.0)"
        );
    }
    let p = |p: &manylight::gl::caps::Precision| {
        format!(
            "-2^{}..2^{}, {} bits",
            p.range_min, p.range_max, p.precision
        )
    };
    w!(
        out,
        "fragment highp     {}",
        if caps.fragment_has_highp() {
            p(&caps.fragment_highp)
        } else {
            "not supported".into()
        }
    );
    w!(out, "fragment mediump   {}", p(&caps.fragment_mediump));
    w!(out, "float textures     {}", caps.float_textures);
    w!(
        out,
        "depth24            {} (own targets' depth: {} bits)",
        caps.depth24,
        caps.own_depth_format().1
    );
    w!(out, "timer queries      {}", caps.timer_query);
    let cap = manylight::methods::capacity::capacities(caps);
    w!(
        out,
        "capacities         forward {} lights a draw; tiled/clustered {} visible lights, {} list entries, {} a cell, {} grid texels",
        cap.forward_lights,
        cap.indexed_lights,
        cap.index_entries,
        cap.cell_lights
            .map_or_else(|| "any number".to_string(), |n| n.to_string()),
        cap.grid_texels
    );
    w!(out, "methods");
    for (name, s) in methods {
        match s {
            Support::Supported => w!(out, "  {name:<10} supported"),
            Support::Fallback(r) => w!(out, "  {name:<10} fallback: {r}"),
            Support::Unsupported(r) => w!(out, "  {name:<10} unsupported: {r}"),
        }
    }
    if list_extensions {
        w!(out, "extensions         {}", caps.extensions.len());
        for e in &caps.extensions {
            w!(out, "  {e}");
        }
    } else {
        let n = caps.extensions.len();
        w!(out, "extensions         {n} (--extensions lists them)");
    }
    out
}

fn format_scene_report(r: &serde_json::Value) -> String {
    let mut out = String::new();
    w!(
        out,
        "scene {}: features {}",
        r["scene"].as_str().unwrap_or("?"),
        r["features"]
    );
    for m in r["methods"].as_array().into_iter().flatten() {
        let method = m["method"].as_str().unwrap_or("?");
        match m["error"].as_str() {
            Some(e) => w!(out, "  {method:<10} cannot render it: {e}"),
            None => w!(
                out,
                "  {method:<10} holds {} bytes of GPU memory",
                m["gpu_bytes"]
            ),
        }
    }
    w!(out, "shader variants built");
    for v in r["variants"].as_array().into_iter().flatten() {
        w!(
            out,
            "  {:<10} {:>6} bytes  {}",
            v["shader"].as_str().unwrap_or("?"),
            v["source_bytes"],
            v["features"]
        );
    }
    out
}

/// The most threads of the pool one light assignment takes.
fn assignment_threads() -> usize {
    rayon::current_num_threads().min(manylight::cluster::assign::MAX_ASSIGN_THREADS)
}
