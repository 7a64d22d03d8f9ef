//! Desktop OpenGL through OSMesa (Mesa's off-screen GL), loaded at run time from
//! `libOSMesa.so.8`: the capability matrix's "desktop GL" configuration. The renderer runs the
//! ES 3.0 feature level on it, with the same shaders assembled as GLSL 3.30 core.
#![allow(unsafe_code)]

use std::ffi::{c_char, c_int, c_void, CString};

use super::GlError;

type CreateContextAttribs = unsafe extern "C" fn(*const c_int, *mut c_void) -> *mut c_void;
type MakeCurrent = unsafe extern "C" fn(*mut c_void, *mut c_void, u32, c_int, c_int) -> u8;
type GetProcAddress = unsafe extern "C" fn(*const c_char) -> *const c_void;
type DestroyContext = unsafe extern "C" fn(*mut c_void);

// From GL/osmesa.h.
const OSMESA_FORMAT: c_int = 0x22;
const OSMESA_RGBA: c_int = 0x1908;
const OSMESA_DEPTH_BITS: c_int = 0x30;
const OSMESA_PROFILE: c_int = 0x33;
const OSMESA_CORE_PROFILE: c_int = 0x34;
const OSMESA_COMPAT_PROFILE: c_int = 0x35;
const OSMESA_CONTEXT_MAJOR_VERSION: c_int = 0x36;
const OSMESA_CONTEXT_MINOR_VERSION: c_int = 0x37;

/// A current OSMesa context. Keep it alive while anything uses its GL context.
pub struct OsMesaContext {
    _lib: libloading::Library,
    context: *mut c_void,
    get_proc: GetProcAddress,
    destroy: DestroyContext,
    // OSMesa renders the default framebuffer into this; the renderer draws into its own FBOs.
    _buffer: Vec<u8>,
}

impl OsMesaContext {
    /// Loads libOSMesa and makes a 3.3 core-profile context current on this thread.
    pub fn new() -> Result<OsMesaContext, GlError> {
        Self::with_profile(OSMESA_CORE_PROFILE, "core")
    }

    /// As [`new`](Self::new), a compatibility-profile context: what a toolkit gives by default.
    pub fn compatibility() -> Result<OsMesaContext, GlError> {
        Self::with_profile(OSMESA_COMPAT_PROFILE, "compatibility")
    }

    fn with_profile(profile: c_int, name: &str) -> Result<OsMesaContext, GlError> {
        let unavailable = |e: String| {
            GlError::Unsupported(format!("OSMesa is not available: {e}; install libosmesa6"))
        };
        let lib = unsafe { libloading::Library::new("libOSMesa.so.8") }
            .or_else(|_| unsafe { libloading::Library::new("libOSMesa.so") })
            .map_err(|e| unavailable(e.to_string()))?;
        // SAFETY: the symbol types are those of GL/osmesa.h.
        let (create, make_current, get_proc, destroy) = unsafe {
            let sym = |name: &[u8]| lib.get::<*const c_void>(name).map(|s| *s);
            (
                std::mem::transmute::<*const c_void, CreateContextAttribs>(
                    sym(b"OSMesaCreateContextAttribs\0").map_err(|e| unavailable(e.to_string()))?,
                ),
                std::mem::transmute::<*const c_void, MakeCurrent>(
                    sym(b"OSMesaMakeCurrent\0").map_err(|e| unavailable(e.to_string()))?,
                ),
                std::mem::transmute::<*const c_void, GetProcAddress>(
                    sym(b"OSMesaGetProcAddress\0").map_err(|e| unavailable(e.to_string()))?,
                ),
                std::mem::transmute::<*const c_void, DestroyContext>(
                    sym(b"OSMesaDestroyContext\0").map_err(|e| unavailable(e.to_string()))?,
                ),
            )
        };
        let attribs = [
            OSMESA_FORMAT,
            OSMESA_RGBA,
            OSMESA_DEPTH_BITS,
            24,
            OSMESA_PROFILE,
            profile,
            OSMESA_CONTEXT_MAJOR_VERSION,
            3,
            OSMESA_CONTEXT_MINOR_VERSION,
            3,
            0,
        ];
        // SAFETY: a zero-terminated attribute list, no share context.
        let context = unsafe { create(attribs.as_ptr(), std::ptr::null_mut()) };
        if context.is_null() {
            return Err(unavailable(format!(
                "OSMesaCreateContextAttribs refused a 3.3 {name} context"
            )));
        }
        let mut buffer = vec![0u8; 4];
        // SAFETY: a 1×1 RGBA8 buffer that lives as long as the context.
        let ok = unsafe { make_current(context, buffer.as_mut_ptr().cast(), 0x1401, 1, 1) };
        if ok == 0 {
            unsafe { destroy(context) };
            return Err(unavailable("OSMesaMakeCurrent failed".into()));
        }
        Ok(OsMesaContext {
            _lib: lib,
            context,
            get_proc,
            destroy,
            _buffer: buffer,
        })
    }

    /// A glow context for the current OSMesa context.
    pub fn load_gl(&self) -> glow::Context {
        unsafe {
            glow::Context::from_loader_function(|name| {
                let name = CString::new(name).expect("GL names have no NUL");
                (self.get_proc)(name.as_ptr())
            })
        }
    }
}

impl Drop for OsMesaContext {
    fn drop(&mut self) {
        // SAFETY: the context was created by this library and is destroyed once.
        unsafe { (self.destroy)(self.context) };
    }
}
