//! OBJ + MTL loading: real scenes from $MANYLIGHT_ASSETS render lit, and bad files give the
//! errors and warnings the loader promises.

mod common;

use std::path::Path;

use common::{assets_dir, Gpu};
use glam::DMat4;
use manylight::scene::{self, obj, Scene, SceneError};
use manylight::{EsVersion, RenderOptions};

/// Mean luminance and the fraction of pixels brighter than the background.
fn brightness(img: &image::RgbaImage) -> (f64, f64) {
    let n = (img.width() * img.height()) as f64;
    let mut sum = 0.0;
    let mut lit = 0.0;
    for p in img.pixels() {
        let l = (p[0] as f64 + p[1] as f64 + p[2] as f64) / 3.0;
        sum += l;
        if l > 8.0 {
            lit += 1.0;
        }
    }
    (sum / n, lit / n)
}

#[test]
fn cornell_box_loads_and_renders_lit_on_es2_and_es3() {
    let Some(dir) = assets_dir() else { return };
    let path = dir.join("cornell-box/CornellBox-Original.obj");
    let (scene, report) = scene::load(path.to_str().unwrap(), Some((64, 3))).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    assert!(
        scene
            .materials
            .iter()
            .any(|m| m.diffuse.x > 0.5 && m.diffuse.y < 0.2),
        "red wall material from Kd"
    );
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::new(es);
        let img = gpu.render(&scene, 128, 128, &RenderOptions::default());
        let (mean, lit) = brightness(&img);
        assert!(
            mean > 20.0 && lit > 0.5,
            "{es}: cornell box too dark (mean {mean:.1}, lit {lit:.2})"
        );
    }
}

#[test]
fn teapot_texture_is_bound_from_its_mtl() {
    let Some(dir) = assets_dir() else { return };
    let path = dir.join("teapot/teapot.obj");
    let (scene, report) = scene::load(path.to_str().unwrap(), Some((32, 1))).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    assert!(
        scene.materials.iter().any(|m| m.diffuse_texture.is_some()),
        "default.png not bound"
    );
    assert!(
        scene
            .objects
            .iter()
            .all(|o| o.mesh.normals.len() == o.mesh.positions.len()),
        "normals computed"
    );
    let mut gpu = Gpu::new(EsVersion::Es3);
    let img = gpu.render(&scene, 128, 96, &RenderOptions::default());
    assert!(brightness(&img).1 > 0.1, "teapot not visible");
}

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn load_obj(path: &Path) -> Result<(Scene, obj::LoadReport), SceneError> {
    let mut scene = Scene::empty();
    let report = obj::load_into(&mut scene, path, DMat4::IDENTITY, None)?;
    Ok((scene, report))
}

#[test]
fn malformed_obj_files_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("garbage.obj", "v 1 2 three\nf 1 2 3\n", "parse"),
        ("oob.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "garbage"),
        (
            "nan.obj",
            "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            "positions",
        ),
        ("empty.obj", "# nothing here\n", "no faces"),
    ];
    for (name, text, needle) in cases {
        let path = write(dir.path(), name, text);
        let err = load_obj(&path).expect_err(name).to_string();
        assert!(err.contains(name), "error should name the file: {err}");
        if needle != "garbage" {
            assert!(
                err.to_lowercase().contains(needle),
                "{name}: expected `{needle}` in: {err}"
            );
        }
    }
    let missing = load_obj(&dir.path().join("absent.obj"))
        .unwrap_err()
        .to_string();
    assert!(missing.contains("absent.obj"), "{missing}");
}

#[test]
fn missing_texture_warns_and_falls_back_to_the_flat_colour() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "m.mtl",
        "newmtl red\nKd 0.9 0.1 0.1\nmap_Kd textures\\does_not_exist.png\n",
    );
    let path = write(
        dir.path(),
        "tri.obj",
        "mtllib m.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl red\nf 1/1 2/2 3/3\n",
    );
    let (mut scene, report) = load_obj(&path).expect("a missing texture must not abort the load");
    assert_eq!(report.warnings.len(), 1, "{:?}", report.warnings);
    assert!(report.warnings[0].contains("does_not_exist.png"));
    let red = scene.materials.iter().find(|m| m.name == "red").unwrap();
    assert!(red.diffuse_texture.is_none());
    assert_eq!(red.diffuse.x, 0.9);
    // And it renders in its flat colour: red dominates in the middle of the image.
    scene.frame_camera();
    scene.ambient = glam::Vec3::ONE;
    let mut gpu = Gpu::new(EsVersion::Es3);
    let img = gpu.render(&scene, 64, 64, &RenderOptions::default());
    let p = img.get_pixel(32, 32);
    assert!(p[0] > 150 && p[1] < 120, "expected flat red, got {p:?}");
}

#[test]
fn texture_with_other_case_and_backslashes_is_found() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("Maps")).unwrap();
    image::RgbaImage::from_pixel(4, 4, image::Rgba([0, 255, 0, 255]))
        .save(dir.path().join("Maps/Green.PNG"))
        .unwrap();
    write(
        dir.path(),
        "m.mtl",
        "newmtl g\nKd 1 1 1\nmap_Kd maps\\green.png\n",
    );
    let path = write(dir.path(), "t.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl g\nf 1/1 2/2 3/3\n");
    let (scene, report) = load_obj(&path).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    assert!(scene.materials[0].diffuse_texture.is_some());
}
