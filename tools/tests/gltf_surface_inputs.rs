//! glTF surface inputs as artists export them, on files the tests write: a normal-mapped plane
//! under a grazing light (tangents from the file and generated), emission with its strength
//! and texture plus ambient occlusion, `COLOR_0` vertex colours, and a base colour texture
//! through `KHR_texture_transform` (a required extension). Each picture is checked pixel by
//! pixel against the f64 twin (`manylight::scene::shading` + `surface_maps`), each oracle is
//! checked to differ from the one without its feature (so the test can fail), and tiled,
//! clustered and deferred must equal forward on ES 2.0 and 3.0.

mod common;
#[path = "gltf_surface_inputs/second_set.rs"]
mod second_set;
#[path = "gltf_surface_inputs/support.rs"]
mod support;

use std::path::Path;

use common::Gpu;
use glam::{DVec2, DVec3, Vec2, Vec3};
use manylight::scene::shading::srgb_to_linear;
use manylight::scene::surface_maps::{occlusion_factor, perturbed_normal, TextureTransform};
use manylight::scene::{self, Camera, Light, Scene};
use manylight::{EsVersion, RenderOptions};
use serde_json::json;
use support::*;

/// Loads a written file with the view, lights and ambient every test uses.
fn scene_of(path: &Path, lights: Vec<Light>, ambient: f32) -> (Scene, Vec<String>) {
    let (mut s, report) = scene::load(path.to_str().unwrap(), Some((0, 1))).expect("loads");
    s.camera = Camera::perspective(DVec3::new(0.0, -0.4, 1.6), DVec3::ZERO, 60.0, 0.1, 20.0);
    s.lights = lights;
    s.ambient = Vec3::splat(ambient);
    s.validate().unwrap();
    // The files carry no lights (the test adds them): less gltf_manners.rs's hint.
    let warnings = report.warnings.into_iter();
    (
        s,
        warnings
            .filter(|w| !w.starts_with("no lights in "))
            .collect(),
    )
}

/// Renders `scene` with every method on ES 2.0 (also as a device without fragment highp) and
/// 3.0: forward against the twin within `tolerance`, every other method against forward
/// within 2/255 (and the twin).
fn check_every_method(what: &str, scene: &Scene, want: &[Option<[f64; 3]>], tolerance: f64) {
    check_every_method_by_level(what, scene, [want, want], tolerance)
}

/// [`check_every_method`] with the twin's values for ES 2.0 and for ES 3.0, where they differ:
/// a colour texture's texels are decoded after filtering on ES 2.0 and before on ES 3.0.
fn check_every_method_by_level(
    what: &str,
    scene: &Scene,
    wants: [&[Option<[f64; 3]>]; 2],
    tolerance: f64,
) {
    check_levels(what, scene, wants, tolerance, true)
}

/// [`check_every_method`] on contexts with fragment highp only: for a picture that fp16
/// positions and normals cannot place (docs/precision.md).
fn check_every_method_with_highp(
    what: &str,
    scene: &Scene,
    want: &[Option<[f64; 3]>],
    tolerance: f64,
) {
    check_levels(what, scene, [want, want], tolerance, false)
}

fn check_levels(
    what: &str,
    scene: &Scene,
    [want_es2, want_es3]: [&[Option<[f64; 3]>]; 2],
    tolerance: f64,
    without_highp: bool,
) {
    // ES 2.0, ES 2.0 on a device without fragment highp (every float fp16 here), ES 3.0 (not
    // in a child capped to ES 2.0: `second_set::PURE_ES2`).
    let levels = [
        (EsVersion::Es2, false),
        (EsVersion::Es2, true),
        (EsVersion::Es3, false),
    ];
    let pure_es2 = std::env::var_os(second_set::PURE_ES2).is_some();
    let levels = levels
        .into_iter()
        .take(if pure_es2 { 2 } else { 3 })
        .filter(|&(_, no_highp)| without_highp || !no_highp);
    for (es, no_fragment_highp) in levels {
        let restrictions = manylight::gl::Restrictions {
            no_fragment_highp,
            ..Default::default()
        };
        let mut gpu = Gpu::restricted(es, &restrictions);
        if pure_es2 {
            let caps = gpu.r().caps();
            let vao = caps.has_extension("GL_OES_vertex_array_object");
            assert!(
                !caps.context_has_es3_state() && !vao,
                "the cap left vertex arrays"
            );
        }
        let want = if es == EsVersion::Es3 {
            want_es3
        } else {
            want_es2
        };
        let es = format!("{es}{}", if no_fragment_highp { " mediump" } else { "" });
        let opts = RenderOptions::default();
        gpu.r().set_method_named("forward").unwrap();
        let forward = gpu.render(scene, W, H, &opts);
        let (err, at, n) = error(&forward, want);
        eprintln!("{what} {es} forward: {err:.2}/255 at {at:?} over {n} pixels");
        assert!(n > (W * H / 3) as usize, "{what}: only {n} pixels compared");
        assert!(
            err <= tolerance,
            "{what} {es} forward: {err:.2}/255 from the f64 twin at {at:?}"
        );
        // Without fragment highp only forward runs (the culled methods need exact cells).
        let mut methods = if no_fragment_highp {
            vec![]
        } else {
            vec!["tiled", "clustered"]
        };
        if es == "ES 3.0" {
            methods.push("deferred");
        }
        for method in methods {
            gpu.r().set_method_named(method).unwrap();
            let img = gpu.render(scene, W, H, &opts);
            let d = img
                .pixels()
                .zip(forward.pixels())
                .flat_map(|(a, b)| (0..3).map(move |k| (a[k] as i32 - b[k] as i32).abs()))
                .max()
                .unwrap_or(0);
            assert!(
                d <= 2,
                "{what} {es} {method}: differs from forward by {d}/255"
            );
            let (err, at, _) = error(&img, want);
            assert!(
                err <= tolerance,
                "{what} {es} {method}: {err:.2}/255 from the f64 twin at {at:?}"
            );
        }
    }
}

/// A light low over the plane's −x edge, so a normal tilted towards it shows.
fn grazing_light() -> Vec<Light> {
    vec![Light::point(
        DVec3::new(-2.5, 0.2, 0.35),
        8.0,
        Vec3::new(1.0, 0.95, 0.9),
        9.0,
    )]
}

/// `lights` mirrored through the plane (z to −z), for a view from behind it.
fn behind(lights: Vec<Light>) -> Vec<Light> {
    lights
        .into_iter()
        .map(|mut l| {
            l.position.z = -l.position.z;
            l
        })
        .collect()
}

#[test]
fn a_normal_map_tilts_the_shading_normal_with_file_and_generated_tangents() {
    let dir = tempfile::tempdir().unwrap();
    // The plane's mapping is upright, so MikkTSpace gives +x with the bitangent up the image
    // (w = +1, glTF's convention); the file's tangents say the other hand (w = −1). Each file's
    // texel tilts the normal towards −x (the light) and −y (the eye), scale 0.8 on x and y
    // (the shaders light a mapped normal as it is, also one tilted away from the eye, and so
    // does the twin here).
    let down = [60u8, 215, 200, 255];
    let up = [60u8, 40, 200, 255];
    // Double-sided: the plane is also seen from behind (below).
    let material = json!({
        "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.7, 0.6, 1.0], "roughnessFactor": 1.0,
                                 "metallicFactor": 0.0},
        "normalTexture": {"index": 0, "scale": 0.8},
        "doubleSided": true,
    });
    let mut plane = Plane::new(material);
    plane.images.push(png(1, 1, &[up]));
    let generated = plane.write(dir.path(), "generated.gltf");
    plane.images[0] = png(1, 1, &[down]);
    let tangents: Vec<u8> = [1.0f32, 0.0, 0.0, -1.0]
        .repeat(4)
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    plane.extra.push(("TANGENT", FLOAT, "VEC4", tangents));
    let from_file = plane.write(dir.path(), "tangents.gltf");

    let rgb = |t: [u8; 4]| DVec3::new(t[0] as f64, t[1] as f64, t[2] as f64) / 255.0;
    let albedo = DVec3::new(0.8, 0.7, 0.6);
    let mapped = |texel: [u8; 4], w: f64| {
        move |p: DVec3, _: DVec2, _: [f64; 4]| {
            let n = perturbed_normal(DVec3::Z, DVec3::X, w, rgb(texel), 0.8);
            (surface(p, n, albedo), DVec3::ZERO, 1.0)
        }
    };
    let flat = |p: DVec3, _: DVec2, _: [f64; 4]| (surface(p, DVec3::Z, albedo), DVec3::ZERO, 1.0);
    for (path, texel, w) in [(&generated, up, 1.0), (&from_file, down, -1.0)] {
        let (s, warnings) = scene_of(path, grazing_light(), 0.02);
        assert!(warnings.is_empty(), "{warnings:?}");
        assert_eq!(s.materials[0].maps.normal_scale, 0.8);
        let want = oracle(&s, &mapped(texel, w));
        assert_changes(&want, &oracle(&s, &flat), 30.0, "the normal map");
        // The other hand (green read the other way) must show too.
        assert_changes(
            &want,
            &oracle(&s, &mapped(texel, -w)),
            10.0,
            "the handedness",
        );
        check_every_method("normal map", &s, &want, 3.0);
    }
    // Without a light nothing reads the normal: ambient only, as without the map (the
    // ambient-only variant asked for the map's uniforms, which its compiler had dropped, and
    // failed to link).
    let (s, _) = scene_of(&generated, Vec::new(), 0.3);
    check_every_method("normal map without lights", &s, &oracle(&s, &flat), 3.0);
    // Seen from behind, with the light on the eye's side: the back face's shading normal is
    // the front's reversed whole (glTF 2.0 §3.9.5); mapped in a frame flipped with the
    // normal, the tilt along the tangent would be mirrored.
    let (mut s, _) = scene_of(&from_file, behind(grazing_light()), 0.02);
    s.camera = Camera::perspective(DVec3::new(0.0, -0.4, -1.6), DVec3::ZERO, 60.0, 0.1, 20.0);
    let back = |p: DVec3, _: DVec2, _: [f64; 4]| {
        let n = perturbed_normal(DVec3::Z, DVec3::X, -1.0, rgb(down), 0.8);
        (surface(p, -n, albedo), DVec3::ZERO, 1.0)
    };
    let want = oracle(&s, &back);
    let mirrored_back = |p: DVec3, _: DVec2, _: [f64; 4]| {
        let n = perturbed_normal(DVec3::Z, DVec3::X, -1.0, rgb(down), 0.8);
        let n = DVec3::new(n.x, -n.y, -n.z);
        (surface(p, n, albedo), DVec3::ZERO, 1.0)
    };
    assert_changes(
        &want,
        &oracle(&s, &mirrored_back),
        10.0,
        "a mirrored back face",
    );
    check_every_method("normal map seen from behind", &s, &want, 3.0);
    // Mirrored along x: the tangent turns to −x and the bitangent keeps pointing down the
    // image, so the handedness flips with the transform's determinant.
    let (mut s, _) = scene_of(&from_file, grazing_light(), 0.02);
    s.objects[0].transform = glam::DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0));
    let mirrored = |w: f64| {
        move |p: DVec3, _: DVec2, _: [f64; 4]| {
            let n = perturbed_normal(DVec3::Z, -DVec3::X, w, rgb(down), 0.8);
            (surface(p, n, albedo), DVec3::ZERO, 1.0)
        }
    };
    let want = oracle(&s, &mirrored(1.0));
    assert_changes(&want, &oracle(&s, &mirrored(-1.0)), 10.0, "the handedness");
    check_every_method("mirrored normal map", &s, &want, 3.0);
}

/// The twin's picture of the plane (its base colour, roughness 1) under a normal map of one
/// `texel` at `scale`, checked to differ from the plane's without it by 30/255 somewhere.
fn one_texel_map_oracle(
    s: &Scene,
    texel: [u8; 4],
    scale: f64,
    what: &str,
) -> Vec<Option<[f64; 3]>> {
    let rgb = DVec3::new(texel[0] as f64, texel[1] as f64, texel[2] as f64) / 255.0;
    let albedo = DVec3::new(0.8, 0.7, 0.6);
    let mapped = |p: DVec3, _: DVec2, _: [f64; 4]| {
        let n = perturbed_normal(DVec3::Z, DVec3::X, 1.0, rgb, scale);
        (surface(p, n, albedo), DVec3::ZERO, 1.0)
    };
    let flat = |p: DVec3, _: DVec2, _: [f64; 4]| (surface(p, DVec3::Z, albedo), DVec3::ZERO, 1.0);
    let want = oracle(s, &mapped);
    assert_changes(&want, &oracle(s, &flat), 30.0, what);
    want
}

/// A bright light a millimetre above a normal-mapped surface: where the mapped normal turns
/// away from it decides the picture. A sampler is `lowp` unless declared otherwise, and
/// llvmpipe reads a `lowp` texel in fp16, which tilted the normal by ~3e-4 and moved that
/// line: 226/255 from the twin on pixels along it, in every method (read at `highp` now).
#[test]
fn a_normal_map_is_read_precisely_enough_for_a_light_just_above_it() {
    let dir = tempfile::tempdir().unwrap();
    let material = json!({
        "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.7, 0.6, 1.0], "roughnessFactor": 1.0,
                                 "metallicFactor": 0.0},
        "normalTexture": {"index": 0},
    });
    let mut plane = Plane::new(material);
    let texel = [200u8, 90, 200, 255];
    plane.images.push(png(1, 1, &[texel]));
    let path = plane.write(dir.path(), "close.gltf");
    // Above where pixel (46, 40)'s centre meets the plane: bright enough to saturate wherever
    // the mapped normal faces it, so the line where it turns away (N·L = 0) crosses the
    // picture, and pixels by that line show how precisely the normal was read.
    let (s, _) = scene_of(&path, vec![], 0.02);
    let (o, d) = manylight::scene::raycast::pixel_ray(&s.camera, W, H, 46.5, 40.5);
    let under = o - d * (o.z / d.z);
    let light = Light::point(DVec3::new(under.x, under.y, 1e-3), 3.0, Vec3::ONE, 6e4);
    let (s, warnings) = scene_of(&path, vec![light], 0.02);
    assert!(warnings.is_empty(), "{warnings:?}");
    let want = one_texel_map_oracle(&s, texel, 1.0, "the normal map");
    check_every_method_with_highp("a light just above a normal map", &s, &want, 3.0);
}

/// At `scale` 0 glTF's normal is `normalize((2·rgb − 1)·(0, 0, 1))`: the surface's own where a
/// texel's blue is 128 or more, turned round where it is less. Such a map was left out as one
/// that changes nothing, and the plane drawn lit where it faces away from the light.
#[test]
fn a_normal_map_of_scale_0_turns_the_normal_where_its_blue_is_below_half() {
    let dir = tempfile::tempdir().unwrap();
    let material = json!({
        "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.7, 0.6, 1.0], "roughnessFactor": 1.0,
                                 "metallicFactor": 0.0},
        "normalTexture": {"index": 0, "scale": 0.0},
    });
    let mut plane = Plane::new(material);
    // Blue 127: just below half, z = 2·127/255 − 1 < 0.
    let turned = [128u8, 128, 127, 255];
    plane.images.push(png(1, 1, &[turned]));
    let path = plane.write(dir.path(), "scale0.gltf");
    let (s, warnings) = scene_of(&path, grazing_light(), 0.02);
    assert!(warnings.is_empty(), "{warnings:?}");
    assert!(s.materials[0].maps.normal.is_some(), "the map was left out");
    let want = one_texel_map_oracle(&s, turned, 0.0, "the turned normal");
    check_every_method("normal map of scale 0", &s, &want, 3.0);
}

/// A normal map on a mesh built in code, which has no tangents, is not applied, and that is
/// said once (it passed in silence); the mesh with `Mesh::with_generated_tangents` shows it.
/// In a process of its own: the warning is said once a process.
#[test]
fn a_normal_map_on_a_mesh_without_tangents_is_not_applied_and_said() {
    const CHILD: &str = "MANYLIGHT_TEST_TANGENTLESS";
    if std::env::var_os(CHILD).is_none() {
        common::child::rerun_with(
            "a_normal_map_on_a_mesh_without_tangents_is_not_applied_and_said",
            &[(CHILD, "1")],
            "in a process of its own",
        );
        return;
    }
    use manylight::scene::surface_maps::MapTexture;
    common::warnings::install();
    let said =
        || common::warnings::warnings_containing("is not applied on a mesh without tangents").len();
    let bare = scene::builtin::build("plane", Some((8, 1))).unwrap();
    let tilted = image::RgbaImage::from_pixel(4, 4, image::Rgba([230, 128, 160, 255]));
    let mut mapped = bare.clone();
    for m in &mut mapped.materials {
        m.maps.normal = Some(MapTexture {
            texture: std::sync::Arc::new(scene::Texture::new("tilted", tilted.clone())),
            transform: TextureTransform::IDENTITY,
        });
    }
    let mut gpu = Gpu::new(EsVersion::Es3);
    let opts = RenderOptions::default();
    let want = gpu.render(&bare, 64, 36, &opts);
    for _ in 0..2 {
        let got = gpu.render(&mapped, 64, 36, &opts);
        assert_eq!(manylight::metrics::diff(&want, &got).max_abs, 0);
    }
    assert_eq!(said(), 1, "said once");
    for o in &mut mapped.objects {
        let mesh = (*o.mesh).clone().with_generated_tangents().unwrap().0;
        o.mesh = std::sync::Arc::new(mesh);
    }
    let got = gpu.render(&mapped, 64, 36, &opts);
    let d = manylight::metrics::diff(&want, &got).max_abs;
    assert!(d > 20, "with tangents the map shows: {d} / 255");
    assert_eq!(said(), 1);
}

/// A primitive without `TEXCOORD_0` samples none of its material's textures (each pixel would
/// read the corner texel): its factors draw it, with every method, and the load says which
/// textures went unapplied.
#[test]
fn textures_of_a_primitive_without_texture_coordinates_are_not_applied_and_said() {
    let dir = tempfile::tempdir().unwrap();
    let material = json!({
        "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.7, 0.6, 1.0], "roughnessFactor": 1.0,
                                 "metallicFactor": 0.0, "baseColorTexture": {"index": 0}},
        "normalTexture": {"index": 1},
    });
    let mut plane = Plane::new(material);
    plane.images.push(png(1, 1, &[[20, 200, 40, 255]]));
    plane.images.push(png(1, 1, &[[60, 40, 200, 255]]));
    let path = plane.write(dir.path(), "no_uvs.gltf");
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let attributes = &mut doc["meshes"][0]["primitives"][0]["attributes"];
    attributes.as_object_mut().unwrap().remove("TEXCOORD_0");
    std::fs::write(&path, doc.to_string()).unwrap();
    let (s, warnings) = scene_of(&path, grazing_light(), 0.02);
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("on TEXCOORD_0, which the primitive has not")
                && w.contains("baseColorTexture, normalTexture")
                && w.contains("not applied")),
        "{warnings:?}"
    );
    assert!(
        s.materials[0].diffuse_texture.is_some(),
        "kept for meshes that have them"
    );
    let albedo = DVec3::new(0.8, 0.7, 0.6);
    let flat = |p: DVec3, _: DVec2, _: [f64; 4]| (surface(p, DVec3::Z, albedo), DVec3::ZERO, 1.0);
    let want = oracle(&s, &flat);
    let green = DVec3::new(20.0, 200.0, 40.0) / 255.0;
    let sampled = |p: DVec3, _: DVec2, _: [f64; 4]| {
        let corner = albedo * green.map(srgb_to_linear);
        (surface(p, DVec3::Z, corner), DVec3::ZERO, 1.0)
    };
    assert_changes(&want, &oracle(&s, &sampled), 20.0, "the texture");
    check_every_method("textures without texture coordinates", &s, &want, 3.0);
}

/// (metallic, roughness) = (metallicFactor, roughnessFactor) × the texture's (B, G), linear:
/// factors below 1 and distinct channels, so reading the wrong channel, dropping the factors
/// or the texture, each changes the picture beyond the bar (with both factors 1 and blue 255 a
/// shader ignoring blue passed).
#[test]
fn the_metallic_roughness_texture_multiplies_the_factors_by_its_blue_and_green() {
    let dir = tempfile::tempdir().unwrap();
    // R 30 (unused), G 204 (0.8), B 64 (0.251): linear data, not sRGB.
    let texel = [30u8, 204, 64, 255];
    let (metallic_factor, roughness_factor) = (0.9, 0.4);
    let material = json!({
        "pbrMetallicRoughness": {
            "baseColorFactor": [0.9, 0.6, 0.3, 1.0],
            "metallicFactor": metallic_factor,
            "roughnessFactor": roughness_factor,
            "metallicRoughnessTexture": {"index": 0},
        },
    });
    let mut plane = Plane::new(material);
    plane.images.push(png(1, 1, &[texel]));
    let path = plane.write(dir.path(), "mr.gltf");
    let light = Light::point(DVec3::new(0.0, 0.35, 0.5), 3.0, Vec3::ONE, 2.0);
    let (s, warnings) = scene_of(&path, vec![light], 0.02);
    assert!(warnings.is_empty(), "{warnings:?}");
    let albedo = DVec3::new(0.9, 0.6, 0.3);
    let model = |metallic: f64, roughness: f64| {
        move |p: DVec3, _: DVec2, _: [f64; 4]| {
            let mut surface = surface(p, DVec3::Z, albedo);
            (surface.metallic, surface.roughness) = (metallic, roughness);
            (surface, DVec3::ZERO, 1.0)
        }
    };
    let [r, g, b] = [texel[0], texel[1], texel[2]].map(|c| f64::from(c) / 255.0);
    let want = oracle(&s, &model(metallic_factor * b, roughness_factor * g));
    for (wrong, metallic, roughness) in [
        ("the texture ignored", metallic_factor, roughness_factor),
        ("the factors ignored", b, g),
        (
            "blue and green swapped",
            metallic_factor * g,
            roughness_factor * b,
        ),
        (
            "metallic from red",
            metallic_factor * r,
            roughness_factor * g,
        ),
    ] {
        assert_changes(&want, &oracle(&s, &model(metallic, roughness)), 6.0, wrong);
    }
    check_every_method("metallic-roughness texture", &s, &want, 3.0);
}

#[test]
fn emission_with_its_strength_and_texture_adds_light_and_occlusion_darkens_the_ambient() {
    let dir = tempfile::tempdir().unwrap();
    let emissive_texel = [200u8, 90, 250, 255];
    let occlusion_texel = [90u8, 255, 0, 255];
    let material = json!({
        "pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.7, 0.7, 1.0], "roughnessFactor": 1.0,
                                 "metallicFactor": 0.0},
        "emissiveFactor": [0.2, 0.15, 0.05],
        "emissiveTexture": {"index": 0},
        "occlusionTexture": {"index": 1, "strength": 0.75},
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 2.0}},
    });
    let mut plane = Plane::new(material);
    plane.images.push(png(1, 1, &[emissive_texel]));
    plane.images.push(png(1, 1, &[occlusion_texel]));
    plane.extensions.push("KHR_materials_emissive_strength");
    let path = plane.write(dir.path(), "emissive.gltf");
    let (s, warnings) = scene_of(&path, grazing_light(), 0.4);
    assert!(warnings.is_empty(), "{warnings:?}");
    let m = &s.materials[0].maps;
    assert_eq!(m.emissive, Vec3::new(0.4, 0.3, 0.1));
    assert!(m.emissive_texture.is_some() && m.occlusion.is_some());

    let emitted = DVec3::new(0.4, 0.3, 0.1)
        * DVec3::from_array(
            emissive_texel.map(|c| srgb_to_linear(c as f64 / 255.0))[..3]
                .try_into()
                .unwrap(),
        );
    let ao = occlusion_factor(occlusion_texel[0] as f64 / 255.0, 0.75);
    let albedo = DVec3::splat(0.7);
    let model = |emits: bool, occludes: bool| {
        move |p: DVec3, _: DVec2, _: [f64; 4]| {
            (
                surface(p, DVec3::Z, albedo),
                if emits { emitted } else { DVec3::ZERO },
                if occludes { ao } else { 1.0 },
            )
        }
    };
    let want = oracle(&s, &model(true, true));
    for (what, without) in [
        ("emission", oracle(&s, &model(false, true))),
        ("occlusion", oracle(&s, &model(true, false))),
    ] {
        assert_changes(&want, &without, 20.0, what);
    }
    check_every_method("emission and occlusion", &s, &want, 3.0);
}

#[test]
fn vertex_colours_multiply_the_base_colour() {
    let dir = tempfile::tempdir().unwrap();
    let colours: [[u8; 4]; 4] = [
        [255, 40, 40, 255],
        [40, 255, 60, 255],
        [50, 60, 255, 255],
        [255, 255, 255, 128],
    ];
    let material = json!({
        "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.8, 0.7, 1.0], "roughnessFactor": 1.0,
                                 "metallicFactor": 0.0},
    });
    let mut plane = Plane::new(material);
    plane.extra.push((
        "COLOR_0",
        UNSIGNED_BYTE,
        "VEC4",
        colours.as_flattened().to_vec(),
    ));
    let path = plane.write(dir.path(), "colours.gltf");
    let lights = vec![Light::point(DVec3::new(0.3, 0.2, 1.2), 5.0, Vec3::ONE, 3.0)];
    let (s, warnings) = scene_of(&path, lights, 0.1);
    assert!(warnings.is_empty(), "{warnings:?}");
    let base = DVec3::new(0.9, 0.8, 0.7);
    let corner = |k: usize| {
        DVec3::new(
            colours[k][0] as f64,
            colours[k][1] as f64,
            colours[k][2] as f64,
        ) / 255.0
    };
    let coloured = |p: DVec3, _: DVec2, w: [f64; 4]| {
        let c: DVec3 = (0..4).map(|k| corner(k) * w[k]).sum();
        (surface(p, DVec3::Z, base * c), DVec3::ZERO, 1.0)
    };
    let plain = |p: DVec3, _: DVec2, _: [f64; 4]| (surface(p, DVec3::Z, base), DVec3::ZERO, 1.0);
    let want = oracle(&s, &coloured);
    assert_changes(&want, &oracle(&s, &plain), 40.0, "vertex colours");
    check_every_method("vertex colours", &s, &want, 3.0);
}

#[test]
fn a_required_texture_transform_offsets_rotates_and_scales_the_base_colour() {
    check_transformed_base_colour(Vec2::new(0.3, 0.1), "texture transform");
}

/// An offset far from 0 (a texture scrolled for hours) draws as its remainder through the
/// REPEAT wrap: added in f32 per vertex, 65 536 kept coordinates 2⁻⁷ of the texture apart
/// (19/255 on llvmpipe, 122/255 on SwiftShader) and 10⁶ 1/16 of it.
#[test]
fn a_far_texture_offset_draws_as_its_remainder() {
    check_transformed_base_colour(Vec2::new(65_536.25, -1_000_000.5), "far offset");
}

/// A base colour texture through a required transform of `offset`, a rotation and a scale,
/// against the twin on every method and level.
fn check_transformed_base_colour(offset: Vec2, what: &str) {
    let dir = tempfile::tempdir().unwrap();
    let texels = [
        [230u8, 40, 40, 255],
        [40, 220, 60, 255],
        [40, 60, 230, 255],
        [230, 230, 60, 255],
    ];
    let transform = TextureTransform {
        offset,
        rotation: 0.5,
        scale: Vec2::new(0.7, 1.3),
        uv_set: 0,
    };
    let material = json!({
        "pbrMetallicRoughness": {
            "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {
                "offset": [offset.x, offset.y], "rotation": 0.5, "scale": [0.7, 1.3]}}},
            "roughnessFactor": 1.0,
            "metallicFactor": 0.0,
        },
    });
    let mut plane = Plane::new(material);
    plane.images.push(png(2, 2, &texels));
    plane.extensions.push("KHR_texture_transform");
    plane.required = true;
    let path = plane.write(dir.path(), "transform.gltf");
    let lights = vec![Light::point(
        DVec3::new(-0.2, 0.3, 1.5),
        6.0,
        Vec3::ONE,
        3.0,
    )];
    let (s, warnings) = scene_of(&path, lights, 0.15);
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(s.materials[0].maps.base_transform, transform);
    // Decoded after filtering (ES 2.0) or before (ES 3.0's sRGB textures).
    let model = |t: TextureTransform, decoded_first: bool| {
        move |p: DVec3, uv: DVec2, _: [f64; 4]| {
            let albedo = bilinear_colour(&texels, 2, 2, t.apply(uv), decoded_first);
            (surface(p, DVec3::Z, albedo), DVec3::ZERO, 1.0)
        }
    };
    let want = [false, true].map(|first| oracle(&s, &model(transform, first)));
    assert_changes(
        &want[0],
        &oracle(&s, &model(TextureTransform::IDENTITY, false)),
        40.0,
        "the transform",
    );
    // Filtering decoded texels (glTF 2.0 §3.9.2) is visibly brighter between dark and light
    // texels than decoding the filtered value.
    let order = assert_changes(&want[0], &want[1], 10.0, "decode order");
    eprintln!("decoding before filtering changes the picture by {order:.1}/255");
    check_every_method_by_level(what, &s, [&want[0], &want[1]], 3.0);
}

/// A transform's `texCoord` that is not a set number (a string, a fraction, negative, past
/// 2³² − 1) on a normal texture makes the transform malformed: a warning, and the texture
/// bound on its own set without it, not the rest of the transform applied silently.
#[test]
fn a_transform_whose_set_is_not_a_number_is_malformed() {
    let dir = tempfile::tempdir().unwrap();
    for set in [json!("x"), json!(1.5), json!(-1), json!(4294967296u64)] {
        let material = json!({
            "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
            "normalTexture": {"index": 0, "extensions": {"KHR_texture_transform": {
                "texCoord": set, "scale": [2, 2]}}},
        });
        let mut plane = Plane::new(material);
        plane.images.push(png(1, 1, &[[128, 128, 255, 255]]));
        plane.extensions.push("KHR_texture_transform");
        let path = plane.write(dir.path(), "set.gltf");
        let (s, warnings) = scene_of(&path, grazing_light(), 0.1);
        let all = warnings.join("\n");
        assert!(
            all.contains("normalTexture.extensions.KHR_texture_transform: malformed"),
            "texCoord {set}: {all}"
        );
        let normal = s.materials[0]
            .maps
            .normal
            .as_ref()
            .expect("normal map bound");
        assert!(normal.transform.is_identity(), "texCoord {set}");
    }
}

#[test]
fn other_texture_sets_malformed_transforms_and_every_colour_format_are_handled() {
    let dir = tempfile::tempdir().unwrap();
    let material = json!({
        "pbrMetallicRoughness": {
            "baseColorTexture": {"index": 0},
            "metallicRoughnessTexture": {"index": 0},
        },
        "normalTexture": {"index": 0, "extensions": {"KHR_texture_transform": {
            "offset": [0.5], "rotation": 0.5}}},
        "emissiveFactor": [1.0, 1.0, 1.0],
        "emissiveTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"texCoord": 1}}},
        "occlusionTexture": {"index": 0, "texCoord": 1},
    });
    let mut plane = Plane::new(material);
    plane.images.push(png(1, 1, &[[10, 20, 30, 255]]));
    plane.extensions.push("KHR_texture_transform");
    let colours: Vec<u8> = [0.5f32, 0.25, 2.0]
        .repeat(4)
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    plane.extra.push(("COLOR_0", FLOAT, "VEC3", colours));
    let path = plane.write(dir.path(), "sets.gltf");
    let (s, warnings) = scene_of(&path, grazing_light(), 0.1);
    let all = warnings.join("\n");
    assert!(
        all.contains("normalTexture.extensions.KHR_texture_transform: malformed"),
        "{all}"
    );
    assert!(
        all.contains("(occlusionTexture, emissiveTexture) on TEXCOORD_1, which the primitive"),
        "{all}"
    );
    assert!(
        all.contains("COLOR_0") && all.contains("outside [0, 1]"),
        "{all}"
    );
    assert_eq!(warnings.len(), 3, "{all}");
    let m = &s.materials[0];
    assert!(m.diffuse_texture.is_some() && m.maps.base_transform.is_identity());
    let normal = m.maps.normal.as_ref().expect("normal map bound");
    assert!(normal.transform.is_identity());
    assert!(m.maps.metallic_roughness.is_some());
    // Kept for a mesh with the second set; this one has none, so they are not sampled.
    let second = |t: &Option<manylight::MapTexture>| t.as_ref().unwrap().transform.uv_set == 1;
    assert!(second(&m.maps.emissive_texture) && second(&m.maps.occlusion));
    let mesh = &s.objects[0].mesh;
    // Float colours are clamped to [0, 1] (warned of above); VEC3 gets alpha 1.
    assert!(mesh
        .colors
        .iter()
        .all(|c| *c == glam::Vec4::new(0.5, 0.25, 1.0, 1.0)));
    assert_eq!(mesh.tangents.len(), 4, "generated for the normal map");

    // 16-bit normalized colours read too; a SCALAR one is ignored with a warning.
    let mut plane = Plane::new(json!({}));
    let colours: Vec<u8> = [65535u16, 0, 32768, 65535]
        .repeat(4)
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    plane
        .extra
        .push(("COLOR_0", UNSIGNED_SHORT, "VEC4", colours));
    let (s, _) = scene_of(&plane.write(dir.path(), "u16.gltf"), vec![], 0.1);
    let c = s.objects[0].mesh.colors[0];
    assert!(
        s.objects[0].mesh.tangents.is_empty(),
        "tangents only for normal maps"
    );
    assert!(
        (c - glam::Vec4::new(1.0, 0.0, 0.5, 1.0))
            .abs()
            .max_element()
            < 1e-4,
        "{c}"
    );
    let mut plane = Plane::new(json!({}));
    plane.extra.push(("COLOR_0", FLOAT, "SCALAR", vec![0; 16]));
    let (s, warnings) = scene_of(&plane.write(dir.path(), "scalar.gltf"), vec![], 0.1);
    assert!(s.objects[0].mesh.colors.is_empty());
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("COLOR_0") && w.contains("ignored")),
        "{warnings:?}"
    );
    // All white and opaque multiplies by 1, as exporters often write it: the mesh keeps no
    // colours (16 bytes a vertex and a variant less); one element off white keeps them all.
    for (name, last, kept) in [("white.gltf", 65535u16, false), ("grey.gltf", 65534, true)] {
        let mut plane = Plane::new(json!({}));
        let mut colours = [65535u16; 16];
        colours[15] = last;
        let bytes = colours.iter().flat_map(|v| v.to_le_bytes()).collect();
        plane.extra.push(("COLOR_0", UNSIGNED_SHORT, "VEC4", bytes));
        let (s, _) = scene_of(&plane.write(dir.path(), name), vec![], 0.1);
        assert_eq!(!s.objects[0].mesh.colors.is_empty(), kept, "{name}");
    }
    let mut plane = Plane::new(json!({}));
    let white: Vec<u8> = [1.0f32; 12].iter().flat_map(|v| v.to_le_bytes()).collect();
    plane.extra.push(("COLOR_0", FLOAT, "VEC3", white));
    let (s, _) = scene_of(&plane.write(dir.path(), "white3.gltf"), vec![], 0.1);
    assert!(s.objects[0].mesh.colors.is_empty(), "white VEC3");
}

/// Pay for use: a variant without the surface inputs has none of their code, attributes or
/// varyings; each input's variant has its own.
#[test]
fn variants_without_surface_inputs_contain_none_of_their_code() {
    use manylight::gl::shader_source::{assemble, Stage};
    use manylight::methods::ShaderFeatures as F;
    let needles = [
        (F::VERTEX_COLOR, "a_color", Stage::Vertex),
        (F::VERTEX_COLOR, "v_color", Stage::Fragment),
        (F::NORMAL_MAP, "a_tangent", Stage::Vertex),
        (F::NORMAL_MAP, "u_normalTex", Stage::Fragment),
        (F::EMISSIVE, "u_emissive", Stage::Fragment),
        (
            F::EMISSIVE | F::EMISSIVE_MAP,
            "u_emissiveTex",
            Stage::Fragment,
        ),
        (F::OCCLUSION, "u_occlusionTex", Stage::Fragment),
        (
            F::MR_TEXTURE | F::METALLIC_ROUGHNESS,
            "u_metallicRoughnessTex",
            Stage::Fragment,
        ),
        (F::TEXTURE_TRANSFORM, "u_albedoUvTransform", Stage::Vertex),
        (F::TEXTURE_TRANSFORM, "v_uvAlbedoNormal", Stage::Fragment),
        (F::SECOND_UVS | F::TEXTURE_TRANSFORM, "a_uv1", Stage::Vertex),
        (
            F::SECOND_UVS | F::TEXTURE_TRANSFORM,
            "u_occlusionUvSet",
            Stage::Vertex,
        ),
    ];
    for es in [EsVersion::Es2, EsVersion::Es3] {
        for shader in ["forward", "clustered"] {
            let source = |f: F, stage| assemble(shader, stage, es, &f.defines(es, 64)).unwrap();
            for (bits, needle, stage) in needles {
                let lean = source(F(F::TEXTURE), stage);
                assert!(
                    !lean.contains(needle),
                    "{shader} {es}: `{needle}` without its feature"
                );
                let with = source(F(bits | F::TEXTURE), stage);
                assert!(with.contains(needle), "{shader} {es}: `{needle}` missing");
            }
        }
    }
}

/// Values past f32 in the file (1e300 reads as infinity) were replaced without a word: each is
/// now warned of, naming its path; an infinite emissive strength is clamped as a large one is,
/// both keeping the emission's hue.
#[test]
fn values_past_f32_are_warned_of_by_path() {
    let dir = tempfile::tempdir().unwrap();
    let material = json!({
        "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.7, 0.6, 1.0]},
        "normalTexture": {"index": 0, "scale": 1e300},
        "occlusionTexture": {"index": 0, "strength": 1e300},
        "emissiveFactor": [1.0, 0.5, 0.0],
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 1e300}},
    });
    let mut plane = Plane::new(material);
    plane.images.push(png(1, 1, &[[128, 128, 255, 255]]));
    plane.extensions.push("KHR_materials_emissive_strength");
    let path = plane.write(dir.path(), "huge.gltf");
    let (s, warnings) = scene_of(&path, grazing_light(), 0.02);
    let all = warnings.join("\n");
    for needle in [
        "normalTexture.scale",
        "occlusionTexture.strength",
        "KHR_materials_emissive_strength",
    ] {
        assert!(all.contains(needle), "{needle}: {all}");
    }
    let maps = &s.materials[0].maps;
    assert_eq!((maps.normal_scale, maps.occlusion_strength), (1.0, 1.0));
    // The factor's hue at the cap: clamped channel by channel it was (1024, 1024, 0).
    assert_eq!(maps.emissive, Vec3::new(1024.0, 512.0, 0.0));
    // Finite and huge, the values are written short: `{}` wrote 3e38 in 39 digits.
    let material = json!({
        "pbrMetallicRoughness": {"baseColorFactor": [3e38, 0.5, 0.5, 1.0]},
        "normalTexture": {"index": 0, "scale": 3e38},
        "emissiveFactor": [1.0, 0.5, 0.0],
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 3e38}},
    });
    let mut plane = Plane::new(material);
    plane.images.push(png(1, 1, &[[128, 128, 255, 255]]));
    plane.extensions.push("KHR_materials_emissive_strength");
    let path = plane.write(dir.path(), "finite.gltf");
    let (s, warnings) = scene_of(&path, grazing_light(), 0.02);
    let all = warnings.join("\n");
    assert!(all.contains("normalTexture.scale: 3e38 taken as"), "{all}");
    assert!(
        all.contains("strength [3e38, 1.5e38, 0] clamped to [1024, 512, 0]"),
        "{all}"
    );
    assert_eq!(s.materials[0].maps.emissive, Vec3::new(1024.0, 512.0, 0.0));
    // A factor past f32 at strength 0 emits nothing (0 × ∞), as at any other strength 0.
    let material = json!({
        "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.7, 0.6, 1.0]},
        "emissiveFactor": [1e300, 0.5, 0.0],
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 0.0}},
    });
    let mut plane = Plane::new(material);
    plane.extensions.push("KHR_materials_emissive_strength");
    let path = plane.write(dir.path(), "dark.gltf");
    let (s, _) = scene_of(&path, grazing_light(), 0.02);
    assert_eq!(s.materials[0].maps.emissive, Vec3::ZERO);
    assert!(
        all.contains("baseColorFactor [3e38, 0.5, 0.5] clamped to [1024, 0.5, 0.5]"),
        "{all}"
    );
    assert!(!all.contains("00000000"), "{all}");
}
