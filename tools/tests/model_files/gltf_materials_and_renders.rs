//! glTF materials and textures, on files the tests write: a textured mesh from a `.gltf` with a
//! side image, from a GLB and with a data URI; MASK and BLEND materials; a missing or
//! undecodable texture; and a whole scene (a textured floor, a wall placed through a parent
//! node, a BLEND pane, point and spot lights, a camera) rendered against the same scene written
//! as JSON + OBJ.

use crate::common;

use std::path::Path;

use common::files::{load, write};
use common::gltf::{base64, Builder};
use common::gltf_models::{checker_png, floor, pane, primitive, quad_obj, quat};
use common::Gpu;
use glam::{DQuat, DVec3, Vec3};
use manylight::scene;
use manylight::{EsVersion, RenderOptions};
use serde_json::{json, Value};

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
