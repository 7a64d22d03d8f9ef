//! A model's texture names (an MTL file's, a glTF file's relative URIs): found, confined to
//! the model's folder.
//!
//! Real MTL files name textures with other letter case than the file on disk, with Windows
//! backslashes, or with folders that were flattened when the model was shared. Resolution
//! tries, in order: the path as written (backslashes turned into `/`) relative to the MTL's
//! folder; the same path matched case-insensitively component by component; both again from
//! the model's folder where the MTL lies in a folder of its own; the bare file name,
//! case-insensitively, in the MTL's folder, then in the model's. A name leading out of the
//! model's folder is refused unless allowed (a `..` that stays inside is taken out), but its
//! bare file name is still looked for (an exporter's `C:\Users\…\wood.png`). Each name is
//! looked up once a load, each folder listed once a load however many names are looked for in
//! it, and a name is matched folder by folder only so deep.

use std::collections::HashMap;
use std::ffi::OsString;
use std::path::{Path, PathBuf};

use crate::scene::access;

/// Most components of a name matched folder by folder in other letter case (a name through a
/// link to its own folder, `d/d/d/…/t.png`, would look into a folder for each); a deeper name
/// is still found as written or by its bare file name.
pub(super) const MAX_MATCHED_COMPONENTS: usize = 32;

/// The folders one load has listed, by the folder each is (links resolved): each is listed
/// once, however many names are looked for in it (a library of thousands of names missing
/// from a folder of thousands of files listed it for each, for minutes).
#[derive(Default)]
pub(crate) struct Listings {
    /// Per folder: each entry's name in lower case, and as it is.
    by_folder: HashMap<PathBuf, HashMap<String, OsString>>,
}

impl Listings {
    /// The entry of `dir` named `name` in any letter case (`dir` empty: the working folder,
    /// which a model named without a folder lies in); of two that differ only in case, the
    /// one the folder lists first. A folder whose real location is not inside `within` (a
    /// real folder; `None`: anywhere) is not listed: [`Found::Outside`].
    fn find(&mut self, dir: &Path, name: &str, within: Option<&Path>) -> Found {
        if name == ".." {
            return Found::Entry(dir.join(".."));
        }
        let listed = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        let Ok(folder) = std::fs::canonicalize(listed) else {
            return Found::Nothing;
        };
        if within.is_some_and(|root| !folder.starts_with(root)) {
            return Found::Outside;
        }
        let entries = self.by_folder.entry(folder).or_insert_with(|| {
            #[cfg(test)]
            FOLDERS_LISTED.with(|n| n.set(n.get() + 1));
            let mut entries = HashMap::new();
            for entry in std::fs::read_dir(listed).into_iter().flatten().flatten() {
                let file_name = entry.file_name();
                let lower = file_name.to_string_lossy().to_lowercase();
                entries.entry(lower).or_insert(file_name);
            }
            entries
        });
        match entries.get(&name.to_lowercase()) {
            Some(file_name) => Found::Entry(listed.join(file_name)),
            None => Found::Nothing,
        }
    }

    /// How many folders were listed.
    #[cfg(test)]
    pub(super) fn listed(&self) -> usize {
        self.by_folder.len()
    }
}

/// What [`Listings::find`] found in a folder.
enum Found {
    Entry(PathBuf),
    Nothing,
    /// The folder lies outside the one the search is confined to (a link leads out): it was
    /// not listed.
    Outside,
}

#[cfg(test)]
thread_local! {
    /// Folders listed on this thread by any [`Listings`], for tests of whole loads.
    pub(crate) static FOLDERS_LISTED: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// Finds the textures one OBJ load's MTL statements name: each name once (materials often
/// share one), each folder listed once.
#[derive(Default)]
pub(super) struct TextureFinder {
    /// By (the MTL's folder, the name).
    found: HashMap<(String, String), Result<Option<PathBuf>, String>>,
    pub(super) listings: Listings,
}

impl TextureFinder {
    /// The file an MTL texture statement's file name (after its options) names, from the
    /// MTL's folder `mtl_folder` (relative to `base_dir`, `/` separating; empty for the
    /// model's folder itself), inside `base_dir` (links resolved) unless `allow_outside`:
    /// `Ok(None)` when none is found, `Err` with the refusal when the name leads out of the
    /// folder and its bare file name is not in it either. A name of several words not found
    /// is tried by its last word too (a name written after options the MTL reader does not
    /// know). Remembered by folder and name.
    pub(super) fn find(
        &mut self,
        base_dir: &Path,
        mtl_folder: &str,
        name: &str,
        allow_outside: bool,
    ) -> Result<Option<PathBuf>, String> {
        let key = (mtl_folder.to_string(), name.to_string());
        if let Some(found) = self.found.get(&key) {
            return found.clone();
        }
        let found = self.find_anew(base_dir, mtl_folder, name.trim(), allow_outside);
        self.found.insert(key, found.clone());
        found
    }

    fn find_anew(
        &mut self,
        base_dir: &Path,
        mtl_folder: &str,
        name: &str,
        allow_outside: bool,
    ) -> Result<Option<PathBuf>, String> {
        let found = self.find_named(base_dir, mtl_folder, name, allow_outside)?;
        match name.split_whitespace().last() {
            Some(last) if found.is_none() && last != name => {
                self.find_named(base_dir, mtl_folder, last, allow_outside)
            }
            _ => Ok(found),
        }
    }

    /// [`TextureFinder::find`] for the whole of `name`: as written from the MTL's folder
    /// (or in other letter case), then from the model's where the MTL lies in a folder of
    /// its own (an exporter that wrote the OBJ's paths), then by its bare file name in the
    /// MTL's folder and the model's. The refusal, if any, is the MTL's path's.
    fn find_named(
        &mut self,
        base_dir: &Path,
        mtl_folder: &str,
        name: &str,
        allow_outside: bool,
    ) -> Result<Option<PathBuf>, String> {
        if name.is_empty() {
            return Ok(None);
        }
        let written = name.replace('\\', "/");
        let absolute = access::inside(&written) == Err(access::ABSOLUTE);
        let from_mtl = match mtl_folder {
            "" => written.clone(),
            _ if absolute => written.clone(),
            folder => format!("{folder}/{written}"),
        };
        let mut refusal = None;
        let checked = |p: PathBuf, refusal: &mut Option<String>| match access::resolve(
            base_dir,
            &p,
            allow_outside,
        ) {
            Ok(_) => Some(p),
            Err(r) => {
                refusal.get_or_insert(r);
                None
            }
        };
        let model_too = from_mtl != written;
        for (path, first) in [(from_mtl.as_str(), true), (written.as_str(), false)] {
            if !first && !model_too {
                break;
            }
            let relative = match access::join(base_dir, path, allow_outside) {
                Ok(_) => access::inside(path).unwrap_or(path.into()),
                Err(r) => {
                    if first {
                        refusal = Some(r);
                    }
                    continue;
                }
            };
            let matched = match_in(base_dir, &relative, allow_outside, &mut self.listings);
            let candidate = match matched {
                Some(Matched::File(p) | Matched::Outside(p)) => p,
                _ => continue,
            };
            let mut ignored = None;
            let why = if first { &mut refusal } else { &mut ignored };
            if let Some(found) = checked(candidate, why) {
                return Ok(Some(found));
            }
        }
        let mtl_dir = base_dir.join(mtl_folder);
        let folders = [Some(mtl_dir.as_path()), model_too.then_some(base_dir)];
        for dir in folders.into_iter().flatten() {
            if let Some(p) = bare_file_in(dir, &written, &mut self.listings) {
                if let Some(found) = checked(p, &mut refusal) {
                    return Ok(Some(found));
                }
            }
        }
        refusal.map_or(Ok(None), Err)
    }
}

/// What `find` finds of `written` (`/` separating) from `base_dir`, given the path as joined
/// and the name with any `..` inside the folder taken out, where the name stays in the
/// folder; else, unless `allow_outside`, its bare file name in the folder, or the refusal
/// when it is not there (an exporter's absolute path). What is found is checked with its
/// links resolved and kept as found (its name in messages stays the model's).
pub(super) fn within_folder(
    base_dir: &Path,
    written: &str,
    allow_outside: bool,
    listings: &mut Listings,
    find: impl FnOnce(PathBuf, &str, &mut Listings) -> Option<PathBuf>,
) -> Result<Option<PathBuf>, String> {
    let found = match access::join(base_dir, written, allow_outside) {
        Ok(joined) => {
            let relative = access::inside(written).unwrap_or(written.into());
            find(joined, &relative, listings)
        }
        Err(refusal) => Some(bare_file_in(base_dir, written, listings).ok_or(refusal)?),
    };
    found
        .map(|p| access::resolve(base_dir, &p, allow_outside).map(|_| p))
        .transpose()
}

/// The file `name`'s last component names in `dir` (in any letter case), if it is one.
fn bare_file_in(dir: &Path, name: &str, listings: &mut Listings) -> Option<PathBuf> {
    let file_name = name
        .rsplit('/')
        .next()
        .filter(|n| !n.is_empty() && *n != "..")?;
    // `dir` is the model's folder itself: no need to confine it to itself.
    match listings.find(dir, file_name, None) {
        Found::Entry(p) => p.is_file().then_some(p),
        Found::Nothing | Found::Outside => None,
    }
}

/// Finds the file a texture name (an MTL statement's after its options, or a glTF URI,
/// either of which may hold spaces) means (see the module docs for the order).
/// Links may lead anywhere (the caller checks where what is found lies).
pub fn resolve_texture(base_dir: &Path, name: &str) -> Option<PathBuf> {
    resolve_in(base_dir, name, true, &mut Listings::default())
}

/// [`resolve_texture`] with the folders `listings` has listed (one load's, so each folder is
/// listed once however many names it is searched for). Unless `allow_outside`, no folder
/// outside `base_dir` (links resolved) is listed: where a link in the name's folders leads
/// out, the name's bare file name in `base_dir`, or else the path up to that link, for the
/// caller's check of where it lies ([`access::resolve`]) to refuse by name.
pub(crate) fn resolve_in(
    base_dir: &Path,
    name: &str,
    allow_outside: bool,
    listings: &mut Listings,
) -> Option<PathBuf> {
    let name = name.replace('\\', "/");
    match match_in(base_dir, &name, allow_outside, listings)? {
        Matched::File(p) => Some(p),
        Matched::Outside(link) => bare_file_in(base_dir, &name, listings).or(Some(link)),
        Matched::Nothing => bare_file_in(base_dir, &name, listings),
    }
}

/// What [`match_in`] found of a name.
enum Matched {
    /// The file, as written or in other letter case.
    File(PathBuf),
    /// The path up to a link in the name's folders that leads out of the folder.
    Outside(PathBuf),
    Nothing,
}

/// The file `name` (`/` separating) names from `base_dir`, as written or matched in other
/// letter case folder by folder; `None` where the folder itself cannot be resolved.
fn match_in(
    base_dir: &Path,
    name: &str,
    allow_outside: bool,
    listings: &mut Listings,
) -> Option<Matched> {
    let as_written = base_dir.join(name);
    if as_written.is_file() {
        return Some(Matched::File(as_written));
    }
    let real_base = if allow_outside {
        None
    } else {
        let base = if base_dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            base_dir
        };
        Some(std::fs::canonicalize(base).ok()?)
    };
    let parts: Vec<&str> = name
        .split('/')
        .filter(|p| !p.is_empty() && *p != ".")
        .collect();
    if parts.len() > MAX_MATCHED_COMPONENTS {
        return Some(Matched::Nothing);
    }
    let mut dir = base_dir.to_path_buf();
    for part in parts {
        match listings.find(&dir, part, real_base.as_deref()) {
            Found::Entry(p) => dir = p,
            Found::Nothing => return Some(Matched::Nothing),
            Found::Outside => return Some(Matched::Outside(dir)),
        }
    }
    Some(if dir.is_file() {
        Matched::File(dir)
    } else {
        Matched::Nothing
    })
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
            TextureFinder::default().find(dir.path(), "", "-unknown 1 Textures/Brick.PNG", false),
            Ok(Some(want))
        );
        std::fs::write(dir.path().join("Textures").join("Old Brick.png"), b"x").unwrap();
        assert_eq!(
            resolve_texture(dir.path(), "textures/old brick.PNG"),
            Some(dir.path().join("Textures").join("Old Brick.png"))
        );
        assert_eq!(resolve_texture(dir.path(), "missing.png"), None);
    }

    /// A model folder inside a temporary root holding `secret.png` (found by name only, never
    /// decoded here).
    fn model_beside_a_secret_image() -> (tempfile::TempDir, PathBuf) {
        let root = tempfile::tempdir().unwrap();
        let model = root.path().join("model");
        std::fs::create_dir(&model).unwrap();
        std::fs::write(root.path().join("secret.png"), b"secret").unwrap();
        (root, model)
    }

    #[test]
    fn textures_outside_the_models_folder_are_refused_unless_allowed() {
        let (root, model) = model_beside_a_secret_image();
        let secret = root.path().join("secret.png");
        let absolute = secret.to_str().unwrap().to_string();
        for name in ["../secret.png", "./../secret.png", absolute.as_str()] {
            let refusal = TextureFinder::default()
                .find(&model, "", name, false)
                .unwrap_err();
            assert!(
                refusal.contains("outside the model's folder"),
                "{name}: {refusal}"
            );
            assert!(
                TextureFinder::default()
                    .find(&model, "", name, true)
                    .unwrap()
                    .is_some(),
                "{name}"
            );
        }
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(&secret, model.join("link.png")).unwrap();
            let refusal = TextureFinder::default()
                .find(&model, "", "link.png", false)
                .unwrap_err();
            assert!(refusal.contains("a link leads out"), "{refusal}");
            assert!(TextureFinder::default()
                .find(&model, "", "link.png", true)
                .unwrap()
                .is_some());
        }
        // An exporter's absolute path is still found by its file name in the folder.
        std::fs::write(model.join("wood.png"), b"x").unwrap();
        let found = TextureFinder::default()
            .find(&model, "", "C:\\Users\\bob\\Wood.PNG", false)
            .unwrap();
        assert_eq!(found, Some(model.join("wood.png")));
        let found = TextureFinder::default()
            .find(&model, "", "/home/bob/maps/wood.png", false)
            .unwrap();
        assert_eq!(found, Some(model.join("wood.png")));
        assert_eq!(
            TextureFinder::default()
                .find(&model, "", "missing.png", false)
                .unwrap(),
            None
        );
    }

    /// A name matched in other letter case through a link to a folder outside the model's
    /// is refused by the link's name, and the folder it leads to is never listed (a link to a
    /// huge folder, or to `/proc`, would be read whole).
    #[cfg(unix)]
    #[test]
    fn folders_a_link_leads_out_to_are_not_listed() {
        let (root, model) = model_beside_a_secret_image();
        std::os::unix::fs::symlink(root.path(), model.join("d")).unwrap();
        let mut finder = TextureFinder::default();
        let refusal = finder.find(&model, "", "D/SECRET.png", false).unwrap_err();
        assert!(refusal.contains("`d` is outside"), "{refusal}");
        assert!(refusal.contains("a link leads out"), "{refusal}");
        assert_eq!(finder.listings.listed(), 1, "only the model's folder");
        // Its bare file name in the model's folder is still found (a flattened folder).
        std::fs::write(model.join("Secret.png"), b"x").unwrap();
        let found = TextureFinder::default().find(&model, "", "D/SECRET.png", false);
        assert_eq!(found, Ok(Some(model.join("Secret.png"))));
        std::fs::remove_file(model.join("Secret.png")).unwrap();
        let mut finder = TextureFinder::default();
        let found = finder.find(&model, "", "D/SECRET.png", true).unwrap();
        assert_eq!(found, Some(model.join("d").join("secret.png")));
        assert_eq!(finder.listings.listed(), 2);
    }

    #[test]
    fn a_model_in_the_working_folder_finds_a_bare_file_name_there() {
        // The tests run in the package's folder, beside its Cargo.toml.
        let found = bare_file_in(
            Path::new(""),
            "C:/Users/bob/CARGO.toml",
            &mut Listings::default(),
        );
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
