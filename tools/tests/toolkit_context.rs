//! A renderer on a context the game made through the system's EGL itself (as glutin and
//! Android do), with manylight never loading an EGL of its own in this process: the renderer
//! still knows when its context is not current, so replacing it on a new context (Android's
//! pause and resume) never deletes the new context's objects, and a call with no context
//! current is `GlError::NotCurrent`.
#![allow(unsafe_code)] // the game's side: raw EGL and glow calls

mod common;

use common::game_target::sized_framebuffer;

use khronos_egl as egl;
use manylight::glow::{self, HasContext};
use manylight::{EsVersion, RenderOptions, Renderer};

/// `EGL_PLATFORM_SURFACELESS_MESA`: contexts without a window, on Mesa.
const PLATFORM_SURFACELESS_MESA: egl::Enum = 0x31DD;

/// The game's EGL: the system's `libEGL`, loaded by the game, not by manylight.
struct GameEgl {
    egl: egl::DynamicInstance<egl::EGL1_5>,
    display: egl::Display,
    config: egl::Config,
}

impl GameEgl {
    /// `None` (the test skips) where the system's EGL cannot make a surfaceless ES 3.0 context.
    fn new() -> Option<GameEgl> {
        let egl = unsafe {
            egl::DynamicInstance::<egl::EGL1_5>::load_required_from_filename("libEGL.so.1")
        }
        .ok()?;
        let display = unsafe {
            egl.get_platform_display(
                PLATFORM_SURFACELESS_MESA,
                egl::DEFAULT_DISPLAY,
                &[egl::ATTRIB_NONE],
            )
        }
        .ok()?;
        egl.initialize(display).ok()?;
        egl.bind_api(egl::OPENGL_ES_API).ok()?;
        let attributes = [
            egl::RENDERABLE_TYPE,
            egl::OPENGL_ES3_BIT,
            egl::SURFACE_TYPE,
            egl::PBUFFER_BIT,
            egl::NONE,
        ];
        let config = egl.choose_first_config(display, &attributes).ok()??;
        Some(GameEgl {
            egl,
            display,
            config,
        })
    }

    fn context(&self) -> egl::Context {
        let attributes = [egl::CONTEXT_CLIENT_VERSION, 3, egl::NONE];
        self.egl
            .create_context(self.display, self.config, None, &attributes)
            .expect("an ES 3.0 context")
    }

    fn make_current(&self, context: Option<egl::Context>) {
        self.egl
            .make_current(self.display, None, None, context)
            .expect("eglMakeCurrent");
    }

    fn glow(&self) -> glow::Context {
        unsafe {
            glow::Context::from_loader_function(|name| {
                self.egl
                    .get_proc_address(name)
                    .map_or(std::ptr::null(), |f| f as *const _)
            })
        }
    }
}

fn game_egl_or_skip() -> Option<GameEgl> {
    if common::other_implementation_than_mesa("a context made through the system's EGL") {
        return None;
    }
    let game = GameEgl::new();
    if game.is_none() {
        common::skip("the system's EGL makes no surfaceless ES 3.0 context");
    }
    game
}

#[test]
fn replacing_a_renderer_on_a_new_context_leaves_that_contexts_objects_alone() {
    let Some(game) = game_egl_or_skip() else {
        return;
    };
    common::warnings::install();
    let scene = manylight::scene::builtin::build("plane", Some((16, 1))).unwrap();
    let first = game.context();
    game.make_current(Some(first));
    let mut old = Renderer::new(game.glow(), EsVersion::Es3).unwrap();
    old.render_offscreen(&scene, 64, 36, &RenderOptions::default())
        .unwrap();
    // Android's pause: the context goes; resume: a new one, the game's objects first, then a
    // new renderer, built before the old one is dropped (`self.renderer = Some(new)`).
    game.make_current(None);
    game.egl.destroy_context(game.display, first).unwrap();
    let second = game.context();
    game.make_current(Some(second));
    let gl = game.glow();
    // The game's objects, its framebuffer left unbound.
    let target = unsafe { sized_framebuffer(&gl, glow::RGBA8, (16, 16)) };
    unsafe { gl.bind_framebuffer(glow::FRAMEBUFFER, None) };
    let mut new = Renderer::new(game.glow(), EsVersion::Es3).unwrap();
    let before = common::warnings::warnings_containing("not freed").len();
    drop(old);
    unsafe {
        assert!(
            gl.is_texture(target.colour()),
            "the game's texture was deleted"
        );
        assert!(
            gl.is_framebuffer(target.fbo()),
            "the game's framebuffer was deleted"
        );
    }
    assert_eq!(
        common::warnings::warnings_containing("not freed").len(),
        before + 1,
        "one warning that the old renderer's objects were left"
    );
    let (img, _) = new
        .render_offscreen(&scene, 64, 36, &RenderOptions::default())
        .unwrap();
    assert!(
        img.pixels().any(|p| p[0] > 0),
        "the new renderer drew nothing"
    );
    drop(new);
    game.make_current(None);
    game.egl.destroy_context(game.display, second).unwrap();
}

#[test]
fn calls_with_no_context_current_are_not_current_errors() {
    let Some(game) = game_egl_or_skip() else {
        return;
    };
    let context = game.context();
    game.make_current(Some(context));
    let gl_for_later = game.glow();
    let mut renderer = Renderer::new(game.glow(), EsVersion::Es3).unwrap();
    let scene = manylight::scene::builtin::build("plane", Some((16, 1))).unwrap();
    game.make_current(None);
    let not_current =
        |e: manylight::Error| matches!(e, manylight::Error::Gl(manylight::gl::GlError::NotCurrent));
    // A renderer made before the game makes its context current (the probe panicked).
    let made = Renderer::new(gl_for_later, EsVersion::Es3);
    assert!(
        made.is_err_and(not_current),
        "Renderer::new with no context current"
    );
    let switched = renderer.set_method_named("tiled");
    assert!(
        switched.is_err_and(not_current),
        "set_method with no context current"
    );
    let rendered = renderer.render_offscreen(&scene, 64, 36, &RenderOptions::default());
    assert!(
        rendered.is_err_and(not_current),
        "render_offscreen with no context current"
    );
    game.make_current(Some(context));
    renderer.set_method_named("tiled").unwrap();
    renderer
        .render_offscreen(&scene, 64, 36, &RenderOptions::default())
        .unwrap();
    drop(renderer);
    game.make_current(None);
    game.egl.destroy_context(game.display, context).unwrap();
}
