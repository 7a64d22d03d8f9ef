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

/// A frame that panicked between the GPU timer's begin and end left its query running, and
/// the next timed frame's begin was refused: GPU timing off for good.
#[test]
fn a_frame_that_panicked_mid_query_leaves_gpu_timing_on() {
    let Some(ctx) = context_or_skip(EsVersion::Es3) else {
        return;
    };
    let mut renderer = Renderer::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    if !renderer.caps().timer_query {
        eprintln!("skipped: no GL_EXT_disjoint_timer_query here");
        return;
    }
    let scene = crate::scene::builtin::build("plane", Some((4, 1))).unwrap();
    let options = crate::RenderOptions::default();
    let (_, stats) = renderer.render_offscreen(&scene, 16, 9, &options).unwrap();
    assert!(stats.time.gpu_ms.is_some(), "no GPU time to begin with");
    let caught = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let _ = renderer.hosted(|r| -> Result<(), crate::Error> {
            if let Some(Some(timer)) = &r.timer {
                timer.begin(&r.dev, 0);
            }
            panic!("a bug between the query's begin and end");
        });
    }));
    assert!(caught.is_err());
    let (_, stats) = renderer.render_offscreen(&scene, 16, 9, &options).unwrap();
    assert!(stats.time.gpu_ms.is_some(), "GPU timing turned off");
    renderer.destroy();
}

/// A frame that does not wait for the GPU still gets GPU time: an earlier frame's, read once
/// it finished, without stalling (a game's frames).
#[test]
fn frames_that_do_not_wait_report_the_gpu_time_of_a_finished_frame() {
    let Some(ctx) = context_or_skip(EsVersion::Es3) else {
        return;
    };
    let mut renderer = Renderer::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    if !renderer.caps().timer_query {
        eprintln!("skipped: no GL_EXT_disjoint_timer_query here");
        return;
    }
    let scene = crate::scene::builtin::build("plane", Some((64, 1))).unwrap();
    let options = crate::RenderOptions {
        wait_for_gpu: false,
        ..Default::default()
    };
    let timed: Vec<Option<f64>> = (0..12)
        .map(|_| {
            let (_, stats) = renderer.render_offscreen(&scene, 64, 36, &options).unwrap();
            stats.time.gpu_ms
        })
        .collect();
    let read = timed.iter().flatten().count();
    assert!(read >= 6, "GPU times read: {timed:?}");
    assert!(
        timed.iter().flatten().all(|ms| ms.is_finite() && *ms > 0.0),
        "{timed:?}"
    );
    renderer.destroy();
}

/// An application timing its own work around a frame has an elapsed-time query running: the
/// frame goes untimed (beginning a second one would fail and turn timing off for good), and
/// the next frame is timed again. With `gpu_timer: false` no query is made at all.
#[test]
fn a_frame_inside_the_applications_own_query_goes_untimed() {
    let Some(ctx) = context_or_skip(EsVersion::Es3) else {
        return;
    };
    let mut renderer = Renderer::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    if !renderer.caps().timer_query {
        eprintln!("skipped: no GL_EXT_disjoint_timer_query here");
        return;
    }
    let scene = crate::scene::builtin::build("plane", Some((4, 1))).unwrap();
    let options = crate::RenderOptions::default();
    let fns = crate::gl::ext_fns::timer_query_fns().unwrap();
    let mut query = 0;
    let (_, inside) = unsafe {
        (fns.gen_queries)(1, &mut query);
        (fns.begin_query)(0x88BF, query);
        let inside = renderer.render_offscreen(&scene, 16, 9, &options).unwrap();
        (fns.end_query)(0x88BF);
        (fns.delete_queries)(1, &query);
        inside
    };
    assert_eq!(inside.time.gpu_ms, None);
    let (_, after) = renderer.render_offscreen(&scene, 16, 9, &options).unwrap();
    assert!(after.time.gpu_ms.is_some(), "GPU timing turned off");

    let mut untimed = Renderer::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    let off = crate::RenderOptions {
        gpu_timer: false,
        ..Default::default()
    };
    let (_, stats) = untimed.render_offscreen(&scene, 16, 9, &off).unwrap();
    assert_eq!(stats.time.gpu_ms, None);
    assert!(untimed.timer.is_none(), "no query made");
    untimed.destroy();
    renderer.destroy();
}
