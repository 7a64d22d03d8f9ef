//! Headless GL contexts through EGL.
//!
//! libEGL is loaded at run time (the system's `libEGL.so.1`, or another implementation's:
//! [`super::gles_lib`]), so the binary starts — and can say clearly what is missing — on
//! machines without it. Display choice: the `EGL_MESA_platform_surfaceless`
//! platform when there is no window system (no `DISPLAY` / `WAYLAND_DISPLAY`) and the client
//! supports it, else the default display; if the first choice fails, the other is tried.
//! The context is made current without a surface where EGL ≥ 1.5 or
//! `EGL_KHR_surfaceless_context` allows, else with a 1×1 pbuffer. Rendering always goes to
//! the renderer's own framebuffer objects.
#![allow(unsafe_code)]

use std::sync::{Condvar, Mutex, MutexGuard};
use std::time::Duration;

use khronos_egl as egl;

use super::gles_lib::{self, Egl, GlesLibrary};
use super::{EsVersion, GlError};

#[cfg(test)]
mod thread_tests;

/// A headless context for a unit test, or `None` where the machine has no EGL (the test then
/// skips); with `MANYLIGHT_REQUIRE_ALL_TESTS` set, no context fails the test instead.
#[cfg(test)]
pub(crate) fn context_or_skip(es: EsVersion) -> Option<HeadlessContext> {
    match HeadlessContext::new(es) {
        Ok(ctx) => Some(ctx),
        Err(e) => {
            assert!(
                std::env::var_os("MANYLIGHT_REQUIRE_ALL_TESTS").is_none(),
                "no headless context: {e}"
            );
            eprintln!("skipped: no headless {es} context ({e})");
            None
        }
    }
}

/// `EGL_PLATFORM_SURFACELESS_MESA`.
const PLATFORM_SURFACELESS_MESA: egl::Enum = 0x31DD;

/// An EGL display + context, current on the creating thread until
/// [`HeadlessContext::release_current`]. Keep it alive as long as anything uses the GL context
/// it made (the [`crate::Renderer`] built from [`HeadlessContext::load_gl`]).
pub struct HeadlessContext {
    lib: &'static GlesLibrary,
    display: egl::Display,
    context: egl::Context,
    surface: Option<egl::Surface>,
    info: EglInfo,
    /// The thread that made it, the only one it may be current on where it cannot move
    /// ([`HeadlessContext::can_move_between_threads`]).
    made_on: std::thread::ThreadId,
}

// SAFETY: the EGL handles are process-wide and EGL may be called from any thread; a context
// is current on at most one thread, which EGL itself enforces (EGL_BAD_ACCESS), and dropping
// it where it is not current only releases the dropping thread's own context.
unsafe impl Send for HeadlessContext {}

/// How the context was made, for `manylight info`.
#[derive(Clone, Debug, serde::Serialize)]
pub struct EglInfo {
    /// `surfaceless` or `default`.
    pub platform: String,
    /// EGL version of the display.
    pub egl_version: String,
    /// `EGL_VENDOR`.
    pub egl_vendor: String,
    /// True when no surface is bound (surfaceless context).
    pub surfaceless_context: bool,
    /// ES version requested from EGL.
    pub requested: EsVersion,
    /// The folder the implementation was loaded from (`--gles-lib`, `MANYLIGHT_GLES_LIB`);
    /// `None`: the system's `libEGL.so.1`.
    pub gles_lib: Option<std::path::PathBuf>,
    /// A driver workaround: once its last headless context is gone, the display is terminated
    /// before a context is made on another thread (and initialised again by it). ANGLE's GL
    /// back end keeps a native context current on the thread that initialised the display, and
    /// a context made on another thread after that one ended crashed it in `eglMakeCurrent` (a
    /// test harness runs each test on a new thread). Not at each last drop: ANGLE keeps an X
    /// connection from every `eglInitialize`. Only for ANGLE: elsewhere the display may be
    /// shared with an application's own contexts.
    pub terminate_when_unused: bool,
    /// A driver workaround: the implementation's headless contexts live on one thread at a
    /// time, so [`HeadlessContext::new`] on another thread waits until they are gone. ANGLE,
    /// for the reason above: a context made on a second thread while the first one's were
    /// alive crashed it in `eglMakeCurrent`. There a context is dropped on the thread that
    /// made it (where it is current): dropped elsewhere, it counts as gone while it may still
    /// be current on its own thread.
    pub one_thread_at_a_time: bool,
}

fn egl_err(call: &'static str) -> impl Fn(egl::Error) -> GlError {
    move |e| GlError::Egl {
        call,
        error: egl_error_text(e),
    }
}

/// EGL's error by its name and what it means (khronos-egl's text, whose parenthesis it leaves
/// open for two of them, closed).
fn egl_error_text(e: egl::Error) -> String {
    use egl::Error::*;
    let name = match e {
        NotInitialized => "EGL_NOT_INITIALIZED",
        BadAccess => "EGL_BAD_ACCESS",
        BadAlloc => "EGL_BAD_ALLOC",
        BadAttribute => "EGL_BAD_ATTRIBUTE",
        BadContext => "EGL_BAD_CONTEXT",
        BadConfig => "EGL_BAD_CONFIG",
        BadCurrentSurface => "EGL_BAD_CURRENT_SURFACE",
        BadDisplay => "EGL_BAD_DISPLAY",
        BadSurface => "EGL_BAD_SURFACE",
        BadMatch => "EGL_BAD_MATCH",
        BadParameter => "EGL_BAD_PARAMETER",
        BadNativePixmap => "EGL_BAD_NATIVE_PIXMAP",
        BadNativeWindow => "EGL_BAD_NATIVE_WINDOW",
        ContextLost => "EGL_CONTEXT_LOST",
    };
    let mut text = e.to_string().trim_end_matches('.').to_string();
    if text.matches('(').count() > text.matches(')').count() {
        text.push(')');
    }
    format!("{name}: {text}")
}

/// Said when an EGL without a surfaceless platform fails and no display server runs.
const NO_DISPLAY_HINT: &str = "this EGL has no surfaceless platform and needs a display \
     server, and none is set (DISPLAY and WAYLAND_DISPLAY are unset): run under one, for \
     example `xvfb-run -a`";

impl HeadlessContext {
    /// Creates a context for `es` and makes it current on this thread.
    ///
    /// Where the implementation runs its contexts on one thread at a time (ANGLE's GL back end,
    /// [`EglInfo::one_thread_at_a_time`]), a thread asking while another thread's contexts are
    /// alive waits until they are all dropped, as a test harness running tests in parallel
    /// needs: ANGLE crashed the process there. It waits as long as the other thread drops a
    /// context now and then, and fails with [`GlError::ContextsOnAnotherThread`] after a minute
    /// in which none went (a thread holding a context while it waits for this one would
    /// otherwise hang both).
    pub fn new(es: EsVersion) -> Result<Self, GlError> {
        Self::new_waiting_at_most(es, ONE_THREAD_PATIENCE)
    }

    /// [`HeadlessContext::new`] with its patience given (the tests shorten it).
    fn new_waiting_at_most(es: EsVersion, patience: Duration) -> Result<Self, GlError> {
        let lib = gles_lib::library()?;
        let egl = lib.egl();
        let client_ext = egl
            .query_string(None, egl::EXTENSIONS)
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let window_system =
            std::env::var_os("DISPLAY").is_some() || std::env::var_os("WAYLAND_DISPLAY").is_some();
        let surfaceless_ok = client_ext.contains("EGL_MESA_platform_surfaceless");
        let order: &[&str] = if surfaceless_ok && !window_system {
            &["surfaceless", "default"]
        } else if surfaceless_ok {
            &["default", "surfaceless"]
        } else {
            &["default"]
        };
        // Held while the display is initialised and the context made, so a drop on another
        // thread cannot terminate the display in between (see `LIVE_CONTEXTS`).
        let mut live = wait_for_other_threads(lock_live(), patience)?;
        // ANGLE's display, left initialised by another thread's contexts, all gone
        // (`LiveContexts::initialised_by`): terminated before this thread initialises it.
        let here = std::thread::current().id();
        if live.count == 0 && live.initialised_by.is_some_and(|by| by != here) {
            if let Some(display) = unsafe { egl.get_display(egl::DEFAULT_DISPLAY) } {
                let _ = egl.terminate(display);
            }
            live.initialised_by = None;
        }
        let mut last_err = None;
        for platform in order {
            match Self::with_platform(egl, platform, es) {
                Ok((display, context, surface, info)) => {
                    live.count += 1;
                    if info.one_thread_at_a_time {
                        live.only_thread = Some(std::thread::current().id());
                    }
                    return Ok(HeadlessContext {
                        lib,
                        display,
                        context,
                        surface,
                        info,
                        made_on: std::thread::current().id(),
                    });
                }
                Err(e @ GlError::VersionUnavailable { .. }) => return Err(e),
                Err(e) => {
                    log::info!("EGL {platform} display failed: {e}");
                    last_err = Some(e);
                }
            }
        }
        let err = last_err.expect("at least one platform tried");
        Err(match err {
            // An EGL that needs a window system (ANGLE's on Linux) where none runs.
            GlError::Egl { call, error } if !surfaceless_ok && !window_system => GlError::Egl {
                call,
                error: format!("{error}; {NO_DISPLAY_HINT}"),
            },
            other => other,
        })
    }

    fn open_display(egl: &Egl, platform: &str) -> Result<egl::Display, GlError> {
        if platform == "surfaceless" {
            let egl15 = egl.upcast::<egl::EGL1_5>().ok_or_else(|| GlError::Egl {
                call: "eglGetPlatformDisplay",
                error: "EGL 1.5 is not available".into(),
            })?;
            unsafe {
                egl15.get_platform_display(
                    PLATFORM_SURFACELESS_MESA,
                    egl::DEFAULT_DISPLAY,
                    &[egl::ATTRIB_NONE],
                )
            }
            .map_err(egl_err("eglGetPlatformDisplay"))
        } else {
            unsafe { egl.get_display(egl::DEFAULT_DISPLAY) }.ok_or(GlError::Egl {
                call: "eglGetDisplay",
                error: "no default display".into(),
            })
        }
    }

    #[allow(clippy::type_complexity)]
    fn with_platform(
        egl: &Egl,
        platform: &str,
        es: EsVersion,
    ) -> Result<(egl::Display, egl::Context, Option<egl::Surface>, EglInfo), GlError> {
        let display = Self::open_display(egl, platform)?;
        let (major, minor) = egl.initialize(display).map_err(egl_err("eglInitialize"))?;
        egl.bind_api(egl::OPENGL_ES_API)
            .map_err(egl_err("eglBindAPI"))?;
        let renderable = match es {
            EsVersion::Es2 => egl::OPENGL_ES2_BIT,
            EsVersion::Es3 => egl::OPENGL_ES3_BIT,
        };
        let with_pbuffer = [
            egl::RENDERABLE_TYPE,
            renderable,
            egl::SURFACE_TYPE,
            egl::PBUFFER_BIT,
            egl::NONE,
        ];
        let any_surface = [egl::RENDERABLE_TYPE, renderable, egl::NONE];
        let config = match egl
            .choose_first_config(display, &with_pbuffer)
            .map_err(egl_err("eglChooseConfig"))?
        {
            Some(c) => Some(c),
            None => egl
                .choose_first_config(display, &any_surface)
                .map_err(egl_err("eglChooseConfig"))?,
        };
        let config = config.ok_or_else(|| GlError::VersionUnavailable {
            requested: es,
            reason: format!("no EGL config can render OpenGL {es} on the {platform} display"),
        })?;
        let context = egl
            .create_context(
                display,
                config,
                None,
                &[
                    egl::CONTEXT_CLIENT_VERSION,
                    es.major() as egl::Int,
                    egl::NONE,
                ],
            )
            .map_err(|e| GlError::VersionUnavailable {
                requested: es,
                reason: format!(
                    "eglCreateContext: {}{}",
                    egl_error_text(e),
                    super::caps::mesa_switches_note()
                ),
            })?;
        let display_ext = egl
            .query_string(Some(display), egl::EXTENSIONS)
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let surfaceless =
            (major, minor) >= (1, 5) || display_ext.contains("EGL_KHR_surfaceless_context");
        let surface = if surfaceless {
            None
        } else {
            Some(
                egl.create_pbuffer_surface(
                    display,
                    config,
                    &[egl::WIDTH, 1, egl::HEIGHT, 1, egl::NONE],
                )
                .map_err(|e| {
                    let _ = egl.destroy_context(display, context);
                    egl_err("eglCreatePbufferSurface")(e)
                })?,
            )
        };
        if let Err(e) = egl.make_current(display, surface, surface, Some(context)) {
            if let Some(s) = surface {
                let _ = egl.destroy_surface(display, s);
            }
            let _ = egl.destroy_context(display, context);
            return Err(egl_err("eglMakeCurrent")(e));
        }
        let egl_version_string = egl
            .query_string(Some(display), egl::VERSION)
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let egl_vendor = egl
            .query_string(Some(display), egl::VENDOR)
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let info = EglInfo {
            platform: platform.to_string(),
            egl_version: format!("{major}.{minor}"),
            egl_vendor,
            surfaceless_context: surface.is_none(),
            requested: es,
            gles_lib: gles_lib::chosen_folder(),
            terminate_when_unused: egl_version_string.contains("ANGLE"),
            one_thread_at_a_time: egl_version_string.contains("ANGLE"),
        };
        Ok((display, context, surface, info))
    }

    /// A glow context for this context, which must be current on the calling thread (as
    /// [`HeadlessContext::new`] leaves it); cheap: it loads function pointers. Elsewhere
    /// [`GlError::ContextNotCurrent`].
    pub fn load_gl(&self) -> Result<glow::Context, GlError> {
        if self.lib.egl().get_current_context() != Some(self.context) {
            return Err(GlError::ContextNotCurrent);
        }
        Ok(unsafe { glow::Context::from_loader_function(|name| self.lib.proc_address(name)) })
    }

    /// Whether the context may be made current on a thread other than the one that made it.
    /// Not on ANGLE: its GL back end keeps a native context current on the thread that
    /// initialised the display, and crashed in `eglMakeCurrent` when a context was made
    /// current on another (docs/drivers.md).
    pub fn can_move_between_threads(&self) -> bool {
        !self.info.terminate_when_unused
    }

    /// Makes the context current on the calling thread, as [`HeadlessContext::new`] did on
    /// the creating one: how a context moves to another thread (a test harness's pool, say),
    /// after [`HeadlessContext::release_current`] on the thread that used it last. An error
    /// on another thread than the creating one where the context cannot move
    /// ([`HeadlessContext::can_move_between_threads`]).
    pub fn make_current(&self) -> Result<(), GlError> {
        if !self.can_move_between_threads() && std::thread::current().id() != self.made_on {
            return Err(GlError::Unsupported(format!(
                "this {} context cannot be made current on another thread than the one that \
                 made it",
                self.info.egl_vendor
            )));
        }
        let _lock = lock_live();
        self.lib
            .egl()
            .make_current(self.display, self.surface, self.surface, Some(self.context))
            .map_err(|e| GlError::Egl {
                call: "eglMakeCurrent",
                error: if matches!(e, egl::Error::BadAccess) {
                    format!(
                        "{}: it is current on another thread, which must release_current it \
                         first (a thread that ended without doing so keeps it)",
                        egl_error_text(e)
                    )
                } else {
                    egl_error_text(e)
                },
            })
    }

    /// Makes no context current on the calling thread, so that another thread may make this
    /// one current. Nothing may draw with it here until [`HeadlessContext::make_current`].
    pub fn release_current(&self) -> Result<(), GlError> {
        let _lock = lock_live();
        self.lib
            .egl()
            .make_current(self.display, None, None, None)
            .map_err(egl_err("eglMakeCurrent"))
    }

    /// How the context was made.
    pub fn info(&self) -> &EglInfo {
        &self.info
    }
}

impl Drop for HeadlessContext {
    fn drop(&mut self) {
        // The display is shared by every context of the process (EGL returns the same handle),
        // so it is terminated only on ANGLE, only once no headless context is left, and only
        // when another thread makes the next (`EglInfo::terminate_when_unused`).
        let egl = self.lib.egl();
        // Under the lock `new` holds too: SwiftShader's display keeps its surfaces and contexts
        // in sets it does not lock, and tore them when two threads created or destroyed at once.
        let mut live = lock_live();
        // Released only where it is current: another context current on this thread (a test
        // holding an ES 2.0 and an ES 3.0 context) stays current.
        if egl.get_current_context() == Some(self.context) {
            let _ = egl.make_current(self.display, None, None, None);
        }
        if let Some(s) = self.surface {
            let _ = egl.destroy_surface(self.display, s);
        }
        let _ = egl.destroy_context(self.display, self.context);
        live.count -= 1;
        if live.count == 0 {
            live.only_thread = None;
            if self.info.terminate_when_unused {
                // Terminated by the next context made on another thread (`new`).
                live.initialised_by = Some(self.made_on);
            }
        }
        CONTEXT_DROPPED.notify_all();
    }
}

/// How long [`HeadlessContext::new`] waits for another thread's contexts where contexts live on
/// one thread at a time ([`EglInfo::one_thread_at_a_time`]) without any of them being dropped.
const ONE_THREAD_PATIENCE: Duration = Duration::from_secs(60);

/// The headless contexts alive in the process.
struct LiveContexts {
    count: usize,
    /// The thread they live on, where the implementation allows one at a time
    /// ([`EglInfo::one_thread_at_a_time`]).
    only_thread: Option<std::thread::ThreadId>,
    /// Where the display is terminated only when a context is made on another thread
    /// ([`EglInfo::terminate_when_unused`]): the thread whose contexts left it initialised.
    /// ANGLE opens a connection to the X server at each `eglInitialize` and keeps it after
    /// `eglTerminate`, so terminating at every last drop made the 255th context of a thread
    /// fail (Xvfb's 256 clients).
    initialised_by: Option<std::thread::ThreadId>,
}

/// Headless contexts alive in the process, for the ANGLE workarounds of
/// [`EglInfo::terminate_when_unused`] and [`EglInfo::one_thread_at_a_time`]; its lock also
/// serialises making, moving and destroying contexts (SwiftShader's EGL display is not
/// thread-safe there).
static LIVE_CONTEXTS: Mutex<LiveContexts> = Mutex::new(LiveContexts {
    count: 0,
    only_thread: None,
    initialised_by: None,
});

/// Signalled whenever a headless context is dropped.
static CONTEXT_DROPPED: Condvar = Condvar::new();

fn lock_live() -> MutexGuard<'static, LiveContexts> {
    LIVE_CONTEXTS.lock().unwrap_or_else(|e| e.into_inner())
}

/// Waits, where contexts live on one thread at a time, until no other thread's are alive; an
/// error once `patience` passes without one of them being dropped.
fn wait_for_other_threads(
    mut live: MutexGuard<'static, LiveContexts>,
    patience: Duration,
) -> Result<MutexGuard<'static, LiveContexts>, GlError> {
    let here = std::thread::current().id();
    let mut said = false;
    while live.only_thread.is_some_and(|owner| owner != here) {
        if !said {
            log::info!(
                "waiting for another thread's {} headless contexts: this implementation runs \
                 contexts on one thread at a time",
                live.count
            );
            said = true;
        }
        let (guard, wait) = CONTEXT_DROPPED
            .wait_timeout(live, patience)
            .unwrap_or_else(|e| e.into_inner());
        live = guard;
        if wait.timed_out() && live.only_thread.is_some_and(|owner| owner != here) {
            return Err(GlError::ContextsOnAnotherThread {
                contexts: live.count,
                waited_s: patience.as_secs_f64(),
            });
        }
    }
    Ok(live)
}

/// The other thread's contexts, in [`GlError::ContextsOnAnotherThread`]'s message.
pub(crate) fn contexts_phrase(contexts: usize) -> String {
    match contexts {
        1 => "its context".into(),
        n => format!("its {n} contexts"),
    }
}
