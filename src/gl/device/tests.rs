//! Tests of the device: its errors, a lost context, and the llvmpipe turn of its probe.

use super::*;

/// An incomplete target names itself and its size (a 16 384² MSAA target said only
/// `framebuffer incomplete: status 0x8cd6`).
#[test]
fn an_incomplete_framebuffer_names_the_target_and_the_status() {
    let e = GlError::FramebufferIncomplete {
        what: "a 16384×16384 target with 4 samples".into(),
        status: glow::FRAMEBUFFER_INCOMPLETE_ATTACHMENT,
    }
    .to_string();
    assert!(e.contains("16384×16384 target with 4 samples"), "{e}");
    assert!(e.contains("GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT"), "{e}");
    assert!(e.contains("0x8cd6"), "{e}");
    let unknown = framebuffer_status_name(0x1234);
    assert_eq!(unknown, "an unknown status");
    // glCheckFramebufferStatus returns 0 where it fails itself, which is no unknown status.
    let failed = GlError::FramebufferIncomplete {
        what: "a 64×36 Rgba8 target".into(),
        status: 0,
    }
    .to_string();
    assert!(failed.contains("the check itself failed"), "{failed}");
}

/// A lost context is an error of its own (a game makes a new context for it) and says
/// what to do; it read "unknown GL error (0x0507)".
#[test]
fn a_lost_context_is_named_apart_from_other_driver_errors() {
    let lost = driver_error(glow::CONTEXT_LOST, "a draw");
    assert!(matches!(&lost, GlError::ContextLost(what) if what == "a draw"));
    assert!(lost.to_string().contains("Renderer::abandon"), "{lost}");
    assert!(matches!(
        driver_error(glow::OUT_OF_MEMORY, "a draw"),
        GlError::OutOfMemory(_)
    ));
    let other = driver_error(glow::INVALID_ENUM, "a draw");
    assert!(other
        .to_string()
        .contains("GL_INVALID_ENUM (0x0500) after a draw"));
    assert_eq!(error_name(glow::CONTEXT_LOST), "GL_CONTEXT_LOST");
}

/// On llvmpipe, a new device's capability probe (GL objects made and deleted) waits while
/// another thread holds the turn (`driver_turns`), as a renderer's calls do: the holder
/// sees no device made while it holds the turn, however slow the probe.
#[test]
fn on_llvmpipe_the_probe_waits_for_the_turn() {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::{mpsc, Arc};
    let Some(ctx) = crate::gl::context::context_or_skip(EsVersion::Es3) else {
        return;
    };
    let renderer = Device::new(ctx.load_gl().unwrap(), EsVersion::Es3)
        .unwrap()
        .caps()
        .renderer
        .clone();
    if !super::super::driver_turns::needed_by(&renderer) {
        eprintln!("skipped: not llvmpipe ({renderer})");
        return;
    }
    let (held, wait_held) = mpsc::channel();
    let made = Arc::new(AtomicBool::new(false));
    let holder = {
        let made = made.clone();
        std::thread::spawn(move || {
            let turn = super::super::driver_turns::Turn::take_if(true);
            held.send(()).unwrap();
            // Time for the other thread's probe to finish wrongly meanwhile.
            std::thread::sleep(std::time::Duration::from_millis(500));
            let made_meanwhile = made.load(Ordering::SeqCst);
            drop(turn);
            made_meanwhile
        })
    };
    wait_held.recv().unwrap();
    Device::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    made.store(true, Ordering::SeqCst);
    let made_meanwhile = holder.join().unwrap();
    assert!(
        !made_meanwhile,
        "a device was made while another thread held the turn"
    );
}

/// A driver may say GL_CONTEXT_LOST once, and then nothing: once said, at a call's start
/// (where it was taken for the application's error) or by a check, every later check says
/// so too.
#[test]
fn a_lost_context_stays_lost() {
    let Some(ctx) = crate::gl::context::context_or_skip(EsVersion::Es3) else {
        return;
    };
    let dev = Device::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    dev.check("a healthy context").unwrap();
    dev.lost.set(true);
    for what in ["a draw", "an upload"] {
        let e = dev.check(what).unwrap_err();
        assert!(matches!(&e, GlError::ContextLost(w) if w == what), "{e}");
    }
    let e = dev.incomplete_framebuffer("a target".into(), 0);
    assert!(matches!(e, GlError::ContextLost(_)), "{e}");
}

/// A context lost before `Renderer::new` (Android: a GPU reset while the app rebuilt) says
/// `GL_CONTEXT_LOST` among its pending errors and then answers no query: the device is
/// `ContextLost`, what a game rebuilds its context for, not `NotCurrent`, which it took for the
/// application's error and then for no context at all. GL reports pending errors in any order:
/// behind an error the application left, the loss was drained unseen.
#[test]
fn a_device_made_on_a_lost_context_says_it_is_lost() {
    use std::ffi::{c_char, c_void, CStr};
    use std::sync::Mutex;
    static PENDING: Mutex<Vec<u32>> = Mutex::new(Vec::new());
    // A lost context's entry points: its pending errors said once each (the last first),
    // queries that write nothing.
    extern "system" fn get_error() -> u32 {
        let mut pending = PENDING.lock().unwrap_or_else(|e| e.into_inner());
        pending.pop().unwrap_or(glow::NO_ERROR)
    }
    extern "system" fn get_integerv(_name: u32, _out: *mut i32) {}
    extern "system" fn get_string(_name: u32) -> *const c_char {
        c"OpenGL ES 3.0 lost".as_ptr()
    }
    let lost_context = || unsafe {
        glow::Context::from_loader_function_cstr(|name: &CStr| match name.to_bytes() {
            b"glGetError" => get_error as *const c_void,
            b"glGetIntegerv" => get_integerv as *const c_void,
            b"glGetString" => get_string as *const c_void,
            _ => std::ptr::null(),
        })
    };
    for pending in [
        vec![glow::CONTEXT_LOST],
        vec![glow::CONTEXT_LOST, glow::INVALID_ENUM],
    ] {
        *PENDING.lock().unwrap() = pending.clone();
        let lost = Device::new(lost_context(), EsVersion::Es3)
            .err()
            .expect("no device");
        assert!(
            matches!(lost, GlError::ContextLost(_)),
            "{pending:?}: {lost:?}"
        );
    }
}
