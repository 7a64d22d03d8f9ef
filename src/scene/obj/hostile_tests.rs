//! OBJ files written to make the loader read, warn or keep without end: each read and each
//! warning is bounded.

use super::tests::load;
use super::textures::TextureCache;
use crate::scene::texture_budget::TextureBudget;
use std::sync::Arc;

/// `mtllib` lines repeating a name, or naming thousands of libraries, warn a bounded number of
/// times; the library named before them is still read.
#[test]
fn mtllib_lines_without_end_warn_a_bounded_number_of_times() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("m.mtl"), "newmtl red\nKd 1 0 0\n").unwrap();
    let mut obj = String::from("mtllib m.mtl\n");
    obj += &"mtllib ../outside.mtl\n".repeat(1000);
    for i in 0..1000 {
        obj += &format!("mtllib missing{i}.mtl\n");
    }
    obj += "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n";
    let path = dir.path().join("m.obj");
    std::fs::write(&path, obj).unwrap();
    let (scene, report) = load(&path);
    let refused = report
        .warnings
        .iter()
        .filter(|w| w.contains("outside.mtl"))
        .count();
    assert_eq!(refused, 1, "{:?}", report.warnings);
    assert!(
        report.warnings.len() <= super::MAX_MTL_LIBRARIES + 4,
        "{} warnings",
        report.warnings.len()
    );
    assert!(report
        .warnings
        .iter()
        .any(|w| w.contains("material libraries named; the rest are not read")));
    assert_eq!(scene.materials[0].name, "red");
}

/// One texture file named through a link to the folder is decoded once; past what the
/// model's textures may read together, a texture is left out with a warning.
#[cfg(all(unix, feature = "png"))]
#[test]
fn a_texture_is_decoded_once_whatever_names_it_and_reads_are_bounded() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbaImage::from_pixel(2, 2, image::Rgba([9, 9, 9, 255]))
        .save(dir.path().join("t.png"))
        .unwrap();
    std::os::unix::fs::symlink(".", dir.path().join("d")).unwrap();
    let mut cache = TextureCache::default();
    let mut budget = TextureBudget::default();
    let mut warnings = Vec::new();
    let mut warn = |w: String| warnings.push(w);
    let names = ["t.png", "d/t.png", "d/d/t.png"];
    let loaded: Vec<_> = names
        .iter()
        .map(|n| {
            cache
                .load(&dir.path().join(n), None, &mut budget, &mut warn)
                .unwrap()
        })
        .collect();
    assert!(loaded.iter().all(|t| Arc::ptr_eq(t, &loaded[0])));
    let mut once = TextureBudget::default();
    once.take(2, 2).unwrap();
    assert_eq!(budget.left(), once.left(), "decoded once");

    let size = std::fs::metadata(dir.path().join("t.png")).unwrap().len();
    let mut cache = TextureCache::with_read_limit(size);
    std::fs::copy(dir.path().join("t.png"), dir.path().join("u.png")).unwrap();
    let mut budget = TextureBudget::default();
    assert!(cache
        .load(&dir.path().join("t.png"), None, &mut budget, &mut warn)
        .is_some());
    assert!(cache
        .load(&dir.path().join("u.png"), None, &mut budget, &mut warn)
        .is_none());
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("u.png is not read: the model's textures together")),
        "{warnings:?}"
    );
}

/// Each texture name is looked up once a load and each folder listed once, however many
/// names are missing from it; a name is matched folder by folder only so deep (past it, it
/// is found as written or by its bare file name).
#[cfg(unix)]
#[test]
fn texture_lookups_list_each_folder_once_and_match_so_deep() {
    use crate::scene::texture_names::{TextureFinder, MAX_MATCHED_COMPONENTS};
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path();
    std::fs::create_dir(base.join("sub")).unwrap();
    std::fs::write(base.join("sub").join("t.png"), b"x").unwrap();
    std::os::unix::fs::symlink(".", base.join("d")).unwrap();
    let want = Ok(Some(base.join("sub").join("t.png").canonicalize().unwrap()));
    let mut finder = TextureFinder::default();
    // What is found is kept as found (through the links): compared by the file it is.
    let mut find = |name: &str| {
        finder
            .find(base, "", name, false)
            .map(|found| found.map(|p| p.canonicalize().unwrap()))
    };
    let deep = |links: usize| format!("{}SUB/T.PNG", "d/".repeat(links));
    assert_eq!(find(&deep(MAX_MATCHED_COMPONENTS - 2)), want);
    assert_eq!(find(&deep(MAX_MATCHED_COMPONENTS - 1)), Ok(None));
    for i in 0..2000 {
        assert_eq!(find(&format!("Missing{i}.png")), Ok(None));
    }
    assert_eq!(find("Sub/T.png"), want, "found past 2 000 missing names");
    // The base folder (through every `d`, the same folder) and `sub`.
    assert_eq!(finder.listings.listed(), 2);
}

/// A polyline (`l`) of three points is not drawn as a filled triangle (tobj read it as one),
/// and lines and faces of fewer than three corners are named in one warning.
#[test]
fn lines_are_not_drawn_as_faces() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.obj");
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\n\
                f 1 2 3\nl 4 5 6\nl 4 5\nf 4\n";
    std::fs::write(&path, text).unwrap();
    let (scene, report) = load(&path);
    let triangles: usize = scene.objects.iter().map(|o| o.mesh.indices.len() / 3).sum();
    assert_eq!(triangles, 1);
    let said: Vec<_> = report
        .warnings
        .iter()
        .filter(|w| w.contains("3 lines (`l`) and faces of fewer than three corners"))
        .collect();
    assert_eq!(said.len(), 1, "{:?}", report.warnings);
    assert!(said[0].contains("line 8"), "{}", said[0]);
}

/// One line (`l`) is named in the singular.
#[test]
fn one_line_is_named_in_the_singular() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.obj");
    std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nl 1 2\n").unwrap();
    let (_, report) = load(&path);
    let said: Vec<_> = report
        .warnings
        .iter()
        .filter(|w| w.contains("(`l`)"))
        .collect();
    assert_eq!(said.len(), 1, "{:?}", report.warnings);
    assert!(
        said[0].contains("a line (`l`) or face of fewer than three corners (at line 5) is not"),
        "{}",
        said[0]
    );
}

/// A texture's link swapped, load after load, between an image in the model's folder and one
/// outside it: the outside image is never read. The look before opening follows the link as
/// it was; the check of the open handle sees where it leads then.
#[cfg(all(any(target_os = "linux", target_os = "android"), feature = "png"))]
#[test]
fn a_link_swapped_to_lead_out_of_the_folder_is_never_read() {
    let root = tempfile::tempdir().unwrap();
    let dir = root.path().join("model");
    std::fs::create_dir(&dir).unwrap();
    let image = |rgb: [u8; 3], path: std::path::PathBuf| {
        let [r, g, b] = rgb;
        image::RgbaImage::from_pixel(1, 1, image::Rgba([r, g, b, 255]))
            .save_with_format(path, image::ImageFormat::Png)
            .unwrap()
    };
    image([200, 0, 0], dir.join("inside.png"));
    image([0, 200, 0], root.path().join("outside.png"));
    std::fs::write(dir.join("m.mtl"), "newmtl m\nKd 1 1 1\nmap_Kd t.png\n").unwrap();
    let path = dir.join("m.obj");
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl m\nf 1/1 2/1 3/1\n";
    std::fs::write(&path, obj).unwrap();
    let (link, next) = (dir.join("t.png"), dir.join("next"));
    std::os::unix::fs::symlink("inside.png", &link).unwrap();
    let stop = Arc::new(std::sync::atomic::AtomicBool::new(false));
    let swapper = {
        let stop = stop.clone();
        std::thread::spawn(move || {
            while !stop.load(std::sync::atomic::Ordering::Relaxed) {
                for target in ["../outside.png", "inside.png"] {
                    std::os::unix::fs::symlink(target, &next).unwrap();
                    std::fs::rename(&next, &link).unwrap();
                }
            }
        })
    };
    let mut outcomes = [0; 2];
    for _ in 0..2000 {
        let (scene, _) = load(&path);
        match &scene.materials[0].diffuse_texture {
            Some(texture) => {
                assert_eq!(
                    texture.image.get_pixel(0, 0)[1],
                    0,
                    "the outside image was read"
                );
                outcomes[0] += 1;
            }
            None => outcomes[1] += 1,
        }
    }
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    swapper.join().unwrap();
    assert!(outcomes.iter().all(|&n| n > 0), "{outcomes:?}");
}
