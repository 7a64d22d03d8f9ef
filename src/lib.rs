//! # manylight
//!
//! Thousands of dynamic point and spot lights on OpenGL ES 2.0 and 3.0, mobile first.
//!
//! Layers (arrows point down, nothing points up):
//!
//! ```text
//!  renderer ──► methods/ (forward, …)   one file per shading method + the METHODS table
//!           ├─► options, gpu_scene  what a frame is asked to do; the scene's uploaded meshes
//!           ├─► cluster/  GL-free CPU light data (texel packing, later the cluster grid)
//!           ├─► scene/    GL-free scenes: camera, lights, meshes, materials, OBJ, built-ins
//!           ├─► metrics/  image comparison
//!           └─► gl/       the only module that calls glow (and the only one with `unsafe`)
//! ```
//!
//! A minimal headless render:
//!
//! ```no_run
//! use manylight::{gl::HeadlessContext, EsVersion, Renderer, RenderOptions, scene};
//! let ctx = HeadlessContext::new(EsVersion::Es3)?;
//! let mut renderer = Renderer::new(ctx.load_gl(), EsVersion::Es3)?;
//! let scene = scene::builtin::build("courtyard", Some((256, 7)))?;
//! let (image, stats) = renderer.render_offscreen(&scene, 256, 144, &RenderOptions::default())?;
//! image.save("out.png")?;
//! println!("{} ms", stats.frame_ms);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod cluster;
pub mod error;
pub mod gl;
pub mod gpu_scene;
pub mod methods;
pub mod metrics;
pub mod options;
pub mod renderer;
pub mod scene;

pub use error::Error;

/// The README's Rust examples, compiled as doc tests so they stay true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
pub use gl::EsVersion;
pub use options::{CountKind, RenderOptions, ToneMap, MAX_TIMED_FRAMES};
pub use renderer::{FrameStats, Renderer};
