//! The crate-level error: one variant per layer, plus the renderer's own.

use crate::gl::GlError;
use crate::scene::SceneError;

/// Anything the library can fail with.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// From the GL layer (context, shaders, resources).
    #[error(transparent)]
    Gl(#[from] GlError),
    /// From the scene layer (files, parsing, validation).
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// A method name that is not in the method table.
    #[error(
        "unknown method `{}` (available: {available})",
        crate::scene::shown::name(name)
    )]
    UnknownMethod {
        /// What was asked for.
        name: String,
        /// The table's names.
        available: String,
    },
    /// A method this context cannot run, with what is missing.
    #[error("method `{method}` is not supported on this context: {reason} (methods that run here: {runnable})")]
    UnsupportedMethod {
        /// The method.
        method: String,
        /// What is missing.
        reason: String,
        /// The methods this context can run, comma-separated.
        runnable: String,
    },
    /// Multisampling asked for ([`RenderOptions::samples`](crate::RenderOptions::samples))
    /// that this context, method or output cannot do.
    #[error("{samples} samples per pixel (MSAA): {reason}")]
    Msaa {
        /// Samples asked for.
        samples: u32,
        /// Why not, and what would run.
        reason: String,
    },
    /// A [`RenderOptions`](crate::RenderOptions) field, or another argument of a render call
    /// (`render_light_counts`'s `kind`), the frame cannot be made from.
    #[error("invalid `{field}`: {reason}")]
    InvalidOption {
        /// The field or argument, as written in code (`exposure_ev`, `grid.footprint_px`,
        /// `kind`, …).
        field: &'static str,
        /// What it must be, and what it was.
        reason: String,
    },
    /// A frame of no pixels (a minimised window): nothing to draw, which a game skips.
    #[error("viewport {width}×{height} is empty")]
    EmptyViewport {
        /// The frame's width asked for.
        width: u32,
        /// Its height.
        height: u32,
    },
    /// A request the renderer cannot satisfy (too many lights for a method, light counts past
    /// what a target can hold, …). A frame too large for the context is
    /// [`GlError::TooLarge`].
    #[error("{0}")]
    Limit(String),
    /// Writing an output file failed.
    #[error("cannot write {path}: {reason}")]
    Output {
        /// The file.
        path: String,
        /// Why.
        reason: String,
    },
}
