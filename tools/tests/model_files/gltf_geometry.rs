//! glTF meshes and nodes, on files the tests write (JSON with data URIs, external buffer
//! files): flat normals for a primitive without normals and strips unrolled, the node
//! hierarchy's transforms (worked out by hand), indices of every width, sparse accessors,
//! `extras` of any JSON type and custom attributes, and fallback tangents for a fan past
//! MikkTSpace's bound.

use crate::common;

use common::files::{load, write};
use common::gltf::{base64, Builder, FLOAT, UNSIGNED_BYTE, UNSIGNED_INT, UNSIGNED_SHORT};
use common::gltf_models::{checker_png, triangle};
use glam::{DVec3, Vec3};
use serde_json::json;

#[test]
fn missing_normals_become_flat_ones_and_strips_unroll() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    // A bent strip: two triangles at a right angle, sharing an edge.
    let p = b.floats(
        &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 1.0, 1.0, 0.0],
        "VEC3",
    );
    let rest = json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": p}, "mode": 5}]}]});
    let path = write(dir.path(), "strip.gltf", b.gltf(rest));
    let (scene, report) = load(&path).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    let mesh = &scene.objects[0].mesh;
    assert_eq!(mesh.triangle_count(), 2);
    assert_eq!(mesh.positions.len(), 6, "each triangle its own vertices");
    for tri in mesh.indices.chunks(3) {
        let n = mesh.normals[tri[0] as usize];
        for &i in tri {
            assert_eq!(mesh.normals[i as usize], n, "flat: one normal per triangle");
        }
    }
    let (a, b) = (mesh.normals[0], mesh.normals[3]);
    assert!(
        a.dot(b).abs() < 1e-6,
        "the two faces are at a right angle: {a} {b}"
    );
}

#[test]
fn the_node_hierarchy_places_a_child_mesh_with_its_parents_transforms() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let p = b.floats(&[1.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 3.0], "VEC3");
    let half = std::f64::consts::FRAC_1_SQRT_2;
    let rest = json!({
        "scene": 1,
        "scenes": [{"nodes": []}, {"nodes": [0]}],
        "nodes": [
            // Parent: translate, then a quarter turn about +Y, then scale 2.
            {"translation": [10, 0, 0], "rotation": [0, half, 0, half], "scale": [2, 2, 2],
             "children": [1]},
            // Child: a column-major matrix translating by (0, 1, 0) and scaling x by 3.
            {"matrix": [3,0,0,0, 0,1,0,0, 0,0,1,0, 0,1,0,1], "children": [2]},
            {"mesh": 0, "translation": [0, 0, 5]}
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": p}}]}],
    });
    let path = write(dir.path(), "tree.gltf", b.gltf(rest));
    let (scene, _) = load(&path).unwrap();
    assert_eq!(scene.objects.len(), 1);
    let o = &scene.objects[0];
    // By hand: grandchild local p → +(0,0,5) → child: x·3, +(0,1,0) → parent: ·2, then a
    // quarter turn about Y ((x, y, z) → (z, y, −x)), then +(10, 0, 0).
    let by_hand = |p: DVec3| {
        let p = p + DVec3::new(0.0, 0.0, 5.0);
        let p = DVec3::new(p.x * 3.0, p.y + 1.0, p.z);
        let p = p * 2.0;
        DVec3::new(p.z, p.y, -p.x) + DVec3::new(10.0, 0.0, 0.0)
    };
    for v in &o.mesh.positions {
        let got = o.transform.transform_point3(v.as_dvec3());
        let want = by_hand(v.as_dvec3());
        assert!((got - want).length() < 1e-9, "{v}: got {got}, want {want}");
    }
    // The first vertex worked through once more, as numbers: (1,0,0) → (1,0,5) → (3,1,5) →
    // (6,2,10) → (10,2,−6) → (20,2,−6).
    let first = o.transform.transform_point3(DVec3::X);
    assert!(
        (first - DVec3::new(20.0, 2.0, -6.0)).length() < 1e-9,
        "{first}"
    );
}

#[test]
fn indices_of_every_width_and_none_give_the_same_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let corners = [
        0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0,
    ];
    let list = [0u32, 1, 2, 0, 2, 3];
    let mut meshes = Vec::new();
    for width in [1, 2, 4, 0] {
        let mut b = Builder::default();
        let p = b.floats(&corners, "VEC3");
        let n = b.floats(&[0.0, 0.0, 1.0].repeat(4), "VEC3");
        let mut prim = json!({"attributes": {"POSITION": p, "NORMAL": n}});
        if width > 0 {
            let bytes: Vec<u8> = list
                .iter()
                .flat_map(|&i| i.to_le_bytes()[..width].to_vec())
                .collect();
            let component = [0, UNSIGNED_BYTE, UNSIGNED_SHORT, 0, UNSIGNED_INT][width];
            prim["indices"] = json!(b.accessor(&bytes, component, "SCALAR", list.len()));
        } else {
            // No indices: the vertices in order, two triangles' worth.
            let p = b.floats(
                &list
                    .iter()
                    .flat_map(|&i| corners[i as usize * 3..i as usize * 3 + 3].to_vec())
                    .collect::<Vec<_>>(),
                "VEC3",
            );
            let n = b.floats(&[0.0, 0.0, 1.0].repeat(6), "VEC3");
            prim = json!({"attributes": {"POSITION": p, "NORMAL": n}});
        }
        let doc = json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [prim]}]});
        let path = write(dir.path(), &format!("w{width}.gltf"), b.gltf(doc));
        let (scene, _) = load(&path).unwrap();
        let m = &scene.objects[0].mesh;
        let triangles: Vec<[Vec3; 3]> = m
            .indices
            .chunks(3)
            .map(|t| [0, 1, 2].map(|k| m.positions[t[k] as usize]))
            .collect();
        meshes.push(triangles);
    }
    assert!(meshes.windows(2).all(|w| w[0] == w[1]), "{meshes:?}");
}

#[test]
fn an_external_buffer_file_and_a_sparse_accessor_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let p = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3");
    // Sparse: vertex 2 replaced by (0, 5, 0).
    let indices = b.view(&2u16.to_le_bytes());
    let values = b.view(&[0.0f32, 5.0, 0.0].map(f32::to_le_bytes).concat());
    b.accessors[p]["sparse"] = json!({"count": 1,
        "indices": {"bufferView": indices, "componentType": UNSIGNED_SHORT},
        "values": {"bufferView": values}});
    // And a sparse accessor with no buffer view at all: zeros, then the substitution (its
    // index read from byte 2 of its view).
    let offset_indices = b.view(&[u16::MAX, 2].map(u16::to_le_bytes).concat());
    b.accessors
        .push(json!({"componentType": FLOAT, "type": "VEC3", "count": 3,
        "sparse": {"count": 1,
            "indices": {"bufferView": offset_indices, "byteOffset": 2,
                "componentType": UNSIGNED_SHORT},
            "values": {"bufferView": values}}}));
    let doc = json!({"scenes": [{"nodes": [0, 1]}], "nodes": [{"mesh": 0}, {"mesh": 1}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": p}}]},
                   {"primitives": [{"attributes": {"POSITION": 1 + p}}]}]});
    std::fs::write(dir.path().join("mesh data.bin"), &b.bin).unwrap();
    let path = write(
        dir.path(),
        "external.gltf",
        b.document(doc, Some("mesh%20data.bin".into())).to_string(),
    );
    let (scene, _) = load(&path).unwrap();
    // Flat normals: the triangle's three vertices in order.
    assert_eq!(
        scene.objects[0].mesh.positions,
        [Vec3::ZERO, Vec3::X, Vec3::new(0.0, 5.0, 0.0)]
    );
    assert_eq!(
        scene.objects[1].mesh.positions,
        [Vec3::ZERO, Vec3::ZERO, Vec3::new(0.0, 5.0, 0.0)]
    );
    // A sparse index past the accessor's count is an error naming it.
    b.views[indices]["byteLength"] = json!(2);
    let bad_index = b.view(&7u16.to_le_bytes());
    b.accessors[p]["sparse"]["indices"]["bufferView"] = json!(bad_index);
    std::fs::write(dir.path().join("mesh data.bin"), &b.bin).unwrap();
    let doc = json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": p}}]}]});
    let path = write(
        dir.path(),
        "sparse.gltf",
        b.document(doc, Some("mesh%20data.bin".into())).to_string(),
    );
    let err = load(&path).unwrap_err().to_string();
    assert!(
        err.contains("accessors[0].sparse.indices") && err.contains("element 0 is out of range"),
        "{err}"
    );
    assert!(
        !err.contains("is 7"),
        "the index's value is not shown: {err}"
    );
}

#[test]
fn extras_of_any_json_type_and_custom_attributes_are_valid_and_ignored() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let base = triangle(&mut b);
    for extras in [
        json!(5),
        json!("x"),
        json!([1, {"a": null}]),
        json!(null),
        json!(true),
        json!({}),
    ] {
        let mut doc = base.clone();
        doc["extras"] = extras.clone();
        doc["nodes"][0]["extras"] = extras.clone();
        doc["scenes"][0]["extras"] = extras.clone();
        doc["meshes"][0]["extras"] = extras.clone();
        doc["meshes"][0]["primitives"][0]["extras"] = extras.clone();
        let mut doc = b.document(doc, None);
        doc["asset"]["extras"] = extras.clone();
        doc["accessors"][0]["extras"] = extras.clone();
        doc["buffers"][0]["uri"] = json!(format!(
            "data:application/octet-stream;base64,{}",
            base64(&b.bin)
        ));
        doc["buffers"][0]["extras"] = extras.clone();
        // An application-specific attribute (a leading underscore) is valid glTF too.
        doc["meshes"][0]["primitives"][0]["attributes"]["_TEMPERATURE"] = json!(0);
        let path = write(dir.path(), "extras.gltf", doc.to_string());
        let (scene, _) = load(&path).unwrap_or_else(|e| panic!("extras {extras}: {e}"));
        assert_eq!(scene.objects.len(), 1);
    }
}

#[test]
fn a_normal_mapped_fan_beyond_the_mikktspace_bound_gets_fallback_tangents_and_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "checker.png", checker_png());
    // 300 triangles around one vertex (over the 256 corners MikkTSpace gets at one position),
    // mapped upright: u along +x, v down the image (−y).
    let rim = 300u16;
    let mut positions = vec![0.0f32; 3];
    for k in 0..=rim {
        let a = k as f32 / rim as f32 * 6.0;
        positions.extend([a.cos(), a.sin(), 0.0]);
    }
    let normals = [0.0f32, 0.0, 1.0].repeat(rim as usize + 2);
    let uvs: Vec<f32> = positions.chunks(3).flat_map(|p| [p[0], -p[1]]).collect();
    let indices: Vec<u16> = (1..=rim).flat_map(|k| [0, k, k + 1]).collect();
    let mut b = Builder::default();
    let (p, n, t) = (
        b.floats(&positions, "VEC3"),
        b.floats(&normals, "VEC3"),
        b.floats(&uvs, "VEC2"),
    );
    let i = b.u16s(&indices);
    let rest = json!({
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": p, "NORMAL": n, "TEXCOORD_0": t},
                                    "indices": i, "material": 0}]}],
        "materials": [{"normalTexture": {"index": 0}}],
        "textures": [{"source": 0}], "images": [{"uri": "checker.png"}],
    });
    let (scene, report) = load(&write(dir.path(), "fan.gltf", b.gltf(rest))).unwrap();
    let warned: Vec<_> = report
        .warnings
        .iter()
        .filter(|w| w.contains("900 of 900 triangle corners have no MikkTSpace tangent"))
        .collect();
    assert_eq!(warned.len(), 1, "{:?}", report.warnings);
    let mesh = &scene.objects[0].mesh;
    assert_eq!(mesh.tangents.len(), mesh.positions.len());
    for t in &mesh.tangents {
        assert!(
            (*t - glam::Vec4::new(1.0, 0.0, 0.0, 1.0)).length() < 1e-5,
            "{t}"
        );
    }
}

/// A primitive without normals ignores its tangents (glTF 2.0 §3.7.2.1): a normal map gets
/// generated ones, here +x for a quad mapped upright, not the file's +y.
#[test]
fn a_primitive_without_normals_ignores_its_tangents() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "checker.png", checker_png());
    let mut b = Builder::default();
    let p = b.floats(
        &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0],
        "VEC3",
    );
    let t = b.floats(&[0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0], "VEC2");
    let tangent = b.floats(&[0.0, 1.0, 0.0, 1.0].repeat(4), "VEC4");
    let i = b.u16s(&[0, 1, 2, 0, 2, 3]);
    let rest = json!({
        "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": p, "TEXCOORD_0": t,
                                                   "TANGENT": tangent},
                                    "indices": i, "material": 0}]}],
        "materials": [{"normalTexture": {"index": 0}}],
        "textures": [{"source": 0}], "images": [{"uri": "checker.png"}],
    });
    let (scene, _) = load(&write(dir.path(), "quad.gltf", b.gltf(rest))).unwrap();
    let mesh = &scene.objects[0].mesh;
    assert_eq!(mesh.tangents.len(), mesh.positions.len());
    for t in &mesh.tangents {
        assert!(
            (t.truncate() - Vec3::X).length() < 1e-5,
            "not the generated tangent: {t}"
        );
    }
}

/// A primitive listing one triangle over and over (through its indices, in either winding)
/// keeps one copy with a warning counting the rest (one of each winding when single-sided:
/// the two windings are its two sides); a copy whose colour differs stays, and a blended
/// surface keeps every copy (they blend).
#[test]
fn duplicate_triangles_are_dropped_from_opaque_primitives_only() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let p = b.floats(
        &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0],
        "VEC3",
    );
    let n = b.floats(&[0.0, 0.0, 1.0].repeat(4), "VEC3");
    let c = b.floats(
        &[[1.0, 1.0, 1.0, 1.0].repeat(3), vec![1.0, 0.0, 0.0, 1.0]].concat(),
        "VEC4",
    );
    // 1 000 copies of (0 1 2), half of them reversed, then one through vertex 3 (another colour).
    let mut indices: Vec<u16> = (0..1000)
        .flat_map(|k| if k % 2 == 0 { [0, 1, 2] } else { [2, 1, 0] })
        .collect();
    indices.extend([3, 1, 2]);
    let i = b.u16s(&indices);
    let cases = [
        ("OPAQUE", true, 2, Some(999)),
        ("OPAQUE", false, 3, Some(998)),
        ("BLEND", false, 1001, None),
    ];
    for (mode, double_sided, kept, dropped) in cases {
        let rest = json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
            "materials": [{"alphaMode": mode, "doubleSided": double_sided}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": p, "NORMAL": n, "COLOR_0": c},
                "indices": i, "material": 0}]}]});
        let (scene, report) = load(&write(dir.path(), "dup.gltf", b.gltf(rest))).unwrap();
        let what = format!("{mode}, doubleSided {double_sided}");
        assert_eq!(scene.objects[0].mesh.triangle_count(), kept, "{what}");
        let warned = report
            .warnings
            .iter()
            .find(|w| w.contains("duplicate triangles"));
        let said = dropped.map(|n| format!("{n} duplicate triangles"));
        assert_eq!(
            warned.is_some(),
            said.is_some(),
            "{what}: {:?}",
            report.warnings
        );
        if let (Some(w), Some(said)) = (warned, said) {
            assert!(w.contains(&said), "{what}: {w}");
        }
    }
}
