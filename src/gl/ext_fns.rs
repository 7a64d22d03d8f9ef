//! GL entry points glow does not wrap, loaded through EGL: ES 2.0's
//! `glRenderbufferStorageMultisampleEXT` (`GL_EXT_multisampled_render_to_texture`), without
//! which that extension's colour attachment has no multisampled depth to go with it.
//!
//! glow takes the caller's GL context already loaded, so these come from
//! `eglGetProcAddress` of the process's `libEGL`: where an ES 2.0 context comes from on
//! Android and Linux. A context made otherwise (none here) simply finds none, and MSAA on
//! ES 2.0 is then unsupported with that reason.
#![allow(unsafe_code)]

/// `glRenderbufferStorageMultisampleEXT(target, samples, internalformat, width, height)`.
pub type RenderbufferStorageMultisampleExt =
    unsafe extern "system" fn(target: u32, samples: i32, format: u32, width: i32, height: i32);

/// Loads `glRenderbufferStorageMultisampleEXT` from `libEGL`, if it is there.
pub fn renderbuffer_storage_multisample_ext() -> Option<RenderbufferStorageMultisampleExt> {
    type Egl = khronos_egl::DynamicInstance<khronos_egl::EGL1_4>;
    // Kept loaded for the whole process: the pointer it hands out must outlive every Device
    // (dropping the instance would unload the library it points into, were it the last user).
    static EGL: std::sync::OnceLock<Option<Egl>> = std::sync::OnceLock::new();
    let egl = EGL
        .get_or_init(|| {
            unsafe { Egl::load_required_from_filename("libEGL.so.1") }
                .or_else(|_| unsafe { Egl::load_required_from_filename("libEGL.so") })
                .ok()
        })
        .as_ref()?;
    let f = egl.get_proc_address("glRenderbufferStorageMultisampleEXT")?;
    // SAFETY: the extension specifies this signature for the entry point of that name, and
    // the library stays loaded (above).
    Some(unsafe {
        std::mem::transmute::<extern "system" fn(), RenderbufferStorageMultisampleExt>(f)
    })
}
