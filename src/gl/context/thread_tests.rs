//! A headless context moved to another thread, as a test harness's pool of contexts does.

use super::HeadlessContext;
use crate::gl::EsVersion;
use crate::scene::builtin;
use crate::{RenderOptions, Renderer};

/// Renders the lit built-in plane with a new renderer on the current context.
fn render_plane(ctx: &HeadlessContext) -> image::RgbaImage {
    let mut renderer = Renderer::new(ctx.load_gl(), EsVersion::Es3).expect("renderer");
    let scene = builtin::build("plane", Some((16, 1))).unwrap();
    let (img, _) = renderer
        .render_offscreen(&scene, 32, 18, &RenderOptions::default())
        .expect("render");
    renderer.destroy();
    img
}

/// Released on its thread, the context draws the same picture on another where the
/// implementation lets it move; where it does not (ANGLE), making it current there is an
/// error, not a crash. Either way it is current again on its own thread afterwards.
#[test]
fn a_released_context_draws_on_another_thread_or_is_refused_there() {
    let Some(ctx) = super::context_or_skip(EsVersion::Es3) else {
        return;
    };
    let here = render_plane(&ctx);
    assert!(
        here.pixels().any(|p| p[0] > 16),
        "the plane's lights drew nothing"
    );
    ctx.release_current().unwrap();
    let (ctx, there) = std::thread::spawn(move || {
        let there = match ctx.make_current() {
            Ok(()) => {
                assert!(ctx.can_move_between_threads());
                let img = render_plane(&ctx);
                ctx.release_current().unwrap();
                Some(img)
            }
            Err(e) => {
                assert!(!ctx.can_move_between_threads(), "{e}");
                assert!(e.to_string().contains("another thread"), "{e}");
                None
            }
        };
        (ctx, there)
    })
    .join()
    .unwrap();
    if let Some(there) = there {
        assert!(here == there, "another picture on another thread");
    }
    ctx.make_current().unwrap();
    assert!(render_plane(&ctx) == here, "another picture back home");
}
