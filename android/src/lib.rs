//! # manylight-android
//!
//! The Android app shell of manylight: a `NativeActivity` (android-activity, driven through
//! winit) that makes an EGL OpenGL ES context with glutin — ES 3.0, else ES 2.0 — builds a
//! [`manylight::Renderer`] on it and renders the built-in default scene with 1 024 seeded
//! random lights every frame (64 where the device runs only forward). A one-finger drag orbits
//! the camera around the scene centre.
//!
//! Lifecycle: the window surface exists only between `resumed` and `suspended`. On suspend
//! the surface and window are dropped and the context is made not current but kept, so the
//! renderer's GPU resources survive; on resume a new surface is made for the new native
//! window. If the context cannot be made current again, it is rebuilt with a fresh renderer.
//!
//! A frame or a resume that fails is logged (once while it fails the same way) and tried again
//! a second later ([`retry`]); a context lost while shown is rebuilt at once, unless it was lost
//! again within seconds ([`retry::Losses`]). Back leaves the app.
//!
//! Only [`orbit`] and [`retry`] are built on other targets (so they are unit-tested on the
//! host); everything else is Android-only.

pub mod orbit;
pub mod retry;

#[cfg(target_os = "android")]
mod app;

/// The entry point android-activity calls on its own thread once the activity is created.
/// However the shell ends, a panic included, it ends the process: winit makes one event loop a
/// process, and android-activity keeps the process for the next launch, which could not start
/// another and would close at once, launch after launch.
#[cfg(target_os = "android")]
#[no_mangle]
fn android_main(activity: android_activity::AndroidApp) {
    let ended = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| app::run(activity)));
    std::process::exit(i32::from(ended.is_err()));
}
