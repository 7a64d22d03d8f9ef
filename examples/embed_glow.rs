//! Embedding: manylight draws into a framebuffer the application owns, on the application's
//! own GL context, between the application's own draw calls.
//!
//! ```text
//! cargo run --release --example embed_glow -- [OUT.png]
//! ```
//!
//! The "application" here makes its GL context with `HeadlessContext` to stay short; a game
//! has one from glutin, SDL or Android's EGL already. What matters is the order:
//!
//! 1. hand manylight the application's `glow::Context`, shared as an `Arc` (as egui and
//!    three-d hold theirs; a `glow::Context` of its own, loaded from the same current context,
//!    works as well);
//! 2. bind the target (here an FBO with a texture; in a game, often the default framebuffer)
//!    and call [`Renderer::render`], which draws into whatever is bound, with the viewport it
//!    is given;
//! 3. carry on: manylight gives back the GL state it found (framebuffer, vertex array on ES 3.0,
//!    program, textures, blend, depth, viewport, …; the README's "Sharing the context with a
//!    game" lists it), so the application's next pass starts where it left off. An application
//!    that sets all its state before each pass skips that save, and the queries a threaded
//!    driver waits on: `renderer.set_gl_state_handling(GlStateHandling::Reset)` leaves GL's
//!    initial values instead, with the application's framebuffer still bound.
//!
//! `image` is manylight's re-export (`manylight::image`, the type its offscreen renders
//! return); `rayon`, for joining its pool, is a crate of its own that a game copying this adds
//! to its `Cargo.toml` (manylight uses rayon's global pool, and does not re-export it).
#![allow(unsafe_code)] // raw glow calls: the application's side of the example

use std::path::Path;

use manylight::glow::{self, HasContext};
use manylight::{builtin_scene, EsVersion, HeadlessContext, RandomLights, RenderOptions, Renderer};

/// The application's render target: a colour texture and depth buffer on an FBO.
struct AppTarget {
    fbo: glow::Framebuffer,
    color: glow::Texture,
    depth: glow::Renderbuffer,
}

impl AppTarget {
    /// # Safety
    /// `gl` must be current.
    unsafe fn new(gl: &glow::Context, width: i32, height: i32) -> Result<AppTarget, String> {
        let color = gl.create_texture()?;
        gl.bind_texture(glow::TEXTURE_2D, Some(color));
        gl.tex_image_2d(
            glow::TEXTURE_2D,
            0,
            glow::RGBA as i32,
            width,
            height,
            0,
            glow::RGBA,
            glow::UNSIGNED_BYTE,
            glow::PixelUnpackData::Slice(None),
        );
        gl.tex_parameter_i32(
            glow::TEXTURE_2D,
            glow::TEXTURE_MIN_FILTER,
            glow::LINEAR as i32,
        );
        let depth = gl.create_renderbuffer()?;
        gl.bind_renderbuffer(glow::RENDERBUFFER, Some(depth));
        // 24 bits, as manylight's own targets use: the shading pass after the depth prepass
        // tests `LEQUAL`, and with 16 bits (near 0.1, far 80) a surface up to ~10 cm behind
        // the visible one at 25 m falls in the same depth step and is shaded over it.
        gl.renderbuffer_storage(glow::RENDERBUFFER, glow::DEPTH_COMPONENT24, width, height);
        let fbo = gl.create_framebuffer()?;
        gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
        gl.framebuffer_texture_2d(
            glow::FRAMEBUFFER,
            glow::COLOR_ATTACHMENT0,
            glow::TEXTURE_2D,
            Some(color),
            0,
        );
        gl.framebuffer_renderbuffer(
            glow::FRAMEBUFFER,
            glow::DEPTH_ATTACHMENT,
            glow::RENDERBUFFER,
            Some(depth),
        );
        let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
        if status != glow::FRAMEBUFFER_COMPLETE {
            return Err(format!("application FBO incomplete: {status:#x}"));
        }
        Ok(AppTarget { fbo, color, depth })
    }

    /// # Safety
    /// `gl` must be current.
    unsafe fn destroy(self, gl: &glow::Context) {
        gl.delete_framebuffer(self.fbo);
        gl.delete_texture(self.color);
        gl.delete_renderbuffer(self.depth);
    }
}

/// Renders the courtyard into the application's FBO, draws the application's own overlay (a
/// scissored bar along the bottom) after it, reads the result back and writes it to `out`.
pub fn run(out: &Path, width: u32, height: u32) -> Result<(), Box<dyn std::error::Error>> {
    let ctx = HeadlessContext::new(EsVersion::Es3)?;
    let app_gl = std::sync::Arc::new(ctx.load_gl()?);
    let mut renderer = Renderer::new(app_gl.clone(), EsVersion::Es3)?;
    let scene = builtin_scene(
        "courtyard",
        Some(RandomLights {
            count: 512,
            seed: 3,
        }),
    )?;
    let (w, h) = (width as i32, height as i32);
    let target = unsafe { AppTarget::new(&app_gl, w, h)? };
    let result = (|| -> Result<manylight::image::RgbaImage, Box<dyn std::error::Error>> {
        unsafe {
            app_gl.bind_framebuffer(glow::FRAMEBUFFER, Some(target.fbo));
            app_gl.viewport(0, 0, w, h);
        }
        // A game sets `wait_for_gpu: false`: the frame's work is queued, not waited for.
        let options = RenderOptions {
            wait_for_gpu: false,
            ..RenderOptions::default()
        };
        let stats = renderer.render(&scene, width, height, &options)?;
        println!(
            "manylight: {} lights, {} method, {:.2} ms CPU",
            stats.lights.total, stats.method, stats.time.frame_ms
        );
        let mut pixels = vec![0u8; (width * height * 4) as usize];
        unsafe {
            let bound = app_gl.get_parameter_framebuffer(glow::FRAMEBUFFER_BINDING);
            if bound != Some(target.fbo) {
                return Err("manylight left another framebuffer bound".into());
            }
            // The application's own pass on top: a bar along the bottom edge.
            app_gl.enable(glow::SCISSOR_TEST);
            app_gl.scissor(0, 0, w, h / 16);
            app_gl.clear_color(0.9, 0.6, 0.1, 1.0);
            app_gl.clear(glow::COLOR_BUFFER_BIT);
            app_gl.disable(glow::SCISSOR_TEST);
            app_gl.read_pixels(
                0,
                0,
                w,
                h,
                glow::RGBA,
                glow::UNSIGNED_BYTE,
                glow::PixelPackData::Slice(Some(&mut pixels)),
            );
        }
        // GL rows start at the bottom; images at the top.
        let rows: Vec<u8> = pixels
            .chunks_exact((width * 4) as usize)
            .rev()
            .flatten()
            .copied()
            .collect();
        Ok(manylight::image::RgbaImage::from_raw(width, height, rows).ok_or("readback size")?)
    })();
    renderer.destroy();
    unsafe {
        app_gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        target.destroy(&app_gl);
    }
    result?.save(out)?;
    Ok(())
}

#[allow(dead_code)] // `tests/examples.rs` includes this file and calls `run` itself.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The thread that renders joins rayon's global pool before anything uses rayon, so the CPU
    // light assignment starts on it at once instead of waiting for a pool thread to wake
    // (README, "Embedding").
    if let Err(e) = rayon::ThreadPoolBuilder::new()
        .use_current_thread()
        .build_global()
    {
        eprintln!("rayon's pool left as it was: {e}");
    }
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "embedded.png".into());
    run(Path::new(&out), 640, 360)?;
    println!("{out}: the courtyard in the application's framebuffer, its overlay on top");
    Ok(())
}
