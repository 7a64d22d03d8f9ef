//! Memory bounds of repeated and oversized input: a scene file naming one model many times
//! holds and uploads it once, duplicate triangles are dropped without changing the picture,
//! and oversized textures are kept scaled down, each with the warning the loader promises.

mod common;

use std::collections::HashSet;
use std::path::Path;
use std::sync::Arc;

use common::Gpu;
use manylight::scene::{self, Scene};
use manylight::{EsVersion, RenderOptions};

fn distinct_meshes(scene: &Scene) -> usize {
    let set: HashSet<*const manylight::Mesh> =
        scene.objects.iter().map(|o| Arc::as_ptr(&o.mesh)).collect();
    set.len()
}

/// Two objects (a red quad, a green triangle behind it) and their MTL.
fn write_model(dir: &Path) {
    std::fs::write(
        dir.join("m.obj"),
        "mtllib m.mtl\no quad\nusemtl red\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n\
         f 1 2 3\nf 1 3 4\no tri\nusemtl green\nv -1 -1 -1\nv 1 -1 -1\nv 0 1 -1\nf 5 6 7\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("m.mtl"),
        "newmtl red\nKd 0.9 0.1 0.1\nnewmtl green\nKd 0.1 0.9 0.1\n",
    )
    .unwrap();
}

/// A scene file placing `m.obj` `n` times in a row along x (every tenth reference recoloured,
/// every third spelled another way), with a camera and a light seeing the first few.
fn scene_file(dir: &Path, n: usize) -> std::path::PathBuf {
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    let objects: Vec<serde_json::Value> = (0..n)
        .map(|i| {
            let path = ["m.obj", "./m.obj", "sub/../m.obj"][i % 3];
            let mut o = serde_json::json!({"obj": path,
                "transform": {"translate": [i as f64 * 2.5, 0, 0]}});
            if i % 10 == 9 {
                o["color"] = serde_json::json!([0.2, 0.2, 0.9]);
            }
            o
        })
        .collect();
    let text = serde_json::json!({
        "camera": {"position": [2.5, 0, 9], "target": [2.5, 0, 0]},
        "objects": objects,
        "lights": [{"kind": "point", "position": [2.5, 0, 4], "radius": 30, "color": [1, 1, 1],
                    "intensity": 3}]
    });
    let file = dir.join(format!("s{n}.json"));
    std::fs::write(&file, text.to_string()).unwrap();
    file
}

#[test]
fn a_scene_file_naming_one_obj_1000_times_holds_and_uploads_it_once() {
    let dir = tempfile::tempdir().unwrap();
    write_model(dir.path());
    let load = |n| scene::load(scene_file(dir.path(), n).to_str().unwrap(), None).unwrap();
    let (one, _) = load(1);
    let (many, report) = load(1000);
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    assert_eq!(many.objects.len(), 2000);
    assert_eq!(distinct_meshes(&many), 2, "one mesh per object of the OBJ");
    // Uncoloured references share the file's materials; each recoloured one has its own.
    assert_eq!(many.materials.len(), 3 + 100 * 3);

    // On the GPU: the same buffers for 1 000 placements as for one.
    let options = RenderOptions::default();
    let buffers = |scene: &Scene| {
        let mut gpu = Gpu::new(EsVersion::Es3);
        gpu.r().set_method_named("forward").unwrap();
        let image = gpu.render(scene, 64, 36, &options);
        (gpu.r().live_gl_objects().buffers, image)
    };
    let (one_buffers, _) = buffers(&one);
    let (many_buffers, image) = buffers(&many);
    assert_eq!(many_buffers, one_buffers);
    // The shared placements still draw: the first (red) quad fills the middle of the view.
    let centre = image.get_pixel(32, 18);
    assert!(centre[0] > 2 * centre[1].max(8), "{centre:?}");
}

#[test]
fn a_gltf_named_many_times_shares_its_meshes_and_textures() {
    let dir = tempfile::tempdir().unwrap();
    // A textured quad (glTF with an embedded PNG in a data URI).
    let mut png = Vec::new();
    image::RgbaImage::from_pixel(4, 4, image::Rgba([200, 100, 50, 255]))
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let f = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let mut bin = f(&[-1.0, -1.0, 0.0, 1.0, -1.0, 0.0, 1.0, 1.0, 0.0]);
    bin.extend(f(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0]));
    use base64::Engine;
    let b64 = |b: &[u8]| base64::engine::general_purpose::STANDARD.encode(b);
    let doc = serde_json::json!({
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1},
                                     "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}],
        "images": [{"uri": format!("data:image/png;base64,{}", b64(&png))}],
        "buffers": [{"byteLength": bin.len(),
                     "uri": format!("data:application/octet-stream;base64,{}", b64(&bin))}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36,
                                                          "byteLength": 24}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "type": "VEC3", "count": 3,
             "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "type": "VEC2", "count": 3}
        ]
    });
    std::fs::write(dir.path().join("q.gltf"), doc.to_string()).unwrap();
    let objects: Vec<serde_json::Value> = (0..200)
        .map(|i| serde_json::json!({"gltf": "q.gltf", "transform": {"translate": [i, 0, 0]}}))
        .collect();
    let file = dir.path().join("s.json");
    std::fs::write(&file, serde_json::json!({"objects": objects}).to_string()).unwrap();
    let (scene, _) = scene::load(file.to_str().unwrap(), None).unwrap();
    assert_eq!((scene.objects.len(), distinct_meshes(&scene)), (200, 1));
    let textures: HashSet<*const manylight::Texture> = scene
        .materials
        .iter()
        .filter_map(|m| m.diffuse_texture.as_ref().map(Arc::as_ptr))
        .collect();
    assert_eq!(textures.len(), 1);
    assert_eq!(
        scene.materials.len(),
        1,
        "uncoloured references share the material"
    );
    // A placement past the coordinate limit is refused, naming the scene file's transform, on
    // the first reference and on a later one.
    for far in [
        [[0.0, 0.0, 0.0], [1e13, 0.0, 0.0]],
        [[1e13, 0.0, 0.0], [0.0, 0.0, 0.0]],
    ] {
        let objects: Vec<serde_json::Value> = far
            .iter()
            .map(|t| serde_json::json!({"gltf": "q.gltf", "transform": {"translate": t}}))
            .collect();
        std::fs::write(&file, serde_json::json!({"objects": objects}).to_string()).unwrap();
        let err = scene::load(file.to_str().unwrap(), None)
            .unwrap_err()
            .to_string();
        let far_one = far.iter().position(|t| t[0] != 0.0).unwrap();
        let field = format!("objects[{far_one}].transform");
        assert!(err.contains(&field) && err.contains("past"), "{err}");
    }

    // With a light, the file is read at its first reference only and its light placed by
    // each reference's transform: three lights, one mesh, one read.
    let mut lit = doc.clone();
    lit["extensionsUsed"] = serde_json::json!(["KHR_lights_punctual"]);
    lit["extensions"] = serde_json::json!({"KHR_lights_punctual": {"lights": [
        {"type": "point", "intensity": 2, "range": 3}]}});
    lit["nodes"][0]["extensions"] = serde_json::json!({"KHR_lights_punctual": {"light": 0}});
    let lit_references = |count: usize| {
        let objects: Vec<serde_json::Value> = (0..count)
            .map(|i| serde_json::json!({"gltf": "lit.gltf", "transform": {"translate": [i, 0, 0]}}))
            .collect();
        std::fs::write(&file, serde_json::json!({"objects": objects}).to_string()).unwrap();
        let before = scene::input::bytes_read();
        let (scene, _) = scene::load(file.to_str().unwrap(), None).unwrap();
        let read = scene::input::bytes_read() - before;
        (scene, read)
    };
    std::fs::write(dir.path().join("lit.gltf"), lit.to_string()).unwrap();
    let (scene, read) = lit_references(3);
    assert_eq!((scene.objects.len(), distinct_meshes(&scene)), (3, 1));
    let xs: Vec<f64> = scene.lights.iter().map(|l| l.position.x).collect();
    assert_eq!(xs, [0.0, 1.0, 2.0]);
    let scene_file = std::fs::metadata(&file).unwrap().len();
    let lit_file = std::fs::metadata(dir.path().join("lit.gltf"))
        .unwrap()
        .len();
    assert_eq!(
        read,
        scene_file + lit_file,
        "the scene file and the glTF once"
    );
    // Work no bytes pay for is not done again either: a 1 KB file whose index accessor has no
    // buffer view decodes a million zero indices at each read (0.14 s on the dev VM); a
    // thousand references, each reading it again, took minutes.
    // Its first three indices (0, 1, 2) are sparse values in a buffer of their own.
    let sparse: Vec<u8> = [0u32, 1, 2, 0, 1, 2]
        .iter()
        .flat_map(|i| i.to_le_bytes())
        .collect();
    lit["buffers"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({
        "byteLength": 24,
        "uri": format!("data:application/octet-stream;base64,{}", b64(&sparse))}));
    let views = lit["bufferViews"].as_array_mut().unwrap();
    views.push(serde_json::json!({"buffer": 1, "byteLength": 12}));
    views.push(serde_json::json!({"buffer": 1, "byteOffset": 12, "byteLength": 12}));
    lit["accessors"]
        .as_array_mut()
        .unwrap()
        .push(serde_json::json!({
        "componentType": 5125, "type": "SCALAR", "count": (1 << 20) - 1,
        "sparse": {"count": 3, "indices": {"bufferView": 2, "componentType": 5125},
                   "values": {"bufferView": 3}}}));
    lit["meshes"][0]["primitives"][0]["indices"] = serde_json::json!(2);
    std::fs::write(dir.path().join("lit.gltf"), lit.to_string()).unwrap();
    let (scene, read) = lit_references(1000);
    assert_eq!((scene.objects.len(), scene.lights.len()), (1000, 1000));
    let lit_file = std::fs::metadata(dir.path().join("lit.gltf"))
        .unwrap()
        .len();
    let scene_file = std::fs::metadata(&file).unwrap().len();
    assert_eq!(read, scene_file + lit_file, "the glTF read once");
}

/// An OBJ is read again for each other texture override (each may name a file of its own):
/// such re-reads stop once past 1 GiB, naming the reference.
#[test]
fn obj_rereads_for_other_textures_are_bounded() {
    if common::independent_of_the_implementation("the OBJ re-read bound") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    write_model(dir.path());
    let obj = dir.path().join("m.obj");
    let mut text = std::fs::read_to_string(&obj).unwrap();
    text += &format!("# {}\n", "x".repeat(4 << 20));
    std::fs::write(&obj, text).unwrap();
    let objects: Vec<serde_json::Value> = (0..300)
        .map(|i| serde_json::json!({"obj": "m.obj", "texture": format!("missing{i}.png")}))
        .collect();
    let file = dir.path().join("s.json");
    std::fs::write(&file, serde_json::json!({"objects": objects}).to_string()).unwrap();
    let Err(err) = scene::load(file.to_str().unwrap(), None) else {
        panic!("300 re-reads of a 4 MiB OBJ loaded");
    };
    let err = err.to_string();
    assert!(
        err.contains("read again for each other `texture`")
            && err.contains("passed 1024 MiB before objects[257]"),
        "{err}"
    );
}

/// An OBJ repeating a quad thousands of times (in every rotation and winding) loads as the
/// quad, with one warning giving the count, and renders exactly as the quad written once; a
/// transparent object keeps its copies (each blends once more).
#[test]
fn duplicate_triangles_are_dropped_with_a_count_and_the_picture_kept() {
    let dir = tempfile::tempdir().unwrap();
    // Normals given: computed ones would weigh the copies (and did before they were dropped).
    let header = "mtllib m.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nv -1 -1 0\nv 0 -1 -1\n\
                  vn 0 0 1\nvn 0 -1 0\nusemtl solid\n";
    let faces = "f 1//1 2//1 3//1\nf 1//1 3//1 4//1\nf 1//2 2//2 6//2\n";
    let mut repeated = format!("{header}{faces}");
    for _ in 0..2500 {
        // Rotated, reversed, and through vertex 5 (vertex 1's position again).
        repeated += "f 2//1 3//1 1//1\nf 4//1 3//1 1//1\nf 5//1 3//1 4//1\nf 3//1 1//1 2//1\n";
    }
    let once = format!("{header}{faces}");
    let mtl = "newmtl solid\nKd 0.8 0.6 0.2\nnewmtl glass\nKd 0.2 0.6 0.8\nd 0.5\n";
    std::fs::write(dir.path().join("m.mtl"), mtl).unwrap();
    let load = |name: &str, text: &str| {
        let file = dir.path().join(name);
        std::fs::write(&file, text).unwrap();
        scene::load(file.to_str().unwrap(), Some((8, 3))).unwrap()
    };
    let (deduped, report) = load("repeated.obj", &repeated);
    let (written_once, clean) = load("once.obj", &once);
    assert!(clean.warnings.is_empty(), "{:?}", clean.warnings);
    assert_eq!(deduped.objects[0].mesh.triangle_count(), 3);
    assert_eq!(report.warnings.len(), 1, "{:?}", report.warnings);
    assert!(
        report.warnings[0].contains("10000 duplicate triangles dropped"),
        "{}",
        report.warnings[0]
    );
    let mut gpu = Gpu::new(EsVersion::Es3);
    let options = RenderOptions::default();
    let a = gpu.render(&deduped, 64, 36, &options);
    let b = gpu.render(&written_once, 64, 36, &options);
    assert!(a.pixels().any(|p| p[0] > 20), "the quad is lit");
    assert!(a == b, "the picture changed");

    let glass = repeated.replace("usemtl solid", "usemtl glass");
    let (kept, report) = load("glass.obj", &glass);
    assert_eq!(kept.objects[0].mesh.triangle_count(), 3 + 10_000);
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
}

/// A texture wider than the kept budget is scaled down, aspect kept, with a warning naming it.
#[test]
fn an_oversized_texture_is_kept_scaled_down_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let wide = image::RgbImage::from_pixel(6000, 3, image::Rgb([30, 160, 90]));
    wide.save(dir.path().join("Wide.png")).unwrap();
    std::fs::write(
        dir.path().join("m.mtl"),
        "newmtl t\nKd 1 1 1\nmap_Kd Wide.png\n",
    )
    .unwrap();
    let obj = "mtllib m.mtl\nusemtl t\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n\
               f 1/1 2/2 3/3\n";
    let file = dir.path().join("m.obj");
    std::fs::write(&file, obj).unwrap();
    let (scene, report) = scene::load(file.to_str().unwrap(), Some((4, 1))).unwrap();
    let texture = scene.materials[0].diffuse_texture.as_ref().unwrap();
    let kept = scene::texture_budget::MAX_STORED_TEXTURE_SIDE;
    assert_eq!(texture.image.dimensions(), (kept, 2));
    assert_eq!(texture.image.get_pixel(10, 1).0, [30, 160, 90, 255]);
    assert_eq!(report.warnings.len(), 1, "{:?}", report.warnings);
    let warning = &report.warnings[0];
    assert!(
        warning.contains("Wide.png") && warning.contains("6000×3"),
        "{warning}"
    );
}

/// A mesh placed 100 000 times: the scene's bounds are those of its placements (each distinct
/// mesh's vertices are walked once, not once a placement).
#[test]
fn bounds_of_a_mesh_placed_many_times() {
    use glam::{DMat4, DVec3, Vec3};
    let mesh = Arc::new(
        manylight::Mesh::new(
            vec![
                Vec3::new(-1.0, 0.0, 0.0),
                Vec3::new(1.0, 2.0, 0.5),
                Vec3::ZERO,
            ],
            vec![],
            vec![],
            vec![0, 1, 2],
        )
        .unwrap(),
    );
    let mut scene = Scene::empty();
    let material = scene.add_material(manylight::Material::default());
    for i in 0..100_000 {
        let at = DVec3::new((i % 500) as f64 * 4.0, 0.0, (i / 500) as f64 * -3.0);
        let turn = if i == 77 {
            DMat4::from_rotation_z(std::f64::consts::PI)
        } else {
            DMat4::IDENTITY
        };
        scene.add_object(mesh.clone(), material, DMat4::from_translation(at) * turn);
    }
    let b = scene.bounds().unwrap();
    // Placement 77 (at x = 308) is turned half round z: its y runs down to -2.
    let want_min = DVec3::new(-1.0, -2.0, -597.0);
    let want_max = DVec3::new(1997.0, 2.0, 0.5);
    assert!((b.min - want_min).length() < 1e-9, "{:?}", b.min);
    assert!((b.max - want_max).length() < 1e-9, "{:?}", b.max);
}

/// A game that rebuilds a mesh every frame (or edits one through `Arc::make_mut`, which copies
/// it while the renderer holds the old one) keeps the renderer's buffers and textures bounded:
/// an upload is freed once the application no longer holds its mesh or texture.
#[test]
fn meshes_and_textures_the_game_dropped_are_freed() {
    let mut s = scene::builtin::build("plane", Some((16, 1))).unwrap();
    let image = image::RgbaImage::from_pixel(2, 2, image::Rgba([200, 100, 50, 255]));
    let mut gpu = Gpu::new(EsVersion::Es3);
    gpu.r().set_method_named("forward").unwrap(); // no texture ring of its own
    let options = RenderOptions::default();
    gpu.render(&s, 32, 18, &options);
    let baseline = gpu.r().live_gl_objects();
    for frame in 0..20 {
        // A new mesh and a new texture each frame, the old ones dropped.
        let mesh = (*s.objects[0].mesh).clone();
        s.objects[0].mesh = Arc::new(mesh);
        // A new image too: textures reading one image share its upload.
        let fresh = manylight::scene::Texture::new(format!("frame {frame}"), image.clone());
        s.materials[0].diffuse_texture = Some(Arc::new(fresh));
        gpu.render(&s, 32, 18, &options);
        let live = gpu.r().live_gl_objects();
        assert_eq!(
            (live.buffers, live.textures),
            (baseline.buffers, baseline.textures + 1),
            "frame {frame}: one mesh's buffers and one texture, not every frame's"
        );
    }
}

/// A sparse file of `len` bytes starting with `head` (no disk space for the rest).
fn sparse_file(path: &Path, head: &[u8], len: u64) {
    std::fs::write(path, head).unwrap();
    std::fs::OpenOptions::new()
        .write(true)
        .open(path)
        .unwrap()
        .set_len(len)
        .unwrap();
}

const MIB: u64 = 1 << 20;

/// 20 buffers naming one 64 MiB file, each for its first few bytes: each read its whole file
/// (20 × 64 MiB, where the budget was charged 20 × 110 bytes; 3.15 GB of memory with a 256 MiB
/// file). A buffer now reads its own `byteLength` bytes.
#[test]
fn gltf_buffers_naming_one_large_file_read_only_their_own_bytes() {
    use common::gltf::Builder;
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let triangle = common::gltf_models::triangle(&mut b);
    sparse_file(&dir.path().join("big.bin"), &b.bin, 64 * MIB);
    let n = 20;
    let mut doc = b.document(triangle, Some("big.bin".into()));
    let buffer = doc["buffers"][0].clone();
    let (views, accessors) = (doc["bufferViews"].clone(), doc["accessors"].clone());
    let (mut all_views, mut all_accessors, mut meshes, mut nodes) =
        (vec![], vec![], vec![], vec![]);
    for i in 0..n {
        let first_view = all_views.len();
        for v in views.as_array().unwrap() {
            let mut v = v.clone();
            v["buffer"] = serde_json::json!(i);
            all_views.push(v);
        }
        let first_accessor = all_accessors.len();
        for a in accessors.as_array().unwrap() {
            let mut a = a.clone();
            a["bufferView"] =
                serde_json::json!(first_view + a["bufferView"].as_u64().unwrap() as usize);
            all_accessors.push(a);
        }
        let mut mesh = doc["meshes"][0].clone();
        let prim = &mut mesh["primitives"][0];
        prim["attributes"]["POSITION"] = serde_json::json!(first_accessor);
        prim["indices"] = serde_json::json!(first_accessor + 1);
        meshes.push(mesh);
        nodes.push(serde_json::json!({"mesh": i}));
    }
    doc["buffers"] = serde_json::json!(vec![buffer; n]);
    doc["bufferViews"] = serde_json::json!(all_views);
    doc["accessors"] = serde_json::json!(all_accessors);
    doc["meshes"] = serde_json::json!(meshes);
    doc["nodes"] = serde_json::json!(nodes);
    doc["scenes"] = serde_json::json!([{"nodes": (0..n).collect::<Vec<_>>()}]);
    let path = common::files::write(dir.path(), "m.gltf", doc.to_string());
    let before = scene::input::bytes_read();
    let (loaded, _) = common::files::load(&path).unwrap();
    let read = scene::input::bytes_read() - before;
    assert_eq!(loaded.objects.len(), n);
    let own = (n * b.bin.len()) as u64 + doc.to_string().len() as u64;
    assert!(
        read <= own,
        "read {read} bytes for {own} bytes of buffers and JSON"
    );
}

/// `dir/m.gltf`: `n` quads, each with a material of its own whose base colour is image `i`,
/// which names the file `uri(i)`.
fn textured_quads(dir: &Path, n: usize, uri: impl Fn(usize) -> String) -> std::path::PathBuf {
    let mut b = common::gltf::Builder::default();
    let quad = common::gltf_models::floor();
    let meshes: Vec<_> = (0..n)
        .map(|i| serde_json::json!({"primitives": [common::gltf_models::primitive(&mut b, &quad, Some(i))]}))
        .collect();
    let doc = serde_json::json!({
        "scenes": [{"nodes": (0..n).collect::<Vec<_>>()}],
        "nodes": (0..n).map(|i| serde_json::json!({"mesh": i})).collect::<Vec<_>>(),
        "meshes": meshes,
        "materials": (0..n).map(|i| serde_json::json!(
            {"pbrMetallicRoughness": {"baseColorTexture": {"index": i}}})).collect::<Vec<_>>(),
        "textures": (0..n).map(|i| serde_json::json!({"source": i})).collect::<Vec<_>>(),
        "images": (0..n).map(|i| serde_json::json!({"uri": uri(i)})).collect::<Vec<_>>(),
    });
    common::files::write(dir, "m.gltf", b.gltf(doc))
}

/// 30 images naming one file of 16 MiB (a PNG followed by zeros) were each read and decoded
/// (400 such took over a minute): the file is now read once and its texture shared.
#[test]
fn gltf_images_naming_one_file_read_and_decode_it_once() {
    let dir = tempfile::tempdir().unwrap();
    sparse_file(
        &dir.path().join("big.png"),
        &common::gltf_models::checker_png(),
        16 * MIB,
    );
    let n = 30;
    let path = textured_quads(dir.path(), n, |_| "big.png".to_string());
    let before = scene::input::bytes_read();
    let (loaded, report) = common::files::load(&path).unwrap();
    let read = scene::input::bytes_read() - before;
    assert!(read < 2 * 16 * MIB, "read {} MiB", read / MIB);
    let textures: HashSet<*const manylight::scene::Texture> = loaded
        .materials
        .iter()
        .map(|m| Arc::as_ptr(m.diffuse_texture.as_ref().expect("textured")))
        .collect();
    assert_eq!(textures.len(), 1, "{:?}", report.warnings);
}

/// Images in distinct files share one budget for what they read: five files of 250 MiB (each
/// within the texture limit) pass a model's 1 GiB, and the last gets its flat colour with a
/// warning instead of being read.
#[test]
fn gltf_images_together_read_at_most_a_models_limit() {
    let dir = tempfile::tempdir().unwrap();
    let n = 5;
    for i in 0..n {
        sparse_file(
            &dir.path().join(format!("big{i}.png")),
            &common::gltf_models::checker_png(),
            250 * MIB,
        );
    }
    let path = textured_quads(dir.path(), n, |i| format!("big{i}.png"));
    let before = scene::input::bytes_read();
    let (loaded, report) = common::files::load(&path).unwrap();
    let read = scene::input::bytes_read() - before;
    assert!(read <= 1024 * MIB, "read {} MiB", read / MIB);
    let textured = loaded
        .materials
        .iter()
        .filter(|m| m.diffuse_texture.is_some())
        .count();
    assert_eq!(textured, 4);
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("big4.png") && w.contains("images together")),
        "{:?}",
        report.warnings
    );
}

/// A scene's root list naming one node 4 million times (an 8 MB file) was stacked whole, 144
/// bytes an entry, before the repeat was found: gigabytes from megabytes (8.1 GB at 100 MB).
/// Under a 384 MiB address-space limit (the old walk needed 576 MiB here) the load must
/// still end in its error, not an abort.
#[test]
fn a_root_list_repeating_one_node_is_refused_within_bounded_memory() {
    let Ok(prlimit) = which_prlimit() else {
        common::skip("no prlimit (util-linux) to bound the child's memory");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let mut b = common::gltf::Builder::default();
    let mut doc = common::gltf_models::triangle(&mut b);
    let repeats = 4_000_000;
    doc["scenes"] = serde_json::json!([{"nodes": vec![0; repeats]}]);
    let path = common::files::write(dir.path(), "m.gltf", b.gltf(doc));
    let out = render_within_384_mib(&prlimit, &path, dir.path());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("roots list nodes[0] twice"), "{stderr}");
}

/// tobj keeps every MTL statement it does not read as a string in a map per material, about
/// 100 bytes a line: four libraries of 16 MiB of distinct short statements (`#c0`, `#c1`, …,
/// comments to anyone else) held some 2 GB. The loader now gives tobj only the statements it
/// reads or the loader looks up, so under a 384 MiB address-space limit the model renders.
#[test]
fn mtl_statements_tobj_would_keep_do_not_grow_memory() {
    let Ok(prlimit) = which_prlimit() else {
        common::skip("no prlimit (util-linux) to bound the child's memory");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let mut obj = String::new();
    for library in 0..4 {
        let mut mtl = format!("newmtl m{library}\nKd 0.8 0.8 0.8\n");
        let mut i = 0u64;
        while mtl.len() < (16 << 20) - 32 {
            mtl.push_str(&format!("#{i:x}\n"));
            i += 1;
        }
        std::fs::write(dir.path().join(format!("l{library}.mtl")), mtl).unwrap();
        obj.push_str(&format!("mtllib l{library}.mtl\n"));
    }
    obj.push_str("usemtl m0\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n");
    let path = dir.path().join("m.obj");
    std::fs::write(&path, obj).unwrap();
    let out = render_within_384_mib(&prlimit, &path, dir.path());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
}

/// A failed allocation inside tobj aborts the process, and so did the read of a file larger
/// than the memory left. Under a 384 MiB address-space limit, a face of 2²³ corners (a 16 MB
/// OBJ whose load peaks at about 0.55 GB, which aborted here) and a 512 MiB file are refused
/// with an error naming the file, each before its memory is taken, and a small OBJ renders.
#[test]
fn an_obj_larger_than_the_memory_left_is_an_error_not_an_abort() {
    let Ok(prlimit) = which_prlimit() else {
        common::skip("no prlimit (util-linux) to bound the child's memory");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let mut fan = String::from("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf");
    for i in 0..1 << 23 {
        fan.push_str([" 1", " 2", " 3", " 4"][i % 4]);
    }
    fan.push('\n');
    let fan_path = dir.path().join("fan.obj");
    std::fs::write(&fan_path, fan).unwrap();
    // A sparse file: no disk taken, and the reader refuses it before reading a byte.
    let big_path = dir.path().join("big.obj");
    let big = std::fs::File::create(&big_path).unwrap();
    big.set_len(512 << 20).unwrap();
    for (path, says) in [
        (
            &fan_path,
            "loading it (faces: 1, vertices: 4) may take up to",
        ),
        (&big_path, "OBJ file of 536870912 bytes: more than"),
    ] {
        let out = render_within_384_mib(&prlimit, path, dir.path());
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{}: {stderr}", path.display());
        assert!(stderr.contains(says), "{stderr}");
        assert!(stderr.contains("this process can allocate now"), "{stderr}");
    }
    let small = dir.path().join("small.obj");
    std::fs::write(&small, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
    let out = render_within_384_mib(&prlimit, &small, dir.path());
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `bench-assign` builds its workload from the default scene: lights it cannot allocate are
/// the error `render` gives for them, where the workload's `expect` panicked.
#[test]
fn bench_assign_past_the_memory_left_is_an_error_not_a_panic() {
    let Ok(prlimit) = which_prlimit() else {
        common::skip("no prlimit (util-linux) to bound the child's memory");
        return;
    };
    let max = manylight::scene::input::MAX_LIGHTS.to_string();
    let out = std::process::Command::new(prlimit)
        .arg("--as=402653184")
        .arg(env!("CARGO_BIN_EXE_manylight"))
        .env("RAYON_NUM_THREADS", "1")
        .env("MALLOC_ARENA_MAX", "1")
        .args(["bench-assign", "--runs", "1", "--lights"])
        .arg(&max)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.starts_with(&format!(
            "error: invalid value for `lights`: {max} lights need"
        )),
        "{stderr}"
    );
}

/// A glTF primitive without normals is drawn flat: each triangle's corners get their own
/// copies of the vertex colours. Those copies (16 bytes a corner) were made before the
/// unshared vertices were counted against the file's limit, so a 12 MB strip of byte indices
/// (36 M corners, 0.58 GB of colours) aborted under 384 MiB before its error.
#[test]
fn flat_shaded_gltf_vertices_are_counted_before_they_are_copied() {
    use common::gltf::{Builder, UNSIGNED_BYTE};
    let Ok(prlimit) = which_prlimit() else {
        common::skip("no prlimit (util-linux) to bound the child's memory");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let corners: Vec<f32> = (0..256)
        .flat_map(|i| [i as f32, (i % 7) as f32, 0.0])
        .collect();
    let p = b.floats(&corners, "VEC3");
    let c = b.floats(&[0.5; 4 * 256], "VEC4");
    let strip: Vec<u8> = (0..12_000_000u32).map(|i| (i % 256) as u8).collect();
    let i = b.accessor(&strip, UNSIGNED_BYTE, "SCALAR", strip.len());
    let doc = serde_json::json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": p, "COLOR_0": c},
                                    "indices": i, "mode": 5}]}]});
    let path = dir.path().join("strip.glb");
    std::fs::write(&path, b.glb(doc)).unwrap();
    let out = render_within_384_mib(&prlimit, &path, dir.path());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("meshes[0].primitives[0]"), "{stderr}");
    assert!(stderr.contains("vertices"), "{stderr}");
}

/// A PNG's colour profile is never used (textures are taken as sRGB), but the decoder
/// inflated it up to its 512 MiB limit: a 4×4 texture whose 0.3 MB profile inflates to
/// 300 MiB aborted a render under 384 MiB. The profile is now taken out unread, and the
/// texture's colour reaches the frame. So too with bytes after the image's end, which the
/// decoder ignores and which once hid the profile from the code that takes it out.
#[test]
fn a_pngs_colour_profile_is_not_inflated() {
    use image::ImageEncoder;
    let Ok(prlimit) = which_prlimit() else {
        common::skip("no prlimit (util-linux) to bound the child's memory");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let mut png = Vec::new();
    let mut encoder = image::codecs::png::PngEncoder::new(&mut png);
    encoder.set_icc_profile(vec![0; 300 << 20]).unwrap();
    let red = [230u8, 20, 20, 255].repeat(16);
    encoder
        .write_image(&red, 4, 4, image::ExtendedColorType::Rgba8)
        .unwrap();
    assert!(png.len() < 1 << 20, "{} bytes", png.len());
    let path = textured_quad(dir.path(), "t.png");
    for trailing in [&b""[..], b"\0"] {
        std::fs::write(dir.path().join("t.png"), [&png[..], trailing].concat()).unwrap();
        let out = render_within_384_mib(&prlimit, &path, dir.path());
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{trailing:?}: {stderr}");
        assert!(
            !stderr.contains("t.png"),
            "no warning of the texture: {stderr}"
        );
        let frame = image::open(dir.path().join("x.png")).unwrap().to_rgba8();
        let centre = frame.get_pixel(4, 4).0;
        assert!(centre[0] > 2 * centre[1].max(centre[2]), "{centre:?}");
    }
}

/// A progressive JPEG of 16 384² in one component (its coefficients 512 MiB) whose frame
/// hid behind a fake 1×1 one, inside a segment the decoder skips by its length and the
/// check read as a marker without one: its coefficients went unchecked, and it aborted a
/// render under a 900 MB address-space limit. It is refused from its real frame's headers.
#[test]
fn a_jpeg_frame_hidden_from_the_check_is_still_refused() {
    let Ok(prlimit) = which_prlimit() else {
        common::skip("no prlimit (util-linux) to bound the child's memory");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let mut jpeg = vec![0xFF, 0xD8];
    // `FF 01` holding a 1×1 progressive frame.
    jpeg.extend([
        0xFF, 0x01, 0, 15, 0xFF, 0xC2, 0, 11, 8, 0, 1, 0, 1, 1, 1, 0x11, 0,
    ]);
    jpeg.extend([0xFF, 0xDB, 0, 67, 0]);
    jpeg.extend([1; 64]);
    jpeg.extend([0xFF, 0xC2, 0, 11, 8, 0x40, 0, 0x40, 0, 1, 1, 0x11, 0]);
    for class in [0x00, 0x10] {
        // One code of length 1, for symbol 0.
        jpeg.extend([0xFF, 0xC4, 0, 20, class, 1]);
        jpeg.extend([0; 16]);
    }
    jpeg.extend([0xFF, 0xDA, 0, 8, 1, 1, 0, 0, 0, 0]);
    jpeg.extend([0; 64]);
    jpeg.extend([0xFF, 0xD9]);
    std::fs::write(dir.path().join("t.jpg"), jpeg).unwrap();
    let path = textured_quad(dir.path(), "t.jpg");
    let out = render_within_384_mib(&prlimit, &path, dir.path());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(
        stderr.contains("a progressive JPEG of 16384×16384"),
        "{stderr}"
    );
}

/// An OBJ quad in `dir` whose material maps `texture` (a file name in `dir`): its path.
fn textured_quad(dir: &Path, texture: &str) -> std::path::PathBuf {
    std::fs::write(
        dir.join("m.mtl"),
        format!("newmtl m\nKd 1 1 1\nmap_Kd {texture}\n"),
    )
    .unwrap();
    let path = dir.join("m.obj");
    std::fs::write(
        &path,
        "mtllib m.mtl\nusemtl m\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n\
         vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n",
    )
    .unwrap();
    path
}

/// `manylight render` of `scene` (8 × 8, into `dir`) under a 384 MiB address-space limit.
fn render_within_384_mib(prlimit: &Path, scene: &Path, dir: &Path) -> std::process::Output {
    std::process::Command::new(prlimit)
        .arg("--as=402653184")
        .arg(env!("CARGO_BIN_EXE_manylight"))
        // What the address space holds besides the load, the same on any machine: one
        // worker thread, one malloc arena.
        .env("RAYON_NUM_THREADS", "1")
        .env("MALLOC_ARENA_MAX", "1")
        .args(["render", "--size", "8x8", "--scene"])
        .arg(scene)
        .arg("--out")
        .arg(dir.join("x.png"))
        .output()
        .unwrap()
}

fn which_prlimit() -> Result<std::path::PathBuf, ()> {
    ["/usr/bin/prlimit", "/bin/prlimit"]
        .iter()
        .map(std::path::PathBuf::from)
        .find(|p| p.is_file())
        .ok_or(())
}

/// A sparse POSITION without a buffer view claims its count for free: 703 bytes of glTF with
/// 2²⁵ such vertices took 2.4 GB. Past `MAX_UNBACKED_ELEMENTS` it is refused naming the
/// accessor; a small one (zeros but for its sparse values) still loads.
#[test]
fn gltf_accessors_without_a_buffer_view_are_bounded() {
    use common::gltf::Builder;
    use manylight::scene::gltf::MAX_UNBACKED_ELEMENTS;
    let dir = tempfile::tempdir().unwrap();
    let document = |count: usize| {
        let mut b = Builder::default();
        let index_bytes: Vec<u8> = [0u16, 1, 2].iter().flat_map(|v| v.to_le_bytes()).collect();
        let sparse_indices = b.view(&index_bytes);
        let values: Vec<u8> = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let sparse_values = b.view(&values);
        b.accessors.push(serde_json::json!({
            "componentType": 5126, "type": "VEC3", "count": count,
            "min": [0, 0, 0], "max": [1, 1, 0],
            "sparse": {"count": 3,
                "indices": {"bufferView": sparse_indices, "componentType": 5123},
                "values": {"bufferView": sparse_values}}
        }));
        let position = b.accessors.len() - 1;
        let indices = b.u16s(&[0, 1, 2]);
        b.gltf(serde_json::json!({
            "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": position},
                "indices": indices}]}]
        }))
    };
    let path = common::files::write(dir.path(), "small.gltf", document(3));
    let (scene, _) = common::files::load(&path).unwrap();
    assert_eq!(scene.objects.len(), 1);
    let path = common::files::write(dir.path(), "big.gltf", document(MAX_UNBACKED_ELEMENTS + 1));
    let err = common::files::load(&path).unwrap_err().to_string();
    assert!(
        err.contains("accessors[0]") && err.contains("without a bufferView"),
        "{err}"
    );
}

/// A driver out of memory in an upload or an allocation fails that frame with an error naming
/// the step, and the renderer keeps nothing the failed step made: a game that logs the error
/// and renders on (each frame tries the step again) does not lose GPU memory frame after frame,
/// and once memory is back its frame and its objects are those of a renderer that never failed.
/// The failures are injected (`Renderer::fail_gl_checks_naming`): a real driver fails these
/// steps only under memory pressure.
#[test]
fn a_failed_upload_or_allocation_keeps_nothing_it_made() {
    let mut s = scene::builtin::build("plane", Some((16, 1))).unwrap();
    let image = image::RgbaImage::from_pixel(2, 2, image::Rgba([200, 100, 50, 255]));
    s.materials[0].diffuse_texture = Some(Arc::new(manylight::scene::Texture::new(
        "orange".to_string(),
        image,
    )));
    let options = RenderOptions::default();
    let objects = |l: manylight::gl::device::LiveObjects| {
        (l.buffers, l.textures, l.framebuffers, l.renderbuffers)
    };
    for (es, method, step) in [
        (EsVersion::Es3, "clustered", "mesh upload"),
        (EsVersion::Es3, "clustered", "image texture"),
        (EsVersion::Es3, "forward", "allocating a"),
        (EsVersion::Es3, "clustered", "offscreen target creation"),
        (EsVersion::Es3, "deferred", "G-buffer"),
        (EsVersion::Es3, "deferred", "instance buffer"),
        (EsVersion::Es3, "clustered", "data texture upload"),
        (EsVersion::Es2, "forward", "data texture upload"),
        (EsVersion::Es2, "forward", "mesh upload"),
        (EsVersion::Es2, "clustered", "image texture"),
    ] {
        let mut healthy = Gpu::new(es);
        healthy.r().set_method_named(method).unwrap();
        let expected = healthy.render(&s, 32, 18, &options);
        let expected_objects = objects(healthy.r().live_gl_objects());
        drop(healthy);

        let mut gpu = Gpu::new(es);
        gpu.r().set_method_named(method).unwrap();
        gpu.r().fail_gl_checks_naming(Some(step));
        let mut first = None;
        for frame in 0..3 {
            let error = gpu.r().render_offscreen(&s, 32, 18, &options).unwrap_err();
            let message = error.to_string();
            assert!(
                message.contains("GL_OUT_OF_MEMORY") && message.contains(step),
                "{es} {method}, {step}: {message}"
            );
            let live = objects(gpu.r().live_gl_objects());
            let first = *first.get_or_insert(live);
            assert_eq!(
                live, first,
                "{es} {method}, {step}: frame {frame} kept more GL objects (buffers, textures, \
                 framebuffers, renderbuffers) than the first failed frame"
            );
        }
        gpu.r().fail_gl_checks_naming(None);
        let recovered = gpu.render(&s, 32, 18, &options);
        assert!(
            recovered == expected,
            "{es} {method}, {step}: the frame after the failures differs"
        );
        assert_eq!(
            objects(gpu.r().live_gl_objects()),
            expected_objects,
            "{es} {method}, {step}: the failures left GL objects behind"
        );
    }
}

/// A still scene after a burst of lights: the frame that would shrink the light data to the
/// few lights' size uploads it again, and where that upload fails (out of memory), clustered
/// kept the burst's texture sets: with memory back, the next frame uploaded into one of them
/// and held 9× the light data of a renderer that never failed. Now the failure frees the
/// ring. The grid is fixed, so that only the shrink uploads in the still frames.
#[test]
fn a_failed_shrink_after_a_burst_frees_the_burst_sets() {
    use manylight::cluster::grid::GridMode;
    use manylight::gl::texture::SHRINK_AFTER;
    let few = scene::builtin::build("plane", Some((20, 5))).unwrap();
    let mut many = scene::builtin::build("plane", Some((5000, 5))).unwrap();
    let mut options = RenderOptions::default();
    options.grid.mode = GridMode::Fixed;
    let objects = |l: manylight::gl::device::LiveObjects| (l.buffers, l.textures);
    let mut healthy = Gpu::new(EsVersion::Es3);
    let mut failing = Gpu::new(EsVersion::Es3);
    for gpu in [&mut healthy, &mut failing] {
        gpu.r().set_method_named("clustered").unwrap();
        gpu.render(&few, 32, 18, &options);
        for k in 0..3 {
            many.lights[0].position.x += 1e-3 * k as f64;
            gpu.render(&many, 32, 18, &options);
        }
        // Lists uploaded again: the still frames count from here.
        gpu.render(&few, 32, 18, &options);
    }
    failing
        .r()
        .fail_gl_checks_naming(Some("data texture upload"));
    let mut failed_at = None;
    for frame in 0..2 * SHRINK_AFTER {
        match failing.r().render_offscreen(&few, 32, 18, &options) {
            Ok(_) => {}
            Err(e) => {
                let message = e.to_string();
                assert!(message.contains("GL_OUT_OF_MEMORY"), "{message}");
                failed_at = Some(frame);
                break;
            }
        }
    }
    let failed_at = failed_at.expect("a still frame uploaded the light data again");
    failing.r().fail_gl_checks_naming(None);
    for _ in 0..=failed_at {
        healthy.render(&few, 32, 18, &options);
    }
    let (expected, expected_stats) = healthy
        .r()
        .render_offscreen(&few, 32, 18, &options)
        .unwrap();
    let (recovered, stats) = failing
        .r()
        .render_offscreen(&few, 32, 18, &options)
        .unwrap();
    assert!(recovered == expected, "the frame after the failure differs");
    // The fresh set is sized to the few lights; the healthy renderer's kept what a quarter
    // or more of it holds.
    assert!(
        stats.memory.method_gpu_bytes <= expected_stats.memory.method_gpu_bytes,
        "clustered's light data after the failed shrink (at still frame {failed_at}): {} bytes, \
         {} without the failure",
        stats.memory.method_gpu_bytes,
        expected_stats.memory.method_gpu_bytes
    );
    assert_eq!(
        objects(failing.r().live_gl_objects()),
        objects(healthy.r().live_gl_objects()),
        "GL objects (buffers, textures) after the failed shrink"
    );
}

/// [`render_within_384_mib`]'s exit code and standard error, or `None` (said) where this
/// machine has no `prlimit`.
fn rendered_within_384_mib(scene: &Path, dir: &Path) -> Option<(Option<i32>, String)> {
    let Ok(prlimit) = which_prlimit() else {
        common::skip("no prlimit (util-linux) to bound the child's memory");
        return None;
    };
    let out = render_within_384_mib(&prlimit, scene, dir);
    Some((
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    ))
}

/// [`rendered_within_384_mib`] of an OBJ triangle in `dir` whose material's texture is
/// `image`, written as `name`.
fn textured_triangle_within_384_mib(
    dir: &Path,
    name: &str,
    image: &[u8],
) -> Option<(Option<i32>, String)> {
    std::fs::write(dir.join(name), image).unwrap();
    let mtl = format!("newmtl m\nKd 0.8 0.8 0.8\nmap_Kd {name}\n");
    std::fs::write(dir.join("m.mtl"), mtl).unwrap();
    let path = dir.join("m.obj");
    std::fs::write(
        &path,
        "mtllib m.mtl\nusemtl m\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n\
         f 1/1 2/2 3/3\n",
    )
    .unwrap();
    rendered_within_384_mib(&path, dir)
}

/// `image` aborts the process where an allocation fails. A 35-byte GIF whose screen is
/// 11 585² (536 MB of RGBA), the texture of a small OBJ, aborted its load under a 384 MiB
/// address-space limit (helper-129); the decode is now asked of the allocator first, and the
/// material keeps its flat colour with a warning naming the texture.
#[test]
fn a_texture_larger_than_the_memory_left_keeps_the_flat_colour_not_an_abort() {
    let dir = tempfile::tempdir().unwrap();
    // Logical screen 0x2d41 = 11 585 a side; one 1×1 frame of one colour.
    let mut gif = b"GIF89a\x41\x2d\x41\x2d\x00\x00\x00".to_vec();
    gif.extend_from_slice(b"\x2c\x00\x00\x00\x00\x01\x00\x01\x00\x80\x00\x00\x00\xff\xff\xff");
    gif.extend_from_slice(b"\x02\x02\x44\x01\x00\x3b");
    let Some((code, stderr)) = textured_triangle_within_384_mib(dir.path(), "big.gif", &gif) else {
        return;
    };
    assert_eq!(code, Some(0), "{stderr}");
    assert!(
        stderr.contains("big.gif could not be decoded (11585×11585 pixels need"),
        "{stderr}"
    );
}

/// A GIF's first frame may be larger than its logical screen, which is the size `image`
/// reports: a 1×1 screen with an 11 000² frame (484 MB for the decoder's frame buffer), the
/// texture of a small OBJ, aborted its load under a 384 MiB address-space limit (helper-153).
/// The frame is now read from its descriptor and asked of the allocator with the image: its
/// RGBA and its palette indices, 5 bytes a pixel. At 9 000² (324 MB of RGBA, then 81 MB of
/// indices) counting the RGBA alone still aborted (helper-154).
#[test]
fn a_gif_frame_larger_than_its_screen_is_asked_for_not_an_abort() {
    let dir = tempfile::tempdir().unwrap();
    // Screen 1×1 with a palette of two; the frame at (0, 0), 0x2328 = 9 000 a side.
    let mut gif = b"GIF89a\x01\x00\x01\x00\x80\x00\x00\x00\x00\x00\xff\xff\xff".to_vec();
    gif.extend_from_slice(b"\x2c\x00\x00\x00\x00\x28\x23\x28\x23\x00\x02\x02\x44\x01\x00\x3b");
    let Some((code, stderr)) = textured_triangle_within_384_mib(dir.path(), "wide.gif", &gif)
    else {
        return;
    };
    assert_eq!(code, Some(0), "{stderr}");
    assert!(
        stderr.contains(
            "wide.gif could not be decoded (1×1 pixels and what the decoder holds \
                         besides them need"
        ),
        "{stderr}"
    );
}

/// A 66-byte scene file asking for a million random lights (a quarter of the limit) aborted
/// under a 384 MiB address-space limit: the lights are made at load, and the frame's copies of
/// them were refused by the allocator (helper-129). The load and the frame now ask first, so
/// it is an error naming the count; a few thousand lights still render there.
#[test]
fn lights_past_the_memory_left_are_an_error_not_an_abort() {
    let dir = tempfile::tempdir().unwrap();
    for (count, expected) in [(1_000_000, 1), (4_000, 0)] {
        let path = common::files::write(
            dir.path(),
            &format!("l{count}.json"),
            format!(r#"{{"objects":[{{"builtin":"plane"}}],"random_lights":{{"count":{count}}}}}"#),
        );
        let Some((code, stderr)) = rendered_within_384_mib(&path, dir.path()) else {
            return;
        };
        assert_eq!(code, Some(expected), "{count}: {stderr}");
        if expected == 1 {
            assert!(
                stderr.contains(&format!("{count} lights need about")),
                "{stderr}"
            );
        }
    }
}

/// A 16 MB glTF triangle strip of four vertices unrolls to 16 M triangles; building them (the
/// duplicate search alone takes 16 bytes a triangle) aborted under a 384 MiB address-space
/// limit (helper-129). The primitive is now asked of the allocator first: an error naming it,
/// as the OBJ loader's.
#[test]
fn a_gltf_primitive_larger_than_the_memory_left_is_an_error_not_an_abort() {
    let dir = tempfile::tempdir().unwrap();
    let count = 1usize << 24;
    let mut bin: Vec<u8> = [
        [0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ]
    .iter()
    .flatten()
    .flat_map(|v| v.to_le_bytes())
    .collect();
    // Normals given, so no vertex is unshared for flat shading.
    bin.extend(
        [[0f32, 0.0, 1.0]; 4]
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes()),
    );
    bin.extend((0..count).map(|i| (i % 4) as u8));
    std::fs::write(dir.path().join("strip.bin"), &bin).unwrap();
    let doc = serde_json::json!({
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 2}, "indices": 1, "mode": 5}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5121, "count": count, "type": "SCALAR"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC3"}
        ],
        "bufferViews": [
            {"buffer": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 96, "byteLength": count},
            {"buffer": 0, "byteOffset": 48, "byteLength": 48}
        ],
        "buffers": [{"byteLength": bin.len(), "uri": "strip.bin"}]
    });
    let path = common::files::write(dir.path(), "strip.gltf", doc.to_string());
    let Some((code, stderr)) = rendered_within_384_mib(&path, dir.path()) else {
        return;
    };
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("meshes[0].primitives[0]: building its 4 vertices and 16777214 triangles"),
        "{stderr}"
    );
    assert!(
        stderr.contains("more than this process can allocate now"),
        "{stderr}"
    );
}

/// A scene file is parsed whole before its objects are placed: 16 MiB of `{},` took 1.25 GB
/// and 700 000 `{"builtin":"plane"}` some 700 MB placed, each aborting under a 384 MiB
/// address-space limit (helper-129). The first is now refused before parsing (too many JSON
/// objects), the second before placing (more than the process can allocate).
#[test]
fn a_scene_file_of_many_objects_is_an_error_not_an_abort() {
    let dir = tempfile::tempdir().unwrap();
    let list = |object: &str, n: usize| format!(r#"{{"objects":[{}]}}"#, vec![object; n].join(","));
    for (name, text, says) in [
        (
            "empty.json",
            list("{}", 5_000_000),
            "objects and arrays, more than the",
        ),
        (
            "planes.json",
            list(r#"{"builtin":"plane"}"#, 700_000),
            "placing its 700000 objects takes about",
        ),
    ] {
        let path = common::files::write(dir.path(), name, text);
        let Some((code, stderr)) = rendered_within_384_mib(&path, dir.path()) else {
            return;
        };
        assert_eq!(code, Some(1), "{name}: {stderr}");
        assert!(stderr.contains(says), "{name}: {stderr}");
    }
}

/// 3 MB of empty glTF nodes, within the JSON limits, parse into some 600 MB (every one of the
/// loader's parses holds each node): it aborted under a 384 MiB address-space limit in the
/// second parse (helper-129). The parses are now asked of the allocator first.
#[test]
fn a_gltf_whose_json_parse_cannot_be_allocated_is_an_error_not_an_abort() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = common::gltf::Builder::default();
    let mut doc = common::gltf_models::triangle(&mut b);
    let nodes = doc["nodes"].as_array_mut().unwrap();
    nodes.extend(std::iter::repeat_n(serde_json::json!({}), 1_000_000));
    let path = common::files::write(dir.path(), "m.gltf", b.gltf(doc));
    let Some((code, stderr)) = rendered_within_384_mib(&path, dir.path()) else {
        return;
    };
    assert_eq!(code, Some(1), "{stderr}");
    assert!(stderr.contains("parsing its JSON ("), "{stderr}");
    assert!(
        stderr.contains("more than this process can allocate now"),
        "{stderr}"
    );
}

/// Meshes whose primitives name the same accessors, mode and material build one mesh: 32
/// meshes over one 29 MB normal-mapped grid were decoded, given tangents and uploaded 32
/// times (3.4 GB; helper-129). Another material, or other accessors, still build their own.
#[test]
fn gltf_primitives_naming_the_same_accessors_share_one_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = common::gltf::Builder::default();
    let mut doc = common::gltf_models::triangle(&mut b);
    let prim = doc["meshes"][0]["primitives"][0].clone();
    let mut red = prim.clone();
    red["material"] = serde_json::json!(0);
    let mut other = prim.clone();
    other["indices"] = serde_json::json!(b.u16s(&[0, 2, 1]));
    doc["materials"] =
        serde_json::json!([{"pbrMetallicRoughness": {"baseColorFactor": [1, 0, 0, 1]}}]);
    doc["meshes"] = serde_json::json!([
        {"primitives": [prim]}, {"primitives": [prim]}, {"primitives": [red]},
        {"primitives": [other]}
    ]);
    // Apart, so that none is a repeat of another's placement.
    doc["nodes"] = serde_json::json!((0..4)
        .map(|i| serde_json::json!({"mesh": i, "translation": [2 * i, 0, 0]}))
        .collect::<Vec<_>>());
    doc["scenes"] = serde_json::json!([{"nodes": [0, 1, 2, 3]}]);
    let path = common::files::write(dir.path(), "m.gltf", b.gltf(doc));
    let (s, _) = scene::load(path.to_str().unwrap(), None).unwrap();
    assert_eq!(s.objects.len(), 4);
    assert!(
        Arc::ptr_eq(&s.objects[0].mesh, &s.objects[1].mesh),
        "one mesh for both"
    );
    assert_eq!(
        distinct_meshes(&s),
        3,
        "another material and other indices build their own"
    );
}
