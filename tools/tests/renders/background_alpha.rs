//! The image's alpha over a transparent background (`clear_color` alpha 0), for compositing:
//! a surface of opacity `a` in front of nothing gives alpha `a`, two such layers
//! `1 − (1 − a)²`, an opaque one 1 and an empty pixel 0, with every method on ES 2.0 and 3.0.
//! The blend kept the background's alpha, so glass over a transparent background came back
//! with alpha 0 and vanished when composited.

use crate::common;

use std::sync::Arc;

use glam::{DMat4, DVec3, Vec3};
use manylight::scene::{Light, Material, Object, Scene};
use manylight::{Camera, MeshBuilder, RenderOptions};

const W: u32 = 96;
const H: u32 = 54;

/// Side by side in front of nothing: on the left a half-transparent quad, in the middle an
/// opaque one, on the right a half-transparent box (two layers: its far and near sides).
fn scene() -> Scene {
    let mut s = Scene::empty();
    let mut glass = Material::flat("glass", Vec3::new(0.3, 0.8, 0.5));
    glass.alpha = 0.5;
    let glass = s.add_material(glass);
    let stone = s.add_material(Material::flat("stone", Vec3::splat(0.6)));
    let quad = |x: f32| {
        let mut b = MeshBuilder::new();
        b.quad(
            Vec3::new(x - 0.6, -0.6, 0.0),
            Vec3::new(x + 0.6, -0.6, 0.0),
            Vec3::new(x + 0.6, 0.6, 0.0),
            Vec3::new(x - 0.6, 0.6, 0.0),
        );
        Arc::new(b.build().unwrap())
    };
    let mut cube = MeshBuilder::new();
    cube.cuboid(Vec3::splat(-0.5), Vec3::splat(0.5));
    for (mesh, material, transform) in [
        (quad(-1.7), glass, DMat4::IDENTITY),
        (quad(0.0), stone, DMat4::IDENTITY),
        (
            Arc::new(cube.build().unwrap()),
            glass,
            DMat4::from_translation(DVec3::new(1.7, 0.0, 0.0)),
        ),
    ] {
        s.objects.push(Object {
            mesh,
            material,
            transform,
        });
    }
    s.ambient = Vec3::splat(0.2);
    s.camera = Camera::perspective(DVec3::new(0.0, 0.0, 4.0), DVec3::ZERO, 55.0, 0.1, 20.0);
    s.lights = vec![Light::point(DVec3::new(0.0, 1.0, 2.0), 8.0, Vec3::ONE, 2.0)];
    s.validate().unwrap();
    s
}

#[test]
fn alpha_over_a_transparent_background_is_coverage() {
    let opts = RenderOptions {
        clear_color: [0.0; 4],
        ..Default::default()
    };
    let s = scene();
    common::each_method(|es, method, gpu| {
        let img = gpu.render(&s, W, H, &opts);
        let alpha = |x: u32| img.get_pixel(x, H / 2)[3];
        // Columns through the middle of each object, and one between them.
        let (quad, opaque, cube, empty) = (
            alpha(W / 2 - 27),
            alpha(W / 2),
            alpha(W / 2 + 27),
            alpha(W / 2 - 12),
        );
        let place = format!("{es} {method}");
        assert!(quad.abs_diff(128) <= 1, "{place}: glass quad alpha {quad}");
        assert_eq!(opaque, 255, "{place}: opaque quad");
        assert!(cube.abs_diff(191) <= 1, "{place}: glass box alpha {cube}");
        assert_eq!(empty, 0, "{place}: background");
    });
}
