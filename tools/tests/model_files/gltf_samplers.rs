//! glTF samplers are applied: each texture wraps and filters as its sampler says (§5.26), with
//! every method on ES 2.0 and 3.0. Four quads read one 2 × 2 image through four samplers
//! (the image uploaded once, its parameters set per draw) over texture coordinates from −1 to
//! 2; every pixel away from a texel's edge shows the texel the test works out for its wrap,
//! and a linear filter blends neighbouring texels where a nearest one never does.

use crate::common;
use crate::texel_quads::{self, texel_at, wrapped, H, TEXELS, W};

use common::gltf::{base64, Builder};
use manylight::sampling::Wrap;
use serde_json::{json, Value};

/// glTF's wrap and filter codes.
const CLAMP: u32 = 33071;
const NEAREST: u32 = 9728;
const LINEAR: u32 = 9729;

/// The four quads' samplers, left to right then top to bottom: (wrapS, wrapT, filter), or
/// none (the third: repeating, linear, mipmapped), drawn after one that is not the default
/// (the shared upload's parameters must be set back).
const SAMPLERS: [Option<(Wrap, Wrap, u32)>; 4] = [
    Some((Wrap::MirroredRepeat, Wrap::Repeat, NEAREST)),
    Some((Wrap::ClampToEdge, Wrap::MirroredRepeat, NEAREST)),
    None,
    Some((Wrap::Repeat, Wrap::ClampToEdge, NEAREST)),
];

/// glTF's code for `wrap`.
fn code(wrap: Wrap) -> u32 {
    match wrap {
        Wrap::Repeat => 10497,
        Wrap::ClampToEdge => CLAMP,
        Wrap::MirroredRepeat => 33648,
    }
}

fn png() -> Vec<u8> {
    common::gltf_models::png_bytes(&texel_quads::image())
}

/// The document: an orthographic camera looking down −Z at the four quads, each a quarter of
/// the view with texture coordinates from (−1, −1) at its top left to (2, 2) at its bottom
/// right.
fn document() -> String {
    let mut b = Builder::default();
    let a = texel_quads::half_width() as f32;
    let mut meshes = Vec::new();
    let mut nodes = Vec::new();
    for q in 0..4 {
        let (x0, y0, x1, y1) = texel_quads::quad_corners(q);
        let [x0, y0, x1, y1] = [x0, y0, x1, y1].map(|c| c as f32);
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
        .map(|&(s, t, f)| {
            json!({"wrapS": code(s), "wrapT": code(t), "magFilter": f, "minFilter": f})
        })
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

#[test]
fn each_texture_wraps_and_filters_as_its_sampler_says_with_every_method() {
    let dir = tempfile::tempdir().unwrap();
    let path = common::files::write(dir.path(), "samplers.gltf", document());
    let (scene, _) = common::files::load(&path).unwrap();
    common::each_method_showing_colours(&scene, W, H, |es, method, _, img| {
        let (mut checked, mut blended) = ([0usize; 4], 0);
        for (x, y, p) in img.enumerate_pixels() {
            let Some((q, u, v)) = texel_quads::quad_and_uv(x, y) else {
                continue;
            };
            let (wrap_u, wrap_v, filter) =
                SAMPLERS[q].unwrap_or((Wrap::Repeat, Wrap::Repeat, LINEAR));
            let ((wu, edge_u), (wv, edge_v)) = (wrapped(u, wrap_u), wrapped(v, wrap_v));
            let edge = edge_u.min(edge_v);
            // The texels' edges are left to rounding.
            if edge < 0.08 {
                continue;
            }
            let shown = common::texel_shown(p, &TEXELS);
            let want = texel_at(wu, wv);
            if filter == LINEAR && edge < 0.25 {
                // Within a quarter texel of an edge a linear filter blends.
                blended += (shown != Some(want)) as usize;
                continue;
            }
            assert_eq!(
                shown,
                Some(want),
                "{es} {method}: pixel ({x}, {y}) of quad {q} at uv ({u:.3}, {v:.3}) is {p:?}"
            );
            checked[q] += 1;
        }
        assert!(
            checked.iter().all(|&n| n > 500),
            "{es} {method}: pixels checked per quad {checked:?}"
        );
        assert!(
            blended > 20,
            "{es} {method}: the linear filter blended only {blended} pixels near edges"
        );
    });
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
