//! Writing the command line's files so that no failure is lost: every byte goes through a
//! buffer that is flushed and synced, the first write error is kept even where an encoder
//! swallows it (the GIF trailer), and every error names the file.
//!
//! A regular file is written to a hidden temporary file beside it (`.NAME.PID.N.tmp`, or
//! `.manylight.PID.N.tmp` for a name too long for that) that is renamed over it once
//! complete: a failure half-way (a full disk) leaves the old file, or none, never a truncated
//! one that looks valid. A device, FIFO or socket, standard output
//! (`-`, `/dev/stdout`: from where the shell left it, whatever it is) and a name that reopens a
//! descriptor (`/dev/fd/N`, `/proc/self/fd/N`: truncated) are written in place. A FIFO that no
//! process reads is an error, not a wait.

use std::ffi::OsString;
use std::fs::{File, OpenOptions, Permissions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Mutex, MutexGuard, OnceLock};

/// A file that could not be written, and why (the OS error).
#[derive(Debug)]
pub struct WriteError {
    /// The file as the user named it.
    pub path: PathBuf,
    /// What the system said.
    pub source: io::Error,
}

impl std::fmt::Display for WriteError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let path = manylight::scene::shown::path(&self.path);
        write!(f, "cannot write {path}: {}", self.source)
    }
}

impl std::error::Error for WriteError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&self.source)
    }
}

/// An image in memory (RGBA or RGB, 8 bits a channel: what the command line writes).
pub type Picture<P> = image::ImageBuffer<P, Vec<<P as image::Pixel>::Subpixel>>;

/// Where the bytes go until [`OutputFile::commit`].
enum Target {
    /// A temporary file renamed over `dest` when complete (with `permissions`, those of the
    /// file it replaces).
    Replace {
        temp: PathBuf,
        dest: PathBuf,
        permissions: Option<Permissions>,
    },
    /// Written in place: a device, FIFO or socket, standard output, or a regular file a
    /// descriptor's name reopens.
    InPlace,
}

/// An output file being written: [`Write`] into it, then [`OutputFile::commit`]. Dropped
/// without a commit, it leaves the destination as it was.
pub struct OutputFile {
    path: PathBuf,
    target: Target,
    writer: Option<BufWriter<File>>,
    /// The first write error, kept for [`OutputFile::commit`] even if the writer's caller
    /// ignored it.
    failed: Option<io::Error>,
}

/// Numbers the temporary files of one process.
static TEMP_COUNTER: AtomicU32 = AtomicU32::new(0);

/// The temporary files being written now, which a signal that ends the process removes
/// (`crate::signals`). Each is listed while its file exists: created, renamed and removed with
/// the lock held, so that a signal's removal never races them.
static LIVE_TEMPORARIES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn live_temporaries() -> MutexGuard<'static, Vec<PathBuf>> {
    LIVE_TEMPORARIES.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes every temporary file being written, then runs `then` with the list still locked, so
/// that no new one is made, renamed or removed meanwhile (`then` ends the process).
pub(crate) fn remove_temporaries_then(then: impl FnOnce()) {
    let mut live = live_temporaries();
    for temp in live.drain(..) {
        let _ = std::fs::remove_file(temp);
    }
    then();
}

/// The files the process's scenes were read from, by [`identity`]: no output replaces one.
fn inputs() -> MutexGuard<'static, Vec<PathBuf>> {
    static INPUTS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
    INPUTS.lock().unwrap_or_else(|e| e.into_inner())
}

/// Keeps every output of this process off `files`, which a scene was read from
/// (`LoadReport::files`): [`OutputFile::create`] refuses them, naming the file, so an output
/// that a subcommand names itself (a benchmark's heat map, a matrix cell's picture) cannot
/// replace a model or texture of the same name.
pub fn protect_inputs(files: &[PathBuf]) {
    let mut inputs = inputs();
    for file in files {
        let id = identity(file);
        if !inputs.contains(&id) {
            inputs.push(id);
        }
    }
}

impl OutputFile {
    /// Opens `path` for writing: fails now, naming it, where it cannot be written (a folder, a
    /// missing folder, a read-only file or folder, a file a scene was read from). `-` is
    /// standard output.
    pub fn create(path: &Path) -> Result<OutputFile, WriteError> {
        let fail = |source| WriteError {
            path: path.to_path_buf(),
            source,
        };
        if !is_stream(path) && inputs().contains(&identity(path)) {
            return Err(fail(io::Error::other(
                "a scene was read from it: it would be overwritten",
            )));
        }
        // An existing file is opened for writing (not truncated) to learn whether it may be
        // written at all and what it is; a symbolic link is followed, and its target replaced.
        let dash = path == Path::new("-");
        let opened = match own_stdout_named(path) {
            _ if dash => stdout_file(),
            Some(own) => own.try_clone(),
            None => open_without_waiting(path),
        };
        let (target, file) = match opened {
            Ok(existing) => {
                let meta = existing.metadata().map_err(fail)?;
                if names_stdout(path) {
                    // Standard output, whatever it is: written where the shell left it (after
                    // what came before in `{ echo; manylight; } > f`, at the end under `>>`),
                    // never truncated, as `print_stdout` writes.
                    (Target::InPlace, existing)
                } else if meta.is_file() && is_descriptor_alias(path) {
                    // `/dev/fd/N`, `/proc/self/fd/N`: reopened at its start, so truncated, as
                    // any program opening that name for writing does.
                    existing.set_len(0).map_err(fail)?;
                    (Target::InPlace, existing)
                } else if meta.is_file() {
                    let dest = std::fs::canonicalize(path).map_err(fail)?;
                    // The file itself may be written, its folder not: say which stops it.
                    let in_folder = |e: io::Error| match e.kind() {
                        io::ErrorKind::PermissionDenied => io::Error::new(
                            e.kind(),
                            format!(
                                "its folder cannot be written ({e}): the new file is written \
                                 beside the old one and renamed over it"
                            ),
                        ),
                        _ => e,
                    };
                    let (temp, file) = create_temp(&dest).map_err(|e| fail(in_folder(e)))?;
                    let permissions = Some(meta.permissions());
                    (
                        Target::Replace {
                            temp,
                            dest,
                            permissions,
                        },
                        file,
                    )
                } else {
                    (Target::InPlace, existing)
                }
            }
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                // A dangling link: its target is created, as `File::create` would.
                let dest = follow_links(path);
                let (temp, file) = create_temp(&dest).map_err(fail)?;
                (
                    Target::Replace {
                        temp,
                        dest,
                        permissions: None,
                    },
                    file,
                )
            }
            Err(e) => return Err(fail(e)),
        };
        Ok(OutputFile {
            path: path.to_path_buf(),
            target,
            writer: Some(BufWriter::new(file)),
            failed: None,
        })
    }

    /// The file as the user named it.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Flushes, syncs and puts the file in place; the first error met on the way, naming the
    /// file.
    pub fn commit(mut self) -> Result<(), WriteError> {
        let result = self.finish();
        self.outcome(result)
    }

    fn finish(&mut self) -> io::Result<()> {
        if let Some(e) = self.failed.take() {
            return Err(e);
        }
        let writer = self.writer.take().expect("an output file commits once");
        let file = writer.into_inner().map_err(|e| e.into_error())?;
        if let Target::Replace {
            temp,
            dest,
            permissions,
        } = &mut self.target
        {
            // Synced before the rename, so the new name never points at unwritten data; a
            // device or pipe has nothing to sync.
            file.sync_all()?;
            if let Some(p) = permissions.take() {
                std::fs::set_permissions(&*temp, p)?;
            }
            // Put in place with the others by `Deferred::commit`; until then the temporary
            // file stays live (a signal removes it).
            let file = (temp.clone(), dest.clone());
            if with_deferred(|d| d.as_mut().map(|waiting| waiting.push(file)).is_some()) {
                self.target = Target::InPlace;
                return Ok(());
            }
            let mut live = live_temporaries();
            std::fs::rename(&*temp, &*dest)?;
            live.retain(|t| t != temp);
            drop(live);
            self.target = Target::InPlace;
        }
        Ok(())
    }
}

impl Write for OutputFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let writer = self.writer.as_mut().ok_or(io::ErrorKind::BrokenPipe)?;
        writer.write(buf).inspect_err(|e| self.keep(e))
    }

    fn flush(&mut self) -> io::Result<()> {
        let writer = self.writer.as_mut().ok_or(io::ErrorKind::BrokenPipe)?;
        writer.flush().inspect_err(|e| self.keep(e))
    }
}

impl OutputFile {
    /// Keeps the first error (a copy: the caller gets the original).
    fn keep(&mut self, e: &io::Error) {
        if self.failed.is_none() {
            self.failed = Some(match e.raw_os_error() {
                Some(code) => io::Error::from_raw_os_error(code),
                None => io::Error::new(e.kind(), e.to_string()),
            });
        }
    }
}

impl Drop for OutputFile {
    fn drop(&mut self) {
        if let Target::Replace { temp, .. } = &self.target {
            drop(self.writer.take());
            discard(&mut live_temporaries(), temp);
        }
    }
}

/// Removes the temporary file `temp` where it is still there, and takes it off `live`.
fn discard(live: &mut Vec<PathBuf>, temp: &Path) {
    let _ = std::fs::remove_file(temp);
    live.retain(|t| t != temp);
}

thread_local! {
    /// The files this thread wrote whole and synced, as (temporary, destination), whose
    /// renames wait for [`Deferred::commit`]; `None` where its commits are not deferred.
    static DEFERRED: std::cell::RefCell<Option<Vec<(PathBuf, PathBuf)>>> =
        const { std::cell::RefCell::new(None) };
}

/// Runs `f` on this thread's deferred commits.
fn with_deferred<T>(f: impl FnOnce(&mut Option<Vec<(PathBuf, PathBuf)>>) -> T) -> T {
    DEFERRED.with_borrow_mut(f)
}

/// Defers the renames of every file this thread commits from now on to [`Deferred::commit`],
/// so that a command writing many (a benchmark's report folder) replaces all of them or none:
/// stopped half-way by an error or a signal, its destinations stay as they were, their
/// temporary files removed.
pub fn defer_commits() -> Deferred {
    with_deferred(|d| *d = Some(Vec::new()));
    Deferred(())
}

/// Commits deferred by [`defer_commits`]; dropped without [`Deferred::commit`], their files
/// are removed and the destinations left as they were.
pub struct Deferred(());

impl Deferred {
    /// Puts every deferred file in place; the first rename that fails is an error naming its
    /// file, and the files after it are removed.
    pub fn commit(self) -> Result<(), WriteError> {
        let waiting = with_deferred(Option::take).unwrap_or_default();
        let mut live = live_temporaries();
        let mut failed = None;
        for (temp, dest) in waiting {
            if failed.is_none() {
                if let Err(source) = std::fs::rename(&temp, &dest) {
                    failed = Some(WriteError { path: dest, source });
                }
            }
            discard(&mut live, &temp);
        }
        failed.map_or(Ok(()), Err)
    }
}

impl Drop for Deferred {
    fn drop(&mut self) {
        if let Some(waiting) = with_deferred(Option::take) {
            let mut live = live_temporaries();
            for (temp, _) in waiting {
                discard(&mut live, &temp);
            }
        }
    }
}

/// `path` opened for writing, without waiting for a reader: opening a FIFO that no process
/// reads blocked until one came, so `--out fifo` hung before any work, saying nothing. Such a
/// FIFO is an error now; one with a reader is opened again as usual (blocking writes).
fn open_without_waiting(path: &Path) -> io::Result<File> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
        let probe = OpenOptions::new()
            .write(true)
            .custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY)
            .open(path);
        match probe {
            Err(e)
                if e.raw_os_error() == Some(libc::ENXIO)
                    && std::fs::metadata(path).is_ok_and(|m| m.file_type().is_fifo()) =>
            {
                Err(io::Error::other(
                    "a FIFO that no process reads: start its reader first",
                ))
            }
            Ok(file) if file.metadata()?.file_type().is_fifo() => {
                OpenOptions::new().write(true).open(path)
            }
            Ok(file) if file.metadata()?.is_file() => Ok(file),
            // A device (a terminal's writes must not fail for want of room): as usual.
            Ok(_) => OpenOptions::new().write(true).open(path),
            Err(e) => Err(e),
        }
    }
    #[cfg(not(unix))]
    OpenOptions::new().write(true).open(path)
}

/// Whether `path` is one of the system's names for an open descriptor (`/dev/stdout`,
/// `/dev/fd/N`, `/proc/self/fd/N`): written in place, whatever it points at. Other files under
/// `/dev` (`/dev/shm`'s) are files like any other, replaced whole; all of `/dev` was taken as
/// a stream, and a file there was truncated before a write that then failed.
fn is_descriptor_alias(path: &Path) -> bool {
    let mut parts = path.components().map(|c| c.as_os_str());
    let mut next = || parts.next().and_then(|p| p.to_str());
    matches!(
        (next(), next(), next(), next()),
        (
            Some("/"),
            Some("dev"),
            Some("stdout" | "stderr" | "stdin"),
            None
        ) | (Some("/"), Some("dev"), Some("fd"), Some(_))
            | (Some("/"), Some("proc"), Some(_), Some("fd"))
    )
}

/// `path` with symbolic links followed to the last one's target, which need not exist (at most
/// 40 links, the system's own limit; past it, the last path reached).
fn follow_links(path: &Path) -> PathBuf {
    let mut path = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::read_link(&path) {
            Ok(target) => {
                path = match path.parent() {
                    Some(folder) => folder.join(target),
                    None => target,
                }
            }
            Err(_) => break,
        }
    }
    path
}

/// Longest file name most file systems take, in bytes (ext4's, tmpfs's, APFS's `NAME_MAX`).
const NAME_MAX: usize = 255;

/// Creates `.NAME.PID.N.tmp` beside `dest`, new (never an existing file); `.manylight.PID.N.tmp`
/// where NAME is too long for that, so a name the file system takes is written.
fn create_temp(dest: &Path) -> io::Result<(PathBuf, File)> {
    let name = dest
        .file_name()
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "the path names no file"))?;
    let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
    let suffix = format!(".{}.{n}.tmp", std::process::id());
    let mut temp_name = OsString::from(".");
    if 1 + name.len() + suffix.len() <= NAME_MAX {
        temp_name.push(name);
    } else {
        temp_name.push("manylight");
    }
    temp_name.push(suffix);
    let temp = dest.with_file_name(temp_name);
    let mut live = live_temporaries();
    let file = OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&temp)?;
    live.push(temp.clone());
    Ok((temp, file))
}

impl OutputFile {
    /// Writes `bytes` and commits.
    pub fn commit_bytes(mut self, bytes: &[u8]) -> Result<(), WriteError> {
        match self.write_all(bytes) {
            Ok(()) => self.commit(),
            Err(source) => self.outcome(Err(source)),
        }
    }

    /// Writes `image` as a PNG and commits.
    pub fn commit_png<P>(mut self, image: &Picture<P>) -> Result<(), WriteError>
    where
        P: image::PixelWithColorType,
        [P::Subpixel]: image::EncodableLayout,
    {
        // The encoder holds the whole compressed picture, at most about its raw size.
        let raw = std::mem::size_of_val(image.as_raw().as_slice()) as u64;
        if let Err(e) = encoding_fits(raw, image.dimensions()) {
            return self.outcome(Err(e));
        }
        let encoder = image::codecs::png::PngEncoder::new(&mut self);
        match image.write_with_encoder(encoder) {
            Ok(()) => self.commit(),
            Err(e) => self.outcome(Err(image_to_io(e))),
        }
    }

    /// `result` naming the file; a closed pipe on standard output (`--out - | head`) ends the
    /// output quietly, as [`print_stdout`] does (a named FIFO's reader leaving is an error).
    fn outcome(&self, result: io::Result<()>) -> Result<(), WriteError> {
        match result {
            Err(e) if e.kind() == io::ErrorKind::BrokenPipe && names_stdout(&self.path) => Ok(()),
            Err(source) => Err(WriteError {
                path: self.path.clone(),
                source,
            }),
            Ok(()) => Ok(()),
        }
    }
}

/// Whether an encoder's `bytes` for a `w × h` picture can be allocated now: a refused
/// allocation inside an encoder aborts the process (16 384² under `ulimit -v 4000000`), where
/// this is an error naming the file.
pub fn encoding_fits(bytes: u64, (w, h): (u32, u32)) -> io::Result<()> {
    if can_allocate(bytes) {
        return Ok(());
    }
    Err(io::Error::new(
        io::ErrorKind::OutOfMemory,
        format!(
            "encoding its {w}×{h} picture takes up to {} MiB, more than this process can \
             allocate now",
            bytes.div_ceil(1 << 20)
        ),
    ))
}

/// The library's probe ([`can_allocate`](manylight::scene::alloc_probe::can_allocate)), which
/// a test here may limit.
fn can_allocate(bytes: u64) -> bool {
    #[cfg(test)]
    if ALLOCATABLE
        .with(std::cell::Cell::get)
        .is_some_and(|most| bytes > most)
    {
        return false;
    }
    manylight::scene::alloc_probe::can_allocate(bytes)
}

#[cfg(test)]
thread_local! {
    /// Most bytes [`can_allocate`] grants on this thread (tests of a memory limit).
    static ALLOCATABLE: std::cell::Cell<Option<u64>> = const { std::cell::Cell::new(None) };
}

/// Writes `bytes` to `path` (see the module's notes).
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), WriteError> {
    OutputFile::create(path)?.commit_bytes(bytes)
}

/// Writes `image` to `path` as a PNG (see the module's notes).
pub fn save_png<P>(path: &Path, image: &Picture<P>) -> Result<(), WriteError>
where
    P: image::PixelWithColorType,
    [P::Subpixel]: image::EncodableLayout,
{
    OutputFile::create(path)?.commit_png(image)
}

/// The I/O error inside an image error, or the image error as one.
fn image_to_io(e: image::ImageError) -> io::Error {
    match e {
        image::ImageError::IoError(e) => e,
        other => io::Error::other(other.to_string()),
    }
}

/// Where a JSON output goes: a file, or standard output for `-` (whose caller then sends its
/// summary lines to standard error, so that standard output is the JSON alone).
pub enum JsonOut {
    /// A file, written beside itself and renamed over it (see the module's notes).
    File(OutputFile),
    /// Standard output.
    Stdout,
}

impl JsonOut {
    /// `path`'s destination, a file opened now: one that cannot be written fails before the
    /// work, not after.
    pub fn create(path: &Path) -> Result<JsonOut, WriteError> {
        if path == Path::new("-") {
            Ok(JsonOut::Stdout)
        } else {
            Ok(JsonOut::File(OutputFile::create(path)?))
        }
    }

    /// Writes `json` and commits the file.
    pub fn commit(self, json: &str) -> Result<(), Box<dyn std::error::Error>> {
        match self {
            JsonOut::File(file) => file.commit_bytes(json.as_bytes())?,
            JsonOut::Stdout => print_stdout(json)?,
        }
        Ok(())
    }
}

/// Standard output as the process was given it, once [`keep_stdout_for_own_output`] has
/// pointed descriptor 1 at standard error.
static OWN_STDOUT: OnceLock<File> = OnceLock::new();

/// Keeps standard output for the command line's own output and sends what the libraries loaded
/// in this process print there to standard error: a driver's `printf` (Mesa's "extension …
/// cannot be disabled" under `MESA_EXTENSION_OVERRIDE`, flushed at exit) would otherwise
/// follow `info --json` or `--stats -` and break whatever parses them. Call once, before any
/// GL library is loaded; [`print_stdout`] and `/dev/stdout` as an output then reach the
/// original. Unix only; where either stream is closed nothing changes.
pub fn keep_stdout_for_own_output() {
    #[cfg(unix)]
    {
        use std::os::fd::AsFd;
        let Ok(saved) = io::stdout().as_fd().try_clone_to_owned() else {
            return;
        };
        if rustix::stdio::dup2_stdout(io::stderr().as_fd()).is_ok() {
            let _ = OWN_STDOUT.set(File::from(saved));
        }
    }
}

/// The original standard output, for a path that names it (`/dev/stdout`, `/dev/fd/1`,
/// `/proc/self/fd/1`, this process's `/proc/PID/fd/1`, or a link to one of them), once
/// descriptor 1 no longer does.
fn own_stdout_named(path: &Path) -> Option<&'static File> {
    let own = OWN_STDOUT.get()?;
    let pid = format!("/proc/{}/fd/1", std::process::id());
    let names = [
        "/dev/stdout",
        "/dev/fd/1",
        "/proc/self/fd/1",
        "/proc/thread-self/fd/1",
        &pid,
    ];
    let mut hop = std::path::absolute(path).ok()?;
    // Each link on the way, as `follow_links` takes them (40 at most).
    for _ in 0..40 {
        if names.iter().any(|name| hop == Path::new(name)) {
            return Some(own);
        }
        let target = std::fs::read_link(&hop).ok()?;
        hop = match hop.parent() {
            Some(folder) => folder.join(target),
            None => target,
        };
    }
    None
}

/// Whether `path` names standard output: `-`, or one of the system's names for descriptor 1
/// (`/dev/stdout`, `/dev/fd/1`, `/proc/self/fd/1`, or a link to one) once
/// [`keep_stdout_for_own_output`] has run.
pub fn names_stdout(path: &Path) -> bool {
    path == Path::new("-") || own_stdout_named(path).is_some()
}

/// What standard output is redirected to, as [`identity`] spells it: `-` and `/dev/stdout`
/// named the file a shell's `> f` or `>> f` opened no more than any other name did, so an output
/// or the scene there went unnoticed (`--out - >> scene.json` replaced the scene).
fn stdout_identity() -> PathBuf {
    #[cfg(unix)]
    {
        use std::os::fd::AsRawFd;
        let fd = OWN_STDOUT.get().map_or(1, |own| own.as_raw_fd());
        let alias = PathBuf::from(format!("/proc/self/fd/{fd}"));
        std::fs::canonicalize(&alias).unwrap_or(alias)
    }
    #[cfg(not(unix))]
    PathBuf::from("-")
}

/// Whether `path` is a stream (a device, FIFO or socket, standard output's included), which
/// two outputs may share: neither overwrites the other there.
pub fn is_stream(path: &Path) -> bool {
    let meta = if names_stdout(path) {
        stdout_file().and_then(|f| f.metadata())
    } else {
        std::fs::metadata(path)
    };
    meta.is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// Standard output as a file of its own (the original one, where descriptor 1 was redirected).
fn stdout_file() -> io::Result<File> {
    if let Some(own) = OWN_STDOUT.get() {
        return own.try_clone();
    }
    #[cfg(unix)]
    {
        use std::os::fd::AsFd;
        io::stdout().as_fd().try_clone_to_owned().map(File::from)
    }
    #[cfg(not(unix))]
    Err(io::ErrorKind::Unsupported.into())
}

/// Writes `text` to standard output and flushes it. A closed pipe (`manylight info | head`)
/// ends the output quietly; any other error (a full disk) is returned.
pub fn print_stdout(text: &str) -> Result<(), String> {
    let written = match OWN_STDOUT.get() {
        Some(mut own) => own.write_all(text.as_bytes()).and_then(|()| own.flush()),
        None => {
            let mut out = io::stdout().lock();
            out.write_all(text.as_bytes()).and_then(|()| out.flush())
        }
    };
    match written {
        Err(e) if e.kind() != io::ErrorKind::BrokenPipe => {
            Err(format!("cannot write to standard output: {e}"))
        }
        _ => Ok(()),
    }
}

/// The file `path` names, spelled one way: symbolic links resolved, `.` and `..` gone, made
/// absolute; for a file that does not exist yet, its folder resolved. Two outputs with the same
/// identity would overwrite each other.
pub fn identity(path: &Path) -> PathBuf {
    if names_stdout(path) {
        return stdout_identity();
    }
    if let Ok(p) = std::fs::canonicalize(path) {
        return p;
    }
    let path = follow_links(path);
    let absolute = std::path::absolute(&path).unwrap_or(path);
    match (absolute.parent(), absolute.file_name()) {
        (Some(parent), Some(name)) => std::fs::canonicalize(parent)
            .unwrap_or_else(|_| parent.to_path_buf())
            .join(name),
        _ => absolute,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_complete_file_replaces_the_old_one_and_keeps_its_permissions() {
        use std::os::unix::fs::PermissionsExt;
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        let path = dir.join("a.json");
        std::fs::write(&path, "old").unwrap();
        std::fs::set_permissions(&path, Permissions::from_mode(0o640)).unwrap();
        write_bytes(&path, b"new").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        let mode = std::fs::metadata(&path).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o640);
        assert_eq!(
            std::fs::read_dir(dir).unwrap().count(),
            1,
            "a temporary file is left"
        );
    }

    /// A picture whose encoding cannot be allocated is an error naming the file, the old file
    /// whole and no temporary left.
    #[test]
    fn a_picture_whose_encoding_cannot_be_allocated_is_an_error() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        let path = dir.join("a.png");
        std::fs::write(&path, "old").unwrap();
        let picture = image::RgbaImage::new(64, 32);
        ALLOCATABLE.with(|a| a.set(Some(1000)));
        let refused = save_png(&path, &picture);
        ALLOCATABLE.with(|a| a.set(None));
        let message = refused.unwrap_err().to_string();
        assert!(message.contains("a.png"), "{message}");
        assert!(
            message.contains("encoding its 64×32 picture takes up to 1 MiB"),
            "{message}"
        );
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(
            std::fs::read_dir(dir).unwrap().count(),
            1,
            "a temporary file is left"
        );
        save_png(&path, &picture).unwrap();
        assert_eq!(image::open(&path).unwrap().width(), 64);
    }

    /// Deferred commits put every file in place together, or, dropped before, none.
    #[test]
    fn deferred_commits_replace_all_files_or_none() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        let (a, b) = (dir.join("a.json"), dir.join("b.json"));
        std::fs::write(&a, "old").unwrap();
        let files = || {
            let mut names: Vec<_> = (std::fs::read_dir(dir).unwrap())
                .map(|e| e.unwrap().file_name().into_string().unwrap())
                .collect();
            names.sort();
            names
        };
        for commit in [false, true] {
            let deferred = defer_commits();
            write_bytes(&a, b"new a").unwrap();
            write_bytes(&b, b"new b").unwrap();
            // Written and synced, not yet in place.
            assert_eq!(std::fs::read(&a).unwrap(), b"old");
            assert!(!b.exists());
            assert_eq!(files().len(), 3, "{:?}", files());
            if commit {
                deferred.commit().unwrap();
            } else {
                drop(deferred);
                assert_eq!(files(), ["a.json"], "stopped: as it was");
                assert_eq!(std::fs::read(&a).unwrap(), b"old");
            }
        }
        assert_eq!(files(), ["a.json", "b.json"]);
        assert_eq!(std::fs::read(&a).unwrap(), b"new a");
        // Not deferred any more: a commit puts its file in place at once.
        write_bytes(&b, b"newer b").unwrap();
        assert_eq!(std::fs::read(&b).unwrap(), b"newer b");
    }

    /// A name of up to 255 bytes, which the file system takes, is written: its temporary
    /// file's name, 13 or more bytes longer, was refused ("File name too long").
    #[test]
    fn the_longest_name_the_file_system_takes_is_written() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        for length in [240, NAME_MAX] {
            let path = dir.join(format!("{}.json", "a".repeat(length - 5)));
            std::fs::write(&path, "old").unwrap();
            write_bytes(&path, b"new").unwrap();
            assert_eq!(std::fs::read(&path).unwrap(), b"new", "{length}");
            std::fs::remove_file(&path).unwrap();
            assert_eq!(
                std::fs::read_dir(dir).unwrap().count(),
                0,
                "{length}: a temporary file is left"
            );
        }
    }

    #[test]
    fn an_uncommitted_file_leaves_the_old_one_and_no_temporary_file() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        let path = dir.join("a.png");
        std::fs::write(&path, "old").unwrap();
        let mut file = OutputFile::create(&path).unwrap();
        file.write_all(b"half").unwrap();
        drop(file);
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(std::fs::read_dir(dir).unwrap().count(), 1);
    }

    #[test]
    fn a_symbolic_link_keeps_pointing_at_the_file_it_named() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        std::fs::write(dir.join("real.json"), "old").unwrap();
        std::os::unix::fs::symlink("real.json", dir.join("link.json")).unwrap();
        write_bytes(&dir.join("link.json"), b"new").unwrap();
        assert!(std::fs::symlink_metadata(dir.join("link.json"))
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read(dir.join("real.json")).unwrap(), b"new");
        assert_eq!(
            identity(&dir.join("link.json")),
            identity(&dir.join("real.json"))
        );
    }

    #[test]
    fn a_full_device_is_an_error_naming_it() {
        let e = write_bytes(Path::new("/dev/full"), b"{}").unwrap_err();
        assert_eq!(e.path, Path::new("/dev/full"));
        assert_eq!(e.source.raw_os_error(), Some(28), "{e}");
        // A caller that ignores a write error (the GIF encoder's trailer) still gets one.
        let mut file = OutputFile::create(Path::new("/dev/full")).unwrap();
        let _ = file.write_all(&[0; 64 * 1024]);
        let _ = file.write_all(b"more");
        let e = file.commit().unwrap_err();
        assert!(e.to_string().contains("/dev/full"), "{e}");
    }

    #[test]
    fn a_dangling_link_writes_its_target() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        std::os::unix::fs::symlink("new.json", dir.join("link.json")).unwrap();
        assert_eq!(
            identity(&dir.join("link.json")),
            identity(&dir.join("new.json"))
        );
        write_bytes(&dir.join("link.json"), b"new").unwrap();
        assert_eq!(std::fs::read(dir.join("new.json")).unwrap(), b"new");
        assert!(std::fs::symlink_metadata(dir.join("link.json"))
            .unwrap()
            .file_type()
            .is_symlink());
    }

    #[test]
    fn spellings_of_one_file_have_one_identity() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        let a = identity(&dir.join("x.png"));
        let b = identity(&dir.join(".").join("x.png"));
        let sub = dir.join("sub");
        std::fs::create_dir(&sub).unwrap();
        let c = identity(&sub.join("..").join("x.png"));
        assert_eq!(a, b);
        assert_eq!(a, c);
        assert_ne!(a, identity(&dir.join("y.png")));
    }
}
