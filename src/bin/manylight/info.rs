//! `manylight info`.

use clap::Parser;
use manylight::gl::{Caps, HeadlessContext};
use manylight::methods::{Support, METHODS};
use manylight::Renderer;

use crate::EsArg;

/// Options of `manylight info`.
#[derive(Parser, Debug)]
pub struct InfoArgs {
    /// OpenGL ES version of the context to probe.
    #[arg(long, value_enum, default_value = "3")]
    pub es: EsArg,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Runs the command.
pub fn run(args: &InfoArgs) -> Result<(), Box<dyn std::error::Error>> {
    let es = args.es.into();
    let ctx = HeadlessContext::new(es)?;
    let renderer = Renderer::new(ctx.load_gl(), es)?;
    let caps = renderer.caps().clone();
    let fp16 = renderer.mediump_is_fp16();
    renderer.destroy();
    let fp16 = fp16?;
    let methods: Vec<_> = METHODS
        .iter()
        .map(|m| (m.name, (m.supported)(&caps)))
        .collect();
    if args.json {
        let value = serde_json::json!({
            "egl": ctx.info(),
            "caps": caps,
            "mediump_is_fp16": fp16,
            "methods": methods.iter().map(|(name, s)| serde_json::json!({"name": name, "support": s})).collect::<Vec<_>>(),
        });
        print_stdout(&(serde_json::to_string_pretty(&value)? + "\n"));
    } else {
        let mut text = format_text(&caps, ctx.info(), &methods);
        text.push_str(&format!("mediump runs as      {}\n", if fp16 { "fp16 (measured)" } else { "fp32 (measured)" }));
        print_stdout(&text);
    }
    Ok(())
}

/// Writes to stdout, treating a closed pipe (`manylight info | head`) as the end, not a panic.
fn print_stdout(text: &str) {
    use std::io::Write;
    let _ = std::io::stdout().lock().write_all(text.as_bytes());
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
    let p = |p: &manylight::gl::caps::Precision| {
        format!(
            "2^{}..2^{}, {} bits",
            -p.range_min, p.range_max, p.precision
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
    w!(out, "depth24            {}", caps.depth24);
    w!(out, "timer queries      {}", caps.timer_query);
    w!(out, "extensions         {}", caps.extensions.len());
    for e in &caps.extensions {
        w!(out, "  {e}");
    }
    w!(out, "methods");
    for (name, s) in methods {
        match s {
            Support::Supported => w!(out, "  {name:<10} supported"),
            Support::Fallback(r) => w!(out, "  {name:<10} fallback: {r}"),
            Support::Unsupported(r) => w!(out, "  {name:<10} unsupported: {r}"),
        }
    }
    out
}
