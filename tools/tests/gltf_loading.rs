//! glTF 2.0 loading, on files the tests write (JSON with base64 data-URI buffers, GLBs
//! assembled here, PNGs written with `image`): meshes, the node hierarchy, materials and
//! textures, cameras, `KHR_lights_punctual`, glTF objects in JSON scene files, malformed files
//! (each a clear error naming the file and the glTF path at fault) and a render of a glTF
//! scene against the same scene written as JSON + OBJ.

mod common;

use std::path::{Path, PathBuf};

use common::gltf::{base64, Builder, FLOAT, UNSIGNED_SHORT};
use common::Gpu;
use glam::{DMat4, DQuat, DVec3, Vec3};
use manylight::scene::{self, LightKind, Scene};
use manylight::{EsVersion, RenderOptions};
use serde_json::{json, Value};

const UNSIGNED_INT: u32 = 5125;

/// A primitive (positions, normals, uvs, u16 indices) as glTF JSON.
fn primitive(b: &mut Builder, quad: &Quad, material: Option<usize>) -> Value {
    let p = b.floats(&quad.positions, "VEC3");
    let n = b.floats(&quad.normals, "VEC3");
    let t = b.floats(&quad.uvs, "VEC2");
    let i = b.u16s(&[0, 1, 2, 0, 2, 3]);
    let mut v = json!({"attributes": {"POSITION": p, "NORMAL": n, "TEXCOORD_0": t}, "indices": i});
    if let Some(m) = material {
        v["material"] = json!(m);
    }
    v
}

/// A unit quad's vertex data: four corners, their normals and texture coordinates (glTF's:
/// v down from the image's top).
struct Quad {
    positions: Vec<f32>,
    normals: Vec<f32>,
    uvs: Vec<f32>,
}

/// The floor: 4 × 4 in XZ at y = 0, facing +Y.
fn floor() -> Quad {
    Quad {
        positions: vec![
            -2.0, 0.0, 2.0, 2.0, 0.0, 2.0, 2.0, 0.0, -2.0, -2.0, 0.0, -2.0,
        ],
        normals: [0.0, 1.0, 0.0].repeat(4),
        uvs: vec![0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0],
    }
}

/// A wall or pane: `w` × `h` in XY from the origin's bottom edge, facing +Z.
fn pane(w: f32, h: f32) -> Quad {
    Quad {
        positions: vec![
            -w / 2.0,
            0.0,
            0.0,
            w / 2.0,
            0.0,
            0.0,
            w / 2.0,
            h,
            0.0,
            -w / 2.0,
            h,
            0.0,
        ],
        normals: [0.0, 0.0, 1.0].repeat(4),
        uvs: vec![0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0],
    }
}

/// The same quad as OBJ text (texture v flipped: OBJ's v points up) with its MTL.
fn quad_obj(q: &Quad, material: &str) -> String {
    let mut s = format!("mtllib {material}.mtl\nusemtl {material}\n");
    for p in q.positions.chunks(3) {
        s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for n in q.normals.chunks(3) {
        s += &format!("vn {} {} {}\n", n[0], n[1], n[2]);
    }
    for t in q.uvs.chunks(2) {
        s += &format!("vt {} {}\n", t[0], 1.0 - t[1]);
    }
    s + "f 1/1/1 2/2/2 3/3/3\nf 1/1/1 3/3/3 4/4/4\n"
}

/// A 4 × 4 checker with one odd corner, so a flipped or mirrored mapping shows.
fn checker_png() -> Vec<u8> {
    let img = image::RgbaImage::from_fn(4, 4, |x, y| {
        if (x, y) == (0, 0) {
            image::Rgba([250, 30, 30, 255])
        } else if (x + y) % 2 == 0 {
            image::Rgba([220, 220, 200, 255])
        } else {
            image::Rgba([40, 70, 120, 255])
        }
    });
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    png
}

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn load(path: &Path) -> Result<(Scene, manylight::scene::obj::LoadReport), scene::SceneError> {
    // No random lights: the file's own only.
    without_no_lights_hint(scene::load(path.to_str().unwrap(), Some((0, 1))))
}

/// A load's result less the hint that a file has no lights (gltf_manners.rs checks it).
fn without_no_lights_hint(
    loaded: Result<(Scene, manylight::scene::obj::LoadReport), scene::SceneError>,
) -> Result<(Scene, manylight::scene::obj::LoadReport), scene::SceneError> {
    loaded.map(|(scene, mut report)| {
        report.warnings.retain(|w| !w.starts_with("no lights in "));
        (scene, report)
    })
}

fn quat(q: DQuat) -> Value {
    json!([q.x, q.y, q.z, q.w])
}

#[test]
fn a_textured_mesh_loads_from_gltf_with_a_side_file_and_from_glb() {
    let dir = tempfile::tempdir().unwrap();
    let png = checker_png();
    write(dir.path(), "checker.png", &png);
    let mut b = Builder::default();
    let prim = primitive(&mut b, &floor(), Some(0));
    let material = json!([{"name": "checker", "pbrMetallicRoughness":
        {"baseColorFactor": [0.5, 1, 1, 1], "baseColorTexture": {"index": 0}, "roughnessFactor": 0.5}}]);
    let rest = json!({
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [prim]}], "materials": material,
        "textures": [{"source": 0}], "images": [{"uri": "checker.png"}],
    });
    let gltf = write(dir.path(), "floor.gltf", b.gltf(rest.clone()));
    // The GLB embeds the image in a buffer view.
    let image_view = b.view(&png);
    let mut embedded = rest;
    embedded["images"] = json!([{"bufferView": image_view, "mimeType": "image/png"}]);
    let glb_path = write(dir.path(), "floor.glb", b.glb(embedded.clone()));
    // And a data URI image in a .gltf.
    embedded["images"] = json!([{"uri": format!("data:image/png;base64,{}", base64(&png))}]);
    let data_uri = write(dir.path(), "floor-data.gltf", b.gltf(embedded));
    for path in [gltf, glb_path, data_uri] {
        let (scene, report) = load(&path).unwrap();
        assert!(
            report.warnings.is_empty(),
            "{}: {:?}",
            path.display(),
            report.warnings
        );
        assert_eq!(scene.objects.len(), 1);
        let o = &scene.objects[0];
        assert_eq!(o.mesh.positions.len(), 4);
        assert_eq!(o.mesh.indices, [0, 1, 2, 0, 2, 3]);
        assert_eq!(
            o.mesh.uvs[0],
            glam::Vec2::new(0.0, 1.0),
            "glTF uvs are not flipped"
        );
        let m = &scene.materials[o.material];
        assert_eq!(m.name, "checker");
        assert_eq!(m.diffuse, Vec3::new(0.5, 1.0, 1.0));
        assert!(!m.is_transparent());
        assert!(
            (m.shininess - 30.0).abs() < 1e-3,
            "roughness 0.5: {}",
            m.shininess
        );
        let t = m.diffuse_texture.as_ref().expect("texture bound");
        assert_eq!(t.image.dimensions(), (4, 4));
        assert_eq!(t.image.get_pixel(0, 0).0, [250, 30, 30, 255]);
    }
}

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

fn lights_document(b: &mut Builder) -> Value {
    let p = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3");
    json!({
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1, 0.5, 0.25], "intensity": 3, "range": 7},
            {"type": "point", "intensity": 2048},
            {"type": "spot", "intensity": 5, "range": 9,
             "spot": {"innerConeAngle": 0.25, "outerConeAngle": 0.5}},
            {"type": "directional", "intensity": 100}
        ]}},
        "scenes": [{"nodes": [0, 1, 2, 3, 4]}],
        "nodes": [
            {"translation": [1, 2, 3], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"translation": [-1, 0, 0], "scale": [5, 5, 5],
             "extensions": {"KHR_lights_punctual": {"light": 1}}},
            // Aimed down: a quarter turn about +X takes −Z to −Y.
            {"translation": [0, 4, 0], "rotation": quat(DQuat::from_rotation_x(-std::f64::consts::FRAC_PI_2)),
             "extensions": {"KHR_lights_punctual": {"light": 2}}},
            {"extensions": {"KHR_lights_punctual": {"light": 3}}},
            {"mesh": 0}
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": p}}]}],
    })
}

#[test]
fn point_and_spot_lights_come_with_positions_directions_radii_and_cones() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let doc = lights_document(&mut b);
    let path = write(dir.path(), "lights.gltf", b.gltf(doc));
    let (scene, report) = load(&path).unwrap();
    assert_eq!(scene.lights.len(), 3);
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    // The directional light: the node's −Z, lux on the candela's scale.
    assert_eq!(scene.directional_lights.len(), 1);
    let sun = &scene.directional_lights[0];
    assert_eq!(sun.direction, DVec3::NEG_Z);
    assert_eq!(sun.color, Vec3::ONE);
    assert_eq!(
        f64::from(sun.intensity),
        100.0 * scene::gltf::LUX_TO_INTENSITY
    );
    let point = &scene.lights[0];
    assert_eq!(point.kind, LightKind::Point);
    assert_eq!(point.position, DVec3::new(1.0, 2.0, 3.0));
    assert_eq!(point.radius, 7.0);
    assert_eq!(point.color, Vec3::new(1.0, 0.5, 0.25));
    assert_eq!(
        f64::from(point.intensity),
        3.0 * scene::gltf::CANDELA_TO_INTENSITY
    );
    // One photometric scale: 2 048 cd is intensity 1.
    assert_eq!(scene.lights[1].intensity, 1.0);
    // No range: where 1 / (d² + 1) falls to the cut-off; scale does not change it.
    let unbounded = &scene.lights[1];
    let want = (1.0 / scene::gltf::UNBOUNDED_CUTOFF - 1.0).sqrt();
    assert!(
        (f64::from(unbounded.radius) - want).abs() < 1e-4,
        "{}",
        unbounded.radius
    );
    assert!((unbounded.radius - 31.98).abs() < 0.01);
    let spot = &scene.lights[2];
    assert_eq!(spot.position, DVec3::new(0.0, 4.0, 0.0));
    assert_eq!(spot.radius, 9.0);
    let LightKind::Spot {
        direction,
        inner_deg,
        outer_deg,
    } = spot.kind
    else {
        panic!("not a spot: {spot:?}");
    };
    assert!((direction - DVec3::NEG_Y).length() < 1e-9, "{direction}");
    assert!(
        (inner_deg - 0.25f32.to_degrees() as f64).abs() < 1e-4,
        "{inner_deg}"
    );
    assert!((outer_deg - 28.6479).abs() < 1e-3, "{outer_deg}");
}

#[test]
fn a_gltf_object_in_a_json_scene_brings_its_lights_and_camera_placed_by_its_transform() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let mut doc = lights_document(&mut b);
    doc["cameras"] = json!([{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}]);
    doc["nodes"][4]["camera"] = json!(0);
    doc["nodes"][4]["translation"] = json!([0, 0, 5]);
    write(dir.path(), "lamps.gltf", b.gltf(doc));
    let json_path = write(
        dir.path(),
        "scene.json",
        r#"{"objects": [{"gltf": "lamps.gltf",
             "transform": {"translate": [10, 0, 0], "rotate_y_deg": 90}}],
            "lights": [{"kind": "point", "position": [0, 0, 0], "radius": 1, "color": [1, 1, 1]}]}"#,
    );
    let (scene, _) = scene::load(json_path.to_str().unwrap(), None).unwrap();
    assert_eq!(
        scene.lights.len(),
        4,
        "three from the glTF, one from the JSON"
    );
    let place = DMat4::from_translation(DVec3::new(10.0, 0.0, 0.0))
        * DMat4::from_rotation_y(90f64.to_radians());
    let want = place.transform_point3(DVec3::new(1.0, 2.0, 3.0));
    assert!((scene.lights[0].position - want).length() < 1e-9);
    assert!((scene.lights[0].position - DVec3::new(13.0, 2.0, -1.0)).length() < 1e-9);
    assert_eq!(scene.lights[0].radius, 7.0, "radius not scaled");
    // The sun turned with the object: the quarter turn about +Y takes −Z to −X.
    let sun = scene.directional_lights[0].direction;
    assert!((sun - DVec3::NEG_X).length() < 1e-9, "{sun}");
    // The camera: the only object's own, placed too, looking down the turned −Z (−X).
    let cam = scene.camera;
    assert!((cam.position - place.transform_point3(DVec3::new(0.0, 0.0, 5.0))).length() < 1e-9);
    let forward = (cam.target - cam.position).normalize();
    assert!((forward - DVec3::NEG_X).length() < 1e-9, "{forward}");
    // Both `obj` and `gltf` on one object is an error naming it.
    let both = write(
        dir.path(),
        "both.json",
        r#"{"objects": [{"gltf": "lamps.gltf", "obj": "x.obj"}]}"#,
    );
    let err = scene::load(both.to_str().unwrap(), None)
        .unwrap_err()
        .to_string();
    assert!(err.contains("objects[0]") && err.contains("gltf"), "{err}");
}

#[test]
fn cameras_perspective_with_infinite_far_and_orthographic() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let p = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3");
    let turn = DQuat::from_rotation_y(std::f64::consts::FRAC_PI_2);
    let doc = |camera: Value| {
        json!({
            "scenes": [{"nodes": [0, 1, 2]}],
            "cameras": [camera, {"type": "perspective", "perspective": {"yfov": 1.5, "znear": 1}}],
            "nodes": [
                {"mesh": 0},
                // A parent moves the camera's node; a second camera later is not used.
                {"translation": [0, 1, 0], "children": [3]},
                {"camera": 1},
                {"camera": 0, "translation": [4, 0, 0], "rotation": quat(turn), "scale": [3, 3, 3]}
            ],
            "meshes": [{"primitives": [{"attributes": {"POSITION": p}}]}],
        })
    };
    let persp = doc(json!({"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.05}}));
    let path = write(dir.path(), "persp.gltf", b.gltf(persp));
    let (scene, _) = load(&path).unwrap();
    let cam = scene.camera;
    assert_eq!(cam.position, DVec3::new(4.0, 1.0, 0.0));
    let forward = (cam.target - cam.position).normalize();
    assert!(
        (forward - DVec3::NEG_X).length() < 1e-12,
        "−Z turned a quarter about Y: {forward}"
    );
    assert!((cam.up - DVec3::Y).length() < 1e-12);
    match cam.projection {
        scene::Projection::Perspective {
            fov_y_deg,
            near,
            far,
        } => {
            assert!((fov_y_deg - 0.7f32.to_degrees() as f64).abs() < 1e-4);
            assert_eq!(near, 0.05f32 as f64);
            assert!(far.is_infinite(), "no zfar: an infinite far plane");
        }
        p => panic!("{p:?}"),
    }
    let ortho = doc(json!({"type": "orthographic",
        "orthographic": {"xmag": 3, "ymag": 2, "znear": 0.5, "zfar": 40}}));
    let path = write(dir.path(), "ortho.gltf", b.gltf(ortho));
    let (scene, _) = load(&path).unwrap();
    assert_eq!(
        scene.camera.projection,
        scene::Projection::Orthographic {
            height: 4.0,
            near: 0.5,
            far: 40.0
        }
    );
    // No camera: framed on the bounds as for OBJ.
    let mut none = doc(json!({"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.05}}));
    none["nodes"] = json!([{"mesh": 0}]);
    none["scenes"] = json!([{"nodes": [0]}]);
    none.as_object_mut().unwrap().remove("cameras");
    let path = write(dir.path(), "framed.gltf", b.gltf(none));
    let (mut scene, _) = load(&path).unwrap();
    let camera = scene.camera;
    scene.frame_camera();
    assert_eq!(camera, scene.camera);
}

/// The comparison scene: a textured floor, a red wall placed through a parent node, a
/// half-transparent blue pane (BLEND), a point and a spot light and a camera.
struct Comparison {
    gltf: Value,
    builder: Builder,
    json: Value,
}

fn comparison(dir: &Path) -> Comparison {
    let png = checker_png();
    write(dir, "checker.png", &png);
    let mut b = Builder::default();
    let floor_prim = primitive(&mut b, &floor(), Some(0));
    let wall_prim = primitive(&mut b, &pane(2.0, 1.5), Some(1));
    let glass_prim = primitive(&mut b, &pane(1.0, 1.0), Some(2));
    let image_view = b.view(&png);
    let wall_turn = DQuat::from_rotation_y(30f64.to_radians());
    let spot_turn = DQuat::from_rotation_x(-std::f64::consts::FRAC_PI_2);
    let cam_turn = DQuat::from_rotation_x(-20f64.to_radians());
    let gltf = json!({
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            // 8 and 12 in the JSON scene: candela × 2⁻¹¹ (docs/gltf.md).
            {"type": "point", "color": [1, 0.9, 0.8], "intensity": 8 * 2048, "range": 6},
            {"type": "spot", "intensity": 12 * 2048, "range": 8,
             "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.6}}
        ]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 3, 4, 5, 6]}],
        "nodes": [
            {"mesh": 0},
            {"translation": [0, 0.5, 0], "children": [2]},
            {"mesh": 1, "translation": [0.5, 0, -1], "rotation": quat(wall_turn), "scale": [0.8, 0.8, 0.8]},
            {"mesh": 2, "translation": [0, 0.6, 2.2]},
            {"translation": [-1, 1.2, 0.5], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"translation": [1.2, 2.5, 0.5], "rotation": quat(spot_turn),
             "extensions": {"KHR_lights_punctual": {"light": 1}}},
            {"camera": 0, "translation": [0, 2, 5], "rotation": quat(cam_turn)}
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.05, "zfar": 50}}],
        "meshes": [{"primitives": [floor_prim]}, {"primitives": [wall_prim]}, {"primitives": [glass_prim]}],
        "materials": [
            {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}},
            {"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.1, 0.1, 1]}},
            {"alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.2, 0.9, 0.5]}}
        ],
        "textures": [{"source": 0}],
        "images": [{"bufferView": image_view, "mimeType": "image/png"}],
    });
    // The same as OBJ files and a JSON scene.
    write(dir, "floor.obj", quad_obj(&floor(), "floor"));
    write(dir, "wall.obj", quad_obj(&pane(2.0, 1.5), "wall"));
    write(dir, "glass.obj", quad_obj(&pane(1.0, 1.0), "glass"));
    write(
        dir,
        "floor.mtl",
        "newmtl floor\nKd 1 1 1\nKs 0.04 0.04 0.04\nNs 0\nmap_Kd checker.png\n",
    );
    write(
        dir,
        "wall.mtl",
        "newmtl wall\nKd 0.8 0.1 0.1\nKs 0.04 0.04 0.04\nNs 0\n",
    );
    write(
        dir,
        "glass.mtl",
        "newmtl glass\nKd 0.1 0.2 0.9\nKs 0.04 0.04 0.04\nNs 0\nd 0.5\n",
    );
    let spot_dir = spot_turn * DVec3::NEG_Z;
    let cam_pos = DVec3::new(0.0, 2.0, 5.0);
    let json = json!({
        "camera": {"position": cam_pos.to_array(), "target": (cam_pos + cam_turn * DVec3::NEG_Z).to_array(),
                   "up": (cam_turn * DVec3::Y).to_array(), "fov_y_deg": (0.9f32 as f64).to_degrees(),
                   "near": 0.05f32 as f64, "far": 50.0},
        "objects": [
            {"obj": "floor.obj"},
            {"obj": "wall.obj", "transform": {"translate": [0.5, 0.5, -1], "rotate_y_deg": 30, "scale": 0.8}},
            {"obj": "glass.obj", "transform": {"translate": [0, 0.6, 2.2]}}
        ],
        "lights": [
            {"kind": "point", "position": [-1, 1.2, 0.5], "radius": 6, "color": [1, 0.9, 0.8], "intensity": 8},
            {"kind": "spot", "position": [1.2, 2.5, 0.5], "radius": 8, "color": [1, 1, 1], "intensity": 12,
             "direction": spot_dir.to_array(), "inner_deg": (0.3f32 as f64).to_degrees(),
             "outer_deg": (0.6f32 as f64).to_degrees()}
        ]
    });
    Comparison {
        gltf,
        builder: b,
        json,
    }
}

#[test]
fn a_gltf_scene_renders_as_the_same_scene_written_as_json_and_obj() {
    let dir = tempfile::tempdir().unwrap();
    let c = comparison(dir.path());
    let glb_path = write(dir.path(), "scene.glb", c.builder.glb(c.gltf.clone()));
    let json_path = write(dir.path(), "scene.json", c.json.to_string());
    let (from_gltf, report) = load(&glb_path).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    let (from_json, _) = scene::load(json_path.to_str().unwrap(), None).unwrap();
    let glass = from_gltf
        .objects
        .iter()
        .map(|o| &from_gltf.materials[o.material])
        .find(|m| m.is_transparent())
        .expect("the BLEND material is transparent");
    assert_eq!(glass.alpha, 0.5);
    // glTF materials are metallic-roughness (the factors' defaults: metallic 1, roughness 1);
    // OBJ's are Blinn-Phong. The comparison is of geometry, textures, lights and camera, so
    // the glTF materials are shaded with the Blinn-Phong parameters the loader also fills.
    let mut from_gltf = from_gltf;
    for m in &mut from_gltf.materials {
        assert_eq!(
            m.model,
            manylight::scene::MaterialModel::MetallicRoughness,
            "{}",
            m.name
        );
        assert_eq!((m.metallic, m.roughness), (1.0, 1.0), "{}", m.name);
        m.model = manylight::scene::MaterialModel::BlinnPhong;
    }
    let mut gpu = Gpu::new(EsVersion::Es3);
    for method in ["forward", "clustered"] {
        gpu.r().set_method_named(method).unwrap();
        let a = gpu.render(&from_gltf, 160, 96, &RenderOptions::default());
        let b = gpu.render(&from_json, 160, 96, &RenderOptions::default());
        let d = manylight::metrics::diff(&a, &b);
        assert!(
            d.max_abs <= 2,
            "{method}: glTF and JSON/OBJ differ by {d:?}"
        );
        // Not a black frame: the comparison means something.
        let lit = a.pixels().filter(|p| p[0].max(p[1]).max(p[2]) > 40).count();
        assert!(lit > 160 * 96 / 6, "{method}: only {lit} lit pixels");
    }
}

#[test]
fn a_blend_material_is_drawn_through_the_transparent_path() {
    let dir = tempfile::tempdir().unwrap();
    let c = comparison(dir.path());
    let path = write(dir.path(), "scene.gltf", c.builder.gltf(c.gltf.clone()));
    let (scene, _) = load(&path).unwrap();
    let glass = scene
        .objects
        .iter()
        .position(|o| scene.materials[o.material].is_transparent())
        .unwrap();
    // Where the pane's centre lands on screen.
    let (w, h) = (160u32, 96u32);
    let centre = scene.objects[glass]
        .transform
        .transform_point3(DVec3::new(0.0, 0.5, 0.0));
    let clip = scene.camera.projection_matrix(w as f64 / h as f64)
        * scene.camera.view_matrix()
        * centre.extend(1.0);
    let (x, y) = (clip.x / clip.w, clip.y / clip.w);
    let (px, py) = (
        ((x + 1.0) / 2.0 * w as f64) as u32,
        ((1.0 - y) / 2.0 * h as f64) as u32,
    );
    let mut gpu = Gpu::new(EsVersion::Es3);
    let opts = RenderOptions::default();
    let blended = *gpu.render(&scene, w, h, &opts).get_pixel(px, py);
    let mut opaque = scene.clone();
    let m = opaque.objects[glass].material;
    opaque.materials[m].alpha = 1.0;
    let solid = *gpu.render(&opaque, w, h, &opts).get_pixel(px, py);
    let mut without = scene.clone();
    without.objects.remove(glass);
    let behind = *gpu.render(&without, w, h, &opts).get_pixel(px, py);
    assert_ne!(blended, solid, "alpha 0.5 is not drawn opaque");
    assert_ne!(blended, behind, "the pane is drawn");
    // Blue pane over what is behind: bluer than behind, less blue than the solid pane.
    for c in 0..3 {
        let (lo, hi) = (solid[c].min(behind[c]), solid[c].max(behind[c]));
        assert!(
            blended[c] + 2 >= lo && blended[c] <= hi + 2,
            "channel {c}: {blended:?} not between {solid:?} and {behind:?}"
        );
    }
}

#[test]
fn a_mask_material_below_its_cutoff_is_invisible_and_above_is_opaque() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let prim = primitive(&mut b, &floor(), Some(0));
    let prim2 = primitive(&mut b, &floor(), Some(1));
    let doc = json!({
        "scenes": [{"nodes": [0, 1]}], "nodes": [{"mesh": 0}, {"mesh": 1}],
        "meshes": [{"primitives": [prim]}, {"primitives": [prim2]}],
        "materials": [
            {"alphaMode": "MASK", "alphaCutoff": 0.6, "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.5]}},
            {"alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.5]}}
        ],
    });
    let path = write(dir.path(), "mask.gltf", b.gltf(doc));
    let (scene, _) = load(&path).unwrap();
    let alphas: Vec<f32> = scene
        .objects
        .iter()
        .map(|o| scene.materials[o.material].alpha)
        .collect();
    assert_eq!(alphas, [0.0, 1.0]);
}

/// A minimal valid triangle, for the malformed variants below.
fn triangle(b: &mut Builder) -> Value {
    let p = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3");
    let i = b.u16s(&[0, 1, 2]);
    json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": p}, "indices": i}]}]})
}

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
fn a_missing_texture_is_a_warning_and_the_flat_colour() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let prim = primitive(&mut b, &floor(), Some(0));
    let doc = json!({
        "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [prim]}],
        "materials": [{"name": "m", "pbrMetallicRoughness":
            {"baseColorFactor": [0.2, 0.4, 0.6, 1], "baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}, {"source": 1}],
        "images": [{"uri": "absent.png"}, {"uri": "data:image/png;base64,AAAA"}],
    });
    let path = write(dir.path(), "notex.gltf", b.gltf(doc.clone()));
    let (scene, report) = load(&path).unwrap();
    let m = &scene.materials[scene.objects[0].material];
    assert!(m.diffuse_texture.is_none());
    assert_eq!(m.diffuse, Vec3::new(0.2, 0.4, 0.6));
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("absent.png") && w.contains("flat colour")),
        "{:?}",
        report.warnings
    );
    // An image that does not decode: the same.
    let mut doc = doc;
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["index"] = json!(1);
    let path = write(dir.path(), "badtex.gltf", b.gltf(doc));
    let (_, report) = load(&path).unwrap();
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("could not be decoded")),
        "{:?}",
        report.warnings
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
            let component = [0, 5121, UNSIGNED_SHORT, 0, UNSIGNED_INT][width];
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
    // And a sparse accessor with no buffer view at all: zeros, then the substitution.
    b.accessors
        .push(json!({"componentType": FLOAT, "type": "VEC3", "count": 3,
        "sparse": {"count": 1,
            "indices": {"bufferView": indices, "componentType": UNSIGNED_SHORT},
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

fn load_with(
    path: &Path,
    allow: bool,
) -> Result<(Scene, manylight::scene::obj::LoadReport), scene::SceneError> {
    let mut options = manylight::LoadOptions::default();
    options.allow_outside_files = allow;
    without_no_lights_hint(scene::load_with(
        path.to_str().unwrap(),
        Some((0, 1)),
        &options,
    ))
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
    // A flat (singular) matrix is a flat object, not an error.
    let mut doc = base.clone();
    doc["nodes"][0]["matrix"] = json!([1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);
    let path = write(dir.path(), "flat.gltf", b.gltf(doc));
    assert_eq!(load(&path).unwrap().0.objects.len(), 1);
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
}

#[test]
fn a_file_lit_only_by_a_sun_is_lit_as_the_model_says() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let floor_prim = primitive(&mut b, &floor(), Some(0));
    // The sun's node aimed down and forward: −Z turned 50° about +X.
    let sun_turn = DQuat::from_rotation_x(-50f64.to_radians());
    let cam_turn = DQuat::from_rotation_x(-20f64.to_radians());
    let gltf = json!({
        "extensionsUsed": ["KHR_lights_punctual"],
        // 2 048 lux: intensity 1 on the photometric scale (docs/gltf.md).
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "directional", "color": [1, 0.9, 0.8], "intensity": 2048}
        ]}},
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [
            {"mesh": 0},
            {"translation": [0, 5, 0], "rotation": quat(sun_turn),
             "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"camera": 0, "translation": [0, 2, 5], "rotation": quat(cam_turn)}
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.05, "zfar": 50}}],
        "meshes": [{"primitives": [floor_prim]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1]}}],
    });
    let path = write(dir.path(), "sunny.gltf", b.gltf(gltf));
    let (scene, report) = load(&path).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    assert!(scene.lights.is_empty());
    let sun = scene.directional_lights[0];
    assert!((sun.direction - sun_turn * DVec3::NEG_Z).length() < 1e-9);
    assert_eq!(sun.intensity, 1.0);
    let mut gpu = Gpu::new(EsVersion::Es3);
    let img = gpu.render(&scene, 96, 54, &RenderOptions::default());
    let caps = gpu.r().caps().clone();
    let encoding = manylight::metrics::cpu_reference::Encoding::Srgb;
    let (err, at, n) = common::max_oracle_error(&img, &scene, encoding, &caps);
    assert!(
        n > 96 * 54 / 8 && err <= 2.0,
        "{err:.2}/255 at {at:?} over {n}"
    );
    // Neither black nor white: the floor at 0.8 × cos 40° of the sun (sRGB 207).
    let lit: Vec<u8> = img
        .pixels()
        .map(|p| p[0].max(p[1]).max(p[2]))
        .filter(|&v| v > 40)
        .collect();
    assert!(lit.len() > 96 * 54 / 8, "only {} lit pixels", lit.len());
    let peak = lit.iter().max().copied().unwrap_or(0);
    assert!((150..=240).contains(&peak), "brightest {peak}/255");
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

#[test]
fn a_spot_cone_wider_than_the_spec_allows_is_drawn_as_given_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let mut doc = triangle(&mut b);
    doc["nodes"] = json!([
        {"mesh": 0},
        {"translation": [0, 0, 1], "extensions": {"KHR_lights_punctual": {"light": 0}}}
    ]);
    doc["scenes"] = json!([{"nodes": [0, 1]}]);
    doc["extensionsUsed"] = json!(["KHR_lights_punctual"]);
    doc["extensions"] = json!({"KHR_lights_punctual": {"lights": [
        {"type": "spot", "intensity": 100, "spot": {"outerConeAngle": 2.0}}]}});
    let path = write(dir.path(), "wide.gltf", b.gltf(doc));
    let (scene, report) = load(&path).unwrap();
    assert_eq!(scene.lights.len(), 1, "drawn");
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("lights[0]") && w.contains("spot.outerConeAngle (2) is past π/2")),
        "{:?}",
        report.warnings
    );
}
