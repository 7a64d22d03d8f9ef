//! What `Renderer::render` needs of the framebuffer a game binds, and what a game's own GL
//! mistakes do to a call: a framebuffer that cannot take the frame is an error naming why (it
//! returned `Ok` with a wrong picture, or panicked in debug builds); a GL error the game left
//! pending is neither the renderer's error nor the end of its GPU timing; a renderer left
//! behind with its context says so once, not once for each of its objects.
#![allow(unsafe_code)] // the game's side: raw glow calls

use crate::common;

use common::warnings::warnings_containing;
use manylight::glow::{self, HasContext};
use manylight::scene;
use manylight::{Error, EsVersion, GlError, HeadlessContext, RenderOptions, Renderer};

const SIZE: (i32, i32) = (64, 36);

/// A game's RGBA8 framebuffer of [`SIZE`] with the depth renderbuffer `depth` (`None`:
/// none), bound.
unsafe fn game_fbo(gl: &glow::Context, depth: Option<u32>) -> glow::Framebuffer {
    game_fbo_of(gl, glow::RGBA8, depth)
}

/// [`game_fbo`] with a colour renderbuffer of `format`.
unsafe fn game_fbo_of(gl: &glow::Context, format: u32, depth: Option<u32>) -> glow::Framebuffer {
    let (w, h) = SIZE;
    let colour = gl.create_renderbuffer().unwrap();
    gl.bind_renderbuffer(glow::RENDERBUFFER, Some(colour));
    gl.renderbuffer_storage(glow::RENDERBUFFER, format, w, h);
    let fbo = gl.create_framebuffer().unwrap();
    gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
    gl.framebuffer_renderbuffer(
        glow::FRAMEBUFFER,
        glow::COLOR_ATTACHMENT0,
        glow::RENDERBUFFER,
        Some(colour),
    );
    if let Some(format) = depth {
        let rb = gl.create_renderbuffer().unwrap();
        gl.bind_renderbuffer(glow::RENDERBUFFER, Some(rb));
        gl.renderbuffer_storage(glow::RENDERBUFFER, format, w, h);
        gl.framebuffer_renderbuffer(
            glow::FRAMEBUFFER,
            glow::DEPTH_ATTACHMENT,
            glow::RENDERBUFFER,
            Some(rb),
        );
    }
    assert_eq!(
        gl.check_framebuffer_status(glow::FRAMEBUFFER),
        glow::FRAMEBUFFER_COMPLETE
    );
    fbo
}

/// A game's context (current), its GL functions and a renderer on it. Bound in this order,
/// they drop in the reverse one: the renderer while its context is still current.
fn game(es: EsVersion) -> (HeadlessContext, glow::Context, Renderer) {
    let ctx = HeadlessContext::new(es).unwrap();
    let gl = ctx.load_gl().unwrap();
    let renderer = Renderer::new(ctx.load_gl().unwrap(), es).unwrap();
    (ctx, gl, renderer)
}

fn plane() -> manylight::Scene {
    scene::builtin::build("plane", Some((8, 1))).unwrap()
}

fn render(
    r: &mut Renderer,
    options: &RenderOptions,
) -> Result<manylight::FrameStats, manylight::Error> {
    r.render(&plane(), SIZE.0 as u32, SIZE.1 as u32, options)
}

/// Without a depth buffer every method drew a wrong picture (17 003 of 36 864 pixels moved,
/// returning `Ok`); now it is refused, unless the renderer's own MSAA target brings the
/// depth. A 16-bit one draws, and is warned of once.
#[test]
fn a_framebuffer_without_depth_is_refused_and_a_shallow_one_warned_of() {
    common::warnings::install();
    for es in [EsVersion::Es3, EsVersion::Es2] {
        let (_ctx, gl, mut r) = game(es);
        unsafe { game_fbo(&gl, None) };
        let err = render(&mut r, &RenderOptions::default()).unwrap_err();
        assert!(
            matches!(err, manylight::Error::Gl(GlError::BoundFramebuffer(_))),
            "{es}: {err}"
        );
        assert!(err.to_string().contains("no depth buffer"), "{es}: {err}");
        if es == EsVersion::Es3 {
            let msaa = RenderOptions {
                samples: 4,
                ..Default::default()
            };
            render(&mut r, &msaa).expect("MSAA brings its own depth");
        }
        let before = warnings_containing("depth buffer has 16 bits").len();
        unsafe { game_fbo(&gl, Some(glow::DEPTH_COMPONENT16)) };
        render(&mut r, &RenderOptions::default()).unwrap();
        render(&mut r, &RenderOptions::default()).unwrap();
        assert_eq!(
            warnings_containing("depth buffer has 16 bits").len(),
            before + 1,
            "{es}: warned once"
        );
        if r.caps().depth24 {
            unsafe { game_fbo(&gl, Some(glow::DEPTH_COMPONENT24)) };
            render(&mut r, &RenderOptions::default()).unwrap();
        }
    }
}

/// A colour buffer of integers takes no frame's colours (GL leaves them undefined): drawn
/// into, an `RGBA8UI` one read back only 0s and 255s with `Ok`, and an MSAA frame's resolve
/// failed naming the resolve. It is refused, naming the format, either way.
#[test]
fn a_framebuffer_of_integer_colour_is_refused() {
    let (_ctx, gl, mut r) = game(EsVersion::Es3);
    for samples in [1, 4] {
        let options = RenderOptions {
            samples,
            ..Default::default()
        };
        for format in [glow::RGBA8UI, glow::RGBA16I] {
            unsafe { game_fbo_of(&gl, format, Some(glow::DEPTH_COMPONENT24)) };
            let err = render(&mut r, &options).unwrap_err();
            assert!(
                matches!(&err, Error::Gl(GlError::BoundFramebuffer(m)) if m.contains("integers")),
                "{format:#x} ×{samples}: {err}"
            );
        }
        // A normalized one still takes the frame.
        unsafe { game_fbo_of(&gl, glow::RGBA8, Some(glow::DEPTH_COMPONENT24)) };
        render(&mut r, &options).unwrap();
    }
}

/// HDR colour into a game's RGBA8 framebuffer is clamped there, which was silent: it is warned
/// of once a renderer, and neither an LDR frame there nor HDR into a float colour buffer
/// (where the context can draw one) is.
#[test]
fn hdr_into_a_fixed_point_framebuffer_is_warned_of_once() {
    common::warnings::install();
    const SAID: &str = "colour is fixed-point";
    let hdr = RenderOptions {
        hdr: true,
        ..Default::default()
    };
    for es in [EsVersion::Es3, EsVersion::Es2] {
        let (_ctx, gl, mut r) = game(es);
        let before = warnings_containing(SAID).len();
        unsafe { game_fbo(&gl, Some(glow::DEPTH_COMPONENT16)) };
        render(&mut r, &RenderOptions::default()).unwrap();
        assert_eq!(
            warnings_containing(SAID).len(),
            before,
            "{es}: LDR is not warned of"
        );
        render(&mut r, &hdr).unwrap();
        render(&mut r, &hdr).unwrap();
        assert_eq!(
            warnings_containing(SAID).len(),
            before + 1,
            "{es}: warned once"
        );
    }
    let (_ctx, gl, mut r) = game(EsVersion::Es3);
    if r.caps().hdr_output() {
        let before = warnings_containing(SAID).len();
        unsafe { game_fbo_of(&gl, glow::RGBA16F, Some(glow::DEPTH_COMPONENT16)) };
        render(&mut r, &hdr).unwrap();
        assert_eq!(
            warnings_containing(SAID).len(),
            before,
            "a float buffer keeps HDR"
        );
    }
}

/// An incomplete framebuffer (here one with no attachment) is refused by its status, where a
/// debug build panicked on the GL error of the geometry pass.
#[test]
fn an_incomplete_framebuffer_is_refused_naming_its_status() {
    let (_ctx, gl, mut r) = game(EsVersion::Es3);
    unsafe {
        let fbo = gl.create_framebuffer().unwrap();
        gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
    }
    let err = render(&mut r, &RenderOptions::default()).unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("incomplete")
            && text.contains("GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT"),
        "{text}"
    );
    // The same renderer draws once the game binds a framebuffer that can take the frame.
    unsafe { game_fbo(&gl, Some(glow::DEPTH_COMPONENT24)) };
    render(&mut r, &RenderOptions::default()).unwrap();
}

/// A framebuffer's completeness is asked when frames start going to it, not every frame (a
/// round trip on a threaded driver): one the game makes incomplete after a frame (its colour
/// storage respecified at 0×0) fails the next frame with GL's error, the frame after that names
/// its status, and once the game repairs it the same renderer draws again.
#[test]
fn a_framebuffer_made_incomplete_after_a_frame_fails_and_is_then_named() {
    let (_ctx, gl, mut r) = game(EsVersion::Es3);
    let colour = unsafe {
        game_fbo(&gl, Some(glow::DEPTH_COMPONENT24));
        let name = gl.get_framebuffer_attachment_parameter_i32(
            glow::FRAMEBUFFER,
            glow::COLOR_ATTACHMENT0,
            glow::FRAMEBUFFER_ATTACHMENT_OBJECT_NAME,
        );
        glow::NativeRenderbuffer(std::num::NonZeroU32::new(name as u32).unwrap())
    };
    let storage = |(w, h): (i32, i32)| unsafe {
        gl.bind_renderbuffer(glow::RENDERBUFFER, Some(colour));
        gl.renderbuffer_storage(glow::RENDERBUFFER, glow::RGBA8, w, h);
    };
    render(&mut r, &RenderOptions::default()).unwrap();
    storage((0, 0));
    let first = render(&mut r, &RenderOptions::default()).unwrap_err();
    assert!(
        first
            .to_string()
            .contains("GL_INVALID_FRAMEBUFFER_OPERATION"),
        "{first}"
    );
    let named = render(&mut r, &RenderOptions::default()).unwrap_err();
    let text = named.to_string();
    assert!(
        text.contains("incomplete") && text.contains("GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT"),
        "{text}"
    );
    storage(SIZE);
    render(&mut r, &RenderOptions::default()).unwrap();
}

/// A frame wider than `GL_MAX_VIEWPORT_DIMS` is refused naming the limit (GL clamped the
/// viewport and the call returned `Ok`), by `render` and `render_offscreen` alike (one gave a
/// limit's text and the other an unsupported capability): a game matches one error. (The
/// renderer's own targets' limits give the same error: `src/gl/target_size.rs`.) A frame of
/// `u32::MAX` pixels a side too (`render` named its origin, past GL's window coordinates).
#[test]
fn a_frame_past_the_viewport_limit_is_refused_alike_by_every_call() {
    let (_ctx, gl, mut r) = game(EsVersion::Es3);
    let [max_w, max_h] = r.caps().max_viewport_dims;
    assert!(max_w > 0, "GL_MAX_VIEWPORT_DIMS was not read");
    unsafe { game_fbo(&gl, Some(glow::DEPTH_COMPONENT24)) };
    let options = RenderOptions::default();
    for (w, h) in [(max_w as u32 + 1, 8), (u32::MAX, u32::MAX)] {
        let expected = (w, h, "GL_MAX_VIEWPORT_DIMS", max_w as u32, max_h as u32);
        let refusals = [
            r.render(&plane(), w, h, &options).unwrap_err(),
            r.render_offscreen(&plane(), w, h, &options).unwrap_err(),
        ];
        for err in refusals {
            match &err {
                Error::Gl(GlError::TooLarge {
                    width,
                    height,
                    limit,
                    max_width,
                    max_height,
                    ..
                }) => assert_eq!((*width, *height, *limit, *max_width, *max_height), expected),
                other => panic!("{other}"),
            }
            assert!(err.to_string().contains("GL_MAX_VIEWPORT_DIMS"), "{err}");
        }
    }
}

/// A frame reaching past the game's framebuffer (one not resized with the window) is drawn in
/// part, as GL draws it, and warned of once (it passed in silence); the game's texture and
/// renderbuffer bindings, which the size query changes, are as they were after the call.
/// Renderbuffer colour on every context; texture colour where the context can say a texture's
/// size (ES 3.1 and later: Mesa's 3.2, and ES 2.0 played on it).
#[test]
fn a_frame_past_the_games_framebuffer_is_warned_of_once() {
    common::warnings::install();
    let past = "reaches past the bound framebuffer's 64×36 colour buffer";
    for es in [EsVersion::Es3, EsVersion::Es2] {
        let (_ctx, gl, mut r) = game(es);
        // 16-bit depth: a true ES 2.0 context (ANGLE's) may lack 24.
        unsafe { game_fbo(&gl, Some(glow::DEPTH_COMPONENT16)) };
        let before = warnings_containing(past).len();
        render(&mut r, &RenderOptions::default()).unwrap();
        let moved = RenderOptions {
            origin: [8, 0],
            ..Default::default()
        };
        render(&mut r, &moved).unwrap();
        let said = warnings_containing(past);
        assert_eq!(said.len(), before + 1, "{es}: {said:?}");
        assert!(
            said[before].contains("64×36 frame at (8, 0)"),
            "{}",
            said[before]
        );
        r.render(&plane(), 128, 72, &RenderOptions::default())
            .unwrap();
        assert_eq!(warnings_containing(past).len(), before + 1, "{es}: once");
    }
    for es in [EsVersion::Es3, EsVersion::Es2] {
        let (_ctx, gl, mut r) = game(es);
        if r.caps().context_version.as_str() < "3.1" {
            continue; // no texture size to ask
        }
        let target = unsafe { common::game_target::sized_framebuffer(&gl, glow::RGBA8, SIZE) };
        let (texture, renderbuffer) = unsafe {
            let texture = gl.create_texture().unwrap();
            gl.bind_texture(glow::TEXTURE_2D, Some(texture));
            let renderbuffer = gl.create_renderbuffer().unwrap();
            gl.bind_renderbuffer(glow::RENDERBUFFER, Some(renderbuffer));
            (texture, renderbuffer)
        };
        let before = warnings_containing(past).len();
        render(&mut r, &RenderOptions::default()).unwrap();
        r.render(&plane(), 65, 36, &RenderOptions::default())
            .unwrap();
        assert_eq!(warnings_containing(past).len(), before + 1, "{es} texture");
        unsafe {
            let bound_texture = gl.get_parameter_texture(glow::TEXTURE_BINDING_2D);
            assert_eq!(bound_texture, Some(texture), "{es}: the game's texture");
            let bound = gl.get_parameter_i32(glow::RENDERBUFFER_BINDING) as u32;
            assert_eq!(bound, renderbuffer.0.get(), "{es}: the game's renderbuffer");
            gl.delete_texture(texture);
            gl.delete_renderbuffer(renderbuffer);
            common::game_target::free_game_framebuffer(&gl, target);
        }
    }
}

/// The same for a layer of a 3D or array texture (no warning: only 2D textures were asked),
/// where the context can say a texture's size; the game's bindings of those targets, which
/// the size query tries in turn, are as they were.
#[test]
fn a_frame_past_a_layer_of_the_games_texture_is_warned_of_once() {
    common::warnings::install();
    let past = "reaches past the bound framebuffer's 64×36 colour buffer";
    for target in [glow::TEXTURE_3D, glow::TEXTURE_2D_ARRAY] {
        let (_ctx, gl, mut r) = game(EsVersion::Es3);
        if r.caps().context_version.as_str() < "3.1" {
            return; // no texture size to ask (SwiftShader's and ANGLE's ES 3.0): nothing to warn
        }
        let (w, h) = SIZE;
        let (fbo, layered, others) = unsafe {
            let layered = gl.create_texture().unwrap();
            gl.bind_texture(target, Some(layered));
            gl.tex_storage_3d(target, 1, glow::RGBA8, w, h, 3);
            let fbo = game_fbo(&gl, Some(glow::DEPTH_COMPONENT24));
            let attachment = glow::COLOR_ATTACHMENT0;
            gl.framebuffer_texture_layer(glow::FRAMEBUFFER, attachment, Some(layered), 0, 2);
            let complete = gl.check_framebuffer_status(glow::FRAMEBUFFER);
            assert_eq!(complete, glow::FRAMEBUFFER_COMPLETE);
            // The game's own textures bound at the targets the query tries.
            let others = [glow::TEXTURE_2D, glow::TEXTURE_2D_ARRAY, glow::TEXTURE_3D].map(|t| {
                let texture = gl.create_texture().unwrap();
                gl.bind_texture(t, Some(texture));
                (t, texture)
            });
            (fbo, layered, others)
        };
        let before = warnings_containing(past).len();
        render(&mut r, &RenderOptions::default()).unwrap();
        assert_eq!(
            warnings_containing(past).len(),
            before,
            "0x{target:x}: fits"
        );
        r.render(&plane(), 65, 36, &RenderOptions::default())
            .unwrap();
        assert_eq!(warnings_containing(past).len(), before + 1, "0x{target:x}");
        unsafe {
            for (t, texture) in others {
                let binding = match t {
                    glow::TEXTURE_2D => glow::TEXTURE_BINDING_2D,
                    glow::TEXTURE_2D_ARRAY => glow::TEXTURE_BINDING_2D_ARRAY,
                    _ => glow::TEXTURE_BINDING_3D,
                };
                let bound = gl.get_parameter_texture(binding);
                assert_eq!(bound, Some(texture), "0x{target:x}: the game's 0x{t:x}");
                gl.delete_texture(texture);
            }
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            gl.delete_framebuffer(fbo);
            gl.delete_texture(layered);
        }
    }
}

/// A GL error the game left pending was the first check's error (`render_offscreen`: "after
/// allocating a target"), and turned GPU timing off for good; it is now cleared at the call,
/// with a warning.
#[test]
fn a_gl_error_the_game_left_pending_is_not_the_renderers() {
    common::warnings::install();
    let said = || warnings_containing("was pending when the renderer was called").len();
    let before = said();
    let (_ctx, gl, mut r) = game(EsVersion::Es3);
    let game_bug = || unsafe { gl.enable(0x1234) };
    game_bug();
    r.render_offscreen(&plane(), 32, 18, &RenderOptions::default())
        .expect("offscreen, with the game's error pending");
    unsafe { game_fbo(&gl, Some(glow::DEPTH_COMPONENT24)) };
    for _ in 0..2 {
        game_bug();
        let stats = render(&mut r, &RenderOptions::default()).expect("into the game's framebuffer");
        if r.caps().timer_query {
            assert!(stats.time.gpu_ms.is_some(), "GPU timing turned off");
        }
        assert_eq!(unsafe { gl.get_error() }, glow::NO_ERROR);
    }
    // Said once a renderer (later ones at debug level): this renderer said it.
    assert_eq!(said(), before + 1, "the cleared error is said once");
    assert!(warnings_containing("GPU timing off").is_empty());
}

/// A GL error the game left pending when it makes the renderer is cleared by the capability
/// probe (its queries may leave errors of their own): said, as at a call, not dropped silently.
#[test]
fn a_gl_error_pending_when_the_renderer_is_made_is_said() {
    common::warnings::install();
    let ctx = HeadlessContext::new(EsVersion::Es3).unwrap();
    let gl = ctx.load_gl().unwrap();
    unsafe { gl.enable(0x1235) };
    let _r = Renderer::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    assert!(
        !warnings_containing("GL_INVALID_ENUM (0x0500) was pending when the renderer was created")
            .is_empty(),
        "the cleared error is said"
    );
}

/// `abandon` (the context is lost) and a drop with no context current leave the renderer's
/// objects with one warning at most, where each object used to add its own "leaked".
#[test]
fn a_renderer_left_behind_says_so_once() {
    common::warnings::install();
    let ctx = HeadlessContext::new(EsVersion::Es3).unwrap();
    let mut r = Renderer::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    r.render_offscreen(&plane(), 32, 18, &RenderOptions::default())
        .unwrap();
    r.abandon();
    let mut r = Renderer::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    r.render_offscreen(&plane(), 32, 18, &RenderOptions::default())
        .unwrap();
    ctx.release_current().unwrap();
    drop(r);
    assert_eq!(
        warnings_containing("the renderer's GL objects are not freed").len(),
        1
    );
    let leaked = warnings_containing("dropped without destroy()");
    assert!(leaked.is_empty(), "{leaked:?}");
}
