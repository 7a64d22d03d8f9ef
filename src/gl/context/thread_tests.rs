//! A headless context moved to another thread, as a test harness's pool of contexts does.

use super::HeadlessContext;
use crate::gl::EsVersion;
use crate::scene::builtin;
use crate::{RenderOptions, Renderer};

/// Renders the lit built-in plane with a new renderer on the current context.
fn render_plane(ctx: &HeadlessContext) -> image::RgbaImage {
    let mut renderer = Renderer::new(ctx.load_gl().expect("gl"), EsVersion::Es3).expect("renderer");
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

/// Two contexts on one thread (an ES 2.0 and an ES 3.0 one in a test): dropping the one that is
/// not current leaves the other current, and a glow context is refused for the one that is not
/// current instead of panicking inside glow.
#[test]
fn dropping_a_context_not_current_leaves_the_current_one() {
    let Some(first) = super::context_or_skip(EsVersion::Es3) else {
        return;
    };
    let second = HeadlessContext::new(EsVersion::Es3).expect("a second context");
    assert!(matches!(
        first.load_gl(),
        Err(crate::gl::GlError::ContextNotCurrent)
    ));
    first.make_current().unwrap();
    drop(second);
    let img = render_plane(&first);
    assert!(
        img.pixels().any(|p| p[0] > 16),
        "the plane's lights drew nothing"
    );
}

/// A context left current by a thread that ended cannot be made current elsewhere on Mesa: the
/// error says why and what to do. (SwiftShader releases it when the thread ends, as EGL allows.)
#[test]
fn a_context_kept_by_an_ended_thread_says_so() {
    let Some(ctx) = super::context_or_skip(EsVersion::Es3) else {
        return;
    };
    if !ctx.can_move_between_threads() {
        return;
    }
    ctx.release_current().unwrap();
    let ctx = std::thread::spawn(move || {
        ctx.make_current().unwrap();
        ctx
    })
    .join()
    .unwrap();
    if let Err(e) = ctx.make_current() {
        let err = e.to_string();
        assert!(err.contains("release_current"), "{err}");
        assert!(err.contains("EGL_BAD_ACCESS"), "{err}");
    }
}

/// Threads that each make a context at once (a test harness running tests in parallel) draw the
/// same picture. Where contexts live on one thread at a time (ANGLE, which crashed making the
/// second thread's context, however the draws were ordered), the threads take turns: no two
/// threads' contexts were alive at once. The draws themselves take turns here, since
/// SwiftShader now and then corrupts a frame drawn while another thread draws (drivers.md).
#[test]
fn threads_making_contexts_at_once_draw_the_same_picture() {
    const THREADS: usize = 4;
    let start = std::sync::Barrier::new(THREADS);
    let one_draw_at_a_time = std::sync::Mutex::new(());
    let lives = std::thread::scope(|s| {
        let threads: Vec<_> = (0..THREADS)
            .map(|_| {
                s.spawn(|| {
                    start.wait();
                    let ctx = super::context_or_skip(EsVersion::Es3)?;
                    let made = std::time::Instant::now();
                    let img = {
                        let _turn = one_draw_at_a_time.lock().unwrap();
                        render_plane(&ctx)
                    };
                    let turns = ctx.info().one_thread_at_a_time;
                    let ended = std::time::Instant::now();
                    drop(ctx);
                    Some((made, ended, turns, img))
                })
            })
            .collect();
        let lives: Vec<_> = threads.into_iter().map(|t| t.join().unwrap()).collect();
        lives.into_iter().collect::<Option<Vec<_>>>()
    });
    let Some(lives) = lives else {
        return;
    };
    for (_, _, _, img) in &lives[1..] {
        assert!(*img == lives[0].3, "another picture on another thread");
    }
    if lives[0].2 {
        for (i, a) in lives.iter().enumerate() {
            for b in &lives[i + 1..] {
                assert!(
                    a.1 <= b.0 || b.1 <= a.0,
                    "two threads' contexts alive at once"
                );
            }
        }
    }
}

/// Where contexts live on one thread at a time, a thread asking while another's context is
/// alive gets it once that one is dropped, and an error, not a wait without end, when none is
/// dropped in its patience. Elsewhere both threads have theirs at once.
#[test]
fn a_thread_waits_for_another_threads_context_within_its_patience() {
    let Some(ctx) = super::context_or_skip(EsVersion::Es3) else {
        return;
    };
    let patience = std::time::Duration::from_millis(200);
    let refused = std::thread::spawn(move || {
        HeadlessContext::new_waiting_at_most(EsVersion::Es3, patience).map(drop)
    })
    .join()
    .unwrap();
    if !ctx.info().one_thread_at_a_time {
        refused.expect("a context on a second thread at once");
        return;
    }
    let err = refused.expect_err("made while another thread's context lived");
    assert!(
        matches!(
            err,
            crate::gl::GlError::ContextsOnAnotherThread { contexts: 1, .. }
        ),
        "{err:?}"
    );
    assert!(err.to_string().contains("one thread at a time"), "{err}");
    let patient = std::thread::spawn(move || {
        let ctx = HeadlessContext::new_waiting_at_most(EsVersion::Es3, 30 * patience)?;
        Ok::<_, crate::gl::GlError>(render_plane(&ctx))
    });
    std::thread::sleep(patience);
    let here = render_plane(&ctx);
    drop(ctx);
    let there = patient
        .join()
        .unwrap()
        .expect("made once the other was dropped");
    assert!(here == there, "another picture on another thread");
}

/// The wait's error reads as a sentence for one context or several (it said "kept its 1").
#[test]
fn the_wait_error_counts_the_other_threads_contexts_in_words() {
    let error = |contexts| {
        crate::gl::GlError::ContextsOnAnotherThread {
            contexts,
            waited_s: 60.25,
        }
        .to_string()
    };
    assert!(
        error(1).contains("kept its context for 60.2 s"),
        "{}",
        error(1)
    );
    assert!(
        error(3).contains("kept its 3 contexts for 60.2 s"),
        "{}",
        error(3)
    );
}
