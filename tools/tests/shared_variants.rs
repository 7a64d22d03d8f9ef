//! A scene whose materials ask for more shader variants than a renderer builds for one scene
//! (`MAX_SURFACE_VARIANTS`, 32): its objects share superset variants, so it builds few
//! programs, and it draws the same picture as the same objects drawn a few at a time (each
//! group asking for few variants, drawn with its own).

mod common;

use std::collections::HashSet;
use std::sync::Arc;

use common::Gpu;
use glam::{DMat4, DVec3, Vec2, Vec3, Vec4};
use manylight::methods::ShaderFeatures as F;
use manylight::scene::meshbuild::MeshBuilder;
use manylight::scene::surface_maps::{MapTexture, TextureTransform};
use manylight::scene::{Camera, Light, Material, Mesh, Scene, Texture};
use manylight::{EsVersion, RenderOptions};

const W: u32 = 256;
const H: u32 = 144;
/// Objects in a row and rows: one object (and material) each.
const COLUMNS: usize = 8;
const ROWS: usize = 6;
/// Objects drawn together in a group render: too few for shared variants.
const GROUP: usize = 15;

/// A unit quad in the z = 0 plane facing +Z, with vertex colours, tangents and texture
/// coordinates where asked.
fn quad([colours, tangents, uvs]: [bool; 3]) -> Mesh {
    let corner = |x, y| Vec3::new(x, y, 0.0);
    let mut b = MeshBuilder::new();
    b.quad(
        corner(-0.5, -0.5),
        corner(0.5, -0.5),
        corner(0.5, 0.5),
        corner(-0.5, 0.5),
    );
    let mut mesh = b.build().unwrap();
    if colours {
        let colors = [
            [1.0, 0.4, 0.2],
            [0.3, 1.0, 0.5],
            [0.2, 0.5, 1.0],
            [0.9, 0.9, 0.3],
        ];
        mesh.colors = colors.map(|c| Vec3::from(c).extend(1.0)).to_vec();
    }
    if tangents {
        mesh.tangents = vec![Vec4::new(1.0, 0.0, 0.0, 1.0); 4];
    }
    if !uvs {
        mesh.uvs.clear();
    }
    mesh
}

/// A 4 × 4 texture whose texels differ, so where it is sampled shows; with `holes`, every
/// other texel is transparent.
fn texture(name: &str, seed: u8, holes: bool) -> Arc<Texture> {
    let image = image::RgbaImage::from_fn(4, 4, |x, y| {
        let v = |k: u32| (seed as u32 * 37 + x * 53 + y * 91 + k * 29) % 200 + 40;
        let alpha = if holes && (x + y) % 2 == 1 { 0 } else { 255 };
        image::Rgba([v(0) as u8, v(1) as u8, v(2) as u8, alpha])
    });
    Arc::new(Texture::new(name.to_string(), image))
}

fn map(name: &str, seed: u8, transform: TextureTransform) -> Option<MapTexture> {
    Some(MapTexture {
        texture: texture(name, seed, false),
        transform,
    })
}

/// The `k`-th material: each bit of `k` turns on one input (vertex colours are the mesh's),
/// a few residues the metallic-roughness BRDF, a normal map and the alpha modes.
fn material(k: usize) -> Material {
    let bit = |b: usize| k >> b & 1 != 0;
    let base = Vec3::new(0.8, 0.6 + 0.004 * k as f32, 0.5);
    let metallic_roughness = k % 5 == 1;
    let mut m = if metallic_roughness {
        Material::metallic_roughness(&format!("m{k}"), base, 0.7, 0.4)
    } else {
        let specular = if bit(1) { Vec3::splat(0.3) } else { Vec3::ZERO };
        Material::glossy(&format!("m{k}"), base, specular, 24.0)
    };
    let scaled = TextureTransform {
        scale: Vec2::splat(2.0),
        uv_set: 0,
        ..TextureTransform::IDENTITY
    };
    if bit(2) {
        m.maps.emissive = Vec3::new(0.3, 0.1, 0.05);
    }
    if bit(3) {
        m.maps.occlusion = map("occlusion", k as u8, TextureTransform::IDENTITY);
        m.maps.occlusion_strength = 0.8;
    }
    let (cut, blend) = (k % 13 == 7, k % 17 == 9);
    if bit(4) || cut || blend {
        m.diffuse_texture = Some(texture("albedo", k as u8, cut || blend));
        if bit(1) {
            m.maps.base_transform = scaled;
        }
    }
    m.alpha_cutoff = cut.then_some(0.5);
    m.alpha_texture = blend;
    if bit(5) {
        m.maps.emissive = Vec3::new(0.2, 0.3, 0.1);
        m.maps.emissive_texture = map("emission", k as u8, TextureTransform::IDENTITY);
    }
    if metallic_roughness && bit(1) {
        m.maps.metallic_roughness = map("metallic-roughness", k as u8, scaled);
    }
    if k % 7 == 3 {
        m.maps.normal = map("normal", 9, TextureTransform::IDENTITY);
    }
    if k % 11 == 5 {
        m.alpha = 0.6;
    }
    m
}

/// The objects `objects` of the full grid (the others left out), lit by point lights over it.
fn scene(objects: impl Iterator<Item = usize>) -> Scene {
    let mut s = Scene::empty();
    s.materials = (0..COLUMNS * ROWS).map(material).collect();
    for k in objects {
        let (column, row) = ((k % COLUMNS) as f64, (k / COLUMNS) as f64);
        let at = DVec3::new(
            column - COLUMNS as f64 / 2.0 + 0.5,
            row - ROWS as f64 / 2.0 + 0.5,
            0.0,
        );
        // A few meshes without texture coordinates: their materials' textures are not
        // sampled, and a shared variant reads the white texture there.
        let uvs = k % 9 != 4;
        let mesh = quad([k & 1 != 0, k % 7 == 3 && uvs, uvs]);
        let transform = DMat4::from_translation(at) * DMat4::from_scale(DVec3::splat(0.8));
        s.add_object(mesh, k, transform);
    }
    s.lights = (0..12)
        .map(|i| {
            let f = i as f64;
            let at = DVec3::new((f * 1.9).sin() * 4.0, (f * 1.3).cos() * 2.5, 0.8);
            Light::point(at, 3.0, Vec3::new(1.0, 0.8, 0.6), 1.2)
        })
        .collect();
    s.ambient = Vec3::splat(0.25);
    s.camera = Camera::perspective(DVec3::new(0.0, 0.0, 7.0), DVec3::ZERO, 60.0, 0.5, 20.0);
    s
}

/// Whether two pixels differ by more than `by` in a channel.
fn differ(a: &image::Rgba<u8>, b: &image::Rgba<u8>, by: u8) -> bool {
    (0..3).any(|c| a[c].abs_diff(b[c]) > by)
}

/// The geometry-pass variants a renderer built for `shader`.
fn variants(gpu: &mut Gpu, shader: &str) -> Vec<u64> {
    let report = gpu.r().program_report();
    let built = report.iter().filter(|p| p.shader == shader);
    built.map(|p| p.features).collect()
}

#[test]
fn many_material_variants_share_programs_and_draw_the_same_picture() {
    let n = COLUMNS * ROWS;
    let opts = RenderOptions::default();
    // Forward shades with the same surface code as clustered; deferred's G-buffer has its own.
    for (es, method, shader) in [
        (EsVersion::Es2, "clustered", "clustered"),
        (EsVersion::Es3, "deferred", "gbuffer"),
    ] {
        let what = format!("{es} {method}");
        let mut gpu = Gpu::fresh(es);
        gpu.r().set_method_named(method).unwrap();
        let (full, stats) = gpu.r().render_offscreen(&scene(0..n), W, H, &opts).unwrap();
        let shared = variants(&mut gpu, shader);
        assert!(
            shared.len() <= 16,
            "{what}: {} {shader} programs for the whole scene ({} built in all)",
            shared.len(),
            stats.programs_built
        );
        // They differ only in the inputs that have no neutral value and the BRDF.
        let apart = F::NORMAL_MAP
            | F::ALPHA_MASK
            | F::TEXTURE_ALPHA
            | F::VERTEX_ALPHA
            | F::METALLIC_ROUGHNESS;
        let kinds: HashSet<u64> = shared.iter().map(|f| f & apart).collect();
        assert_eq!(kinds.len(), shared.len(), "{what}: {shared:x?}");
        let empty = gpu.render(&scene(0..0), W, H, &opts);
        let drawn =
            |img: &image::RgbaImage, x, y| differ(img.get_pixel(x, y), empty.get_pixel(x, y), 0);
        let mut covered = vec![false; (W * H) as usize];
        let (mut compared, mut worst) = (0usize, 0u8);
        for first in (0..n).step_by(GROUP) {
            let group = gpu.render(&scene(first..(first + GROUP).min(n)), W, H, &opts);
            for (x, y, p) in group.enumerate_pixels() {
                if !drawn(&group, x, y) {
                    continue;
                }
                covered[(y * W + x) as usize] = true;
                compared += 1;
                let q = full.get_pixel(x, y);
                let d = (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap();
                worst = worst.max(d);
                assert!(
                    d <= 2,
                    "{what}: ({x}, {y}) is {q:?} in the whole scene, {p:?} drawn in its group"
                );
            }
        }
        // Every object pixel of the whole scene was compared.
        let missed = (full.enumerate_pixels())
            .filter(|&(x, y, _)| drawn(&full, x, y) && !covered[(y * W + x) as usize])
            .count();
        assert_eq!(missed, 0, "{what}: object pixels no group drew");
        assert!(
            compared > (W * H / 5) as usize,
            "{what}: {compared} pixels compared"
        );
        // The groups, drawn with their own variants, needed many more: the test can fail.
        let own = variants(&mut gpu, shader).len() - shared.len();
        assert!(
            own > 32,
            "{what}: the groups built only {own} variants of their own"
        );
        eprintln!(
            "{what}: {} shared variants against {own}; {compared} pixels within {worst}/255",
            shared.len()
        );
    }
}
