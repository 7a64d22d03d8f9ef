//! A build without some loaders or decoders (cargo features) refuses their files clearly. Each
//! test runs only in a build that leaves its feature out (CI builds the library's unit tests
//! with `--no-default-features` too).

#[allow(unused_imports)]
use super::{load_scene, SceneError};

/// Loads `name` holding `text` from a fresh folder and returns the error.
#[allow(dead_code)]
fn refusal(name: &str, text: &str) -> (String, SceneError) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    let err = load_scene(path.to_str().unwrap(), None).expect_err("loaded without its loader");
    (path.display().to_string(), err)
}

#[cfg(not(feature = "obj"))]
#[test]
fn an_obj_file_without_the_obj_feature_names_it() {
    let (path, err) = refusal("box.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    assert!(
        matches!(err, SceneError::NotBuilt { feature: "obj", .. }),
        "{err:?}"
    );
    let text = err.to_string();
    assert!(
        text.contains(&path) && text.contains("`obj` feature is off"),
        "{text}"
    );
}

#[cfg(not(feature = "gltf"))]
#[test]
fn a_gltf_or_glb_file_without_the_gltf_feature_names_it() {
    for name in ["lamp.gltf", "LAMP.GLB"] {
        let (path, err) = refusal(name, r#"{"asset": {"version": "2.0"}}"#);
        assert!(
            matches!(
                err,
                SceneError::NotBuilt {
                    feature: "gltf",
                    ..
                }
            ),
            "{err:?}"
        );
        let text = err.to_string();
        assert!(
            text.contains(&path) && text.contains("`gltf` feature is off"),
            "{text}"
        );
    }
}

#[cfg(not(feature = "scene-files"))]
#[test]
fn a_scene_file_without_the_scene_files_feature_names_it() {
    let (_, err) = refusal("scene.json", r#"{"objects": [{"builtin": "plane"}]}"#);
    assert!(
        matches!(
            err,
            SceneError::NotBuilt {
                feature: "scene-files",
                ..
            }
        ),
        "{err:?}"
    );
}

/// A scene file's model whose loader is left out: the model's file is named.
#[cfg(all(feature = "scene-files", not(feature = "obj"), not(feature = "gltf")))]
#[test]
fn a_scene_files_model_without_its_loader_names_the_model() {
    for (key, model, feature) in [("obj", "box.obj", "obj"), ("gltf", "lamp.glb", "gltf")] {
        let text = format!(r#"{{"objects": [{{"{key}": "{model}"}}]}}"#);
        let (_, err) = refusal("scene.json", &text);
        match err {
            SceneError::NotBuilt {
                path, feature: f, ..
            } => {
                assert_eq!(f, feature);
                assert!(path.ends_with(model), "{}", path.display());
            }
            other => panic!("{other:?}"),
        }
    }
}

/// A texture whose decoder is left out is refused naming the feature, as the loaders' warning
/// then says (the material keeps its flat colour).
#[cfg(not(feature = "png"))]
#[test]
fn a_png_texture_without_the_png_feature_names_it() {
    // The signature and an IHDR of 4 × 4: the format is known from the first bytes.
    let mut png = b"\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\0\0\0\x04\0\0\0\x04\x08\x06\0\0\0".to_vec();
    png.extend_from_slice(&[0; 4]);
    let mut budget = super::texture_budget::TextureBudget::default();
    let err = super::texture_budget::decode_texture_bytes(&png, None, &mut budget)
        .expect_err("decoded without a PNG decoder");
    assert!(err.contains("`png` feature is off"), "{err}");
}

#[cfg(not(feature = "jpeg"))]
#[test]
fn a_jpeg_texture_without_the_jpeg_feature_names_it() {
    let jpeg = [0xFF, 0xD8, 0xFF, 0xE0, 0, 16, b'J', b'F', b'I', b'F', 0];
    let mut budget = super::texture_budget::TextureBudget::default();
    let err = super::texture_budget::decode_texture_bytes(
        &jpeg,
        Some(image::ImageFormat::Jpeg),
        &mut budget,
    )
    .expect_err("decoded without a JPEG decoder");
    assert!(err.contains("`jpeg` feature is off"), "{err}");
}
