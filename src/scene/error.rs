//! Errors of the scene layer: file I/O, parsing and validation. Every validation error names
//! the field it is about (`lights[3].radius`, `materials[2] (stone).shininess`, …). What an
//! error quotes from a file (a path, a name, a key) has its control characters escaped and is
//! cut at a length ([`shown`]).

use std::path::PathBuf;

use super::shown;

/// What went wrong while building, loading or validating a scene.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// A value is out of its valid range (NaN, negative radius, outer < inner, …).
    #[error(
        "invalid value for `{}`: {}",
        shown::reason(field),
        shown::reason(reason)
    )]
    Invalid {
        /// Path of the offending field, e.g. `lights[3].radius`.
        field: String,
        /// Why it is rejected.
        reason: String,
    },
    /// A file could not be read.
    #[error("cannot read {}: {source}", shown::path(path))]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// An OBJ file could not be parsed.
    #[error("malformed OBJ {}: {}", shown::path(path), shown::reason(reason))]
    Obj {
        /// The file.
        path: PathBuf,
        /// What tobj or the loader reported.
        reason: String,
    },
    /// A glTF file (`.gltf` or `.glb`) is malformed or cannot be shown; `reason` names the
    /// part of the file at fault, e.g. `meshes[2].primitives[0]: index 9 out of range …`.
    #[error("malformed glTF {}: {}", shown::path(path), shown::reason(reason))]
    Gltf {
        /// The `.gltf` or `.glb` file.
        path: PathBuf,
        /// What is wrong, starting with the glTF path of the object at fault.
        reason: String,
    },
    /// A glTF file asks for what the renderer cannot do (an extension it requires, or
    /// nothing to draw); `reason` names it.
    #[error("unsupported glTF {}: {}", shown::path(path), shown::reason(reason))]
    GltfUnsupported {
        /// The `.gltf` or `.glb` file.
        path: PathBuf,
        /// What it asks for, e.g. `extensionsRequired lists KHR_draco_mesh_compression, …`.
        reason: String,
    },
    /// A scene file is not valid JSON for the scene schema.
    #[error("scene file {}: {}", shown::path(path), shown::reason(reason))]
    SceneFile {
        /// The file.
        path: PathBuf,
        /// serde's message (includes line, column and the unknown or missing field).
        reason: String,
    },
    /// A scene file's value is refused: `error` names the field and why (an [`Invalid`]
    /// value or an [`UnknownBuiltin`] name). A model file it names reports its own errors.
    ///
    /// [`Invalid`]: SceneError::Invalid
    /// [`UnknownBuiltin`]: SceneError::UnknownBuiltin
    #[error("scene file {}: {error}", shown::path(path))]
    InSceneFile {
        /// The file.
        path: PathBuf,
        /// What is wrong in it.
        error: Box<SceneError>,
    },
    /// A file whose type the loader does not read (by its extension).
    #[error("unsupported scene file type: {} (a scene is a built-in name, or a .obj, .gltf, .glb or .json file)", shown::path(path))]
    UnsupportedFile {
        /// The file.
        path: PathBuf,
    },
    /// A file of a kind whose loader this build of the crate left out (a cargo feature).
    #[error(
        "{} is {kind}, and this build of manylight reads none: its `{feature}` feature is off",
        shown::path(path)
    )]
    NotBuilt {
        /// The file.
        path: PathBuf,
        /// What kind of file it is (`an OBJ model`).
        kind: &'static str,
        /// The crate's feature that reads it.
        feature: &'static str,
    },
    /// A built-in scene name that does not exist.
    #[error("unknown built-in scene `{}` (available: {})", shown::name(name), available.join(", "))]
    UnknownBuiltin {
        /// What was asked for.
        name: String,
        /// The built-in scenes' names.
        available: &'static [&'static str],
    },
}

impl SceneError {
    /// `error`, met in scene file `path`, naming the file where `error` names none.
    pub(crate) fn in_scene_file(path: &std::path::Path, error: SceneError) -> Self {
        match error {
            SceneError::Invalid { .. } | SceneError::UnknownBuiltin { .. } => {
                SceneError::InSceneFile {
                    path: path.to_path_buf(),
                    error: Box::new(error),
                }
            }
            named => named,
        }
    }

    /// Shorthand for [`SceneError::Invalid`].
    pub fn invalid(field: impl Into<String>, reason: impl Into<String>) -> Self {
        SceneError::Invalid {
            field: field.into(),
            reason: reason.into(),
        }
    }
}
