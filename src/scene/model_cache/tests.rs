//! The model cache: limits, shared meshes and textures, and glTF files placed again.

use super::*;

#[test]
fn counts_past_the_budget_are_errors_naming_the_object() {
    assert!(check_counts(MAX_SCENE_OBJECTS, MAX_SCENE_MATERIALS, "objects[3]").is_ok());
    let err = check_counts(MAX_SCENE_OBJECTS + 1, 1, "objects[3]").unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("objects[3]") && text.contains("1048577 objects"),
        "{text}"
    );
    let err = check_counts(1, MAX_SCENE_MATERIALS + 1, "objects[9]").unwrap_err();
    assert!(err.to_string().contains("materials"), "{err}");
}

/// Distinct meshes are counted across the checks (each check sees only the objects placed
/// since the last), shared ones once; one past the limit is an error naming the object.
#[test]
fn distinct_meshes_past_the_budget_are_an_error_naming_the_object() {
    let triangle = || {
        let p = vec![glam::Vec3::ZERO, glam::Vec3::X, glam::Vec3::Y];
        Arc::new(Mesh::new(p, vec![], vec![], vec![0, 1, 2]).unwrap())
    };
    let mut scene = Scene::empty();
    let material = scene.add_material(Material::default());
    let place = |scene: &mut Scene, mesh: Arc<Mesh>| {
        scene.objects.push(Object {
            mesh,
            material,
            transform: DMat4::IDENTITY,
        })
    };
    let mut count = MeshCount::default();
    let shared = triangle();
    for _ in 0..3 {
        place(&mut scene, shared.clone());
    }
    check_budget(&scene, &mut count, "objects[0]").unwrap();
    for _ in 1..MAX_SCENE_MESHES {
        place(&mut scene, triangle());
    }
    check_budget(&scene, &mut count, "objects[1]").unwrap();
    place(&mut scene, shared.clone());
    check_budget(&scene, &mut count, "objects[2]").unwrap();
    place(&mut scene, triangle());
    let err = check_budget(&scene, &mut count, "objects[3]").unwrap_err();
    let text = err.to_string();
    let over = format!("{} distinct meshes", MAX_SCENE_MESHES + 1);
    assert!(
        text.contains("objects[3]") && text.contains(&over),
        "{text}"
    );
}

/// A glTF `name` with a light and one texture, in a data URI.
fn lit_textured_gltf(dir: &Path, name: &str) -> PathBuf {
    use base64::Engine;
    let b64 = |b: &[u8]| base64::engine::general_purpose::STANDARD.encode(b);
    let mut png = Vec::new();
    image::RgbaImage::from_pixel(4, 4, image::Rgba([200, 100, 50, 255]))
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let floats = [
        -1.0f32, -1.0, 0.0, 1.0, -1.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0,
    ];
    let bin: Vec<u8> = floats.iter().flat_map(|x| x.to_le_bytes()).collect();
    let doc = serde_json::json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "intensity": 2, "range": 3}]}},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "extensions": {"KHR_lights_punctual": {"light": 0}}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1},
                                     "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}],
        "images": [{"uri": format!("data:image/png;base64,{}", b64(&png))}],
        "buffers": [{"byteLength": bin.len(),
                     "uri": format!("data:application/octet-stream;base64,{}", b64(&bin))}],
        "bufferViews": [{"buffer": 0, "byteLength": 36},
                        {"buffer": 0, "byteOffset": 36, "byteLength": 24}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 3,
             "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "type": "VEC2", "count": 3}
        ]
    });
    let path = dir.join(name);
    std::fs::write(&path, doc.to_string()).unwrap();
    path
}

/// One image file read through two samplers (two materials) by two glTF files, the first
/// placed three times: each texture keeps its sampling, all share one copy of the pixels,
/// and the second file's copy, dropped, is given back to the budget once (not once a
/// sampling).
#[test]
fn textures_of_one_image_keep_their_samplings_and_one_copy_of_its_pixels() {
    use crate::scene::texture::{Filter, Wrap};
    let dir = tempfile::tempdir().unwrap();
    image::RgbaImage::from_pixel(4, 4, image::Rgba([200, 100, 50, 255]))
        .save(dir.path().join("tex.png"))
        .unwrap();
    let two_samplers = |name: &str| {
        let path = lit_textured_gltf(dir.path(), name);
        let mut doc: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let primitive = doc["meshes"][0]["primitives"][0].clone();
        let mut second = primitive.clone();
        second["material"] = serde_json::json!(1);
        doc["meshes"][0]["primitives"] = serde_json::json!([primitive, second]);
        doc["materials"] = serde_json::json!([
            {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}},
            {"pbrMetallicRoughness": {"baseColorTexture": {"index": 1}}}
        ]);
        doc["samplers"] = serde_json::json!([{"wrapS": 33071, "magFilter": 9728}]);
        doc["textures"] = serde_json::json!([{"source": 0}, {"source": 0, "sampler": 0}]);
        doc["images"] = serde_json::json!([{"uri": "tex.png"}]);
        std::fs::write(&path, doc.to_string()).unwrap();
        path
    };
    let (first, second) = (two_samplers("a.gltf"), two_samplers("b.gltf"));
    let mut cache = ModelCache::new(LoadOptions::default());
    // Room for two copies of the 4 × 4 image while the second file decodes its own.
    cache.texture_budget = TextureBudget::with_left(2 * 64 + 63);
    let mut scene = Scene::empty();
    for (x, path) in [&first, &first, &first, &second].into_iter().enumerate() {
        let transform = DMat4::from_translation(glam::DVec3::new(x as f64, 0.0, 0.0));
        let loaded = cache
            .place_gltf(&mut scene, path, transform, false, "objects[0].transform")
            .unwrap();
        assert!(loaded.0.warnings.is_empty(), "{:?}", loaded.0);
    }
    assert_eq!(cache.texture_budget.left(), 64 + 63);
    let clamped = Sampling {
        wrap_u: Wrap::ClampToEdge,
        magnify: Filter::Nearest,
        ..Sampling::default()
    };
    let textures: Vec<&Arc<Texture>> = scene
        .materials
        .iter()
        .map(|m| m.diffuse_texture.as_ref().expect("kept"))
        .collect();
    // The first file's three references share its two materials.
    assert_eq!(textures.len(), 4);
    for (i, t) in textures.iter().enumerate() {
        let want = if i % 2 == 0 {
            Sampling::default()
        } else {
            clamped
        };
        assert_eq!(t.sampling, want, "material {i}");
        assert!(Arc::ptr_eq(&t.image, &textures[0].image), "material {i}");
    }
}

/// A file is read at its first reference only: a later one places its objects, its
/// lights (a point light and a sun) and its camera as reading the file at that
/// reference's transform would.
#[test]
fn a_file_is_read_at_its_first_reference_only_and_placed_as_reading_it_there_would() {
    let dir = tempfile::tempdir().unwrap();
    let lit = lit_textured_gltf(dir.path(), "lit.gltf");
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&lit).unwrap()).unwrap();
    let unlit = dir.path().join("unlit.gltf");
    let mut unlit_doc = doc.clone();
    unlit_doc["nodes"][0] = serde_json::json!({"mesh": 0});
    std::fs::write(&unlit, unlit_doc.to_string()).unwrap();
    doc["extensions"]["KHR_lights_punctual"]["lights"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({"type": "directional", "intensity": 3}));
    doc["cameras"] = serde_json::json!([{"type": "perspective",
        "perspective": {"yfov": 0.8, "znear": 0.1, "zfar": 50}}]);
    doc["nodes"] = serde_json::json!([
        {"mesh": 0, "extensions": {"KHR_lights_punctual": {"light": 0}},
         "translation": [0.5, 0, 2]},
        {"camera": 0, "translation": [0, 1, 6]},
        {"rotation": [0.3826834, 0, 0, 0.9238795],
         "extensions": {"KHR_lights_punctual": {"light": 1}}}
    ]);
    doc["scenes"] = serde_json::json!([{"nodes": [0, 1, 2]}]);
    std::fs::write(&lit, doc.to_string()).unwrap();
    let size = |path: &Path| std::fs::metadata(path).unwrap().len();
    let at = |x: f64| {
        DMat4::from_translation(glam::DVec3::new(x, 1.0, 0.0))
            * DMat4::from_rotation_z(x)
            * DMat4::from_scale(glam::DVec3::splat(x))
    };
    let mut cache = ModelCache::new(LoadOptions::default());
    let mut scene = Scene::empty();
    let mut cameras = Vec::new();
    let mut reads = |path: &Path, x: f64| {
        let before = crate::scene::input::bytes_read();
        let field = "objects[0].transform";
        let (report, camera) = cache
            .place_gltf(&mut scene, path, at(x), false, field)
            .unwrap();
        cameras.push(camera);
        if x == 3.0 {
            assert!(report.warnings.is_empty(), "{:?}", report.warnings);
        }
        crate::scene::input::bytes_read() - before
    };
    assert_eq!([reads(&lit, 2.0), reads(&lit, 3.0)], [size(&lit), 0]);
    assert_eq!([reads(&unlit, 2.0), reads(&unlit, 3.0)], [size(&unlit), 0]);
    let read_there = |path: &Path| {
        let mut read_there = Scene::empty();
        let mut budget = TextureBudget::default();
        let options = LoadOptions::default();
        let loaded = crate::scene::gltf::load_into(
            &mut read_there,
            path,
            at(3.0),
            "transform",
            &options,
            &mut budget,
        )
        .unwrap();
        (read_there, loaded.camera)
    };
    let (lit_there, camera_there) = read_there(&lit);
    assert_eq!(scene.lights.len(), 2);
    assert_eq!(scene.lights[1], lit_there.lights[0]);
    assert_ne!(scene.lights[0], scene.lights[1]);
    assert_eq!(scene.directional_lights.len(), 2);
    assert_eq!(scene.directional_lights[1], lit_there.directional_lights[0]);
    assert_eq!(scene.objects[1].transform, lit_there.objects[0].transform);
    assert!(camera_there.is_some());
    assert_eq!(cameras[1], camera_there);
    assert_ne!(cameras[0], cameras[1]);
    assert_eq!(cameras[2..], [None, None]);
    let (unlit_there, _) = read_there(&unlit);
    let placed = scene.objects.last().unwrap();
    assert_eq!(placed.transform, unlit_there.objects[0].transform);
    assert_ne!(placed.transform, scene.objects[2].transform);
}

/// A later reference whose transform the file's contents refuse fails as reading the file
/// there fails, naming its own transform, and leaves the scene as it was; a file of lights
/// alone whose lights such a transform leaves out has nothing to show there either.
#[test]
fn a_later_reference_is_refused_as_reading_the_file_there_is() {
    let dir = tempfile::tempdir().unwrap();
    let lit = lit_textured_gltf(dir.path(), "lit.gltf");
    let mut cache = ModelCache::new(LoadOptions::default());
    let mut scene = Scene::empty();
    let field = "objects[1].transform";
    let far = DMat4::from_translation(glam::DVec3::new(1e13, 0.0, 0.0));
    cache
        .place_gltf(
            &mut scene,
            &lit,
            DMat4::IDENTITY,
            false,
            "objects[0].transform",
        )
        .unwrap();
    let counts = |s: &Scene| (s.objects.len(), s.materials.len(), s.lights.len());
    let before = counts(&scene);
    let err = cache
        .place_gltf(&mut scene, &lit, far, false, field)
        .unwrap_err()
        .to_string();
    assert_eq!(counts(&scene), before);
    let read_there = |path: &Path, transform: DMat4| {
        let mut budget = TextureBudget::default();
        let options = LoadOptions::default();
        let mut scene = Scene::empty();
        crate::scene::gltf::load_into(&mut scene, path, transform, field, &options, &mut budget)
            .unwrap_err()
            .to_string()
    };
    // The read names the node and primitive too.
    for said in [&err, &read_there(&lit, far)] {
        assert!(
            said.contains(field) && said.contains("past ±1e12"),
            "{said}"
        );
    }
    // A sun alone, left out by a transform that flattens its direction to nothing.
    let lamp = dir.path().join("lamp.gltf");
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&lit).unwrap()).unwrap();
    doc["extensions"]["KHR_lights_punctual"]["lights"] =
        serde_json::json!([{"type": "directional", "intensity": 3}]);
    doc["nodes"][0] = serde_json::json!({"extensions": {"KHR_lights_punctual": {"light": 0}}});
    std::fs::write(&lamp, doc.to_string()).unwrap();
    cache
        .place_gltf(
            &mut scene,
            &lamp,
            DMat4::IDENTITY,
            false,
            "objects[2].transform",
        )
        .unwrap();
    let before = counts(&scene);
    let flat = DMat4::from_scale(glam::DVec3::ZERO);
    let err = cache
        .place_gltf(&mut scene, &lamp, flat, false, field)
        .unwrap_err()
        .to_string();
    assert_eq!(counts(&scene), before);
    let there = read_there(&lamp, flat);
    for said in [&err, &there] {
        assert!(said.contains("nothing to show"), "{said}");
    }
}

/// A glTF file's suns count against the scene's lights before a reference places them:
/// nothing else bounds what many references to a file of many suns make.
#[test]
fn suns_count_against_the_scenes_lights() {
    let dir = tempfile::tempdir().unwrap();
    let lit = lit_textured_gltf(dir.path(), "sun.gltf");
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&lit).unwrap()).unwrap();
    doc["extensions"]["KHR_lights_punctual"]["lights"] =
        serde_json::json!([{"type": "directional", "intensity": 3}]);
    std::fs::write(&lit, doc.to_string()).unwrap();
    let mut cache = ModelCache::new(LoadOptions::default());
    let mut scene = Scene::empty();
    let mut place = |scene: &mut Scene, i: usize| {
        let field = format!("objects[{i}].transform");
        cache.place_gltf(scene, &lit, DMat4::IDENTITY, false, &field)
    };
    place(&mut scene, 0).unwrap();
    let sun = scene.directional_lights[0];
    scene.directional_lights = vec![sun; crate::scene::input::MAX_LIGHTS - 1];
    place(&mut scene, 1).unwrap();
    let before = scene.objects.len();
    let err = place(&mut scene, 2).unwrap_err().to_string();
    assert!(err.contains("more than the"), "{err}");
    assert_eq!(scene.objects.len(), before);
    assert_eq!(
        scene.directional_lights.len(),
        crate::scene::input::MAX_LIGHTS
    );
}

/// A file placed again holds its textures once, within room for one copy.
#[test]
fn a_file_placed_again_keeps_its_textures_with_room_for_one_copy() {
    let dir = tempfile::tempdir().unwrap();
    let path = lit_textured_gltf(dir.path(), "lit.gltf");
    let mut cache = ModelCache::new(LoadOptions::default());
    // Room for the 4 × 4 texture once, not twice.
    cache.texture_budget = TextureBudget::with_left(64 + 63);
    let mut scene = Scene::empty();
    for x in 0..3 {
        let transform = DMat4::from_translation(glam::DVec3::new(x as f64, 0.0, 0.0));
        let loaded = cache
            .place_gltf(&mut scene, &path, transform, false, "objects[0].transform")
            .unwrap();
        assert!(loaded.0.warnings.is_empty(), "{:?}", loaded.0);
    }
    assert_eq!(scene.lights.len(), 3, "one light a reference");
    let textures: std::collections::HashSet<_> = scene
        .materials
        .iter()
        .map(|m| m.diffuse_texture.as_ref().map(Arc::as_ptr))
        .collect();
    assert_eq!(textures.len(), 1, "one texture, held once: {textures:?}");
    assert!(!textures.contains(&None));
    assert_eq!(cache.texture_budget.left(), 63);
    // Another such file's texture does not fit: left out (said once) on every reference.
    let other = lit_textured_gltf(dir.path(), "other.gltf");
    for reference in 0..2 {
        let field = "objects[3].transform";
        let loaded = cache
            .place_gltf(&mut scene, &other, DMat4::IDENTITY, false, field)
            .unwrap();
        let material = scene.objects.last().unwrap().material;
        assert!(scene.materials[material].diffuse_texture.is_none());
        let warnings = &loaded.0.warnings;
        let said = warnings.iter().any(|w| w.contains("left out"));
        assert_eq!(said, reference == 0, "{warnings:?}");
    }
    assert_eq!(cache.texture_budget.left(), 63);
}
