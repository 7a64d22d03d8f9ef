//! Hostile glTF files, on files the tests write: buffer and image URIs leaving the model's
//! folder (`..`, `%2e%2e`, absolute paths, links) are refused unless outside files are allowed
//! (in the library and on the command line); a scene file may name models anywhere but their
//! own URIs stay confined; a folder or a device is named as not a file; and no error shows a
//! byte of an outside file or a string of a JSON file that is not glTF.

mod common;

use std::path::PathBuf;

use common::files::{load, load_with, write};
use common::gltf::{base64, Builder};
use common::gltf_models::{checker_png, floor, primitive, triangle};
use serde_json::{json, Value};

/// What a test model may not read: files beside its folder, with bytes a message must never
/// show. `b.bin` is a valid buffer for the model (so a load that reads it succeeds).
struct Outside {
    root: tempfile::TempDir,
}

const SENTINEL: &str = "SENTINEL-83-do-not-show";

impl Outside {
    fn new(bin: &[u8]) -> Outside {
        let root = tempfile::tempdir().unwrap();
        std::fs::create_dir(root.path().join("model")).unwrap();
        std::fs::write(root.path().join("b.bin"), bin).unwrap();
        std::fs::write(root.path().join("secret.txt"), SENTINEL.repeat(4)).unwrap();
        std::fs::write(root.path().join("secret.png"), checker_png()).unwrap();
        Outside { root }
    }

    fn model(&self) -> PathBuf {
        self.root.path().join("model")
    }
}

#[test]
fn buffer_uris_outside_the_models_folder_are_refused_unless_allowed() {
    let mut b = Builder::default();
    let doc = triangle(&mut b);
    let out = Outside::new(&b.bin);
    std::fs::create_dir(out.model().join("sub")).unwrap();
    let abs = out.root.path().join("b.bin");
    #[cfg(unix)]
    std::os::unix::fs::symlink(&abs, out.model().join("link.bin")).unwrap();
    let mut uris = vec![
        "../b.bin".to_string(),
        "%2e%2e/b.bin".into(),
        "%2E%2E%2Fb.bin".into(),
        "sub/../../b.bin".into(),
        abs.to_str().unwrap().into(),
        abs.to_str().unwrap().replace('.', "%2e"),
    ];
    if cfg!(unix) {
        uris.push("link.bin".into());
    }
    for uri in &uris {
        let path = write(
            &out.model(),
            "m.gltf",
            b.document(doc.clone(), Some(uri.clone())).to_string(),
        );
        let err = load(&path).unwrap_err().to_string();
        assert!(
            err.contains("buffers[0].uri") && err.contains("outside the model's folder"),
            "{uri}: {err}"
        );
        assert!(err.contains("--allow-outside-files"), "{err}");
        let (scene, _) = load_with(&path, true).unwrap_or_else(|e| panic!("{uri}: {e}"));
        assert_eq!(scene.objects.len(), 1, "{uri}");
    }
    // Other systems' absolute forms are refused before anything is looked up.
    for uri in [
        "C:/b.bin",
        "c:%5Cb.bin",
        "%5C%5Cserver%5Cshare%5Cb.bin",
        "\\\\server\\b.bin",
    ] {
        let path = write(
            &out.model(),
            "m.gltf",
            b.document(doc.clone(), Some(uri.into())).to_string(),
        );
        let err = load(&path).unwrap_err().to_string();
        assert!(err.contains("outside the model's folder"), "{uri}: {err}");
    }
    // A file inside the folder is read as before.
    std::fs::write(out.model().join("in.bin"), &b.bin).unwrap();
    let path = write(
        &out.model(),
        "m.gltf",
        b.document(doc, Some("./in.bin".into())).to_string(),
    );
    assert_eq!(load(&path).unwrap().0.objects.len(), 1);
}

#[test]
fn an_index_accessor_over_an_outside_text_file_shows_none_of_its_bytes() {
    let mut b = Builder::default();
    let doc = triangle(&mut b);
    let out = Outside::new(&b.bin);
    // The text file as a second buffer, read as the indices.
    let data = format!("data:application/octet-stream;base64,{}", base64(&b.bin));
    let mut doc = b.document(doc, Some(data));
    let text = SENTINEL.repeat(4);
    doc["buffers"]
        .as_array_mut()
        .unwrap()
        .push(json!({"uri": "../secret.txt", "byteLength": text.len()}));
    doc["bufferViews"][1] = json!({"buffer": 1, "byteOffset": 0, "byteLength": 6});
    let path = write(&out.model(), "m.gltf", doc.to_string());
    let refused = load(&path).unwrap_err().to_string();
    assert!(refused.contains("buffers[1].uri"), "{refused}");
    // Allowed: read, and the index error says where, not what the bytes were.
    let err = load_with(&path, true).unwrap_err().to_string();
    let shown_value = u16::from_le_bytes([text.as_bytes()[0], text.as_bytes()[1]]);
    assert!(
        err.contains("element 0 is out of range for 3 vertices"),
        "{err}"
    );
    for secret in [SENTINEL.to_string(), shown_value.to_string()] {
        assert!(!err.contains(&secret), "{err}");
    }
}

#[test]
fn image_uris_outside_the_models_folder_are_refused_unless_allowed() {
    let mut b = Builder::default();
    let prim = primitive(&mut b, &floor(), Some(0));
    let out = Outside::new(&b.bin);
    #[cfg(unix)]
    std::os::unix::fs::symlink(
        out.root.path().join("secret.png"),
        out.model().join("link.png"),
    )
    .unwrap();
    let mut uris = vec!["../secret.png", "%2e%2e/secret.png", "..\\secret.png"];
    if cfg!(unix) {
        uris.push("link.png");
    }
    for uri in uris {
        let doc = json!({
            "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [prim]}],
            "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
            "textures": [{"source": 0}], "images": [{"uri": uri}],
        });
        let path = write(&out.model(), "m.gltf", b.gltf(doc));
        let err = load(&path).unwrap_err().to_string();
        assert!(
            err.contains("images[0].uri") && err.contains("outside the model's folder"),
            "{uri}: {err}"
        );
        if uri.contains('\\') {
            continue; // a backslash is no separator here: allowed, the file is just absent
        }
        let (scene, report) = load_with(&path, true).unwrap();
        assert!(report.warnings.is_empty(), "{uri}: {:?}", report.warnings);
        assert!(scene.materials[0].diffuse_texture.is_some(), "{uri}");
    }
    // A folder in the model's folder is named as not a file (it was "not found"); a link to a
    // device outside is refused as leading out.
    std::fs::create_dir(out.model().join("maps")).unwrap();
    #[cfg(unix)]
    std::os::unix::fs::symlink("/dev/zero", out.model().join("zero.png")).unwrap();
    let image_doc = |uri: &str| {
        json!({
            "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [prim]}],
            "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
            "textures": [{"source": 0}], "images": [{"uri": uri}],
        })
    };
    let path = write(&out.model(), "m.gltf", b.gltf(image_doc("maps")));
    let (scene, report) = load(&path).unwrap();
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("`maps` is not a regular file")),
        "{:?}",
        report.warnings
    );
    assert!(scene.materials[0].diffuse_texture.is_none());
    if cfg!(unix) {
        let path = write(&out.model(), "m.gltf", b.gltf(image_doc("zero.png")));
        let err = load(&path).unwrap_err().to_string();
        assert!(err.contains("a link leads out"), "{err}");
    }
}

#[test]
fn a_scene_file_may_name_models_anywhere_but_their_own_uris_stay_confined() {
    let mut b = Builder::default();
    let doc = triangle(&mut b);
    let out = Outside::new(&b.bin);
    std::fs::write(out.model().join("in.bin"), &b.bin).unwrap();
    write(
        &out.model(),
        "in.gltf",
        b.document(doc.clone(), Some("in.bin".into())).to_string(),
    );
    write(
        &out.model(),
        "out.gltf",
        b.document(doc, Some("../b.bin".into())).to_string(),
    );
    let scenes = out.root.path().join("scenes");
    std::fs::create_dir(&scenes).unwrap();
    let ok = write(
        &scenes,
        "ok.json",
        r#"{"objects": [{"gltf": "../model/in.gltf"}]}"#,
    );
    assert_eq!(load(&ok).unwrap().0.objects.len(), 1);
    let bad = write(
        &scenes,
        "bad.json",
        r#"{"objects": [{"gltf": "../model/out.gltf"}]}"#,
    );
    let err = load(&bad).unwrap_err().to_string();
    assert!(
        err.contains("out.gltf") && err.contains("buffers[0].uri"),
        "{err}"
    );
    assert_eq!(load_with(&bad, true).unwrap().0.objects.len(), 1);
}

#[test]
fn gltf_files_and_buffers_are_named_as_such_in_limit_errors() {
    let out = Outside::new(&[]);
    let folder = out.model().join("folder.gltf");
    std::fs::create_dir(&folder).unwrap();
    let err = load(&folder).unwrap_err().to_string();
    assert!(err.contains("the glTF file must be a file"), "{err}");
    assert!(!err.contains("OBJ"), "{err}");
    #[cfg(unix)]
    {
        let mut b = Builder::default();
        let doc = triangle(&mut b);
        let path = write(
            &out.model(),
            "zero.gltf",
            b.document(doc, Some("/dev/zero".into())).to_string(),
        );
        assert!(load(&path).unwrap_err().to_string().contains("outside"));
        let err = load_with(&path, true).unwrap_err().to_string();
        assert!(
            err.contains("buffers[0]") && err.contains("the glTF buffer must be a file"),
            "{err}"
        );
    }
}

#[test]
fn the_cli_refuses_an_outside_buffer_unless_allow_outside_files_is_given() {
    let mut b = Builder::default();
    let doc = triangle(&mut b);
    let out = Outside::new(&b.bin);
    let gltf = b.document(doc, Some("../b.bin".into())).to_string();
    write(&out.model(), "m.gltf", gltf);
    let args = [
        "render",
        "--scene",
        "model/m.gltf",
        "--size",
        "64x36",
        "--lights",
        "4",
        "--out",
        "o.png",
    ];
    let refused = common::cli::expect_exit(&args, &[], out.root.path(), 1, "buffers[0].uri");
    assert!(refused.contains("--allow-outside-files"), "{refused}");
    assert!(!out.root.path().join("o.png").exists());
    let allowed = [&args[..], &["--allow-outside-files"]].concat();
    common::cli::expect_status(&allowed, &[], out.root.path(), 0);
    assert!(out.root.path().join("o.png").is_file());
}

#[test]
fn a_json_file_that_is_not_gltf_shows_none_of_its_strings() {
    // A scene file may name any file as its glTF: serde's own message would quote the value.
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "config.json",
        format!(r#"{{"asset": "{SENTINEL}", "token": 1}}"#),
    );
    let scene_file = write(
        dir.path(),
        "s.json",
        r#"{"objects": [{"gltf": "config.json"}]}"#,
    );
    let mut paths = vec![scene_file];
    for (name, text) in [
        (
            "enum.gltf",
            format!(r#"{{"asset": {{"version": "2.0"}}, "scene": "{SENTINEL}"}}"#),
        ),
        ("syntax.gltf", format!(r#"{{"asset": {SENTINEL}}}"#)),
    ] {
        paths.push(write(dir.path(), name, text));
    }
    for path in paths {
        let err = load(&path).unwrap_err().to_string();
        assert!(err.contains("line 1"), "{err}");
        assert!(!err.contains(SENTINEL), "{err}");
    }
    let path = write(dir.path(), "none.gltf", "{}");
    let err = load(&path).unwrap_err().to_string();
    assert!(err.contains("missing field `asset`"), "{err}");
    // Keys the file made up are not shown where an error names a field: a number past u32
    // under one, an application-specific attribute (`_NAME`) with an index out of range.
    let made_up_key = SENTINEL.replace('-', "_");
    for (name, text) in [
        (
            "wide.gltf",
            format!(r#"{{"{made_up_key}": [{{"n": 1700000000000}}]}}"#),
        ),
        (
            "attribute.gltf",
            format!(
                r#"{{"asset": {{"version": "2.0"}}, "meshes": [{{"primitives":
                [{{"attributes": {{"_{made_up_key}": 5}}}}]}}]}}"#
            ),
        ),
    ] {
        let err = load(&write(dir.path(), name, text))
            .unwrap_err()
            .to_string();
        assert!(err.contains("meshes[0]") || err.contains("…[0]"), "{err}");
        assert!(!err.contains(&made_up_key), "{err}");
    }
}

/// Distinct meshes each cost a fixed few KB besides their data: a small file listing more than
/// `MAX_SCENE_MESHES` of them (one triangle's accessor shared by all, each with its own
/// material) is refused naming the first one past the limit, before memory runs out; as many
/// placements of one mesh load.
#[test]
fn more_distinct_meshes_than_the_limit_are_refused_naming_the_first_past_it() {
    use manylight::scene::MAX_SCENE_MESHES;
    let mut b = Builder::default();
    let p = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3");
    let n = MAX_SCENE_MESHES + 1;
    let dir = tempfile::tempdir().unwrap();
    // Each mesh's primitive names its own material (the same accessors and material would
    // build one mesh for all).
    let model = |meshes: usize| {
        let mesh =
            |i: usize| json!({"primitives": [{"attributes": {"POSITION": p}, "material": i}]});
        b.gltf(json!({
            "scene": 0,
            "scenes": [{"nodes": (0..n).collect::<Vec<_>>()}],
            "nodes": (0..n).map(|i| json!({"mesh": i % meshes})).collect::<Vec<_>>(),
            "meshes": (0..meshes).map(mesh).collect::<Vec<_>>(),
            "materials": vec![json!({}); meshes],
        }))
    };
    let err = load(&write(dir.path(), "many.gltf", model(n)))
        .unwrap_err()
        .to_string();
    let past = format!("meshes[{MAX_SCENE_MESHES}].primitives[0]");
    assert!(
        err.contains(&past) && err.contains(&MAX_SCENE_MESHES.to_string()),
        "{err}"
    );
    // They load; placed alike (one mesh, one material, the identity), all but one are
    // dropped as repeats, with a warning.
    let (scene, report) = load(&write(dir.path(), "shared.gltf", model(1))).unwrap();
    assert_eq!(scene.objects.len(), 1);
    let repeats = format!("{} objects repeat an earlier one", n - 1);
    assert!(
        report.warnings.iter().any(|w| w.contains(&repeats)),
        "{:?}",
        report.warnings
    );
    // Primitives skipped as points hold nothing and do not count.
    let points = json!({"primitives": [{"attributes": {"POSITION": p}, "mode": 0}]});
    let triangle = json!({"primitives": [{"attributes": {"POSITION": p}}]});
    let mut meshes = vec![points; n];
    meshes.push(triangle);
    let skipped = b.gltf(json!({
        "scene": 0,
        "scenes": [{"nodes": (0..=n).collect::<Vec<_>>()}],
        "nodes": (0..=n).map(|i| json!({"mesh": i})).collect::<Vec<_>>(),
        "meshes": meshes,
    }));
    let (scene, _) = load(&write(dir.path(), "points.gltf", skipped)).unwrap();
    assert_eq!(scene.objects.len(), 1);
}

/// Placements count toward the limit whether their primitive is drawn or skipped: nodes that
/// place a mesh of skipped (points) primitives were walked nodes × primitives times, with no
/// limit (half a million nodes and 250 000 primitives: hours).
#[test]
fn placements_of_skipped_primitives_count_toward_the_limit() {
    use manylight::scene::MAX_SCENE_OBJECTS;
    let mut b = Builder::default();
    let p = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3");
    let points = json!({"attributes": {"POSITION": p}, "mode": 0});
    let nodes = MAX_SCENE_OBJECTS / 2 + 1;
    let model = b.gltf(json!({
        "scene": 0,
        "scenes": [{"nodes": (0..nodes).collect::<Vec<_>>()}],
        "nodes": vec![json!({"mesh": 0}); nodes],
        "meshes": [{"primitives": [points.clone(), points]}],
    }));
    let dir = tempfile::tempdir().unwrap();
    let err = load(&write(dir.path(), "points.gltf", model))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("placed primitives") && err.contains(&MAX_SCENE_OBJECTS.to_string()),
        "{err}"
    );
}

/// Images that do not decode are named with the kind of failure only: the decoders' own
/// messages quote the file (a PNG chunk's type, a BMP header read as a number, a TGA's image
/// type), and no message may show a file's bytes.
#[test]
fn an_image_that_does_not_decode_is_warned_of_without_its_bytes() {
    let secret = b"SECRETPASSWORD".repeat(4);
    let png = |chunk: &[u8]| [b"\x89PNG\r\n\x1a\n".as_slice(), chunk].concat();
    let ihdr = b"\0\0\0\x0dIHDR\0\0\0\x04\0\0\0\x04\x08\x02\0\0\0\x26\x93\x09\x29";
    let images: [(&str, Vec<u8>); 4] = [
        ("chunk.png", png(b"\0\0\0\x06SECRETDATA\x1e\xd0\x1d\xfa")),
        (
            "second.png",
            png(&[ihdr.as_slice(), b"\0\0\0\x04PASSword\xc5\x647-"].concat()),
        ),
        ("header.bmp", [b"BM".as_slice(), &secret].concat()),
        ("kind.tga", [b"\0\0\x02".as_slice(), &secret].concat()),
    ];
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in &images {
        write(dir.path(), name, bytes);
        let mut b = Builder::default();
        let mut doc = triangle(&mut b);
        doc["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
        doc["textures"] = json!([{"source": 0}]);
        doc["images"] = json!([{"uri": name}]);
        doc["meshes"][0]["primitives"][0]["material"] = json!(0);
        let path = write(dir.path(), "model.gltf", b.gltf(doc));
        let (_, report) = load(&path).unwrap();
        let warning = report
            .warnings
            .iter()
            .find(|w| w.contains("could not be decoded"))
            .unwrap_or_else(|| panic!("{name}: {:?}", report.warnings));
        for quoted in ["SECR", "PASS", "1163084882", "Unknown("] {
            assert!(!warning.contains(quoted), "{name}: {warning}");
        }
    }
}

/// serde_json reads 128 levels of nesting at most, where the `gltf` crate skips any depth: a
/// deeply nested value must neither hide a later field from the loader's checks nor make it
/// drop a material's texture transform without a word.
#[test]
fn deep_nesting_hides_no_field_and_drops_no_transform() {
    let dir = tempfile::tempdir().unwrap();
    let deep = format!("{}{}", "[".repeat(300), "]".repeat(300));
    let with_deep = |text: String| text.replace("\"DEEP\"", &deep);

    // An index past u32, which the crate would read as mesh 0, after a deep made-up member.
    let mut b = Builder::default();
    let mut doc = triangle(&mut b);
    doc["made_up"] = json!("DEEP");
    doc["nodes"][0]["mesh"] = json!(4_294_967_296u64);
    let path = write(dir.path(), "index.gltf", with_deep(b.gltf(doc)));
    let err = load(&path).unwrap_err().to_string();
    assert!(err.contains("nodes[0].mesh"), "{err}");

    // A textured floor whose base colour texture is shifted and scaled.
    let transform = json!({"offset": [0.5, 0.0], "scale": [0.5, 1.0]});
    let textured = |b: &mut Builder, info_extras: Value, material_extras: Value| {
        let prim = primitive(b, &floor(), Some(0));
        json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
               "meshes": [{"primitives": [prim]}],
               "materials": [{"extras": material_extras, "pbrMetallicRoughness": {
                   "baseColorTexture": {"index": 0, "extensions": {
                       "KHR_texture_transform": info_extras}}}}],
               "textures": [{"source": 0}],
               "images": [{"uri": format!("data:image/png;base64,{}", base64(&checker_png()))}],
               "extensionsUsed": ["KHR_texture_transform"]})
    };
    let shifted = manylight::scene::surface_maps::TextureTransform {
        offset: glam::Vec2::new(0.5, 0.0),
        rotation: 0.0,
        scale: glam::Vec2::new(0.5, 1.0),
        uv_set: 0,
    };
    let mut b = Builder::default();
    let doc = textured(&mut b, transform.clone(), json!("DEEP"));
    let path = write(dir.path(), "extras.gltf", with_deep(b.gltf(doc)));
    let (scene, report) = load(&path).unwrap();
    assert_eq!(scene.materials[0].maps.base_transform, shifted);
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);

    // Nested deep inside the transform itself: drawn untransformed, and said so.
    let mut deep_transform = transform;
    deep_transform["extras"] = json!("DEEP");
    let mut b = Builder::default();
    let doc = textured(&mut b, deep_transform, json!(null));
    let path = write(dir.path(), "inside.gltf", with_deep(b.gltf(doc)));
    let (scene, report) = load(&path).unwrap();
    assert_eq!(
        scene.materials[0].maps.base_transform,
        manylight::scene::surface_maps::TextureTransform::IDENTITY
    );
    let all = report.warnings.join("\n");
    assert!(
        all.contains("KHR_texture_transform unreadable") && all.contains("untransformed"),
        "{all}"
    );
}
