//! How a device tells whether its own context is current: EGL's handle of the current
//! context, and a buffer of the device's own that only its context holds, since ANGLE and
//! SwiftShader give a new context the handle of one destroyed before it.
#![allow(unsafe_code)]

use std::sync::atomic::{AtomicU32, Ordering};

use glow::HasContext;

use super::GlError;

/// Which EGL says what context is current, and the device's own context there.
#[derive(Clone, Copy, Debug)]
pub(super) enum ContextWatch {
    /// The EGL manylight loaded (a `HeadlessContext`'s), which reported this context current
    /// at creation.
    Loaded(usize),
    /// The system's EGL, which reported this context current at creation: the application's
    /// context came from it (glutin's, Android's).
    System(usize),
    /// Neither can tell (GLX, WGL, another EGL): never checked.
    Unknown,
}

impl ContextWatch {
    /// The watch for the context current now.
    pub(super) fn of_current() -> ContextWatch {
        let loaded = super::gles_lib::current_context();
        if let Some(Some(context)) = loaded {
            return ContextWatch::Loaded(context);
        }
        // The EGL manylight loaded has none current (or none was loaded): the context may be a
        // toolkit's, from the system's EGL (a process that also made a `HeadlessContext`).
        match super::ext_fns::system_current_context() {
            Some(Some(context)) => ContextWatch::System(context),
            // No EGL context current while a context works: it is neither EGL's (GLX, WGL,
            // OSMesa), and watching one that has none would refuse every call.
            _ => ContextWatch::Unknown,
        }
    }

    /// Whether EGL names this watch's context current: `NotCurrent` where it names none,
    /// `OtherContext` where it names another, `Ok(true)` where it names this one's handle and
    /// `Ok(false)` where it cannot tell.
    pub(super) fn handle_is_current(self) -> Result<bool, GlError> {
        let (now, own) = match self {
            ContextWatch::Loaded(own) => (super::gles_lib::current_context(), own),
            ContextWatch::System(own) => (super::ext_fns::system_current_context(), own),
            ContextWatch::Unknown => return Ok(false),
        };
        match now {
            Some(None) => Err(GlError::NotCurrent),
            Some(Some(now)) if now != own => Err(GlError::OtherContext),
            Some(Some(_)) => Ok(true),
            None => Ok(false),
        }
    }
}

/// Witness sizes: odd byte counts, which no buffer of the renderer has (its vertex and index
/// data come in whole 16-bit indices or 32-bit floats), each renderer the next one.
const WITNESS_SIZES: u32 = 8192;
static NEXT_WITNESS: AtomicU32 = AtomicU32::new(0);

/// A buffer of a size the renderers made before it in this process did not take (up to
/// [`WITNESS_SIZES`] of them): a new context that got the device's context's EGL handle has
/// no buffer of that name and size, however many of its own it made.
pub(super) struct Witness {
    buffer: glow::Buffer,
    size: i32,
}

impl Witness {
    /// Makes the witness in the context current now, leaving its `GL_ARRAY_BUFFER` binding as
    /// it was.
    pub(super) fn new(gl: &glow::Context) -> Result<Witness, GlError> {
        let k = NEXT_WITNESS.fetch_add(1, Ordering::Relaxed) % WITNESS_SIZES;
        let size = 2 * k as i32 + 1;
        let buffer = unsafe { gl.create_buffer() }.map_err(GlError::Create)?;
        let witness = Witness { buffer, size };
        with_array_buffer(gl, buffer, true, || unsafe {
            gl.buffer_data_size(glow::ARRAY_BUFFER, size, glow::STATIC_DRAW)
        });
        // Without its storage (out of memory) it would say every later call is another
        // context's.
        if !witness.is_held(gl, true) {
            witness.delete(gl);
            return Err(GlError::OutOfMemory(format!(
                "the renderer's {size}-byte context witness buffer could not be made"
            )));
        }
        Ok(witness)
    }

    /// Whether the context current now holds this witness, leaving its `GL_ARRAY_BUFFER`
    /// binding as it was where `keep_binding`, else at 0 without reading it (a call that
    /// resets the application's state: `GlStateHandling::Reset`).
    pub(super) fn is_held(&self, gl: &glow::Context, keep_binding: bool) -> bool {
        // Binding a name that is no buffer of this context would make one.
        if !unsafe { gl.is_buffer(self.buffer) } {
            return false;
        }
        let size = with_array_buffer(gl, self.buffer, keep_binding, || unsafe {
            gl.get_buffer_parameter_i32(glow::ARRAY_BUFFER, glow::BUFFER_SIZE)
        });
        size == self.size
    }

    /// Deletes the witness (in its own context, which must be current).
    pub(super) fn delete(self, gl: &glow::Context) {
        unsafe { gl.delete_buffer(self.buffer) };
    }
}

/// Runs `f` with `buffer` bound to `GL_ARRAY_BUFFER`, then binds back what was bound (where
/// `keep`; else none).
fn with_array_buffer<T>(
    gl: &glow::Context,
    buffer: glow::Buffer,
    keep: bool,
    f: impl FnOnce() -> T,
) -> T {
    let before = match keep {
        true => unsafe { gl.get_parameter_buffer(glow::ARRAY_BUFFER_BINDING) },
        false => None,
    };
    unsafe { gl.bind_buffer(glow::ARRAY_BUFFER, Some(buffer)) };
    let result = f();
    unsafe { gl.bind_buffer(glow::ARRAY_BUFFER, before) };
    result
}
