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
    renderer.destroy();
    let methods: Vec<_> = METHODS
        .iter()
        .map(|m| (m.name, (m.supported)(&caps)))
        .collect();
    if args.json {
        let value = serde_json::json!({
            "egl": ctx.info(),
            "caps": caps,
            "methods": methods.iter().map(|(name, s)| serde_json::json!({"name": name, "support": s})).collect::<Vec<_>>(),
        });
        println!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        print_text(&caps, ctx.info(), &methods);
    }
    Ok(())
}

fn print_text(caps: &Caps, egl: &manylight::gl::context::EglInfo, methods: &[(&str, Support)]) {
    println!("feature level      {} (context {})", caps.es, caps.context_version);
    println!("GL_VERSION         {}", caps.gl_version);
    println!("GLSL               {}", caps.glsl_version);
    println!("GL_RENDERER        {}", caps.renderer);
    println!("GL_VENDOR          {}", caps.vendor);
    println!(
        "EGL                {} ({}, {} platform, {})",
        egl.egl_version,
        egl.egl_vendor,
        egl.platform,
        if egl.surfaceless_context { "surfaceless context" } else { "1x1 pbuffer" }
    );
    println!("max texture size   {}", caps.max_texture_size);
    println!("frag uniform vecs  {}", caps.max_fragment_uniform_vectors);
    println!("texture units      {}", caps.max_texture_image_units);
    println!("draw buffers       {} (colour attachments {})", caps.max_draw_buffers, caps.max_color_attachments);
    let p = |p: &manylight::gl::caps::Precision| format!("2^{}..2^{}, {} bits", -p.range_min, p.range_max, p.precision);
    println!("fragment highp     {}", if caps.fragment_has_highp() { p(&caps.fragment_highp) } else { "not supported".into() });
    println!("fragment mediump   {}", p(&caps.fragment_mediump));
    println!("float textures     {}", caps.float_textures);
    println!("depth24            {}", caps.depth24);
    println!("timer queries      {}", caps.timer_query);
    println!("extensions         {}", caps.extensions.len());
    for e in &caps.extensions {
        println!("  {e}");
    }
    println!("methods");
    for (name, s) in methods {
        match s {
            Support::Supported => println!("  {name:<10} supported"),
            Support::Fallback(r) => println!("  {name:<10} fallback: {r}"),
            Support::Unsupported(r) => println!("  {name:<10} unsupported: {r}"),
        }
    }
}
