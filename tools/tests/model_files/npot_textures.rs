//! Images of any size are uploaded at their size where the context allows it (ES 3.0, or ES 2.0
//! with `GL_OES_texture_npot`, which Mesa, SwiftShader and ANGLE all list): a 3 × 1 image
//! read through a nearest filter shows its three texels exactly, with every method on ES 2.0
//! and 3.0. Scaled to a power of two (2 × 1, area-averaged) its middle third would show blends.
//! `command_line/cli.rs` checks the context without the extension.

use crate::common;

use common::gltf::{base64, Builder};
use serde_json::json;

const W: u32 = 96;
const H: u32 = 32;

/// The image's texels, left to right.
const TEXELS: [[u8; 3]; 3] = [[255, 0, 0], [0, 255, 0], [0, 0, 255]];

fn png() -> Vec<u8> {
    common::gltf_models::png_bytes(&image::RgbaImage::from_fn(3, 1, |x, _| {
        let [r, g, b] = TEXELS[x as usize];
        image::Rgba([r, g, b, 255])
    }))
}

/// One quad filling an orthographic view, texture coordinates 0 to 1 across it, its image
/// read through a nearest filter.
fn document() -> String {
    let mut b = Builder::default();
    let a = W as f32 / H as f32;
    let p = b.floats(
        &[-a, -1.0, 0.0, a, -1.0, 0.0, a, 1.0, 0.0, -a, 1.0, 0.0],
        "VEC3",
    );
    let n = b.floats(&[0.0, 0.0, 1.0].repeat(4), "VEC3");
    let t = b.floats(&[0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0], "VEC2");
    let i = b.u16s(&[0, 1, 2, 0, 2, 3]);
    const NEAREST: u32 = 9728;
    const CLAMP: u32 = 33071;
    b.gltf(json!({
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 1]}],
        "cameras": [{"type": "orthographic",
            "orthographic": {"xmag": a, "ymag": 1.0, "znear": 0.1, "zfar": 10}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": p, "NORMAL": n,
            "TEXCOORD_0": t}, "indices": i, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
            "metallicFactor": 0.0, "roughnessFactor": 1.0}}],
        "samplers": [{"wrapS": CLAMP, "wrapT": CLAMP, "magFilter": NEAREST,
            "minFilter": NEAREST}],
        "textures": [{"source": 0, "sampler": 0}],
        "images": [{"uri": format!("data:image/png;base64,{}", base64(&png()))}],
    }))
}

#[test]
fn an_image_of_three_texels_shows_each_exactly_with_every_method() {
    let dir = tempfile::tempdir().unwrap();
    let path = common::files::write(dir.path(), "npot.gltf", document());
    let (scene, _) = common::files::load(&path).unwrap();
    common::each_method_showing_colours(&scene, W, H, |es, method, gpu, img| {
        assert!(
            gpu.r().caps().npot_textures,
            "{es}: this implementation lists no GL_OES_texture_npot"
        );
        for y in 1..H - 1 {
            for x in 0..W {
                // Two pixels each side of a texel's edge are left to rounding.
                let third = W / 3;
                if x % third < 2 || x % third >= third - 2 {
                    continue;
                }
                let p = img.get_pixel(x, y);
                let want = TEXELS[(x / third) as usize];
                let off = (0..3).map(|c| p[c].abs_diff(want[c])).max().unwrap();
                assert!(
                    off <= 2,
                    "{es} {method}: pixel ({x}, {y}) is {p:?}, texel {want:?}"
                );
            }
        }
    });
}
