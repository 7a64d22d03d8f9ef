//! glTF images → [`Texture`]s: embedded in a GLB buffer view, in a `data:` URI, or a file next
//! to the `.gltf`. Decoded with the limits the OBJ loader's textures have (at most
//! [`MAX_TEXTURE_SIDE`](crate::scene::obj::MAX_TEXTURE_SIDE) pixels a side, files within [`FileKind::Texture`]'s limit); an image
//! that is missing or does not decode is a warning and its material keeps its flat colour,
//! never an abort — as with OBJ. A file outside the glTF file's folder is refused unless the
//! load allows it ([`crate::scene::access`]).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::buffers::Buffers;
use super::uri::{self, Uri};
use crate::scene::input::{read_bounded_within, FileKind, LIMIT_VARIABLE};
use crate::scene::texture::{Filter, Sampling, Wrap};
use crate::scene::texture_budget::{self, decode_texture_bytes, TextureBudget};
use crate::scene::texture_names::{resolve_in as resolve_texture_in, Listings};
use crate::scene::Texture;
use crate::scene::{access, shown};

/// Decoded images of one glTF file, by image index and by where their bytes lie (`None`:
/// failed, warned once), the textures reading them through a sampler other than the default,
/// and what is left of the scene's texture budget and of the bytes the images may read.
pub(super) struct Textures {
    loaded: HashMap<usize, Option<Arc<Texture>>>,
    /// By image index and sampling: each shares its image's pixels.
    sampled: HashMap<(usize, Sampling), Arc<Texture>>,
    by_source: HashMap<Source, Option<Arc<Texture>>>,
    /// Encoded bytes the model's images may still read from files or decode from buffer
    /// views, all together: the limit on a model's buffers, so many images of large distinct
    /// files or views cannot read and decode without end.
    encoded_left: u64,
    pub budget: TextureBudget,
    /// The folders listed to find images in other letter case, each once a load.
    listings: Listings,
}

/// Where an image's encoded bytes lie, and the format they are decoded as, when images can
/// share them: a file or a buffer view named by many images is read and decoded once.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum Source {
    View(usize, Option<image::ImageFormat>),
    File(PathBuf, Option<image::ImageFormat>),
}

impl Textures {
    /// None decoded yet, `budget` left for those that will be.
    pub fn new(budget: TextureBudget) -> Textures {
        Textures {
            loaded: HashMap::new(),
            sampled: HashMap::new(),
            by_source: HashMap::new(),
            encoded_left: FileKind::GltfBuffer.limit(),
            budget,
            listings: Listings::default(),
        }
    }

    /// `texture`: its image (see [`Textures::load`]) read through its sampler.
    pub fn load_texture(
        &mut self,
        texture: &gltf::Texture,
        buffers: &mut Buffers,
        gltf_path: &Path,
        warnings: &mut Vec<String>,
    ) -> Result<Option<Arc<Texture>>, String> {
        let image = texture.source();
        let Some(plain) = self.load(&image, buffers, gltf_path, warnings)? else {
            return Ok(None);
        };
        let sampling = sampling_of(&texture.sampler());
        if sampling == plain.sampling {
            return Ok(Some(plain));
        }
        let sampled = self
            .sampled
            .entry((image.index(), sampling))
            .or_insert_with(|| Arc::new(plain.with_sampling(sampling)));
        Ok(Some(sampled.clone()))
    }

    /// The texture of `image`, decoded once. Problems with the image data itself are warnings
    /// (`None`); a buffer view past its buffer is an error, as anywhere else in the file.
    pub fn load(
        &mut self,
        image: &gltf::Image,
        buffers: &mut Buffers,
        gltf_path: &Path,
        warnings: &mut Vec<String>,
    ) -> Result<Option<Arc<Texture>>, String> {
        if let Some(t) = self.loaded.get(&image.index()) {
            return Ok(t.clone());
        }
        let field = format!("images[{}]", image.index());
        let texture = match locate(image, buffers, gltf_path, &field, &mut self.listings)? {
            Err(warning) => {
                warnings.push(warning);
                None
            }
            Ok(located) => {
                let source = located.source();
                match source.as_ref().and_then(|s| self.by_source.get(s)) {
                    Some(shared) => shared.clone(),
                    None => {
                        let texture = self.decode(located, buffers, &field, warnings)?;
                        if let Some(source) = source {
                            self.by_source.insert(source, texture.clone());
                        }
                        texture
                    }
                }
            }
        };
        self.loaded.insert(image.index(), texture.clone());
        Ok(texture)
    }

    /// Reads and decodes a located image within the limits; a problem is a warning (`None`).
    fn decode(
        &mut self,
        located: Located,
        buffers: &mut Buffers,
        field: &str,
        warnings: &mut Vec<String>,
    ) -> Result<Option<Arc<Texture>>, String> {
        let limit = FileKind::Texture.limit();
        let size = match &located.bytes {
            // Checked to lie within its buffer first, as everywhere else in the file.
            Bytes::View(view) => buffers
                .view(view)
                .map_err(|e| format!("{field}: {e}"))?
                .len() as u64,
            Bytes::Data(bytes) => bytes.len() as u64,
            // Refused unread when the file alone would pass the limits.
            Bytes::File(path) => std::fs::metadata(path).map_or(0, |m| m.len()),
        };
        let refusal = if size > limit {
            Some(format!(
                "texture {} of {size} bytes exceeds the limit of {limit} bytes (set \
                 {LIMIT_VARIABLE} to raise it); using the flat colour",
                located.name
            ))
        } else if size > self.encoded_left {
            Some(format!(
                "texture {}: the model's images together pass the limit of {} bytes on what \
                 they may read (set {LIMIT_VARIABLE} to raise it); using the flat colour",
                located.name,
                FileKind::GltfBuffer.limit()
            ))
        } else {
            None
        };
        if let Some(refusal) = refusal {
            warnings.push(refusal);
            return Ok(None);
        }
        let file_bytes;
        let within = buffers.confinement();
        let bytes: &[u8] = match &located.bytes {
            Bytes::View(view) => buffers.view(view).map_err(|e| format!("{field}: {e}"))?,
            Bytes::Data(bytes) => bytes,
            Bytes::File(path) => match read_bounded_within(path, FileKind::Texture, within) {
                Ok(bytes) => {
                    file_bytes = bytes;
                    &file_bytes
                }
                Err(e) => {
                    warnings.push(format!(
                        "texture {} could not be decoded ({e}); using the flat colour",
                        path.display()
                    ));
                    return Ok(None);
                }
            },
        };
        self.encoded_left = self.encoded_left.saturating_sub(bytes.len() as u64);
        Ok(
            match decode_texture_bytes(bytes, located.format, &mut self.budget) {
                Ok(img) => {
                    let (image, scaled) = texture_budget::to_rgba8(img, &located.name);
                    warnings.extend(scaled);
                    Some(Arc::new(Texture::new(located.name, image)))
                }
                Err(why) => {
                    warnings.push(format!(
                        "texture {} {why}; using the flat colour",
                        located.name
                    ));
                    None
                }
            },
        )
    }
}

/// A glTF sampler as [`Sampling`]: a filter the file leaves out is linear, mipmapped
/// between the two nearest levels (the renderer's default).
pub(super) fn sampling_of(sampler: &gltf::texture::Sampler) -> Sampling {
    use gltf::texture::{MagFilter, MinFilter, WrappingMode};
    let wrap = |mode| match mode {
        WrappingMode::Repeat => Wrap::Repeat,
        WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
    };
    let magnify = match sampler.mag_filter() {
        Some(MagFilter::Nearest) => Filter::Nearest,
        Some(MagFilter::Linear) | None => Filter::Linear,
    };
    let (minify, mipmap) = match sampler.min_filter() {
        Some(MinFilter::Nearest) => (Filter::Nearest, None),
        Some(MinFilter::Linear) => (Filter::Linear, None),
        Some(MinFilter::NearestMipmapNearest) => (Filter::Nearest, Some(Filter::Nearest)),
        Some(MinFilter::LinearMipmapNearest) => (Filter::Linear, Some(Filter::Nearest)),
        Some(MinFilter::NearestMipmapLinear) => (Filter::Nearest, Some(Filter::Linear)),
        Some(MinFilter::LinearMipmapLinear) | None => (Filter::Linear, Some(Filter::Linear)),
    };
    Sampling {
        wrap_u: wrap(sampler.wrap_s()),
        wrap_v: wrap(sampler.wrap_t()),
        magnify,
        minify,
        mipmap,
    }
}

/// Where an image's encoded bytes are, not yet read: its name for messages and its format.
struct Located<'d> {
    bytes: Bytes<'d>,
    name: String,
    format: Option<image::ImageFormat>,
}

enum Bytes<'d> {
    View(gltf::buffer::View<'d>),
    Data(Vec<u8>),
    File(PathBuf),
}

impl Located<'_> {
    /// What other images may share (a `data:` URI belongs to its image alone).
    fn source(&self) -> Option<Source> {
        match &self.bytes {
            // With the format it is decoded as: a `mimeType` names it for an image.
            Bytes::View(view) => Some(Source::View(view.index(), self.format)),
            Bytes::Data(_) => None,
            Bytes::File(path) => Some(Source::File(path.clone(), self.format)),
        }
    }
}

fn format_of(media_type: &str) -> Option<image::ImageFormat> {
    image::ImageFormat::from_mime_type(media_type)
}

/// Where the image's encoded bytes are (outer `Err`: a malformed file; inner `Err`: a
/// warning).
fn locate<'d>(
    image: &gltf::Image,
    buffers: &Buffers<'d>,
    gltf_path: &Path,
    field: &str,
    listings: &mut Listings,
) -> Result<Result<Located<'d>, String>, String> {
    let embedded_name = format!("{}#{field}", gltf_path.display());
    // From the JSON rather than `image.source()`, which assumes a `uri` where there is no
    // `bufferView` and a `mimeType` where there is one.
    let Some(json) = buffers.document().as_json().images.get(image.index()) else {
        return Ok(Err(format!(
            "{field} does not exist; using the flat colour"
        )));
    };
    let mime_type = json.mime_type.as_ref().map(|m| m.0.clone());
    if let Some(view_index) = json.buffer_view {
        let Some(view) = buffers.document().views().nth(view_index.value()) else {
            return Err(format!(
                "{field}.bufferView: no bufferViews[{}]",
                view_index.value()
            ));
        };
        return Ok(Ok(Located {
            bytes: Bytes::View(view),
            name: embedded_name,
            format: mime_type.as_deref().and_then(format_of),
        }));
    }
    let Some(text) = json.uri.as_deref() else {
        return Ok(Err(format!(
            "{field} has neither a uri nor a bufferView; using the flat colour"
        )));
    };
    match uri::parse(text) {
        Err(e) => Ok(Err(format!("{field}.uri: {e}; using the flat colour"))),
        Ok(Uri::Data { media_type, bytes }) => Ok(Ok(Located {
            bytes: Bytes::Data(bytes),
            name: embedded_name,
            format: format_of(mime_type.as_deref().unwrap_or(&media_type)),
        })),
        Ok(Uri::File(name)) => {
            let (base_dir, allow_outside) = buffers.base_dir();
            let uri_field = format!("{field}.uri");
            let Some(base_dir) = base_dir else {
                let embedded = "a bufferView or a data: URI";
                let why = super::buffers::reads_no_files(&uri_field, &name, embedded);
                return Ok(Err(format!("{why}; using the flat colour")));
            };
            let as_written = access::join(base_dir, &name, allow_outside)
                .map_err(|e| format!("{uri_field}: {e}"))?;
            // As written first (names may hold spaces); then in other letter case or
            // flattened folders, as OBJ textures are found. Wherever found, it must lie
            // inside the folder (a link may lead out).
            let path = if as_written.is_file() {
                Some(as_written)
            } else if as_written.exists() {
                // A FIFO, device or folder (or a link to one): named so, once it is known to
                // lie inside the folder.
                access::resolve(base_dir, &as_written, allow_outside)
                    .map_err(|e| format!("{uri_field}: {e}"))?;
                return Ok(Err(format!(
                    "{field}: texture `{}` is not a regular file (a folder, device or FIFO); \
                     using its flat colour",
                    shown::name(&name)
                )));
            } else {
                // Any `..` that stays in the folder taken out, as the join did.
                let relative = access::inside(&name).unwrap_or(name.as_str().into());
                resolve_texture_in(base_dir, &relative, allow_outside, listings)
            };
            let path = match path {
                Some(p) => Some(
                    access::resolve(base_dir, &p, allow_outside)
                        .map_err(|e| format!("{uri_field}: {e}"))?,
                ),
                None => None,
            };
            let Some(path) = path else {
                return Ok(Err(format!(
                    "{field}: texture `{}` not found next to {}; using its flat colour",
                    shown::name(&name),
                    gltf_path.display()
                )));
            };
            let format = mime_type
                .as_deref()
                .and_then(format_of)
                .or_else(|| image::ImageFormat::from_path(&path).ok());
            Ok(Ok(Located {
                name: path.display().to_string(),
                bytes: Bytes::File(path),
                format,
            }))
        }
    }
}

/// Decodes with the OBJ loader's limits ([`decode_texture_bytes`]) and a whole budget.
#[cfg(test)]
fn decode(bytes: &[u8], format: Option<image::ImageFormat>) -> Result<image::DynamicImage, String> {
    decode_texture_bytes(bytes, format, &mut TextureBudget::default())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Images not found as written are searched for in other letter case: the model's folder
    /// is listed once a load, not once an image (20 000 images over a folder of 50 000 files
    /// listed it 20 000 times: minutes).
    #[test]
    fn the_folder_is_listed_once_however_many_images_are_missing() {
        let dir = tempfile::tempdir().unwrap();
        for i in 0..50 {
            std::fs::write(dir.path().join(format!("other{i}.txt")), "").unwrap();
        }
        let positions: Vec<u8> = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        std::fs::write(dir.path().join("b.bin"), &positions).unwrap();
        let n = 20;
        let doc = serde_json::json!({
            "asset": {"version": "2.0"},
            "buffers": [{"uri": "b.bin", "byteLength": 36}],
            "bufferViews": [{"buffer": 0, "byteLength": 36}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                "min": [0, 0, 0], "max": [1, 1, 0]}],
            "images": (0..n).map(|i| serde_json::json!({"uri": format!("missing{i}.png")}))
                .collect::<Vec<_>>(),
            "textures": (0..n).map(|i| serde_json::json!({"source": i})).collect::<Vec<_>>(),
            "materials": (0..n)
                .map(|i| serde_json::json!({"pbrMetallicRoughness":
                    {"baseColorTexture": {"index": i}}}))
                .collect::<Vec<_>>(),
            "meshes": [{"primitives": (0..n)
                .map(|i| serde_json::json!({"attributes": {"POSITION": 0}, "material": i}))
                .collect::<Vec<_>>()}],
            "nodes": [{"mesh": 0}],
            "scenes": [{"nodes": [0]}],
        });
        let path = dir.path().join("m.gltf");
        std::fs::write(&path, doc.to_string()).unwrap();
        let before = crate::scene::texture_names::FOLDERS_LISTED.with(std::cell::Cell::get);
        let (_, report) = crate::scene::load(path.to_str().unwrap(), None).unwrap();
        let listed =
            crate::scene::texture_names::FOLDERS_LISTED.with(std::cell::Cell::get) - before;
        let missing = report
            .warnings
            .iter()
            .filter(|w| w.contains("not found"))
            .count();
        assert_eq!(missing, n, "{:?}", report.warnings);
        assert_eq!(listed, 1);
    }

    /// Every wrap and filter code of glTF 2.0 §5.26 as the GL parameter of the same name;
    /// left out, a filter is the renderer's default and a wrap `REPEAT`.
    #[test]
    fn samplers_map_to_their_gl_parameters() {
        let samplers = r#"[
            {},
            {"wrapS": 33071, "wrapT": 33648, "magFilter": 9728, "minFilter": 9728},
            {"wrapS": 33648, "wrapT": 10497, "magFilter": 9729, "minFilter": 9729},
            {"minFilter": 9984}, {"minFilter": 9985}, {"minFilter": 9986}, {"minFilter": 9987}
        ]"#;
        let json = format!(
            r#"{{"asset": {{"version": "2.0"}}, "images": [{{"uri": "a.png"}}],
                "samplers": {samplers},
                "textures": [{}]}}"#,
            (0..7)
                .map(|i| format!(r#"{{"source": 0, "sampler": {i}}}"#))
                .chain([r#"{"source": 0}"#.to_string()])
                .collect::<Vec<_>>()
                .join(", ")
        );
        let document = gltf::Gltf::from_slice(json.as_bytes()).unwrap().document;
        let got: Vec<Sampling> = document
            .textures()
            .map(|t| sampling_of(&t.sampler()))
            .collect();
        let (n, l) = (Filter::Nearest, Filter::Linear);
        let with = |minify, mipmap| Sampling {
            minify,
            mipmap,
            ..Sampling::default()
        };
        let want = [
            Sampling::default(),
            Sampling {
                wrap_u: Wrap::ClampToEdge,
                wrap_v: Wrap::MirroredRepeat,
                magnify: n,
                minify: n,
                mipmap: None,
            },
            Sampling {
                wrap_u: Wrap::MirroredRepeat,
                wrap_v: Wrap::Repeat,
                magnify: l,
                minify: l,
                mipmap: None,
            },
            with(n, Some(n)),
            with(l, Some(n)),
            with(n, Some(l)),
            with(l, Some(l)),
            Sampling::default(),
        ];
        assert_eq!(got, want);
        assert_eq!(
            Sampling::default(),
            Sampling {
                wrap_u: Wrap::Repeat,
                wrap_v: Wrap::Repeat,
                magnify: l,
                minify: l,
                mipmap: Some(l),
            }
        );
    }

    #[test]
    #[cfg(feature = "png")]
    fn decodes_a_png_and_refuses_a_claimed_giant() {
        let img = image::RgbaImage::from_pixel(3, 2, image::Rgba([10, 20, 30, 255]));
        let mut png = Vec::new();
        img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .unwrap();
        let decoded = decode(&png, format_of("image/png")).unwrap();
        assert_eq!((decoded.width(), decoded.height()), (3, 2));
        // The same PNG with its header claiming 100 000 × 2 pixels.
        let mut giant = png.clone();
        giant[16..20].copy_from_slice(&100_000u32.to_be_bytes());
        assert!(decode(&giant, None).is_err());
        assert!(decode(b"not an image", format_of("image/jpeg")).is_err());
    }
}
