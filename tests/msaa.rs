//! Multisampling (`RenderOptions::samples`): every method that supports it still equals plain
//! forward with the same samples; along a polygon edge the resolved pixels take exactly the
//! coverage fractions of 4 samples, where without MSAA they are all-or-nothing; unsupported
//! cases are clear errors.

mod common;

use std::sync::Arc;

use common::Gpu;
use glam::{DMat4, DVec3, Vec3};
use manylight::scene::meshbuild::MeshBuilder;
use manylight::scene::{self, Camera, Material, Object, Scene};
use manylight::{EsVersion, RenderOptions};

fn msaa(samples: u32) -> RenderOptions {
    RenderOptions {
        samples,
        ..RenderOptions::default()
    }
}

#[test]
fn every_method_with_msaa_matches_forward_with_msaa() {
    let scene = scene::builtin::build("courtyard", Some((64, 2))).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    gpu.r().set_method("forward").unwrap();
    let reference = gpu.render(&scene, 128, 72, &msaa(4));
    let single = gpu.render(&scene, 128, 72, &msaa(1));
    assert_ne!(reference, single, "4 samples changed nothing");
    for method in ["tiled", "clustered", "auto"] {
        gpu.r().set_method(method).unwrap();
        let (img, stats) = gpu.r().render_offscreen(&scene, 128, 72, &msaa(4)).unwrap();
        assert_eq!(stats.samples, 4);
        assert_eq!(stats.msaa_bytes, 128 * 72 * 4 * 8);
        let d = manylight::metrics::diff(&reference, &img);
        assert!(d.max_abs <= 2, "{method}: {} / 255 from forward", d.max_abs);
    }
}

/// A white square turned 30° about the view axis on black, lit by ambient light alone: each
/// pixel's value is its coverage.
fn turned_square() -> Scene {
    let mut s = Scene::empty();
    let white = s.add_material(Material::flat("white", Vec3::ONE));
    let mut square = MeshBuilder::new();
    square.quad(
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
    );
    s.objects.push(Object {
        mesh: Arc::new(square.build()),
        material: white,
        transform: DMat4::from_rotation_z(30f64.to_radians()),
    });
    s.ambient = Vec3::ONE;
    s.camera = Camera::perspective(DVec3::new(0.0, 0.0, 4.0), DVec3::ZERO, 60.0, 0.1, 10.0);
    s
}

#[test]
fn edges_get_the_coverage_fractions_of_their_samples() {
    let scene = turned_square();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let linear = |samples| RenderOptions {
        linear: true,
        ..msaa(samples)
    };
    let plain = gpu.render(&scene, 96, 96, &linear(1));
    assert!(
        plain.pixels().all(|p| p[0] == 0 || p[0] == 255),
        "without MSAA every pixel is covered or not"
    );
    let smooth = gpu.render(&scene, 96, 96, &linear(4));
    let mut partial = 0;
    for p in smooth.pixels() {
        // The resolve averages 4 samples: k/4 of white, k = 0..=4.
        let k = (p[0] as f64 / 255.0 * 4.0).round();
        assert!(
            (p[0] as f64 - k * 255.0 / 4.0).abs() <= 1.0,
            "{} is not a coverage of 4 samples",
            p[0]
        );
        partial += usize::from(k > 0.0 && k < 4.0);
    }
    // The square's outline is about 166 pixels long here (sides of 41.6 px); with 4 samples
    // 100 of the pixels it crosses come out partly covered on llvmpipe.
    assert!(
        partial > 60,
        "only {partial} edge pixels are partly covered"
    );
    // Away from the edges nothing changes.
    assert_eq!(smooth.get_pixel(48, 48)[0], 255);
    assert_eq!(smooth.get_pixel(2, 2)[0], 0);
}

#[test]
fn unsupported_msaa_is_a_clear_error() {
    let scene = scene::builtin::build("plane", Some((4, 1))).unwrap();
    let mut es3 = Gpu::new(EsVersion::Es3);
    es3.r().set_method("deferred").unwrap();
    let err = es3
        .r()
        .render_offscreen(&scene, 16, 16, &msaa(4))
        .unwrap_err();
    assert!(err.to_string().contains("deferred"), "{err}");
    es3.r().set_method("clustered").unwrap();
    let err = es3
        .r()
        .render_offscreen(&scene, 16, 16, &msaa(64))
        .unwrap_err();
    assert!(err.to_string().contains("GL_MAX_SAMPLES"), "{err}");
    let err = es3
        .r()
        .render_offscreen_hdr(&scene, 16, 16, &msaa(4))
        .unwrap_err();
    assert!(err.to_string().contains("HDR"), "{err}");
    drop(es3);
    let mut es2 = Gpu::new(EsVersion::Es2);
    let err = es2
        .r()
        .render_offscreen(&scene, 16, 16, &msaa(4))
        .unwrap_err();
    assert!(err.to_string().contains("ES 3.0"), "{err}");
}
