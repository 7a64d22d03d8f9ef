//! The GPU timer as a frame uses it: results read at once or frames later, a query left
//! running by a panicked frame, an application's own query around a frame.
#![allow(unsafe_code)] // the application's own query: the extension's entry points

use glow::HasContext;

use crate::gl::context::context_or_skip;
use crate::gl::EsVersion;
use crate::{HeadlessContext, Renderer};

/// An ES 3.0 context and a renderer on it, where the context has timer queries (the
/// renderer, bound second, is dropped first).
fn timed_renderer() -> Option<(HeadlessContext, Renderer)> {
    let ctx = context_or_skip(EsVersion::Es3)?;
    let renderer = Renderer::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    if !renderer.caps().timer_query {
        eprintln!("skipped: no GL_EXT_disjoint_timer_query here");
        return None;
    }
    Some((ctx, renderer))
}

/// A frame that panicked between the GPU timer's begin and end left its query running, and
/// the next timed frame's begin was refused: GPU timing off for good.
#[test]
fn a_frame_that_panicked_mid_query_leaves_gpu_timing_on() {
    let Some((ctx, mut renderer)) = timed_renderer() else {
        return;
    };
    let scene = crate::scene::builtin::build("plane", Some((4, 1))).unwrap();
    let options = crate::RenderOptions::default();
    let (_, stats) = renderer.render_offscreen(&scene, 16, 9, &options).unwrap();
    assert!(stats.time.gpu_ms.is_some(), "no GPU time to begin with");
    let caught = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let _ = renderer.hosted(|r| -> Result<(), crate::Error> {
            if let Some(Some(timer)) = &r.timer {
                timer.begin(&r.dev, 0, true);
            }
            panic!("a bug between the query's begin and end");
        });
    }));
    assert!(caught.is_err());
    // The panicked frame's query was ended: the application's own begins.
    let gl = ctx.load_gl().unwrap();
    let fns = crate::gl::ext_fns::timer_query_fns().unwrap();
    unsafe {
        let mut query = 0;
        (fns.gen_queries)(1, &mut query);
        (fns.begin_query)(0x88BF, query);
        assert_eq!(
            gl.get_error(),
            glow::NO_ERROR,
            "the application's query refused"
        );
        (fns.end_query)(0x88BF);
        (fns.delete_queries)(1, &query);
    }
    let (_, stats) = renderer.render_offscreen(&scene, 16, 9, &options).unwrap();
    assert!(stats.time.gpu_ms.is_some(), "GPU timing turned off");
    renderer.destroy();
}

/// A frame that does not wait for the GPU still gets GPU time: an earlier frame's, read once
/// it finished, without stalling (a game's frames).
#[test]
fn frames_that_do_not_wait_report_the_gpu_time_of_a_finished_frame() {
    let Some((_ctx, mut renderer)) = timed_renderer() else {
        return;
    };
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
    let Some((ctx, mut renderer)) = timed_renderer() else {
        return;
    };
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

/// A frame that waits for the GPU, after frames that did not while the GPU lagged, finds every
/// query in flight: it waits for the oldest one's result and is timed, not left without.
#[test]
fn a_waiting_frame_is_timed_when_every_query_is_in_flight() {
    let Some((_ctx, renderer)) = timed_renderer() else {
        return;
    };
    let dev = &renderer.dev;
    let timer = crate::gl::timer::GpuTimer::new(dev).expect("timer queries");
    for serial in 0..crate::gl::timer::RING as u64 {
        timer.begin(dev, serial, false);
        assert_eq!(timer.end(dev, false), None);
    }
    // Not waiting: no query is free, so the frame goes untimed.
    timer.begin(dev, 10, false);
    assert_eq!(
        timer.end(dev, true),
        None,
        "a frame without a free query was timed"
    );
    timer.begin(dev, 11, true);
    let ms = timer.end(dev, true);
    assert!(ms.is_some_and(|ms| ms.is_finite() && ms >= 0.0), "{ms:?}");
    timer.destroy(dev);
}

/// A game timing its own work around many frames sees at most one GL error of the renderer's
/// making in its debug callback: the first frame's begin finds its query (the frame goes
/// untimed), and from then on each frame asks first. It saw one every frame (helper-150), and
/// once its query ends the frames are timed again.
#[test]
fn frames_inside_the_applications_query_raise_one_error_at_most() {
    let Some((ctx, mut renderer)) = timed_renderer() else {
        return;
    };
    let gl = ctx.load_gl().unwrap();
    if !renderer.caps().has_extension("GL_KHR_debug") {
        eprintln!("skipped: no GL_KHR_debug here");
        return;
    }
    let errors = std::sync::Arc::new(std::sync::atomic::AtomicUsize::new(0));
    let seen = errors.clone();
    let mut gl = gl;
    unsafe {
        gl.enable(glow::DEBUG_OUTPUT);
        gl.enable(glow::DEBUG_OUTPUT_SYNCHRONOUS);
        gl.debug_message_callback(move |_, kind, _, _, _| {
            if kind == glow::DEBUG_TYPE_ERROR {
                seen.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
            }
        });
    }
    let scene = crate::scene::builtin::build("plane", Some((4, 1))).unwrap();
    let options = crate::RenderOptions {
        wait_for_gpu: false,
        ..Default::default()
    };
    let fns = crate::gl::ext_fns::timer_query_fns().unwrap();
    let mut query = 0;
    unsafe {
        (fns.gen_queries)(1, &mut query);
        (fns.begin_query)(0x88BF, query);
        for _ in 0..5 {
            renderer.render_offscreen(&scene, 16, 9, &options).unwrap();
        }
        (fns.end_query)(0x88BF);
        (fns.delete_queries)(1, &query);
    }
    let inside = errors.load(std::sync::atomic::Ordering::SeqCst);
    assert!(inside <= 1, "{inside} GL errors in 5 frames");
    let timed = (0..8).any(|_| {
        let (_, stats) = renderer.render_offscreen(&scene, 16, 9, &options).unwrap();
        stats.time.gpu_ms.is_some()
    });
    assert!(timed, "GPU timing did not come back");
    assert_eq!(errors.load(std::sync::atomic::Ordering::SeqCst), inside);
    unsafe { gl.disable(glow::DEBUG_OUTPUT) };
    renderer.destroy();
}
