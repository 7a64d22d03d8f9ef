//! The winit application: EGL setup, suspend/resume, touch input and the frame loop.

use std::cmp::Reverse;
use std::ffi::CStr;
use std::num::NonZeroU32;
use std::time::Instant;

use android_activity::AndroidApp;
use glutin::config::{Api, Config, ConfigTemplateBuilder, GlConfig};
use glutin::context::{ContextApi, ContextAttributesBuilder, Version};
use glutin::context::{NotCurrentContext, NotCurrentGlContext};
use glutin::context::{PossiblyCurrentContext, PossiblyCurrentGlContext};
use glutin::display::{Display, DisplayApiPreference, GlDisplay};
use glutin::error::ErrorKind;
use glutin::surface::{GlSurface, Surface, SurfaceAttributesBuilder, SwapInterval, WindowSurface};
use manylight::{builtin_scene, Method, RandomLights, Scene, DEFAULT_SCENE};
use manylight::{Error, GlError, GlStateHandling};
use manylight::{EsVersion, FrameStats, RenderOptions, Renderer};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalPosition;
use winit::event::{ElementState, Touch, TouchPhase, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::platform::android::EventLoopBuilderExtAndroid;
use winit::raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use winit::window::{Window, WindowId};

use crate::orbit::Orbit;
use crate::retry::{Losses, Retry};

/// Seeded random lights in the default scene.
const LIGHTS: usize = 1024;
/// The lights kept where the device runs only forward (an ES 2.0 GPU without fragment `highp`),
/// which evaluates every light at every pixel.
const FORWARD_LIGHTS: usize = 64;
/// Seconds between frame-statistics lines in logcat.
const LOG_EVERY_S: f64 = 2.0;

/// Sets up logging and the thread pool, and runs the event loop until the activity is
/// destroyed (`android_main` then ends the process).
pub fn run(activity: AndroidApp) {
    android_logger::init_once(
        android_logger::Config::default()
            .with_max_level(log::LevelFilter::Info)
            .with_tag("manylight"),
    );
    // A panic's message goes to standard error, which Android drops: logcat gets it.
    std::panic::set_hook(Box::new(|panic| log::error!("{panic}")));
    // This thread lives as long as the process: as one of rayon's pool, a frame's light
    // assignment starts on it at once instead of waiting for a sleeping worker to wake.
    if let Err(e) = rayon::ThreadPoolBuilder::new()
        .use_current_thread()
        .build_global()
    {
        log::warn!("the render thread is not one of the assignment's pool: {e}");
    }
    let lights = RandomLights {
        count: LIGHTS,
        seed: 1,
    };
    let scene = match builtin_scene(DEFAULT_SCENE, Some(lights)) {
        Ok(s) => s,
        Err(e) => return log::error!("cannot build the default scene: {e}"),
    };
    let event_loop = match EventLoop::builder().with_android_app(activity).build() {
        Ok(l) => l,
        Err(e) => return log::error!("cannot create the event loop: {e}"),
    };
    let center = scene.bounds().map_or(scene.camera.target, |b| b.center());
    let mut shell = Shell {
        orbit: Orbit::around(center, &scene.camera),
        scene,
        egl: None,
        parked: None,
        live: None,
        renderer: None,
        touch: None,
        frames: 0,
        since: Instant::now(),
        stats: FrameStats::default(),
        retry: Retry::default(),
        losses: Losses::default(),
        resumed: false,
    };
    if let Err(e) = event_loop.run_app(&mut shell) {
        log::error!("event loop failed: {e}");
    }
}

/// The EGL display and the config and version chosen on it (kept for the process).
struct Egl {
    display: Display,
    config: Config,
    es: EsVersion,
}

/// What exists only while the activity is resumed. Fields drop in order: surface first.
struct Live {
    surface: Surface<WindowSurface>,
    context: PossiblyCurrentContext,
    window: Window,
}

struct Shell {
    scene: Scene,
    orbit: Orbit,
    egl: Option<Egl>,
    /// The context while suspended (not current, no surface).
    parked: Option<NotCurrentContext>,
    live: Option<Live>,
    /// Lives as long as its context (across suspend/resume).
    renderer: Option<Renderer>,
    /// The finger that orbits and where it was last.
    touch: Option<(u64, PhysicalPosition<f64>)>,
    frames: u32,
    since: Instant,
    /// The last frame's figures, filled in place: `render_reusing` allocates nothing per frame.
    stats: FrameStats,
    /// A frame or resume that failed, to be tried again.
    retry: Retry,
    /// Contexts lost while shown, so that one lost every frame is not rebuilt every frame.
    losses: Losses,
    /// Between `resumed` and `suspended`.
    resumed: bool,
}

/// Why a frame was not presented.
enum FrameError {
    /// The context was lost (`EGL_CONTEXT_LOST`, `GL_CONTEXT_LOST`): it and the renderer are
    /// made anew.
    ContextLost(String),
    /// Anything else: tried again a little later.
    Other(String),
}

impl ApplicationHandler for Shell {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        self.resumed = true;
        self.try_show(event_loop);
    }

    fn suspended(&mut self, _: &ActiveEventLoop) {
        self.resumed = false;
        // A finger down when the activity paused may never be reported lifted.
        self.touch = None;
        // The native window goes away: drop the surface (and window), keep the context.
        if let Some(Live {
            surface,
            context,
            window,
        }) = self.live.take()
        {
            match context.make_not_current() {
                Ok(c) => self.parked = Some(c),
                Err(e) => log::warn!("cannot release the context ({e}); it will be rebuilt"),
            }
            drop(surface);
            drop(window);
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                if let (Some(live), Some(w), Some(h)) = (
                    &self.live,
                    NonZeroU32::new(size.width),
                    NonZeroU32::new(size.height),
                ) {
                    live.surface.resize(&live.context, w, h);
                    live.window.request_redraw();
                }
            }
            WindowEvent::Touch(touch) => self.touch(touch),
            // Back, which winit marks handled so Android never sees it, leaves the app.
            WindowEvent::KeyboardInput { event, .. }
                if event.state == ElementState::Pressed
                    && event.logical_key == Key::Named(NamedKey::BrowserBack) =>
            {
                event_loop.exit()
            }
            WindowEvent::RedrawRequested => match self.frame() {
                Ok(drew) => {
                    if self.retry.redrawn(drew) {
                        log::info!("rendering again");
                    }
                }
                Err(FrameError::ContextLost(e)) => {
                    let now = Instant::now();
                    let loss = self.losses.lost(now);
                    if loss.log {
                        log::warn!(
                            "{e}: the context was lost ({} in a row); rebuilding it and the \
                             renderer{}",
                            loss.in_run,
                            if loss.rebuild_now {
                                ""
                            } else {
                                " a second from now"
                            }
                        );
                    }
                    self.lose_context();
                    if loss.rebuild_now {
                        self.try_show(event_loop);
                    } else {
                        self.retry.failed(&e, now);
                    }
                }
                Err(FrameError::Other(e)) => self.failed(&e),
            },
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        // Due while suspended, the try is the next resume's.
        if self.retry.due(Instant::now()) && self.resumed {
            match &self.live {
                Some(live) => live.window.request_redraw(),
                None => self.try_show(event_loop),
            }
        }
        // Asleep until an event, or the next try: never a wake-up time already past.
        let flow = self
            .retry
            .next()
            .map_or(ControlFlow::Wait, ControlFlow::WaitUntil);
        event_loop.set_control_flow(flow);
    }

    fn exiting(&mut self, _: &ActiveEventLoop) {
        // GL objects can only be freed with the context current, i.e. while shown. Android
        // suspends before it exits, so usually the context is parked: the renderer then goes
        // without a GL call (the context and its objects go with the process), before the
        // parked context is dropped.
        if let Some(r) = self.renderer.take() {
            if self.live.is_some() {
                r.destroy();
            } else {
                r.abandon();
            }
        }
    }
}

impl Shell {
    /// [`Shell::show`], tried again a second later while it fails.
    fn try_show(&mut self, event_loop: &ActiveEventLoop) {
        match self.show(event_loop) {
            Ok(()) => {
                if self.retry.succeeded() {
                    log::info!("shown again");
                }
            }
            Err(e) => self.failed(&e),
        }
    }

    /// Logs a failure (once while it repeats); `about_to_wait` wakes the loop for the next try.
    fn failed(&mut self, error: &str) {
        if self.retry.failed(error, Instant::now()) {
            log::error!("{error}; trying again every second");
        }
    }

    /// Lets the lost context go with everything made in it: the renderer without a GL call,
    /// then the surface, the context and the window, so that [`Shell::show`] makes them anew.
    fn lose_context(&mut self) {
        if let Some(r) = self.renderer.take() {
            r.abandon();
        }
        self.parked = None;
        if let Some(live) = self.live.take() {
            release(live.context, live.surface);
        }
    }

    /// Makes the display and context on first use, a surface for the new native window, and
    /// the renderer when there is none.
    fn show(&mut self, event_loop: &ActiveEventLoop) -> Result<(), String> {
        if self.live.is_some() {
            return Ok(());
        }
        if self.egl.is_none() {
            let (egl, context) = open_egl(event_loop)?;
            self.egl = Some(egl);
            self.parked = Some(context);
        }
        let egl = self.egl.as_ref().ok_or("no EGL display")?;
        let window = event_loop
            .create_window(Window::default_attributes())
            .map_err(|e| format!("cannot create the window: {e}"))?;
        let size = window.inner_size();
        let handle = window
            .window_handle()
            .map_err(|e| format!("no native window: {e}"))?
            .as_raw();
        let attributes = SurfaceAttributesBuilder::<WindowSurface>::new().build(
            handle,
            NonZeroU32::new(size.width).unwrap_or(NonZeroU32::MIN),
            NonZeroU32::new(size.height).unwrap_or(NonZeroU32::MIN),
        );
        // SAFETY: the native window outlives the surface (`Live` drops the surface first and
        // `suspended` drops both before Android destroys the window).
        let surface = unsafe { egl.display.create_window_surface(&egl.config, &attributes) }
            .map_err(|e| format!("cannot create the window surface: {e}"))?;
        // The kept context, or a new one (first start, or the old one could not be released);
        // taken once the surface exists, so a failed window or surface keeps it for the retry.
        let (parked, kept) = match self.parked.take() {
            Some(c) => (c, true),
            None => {
                // Its objects went with the old context: let it go without a GL call.
                if let Some(old) = self.renderer.take() {
                    old.abandon();
                }
                (create_context(egl)?, false)
            }
        };
        let context = match parked.make_current(&surface) {
            Ok(c) => c,
            Err(e) if kept => {
                // Context loss while suspended: start over with a new context and renderer.
                log::warn!("the kept context is gone ({e}); rebuilding it");
                if let Some(old) = self.renderer.take() {
                    old.abandon();
                }
                create_context(egl)?
                    .make_current(&surface)
                    .map_err(|e| format!("cannot make the context current: {e}"))?
            }
            Err(e) => return Err(format!("cannot make the context current: {e}")),
        };
        if let Err(e) = surface.set_swap_interval(&context, SwapInterval::Wait(NonZeroU32::MIN)) {
            log::info!("no vsync: {e}");
        }
        if self.renderer.is_none() {
            match new_renderer(egl, &mut self.scene) {
                Ok(renderer) => self.renderer = Some(renderer),
                Err(Failed { message, lost }) => {
                    // Released first: a surface dropped while current stays bound to the
                    // window, whose next surface EGL then refuses. Kept for the retry unless
                    // lost, GL or EGL says so (the retry then makes a new one).
                    let lost = lost
                        || context
                            .make_current(&surface)
                            .is_err_and(|e| e.error_kind() == ErrorKind::ContextLost);
                    match (context.make_not_current(), lost) {
                        (Ok(c), false) => self.parked = Some(c),
                        (Ok(_), true) => {}
                        (Err(e), _) => log::warn!("cannot release the context: {e}"),
                    }
                    drop(surface);
                    return Err(message);
                }
            }
        }
        window.request_redraw();
        // The first statistics line after a pause covers frames, not the pause.
        self.frames = 0;
        self.since = Instant::now();
        self.live = Some(Live {
            surface,
            context,
            window,
        });
        Ok(())
    }

    /// One finger orbits; others are ignored.
    fn touch(&mut self, touch: Touch) {
        let Touch {
            id,
            phase,
            location,
            ..
        } = touch;
        match (phase, self.touch) {
            (TouchPhase::Started, None) => self.touch = Some((id, location)),
            (TouchPhase::Moved, Some((finger, last))) if finger == id => {
                let width = self
                    .live
                    .as_ref()
                    .map_or(1.0, |l| f64::from(l.window.inner_size().width));
                self.orbit
                    .drag(location.x - last.x, location.y - last.y, width);
                self.touch = Some((id, location));
            }
            (TouchPhase::Ended | TouchPhase::Cancelled, Some((finger, _))) if finger == id => {
                self.touch = None
            }
            _ => {}
        }
    }

    /// Renders and presents one frame, then asks for the next; false where there was nothing
    /// to draw into (suspended, or a resume that failed, or a zero-sized window).
    fn frame(&mut self) -> Result<bool, FrameError> {
        let (Some(live), Some(renderer)) = (&self.live, self.renderer.as_mut()) else {
            return Ok(false);
        };
        let size = live.window.inner_size();
        if size.width == 0 || size.height == 0 {
            return Ok(false);
        }
        self.orbit.apply(&mut self.scene.camera);
        let stats = &mut self.stats;
        let rendered = renderer.render_reusing(
            &self.scene,
            size.width,
            size.height,
            &frame_options(),
            stats,
        );
        if let Err(e) = rendered {
            let message = format!("render failed: {e}");
            // GL says so where it has robustness; EGL answers eglMakeCurrent with
            // EGL_CONTEXT_LOST after a power event. Either way no swap comes to see it.
            let gl_lost = is_lost(&e);
            let egl_lost = live
                .context
                .make_current(&live.surface)
                .is_err_and(|e| e.error_kind() == ErrorKind::ContextLost);
            return Err(match gl_lost || egl_lost {
                true => FrameError::ContextLost(message),
                false => FrameError::Other(message),
            });
        }
        if stats.programs_built > 0 {
            log::info!("a frame built {} shader programs", stats.programs_built);
        }
        if let Err(e) = live.surface.swap_buffers(&live.context) {
            let message = format!("eglSwapBuffers: {e}");
            return Err(match e.error_kind() {
                ErrorKind::ContextLost => FrameError::ContextLost(message),
                // A surface that went away mid-frame: the next resume makes a new one.
                _ => FrameError::Other(message),
            });
        }
        live.window.request_redraw();
        self.frames += 1;
        let elapsed = self.since.elapsed().as_secs_f64();
        if elapsed >= LOG_EVERY_S {
            log::info!(
                "{} · {} lights · {}x{} · {:.1} ms/frame · assign {:.2} ms",
                stats.method,
                stats.lights.total,
                size.width,
                size.height,
                elapsed * 1e3 / f64::from(self.frames),
                stats.time.assign_ms
            );
            self.frames = 0;
            self.since = Instant::now();
        }
        Ok(true)
    }
}

/// Makes `context` not current, then drops it and `surface`. Dropped while current, EGL keeps
/// both until another context is made current, and the surface keeps the native window:
/// Android then refuses a new surface for it (`EGL_BAD_ALLOC`).
fn release(context: PossiblyCurrentContext, surface: Surface<WindowSurface>) {
    if let Err(e) = context.make_not_current() {
        log::warn!("cannot release the lost context: {e}");
    }
    drop(surface);
}

/// A renderer on the current context, its method picked and the scene's shaders built (for
/// the window's framebuffer the frames draw into, rather than in the first frames, each compile
/// a hitch). Where the device runs only forward, the scene keeps the lights forward can draw
/// on a weak GPU.
fn new_renderer(egl: &Egl, scene: &mut Scene) -> Result<Renderer, Failed> {
    // SAFETY: glutin returns EGL's entry points (or null); glow stores them, and the context
    // stays current on this thread whenever the renderer draws.
    let gl = unsafe {
        manylight::glow::Context::from_loader_function_cstr(|name: &CStr| {
            egl.display.get_proc_address(name)
        })
    };
    let mut renderer = Renderer::new(gl, egl.es).map_err(|e| Failed::from(&e))?;
    // The app draws nothing else, so it has no GL state to be given back: the renderer skips
    // saving it, the queries an Android driver's thread would make each frame wait on.
    renderer.set_gl_state_handling(GlStateHandling::Reset);
    pick_method(&mut renderer)?;
    if renderer.method() == Method::Forward && scene.lights.len() > FORWARD_LIGHTS {
        log::warn!(
            "only forward runs here: drawing {FORWARD_LIGHTS} of the {} lights, each of which \
             it evaluates at every pixel",
            scene.lights.len()
        );
        scene.truncate_lights(FORWARD_LIGHTS);
    }
    match renderer.warm_up(scene, &frame_options()) {
        Ok(w) => log::info!("warmed up: {} programs in {:.0} ms", w.programs_built, w.ms),
        Err(e) => log::warn!("warm-up failed (the first frames build what it did not): {e}"),
    }
    let caps = renderer.caps();
    log::info!(
        "{} on {} ({}), method {}",
        egl.es,
        caps.renderer,
        caps.gl_version,
        renderer.method()
    );
    Ok(renderer)
}

/// What every frame is drawn with: a game's frame does not wait for the GPU.
fn frame_options() -> RenderOptions {
    RenderOptions {
        wait_for_gpu: false,
        ..RenderOptions::default()
    }
}

/// The default method, else the first of the table this device runs (an ES 2.0 GPU without
/// fragment `highp` cannot run the culling methods).
fn pick_method(renderer: &mut Renderer) -> Result<(), Failed> {
    let methods = std::iter::once(Method::default()).chain(Method::ALL);
    let mut failures = Vec::new();
    for method in methods {
        match renderer.set_method(method) {
            Ok(_) => return Ok(()),
            Err(e) if is_lost(&e) => return Err(Failed::from(&e)),
            Err(e) => failures.push(e.to_string()),
        }
    }
    Err(Failed {
        message: format!("no shading method runs here: {}", failures.join("; ")),
        lost: false,
    })
}

/// Why a renderer could not be made, and whether GL said the context was lost.
struct Failed {
    message: String,
    lost: bool,
}

impl From<&Error> for Failed {
    fn from(e: &Error) -> Failed {
        Failed {
            message: e.to_string(),
            lost: is_lost(e),
        }
    }
}

/// GL said the context was lost (`GL_CONTEXT_LOST`).
fn is_lost(e: &Error) -> bool {
    matches!(e, Error::Gl(GlError::ContextLost(_)))
}

/// The EGL display of the event loop, the first of ES 3.0 / ES 2.0 that has a usable config
/// and gives a context, and that context.
fn open_egl(event_loop: &ActiveEventLoop) -> Result<(Egl, NotCurrentContext), String> {
    let raw = event_loop
        .display_handle()
        .map_err(|e| format!("no display handle: {e}"))?
        .as_raw();
    // SAFETY: an Android display handle carries no pointer; EGL's default display is used.
    let display = unsafe { Display::new(raw, DisplayApiPreference::Egl) }
        .map_err(|e| format!("cannot open the EGL display: {e}"))?;
    let mut failures = Vec::new();
    for es in [EsVersion::Es3, EsVersion::Es2] {
        let api = match es {
            EsVersion::Es2 => Api::GLES2,
            EsVersion::Es3 => Api::GLES3,
        };
        // No stencil asked for (glutin's template asks for 8 bits): the renderer uses none.
        let template = ConfigTemplateBuilder::new()
            .with_api(api)
            .with_alpha_size(0)
            .with_depth_size(16)
            .with_stencil_size(0)
            .build();
        // SAFETY: only queries the display's configs.
        let config = unsafe { display.find_configs(template) }
            .ok()
            .and_then(|configs| {
                // No multisampling, then a 24-bit depth buffer if there is one; among equals
                // the first, as EGL sorts them (slow and non-conformant configs last).
                configs
                    .enumerate()
                    .max_by_key(|(i, c)| {
                        (c.num_samples() == 0, c.depth_size().min(24), Reverse(*i))
                    })
                    .map(|(_, c)| c)
            });
        let Some(config) = config else {
            failures.push(format!("{es}: no window config with a depth buffer"));
            continue;
        };
        let egl = Egl {
            display: display.clone(),
            config,
            es,
        };
        match create_context(&egl) {
            Ok(context) => {
                if !failures.is_empty() {
                    log::warn!("falling back to {es}: {}", failures.join("; "));
                }
                return Ok((egl, context));
            }
            Err(e) => failures.push(format!("{es}: {e}")),
        }
    }
    Err(format!(
        "no OpenGL ES context available: {}",
        failures.join("; ")
    ))
}

/// A not-yet-current context for the chosen config and version.
fn create_context(egl: &Egl) -> Result<NotCurrentContext, String> {
    let attributes = ContextAttributesBuilder::new()
        .with_context_api(ContextApi::Gles(Some(Version::new(
            egl.es.major() as u8,
            0,
        ))))
        .build(None);
    // SAFETY: a plain context, shared with nothing and not tied to a window handle.
    unsafe { egl.display.create_context(&egl.config, &attributes) }
        .map_err(|e| format!("eglCreateContext: {e}"))
}
