//! A renderer call that panics still gives the application its GL state back, and the calls
//! after it still save and restore it (a harness or engine that catches panics goes on).
#![allow(unsafe_code)] // the application's side: raw glow calls

use glow::HasContext;

use crate::gl::context::context_or_skip;
use crate::gl::EsVersion;
use crate::gl::HeadlessContext;
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

/// On llvmpipe, a call of a renderer on another thread waits until this thread's call has
/// ended (`gl::driver_turns`): two contexts at work at once crashed Mesa 22.3's llvmpipe.
#[test]
fn on_llvmpipe_calls_of_renderers_on_two_threads_take_turns() {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::{mpsc, Arc};
    let Some(ctx) = context_or_skip(EsVersion::Es3) else {
        return;
    };
    let mut second = Renderer::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    // ANGLE's contexts live on one thread at a time: a second thread's would wait for these.
    if !crate::gl::driver_turns::needed_by(&second.caps().renderer)
        || ctx.info().one_thread_at_a_time
    {
        let renderer = &second.caps().renderer;
        eprintln!("skipped: not llvmpipe, or ANGLE's one thread at a time ({renderer})");
        second.destroy();
        return;
    }
    let (entered, wait_entered) = mpsc::channel();
    let ended = Arc::new(AtomicBool::new(false));
    let first = {
        let ended = ended.clone();
        std::thread::spawn(move || {
            let ctx = HeadlessContext::new(EsVersion::Es3).unwrap();
            let mut first = Renderer::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
            first
                .hosted(|_| {
                    entered.send(()).unwrap();
                    // Time for the other thread's call to start wrongly meanwhile.
                    std::thread::sleep(std::time::Duration::from_millis(100));
                    ended.store(true, Ordering::SeqCst);
                    Ok(())
                })
                .unwrap();
            first.destroy();
        })
    };
    wait_entered.recv().unwrap();
    ctx.make_current().unwrap();
    let waited = second.hosted(|_| Ok(ended.load(Ordering::SeqCst))).unwrap();
    first.join().unwrap();
    second.destroy();
    assert!(
        waited,
        "a call started while another thread's was under way"
    );
}
