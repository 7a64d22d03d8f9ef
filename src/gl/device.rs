//! A glow context plus its capabilities, and the frame-level calls every pass needs.
#![allow(unsafe_code)]

use glow::HasContext;

use super::call_state::CallState;
pub use super::call_state::StateCalls;
use super::context_watch::{ContextWatch, Witness};
use super::host_entry::HostEntry;
use super::vertex_arrays::VertexArrays;
use super::{Caps, EsVersion, GlError, Restrictions};

/// The GL context the renderer draws with. Created from a glow context the caller owns (a
/// game's, or [`super::HeadlessContext::load_gl`]) and the ES level to restrict itself to.
pub struct Device {
    pub(crate) gl: std::sync::Arc<glow::Context>,
    caps: Caps,
    live: std::cell::Cell<LiveObjects>,
    /// Draw calls made since the device was created (`gl::mesh` makes every one of a frame).
    draw_calls: std::cell::Cell<u64>,
    /// `glRenderbufferStorageMultisampleEXT`, on ES 2.0 with
    /// `GL_EXT_multisampled_render_to_texture` (see [`super::ext_fns`]).
    pub(crate) renderbuffer_storage_multisample_ext:
        Option<super::ext_fns::RenderbufferStorageMultisampleExt>,
    /// The renderer's own vertex array object, with how this context binds one (an ES 3.x or
    /// desktop context, ES 2.0 with `GL_OES_vertex_array_object`), bound when each call
    /// starts, so a game's bound one keeps its buffers and attributes.
    own_vertex_array: Option<(glow::VertexArray, VertexArrays)>,
    /// What the context has of the application's state each call saves.
    host: super::host_state::HostFeatures,
    /// What each call does with the application's state (the outermost call's entry).
    state_handling: std::cell::Cell<super::GlStateHandling>,
    /// Nesting depth of [`Device::enter_host`] (the outermost call saves the state).
    host_depth: std::cell::Cell<u32>,
    /// Calls take turns with other threads' ([`super::driver_turns`]: llvmpipe).
    takes_turns: bool,
    /// The framebuffer the application had bound when the outermost call started.
    host_framebuffer: std::cell::Cell<Option<glow::Framebuffer>>,
    /// The driver refused a query of a frame's target once: each is drained on its own from
    /// then on ([`Device::target_format`](super::bound_framebuffer)).
    pub(super) target_queries_refused: std::cell::Cell<bool>,
    /// What this call has bound, and the state calls made.
    call: CallState,
    /// The polygon offset this call draws with (materials' depth bias).
    depth_bias: super::depth_bias::DepthBias,
    /// Whether a GL error the application left pending has been reported (once a device).
    warned_pending_error: std::cell::Cell<bool>,
    /// GL said the context was lost (`GL_CONTEXT_LOST`, which a driver may say only once): every
    /// later check says so too, since a lost context never comes back.
    lost: std::cell::Cell<bool>,
    /// How the device tells whether its context is current: EGL's handle, then the witness
    /// (where EGL can tell).
    context: ContextWatch,
    witness: Option<Witness>,
    /// `lab`: checks whose description contains this fail as out of memory (see
    /// [`Device::fail_checks_naming`]).
    #[cfg(feature = "lab")]
    failing_checks: std::cell::Cell<Option<&'static str>>,
}

/// GL objects currently alive, as counted by the renderer's own create/delete calls: what
/// tests use to check that switching methods frees the previous method's resources.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct LiveObjects {
    /// Textures.
    pub textures: i64,
    /// Buffers.
    pub buffers: i64,
    /// Framebuffers.
    pub framebuffers: i64,
    /// Renderbuffers.
    pub renderbuffers: i64,
    /// Programs.
    pub programs: i64,
    /// Vertex array objects of meshes (where the context has them).
    pub vertex_arrays: i64,
}

macro_rules! tracked {
    ($create:ident, $delete:ident, $ty:ty, $field:ident) => {
        pub(crate) fn $create(&self) -> Result<$ty, GlError> {
            let object = unsafe { self.gl.$create() }.map_err(creation_failed)?;
            self.count(|l| l.$field += 1);
            Ok(object)
        }

        pub(crate) fn $delete(&self, object: $ty) {
            unsafe { self.gl.$delete(object) };
            self.count(|l| l.$field -= 1);
        }
    };
}

/// A creation error, or the usual cause when EGL says no context is current here: the context
/// (a `HeadlessContext`, say) was dropped, or another made current, while the renderer lived.
fn creation_failed(reason: String) -> GlError {
    if super::gles_lib::current_context() == Some(None) {
        GlError::NotCurrent
    } else {
        GlError::Create(reason)
    }
}

impl Device {
    /// Wraps a current glow context and probes its capabilities.
    pub fn new(
        gl: impl Into<std::sync::Arc<glow::Context>>,
        es: EsVersion,
    ) -> Result<Device, GlError> {
        Device::restricted(gl, es, &Restrictions::default())
    }

    /// [`Device::new`] playing a weaker device (see [`Restrictions`]).
    pub fn restricted(
        gl: impl Into<std::sync::Arc<glow::Context>>,
        es: EsVersion,
        restrictions: &Restrictions,
    ) -> Result<Device, GlError> {
        let gl = gl.into();
        // The probe clears errors its own queries may leave: one the application left is said
        // first, as a call of the renderer says it.
        let pending = drain_errors(&gl);
        if pending == glow::CONTEXT_LOST {
            // Not the application's error, and the context answers no query from now on.
            return Err(GlError::ContextLost("the renderer's creation".into()));
        }
        if pending != glow::NO_ERROR {
            log::warn!(
                "{} (0x{pending:04x}) was pending when the renderer was created: the \
                 application's, cleared so that it is not taken for the renderer's",
                error_name(pending)
            );
        }
        // With no context current, GL calls do nothing and `glGetString` gives null, on which
        // the probe's glow call panics; any context's largest texture is 64 texels or more.
        if unsafe { gl.get_parameter_i32(glow::MAX_TEXTURE_SIZE) } <= 0 {
            return Err(GlError::NotCurrent);
        }
        // The probe makes and deletes GL objects, so it takes the turn too (driver_turns).
        let renderer = unsafe { gl.get_parameter_string(glow::RENDERER) };
        let takes_turns = super::driver_turns::needed_by(&renderer);
        let _turn = super::driver_turns::Turn::take_if(takes_turns);
        let mut caps = Caps::probe(&gl, es)?;
        caps.restrict(restrictions)?;
        // A core profile draws nothing without a bound vertex array object; on an ES 3.x
        // context, or ES 2.0 with `GL_OES_vertex_array_object`, one of the renderer's own (at
        // either level) leaves a game's untouched: its arrays, and their divisors, which ES 2.0
        // calls cannot reset.
        let vertex_arrays = if caps.desktop || caps.context_has_es3_state() {
            Some(VertexArrays::Core)
        } else if caps.has_extension("GL_OES_vertex_array_object") {
            VertexArrays::oes()
        } else {
            None
        };
        let context = ContextWatch::of_current();
        let witness = match context {
            ContextWatch::Unknown => None,
            _ => Some(Witness::new(&gl)?),
        };
        let own_vertex_array = match vertex_arrays.map(|v| (v.create(&gl), v)) {
            Some((Ok(vao), v)) => Some((vao, v)),
            Some((Err(e), _)) => {
                // A creation that fails leaves nothing in the game's context.
                if let Some(witness) = witness {
                    witness.delete(&gl);
                }
                return Err(GlError::Create(e));
            }
            None => None,
        };
        let renderbuffer_storage_multisample_ext = if caps.msaa_render_to_texture {
            let f = super::ext_fns::renderbuffer_storage_multisample_ext();
            if f.is_none() {
                log::warn!(
                    "GL_EXT_multisampled_render_to_texture is listed but \
                     glRenderbufferStorageMultisampleEXT could not be loaded through EGL: \
                     no MSAA on this context"
                );
                caps.msaa_render_to_texture = false;
                caps.max_samples = 0;
            }
            f
        } else {
            None
        };
        let units = unsafe { gl.get_parameter_i32(glow::MAX_COMBINED_TEXTURE_IMAGE_UNITS) };
        let host =
            super::host_state::HostFeatures::of(&gl, &caps, own_vertex_array.is_some(), units);
        let clamp_listed = caps.has_extension("GL_EXT_polygon_offset_clamp");
        let set_clamp = super::ext_fns::polygon_offset_clamp_ext(|e| caps.has_extension(e));
        if clamp_listed && set_clamp.is_none() {
            log::warn!(
                "GL_EXT_polygon_offset_clamp is listed but glPolygonOffsetClampEXT could not be \
                 loaded through EGL: a call that draws a biased material leaves the game's \
                 polygon offset clamp at 0"
            );
        }
        let depth_bias = super::depth_bias::DepthBias::new(clamp_listed, set_clamp);
        Ok(Device {
            gl,
            caps,
            live: std::cell::Cell::new(LiveObjects::default()),
            draw_calls: std::cell::Cell::new(0),
            renderbuffer_storage_multisample_ext,
            host,
            own_vertex_array,
            state_handling: std::cell::Cell::default(),
            host_depth: std::cell::Cell::new(0),
            takes_turns,
            host_framebuffer: std::cell::Cell::new(None),
            target_queries_refused: std::cell::Cell::new(false),
            call: CallState::default(),
            depth_bias,
            warned_pending_error: std::cell::Cell::new(false),
            lost: std::cell::Cell::new(false),
            context,
            witness,
            #[cfg(feature = "lab")]
            failing_checks: std::cell::Cell::new(None),
        })
    }

    /// Whether this device's context is current on this thread: an error when EGL says no
    /// context is, or another one (its GL names would be that context's objects), also where
    /// that one has the handle EGL gave the device's context before it was destroyed.
    pub(crate) fn check_current(&self) -> Result<(), GlError> {
        if !self.context.handle_is_current()? {
            return Ok(());
        }
        let Some(witness) = &self.witness else {
            return Ok(());
        };
        let _turn = self.turn();
        if witness.is_held(&self.gl, self.saves_state()) {
            return Ok(());
        }
        // A lost context holds no objects either, and says so once among the pending errors.
        self.clear_pending_errors();
        if self.lost.get() {
            return Err(GlError::ContextLost(
                "the check that the renderer's context is current".into(),
            ));
        }
        Err(GlError::OtherContext)
    }

    /// Runs `f` as one call of the renderer ([`Device::enter_host`] to
    /// [`Device::leave_host`]), giving the application its state back also when `f` panics
    /// (the panic then goes on): a caller that catches it keeps a working renderer.
    pub(crate) fn host_call<T>(&self, f: impl FnOnce() -> T) -> T {
        let saved = self.enter_host();
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
        self.leave_host(saved);
        result.unwrap_or_else(|panic| std::panic::resume_unwind(panic))
    }

    /// Starts a call of the renderer: clears GL errors the application left pending (they are
    /// not the renderer's), saves the application's GL state ([`super::host_state`]; or reads
    /// only its framebuffer: [`super::GlStateHandling::Reset`]) and sets what the renderer
    /// assumes, after waiting for its turn where calls on several
    /// threads take turns ([`super::driver_turns`]); `None` inside a call already started.
    /// Pair it with [`Device::leave_host`] in a way a panic cannot skip
    /// ([`Device::host_call`]).
    pub(crate) fn enter_host(&self) -> Option<HostEntry> {
        let depth = self.host_depth.get();
        self.host_depth.set(depth + 1);
        (depth == 0).then(|| {
            // Given back here should the state save panic, else by the matching leave_host.
            let turn = self.turn();
            // The application may have bound any program, or set any attribute value, since
            // the last call; entering binds the renderer's own vertex array.
            self.call.forget(self.own_vertex_array.map(|(vao, _)| vao));
            self.clear_pending_errors();
            let handling = self.state_handling.get();
            let saved = HostEntry::enter(&self.gl, &self.host, self.own_vertex_array, handling);
            self.host_framebuffer.set(saved.draw_framebuffer());
            turn.keep();
            saved
        })
    }

    /// What calls do with the application's state from the next one on.
    pub(crate) fn set_state_handling(&self, handling: super::GlStateHandling) {
        self.state_handling.set(handling);
    }

    pub(crate) fn state_handling(&self) -> super::GlStateHandling {
        self.state_handling.get()
    }

    /// Calls save the application's state and give it back (the default handling).
    fn saves_state(&self) -> bool {
        self.state_handling.get() == super::GlStateHandling::SaveAndRestore
    }

    /// A frame is drawn into the application's framebuffer: where the call did not save the
    /// state, this points its draw buffers at its attachment 0 alone (saving does so on entry,
    /// and gives the list back).
    pub(crate) fn draw_into_host_framebuffer(&self) {
        if !self.saves_state() {
            let target = self.host_framebuffer();
            super::host_reset::draw_into_attachment_0(&self.gl, &self.host, target);
        }
    }

    /// The framebuffer the application had bound for drawing when this call started (`None`:
    /// the default one), as the state save read it: where [`Renderer::render`] draws.
    ///
    /// [`Renderer::render`]: crate::Renderer::render
    pub(crate) fn host_framebuffer(&self) -> Option<glow::Framebuffer> {
        self.host_framebuffer.get()
    }

    /// Ends a call started by [`Device::enter_host`], giving the application its state back.
    pub(crate) fn leave_host(&self, saved: Option<HostEntry>) {
        self.host_depth.set(self.host_depth.get().saturating_sub(1));
        if let Some(saved) = saved {
            // Given back once the state is, or should giving it back panic.
            let _turn = super::driver_turns::Turn::held(self.takes_turns);
            // Before the state goes back: that switches the game's polygon offset on again.
            self.depth_bias.leave(&self.gl);
            saved.leave(&self.gl, &self.host, self.own_vertex_array);
            self.call.forget(None);
        }
    }

    /// This thread's turn, for GL work outside a renderer call (freeing the renderer's
    /// objects), where calls take turns ([`super::driver_turns`]); held until dropped.
    pub(crate) fn turn(&self) -> super::driver_turns::Turn {
        super::driver_turns::Turn::take_if(self.takes_turns)
    }

    /// Whether a call of the renderer is under way (what it binds is known only then).
    fn in_call(&self) -> bool {
        self.host_depth.get() > 0
    }

    /// Drains the GL errors pending when a call starts, saying so once: otherwise the first
    /// check of the call would report the application's error as the renderer's.
    fn clear_pending_errors(&self) {
        let first = self.drain_errors();
        if first == glow::NO_ERROR {
            return;
        }
        if first == glow::CONTEXT_LOST {
            // Not the application's: the call's first check reports it.
            self.lost.set(true);
            return;
        }
        let message = format!(
            "{} (0x{first:04x}) was pending when the renderer was called: the application's, \
             cleared so that it is not taken for the renderer's",
            error_name(first)
        );
        if self.warned_pending_error.replace(true) {
            log::debug!("{message}");
        } else {
            log::warn!("{message} (said once; later ones are logged at debug level)");
        }
    }

    /// Deletes the device's own objects, its vertex array and witness (with the renderer's
    /// other objects, in its context).
    pub(crate) fn delete_own_objects(&mut self) {
        if let Some((vao, v)) = self.own_vertex_array.take() {
            v.delete(&self.gl, vao);
        }
        if let Some(witness) = self.witness.take() {
            witness.delete(&self.gl);
        }
    }

    /// `lab`: from now on, every [`Device::check`] whose description contains `name` fails as if
    /// the driver had run out of memory there (`None`: none), so tests can reach the error
    /// paths of uploads and allocations that a real driver fails only under memory pressure.
    #[cfg(feature = "lab")]
    pub fn fail_checks_naming(&self, name: Option<&'static str>) {
        self.failing_checks.set(name);
    }

    /// GL objects alive now (created and not yet deleted by this crate).
    pub fn live_objects(&self) -> LiveObjects {
        self.live.get()
    }

    /// Counts `n` programs built by another device on this context as this one's (a negative
    /// `n`: handed to another), for `Renderer::adopt_programs` (with `lab`).
    pub(crate) fn count_handed_programs(&self, n: i64) {
        self.count(|l| l.programs += n);
    }

    /// Counts one draw call.
    pub(crate) fn count_draw_call(&self) {
        self.draw_calls.set(self.draw_calls.get() + 1);
    }

    /// Draw calls made so far (a frame's: the difference across it).
    pub(crate) fn draw_calls(&self) -> u64 {
        self.draw_calls.get()
    }

    fn count(&self, f: impl FnOnce(&mut LiveObjects)) {
        let mut l = self.live.get();
        f(&mut l);
        self.live.set(l);
    }

    tracked!(create_texture, delete_texture, glow::Texture, textures);
    tracked!(create_buffer, delete_buffer, glow::Buffer, buffers);
    tracked!(
        create_framebuffer,
        delete_framebuffer,
        glow::Framebuffer,
        framebuffers
    );
    tracked!(
        create_renderbuffer,
        delete_renderbuffer,
        glow::Renderbuffer,
        renderbuffers
    );
    /// Whether meshes keep their arrays in vertex array objects of their own: where the
    /// renderer has one for its calls.
    pub(crate) fn mesh_vertex_arrays(&self) -> bool {
        self.own_vertex_array.is_some()
    }

    pub(crate) fn create_mesh_vertex_array(&self) -> Result<glow::VertexArray, GlError> {
        let (_, v) = self
            .own_vertex_array
            .ok_or_else(|| GlError::Create("no vertex arrays".into()))?;
        let vao = v.create(&self.gl).map_err(creation_failed)?;
        self.count(|l| l.vertex_arrays += 1);
        Ok(vao)
    }

    /// Deletes a mesh's vertex array; where it was bound, the renderer's own is bound instead
    /// (GL would bind none, which a desktop core context cannot draw or point arrays with).
    pub(crate) fn delete_mesh_vertex_array(&self, vao: glow::VertexArray) {
        let Some((own, v)) = self.own_vertex_array else {
            return;
        };
        v.delete(&self.gl, vao);
        self.count(|l| l.vertex_arrays -= 1);
        if self.call.vertex_array() == Some(vao) {
            self.call.forget_vertex_array();
            self.bind_vertex_array(own);
        }
    }

    /// Binds the renderer's own vertex array where it has one, for arrays that are no mesh's
    /// (a mesh's vertex array keeps its arrays).
    pub(crate) fn bind_own_vertex_array(&self) {
        if let Some((vao, _)) = self.own_vertex_array {
            self.bind_vertex_array(vao);
        }
    }

    /// Binds `vao`, unless this call already did.
    pub(crate) fn bind_vertex_array(&self, vao: glow::VertexArray) {
        if let Some((_, arrays)) = self.own_vertex_array {
            self.call
                .bind_vertex_array(&self.gl, arrays, vao, self.in_call());
        }
    }

    /// Sets the constant values of the attributes a mesh lacks (`needed`, bit `i`:
    /// `absent_attributes::ABSENT[i]`), each once a call unless a draw spent it.
    pub(crate) fn set_absent_values(&self, needed: u8) {
        self.call
            .set_absent_values(&self.gl, needed, self.in_call());
    }

    /// A mesh with arrays at those locations (`arrays`, the same bits) is to draw: their
    /// constants are set again before the next mesh that lacks them.
    pub(crate) fn forget_absent_values(&self, arrays: u8) {
        self.call.forget_absent_values(arrays);
    }

    /// Draws from now on `bias` depth-buffer steps toward the camera (`Material::depth_bias`).
    pub(crate) fn set_depth_bias(&self, bias: f32) {
        self.depth_bias.set(&self.gl, bias, self.saves_state());
    }

    /// A frame with a biased material starts: what the depth bias gives back is read now,
    /// before the frame's draws are queued.
    pub(crate) fn prepare_depth_bias(&self) {
        self.depth_bias.prepare(&self.gl, self.saves_state());
    }

    /// Counts a state call ([`StateCalls`]).
    pub(crate) fn count_state_call(&self, f: impl FnOnce(&mut StateCalls)) {
        self.call.count(f);
    }

    /// State calls made so far (a frame's: the difference across it).
    pub(crate) fn state_calls(&self) -> StateCalls {
        self.call.calls()
    }

    pub(crate) fn create_program(&self) -> Result<glow::Program, GlError> {
        let program = unsafe { self.gl.create_program() }.map_err(creation_failed)?;
        self.count(|l| l.programs += 1);
        Ok(program)
    }

    pub(crate) fn delete_program(&self, program: glow::Program) {
        self.call.forget_program(program);
        unsafe { self.gl.delete_program(program) };
        self.count(|l| l.programs -= 1);
    }

    /// Makes `program` current, unless this call already did.
    pub(crate) fn use_program(&self, program: glow::Program) {
        self.call.use_program(&self.gl, program, self.in_call());
    }

    /// The probed capabilities.
    pub fn caps(&self) -> &Caps {
        &self.caps
    }

    /// The capabilities, to play a device with other limits in a test.
    #[cfg(test)]
    pub(crate) fn caps_mut(&mut self) -> &mut Caps {
        &mut self.caps
    }

    /// The feature level in use.
    pub fn es(&self) -> EsVersion {
        self.caps.es
    }

    /// Sets the viewport.
    pub fn viewport(&self, x: i32, y: i32, width: i32, height: i32) {
        unsafe { self.gl.viewport(x, y, width, height) }
    }

    /// Clears colour and depth within `[x, y, width, height]` of the bound framebuffer only
    /// (a scissored clear; the scissor test is off again after it).
    pub fn clear_rect(&self, rect: [i32; 4], color: [f32; 4]) {
        self.clear_rect_of(rect, Some(color), true);
    }

    /// Clears the colour (where `color` is given) and the depth (where `depth`) of a rectangle
    /// of the bound framebuffer.
    pub fn clear_rect_of(
        &self,
        [x, y, width, height]: [i32; 4],
        color: Option<[f32; 4]>,
        depth: bool,
    ) {
        let mut bits = 0;
        unsafe {
            self.gl.enable(glow::SCISSOR_TEST);
            self.gl.scissor(x, y, width, height);
            if let Some(c) = color {
                self.gl.color_mask(true, true, true, true);
                self.gl.clear_color(c[0], c[1], c[2], c[3]);
                bits |= glow::COLOR_BUFFER_BIT;
            }
            if depth {
                self.gl.depth_mask(true);
                self.gl.clear_depth_f32(1.0);
                bits |= glow::DEPTH_BUFFER_BIT;
            }
            if bits != 0 {
                self.gl.clear(bits);
            }
            self.gl.disable(glow::SCISSOR_TEST);
        }
    }

    /// Clears colour and depth of the bound framebuffer.
    pub fn clear(&self, color: [f32; 4]) {
        unsafe {
            self.gl.color_mask(true, true, true, true);
            self.gl.depth_mask(true);
            self.gl.clear_color(color[0], color[1], color[2], color[3]);
            self.gl.clear_depth_f32(1.0);
            self.gl
                .clear(glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT);
        }
    }

    /// Clears only the colour of the bound framebuffer (its depth, if any, is kept).
    pub fn clear_color_only(&self, color: [f32; 4]) {
        unsafe {
            self.gl.color_mask(true, true, true, true);
            self.gl.clear_color(color[0], color[1], color[2], color[3]);
            self.gl.clear(glow::COLOR_BUFFER_BIT);
        }
    }

    /// Blocks until the GPU has finished all submitted work (wall-clock frame timing).
    pub fn finish(&self) {
        unsafe { self.gl.finish() }
    }

    /// The framebuffer bound now (`None`: the default one, a window's back buffer).
    pub fn bound_framebuffer(&self) -> Option<glow::Framebuffer> {
        unsafe { self.gl.get_parameter_framebuffer(glow::FRAMEBUFFER_BINDING) }
    }

    /// The error a `glCheckFramebufferStatus` of `what` that gave `status` left pending: a
    /// status of 0 is the call's own failure (as on a lost context), not a verdict.
    pub(crate) fn check_status_call(&self, status: u32, what: &str) -> Result<(), GlError> {
        match status {
            0 => self.check(&format!("checking {what}")),
            _ => Ok(()),
        }
    }

    /// The error of a framebuffer `what` whose `glCheckFramebufferStatus` gave `status`, not
    /// complete ([`Device::check_status_call`]'s where the call itself failed).
    pub(crate) fn incomplete_framebuffer(&self, what: String, status: u32) -> GlError {
        match self.check_status_call(status, &what) {
            Err(e) => e,
            Ok(()) => GlError::FramebufferIncomplete { what, status },
        }
    }

    /// `glCheckFramebufferStatus` of the bound framebuffer.
    pub(crate) fn bound_framebuffer_status(&self) -> u32 {
        unsafe { self.gl.check_framebuffer_status(glow::FRAMEBUFFER) }
    }

    /// The first pending GL error (or `NO_ERROR`), with the queue drained: at most one flag
    /// per error kind is pending, so a few reads empty it (bounded all the same, for a driver
    /// that keeps reporting a lost context).
    pub(crate) fn drain_errors(&self) -> u32 {
        drain_errors(&self.gl)
    }

    /// Binds `fbo` (`None`: the default framebuffer).
    pub fn bind_framebuffer(&self, fbo: Option<glow::Framebuffer>) {
        unsafe { self.gl.bind_framebuffer(glow::FRAMEBUFFER, fbo) }
    }

    /// Copies the buffers of `mask` (`glow::COLOR_BUFFER_BIT`, `DEPTH_BUFFER_BIT`) of the
    /// `size` pixels at the corner of framebuffer `from` into `into` (`None`: the default
    /// one) at `to`, nearest (ES 3.0: a multisampled source is resolved, and only onto the
    /// corner); leaves `into` bound.
    pub fn blit(
        &self,
        from: glow::Framebuffer,
        into: Option<glow::Framebuffer>,
        (width, height): (u32, u32),
        to: [u32; 2],
        mask: u32,
    ) {
        let (w, h) = (width as i32, height as i32);
        let (x, y) = (to[0] as i32, to[1] as i32);
        unsafe {
            self.gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(from));
            self.gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, into);
            self.gl
                .blit_framebuffer(0, 0, w, h, x, y, x + w, y + h, mask, glow::NEAREST);
        }
        self.bind_framebuffer(into);
    }

    /// Binds the default framebuffer (a window's back buffer).
    pub fn bind_default_framebuffer(&self) {
        unsafe { self.gl.bind_framebuffer(glow::FRAMEBUFFER, None) }
    }

    /// Returns the first pending GL error as [`GlError::Driver`], draining the queue.
    pub fn check(&self, what: &str) -> Result<(), GlError> {
        #[cfg(feature = "lab")]
        if self
            .failing_checks
            .get()
            .is_some_and(|name| what.contains(name))
        {
            self.drain_errors();
            return Err(GlError::OutOfMemory(format!(
                "the driver reported GL_OUT_OF_MEMORY after {what} (injected)"
            )));
        }
        let code = self.drain_errors();
        if code == glow::CONTEXT_LOST {
            self.lost.set(true);
        }
        match code {
            _ if self.lost.get() => Err(GlError::ContextLost(what.to_string())),
            glow::NO_ERROR => Ok(()),
            code => Err(driver_error(code, what)),
        }
    }
}

/// Debug builds check `glGetError` after the wrapped step and return its error from the
/// enclosing function; release builds compile it out (a frame's own checks still run via
/// [`Device::check`]: a few a frame, none per draw, and per upload only where one allocates;
/// `tools/tests/round_trips.rs`).
macro_rules! gl_check {
    ($device:expr, $what:expr) => {
        #[cfg(debug_assertions)]
        $device.check($what)?;
    };
}
pub(crate) use gl_check;

/// Clears the context's pending GL errors (at most 17: a lost context may report errors
/// forever) and returns the first, or `GL_CONTEXT_LOST` where any was (GL reports pending
/// errors in any order, and a lost context says so once), or `NO_ERROR`.
fn drain_errors(gl: &glow::Context) -> u32 {
    let first = unsafe { gl.get_error() };
    if first == glow::NO_ERROR || first == glow::CONTEXT_LOST {
        return first;
    }
    for _ in 0..16 {
        match unsafe { gl.get_error() } {
            glow::NO_ERROR => break,
            glow::CONTEXT_LOST => return glow::CONTEXT_LOST,
            _ => {}
        }
    }
    first
}

/// Name of a `glCheckFramebufferStatus` result.
pub fn framebuffer_status_name(status: u32) -> &'static str {
    match status {
        glow::FRAMEBUFFER_INCOMPLETE_ATTACHMENT => {
            "GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT (an attachment the driver could not make, \
             as when it runs out of memory at this size)"
        }
        glow::FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT => {
            "GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT"
        }
        glow::FRAMEBUFFER_INCOMPLETE_DIMENSIONS => "GL_FRAMEBUFFER_INCOMPLETE_DIMENSIONS",
        glow::FRAMEBUFFER_INCOMPLETE_MULTISAMPLE => "GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE",
        glow::FRAMEBUFFER_UNSUPPORTED => "GL_FRAMEBUFFER_UNSUPPORTED",
        // What the check returns where it fails itself (GL ES 3.2, 9.4.2).
        0 => "no status: the check itself failed (a GL error, as in a lost or invalid context)",
        _ => "an unknown status",
    }
}

/// The error a pending `glGetError` `code` after `what` is: running out of memory and a lost
/// context by name, since a caller does something else about each.
pub(crate) fn driver_error(code: u32, what: &str) -> GlError {
    match code {
        glow::OUT_OF_MEMORY => {
            GlError::OutOfMemory(format!("the driver reported GL_OUT_OF_MEMORY after {what}"))
        }
        glow::CONTEXT_LOST => GlError::ContextLost(what.to_string()),
        _ => GlError::Driver {
            what: what.to_string(),
            name: error_name(code),
            code,
        },
    }
}

/// Name of a `glGetError` code.
pub fn error_name(code: u32) -> &'static str {
    match code {
        glow::CONTEXT_LOST => "GL_CONTEXT_LOST",
        glow::INVALID_ENUM => "GL_INVALID_ENUM",
        glow::INVALID_VALUE => "GL_INVALID_VALUE",
        glow::INVALID_OPERATION => "GL_INVALID_OPERATION",
        glow::INVALID_FRAMEBUFFER_OPERATION => "GL_INVALID_FRAMEBUFFER_OPERATION",
        glow::OUT_OF_MEMORY => "GL_OUT_OF_MEMORY",
        _ => "unknown GL error",
    }
}

#[cfg(test)]
mod tests;
