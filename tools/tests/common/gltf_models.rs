//! Small models the glTF tests write: a quad (the floor, a pane) as a glTF primitive and as
//! OBJ text, a checker texture, a one-triangle document, a document with one light of each
//! kind, and rotations in glTF's order.

use glam::DQuat;
use serde_json::{json, Value};

use super::gltf::Builder;

/// A quad's vertex data: four corners, their normals and texture coordinates (glTF's:
/// v down from the image's top).
pub struct Quad {
    pub positions: Vec<f32>,
    pub normals: Vec<f32>,
    pub uvs: Vec<f32>,
}

/// The floor: 4 × 4 in XZ at y = 0, facing +Y.
pub fn floor() -> Quad {
    Quad {
        positions: vec![
            -2.0, 0.0, 2.0, 2.0, 0.0, 2.0, 2.0, 0.0, -2.0, -2.0, 0.0, -2.0,
        ],
        normals: [0.0, 1.0, 0.0].repeat(4),
        uvs: vec![0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0],
    }
}

/// A wall or pane: `w` × `h` in XY from the origin's bottom edge, facing +Z.
pub fn pane(w: f32, h: f32) -> Quad {
    Quad {
        positions: vec![
            -w / 2.0,
            0.0,
            0.0,
            w / 2.0,
            0.0,
            0.0,
            w / 2.0,
            h,
            0.0,
            -w / 2.0,
            h,
            0.0,
        ],
        normals: [0.0, 0.0, 1.0].repeat(4),
        uvs: vec![0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0],
    }
}

/// A primitive (positions, normals, uvs, u16 indices) as glTF JSON.
pub fn primitive(b: &mut Builder, quad: &Quad, material: Option<usize>) -> Value {
    let p = b.floats(&quad.positions, "VEC3");
    let n = b.floats(&quad.normals, "VEC3");
    let t = b.floats(&quad.uvs, "VEC2");
    let i = b.u16s(&[0, 1, 2, 0, 2, 3]);
    let mut v = json!({"attributes": {"POSITION": p, "NORMAL": n, "TEXCOORD_0": t}, "indices": i});
    if let Some(m) = material {
        v["material"] = json!(m);
    }
    v
}

/// The same quad as OBJ text (texture v flipped: OBJ's v points up) with its MTL.
pub fn quad_obj(q: &Quad, material: &str) -> String {
    let mut s = format!("mtllib {material}.mtl\nusemtl {material}\n");
    for p in q.positions.chunks(3) {
        s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for n in q.normals.chunks(3) {
        s += &format!("vn {} {} {}\n", n[0], n[1], n[2]);
    }
    for t in q.uvs.chunks(2) {
        s += &format!("vt {} {}\n", t[0], 1.0 - t[1]);
    }
    s + "f 1/1/1 2/2/2 3/3/3\nf 1/1/1 3/3/3 4/4/4\n"
}

/// A 4 × 4 checker with one odd corner, so a flipped or mirrored mapping shows.
pub fn checker_png() -> Vec<u8> {
    let img = image::RgbaImage::from_fn(4, 4, |x, y| {
        if (x, y) == (0, 0) {
            image::Rgba([250, 30, 30, 255])
        } else if (x + y) % 2 == 0 {
            image::Rgba([220, 220, 200, 255])
        } else {
            image::Rgba([40, 70, 120, 255])
        }
    });
    png_bytes(&img)
}

/// `img` encoded as a PNG file's bytes.
pub fn png_bytes(img: &image::RgbaImage) -> Vec<u8> {
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    png
}

/// A rotation as glTF writes it: x, y, z, w.
pub fn quat(q: DQuat) -> Value {
    json!([q.x, q.y, q.z, q.w])
}

/// A minimal valid document: one triangle with u16 indices, for variants of it.
pub fn triangle(b: &mut Builder) -> Value {
    let p = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3");
    let i = b.u16s(&[0, 1, 2]);
    json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": p}, "indices": i}]}]})
}

/// A document with one light of each kind (two points, one with no range; a spot aimed down;
/// a sun) on their nodes, and a triangle on the last node (`nodes[4]`).
pub fn lights_document(b: &mut Builder) -> Value {
    let p = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3");
    json!({
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1, 0.5, 0.25], "intensity": 3, "range": 7},
            {"type": "point", "intensity": 2048},
            {"type": "spot", "intensity": 5, "range": 9,
             "spot": {"innerConeAngle": 0.25, "outerConeAngle": 0.5}},
            {"type": "directional", "intensity": 100}
        ]}},
        "scenes": [{"nodes": [0, 1, 2, 3, 4]}],
        "nodes": [
            {"translation": [1, 2, 3], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"translation": [-1, 0, 0], "scale": [5, 5, 5],
             "extensions": {"KHR_lights_punctual": {"light": 1}}},
            // Aimed down: a quarter turn about +X takes −Z to −Y.
            {"translation": [0, 4, 0], "rotation": quat(DQuat::from_rotation_x(-std::f64::consts::FRAC_PI_2)),
             "extensions": {"KHR_lights_punctual": {"light": 2}}},
            {"extensions": {"KHR_lights_punctual": {"light": 3}}},
            {"mesh": 0}
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": p}}]}],
    })
}
