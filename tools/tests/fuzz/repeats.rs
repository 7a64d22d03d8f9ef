//! Generators for models placed many times: scene files naming the same OBJ and glTF files
//! again and again (under other spellings of the path, with other transforms and colours),
//! and glTF nodes placing one mesh many times, with and without lights and cameras. What loads must hold each distinct mesh once —
//! in the scene and in the ray caster, whose memory a placement adds to stays a constant.

use std::collections::HashSet;
use std::sync::Arc;

use manylight::scene::raycast::SceneRaycaster;
use proptest::prelude::*;

use super::{config, gltf_glb, gltf_valid, render_finite, workspace};

/// A small valid OBJ with `groups` objects and a material library with a texture.
fn obj_with_groups(groups: usize) -> String {
    let mut text = String::from("mtllib m.mtl\n");
    for g in 0..groups {
        let z = g as f32 * 0.5;
        text += &format!(
            "o part{g}\nusemtl {}\nv 0 0 {z}\nv 1 0 {z}\nv 0 1 {z}\nv 1 1 {z}\nvt 0 0\nvt 1 0\n\
             vt 0 1\nvt 1 1\n",
            if g % 2 == 0 { "a" } else { "b" }
        );
        let b = 4 * g + 1;
        text += &format!(
            "f {b}/1 {}/2 {}/3\nf {}/2 {}/4 {}/3\n",
            b + 1,
            b + 2,
            b + 1,
            b + 3,
            b + 2
        );
    }
    text
}

const MTL: &str = "newmtl a\nKd 0.8 0.2 0.2\nmap_Kd tex.png\nnewmtl b\nKd 0.2 0.8 0.2\nd 0.5\n";

/// One `objects` entry of a scene file.
fn reference() -> impl Strategy<Value = serde_json::Value> {
    let path = prop::sample::select(vec!["m.obj", "./m.obj", "sub/../m.obj", "m.glb", "./m.glb"]);
    let scale = prop_oneof![
        (0.1f64..3.0).prop_map(serde_json::Value::from),
        prop::array::uniform3(prop_oneof![-2.0f64..-0.1, 0.1f64..2.0])
            .prop_map(|s| serde_json::json!(s)),
    ];
    (
        path,
        prop::array::uniform3(-20.0f64..20.0),
        -180.0f64..180.0,
        prop::option::weighted(0.5, scale),
        prop::option::weighted(0.2, prop::array::uniform3(0.0f32..1.0)),
        prop::option::weighted(0.1, Just("tex.png")),
    )
        .prop_map(|(path, translate, rotate, scale, color, texture)| {
            let kind = if path.ends_with(".glb") {
                "gltf"
            } else {
                "obj"
            };
            let mut transform = serde_json::json!({"translate": translate, "rotate_y_deg": rotate});
            if let Some(s) = scale {
                transform["scale"] = s;
            }
            let mut o = serde_json::json!({kind: path, "transform": transform});
            if let Some(c) = color {
                o["color"] = serde_json::json!(c);
            }
            if let (Some(t), "obj") = (texture, kind) {
                o["texture"] = serde_json::json!(t);
            }
            o
        })
}

/// Distinct meshes of a loaded scene, by `Arc` identity.
fn distinct_meshes(scene: &manylight::Scene) -> usize {
    let set: HashSet<*const manylight::Mesh> =
        scene.objects.iter().map(|o| Arc::as_ptr(&o.mesh)).collect();
    set.len()
}

proptest! {
    #![proptest_config(config(40))]

    #[test]
    fn repeated_models_are_held_once(
        groups in 1usize..4,
        placements in 0usize..40,
        refs in prop::collection::vec(reference(), 1..200),
        render in prop::bool::weighted(0.2),
        lit in any::<bool>(),
    ) {
        let dir = workspace();
        std::fs::write(dir.path().join("m.obj"), obj_with_groups(groups)).unwrap();
        std::fs::write(dir.path().join("m.mtl"), MTL).unwrap();
        // The glTF places its mesh (two primitives) `placements` more times through nodes.
        let (mut doc, bin) = gltf_valid();
        if !lit {
            // Read once either way; with lights and a camera, each reference places them.
            let root = doc.as_object_mut().unwrap();
            root.remove("extensions");
            root.remove("extensionsUsed");
            root.remove("cameras");
            for node in doc["nodes"].as_array_mut().unwrap() {
                let node = node.as_object_mut().unwrap();
                node.remove("camera");
                node.remove("extensions");
            }
        }
        for i in 0..placements {
            let n = doc["nodes"].as_array().unwrap().len();
            doc["nodes"].as_array_mut().unwrap().push(
                serde_json::json!({"mesh": 0, "translation": [i as f64 * 0.1, 0, -1]}),
            );
            doc["scenes"][0]["nodes"].as_array_mut().unwrap().push(serde_json::json!(n));
        }
        std::fs::write(dir.path().join("m.glb"), gltf_glb(doc.to_string().as_bytes(), &bin))
            .unwrap();
        let refs_count = refs.len();
        let file = dir.path().join("s.json");
        let text = serde_json::json!({"objects": refs, "random_lights": {"count": 4, "seed": 1}});
        std::fs::write(&file, text.to_string()).unwrap();
        let (scene, report) = manylight::scene::load(file.to_str().unwrap(), None)
            .unwrap_or_else(|e| panic!("{e}\n{text}"));
        // One OBJ mesh a group, two glTF primitives: however many references and placements.
        let most = groups + 2;
        prop_assert!(distinct_meshes(&scene) <= most, "{} meshes", distinct_meshes(&scene));
        prop_assert!(report.warnings.len() <= 4, "{:?}", report.warnings);
        let caster = SceneRaycaster::new(&scene);
        prop_assert!(caster.mesh_count() <= most);
        let triangles = 2 * groups + 4;
        prop_assert!(
            caster.heap_bytes() <= 400 * scene.objects.len() + 128 * triangles + 4096,
            "{} bytes for {} objects ({refs_count} references)",
            caster.heap_bytes(),
            scene.objects.len()
        );
        if render {
            render_finite(&scene, &text.to_string());
        }
    }
}
