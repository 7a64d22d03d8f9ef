//! glTF `alphaMode: MASK` cut out by the base colour texture's alpha (leaves, fences), and
//! `BLEND` blended by it: a pane whose texture is transparent on its left half and opaque on
//! its right stands in front of a lit wall. With `MASK` every pixel is either the picture
//! without the pane (where it is cut) or the picture with the pane opaque (where it is not),
//! and both occur, with every method on ES 2.0 and 3.0: the cut holds in the depth prepass's
//! place, in the G-buffer and in the depth test of what lies behind. With `BLEND` every pixel
//! lies between the two (filtering blends the texels' alphas where they meet).

use crate::common;

use std::path::Path;

use common::files::{load, write};
use common::gltf::{base64, Builder};
use common::gltf_models::{floor, pane, primitive, quat};
use glam::{DQuat, DVec3, Vec3};
use manylight::scene::{Light, Scene};
use manylight::{EsVersion, RenderOptions};
use serde_json::{json, Value};

const W: u32 = 128;
const H: u32 = 72;

/// A 16 × 1 texture: transparent green texels on the left half, opaque yellow ones on the
/// right (wide enough that filtering mixes them only near the middle and the edges).
fn half_cut_png() -> Vec<u8> {
    let texels = [[40u8, 200, 60, 0], [230, 210, 40, 255]];
    let img = image::RgbaImage::from_fn(16, 1, |x, _| image::Rgba(texels[(x / 8) as usize]));
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    png
}

/// The scene with the pane's material in `alpha_mode` (`None`: no pane at all), its texture
/// [`half_cut_png`].
fn scene_with_pane(dir: &Path, alpha_mode: Option<&str>) -> Scene {
    scene_with_pane_of(dir, alpha_mode, &half_cut_png())
}

/// [`scene_with_pane`] with the pane's texture `png`.
fn scene_with_pane_of(dir: &Path, alpha_mode: Option<&str>, png: &[u8]) -> Scene {
    scene_with_pane_of_factor(dir, alpha_mode, png, 1.0)
}

/// [`scene_with_pane_of`] with the pane's `baseColorFactor` alpha `factor_alpha`.
fn scene_with_pane_of_factor(
    dir: &Path,
    alpha_mode: Option<&str>,
    png: &[u8],
    factor_alpha: f32,
) -> Scene {
    let mut b = Builder::default();
    let pane_prim = primitive(&mut b, &pane(1.6, 1.2), Some(2));
    let material = json!({"alphaMode": alpha_mode.unwrap_or("OPAQUE"), "alphaCutoff": 0.5,
        "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0,
                                 "baseColorFactor": [1, 1, 1, factor_alpha]}});
    let texture = json!({
        "samplers": [{"magFilter": 9728, "minFilter": 9728}],
        "textures": [{"source": 0, "sampler": 0}],
        "images": [{"uri": format!("data:image/png;base64,{}", base64(png))}],
    });
    let name = format!("pane_{}_{factor_alpha}.gltf", alpha_mode.unwrap_or("none"));
    let front = alpha_mode.map(|_| (pane_prim, material));
    scene_around(dir, &name, b, front, texture)
}

/// A floor, a red wall behind and, with `front`, a pane (its primitive, whose material is
/// number 2, and that material) in front, seen by the file's camera and lit by one light;
/// `extra` adds top-level glTF members (the pane's texture).
fn scene_around(
    dir: &Path,
    name: &str,
    mut b: Builder,
    front: Option<(Value, Value)>,
    extra: Value,
) -> Scene {
    let floor_prim = primitive(&mut b, &floor(), Some(0));
    let wall_prim = primitive(&mut b, &pane(3.0, 2.0), Some(1));
    let mut nodes = vec![
        json!({"mesh": 0}),
        json!({"mesh": 1, "translation": [0, 0, -1.5]}),
        json!({"camera": 0, "translation": [0, 1, 3],
               "rotation": quat(DQuat::from_rotation_x(-0.15))}),
    ];
    let mut meshes = vec![
        json!({"primitives": [floor_prim]}),
        json!({"primitives": [wall_prim]}),
    ];
    let mut materials = vec![
        json!({"pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.7, 0.7, 1], "metallicFactor": 0}}),
        json!({"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.1, 0.1, 1], "metallicFactor": 0}}),
    ];
    if let Some((prim, material)) = front {
        nodes.push(json!({"mesh": 2, "translation": [0, 0.3, 0.5]}));
        meshes.push(json!({"primitives": [prim]}));
        materials.push(material);
    }
    let scene_nodes: Vec<usize> = (0..nodes.len()).collect();
    let mut gltf = json!({
        "scenes": [{"nodes": scene_nodes}],
        "nodes": nodes,
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.05, "zfar": 50}}],
        "meshes": meshes,
        "materials": materials,
    });
    if let (Some(gltf), Some(extra)) = (gltf.as_object_mut(), extra.as_object()) {
        gltf.extend(extra.clone());
    }
    let (mut scene, _) = load(&write(dir, name, b.gltf(gltf))).unwrap();
    scene.lights = vec![Light::point(DVec3::new(0.5, 1.5, 1.5), 8.0, Vec3::ONE, 6.0)];
    scene.ambient = Vec3::splat(0.05);
    scene
}

#[test]
fn a_masked_texture_cuts_the_pane_where_its_alpha_is_below_the_cutoff() {
    let dir = tempfile::tempdir().unwrap();
    let masked = scene_with_pane(dir.path(), Some("MASK"));
    let opaque = scene_with_pane(dir.path(), Some("OPAQUE"));
    let without = scene_with_pane(dir.path(), None);
    let pane_material = masked
        .materials
        .iter()
        .find(|m| m.alpha_cutoff.is_some())
        .expect("the MASK material cuts by its texture");
    assert_eq!(pane_material.alpha_cutoff, Some(0.5));
    for_every_method(
        &[&masked, &opaque, &without],
        |es, method, [cut, solid, behind]| {
            assert_cut_or_whole(&format!("{es} {method}"), [cut, solid, behind], W * H / 20);
        },
    );
}

/// A 16 × 1 texture: half-transparent texels (alpha 128) on the left half, opaque ones on the
/// right, all yellow.
fn half_translucent_png() -> Vec<u8> {
    let alphas = [128u8, 255];
    let img = image::RgbaImage::from_fn(16, 1, |x, _| {
        image::Rgba([230, 210, 40, alphas[(x / 8) as usize]])
    });
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    png
}

#[test]
fn a_blended_texture_blends_the_pane_by_its_alpha_times_the_factor() {
    let dir = tempfile::tempdir().unwrap();
    let png = half_translucent_png();
    // Opacity 0.5 × 128/255 on the left half, 0.5 × 1 on the right.
    let blended = scene_with_pane_of_factor(dir.path(), Some("BLEND"), &png, 0.5);
    let opaque = scene_with_pane_of_factor(dir.path(), Some("OPAQUE"), &png, 1.0);
    let without = scene_with_pane(dir.path(), None);
    assert!(
        blended
            .materials
            .iter()
            .any(|m| m.alpha_texture && m.is_transparent()),
        "the BLEND material takes its texture's alpha"
    );
    // A BLEND material whose texture is opaque everywhere stays an opaque object.
    let solid_png = common::gltf_models::checker_png();
    let solid_blend = scene_with_pane_of(dir.path(), Some("BLEND"), &solid_png);
    assert!(solid_blend.materials.iter().all(|m| !m.is_transparent()));
    let opacities = [0.5 * 128.0 / 255.0, 0.5];
    for_every_method(
        &[&blended, &opaque, &without],
        |es, method, [mixed, solid, behind]| {
            // The blend of an 8-bit target: opacity × pane + (1 − opacity) × what is behind,
            // in stored values. Where the pane shows, each pixel is one of the two mixes
            // (or between them where filtering meets the halves).
            let mut at = [0usize; 2];
            for ((m, s), b) in mixed.pixels().zip(solid.pixels()).zip(behind.pixels()) {
                if (0..3).all(|k| s[k].abs_diff(b[k]) < 24) {
                    continue; // no pane here, or the pane as bright as what it covers
                }
                let mix = |a: f64, k: usize| a * s[k] as f64 + (1.0 - a) * b[k] as f64;
                let near = |a: f64| (0..3).all(|k| (m[k] as f64 - mix(a, k)).abs() <= 3.0);
                let between = (0..3).all(|k| {
                    let (lo, hi) = (mix(opacities[0], k), mix(opacities[1], k));
                    (lo.min(hi) - 3.0..=lo.max(hi) + 3.0).contains(&(m[k] as f64))
                });
                assert!(
                    between,
                    "{es} {method}: a pixel {m:?} is not a mix of the pane {s:?} over {b:?} \
                     at opacity {opacities:?}"
                );
                for (n, &a) in opacities.iter().enumerate() {
                    at[n] += usize::from(near(a));
                }
            }
            let enough = (W * H / 40) as usize;
            assert!(
                at.iter().all(|&n| n > enough),
                "{es} {method}: {at:?} pixels at opacities {opacities:?}"
            );
        },
    );
}

/// The scene with an untextured pane whose `COLOR_0` alphas are `alphas` (corners: bottom
/// left, bottom right, top right, top left), its material in `alpha_mode` (`None`: no pane).
fn scene_with_coloured_pane(dir: &Path, alpha_mode: Option<&str>, alphas: [f32; 4]) -> Scene {
    let mut b = Builder::default();
    let mut pane_prim = primitive(&mut b, &pane(1.6, 1.2), Some(2));
    let colours: Vec<f32> = alphas.iter().flat_map(|&a| [1.0, 1.0, 1.0, a]).collect();
    pane_prim["attributes"]["COLOR_0"] = json!(b.floats(&colours, "VEC4"));
    let material = json!({"alphaMode": alpha_mode.unwrap_or("OPAQUE"), "alphaCutoff": 0.5,
        "pbrMetallicRoughness": {"metallicFactor": 0, "baseColorFactor": [0.9, 0.8, 0.2, 1]}});
    let name = format!("coloured_pane_{}.gltf", alpha_mode.unwrap_or("none"));
    let front = alpha_mode.map(|_| (pane_prim, material));
    scene_around(dir, &name, b, front, json!({}))
}

/// glTF's base colour alpha is the factor's × the texture's × `COLOR_0`'s: vertex alpha 0.5
/// blends a `BLEND` pane at 0.5 everywhere, and alphas 0 on the left and 1 on the right cut a
/// `MASK` pane (cutoff 0.5) down the middle. Both showed the pane opaque when vertex alpha was
/// ignored.
#[test]
fn vertex_alpha_blends_and_cuts_as_the_base_colour_alpha() {
    let dir = tempfile::tempdir().unwrap();
    let half = [0.5; 4];
    let blended = scene_with_coloured_pane(dir.path(), Some("BLEND"), half);
    let opaque = scene_with_coloured_pane(dir.path(), Some("OPAQUE"), half);
    let without = scene_with_coloured_pane(dir.path(), None, half);
    assert!(blended.materials.iter().any(|m| m.is_transparent()));
    assert!(opaque.materials.iter().all(|m| !m.is_transparent()));
    for_every_method(
        &[&blended, &opaque, &without],
        |es, method, [mixed, solid, behind]| {
            let mut panes = 0;
            for ((m, s), b) in mixed.pixels().zip(solid.pixels()).zip(behind.pixels()) {
                if (0..3).all(|k| s[k].abs_diff(b[k]) < 24) {
                    continue;
                }
                let mix = |k: usize| 0.5 * s[k] as f64 + 0.5 * b[k] as f64;
                assert!(
                    (0..3).all(|k| (m[k] as f64 - mix(k)).abs() <= 3.0),
                    "{es} {method}: a pixel {m:?} is not half the pane {s:?} over {b:?}"
                );
                panes += 1;
            }
            assert!(
                panes > (W * H / 20) as usize,
                "{es} {method}: {panes} pane pixels"
            );
        },
    );
    let ramp = [0.0, 1.0, 1.0, 0.0];
    let masked = scene_with_coloured_pane(dir.path(), Some("MASK"), ramp);
    let opaque = scene_with_coloured_pane(dir.path(), Some("OPAQUE"), ramp);
    for_every_method(
        &[&masked, &opaque, &without],
        |es, method, [cut, solid, behind]| {
            assert_cut_or_whole(&format!("{es} {method}"), [cut, solid, behind], W * H / 40);
        },
    );
}

/// Asserts that every pixel of `cut` is the scene without the pane (`behind`) or with it
/// opaque (`solid`), and that more than `enough` pixels are each.
fn assert_cut_or_whole(what: &str, [cut, solid, behind]: [image::RgbaImage; 3], enough: u32) {
    let (mut as_behind, mut as_solid) = (0, 0);
    for ((c, s), b) in cut.pixels().zip(solid.pixels()).zip(behind.pixels()) {
        let near = |x: &image::Rgba<u8>| (0..3).all(|k| c[k].abs_diff(x[k]) <= 1);
        let (is_behind, is_solid) = (near(b), near(s));
        assert!(
            is_behind || is_solid,
            "{what}: a pixel {c:?} is neither the scene without the pane {b:?} nor with it \
             opaque {s:?}"
        );
        // Where the pane makes a difference, which side won.
        if is_behind && !is_solid {
            as_behind += 1;
        } else if is_solid && !is_behind {
            as_solid += 1;
        }
    }
    assert!(
        as_behind > enough && as_solid > enough,
        "{what}: {as_behind} pixels cut and {as_solid} drawn"
    );
}

/// Renders each of `scenes` with every method on ES 2.0 and 3.0 (deferred on 3.0 only) and
/// hands `check` the pictures.
fn for_every_method(
    scenes: &[&Scene; 3],
    mut check: impl FnMut(EsVersion, &str, [image::RgbaImage; 3]),
) {
    let opts = RenderOptions::default();
    common::each_method(|es, method, gpu| {
        check(
            es,
            method,
            scenes.map(|scene| gpu.render(scene, W, H, &opts)),
        );
    });
}

/// A blended primitive whose `COLOR_0` alpha is 0 at every vertex draws nothing: said at
/// load, as a material alpha of 0 is; one vertex above 0 draws something, and is not.
#[test]
fn vertex_alpha_of_zero_everywhere_is_warned_of_as_fully_transparent() {
    let dir = tempfile::tempdir().unwrap();
    for (last_alpha, warned) in [(0.0, true), (0.5, false)] {
        let mut b = Builder::default();
        let p = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3");
        let c = b.floats(
            &[
                1.0, 1.0, 1.0, 0.0, 1.0, 1.0, 1.0, 0.0, 1.0, 1.0, 1.0, last_alpha,
            ],
            "VEC4",
        );
        let rest = json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
            "materials": [{"alphaMode": "BLEND"}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": p, "COLOR_0": c},
                "material": 0}]}]});
        let (_, report) = load(&write(dir.path(), "a.gltf", b.gltf(rest))).unwrap();
        let said = report
            .warnings
            .iter()
            .any(|w| w.contains("fully transparent"));
        assert_eq!(said, warned, "{last_alpha}: {:?}", report.warnings);
    }
}

/// Colours outside [0, 1] are clamped by the mesh: a `COLOR_0` of −1e30 drew black without a
/// word. Said at load, naming the attribute and how many; colours within it say nothing.
#[test]
fn vertex_colours_outside_zero_to_one_are_warned_of() {
    let dir = tempfile::tempdir().unwrap();
    for (first, warned) in [(-1e30, true), (1.5, true), (0.25, false)] {
        let mut b = Builder::default();
        let p = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3");
        let c = b.floats(&[first, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5], "VEC3");
        let rest = json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": p, "COLOR_0": c}}]}]});
        let (_, report) = load(&write(dir.path(), "c.gltf", b.gltf(rest))).unwrap();
        let said = report
            .warnings
            .iter()
            .any(|w| w.contains("COLOR_0") && w.contains("outside [0, 1]"));
        assert_eq!(said, warned, "{first}: {:?}", report.warnings);
    }
}
