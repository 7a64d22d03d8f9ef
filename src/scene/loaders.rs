//! The model and scene-file loaders that cargo features build: one table of what each reads
//! and its feature, for the refusal of a file whose loader this build left out.

use std::path::Path;

use super::error::SceneError;

/// A file loader that a cargo feature builds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Loader {
    Obj,
    Gltf,
    SceneFile,
}

impl Loader {
    /// The loader of files with this extension (lower case, no dot).
    pub(crate) fn for_extension(ext: &str) -> Option<Loader> {
        match ext {
            "obj" => Some(Loader::Obj),
            "gltf" | "glb" => Some(Loader::Gltf),
            "json" => Some(Loader::SceneFile),
            _ => None,
        }
    }

    /// Whether this build of the crate has the loader.
    pub(crate) fn built(self) -> bool {
        match self {
            Loader::Obj => cfg!(feature = "obj"),
            Loader::Gltf => cfg!(feature = "gltf"),
            Loader::SceneFile => cfg!(feature = "scene-files"),
        }
    }

    /// The refusal of `path`, a file this loader reads, in a build without it.
    pub(crate) fn left_out(self, path: &Path) -> SceneError {
        let (kind, feature) = match self {
            Loader::Obj => ("an OBJ model", "obj"),
            Loader::Gltf => ("a glTF model", "gltf"),
            Loader::SceneFile => ("a JSON scene file", "scene-files"),
        };
        SceneError::NotBuilt {
            path: path.to_path_buf(),
            kind,
            feature,
        }
    }
}
