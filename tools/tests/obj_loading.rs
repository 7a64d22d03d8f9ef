//! OBJ + MTL loading, on files the tests write (a box written like the Cornell box, a textured
//! model without normals, malformed files, textures named in other case): what the loader
//! promises. The real scenes of `$MANYLIGHT_ASSETS` render lit too, when it is set.

mod common;

use std::path::Path;

use common::files::write;
use common::{asset, Gpu};
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

/// Why the real-scene tests are ignored in a build without `MANYLIGHT_ASSETS`.
const NEEDS_ASSETS: &str = "needs the real scenes: set MANYLIGHT_ASSETS (scripts/fetch-assets)";

#[test]
#[cfg_attr(
    not(manylight_assets),
    ignore = "needs the real scenes: set MANYLIGHT_ASSETS (scripts/fetch-assets)"
)]
fn cornell_box_loads_and_renders_lit_on_es2_and_es3() {
    let path = asset("cornell-box/CornellBox-Original.obj");
    let (scene, report) = scene::load(path.to_str().unwrap(), Some((64, 3))).unwrap();
    // The file itself doubles two faces of `leftWall` and of `shortBox`: dropped, and said.
    let (duplicates, others): (Vec<_>, Vec<_>) = report
        .warnings
        .iter()
        .partition(|w| w.contains("duplicate triangles dropped"));
    // Its lamp's `Ke 17 12 4` is emission, which OBJ materials do not draw: said once (the
    // other materials' `Ke 0 0 0` are not).
    assert_eq!(others.len(), 1, "{others:?}");
    assert!(
        others[0].contains("MTL statements not applied: Ke (1 material)"),
        "{others:?}"
    );
    assert_eq!(duplicates.len(), 2, "{duplicates:?}");
    assert!(
        scene
            .materials
            .iter()
            .any(|m| m.diffuse.x > 0.5 && m.diffuse.y < 0.2),
        "red wall material from Kd"
    );
    assert_lit_on_es2_and_es3(&scene, "cornell box");
}

#[test]
#[cfg_attr(
    not(manylight_assets),
    ignore = "needs the real scenes: set MANYLIGHT_ASSETS (scripts/fetch-assets)"
)]
fn teapot_texture_is_bound_from_its_mtl() {
    let path = asset("teapot/teapot.obj");
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

#[test]
fn the_ignore_reason_names_the_variable_and_the_script() {
    // The attribute needs a literal; this keeps the two spellings from drifting apart.
    let source = include_str!("obj_loading.rs");
    let attribute = format!("ignore = \"{NEEDS_ASSETS}\"");
    assert_eq!(source.matches(&attribute).count(), 2, "{attribute}");
}

fn assert_lit_on_es2_and_es3(scene: &Scene, what: &str) {
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::new(es);
        let img = gpu.render(scene, 128, 128, &RenderOptions::default());
        let (mean, lit) = brightness(&img);
        // The automatic camera shows the whole model with a margin: a box seen from three
        // quarters covers about 40 % of a square frame, all of it lit.
        assert!(
            mean > 20.0 && lit > 0.3,
            "{es}: {what} too dark (mean {mean:.1}, lit {lit:.2})"
        );
    }
}

/// An open box written the way the Cornell box's files are (CRLF line ends, tab-separated
/// vertex lines, an emissive `Ke` the loader ignores, no normals): five inward-facing walls,
/// red on the left, green on the right.
const BOX_OBJ: &str = "# written by the test\r\nmtllib box.mtl\r\n\
v\t-1\t-1\t-1\r\nv\t1\t-1\t-1\r\nv\t1\t1\t-1\r\nv\t-1\t1\t-1\r\n\
v -1 -1 1\r\nv 1 -1 1\r\nv 1 1 1\r\nv -1 1 1\r\n\
usemtl white\r\nf 1 2 3 4\r\nf 1 5 6 2\r\nf 4 3 7 8\r\n\
usemtl red\r\nf 1 4 8 5\r\n\
usemtl green\r\nf 2 6 7 3\r\n";

const BOX_MTL: &str = "newmtl white\r\nKd 0.73 0.73 0.73\r\n\
newmtl red\r\nKd\t0.63 0.065 0.05\r\nKe 0 0 0\r\n\
newmtl green\r\nKd 0.14 0.45 0.091\r\nKe 0 0 0\r\n";

#[test]
fn a_box_written_like_the_cornell_box_loads_and_renders_lit_on_es2_and_es3() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "box.mtl", BOX_MTL);
    let path = write(dir.path(), "box.obj", BOX_OBJ);
    let (scene, report) = scene::load(path.to_str().unwrap(), Some((64, 3))).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    let diffuse = |name: &str| {
        scene
            .materials
            .iter()
            .find(|m| m.name == name)
            .unwrap_or_else(|| panic!("material {name}"))
            .diffuse
    };
    assert_eq!(diffuse("red"), glam::Vec3::new(0.63, 0.065, 0.05));
    assert_eq!(diffuse("green"), glam::Vec3::new(0.14, 0.45, 0.091));
    let triangles: usize = scene.objects.iter().map(|o| o.mesh.indices.len() / 3).sum();
    assert_eq!(triangles, 10, "five quads triangulated");
    assert_lit_on_es2_and_es3(&scene, "generated box");
}

/// An octahedron with texture coordinates and no normals, its MTL naming a PNG.
fn write_textured_octahedron(dir: &Path) -> std::path::PathBuf {
    image::RgbaImage::from_pixel(8, 8, image::Rgba([40, 60, 230, 255]))
        .save(dir.join("blue.png"))
        .unwrap();
    write(
        dir,
        "oct.mtl",
        "newmtl painted\nKd 1 1 1\nmap_Kd blue.png\n",
    );
    write(
        dir,
        "oct.obj",
        "mtllib oct.mtl\nv 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
         vt 0 0\nvt 1 0\nvt 0.5 1\nusemtl painted\n\
         f 1/1 3/2 5/3\nf 3/1 2/2 5/3\nf 2/1 4/2 5/3\nf 4/1 1/2 5/3\n\
         f 3/1 1/2 6/3\nf 2/1 3/2 6/3\nf 4/1 2/2 6/3\nf 1/1 4/2 6/3\n",
    )
}

#[test]
fn a_textured_model_without_normals_gets_its_texture_and_outward_normals() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_textured_octahedron(dir.path());
    let (mut scene, report) = scene::load(path.to_str().unwrap(), Some((16, 1))).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    let painted = scene
        .materials
        .iter()
        .find(|m| m.name == "painted")
        .unwrap();
    let texture = painted.diffuse_texture.as_ref().expect("blue.png bound");
    assert_eq!(texture.image.dimensions(), (8, 8));
    for object in &scene.objects {
        let mesh = &object.mesh;
        assert_eq!(mesh.normals.len(), mesh.positions.len(), "normals computed");
        // The octahedron is centred on the origin: every computed normal points away from it.
        for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
            assert!((n.length() - 1.0).abs() < 1e-4, "unit normal {n}");
            assert!(n.dot(*p) > 0.0, "normal {n} at {p} points inwards");
        }
    }
    // Lit by ambient only, the visible surface takes the texture's colour.
    scene.lights.clear();
    scene.ambient = glam::Vec3::ONE;
    let mut gpu = Gpu::new(EsVersion::Es2);
    let opts = RenderOptions {
        linear: true,
        ..RenderOptions::default()
    };
    let img = gpu.render(&scene, 64, 64, &opts);
    // Textures are sRGB-encoded and the linear output is not: decode them the sRGB way.
    let decoded = |c: f64| {
        let c = c / 255.0;
        let linear = if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        };
        linear * 255.0
    };
    let p = img.get_pixel(32, 32);
    for (channel, stored) in [40.0, 60.0, 230.0].into_iter().enumerate() {
        let expected = decoded(stored);
        assert!(
            (p[channel] as f64 - expected).abs() <= 2.0,
            "channel {channel}: expected {expected:.1} from the texture, got {p:?}"
        );
    }
}

fn load_obj(path: &Path) -> Result<(Scene, scene::LoadReport), SceneError> {
    let mut scene = Scene::empty();
    let options = manylight::LoadOptions::default();
    let mut textures = manylight::scene::texture_budget::TextureBudget::default();
    let report = obj::load_into(
        &mut scene,
        path,
        DMat4::IDENTITY,
        None,
        &options,
        &mut textures,
    )?;
    Ok((scene, report))
}

#[test]
fn malformed_obj_files_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "garbage.obj",
            "v 1 2 three\nf 1 2 3\n",
            "line 1: `v` needs 3 numbers",
        ),
        (
            "oob.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
            "line 4: `f` corner 3: its vertex index is not one of the 3",
        ),
        (
            "word.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 three\n",
            "line 4: `f` corner 3: its vertex index is not a whole number",
        ),
        (
            "past_i64.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n",
            "line 4: `f` corner 3: its vertex index is not one of the 3",
        ),
        (
            "vt.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/-3 3/1\n",
            "corner 2: its texture coordinate index",
        ),
        (
            "nan.obj",
            "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            "line 1: `v` number 1: not a finite number",
        ),
        // Finite as written, infinite as tobj's f32: named by line, not as `inf` later.
        (
            "huge.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1e39 0\nf 1 2 3\n",
            "line 3: `v` number 2: not a finite number within f32's range",
        ),
        // A trailing backslash (no line continuation in tobj): its "position parse error"
        // named no line.
        (
            "continued.obj",
            "v 0 0 0\nv 1 0 0 \\\nv 0 1 0\nf 1 2 3\n",
            "line 2: `v` w (the 4th value) is not a number",
        ),
        // A normal index past i64 in a file with no normals: tobj's "face parse error"
        // named no line.
        (
            "wide.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//99999999999999999999 2 3\n",
            "line 4: `f` corner 1: its normal index",
        ),
        ("empty.obj", "# nothing here\n", "no faces"),
    ];
    for (name, text, needle) in cases {
        let path = write(dir.path(), name, text);
        let err = load_obj(&path).expect_err(name).to_string();
        assert!(err.contains(name), "error should name the file: {err}");
        assert!(
            err.to_lowercase().contains(&needle.to_lowercase()),
            "{name}: expected `{needle}` in: {err}"
        );
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

/// MTL factors beyond what the fp16 colour tier holds (they turned the lit surface black):
/// clamped with a warning naming the material and key, and the surface renders lit and finite.
#[test]
fn material_factors_beyond_fp16_are_clamped_with_a_warning_and_render_lit() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "hot.mtl",
        "newmtl hot\nKd 30000 30000 30000\nKs 1e20 1e20 1e20\nNs 10\n",
    );
    let path = write(
        dir.path(),
        "hot.obj",
        "mtllib hot.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nusemtl hot\nf 1 2 3 4\n",
    );
    let (scene, report) = scene::load(path.to_str().unwrap(), Some((8, 2))).unwrap();
    assert_eq!(report.warnings.len(), 2, "{:?}", report.warnings);
    assert!(report.warnings.iter().all(|w| w.contains("`hot`")));
    let hot = &scene.materials[0];
    assert_eq!(hot.diffuse, glam::Vec3::splat(1024.0));
    assert_eq!(hot.specular, glam::Vec3::splat(1024.0));
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::new(es);
        let img = gpu.render(&scene, 64, 64, &RenderOptions::default());
        // Ambient alone (0.02 × 1024) saturates the surface: its middle is white, not black.
        let centre = img.get_pixel(32, 32);
        assert!(
            centre.0[..3].iter().all(|&c| c >= 250),
            "{es}: the surface went dark: {centre:?}"
        );
        let (hdr, _) = gpu
            .r()
            .render_offscreen_hdr(&scene, 64, 64, &RenderOptions::default())
            .unwrap();
        assert!(
            hdr.iter().flatten().all(|v| v.is_finite()),
            "{es}: NaN or Inf in the frame"
        );
    }
}

/// A PNG whose header claims 100 000 × 100 000 pixels (a decompression bomb, or a texture far
/// past any GPU's limit) is refused from its header: a warning and the flat colour, at once.
#[test]
fn a_texture_claiming_a_huge_size_is_refused_from_its_header() {
    let dir = tempfile::tempdir().unwrap();
    // A real 1×1 PNG, its IHDR rewritten to 100 000 × 100 000 (and its CRC fixed).
    let mut png = Vec::new();
    image::RgbaImage::from_pixel(1, 1, image::Rgba([9, 9, 9, 255]))
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let ihdr = 8 + 4; // signature, chunk length
    png[ihdr + 4..ihdr + 8].copy_from_slice(&100_000u32.to_be_bytes());
    png[ihdr + 8..ihdr + 12].copy_from_slice(&100_000u32.to_be_bytes());
    let crc = crc32(&png[ihdr..ihdr + 4 + 13]);
    png[ihdr + 4 + 13..ihdr + 4 + 17].copy_from_slice(&crc.to_be_bytes());
    std::fs::write(dir.path().join("bomb.png"), &png).unwrap();
    write(
        dir.path(),
        "m.mtl",
        "newmtl m\nKd 0.5 0.5 0.5\nmap_Kd bomb.png\n",
    );
    let path = write(
        dir.path(),
        "t.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n",
    );
    // The warning names the limit: the header was refused before any decoding (a decode would
    // allocate 40 GB and fail with the image crate's own error instead).
    let (scene, report) = load_obj(&path).unwrap();
    assert_eq!(report.warnings.len(), 1, "{:?}", report.warnings);
    assert!(
        report.warnings[0].contains("bomb.png"),
        "{:?}",
        report.warnings
    );
    assert!(
        report.warnings[0].contains("limit"),
        "{:?}",
        report.warnings
    );
    assert!(scene.materials[0].diffuse_texture.is_none());
}

/// CRC-32 (ISO-HDLC, as PNG chunks use), bit by bit: small and only for the test above.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xFFFF_FFFFu32;
    for &b in bytes {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// What tobj accepts, the pre-checks accept too: faces before their vertices, texture and
/// normal indices in a file that has none, `p` lines; and TGA textures, which have no magic
/// bytes, decode by their extension.
#[test]
fn files_tobj_accepts_are_not_refused_by_the_checks() {
    let dir = tempfile::tempdir().unwrap();
    let tga = image::DynamicImage::ImageRgba8(image::RgbaImage::from_pixel(
        2,
        2,
        image::Rgba([10, 200, 30, 255]),
    ));
    tga.save(dir.path().join("grass.tga")).unwrap();
    write(
        dir.path(),
        "m.mtl",
        "newmtl m\nKd 1 1 1\nmap_Kd grass.tga\n",
    );
    let path = write(
        dir.path(),
        "lenient.obj",
        "mtllib m.mtl\nmtllib m.mtl\nusemtl m\np 1\nf 1/1/1 2/2/2 3/3/3\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf -3 -2 -1\n",
    );
    let (scene, report) = load_obj(&path).unwrap();
    // Its faces' texture indices name none (the file has no `vt`): only that is said.
    let said = &report.warnings;
    assert!(
        said.len() == 1 && said[0].contains("no texture coordinates (`vt`)"),
        "{said:?}"
    );
    let triangles: usize = scene.objects.iter().map(|o| o.mesh.indices.len() / 3).sum();
    assert_eq!(triangles, 2);
    assert!(
        scene.materials.iter().any(|m| m.diffuse_texture.is_some()),
        "grass.tga bound"
    );
}

/// The JPEG checks walk a file's segments as the decoder does and refuse one the two read
/// apart: files from a real encoder (libjpeg-turbo 2.1's `cjpeg` of a 64×48 gradient:
/// `-progressive`, `-progressive -restart 1B`, `-grayscale -progressive`, `-restart 1`) must
/// pass them and load at their size, with no warning.
#[test]
fn jpegs_from_a_real_encoder_pass_the_checks() {
    let images = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/images");
    for name in [
        "progressive_420.jpg",
        "progressive_restarts.jpg",
        "progressive_grey.jpg",
        "baseline_restarts.jpg",
    ] {
        let dir = tempfile::tempdir().unwrap();
        std::fs::copy(images.join(name), dir.path().join(name)).unwrap();
        write(
            dir.path(),
            "m.mtl",
            format!("newmtl m\nKd 1 1 1\nmap_Kd {name}\n"),
        );
        let path = write(
            dir.path(),
            "q.obj",
            "mtllib m.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n\
             f 1/1 2/2 3/3\n",
        );
        let (scene, report) = load_obj(&path).unwrap();
        assert!(report.warnings.is_empty(), "{name}: {:?}", report.warnings);
        let texture = scene.materials[0].diffuse_texture.as_ref();
        let size = texture.map(|t| t.image.dimensions());
        assert_eq!(size, Some((64, 48)), "{name}");
    }
}

#[test]
fn a_latin1_name_loads_with_a_warning_and_cr_only_lines_load_as_lf_ones() {
    let dir = tempfile::tempdir().unwrap();
    let lf = "mtllib m.mtl\no quad\nusemtl red\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    std::fs::write(dir.path().join("m.mtl"), "newmtl red\nKd 1 0 0\n").unwrap();
    let (want, report) = load_obj(&write(dir.path(), "lf.obj", lf)).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    // Old Mac line ends: a lone CR ends a line, in the OBJ and in its MTL.
    std::fs::write(dir.path().join("cr.mtl"), "newmtl red\rKd 1 0 0\r").unwrap();
    let cr = lf.replace("m.mtl", "cr.mtl").replace('\n', "\r");
    let (got, report) = load_obj(&write(dir.path(), "cr.obj", &cr)).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    assert_eq!(got.objects.len(), want.objects.len());
    assert_eq!(
        got.objects[0].mesh.positions,
        want.objects[0].mesh.positions
    );
    assert_eq!(got.objects[0].mesh.indices, want.objects[0].mesh.indices);
    assert_eq!(got.materials[0].diffuse, want.materials[0].diffuse);
    // A UTF-8 byte-order mark before `mtllib` and before `newmtl`: the material still loads.
    std::fs::write(dir.path().join("bom.mtl"), "\u{feff}newmtl red\nKd 1 0 0\n").unwrap();
    let bom = format!("\u{feff}{}", lf.replace("m.mtl", "bom.mtl"));
    let (got, report) = load_obj(&write(dir.path(), "bom.obj", &bom)).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    assert_eq!(got.materials[0].diffuse, want.materials[0].diffuse);
    // A Latin-1 object name (`é` as the single byte 0xE9): loaded, with a warning.
    let mut latin1 = lf.replace("o quad", "o caf\u{1}").into_bytes();
    let at = latin1.iter().position(|&b| b == 1).unwrap();
    latin1[at] = 0xE9;
    let path = dir.path().join("latin1.obj");
    std::fs::write(&path, &latin1).unwrap();
    let (got, report) = load_obj(&path).unwrap();
    assert_eq!(
        got.objects[0].mesh.positions,
        want.objects[0].mesh.positions
    );
    assert!(
        report.warnings.iter().any(|w| w.contains("not UTF-8")),
        "{:?}",
        report.warnings
    );
}

#[test]
fn obj_and_mtl_errors_do_not_show_the_files_text() {
    let dir = tempfile::tempdir().unwrap();
    let secret = "hunter2-secret";
    for (name, text) in [
        ("word.obj", format!("v 1 2 {secret}\nf 1 1 1\n")),
        (
            "face.obj",
            format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 {secret}\n"),
        ),
    ] {
        let err = load_obj(&write(dir.path(), name, &text))
            .unwrap_err()
            .to_string();
        assert!(err.contains("line ") && !err.contains(secret), "{err}");
    }
}

/// A texture that is a folder in the model's folder is named as not a file; a device
/// (`/dev/zero`) lies outside it and is refused as such. Both keep the flat colour.
#[cfg(unix)]
#[test]
fn a_texture_that_is_a_folder_or_a_device_is_named_so_and_the_flat_colour_kept() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("maps")).unwrap();
    std::fs::write(
        dir.path().join("m.mtl"),
        "newmtl red\nKd 1 0 0\nmap_Kd maps\nnewmtl zero\nKd 1 0 0\nmap_Kd /dev/zero\n",
    )
    .unwrap();
    let obj =
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\nusemtl zero\nf 1 3 2\n";
    let (scene, report) = load_obj(&write(dir.path(), "d.obj", obj)).unwrap();
    let warned = |needles: &[&str]| {
        report
            .warnings
            .iter()
            .any(|w| needles.iter().all(|n| w.contains(n)))
    };
    assert!(
        warned(&["`maps`", "not a regular file"]),
        "{:?}",
        report.warnings
    );
    assert!(
        warned(&["/dev/zero", "outside the model's folder"]),
        "{:?}",
        report.warnings
    );
    assert!(scene.materials[..2]
        .iter()
        .all(|m| m.diffuse_texture.is_none()));
}

#[test]
fn mtl_statements_the_blinn_phong_material_cannot_apply_are_named_once() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "pbr.mtl",
        "newmtl a\nKd 0.5 0.5 0.5\nmap_Bump n.png\nPr 0.4\nPm 1\nKe 0 0 0\nnewmtl b\nKd 1 0 0\nPr 0.2\nKe 2 1 0\n",
    );
    let obj = write(
        dir.path(),
        "pbr.obj",
        "mtllib pbr.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\nusemtl b\nf 1 3 2\n",
    );
    let (_, report) = load_obj(&obj).unwrap();
    let notes: Vec<_> = report
        .warnings
        .iter()
        .filter(|w| w.contains("MTL statements not applied"))
        .collect();
    assert_eq!(notes.len(), 1, "{:?}", report.warnings);
    for part in [
        "bump/map_Bump (1 material)",
        "Pr (2 materials)",
        "Pm (1 material)",
    ] {
        assert!(notes[0].contains(part), "{part}: {}", notes[0]);
    }
    // Material a's `Ke 0 0 0` changes nothing; b's emission is counted.
    assert!(notes[0].contains("Ke (1 material)"), "{}", notes[0]);
    // A plain Blinn-Phong MTL says nothing of the kind.
    write(
        dir.path(),
        "plain.mtl",
        "newmtl a\nKd 0.5 0.5 0.5\nKs 0.2 0.2 0.2\nNs 20\n",
    );
    let plain = write(
        dir.path(),
        "plain.obj",
        "mtllib plain.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n",
    );
    let (_, report) = load_obj(&plain).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
}

/// A model whose every material is fully transparent would render the background alone: the
/// load says so rather than leaving a blank frame unexplained. One visible object is enough.
#[test]
fn a_model_drawn_fully_transparent_is_warned_of() {
    let dir = tempfile::tempdir().unwrap();
    let mtl = "newmtl glass\nKd 1 1 1\nd 0\nnewmtl stone\nKd 1 1 1\n";
    write(dir.path(), "m.mtl", mtl);
    let faces = |names: &[&str]| {
        let mut obj = String::from("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
        for name in names {
            obj += &format!("usemtl {name}\nf 1 2 3\n");
        }
        obj
    };
    let warned = |obj: String| {
        let path = write(dir.path(), "m.obj", &obj);
        let (_, report) = scene::load(path.to_str().unwrap(), None).unwrap();
        report
            .warnings
            .iter()
            .any(|w| w.contains("fully transparent"))
    };
    assert!(warned(faces(&["glass"])));
    assert!(!warned(faces(&["glass", "stone"])));
}

/// Faces whose corners name texture coordinates and normals in some places and not in others
/// (valid OBJ) load with a warning: every vertex keeps the coordinate and normal its corner
/// names, the others take (0, 0) and their face's normal. tobj alone left the coordinates
/// out of line with the vertices ("3 texture coordinates for 6 vertices").
#[test]
fn faces_with_and_without_texture_coordinates_in_one_object_load() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "mixed.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0.25 0.5\nvt 0.75 0.5\nvt 0.25 1\n\
         vn 0 0 -1\nf 1/1/1 2/2/1 3/3/1\nf 2 4 3\n",
    );
    let (scene, report) = load_obj(&path).unwrap();
    assert!(
        report.warnings.iter().any(|w| w.contains("mixed.obj")
            && w.contains("some face corners name a texture coordinate or normal")),
        "{:?}",
        report.warnings
    );
    let mesh = &scene.objects[0].mesh;
    assert_eq!(mesh.uvs.len(), mesh.positions.len());
    assert_eq!(mesh.normals.len(), mesh.positions.len());
    let centre = mesh.positions.iter().sum::<glam::Vec3>() / mesh.positions.len() as f32;
    for ((p, uv), n) in mesh.positions.iter().zip(&mesh.uvs).zip(&mesh.normals) {
        // Stored about the object's centre, with v flipped (images store row 0 at the top).
        let at = (*p - centre + glam::Vec3::new(0.5, 0.5, 0.0)).round();
        let textured = match (at.x, at.y) {
            (0.0, 0.0) => Some([0.25, 0.5]),
            (1.0, 0.0) => Some([0.75, 0.5]),
            (0.0, 1.0) => Some([0.25, 0.0]),
            _ => None,
        };
        match textured {
            // The first face's corners: as written, and the file's normal (facing −z).
            Some(expected) if n.z < 0.0 => assert_eq!(uv.to_array(), expected, "{at}"),
            // The second face's: (0, 0) flipped, and the face's own normal (+z, its winding).
            _ => {
                assert_eq!(uv.to_array(), [0.0, 1.0], "{at}");
                assert!((*n - glam::Vec3::Z).length() < 1e-6, "{at}: {n}");
            }
        }
    }
}

/// A model so small (a box of 2·10⁻⁵) that the random lights fitted to it have radii below the
/// distance the shaders leave out around a light (2⁻¹³): they light nothing, and the loader
/// says so rather than leaving a dark frame unexplained. A box of 6·10⁻³ (under 64 · 2⁻¹³)
/// has lights that reach further, but a light near it leaves a fair part of it unlit: said
/// too. At 10⁻² and at 2 units, neither.
#[test]
fn models_too_small_for_the_distance_left_out_around_lights_are_named_at_load() {
    let dir = tempfile::tempdir().unwrap();
    let scaled = |s: f64| {
        let line = |l: &str| {
            let mut words = l.split_whitespace();
            if words.next() != Some("v") {
                return format!("{l}\n");
            }
            let v: Vec<String> = words
                .map(|x| (x.parse::<f64>().unwrap() * s).to_string())
                .collect();
            format!("v {}\n", v.join(" "))
        };
        BOX_OBJ.lines().map(line).collect::<String>()
    };
    write(dir.path(), "box.mtl", BOX_MTL);
    // (scale, lights named as lighting nothing, model named as tiny)
    for (scale, unlit, tiny) in [
        (1.0, false, false),
        (5e-3, false, false),
        (3e-3, false, true),
        (1e-5, true, false),
    ] {
        let path = write(dir.path(), "box.obj", scaled(scale));
        let (scene, report) = scene::load(path.to_str().unwrap(), Some((64, 3))).unwrap();
        let radius = scene.lights.iter().map(|l| l.radius).fold(0.0, f32::max);
        let said = |what: &str| report.warnings.iter().any(|w| w.contains(what));
        let at = format!("scale {scale:e}, radii up to {radius:e}: {report:?}");
        assert_eq!(said("light nothing"), unlit, "{at}");
        assert_eq!(said("the model is"), tiny, "{at}");
    }
}

/// Each OBJ object with faces (after `o`, `g` or a change of material) is a mesh of its own:
/// more than `MAX_SCENE_MESHES` of them is refused before parsing, naming the line where the
/// first one past the limit begins. Repeating the current material splits nothing.
#[test]
fn more_objects_than_the_mesh_limit_are_refused_naming_the_line() {
    use manylight::scene::MAX_SCENE_MESHES;
    let dir = tempfile::tempdir().unwrap();
    let n = MAX_SCENE_MESHES + 1;
    let mut text = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    for i in 0..n {
        text += &format!("o part{i}\nf 1 2 3\n");
    }
    let err = load_obj(&write(dir.path(), "groups.obj", &text))
        .unwrap_err()
        .to_string();
    // Three vertex lines, then two lines per object: the last object's face.
    let line = 3 + 2 * n;
    assert!(
        err.contains(&format!("line {line}:")) && err.contains(&MAX_SCENE_MESHES.to_string()),
        "{err}"
    );
    let mut same = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\no one\n");
    for _ in 0..n {
        same += "usemtl m\nf 1 2 3\n";
    }
    let (scene, _) = load_obj(&write(dir.path(), "one.obj", &same)).unwrap();
    assert_eq!(scene.objects.len(), 1);
}

/// `usemtl` naming a material no library defines draws its faces in the default grey: said,
/// with how many names and the first line, not the names (the file's text).
#[test]
fn usemtl_naming_an_undefined_material_is_warned_of() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "m.mtl", "newmtl red\nKd 0.9 0.1 0.1\n");
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n\
               usemtl nosuch\nf 1 3 2\nusemtl other\nf 3 2 1\nusemtl nosuch\nf 2 1 3\n";
    let (_, report) = load_obj(&write(dir.path(), "u.obj", obj)).unwrap();
    let warning = report
        .warnings
        .iter()
        .find(|w| w.contains("defined by no material library"))
        .unwrap_or_else(|| panic!("{:?}", report.warnings));
    assert!(
        warning.contains("2 material names") && warning.contains("line 7"),
        "{warning}"
    );
    assert!(!warning.contains("nosuch"), "{warning}");
    let defined = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n";
    let (_, report) = load_obj(&write(dir.path(), "d.obj", defined)).unwrap();
    assert!(
        !report
            .warnings
            .iter()
            .any(|w| w.contains("no material library")),
        "{:?}",
        report.warnings
    );
}

/// A library's materials no face uses are not kept, and their textures are not even looked
/// for (a missing one is not warned of); the face's material is the one it names.
#[test]
fn only_the_materials_faces_use_are_kept() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "m.mtl",
        "newmtl unused\nKd 0 1 0\nmap_Kd gone.png\nnewmtl red\nKd 0.9 0.1 0.1\n\
         newmtl also_unused\nKd 0 0 1\n",
    );
    let path = write(
        dir.path(),
        "tri.obj",
        "mtllib m.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nusemtl red\nf 1 2 3\n",
    );
    let (scene, report) = load_obj(&path).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    let names: Vec<&str> = scene.materials.iter().map(|m| m.name.as_str()).collect();
    assert!(
        !names.contains(&"unused") && !names.contains(&"also_unused"),
        "{names:?}"
    );
    let material = &scene.materials[scene.objects[0].material];
    assert_eq!((material.name.as_str(), material.diffuse.x), ("red", 0.9));
}

/// 1.1 million `newmtl` lines (16 MB) took 1.1 GB: a library that takes the libraries past
/// 65 536 materials together is refused naming its line; the ones before it stay.
#[test]
fn material_libraries_past_the_material_limit_are_refused_by_line() {
    let dir = tempfile::tempdir().unwrap();
    let limit = manylight::scene::obj::MAX_OBJ_MATERIALS;
    let half: String = (0..limit / 2).map(|i| format!("newmtl a{i}\n")).collect();
    write(dir.path(), "a.mtl", &half);
    let rest: String = (0..limit / 2 + 1)
        .map(|i| format!("newmtl b{i}\n"))
        .collect();
    write(dir.path(), "b.mtl", &rest);
    let obj = "mtllib a.mtl\nmtllib b.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nusemtl a0\nf 1 2 3\n";
    let path = write(dir.path(), "tri.obj", obj);
    let (scene, report) = load_obj(&path).unwrap();
    let all = report.warnings.join("\n");
    assert!(
        all.contains("b.mtl") && all.contains(&format!("line {}", limit / 2 + 1)),
        "{all}"
    );
    // What the first library defined stays the face's.
    assert_eq!(scene.materials[scene.objects[0].material].name, "a0");
    // One library within the limit loads.
    let path = write(dir.path(), "one.obj", obj.replace("mtllib b.mtl\n", ""));
    let (scene, report) = load_obj(&path).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    assert_eq!(scene.materials[scene.objects[0].material].name, "a0");
}

/// Vertex colours on some `v` lines only: tobj failed a face using one without ("face vertex
/// color index out of bounds", no line named). They are taken off with a warning naming the
/// lines, and the model loads.
#[test]
fn vertex_colours_on_some_positions_only_are_ignored_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "tri.obj",
        "v -1 -1 0 1 0 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n",
    );
    let (scene, report) = load_obj(&path).unwrap();
    assert_eq!(scene.objects.len(), 1);
    let all = report.warnings.join("\n");
    assert!(
        all.contains("vertex colours on some `v` lines only (line 1 has one, line 2 none)"),
        "{all}"
    );
}

/// OBJ's `vt u` (its v 0): tobj needs two numbers and refused the file; it loads, with the
/// coordinate (u, 0) (flipped to (u, 1) for the image's rows).
#[test]
fn a_texture_coordinate_of_one_number_has_v_zero() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "tri.obj",
        "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0.25\nvt 0.5 0.5\nf 1/1 2/2 3/2\n",
    );
    let (scene, report) = load_obj(&path).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    let uvs = &scene.objects[0].mesh.uvs;
    assert!(uvs.contains(&glam::Vec2::new(0.25, 1.0)), "{uvs:?}");
}
