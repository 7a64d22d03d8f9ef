//! Malformed glTF files, on files the tests write: each is an error naming the file and the
//! glTF path at fault (truncated GLBs, indices and accessors out of range, node cycles,
//! non-finite or huge values, missing buffers, bad lights, integers that would wrap, non-affine
//! matrices, a GLB's foreign first chunk); a scene file's transform that places a model out of
//! range is blamed on the scene file.

use crate::common;

use common::files::{load, write};
use common::gltf::Builder;
use common::gltf_models::{floor, lights_document, quad_obj, triangle};
use serde_json::json;

#[test]
fn malformed_files_are_errors_naming_the_file_and_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let mut cases: Vec<(&str, Vec<u8>, Vec<&str>)> = Vec::new();
    // Truncated GLB.
    {
        let mut b = Builder::default();
        let doc = triangle(&mut b);
        let full = b.glb(doc);
        cases.push((
            "truncated.glb",
            full[..full.len() / 2].to_vec(),
            vec!["truncated GLB"],
        ));
        cases.push((
            "header.glb",
            full[..10].to_vec(),
            vec!["truncated GLB", "header"],
        ));
    }
    // Index out of range.
    {
        let mut b = Builder::default();
        let p = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3");
        let i = b.u16s(&[0, 1, 9]);
        let doc = json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": p}, "indices": i}]}]});
        cases.push((
            "index.gltf",
            b.gltf(doc).into_bytes(),
            vec![
                "meshes[0].primitives[0].indices",
                "element 2 is out of range for 3 vertices",
            ],
        ));
    }
    // An accessor past the end of its buffer view; a view past its buffer.
    {
        let mut b = Builder::default();
        let mut doc = triangle(&mut b);
        b.accessors[0]["count"] = json!(100);
        cases.push((
            "accessor.gltf",
            b.gltf(doc.clone()).into_bytes(),
            vec!["POSITION (accessors[0])", "past the end of bufferViews[0]"],
        ));
        b.accessors[0]["count"] = json!(3);
        b.views[1]["byteLength"] = json!(4000);
        b.accessors[1]["count"] = json!(3);
        doc["meshes"][0]["primitives"][0]["indices"] = json!(1);
        cases.push((
            "view.gltf",
            b.gltf(doc).into_bytes(),
            vec!["bufferViews[1]", "past the end of buffers[0]"],
        ));
    }
    // A node cycle, and a node with two parents.
    {
        let mut b = Builder::default();
        let mut doc = triangle(&mut b);
        doc["nodes"] = json!([{"children": [1]}, {"children": [2]}, {"mesh": 0, "children": [0]}]);
        cases.push((
            "cycle.gltf",
            b.gltf(doc.clone()).into_bytes(),
            vec!["nodes[0]", "cycle"],
        ));
        doc["nodes"] = json!([{"children": [2]}, {"children": [2]}, {"mesh": 0}]);
        doc["scenes"] = json!([{"nodes": [0, 1]}]);
        cases.push((
            "parents.gltf",
            b.gltf(doc).into_bytes(),
            vec!["nodes[2]", "one parent"],
        ));
    }
    // A NaN position.
    {
        let mut b = Builder::default();
        let p = b.floats(&[0.0, 0.0, 0.0, f32::NAN, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3");
        let doc = json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": p}}]}]});
        cases.push((
            "nan.gltf",
            b.gltf(doc).into_bytes(),
            vec![
                "meshes[0].primitives[0].attributes.POSITION",
                "element 1",
                "finite",
            ],
        ));
    }
    // A huge position (past the object-space limit).
    {
        let mut b = Builder::default();
        let p = b.floats(&[0.0, 0.0, 0.0, 3e30, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3");
        let doc = json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": p}}]}]});
        cases.push((
            "huge.gltf",
            b.gltf(doc).into_bytes(),
            vec!["POSITION", "element 1", "past"],
        ));
    }
    // A missing buffer file.
    {
        let mut b = Builder::default();
        let doc = triangle(&mut b);
        let mut doc = b.document(doc, Some("missing.bin".into()));
        doc["asset"] = json!({"version": "2.0"});
        cases.push((
            "nobuffer.gltf",
            doc.to_string().into_bytes(),
            vec!["buffers[0]", "missing.bin"],
        ));
    }
    // A huge count, with no buffer view behind it (all zeros): refused before allocating.
    {
        let mut b = Builder::default();
        let doc = triangle(&mut b);
        b.accessors[0]["count"] = json!(4_000_000_000u64);
        cases.push((
            "count.gltf",
            b.gltf(doc).into_bytes(),
            vec!["accessors[0]", "4000000000", "limit"],
        ));
    }
    // Node transforms, lights, structure.
    {
        let mut b = Builder::default();
        let mut doc = triangle(&mut b);
        doc["nodes"][0]["scale"] = json!([1e300, 1e300, 1e300]);
        cases.push((
            "scale.gltf",
            b.gltf(doc.clone()).into_bytes(),
            vec!["nodes[0]", "bounds"],
        ));
        // Scaled into f32's subnormal numbers: a black frame, not an object.
        doc["nodes"][0]["scale"] = json!([1e-40, 1e-40, 1e-40]);
        cases.push((
            "tiny.gltf",
            b.gltf(doc.clone()).into_bytes(),
            vec!["nodes[0]", "shrinks the object to"],
        ));
        doc["nodes"][0] = json!({"mesh": 0, "rotation": [0, 0, 0, 0]});
        cases.push((
            "rotation.gltf",
            b.gltf(doc.clone()).into_bytes(),
            vec!["nodes[0].rotation"],
        ));
        doc["nodes"][0] = json!({"mesh": 0, "extensions": {"KHR_lights_punctual": {"light": 0}}});
        doc["extensions"] = json!({"KHR_lights_punctual": {"lights": [
            {"type": "spot", "spot": {"innerConeAngle": 0.7, "outerConeAngle": 0.2}}]}});
        cases.push((
            "cone.gltf",
            b.gltf(doc.clone()).into_bytes(),
            // In the file's own terms, not the converted `outer_deg`.
            vec![
                "lights[0]",
                "spot.innerConeAngle (0.7)",
                "spot.outerConeAngle (0.2)",
            ],
        ));
        doc["nodes"][0] = json!({"mesh": 0, "extensions": {"KHR_lights_punctual": {"light": 3}}});
        cases.push((
            "light_index.gltf",
            b.gltf(doc.clone()).into_bytes(),
            // The file's spelling of the extension, not the crate's `khrLightsPunctual`.
            vec!["nodes[0].extensions.KHR_lights_punctual.light"],
        ));
        doc.as_object_mut().unwrap().remove("extensions");
        doc["nodes"][0] = json!({"mesh": 0});
        doc["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
        cases.push((
            "draco.gltf",
            b.gltf(doc.clone()).into_bytes(),
            vec!["extensionsRequired"],
        ));
        doc.as_object_mut().unwrap().remove("extensionsRequired");
        doc["nodes"] = json!([{}]);
        cases.push((
            "empty.gltf",
            b.gltf(doc.clone()).into_bytes(),
            vec!["nothing to show"],
        ));
        doc["nodes"] = json!([{"mesh": 7}]);
        cases.push((
            "dangling.gltf",
            b.gltf(doc).into_bytes(),
            vec!["nodes[0].mesh"],
        ));
    }
    {
        let mut b = Builder::default();
        let doc = triangle(&mut b);
        let mut doc = b.document(
            doc,
            Some("data:application/octet-stream;base64,AA*A".into()),
        );
        doc["asset"] = json!({"version": "2.0"});
        cases.push((
            "base64.gltf",
            doc.to_string().into_bytes(),
            vec!["buffers[0].uri", "base64"],
        ));
    }
    cases.push(("json.gltf", b"{\"asset\": ".to_vec(), vec!["JSON"]));
    // Five million empty nodes, 15 MB that would parse into 3 GB: refused before parsing.
    {
        let mut b = Builder::default();
        let triangle = triangle(&mut b);
        let text = b.document(triangle, None).to_string();
        let nodes = format!("\"nodes\":[{{\"mesh\":0}}{}]", ",{}".repeat(5_000_000));
        let text = text.replacen("\"nodes\":[{\"mesh\":0}]", &nodes, 1);
        assert!(text.len() > 15_000_000);
        cases.push((
            "nodes.gltf",
            text.into_bytes(),
            vec!["holds 5000", "objects and arrays", "refused before parsing"],
        ));
    }
    for (name, bytes, needles) in cases {
        let path = write(dir.path(), name, &bytes);
        let err = match load(&path) {
            Ok(_) => panic!("{name} loaded"),
            Err(e) => e.to_string(),
        };
        assert!(err.contains(name), "the error should name the file: {err}");
        for needle in needles {
            assert!(
                err.contains(needle),
                "{name}: expected `{needle}` in: {err}"
            );
        }
    }
}

#[test]
fn structural_values_that_wrap_or_cannot_be_drawn_are_refused_by_field() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let base = triangle(&mut b);
    // 2³² + 4 would wrap to TRIANGLES, 2³² to POINTS (and be skipped): both refused.
    let mode = "/meshes/0/primitives/0/mode";
    let cases = [
        (
            "mode",
            mode,
            json!(4294967300u64),
            "meshes[0].primitives[0].mode: a number past",
        ),
        (
            "mode0",
            mode,
            json!(4294967296u64),
            "meshes[0].primitives[0].mode",
        ),
        (
            "mesh",
            "/nodes/0/mesh",
            json!(4294967296u64),
            "nodes[0].mesh",
        ),
        (
            "projective",
            "/nodes/0/matrix",
            json!([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, -1, 0, 0, 0, 1]),
            "nodes[0].matrix: not an affine transform (last row 0 0 -1 1",
        ),
        (
            "zero_row",
            "/nodes/0/matrix",
            json!([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0]),
            "nodes[0].matrix: not an affine transform (last row 0 0 0 0",
        ),
    ];
    for (name, pointer, value, want) in cases {
        let mut doc = base.clone();
        let (parent, key) = pointer.rsplit_once('/').unwrap();
        doc.pointer_mut(parent).unwrap()[key] = value;
        let path = write(dir.path(), &format!("{name}.gltf"), b.gltf(doc));
        let err = load(&path).unwrap_err().to_string();
        assert!(err.contains(want), "{name}: {err}");
    }
    // A flat (singular) matrix is a flat object, not an error: drawn where the triangle (in
    // the XY plane) keeps its area, nothing to draw where it becomes a line.
    let mut doc = base.clone();
    doc["nodes"][0]["matrix"] = json!([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1]);
    let path = write(dir.path(), "flat.gltf", b.gltf(doc.clone()));
    assert_eq!(load(&path).unwrap().0.objects.len(), 1);
    doc["nodes"][0]["matrix"] = json!([1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);
    let path = write(dir.path(), "line.gltf", b.gltf(doc));
    let err = load(&path).unwrap_err().to_string();
    assert!(err.contains("nothing to draw"), "{err}");
    // A GLB whose first chunk is neither JSON nor BIN says what it is.
    let mut bytes = b.glb(base);
    bytes[16..20].copy_from_slice(b"ABCD");
    let path = write(dir.path(), "chunk.glb", &bytes);
    let err = load(&path).unwrap_err().to_string();
    assert!(
        err.contains("first chunk has type 0x44434241 `ABCD`"),
        "{err}"
    );
}

#[test]
fn a_scene_files_transform_that_places_a_model_out_of_range_is_blamed_on_the_scene_file() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let mut doc = lights_document(&mut b);
    doc["cameras"] = json!([{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}]);
    doc["nodes"][4]["camera"] = json!(0);
    write(dir.path(), "lamps.gltf", b.gltf(doc.clone()));
    // Lights and a camera only, no mesh: placed far by the transform all the same.
    doc["nodes"][0].as_object_mut().unwrap().remove("mesh");
    write(dir.path(), "lights.gltf", b.gltf(doc));
    // A mesh only.
    let mut t = Builder::default();
    let tri = triangle(&mut t);
    write(dir.path(), "tri.gltf", t.gltf(tri));
    write(dir.path(), "q.obj", quad_obj(&floor(), "q"));
    write(dir.path(), "q.mtl", "newmtl q\nKd 1 1 1\n");
    for (model, transform) in [
        (r#""gltf": "lamps.gltf""#, r#"{"translate": [1e13, 0, 0]}"#),
        (r#""gltf": "lamps.gltf""#, r#"{"scale": 1e300}"#),
        (
            r#""gltf": "lights.gltf""#,
            r#"{"translate": [0, -2e12, 0]}"#,
        ),
        (r#""gltf": "tri.gltf""#, r#"{"translate": [0, 0, 5e12]}"#),
        (r#""obj": "q.obj""#, r#"{"translate": [0, 0, 5e12]}"#),
        (r#""builtin": "plane""#, r#"{"scale": [1e200, 1, 1]}"#),
        (r#""gltf": "tri.gltf""#, r#"{"scale": 1e-40}"#),
        (r#""obj": "q.obj""#, r#"{"scale": 1e-40}"#),
    ] {
        let text = format!(
            r#"{{"objects": [{{"builtin": "plane"}}, {{{model}, "transform": {transform}}}]}}"#
        );
        let path = write(dir.path(), "far.json", &text);
        let err = load(&path).unwrap_err().to_string();
        assert!(err.contains("`objects[1].transform`"), "{text}: {err}");
        assert!(
            !err.contains("malformed glTF") && !err.contains("camera.position"),
            "{err}"
        );
    }
    // Only the file's camera out of range (far from its triangle): the scene loads framed on
    // the triangle, and the warning blames the placing.
    let mut cam = triangle(&mut t);
    cam["cameras"] = json!([{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}]);
    cam["nodes"] = json!([{"mesh": 0}, {"camera": 0, "translation": [0, 0, 5]}]);
    cam["scenes"] = json!([{"nodes": [0, 1]}]);
    write(dir.path(), "seen.gltf", t.gltf(cam));
    let path = write(
        dir.path(),
        "seen.json",
        r#"{"objects": [{"gltf": "seen.gltf", "transform": {"scale": 4e11}}]}"#,
    );
    let (mut scene, report) = load(&path).unwrap();
    let said = report.warnings.join("\n");
    assert!(
        said.contains("placing nodes[1] (cameras[0])") && said.contains("is not used"),
        "{said}"
    );
    let camera = scene.camera;
    scene.frame_camera();
    assert_eq!(camera, scene.camera);
    // Within range, but too large for a camera framing it to stay within range: the missing
    // `camera` is named, and giving one loads.
    let big = r#"{"builtin": "plane", "transform": {"scale": 1e11}}"#;
    // Two objects: framed rather than the built-in's own camera.
    let objects = format!(r#""objects": [{big}, {{"builtin": "plane"}}]"#);
    let path = write(dir.path(), "big.json", format!("{{{objects}}}"));
    let err = load(&path).unwrap_err().to_string();
    assert!(
        err.contains("`camera`") && err.contains("give `camera`"),
        "{err}"
    );
    let camera = r#""camera": {"position": [0, 1, 9e11], "target": [0, 0, 0]}"#;
    let text = format!("{{{objects}, {camera}}}");
    let path = write(dir.path(), "big.json", &text);
    load(&path).unwrap();
}

/// A document that is valid JSON but not glTF names the field that does not fit (an array too
/// long, a field given twice, an index past u32), never "not valid JSON", and never a name the
/// file made up.
#[test]
fn a_value_that_does_not_fit_the_schema_is_named_by_its_field() {
    let dir = tempfile::tempdir().unwrap();
    let asset = r#""asset": {"version": "2.0"}"#;
    let cases = [
        (
            format!(r#"{{{asset}, "nodes": [{{"rotation": [0, 0, 0, 1, 0]}}]}}"#),
            "nodes[0].rotation: the wrong type or form",
        ),
        (
            format!(r#"{{{asset}, "scene": 0, "scene": 0, "scenes": [{{}}]}}"#),
            "`scene` given twice",
        ),
        (
            format!(
                r#"{{{asset}, "materials": [{{"pbrMetallicRoughness":
                    {{"baseColorTexture": {{"index": 0, "texCoord": 4294967296}}}}}}]}}"#
            ),
            "materials[0].pbrMetallicRoughness.baseColorTexture.texCoord",
        ),
        (
            format!(
                r#"{{{asset}, "meshes": [{{"primitives": [{{"attributes":
                    {{"SECRET_KEY": true}}}}]}}]}}"#
            ),
            "meshes[0].primitives[0].attributes",
        ),
    ];
    for (json, expected) in &cases {
        let err = load(&write(dir.path(), "m.gltf", json))
            .unwrap_err()
            .to_string();
        assert!(err.contains(expected), "{expected}: {err}");
        assert!(
            !err.contains("not valid JSON") && !err.contains("SECRET"),
            "{err}"
        );
    }
}

/// A glTF version this loader does not read (a major version past 2, a minVersion past 2.0)
/// is refused naming the field, without the file's string; 2.x and minVersion 2.0 load.
#[test]
fn versions_past_2_0_are_refused_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let base = triangle(&mut b);
    let with = |asset: serde_json::Value| {
        let mut doc = serde_json::from_str::<serde_json::Value>(&b.gltf(base.clone())).unwrap();
        doc["asset"] = asset;
        doc.to_string()
    };
    for (asset, refused) in [
        (json!({"version": "3.0"}), Some("asset.version")),
        (
            json!({"version": "2.0", "minVersion": "2.5"}),
            Some("asset.minVersion"),
        ),
        (json!({"version": "2.1", "minVersion": "2.0"}), None),
        (json!({"version": "2.0"}), None),
    ] {
        let loaded = load(&write(dir.path(), "v.gltf", with(asset.clone())));
        match refused {
            Some(field) => {
                let err = loaded.unwrap_err().to_string();
                assert!(
                    err.contains(field) && !err.contains("2.5") && !err.contains("3.0"),
                    "{err}"
                );
            }
            None => {
                loaded.unwrap_or_else(|e| panic!("{asset}: {e}"));
            }
        }
    }
}
