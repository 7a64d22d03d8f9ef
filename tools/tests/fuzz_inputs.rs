//! Fuzzing what parses input: generated OBJ and MTL text and scene JSON (proptest, seeded by
//! proptest's own persistence; failures shrink to a minimal file and are saved under
//! `tests/proptest-regressions/fuzz_inputs.txt`), plus the hand-kept corpus of hostile files in
//! `tests/fuzz_corpus/`. Every input must load or be refused with a message — no panic — and
//! every accepted scene must render a finite frame (or be refused with a clear limit) through
//! forward and clustered. `MANYLIGHT_FUZZ_CASES` scales the case counts (default 1: a few
//! thousand cases in all, well under a minute).

mod common;
#[path = "fuzz/numerics.rs"]
mod numerics;
#[path = "fuzz/outputs.rs"]
mod outputs;
#[path = "fuzz/repeats.rs"]
mod repeats;

use std::cell::RefCell;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use std::sync::OnceLock;

use common::Gpu;
use manylight::scene::{self, Scene};
use manylight::{EsVersion, RenderOptions};
use proptest::prelude::*;
use proptest::test_runner::FileFailurePersistence;

/// `base` cases times `MANYLIGHT_FUZZ_CASES`; a failure's seed is kept in
/// `tests/proptest-regressions/fuzz_inputs.txt` (commit it: it is replayed first next time).
fn config(base: u32) -> ProptestConfig {
    let scale = std::env::var("MANYLIGHT_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse::<u32>().ok())
        .unwrap_or(1);
    ProptestConfig {
        cases: base.saturating_mul(scale.max(1)),
        failure_persistence: Some(Box::new(FileFailurePersistence::Direct(
            "tests/proptest-regressions/fuzz_inputs.txt",
        ))),
        ..ProptestConfig::default()
    }
}

fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        40 => (-10.0f64..10.0).prop_map(|v| format!("{v}")),
        1 => prop::sample::select(vec![
            "0", "-0", "1", "1e-45", "1e-300", "1e9", "3.4e38", "1e39", "nan", "inf", "-inf",
            "x", "", "1,5", "0x10", "1e",
        ])
        .prop_map(String::from),
    ]
}

fn index() -> impl Strategy<Value = String> {
    prop_oneof![
        90 => (1i64..6).prop_map(|i| i.to_string()),
        9 => (-3i64..0).prop_map(|i| i.to_string()),
        1 => prop::sample::select(vec!["0", "99999999999", "4294967296", "x", ""])
            .prop_map(String::from),
    ]
}

fn face_vertex() -> impl Strategy<Value = String> {
    (
        index(),
        prop::option::of(index()),
        prop::option::of(index()),
    )
        .prop_map(|(v, t, n)| match (t, n) {
            (None, None) => v,
            (Some(t), None) => format!("{v}/{t}"),
            (None, Some(n)) => format!("{v}//{n}"),
            (Some(t), Some(n)) => format!("{v}/{t}/{n}"),
        })
}

fn obj_line() -> impl Strategy<Value = String> {
    prop_oneof![
        12 => (number(), number(), number()).prop_map(|(a, b, c)| format!("v {a} {b} {c}")),
        2 => (number(), number()).prop_map(|(a, b)| format!("vt {a} {b}")),
        2 => (number(), number(), number()).prop_map(|(a, b, c)| format!("vn {a} {b} {c}")),
        8 => prop::collection::vec(face_vertex(), 3..5).prop_map(|v| format!("f {}", v.join(" "))),
        1 => prop::collection::vec(face_vertex(), 0..7).prop_map(|v| format!("f {}", v.join(" "))),
        2 => prop::sample::select(vec![
            "mtllib m.mtl", "mtllib missing.mtl", "mtllib", "mtllib /dev/zero", "mtllib .",
            "usemtl a", "usemtl b", "usemtl", "o thing", "g", "s 1", "l 1 2", "p 1", "# c", "",
            " \t ", "v 1 2", "f", "vt", "\u{feff}v 0 0 0",
        ])
        .prop_map(String::from),
        1 => "[ -~]{0,24}",
    ]
}

/// OBJ text: mostly a valid little mesh (six vertices, texture coordinates and normals each,
/// so that the generated faces' indices resolve), then generated lines — valid structure
/// first, so the generated lines are not all refused at the first bad token.
fn obj_text(max: usize) -> impl Strategy<Value = String> {
    (prop::bool::weighted(0.8), lines(obj_line(), max)).prop_map(|(prefix, body)| {
        let base = "mtllib m.mtl\nusemtl a\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n\
                    v 0 0 1\nv 0 0 -1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0\nvt 0 0.5\n\
                    vn 0 0 1\nvn 0 1 0\nvn 1 0 0\nvn 0 0 -1\nvn 0 -1 0\nvn -1 0 0\n\
                    f 1/1 2/2 3/3\n";
        if prefix {
            format!("{base}{body}")
        } else {
            body
        }
    })
}

fn mtl_line() -> impl Strategy<Value = String> {
    let key = prop::sample::select(vec!["Kd", "Ks", "Ka", "Ke", "Ns", "d", "Tr", "Ni"]);
    prop_oneof![
        2 => prop::sample::select(vec!["newmtl a", "newmtl b", "newmtl"]).prop_map(String::from),
        6 => (key.clone(), prop::collection::vec(number(), 3..4))
            .prop_map(|(k, v)| format!("{k} {}", v.join(" "))),
        1 => (key, prop::collection::vec(number(), 0..5))
            .prop_map(|(k, v)| format!("{k} {}", v.join(" "))),
        2 => prop::sample::select(vec![
            "map_Kd tex.png", "map_Kd TEX.PNG", "map_Kd missing.png", "map_Kd bad.png",
            "map_Kd", "map_Kd -bm 1 tex.png", "map_Kd sub\\tex.png", "map_Kd /dev/zero",
            "illum 2",
        ])
        .prop_map(String::from),
        1 => "[ -~]{0,24}",
    ]
}

fn lines(line: impl Strategy<Value = String>, max: usize) -> impl Strategy<Value = String> {
    (prop::collection::vec(line, 0..max), any::<bool>())
        .prop_map(|(lines, crlf)| lines.join(if crlf { "\r\n" } else { "\n" }))
}

thread_local! {
    /// One context for every case of a test (made lazily, on the test's thread).
    static GPU: RefCell<Option<Gpu>> = const { RefCell::new(None) };
}

/// Renders an accepted scene small through forward and clustered into a half-float target:
/// every value finite, or a clear limit error.
fn render_finite(scene: &Scene, what: &str) {
    GPU.with(|cell| {
        let mut cell = cell.borrow_mut();
        let gpu = cell.get_or_insert_with(|| Gpu::new(EsVersion::Es3));
        for method in ["forward", "clustered"] {
            gpu.r().set_method_named(method).unwrap();
            match gpu
                .r()
                .render_offscreen_hdr(scene, 16, 9, &RenderOptions::default())
            {
                Ok((pixels, _)) => assert!(
                    pixels.iter().flatten().all(|v| v.is_finite()),
                    "{method}: NaN or Inf in the frame of {what}"
                ),
                Err(manylight::Error::Limit(reason)) => assert!(!reason.is_empty()),
                Err(e) => panic!("{method}: {what}: unexpected error {e}"),
            }
        }
    });
}

/// Loads `spec` under `catch_unwind`: a panic fails the test, a refusal must carry a message
/// other than the loader's last guard against a parser's panic (`guard`: the checks before the
/// parser must have refused the file instead), and a loaded scene must validate. `what`
/// describes the input for a failure.
fn load_guarded(
    spec: &str,
    lights: Option<(usize, u64)>,
    guard: &str,
    what: impl Fn() -> String,
) -> Result<Scene, String> {
    match catch_unwind(AssertUnwindSafe(|| scene::load(spec, lights))) {
        Err(_) => panic!("loading {spec} panicked:\n{}", what()),
        Ok(Err(e)) => {
            let message = e.to_string();
            assert!(!message.is_empty());
            assert!(
                !message.contains(guard),
                "the parser panicked on {spec} ({guard}): {message}\n{}",
                what()
            );
            Err(message)
        }
        Ok(Ok((scene, _))) => {
            scene.validate().expect("a loaded scene validates");
            Ok(scene)
        }
    }
}

/// Loads `file` as a user would (with a few random lights), asserting no panic and a message
/// on refusal; renders what is accepted when `render` is set. The refusal's message, if any.
fn load_and_check(file: &Path, render: bool) -> Result<(), String> {
    let spec = file.to_str().unwrap();
    // Scene files keep their own lights (and random_lights count); OBJ files get a few.
    let lights = (!spec.ends_with(".json")).then_some((4, 1));
    let scene = load_guarded(spec, lights, "(tobj) failed", || describe(file))?;
    if render {
        render_finite(&scene, &describe(file));
    }
    Ok(())
}

fn describe(file: &Path) -> String {
    let dir = file.parent().unwrap();
    ["m.obj", "m.mtl", "s.json"]
        .iter()
        .filter_map(|n| {
            let text = std::fs::read_to_string(dir.join(n)).ok()?;
            Some(format!("--- {n}\n{text}"))
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// A folder with the side files generated OBJ/MTL text refers to: a real texture (also in
/// other case) and one that is not an image.
fn workspace() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let tex = image::RgbaImage::from_pixel(2, 2, image::Rgba([200, 100, 50, 255]));
    tex.save(dir.path().join("tex.png")).unwrap();
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    tex.save(dir.path().join("sub/tex.png")).unwrap();
    std::fs::write(dir.path().join("bad.png"), b"not a png").unwrap();
    dir
}

/// Whether this run leaves the cases that only load to the run on the system's GL (said once).
fn loading_alone_not_applicable() -> bool {
    static SKIP: OnceLock<bool> = OnceLock::new();
    *SKIP.get_or_init(|| {
        common::independent_of_the_implementation("loading generated OBJ and MTL files")
    })
}

proptest! {
    #![proptest_config(config(4000))]

    #[test]
    fn generated_obj_and_mtl_load_or_are_refused(
        obj in obj_text(24),
        mtl in lines(mtl_line(), 12),
    ) {
        if loading_alone_not_applicable() {
            return Ok(());
        }
        let dir = workspace();
        std::fs::write(dir.path().join("m.mtl"), &mtl).unwrap();
        let file = dir.path().join("m.obj");
        std::fs::write(&file, &obj).unwrap();
        let _ = load_and_check(&file, false);
    }
}

proptest! {
    #![proptest_config(config(400))]

    #[test]
    fn generated_obj_scenes_that_load_render_finite_frames(
        obj in obj_text(16),
        mtl in lines(mtl_line(), 8),
    ) {
        let dir = workspace();
        std::fs::write(dir.path().join("m.mtl"), &mtl).unwrap();
        let file = dir.path().join("m.obj");
        std::fs::write(&file, &obj).unwrap();
        let _ = load_and_check(&file, true);
    }
}

/// The OBJ generators above make files the loader accepts, most of the time: a loader that
/// refused every file would pass them. 200 cases of each generator, from a fixed seed, at
/// least a quarter of which load.
#[test]
fn most_generated_obj_files_load() {
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;
    let mut runner = TestRunner::deterministic();
    for (lines_at_most, mtl_lines) in [(24, 12), (16, 8)] {
        let strategy = (obj_text(lines_at_most), lines(mtl_line(), mtl_lines));
        let mut loaded = 0;
        for _ in 0..200 {
            let (obj, mtl) = strategy.new_tree(&mut runner).unwrap().current();
            let dir = workspace();
            std::fs::write(dir.path().join("m.mtl"), &mtl).unwrap();
            let file = dir.path().join("m.obj");
            std::fs::write(&file, &obj).unwrap();
            loaded += usize::from(load_and_check(&file, false).is_ok());
        }
        // The generators are hostile by design: some numbers and indices are bad, and one bad
        // one refuses the file.
        assert!(
            loaded >= 50,
            "only {loaded} of 200 generated OBJ files loaded"
        );
    }
}

/// A JSON number: mostly from `sane`, sometimes an extreme finite value (JSON has no NaN).
fn json_number(sane: std::ops::Range<f64>) -> impl Strategy<Value = serde_json::Value> {
    prop_oneof![
        30 => sane.prop_map(serde_json::Value::from),
        1 => (-20.0f64..20.0).prop_map(serde_json::Value::from),
        1 => prop::sample::select(vec![
            0.0, -0.0, 1e-300, 1e-9, 1e9, 1e12, 1e20, 1e38, 3.5e38, 1e300, f64::MAX, -f64::MAX,
        ])
        .prop_map(serde_json::Value::from),
    ]
}

fn vec3(sane: std::ops::Range<f64>) -> impl Strategy<Value = serde_json::Value> {
    prop_oneof![
        20 => prop::collection::vec(json_number(sane.clone()), 3..4),
        1 => prop::collection::vec(json_number(sane), 0..6),
    ]
    .prop_map(serde_json::Value::from)
}

fn light() -> impl Strategy<Value = serde_json::Value> {
    (
        prop::sample::select(vec!["point", "point", "point", "spot", "spot", "area"]),
        vec3(-3.0..3.0),
        json_number(0.5..6.0),
        vec3(0.0..1.0),
        json_number(0.0..4.0),
        vec3(-1.0..1.0),
        json_number(0.0..60.0),
        json_number(0.0..90.0),
    )
        .prop_map(
            |(kind, position, radius, color, intensity, direction, inner, outer)| {
                let mut l = serde_json::json!({
                    "kind": kind, "position": position, "radius": radius, "color": color,
                    "intensity": intensity,
                });
                if kind == "spot" {
                    l["direction"] = direction;
                    l["inner_deg"] = inner;
                    l["outer_deg"] = outer;
                }
                l
            },
        )
}

fn scene_json() -> impl Strategy<Value = serde_json::Value> {
    let object = prop_oneof![
        8 => prop::sample::select(vec!["plane", "plane", "pillars", "nowhere"])
            .prop_map(|b| serde_json::json!({"builtin": b})),
        4 => Just(serde_json::json!({"obj": "m.obj"})),
        1 => Just(serde_json::json!({"obj": "/dev/zero"})),
    ];
    let count = prop::sample::select(vec![0u64, 1, 7, 5_000_000, 4_294_967_296, u64::MAX]);
    (
        (vec3(-1.0..1.0), vec3(-1.0..1.0)),
        (
            json_number(20.0..90.0),
            json_number(0.01..1.0),
            json_number(5.0..200.0),
        ),
        (any::<bool>(), any::<bool>()),
        prop::collection::vec(object, 1..3),
        prop::collection::vec(light(), 0..4),
        prop::option::of(count),
        vec3(0.0..0.2),
    )
        .prop_map(
            |(
                (offset, target),
                (fov, near, far),
                (ortho, keep_camera),
                objects,
                lights,
                count,
                ambient,
            )| {
                let mut s = serde_json::json!({
                    "objects": objects, "lights": lights, "ambient": ambient,
                });
                // Half the files keep the framed default camera, so the rest of the file is
                // what decides.
                if keep_camera {
                    let mut position = offset;
                    if let Some(z) = position.get_mut(2) {
                        *z = serde_json::Value::from(z.as_f64().unwrap_or(0.0) + 6.0);
                    }
                    let mut camera = serde_json::json!({
                        "position": position, "target": target, "near": near, "far": far,
                    });
                    if ortho {
                        camera["projection"] = "orthographic".into();
                        camera["height"] =
                            serde_json::Value::from(fov.as_f64().unwrap_or(1.0) / 10.0);
                    } else {
                        camera["fov_y_deg"] = fov;
                    }
                    s["camera"] = camera;
                }
                if let Some(count) = count {
                    s["random_lights"] = serde_json::json!({"count": count, "seed": 3});
                }
                s
            },
        )
}

proptest! {
    #![proptest_config(config(1000))]

    #[test]
    fn generated_scene_files_load_or_are_refused_and_render_finite(value in scene_json()) {
        let dir = workspace();
        std::fs::write(
            dir.path().join("m.obj"),
            "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n",
        )
        .unwrap();
        let file = dir.path().join("s.json");
        std::fs::write(&file, value.to_string()).unwrap();
        let spec = file.to_str().unwrap().to_string();
        // The file's own lights only: no override of its random_lights count.
        match catch_unwind(AssertUnwindSafe(|| scene::load(&spec, None))) {
            Err(_) => panic!("loading panicked:\n{value}"),
            Ok(Err(e)) => prop_assert!(!e.to_string().is_empty()),
            Ok(Ok((scene, _))) => render_finite(&scene, &value.to_string()),
        }
    }
}

/// The kept corpus: hostile files found by hand and by this fuzzer, each loaded and rendered.
#[test]
fn the_corpus_loads_or_is_refused_and_renders_finite() {
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_corpus");
    let mut entries: Vec<_> = std::fs::read_dir(&corpus)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj" || e == "json"))
        .collect();
    entries.sort();
    // Each file's outcome: `None` loads (and renders finite frames), `Some(words)` is refused
    // with an error containing them.
    let expected: &[(&str, Option<&str>)] = &[
        (
            "array_with_too_many_values.json",
            Some("lights[0].direction: too many values"),
        ),
        ("camera_far_away.json", Some("camera.position")),
        ("crlf_tabs_missing_refs.obj", None),
        ("dev_zero_mtllib.obj", None),
        ("faces_out_of_range.obj", Some("line 4: `f` corner 3")),
        ("far_plane_max_huge_radius.json", None),
        ("hot_material.obj", None),
        (
            "huge_vertices.obj",
            Some("mesh.positions[0]`: must be within"),
        ),
        ("random_lights_u64_max.json", Some("random_lights.count")),
        ("short_colour.obj", None),
        ("tiny_orthographic.json", Some("camera.height")),
    ];
    let names: Vec<_> = entries
        .iter()
        .map(|p| p.file_name().unwrap().to_str().unwrap())
        .collect();
    let listed: Vec<_> = expected.iter().map(|(n, _)| *n).collect();
    assert_eq!(names, listed, "every corpus file has its outcome here");
    for (file, (name, refusal)) in entries.iter().zip(expected) {
        match (load_and_check(file, true), refusal) {
            (Ok(()), None) => {}
            (Err(e), Some(words)) => assert!(e.contains(words), "{name}: {e}"),
            (outcome, _) => panic!("{name}: expected {refusal:?}, got {outcome:?}"),
        }
    }
}

// glTF: proptest mutations of a valid file — values replaced anywhere in its JSON, bytes of a
// GLB flipped, cut short or inserted — each loads or is refused with a message, never a panic
// (nor the loader's last guard turning a panic inside the `gltf` crate into an error); what
// loads renders finite frames.

fn gltf_base64(bytes: &[u8]) -> String {
    use base64::Engine;
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// A valid glTF document (without its buffer's `uri`) and its binary buffer: an indexed,
/// textured quad placed twice through a node hierarchy, a second material that blends, a
/// point and a spot light, a camera.
fn gltf_valid() -> (serde_json::Value, Vec<u8>) {
    let mut bin = Vec::new();
    let mut views = Vec::new();
    let mut push = |bytes: Vec<u8>| {
        views.push(
            serde_json::json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()}),
        );
        bin.extend(bytes);
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
    };
    let f = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    push(f(&[
        -1.0, -1.0, 0.0, 1.0, -1.0, 0.0, 1.0, 1.0, 0.0, -1.0, 1.0, 0.0,
    ]));
    push(f(&[0.0, 0.0, 1.0].repeat(4)));
    push(f(&[0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0]));
    push(
        [0u16, 1, 2, 0, 2, 3]
            .iter()
            .flat_map(|i| i.to_le_bytes())
            .collect(),
    );
    let tex = image::RgbaImage::from_pixel(2, 2, image::Rgba([200, 100, 50, 255]));
    let mut png = Vec::new();
    tex.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    push(png);
    let doc = serde_json::json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1, 0.8, 0.6], "intensity": 3, "range": 5},
            {"type": "spot", "intensity": 4, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}}
        ]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 3]}],
        "nodes": [
            {"translation": [0, 1, 0], "rotation": [0, 0.38268343, 0, 0.9238795], "children": [1, 2]},
            {"mesh": 0, "scale": [2, 2, 2]},
            {"mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,-2,1],
             "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"translation": [0, 1, 6], "camera": 0, "children": [4]},
            {"translation": [1, 2, 0], "extensions": {"KHR_lights_punctual": {"light": 1}}}
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "zfar": 100}}],
        "meshes": [{"primitives": [
            {"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0},
            {"attributes": {"POSITION": 0}, "material": 1, "mode": 5}
        ]}],
        "materials": [
            {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "roughnessFactor": 0.4}},
            {"alphaMode": "BLEND", "doubleSided": true,
             "pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.4, 1, 0.5]}}
        ],
        "textures": [{"source": 0}],
        "images": [{"bufferView": 4, "mimeType": "image/png"}],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": views,
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 4,
             "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "type": "VEC3", "count": 4},
            {"bufferView": 2, "componentType": 5126, "type": "VEC2", "count": 4},
            {"bufferView": 3, "componentType": 5123, "type": "SCALAR", "count": 6}
        ]
    });
    (doc, bin)
}

fn gltf_glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let mut json = json.to_vec();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

/// JSON pointers of every value in `v` (objects' members and arrays' elements, at any depth).
fn gltf_pointers(v: &serde_json::Value, at: String, out: &mut Vec<String>) {
    match v {
        serde_json::Value::Object(m) => {
            for (k, child) in m {
                let p = format!("{at}/{k}");
                out.push(p.clone());
                gltf_pointers(child, p, out);
            }
        }
        serde_json::Value::Array(a) => {
            for (i, child) in a.iter().enumerate() {
                let p = format!("{at}/{i}");
                out.push(p.clone());
                gltf_pointers(child, p, out);
            }
        }
        _ => {}
    }
}

fn gltf_replacement() -> impl Strategy<Value = serde_json::Value> {
    prop::sample::select(vec![
        serde_json::json!(0),
        serde_json::json!(1),
        serde_json::json!(2),
        serde_json::json!(3),
        serde_json::json!(5),
        serde_json::json!(-1),
        serde_json::json!(0.5),
        serde_json::json!(1e9),
        serde_json::json!(4294967295u64),
        serde_json::json!(4294967296u64),
        serde_json::json!(1e39),
        serde_json::json!(-1e300),
        serde_json::json!(null),
        serde_json::json!("x"),
        serde_json::json!("BLEND"),
        serde_json::json!("MASK"),
        serde_json::json!("spot"),
        serde_json::json!("directional"),
        serde_json::json!("orthographic"),
        serde_json::json!("missing.bin"),
        serde_json::json!("data:application/octet-stream;base64,AAAA"),
        serde_json::json!([]),
        serde_json::json!([0]),
        serde_json::json!([1, 0]),
        serde_json::json!([0, 0, 0, 0]),
        serde_json::json!({}),
    ])
}

/// Loads a mutated glTF file: no panic, a message on refusal, a valid scene otherwise (rendered
/// when `render` is set).
fn gltf_check(file: &Path, render: bool, what: &str) -> Result<(), String> {
    let spec = file.to_str().unwrap();
    let scene = load_guarded(spec, Some((2, 1)), "(gltf crate) failed", || what.into())?;
    if render {
        render_finite(&scene, what);
    }
    Ok(())
}

/// The valid glTF with the values at `picks` (indices into its JSON pointers) replaced,
/// written into `dir` as a `.glb` or a `.gltf` with its buffer inline; the file and its JSON.
fn write_mutated_gltf(
    picks: Vec<(prop::sample::Index, serde_json::Value)>,
    as_glb: bool,
    dir: &Path,
) -> (std::path::PathBuf, String) {
    let (mut doc, bin) = gltf_valid();
    let mut pointers = Vec::new();
    gltf_pointers(&doc, String::new(), &mut pointers);
    for (index, value) in picks {
        let pointer = index.get(&pointers);
        if let Some(slot) = doc.pointer_mut(pointer) {
            *slot = value;
        }
    }
    let file = if as_glb {
        let file = dir.join("m.glb");
        std::fs::write(&file, gltf_glb(doc.to_string().as_bytes(), &bin)).unwrap();
        file
    } else {
        if let Some(buffer) = doc.pointer_mut("/buffers/0") {
            if buffer.is_object() && buffer.get("uri").is_none() {
                buffer["uri"] = serde_json::Value::from(format!(
                    "data:application/octet-stream;base64,{}",
                    gltf_base64(&bin)
                ));
            }
        }
        let file = dir.join("m.gltf");
        std::fs::write(&file, doc.to_string()).unwrap();
        file
    };
    (file, doc.to_string())
}

/// The mutation fuzzer below makes documents the loader accepts, often enough to reach the
/// renderer: a loader that refused every document would pass it. 200 cases from a fixed seed.
#[test]
fn many_mutated_gltf_documents_load_and_render() {
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;
    let mut runner = TestRunner::deterministic();
    let strategy = (
        prop::collection::vec((any::<prop::sample::Index>(), gltf_replacement()), 1..4),
        any::<bool>(),
    );
    let (mut loaded, mut rendered) = (0, 0);
    for _ in 0..200 {
        let (picks, as_glb) = strategy.new_tree(&mut runner).unwrap().current();
        let dir = workspace();
        let (file, doc) = write_mutated_gltf(picks, as_glb, dir.path());
        let render = rendered < 10;
        if gltf_check(&file, render, &doc).is_ok() {
            loaded += 1;
            rendered += usize::from(render);
        }
    }
    // The replacements are hostile by design (one bad value refuses the document): 10 of
    // the 200 loaded when this was written, each of them rendered.
    assert!(
        loaded >= 5,
        "only {loaded} of 200 mutated glTF documents loaded"
    );
    assert_eq!(rendered, loaded.min(10));
}

proptest! {
    #![proptest_config(config(600))]

    #[test]
    fn mutated_gltf_json_loads_or_is_refused(
        picks in prop::collection::vec((any::<prop::sample::Index>(), gltf_replacement()), 1..4),
        as_glb in any::<bool>(),
        render in prop::bool::weighted(0.3),
    ) {
        let dir = workspace();
        let (file, doc) = write_mutated_gltf(picks, as_glb, dir.path());
        let _ = gltf_check(&file, render, &doc);
    }

    #[test]
    fn mutated_glb_bytes_load_or_are_refused(
        flips in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 0..6),
        cut in prop::option::weighted(0.2, any::<prop::sample::Index>()),
        insert in prop::option::weighted(0.1, (any::<prop::sample::Index>(), prop::collection::vec(any::<u8>(), 1..9))),
    ) {
        let (doc, bin) = gltf_valid();
        let mut bytes = gltf_glb(doc.to_string().as_bytes(), &bin);
        for (at, value) in flips {
            let i = at.index(bytes.len());
            bytes[i] = value;
        }
        if let Some((at, extra)) = insert {
            let i = at.index(bytes.len());
            bytes.splice(i..i, extra);
        }
        if let Some(at) = cut {
            bytes.truncate(at.index(bytes.len()));
        }
        let dir = workspace();
        let file = dir.path().join("m.glb");
        std::fs::write(&file, &bytes).unwrap();
        let _ = gltf_check(&file, false, &format!("{} bytes", bytes.len()));
    }
}

// Hostile glTF structure: URIs leaving the folder, extras, matrices, modes, accessor fields.
#[path = "fuzz/gltf_hostile.rs"]
mod gltf_hostile;

#[test]
fn the_valid_gltf_the_fuzzer_mutates_loads_and_renders() {
    let (doc, bin) = gltf_valid();
    let dir = workspace();
    let file = dir.path().join("m.glb");
    std::fs::write(&file, gltf_glb(doc.to_string().as_bytes(), &bin)).unwrap();
    let (scene, report) = scene::load(file.to_str().unwrap(), Some((0, 1))).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    assert_eq!((scene.objects.len(), scene.lights.len()), (4, 2));
    render_finite(&scene, "the valid glTF");
}

proptest! {
    #![proptest_config(config(48))]

    /// Transforms near 0 and 10¹², unusable normals, long and short spot axes and large
    /// ranges, on ES 3.0, ES 2.0 and without fragment highp (`fuzz/numerics.rs`).
    #[test]
    fn extreme_numbers_light_what_they_should_or_are_refused_by_name(case in numerics::case()) {
        numerics::check(&case);
    }

    /// glTF node scales of 0 or tiny along an axis, or huge, load and render finite frames.
    #[test]
    fn gltf_node_scales_near_zero_and_huge_load_and_render(
        scale in (numerics::scale_factor(), numerics::scale_factor(), numerics::scale_factor()),
        node in 0usize..2,
    ) {
        let (mut doc, bin) = gltf_valid();
        doc["nodes"][node]["scale"] = serde_json::json!([scale.0, scale.1, scale.2]);
        let dir = workspace();
        let file = dir.path().join("m.glb");
        std::fs::write(&file, gltf_glb(doc.to_string().as_bytes(), &bin)).unwrap();
        // Finite scales are the file's to choose: the file loads. Node 0 holds both meshes: a
        // zero scale, or one 10⁶ times below another, may flatten every triangle to under 10⁻¹²
        // of the largest area the transform gives, and below 10⁻¹⁵⁰ a product of two scales
        // (an area) underflows f64 (the documented "nothing to draw"). x and y scales both
        // below 10⁻³⁶ shrink the quad (2 to 4 across in its XY plane) below
        // `MIN_PLACED_SIZE`, into f32's subnormal numbers: refused naming the node placing it
        // (it rendered black).
        let what = format!("node {node} scale {scale:?}");
        let (least, most) = [scale.0, scale.1, scale.2]
            .iter()
            .fold((f64::MAX, 0.0f64), |(l, m), &s| (l.min(s), m.max(s)));
        let flat = node == 0 && (least <= most * 1e-6 || least < 1e-150);
        let shrunk = scale.0.max(scale.1) < manylight::scene::mesh::MIN_PLACED_SIZE;
        match gltf_check(&file, true, &what) {
            Ok(()) if !shrunk => {}
            Err(e) if flat && e.contains("nothing to draw") => {}
            Err(e) if shrunk && e.contains("shrinks the object") => {}
            Ok(()) => panic!("{what}: loaded, though shrunk below f32's normal numbers"),
            Err(e) => panic!("{what}: refused: {e}"),
        }
    }
}
