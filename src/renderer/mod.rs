//! The renderer: owns the GL device, the program cache, the uploaded scene and the current
//! shading method; renders a [`Scene`](crate::scene::Scene) and reports [`FrameStats`].
//!
//! Layout: the [`Renderer`] itself (creation, method choice, teardown) here; what a frame
//! reports in `stats`; drawing a frame into the bound framebuffer (with MSAA) in `frame`, with
//! its light gathering, shader features and grid depth in `frame_setup`; offscreen renders
//! read back to the CPU (colour, HDR, light counts) in `offscreen`.

mod bound_target;
mod depth_warning;
mod empty_scene;
mod fp16_channels;
mod fp16_range;
mod frame;
mod frame_inputs;
mod frame_report;
mod frame_setup;
#[cfg(test)]
mod hosted_tests;
mod light_high_water;
mod method;
mod offscreen;
mod programs;
mod shared_surfaces;
mod stats;
#[cfg(test)]
mod timer_tests;
mod uploads;
mod warm_up;

use crate::cluster::view_light::GpuLight;
use crate::gl::framebuffer::OffscreenTarget;
use crate::gl::left_objects::LeftObjects;
use crate::gl::program::ProgramCache;
use crate::gl::{Caps, Device, EsVersion};
pub use crate::gpu_scene::GpuScene;
use crate::methods::{self, ShadingMethod, Support};
pub use crate::metrics::counts::LightCounts;
pub use crate::options::{CountKind, RenderOptions, ToneMap};
use crate::Error;
pub use method::Method;
pub use stats::{ContextStats, FrameStats, GridStats, LightStats, MemoryStats, TimeStats};
pub use warm_up::WarmUp;

/// Renders scenes with one shading method at a time.
///
/// A renderer stays on the thread that made it (it is not `Send`): its GL objects belong to a
/// context current there. Tests that render in parallel make a [`HeadlessContext`](crate::HeadlessContext)
/// and a renderer each, which is cheap; a context moves between threads only after
/// [`HeadlessContext::release_current`](crate::HeadlessContext::release_current) on the one
/// it leaves.
pub struct Renderer {
    dev: Device,
    programs: ProgramCache,
    gpu_scene: GpuScene,
    method: Box<dyn ShadingMethod>,
    /// The plain-forward pass that draws `CountKind::Reaching` frames whatever the method:
    /// made at the first such frame, kept for the next ones.
    reaching_pass: Option<Box<dyn ShadingMethod>>,
    /// Frames without a reaching count in a row (the pass is freed after
    /// [`methods::IDLE_FRAMES_KEPT`]).
    reaching_idle: u32,
    support: Support,
    target: Option<OffscreenTarget>,
    /// The multisampled target `render_offscreen` draws into with `RenderOptions::samples`,
    /// kept for two sizes (two views a frame).
    msaa: crate::gl::two_sizes::TwoSizes<crate::gl::multisample::MultisampleTarget>,
    /// The GPU timer: `None` until first needed, then `Some(None)` where the context has no
    /// timer queries.
    timer: Option<Option<crate::gl::timer::GpuTimer>>,
    /// Frames rendered: the number the GPU timer's results are matched to their frames by.
    frame_serial: u64,
    /// The frame being drawn goes into the renderer's own MSAA target.
    own_msaa_frame: bool,
    /// What the frame being drawn clears (`RenderOptions::clear`, or everything offscreen).
    frame_clear: crate::options::Clear,
    /// What the default method's support would warn about: said at the first frame, unless
    /// the caller picks a method first (whose own support is then what is said).
    pending_warning: Option<String>,
    /// GL objects already freed (by `destroy`; dropping then does nothing more).
    freed: bool,
    /// The frame's active lights in view space (kept: a frame fills it without allocating).
    lights: Vec<GpuLight>,
    /// Those of `lights` a context without fragment `highp` can place, when it leaves some out.
    placed: fp16_range::PlacedLights,
    /// Changes whenever `lights` may differ from the last frame's ([`FrameContext`]'s
    /// `lights_generation`).
    lights_generation: u64,
    /// The frames being drawn are timed ([`MeasureOptions::timed_frames`]): each counts as
    /// one whose lights moved, so it times an assignment, not a reuse.
    timing_frames: bool,
    /// Which directional lights the frame shows (kept likewise).
    shown_directional: Vec<usize>,
    /// More directional lights than are shown was announced (once per renderer).
    warned_directional: bool,
    /// A bound framebuffer's shallow depth buffer was announced (once per renderer).
    warned_depth_bits: bool,
    /// HDR colour into a fixed-point framebuffer was warned of.
    warned_hdr_fixed_point: bool,
    /// A frame past the bound framebuffer's colour buffer was warned of.
    warned_past_framebuffer: bool,
    /// The framebuffer and the frame's rectangle in it the last frame checked its colour
    /// buffer's size for (see `warn_past_bound_colour`).
    placed_in: Option<(Option<glow::Framebuffer>, [u32; 4])>,
    /// The application's framebuffer the last frame drew into without an error: complete, not
    /// asked again while frames go there (see `check_bound_target`).
    complete_target: Option<Option<glow::Framebuffer>>,
    /// The frame being drawn goes to a framebuffer that encodes sRGB itself: drawn with linear
    /// output (and, with MSAA on ES 3.0, an sRGB multisampled target).
    srgb_destination: bool,
    /// A camera too coarse in depth for the scene was announced (once per renderer).
    warned_depth_step: bool,
    /// A scene without triangles was announced (once per renderer).
    warned_nothing_to_draw: bool,
    /// Whether frames take the shared surface variants.
    shared_surfaces: shared_surfaces::SharedSurfaces,
    /// The light count whose frame memory was last asked of the allocator.
    lights_probed: usize,
    /// When the CPU buffers a burst of lights grew are given back.
    light_high_water: light_high_water::LightHighWater,
    /// A far plane the `f32` projection cannot clip at was announced (once per renderer).
    warned_unclipped_far: bool,
    /// Whether a light brighter than the fp16 radiance form holds was said (without fragment
    /// highp; once a renderer).
    warned_capped_radiance: bool,
    /// Whether the fp16 cap of the ambient term was said (`fp16_channels`).
    warned_capped_ambient: bool,
    /// The renderer's own 16-bit depth buffer was announced (once per renderer).
    warned_own_depth_bits: bool,
    /// The frame being drawn is a warm-up's ([`Renderer::warm_up`]): into a target of its own,
    /// so what it would say of its depth buffer is not the game's.
    warming_up: bool,
    /// The frame's objects in draw order (kept likewise).
    draw_order: methods::geometry::DrawOrder,
    /// `LP_NUM_THREADS` when the renderer was made (llvmpipe reads it when the context is
    /// made; reading it every frame would allocate).
    lp_num_threads: Option<String>,
    /// Marks the GL objects left when the context is gone ([`Renderer::abandon`], or no
    /// context current at drop), so that they drop without a warning each. Last: fields drop
    /// in declaration order, and the mark must outlive the others.
    left: LeftObjects,
}

impl Renderer {
    /// Creates a renderer on a current GL context, restricted to feature level `es`. The
    /// context must be current during each of its calls and when it is dropped; between them
    /// it may be made not current (an app's suspend keeps it so). A context lost or destroyed
    /// before the renderer: let the renderer go with [`Renderer::abandon`]. `gl` is a
    /// `glow::Context` of its own or one the game shares (`Arc<glow::Context>`, as egui and
    /// three-d hold theirs).
    pub fn new(
        gl: impl Into<std::sync::Arc<glow::Context>>,
        es: EsVersion,
    ) -> Result<Renderer, Error> {
        Renderer::restricted(gl, es, &crate::gl::Restrictions::default())
    }

    /// [`Renderer::new`] playing a weaker device than the driver (see
    /// [`crate::gl::Restrictions`]): for example one without fragment highp, where only
    /// methods that need no highp run (the default method falls back to forward).
    pub fn restricted(
        gl: impl Into<std::sync::Arc<glow::Context>>,
        es: EsVersion,
        restrictions: &crate::gl::Restrictions,
    ) -> Result<Renderer, Error> {
        let forward = methods::find("forward")?;
        let mut desc = methods::find(methods::DEFAULT_METHOD)?;
        let mut dev = Device::restricted(gl, es, restrictions)?;
        let mut support = (desc.supported)(dev.caps());
        let mut pending_warning = None;
        let mut replaced = None;
        if let Support::Unsupported(reason) = &support {
            let why = format!(
                "the default method `{}` is unsupported here ({reason})",
                desc.name
            );
            pending_warning = Some(format!("{why}; rendering with `forward`"));
            replaced = Some(why);
            desc = forward;
            support = (desc.supported)(dev.caps());
        }
        if let Support::Fallback(reason) = &support {
            let note = format!("method `{}` runs with a fallback: {reason}", desc.name);
            pending_warning = Some(match pending_warning {
                Some(first) => format!("{first}; {note}"),
                None => note,
            });
        }
        // Forward standing in for the default is a fallback too, which the frames' stats say.
        support = match (replaced, support) {
            (Some(why), Support::Supported) => Support::Fallback(why),
            (Some(why), Support::Fallback(reason)) => Support::Fallback(format!("{why}; {reason}")),
            (_, support) => support,
        };
        let method = match dev.host_call(|| (desc.create)(&dev)) {
            Ok(method) => method,
            Err(e) => {
                // A creation that fails leaves nothing in the game's context (nor deletes
                // another's objects).
                if dev.check_current().is_ok() {
                    let _turn = dev.turn();
                    dev.delete_own_objects();
                }
                return Err(e);
            }
        };
        Ok(Renderer {
            dev,
            programs: ProgramCache::new(),
            gpu_scene: GpuScene::default(),
            method,
            reaching_pass: None,
            reaching_idle: 0,
            support,
            target: None,
            msaa: Default::default(),
            timer: None,
            frame_serial: 0,
            own_msaa_frame: false,
            frame_clear: crate::options::Clear::All,
            pending_warning,
            freed: false,
            lights: Vec::new(),
            placed: fp16_range::PlacedLights::default(),
            lights_generation: 0,
            timing_frames: false,
            shown_directional: Vec::new(),
            warned_directional: false,
            warned_depth_bits: false,
            warned_hdr_fixed_point: false,
            warned_past_framebuffer: false,
            placed_in: None,
            complete_target: None,
            srgb_destination: false,
            warned_depth_step: false,
            warned_nothing_to_draw: false,
            shared_surfaces: Default::default(),
            lights_probed: 0,
            light_high_water: Default::default(),
            warned_unclipped_far: false,
            warned_capped_radiance: false,
            warned_capped_ambient: false,
            warned_own_depth_bits: false,
            warming_up: false,
            draw_order: methods::geometry::DrawOrder::default(),
            lp_num_threads: std::env::var("LP_NUM_THREADS").ok(),
            left: LeftObjects::default(),
        })
    }

    /// Frees the renderer's GL objects except its built programs, which it hands over for
    /// [`Renderer::adopt_programs`] (`lab`: the tests keep them per context, since SwiftShader
    /// compiles each program's code again for every new one).
    #[cfg(feature = "lab")]
    pub fn destroy_keeping_programs(mut self) -> ProgramCache {
        let programs = std::mem::take(&mut self.programs);
        self.dev.count_handed_programs(-(programs.len() as i64));
        self.free_gl();
        programs
    }

    /// Uses `programs`, built by an earlier renderer on this same context (from
    /// [`Renderer::destroy_keeping_programs`]), instead of building them again. (A program
    /// keeps the uniform values last set in it; each draw sets the ones it reads.)
    #[cfg(feature = "lab")]
    pub fn adopt_programs(&mut self, programs: ProgramCache) {
        self.dev.count_handed_programs(programs.len() as i64);
        let mut own = std::mem::replace(&mut self.programs, programs);
        let _turn = self.dev.turn();
        own.destroy(&self.dev);
    }

    /// The probed capabilities.
    pub fn caps(&self) -> &Caps {
        self.dev.caps()
    }

    /// Whether the fragment stage evaluates `mediump` as fp16 (measured with a tiny render).
    pub fn mediump_is_fp16(&self) -> Result<bool, Error> {
        self.dev.check_current()?;
        Ok(self
            .dev
            .host_call(|| crate::gl::precision_probe::mediump_is_fp16(&self.dev))?)
    }

    /// Runs `f` between the application's GL state saved and given back (see
    /// `gl::host_state`), after checking that the renderer's context is current. As
    /// [`Device::host_call`], but `f` gets the renderer: the state comes back also when `f`
    /// panics.
    fn hosted<T>(&mut self, f: impl FnOnce(&mut Self) -> Result<T, Error>) -> Result<T, Error> {
        self.dev.check_current()?;
        let host = self.dev.enter_host();
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| f(self)));
        if result.is_err() {
            // A frame that panicked between the GPU timer's begin and end left its query
            // running: ended, or the application's own queries would be refused.
            if let Some(Some(t)) = &self.timer {
                t.end_running(&self.dev);
            }
        }
        if !matches!(result, Ok(Ok(_))) {
            // A failed call's own GL errors, not to be reported as the game's next time.
            self.dev.drain_errors();
        }
        self.dev.leave_host(host);
        result.unwrap_or_else(|panic| std::panic::resume_unwind(panic))
    }

    /// Runs `f`, then `restore` whether `f` returned or panicked (the panic then goes on): what
    /// a call sets aside for its length (a method, a target, a flag) comes back also for a
    /// caller that catches the panic, and is not leaked with it.
    fn restoring<T>(
        &mut self,
        f: impl FnOnce(&mut Self) -> T,
        restore: impl FnOnce(&mut Self),
    ) -> T {
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| f(self)));
        restore(self);
        result.unwrap_or_else(|panic| std::panic::resume_unwind(panic))
    }

    /// `lab`: makes the GL checks whose description contains `name` fail as out of memory
    /// (`None`: none), to test what a failed upload or allocation leaves behind.
    #[cfg(feature = "lab")]
    pub fn fail_gl_checks_naming(&self, name: Option<&'static str>) {
        self.dev.fail_checks_naming(name);
    }

    /// Programs bound and uniforms set so far (`lab`: tests count a frame's).
    #[cfg(feature = "lab")]
    pub fn gl_state_calls(&self) -> crate::gl::device::StateCalls {
        self.dev.state_calls()
    }

    /// GL objects the renderer holds now (`lab`: the soak tests count them).
    #[cfg(feature = "lab")]
    pub fn live_gl_objects(&self) -> crate::gl::device::LiveObjects {
        self.dev.live_objects()
    }

    /// Every shader variant built so far: shader, feature bits and assembled source size
    /// (`lab`: `manylight info --scene`).
    #[cfg(feature = "lab")]
    pub fn program_report(&self) -> Vec<crate::gl::program::ProgramInfo> {
        self.programs.report()
    }

    /// The method drawing now: the one set last, or [`Method::Clustered`] by default, or
    /// what `Renderer::new` fell back to where the default cannot run here.
    pub fn method(&self) -> Method {
        let name = self.method.name();
        Method::ALL
            .into_iter()
            .find(|m| m.name() == name)
            .unwrap_or_default()
    }

    /// Whether `method` runs on this renderer's context, without switching to it: supported,
    /// with a fallback (the reason names the degradation), or not (the reason names what is
    /// missing). `Method::ALL` filtered by it lists what a device can run.
    pub fn support(&self, method: Method) -> Support {
        methods::find(method.name()).map_or_else(
            |e| Support::Unsupported(e.to_string()),
            |m| (m.supported)(self.dev.caps()),
        )
    }

    /// What each call does with the GL state the application left: saves it and gives it
    /// back (the default), or reads only the bound framebuffer and leaves GL's initial values
    /// ([`GlStateHandling::Reset`](crate::GlStateHandling::Reset): for an engine that sets its
    /// own state before it draws, sparing the queries a threaded driver waits on). From the
    /// next call on.
    pub fn set_gl_state_handling(&mut self, handling: crate::GlStateHandling) {
        self.dev.set_state_handling(handling);
    }

    /// What calls do with the application's GL state ([`Renderer::set_gl_state_handling`]).
    pub fn gl_state_handling(&self) -> crate::GlStateHandling {
        self.dev.state_handling()
    }

    /// Switches method. Unsupported methods are an error naming what is missing; a fallback
    /// is returned as `Some(reason)` (also logged as a warning). The previous method's GPU
    /// resources are freed.
    pub fn set_method(&mut self, method: Method) -> Result<Option<String>, Error> {
        self.set_method_named(method.name())
    }

    /// [`Renderer::set_method`] by name, as `--method` or a settings file gives it
    /// (`"clustered"`, …); an unknown name is [`Error::UnknownMethod`].
    pub fn set_method_named(&mut self, name: &str) -> Result<Option<String>, Error> {
        self.hosted(|r| r.switch_method(name))
    }

    /// [`Renderer::set_method_named`] with the application's GL state saved.
    fn switch_method(&mut self, name: &str) -> Result<Option<String>, Error> {
        let desc = methods::find(name)?;
        let support = (desc.supported)(self.dev.caps());
        if let Support::Unsupported(reason) = &support {
            let caps = self.dev.caps();
            let runnable: Vec<&str> = methods::METHODS
                .iter()
                .filter(|m| !matches!((m.supported)(caps), Support::Unsupported(_)))
                .map(|m| m.name)
                .collect();
            return Err(Error::UnsupportedMethod {
                method: name.to_string(),
                reason: reason.clone(),
                runnable: runnable.join(", "),
            });
        }
        // An explicit choice replaces what the default method would have warned about (a
        // refused one above does not: the default method stays).
        let unannounced = self.pending_warning.take().is_some();
        let switching = desc.name != self.method.name();
        if switching {
            let new = (desc.create)(&self.dev)?;
            let mut old = std::mem::replace(&mut self.method, new);
            old.destroy(&self.dev);
        }
        self.support = support.clone();
        Ok(match support {
            Support::Fallback(reason) => {
                // Announced once, when the method is taken up (here or at the first frame).
                if switching || unannounced {
                    log::warn!("method `{name}` runs with a fallback: {reason}");
                }
                Some(reason)
            }
            _ => None,
        })
    }

    /// The cell grid and light lists of the last tiled or clustered frame (for tests and
    /// tools that check what the shader read); `None` for other methods (`lab`).
    #[cfg(feature = "lab")]
    pub fn last_light_lists(&self) -> Option<methods::LightLists<'_>> {
        self.method.light_lists()
    }

    /// Frees every GL object the renderer made, while its context is still current.
    /// Dropping the renderer does the same (so an early return on an error frees everything
    /// quietly); `destroy` only makes the moment explicit.
    pub fn destroy(mut self) {
        self.free_gl();
    }

    /// Forgets the renderer's GL objects without a GL call: for a context that is gone (an
    /// Android app's EGL context lost while it was paused), whose names must not be deleted
    /// in whatever context is current now. A new renderer then starts on the new context.
    pub fn abandon(mut self) {
        self.freed = true;
        self.left.leave();
    }

    fn free_gl(&mut self) {
        if self.freed {
            return;
        }
        self.freed = true;
        // Its objects' names would be another context's: leave them (a leak) rather than
        // delete those.
        if let Err(e) = self.dev.check_current() {
            log::warn!("the renderer's GL objects are not freed: {e}");
            self.left.leave();
            return;
        }
        // Deleting large textures while another context drew may crash llvmpipe too.
        let _turn = self.dev.turn();
        if let Some(Some(t)) = self.timer.take() {
            t.end_running(&self.dev);
            t.destroy(&self.dev);
        }
        self.method.destroy(&self.dev);
        if let Some(mut pass) = self.reaching_pass.take() {
            pass.destroy(&self.dev);
        }
        self.programs.destroy(&self.dev);
        self.gpu_scene.destroy(&self.dev);
        if let Some(mut t) = self.target.take() {
            t.destroy(&self.dev);
        }
        for mut t in self.msaa.take_all() {
            t.destroy(&self.dev);
        }
        self.dev.delete_own_objects();
    }
}

impl Drop for Renderer {
    /// Frees the GL objects on the renderer's context, which must be current (another one
    /// current, or none, leaves them with a warning; see [`Renderer::new`]).
    fn drop(&mut self) {
        self.free_gl();
    }
}
