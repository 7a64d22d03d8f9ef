//! Textures on `TEXCOORD_1` (a baked occlusion map's own unwrap): each texture samples the set
//! its `texCoord` (or its transform's `texCoord`) names, a normal map's generated tangents
//! follow its set, and a primitive without the set a texture reads draws without it.

use super::*;

/// Set in the child that runs a test again on Mesa capped to ES 2.0 without vertex array
/// objects (a Mali-400's context): only the ES 2.0 levels are drawn there.
pub const PURE_ES2: &str = "MANYLIGHT_TEST_PURE_ES2";

/// The plane's second set: its first turned half a turn, `(1 − u, 1 − v)`, so a texture read
/// through the wrong set shows.
const SECOND_UVS: [f32; 8] = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0];

fn second_set(uv: DVec2) -> DVec2 {
    DVec2::ONE - uv
}

fn with_second_set(material: serde_json::Value) -> Plane {
    let mut plane = Plane::new(material);
    let bytes = SECOND_UVS.iter().flat_map(|v| v.to_le_bytes()).collect();
    plane.extra.push(("TEXCOORD_1", FLOAT, "VEC2", bytes));
    plane
}

#[test]
fn the_base_colour_and_occlusion_sample_the_set_they_name() {
    let dir = tempfile::tempdir().unwrap();
    let texels = [
        [230u8, 40, 40, 255],
        [40, 220, 60, 255],
        [40, 60, 230, 255],
        [230, 230, 60, 255],
    ];
    let occlusion = [[30u8, 0, 0, 255], [255, 0, 0, 255]];
    // The occlusion reads set 1 through its transform's override of `texCoord` 0, scaled.
    let scale = Vec2::new(1.5, 1.0);
    let material = json!({
        "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1},
                                 "roughnessFactor": 1.0, "metallicFactor": 0.0},
        "occlusionTexture": {"index": 1, "extensions": {"KHR_texture_transform": {
            "texCoord": 1, "scale": [1.5, 1.0]}}},
    });
    let mut plane = with_second_set(material);
    plane.images.push(png(2, 2, &texels));
    plane.images.push(png(2, 1, &occlusion));
    plane.extensions.push("KHR_texture_transform");
    let path = plane.write(dir.path(), "second_set.gltf");
    let (s, warnings) = scene_of(&path, grazing_light(), 0.5);
    assert!(warnings.is_empty(), "{warnings:?}");
    let mesh = &s.objects[0].mesh;
    assert_eq!(mesh.second_uvs.len(), 4, "TEXCOORD_1 read");
    let maps = &s.materials[0].maps;
    assert_eq!(maps.base_transform.uv_set, 1);
    let occlusion_transform = maps.occlusion.as_ref().expect("occlusion bound").transform;
    assert_eq!(
        occlusion_transform,
        TextureTransform {
            scale,
            uv_set: 1,
            ..TextureTransform::IDENTITY
        }
    );
    // `set` picks the coordinates the textures read: the second set (right), or the first.
    let model = |set: fn(DVec2) -> DVec2, decoded_first: bool| {
        move |p: DVec3, uv: DVec2, _: [f64; 4]| {
            let uv = set(uv);
            let albedo = bilinear_colour(&texels, 2, 2, uv, decoded_first);
            let ao = bilinear_linear(&occlusion, 2, 1, uv * scale.as_dvec2()).x;
            (surface(p, DVec3::Z, albedo), DVec3::ZERO, ao)
        }
    };
    let want = [false, true].map(|first| oracle(&s, &model(second_set, first)));
    let first_set = oracle(&s, &model(|uv| uv, false));
    assert_changes(&want[0], &first_set, 40.0, "the set");
    check_every_method_by_level("second set", &s, [&want[0], &want[1]], 3.0);
}

#[test]
fn a_normal_map_on_the_second_set_gets_its_tangents_along_that_set() {
    let dir = tempfile::tempdir().unwrap();
    let up = [60u8, 40, 200, 255];
    let material = json!({
        "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.7, 0.6, 1.0], "roughnessFactor": 1.0,
                                 "metallicFactor": 0.0},
        "normalTexture": {"index": 0, "scale": 0.8, "texCoord": 1},
    });
    let mut plane = with_second_set(material);
    plane.images.push(png(1, 1, &[up]));
    let path = plane.write(dir.path(), "normal_second_set.gltf");
    let (s, warnings) = scene_of(&path, grazing_light(), 0.02);
    assert!(warnings.is_empty(), "{warnings:?}");
    // The second set's u grows along −x (the first's along +x): MikkTSpace along it.
    let tangents = &s.objects[0].mesh.tangents;
    assert_eq!(tangents.len(), 4);
    for t in tangents {
        assert!(
            (*t - glam::Vec4::new(-1.0, 0.0, 0.0, 1.0)).length() < 1e-5,
            "{t}"
        );
    }
    let rgb = DVec3::new(up[0] as f64, up[1] as f64, up[2] as f64) / 255.0;
    let albedo = DVec3::new(0.8, 0.7, 0.6);
    let mapped = |tangent: DVec3| {
        move |p: DVec3, _: DVec2, _: [f64; 4]| {
            let n = perturbed_normal(DVec3::Z, tangent, 1.0, rgb, 0.8);
            (surface(p, n, albedo), DVec3::ZERO, 1.0)
        }
    };
    let want = oracle(&s, &mapped(DVec3::NEG_X));
    assert_changes(
        &want,
        &oracle(&s, &mapped(DVec3::X)),
        20.0,
        "the tangent's direction",
    );
    check_every_method("normal map on the second set", &s, &want, 3.0);
}

#[test]
fn textures_on_a_set_the_primitive_lacks_are_said_and_not_applied() {
    let dir = tempfile::tempdir().unwrap();
    let material = json!({
        "pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.6, 0.6, 1.0],
                                 "roughnessFactor": 1.0, "metallicFactor": 0.0},
        "occlusionTexture": {"index": 0, "texCoord": 1},
        "emissiveFactor": [0.1, 0.05, 0.0],
        "emissiveTexture": {"index": 0, "texCoord": 2},
    });
    // TEXCOORD_0 only.
    let mut plane = Plane::new(material);
    plane.images.push(png(1, 1, &[[20, 20, 20, 255]]));
    let path = plane.write(dir.path(), "no_second_set.gltf");
    let (s, warnings) = scene_of(&path, grazing_light(), 0.5);
    let all = warnings.join("\n");
    assert!(
        all.contains("occlusionTexture) on TEXCOORD_1, which the primitive has not"),
        "{all}"
    );
    assert!(
        all.contains("emissiveTexture: uses TEXCOORD_2; only TEXCOORD_0 and TEXCOORD_1"),
        "{all}"
    );
    assert_eq!(warnings.len(), 2, "{all}");
    assert!(s.objects[0].mesh.second_uvs.is_empty());
    assert!(s.materials[0].maps.emissive_texture.is_none());
    // The occlusion map is kept on the material (another mesh may have the set) but this
    // plane draws without it, as without any texture.
    assert!(s.materials[0].maps.occlusion.is_some());
    let emission = DVec3::new(0.1, 0.05, 0.0);
    let model = |ao: f64| {
        move |p: DVec3, _: DVec2, _: [f64; 4]| {
            (surface(p, DVec3::Z, DVec3::splat(0.6)), emission, ao)
        }
    };
    let want = oracle(&s, &model(1.0));
    assert_changes(
        &want,
        &oracle(&s, &model(20.0 / 255.0)),
        20.0,
        "the occlusion",
    );
    check_every_method("a set the primitive lacks", &s, &want, 3.0);
}

/// Without vertex array objects the arrays are the context's: the second set's array at
/// location 5 is pointed and switched off draw by draw (`gl::mesh`).
#[test]
fn the_second_set_draws_on_es2_without_vertex_arrays() {
    if std::env::var_os(PURE_ES2).is_some()
        || crate::common::other_implementation_than_mesa("MESA_GLES_VERSION_OVERRIDE")
    {
        return;
    }
    let envs = [
        ("MESA_GLES_VERSION_OVERRIDE", "2.0"),
        ("MESA_EXTENSION_OVERRIDE", "-GL_OES_vertex_array_object"),
        (PURE_ES2, "1"),
    ];
    for test in [
        "second_set::the_base_colour_and_occlusion_sample_the_set_they_name",
        "second_set::a_normal_map_on_the_second_set_gets_its_tangents_along_that_set",
    ] {
        crate::common::child::rerun_with(test, &envs, "on ES 2.0 without vertex arrays");
    }
}

/// The second set and tangents are kept only for textures that are drawn: an emissive texture
/// of a material that does not emit reads nothing, a normal map on a set past 1 is not bound
/// and takes none of the file's tangents, and neither an occlusion map whose image does not
/// decode nor a normal map of scale 0 whose texels all face out (`turns_no_normal`) keeps the
/// set or tangents.
#[test]
fn a_mesh_keeps_the_second_set_and_tangents_only_for_textures_drawn() {
    let dir = tempfile::tempdir().unwrap();
    let unlit = json!({"emissiveTexture": {"index": 0, "texCoord": 1}});
    let mut plane = with_second_set(unlit);
    plane.images.push(png(1, 1, &[[200, 200, 200, 255]]));
    let (s, warnings) = scene_of(&plane.write(dir.path(), "unlit.gltf"), vec![], 0.5);
    assert!(warnings.is_empty(), "{warnings:?}");
    assert!(
        s.objects[0].mesh.second_uvs.is_empty(),
        "read for no texture"
    );

    let third = json!({"occlusionTexture": {"index": 0, "texCoord": 1},
                       "normalTexture": {"index": 0, "texCoord": 2}});
    let mut plane = with_second_set(third);
    plane.images.push(png(1, 1, &[[200, 200, 200, 255]]));
    let tangents = [1.0f32, 0.0, 0.0, 1.0].repeat(4);
    let bytes = tangents.iter().flat_map(|v| v.to_le_bytes()).collect();
    plane.extra.push(("TANGENT", FLOAT, "VEC4", bytes));
    let (s, warnings) = scene_of(&plane.write(dir.path(), "third.gltf"), vec![], 0.5);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].contains("normalTexture: uses TEXCOORD_2"),
        "{warnings:?}"
    );
    let mesh = &s.objects[0].mesh;
    assert_eq!(mesh.second_uvs.len(), 4, "read for the occlusion");
    assert!(
        mesh.tangents.is_empty(),
        "tangents for an unbound normal map"
    );

    let undecodable = json!({"occlusionTexture": {"index": 0, "texCoord": 1}});
    let mut plane = with_second_set(undecodable);
    plane.images.push(b"not a PNG".to_vec());
    let (s, warnings) = scene_of(&plane.write(dir.path(), "broken.gltf"), vec![], 0.5);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains("images[0]"), "{warnings:?}");
    assert!(s.materials[0].maps.occlusion.is_none());
    assert!(
        s.objects[0].mesh.second_uvs.is_empty(),
        "read for an image that did not decode"
    );

    let flat = json!({"normalTexture": {"index": 0, "texCoord": 1, "scale": 0.0}});
    let mut plane = with_second_set(flat);
    plane.images.push(png(1, 1, &[[128, 128, 255, 255]]));
    let (s, warnings) = scene_of(&plane.write(dir.path(), "flat.gltf"), vec![], 0.5);
    assert!(warnings.is_empty(), "{warnings:?}");
    assert!(
        s.materials[0].maps.normal.is_none(),
        "a normal map of scale 0 whose texels all face out was kept"
    );
    let mesh = &s.objects[0].mesh;
    assert!(
        mesh.second_uvs.is_empty(),
        "read for a normal map of scale 0"
    );
    assert!(
        mesh.tangents.is_empty(),
        "tangents for a normal map of scale 0"
    );
}
