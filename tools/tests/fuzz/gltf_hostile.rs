//! glTF structure from a hostile source: the fuzzer's valid file with its buffer and image URIs
//! pointing in and out of the model's folder (`..`, `%2e%2e`, absolute, other systems' forms,
//! schemes, links leading out), odd `extras`, node matrices, primitive modes and accessor
//! counts and offsets. Every case loads or is refused with a message, never panics, and never
//! reads a file outside the folder: the files beside it are a valid buffer whose vertices lie
//! at x = 777 and whose triangles start at other corners, a magenta image and a text
//! sentinel, and nothing loaded nor any message may come from them.

use super::*;

/// The text beside the model's folder; no message may contain it.
const SENTINEL: &str = "SENTINEL-TEXT-do-not-show";
/// The colour of the image beside the folder; no loaded texture may contain it.
const MAGENTA: [u8; 4] = [255, 0, 255, 255];
/// The indices of the buffer beside the folder: the valid file's triangles, each started at
/// another corner (wound as before: the loader turns a triangle wound against its normals
/// round, which would make any list of these triangles read the same).
const OUTSIDE_INDICES: [u16; 6] = [1, 2, 0, 2, 3, 0];

/// A root folder holding `model/` (the glTF, `in.bin`, `in.png`, `sub/`, links to the outside)
/// and, beside it, what the model must not read: `s.bin`, `s.png`, `s.txt`.
fn folders(bin: &[u8]) -> (tempfile::TempDir, std::path::PathBuf) {
    let root = tempfile::tempdir().unwrap();
    let model = root.path().join("model");
    std::fs::create_dir_all(model.join("sub")).unwrap();
    std::fs::write(model.join("in.bin"), bin).unwrap();
    image::RgbaImage::from_pixel(2, 2, image::Rgba([200, 100, 50, 255]))
        .save(model.join("in.png"))
        .unwrap();
    // The same buffer with its positions moved by 777 along x (beyond any of the model's own;
    // moved, not flattened, so it still draws) and its indices turned: loads if read. (Views:
    // 48 bytes of positions, 48 of normals, 32 of uvs, then the indices.)
    let mut outside = bin.to_vec();
    for v in outside[..48].chunks_exact_mut(12) {
        let x = f32::from_le_bytes(v[..4].try_into().unwrap()) + 777.0;
        v[..4].copy_from_slice(&x.to_le_bytes());
    }
    let indices: Vec<u8> = OUTSIDE_INDICES
        .iter()
        .flat_map(|i| i.to_le_bytes())
        .collect();
    outside[128..140].copy_from_slice(&indices);
    std::fs::write(root.path().join("s.bin"), &outside).unwrap();
    image::RgbaImage::from_pixel(2, 2, image::Rgba(MAGENTA))
        .save(root.path().join("s.png"))
        .unwrap();
    std::fs::write(root.path().join("s.txt"), SENTINEL.repeat(64)).unwrap();
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(root.path().join("s.bin"), model.join("link.bin")).unwrap();
        std::os::unix::fs::symlink(root.path().join("s.png"), model.join("link.png")).unwrap();
        std::os::unix::fs::symlink(root.path(), model.join("up")).unwrap();
    }
    (root, model)
}

/// A URI for a file named `stem.ext`: inside the folder, or leaving it every way there is.
/// `{root}` stands for the absolute path of the folder holding the model's folder.
fn uri(ext: &'static str) -> impl Strategy<Value = String> {
    let forms = vec![
        "in.{ext}",
        "./in.{ext}",
        "sub/../in.{ext}",
        "in%2E{ext}",
        "../s.{ext}",
        "%2e%2e/s.{ext}",
        "%2E%2E%2Fs.{ext}",
        "..%5Cs.{ext}",
        "..\\s.{ext}",
        "sub/../../s.{ext}",
        "sub%2F..%2F..%2Fs.{ext}",
        "{root}/s.{ext}",
        "{root}/model/../s.{ext}",
        "file://{root}/s.{ext}",
        "C:/s.{ext}",
        "c:s.{ext}",
        "\\\\server\\share\\s.{ext}",
        "//server/share/s.{ext}",
        "link.{ext}",
        "up/s.{ext}",
        "../s.txt",
        "/dev/zero",
        "missing.{ext}",
        "",
    ];
    prop::sample::select(forms).prop_map(move |f| f.replace("{ext}", ext))
}

/// Any JSON value, a few levels deep: what `extras` may hold.
fn any_json() -> impl Strategy<Value = serde_json::Value> {
    let leaf = prop_oneof![
        Just(serde_json::Value::Null),
        any::<bool>().prop_map(serde_json::Value::from),
        any::<i64>().prop_map(serde_json::Value::from),
        any::<u64>().prop_map(serde_json::Value::from),
        (-1e300f64..1e300).prop_map(serde_json::Value::from),
        "[ -~]{0,8}".prop_map(serde_json::Value::from),
    ];
    leaf.prop_recursive(3, 12, 4, |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..4).prop_map(serde_json::Value::from),
            prop::collection::btree_map("[a-z_]{1,6}", inner, 0..4)
                .prop_map(|m| serde_json::Value::Object(m.into_iter().collect())),
        ]
    })
}

/// A number for a matrix element or an accessor field: ordinary, edge, or past u32.
fn field_number() -> impl Strategy<Value = serde_json::Value> {
    prop::sample::select(vec![
        serde_json::json!(0),
        serde_json::json!(1),
        serde_json::json!(-1),
        serde_json::json!(2),
        serde_json::json!(3),
        serde_json::json!(4),
        serde_json::json!(6),
        serde_json::json!(0.5),
        serde_json::json!(1e-7),
        serde_json::json!(1e-300),
        serde_json::json!(1e300),
        serde_json::json!(4294967295u64),
        serde_json::json!(4294967296u64),
        serde_json::json!(4294967300u64),
        serde_json::json!(u64::MAX),
    ])
}

/// One structural change to the valid document.
#[derive(Debug, Clone)]
enum Change {
    /// `extras` set on the object at a pointer (index into the document's objects).
    Extras(prop::sample::Index, serde_json::Value),
    /// Node 2's matrix (column-major; its last row is elements 3, 7, 11, 15).
    Matrix(Vec<serde_json::Value>),
    /// Primitive 0 or 1's `mode`.
    Mode(bool, serde_json::Value),
    /// An accessor's `count` or `byteOffset`.
    Accessor(prop::sample::Index, bool, serde_json::Value),
}

fn change() -> impl Strategy<Value = Change> {
    prop_oneof![
        (any::<prop::sample::Index>(), any_json()).prop_map(|(i, v)| Change::Extras(i, v)),
        prop::collection::vec(field_number(), 16).prop_map(Change::Matrix),
        // Mostly affine: the first twelve elements generated, the last row 0 0 0 1.
        prop::collection::vec(field_number(), 12).prop_map(|mut m| {
            let row = [0, 0, 0, 1].map(serde_json::Value::from);
            for (i, v) in row.into_iter().enumerate() {
                m.insert(i * 4 + 3, v);
            }
            Change::Matrix(m)
        }),
        (any::<bool>(), field_number()).prop_map(|(p, v)| Change::Mode(p, v)),
        (any::<prop::sample::Index>(), any::<bool>(), field_number())
            .prop_map(|(i, c, v)| Change::Accessor(i, c, v)),
    ]
}

fn apply(doc: &mut serde_json::Value, change: Change) {
    match change {
        Change::Extras(at, value) => {
            let mut pointers = vec![String::new()];
            gltf_pointers(doc, String::new(), &mut pointers);
            pointers.retain(|p| doc.pointer(p).is_some_and(|v| v.is_object()));
            let pointer = at.get(&pointers).clone();
            if let Some(object) = doc.pointer_mut(&pointer).and_then(|v| v.as_object_mut()) {
                object.insert("extras".into(), value);
            }
        }
        Change::Matrix(m) => {
            let node = &mut doc["nodes"][2];
            node["matrix"] = serde_json::Value::from(m);
        }
        Change::Mode(second, value) => {
            doc["meshes"][0]["primitives"][usize::from(second)]["mode"] = value;
        }
        Change::Accessor(at, count, value) => {
            let i = at.index(4);
            let key = if count { "count" } else { "byteOffset" };
            doc["accessors"][i][key] = value;
        }
    }
}

/// Loads `file` (no panic; a message on refusal) and checks that nothing came from outside
/// the model's folder.
fn check_confined(file: &Path, what: &str) {
    let spec = file.to_str().unwrap();
    match load_guarded(spec, Some((0, 1)), "(gltf crate) failed", || what.into()) {
        Err(message) => assert!(
            !message.contains(&SENTINEL[..12]),
            "a message shows an outside file: {message}\n{what}"
        ),
        Ok(scene) => {
            for o in &scene.objects {
                assert!(
                    o.mesh.positions.iter().all(|p| p.x.abs() < 700.0)
                        && o.mesh.indices[..] != OUTSIDE_INDICES.map(u32::from)[..],
                    "geometry from the outside buffer was loaded: {what}"
                );
            }
            for m in &scene.materials {
                if let Some(t) = &m.diffuse_texture {
                    assert!(
                        t.image.pixels().all(|p| p.0 != MAGENTA),
                        "the outside image was loaded: {what}"
                    );
                }
            }
        }
    }
}

proptest! {
    #![proptest_config(config(300))]

    #[test]
    fn hostile_gltf_structure_loads_or_is_refused_and_reads_nothing_outside(
        buffer_uri in uri("bin"),
        image_uri in prop::option::of(uri("png")),
        changes in prop::collection::vec(change(), 0..3),
        as_glb in prop::bool::weighted(0.2),
    ) {
        let (mut doc, bin) = gltf_valid();
        let (root, model) = folders(&bin);
        let abs = root.path().to_str().unwrap().to_string();
        if let Some(image) = &image_uri {
            doc["images"][0] = serde_json::json!({"uri": image.replace("{root}", &abs)});
        }
        for c in changes {
            apply(&mut doc, c);
        }
        let file = if as_glb {
            // The BIN chunk for buffer 0; a second buffer by URI, used by the index view.
            doc["buffers"]
                .as_array_mut()
                .unwrap()
                .push(serde_json::json!({"uri": buffer_uri.replace("{root}", &abs),
                                         "byteLength": bin.len()}));
            doc["bufferViews"][3]["buffer"] = serde_json::json!(1);
            let file = model.join("m.glb");
            std::fs::write(&file, gltf_glb(doc.to_string().as_bytes(), &bin)).unwrap();
            file
        } else {
            doc["buffers"][0]["uri"] = serde_json::Value::from(buffer_uri.replace("{root}", &abs));
            let file = model.join("m.gltf");
            std::fs::write(&file, doc.to_string()).unwrap();
            file
        };
        check_confined(&file, &doc.to_string());
    }
}

#[test]
fn the_hostile_harness_sees_an_outside_read_when_one_is_allowed() {
    // The oracle itself: with outside files allowed, `../s.bin` loads the x = 777 geometry
    // (so the harness would notice a read that the default let through).
    let (mut doc, bin) = gltf_valid();
    let (_root, model) = folders(&bin);
    doc["buffers"][0]["uri"] = serde_json::json!("../s.bin");
    doc["images"][0] = serde_json::json!({"uri": "../s.png"});
    let file = model.join("m.gltf");
    std::fs::write(&file, doc.to_string()).unwrap();
    let mut options = manylight::LoadOptions::default();
    options.allow_outside_files = true;
    let (scene, _) = scene::load_with(file.to_str().unwrap(), Some((0, 1)), &options).unwrap();
    // The model's own vertices lie within x ∈ [−1, 1]; the outside buffer's, 777 along.
    assert!(scene
        .objects
        .iter()
        .any(|o| o.mesh.positions.iter().all(|p| p.x > 700.0)));
    assert!(scene
        .objects
        .iter()
        .any(|o| o.mesh.indices[..] == OUTSIDE_INDICES.map(u32::from)[..]));
    let textured = scene
        .materials
        .iter()
        .filter_map(|m| m.diffuse_texture.as_ref());
    assert!(textured
        .into_iter()
        .any(|t| t.image.pixels().any(|p| p.0 == MAGENTA)));
    let refused = std::panic::catch_unwind(|| check_confined(&file, "allowed"));
    assert!(refused.is_ok(), "the default refuses it");
}
