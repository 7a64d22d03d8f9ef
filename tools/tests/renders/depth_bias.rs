//! `Material::depth_bias`: a decal lying exactly on a wall, listed (and drawn) before it, shows
//! over the wall with every method on ES 2.0 and 3.0 once biased — opaque, as the decal alone
//! draws it; half transparent, as forward blends it, deferred's rewritten depth included —
//! while without the bias the wall hides much of it, so the test can fail.

use crate::common;

use std::sync::Arc;

use glam::{DMat4, DVec3, Vec3};
use manylight::scene::{Light, Material, Mesh, Object, Scene};
use manylight::{Camera, RenderOptions};

const W: u32 = 96;
const H: u32 = 54;

/// A square of `w` × `h` in the z = 0 plane around the origin, facing +Z.
fn square(w: f32, h: f32) -> Mesh {
    let positions = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]
        .map(|[x, y]| Vec3::new(x * w / 2.0, y * h / 2.0, 0.0))
        .to_vec();
    Mesh::new(positions, vec![Vec3::Z; 4], vec![], vec![0, 1, 2, 0, 2, 3]).unwrap()
}

/// The red decal's bias and opacity.
#[derive(Clone, Copy, Debug)]
struct Decal {
    bias: f32,
    alpha: f32,
}

/// The grey wall (or not) with the decal (or not) on it, the decal listed first: where their
/// depths tie, the wall, drawn later, wins an unbiased depth test.
fn scene(decal: Option<Decal>, wall: bool, eye: DVec3) -> Scene {
    let mut s = Scene::empty();
    if let Some(d) = decal {
        let red = s.add_material(Material {
            depth_bias: d.bias,
            alpha: d.alpha,
            ..Material::flat("decal", Vec3::new(0.9, 0.1, 0.1))
        });
        s.objects.push(Object {
            mesh: Arc::new(square(2.0, 1.4)),
            material: red,
            transform: DMat4::IDENTITY,
        });
    }
    if wall {
        let grey = s.add_material(Material::flat("wall", Vec3::splat(0.6)));
        s.objects.push(Object {
            mesh: Arc::new(square(10.0, 6.0)),
            material: grey,
            transform: DMat4::IDENTITY,
        });
    }
    s.ambient = Vec3::splat(0.1);
    s.camera = Camera::perspective(eye, DVec3::ZERO, 60.0, 0.1, 30.0);
    s.lights = vec![Light::point(
        DVec3::new(0.5, 0.8, 2.0),
        10.0,
        Vec3::ONE,
        8.0,
    )];
    s.validate().unwrap();
    s
}

/// Largest difference of any channel at a pixel.
fn difference(a: &image::RgbaImage, b: &image::RgbaImage, x: u32, y: u32) -> u8 {
    let (p, q) = (a.get_pixel(x, y), b.get_pixel(x, y));
    (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap()
}

/// The pixels where `decal_alone` shows the decal (over the black background).
fn decal_pixels(decal_alone: &image::RgbaImage) -> Vec<(u32, u32)> {
    let pixels = (0..W).flat_map(|x| (0..H).map(move |y| (x, y)));
    let red = |&(x, y): &(u32, u32)| decal_alone.get_pixel(x, y)[0] > 40;
    pixels.filter(red).collect()
}

/// Where the camera looks at the decal from: nearly head-on, and at a grazing 87° to the
/// wall's normal, where a pixel spans many depth steps and the rasterizer's snapping of the two
/// surfaces' different corners parts their depths most.
const EYES: [[f64; 3]; 2] = [[0.4, 0.3, 3.0], [1.2, 0.1, 0.08]];

#[test]
fn a_biased_decal_shows_over_the_surface_it_lies_on_with_every_method() {
    let opts = RenderOptions::default();
    let opaque = |bias| Decal { bias, alpha: 1.0 };
    let transparent = Decal {
        bias: 2.0,
        alpha: 0.5,
    };
    let mut forward_transparent = std::collections::HashMap::new();
    let mut hidden_unbiased = Vec::new();
    common::each_method(|es, method, gpu| {
        for (view, eye) in EYES.into_iter().enumerate() {
            let eye = DVec3::from(eye);
            let what = format!("{es} {method}, eye {eye}");
            let mut render = |decal, wall| gpu.render(&scene(decal, wall, eye), W, H, &opts);
            let alone = render(Some(opaque(2.0)), false);
            let decal = decal_pixels(&alone);
            assert!(decal.len() > 150, "{what}: {} decal pixels", decal.len());
            // Biased, the decal is drawn over the wall as it is drawn alone.
            let biased = render(Some(opaque(2.0)), true);
            let worst = (decal.iter())
                .map(|&(x, y)| difference(&biased, &alone, x, y))
                .max();
            assert!(
                worst <= Some(2),
                "{what}: {worst:?}/255 from the decal alone"
            );
            // Unbiased, the wall drawn after it wins where their depths tie.
            let unbiased = render(Some(opaque(0.0)), true);
            let hidden = (decal.iter())
                .filter(|&&(x, y)| difference(&unbiased, &alone, x, y) > 40)
                .count();
            eprintln!(
                "{what}: {hidden} of {} decal pixels hidden unbiased",
                decal.len()
            );
            hidden_unbiased.push(hidden);
            // Half transparent, blended over the wall as forward blends it.
            let blended = render(Some(transparent), true);
            let wall = render(None, true);
            let shown = (decal.iter())
                .filter(|&&(x, y)| difference(&blended, &wall, x, y) > 20)
                .count();
            assert_eq!(
                shown,
                decal.len(),
                "{what}: the transparent decal is missing"
            );
            if method == "forward" {
                forward_transparent.insert((es, view), blended.clone());
            }
            let forward = forward_transparent
                .get(&(es, view))
                .expect("forward runs first");
            let d = manylight::metrics::diff(forward, &blended);
            assert!(
                d.max_abs <= 2,
                "{what}: {}/255 from forward's transparent decal",
                d.max_abs
            );
        }
    });
    // The wall and the decal's depths do tie: the bias is what draws the decal.
    let tied: usize = hidden_unbiased.iter().sum();
    assert!(tied > 0, "{hidden_unbiased:?}");
}

/// A game's polygon offset clamp (`GL_EXT_polygon_offset_clamp`) left negative would cut the
/// bias toward the camera to almost nothing: the call draws with no clamp (the decal still
/// shows over the wall as it does alone, from both eyes), as `glPolygonOffset` alone would
/// leave it; with the game's clamp kept, 105 of 659 pixels were hidden head-on.
#[test]
fn a_games_negative_offset_clamp_does_not_cut_the_bias() {
    let opts = RenderOptions::default();
    let mut gpu = common::Gpu::new(manylight::EsVersion::Es3);
    if !gpu.r().caps().has_extension("GL_EXT_polygon_offset_clamp") {
        if !common::other_implementation_than_mesa("GL_EXT_polygon_offset_clamp") {
            common::skip("this Mesa lists no GL_EXT_polygon_offset_clamp");
        }
        return;
    }
    let library = manylight::gl::gles_lib::library().unwrap();
    let address = library.proc_address("glPolygonOffsetClampEXT");
    assert!(
        !address.is_null(),
        "the extension is listed without its entry point"
    );
    // SAFETY: the extension's type for glPolygonOffsetClampEXT.
    let set_clamp: extern "system" fn(f32, f32, f32) = unsafe { std::mem::transmute(address) };
    let decal = Some(Decal {
        bias: 2.0,
        alpha: 1.0,
    });
    for eye in EYES.map(DVec3::from) {
        let alone = gpu.render(&scene(decal, false, eye), W, H, &opts);
        let pixels = decal_pixels(&alone);
        gpu.gl();
        set_clamp(0.0, 0.0, -1e-12);
        let clamped = gpu.render(&scene(decal, true, eye), W, H, &opts);
        gpu.gl();
        set_clamp(0.0, 0.0, 0.0);
        let hidden = (pixels.iter())
            .filter(|&&(x, y)| difference(&clamped, &alone, x, y) > 2)
            .count();
        assert_eq!(
            hidden,
            0,
            "eye {eye}: {hidden} of {} decal pixels hidden",
            pixels.len()
        );
    }
}

/// Deferred's light volumes are depth tested one-sidedly against the G-buffer's depth, which a
/// depth bias moves: toward the camera, a sphere's near side failed its `LEQUAL` test in front
/// of the surface, and at a grazing angle, where the bias grows with the depth slope, a wall
/// of bias 64 lost every light (helper-167: mean 20 against forward's 73). A surface drawn
/// off its depth either way, or two drawn off it both ways, is lit as forward lights it.
#[test]
fn surfaces_drawn_off_their_depth_are_lit_as_forward_lights_them() {
    let opts = RenderOptions::default();
    let mut gpu = common::Gpu::new(manylight::EsVersion::Es3);
    // Small lights before the wall, their spheres wholly in front of the near plane.
    let lights: Vec<Light> = (0..12)
        .map(|i| {
            let (x, y) = (f64::from(i % 4) - 1.5, f64::from(i / 4) - 1.0);
            Light::point(DVec3::new(x * 1.5, y * 1.2, 0.6), 1.2, Vec3::ONE, 3.0)
        })
        .collect();
    let cases: [(f32, Option<f32>); 7] = [
        (64.0, None),
        (1024.0, None),
        (-64.0, None),
        (-1024.0, None),
        (2.0, None),
        // A decal drawn toward the camera on a wall drawn away from it.
        (-64.0, Some(64.0)),
        (0.0, None),
    ];
    for (wall_bias, decal_bias) in cases {
        for eye in EYES.map(DVec3::from) {
            let decal = decal_bias.map(|bias| Decal { bias, alpha: 1.0 });
            let mut s = scene(decal, true, eye);
            let wall = s.objects.len() - 1;
            s.materials[s.objects[wall].material].depth_bias = wall_bias;
            s.lights = lights.clone();
            let what = format!("wall {wall_bias}, decal {decal_bias:?}, eye {eye}");
            gpu.r().set_method_named("forward").unwrap();
            let forward = gpu.render(&s, W, H, &opts);
            gpu.r().set_method_named("deferred").unwrap();
            let deferred = gpu.render(&s, W, H, &opts);
            let d = manylight::metrics::diff(&forward, &deferred);
            assert!(
                d.max_abs <= 2,
                "{what}: deferred {}/255 from forward",
                d.max_abs
            );
        }
    }
}
