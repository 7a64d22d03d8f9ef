//! Directional lights (a sun): the picture the f64 model says on ES 2.0 and 3.0, every method
//! equal to plain forward with suns and point lights together, a bright sun without fragment
//! highp (no Inf or NaN, the model's picture where it is not white anyway) and the warning
//! when a scene has more suns than a frame shows.

use crate::common;

use common::{max_oracle_error, mean, warnings, Gpu};
use glam::{DVec3, Vec3};
use manylight::metrics::cpu_reference::Encoding;
use manylight::metrics::diff;
use manylight::scene::{self, DirectionalLight, Scene};
use manylight::{EsVersion, RenderOptions};

const W: u32 = 96;
const H: u32 = 54;

/// A warm sun from the upper left, and a dim blue one low from the right (its direction's
/// length far from 1; not in the plane of the courtyard's floor, where N·L = 0 would make the
/// specular lobe hang on the last bit of the normal).
fn suns() -> Vec<DirectionalLight> {
    vec![
        DirectionalLight::new(DVec3::new(1.0, -2.0, -1.5), Vec3::new(1.0, 0.9, 0.7), 0.6),
        DirectionalLight::new(DVec3::new(-3e5, -1e5, -1e5), Vec3::new(0.2, 0.3, 1.0), 0.4),
    ]
}

/// The `plane` scene (glossy: the specular lobe moves across it) lit by `lights` only.
fn sunlit_plane(lights: Vec<DirectionalLight>) -> Scene {
    let mut scene = scene::builtin::build("plane", None).unwrap();
    scene.directional_lights = lights;
    scene
}

#[test]
fn a_sun_lights_the_plane_as_the_f64_model_says() {
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::new(es);
        let scene = sunlit_plane(suns());
        for method in ["forward", "clustered"] {
            gpu.r().set_method_named(method).unwrap();
            let img = gpu.render(&scene, W, H, &RenderOptions::default());
            let caps = gpu.r().caps().clone();
            let (err, at, n) = max_oracle_error(&img, &scene, Encoding::Srgb, &caps);
            eprintln!("{es} {method}: max {err:.2}/255 at {at:?} over {n} pixels");
            assert!(
                n > (W * H / 2) as usize,
                "{es} {method}: only {n} pixels compared"
            );
            assert!(
                err <= 2.0,
                "{es} {method}: {err:.2}/255 off the f64 model at {at:?}"
            );
            // The sun is most of the picture: the ambient alone is nearly black.
            let dark = gpu.render(&sunlit_plane(Vec::new()), W, H, &RenderOptions::default());
            assert!(
                mean(&img) > mean(&dark) + 60.0,
                "{es} {method}: the sun barely shows"
            );
        }
    }
}

#[test]
fn every_method_matches_forward_with_suns_and_point_lights() {
    let mut scene = scene::builtin::build("courtyard", Some((64, 5))).unwrap();
    scene.directional_lights = suns();
    let mut without_suns = scene.clone();
    without_suns.directional_lights.clear();
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::new(es);
        let opts = RenderOptions::default();
        gpu.r().set_method_named("forward").unwrap();
        let reference = gpu.render(&scene, W, H, &opts);
        let unlit = gpu.render(&without_suns, W, H, &opts);
        assert!(
            diff(&reference, &unlit).max_abs > 40,
            "{es}: the suns barely show"
        );
        let methods: &[&str] = match es {
            EsVersion::Es2 => &["tiled", "clustered"],
            EsVersion::Es3 => &["tiled", "clustered", "deferred"],
        };
        for method in methods {
            gpu.r().set_method_named(method).unwrap();
            let img = gpu.render(&scene, W, H, &opts);
            let d = diff(&reference, &img);
            eprintln!("{es} {method}: {d:?}");
            assert!(d.max_abs <= 2, "{es} {method} differs from forward: {d:?}");
        }
    }
}

#[test]
fn a_bright_sun_without_fragment_highp_stays_finite_and_right() {
    let mut gpu = Gpu::without_fragment_highp();
    // 100 000 lux, past fp16's 65 504, and as bright a sun shining on the plane's back (its
    // contribution there is radiance × 0: Inf × 0 if the radiance overflowed).
    let bright = 1e5f32;
    let lights = vec![
        DirectionalLight::new(
            DVec3::new(1.0, -2.0, -1.5),
            Vec3::new(1.0, 0.9, 0.7),
            bright,
        ),
        DirectionalLight::new(DVec3::new(0.0, 0.3, 1.0), Vec3::ONE, bright),
    ];
    let scene = sunlit_plane(lights.clone());
    let (hdr, _) = gpu
        .r()
        .render_offscreen_hdr(&scene, W, H, &RenderOptions::default())
        .unwrap();
    let bad = hdr
        .iter()
        .filter(|p| !p.iter().all(|c| c.is_finite()))
        .count();
    assert_eq!(bad, 0, "{bad} pixels Inf or NaN");
    // The picture is the model's: the same as the scene with everything 2^EV as bright, on
    // the CPU. At −10 EV the 100 000 lux sun is white, as the model says; a sun of 3 000
    // (radiance read as 3 000 / 64², 64² folded back in) at −12 EV is in the middle, and so
    // is a daylight sun of 20 000 lux at −15 EV (pre-exposed: its fp16 cap of 4 000 drew it
    // at a fifth).
    for (intensity, ev) in [(bright, -10.0), (3000.0, -12.0), (20_000.0, -15.0)] {
        let mut scene = scene.clone();
        for l in &mut scene.directional_lights {
            l.intensity = intensity;
        }
        let opts = RenderOptions {
            exposure_ev: ev,
            ..Default::default()
        };
        let img = gpu.render(&scene, W, H, &opts);
        let mut scaled = scene.clone();
        let s = ev.exp2();
        scaled.ambient *= s;
        for l in &mut scaled.directional_lights {
            l.intensity *= s;
        }
        let caps = gpu.r().caps().clone();
        let (err, at, n) = max_oracle_error(&img, &scaled, Encoding::Srgb, &caps);
        eprintln!("no fragment highp, sun {intensity} at {ev} EV: max {err:.2}/255 at {at:?} over {n}, mean {:.1}", mean(&img));
        assert!(
            n > (W * H / 2) as usize && err <= 3.0,
            "{intensity} at {ev} EV: {err:.2}/255 at {at:?}"
        );
    }
}

#[test]
fn more_than_four_suns_keep_the_brightest_with_one_warning() {
    warnings::install();
    let sun = |x: f64, i: f32| DirectionalLight::new(DVec3::new(x, -1.0, -1.0), Vec3::ONE, i);
    // Six: the two dimmest (but not dark) are left out.
    let scene = sunlit_plane(vec![
        sun(0.5, 0.1),
        sun(-0.5, 0.02),
        sun(0.0, 0.15),
        sun(1.0, 0.12),
        sun(-1.0, 0.03),
        sun(0.2, 0.1),
    ]);
    let mut gpu = Gpu::new(EsVersion::Es3);
    let img = gpu.render(&scene, W, H, &RenderOptions::default());
    gpu.render(&scene, W, H, &RenderOptions::default());
    let caps = gpu.r().caps().clone();
    let (err, at, n) = max_oracle_error(&img, &scene, Encoding::Srgb, &caps);
    // A reference that kept (almost) no pixel would compare nothing and read 0.
    assert!(n >= 50, "only {n} pixels compared");
    assert!(
        err <= 2.0,
        "{err:.2}/255 off the model's brightest four at {at:?}"
    );
    let mut four = scene.clone();
    four.directional_lights.retain(|l| l.intensity >= 0.1);
    assert_eq!(four.directional_lights.len(), 4);
    let d = diff(&img, &gpu.render(&four, W, H, &RenderOptions::default()));
    assert_eq!(d.max_abs, 0, "not the brightest four: {d:?}");
    let warned = warnings::warnings_containing("directional");
    assert_eq!(warned.len(), 1, "one warning for two frames: {warned:?}");
    assert!(warned[0].contains("2 of the scene's 6"), "{warned:?}");
}

#[test]
fn only_a_scene_with_an_active_sun_builds_the_sun_code() {
    use manylight::methods::ShaderFeatures;
    let has_sun_code = |gpu: &mut Gpu| {
        let report = gpu.r().program_report();
        report
            .iter()
            .filter(|p| ShaderFeatures(p.features).has(ShaderFeatures::DIRECTIONAL))
            .map(|p| p.shader.to_string())
            .collect::<Vec<_>>()
    };
    // Fresh: the report is of the variants this renderer built.
    let mut gpu = Gpu::fresh(EsVersion::Es3);
    let mut dark = scene::builtin::build("courtyard", Some((16, 2))).unwrap();
    dark.directional_lights = vec![DirectionalLight::new(DVec3::NEG_Y, Vec3::ONE, 0.0)];
    gpu.r().set_method_named("deferred").unwrap();
    gpu.render(&dark, W, H, &RenderOptions::default());
    assert!(
        has_sun_code(&mut gpu).is_empty(),
        "a dark sun costs nothing"
    );
    let mut lit = dark.clone();
    lit.directional_lights[0].intensity = 1.0;
    gpu.render(&lit, W, H, &RenderOptions::default());
    let mut with_sun = has_sun_code(&mut gpu);
    with_sun.sort();
    // The composite shades the suns; the G-buffer and light passes are the same without.
    assert_eq!(with_sun, ["deferred_composite"], "{with_sun:?}");
}
