//! MTL `map_Kd` options are applied: `-clamp on` draws one copy of the image, `-s` and `-o`
//! scale and move the texture coordinates, and a file name after the options may hold
//! spaces; with every method on ES 2.0 and 3.0. Four quads read one 2 × 2 image over OBJ
//! texture coordinates from −1 to 2; every pixel away from a texel's edge shows the texel the
//! test works out from the MTL format's reading of the options.

use crate::common;
use crate::texel_quads::{self, texel_at, wrapped, H, TEXELS, W};

use glam::DVec3;
use manylight::sampling::Wrap;
use manylight::scene::{Camera, Projection};
use std::sync::Arc;

/// Each quad's `map_Kd` (left to right, then top to bottom) and what the test reads from it:
/// (clamp, scale, offset) of OBJ's coordinates (v up).
const QUADS: [(&str, bool, [f64; 2], [f64; 2]); 4] = [
    ("-clamp on tex.png", true, [1.0, 1.0], [0.0, 0.0]),
    (
        "-s 2 1.5 1 -o 0.25 0.5 0 tex.png",
        false,
        [2.0, 1.5],
        [0.25, 0.5],
    ),
    (
        "-clamp on -s 0.5 0.5 -o 0.25 0.25 my texels.png",
        true,
        [0.5, 0.5],
        [0.25, 0.25],
    ),
    ("my texels.png", false, [1.0, 1.0], [0.0, 0.0]),
];

fn save_image(path: &std::path::Path) {
    texel_quads::image()
        .save_with_format(path, image::ImageFormat::Png)
        .unwrap();
}

/// The model's folder: the OBJ (four quads facing +Z, texture coordinates from (−1, −1) at
/// the bottom left to (2, 2) at the top right), its MTL and the image under two names.
fn model() -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    save_image(&dir.path().join("tex.png"));
    save_image(&dir.path().join("my texels.png"));
    let mut mtl = String::new();
    let mut obj = String::from("mtllib m.mtl\nvt -1 -1\nvt 2 -1\nvt 2 2\nvt -1 2\nvn 0 0 1\n");
    for (q, (statement, ..)) in QUADS.iter().enumerate() {
        mtl += &format!("newmtl q{q}\nKd 1 1 1\nmap_Kd {statement}\n");
        let (x0, y0, x1, y1) = texel_quads::quad_corners(q);
        for (x, y) in [(x0, y0), (x1, y0), (x1, y1), (x0, y1)] {
            obj += &format!("v {x} {y} 0\n");
        }
        let v = 4 * q + 1;
        obj += &format!(
            "usemtl q{q}\nf {}/1/1 {}/2/1 {}/3/1 {}/4/1\n",
            v,
            v + 1,
            v + 2,
            v + 3
        );
    }
    std::fs::write(dir.path().join("m.mtl"), mtl).unwrap();
    let path = dir.path().join("m.obj");
    std::fs::write(&path, obj).unwrap();
    (dir, path)
}

#[test]
fn map_kd_options_clamp_scale_and_move_the_texture_with_every_method() {
    let (_dir, path) = model();
    let (mut scene, report) = common::files::load(&path).unwrap();
    assert!(
        report.warnings.is_empty(),
        "warnings: {:?}",
        report.warnings
    );
    scene.camera = Camera {
        position: DVec3::new(0.0, 0.0, 1.0),
        target: DVec3::ZERO,
        up: DVec3::Y,
        projection: Projection::Orthographic {
            height: 2.0,
            near: 0.1,
            far: 10.0,
        },
    };
    common::each_method_showing_colours(&scene, W, H, |es, method, _, img| {
        let mut checked = [0usize; 4];
        for (x, y, p) in img.enumerate_pixels() {
            let Some((q, u, t)) = texel_quads::quad_and_uv(x, y) else {
                continue;
            };
            // OBJ's v runs up.
            let v = 1.0 - t;
            let (_, clamp, [su, sv], [ou, ov]) = QUADS[q];
            let wrap = if clamp {
                Wrap::ClampToEdge
            } else {
                Wrap::Repeat
            };
            let (wu, edge_u) = wrapped(su * u + ou, wrap);
            // Rows from the image's top: 1 − v.
            let (wt, edge_t) = wrapped(1.0 - (sv * v + ov), wrap);
            // Within a quarter texel of an edge the linear filter blends.
            if edge_u.min(edge_t) < 0.25 {
                continue;
            }
            assert_eq!(
                common::texel_shown(p, &TEXELS),
                Some(texel_at(wu, wt)),
                "{es} {method}: pixel ({x}, {y}) of quad {q} at uv ({u:.3}, {v:.3}) is {p:?}"
            );
            checked[q] += 1;
        }
        assert!(
            checked.iter().all(|&n| n > 500),
            "{es} {method}: pixels checked per quad {checked:?}"
        );
    });
}

/// A clamped texture shares the image of a repeating one on the same file (uploaded once).
#[test]
fn a_clamped_texture_shares_the_repeating_ones_image() {
    let (_dir, path) = model();
    let (scene, _) = common::files::load(&path).unwrap();
    let texture = |q: usize| {
        let name = format!("q{q}");
        let material = scene.materials.iter().find(|m| m.name == name).unwrap();
        material.diffuse_texture.clone().unwrap()
    };
    let (clamped, repeating) = (texture(0), texture(1));
    assert_eq!(clamped.sampling.wrap_u, Wrap::ClampToEdge);
    assert_eq!(clamped.sampling.wrap_v, Wrap::ClampToEdge);
    assert_eq!(repeating.sampling.wrap_u, Wrap::Repeat);
    assert!(Arc::ptr_eq(&clamped.image, &repeating.image));
}

/// Options the material cannot apply and an unusable transform are warnings; the texture is
/// still drawn, untransformed.
#[test]
fn unapplied_options_and_unusable_transforms_are_warnings() {
    let dir = tempfile::tempdir().unwrap();
    save_image(&dir.path().join("tex.png"));
    std::fs::write(
        dir.path().join("m.mtl"),
        "newmtl a\nmap_Kd -mm 0.2 0.5 -t 0.1 0 0 -s nan 1 tex.png\n",
    )
    .unwrap();
    let path = common::files::write(
        dir.path(),
        "m.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl a\nf 1/1 2/1 3/1\n",
    );
    let (scene, report) = common::files::load(&path).unwrap();
    let material = &scene.materials[0];
    assert!(material.diffuse_texture.is_some());
    assert!(material.maps.base_transform.is_identity());
    for said in ["map_Kd options not applied: -mm, -t", "map_Kd -o"] {
        assert!(
            report.warnings.iter().any(|w| w.contains(said)),
            "{said}: {:?}",
            report.warnings
        );
    }
}
