//! A renderer call that panics still gives the application its GL state back, and the calls
//! after it still save and restore it (a harness or engine that catches panics goes on).
#![allow(unsafe_code)] // the application's side: raw glow calls

use glow::HasContext;

use crate::gl::context::context_or_skip;
use crate::gl::EsVersion;
use crate::Renderer;

fn viewport(gl: &glow::Context) -> [i32; 4] {
    let mut v = [0; 4];
    unsafe { gl.get_parameter_i32_slice(glow::VIEWPORT, &mut v) };
    v
}

#[test]
fn a_panicking_call_gives_the_state_back_and_the_next_calls_still_do() {
    let Some(ctx) = context_or_skip(EsVersion::Es3) else {
        return;
    };
    let game = ctx.load_gl().unwrap();
    let mut renderer = Renderer::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    unsafe { game.viewport(1, 2, 3, 4) };
    let caught = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let _ = renderer.hosted(|r| -> Result<(), crate::Error> {
            unsafe { r.dev.gl.viewport(0, 0, 9, 9) };
            panic!("a bug inside a renderer call");
        });
    }));
    assert!(caught.is_err());
    assert_eq!(
        viewport(&game),
        [1, 2, 3, 4],
        "the panicking call's state stayed"
    );
    for _ in 0..2 {
        renderer
            .hosted(|r| {
                unsafe { r.dev.gl.viewport(0, 0, 7, 7) };
                Ok(())
            })
            .unwrap();
        assert_eq!(
            viewport(&game),
            [1, 2, 3, 4],
            "a call after the panic no longer gave the state back"
        );
    }
    let caught = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        renderer.dev.host_call(|| {
            unsafe { renderer.dev.gl.viewport(0, 0, 5, 5) };
            panic!("a bug inside a device call");
        })
    }));
    assert!(caught.is_err());
    assert_eq!(viewport(&game), [1, 2, 3, 4]);
    renderer.hosted(|_| Ok(())).unwrap();
    renderer.destroy();
}
