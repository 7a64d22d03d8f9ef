//! What the fuzz targets share: a folder of their own with a model folder inside it and
//! sentinel files outside it, and the checks every load must pass.
//!
//! The checks, besides "no panic, no abort, no hang, no unbounded memory" (libFuzzer's own):
//! - nothing from outside the model's folder reaches the scene: the sentinels beside it (an
//!   image, a buffer of 12 345.5s, a material), read by a path or through a link in the model's
//!   folder, are never loaded. Images and names are recognised by a hash, never compared as
//!   they are: libFuzzer learns the values a target compares its input with, and would make
//!   the sentinels themselves.
//! - a message (the error, every warning) quotes no control or reordering character and stays
//!   short: it never carries a file's bytes as they are.

use std::hash::{DefaultHasher, Hash, Hasher};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use manylight::image::{Rgba, RgbaImage};
use manylight::{LoadOptions, LoadReport, Scene, SceneError};

const SCENE_OBJ: &str = "mtllib s_model.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
                         vt 0 0\nvt 1 1\nusemtl lit\nf 1/1 2/2 3/1 4/2\n";
const SCENE_MTL: &str = "newmtl lit\nKd 0.5 0.6 0.7\nKs 0.2 0.2 0.2\nNs 32\n";
const SCENE_GLTF: &str = include_str!("s_model.gltf");

/// The sentinel image's size and colour.
const SENTINEL_SIZE: (u32, u32) = (7, 3);
const SENTINEL_PIXEL: [u8; 4] = [9, 8, 7, 255];

/// The value the sentinel buffer repeats (floats are compared without libFuzzer looking).
const SENTINEL_VALUE: f32 = 12_345.5;

/// The name of the sentinel material.
const SENTINEL_MATERIAL: &str = "outside_sentinel";

/// Most characters a message may have: a few quoted names and paths and one parser's reason
/// (which the library cuts at 1 000 characters).
const MAX_MESSAGE: usize = 4096;

/// A fuzz process's folder: `root/model/` holds the files a target writes and the models the
/// scene files name, `root/` the sentinels, and links inside `model/` lead to them.
pub struct Folder {
    model: PathBuf,
    /// The hashes of the sentinel image and material name.
    image_hash: u64,
    name_hash: u64,
}

impl Folder {
    /// The process's folder, made on first use (in the temporary folder, named by the
    /// process's id, so parallel fuzzing jobs do not share one).
    pub fn get() -> &'static Folder {
        static FOLDER: OnceLock<Folder> = OnceLock::new();
        FOLDER.get_or_init(|| Folder::make().expect("the fuzz folder could not be made"))
    }

    fn make() -> std::io::Result<Folder> {
        let root = std::env::temp_dir().join(format!("manylight-fuzz-{}", std::process::id()));
        let model = root.join("model");
        std::fs::create_dir_all(&model)?;
        let sentinel = sentinel_image();
        sentinel
            .save(root.join("outside.png"))
            .map_err(std::io::Error::other)?;
        let values: Vec<u8> = std::iter::repeat_n(SENTINEL_VALUE.to_le_bytes(), 1024)
            .flatten()
            .collect();
        std::fs::write(root.join("outside.bin"), values)?;
        std::fs::write(
            root.join("outside.mtl"),
            format!("newmtl {SENTINEL_MATERIAL}\nKd 0.1 0.2 0.3\nmap_Kd outside.png\n"),
        )?;
        // Links in the model's folder that lead out of it, and a folder link to its parent.
        for (link, target) in [
            ("in_link.png", "../outside.png"),
            ("in_link.bin", "../outside.bin"),
            ("in_link.mtl", "../outside.mtl"),
            ("up", ".."),
        ] {
            let at = model.join(link);
            if at.symlink_metadata().is_err() {
                std::os::unix::fs::symlink(target, at)?;
            }
        }
        // The models the scene-file seeds name: a square with a material, and a triangle
        // with a light and a camera, its buffer inline.
        std::fs::write(model.join("s_model.obj"), SCENE_OBJ)?;
        std::fs::write(model.join("s_model.mtl"), SCENE_MTL)?;
        std::fs::write(model.join("s_model.gltf"), SCENE_GLTF)?;
        Ok(Folder {
            model,
            image_hash: hash(&(sentinel.dimensions(), sentinel.as_raw())),
            name_hash: hash(SENTINEL_MATERIAL),
        })
    }

    /// Writes `bytes` as `name` in the model's folder; its path.
    pub fn write(&self, name: &str, bytes: &[u8]) -> PathBuf {
        let path = self.model.join(name);
        std::fs::write(&path, bytes).expect("a fuzz input could not be written");
        path
    }

    /// The path of `name` in the model's folder.
    pub fn path(&self, name: &str) -> PathBuf {
        self.model.join(name)
    }

    /// Writes each of `parts` as the file `names` gives it in the model's folder, and removes
    /// the named files that get no part (an input that ends early has no texture, say).
    pub fn write_parts(&self, names: &[&str], parts: &[&[u8]]) {
        for (i, name) in names.iter().enumerate() {
            match parts.get(i) {
                Some(bytes) => {
                    self.write(name, bytes);
                }
                None => {
                    let _ = std::fs::remove_file(self.model.join(name));
                }
            }
        }
    }
}

/// `data` cut at its first `parts - 1` bytes 0xFF (a byte UTF-8 text never holds), as many
/// parts as there are (the last takes the rest, 0xFF bytes included).
pub fn split(data: &[u8], parts: usize) -> Vec<&[u8]> {
    data.splitn(parts, |&b| b == 0xFF).collect()
}

/// Loads `path` as the library's `load_scene_with` does for a user (the default options:
/// a model reads only its own folder), then checks what came back: where `confined`, that
/// nothing outside the model's folder was read (a scene file, the user's own, may name files
/// anywhere).
pub fn load_and_check(path: &Path, confined: bool) {
    let spec = path.to_str().expect("the fuzz folder's paths are UTF-8");
    match manylight::load_scene_with(spec, None, &LoadOptions::default()) {
        Ok((mut scene, report)) => {
            check_report(&report);
            if confined {
                Folder::get().check_nothing_from_outside(&scene);
            }
            // What a renderer does with a loaded scene before the GPU sees it.
            let _ = scene.bounds();
            let _ = scene.has_visible_area();
            scene.set_time(1.5);
            if let Err(e) = scene.validate() {
                check_message(&e.to_string());
            }
        }
        Err(e) => check_error(&e),
    }
}

fn check_error(e: &SceneError) {
    check_message(&e.to_string());
}

fn check_report(report: &LoadReport) {
    for warning in &report.warnings {
        check_message(warning);
    }
}

/// A message quotes no control or reordering character and is at most [`MAX_MESSAGE`]
/// characters long. Line ends are allowed: a few messages are written over lines on purpose.
fn check_message(message: &str) {
    let bad = message.chars().find(|&c| {
        (c.is_control() && c != '\n')
            || matches!(c, '\u{61c}' | '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
    });
    assert!(
        bad.is_none(),
        "a message quotes {:?} as it is: {message:?}",
        bad.unwrap()
    );
    let length = message.chars().count();
    assert!(
        length <= MAX_MESSAGE,
        "a message of {length} characters: {:?}…",
        message.chars().take(200).collect::<String>()
    );
}

impl Folder {
    /// Fails if anything of the sentinels outside the model's folder is in `scene`.
    fn check_nothing_from_outside(&self, scene: &Scene) {
        for material in &scene.materials {
            assert_ne!(
                hash(&material.name),
                self.name_hash,
                "the material outside was read"
            );
            let maps = &material.maps;
            let textures = material
                .diffuse_texture
                .iter()
                .chain(maps.normal.iter().map(|m| &m.texture))
                .chain(maps.emissive_texture.iter().map(|m| &m.texture))
                .chain(maps.occlusion.iter().map(|m| &m.texture))
                .chain(maps.metallic_roughness.iter().map(|m| &m.texture));
            for texture in textures {
                assert_ne!(
                    hash(&(texture.image.dimensions(), texture.image.as_raw())),
                    self.image_hash,
                    "the image outside was read ({})",
                    texture.name
                );
            }
        }
        for object in &scene.objects {
            let mesh = &object.mesh;
            let floats = mesh
                .positions
                .iter()
                .chain(&mesh.normals)
                .flat_map(|v| v.to_array())
                .chain(mesh.uvs.iter().flat_map(|v| v.to_array()))
                .chain(mesh.colors.iter().flat_map(|v| v.to_array()))
                .chain(mesh.tangents.iter().flat_map(|v| v.to_array()));
            let mut sentinels = 0;
            for value in floats {
                if value == SENTINEL_VALUE {
                    sentinels += 1;
                    // One by chance is possible; a run of them is the buffer outside.
                    assert!(sentinels < 3, "the buffer outside was read");
                }
            }
        }
    }
}

fn sentinel_image() -> RgbaImage {
    RgbaImage::from_pixel(SENTINEL_SIZE.0, SENTINEL_SIZE.1, Rgba(SENTINEL_PIXEL))
}

fn hash<T: Hash + ?Sized>(value: &T) -> u64 {
    let mut hasher = DefaultHasher::new();
    value.hash(&mut hasher);
    hasher.finish()
}
