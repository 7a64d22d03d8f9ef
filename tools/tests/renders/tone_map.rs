//! Exposure and the tone maps against their CPU formulas (`scene::shading::tone_map`): the
//! `plane` scene with lights bright enough to pass 1 is rendered once as raw radiance (a
//! half-float target, no output stage) and once through each curve; every 8-bit pixel must be
//! the curve of its radiance within 2/255, on ES 2.0 and ES 3.0, linear and sRGB-encoded.

use crate::common;

use common::Gpu;
use glam::{DVec3, Vec3};
use manylight::scene::{self, shading, Light, Scene};
use manylight::{EsVersion, RenderOptions, ToneMap};

fn bright_plane() -> Scene {
    let mut s = scene::builtin::build("plane", None).unwrap();
    s.ambient = Vec3::splat(0.05);
    s.lights = vec![
        Light::point(
            DVec3::new(-0.8, 0.3, 0.6),
            3.0,
            Vec3::new(1.0, 0.6, 0.3),
            6.0,
        ),
        Light::point(
            DVec3::new(0.9, -0.2, 0.4),
            2.0,
            Vec3::new(0.3, 0.5, 1.0),
            3.0,
        ),
    ];
    s
}

#[test]
fn tone_maps_and_exposure_match_their_formulas() {
    let scene = bright_plane();
    let (w, h) = (96, 54);
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::new(es);
        gpu.r().set_method_named("forward").unwrap();
        let (radiance, _) = gpu
            .r()
            .render_offscreen_hdr(&scene, w, h, &RenderOptions::default())
            .unwrap();
        let brightest = radiance
            .iter()
            .map(|p| p[0].max(p[1]).max(p[2]))
            .fold(0.0, f32::max);
        assert!(brightest > 2.0, "{es}: the scene must pass 1 ({brightest})");
        for curve in [
            ToneMap::None,
            ToneMap::Reinhard,
            ToneMap::Aces,
            ToneMap::Neutral,
        ] {
            for exposure_ev in [0.0f32, -1.5, 2.0] {
                for linear in [true, false] {
                    let opts = RenderOptions {
                        tone_map: curve,
                        exposure_ev,
                        linear,
                        ..RenderOptions::default()
                    };
                    let img = gpu.render(&scene, w, h, &opts);
                    let scale = 2f64.powf(exposure_ev as f64);
                    let mut worst = (0.0, 0, [0.0; 3]);
                    for (i, p) in img.pixels().enumerate() {
                        let r = radiance[i];
                        let mapped = shading::tone_map(
                            [
                                r[0] as f64 * scale,
                                r[1] as f64 * scale,
                                r[2] as f64 * scale,
                            ],
                            curve,
                        );
                        for c in 0..3 {
                            let v = mapped[c].clamp(0.0, 1.0);
                            let expected = 255.0
                                * if linear {
                                    v
                                } else {
                                    shading::linear_to_srgb(v)
                                };
                            let error = (p[c] as f64 - expected).abs();
                            if error > worst.0 {
                                worst = (error, i, mapped);
                            }
                        }
                    }
                    assert!(
                        worst.0 <= 2.0,
                        "{es} {curve:?} EV {exposure_ev} linear {linear}: {:.2} / 255 at pixel \
                         {} (curve gives {:?})",
                        worst.0,
                        worst.1,
                        worst.2
                    );
                }
            }
        }
    }
}

#[test]
fn the_curves_keep_their_defining_properties() {
    // Reinhard: 1 → 1/2; ACES fit: 0 → 0 and large → 1; Neutral: dark colours unchanged
    // (less the small toe offset), highlights below 1, and grey stays grey.
    assert_eq!(shading::tone_map([1.0; 3], ToneMap::Reinhard), [0.5; 3]);
    assert_eq!(shading::tone_map([0.0; 3], ToneMap::Aces), [0.0; 3]);
    assert!(shading::tone_map([1e6; 3], ToneMap::Aces)[0] > 0.999);
    let dark = shading::tone_map([0.5, 0.3, 0.2], ToneMap::Neutral);
    assert!(
        (dark[0] - 0.46).abs() < 1e-12 && (dark[2] - 0.16).abs() < 1e-12,
        "{dark:?}"
    );
    let hot = shading::tone_map([40.0, 20.0, 10.0], ToneMap::Neutral);
    assert!(
        hot.iter().all(|&v| v < 1.0) && hot[0] > hot[1] && hot[1] > hot[2],
        "{hot:?}"
    );
    let grey = shading::tone_map([7.0; 3], ToneMap::Neutral);
    assert!(grey[0] == grey[1] && grey[1] == grey[2] && grey[0] < 1.0);
}

#[test]
fn an_exposure_out_of_range_is_refused_naming_the_field() {
    let mut gpu = Gpu::new(EsVersion::Es3);
    for exposure_ev in [f32::NAN, 40.0, -1e9] {
        let err = gpu
            .r()
            .render_offscreen(
                &bright_plane(),
                8,
                8,
                &RenderOptions {
                    exposure_ev,
                    ..RenderOptions::default()
                },
            )
            .unwrap_err()
            .to_string();
        assert!(err.contains("exposure_ev"), "{err}");
    }
}

/// On a device without fragment highp the output stage runs in fp16: the curves must not
/// overflow there (ACES's squares pass 65 504 at c ≈ 165, and Inf/Inf is NaN) — a strongly
/// exposed bright scene comes out white where it is bright. llvmpipe happens to clamp that NaN
/// to 1, so here this guards the other curves and the exposure; drivers that keep NaN (black)
/// also check ACES's cap.
#[test]
fn tone_maps_do_not_overflow_without_fragment_highp() {
    let scene = bright_plane();
    let mut full = Gpu::new(EsVersion::Es2);
    full.r().set_method_named("forward").unwrap();
    let (radiance, _) = full
        .r()
        .render_offscreen_hdr(&scene, 64, 36, &RenderOptions::default())
        .unwrap();
    drop(full);
    let mut gpu = Gpu::without_fragment_highp();
    for curve in [ToneMap::Reinhard, ToneMap::Aces, ToneMap::Neutral] {
        let opts = RenderOptions {
            tone_map: curve,
            exposure_ev: 12.0,
            linear: true,
            ..RenderOptions::default()
        };
        let img = gpu.render(&scene, 64, 36, &opts);
        let mut bright = 0;
        for (i, p) in img.pixels().enumerate() {
            let r = radiance[i];
            // 2^12 × radiance past 1000 in every channel: every curve gives (nearly) 1.
            if r.iter().take(3).all(|&v| v * 4096.0 > 1000.0) {
                assert!(
                    p.0[..3].iter().all(|&c| c >= 250),
                    "{curve:?}: pixel {i} with radiance {r:?} came out {p:?}"
                );
                bright += 1;
            }
        }
        // The plane under the light is that bright (a dark reference would check nothing).
        assert!(bright >= 100, "{curve:?}: {bright} pixels past the cap");
    }
}
