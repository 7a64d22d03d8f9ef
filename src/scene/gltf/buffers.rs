//! The bytes of a glTF file's buffers: the GLB's BIN chunk, `data:` URIs and files next to the
//! `.gltf`, each read once, when first used, within the model size limit.
//!
//! Files are read through [`read_bounded_prefix`] (regular files only, the buffer's own
//! `byteLength` bytes, [`FileKind::GltfBuffer`]'s limit), and all buffers together may hold
//! at most that same limit: a file cannot name the same 1 GiB file a thousand times, nor a
//! few bytes of it a thousand times over. A file URI may name only a file inside the glTF file's
//! folder unless the load allows outside files ([`crate::scene::access`]).

use std::borrow::Cow;
use std::path::{Path, PathBuf};

use super::uri::{self, Uri};
use crate::scene::access;
use crate::scene::input::{read_bounded_prefix, FileKind};

/// Most elements one glTF file's accessors without a buffer view may hold together (16 MiB
/// of `VEC4` floats): their count is free to claim, so without a bound a file of a few hundred
/// bytes took gigabytes.
pub const MAX_UNBACKED_ELEMENTS: usize = 1 << 20;

/// Lazily loaded buffer contents of one glTF document.
pub(super) struct Buffers<'a> {
    document: &'a gltf::Document,
    bin: Option<&'a [u8]>,
    base_dir: Option<&'a Path>,
    allow_outside: bool,
    loaded: Vec<Option<Cow<'a, [u8]>>>,
    /// Bytes still allowed to be read or decoded into buffers.
    budget: u64,
    /// Elements still allowed in accessors without a buffer view.
    unbacked: usize,
}

impl<'a> Buffers<'a> {
    /// Buffers of `document`; `bin` is the GLB's BIN chunk, `base_dir` the folder relative
    /// file URIs start from (`None`: a glTF read from memory, which reads no file);
    /// `allow_outside` lets URIs name files outside it.
    pub fn new(
        document: &'a gltf::Document,
        bin: Option<&'a [u8]>,
        base_dir: Option<&'a Path>,
        allow_outside: bool,
    ) -> Self {
        Buffers {
            document,
            bin,
            base_dir,
            allow_outside,
            loaded: vec![None; document.buffers().len()],
            budget: FileKind::GltfBuffer.limit(),
            unbacked: MAX_UNBACKED_ELEMENTS,
        }
    }

    /// Takes `count` elements of an accessor without a buffer view (zeros but for its sparse
    /// values) from the file's [`MAX_UNBACKED_ELEMENTS`]; `field` names the accessor.
    pub fn take_unbacked(&mut self, count: usize, field: &str) -> Result<(), String> {
        self.unbacked = self.unbacked.checked_sub(count).ok_or_else(|| {
            format!(
                "{field}: {count} elements without a bufferView (zeros but for its sparse \
                 values) pass the limit of {MAX_UNBACKED_ELEMENTS} such elements per file: no \
                 bytes of the file back them"
            )
        })?;
        Ok(())
    }

    /// The file a URI of this document names (`name`, percent-decoded), refused when it lies
    /// outside the glTF file's folder and the load does not allow that. `field` names the URI.
    pub fn file(&self, field: &str, name: &str) -> Result<PathBuf, String> {
        let base_dir =
            (self.base_dir).ok_or_else(|| reads_no_files(field, name, BUFFER_EMBEDDED))?;
        let path = access::join(base_dir, name, self.allow_outside)
            .and_then(|p| access::resolve(base_dir, &p, self.allow_outside))
            .map_err(|e| format!("{field}: {e}"))?;
        Ok(path)
    }

    /// The folder relative file URIs start from (`None` for a glTF read from memory), and
    /// whether names may leave it.
    pub fn base_dir(&self) -> (Option<&'a Path>, bool) {
        (self.base_dir, self.allow_outside)
    }

    /// The folder the document's files must lie in (`None`: anywhere, or no folder to read).
    pub fn confinement(&self) -> Option<&'a Path> {
        self.base_dir
            .and_then(|dir| access::confinement(dir, self.allow_outside))
    }

    /// The document the buffers belong to.
    pub fn document(&self) -> &'a gltf::Document {
        self.document
    }

    /// The whole of buffer `index` (exactly its `byteLength` bytes).
    pub fn buffer(&mut self, index: usize) -> Result<&[u8], String> {
        if self.loaded.get(index).is_none() {
            return Err(format!("buffers[{index}] does not exist"));
        }
        if self.loaded[index].is_none() {
            let data = self.load(index)?;
            self.loaded[index] = Some(data);
        }
        Ok(self.loaded[index].as_deref().unwrap_or_default())
    }

    /// The bytes of a buffer view, checked to lie within its buffer.
    pub fn view(&mut self, view: &gltf::buffer::View) -> Result<&[u8], String> {
        let (offset, length) = (view.offset(), view.length());
        let buffer = view.buffer().index();
        let data = self.buffer(buffer)?;
        let end = offset.checked_add(length).filter(|&e| e <= data.len());
        match end {
            Some(end) => Ok(&data[offset..end]),
            None => Err(format!(
                "bufferViews[{}]: bytes {offset}..{} lie past the end of buffers[{buffer}] ({} \
                 bytes)",
                view.index(),
                offset as u128 + length as u128,
                data.len()
            )),
        }
    }

    fn load(&mut self, index: usize) -> Result<Cow<'a, [u8]>, String> {
        let field = format!("buffers[{index}]");
        let buffer = self
            .document
            .buffers()
            .nth(index)
            .ok_or_else(|| format!("{field} does not exist"))?;
        let length = buffer.length();
        let too_short = |what: String, got: usize| {
            format!("{field}: byteLength is {length} but {what} holds only {got} bytes")
        };
        let bytes: Cow<'a, [u8]> = match buffer.source() {
            gltf::buffer::Source::Bin => {
                let bin = self.bin.ok_or_else(|| {
                    format!("{field} refers to the GLB's BIN chunk, but there is none")
                })?;
                if bin.len() < length {
                    return Err(too_short("the GLB's BIN chunk".into(), bin.len()));
                }
                // The chunk is padded to 4 bytes: the buffer is its first byteLength bytes.
                return Ok(Cow::Borrowed(&bin[..length]));
            }
            gltf::buffer::Source::Uri(text) => {
                if length as u64 > self.budget {
                    return Err(format!(
                        "{field}: byteLength {length} exceeds the {} bytes left of the {}-byte \
                         limit on a model's buffers (set {} to raise it)",
                        self.budget,
                        FileKind::GltfBuffer.limit(),
                        crate::scene::input::LIMIT_VARIABLE
                    ));
                }
                match uri::parse(text).map_err(|e| format!("{field}.uri: {e}"))? {
                    Uri::Data { bytes, .. } => {
                        if bytes.len() < length {
                            return Err(too_short("its data URI".into(), bytes.len()));
                        }
                        Cow::Owned(bytes)
                    }
                    Uri::File(name) => {
                        let path = self.file(&format!("{field}.uri"), &name)?;
                        // Only the buffer's own bytes: a file named by many buffers is
                        // read as often, each time no more than the budget was charged.
                        let within = self.confinement();
                        let bytes =
                            read_bounded_prefix(&path, FileKind::GltfBuffer, length as u64, within)
                                .map_err(|e| format!("{field}: {e}"))?;
                        if bytes.len() < length {
                            return Err(too_short(path.display().to_string(), bytes.len()));
                        }
                        Cow::Owned(bytes)
                    }
                }
            }
        };
        self.budget = self.budget.saturating_sub(length as u64);
        let mut bytes = bytes.into_owned();
        bytes.truncate(length);
        Ok(Cow::Owned(bytes))
    }
}

/// Why a glTF read from memory does not read the file URI `name` at `field`; `embedded` says
/// where the file's bytes could go instead.
pub(super) fn reads_no_files(field: &str, name: &str, embedded: &str) -> String {
    format!(
        "{field}: names the file `{}`, and a glTF read from memory reads no files (embed it: \
         {embedded})",
        crate::scene::shown::name(name)
    )
}

/// Where a buffer's bytes go in a glTF read from memory.
pub(super) const BUFFER_EMBEDDED: &str = "the GLB's BIN chunk or a data: URI";

/// A glTF read from memory whose buffer names a file: refused before anything is decoded.
pub(super) fn file_buffer(document: &gltf::Document) -> Option<String> {
    document.buffers().find_map(|b| match b.source() {
        gltf::buffer::Source::Uri(text) if !uri::is_data(text) => Some(reads_no_files(
            &format!("buffers[{}].uri", b.index()),
            text,
            BUFFER_EMBEDDED,
        )),
        _ => None,
    })
}
