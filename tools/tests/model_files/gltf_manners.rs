//! How the glTF loader treats files as artists export them, on files the tests write: the
//! automatic camera keeps the whole model in the picture, `--lights N` lights a flat model,
//! a file without lights gets a hint and one with nothing to draw an error, unsupported
//! required extensions are named as such, and ignored features are warned once each by name.

use crate::common;

use std::path::Path;

use common::files::write;
use common::gltf::Builder;
use common::{max_oracle_error, mean, Gpu};
use glam::Vec3;
use manylight::metrics::cpu_reference::Encoding;
use manylight::scene::{self, LoadReport, Scene, SceneError};
use manylight::{EsVersion, RenderOptions};
use serde_json::{json, Value};

/// A VEC3 float accessor of `values`.
fn vec3s(b: &mut Builder, values: &[[f32; 3]]) -> usize {
    b.floats(values.as_flattened(), "VEC3")
}

/// An axis-aligned box from `min` to `max` (flat normals: none given) as a primitive.
fn cuboid(b: &mut Builder, min: [f32; 3], max: [f32; 3]) -> Value {
    let corners: Vec<[f32; 3]> = (0..8)
        .map(|i| {
            let pick = |bit: usize, axis: usize| {
                if i & (1 << bit) != 0 {
                    max[axis]
                } else {
                    min[axis]
                }
            };
            [pick(0, 0), pick(1, 1), pick(2, 2)]
        })
        .collect();
    let p = vec3s(b, &corners);
    // Two triangles per face, every face.
    let faces: [[u16; 4]; 6] = [
        [0, 2, 6, 4],
        [1, 5, 7, 3],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 1, 3, 2],
        [4, 6, 7, 5],
    ];
    let idx: Vec<u16> = faces
        .iter()
        .flat_map(|f| [f[0], f[1], f[2], f[0], f[2], f[3]])
        .collect();
    let i = b.u16s(&idx);
    json!({"attributes": {"POSITION": p}, "indices": i})
}

/// A `size` × `size` square in XZ at y = 0, facing +Y.
fn floor(b: &mut Builder, size: f32) -> Value {
    let h = size / 2.0;
    let p = vec3s(b, &[[-h, 0.0, h], [h, 0.0, h], [h, 0.0, -h], [-h, 0.0, -h]]);
    let n = vec3s(b, &[[0.0, 1.0, 0.0]; 4]);
    let i = b.u16s(&[0, 1, 2, 0, 2, 3]);
    json!({"attributes": {"POSITION": p, "NORMAL": n}, "indices": i})
}

/// A document placing each primitive as its own mesh on its own node, white materials.
fn meshes(primitives: Vec<Value>) -> Value {
    let n = primitives.len();
    json!({
        "scene": 0,
        "scenes": [{"nodes": (0..n).collect::<Vec<_>>()}],
        "nodes": (0..n).map(|i| json!({"mesh": i})).collect::<Vec<_>>(),
        "meshes": primitives.into_iter().map(|p| json!({"primitives": [p]})).collect::<Vec<_>>(),
    })
}

/// `--scene FILE --lights N` (`lights` 0: the file's own lights only).
fn load(path: &Path, lights: usize) -> Result<(Scene, LoadReport), SceneError> {
    scene::load(path.to_str().unwrap(), Some((lights, 3)))
}

#[test]
fn the_automatic_camera_keeps_the_whole_model_inside_the_frame() {
    let dir = tempfile::tempdir().unwrap();
    let shapes = [
        // The Khronos Box: a unit cube standing on y = 0.
        ("box", [-0.5, 0.0, -0.5], [0.5, 1.0, 0.5]),
        ("tall", [-0.1, 0.0, -0.1], [0.1, 3.0, 0.1]),
        ("wide", [-4.0, 0.0, -0.2], [4.0, 0.5, 0.2]),
        ("far", [1000.0, 2000.0, -500.0], [1001.0, 2000.5, -499.0]),
    ];
    let mut gpu = Gpu::new(EsVersion::Es3);
    for (name, min, max) in shapes {
        let mut b = Builder::default();
        let doc = meshes(vec![cuboid(&mut b, min, max)]);
        let path = write(dir.path(), &format!("{name}.gltf"), b.gltf(doc));
        let (mut s, _) = load(&path, 0).unwrap();
        // Lit by ambient alone: the model white, the background black.
        s.ambient = Vec3::ONE;
        for (w, h) in [(96, 54), (48, 48)] {
            let img = gpu.render(&s, w, h, &RenderOptions::default());
            let lit = |x: u32, y: u32| img.get_pixel(x, y).0[..3].iter().any(|&c| c > 16);
            let on_edge = (0..w)
                .flat_map(|x| [(x, 0), (x, h - 1)])
                .chain((0..h).flat_map(|y| [(0, y), (w - 1, y)]))
                .filter(|&(x, y)| lit(x, y))
                .count();
            assert_eq!(
                on_edge, 0,
                "{name} at {w}x{h}: the model touches the frame's edge"
            );
            let covered = (0..w)
                .flat_map(|x| (0..h).map(move |y| (x, y)))
                .filter(|&(x, y)| lit(x, y))
                .count();
            // Seen, not a speck: a tall or wide model fills one direction of the frame.
            assert!(
                covered * 40 > (w * h) as usize,
                "{name} at {w}x{h}: only {covered} pixels show the model"
            );
        }
    }
}

#[test]
fn random_lights_light_a_flat_model_as_the_f64_model_says() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let doc = meshes(vec![floor(&mut b, 8.0)]);
    let path = write(dir.path(), "floor.gltf", b.gltf(doc));
    let (mut s, report) = load(&path, 16).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    s.ambient = Vec3::ZERO;
    // The volume reaches a share of the diagonal above the plane, not a sliver of it.
    let above = s.lights.iter().filter(|l| l.position.y > 0.5).count();
    assert!(above >= 4, "only {above} of 16 lights well above the floor");
    let mut gpu = Gpu::new(EsVersion::Es3);
    gpu.r().set_method_named("forward").unwrap();
    let img = gpu.render(&s, 96, 54, &RenderOptions::default());
    // The floor's pixels: those the ambient term alone shows.
    let mut shown = s.clone();
    (shown.ambient, shown.lights) = (Vec3::ONE, Vec::new());
    let mask = gpu.render(&shown, 96, 54, &RenderOptions::default());
    let floor: Vec<u32> = img
        .pixels()
        .zip(mask.pixels())
        .filter(|(_, m)| m[0] > 128)
        .map(|(p, _)| u32::from(p[0].max(p[1]).max(p[2])))
        .collect();
    assert!(
        floor.len() > 96 * 54 / 20,
        "the floor covers {} pixels",
        floor.len()
    );
    let floor_mean = f64::from(floor.iter().sum::<u32>()) / floor.len() as f64;
    eprintln!("floor mean {floor_mean:.1}, picture mean {:.1}", mean(&img));
    assert!(
        floor_mean > 40.0,
        "the floor is nearly black: mean {floor_mean:.1}"
    );
    let (e, at, n) = max_oracle_error(&img, &s, Encoding::Srgb, gpu.r().caps());
    // A reference that kept (almost) no pixel would compare nothing and read 0.
    assert!(n >= 50, "only {n} pixels compared");
    assert!(e <= 2.0, "{e:.1} / 255 off the f64 model at {at:?}");
}

#[test]
fn a_file_without_lights_gets_one_hint_and_one_with_lights_none() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let doc = meshes(vec![cuboid(&mut b, [0.0; 3], [1.0; 3])]);
    let path = write(dir.path(), "dark.gltf", b.gltf(doc));
    let (_, report) = load(&path, 0).unwrap();
    let hint = format!(
        "no lights in {}: ambient only; add lights (`Scene::lights`; `--lights N` on the command line)",
        path.display()
    );
    assert_eq!(report.warnings, [hint], "{:?}", report.warnings);
    let (_, report) = load(&path, 4).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    // A sun alone lights the file: no hint.
    let mut doc = meshes(vec![cuboid(&mut b, [0.0; 3], [1.0; 3])]);
    doc["extensionsUsed"] = json!(["KHR_lights_punctual"]);
    doc["extensions"] = json!({"KHR_lights_punctual":
        {"lights": [{"type": "directional", "intensity": 2048}]}});
    doc["nodes"]
        .as_array_mut()
        .unwrap()
        .push(json!({"extensions": {"KHR_lights_punctual": {"light": 0}}}));
    doc["scenes"][0]["nodes"] = json!([0, 1]);
    let path = write(dir.path(), "sunlit.gltf", b.gltf(doc));
    let (scene, report) = load(&path, 0).unwrap();
    assert_eq!(scene.directional_lights.len(), 1);
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
}

#[test]
fn a_file_with_nothing_to_draw_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let lights = json!({"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 5}]}});
    let light_node = json!({"extensions": {"KHR_lights_punctual": {"light": 0}}});
    // Lights only.
    let only_lights = json!({"extensionsUsed": ["KHR_lights_punctual"], "extensions": lights,
        "scenes": [{"nodes": [0]}], "nodes": [light_node]});
    // A light and points, which are not drawn.
    let mut b = Builder::default();
    let p = vec3s(&mut b, &[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let points = json!({"extensionsUsed": ["KHR_lights_punctual"], "extensions": lights,
        "scenes": [{"nodes": [0, 1]}], "nodes": [light_node, {"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": p}, "mode": 0}]}]});
    for (name, text) in [
        ("lights.gltf", Builder::default().gltf(only_lights)),
        ("points.gltf", b.gltf(points)),
    ] {
        let path = write(dir.path(), name, &text);
        let err = load(&path, 0).unwrap_err().to_string();
        assert!(
            err.contains(name) && err.contains("nothing to draw"),
            "{name}: {err}"
        );
        assert!(!err.contains("malformed"), "{name}: {err}");
    }
    // In a scene file beside something to draw, such a file is a light rig, said once.
    let rig = r#"{"objects": [{"gltf": "lights.gltf"}, {"builtin": "plane"}]}"#;
    let path = write(dir.path(), "rig.json", rig);
    let (s, report) = scene::load(path.to_str().unwrap(), None).unwrap();
    assert_eq!(s.lights.len(), 1);
    let said: Vec<_> = report
        .warnings
        .iter()
        .filter(|w| w.contains("nothing to draw"))
        .collect();
    assert_eq!(
        said,
        ["objects[0]: lights.gltf has nothing to draw: only its lights are used"]
    );
    // A scene file with nothing else to draw is refused like the glTF file alone.
    for (name, text) in [
        (
            "rig_alone.json",
            r#"{"objects": [{"gltf": "lights.gltf"}]}"#,
        ),
        ("empty.json", r#"{"objects": []}"#),
    ] {
        let path = write(dir.path(), name, text);
        let err = scene::load(path.to_str().unwrap(), None)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("objects") && err.contains("nothing to draw"),
            "{name}: {err}"
        );
    }
}

#[test]
fn required_extensions_are_refused_by_name_unless_supported() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let doc = meshes(vec![cuboid(&mut b, [0.0; 3], [1.0; 3])]);
    for ext in [
        "KHR_draco_mesh_compression",
        "EXT_meshopt_compression",
        "KHR_unknown_thing",
    ] {
        let mut doc = doc.clone();
        doc["extensionsUsed"] = json!([ext]);
        doc["extensionsRequired"] = json!([ext]);
        let path = write(dir.path(), "needs.gltf", b.gltf(doc));
        let err = load(&path, 1).unwrap_err().to_string();
        let said = format!("extensionsRequired lists {ext}, which manylight does not support");
        assert!(err.contains(&said), "{err}");
        assert!(
            err.contains("needs.gltf") && !err.contains("malformed"),
            "{err}"
        );
    }
    // Every extension the loader lists as supported may be required.
    for ext in manylight::scene::gltf::SUPPORTED_EXTENSIONS {
        let mut doc = doc.clone();
        doc["extensionsUsed"] = json!([ext]);
        doc["extensionsRequired"] = json!([ext]);
        let path = write(dir.path(), "supported.gltf", b.gltf(doc));
        load(&path, 1).unwrap_or_else(|e| panic!("{ext}: {e}"));
    }
}

#[test]
fn ignored_features_are_warned_once_each_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let cube = cuboid(&mut b, [0.0; 3], [1.0; 3]);
    let morph = vec3s(&mut b, &[[0.0, 0.1, 0.0]; 8]);
    let mut morphed = cube.clone();
    morphed["targets"] = json!([{"POSITION": morph}]);
    let p = vec3s(&mut b, &[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    let times = b.floats(&[0.0, 1.0], "SCALAR");
    let moves = vec3s(&mut b, &[[0.0; 3], [0.0, 1.0, 0.0]]);
    let camera = json!({"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}});
    let doc = json!({
        // Listed twice (against the schema's uniqueItems): still one warning.
        "extensionsUsed": ["KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_clearcoat"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2, 3, 4, 5]}, {"nodes": [0]}],
        "nodes": [
            {"mesh": 0},
            {"mesh": 1, "skin": 0},
            {"mesh": 2},
            {"mesh": 2, "translation": [2, 0, 0]},
            {"camera": 0, "translation": [0, 0, 5]},
            {"camera": 0, "translation": [0, 0, 9]}
        ],
        "meshes": [
            {"primitives": [{"attributes": cube["attributes"], "indices": cube["indices"], "material": 0}]},
            {"primitives": [morphed]},
            {"primitives": [{"attributes": {"POSITION": p}, "mode": 1},
                            {"attributes": {"POSITION": p}, "mode": 1}]}
        ],
        "materials": [{"extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 1},
                                      "KHR_materials_sheen": {"sheenColorFactor": [1, 1, 1]}}}],
        "skins": [{"joints": [0]}],
        "animations": [{"channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}],
                        "samplers": [{"input": times, "output": moves}]}],
        "cameras": [camera],
    });
    let path = write(dir.path(), "features.gltf", b.gltf(doc));
    let (_, report) = load(&path, 1).unwrap();
    let w = &report.warnings;
    for needle in [
        "extension KHR_materials_clearcoat is not supported",
        "extension KHR_materials_sheen is not supported",
        "skins (1) are not applied",
        "morph targets (1 meshes) are not applied",
        "animations (1) are not played",
        "2 scenes: only the default one",
        "2 nodes place cameras: only the first",
        // Two line primitives, placed twice each: one line.
        "mode Lines is not drawn",
    ] {
        let n = w.iter().filter(|l| l.contains(needle)).count();
        assert_eq!(n, 1, "`{needle}` said {n} times in {w:#?}");
    }
    assert!(
        w.iter().all(|l| l.starts_with(&path.display().to_string())),
        "{w:#?}"
    );
    assert_eq!(w.len(), 8, "{w:#?}");
}

#[test]
fn out_of_range_metallic_and_roughness_are_clamped_with_a_warning_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let mut cube = cuboid(&mut b, [0.0; 3], [1.0; 3]);
    cube["material"] = json!(0);
    let mut cube2 = cuboid(&mut b, [2.0; 3], [3.0; 3]);
    cube2["material"] = json!(1);
    let mut doc = meshes(vec![cube, cube2]);
    doc["materials"] = json!([
        {"pbrMetallicRoughness": {"metallicFactor": 5, "roughnessFactor": -2}},
        {"pbrMetallicRoughness": {"metallicFactor": -1, "roughnessFactor": 0.5}}
    ]);
    let path = write(dir.path(), "factors.gltf", b.gltf(doc));
    let (scene, report) = load(&path, 1).unwrap();
    let m = &scene.materials[0];
    assert_eq!((m.metallic, m.roughness), (1.0, 0.0), "{m:?}");
    let w = &report.warnings;
    // Both materials' metallicFactor in one line.
    for needle in [
        "materials[0] (`gltf-material-0`): metallicFactor outside [0, 1] (glTF's range): \
         clamped (and 1 more like it)",
        "materials[0] (`gltf-material-0`): roughnessFactor outside [0, 1]",
    ] {
        let n = w.iter().filter(|l| l.contains(needle)).count();
        assert_eq!(n, 1, "`{needle}` said {n} times in {w:#?}");
    }
}

#[test]
fn a_file_whose_triangles_all_have_zero_area_is_refused_not_drawn_black() {
    let dir = tempfile::tempdir().unwrap();
    // One triangle whose three corners are one point, and one along a line.
    let obj = dir.path().join("points.obj");
    std::fs::write(
        &obj,
        "v 1 2 3\nv 1 2 3\nv 1 2 3\nv 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\nf 4 5 6\n",
    )
    .unwrap();
    let err = manylight::scene::load(obj.to_str().unwrap(), Some((4, 1))).unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("nothing to draw") && text.contains("zero area"),
        "{text}"
    );
    assert!(text.contains("points.obj"), "{text}");
    // One real triangle among them draws.
    std::fs::write(
        &obj,
        "v 1 2 3\nv 1 2 3\nv 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 4 5 6\n",
    )
    .unwrap();
    assert!(manylight::scene::load(obj.to_str().unwrap(), Some((4, 1))).is_ok());
    // A triangle of subnormal coordinates, which a GPU reads as zero (llvmpipe drew it black).
    std::fs::write(&obj, "v 0 0 0\nv 1e-38 0 0\nv 0 1e-38 0\nf 1 2 3\n").unwrap();
    let err = manylight::scene::load(obj.to_str().unwrap(), Some((4, 1))).unwrap_err();
    assert!(err.to_string().contains("zero area"), "{err}");
}
