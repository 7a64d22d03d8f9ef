//! Texture coordinates and texture transforms past ±`MAX_TEXCOORD` (1e9): a transformed
//! coordinate, or its difference across a triangle, overflowed f32 and the lookup gave NaN, so
//! the whole surface drew black without a word. Now an OBJ `vt` or a glTF `TEXCOORD_0` out of
//! range is an error naming it, a glTF transform out of range is ignored with a warning, a
//! material built in code is refused naming the transform, and a surface at the bounds
//! renders.

use crate::common;

use std::sync::Arc;

use common::files::{load, write};
use common::gltf::Builder;
use common::Gpu;
use glam::{DMat4, DVec3, Vec2, Vec3};
use manylight::scene::mesh::MAX_TEXCOORD;
use manylight::scene::surface_maps::TextureTransform;
use manylight::scene::{Camera, Light, Material, Mesh, Object, Scene, Texture};
use manylight::{EsVersion, RenderOptions};
use serde_json::json;

#[test]
fn an_obj_texture_coordinate_out_of_range_is_an_error_naming_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 3e38 0\nvt 0 1\nf 1/1 2/2 3/3\n";
    let err = load(&write(dir.path(), "far.obj", obj))
        .unwrap_err()
        .to_string();
    assert!(err.contains("line 5") && err.contains("±1e9"), "{err}");
}

#[test]
fn a_gltf_texture_coordinate_out_of_range_is_an_error_and_a_transform_is_ignored() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let p = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3");
    let far = b.floats(&[0.0, 0.0, 3e38, 0.0, 0.0, 1.0], "VEC2");
    let near = b.floats(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0], "VEC2");
    let doc = |uv: usize, transform: serde_json::Value| {
        json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
            "extensionsUsed": ["KHR_texture_transform"],
            "materials": [{"emissiveFactor": [1, 1, 1], "emissiveTexture": {"index": 0,
                "extensions": {"KHR_texture_transform": transform}}}],
            "textures": [{"source": 0}],
            "images": [{"uri": format!("data:image/png;base64,{}",
                common::gltf::base64(&common::gltf_models::checker_png()))}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": p, "TEXCOORD_0": uv},
                "material": 0}]}]})
    };
    let err = load(&write(dir.path(), "far.gltf", b.gltf(doc(far, json!({})))))
        .unwrap_err()
        .to_string();
    assert!(err.contains("uvs[1]") && err.contains("1e9"), "{err}");
    let huge = json!({"scale": [2e38, 1], "offset": [2e38, 0]});
    let (scene, report) = load(&write(dir.path(), "t.gltf", b.gltf(doc(near, huge)))).unwrap();
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("KHR_texture_transform") && w.contains("ignored")),
        "{:?}",
        report.warnings
    );
    scene.validate().unwrap();
}

/// One textured quad facing the camera, lit by a point light and ambient.
fn quad_scene(uv_at: f32, transform: TextureTransform) -> Scene {
    let mut scene = Scene::empty();
    let texture = Arc::new(Texture::new(
        "checker",
        image::RgbaImage::from_fn(4, 4, |x, y| {
            image::Rgba(if (x + y) % 2 == 0 {
                [220, 200, 180, 255]
            } else {
                [90, 120, 200, 255]
            })
        }),
    ));
    let mut material = Material::flat("quad", Vec3::ONE);
    material.diffuse_texture = Some(texture);
    material.maps.base_transform = transform;
    let m = scene.add_material(material);
    let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    let positions = corners.map(|(x, y)| Vec3::new(x, y, 0.0)).to_vec();
    let uvs = corners.map(|(x, y)| Vec2::new(x, y) * uv_at).to_vec();
    let mesh = Mesh::new(positions, vec![Vec3::Z; 4], uvs, vec![0, 1, 2, 0, 2, 3]).unwrap();
    scene.objects.push(Object {
        mesh: Arc::new(mesh),
        material: m,
        transform: DMat4::IDENTITY,
    });
    scene.camera = Camera::perspective(DVec3::new(0.0, 0.0, 2.0), DVec3::ZERO, 60.0, 0.1, 10.0);
    scene.lights = vec![Light::point(DVec3::new(0.0, 0.0, 1.0), 4.0, Vec3::ONE, 2.0)];
    scene.ambient = Vec3::splat(0.2);
    scene
}

#[test]
fn a_material_with_a_transform_out_of_range_is_refused_naming_it() {
    let transform = TextureTransform {
        scale: Vec2::new(1.0, 2.0 * MAX_TEXCOORD),
        uv_set: 0,
        ..TextureTransform::IDENTITY
    };
    let err = quad_scene(1.0, transform)
        .validate()
        .unwrap_err()
        .to_string();
    assert!(err.contains("maps.base_transform"), "{err}");
}

/// Coordinates and a transform at the bounds draw the surface (checker colours, possibly
/// aliased), not black, on ES 2.0 and 3.0.
#[test]
fn a_surface_at_the_bounds_renders() {
    let transform = TextureTransform {
        offset: Vec2::splat(MAX_TEXCOORD),
        rotation: 0.7,
        scale: Vec2::splat(MAX_TEXCOORD),
        uv_set: 0,
    };
    let scene = quad_scene(MAX_TEXCOORD, transform);
    scene.validate().unwrap();
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::new(es);
        let (img, _) = gpu
            .r()
            .render_offscreen(&scene, 64, 36, &RenderOptions::default())
            .unwrap();
        // The quad covers the middle of the frame: every pixel there is lit.
        for (x, y) in [(32, 18), (20, 12), (44, 24)] {
            let p = img.get_pixel(x, y);
            assert!(p[0].max(p[1]).max(p[2]) > 20, "{es}: ({x}, {y}) is {p:?}");
        }
    }
}
