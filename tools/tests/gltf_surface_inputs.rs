//! glTF surface inputs as artists export them, on files the tests write: a normal-mapped plane
//! under a grazing light (tangents from the file and generated), emission with its strength
//! and texture plus ambient occlusion, `COLOR_0` vertex colours, and a base colour texture
//! through `KHR_texture_transform` (a required extension). Each picture is checked pixel by
//! pixel against the f64 twin (`manylight::scene::shading` + `surface_maps`), each oracle is
//! checked to differ from the one without its feature (so the test can fail), and tiled,
//! clustered and deferred must equal forward on ES 2.0 and 3.0.

mod common;

use std::path::{Path, PathBuf};

use common::Gpu;
use glam::{DVec2, DVec3, Vec2, Vec3};
use manylight::scene::raycast::pixel_ray;
use manylight::scene::shading::{self, linear_to_srgb, srgb_to_linear, Surface};
use manylight::scene::surface_maps::{occlusion_factor, perturbed_normal, TextureTransform};
use manylight::scene::{self, Camera, Light, Scene};
use manylight::{EsVersion, RenderOptions};
use serde_json::{json, Value};

const W: u32 = 96;
const H: u32 = 54;
const FLOAT: u32 = 5126;
const UNSIGNED_BYTE: u32 = 5121;
const UNSIGNED_SHORT: u32 = 5123;

/// The plane: z = 0, x and y in [−1, 1], facing +Z; u along +x, v down the image (−y).
const CORNERS: [[f32; 3]; 4] = [
    [-1.0, -1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
];
const UVS: [[f32; 2]; 4] = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]];
const TRIANGLES: [u16; 6] = [0, 1, 2, 0, 2, 3];

fn b64(bytes: &[u8]) -> String {
    use base64::Engine;
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

fn png(w: u32, h: u32, texels: &[[u8; 4]]) -> Vec<u8> {
    let img = image::RgbaImage::from_fn(w, h, |x, y| image::Rgba(texels[(y * w + x) as usize]));
    let mut out = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png)
        .unwrap();
    out
}

/// One plane primitive with `material` and optional extra attributes, its images as data URIs
/// (image i is texture i), `extensions` listed as used (and required when `required`).
struct Plane {
    material: Value,
    images: Vec<Vec<u8>>,
    /// (semantic, component type, type, raw bytes)
    extra: Vec<(&'static str, u32, &'static str, Vec<u8>)>,
    extensions: Vec<&'static str>,
    required: bool,
}

impl Plane {
    fn new(material: Value) -> Plane {
        Plane {
            material,
            images: Vec::new(),
            extra: Vec::new(),
            extensions: Vec::new(),
            required: false,
        }
    }

    fn write(&self, dir: &Path, name: &str) -> PathBuf {
        let mut bin = Vec::new();
        let (mut views, mut accessors) = (Vec::new(), Vec::new());
        let mut add = |bytes: &[u8], component: u32, ty: &str, count: usize| {
            while bin.len() % 4 != 0 {
                bin.push(0);
            }
            views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()}));
            bin.extend_from_slice(bytes);
            let mut a = json!({"bufferView": views.len() - 1, "componentType": component,
                               "type": ty, "count": count});
            if component != FLOAT && ty != "SCALAR" {
                a["normalized"] = json!(true);
            }
            accessors.push(a);
            accessors.len() - 1
        };
        let f32s = |v: &[f32]| -> Vec<u8> { v.iter().flat_map(|x| x.to_le_bytes()).collect() };
        let p = add(&f32s(CORNERS.as_flattened()), FLOAT, "VEC3", 4);
        let n = add(&f32s(&[0.0, 0.0, 1.0].repeat(4)), FLOAT, "VEC3", 4);
        let t = add(&f32s(UVS.as_flattened()), FLOAT, "VEC2", 4);
        let idx: Vec<u8> = TRIANGLES.iter().flat_map(|i| i.to_le_bytes()).collect();
        let i = add(&idx, UNSIGNED_SHORT, "SCALAR", 6);
        let mut attributes = json!({"POSITION": p, "NORMAL": n, "TEXCOORD_0": t});
        for (semantic, component, ty, bytes) in &self.extra {
            attributes[*semantic] = json!(add(bytes, *component, ty, 4));
        }
        let images: Vec<Value> = self
            .images
            .iter()
            .map(|png| json!({"uri": format!("data:image/png;base64,{}", b64(png))}))
            .collect();
        let textures: Vec<Value> = (0..images.len()).map(|i| json!({"source": i})).collect();
        let mut doc = json!({
            "asset": {"version": "2.0"},
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": attributes, "indices": i, "material": 0}]}],
            "materials": [self.material],
            "buffers": [{"byteLength": bin.len(),
                         "uri": format!("data:application/octet-stream;base64,{}", b64(&bin))}],
            "bufferViews": views,
            "accessors": accessors,
        });
        if !images.is_empty() {
            doc["images"] = json!(images);
            doc["textures"] = json!(textures);
        }
        if !self.extensions.is_empty() {
            doc["extensionsUsed"] = json!(self.extensions);
            if self.required {
                doc["extensionsRequired"] = json!(self.extensions);
            }
        }
        let path = dir.join(name);
        std::fs::write(&path, doc.to_string()).unwrap();
        path
    }
}

/// Loads a written file with the view, lights and ambient every test uses.
fn scene_of(path: &Path, lights: Vec<Light>, ambient: f32) -> (Scene, Vec<String>) {
    let (mut s, report) = scene::load(path.to_str().unwrap(), Some((0, 1))).expect("loads");
    s.camera = Camera::perspective(DVec3::new(0.0, -0.4, 1.6), DVec3::ZERO, 60.0, 0.1, 20.0);
    s.lights = lights;
    s.ambient = Vec3::splat(ambient);
    s.validate().unwrap();
    (s, report.warnings)
}

/// What the f64 twin needs at one point of the plane: (point, uv, barycentric weights of the
/// quad's corners) → (surface, emitted radiance, ambient occlusion).
type Model<'a> = dyn Fn(DVec3, DVec2, [f64; 4]) -> (Surface, DVec3, f64) + 'a;

/// sRGB 8-bit values the twin expects at every pixel whose centre sees the plane's interior
/// (`None` near its edges and off it).
fn oracle(scene: &Scene, model: &Model) -> Vec<Option<[f64; 3]>> {
    let mut out = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let (o, d) = pixel_ray(&scene.camera, W, H, x as f64 + 0.5, y as f64 + 0.5);
            let t = -o.z / d.z;
            let p = o + d * t;
            if !(t > 0.0 && p.x.abs() < 0.93 && p.y.abs() < 0.93) {
                out.push(None);
                continue;
            }
            let uv = DVec2::new((p.x + 1.0) / 2.0, (1.0 - p.y) / 2.0);
            let (surface, emitted, ao) = model(p, uv, corner_weights(p));
            let v = (scene.camera.position - p).normalize();
            let mut c = shading::shade(&surface, v, &scene.lights, Vec3::ZERO);
            c += scene.ambient.as_dvec3() * surface.albedo * ao + emitted;
            out.push(Some([0, 1, 2].map(|k| linear_to_srgb(c[k]) * 255.0)));
        }
    }
    out
}

/// Barycentric weights of point `p` over the quad's corners, in the triangle that holds it
/// (0 1 2 or 0 2 3): how the rasterizer interpolates vertex attributes.
fn corner_weights(p: DVec3) -> [f64; 4] {
    let c = CORNERS.map(|c| DVec2::new(c[0] as f64, c[1] as f64));
    let q = p.truncate();
    let bary = |a: DVec2, b: DVec2, cc: DVec2| {
        let area = (b - a).perp_dot(cc - a);
        let wa = (b - q).perp_dot(cc - q) / area;
        let wb = (cc - q).perp_dot(a - q) / area;
        [wa, wb, 1.0 - wa - wb]
    };
    let [a, b, cc] = bary(c[0], c[1], c[2]);
    if a >= 0.0 && b >= 0.0 && cc >= 0.0 {
        return [a, b, cc, 0.0];
    }
    let [a, b, cc] = bary(c[0], c[2], c[3]);
    [a, 0.0, b, cc]
}

/// The glTF default surface of the tests' materials (roughness 1: exponent 1, Ks 0.04).
fn surface(p: DVec3, normal: DVec3, albedo: DVec3) -> Surface {
    Surface {
        position: p,
        normal,
        albedo,
        specular: DVec3::splat(0.04),
        exponent: 1.0,
    }
}

/// Largest difference between a picture and the twin's values, in 8-bit steps, and where.
fn error(img: &image::RgbaImage, want: &[Option<[f64; 3]>]) -> (f64, (u32, u32), usize) {
    let (mut worst, mut at, mut n) = (0.0f64, (0, 0), 0);
    for (i, w) in want.iter().enumerate() {
        let Some(w) = w else { continue };
        let (x, y) = (i as u32 % W, i as u32 / W);
        let px = img.get_pixel(x, y);
        n += 1;
        for k in 0..3 {
            let e = (px[k] as f64 - w[k]).abs();
            if e > worst {
                (worst, at) = (e, (x, y));
            }
        }
    }
    (worst, at, n)
}

/// Largest difference between two oracles (how much the feature changes the picture).
fn oracle_gap(a: &[Option<[f64; 3]>], b: &[Option<[f64; 3]>]) -> f64 {
    a.iter()
        .zip(b)
        .filter_map(|(a, b)| Some((a.as_ref()?, b.as_ref()?)))
        .flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k]).abs()))
        .fold(0.0, f64::max)
}

/// Renders `scene` with every method on ES 2.0 (also as a device without fragment highp) and
/// 3.0: forward against the twin within `tolerance`, every other method against forward
/// within 2/255 (and the twin).
fn check_every_method(what: &str, scene: &Scene, want: &[Option<[f64; 3]>], tolerance: f64) {
    // ES 2.0, ES 2.0 on a device without fragment highp (every float fp16 here), ES 3.0.
    for (es, no_fragment_highp) in [
        (EsVersion::Es2, false),
        (EsVersion::Es2, true),
        (EsVersion::Es3, false),
    ] {
        let restrictions = manylight::gl::Restrictions { no_fragment_highp };
        let mut gpu = Gpu::restricted(es, &restrictions);
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

#[test]
fn a_normal_map_tilts_the_shading_normal_with_file_and_generated_tangents() {
    let dir = tempfile::tempdir().unwrap();
    // Tilted towards −x (the light) and +v; scale 0.8 on x and y.
    let texel = [60u8, 215, 200, 255];
    let material = json!({
        "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.7, 0.6, 1.0], "roughnessFactor": 1.0,
                                 "metallicFactor": 0.0},
        "normalTexture": {"index": 0, "scale": 0.8},
    });
    let mut plane = Plane::new(material);
    plane.images.push(png(1, 1, &[texel]));
    let generated = plane.write(dir.path(), "generated.gltf");
    // The same tangent frame written out: +x, bitangent down the image (w = −1).
    let tangents: Vec<u8> = [1.0f32, 0.0, 0.0, -1.0]
        .repeat(4)
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    plane.extra.push(("TANGENT", FLOAT, "VEC4", tangents));
    let from_file = plane.write(dir.path(), "tangents.gltf");

    let rgb = DVec3::new(texel[0] as f64, texel[1] as f64, texel[2] as f64) / 255.0;
    let albedo = DVec3::new(0.8, 0.7, 0.6);
    let mapped = |p: DVec3, _: DVec2, _: [f64; 4]| {
        let n = perturbed_normal(DVec3::Z, DVec3::X, -1.0, rgb, 0.8);
        (surface(p, n, albedo), DVec3::ZERO, 1.0)
    };
    let flat = |p: DVec3, _: DVec2, _: [f64; 4]| (surface(p, DVec3::Z, albedo), DVec3::ZERO, 1.0);
    for path in [&generated, &from_file] {
        let (s, warnings) = scene_of(path, grazing_light(), 0.02);
        assert!(warnings.is_empty(), "{warnings:?}");
        assert_eq!(s.materials[0].maps.normal_scale, 0.8);
        let want = oracle(&s, &mapped);
        let gap = oracle_gap(&want, &oracle(&s, &flat));
        assert!(
            gap > 30.0,
            "the normal map changes the picture by only {gap:.1}/255"
        );
        check_every_method("normal map", &s, &want, 3.0);
    }
    // Mirrored along x: the tangent turns to −x and the bitangent keeps pointing down the
    // image, so the handedness flips with the transform's determinant.
    let (mut s, _) = scene_of(&from_file, grazing_light(), 0.02);
    s.objects[0].transform = glam::DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0));
    let mirrored = |w: f64| {
        move |p: DVec3, _: DVec2, _: [f64; 4]| {
            let n = perturbed_normal(DVec3::Z, -DVec3::X, w, rgb, 0.8);
            (surface(p, n, albedo), DVec3::ZERO, 1.0)
        }
    };
    let want = oracle(&s, &mirrored(1.0));
    let gap = oracle_gap(&want, &oracle(&s, &mirrored(-1.0)));
    assert!(
        gap > 10.0,
        "the handedness changes the picture by only {gap:.1}/255"
    );
    check_every_method("mirrored normal map", &s, &want, 3.0);
}

#[test]
fn emission_with_its_strength_and_texture_adds_light_and_occlusion_darkens_the_ambient() {
    let dir = tempfile::tempdir().unwrap();
    let emissive_texel = [200u8, 90, 250, 255];
    let occlusion_texel = [90u8, 255, 0, 255];
    let material = json!({
        "pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.7, 0.7, 1.0], "roughnessFactor": 1.0},
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
        let gap = oracle_gap(&want, &without);
        assert!(
            gap > 20.0,
            "{what} changes the picture by only {gap:.1}/255"
        );
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
        "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.8, 0.7, 1.0], "roughnessFactor": 1.0},
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
    let gap = oracle_gap(&want, &oracle(&s, &plain));
    assert!(
        gap > 40.0,
        "vertex colours change the picture by only {gap:.1}/255"
    );
    check_every_method("vertex colours", &s, &want, 3.0);
}

/// Bilinear sample with REPEAT of an sRGB texture at `uv`, decoded (as the shader does).
fn bilinear_srgb(texels: &[[u8; 4]], w: usize, h: usize, uv: DVec2) -> DVec3 {
    let (x, y) = (uv.x * w as f64 - 0.5, uv.y * h as f64 - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let at = |i: f64, j: f64| {
        let (i, j) = (
            (i as i64).rem_euclid(w as i64) as usize,
            (j as i64).rem_euclid(h as i64) as usize,
        );
        let t = texels[j * w + i];
        DVec3::new(t[0] as f64, t[1] as f64, t[2] as f64) / 255.0
    };
    let top = at(x0, y0) * (1.0 - fx) + at(x0 + 1.0, y0) * fx;
    let bottom = at(x0, y0 + 1.0) * (1.0 - fx) + at(x0 + 1.0, y0 + 1.0) * fx;
    let c = top * (1.0 - fy) + bottom * fy;
    DVec3::new(
        srgb_to_linear(c.x),
        srgb_to_linear(c.y),
        srgb_to_linear(c.z),
    )
}

#[test]
fn a_required_texture_transform_offsets_rotates_and_scales_the_base_colour() {
    let dir = tempfile::tempdir().unwrap();
    let texels = [
        [230u8, 40, 40, 255],
        [40, 220, 60, 255],
        [40, 60, 230, 255],
        [230, 230, 60, 255],
    ];
    let transform = TextureTransform {
        offset: Vec2::new(0.3, 0.1),
        rotation: 0.5,
        scale: Vec2::new(0.7, 1.3),
    };
    let material = json!({
        "pbrMetallicRoughness": {
            "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {
                "offset": [0.3, 0.1], "rotation": 0.5, "scale": [0.7, 1.3]}}},
            "roughnessFactor": 1.0,
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
    let model = |t: TextureTransform| {
        move |p: DVec3, uv: DVec2, _: [f64; 4]| {
            let albedo = bilinear_srgb(&texels, 2, 2, t.apply(uv));
            (surface(p, DVec3::Z, albedo), DVec3::ZERO, 1.0)
        }
    };
    let want = oracle(&s, &model(transform));
    let gap = oracle_gap(&want, &oracle(&s, &model(TextureTransform::IDENTITY)));
    assert!(
        gap > 40.0,
        "the transform changes the picture by only {gap:.1}/255"
    );
    check_every_method("texture transform", &s, &want, 3.0);
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
    assert!(all.contains("emissiveTexture: uses TEXCOORD_1"), "{all}");
    assert!(all.contains("occlusionTexture: uses TEXCOORD_1"), "{all}");
    assert_eq!(warnings.len(), 3, "{all}");
    let m = &s.materials[0];
    assert!(m.diffuse_texture.is_some() && m.maps.base_transform.is_identity());
    let normal = m.maps.normal.as_ref().expect("normal map bound");
    assert!(normal.transform.is_identity());
    assert!(m.maps.metallic_roughness.is_some());
    assert!(m.maps.emissive_texture.is_none() && m.maps.occlusion.is_none());
    let mesh = &s.objects[0].mesh;
    // Float colours are clamped to [0, 1]; VEC3 gets alpha 1.
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
        (F::MR_TEXTURE, "u_metallicRoughnessTex", Stage::Fragment),
        (F::TEXTURE_TRANSFORM, "u_albedoUvTransform", Stage::Vertex),
        (F::TEXTURE_TRANSFORM, "v_uvAlbedoNormal", Stage::Fragment),
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
