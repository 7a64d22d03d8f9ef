//! # manylight
//!
//! Thousands of dynamic point and spot lights on OpenGL ES 2.0 and 3.0, mobile first: lights
//! are assigned to a cascaded cluster grid on the CPU every frame (every frame in which
//! something moved) and uploaded as textures.
//!
//! ## Start here
//!
//! - A GL context: your own current one as a [`glow::Context`], or a [`HeadlessContext`] (EGL,
//!   no window; keep it alive as long as the renderer).
//! - A [`Renderer`] on it: [`Renderer::render`] into the bound framebuffer (a game's),
//!   [`Renderer::render_reusing`] the same without allocating per frame,
//!   [`Renderer::render_offscreen`] into an image; [`Renderer::set_method`] picks forward,
//!   tiled, clustered (the default), deferred or auto; [`Renderer::warm_up`] builds a scene's
//!   shaders before its first frame.
//! - A [`Scene`]: [`builtin_scene`] or [`load_scene`] (OBJ, glTF, JSON scene files, each a
//!   cargo feature on by default, as are the texture decoders: README, "Embedding";
//!   [`load_scene_with`] and [`LoadOptions`] let a trusted model read outside its folder;
//!   `load_gltf_from_memory` a GLB held in memory, such as an Android APK asset), or built
//!   in code with [`Scene::add_material`], [`MeshBuilder`], [`Scene::add_object`],
//!   [`Light::point`] and [`Light::spot`]; [`Scene::set_time`] poses moving lights
//!   ([`motion`]).
//! - [`RenderOptions`] for the output (tone map, exposure, MSAA, grid) and [`FrameStats`] for
//!   what a frame did.
//!
//! A headless render:
//!
//! ```no_run
//! use manylight::{builtin_scene, EsVersion, HeadlessContext, RandomLights, Renderer, RenderOptions};
//! let ctx = HeadlessContext::new(EsVersion::Es3)?;
//! let mut renderer = Renderer::new(ctx.load_gl()?, EsVersion::Es3)?;
//! let scene = builtin_scene("courtyard", Some(RandomLights { count: 256, seed: 7 }))?;
//! let (image, stats) = renderer.render_offscreen(&scene, 256, 144, &RenderOptions::default())?;
//! image.save("out.png")?;
//! println!("{} ms", stats.time.frame_ms);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! The code's layers and the frame's stages: docs/architecture.md in the repository.
#![deny(unsafe_code)]
#![warn(missing_docs)]

// The internal modules: public with the `lab` feature (for manylight-tools, the tests and
// benchmarks, no stability promise), private otherwise. Each declared twice rather than by a
// macro: rustfmt does not follow modules declared inside a macro, and left them unformatted.
#[cfg(feature = "lab")]
pub mod cluster;
#[cfg(not(feature = "lab"))]
#[allow(dead_code, unused_imports)]
mod cluster;
#[cfg(feature = "lab")]
pub mod error;
#[cfg(not(feature = "lab"))]
#[allow(dead_code, unused_imports)]
mod error;
#[cfg(feature = "lab")]
pub mod gl;
#[cfg(not(feature = "lab"))]
#[allow(dead_code, unused_imports)]
mod gl;
#[cfg(feature = "lab")]
pub mod gpu_scene;
#[cfg(not(feature = "lab"))]
#[allow(dead_code, unused_imports)]
mod gpu_scene;
#[cfg(feature = "lab")]
pub mod methods;
#[cfg(not(feature = "lab"))]
#[allow(dead_code, unused_imports)]
mod methods;
#[cfg(feature = "lab")]
pub mod metrics;
#[cfg(not(feature = "lab"))]
#[allow(dead_code, unused_imports)]
mod metrics;
#[cfg(feature = "lab")]
pub mod options;
#[cfg(not(feature = "lab"))]
#[allow(dead_code, unused_imports)]
mod options;
#[cfg(feature = "lab")]
pub mod renderer;
#[cfg(not(feature = "lab"))]
#[allow(dead_code, unused_imports)]
mod renderer;
#[cfg(feature = "lab")]
pub mod scene;
#[cfg(not(feature = "lab"))]
#[allow(dead_code, unused_imports)]
mod scene;

// The API a game uses: one path each, at the crate root.
pub use cluster::assign::AssignStats;
pub use cluster::grid::{Coverage, GridConfig, GridMeasure, GridMode};
pub use cluster::pack::LightEncoding;
pub use error::Error;
pub use gl::caps::Precision;
pub use gl::context::EglInfo;
pub use gl::gles_lib::select as select_gles_library;
pub use gl::{Caps, EsVersion, GlError, GlStateHandling, HeadlessContext, Restrictions};
pub use methods::Support;
pub use metrics::counts::LightCounts;
pub use metrics::spread::Spread;
pub use options::{
    Clear, CountKind, MeasureOptions, RenderOptions, ToneMap, MAX_EXPOSURE_EV, MAX_TIMED_FRAMES,
};
pub use renderer::{
    ContextStats, FrameStats, GridStats, LightStats, MemoryStats, Method, Renderer, TimeStats,
    WarmUp,
};
pub use scene::features::SceneFeatures;
#[cfg(feature = "gltf")]
pub use scene::load_gltf_from_memory;
pub use scene::meshbuild::MeshBuilder;
pub use scene::surface_maps::{MapTexture, SurfaceMaps, TextureTransform};
pub use scene::LoadReport;
pub use scene::{
    builtin::DEFAULT as DEFAULT_SCENE, builtin::NAMES as BUILTIN_SCENES, builtin_scene, load_scene,
    load_scene_with, Aabb, Camera, Cone, DirectionalLight, Light, LightKind, LoadOptions, Material,
    MaterialModel, Mesh, Object, Projection, RandomLights, Scene, SceneError, Texture,
    MAX_DEPTH_BIAS, MAX_DIRECTIONAL_LIGHTS,
};

/// How lights move over time: a [`Motion`](motion::Motion) per light, set with
/// [`Scene::animate_light`] and posed by [`Scene::set_time`].
pub mod motion {
    pub use crate::scene::motion::{
        Bob, Flicker, LightTrack, Motion, Orbit, OrbitAbout, Sweep, Wander,
    };
}

/// How a [`Texture`] is read: its wrapping and filtering ([`Texture::sampling`]; glTF samplers).
pub mod sampling {
    pub use crate::scene::texture::{Filter, Sampling, Wrap};
}

// The crates whose types the API takes and returns, so a game needs no second version of them.
pub use glam;
pub use glow;
pub use image;

/// The README's Rust examples, compiled as doc tests so they stay true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
