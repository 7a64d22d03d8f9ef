//! An MTL file's textures decoded once each, within what a model's textures may read
//! together (finding them by name: `texture_names.rs`).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::scene::input::{read_bounded_within, FileKind};
use crate::scene::texture_budget::{self, decode_texture_bytes, TextureBudget};
use crate::scene::Texture;

/// The textures one OBJ load decoded, by the file each is (`None`: failed, warned once), and
/// the bytes their files may still read together.
pub(super) struct TextureCache {
    loaded: HashMap<PathBuf, Option<Arc<Texture>>>,
    /// What the model's texture files may read together: as much as the OBJ itself, so many
    /// large distinct files (or one under many names) cannot read without end.
    read_left: u64,
}

impl Default for TextureCache {
    fn default() -> Self {
        TextureCache::with_read_limit(FileKind::Model.limit())
    }
}

impl TextureCache {
    /// None decoded yet, and `bytes` that their files may read together.
    pub(super) fn with_read_limit(bytes: u64) -> TextureCache {
        TextureCache {
            loaded: HashMap::new(),
            read_left: bytes,
        }
    }

    /// The texture at `path`, decoded on first use within `budget`; `warn` hears of a texture
    /// scaled down or left out.
    pub(super) fn load(
        &mut self,
        path: &Path,
        within: Option<&Path>,
        budget: &mut TextureBudget,
        warn: &mut dyn FnMut(String),
    ) -> Option<Arc<Texture>> {
        // By the file it is: a link in the folder or another letter case may name it again.
        let file = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        if let Some(t) = self.loaded.get(&file) {
            return t.clone();
        }
        let tex = match self.decode_texture(path, within, budget) {
            Ok(img) => {
                let name = path.display().to_string();
                let (image, scaled) = texture_budget::to_rgba8(img, &name);
                if let Some(w) = scaled {
                    warn(w);
                }
                Some(Arc::new(Texture::new(name, image)))
            }
            Err(why) => {
                warn(format!(
                    "texture {} {why}; using the flat colour",
                    path.display()
                ));
                None
            }
        };
        self.loaded.insert(file, tex.clone());
        tex
    }

    /// Decodes a texture file read within its size limit and what the model's textures may
    /// still read, refusing images whose decoded size would pass
    /// [`MAX_TEXTURE_SIDE`](super::MAX_TEXTURE_SIDE) on a side (a small PNG can claim
    /// 100 000² pixels), and images past what is left of `budget`. The error completes
    /// "texture NAME …".
    fn decode_texture(
        &mut self,
        path: &Path,
        within: Option<&Path>,
        budget: &mut TextureBudget,
    ) -> Result<image::DynamicImage, String> {
        let size = std::fs::metadata(path).map_or(0, |m| m.len());
        if size > self.read_left {
            return Err(format!(
                "is not read: the model's textures together pass the limit of {} bytes on \
                 what they may read",
                FileKind::Model.limit()
            ));
        }
        let bytes = read_bounded_within(path, FileKind::Texture, within)
            .map_err(|e| format!("could not be decoded ({e})"))?;
        self.read_left = self.read_left.saturating_sub(bytes.len() as u64);
        // The extension first: TGA has no magic bytes to guess from.
        decode_texture_bytes(&bytes, image::ImageFormat::from_path(path).ok(), budget)
    }
}
