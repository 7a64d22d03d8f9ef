//! The only module that calls glow (and the only one allowed `unsafe`).
//!
//! * [`context`] — headless EGL contexts (khronos-egl, `libEGL.so.1` loaded at run time).
//! * [`gles_lib`] — which GLES implementation (the system's, or a folder's) the process loads.
//! * [`caps`] — what the context can do, probed once.
//! * [`device`] — a glow context plus its caps; frame-level calls (viewport, clear, finish).
//! * [`shader_source`] — GLSL assembly from `glsl/` (GL-free, so it is validated offline too).
//! * [`program`] — compile/link, uniforms, and the program cache.
//! * [`texture`], [`framebuffer`], [`mesh`], [`state`] — GPU resources and render state.
//!
//! Every GL object has an explicit `destroy(&Device)`; `Drop` only warns when it was never
//! called, because GL objects cannot be freed without the context at hand.

pub(crate) mod absent_attributes;
pub mod alloc;
pub(crate) mod bound_framebuffer;
pub(crate) mod bound_size;
pub(crate) mod call_state;
pub mod caps;
pub mod context;
mod context_watch;
pub(crate) mod depth_bias;
pub mod device;
pub(crate) mod driver_turns;
pub mod ext_fns;
pub mod framebuffer;
pub mod gbuffer;
pub mod gles_lib;
pub(crate) mod host_attributes;
pub(crate) mod host_draw_buffers;
pub(crate) mod host_entry;
pub(crate) mod host_reset;
pub(crate) mod host_state;
pub(crate) mod instances;
pub(crate) mod left_objects;
pub mod mesh;
pub mod multisample;
#[cfg(feature = "osmesa")]
pub mod osmesa;
pub mod precision_probe;
pub mod program;
pub mod shader_source;
pub(crate) mod shrink;
pub mod state;
pub(crate) mod target_size;
pub mod texture;
pub mod timer;
pub(crate) mod two_sizes;
pub mod uv_sets;
pub(crate) mod vertex_arrays;

pub use caps::Caps;
pub use context::HeadlessContext;
pub use device::Device;
pub use host_entry::GlStateHandling;

use serde::Serialize;

/// Restrictions a renderer puts on itself to play a weaker device than the driver it runs on
/// (the shader-level counterpart of `MESA_GLES_VERSION_OVERRIDE` and
/// `MESA_EXTENSION_OVERRIDE`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Restrictions {
    /// Behave as a device whose fragment stage has no `highp` (Mali-400 class, ES 2.0 only):
    /// the caps report none, and fragment shaders are compiled with every float at `mediump`,
    /// which llvmpipe evaluates in fp16 as such a device does.
    pub no_fragment_highp: bool,
    /// Behave as an ES 2.0 device without float textures (`GL_OES_texture_float` and
    /// `_half_float` unlisted, as `MESA_EXTENSION_OVERRIDE` removes them): the caps report
    /// none, so light records are packed in RGBA8 and every method says so.
    pub no_float_textures: bool,
}

/// The OpenGL ES feature level the renderer targets. With [`EsVersion::Es2`] the renderer uses
/// ES 2.0 core plus probed extensions and compiles GLSL ES 1.00, even on a driver that returns
/// a 3.x context.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum EsVersion {
    /// OpenGL ES 2.0, GLSL ES 1.00.
    #[serde(rename = "2.0")]
    Es2,
    /// OpenGL ES 3.0, GLSL ES 3.00.
    #[serde(rename = "3.0")]
    #[default]
    Es3,
}

impl EsVersion {
    /// Major version number.
    pub fn major(self) -> u32 {
        match self {
            EsVersion::Es2 => 2,
            EsVersion::Es3 => 3,
        }
    }

    /// From a major version number (2 or 3).
    pub fn from_major(major: u32) -> Option<Self> {
        match major {
            2 => Some(EsVersion::Es2),
            3 => Some(EsVersion::Es3),
            _ => None,
        }
    }
}

impl std::fmt::Display for EsVersion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ES {}.0", self.major())
    }
}

/// Errors of the GL layer.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GlError {
    /// libEGL could not be loaded or lacks EGL 1.4.
    #[error("cannot load libEGL.so.1 ({0}); install libegl1 and a driver such as libegl-mesa0")]
    EglLoad(String),
    /// The GLES implementation chosen with `--gles-lib` / `MANYLIGHT_GLES_LIB` could not be
    /// loaded (the folder, what it lacks, or the loader's reason).
    #[error("GLES implementation: {0}")]
    GlesLibrary(String),
    /// An EGL call failed.
    #[error("EGL {call} failed: {error}")]
    Egl {
        /// The EGL function.
        call: &'static str,
        /// EGL's error.
        error: String,
    },
    /// The requested ES version cannot be had: the driver made no such context, or the
    /// context the renderer was given is an older version.
    #[error("OpenGL {requested} is not available: {reason}")]
    VersionUnavailable {
        /// What was asked for.
        requested: EsVersion,
        /// What happened (EGL error or the version the driver returned).
        reason: String,
    },
    /// A shader failed to compile; carries everything needed to find the problem.
    #[error(
        "failed to compile {stage} shader `{shader}` ({dialect}, defines: [{defines}]):\n{log}\n--- source ---\n{numbered_source}"
    )]
    ShaderCompile {
        /// Shader name in `glsl/`.
        shader: String,
        /// `vertex` or `fragment`.
        stage: &'static str,
        /// Dialect it was assembled for.
        dialect: EsVersion,
        /// The variant's `#define`s.
        defines: String,
        /// The driver's info log.
        log: String,
        /// The assembled source with line numbers.
        numbered_source: String,
    },
    /// A program failed to link.
    #[error("failed to link program `{shader}` (defines: [{defines}]): {log}")]
    ProgramLink {
        /// Shader name.
        shader: String,
        /// The variant's `#define`s.
        defines: String,
        /// The driver's info log.
        log: String,
    },
    /// Shader assembly failed (unknown file or include).
    #[error("shader assembly: {0}")]
    ShaderSource(String),
    /// A required capability is missing.
    #[error("{0}")]
    Unsupported(String),
    /// [`HeadlessContext::new`] waited in vain where the implementation runs headless contexts
    /// on one thread at a time (ANGLE): another thread kept its contexts for `waited_s`
    /// seconds without dropping one. It may be asked again once they are gone.
    #[error(
        "this implementation (ANGLE) runs headless contexts on one thread at a time, and \
         another thread kept {} for {waited_s:.1} s without dropping one: drop them first, or \
         make this context on that thread",
        context::contexts_phrase(*.contexts)
    )]
    ContextsOnAnotherThread {
        /// The other thread's contexts alive.
        contexts: usize,
        /// Seconds waited without one being dropped.
        waited_s: f64,
    },
    /// A frame, or a render target made for one, larger than the context allows: past
    /// `GL_MAX_VIEWPORT_DIMS` (a frame into the game's framebuffer), or past
    /// `GL_MAX_TEXTURE_SIZE` or `GL_MAX_RENDERBUFFER_SIZE` (the renderer's own targets:
    /// offscreen, MSAA, deferred's G-buffer). Whichever call meets it, a game renders smaller.
    #[error(
        "{what} of {width}×{height} pixels is larger than this context allows: {limit} allows \
         {max_width}×{max_height}"
    )]
    TooLarge {
        /// What was being made (`a frame`, `an MSAA target`, …).
        what: &'static str,
        /// Width asked for.
        width: u32,
        /// Height asked for.
        height: u32,
        /// The GL limit it passes, by name.
        limit: &'static str,
        /// The widest the limit allows.
        max_width: u32,
        /// The tallest the limit allows.
        max_height: u32,
    },
    /// A framebuffer is incomplete (a driver says so of a target it could not allocate, too).
    #[error(
        "framebuffer incomplete for {what}: 0x{status:04x}, {}",
        device::framebuffer_status_name(*status)
    )]
    FramebufferIncomplete {
        /// The target being made, with its size (`a 16384×16384 target with 4 samples`).
        what: String,
        /// The status `glCheckFramebufferStatus` gave.
        status: u32,
    },
    /// The framebuffer the application bound cannot take the frame: incomplete, or without a
    /// depth buffer (the frame is drawn against one, unless with MSAA).
    #[error("the bound framebuffer cannot take the frame: {0}")]
    BoundFramebuffer(String),
    /// The driver reported an error.
    #[error("GL error {name} (0x{code:04x}) after {what}")]
    Driver {
        /// Which step.
        what: String,
        /// Decoded name.
        name: &'static str,
        /// Raw code.
        code: u32,
    },
    /// Object creation failed.
    #[error("GL object creation failed: {0}")]
    Create(String),
    /// Memory for an image, read-back or GL object could not be had: what it was for, and its
    /// size.
    #[error("out of memory: {0}")]
    OutOfMemory(String),
    /// No context is current on this thread (EGL says so, or, at `Renderer::new`, GL answers
    /// no query).
    #[error("no GL context is current on this thread: was the renderer's context (its HeadlessContext, or the application's own) dropped or released while the Renderer lived, or not yet made current at Renderer::new? Keep it alive and current on this thread as long as the renderer")]
    NotCurrent,
    /// A [`HeadlessContext`] used on a thread where it is not current.
    #[error("this context is not current on the calling thread: call make_current here first (after release_current on the thread where it is current)")]
    ContextNotCurrent,
    /// EGL says another context than the renderer's is current on this thread (also one that
    /// got the handle of the renderer's context, destroyed before it).
    #[error("another GL context than the renderer's is current on this thread: make the renderer's context current again before using it (its objects are that context's), or, where that context is gone, let the renderer go with Renderer::abandon")]
    OtherContext,
    /// The driver lost the context (`GL_CONTEXT_LOST`: a GPU reset, or a power event on a
    /// phone): nothing made in it works any more. Let the renderer go with
    /// [`Renderer::abandon`](crate::Renderer::abandon) and make a new one on a new context.
    #[error("the GL context was lost (GL_CONTEXT_LOST after {0}): let the renderer go with Renderer::abandon and make a new one on a new context")]
    ContextLost(String),
    /// Another context than the renderer's, or none, is current after the light assignment
    /// waited for rayon's pool on one of its workers, which runs other queued jobs meanwhile.
    #[error("another GL context than the renderer's, or none, is current after the light assignment waited for rayon's pool on this worker thread, where it ran other queued jobs: renderers called inside rayon jobs set RenderOptions::max_assign_threads to 1")]
    ContextChangedByPoolJob,
}
