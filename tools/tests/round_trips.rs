//! The calls that return data from the driver (`glGet*`, `glIsEnabled`, `glGetError`,
//! `glCheckFramebufferStatus`…) a steady frame makes into a game's framebuffer. On a threaded
//! driver each one waits for the driver's thread to catch up, so a frame makes none it can do
//! without. Counted through a `glow::Context` whose loader hands the renderer counting
//! wrappers of those entry points (the GPU timer's `EXT` queries come through another loader
//! and are not counted here).
#![allow(unsafe_code)] // the wrappers forward raw GL calls

mod common;

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::ffi::c_void;
use std::sync::atomic::{AtomicPtr, Ordering};

use common::game_target::game_framebuffer;
use manylight::glow;
use manylight::scene;
use manylight::{EsVersion, GlStateHandling, HeadlessContext, RenderOptions, Renderer, Scene};

thread_local! {
    /// Calls on this thread by entry point, and `glGetIntegerv` by parameter too.
    static COUNTS: RefCell<BTreeMap<String, u64>> = RefCell::default();
}

fn count(name: &str) {
    COUNTS.with(|c| *c.borrow_mut().entry(name.to_string()).or_default() += 1);
}

/// Defines, for each entry point, a wrapper that counts its calls and forwards them to the
/// driver's, and `wrap`, which hands out the wrapper in place of the driver's function.
macro_rules! counted {
    ($($name:ident($($arg:ident: $ty:ty),*) $(-> $ret:ty)?;)*) => {
        $(
            #[allow(non_snake_case)]
            mod $name {
                use super::*;
                pub static REAL: AtomicPtr<c_void> = AtomicPtr::new(std::ptr::null_mut());
                pub extern "system" fn wrapper($($arg: $ty),*) $(-> $ret)? {
                    count(stringify!($name));
                    let real = REAL.load(Ordering::Relaxed);
                    // SAFETY: `wrap` stored the driver's function of this name, whose type
                    // the GL specification gives as this one.
                    let real: extern "system" fn($($ty),*) $(-> $ret)? =
                        unsafe { std::mem::transmute(real) };
                    real($($arg),*)
                }
            }
        )*

        /// The counting wrapper of `name` where it is counted and the driver has it.
        fn wrap(name: &str, real: *const c_void) -> *const c_void {
            if real.is_null() {
                return real;
            }
            match name {
                $(stringify!($name) => {
                    $name::REAL.store(real as *mut c_void, Ordering::Relaxed);
                    $name::wrapper as *const c_void
                })*
                _ => real,
            }
        }
    };
}

counted! {
    glGetError() -> u32;
    glGetFloatv(pname: u32, data: *mut f32);
    glGetBooleanv(pname: u32, data: *mut u8);
    glGetInteger64v(pname: u32, data: *mut i64);
    glGetIntegeri_v(pname: u32, index: u32, data: *mut i32);
    glIsEnabled(cap: u32) -> u8;
    glGetVertexAttribfv(index: u32, pname: u32, data: *mut f32);
    glGetVertexAttribiv(index: u32, pname: u32, data: *mut i32);
    glCheckFramebufferStatus(target: u32) -> u32;
    glGetTexLevelParameteriv(target: u32, level: i32, pname: u32, data: *mut i32);
    glGetTexParameteriv(target: u32, pname: u32, data: *mut i32);
    glGetRenderbufferParameteriv(target: u32, pname: u32, data: *mut i32);
    glGetBufferParameteriv(target: u32, pname: u32, data: *mut i32);
    glGetProgramiv(program: u32, pname: u32, data: *mut i32);
    glGetShaderiv(shader: u32, pname: u32, data: *mut i32);
    glGetUniformLocation(program: u32, name: *const i8) -> i32;
    glGetAttribLocation(program: u32, name: *const i8) -> i32;
    glGetQueryiv(target: u32, pname: u32, data: *mut i32);
    glGetQueryObjectuiv(query: u32, pname: u32, data: *mut u32);
    glReadPixels(x: i32, y: i32, w: i32, h: i32, format: u32, ty: u32, data: *mut c_void);
    glFinish();
    glClientWaitSync(sync: *const c_void, flags: u32, timeout: u64) -> u32;
}

/// `GL_GPU_DISJOINT_EXT` (`GL_EXT_disjoint_timer_query`), which glow does not name.
const GPU_DISJOINT_EXT: u32 = 0x8FBB;

/// The driver's `glGetIntegerv` and `glGetFramebufferAttachmentParameteriv`, counted by
/// parameter too: which state a frame asks for is the point.
static GET_INTEGER: AtomicPtr<c_void> = AtomicPtr::new(std::ptr::null_mut());
static GET_ATTACHMENT: AtomicPtr<c_void> = AtomicPtr::new(std::ptr::null_mut());

extern "system" fn get_integer(pname: u32, data: *mut i32) {
    count("glGetIntegerv");
    count(&format!("glGetIntegerv 0x{pname:04x}"));
    // SAFETY: the driver's glGetIntegerv, stored by `counting_gl`.
    let real: extern "system" fn(u32, *mut i32) =
        unsafe { std::mem::transmute(GET_INTEGER.load(Ordering::Relaxed)) };
    real(pname, data)
}

extern "system" fn get_attachment(target: u32, attachment: u32, pname: u32, data: *mut i32) {
    count("glGetFramebufferAttachmentParameteriv");
    count(&format!(
        "glGetFramebufferAttachmentParameteriv 0x{pname:04x}"
    ));
    // SAFETY: the driver's glGetFramebufferAttachmentParameteriv, stored by `counting_gl`.
    let real: extern "system" fn(u32, u32, u32, *mut i32) =
        unsafe { std::mem::transmute(GET_ATTACHMENT.load(Ordering::Relaxed)) };
    real(target, attachment, pname, data)
}

/// A `glow::Context` for the current context whose round trips are counted.
fn counting_gl() -> glow::Context {
    let lib = manylight::gl::gles_lib::library().unwrap();
    unsafe {
        glow::Context::from_loader_function(|name| {
            let real = lib.proc_address(name);
            let by_parameter = match name {
                "glGetIntegerv" => Some((&GET_INTEGER, get_integer as *const c_void)),
                "glGetFramebufferAttachmentParameteriv" => {
                    Some((&GET_ATTACHMENT, get_attachment as *const c_void))
                }
                _ => None,
            };
            match by_parameter {
                Some((slot, wrapper)) if !real.is_null() => {
                    slot.store(real as *mut c_void, Ordering::Relaxed);
                    wrapper
                }
                _ => wrap(name, real),
            }
        })
    }
}

/// Calls per frame over `frames` frames of `draw`, after three (the culled methods' ring of
/// texture sets is then allocated).
fn per_frame(frames: u32, mut draw: impl FnMut(u32)) -> BTreeMap<String, f64> {
    for k in 0..3 {
        draw(k);
    }
    COUNTS.with(|c| c.borrow_mut().clear());
    for k in 3..3 + frames {
        draw(k);
    }
    COUNTS.with(|c| {
        (c.borrow().iter())
            .map(|(name, n)| (name.clone(), *n as f64 / f64::from(frames)))
            .collect()
    })
}

/// The calls of `names` a frame makes, summed.
fn of(counts: &BTreeMap<String, f64>, names: &[&str]) -> f64 {
    names.iter().filter_map(|n| counts.get(*n)).sum()
}

/// `glGetIntegerv` of `pname` a frame makes.
fn integer(counts: &BTreeMap<String, f64>, pname: u32) -> f64 {
    of(counts, &[&format!("glGetIntegerv 0x{pname:04x}")])
}

/// `glGetFramebufferAttachmentParameteriv` of `pname` a frame makes.
fn attachment(counts: &BTreeMap<String, f64>, pname: u32) -> f64 {
    of(
        counts,
        &[&format!(
            "glGetFramebufferAttachmentParameteriv 0x{pname:04x}"
        )],
    )
}

/// A game's context at `es` with its `size` framebuffer bound, a renderer whose calls are
/// counted, and the courtyard with 64 lights; `None` (said) where there is no such context.
fn game_loop(es: EsVersion, (w, h): (u32, u32)) -> Option<(HeadlessContext, Renderer, Scene)> {
    let Some(ctx) = HeadlessContext::new(es).ok() else {
        common::skip("no headless context");
        return None;
    };
    let game = ctx.load_gl().unwrap();
    let renderer = Renderer::new(counting_gl(), es).unwrap();
    let depth24 = es == EsVersion::Es3 || renderer.caps().depth24;
    unsafe { game_framebuffer(&game, depth24, (w as i32, h as i32)) };
    let scene = scene::builtin::build("courtyard", Some((64, 7))).unwrap();
    Some((ctx, renderer, scene))
}

/// A frame of moving lights into a game's framebuffer (the README's game loop: no wait for
/// the GPU) asks the driver each piece of state once: the framebuffer bound (by the state
/// save), a constant never, what is attached once an attachment, no framebuffer status while
/// the target is the last frame's. `glGetError`: once as a call starts (the game's pending
/// errors are not the renderer's), once for the target's queries, once before the GPU timer's
/// query begins (the frame's uploads), once after it (the timer's begin), once before it ends
/// (the draws), once for the timer's results, and a debug build's check after the geometry
/// pass; none per light data upload, so the culled methods' three make no more than forward's
/// one. It was 17 to 18 a frame, the framebuffer binding read 7 times. With the renderer's
/// own MSAA, two more: the frame's errors before the resolve's blit, and the blit's (it was 7
/// more).
#[test]
fn a_frame_into_a_games_framebuffer_asks_the_driver_each_thing_once() {
    let (w, h) = (64, 36);
    for es in [EsVersion::Es3, EsVersion::Es2] {
        // Mesa hands out an ES 3.2 context for 2.0 too, unless its version is capped.
        let Some((_ctx, mut renderer, mut s)) = game_loop(es, (w, h)) else {
            continue;
        };
        let methods: &[(&str, u32)] = match es {
            EsVersion::Es3 => &[
                ("forward", 1),
                ("tiled", 1),
                ("clustered", 1),
                ("deferred", 1),
                ("clustered", 4),
            ],
            EsVersion::Es2 => &[("forward", 1), ("tiled", 1), ("clustered", 1)],
        };
        for &(method, samples) in methods {
            if samples > renderer.caps().max_samples.max(1) as u32 {
                continue;
            }
            let options = RenderOptions {
                wait_for_gpu: false,
                samples,
                ..RenderOptions::default()
            };
            renderer.set_method_named(method).unwrap();
            let counts = per_frame(10, |k| {
                s.lights[0].position.x += 1e-3 * f64::from(k);
                renderer.render(&s, w, h, &options).unwrap();
            });
            let what = format!("{es} {method} ×{samples}: {counts:#?}");
            let bindings = [glow::FRAMEBUFFER_BINDING, glow::READ_FRAMEBUFFER_BINDING]
                .map(|p| integer(&counts, p))
                .iter()
                .sum::<f64>();
            // The state save reads the draw and the read framebuffer (one on ES 2.0).
            assert!(bindings <= 2.0, "framebuffer bindings: {what}");
            assert_eq!(integer(&counts, glow::MAX_DRAW_BUFFERS), 0.0, "{what}");
            assert_eq!(of(&counts, &["glCheckFramebufferStatus"]), 0.0, "{what}");
            let errors = of(&counts, &["glGetError"]);
            let debug_checks = f64::from(u8::from(cfg!(debug_assertions)));
            let resolve = if samples > 1 { 2.0 } else { 0.0 };
            let most = 6.0 + debug_checks + resolve;
            assert!(errors <= most, "glGetError: {what}");
            // The colour and the depth attachment's: what is attached, once each.
            let kinds = attachment(&counts, glow::FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE);
            assert!(kinds <= 2.0, "attachments asked: {what}");
        }
        // An offscreen render draws into the renderer's own target: nothing to ask of it.
        let options = RenderOptions::default();
        let counts = per_frame(5, |k| {
            s.lights[0].position.x += 1e-3 * f64::from(k);
            renderer.render_offscreen(&s, w, h, &options).unwrap();
        });
        let asked = of(&counts, &["glGetFramebufferAttachmentParameteriv"]);
        assert_eq!(asked, 0.0, "{es} offscreen: {counts:#?}");
    }
}

/// With `GlStateHandling::Reset` a frame reads nothing of the game's state but the framebuffer
/// it bound: no capability, no value, no attribute; of the integers, that binding, what the
/// target needs known (its samples; its depth bits on ES 2.0) and the GPU timer's disjoint flag,
/// once each; what is attached; `glGetError` as often as with the state saved. With the state
/// saved, a frame asks 70 or so things more.
#[test]
fn a_frame_with_the_state_reset_reads_only_the_games_framebuffer() {
    let (w, h) = (64, 36);
    for es in [EsVersion::Es3, EsVersion::Es2] {
        let Some((_ctx, mut renderer, mut s)) = game_loop(es, (w, h)) else {
            continue;
        };
        let methods: &[&str] = match es {
            EsVersion::Es3 => &["forward", "clustered", "deferred"],
            EsVersion::Es2 => &["forward", "clustered"],
        };
        let options = RenderOptions {
            wait_for_gpu: false,
            ..RenderOptions::default()
        };
        for method in methods {
            renderer.set_method_named(method).unwrap();
            let mut frames = |handling| {
                renderer.set_gl_state_handling(handling);
                per_frame(10, |k| {
                    s.lights[0].position.x += 1e-3 * f64::from(k);
                    renderer.render(&s, w, h, &options).unwrap();
                })
            };
            let saved = frames(GlStateHandling::SaveAndRestore);
            let counts = frames(GlStateHandling::Reset);
            let what = format!("{es} {method}: {counts:#?}");
            // Nothing but errors, integers, what is attached and the size of the renderer's
            // own witness buffer (which context is current): no capability, value, attribute,
            // program, texture or renderbuffer query.
            let kinds = [
                "glGetError",
                "glGetIntegerv",
                "glGetFramebufferAttachmentParameteriv",
                "glGetBufferParameteriv",
            ];
            let other = |name: &String| !kinds.iter().any(|k| name.starts_with(k));
            let others: Vec<_> = counts.keys().filter(|name| other(name)).collect();
            assert!(others.is_empty(), "{others:?}: {what}");
            // The colour and the depth attachment's type; the colour's encoding and component
            // type (ES 3.0).
            let attached = of(&counts, &["glGetFramebufferAttachmentParameteriv"]);
            assert!(attached <= 4.0, "attachments: {what}");
            let witness = of(&counts, &["glGetBufferParameteriv"]);
            assert!(witness <= 1.0, "buffers: {what}");
            let target = [
                glow::FRAMEBUFFER_BINDING,
                glow::SAMPLES,
                glow::DEPTH_BITS,
                GPU_DISJOINT_EXT,
            ];
            for pname in target {
                assert!(integer(&counts, pname) <= 1.0, "0x{pname:04x}: {what}");
            }
            let others = of(&counts, &["glGetIntegerv"])
                - target.map(|p| integer(&counts, p)).iter().sum::<f64>();
            assert_eq!(others, 0.0, "integers: {what}");
            let errors = |c| of(c, &["glGetError"]);
            assert!(errors(&counts) <= errors(&saved), "glGetError: {what}");
            // The figure docs/performance.md gives.
            let all = |c: &BTreeMap<String, f64>| {
                (c.iter())
                    .filter(|(name, _)| !name.contains(" 0x"))
                    .map(|(_, n)| n)
                    .sum::<f64>()
            };
            eprintln!(
                "{es} {method}: {} → {} calls a frame",
                all(&saved),
                all(&counts)
            );
        }
    }
}
