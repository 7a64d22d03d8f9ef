//! `manylight view`: an interactive window (feature `window`).
//!
//! A winit window with an OpenGL ES context from glutin over EGL (X11 or Wayland; GLX is not
//! used because it cannot create ES contexts). ES 3.0 is preferred and ES 2.0 taken when the
//! driver has no ES 3.0 config or context; the [`manylight::Renderer`] is told which one it
//! got. Every frame renders the scene into the window's default framebuffer without waiting
//! for the GPU, then swaps buffers (vsync where the driver allows it).
//!
//! Controls: WASD move, Q/E down/up, Shift faster, left-drag looks around, 1–5 pick a method
//! by its place in [`manylight::methods::METHODS`], +/- double/halve the random lights, H toggles the
//! light-evaluation heatmap (lights each pixel evaluates, viridis from 0 to 64), M toggles 4×
//! MSAA (resolved into the window), T cycles the tone map (none, Reinhard, ACES, Neutral),
//! Space pauses and resumes the lights' motion (built-in scenes' lights move; scene files
//! say how theirs do), Esc quits.
//! A change that the renderer rejects (say, plain forward over more lights than it can loop
//! over) is reported on stderr and undone. `--frames N` quits after N frames and
//! `--screenshot FILE` saves the last one, read back from the window's framebuffer.

// Submodules live next to this file (src/bin/manylight/), hence the paths.
#[path = "fly_camera.rs"]
mod fly_camera;
#[path = "window_gl.rs"]
mod window_gl;

use std::path::PathBuf;
use std::time::Instant;

use clap::Parser;
use fly_camera::{FlyCamera, Move};
use manylight::methods::METHODS;
use manylight::renderer::CountKind;
use manylight::scene::{self, shown, Scene};
use manylight::{EsVersion, FrameStats, RenderOptions};
use window_gl::Gfx;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, KeyEvent, MouseButton, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, KeyCode, NamedKey, PhysicalKey};
use winit::window::WindowId;

use crate::EsArg;

/// Options of `manylight view`.
#[derive(Parser, Debug)]
#[command(name = "view")]
pub struct ViewArgs {
    /// A built-in scene (an unknown name lists them), an .obj, .gltf/.glb or .json scene file.
    #[arg(long, default_value = scene::builtin::DEFAULT, value_parser = crate::SceneSpec)]
    pub scene: String,
    /// Shading method to start with (keys 1–5 switch: forward, tiled, clustered, deferred,
    /// auto, the order of `manylight info`).
    #[arg(long, default_value = manylight::methods::DEFAULT_METHOD)]
    pub method: String,
    /// OpenGL ES version. Default: 3, or 2 where the driver has no ES 3.0.
    #[arg(long, value_enum)]
    pub es: Option<EsArg>,
    /// Number of seeded random lights (default: 1024; a scene or glTF file's own lights).
    #[arg(long, value_parser = crate::bench_assign::parse_light_count)]
    pub lights: Option<usize>,
    /// Seed of the random lights.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Initial window size as WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", value_parser = parse_window_size)]
    pub size: (u32, u32),
    /// Quit after this many frames (for scripts and tests).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub frames: Option<u64>,
    /// Save the last frame (read back from the window) to this PNG; needs --frames.
    #[arg(long, requires = "frames")]
    pub screenshot: Option<PathBuf>,
    /// Start with the light-evaluation heatmap on (H toggles it).
    #[arg(long)]
    pub heatmap: bool,
    /// Animation time to start at, in seconds (0: the scene as built).
    #[arg(long, default_value_t = 0.0, value_parser = crate::render::parse_time, allow_hyphen_values = true)]
    pub time: f64,
    /// Start with the lights' motion paused (Space resumes it); with `--frames` and
    /// `--screenshot`, the picture is then the frame at `--time`, as `render --time` draws it.
    #[arg(long)]
    pub paused: bool,
    /// Samples per pixel to start with (M toggles between 1 and 4): ES 3.0, or ES 2.0 with
    /// GL_EXT_multisampled_render_to_texture; not deferred.
    #[arg(long, default_value_t = 1, value_parser = crate::render::parse_samples)]
    pub msaa: u32,
}

/// Most random lights `+` goes to.
const MAX_LIGHTS: usize = 1 << 20;
/// The tone map after `current`, in a cycle.
fn next_tone_map(current: manylight::ToneMap) -> manylight::ToneMap {
    use manylight::ToneMap;
    match current {
        ToneMap::None => ToneMap::Reinhard,
        ToneMap::Reinhard => ToneMap::Aces,
        ToneMap::Aces => ToneMap::Neutral,
        ToneMap::Neutral => ToneMap::None,
    }
}

/// Seconds between title-bar updates.
const TITLE_EVERY_S: f64 = 0.25;

/// Runs the viewer until the window closes, Esc, or `--frames`.
/// What `view` says where no window can open (winit's own message names its registry path).
const NO_DISPLAY: &str = "cannot open a window: no X11 or Wayland display (DISPLAY and \
    WAYLAND_DISPLAY are unset or unreachable); run it under a display server, `xvfb-run -a \
    manylight view`, or render headless without a window: `manylight --out F.png`";

pub fn run(args: &ViewArgs) -> Result<(), Box<dyn std::error::Error>> {
    let lights = crate::render::lights_for(&args.scene, args.lights, args.seed);
    // The loader logs each warning (at `warn`, shown by default): not printed again here.
    let (mut scene, report) = scene::load_with(&args.scene, lights, &crate::load_options())?;
    crate::render::check_not_read(
        &[("--screenshot", args.screenshot.as_deref())],
        &report.files,
    )?;
    let lights = lights.map(|(n, _)| n);
    scene.set_time(args.time);
    // Validate the method name before opening a window.
    manylight::methods::find(&args.method)?;
    let extent = scene.bounds().map_or(10.0, |b| b.size().length());
    // winit's message starts with its source path: keep only its reason.
    let event_loop = EventLoop::new().map_err(|e| {
        let e = e.to_string();
        format!("{NO_DISPLAY} ({})", e.rsplit(": ").next().unwrap_or(&e))
    })?;
    // Frames follow one another through `about_to_wait`'s redraw requests (paced by vsync);
    // with none asked for (hidden, or a size it cannot draw), the loop sleeps.
    event_loop.set_control_flow(ControlFlow::Wait);
    say(
        args,
        &format!(
            "controls: WASD move, Q/E down/up, Shift faster, drag to look, 1-{} method, +/- lights, H heatmap, M MSAA, T tone map, Space pause, Esc quit\n",
            METHODS.len()
        ),
    )?;
    let mut app = App {
        args,
        light_count: lights.unwrap_or(scene.lights.len()),
        good: None,
        heatmap: args.heatmap,
        tone_map: manylight::ToneMap::None,
        samples: args.msaa.max(1),
        time_s: args.time,
        paused: args.paused,
        stats: FrameStats::default(),
        scene,
        fly: FlyCamera::new(FlyCamera::speed_for_extent(extent)),
        gfx: None,
        frames: 0,
        drawn_size: None,
        refused_size: None,
        occluded: false,
        last_frame: Instant::now(),
        title: TitleStats::default(),
        done: false,
        result: Ok(()),
    };
    event_loop.run_app(&mut app)?;
    app.result.map_err(Into::into)
}

/// Title-bar figures averaged since the last update.
#[derive(Default)]
struct TitleStats {
    since: Option<Instant>,
    frames: u32,
    wall_s: f64,
    cpu_ms: f64,
    assign_ms: f64,
}

/// What the keys and the fly camera change: a frame that fails after a change goes back to
/// the last frame's (a heatmap past forward's loop, a step into more lights than the method
/// indexes).
#[derive(Clone, Debug, PartialEq)]
struct Settings {
    method: String,
    lights: usize,
    heatmap: bool,
    tone_map: manylight::ToneMap,
    samples: u32,
    camera: manylight::Camera,
}

/// The viewer between events: scene, input, window (once resumed) and the exit status.
struct App<'a> {
    args: &'a ViewArgs,
    scene: Scene,
    /// Random lights asked for (`+`/`-` change it).
    light_count: usize,
    /// What the last frame that rendered was drawn with, to undo a change that fails.
    good: Option<Settings>,
    /// Show light evaluations per pixel instead of the image (H).
    heatmap: bool,
    /// The output stage's curve (T cycles it).
    tone_map: manylight::ToneMap,
    /// Samples per pixel (M toggles MSAA).
    samples: u32,
    /// Animation time in seconds: the lights' pose ([`Scene::set_time`]).
    time_s: f64,
    /// Space stops the animation clock.
    paused: bool,
    /// The last frame's figures, refilled in place every frame.
    stats: FrameStats,
    fly: FlyCamera,
    gfx: Option<Gfx>,
    frames: u64,
    /// The window size of the last frame that rendered.
    drawn_size: Option<(u32, u32)>,
    /// A size whose frame failed after others had rendered: not tried again until the window
    /// is resized (see [`after_failure`]).
    refused_size: Option<(u32, u32)>,
    /// The window is fully hidden: no frames until it shows.
    occluded: bool,
    last_frame: Instant,
    title: TitleStats,
    /// Set once exit was requested: no more frames.
    done: bool,
    result: Result<(), String>,
}

impl ApplicationHandler for App<'_> {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_some() {
            return;
        }
        let es = self.args.es.map(EsVersion::from);
        let made = Gfx::create(event_loop, "manylight", self.args.size, es).and_then(|mut g| {
            if let Some(r) = g.renderer.as_mut() {
                // A fallback is logged as a warning by the renderer.
                r.set_method_named(&self.args.method)
                    .map_err(|e| e.to_string())?;
            }
            Ok(g)
        });
        match made {
            Ok(mut g) => {
                // The scene's shaders built before the first frame (the window stays blank
                // meanwhile, not a first frame that stalls).
                if let Some(r) = g.renderer.as_mut() {
                    if let Err(e) = r.warm_up(&self.scene, &self.frame_options()) {
                        log::warn!("warm-up failed (the first frames build what it did not): {e}");
                    }
                }
                g.window.request_redraw();
                self.gfx = Some(g);
                self.last_frame = Instant::now();
            }
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        match event {
            // Destroyed by another client (`xdotool windowclose`): its size can no longer be
            // asked, which winit answers with a panic.
            WindowEvent::CloseRequested | WindowEvent::Destroyed => self.quit(event_loop),
            WindowEvent::Resized(size) => {
                if let Some(g) = &self.gfx {
                    g.resize(size);
                    g.window.request_redraw();
                }
            }
            WindowEvent::Occluded(occluded) => self.occluded = occluded,
            WindowEvent::Focused(false) => self.fly.release_all(),
            WindowEvent::KeyboardInput { event, .. } => self.key(event_loop, &event),
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => self.fly.set_dragging(state == ElementState::Pressed),
            WindowEvent::CursorMoved { position, .. } => {
                self.fly.cursor_moved(position.x, position.y)
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.redraw(event_loop) {
                    self.fail(event_loop, e);
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _: &ActiveEventLoop) {
        let Some(g) = self.gfx.as_ref().filter(|_| !self.done && !self.occluded) else {
            return;
        };
        let size = g.window.inner_size();
        let size = (size.width, size.height);
        if size.0 > 0 && size.1 > 0 && self.refused_size != Some(size) {
            g.window.request_redraw();
        }
    }

    fn exiting(&mut self, _: &ActiveEventLoop) {
        // Free GL objects while the window and its context still exist.
        if let Some(r) = self.gfx.as_mut().and_then(|g| g.renderer.take()) {
            r.destroy();
        }
    }
}

impl App<'_> {
    /// What the next frame is drawn with: the keys' heatmap, tone map and MSAA.
    fn frame_options(&self) -> RenderOptions {
        RenderOptions {
            wait_for_gpu: false,
            count: if self.heatmap {
                CountKind::Heatmap
            } else {
                CountKind::None
            },
            tone_map: self.tone_map,
            samples: self.samples,
            ..RenderOptions::default()
        }
    }

    /// Stops the loop; the first error is the one reported.
    fn fail(&mut self, event_loop: &ActiveEventLoop, error: String) {
        if self.result.is_ok() {
            self.result = Err(error);
        }
        self.quit(event_loop);
    }

    /// Stops the loop after this event; no frame is drawn after it.
    fn quit(&mut self, event_loop: &ActiveEventLoop) {
        self.done = true;
        event_loop.exit();
    }

    /// Movement keys (held), method digits, light count and Esc.
    fn key(&mut self, event_loop: &ActiveEventLoop, event: &KeyEvent) {
        let pressed = event.state == ElementState::Pressed;
        let PhysicalKey::Code(code) = event.physical_key else {
            return;
        };
        // Physical keys for movement and digits, so they sit in the same place on any layout.
        let movement = match code {
            KeyCode::KeyW => Some(Move::Forward),
            KeyCode::KeyS => Some(Move::Back),
            KeyCode::KeyA => Some(Move::Left),
            KeyCode::KeyD => Some(Move::Right),
            KeyCode::KeyQ => Some(Move::Down),
            KeyCode::KeyE => Some(Move::Up),
            KeyCode::ShiftLeft | KeyCode::ShiftRight => {
                self.fly.set_fast(pressed);
                None
            }
            _ => None,
        };
        if let Some(m) = movement {
            self.fly.set_key(m, pressed);
        }
        if !pressed || event.repeat {
            return;
        }
        // Digits 1–9 by position (physical), so they work on layouts with shifted digits.
        const DIGITS: [KeyCode; 9] = [
            KeyCode::Digit1,
            KeyCode::Digit2,
            KeyCode::Digit3,
            KeyCode::Digit4,
            KeyCode::Digit5,
            KeyCode::Digit6,
            KeyCode::Digit7,
            KeyCode::Digit8,
            KeyCode::Digit9,
        ];
        // `+`/`-` by character, wherever the layout puts them (`=` is `+` unshifted on US).
        let typed = |chars: &[&str]| matches!(&event.logical_key, Key::Character(c) if chars.contains(&c.as_str()));
        if let Some(i) = DIGITS.iter().position(|&d| d == code) {
            self.switch_method(i);
        } else if code == KeyCode::NumpadAdd || typed(&["+", "="]) {
            self.set_lights(self.light_count.saturating_mul(2).clamp(1, MAX_LIGHTS));
        } else if code == KeyCode::NumpadSubtract || typed(&["-"]) {
            self.set_lights(self.light_count / 2);
        } else if code == KeyCode::KeyH {
            self.heatmap = !self.heatmap;
            eprintln!(
                "heatmap: {}",
                if self.heatmap {
                    "light evaluations per pixel, 0 (purple) to 64 (yellow) lights"
                } else {
                    "off"
                }
            );
        } else if code == KeyCode::KeyM {
            self.samples = if self.samples > 1 { 1 } else { 4 };
            eprintln!("MSAA: {} samples", self.samples);
        } else if code == KeyCode::Space {
            self.paused = !self.paused;
            eprintln!(
                "motion: {}",
                match (self.paused, self.scene.is_animated()) {
                    (_, false) => "none (the scene's lights stand still)",
                    (true, true) => "paused",
                    (false, true) => "playing",
                }
            );
        } else if code == KeyCode::KeyT {
            self.tone_map = next_tone_map(self.tone_map);
            eprintln!("tone map: {:?}", self.tone_map);
        } else if event.logical_key == Key::Named(NamedKey::Escape) {
            self.quit(event_loop);
        }
    }

    /// Switches to the `index`-th method of the table; problems go to stderr.
    fn switch_method(&mut self, index: usize) {
        let (Some(desc), Some(r)) = (
            METHODS.get(index),
            self.gfx.as_mut().and_then(|g| g.renderer.as_mut()),
        ) else {
            eprintln!("no method {}: there are {}", index + 1, METHODS.len());
            return;
        };
        match r.set_method_named(desc.name) {
            Ok(None) => eprintln!("method: {}", desc.name),
            Ok(Some(reason)) => eprintln!("warning: {} runs with a fallback: {reason}", desc.name),
            Err(e) => eprintln!("error: {e}"),
        }
    }

    /// Regenerates the random lights with a new count (same seed); problems go to stderr.
    fn set_lights(&mut self, count: usize) {
        match scene::load_with(
            &self.args.scene,
            Some((count, self.args.seed)),
            &crate::load_options(),
        ) {
            // Keep geometry (already uploaded) and camera; only the lights change.
            Ok((new, _)) => {
                self.scene.lights = new.lights;
                self.scene.animation = new.animation;
                self.scene.set_time(self.time_s);
                self.light_count = count;
                eprintln!("lights: {}", self.scene.lights.len());
            }
            Err(e) => eprintln!("error: cannot regenerate lights: {e}"),
        }
    }

    /// Moves the camera, renders one frame, handles `--frames`/`--screenshot`, swaps.
    fn redraw(&mut self, event_loop: &ActiveEventLoop) -> Result<(), String> {
        let options = self.frame_options();
        let Some(g) = self.gfx.as_mut().filter(|_| !self.done) else {
            return Ok(());
        };
        let size = g.window.inner_size();
        if size.width == 0 || size.height == 0 {
            return Ok(()); // minimised
        }
        let now = Instant::now();
        let dt = now.duration_since(self.last_frame).as_secs_f64();
        self.last_frame = now;
        self.fly.update(dt, &mut self.scene.camera);
        if !self.paused && self.scene.is_animated() {
            self.time_s += dt;
            self.scene.set_time(self.time_s);
        }
        let renderer = g.renderer.as_mut().ok_or("renderer already destroyed")?;
        // One FrameStats kept across frames: a steady frame allocates nothing.
        let mut stats = std::mem::take(&mut self.stats);
        let rendered =
            renderer.render_reusing(&self.scene, size.width, size.height, &options, &mut stats);
        match rendered {
            Ok(()) => {}
            // MSAA this context or method cannot do: said once, and off again.
            Err(e) if self.samples > 1 && e.to_string().contains("MSAA") => {
                eprintln!("warning: {e}; MSAA off");
                self.samples = 1;
                return Ok(());
            }
            Err(e) => {
                let size = (size.width, size.height);
                return match after_failure(self.drawn_size, size) {
                    Failure::SkipSize => {
                        if self.refused_size != Some(size) {
                            eprintln!(
                                "error: {e}; no frames at {}x{} until the window is resized",
                                size.0, size.1
                            );
                            self.refused_size = Some(size);
                        }
                        Ok(())
                    }
                    Failure::UndoOrEnd => self.undo_change(e.to_string()),
                };
            }
        };
        self.drawn_size = Some((size.width, size.height));
        self.refused_size = None;
        self.frames += 1;
        if Some(self.frames) == self.args.frames {
            let mut line = format!(
                "{} · {}x{} · {} frames",
                summary(&stats, g.es),
                size.width,
                size.height,
                self.frames
            );
            if let Some(path) = &self.args.screenshot {
                let image = g.read_back(size)?;
                manylight_tools::output::save_png(path, &image).map_err(|e| e.to_string())?;
                line += &format!(" → {}", shown::path(path));
            }
            say(self.args, &format!("{line}\n"))?;
            self.done = true;
            event_loop.exit();
        }
        g.swap()?;
        update_title(&mut self.title, g, &stats, dt);
        // The method's name allocated only when it changed.
        let kept = (self.good.take())
            .filter(|good| good.method == stats.method)
            .map(|good| good.method);
        self.good = Some(self.settings(kept.unwrap_or_else(|| stats.method.clone())));
        self.stats = stats;
        Ok(())
    }

    /// The settings a frame drawn with `method` (the one the renderer ran) has.
    fn settings(&self, method: String) -> Settings {
        Settings {
            method,
            lights: self.light_count,
            heatmap: self.heatmap,
            tone_map: self.tone_map,
            samples: self.samples,
            camera: self.scene.camera,
        }
    }

    /// A frame failed: go back to the last frame's settings where something changed since,
    /// else give up.
    fn undo_change(&mut self, error: String) -> Result<(), String> {
        let renderer = self.gfx.as_mut().and_then(|g| g.renderer.as_mut());
        let (Some(good), Some(method)) = (
            self.good.clone(),
            renderer.map(|r| r.method().name().to_string()),
        ) else {
            return Err(error);
        };
        let now = self.settings(method);
        if now == good {
            return Err(error);
        }
        eprintln!(
            "error: {error}; back to the last frame's {} with {} lights",
            good.method, good.lights
        );
        if let Some(r) = (self.gfx.as_mut().and_then(|g| g.renderer.as_mut()))
            .filter(|_| now.method != good.method)
        {
            r.set_method_named(&good.method)
                .map_err(|e| e.to_string())?;
        }
        (self.heatmap, self.tone_map, self.samples) = (good.heatmap, good.tone_map, good.samples);
        // The camera where it drew, and the keys that moved it let go.
        self.scene.camera = good.camera;
        self.fly.release_all();
        if self.light_count != good.lights {
            self.set_lights(good.lights);
        }
        Ok(())
    }
}

/// What a failed frame leads to.
#[derive(Debug, PartialEq, Eq)]
enum Failure {
    /// The window has a size no frame has been drawn at since the last one that rendered (a
    /// maximised window past the driver's largest viewport or render target, say): frames
    /// wait for the next resize, and the keys' changes stand.
    SkipSize,
    /// At the size frames rendered at: the last key's change is undone, or, with none to undo,
    /// the viewer ends ([`App::undo_change`]).
    UndoOrEnd,
}

/// [`Failure`] for a frame of `size` that failed, `drawn` the size of the last that rendered
/// (`None`: none has, and the first frame's failure ends the viewer).
fn after_failure(drawn: Option<(u32, u32)>, size: (u32, u32)) -> Failure {
    match drawn {
        Some(drawn) if drawn != size => Failure::SkipSize,
        _ => Failure::UndoOrEnd,
    }
}

/// Prints `text` on standard output, or on standard error when the screenshot goes there (so
/// that standard output is the PNG alone; an unwritable standard error is ignored, as by the
/// binary's `eprintln!`).
fn say(args: &ViewArgs, text: &str) -> Result<(), String> {
    let names_stdout = manylight_tools::output::names_stdout;
    if args.screenshot.as_deref().is_some_and(names_stdout) {
        use std::io::Write;
        let _ = std::io::stderr().write_all(text.as_bytes());
        Ok(())
    } else {
        manylight_tools::output::print_stdout(text)
    }
}

/// `manylight · method · ES x · N lights`.
fn summary(stats: &FrameStats, es: EsVersion) -> String {
    format!(
        "manylight · {} · {es} · {} lights",
        stats.method, stats.lights.total
    )
}

/// The summary plus wall-clock frame time, CPU submission time and light assignment time.
fn title(stats: &FrameStats, es: EsVersion, frame_ms: f64) -> String {
    format!(
        "{} · {frame_ms:.1} ms/frame · cpu {:.1} ms · assign {:.2} ms",
        summary(stats, es),
        stats.time.frame_ms,
        stats.time.assign_ms
    )
}

/// Accumulates one frame and rewrites the title every [`TITLE_EVERY_S`].
fn update_title(t: &mut TitleStats, g: &Gfx, stats: &FrameStats, dt: f64) {
    let since = *t.since.get_or_insert_with(Instant::now);
    t.frames += 1;
    t.wall_s += dt;
    t.cpu_ms += stats.time.frame_ms;
    t.assign_ms += stats.time.assign_ms;
    if since.elapsed().as_secs_f64() >= TITLE_EVERY_S {
        let n = f64::from(t.frames);
        let mut mean = stats.clone();
        mean.time.frame_ms = t.cpu_ms / n;
        mean.time.assign_ms = t.assign_ms / n;
        g.window.set_title(&title(&mean, g.es, t.wall_s * 1e3 / n));
        *t = TitleStats::default();
    }
}

/// Largest side a window may ask for: X11's sizes are 16-bit, and winit panicked converting a
/// side of 65 536 (a side the GL cannot draw is refused later, naming its limit).
const MAX_WINDOW_SIDE: u32 = u16::MAX as u32;

/// `--size` of a window: [`crate::render::parse_size`], each side at most [`MAX_WINDOW_SIDE`].
fn parse_window_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = crate::render::parse_size(s)?;
    if w.max(h) > MAX_WINDOW_SIDE {
        return Err(format!(
            "size {w}x{h}: a window side is at most {MAX_WINDOW_SIDE}"
        ));
    }
    Ok((w, h))
}

#[cfg(test)]
mod tests {
    use super::{after_failure, Failure};

    #[test]
    fn a_failure_at_a_new_size_waits_for_a_resize_and_one_at_a_drawn_size_undoes() {
        // Maximised past the driver's limits after frames at 1280x720: wait, keep the keys.
        assert_eq!(
            after_failure(Some((1280, 720)), (20000, 12000)),
            Failure::SkipSize
        );
        // At the size frames were drawn at, the last key's change is what failed.
        assert_eq!(
            after_failure(Some((1280, 720)), (1280, 720)),
            Failure::UndoOrEnd
        );
        // No frame ever rendered: nothing to wait for.
        assert_eq!(after_failure(None, (1280, 720)), Failure::UndoOrEnd);
    }
}
