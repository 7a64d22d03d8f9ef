//! GL entry points glow does not wrap, loaded through EGL: ES 2.0's
//! `glRenderbufferStorageMultisampleEXT` (`GL_EXT_multisampled_render_to_texture`), without
//! which that extension's colour attachment has no multisampled depth to go with it.
//!
//! glow takes the caller's GL context already loaded, so these come from the implementation
//! the context does: the one manylight loaded for its own contexts, else the system's (a
//! window toolkit's, Android's), through `eglGetProcAddress` for an extension's. A context made
//! otherwise (none here) simply finds none, and what needs the entry point is then unsupported
//! with that reason.
#![allow(unsafe_code)]

/// `glRenderbufferStorageMultisampleEXT(target, samples, internalformat, width, height)`.
pub type RenderbufferStorageMultisampleExt =
    unsafe extern "system" fn(target: u32, samples: i32, format: u32, width: i32, height: i32);

/// Loads `glRenderbufferStorageMultisampleEXT` from the current context's implementation
/// ([`super::gles_lib`]), if it is there.
pub fn renderbuffer_storage_multisample_ext() -> Option<RenderbufferStorageMultisampleExt> {
    let f = entry_point("glRenderbufferStorageMultisampleEXT")?;
    // SAFETY: the extension specifies this signature for the entry point of that name, and
    // the library stays loaded for the whole process (gles_lib).
    Some(unsafe {
        std::mem::transmute::<*const std::ffi::c_void, RenderbufferStorageMultisampleExt>(f)
    })
}

/// `glGetVertexAttribPointerv(index, pname, pointer)`.
pub type GetVertexAttribPointerv =
    unsafe extern "system" fn(index: u32, pname: u32, pointer: *mut *mut std::ffi::c_void);
/// `glVertexAttribPointer(index, size, type, normalized, stride, pointer)`.
pub type VertexAttribPointer = unsafe extern "system" fn(
    index: u32,
    size: i32,
    data_type: u32,
    normalized: u8,
    stride: i32,
    pointer: *const std::ffi::c_void,
);

/// The two core entry points that read and set an attribute array's pointer as a pointer:
/// glow offers the setter with a buffer offset only and no getter, and an ES 2.0 game's array
/// may be a client-side pointer.
#[derive(Clone, Copy)]
pub struct AttribPointerFns {
    /// `glGetVertexAttribPointerv`.
    pub get: GetVertexAttribPointerv,
    /// `glVertexAttribPointer`.
    pub set: VertexAttribPointer,
}

/// Loads [`AttribPointerFns`]; `None` when either is missing.
pub fn attrib_pointer_fns() -> Option<AttribPointerFns> {
    type Ptr = *const std::ffi::c_void;
    // SAFETY: each pointer is the core ES 2.0 entry point of that name, given the signature
    // the specification gives it; the library stays loaded for the whole process.
    unsafe {
        Some(AttribPointerFns {
            get: std::mem::transmute::<Ptr, GetVertexAttribPointerv>(core_entry_point(
                "glGetVertexAttribPointerv",
            )?),
            set: std::mem::transmute::<Ptr, VertexAttribPointer>(core_entry_point(
                "glVertexAttribPointer",
            )?),
        })
    }
}

/// `glVertexAttribDivisor{ANGLE,EXT,NV}(index, divisor)`: ES 2.0's instanced arrays.
pub type VertexAttribDivisor = unsafe extern "system" fn(index: u32, divisor: u32);

/// The instanced-arrays extensions of ES 2.0 and their divisor setters' names.
const DIVISOR_EXTENSIONS: [(&str, &str); 3] = [
    ("GL_ANGLE_instanced_arrays", "glVertexAttribDivisorANGLE"),
    ("GL_EXT_instanced_arrays", "glVertexAttribDivisorEXT"),
    ("GL_NV_instanced_arrays", "glVertexAttribDivisorNV"),
];

/// The divisor setter of the first instanced-arrays extension `has` lists whose entry point
/// loads; `None` without one (the arrays then have no divisors).
pub fn vertex_attrib_divisor_ext(has: impl Fn(&str) -> bool) -> Option<VertexAttribDivisor> {
    DIVISOR_EXTENSIONS
        .iter()
        .filter(|(extension, _)| has(extension))
        .find_map(|(_, name)| entry_point(name))
        // SAFETY: each extension specifies this signature for its entry point of that name,
        // and the library stays loaded for the whole process.
        .map(|f| unsafe { std::mem::transmute::<*const std::ffi::c_void, VertexAttribDivisor>(f) })
}

/// `glPolygonOffsetClampEXT(factor, units, clamp)` (`GL_EXT_polygon_offset_clamp`).
pub type PolygonOffsetClamp = unsafe extern "system" fn(factor: f32, units: f32, clamp: f32);

/// `glPolygonOffsetClampEXT` where `has` lists its extension and it loads.
pub fn polygon_offset_clamp_ext(has: impl Fn(&str) -> bool) -> Option<PolygonOffsetClamp> {
    let f =
        entry_point("glPolygonOffsetClampEXT").filter(|_| has("GL_EXT_polygon_offset_clamp"))?;
    // SAFETY: the extension specifies this signature for the entry point of that name, and
    // the library stays loaded for the whole process.
    Some(unsafe { std::mem::transmute::<*const std::ffi::c_void, PolygonOffsetClamp>(f) })
}

/// A core ES 2.0 entry point: from the implementation manylight loaded where it did (a
/// `HeadlessContext`'s), else from the system's `libGLESv2`, the one a window toolkit's context
/// (glutin's, Android's) draws through. Loading manylight's own EGL here instead would tie the
/// renderer's context checks to an EGL the application's context may not come from (under
/// `MANYLIGHT_GLES_LIB`, another implementation than the toolkit's).
fn core_entry_point(name: &str) -> Option<*const std::ffi::c_void> {
    if let Some(lib) = super::gles_lib::loaded() {
        return non_null(lib.proc_address(name));
    }
    static SYSTEM: std::sync::OnceLock<Option<libloading::Library>> = std::sync::OnceLock::new();
    let gles = SYSTEM.get_or_init(|| system_library(&["libGLESv2.so.2", "libGLESv2.so"]));
    symbol(gles.as_ref()?, name)
}

/// An extension's entry point, from the implementation as [`core_entry_point`] picks it, but
/// through `eglGetProcAddress`: an extension's functions need not be exported by `libGLESv2`.
pub(crate) fn entry_point(name: &str) -> Option<*const std::ffi::c_void> {
    if let Some(lib) = super::gles_lib::loaded() {
        return non_null(lib.proc_address(name));
    }
    type GetProcAddress =
        unsafe extern "system" fn(*const std::ffi::c_char) -> *const std::ffi::c_void;
    static GET_PROC_ADDRESS: std::sync::OnceLock<Option<GetProcAddress>> =
        std::sync::OnceLock::new();
    let get_proc_address = GET_PROC_ADDRESS
        .get_or_init(|| {
            let f = symbol(system_egl()?, "eglGetProcAddress")?;
            // SAFETY: EGL 1.4 specifies this signature for `eglGetProcAddress`.
            Some(unsafe { std::mem::transmute::<*const std::ffi::c_void, GetProcAddress>(f) })
        })
        .as_ref()?;
    let cname = std::ffi::CString::new(name).ok()?;
    // SAFETY: a NUL-terminated name, and the library stays loaded for the whole process.
    non_null(unsafe { get_proc_address(cname.as_ptr()) })
}

/// The EGL context current on this thread according to the system's `libEGL` (`Some(None)`:
/// none), or `None` when that library or its `eglGetCurrentContext` cannot be loaded. Only
/// meaningful for a context made through the system's EGL (a window toolkit's, Android's): a
/// context made through GLX, WGL or another EGL is not one it knows.
pub(crate) fn system_current_context() -> Option<Option<usize>> {
    type GetCurrentContext = unsafe extern "system" fn() -> *mut std::ffi::c_void;
    static GET_CURRENT_CONTEXT: std::sync::OnceLock<Option<GetCurrentContext>> =
        std::sync::OnceLock::new();
    let get_current_context = GET_CURRENT_CONTEXT
        .get_or_init(|| {
            let f = symbol(system_egl()?, "eglGetCurrentContext")?;
            // SAFETY: EGL 1.4 specifies this signature for `eglGetCurrentContext`.
            Some(unsafe { std::mem::transmute::<*const std::ffi::c_void, GetCurrentContext>(f) })
        })
        .as_ref()?;
    // SAFETY: no arguments; the library stays loaded for the whole process.
    let context = unsafe { get_current_context() };
    Some((!context.is_null()).then_some(context as usize))
}

/// The system's `libEGL`, loaded once and kept for the whole process (the entry points taken
/// from it stay valid).
fn system_egl() -> Option<&'static libloading::Library> {
    static EGL: std::sync::OnceLock<Option<libloading::Library>> = std::sync::OnceLock::new();
    EGL.get_or_init(|| system_library(&["libEGL.so.1", "libEGL.so"]))
        .as_ref()
}

/// The first of the system's `files` that loads.
fn system_library(files: &[&str]) -> Option<libloading::Library> {
    // SAFETY: the system's GL library, which the application's context already uses; loading
    // it again maps nothing new.
    files
        .iter()
        .find_map(|file| unsafe { libloading::Library::new(file) }.ok())
}

/// The address of `library`'s symbol `name`, if it has one.
fn symbol(library: &libloading::Library, name: &str) -> Option<*const std::ffi::c_void> {
    let cname = std::ffi::CString::new(name).ok()?;
    // SAFETY: only the symbol's address is read; the caller gives it its signature.
    let f = unsafe { library.get::<*const std::ffi::c_void>(cname.as_bytes_with_nul()) }.ok()?;
    non_null(*f)
}

fn non_null(f: *const std::ffi::c_void) -> Option<*const std::ffi::c_void> {
    (!f.is_null()).then_some(f)
}

/// `glGenQueriesEXT(n, ids)`.
pub type GenQueriesExt = unsafe extern "system" fn(n: i32, ids: *mut u32);
/// `glDeleteQueriesEXT(n, ids)`.
pub type DeleteQueriesExt = unsafe extern "system" fn(n: i32, ids: *const u32);
/// `glBeginQueryEXT(target, id)`.
pub type BeginQueryExt = unsafe extern "system" fn(target: u32, id: u32);
/// `glEndQueryEXT(target)`.
pub type EndQueryExt = unsafe extern "system" fn(target: u32);
/// `glGetQueryivEXT(target, pname, params)`.
pub type GetQueryivExt = unsafe extern "system" fn(target: u32, pname: u32, params: *mut i32);
/// `glGetQueryObjectui64vEXT(id, pname, params)`.
pub type GetQueryObjectUi64vExt = unsafe extern "system" fn(id: u32, pname: u32, params: *mut u64);

/// The entry points of `GL_EXT_disjoint_timer_query` (valid on ES 2.0 and 3.0 contexts).
#[derive(Clone, Copy)]
pub struct TimerQueryFns {
    /// `glGenQueriesEXT`.
    pub gen_queries: GenQueriesExt,
    /// `glDeleteQueriesEXT`.
    pub delete_queries: DeleteQueriesExt,
    /// `glBeginQueryEXT`.
    pub begin_query: BeginQueryExt,
    /// `glEndQueryEXT`.
    pub end_query: EndQueryExt,
    /// `glGetQueryObjectui64vEXT`.
    pub get_query_object_ui64v: GetQueryObjectUi64vExt,
    /// `glGetQueryivEXT`.
    pub get_queryiv: GetQueryivExt,
}

/// Loads `GL_EXT_disjoint_timer_query`'s entry points; `None` when any is missing.
pub fn timer_query_fns() -> Option<TimerQueryFns> {
    type Ptr = *const std::ffi::c_void;
    let get = entry_point;
    // SAFETY: each pointer is the entry point of that name, given the signature the
    // extension specifies for it; the library stays loaded for the whole process.
    unsafe {
        Some(TimerQueryFns {
            gen_queries: std::mem::transmute::<Ptr, GenQueriesExt>(get("glGenQueriesEXT")?),
            delete_queries: std::mem::transmute::<Ptr, DeleteQueriesExt>(get(
                "glDeleteQueriesEXT",
            )?),
            begin_query: std::mem::transmute::<Ptr, BeginQueryExt>(get("glBeginQueryEXT")?),
            end_query: std::mem::transmute::<Ptr, EndQueryExt>(get("glEndQueryEXT")?),
            get_query_object_ui64v: std::mem::transmute::<Ptr, GetQueryObjectUi64vExt>(get(
                "glGetQueryObjectui64vEXT",
            )?),
            get_queryiv: std::mem::transmute::<Ptr, GetQueryivExt>(get("glGetQueryivEXT")?),
        })
    }
}
