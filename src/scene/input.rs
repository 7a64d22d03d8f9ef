//! Bounded reads of the files a scene names (scene JSON, OBJ, MTL, glTF, textures) and the limits
//! that keep hostile input from hanging the loader or exhausting memory.
//!
//! Only regular files are read: a FIFO would block `open` forever and `/dev/zero` never ends,
//! so anything else (device, FIFO, socket, folder), and on Linux any file of `/proc` or `/sys`,
//! is refused before it is opened, and looked at again once opened (without waiting, so a
//! FIFO put in its place meanwhile does not block). A file larger than its kind's limit is
//! refused from its size, and the read itself stops one byte past the limit, so a file that
//! grows while it is read cannot get around it. The limits can be raised (or lowered) for
//! every kind at once with `MANYLIGHT_MAX_FILE_MB`.

use std::io::Read;
use std::path::{Path, PathBuf};

use super::SceneError;

/// Most lights a scene may hold (file lights plus random ones; `--lights`). Checked before
/// anything is allocated: 4 Mi lights are about 400 MB of light data on the CPU, and at most
/// 65 536 of them can be visible in a frame anyway.
pub const MAX_LIGHTS: usize = 1 << 22;

/// What a file is, for its size limit and the error message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    /// A JSON scene file (default limit 16 MiB).
    SceneFile,
    /// An OBJ model (1 GiB: the largest real scene tried, the conference room, is 27 MB).
    Model,
    /// A `.gltf` or `.glb` file (the OBJ model's limit).
    Gltf,
    /// A file a glTF buffer's URI names (the OBJ model's limit).
    GltfBuffer,
    /// An MTL material library (16 MiB).
    Materials,
    /// A texture image file (256 MiB; its decoded size is limited separately).
    Texture,
}

/// The environment variable that replaces every file-size limit, in MiB.
pub const LIMIT_VARIABLE: &str = "MANYLIGHT_MAX_FILE_MB";

impl FileKind {
    /// The default size limit in bytes.
    pub fn default_limit(self) -> u64 {
        match self {
            FileKind::SceneFile | FileKind::Materials => 16 << 20,
            FileKind::Model | FileKind::Gltf | FileKind::GltfBuffer => 1 << 30,
            FileKind::Texture => 256 << 20,
        }
    }

    /// The limit in force: `MANYLIGHT_MAX_FILE_MB` if set to a number, else the default.
    /// A value that is not a whole number of MiB is warned of (once) and the default kept.
    pub fn limit(self) -> u64 {
        let Ok(value) = std::env::var(LIMIT_VARIABLE) else {
            return self.default_limit();
        };
        match value.trim().parse::<u64>() {
            Ok(mb) => mb.saturating_mul(1 << 20),
            Err(e) => {
                static WARNED: std::sync::Once = std::sync::Once::new();
                WARNED.call_once(|| {
                    log::warn!(
                        "{LIMIT_VARIABLE} is not a whole number of MiB ({e}); the default \
                         limits apply"
                    )
                });
                self.default_limit()
            }
        }
    }

    fn name(self) -> &'static str {
        match self {
            FileKind::SceneFile => "scene file",
            FileKind::Model => "OBJ file",
            FileKind::Gltf => "glTF file",
            FileKind::GltfBuffer => "glTF buffer",
            FileKind::Materials => "MTL file",
            FileKind::Texture => "texture",
        }
    }

    /// The name with its article ("an OBJ file").
    fn a_name(self) -> String {
        let article = match self {
            FileKind::Model | FileKind::Materials => "an",
            _ => "a",
        };
        format!("{article} {}", self.name())
    }
}

fn refuse(path: &Path, kind: std::io::ErrorKind, reason: String) -> SceneError {
    SceneError::Io {
        path: path.to_path_buf(),
        source: std::io::Error::new(kind, reason),
    }
}

thread_local! {
    /// Bytes [`read_bounded`] has read on this thread: what a caller measures a load by.
    static BYTES_READ: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

thread_local! {
    /// The files [`read_bounded`] has read on this thread while [`recording_files_read`] runs.
    static FILES_READ: std::cell::RefCell<Option<std::collections::BTreeSet<PathBuf>>> =
        const { std::cell::RefCell::new(None) };
}

/// Runs `load`, returning what it returned and every file it read (canonical paths, each
/// once). Nested, the inner load's files count for the outer one too.
pub(crate) fn recording_files_read<T>(load: impl FnOnce() -> T) -> (T, Vec<PathBuf>) {
    let outer = FILES_READ.with(|f| f.replace(Some(Default::default())));
    let value = load();
    let read = FILES_READ.with(|f| f.replace(outer)).unwrap_or_default();
    FILES_READ.with(|f| {
        if let Some(outer) = f.borrow_mut().as_mut() {
            outer.extend(read.iter().cloned());
        }
    });
    (value, read.into_iter().collect())
}

/// Bytes [`read_bounded`] has read on this thread so far (a running count: a caller takes
/// the difference over what it measures).
pub fn bytes_read() -> u64 {
    BYTES_READ.with(std::cell::Cell::get)
}

/// Reads a whole file of `kind`, refusing anything but a regular file within the limit.
pub fn read_bounded(path: &Path, kind: FileKind) -> Result<Vec<u8>, SceneError> {
    read_limited(path, kind, None, None)
}

/// [`read_bounded`] of a file a model names, refused once opened if it really lies outside
/// `folder` (`None`: anywhere; see [`access::confinement`](super::access::confinement)).
pub(crate) fn read_bounded_within(
    path: &Path,
    kind: FileKind,
    folder: Option<&Path>,
) -> Result<Vec<u8>, SceneError> {
    read_limited(path, kind, None, folder)
}

/// Reads at most the first `wanted` bytes of a file of `kind` (a glTF buffer: its
/// `byteLength`, however large the file is) confined to `folder` as [`read_bounded_within`]
/// is, refusing anything but a regular file; `wanted` above the kind's limit is refused.
pub(crate) fn read_bounded_prefix(
    path: &Path,
    kind: FileKind,
    wanted: u64,
    folder: Option<&Path>,
) -> Result<Vec<u8>, SceneError> {
    read_limited(path, kind, Some(wanted), folder)
}

fn read_limited(
    path: &Path,
    kind: FileKind,
    prefix: Option<u64>,
    folder: Option<&Path>,
) -> Result<Vec<u8>, SceneError> {
    let io = |source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    };
    // `metadata` follows symlinks and does not open the file: a FIFO is refused unopened.
    check_readable(path, &std::fs::metadata(path).map_err(io)?, kind)?;
    let file = open_without_waiting(path).map_err(io)?;
    // What is read is what was opened, looked at again: a FIFO or device put in the file's
    // place after the look above is refused now, not read.
    let meta = file.metadata().map_err(io)?;
    check_readable(path, &meta, kind)?;
    if let Some(folder) = folder {
        super::access::opened_within(&file, path, folder)
            .map_err(|reason| refuse(path, std::io::ErrorKind::PermissionDenied, reason))?;
    }
    let limit = kind.limit();
    let too_big = |size: u64| {
        refuse(
            path,
            std::io::ErrorKind::FileTooLarge,
            format!(
                "{} of {size} bytes exceeds the limit of {limit} bytes (set {LIMIT_VARIABLE} \
                 to raise it)",
                kind.name()
            ),
        )
    };
    // The whole file, or the part wanted of it, is what must be within the limit.
    let size = prefix.map_or(meta.len(), |p| p.min(meta.len()));
    if size > limit {
        return Err(too_big(size));
    }
    // Asked for, not taken: a failed allocation would abort the process.
    let mut bytes = Vec::new();
    if bytes.try_reserve_exact(size as usize).is_err() {
        return Err(refuse(
            path,
            std::io::ErrorKind::OutOfMemory,
            format!(
                "{} of {size} bytes: more than this process can allocate now",
                kind.name()
            ),
        ));
    }
    let most = prefix.map_or(limit.saturating_add(1), |p| p.min(limit.saturating_add(1)));
    file.take(most).read_to_end(&mut bytes).map_err(io)?;
    BYTES_READ.with(|read| read.set(read.get().saturating_add(bytes.len() as u64)));
    FILES_READ.with(|files| {
        if let Some(files) = files.borrow_mut().as_mut() {
            files.insert(std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()));
        }
    });
    if bytes.len() as u64 > limit {
        return Err(too_big(bytes.len() as u64));
    }
    Ok(bytes)
}

/// Refuses anything but a regular file outside the kernel's pseudo file systems.
fn check_readable(path: &Path, meta: &std::fs::Metadata, kind: FileKind) -> Result<(), SceneError> {
    if !meta.is_file() {
        return Err(refuse(
            path,
            std::io::ErrorKind::InvalidInput,
            format!(
                "not a regular file (the {} must be a file, not a folder, device or FIFO)",
                kind.name()
            ),
        ));
    }
    if let Some(root) = kernel_file_system(meta) {
        return Err(refuse(
            path,
            std::io::ErrorKind::InvalidInput,
            format!(
                "a file of the kernel's {root} (one can block a read forever or change as it \
                 is read), not {}",
                kind.a_name()
            ),
        ));
    }
    Ok(())
}

/// `path` opened for reading without waiting: opening a FIFO blocks until a writer comes,
/// unless non-blocking (which a regular file's reads ignore). Nor may a terminal become the
/// process's controlling one.
fn open_without_waiting(path: &Path) -> std::io::Result<std::fs::File> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::custom_flags(
        &mut options,
        libc::O_NONBLOCK | libc::O_NOCTTY,
    );
    options.open(path)
}

/// `/proc` or `/sys` when the file lies on that pseudo file system. Their files pass for
/// regular ones, but some block a read until the kernel has something to say (`/proc/kmsg`)
/// and others never end or change as they are read: no scene has a reason to name one.
#[cfg(any(target_os = "linux", target_os = "android"))]
fn kernel_file_system(meta: &std::fs::Metadata) -> Option<&'static str> {
    use std::os::unix::fs::MetadataExt;
    static DEVICES: std::sync::OnceLock<Vec<(&'static str, u64)>> = std::sync::OnceLock::new();
    let devices = DEVICES.get_or_init(|| {
        ["/proc", "/sys"]
            .into_iter()
            .filter_map(|root| Some((root, std::fs::metadata(root).ok()?.dev())))
            .collect()
    });
    devices
        .iter()
        .find(|(_, device)| *device == meta.dev())
        .map(|(root, _)| *root)
}

#[cfg(not(any(target_os = "linux", target_os = "android")))]
fn kernel_file_system(_: &std::fs::Metadata) -> Option<&'static str> {
    None
}

/// Checks that `scene`'s lights and suns, with `added` more, stay within [`MAX_LIGHTS`] before
/// those are made: suns count too, since a scene file may name a file of many suns many times.
pub(crate) fn check_lights_added(
    scene: &super::Scene,
    added: usize,
    field: &str,
) -> Result<(), SceneError> {
    let total = [scene.lights.len(), scene.directional_lights.len(), added]
        .into_iter()
        .fold(0usize, usize::saturating_add);
    check_light_count(total, field)
}

/// Checks a light count before lights are made: `field` names where it came from. Past
/// [`MAX_LIGHTS`], or more than this process can allocate [`BYTES_PER_LIGHT`] for now (an
/// allocation refused later would abort it), it is an error.
pub fn check_light_count(count: usize, field: &str) -> Result<(), SceneError> {
    light_count(count as u64, field)?;
    match light_memory_refusal(count) {
        Some(reason) => Err(SceneError::invalid(field, reason)),
        None => Ok(()),
    }
}

/// Why `count` lights cannot be made and drawn here, if this process cannot allocate
/// [`BYTES_PER_LIGHT`] each now (asked of the allocator and given back); `None` if it can.
pub(crate) fn light_memory_refusal(count: usize) -> Option<String> {
    let bytes = (count as u64).saturating_mul(BYTES_PER_LIGHT);
    (!super::alloc_probe::can_allocate(bytes)).then(|| {
        format!(
            "{count} lights need about {} MiB through a frame ({BYTES_PER_LIGHT} bytes each), \
             which this process cannot allocate now",
            bytes.div_ceil(1 << 20)
        )
    })
}

/// Memory a light takes through loading and a frame, with room to spare over what was
/// measured (docs/cli.md).
pub const BYTES_PER_LIGHT: u64 = 384;

/// A light count given as a 64-bit number: refused like
/// [`check_light_count`]'s, also where it does not fit `usize` (past 2³² on a 32-bit target).
pub fn light_count(count: u64, field: &str) -> Result<usize, SceneError> {
    match usize::try_from(count) {
        Ok(n) if n <= MAX_LIGHTS => Ok(n),
        _ => Err(SceneError::invalid(
            field,
            format!("{count} lights is more than the {MAX_LIGHTS} a scene may hold"),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_folder_is_refused_and_a_small_file_read() {
        let dir = tempfile::tempdir().unwrap();
        let err = read_bounded(dir.path(), FileKind::Model).unwrap_err();
        assert!(err.to_string().contains("not a regular file"), "{err}");
        let file = dir.path().join("a.obj");
        std::fs::write(&file, b"v 0 0 0\n").unwrap();
        assert_eq!(read_bounded(&file, FileKind::Model).unwrap(), b"v 0 0 0\n");
    }

    #[cfg(unix)]
    #[test]
    fn devices_are_refused_without_reading() {
        for device in ["/dev/zero", "/dev/null"] {
            let err = read_bounded(Path::new(device), FileKind::Materials).unwrap_err();
            assert!(err.to_string().contains("not a regular file"), "{err}");
        }
    }

    /// `/proc/kmsg`, readable by root, passes for a regular file and blocked the read until
    /// the kernel logged something; `/proc/self/status` (readable by anyone) stands for it.
    #[cfg(target_os = "linux")]
    #[test]
    fn files_of_proc_and_sys_are_refused_without_reading() {
        for file in [
            "/proc/self/status",
            "/proc/kmsg",
            "/sys/kernel/mm/transparent_hugepage/enabled",
        ] {
            if !Path::new(file).exists() {
                continue;
            }
            let err = read_bounded(Path::new(file), FileKind::SceneFile).unwrap_err();
            assert!(
                err.to_string().contains("a file of the kernel's"),
                "{file}: {err}"
            );
        }
        let err = read_bounded(Path::new("/proc/self/status"), FileKind::Model).unwrap_err();
        assert!(err.to_string().ends_with("not an OBJ file"), "{err}");
        let before = bytes_read();
        let _ = read_bounded(Path::new("/proc/self/status"), FileKind::Texture);
        assert_eq!(bytes_read(), before, "nothing read");
    }

    /// A FIFO opened as a file would block until a writer came, as when one takes a checked
    /// file's place before it is opened: it is opened without waiting and then refused.
    #[cfg(unix)]
    #[test]
    fn a_fifo_opened_is_refused_without_waiting() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("scene.json");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if !made.is_ok_and(|s| s.success()) {
            eprintln!("SKIPPED: mkfifo failed");
            return;
        }
        let (send, receive) = std::sync::mpsc::channel();
        let path = fifo.clone();
        std::thread::spawn(move || {
            let opened = open_without_waiting(&path).and_then(|f| f.metadata());
            let _ = send.send(opened.map(|m| check_readable(&path, &m, FileKind::SceneFile)));
        });
        let outcome = receive.recv_timeout(std::time::Duration::from_secs(20));
        if outcome.is_err() {
            // Lets the blocked open go before failing.
            let _ = std::fs::OpenOptions::new().write(true).open(&fifo);
        }
        let err = outcome
            .expect("opening the FIFO waited")
            .unwrap()
            .unwrap_err();
        assert!(err.to_string().contains("not a regular file"), "{err}");
    }

    /// A file swapped between a regular file and a FIFO while it is read over and over: each
    /// read gets the file's bytes or refuses a FIFO, never the FIFO's (nothing: no writer).
    #[cfg(unix)]
    #[test]
    fn a_fifo_swapped_in_after_the_check_is_not_read() {
        let dir = tempfile::tempdir().unwrap();
        let (regular, fifo) = (dir.path().join("regular"), dir.path().join("fifo"));
        std::fs::write(&regular, b"x").unwrap();
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if !made.is_ok_and(|s| s.success()) {
            eprintln!("SKIPPED: mkfifo failed");
            return;
        }
        let (path, next) = (dir.path().join("scene.json"), dir.path().join("next"));
        std::fs::hard_link(&regular, &path).unwrap();
        let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let swapper = {
            let (stop, path) = (stop.clone(), path.clone());
            std::thread::spawn(move || {
                while !stop.load(std::sync::atomic::Ordering::Relaxed) {
                    for source in [&fifo, &regular] {
                        std::fs::hard_link(source, &next).unwrap();
                        std::fs::rename(&next, &path).unwrap();
                    }
                }
            })
        };
        let mut outcomes = [0; 2];
        for _ in 0..20_000 {
            match read_bounded(&path, FileKind::SceneFile) {
                Ok(bytes) => {
                    assert_eq!(bytes, b"x", "a FIFO was read as the file");
                    outcomes[0] += 1;
                }
                Err(e) if e.to_string().contains("not a regular file") => outcomes[1] += 1,
                // A rename replaces the path at once: it is never missing.
                Err(e) => panic!("{e}"),
            }
        }
        stop.store(true, std::sync::atomic::Ordering::Relaxed);
        swapper.join().unwrap();
        assert!(outcomes.iter().all(|&n| n > 0), "{outcomes:?}");
    }

    #[test]
    fn light_counts_past_the_limit_name_the_field() {
        // The count alone: the whole limit's memory is the machine's to grant.
        assert!(light_count(MAX_LIGHTS as u64, "n").is_ok());
        assert!(check_light_count(1_000, "n").is_ok());
        let err = check_light_count(MAX_LIGHTS + 1, "random_lights.count").unwrap_err();
        assert!(err.to_string().contains("more than the"), "{err}");
        let err = check_light_count(usize::MAX, "random_lights.count").unwrap_err();
        assert!(err.to_string().contains("random_lights.count"), "{err}");
        assert_eq!(light_count(MAX_LIGHTS as u64, "n").unwrap(), MAX_LIGHTS);
        // Past 2³², which a 32-bit usize does not hold: the number as given, not a wrapped one.
        let err = light_count(1 << 32, "lights").unwrap_err().to_string();
        assert!(
            err.contains("lights") && err.contains("4294967296 lights"),
            "{err}"
        );
    }
}
