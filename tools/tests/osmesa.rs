//! Desktop OpenGL through OSMesa renders the default scene through the same methods, matching
//! plain forward there and the ES 3.0 render on EGL. Skipped with a message where libOSMesa is
//! not installed.
#![cfg(feature = "osmesa")]

mod common;

use manylight::gl::osmesa::OsMesaContext;
use manylight::gl::HeadlessContext;
use manylight::methods::METHODS;
use manylight::{scene, EsVersion, RenderOptions, Renderer};

/// A desktop GL context through OSMesa, or `None` (the test skips, saying why) without
/// libOSMesa.
fn osmesa_or_skip() -> Option<OsMesaContext> {
    OsMesaContext::new()
        .map_err(|e| common::skip(&e.to_string()))
        .ok()
}

#[test]
fn osmesa_renders_the_default_scene_through_every_method() {
    let Some(ctx) = osmesa_or_skip() else {
        return;
    };
    let s = scene::builtin::build(scene::builtin::DEFAULT, Some((256, 5))).unwrap();
    let opts = RenderOptions::default();
    let mut r = Renderer::new(ctx.load_gl(), EsVersion::Es3).unwrap();
    assert!(r.caps().desktop, "OSMesa gives desktop GL");
    r.set_method_named("forward").unwrap();
    let (reference, _) = r.render_offscreen(&s, 160, 90, &opts).unwrap();
    for m in METHODS {
        r.set_method_named(m.name)
            .unwrap_or_else(|e| panic!("{}: {e}", m.name));
        let (img, _) = r.render_offscreen(&s, 160, 90, &opts).unwrap();
        let d = manylight::metrics::diff(&reference, &img);
        assert!(
            d.max_abs <= 2,
            "OSMesa {}: {} / 255 from forward",
            m.name,
            d.max_abs
        );
    }
    r.destroy();
    drop(ctx);
    // The same picture as ES 3.0 on Mesa's EGL (another implementation rasterizes edges its
    // own way: tests/gles_implementations.rs compares methods within each).
    if common::other_implementation_than_mesa("OSMesa against Mesa's EGL") {
        return;
    }
    let egl = HeadlessContext::new(EsVersion::Es3).unwrap();
    let mut r = Renderer::new(egl.load_gl().unwrap(), EsVersion::Es3).unwrap();
    r.set_method_named("forward").unwrap();
    let (es3, _) = r.render_offscreen(&s, 160, 90, &opts).unwrap();
    r.destroy();
    let d = manylight::metrics::diff(&reference, &es3);
    assert!(d.max_abs <= 2, "OSMesa vs EGL ES 3.0: {} / 255", d.max_abs);
}

/// Desktop GL's own state a game may leave on: a wireframe polygon mode (a debug view) and
/// sRGB encoding of framebuffers. Neither changes the frame, and both come back.
#[test]
#[allow(unsafe_code)] // the game's side: raw glow calls
fn a_desktop_games_polygon_mode_and_srgb_switch_neither_change_the_frame_nor_stay_changed() {
    use manylight::glow::{self, HasContext};
    let Some(ctx) = osmesa_or_skip() else {
        return;
    };
    let s = scene::builtin::build(scene::builtin::DEFAULT, Some((64, 5))).unwrap();
    let opts = RenderOptions::default();
    let mut r = Renderer::new(ctx.load_gl(), EsVersion::Es3).unwrap();
    let (clean, _) = r.render_offscreen(&s, 96, 54, &opts).unwrap();
    let gl = ctx.load_gl();
    unsafe {
        gl.polygon_mode(glow::FRONT_AND_BACK, glow::LINE);
        gl.enable(glow::FRAMEBUFFER_SRGB);
    }
    let (img, _) = r.render_offscreen(&s, 96, 54, &opts).unwrap();
    let d = manylight::metrics::diff(&clean, &img);
    assert_eq!(d.max_abs, 0, "the game's desktop state changed the frame");
    unsafe {
        let mut mode = [0; 2];
        gl.get_parameter_i32_slice(glow::POLYGON_MODE, &mut mode);
        assert_eq!(
            mode[0],
            glow::LINE as i32,
            "the polygon mode was not given back"
        );
        assert!(
            gl.is_enabled(glow::FRAMEBUFFER_SRGB),
            "sRGB encoding left off"
        );
    }
    // Drawn into a game's sRGB framebuffer with the switch on: the frame is stored as an
    // RGBA8 one stores it (encoded once, by the shader), not encoded again.
    let mut into = |colour: u32| -> Vec<u8> {
        use common::game_target::{sized_framebuffer, stored_then_free};
        let target = unsafe { sized_framebuffer(&gl, colour, (96, 54)) };
        r.render(&s, 96, 54, &opts).unwrap();
        unsafe { stored_then_free(&gl, target, (96, 54)) }
    };
    unsafe { gl.polygon_mode(glow::FRONT_AND_BACK, glow::FILL) };
    let (plain, srgb) = (into(glow::RGBA8), into(glow::SRGB8_ALPHA8));
    let worst = plain.iter().zip(&srgb).map(|(a, b)| a.abs_diff(*b)).max();
    assert!(
        worst <= Some(1),
        "the sRGB framebuffer's frame is {worst:?}/255 off"
    );
    r.destroy();
}

/// A process that made (and dropped) a `HeadlessContext` still renders on a context EGL does
/// not know (OSMesa here; a GLX or WGL game's alike): the renderer took EGL's "no context
/// current" for its own context's state and refused every call as not current.
#[test]
fn a_context_egl_does_not_know_renders_after_a_headless_context_was_dropped() {
    drop(HeadlessContext::new(EsVersion::Es3).unwrap());
    let Some(ctx) = osmesa_or_skip() else {
        return;
    };
    let s = scene::builtin::build(scene::builtin::DEFAULT, Some((16, 5))).unwrap();
    let mut r = Renderer::new(ctx.load_gl(), EsVersion::Es3).unwrap();
    let (img, _) = r
        .render_offscreen(&s, 32, 18, &RenderOptions::default())
        .unwrap();
    assert!(img.pixels().any(|p| p.0[..3] != [0, 0, 0]), "a lit frame");
    r.set_method_named("clustered").unwrap();
    r.destroy();
}

/// A compatibility-profile context (what a toolkit gives by default) renders every method as
/// the core profile does, and keeps the game's constant attributes: saving the game's state
/// read location 0's current value, which that profile refuses (`GL_INVALID_OPERATION`, every
/// offscreen render failed).
#[test]
#[allow(unsafe_code)] // the game's side: raw glow calls
fn a_compatibility_profile_context_renders_as_the_core_profile() {
    use manylight::glow::{self, HasContext};
    let Some(core) = osmesa_or_skip() else {
        return;
    };
    let s = scene::builtin::build(scene::builtin::DEFAULT, Some((64, 5))).unwrap();
    let opts = RenderOptions::default();
    let mut r = Renderer::new(core.load_gl(), EsVersion::Es3).unwrap();
    let (reference, _) = r.render_offscreen(&s, 96, 54, &opts).unwrap();
    r.destroy();
    drop(core);
    let compat = OsMesaContext::compatibility().expect("OSMesa gives a compatibility profile");
    let gl = compat.load_gl();
    let colour = [0.25, 0.5, 0.75, 1.0];
    unsafe { gl.vertex_attrib_4_f32(3, colour[0], colour[1], colour[2], colour[3]) };
    let mut r = Renderer::new(compat.load_gl(), EsVersion::Es3).unwrap();
    for m in METHODS {
        r.set_method_named(m.name).unwrap();
        let (img, _) = r
            .render_offscreen(&s, 96, 54, &opts)
            .unwrap_or_else(|e| panic!("{}: {e}", m.name));
        let d = manylight::metrics::diff(&reference, &img);
        assert!(d.max_abs <= 2, "{}: {} / 255 from core", m.name, d.max_abs);
    }
    let mut current = [0f32; 4];
    unsafe {
        gl.get_vertex_attrib_parameter_f32_slice(3, glow::CURRENT_VERTEX_ATTRIB, &mut current);
        assert_eq!(
            current, colour,
            "the game's constant colour was not given back"
        );
        assert_eq!(gl.get_error(), glow::NO_ERROR);
    }
    r.destroy();
}
