//! Traditional deferred against plain forward, and its capability rules.

mod common;

use common::Gpu;
use manylight::scene;
use manylight::{EsVersion, RenderOptions};

#[test]
fn deferred_matches_forward_within_2_of_255_on_opaque_scenes() {
    let mut gpu = Gpu::new(EsVersion::Es3);
    for name in ["courtyard", "pillars", "plane"] {
        for lights in [64, 1024] {
            let s = scene::builtin::build(name, Some((lights, 21))).unwrap();
            for linear in [false, true] {
                let opts = RenderOptions {
                    linear,
                    ..Default::default()
                };
                gpu.r().set_method_named("forward").unwrap();
                let (reference, _) = gpu.r().render_offscreen(&s, 256, 144, &opts).unwrap();
                gpu.r().set_method_named("deferred").unwrap();
                let (img, stats) = gpu.r().render_offscreen(&s, 256, 144, &opts).unwrap();
                let d = manylight::metrics::diff(&reference, &img);
                eprintln!(
                    "{name} {lights} linear={linear}: max {} rmse {:.3}",
                    d.max_abs, d.rmse
                );
                assert!(
                    d.max_abs <= 2,
                    "{name} {lights}: deferred is {} / 255 from forward",
                    d.max_abs
                );
                let per_pixel = manylight::gl::gbuffer::bytes_per_pixel(gpu.r().caps());
                assert_eq!(stats.memory.gbuffer_bytes, 256 * 144 * per_pixel);
            }
        }
    }
}

#[test]
fn transparent_objects_take_the_forward_fallback() {
    let s = scene::builtin::build("bubbles", Some((128, 2))).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let opts = RenderOptions::default();
    gpu.r().set_method_named("forward").unwrap();
    let (reference, _) = gpu.r().render_offscreen(&s, 192, 108, &opts).unwrap();
    gpu.r().set_method_named("deferred").unwrap();
    let (img, _) = gpu.r().render_offscreen(&s, 192, 108, &opts).unwrap();
    let d = manylight::metrics::diff(&reference, &img);
    assert!(
        d.max_abs <= 2,
        "bubbles: deferred + forward fallback is {} / 255 from forward",
        d.max_abs
    );
}

#[test]
fn deferred_is_unsupported_on_es2_with_a_reason() {
    let mut gpu = Gpu::new(EsVersion::Es2);
    let err = gpu
        .r()
        .set_method_named("deferred")
        .unwrap_err()
        .to_string();
    assert!(err.contains("deferred") && err.contains("ES 3.0"), "{err}");
    // The renderer keeps working with its previous method.
    let s = scene::builtin::build("plane", Some((8, 1))).unwrap();
    assert!(gpu
        .r()
        .render_offscreen(&s, 32, 18, &RenderOptions::default())
        .is_ok());
}
