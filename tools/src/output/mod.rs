//! Writing the command line's files so that no failure is lost: every byte goes through a
//! buffer that is flushed and synced, the first write error is kept even where an encoder
//! swallows it (the GIF trailer), and every error names the file.
//!
//! A regular file is written to a hidden temporary file beside it (`.NAME.PID.N.tmp`, or
//! `.manylight.PID.N.tmp` for a name too long for that) that is renamed over it once
//! complete: a failure half-way (a full disk) leaves the old file, or none, never a truncated
//! one that looks valid. The new file keeps the old one's permissions, not its inode: other
//! hard links still show the old contents, and its owner is the writer. A device, FIFO or
//! socket, standard output (`-`, `/dev/stdout`: from where the shell left it, whatever it is)
//! and a name that reopens a descriptor (`/dev/fd/N`, `/proc/self/fd/N`: truncated) are
//! written in place. A FIFO that no process reads is an error, not a wait.

mod deferred;
mod memory;
mod paths;
mod stdout;
mod temporaries;
#[cfg(test)]
mod tests;

use std::fs::{File, Permissions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

pub use deferred::{defer_commits, Deferred};
pub use memory::encoding_fits;
pub use paths::{check_writable_later, identity, protect_inputs};
pub use stdout::{is_stream, keep_stdout_for_own_output, names_stdout, print_stdout};
pub(crate) use temporaries::remove_temporaries_then;

use deferred::with_deferred;
use paths::{follow_links, inputs, is_descriptor_alias, open_without_waiting};
use stdout::{own_stdout_named, stdout_file};
use temporaries::{create_temp, discard, live_temporaries};

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
