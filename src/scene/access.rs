//! Which files a model may read besides itself. A glTF file names its buffers and images by
//! URI, an OBJ file its material libraries and their textures by path; an untrusted model must
//! not read the user's other files through them, so by default such a name may name only a
//! file inside the model file's own folder: no `..` that climbs out of it, no absolute path
//! (`/x`, `C:/x`, `\\server\x`), no link that leads out of the folder, looked at before a file
//! is opened and once it is open (`opened_within`). [`LoadOptions`] lifts this for trusted
//! local content. Scene files and command lines name models anywhere: they are the user's own.

use std::path::{Path, PathBuf};

/// How [`load_scene_with`](crate::load_scene_with) reads the files a scene names.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct LoadOptions {
    /// Let a model's own references (a glTF file's buffer and image URIs, an OBJ file's
    /// `mtllib` and texture paths) name files outside the model's folder (`../x`, absolute
    /// paths, links leading out). Off by default: a downloaded model must
    /// not read the user's files. Turn it on only for trusted local content.
    pub allow_outside_files: bool,
}

/// What the refusal says after the reason: how to lift it for trusted content.
const HOW_TO_ALLOW: &str = "a model may read only files in its own folder (for trusted \
                            models: --allow-outside-files, or LoadOptions::allow_outside_files)";

/// The path `name` (a percent-decoded URI) names relative to `dir`. Unless `allow_outside`,
/// a name that leaves `dir` as written — absolute, or with a `..` part (`/` and `\` both
/// separate) that climbs above `dir` — is refused before anything on disk is looked at; a
/// `..` that stays inside (`maps/../wood.png`) is taken out, so the kernel never follows a
/// link in the folder back up.
pub(crate) fn join(dir: &Path, name: &str, allow_outside: bool) -> Result<PathBuf, String> {
    if allow_outside {
        return Ok(dir.join(name));
    }
    match inside(name) {
        Ok(name) => Ok(dir.join(&*name)),
        Err(why) => Err(format!(
            "`{}` is outside the model's folder ({why}); refused: {HOW_TO_ALLOW}",
            super::shown::name(name)
        )),
    }
}

/// Why [`inside`] refuses an absolute path.
pub(crate) const ABSOLUTE: &str = "an absolute path";

/// `name` as a path that stays in its folder: unchanged without `..` parts, else with each
/// `..` and the part before it taken out (`/` separating); or why it leaves the folder.
pub(crate) fn inside(name: &str) -> Result<std::borrow::Cow<'_, str>, &'static str> {
    let bytes = name.as_bytes();
    let drive = bytes.len() >= 2 && bytes[0].is_ascii_alphabetic() && bytes[1] == b':';
    if name.starts_with(['/', '\\']) || drive || Path::new(name).is_absolute() {
        return Err(ABSOLUTE);
    }
    if !name.split(['/', '\\']).any(|part| part == "..") {
        return Ok(name.into());
    }
    let mut kept: Vec<&str> = Vec::new();
    for part in name.split(['/', '\\']) {
        match part {
            "" | "." => {}
            ".." => {
                kept.pop().ok_or("`..` leads out of it")?;
            }
            part => kept.push(part),
        }
    }
    Ok(kept.join("/").into())
}

/// `path` (found from `dir` through [`join`]) with its links resolved. Unless
/// `allow_outside`, a path whose real location is not inside `dir`'s is refused: a link in
/// the model's folder may not lead out of it. A path that does not exist comes back as it is
/// (reading it says so); one whose links cannot be resolved otherwise (a chain of them too
/// long to spell out, which opening it would still follow) is refused.
pub(crate) fn resolve(dir: &Path, path: &Path, allow_outside: bool) -> Result<PathBuf, String> {
    let real = match path.canonicalize() {
        Ok(real) => real,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound || allow_outside => {
            return Ok(path.to_path_buf())
        }
        Err(e) => {
            let shown = path.strip_prefix(dir).unwrap_or(path);
            return Err(format!(
                "`{}` cannot be resolved to check it lies in the model's folder ({e}); \
                 refused: {HOW_TO_ALLOW}",
                super::shown::name(&shown.to_string_lossy())
            ));
        }
    };
    if allow_outside {
        return Ok(real);
    }
    let dir = folder_or_here(dir);
    let real_dir = dir.canonicalize().map_err(|e| {
        format!(
            "the model's folder {} cannot be resolved ({e})",
            dir.display()
        )
    })?;
    if real.starts_with(&real_dir) {
        Ok(real)
    } else {
        Err(led_out(dir, path, ""))
    }
}

/// `dir`, or the working folder where it is empty: a file named without a folder (`m.gltf`)
/// has the empty path as its parent.
fn folder_or_here(dir: &Path) -> &Path {
    if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    }
}

/// The refusal of `path` (in `dir`), which a link leads out of the folder (`when`: more on
/// when it was found).
fn led_out(dir: &Path, path: &Path, when: &str) -> String {
    let shown = path.strip_prefix(dir).unwrap_or(path);
    format!(
        "`{}` is outside the model's folder (a link leads out of it{when}); refused: \
         {HOW_TO_ALLOW}",
        super::shown::name(&shown.to_string_lossy())
    )
}

/// The model's folder a load confines its reads to: `dir` (a model file's parent, which may
/// be empty for the working folder) unless `allow_outside`.
pub(crate) fn confinement(dir: &Path, allow_outside: bool) -> Option<&Path> {
    (!allow_outside).then_some(dir)
}

/// Refuses `file`, opened from `path`, when it really lies outside `dir`. [`resolve`] looked
/// before it was opened; a link swapped in since would lead where that look did not go, so
/// this asks the kernel where the open handle is (`/proc/self/fd` on Linux and Android,
/// `F_GETPATH` on Apple's systems). Where it cannot say (another Unix, or no `/proc`), the
/// file at `path`'s real place now must be the one opened, inside `dir`. On other systems
/// (Windows) the look before stands alone.
pub(crate) fn opened_within(file: &std::fs::File, path: &Path, dir: &Path) -> Result<(), String> {
    let dir = folder_or_here(dir);
    let changed = || led_out(dir, path, ", changed after it was looked at");
    // The look before resolved this folder; failing now, it was changed since.
    let real_dir = dir.canonicalize().map_err(|_| changed())?;
    let within = match opened_path(file) {
        Some(opened) => opened.starts_with(kernel_spelling(dir).unwrap_or(real_dir)),
        None => same_file_within(file, path, &real_dir).unwrap_or(true),
    };
    if within {
        Ok(())
    } else {
        Err(changed())
    }
}

/// The folder `dir` as the kernel spells an open file's place in it, where that may differ
/// from its resolved path: Apple's `F_GETPATH` spells names as the disk holds them, which on a
/// volume that ignores case a resolved path may not (`models/` for `Models/`).
fn kernel_spelling(dir: &Path) -> Option<PathBuf> {
    #[cfg(target_vendor = "apple")]
    {
        // A folder opens for reading on Apple's systems (as on any Unix).
        opened_path(&std::fs::File::open(dir).ok()?)
    }
    #[cfg(not(target_vendor = "apple"))]
    {
        let _ = dir;
        None
    }
}

/// Where the kernel says the open `file` is, where it can say.
fn opened_path(file: &std::fs::File) -> Option<PathBuf> {
    #[cfg(any(target_os = "linux", target_os = "android"))]
    {
        use std::os::fd::AsRawFd;
        std::fs::read_link(format!("/proc/self/fd/{}", file.as_raw_fd())).ok()
    }
    #[cfg(target_vendor = "apple")]
    {
        use std::os::unix::ffi::OsStringExt;
        let path = rustix::fs::getpath(file).ok()?;
        Some(PathBuf::from(std::ffi::OsString::from_vec(
            path.into_bytes(),
        )))
    }
    #[cfg(not(any(target_os = "linux", target_os = "android", target_vendor = "apple")))]
    {
        let _ = file;
        None
    }
}

/// Whether `file` is the file `path` really leads to now (the same device and file number),
/// and that lies within `real_dir`; `None` where a file's number is not known (not Unix).
/// Narrower than asking the kernel: links swapped back and forth between the open, this
/// look and the next can still pass it.
fn same_file_within(file: &std::fs::File, path: &Path, real_dir: &Path) -> Option<bool> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        let (Ok(opened), Ok(real)) = (file.metadata(), path.canonicalize()) else {
            return Some(false);
        };
        // Looked at, not opened: a FIFO swapped in since cannot block it.
        let now = std::fs::metadata(&real);
        Some(
            real.starts_with(real_dir)
                && now.is_ok_and(|now| (now.dev(), now.ino()) == (opened.dev(), opened.ino())),
        )
    }
    #[cfg(not(unix))]
    {
        let _ = (file, path, real_dir);
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_that_leave_the_folder_as_written_are_refused() {
        let dir = Path::new("models");
        for name in [
            "../x.bin",
            "a/../../x.bin",
            "a/../..",
            "..\\x.bin",
            "/etc/passwd",
            "\\\\server\\share\\x.bin",
            "C:/x.bin",
            "c:x.bin",
        ] {
            let err = join(dir, name, false).unwrap_err();
            assert!(err.contains("outside the model's folder"), "{name}: {err}");
            assert!(err.contains("--allow-outside-files"), "{err}");
            assert_eq!(join(dir, name, true).unwrap(), dir.join(name));
        }
        for name in ["x.bin", "tex/a b.png", "a..b.bin", "./x.bin", "..x/y"] {
            assert_eq!(join(dir, name, false).unwrap(), dir.join(name), "{name}");
        }
        // A `..` that stays in the folder is taken out with the part it climbs from, so a
        // link there is never followed back up (`maps/` leading elsewhere).
        for (name, inside) in [
            ("maps/../x.bin", "x.bin"),
            ("a/b/../../tex/./x.bin", "tex/x.bin"),
            ("maps\\..\\x.bin", "x.bin"),
        ] {
            assert_eq!(join(dir, name, false).unwrap(), dir.join(inside), "{name}");
        }
    }

    /// A model folder holding `inside.bin` ("I") beside `secret.txt` ("S") in its parent; the
    /// folder's path, and the parent (dropped with the files).
    #[cfg(unix)]
    fn folder_beside_a_secret() -> (PathBuf, tempfile::TempDir) {
        let root = tempfile::tempdir().unwrap();
        let model = root.path().join("model");
        std::fs::create_dir(&model).unwrap();
        std::fs::write(root.path().join("secret.txt"), b"S").unwrap();
        std::fs::write(model.join("inside.bin"), b"I").unwrap();
        (model, root)
    }

    /// Points the link `link` at `target`, replacing what it pointed at.
    #[cfg(unix)]
    fn repoint(link: &Path, target: &str) {
        let _ = std::fs::remove_file(link);
        std::os::unix::fs::symlink(target, link).unwrap();
    }

    /// A link swapped between the open and the look after it: the kernel's word on the open
    /// file refuses it (Linux and Android here, Apple's systems alike).
    #[cfg(any(target_os = "linux", target_os = "android"))]
    #[test]
    fn a_file_opened_through_a_link_swapped_back_is_refused() {
        let (model, _root) = folder_beside_a_secret();
        let link = model.join("swapped.bin");
        repoint(&link, "../secret.txt");
        let secret = std::fs::File::open(&link).unwrap();
        repoint(&link, "inside.bin");
        let err = opened_within(&secret, &link, &model).unwrap_err();
        assert!(err.contains("changed after it was looked at"), "{err}");
        let inside = std::fs::File::open(&link).unwrap();
        assert_eq!(opened_within(&inside, &link, &model), Ok(()));
        // The kernel's word stands where the path no longer leads anywhere.
        std::fs::remove_file(&link).unwrap();
        assert_eq!(opened_within(&inside, &link, &model), Ok(()));
    }

    /// Where the kernel cannot say where an open file is: the file the path leads to now must
    /// be the one opened, and inside the folder.
    #[cfg(unix)]
    #[test]
    fn without_the_kernels_word_the_file_at_the_path_now_must_be_the_one_opened() {
        let (model, _root) = folder_beside_a_secret();
        let real_dir = model.canonicalize().unwrap();
        let link = model.join("swapped.bin");
        repoint(&link, "../secret.txt");
        let secret = std::fs::File::open(&link).unwrap();
        assert_eq!(same_file_within(&secret, &link, &real_dir), Some(false));
        repoint(&link, "inside.bin");
        assert_eq!(same_file_within(&secret, &link, &real_dir), Some(false));
        let inside = std::fs::File::open(&link).unwrap();
        assert_eq!(same_file_within(&inside, &link, &real_dir), Some(true));
        std::fs::remove_file(&link).unwrap();
        assert_eq!(same_file_within(&inside, &link, &real_dir), Some(false));
    }

    #[cfg(unix)]
    #[test]
    fn a_link_leading_out_of_the_folder_is_refused() {
        let (model, root) = folder_beside_a_secret();
        std::os::unix::fs::symlink(root.path().join("secret.txt"), model.join("out.bin")).unwrap();
        std::os::unix::fs::symlink(model.join("inside.bin"), model.join("in.bin")).unwrap();
        let err = resolve(&model, &model.join("out.bin"), false).unwrap_err();
        assert!(err.contains("`out.bin` is outside"), "{err}");
        assert!(resolve(&model, &model.join("out.bin"), true).is_ok());
        let real = resolve(&model, &model.join("in.bin"), false).unwrap();
        assert_eq!(std::fs::read(real).unwrap(), b"I");
        let missing = model.join("missing.bin");
        assert_eq!(resolve(&model, &missing, false).unwrap(), missing);
    }

    /// A file opened through a link that leads out is refused once open, whatever the look
    /// before said (a link swapped in between); unconfined, it is read.
    #[cfg(any(target_os = "linux", target_os = "android"))]
    #[test]
    fn a_file_opened_outside_the_folder_is_refused() {
        use crate::scene::input::{read_bounded_within, FileKind};
        let (model, _root) = folder_beside_a_secret();
        std::os::unix::fs::symlink("../secret.txt", model.join("out.bin")).unwrap();
        std::os::unix::fs::symlink("inside.bin", model.join("in.bin")).unwrap();
        let read = |name: &str, within: Option<&Path>| {
            read_bounded_within(&model.join(name), FileKind::GltfBuffer, within)
        };
        let err = read("out.bin", Some(&model)).unwrap_err().to_string();
        assert!(
            err.contains("`out.bin` is outside the model's folder"),
            "{err}"
        );
        assert_eq!(read("in.bin", Some(&model)).unwrap(), b"I");
        assert_eq!(read("out.bin", None).unwrap(), b"S");
    }

    /// Links whose spelled-out target passes `PATH_MAX` (so resolving them fails with "file
    /// name too long") still lead where opening follows them: out of the folder here.
    #[cfg(unix)]
    #[test]
    fn links_too_long_to_resolve_are_refused() {
        use std::os::unix::fs::symlink;
        let root = tempfile::tempdir().unwrap();
        let model = root.path().join("model");
        std::fs::write(root.path().join("secret.txt"), b"S").unwrap();
        let names: Vec<String> = (0..20)
            .map(|i| format!("{i:02}{}", "d".repeat(248)))
            .collect();
        // Made in two halves through a short link (the whole is past what a path may spell).
        let middle = names[..10].iter().fold(model.clone(), |p, n| p.join(n));
        std::fs::create_dir_all(&middle).unwrap();
        symlink(names[..10].join("/"), model.join("m")).unwrap();
        let middle = model.join("m");
        let deepest = names[10..].iter().fold(middle.clone(), |p, n| p.join(n));
        std::fs::create_dir_all(&deepest).unwrap();
        symlink(names[..10].join("/"), model.join("a")).unwrap();
        symlink(names[10..].join("/"), middle.join("b")).unwrap();
        symlink(format!("{}secret.txt", "../".repeat(21)), deepest.join("c")).unwrap();
        let path = model.join("a/b/c");
        assert_eq!(
            std::fs::read(&path).unwrap(),
            b"S",
            "the kernel follows the chain"
        );
        let err = resolve(&model, &path, false).unwrap_err();
        assert!(err.contains("cannot be resolved"), "{err}");
        assert_eq!(resolve(&model, &path, true).unwrap(), path);
    }

    #[test]
    fn a_model_in_the_working_folder_has_the_empty_path_as_its_folder() {
        // `Path::new("m.gltf").parent()` is `""`: the working folder (the package's, in tests).
        let dir = Path::new("m.gltf").parent().unwrap();
        let path = join(dir, "Cargo.toml", false).unwrap();
        let real = resolve(dir, &path, false).unwrap();
        assert_eq!(real, Path::new("Cargo.toml").canonicalize().unwrap());
    }
}
