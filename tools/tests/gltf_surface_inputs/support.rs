//! The surface-input tests' plane: a glTF file holding it, and the f64 twin's value at every
//! pixel that sees it.

use std::path::{Path, PathBuf};

use glam::{DVec2, DVec3};
use manylight::scene::raycast::pixel_ray;
use manylight::scene::shading::{self, linear_to_srgb, srgb_to_linear, Surface};
use manylight::scene::Scene;
use serde_json::{json, Value};

use crate::common::gltf::base64;

pub const W: u32 = 96;
pub const H: u32 = 54;
pub use crate::common::gltf::{FLOAT, UNSIGNED_BYTE, UNSIGNED_SHORT};

/// The plane: z = 0, x and y in [−1, 1], facing +Z; u along +x, v down the image (−y).
const CORNERS: [[f32; 3]; 4] = [
    [-1.0, -1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
];
const UVS: [[f32; 2]; 4] = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]];
const TRIANGLES: [u16; 6] = [0, 1, 2, 0, 2, 3];

pub fn png(w: u32, h: u32, texels: &[[u8; 4]]) -> Vec<u8> {
    let img = image::RgbaImage::from_fn(w, h, |x, y| image::Rgba(texels[(y * w + x) as usize]));
    let mut out = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png)
        .unwrap();
    out
}

/// One plane primitive with `material` and optional extra attributes, its images as data URIs
/// (image i is texture i), `extensions` listed as used (and required when `required`).
pub struct Plane {
    pub material: Value,
    pub images: Vec<Vec<u8>>,
    /// (semantic, component type, type, raw bytes)
    pub extra: Vec<(&'static str, u32, &'static str, Vec<u8>)>,
    pub extensions: Vec<&'static str>,
    pub required: bool,
}

impl Plane {
    pub fn new(material: Value) -> Plane {
        Plane {
            material,
            images: Vec::new(),
            extra: Vec::new(),
            extensions: Vec::new(),
            required: false,
        }
    }

    pub fn write(&self, dir: &Path, name: &str) -> PathBuf {
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
            .map(|png| json!({"uri": format!("data:image/png;base64,{}", base64(png))}))
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
                         "uri": format!("data:application/octet-stream;base64,{}", base64(&bin))}],
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

/// What the f64 twin needs at one point of the plane: (point, uv, barycentric weights of the
/// quad's corners) → (surface, emitted radiance, ambient occlusion).
pub type Model<'a> = dyn Fn(DVec3, DVec2, [f64; 4]) -> (Surface, DVec3, f64) + 'a;

/// sRGB 8-bit values the twin expects at every pixel whose centre sees the plane's interior
/// (`None` near its edges and off it).
pub fn oracle(scene: &Scene, model: &Model) -> Vec<Option<[f64; 3]>> {
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
            // Lit with the model's normal as given, as the shaders light a mapped normal on a
            // front face, also where it leans away from the eye.
            let mut c: DVec3 = scene
                .lights
                .iter()
                .map(|l| shading::light_contribution(l, &surface, v))
                .sum();
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

/// The surface of the tests' materials: metallic-roughness, a dielectric (metallic 0) of
/// roughness 1.
pub fn surface(p: DVec3, normal: DVec3, albedo: DVec3) -> Surface {
    Surface {
        position: p,
        normal,
        albedo,
        specular: DVec3::ZERO,
        exponent: 1.0,
        model: manylight::MaterialModel::MetallicRoughness,
        metallic: 0.0,
        roughness: 1.0,
    }
}

/// Largest difference between a picture and the twin's values, in 8-bit steps, and where.
pub fn error(img: &image::RgbaImage, want: &[Option<[f64; 3]>]) -> (f64, (u32, u32), usize) {
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

/// Asserts that `other` (the twin's picture without a feature, or with it wrong) differs from
/// `want` by more than `at_least` 8-bit steps somewhere, so the test comparing with `want` can
/// fail; `what` names the change. The difference, for a log.
pub fn assert_changes(
    want: &[Option<[f64; 3]>],
    other: &[Option<[f64; 3]>],
    at_least: f64,
    what: &str,
) -> f64 {
    let gap = oracle_gap(want, other);
    assert!(
        gap > at_least,
        "{what} changes the picture by only {gap:.1}/255"
    );
    gap
}

/// Largest difference between two oracles (how much the feature changes the picture).
fn oracle_gap(a: &[Option<[f64; 3]>], b: &[Option<[f64; 3]>]) -> f64 {
    a.iter()
        .zip(b)
        .filter_map(|(a, b)| Some((a.as_ref()?, b.as_ref()?)))
        .flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k]).abs()))
        .fold(0.0, f64::max)
}

/// Bilinear sample with REPEAT of an sRGB texture at `uv` in linear RGB: its texels decoded
/// first with `decoded_first` (an sRGB texture's sampler, ES 3.0), else the filtered value
/// decoded (the shader, ES 2.0).
pub fn bilinear_colour(
    texels: &[[u8; 4]],
    w: usize,
    h: usize,
    uv: DVec2,
    decoded_first: bool,
) -> DVec3 {
    let decode = |c: DVec3| {
        DVec3::new(
            srgb_to_linear(c.x),
            srgb_to_linear(c.y),
            srgb_to_linear(c.z),
        )
    };
    let c = bilinear(texels, w, h, uv, &|c| {
        if decoded_first {
            decode(c)
        } else {
            c
        }
    });
    if decoded_first {
        c
    } else {
        decode(c)
    }
}

/// Bilinear sample with REPEAT at `uv` of a texture holding linear data (0 to 1).
pub fn bilinear_linear(texels: &[[u8; 4]], w: usize, h: usize, uv: DVec2) -> DVec3 {
    bilinear(texels, w, h, uv, &|c| c)
}

/// Bilinear sample with REPEAT at `uv`, each texel (RGB, 0 to 1) mapped by `texel` first.
fn bilinear(
    texels: &[[u8; 4]],
    w: usize,
    h: usize,
    uv: DVec2,
    texel: &dyn Fn(DVec3) -> DVec3,
) -> DVec3 {
    let (x, y) = (uv.x * w as f64 - 0.5, uv.y * h as f64 - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let at = |i: f64, j: f64| {
        let (i, j) = (
            (i as i64).rem_euclid(w as i64) as usize,
            (j as i64).rem_euclid(h as i64) as usize,
        );
        let t = texels[j * w + i];
        texel(DVec3::new(t[0] as f64, t[1] as f64, t[2] as f64) / 255.0)
    };
    let top = at(x0, y0) * (1.0 - fx) + at(x0 + 1.0, y0) * fx;
    let bottom = at(x0, y0 + 1.0) * (1.0 - fx) + at(x0 + 1.0, y0 + 1.0) * fx;
    top * (1.0 - fy) + bottom * fy
}
