//! An MTL file's textures: found, confined to the model's folder, decoded once each.
//!
//! Real MTL files name textures with other letter case than the file on disk, with Windows
//! backslashes, or with folders that were flattened when the model was shared. Resolution
//! tries, in order: the path as written (backslashes turned into `/`) relative to the MTL's
//! folder; the same path matched case-insensitively component by component; the bare file
//! name, case-insensitively, in the MTL's folder. A name leading out of the model's folder is
//! refused unless allowed, but its bare file name is still looked for in the folder (an
//! exporter's `C:\Users\…\wood.png`). Each name is looked up once a load, and the searches
//! beyond a name's spelling, which list folders, are bounded in number and depth.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::scene::access;
use crate::scene::input::{read_bounded, FileKind};
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
        budget: &mut TextureBudget,
        warn: &mut dyn FnMut(String),
    ) -> Option<Arc<Texture>> {
        // By the file it is: a link in the folder or another letter case may name it again.
        let file = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        if let Some(t) = self.loaded.get(&file) {
            return t.clone();
        }
        let tex = match self.decode_texture(path, budget) {
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
        let bytes = read_bounded(path, FileKind::Texture)
            .map_err(|e| format!("could not be decoded ({e})"))?;
        self.read_left = self.read_left.saturating_sub(bytes.len() as u64);
        // The extension first: TGA has no magic bytes to guess from.
        decode_texture_bytes(&bytes, image::ImageFormat::from_path(path).ok(), budget)
    }
}

/// Most texture names one OBJ load searches for beyond their spelling (in other letter case,
/// by bare file name): each search lists folders, so a library of thousands of names missing
/// from a folder of thousands of files would take minutes. Later names are found as written.
pub(super) const MAX_SEARCHED_NAMES: usize = 1024;

/// Most components of a name matched folder by folder in other letter case (a name through a
/// link to its own folder, `d/d/d/…/t.png`, would list a folder for each).
pub(super) const MAX_MATCHED_COMPONENTS: usize = 32;

/// Finds the textures one OBJ load's MTL statements name: each name once (materials often
/// share one), and at most [`MAX_SEARCHED_NAMES`] names searched beyond their spelling.
#[derive(Default)]
pub(super) struct TextureFinder {
    found: HashMap<String, Result<Option<PathBuf>, String>>,
    searched: usize,
}

impl TextureFinder {
    /// [`find_texture`], remembered by name.
    pub(super) fn find(
        &mut self,
        base_dir: &Path,
        name: &str,
        allow_outside: bool,
    ) -> Result<Option<PathBuf>, String> {
        if let Some(found) = self.found.get(name) {
            return found.clone();
        }
        let search = self.searched < MAX_SEARCHED_NAMES;
        let written = name.trim().replace('\\', "/");
        let as_written = access::join(base_dir, &written, allow_outside).is_ok_and(|p| p.is_file());
        self.searched += usize::from(!as_written);
        let found = find_texture_searching(base_dir, name, allow_outside, search);
        self.found.insert(name.to_string(), found.clone());
        found
    }
}

/// The file an MTL texture statement's file name (after its options) names, inside
/// `base_dir` (links resolved) unless `allow_outside`: `Ok(None)` when none is found, `Err`
/// with the refusal when the name leads out of the folder and its bare file name is not in
/// it either. A name of several words not found is tried by its last word too (a name
/// written after options the MTL reader does not know).
#[cfg(test)]
pub(super) fn find_texture(
    base_dir: &Path,
    name: &str,
    allow_outside: bool,
) -> Result<Option<PathBuf>, String> {
    find_texture_searching(base_dir, name, allow_outside, true)
}

/// [`find_texture`], looking beyond the name's spelling only with `search`.
fn find_texture_searching(
    base_dir: &Path,
    name: &str,
    allow_outside: bool,
    search: bool,
) -> Result<Option<PathBuf>, String> {
    let name = name.trim();
    let found = find_named(base_dir, name, allow_outside, search)?;
    match name.split_whitespace().last() {
        Some(last) if found.is_none() && last != name => {
            find_named(base_dir, last, allow_outside, search)
        }
        _ => Ok(found),
    }
}

/// [`find_texture_searching`] for the whole of `name`.
fn find_named(
    base_dir: &Path,
    name: &str,
    allow_outside: bool,
    search: bool,
) -> Result<Option<PathBuf>, String> {
    if name.is_empty() {
        return Ok(None);
    }
    let written = name.replace('\\', "/");
    within_folder(base_dir, &written, allow_outside, search, |_| {
        resolve_searching(base_dir, name, search)
    })
}

/// What `find` finds of `written` (`/` separating) from `base_dir`, given the path as joined,
/// where the name stays in the folder; else, unless `allow_outside`, its bare file name in
/// the folder (with `search`), or the refusal when it is not there (an exporter's absolute
/// path). What is found is checked with its links resolved and kept as found (its name in
/// messages stays the model's).
pub(super) fn within_folder(
    base_dir: &Path,
    written: &str,
    allow_outside: bool,
    search: bool,
    find: impl FnOnce(PathBuf) -> Option<PathBuf>,
) -> Result<Option<PathBuf>, String> {
    let found = match access::join(base_dir, written, allow_outside) {
        Ok(joined) => find(joined),
        Err(refusal) if search => Some(bare_file_in(base_dir, written).ok_or(refusal)?),
        Err(refusal) => return Err(refusal),
    };
    found
        .map(|p| access::resolve(base_dir, &p, allow_outside).map(|_| p))
        .transpose()
}

/// The file `name`'s last component names in `dir` (in any letter case), if it is one.
fn bare_file_in(dir: &Path, name: &str) -> Option<PathBuf> {
    let file_name = name
        .rsplit('/')
        .next()
        .filter(|n| !n.is_empty() && *n != "..")?;
    find_case_insensitive(dir, file_name).filter(|p| p.is_file())
}

/// Finds the file a texture name (an MTL statement's after its options, or a glTF URI,
/// either of which may hold spaces) means (see the module docs for the order).
pub fn resolve_texture(base_dir: &Path, name: &str) -> Option<PathBuf> {
    resolve_searching(base_dir, name, true)
}

/// [`resolve_texture`], looking beyond the name's spelling only with `search`.
fn resolve_searching(base_dir: &Path, name: &str, search: bool) -> Option<PathBuf> {
    let name = name.replace('\\', "/");
    let as_written = base_dir.join(&name);
    if as_written.is_file() {
        return Some(as_written);
    }
    if !search {
        return None;
    }
    let parts: Vec<&str> = name
        .split('/')
        .filter(|p| !p.is_empty() && *p != ".")
        .collect();
    let mut dir = base_dir.to_path_buf();
    let mut matched = parts.len() <= MAX_MATCHED_COMPONENTS;
    for part in parts {
        if !matched {
            break;
        }
        match find_case_insensitive(&dir, part) {
            Some(p) => dir = p,
            None => matched = false,
        }
    }
    if matched && dir.is_file() {
        return Some(dir);
    }
    bare_file_in(base_dir, &name)
}

/// The entry of `dir` named `name` in any letter case (`dir` empty: the working folder, which
/// a model named without a folder lies in).
fn find_case_insensitive(dir: &Path, name: &str) -> Option<PathBuf> {
    if name == ".." {
        return Some(dir.join(".."));
    }
    let lower = name.to_lowercase();
    let listed = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    std::fs::read_dir(listed)
        .ok()?
        .filter_map(Result::ok)
        .find(|e| e.file_name().to_string_lossy().to_lowercase() == lower)
        .map(|e| e.path())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resolves_case_and_backslashes() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("Textures")).unwrap();
        std::fs::write(dir.path().join("Textures").join("Brick.PNG"), b"x").unwrap();
        let want = dir.path().join("Textures").join("Brick.PNG");
        assert_eq!(
            resolve_texture(dir.path(), "textures\\brick.png"),
            Some(want.clone())
        );
        assert_eq!(
            resolve_texture(dir.path(), "TEXTURES/BRICK.png"),
            Some(want.clone())
        );
        assert_eq!(
            find_texture(dir.path(), "-unknown 1 Textures/Brick.PNG", false),
            Ok(Some(want))
        );
        std::fs::write(dir.path().join("Textures").join("Old Brick.png"), b"x").unwrap();
        assert_eq!(
            resolve_texture(dir.path(), "textures/old brick.PNG"),
            Some(dir.path().join("Textures").join("Old Brick.png"))
        );
        assert_eq!(resolve_texture(dir.path(), "missing.png"), None);
    }

    /// A model folder inside a temporary root holding `secret.png`.
    fn model_beside_a_secret_image() -> (tempfile::TempDir, PathBuf) {
        let root = tempfile::tempdir().unwrap();
        let model = root.path().join("model");
        std::fs::create_dir(&model).unwrap();
        image::RgbaImage::from_pixel(2, 2, image::Rgba([255, 0, 0, 255]))
            .save(root.path().join("secret.png"))
            .unwrap();
        (root, model)
    }

    #[test]
    fn textures_outside_the_models_folder_are_refused_unless_allowed() {
        let (root, model) = model_beside_a_secret_image();
        let secret = root.path().join("secret.png");
        let absolute = secret.to_str().unwrap().to_string();
        for name in ["../secret.png", "./../secret.png", absolute.as_str()] {
            let refusal = find_texture(&model, name, false).unwrap_err();
            assert!(
                refusal.contains("outside the model's folder"),
                "{name}: {refusal}"
            );
            assert!(
                find_texture(&model, name, true).unwrap().is_some(),
                "{name}"
            );
        }
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(&secret, model.join("link.png")).unwrap();
            let refusal = find_texture(&model, "link.png", false).unwrap_err();
            assert!(refusal.contains("a link leads out"), "{refusal}");
            assert!(find_texture(&model, "link.png", true).unwrap().is_some());
        }
        // An exporter's absolute path is still found by its file name in the folder.
        std::fs::write(model.join("wood.png"), b"x").unwrap();
        let found = find_texture(&model, "C:\\Users\\bob\\Wood.PNG", false).unwrap();
        assert_eq!(found, Some(model.join("wood.png")));
        let found = find_texture(&model, "/home/bob/maps/wood.png", false).unwrap();
        assert_eq!(found, Some(model.join("wood.png")));
        assert_eq!(find_texture(&model, "missing.png", false).unwrap(), None);
    }

    #[test]
    fn a_model_in_the_working_folder_finds_a_bare_file_name_there() {
        // The tests run in the package's folder, beside its Cargo.toml.
        let found = bare_file_in(Path::new(""), "C:/Users/bob/CARGO.toml");
        assert_eq!(found, Some(Path::new(".").join("Cargo.toml")));
    }

    #[test]
    fn flattened_folders_fall_back_to_the_file_name() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("wood.jpg"), b"x").unwrap();
        assert_eq!(
            resolve_texture(dir.path(), "C:\\models\\maps\\Wood.JPG"),
            Some(dir.path().join("wood.jpg"))
        );
    }
}
