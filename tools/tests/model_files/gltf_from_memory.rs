//! A glTF held in memory (`load_gltf_from_memory`, an Android game's APK asset): it draws
//! what the same bytes draw from a file, and it reads no file, whatever its URIs name.

use crate::common;

use common::files::write;
use common::gltf::{base64, glb, Builder};
use common::gltf_models::{checker_png, floor, primitive};
use common::Gpu;
use manylight::{load_gltf_from_memory, load_scene, EsVersion, RenderOptions, SceneError};
use serde_json::json;

/// A lit, textured floor whose image lies in the GLB's BIN chunk, with a camera and a light.
fn textured_floor_glb() -> Vec<u8> {
    let mut b = Builder::default();
    let floor = primitive(&mut b, &floor(), Some(0));
    let png = b.view(&checker_png());
    b.glb(json!({
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "intensity": 20, "range": 8}
        ]}},
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [
            {"mesh": 0},
            {"translation": [0.5, 1.5, 0.5], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"camera": 0, "translation": [0, 3, 4], "rotation": [-0.3826834, 0, 0, 0.9238795]}
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}}],
        "meshes": [{"primitives": [floor]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}],
        "images": [{"bufferView": png, "mimeType": "image/png"}]
    }))
}

#[test]
fn a_glb_from_memory_draws_what_the_same_file_draws() {
    let bytes = textured_floor_glb();
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "floor.glb", &bytes);
    let (from_file, _) = load_scene(path.to_str().unwrap(), None).expect("the file");
    let (from_memory, report) =
        load_gltf_from_memory(&bytes, "floor.glb", None).expect("the same bytes in memory");
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    assert_eq!(from_memory.lights.len(), 1);
    assert!(
        from_memory.materials[0].diffuse_texture.is_some(),
        "its texture left out"
    );
    let mut gpu = Gpu::new(EsVersion::Es3);
    let opts = RenderOptions::default();
    let file_image = gpu.render(&from_file, 64, 36, &opts);
    let memory_image = gpu.render(&from_memory, 64, 36, &opts);
    assert!(
        file_image.pixels().any(|p| p[0] > 16),
        "the lit floor drew nothing"
    );
    assert!(file_image == memory_image, "another picture from memory");
}

/// File URIs name nothing to a glTF in memory: a buffer's is an error naming the buffer, an
/// image's a warning naming the image (the material keeps its flat colour), even where a
/// file of that name lies in the working folder.
#[test]
fn a_gltf_from_memory_reads_no_file() {
    let mut b = Builder::default();
    let floor = primitive(&mut b, &floor(), Some(0));
    let scene = json!({
        "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [floor]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}],
        "images": [{"uri": "Cargo.toml"}]
    });
    let external_buffer = b.document(scene.clone(), Some("Cargo.toml".into()));
    let err = load_gltf_from_memory(external_buffer.to_string().as_bytes(), "level.gltf", None)
        .expect_err("a buffer read from a file");
    let text = err.to_string();
    assert!(matches!(err, SceneError::GltfUnsupported { .. }), "{err:?}");
    assert!(
        text.contains("buffers[0].uri") && text.contains("reads no files"),
        "{text}"
    );
    let uri = format!("data:application/octet-stream;base64,{}", base64(&b.bin));
    let external_image = b.document(scene, Some(uri));
    let (loaded, report) =
        load_gltf_from_memory(external_image.to_string().as_bytes(), "level.gltf", None)
            .expect("an image file is only a warning");
    assert!(loaded.materials[0].diffuse_texture.is_none());
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("images[0].uri") && w.contains("reads no files")),
        "{:?}",
        report.warnings
    );
}

/// A byte order mark before the JSON, which the glTF specification lets readers ignore, changes
/// nothing: a GLB's JSON chunk and a `.gltf` file with one draw what they draw without.
#[test]
fn a_byte_order_mark_before_the_json_changes_nothing() {
    const BOM: &[u8] = b"\xEF\xBB\xBF";
    let mut b = Builder::default();
    let floor = primitive(&mut b, &floor(), None);
    let scene = json!({
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "intensity": 20, "range": 8}
        ]}},
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [
            {"mesh": 0},
            {"translation": [0.5, 1.5, 0.5], "extensions": {"KHR_lights_punctual": {"light": 0}}}
        ],
        "meshes": [{"primitives": [floor]}]
    });
    let text = b.gltf(scene.clone());
    let with_bom = |json: &[u8]| [BOM, json].concat();
    let plain_json = b.document(scene, None).to_string();
    let cases = [
        (
            text.as_bytes().to_vec(),
            with_bom(text.as_bytes()),
            "level.gltf",
        ),
        (
            glb(plain_json.as_bytes(), Some(&b.bin)),
            glb(&with_bom(plain_json.as_bytes()), Some(&b.bin)),
            "level.glb",
        ),
    ];
    let mut gpu = Gpu::new(EsVersion::Es3);
    let opts = RenderOptions::default();
    for (plain, marked, name) in cases {
        let (expected, _) = load_gltf_from_memory(&plain, name, None).expect(name);
        let (loaded, report) = load_gltf_from_memory(&marked, name, None)
            .unwrap_or_else(|e| panic!("{name} with a byte order mark: {e}"));
        assert!(report.warnings.is_empty(), "{name}: {:?}", report.warnings);
        assert_eq!(loaded.lights.len(), 1, "{name}");
        let image = gpu.render(&loaded, 64, 36, &opts);
        assert!(
            image.pixels().any(|p| p[0] > 16),
            "{name}: the lit floor drew nothing"
        );
        assert!(
            image == gpu.render(&expected, 64, 36, &opts),
            "{name}: another picture"
        );
    }
}
