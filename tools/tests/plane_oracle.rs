//! Pixels of the `plane` scene against the light model evaluated on the CPU in f64.

mod common;

use common::{max_oracle_error, Gpu};
use glam::{DVec3, Vec3};
use manylight::metrics::cpu_reference::Encoding;
use manylight::scene::{self, Light, Scene};
use manylight::{EsVersion, RenderOptions};

const W: u32 = 256;
const H: u32 = 144;

/// A point light off-axis, a coloured one grazing the plane, a soft spot and a hard spot, a
/// light behind the plane (must contribute nothing) and one with radius 0.
fn lit_plane() -> Scene {
    let mut s = scene::builtin::build("plane", None).unwrap();
    s.ambient = Vec3::splat(0.03);
    s.lights = vec![
        Light::point(
            DVec3::new(-1.5, 0.5, 1.0),
            3.0,
            Vec3::new(1.0, 0.9, 0.8),
            1.2,
        ),
        Light::point(
            DVec3::new(2.0, -0.8, 0.3),
            2.0,
            Vec3::new(0.2, 0.5, 1.0),
            2.0,
        ),
        Light::spot(
            DVec3::new(0.5, 1.2, 1.5),
            4.0,
            Vec3::new(1.0, 0.3, 0.2),
            3.0,
            manylight::Cone {
                direction: DVec3::new(0.1, -0.3, -1.0),
                inner_deg: 12.0,
                outer_deg: 25.0,
            },
        ),
        Light::spot(
            DVec3::new(-2.5, -1.0, 2.0),
            5.0,
            Vec3::new(0.3, 1.0, 0.3),
            1.5,
            manylight::Cone {
                direction: DVec3::new(0.0, 0.0, -1.0),
                inner_deg: 20.0,
                outer_deg: 20.0,
            },
        ),
        Light::point(DVec3::new(0.0, 0.0, -0.5), 3.0, Vec3::ONE, 5.0),
        Light::point(DVec3::new(1.0, 1.0, 1.0), 0.0, Vec3::ONE, 5.0),
    ];
    s
}

fn check(es: EsVersion, opts: RenderOptions, tolerance: f64) -> f64 {
    let scene = lit_plane();
    let mut gpu = Gpu::new(es);
    let img = gpu.render(&scene, W, H, &opts);
    let encoding = if opts.linear {
        Encoding::Linear
    } else {
        Encoding::Srgb
    };
    let (err, at, covered) = max_oracle_error(&img, &scene, encoding, gpu.r().caps());
    eprintln!("{es} {opts:?}: max error {err:.3}/255 at {at:?}");
    // The plane fills the view; only pixels on its diagonal edge are left out.
    assert!(
        covered > (W * H) as usize * 95 / 100,
        "only {covered} pixels compared"
    );
    assert!(
        err <= tolerance,
        "{es}: max error {err:.2}/255 at {at:?} exceeds {tolerance}/255 (opts {opts:?})"
    );
    err
}

#[test]
fn es3_linear_pixels_match_the_light_model() {
    check(
        EsVersion::Es3,
        RenderOptions {
            linear: true,
            ..Default::default()
        },
        2.0,
    );
}

#[test]
fn es2_linear_pixels_match_the_light_model() {
    check(
        EsVersion::Es2,
        RenderOptions {
            linear: true,
            ..Default::default()
        },
        2.0,
    );
}

#[test]
fn srgb_output_matches_the_encoded_light_model() {
    check(EsVersion::Es3, RenderOptions::default(), 2.0);
}

/// The RGBA8 light packing (ES 2.0 without float textures) is lossy; its error on this scene is
/// measured and bounded here (16-bit positions, shared-exponent radiance, 16-bit angles).
#[test]
fn rgba8_light_packing_stays_within_its_measured_error() {
    let opts = RenderOptions {
        linear: true,
        measure: manylight::MeasureOptions {
            force_rgba8_lights: true,
            ..Default::default()
        },
        ..Default::default()
    };
    let err = check(EsVersion::Es2, opts, 3.0);
    eprintln!("RGBA8 light packing: max error {err:.2}/255 on the plane scene");
}

/// The oracle has teeth: moving one light by 5 cm is visible against it.
#[test]
fn oracle_detects_a_slightly_moved_light() {
    let mut scene = lit_plane();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let reference = scene.clone();
    scene.lights[0].position.x += 0.05;
    let img = gpu.render(
        &scene,
        W,
        H,
        &RenderOptions {
            linear: true,
            ..Default::default()
        },
    );
    let (err, _, _) = max_oracle_error(&img, &reference, Encoding::Linear, gpu.r().caps());
    assert!(err > 2.0, "a moved light went unnoticed (error {err})");
}
