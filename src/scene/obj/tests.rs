//! The OBJ loader's own cases: folders, texture overrides and budgets, MTL numbers, objects
//! without texture coordinates.

use super::*;

/// `obj` loaded at the identity with the default options and budget.
pub(super) fn load(obj: &Path) -> (Scene, LoadReport) {
    try_load(obj).unwrap()
}

/// [`load`], its error kept.
fn try_load(obj: &Path) -> Result<(Scene, LoadReport), SceneError> {
    let mut scene = Scene::empty();
    let mut budget = TextureBudget::default();
    let options = LoadOptions::default();
    let report = load_into(
        &mut scene,
        obj,
        DMat4::IDENTITY,
        None,
        &options,
        &mut budget,
    )?;
    Ok((scene, report))
}

/// A model folder inside a temporary root holding `secret.mtl`.
fn model_beside_a_secret_library() -> (tempfile::TempDir, std::path::PathBuf) {
    let root = tempfile::tempdir().unwrap();
    let model = root.path().join("model");
    std::fs::create_dir(&model).unwrap();
    std::fs::write(root.path().join("secret.mtl"), "newmtl red\nKd 1 0 0\n").unwrap();
    (root, model)
}

/// Objects without `vt` whose material has a texture (two here, beside one with `vt`):
/// said once for the material, as the renderer leaves the texture out there.
#[test]
fn a_textured_material_on_objects_without_texture_coordinates_is_said_once() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbaImage::from_pixel(2, 2, image::Rgba([200, 20, 20, 255]))
        .save(dir.path().join("t.png"))
        .unwrap();
    std::fs::write(
        dir.path().join("m.mtl"),
        "newmtl tex\nKd 1 1 1\nmap_Kd t.png\n",
    )
    .unwrap();
    let obj = dir.path().join("m.obj");
    let tri = |o: &str, first: u32| {
        let f = |i: u32| first + i;
        format!("o {o}\nusemtl tex\nf {} {} {}\n", f(0), f(1), f(2))
    };
    let text = format!(
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n{}{}\
         o mapped\nusemtl tex\nf 1/1 2/2 3/3\n",
        tri("bare", 1),
        tri("bare_too", 1)
    );
    std::fs::write(&obj, text).unwrap();
    let (scene, report) = load(&obj);
    let said: Vec<_> = (report.warnings.iter())
        .filter(|w| w.contains("no texture coordinates (`vt`)"))
        .collect();
    assert_eq!(said.len(), 1, "{:?}", report.warnings);
    assert!(
        said[0].contains("`bare`") && said[0].contains("`tex`"),
        "{said:?}"
    );
    let uvs: Vec<bool> = (scene.objects.iter())
        .map(|o| o.mesh.uvs.is_empty())
        .collect();
    assert_eq!(uvs, [true, true, false]);
}

#[test]
fn a_material_library_outside_the_models_folder_is_refused_unless_allowed() {
    let (_root, model) = model_beside_a_secret_library();
    let obj = model.join("m.obj");
    let faces = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n";
    let write = |mtllib: &str| std::fs::write(&obj, format!("mtllib {mtllib}\n{faces}"));
    write("../secret.mtl").unwrap();
    let diffuse = |allow_outside_files| {
        let mut scene = Scene::empty();
        let options = LoadOptions {
            allow_outside_files,
        };
        let mut budget = TextureBudget::default();
        let report = load_into(
            &mut scene,
            &obj,
            DMat4::IDENTITY,
            None,
            &options,
            &mut budget,
        )
        .unwrap();
        let material = scene.objects[0].material;
        (scene.materials[material].diffuse, report.warnings)
    };
    let (refused, warnings) = diffuse(false);
    assert_eq!(refused, Vec3::splat(0.8), "the default grey");
    for said in [
        "mtllib `../secret.mtl` is outside the model's folder",
        "materials not loaded",
    ] {
        assert!(warnings.iter().any(|w| w.contains(said)), "{warnings:?}");
    }
    let (allowed, _) = diffuse(true);
    assert_eq!(allowed, Vec3::new(1.0, 0.0, 0.0));
    // Named by an absolute path (an exporter's), a library in the folder is found by
    // its file name.
    std::fs::write(model.join("own.mtl"), "newmtl red\nKd 0 0 1\n").unwrap();
    write("C:\\Users\\bob\\Own.MTL").unwrap();
    assert_eq!(diffuse(false).0, Vec3::new(0.0, 0.0, 1.0));
    // Named in another letter case, as a Windows exporter may.
    write("OWN.Mtl").unwrap();
    assert_eq!(diffuse(false).0, Vec3::new(0.0, 0.0, 1.0));
}

#[test]
#[cfg(feature = "png")]
fn a_texture_override_leaves_the_mtls_texture_undecoded() {
    let dir = tempfile::tempdir().unwrap();
    for (name, side) in [("big.png", 64), ("small.png", 2)] {
        image::RgbaImage::from_pixel(side, side, image::Rgba([9, 9, 9, 255]))
            .save(dir.path().join(name))
            .unwrap();
    }
    std::fs::write(dir.path().join("m.mtl"), "newmtl t\nmap_Kd big.png\n").unwrap();
    let obj = dir.path().join("m.obj");
    std::fs::write(
        &obj,
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl t\nf 1 2 3\n",
    )
    .unwrap();
    let mut scene = Scene::empty();
    let mut budget = TextureBudget::default();
    let small = dir.path().join("small.png");
    let options = LoadOptions::default();
    load_into(
        &mut scene,
        &obj,
        DMat4::IDENTITY,
        Some(&small),
        &options,
        &mut budget,
    )
    .unwrap();
    let mut expected = TextureBudget::default();
    expected.take(2, 2).unwrap();
    assert_eq!(
        budget.left(),
        expected.left(),
        "only the override's 2 × 2 taken"
    );
    let texture = scene.materials[0].diffuse_texture.as_ref().unwrap();
    assert_eq!(texture.image.dimensions(), (2, 2));
}

#[test]
#[cfg(feature = "png")]
fn textures_past_the_scenes_budget_are_left_out_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let mut mtl = String::new();
    let mut obj = String::from("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
    for i in 0..3 {
        image::RgbaImage::from_pixel(2, 2, image::Rgba([i * 100, 0, 0, 255]))
            .save(dir.path().join(format!("t{i}.png")))
            .unwrap();
        mtl += &format!("newmtl m{i}\nKd 1 1 1\nmap_Kd t{i}.png\n");
        obj += &format!("usemtl m{i}\nf 1 2 3\n");
    }
    std::fs::write(dir.path().join("m.mtl"), mtl).unwrap();
    std::fs::write(dir.path().join("m.obj"), obj).unwrap();
    let mut scene = Scene::empty();
    // Room for two 2 × 2 RGBA8 textures, not three.
    let mut budget = TextureBudget::with_left(2 * 16 + 15);
    let options = LoadOptions::default();
    let path = dir.path().join("m.obj");
    let report = load_into(
        &mut scene,
        &path,
        DMat4::IDENTITY,
        None,
        &options,
        &mut budget,
    )
    .unwrap();
    let textured: Vec<bool> = scene.materials[..3]
        .iter()
        .map(|m| m.diffuse_texture.is_some())
        .collect();
    assert_eq!(textured, [true, true, false]);
    assert_eq!(budget.left(), 15);
    let left_out: Vec<_> = report
        .warnings
        .iter()
        .filter(|w| w.contains("t2.png is left out"))
        .collect();
    assert_eq!(left_out.len(), 1, "{:?}", report.warnings);
}

#[test]
fn out_of_range_mtl_numbers_are_warnings_naming_the_statement() {
    let dir = tempfile::tempdir().unwrap();
    let mtl = "newmtl a\nNs nan\nd -5\nKd nan nan nan\nnewmtl b\nNs 1e308\nd nan\n\
               Ks nan 0.5 2000\nnewmtl c\nNs -1\nd 0.5\nKd 1e38 0 0\nKs 1e40 0 0\n\
               newmtl e\nNs 39.999996\nd 0.3\n";
    std::fs::write(dir.path().join("m.mtl"), mtl).unwrap();
    let mut obj = String::from("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
    for name in ["a", "b", "c", "e"] {
        obj += &format!("usemtl {name}\nf 1 2 3\n");
    }
    std::fs::write(dir.path().join("m.obj"), obj).unwrap();
    let (scene, report) = load(&dir.path().join("m.obj"));
    let kept: Vec<(f32, f32)> = scene.materials[..3]
        .iter()
        .map(|m| (m.shininess, m.alpha))
        .collect();
    assert_eq!(kept, [(1.0, 0.0), (MAX_SHININESS, 1.0), (0.0, 0.5)]);
    // A NaN colour component takes the default's (Kd 0.8, Ks 0), not black.
    assert_eq!(scene.materials[0].diffuse, Vec3::splat(0.8));
    let specular = scene.materials[1].specular;
    assert_eq!(specular, Vec3::new(0.0, 0.5, MAX_COLOR_FACTOR));
    assert!(scene.validate().is_ok());
    for said in [
        "`a`: Ns NaN",
        "`a`: d -5",
        "`a`: Kd [NaN, NaN, NaN] taken as [0.8, 0.8, 0.8]",
        "`b`: Ns 1e308",
        "`b`: d NaN",
        "`b`: Ks [NaN, 0.5, 2000] taken as [0, 0.5, 1024]",
        "`c`: Ns -1",
        "`c`: Kd [1e38, 0, 0] taken as [1024, 0, 0]",
        // Past f32 as written, not as the infinity f32 makes of it.
        "`c`: Ks [1e40, 0, 0] taken as [1024, 0, 0]",
    ] {
        assert!(
            report.warnings.iter().any(|w| w.contains(said)),
            "{said}: {:?}",
            report.warnings
        );
    }
    // Values within range written with more digits than f32 keeps (the Conference
    // room's MTL has 35) are taken as written, without a warning.
    assert!(
        !report.warnings.iter().any(|w| w.contains("`e`")),
        "{:?}",
        report.warnings
    );
}

/// `mtllib a.mtl b.mtl` names two libraries, as the format has it: both are read (a name
/// with a space that is one file is still read as one).
#[test]
fn one_mtllib_line_naming_several_libraries_reads_each() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("l0.mtl"), "newmtl red\nKd 1 0 0\n").unwrap();
    std::fs::write(dir.path().join("l1.mtl"), "newmtl green\nKd 0 1 0\n").unwrap();
    std::fs::write(dir.path().join("my lib.mtl"), "newmtl blue\nKd 0 0 1\n").unwrap();
    let obj = dir.path().join("m.obj");
    let tri =
        |m: &str, first: u32| format!("usemtl {m}\nf {} {} {}\n", first, first + 1, first + 2);
    let text = format!(
        "mtllib l0.mtl l1.mtl\nmtllib my lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n{}{}{}",
        tri("red", 1),
        tri("green", 1),
        tri("blue", 1)
    );
    std::fs::write(&obj, text).unwrap();
    let (scene, report) = load(&obj);
    let diffuse: Vec<Vec3> = (scene.objects.iter())
        .map(|o| scene.materials[o.material].diffuse)
        .collect();
    assert_eq!(
        diffuse,
        [Vec3::X, Vec3::Y, Vec3::Z],
        "{:?}",
        report.warnings
    );
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
}

/// A library that cannot be read is named as a name from a file is, cut after 64
/// characters: a line of the OBJ does not reach the message whole.
#[test]
fn an_unread_librarys_warning_names_the_obj_and_cuts_the_name() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("m.obj");
    let name = format!("{}.mtl", "x/".repeat(900));
    std::fs::write(
        &obj,
        format!("mtllib {name}\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
    )
    .unwrap();
    let (_, report) = load(&obj);
    let said = report
        .warnings
        .iter()
        .find(|w| w.contains("mtllib"))
        .unwrap_or_else(|| panic!("{:?}", report.warnings));
    assert!(said.starts_with(&obj.display().to_string()), "{said}");
    assert!(said.contains("characters more"), "{said}");
    assert!(said.len() < obj.display().to_string().len() + 300, "{said}");
}

/// A library in a folder of its own names its textures from there, as MTL files do: beside
/// itself, by `..` back into the model's folder, and (an exporter that wrote the OBJ's paths)
/// from the model's folder where its own has no such file. A `..` that climbs out of the
/// model's folder is still refused.
#[test]
fn a_library_in_a_subfolder_names_textures_from_its_own_folder() {
    let (_root, model) = model_beside_a_secret_library();
    for folder in ["mats", "tex"] {
        std::fs::create_dir(model.join(folder)).unwrap();
    }
    let image = |path: &Path, width| {
        image::RgbaImage::from_pixel(width, 1, image::Rgba([20, 200, 20, 255]))
            .save(path)
            .unwrap()
    };
    image(&model.join("mats/beside.png"), 1);
    image(&model.join("tex/wood.png"), 2);
    // In the model's folder too: a name is looked for from the library's folder first.
    image(&model.join("beside.png"), 3);
    image(&root_of(&model).join("out.png"), 4);
    let faces = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n";
    let width = |map_kd: &str| {
        std::fs::write(
            model.join("mats/l.mtl"),
            format!("newmtl m\nmap_Kd {map_kd}\n"),
        )
        .unwrap();
        let obj = model.join("m.obj");
        std::fs::write(&obj, format!("mtllib mats/l.mtl\n{faces}")).unwrap();
        let (scene, report) = load(&obj);
        let texture = scene.materials[0].diffuse_texture.as_ref();
        (texture.map(|t| t.image.dimensions().0), report.warnings)
    };
    assert_eq!(width("beside.png").0, Some(1), "beside the library");
    assert_eq!(
        width("..\\tex\\wood.png").0,
        Some(2),
        "back into the model's folder"
    );
    assert_eq!(width("tex/wood.png").0, Some(2), "from the model's folder");
    let (found, warnings) = width("../../out.png");
    assert_eq!(found, None);
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("outside the model's folder") && w.contains("`..` leads out")),
        "{warnings:?}"
    );
    let (found, warnings) = width("missing.png");
    assert_eq!(found, None);
    let said = "texture `missing.png` not found next to its library in";
    assert!(warnings.iter().any(|w| w.contains(said)), "{warnings:?}");
}

/// The folder a model folder from [`model_beside_a_secret_library`] lies in.
fn root_of(model: &Path) -> &Path {
    model.parent().unwrap()
}

/// tobj ends an object at a change of material too, and reads its faces' indices there: a
/// face naming a vertex defined after the `usemtl` is refused with the line and corner, where
/// tobj's own message names neither (the fuzzer's case).
#[test]
fn a_face_past_the_vertices_before_a_change_of_material_is_located() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("m.mtl"), "newmtl m\nKd 1 1 1\n").unwrap();
    let path = dir.path().join("d.obj");
    let obj = "mtllib m.mtl\nv 1 1 0\nv -1 1 0\nf 3 2 1\nusemtl m\nv -1 -1 0\n";
    std::fs::write(&path, obj).unwrap();
    let err = try_load(&path).unwrap_err().to_string();
    assert!(
        err.contains(
            "line 4: `f` corner 1: its vertex index is past the 2 defined before its \
             object ends (line 5)"
        ),
        "{err}"
    );
    // The same material named again ends nothing: the file loads.
    let obj = "mtllib m.mtl\nusemtl m\nv 1 1 0\nv -1 1 0\nf 3 2 1\nusemtl m\nv -1 -1 0\n";
    std::fs::write(&path, obj).unwrap();
    try_load(&path).unwrap();
}
