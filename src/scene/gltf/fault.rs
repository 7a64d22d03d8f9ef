//! Why a glTF import failed, and the error a load reports for it.

use std::path::Path;

use crate::scene::SceneError;

/// What a load says when the glTF crate panics on a file.
pub(super) const PARSER_FAILED: &str =
    "the glTF parser (gltf crate) failed on this file; it is malformed";

/// Why an import failed: the file itself, what it asks for that the loader cannot do, the
/// caller's transform placing what is in it, or memory this process cannot allocate now.
pub(super) enum Fault {
    File(String),
    Unsupported(String),
    Placing(String),
    Memory(String),
}

impl Fault {
    /// The error of a load of `path` placed by the transform the caller calls
    /// `transform_field`.
    pub(super) fn into_error(self, path: &Path, transform_field: &str) -> SceneError {
        let path_buf = path.to_path_buf();
        match self {
            Fault::File(reason) => SceneError::Gltf {
                path: path_buf,
                reason,
            },
            Fault::Unsupported(reason) => SceneError::GltfUnsupported {
                path: path_buf,
                reason,
            },
            Fault::Memory(reason) => SceneError::Io {
                path: path_buf,
                source: std::io::Error::new(std::io::ErrorKind::OutOfMemory, reason),
            },
            Fault::Placing(reason) => {
                SceneError::invalid(transform_field, format!("{reason} (in {})", path.display()))
            }
        }
    }
}

impl From<String> for Fault {
    fn from(reason: String) -> Self {
        Fault::File(reason)
    }
}
