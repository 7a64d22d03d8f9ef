//! # manylight-android
//!
//! The Android app shell of manylight: a `NativeActivity` (android-activity, driven through
//! winit) that makes an EGL OpenGL ES context with glutin — ES 3.0, else ES 2.0 — builds a
//! [`manylight::Renderer`] on it and renders the built-in default scene with 1 024 seeded
//! random lights every frame. A one-finger drag orbits the camera around the scene centre.
//!
//! Lifecycle: the window surface exists only between `resumed` and `suspended`. On suspend
//! the surface and window are dropped and the context is made not current but kept, so the
//! renderer's GPU resources survive; on resume a new surface is made for the new native
//! window. If the context cannot be made current again, it is rebuilt with a fresh renderer.
//!
//! Only [`orbit`] is built on other targets (so it is unit-tested on the host); everything
//! else is Android-only.

pub mod orbit;

#[cfg(target_os = "android")]
mod app;

/// The entry point android-activity calls on its own thread once the activity is created.
#[cfg(target_os = "android")]
#[no_mangle]
fn android_main(activity: android_activity::AndroidApp) {
    app::run(activity);
}
