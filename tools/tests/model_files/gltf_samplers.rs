//! glTF samplers are applied: each texture wraps and filters as its sampler says (§5.26), with
//! every method on ES 2.0 and 3.0. Four quads read one 2 × 2 image through four samplers
//! (the image uploaded once, its parameters set per draw) over texture coordinates from −1 to
//! 2; every pixel away from a texel's edge shows the texel the test works out for its wrap,
//! and a linear filter blends neighbouring texels where a nearest one never does.

use crate::common;

use common::gltf::{base64, Builder};
use common::Gpu;
use glam::Vec3;
use manylight::{EsVersion, RenderOptions};
use serde_json::{json, Value};

const W: u32 = 192;
const H: u32 = 108;

/// The image's texels, row by row from the top: red, green / blue, white.
const TEXELS: [[u8; 3]; 4] = [[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 255]];

/// glTF's wrap codes.
const REPEAT: u32 = 10497;
const CLAMP: u32 = 33071;
const MIRROR: u32 = 33648;
const NEAREST: u32 = 9728;
const LINEAR: u32 = 9729;

/// The four quads' samplers, left to right then top to bottom: (wrapS, wrapT, filter), or
/// none (the third: repeating, linear, mipmapped), drawn after one that is not the default
/// (the shared upload's parameters must be set back).
const SAMPLERS: [Option<(u32, u32, u32)>; 4] = [
    Some((MIRROR, REPEAT, NEAREST)),
    Some((CLAMP, MIRROR, NEAREST)),
    None,
    Some((REPEAT, CLAMP, NEAREST)),
];

fn png() -> Vec<u8> {
    common::gltf_models::png_bytes(&image::RgbaImage::from_fn(2, 2, |x, y| {
        let [r, g, b] = TEXELS[(2 * y + x) as usize];
        image::Rgba([r, g, b, 255])
    }))
}

/// Half the view's width (its height is 2): the quads tile the whole view.
fn half_width() -> f32 {
    W as f32 / H as f32
}

/// The document: an orthographic camera looking down −Z at the four quads, each a quarter of
/// the view with texture coordinates from (−1, −1) at its top left to (2, 2) at its bottom
/// right.
fn document() -> String {
    let mut b = Builder::default();
    let a = half_width();
    let mut meshes = Vec::new();
    let mut nodes = Vec::new();
    for q in 0..4 {
        let (x0, y1) = (
            if q % 2 == 0 { -a } else { 0.0 },
            if q < 2 { 1.0 } else { 0.0 },
        );
        let (x1, y0) = (x0 + a, y1 - 1.0);
        let p = b.floats(
            &[x0, y0, 0.0, x1, y0, 0.0, x1, y1, 0.0, x0, y1, 0.0],
            "VEC3",
        );
        let n = b.floats(&[0.0, 0.0, 1.0].repeat(4), "VEC3");
        let t = b.floats(&[-1.0, 2.0, 2.0, 2.0, 2.0, -1.0, -1.0, -1.0], "VEC2");
        let i = b.u16s(&[0, 1, 2, 0, 2, 3]);
        meshes.push(
            json!({"primitives": [{"attributes": {"POSITION": p, "NORMAL": n,
            "TEXCOORD_0": t}, "indices": i, "material": q}]}),
        );
        nodes.push(json!({"mesh": q}));
    }
    nodes.push(json!({"camera": 0, "translation": [0, 0, 1]}));
    let samplers: Vec<Value> = SAMPLERS
        .iter()
        .flatten()
        .map(|&(s, t, f)| json!({"wrapS": s, "wrapT": t, "magFilter": f, "minFilter": f}))
        .collect();
    let mut sampler = 0;
    let textures: Vec<Value> = SAMPLERS
        .iter()
        .map(|given| match given {
            Some(_) => {
                sampler += 1;
                json!({"source": 0, "sampler": sampler - 1})
            }
            None => json!({"source": 0}),
        })
        .collect();
    let materials: Vec<Value> = (0..4)
        .map(|q| {
            json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": q},
                "metallicFactor": 0.0, "roughnessFactor": 1.0}})
        })
        .collect();
    b.gltf(json!({
        "scenes": [{"nodes": [0, 1, 2, 3, 4]}],
        "nodes": nodes,
        "cameras": [{"type": "orthographic",
            "orthographic": {"xmag": a, "ymag": 1.0, "znear": 0.1, "zfar": 10}}],
        "meshes": meshes,
        "materials": materials,
        "samplers": samplers,
        "textures": textures,
        "images": [{"uri": format!("data:image/png;base64,{}", base64(&png()))}],
    }))
}

/// Coordinate `u` wrapped into [0, 1] as `mode` says (the test's own reading of §5.26).
fn wrap(u: f64, mode: u32) -> f64 {
    match mode {
        REPEAT => u - u.floor(),
        CLAMP => u.clamp(0.0, 1.0),
        MIRROR => {
            let t = u.rem_euclid(2.0);
            if t > 1.0 {
                2.0 - t
            } else {
                t
            }
        }
        _ => unreachable!(),
    }
}

/// The quad pixel (x, y) lies in and its texture coordinates there.
fn quad_and_uv(x: u32, y: u32) -> (usize, f64, f64) {
    let (fx, fy) = (
        (x as f64 + 0.5) / (W as f64 / 2.0),
        (y as f64 + 0.5) / (H as f64 / 2.0),
    );
    let q = (fx >= 1.0) as usize + 2 * (fy >= 1.0) as usize;
    (q, -1.0 + 3.0 * fx.fract(), -1.0 + 3.0 * fy.fract())
}

/// Distance of wrapped coordinate `u` (in texels of the 2-texel image) from the nearest
/// place where the texel read changes: the middle, and with `REPEAT` the image's ends too
/// (where the next copy starts; clamping and mirroring read the same texel on both sides).
fn from_edge(u: f64, mode: u32) -> f64 {
    let middle = (u - 0.5).abs() * 2.0;
    if mode == REPEAT {
        middle.min(u.min(1.0 - u) * 2.0)
    } else {
        middle
    }
}

#[test]
fn each_texture_wraps_and_filters_as_its_sampler_says_with_every_method() {
    let dir = tempfile::tempdir().unwrap();
    let path = common::files::write(dir.path(), "samplers.gltf", document());
    let (mut scene, _) = common::files::load(&path).unwrap();
    scene.ambient = Vec3::ONE;
    let opts = RenderOptions {
        linear: true,
        ..Default::default()
    };
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::new(es);
        for method in common::methods_on(es) {
            gpu.r().set_method_named(method).unwrap();
            let img = gpu.render(&scene, W, H, &opts);
            let (mut checked, mut blended) = ([0usize; 4], 0);
            for y in 0..H {
                for x in 0..W {
                    let (q, u, v) = quad_and_uv(x, y);
                    let (wrap_u, wrap_v, filter) = SAMPLERS[q].unwrap_or((REPEAT, REPEAT, LINEAR));
                    let (wu, wv) = (wrap(u, wrap_u), wrap(v, wrap_v));
                    let shown = common::texel_shown(img.get_pixel(x, y), &TEXELS);
                    let edge = from_edge(wu, wrap_u).min(from_edge(wv, wrap_v));
                    let near_edge = edge < 0.08;
                    // The quads' own borders and the texels' edges are left to rounding.
                    let (px, py) = (
                        (x as f64 + 0.5) % (W as f64 / 2.0),
                        (y as f64 + 0.5) % (H as f64 / 2.0),
                    );
                    if near_edge || px < 1.0 || py < 1.0 {
                        continue;
                    }
                    let column = ((wu * 2.0).floor() as usize).min(1);
                    let row = ((wv * 2.0).floor() as usize).min(1);
                    let want = 2 * row + column;
                    if filter == LINEAR && edge < 0.25 {
                        // Within a quarter texel of an edge a linear filter blends.
                        blended += (shown != Some(want)) as usize;
                        continue;
                    }
                    assert_eq!(
                        shown,
                        Some(want),
                        "{es} {method}: pixel ({x}, {y}) of quad {q} at uv ({u:.3}, {v:.3}) \
                         is {:?}",
                        img.get_pixel(x, y)
                    );
                    checked[q] += 1;
                }
            }
            assert!(
                checked.iter().all(|&n| n > 500),
                "{es} {method}: pixels checked per quad {checked:?}"
            );
            assert!(
                blended > 20,
                "{es} {method}: the linear filter blended only {blended} pixels near edges"
            );
        }
    }
}

/// A material whose base colour and occlusion textures read one image through different
/// samplers reads it through the base colour's (a draw binds an image once), with a warning
/// naming both slots; another material's slots keep their own.
#[test]
fn one_material_reads_an_image_through_one_sampler() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let quad = common::gltf_models::pane(1.0, 1.0);
    let first = common::gltf_models::primitive(&mut b, &quad, Some(0));
    let second = common::gltf_models::primitive(&mut b, &quad, Some(1));
    let doc = b.gltf(json!({
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [first, second]}],
        "materials": [
            {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
             "occlusionTexture": {"index": 1}},
            {"pbrMetallicRoughness": {"baseColorTexture": {"index": 1}}}
        ],
        "samplers": [{"wrapS": CLAMP, "magFilter": NEAREST}],
        "textures": [{"source": 0}, {"source": 0, "sampler": 0}],
        "images": [{"uri": format!("data:image/png;base64,{}", base64(&png()))}],
    }));
    let path = common::files::write(dir.path(), "shared.gltf", doc);
    let (scene, report) = common::files::load(&path).unwrap();
    let said: Vec<&String> = report
        .warnings
        .iter()
        .filter(|w| w.contains("different samplers"))
        .collect();
    assert_eq!(said.len(), 1, "{:?}", report.warnings);
    assert!(
        said[0].contains("materials[0]")
            && said[0].contains("occlusion")
            && said[0].contains("base colour")
            && !said[0].contains("  "),
        "{}",
        said[0]
    );
    let m = &scene.materials;
    let base = m[0].diffuse_texture.as_ref().unwrap();
    let occlusion = &m[0].maps.occlusion.as_ref().unwrap().texture;
    assert_eq!(occlusion.sampling, base.sampling);
    assert_eq!(base.sampling, manylight::sampling::Sampling::default());
    let other = m[1].diffuse_texture.as_ref().unwrap();
    assert_eq!(
        other.sampling.wrap_u,
        manylight::sampling::Wrap::ClampToEdge,
        "another material keeps its own sampler"
    );
}
