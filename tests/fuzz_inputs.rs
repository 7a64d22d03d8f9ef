//! Fuzzing what parses input: generated OBJ and MTL text and scene JSON (proptest, seeded by
//! proptest's own persistence; failures shrink to a minimal file and are saved under
//! `tests/proptest-regressions/fuzz_inputs.txt`), plus the hand-kept corpus of hostile files in
//! `tests/fuzz_corpus/`. Every input must load or be refused with a message — no panic — and
//! every accepted scene must render a finite frame (or be refused with a clear limit) through
//! forward and clustered. `MANYLIGHT_FUZZ_CASES` scales the case counts (default 1: a few
//! thousand cases in all, well under a minute).

mod common;

use std::cell::RefCell;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

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
        30 => (1i64..6).prop_map(|i| i.to_string()),
        3 => (-3i64..0).prop_map(|i| i.to_string()),
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

/// OBJ text: mostly a valid little mesh (six vertices, a few faces), then generated lines —
/// valid structure first, so the generated lines are not all refused at the first bad token.
fn obj_text(max: usize) -> impl Strategy<Value = String> {
    (any::<bool>(), lines(obj_line(), max)).prop_map(|(prefix, body)| {
        let base = "mtllib m.mtl\nusemtl a\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n\
                    v 0 0 1\nv 0 0 -1\nvt 0 0\nvt 1 0\nvt 1 1\nf 1/1 2/2 3/3\n";
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
            gpu.r().set_method(method).unwrap();
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

/// Loads `file` as a user would (with a few random lights), asserting no panic and a message
/// on refusal; renders what is accepted when `render` is set.
fn load_and_check(file: &Path, render: bool) {
    let spec = file.to_str().unwrap();
    // Scene files keep their own lights (and random_lights count); OBJ files get a few.
    let lights = (!spec.ends_with(".json")).then_some((4, 1));
    let loaded = catch_unwind(AssertUnwindSafe(|| scene::load(spec, lights)));
    match loaded {
        Err(_) => panic!("loading {spec} panicked:\n{}", describe(file)),
        Ok(Err(e)) => {
            let message = e.to_string();
            assert!(!message.is_empty());
            // The loader's last guard turned a panic inside tobj into this error: the checks
            // before tobj must have refused the file instead.
            assert!(
                !message.contains("(tobj) failed"),
                "tobj panicked on {spec}:\n{}",
                describe(file)
            );
        }
        Ok(Ok((scene, _))) => {
            scene.validate().expect("a loaded scene validates");
            if render {
                render_finite(&scene, &describe(file));
            }
        }
    }
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

proptest! {
    #![proptest_config(config(4000))]

    #[test]
    fn generated_obj_and_mtl_load_or_are_refused(
        obj in obj_text(24),
        mtl in lines(mtl_line(), 12),
    ) {
        let dir = workspace();
        std::fs::write(dir.path().join("m.mtl"), &mtl).unwrap();
        let file = dir.path().join("m.obj");
        std::fs::write(&file, &obj).unwrap();
        load_and_check(&file, false);
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
        load_and_check(&file, true);
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
    assert!(entries.len() >= 5, "the corpus went missing: {entries:?}");
    for file in entries {
        load_and_check(&file, true);
    }
}
