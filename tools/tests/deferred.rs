//! Traditional deferred against plain forward, and its capability rules.

mod common;

use common::Gpu;
use glam::{DVec3, Vec3};
use manylight::gl::gbuffer;
use manylight::methods::ShaderFeatures;
use manylight::renderer::CountKind;
use manylight::scene::{self, DirectionalLight, Material};
use manylight::{EsVersion, RenderOptions};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// A material the G-buffer's specular target is for.
fn reads_specular(m: &Material) -> bool {
    m.has_specular() || m.is_metallic_roughness()
}

#[test]
fn deferred_matches_forward_within_2_of_255_on_opaque_scenes() {
    let mut gpu = Gpu::new(EsVersion::Es3);
    for name in ["courtyard", "pillars", "plane"] {
        // Linear output changes only the last step, the encoding, whatever the lights: the
        // smaller count checks it. Forward over 1 024 lights is a software GPU's slow part:
        // that count at a quarter of the pixels, as in culled_vs_forward.
        for (lights, encodings, (w, h)) in [
            (64, &[false, true][..], (256, 144)),
            (1024, &[false][..], (128, 72)),
        ] {
            let s = scene::builtin::build(name, Some((lights, 21))).unwrap();
            for &linear in encodings {
                let opts = RenderOptions {
                    linear,
                    ..Default::default()
                };
                let (reference, _) = gpu.render_with("forward", &s, (w, h), &opts);
                let (img, stats) = gpu.render_with("deferred", &s, (w, h), &opts);
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
                let specular = s.materials.iter().any(reads_specular);
                let per_pixel = gbuffer::bytes_per_pixel(gpu.r().caps(), specular);
                assert_eq!(stats.memory.gbuffer_bytes, (w * h) as usize * per_pixel);
            }
        }
    }
}

/// The specular target is made only for a scene with a specular or metallic-roughness
/// material: 8 bytes a pixel fewer without, the picture forward's either way, a sun's
/// included (the composite reads the target too), as the scene gains and loses such a
/// material.
#[test]
fn the_specular_target_is_there_only_for_materials_that_read_it() {
    let mut gpu = Gpu::new(EsVersion::Es3);
    let (w, h) = (128, 72);
    let mut s = scene::builtin::build("pillars", Some((64, 3))).unwrap();
    let sun = DirectionalLight::new(DVec3::new(1.0, -2.0, -1.0), Vec3::ONE, 0.6);
    s.directional_lights.push(sun);
    let matte = |s: &mut scene::Scene| {
        for m in &mut s.materials {
            m.specular = Vec3::ZERO;
        }
    };
    matte(&mut s);
    let mut shiny = s.clone();
    shiny.materials[0].specular = Vec3::splat(0.6);
    shiny.materials[0].shininess = 24.0;
    let mut metal = s.clone();
    metal.materials[0] = Material::metallic_roughness("metal", Vec3::splat(0.8), 1.0, 0.3);
    let pixels = (w * h) as usize;
    let opts = RenderOptions::default();
    for (what, scene, specular) in [
        ("matte", &s, false),
        ("one specular material", &shiny, true),
        ("matte again", &s, false),
        ("one metallic-roughness material", &metal, true),
    ] {
        assert_eq!(
            scene.materials.iter().any(reads_specular),
            specular,
            "{what}"
        );
        let (reference, _) = gpu.render_with("forward", scene, (w, h), &opts);
        let (img, stats) = gpu.render_with("deferred", scene, (w, h), &opts);
        let d = manylight::metrics::diff(&reference, &img);
        assert!(
            d.max_abs <= 2,
            "{what}: deferred is {} / 255 from forward",
            d.max_abs
        );
        let accumulation = if gbuffer::half_float_accumulation(gpu.r().caps()) {
            8
        } else {
            16
        };
        // Albedo 8, normal and depth 16, depth buffer 4, specular 8 where it is made.
        let per_pixel = 28 + accumulation + if specular { 8 } else { 0 };
        assert_eq!(stats.memory.gbuffer_bytes, pixels * per_pixel, "{what}");
    }
}

/// Lights are drawn as instances of their proxy, 65 536 a batch. A scene of 69 000: 64 000
/// small ones in front of the camera but far beside the view first, then 5 000 in view, so
/// the view's lights of the near side's proxy straddle its first batch's end. It matches
/// forward over the 5 000 (the others reach no pixel), each light is uploaded once a frame, as
/// its four `vec4`s, and a still frame uploads them again, since they pass what a stream
/// holds.
#[test]
fn lights_past_one_instance_batch_match_forward_and_upload_once_a_frame() {
    let mut gpu = Gpu::new(EsVersion::Es3);
    let mut s = scene::builtin::build("courtyard", Some((5_000, 3))).unwrap();
    let ahead = (s.camera.target - s.camera.position).normalize();
    let beside = s.camera.position + ahead * 10.0 + ahead.cross(DVec3::Y).normalize() * 100.0;
    let hidden = (0..64_000).map(|i| {
        let at = beside + DVec3::new(0.0, (i % 250) as f64 * 0.05, (i / 250) as f64 * 0.05);
        scene::Light::point(at, 0.2, Vec3::ONE, 1.0)
    });
    let opts = RenderOptions::default();
    let (reference, _) = gpu.render_with("forward", &s, (32, 18), &opts);
    s.lights.splice(0..0, hidden);
    let drawn = s.lights.iter().filter(|l| l.radius > 0.0).count();
    for frame in ["moving", "still"] {
        let (img, stats) = gpu.render_with("deferred", &s, (32, 18), &opts);
        let d = manylight::metrics::diff(&reference, &img);
        assert!(
            d.max_abs <= 2,
            "69 000 lights, {frame}: deferred is {} / 255 from forward",
            d.max_abs
        );
        assert!(!stats.lists_reused, "{frame}");
        assert_eq!(stats.memory.upload_bytes, drawn * 4 * 16, "{frame}");
    }
}

/// Draw calls grow by batches of 65 536 lights, not by lights (a draw call a light before
/// instancing): from 64 to 5 000 lights the same, but for one more where a light of the 5 000
/// takes a kind of proxy none of the 64 takes (on SwiftShader, a sphere reaching behind the
/// eye). Forward's are its objects', whatever the lights.
#[test]
fn lights_add_no_draw_calls() {
    let mut gpu = Gpu::new(EsVersion::Es3);
    let opts = RenderOptions::default();
    let mut calls = |method: &str, lights: usize| {
        let s = scene::builtin::build("courtyard", Some((lights, 3))).unwrap();
        gpu.render_with(method, &s, (32, 18), &opts).1.draw_calls
    };
    let (few, many) = (calls("deferred", 64), calls("deferred", 5_000));
    assert!(few > 2, "{few}");
    assert!(
        (few..=few + 1).contains(&many),
        "{many} draw calls at 5 000 lights, {few} at 64"
    );
    let (few, many) = (calls("forward", 64), calls("forward", 5_000));
    assert!(few > 0);
    assert_eq!(many, few);
}

/// Deferred's instance buffers hold what they have drawn: a few lights keep a few kilobytes,
/// where a fixed buffer of a full batch was held whatever the scene; 5 000 lights grow them to
/// hold every light, so a still frame of them uploads nothing.
#[test]
fn the_light_instance_buffers_grow_with_the_lights_and_hold_them() {
    const LIGHT_BYTES: usize = 4 * 16;
    let mut gpu = Gpu::new(EsVersion::Es3);
    let opts = RenderOptions::default();
    let mut beyond_the_gbuffer = |lights: usize| {
        let s = scene::builtin::build("courtyard", Some((lights, 3))).unwrap();
        let (first, moving) = gpu.render_with("deferred", &s, (32, 18), &opts);
        let (again, still) = gpu.render_with("deferred", &s, (32, 18), &opts);
        assert!(moving.memory.upload_bytes > 0 && !moving.lists_reused);
        assert_eq!(still.memory.upload_bytes, 0, "{lights} lights");
        assert!(still.lists_reused && again == first, "{lights} lights");
        still.memory.method_gpu_bytes - still.memory.gbuffer_bytes
    };
    let few = beyond_the_gbuffer(8);
    assert!(
        few < 64 * 1024,
        "8 lights held {few} bytes past the G-buffer"
    );
    let many = beyond_the_gbuffer(5_000);
    assert!(
        (5_000 * LIGHT_BYTES..=2 * 5_000 * LIGHT_BYTES + few).contains(&many),
        "5 000 lights held {many} bytes past the G-buffer"
    );
}

#[test]
fn transparent_objects_take_the_forward_fallback() {
    let s = scene::builtin::build("bubbles", Some((128, 2))).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let opts = RenderOptions::default();
    let (reference, _) = gpu.render_with("forward", &s, (192, 108), &opts);
    let (img, _) = gpu.render_with("deferred", &s, (192, 108), &opts);
    let d = manylight::metrics::diff(&reference, &img);
    assert!(
        d.max_abs <= 2,
        "bubbles: deferred + forward fallback is {} / 255 from forward",
        d.max_abs
    );
}

/// A translucent copy of an opaque surface on its very vertices (a game's highlight or ghost
/// over a mesh) is hidden by it in forward (`LESS` on equal depths). Deferred drew it: the
/// depth its composite copied from the G-buffer came back one step farther on Mesa's and
/// ANGLE's drivers, so the copy passed over the whole floor (100/255 on llvmpipe), and so
/// over a floor cut out by its alpha (`MASK`), which the depth program cannot draw.
#[test]
fn a_translucent_copy_on_an_opaque_surface_is_hidden_as_in_forward() {
    for cut_out in [None, Some(0.5)] {
        translucent_copy_hidden(cut_out);
    }
}

fn translucent_copy_hidden(cut_out: Option<f32>) {
    let mut s = scene::builtin::build("plane", None).unwrap();
    let floor = s.objects[0].material;
    s.materials[floor].alpha_cutoff = cut_out;
    s.camera =
        manylight::Camera::perspective(DVec3::new(0.0, 3.0, 4.0), DVec3::ZERO, 60.0, 0.1, 100.0);
    s.lights = vec![scene::Light::point(
        DVec3::new(0.0, 1.0, 0.0),
        5.0,
        Vec3::ONE,
        2.0,
    )];
    let mut ghost = s.materials[s.objects[0].material].clone();
    ghost.diffuse = Vec3::new(1.0, 0.0, 1.0);
    ghost.alpha = 0.5;
    s.materials.push(ghost);
    let mut copy = s.objects[0].clone();
    copy.material = s.materials.len() - 1;
    s.objects.push(copy);
    let mut gpu = Gpu::new(EsVersion::Es3);
    let opts = RenderOptions::default();
    let (forward, _) = gpu.render_with("forward", &s, (128, 72), &opts);
    let (deferred, _) = gpu.render_with("deferred", &s, (128, 72), &opts);
    let d = manylight::metrics::diff(&forward, &deferred);
    assert!(
        d.max_abs <= 2,
        "cut out {cut_out:?}: deferred {}/255 from forward on {:.2} % of the pixels",
        d.max_abs,
        100.0 * d.over_2
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

/// Set in the child process that runs the test below without `GL_EXT_float_blend` on Mesa.
const NO_FLOAT_BLEND: &str = "MANYLIGHT_TEST_NO_FLOAT_BLEND";

/// A frame brighter than half floats hold, at an exposure that shows it: a 2·10⁵ light over
/// the plane at −15 EV with Reinhard. Without `GL_EXT_float_blend` (ANGLE; Mesa in the child
/// below) the light accumulation is half-float, where the sum passed 65 504 to Inf and the
/// plane came out white (forward: 238/255 under the light). Now within 2/255 of forward. And
/// its light counts, which stopped at 2 048 there, are exact up to 8 192 lights and refused
/// past that.
#[test]
fn deferred_holds_bright_frames_and_refuses_counts_past_what_its_accumulation_holds() {
    let mut s = scene::builtin::build("plane", None).unwrap();
    s.lights = vec![manylight::scene::Light::point(
        glam::DVec3::new(0.0, 0.0, 1.0),
        10.0,
        glam::Vec3::ONE,
        2e5,
    )];
    let opts = RenderOptions {
        exposure_ev: -15.0,
        tone_map: manylight::ToneMap::Reinhard,
        ..Default::default()
    };
    let mut gpu = Gpu::new(EsVersion::Es3);
    if std::env::var_os(NO_FLOAT_BLEND).is_some() {
        assert!(!gpu.r().caps().has_extension("GL_EXT_float_blend"));
    }
    // Emission too, which the geometry pass writes into the same accumulation.
    for emission in [0.0, 500.0] {
        for m in &mut s.materials {
            m.maps.emissive = glam::Vec3::splat(emission);
        }
        let (reference, _) = gpu.render_with("forward", &s, (128, 72), &opts);
        assert!(common::mean(&reference) > 60.0, "the light shows");
        let (img, _) = gpu.render_with("deferred", &s, (128, 72), &opts);
        let d = manylight::metrics::diff(&reference, &img);
        assert!(
            d.max_abs <= 2,
            "emission {emission}: deferred is {} / 255 from forward",
            d.max_abs
        );
    }
    // HDR output takes no exposure: radiance is accumulated as it is, so a dim one is not
    // pushed into fp16's subnormals (at −15 EV, 0.01 would have kept about 3 bits).
    let mut dim = s.clone();
    dim.lights[0].intensity = 0.05;
    for m in &mut dim.materials {
        m.maps.emissive = glam::Vec3::ZERO;
    }
    let (lit, worst) = deferred_hdr_from_forward(&mut gpu, &dim, &opts, 1e-3);
    assert!(lit > 100, "the dim light shows");
    assert!(worst < 2e-3, "HDR radiance off by {worst} (relative)");
    // Counts: each channel of a half-float accumulation holds every count up to 2 048 (2 048 + 1
    // rounds back to 2 048), and a frame spreads its lights over the four; past 8 192 lights
    // the count is refused rather than stopped short.
    let half = manylight::gl::gbuffer::half_float_accumulation(gpu.r().caps());
    for n in [8_192, 8_193] {
        let light = manylight::scene::Light::point(glam::DVec3::ZERO, 1e4, glam::Vec3::ONE, 1.0);
        s.lights = vec![light; n];
        let counts =
            gpu.r()
                .render_light_counts(&s, 32, 18, &RenderOptions::default(), CountKind::Evals);
        match counts {
            Err(manylight::Error::Limit(e)) if half && n > 8_192 => {
                assert!(e.contains("8192"), "{e}")
            }
            Ok((counts, _)) if !half || n <= 8_192 => assert!(
                counts
                    .counts
                    .iter()
                    .zip(&counts.covered)
                    .all(|(&c, &covered)| !covered || c as usize == n),
                "{n} lights: counts {:?}",
                counts.max()
            ),
            other => panic!("{n} lights, half-float {half}: {:?}", other.map(|_| ())),
        }
    }
}

/// An occlusion map under a bright ambient: the geometry pass starts the accumulation at the
/// surface's whole ambient term, as forward adds it. Written as its difference from ambient ×
/// albedo, which the composite added back from the G-buffer's 11-bit albedo, the occluded term
/// did not cancel (6/255 from forward on llvmpipe, 13/255 on ANGLE), and in a half-float
/// accumulation each light was rounded at the difference's size (45/255 on ANGLE at an
/// ambient of 100).
#[test]
fn deferred_matches_forward_on_occluded_surfaces_under_a_bright_ambient() {
    let mut gpu = Gpu::new(EsVersion::Es3);
    for (ambient, exposure_ev) in [(8.0, 0.0), (1.0, 3.0), (100.0, 0.0)] {
        let s = common::occluded_quad(0.8, &[0, 40, 128, 255], ambient);
        let opts = RenderOptions {
            exposure_ev,
            ..Default::default()
        };
        let (forward, _) = gpu.render_with("forward", &s, (96, 54), &opts);
        let (deferred, _) = gpu.render_with("deferred", &s, (96, 54), &opts);
        let d = manylight::metrics::diff(&forward, &deferred);
        eprintln!(
            "ambient {ambient} at {exposure_ev} EV: deferred {} / 255 from forward",
            d.max_abs
        );
        assert!(
            d.max_abs <= 2,
            "ambient {ambient} at {exposure_ev} EV: deferred is {} / 255 from forward",
            d.max_abs
        );
    }
}

/// Deferred's HDR radiance against forward's at 64×36 (red): the pixels forward lights above
/// `floor`, and the largest relative difference among them.
fn deferred_hdr_from_forward(
    gpu: &mut Gpu,
    s: &scene::Scene,
    opts: &RenderOptions,
    floor: f32,
) -> (usize, f32) {
    let mut hdr = |method: &str| {
        gpu.r().set_method_named(method).unwrap();
        gpu.r().render_offscreen_hdr(s, 64, 36, opts).unwrap().0
    };
    let (forward, deferred) = (hdr("forward"), hdr("deferred"));
    let lit: Vec<(f32, f32)> = (forward.iter().zip(&deferred))
        .map(|(f, d)| (f[0], d[0]))
        .filter(|&(f, _)| f > floor)
        .collect();
    let worst = (lit.iter())
        .map(|&(f, d)| ((d - f) / f).abs())
        .fold(0.0f32, f32::max);
    (lit.len(), worst)
}

/// `n` equal lights on a ring over the plane, each reaching all of it, `total` their summed
/// intensity.
fn ring_of_lights(n: usize, total: f32) -> scene::Scene {
    let mut s = scene::builtin::build("plane", None).unwrap();
    s.lights = (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            let at = glam::DVec3::new(0.5 * a.cos(), 0.5 * a.sin(), 1.0);
            manylight::scene::Light::point(at, 1e3, glam::Vec3::ONE, total / n as f32)
        })
        .collect();
    s
}

/// Many lights on every pixel (helper-152): where the context blends 32-bit floats, deferred
/// sums 1 000 equal lights as forward does (within 2/255). Where it cannot (ANGLE; Mesa in
/// the child below), each proxy's blend rounds the pixel's sum to fp16, and at 1 000 lights
/// deferred was 23/255 from forward with nothing said: it now names that in its support (a
/// fallback, as `Renderer::set_method` warns; `auto`, which may run it, too), and its HDR
/// radiance keeps within what the rounding allows, half a step of the sum for each of `n`
/// additions: `n · 2⁻¹¹` of it.
#[test]
fn many_lights_on_a_pixel_sum_as_forward_or_deferred_says_why_not() {
    use manylight::methods::deferred::HALF_FLOAT_SUMS;
    use manylight::methods::Support;
    use manylight::Method;
    let mut gpu = Gpu::new(EsVersion::Es3);
    let half = manylight::gl::gbuffer::half_float_accumulation(gpu.r().caps());
    let support = gpu.r().support(Method::Deferred);
    if !half {
        assert_eq!(support, Support::Supported);
        let auto = gpu.r().support(Method::Auto);
        assert!(
            !matches!(&auto, Support::Fallback(why) if why.contains(HALF_FLOAT_SUMS)),
            "{auto:?}"
        );
        let s = ring_of_lights(1_000, 2.0);
        let opts = RenderOptions::default();
        let (forward, _) = gpu.render_with("forward", &s, (64, 36), &opts);
        assert!(common::mean(&forward) > 60.0, "the lights show");
        let (deferred, _) = gpu.render_with("deferred", &s, (64, 36), &opts);
        let d = manylight::metrics::diff(&forward, &deferred);
        assert!(
            d.max_abs <= 2,
            "deferred is {} / 255 from forward",
            d.max_abs
        );
        return;
    }
    assert_eq!(support, Support::Fallback(HALF_FLOAT_SUMS.into()));
    // `auto` runs deferred past clustered's index limit: it says so too.
    let auto = gpu.r().support(Method::Auto);
    assert!(
        matches!(&auto, Support::Fallback(why) if why.contains(HALF_FLOAT_SUMS)),
        "{auto:?}"
    );
    let fallback = gpu.r().set_method(Method::Deferred).unwrap();
    assert_eq!(fallback.as_deref(), Some(HALF_FLOAT_SUMS));
    let n = 64;
    let s = ring_of_lights(n, 2.0);
    let opts = RenderOptions::default();
    let (lit, worst) = deferred_hdr_from_forward(&mut gpu, &s, &opts, 1e-2);
    assert!(lit > 1_000, "the lights show");
    let bound = n as f32 * 2f32.powi(-11);
    eprintln!("{n} lights in half floats: HDR radiance off by {worst} at most (bound {bound})");
    assert!(
        worst <= bound,
        "{n} lights: HDR radiance off by {worst} (bound {bound})"
    );
}

/// Faint lights at a high exposure: eight in a ring over the plane, each adding about 2·10⁻⁸ of
/// radiance to a pixel, shown at +15 EV (forward: 17/255 at most). A half-float accumulation
/// (ANGLE; Mesa in the child below) held raw radiance at a positive exposure, where each
/// light's share rounded to zero: the frame was black.
#[test]
fn deferred_keeps_faint_lights_at_a_high_exposure() {
    let mut s = scene::builtin::build("plane", None).unwrap();
    s.ambient = glam::Vec3::ZERO;
    s.lights = (0..8)
        .map(|i| {
            let a = f64::from(i) * std::f64::consts::FRAC_PI_4;
            let at = glam::DVec3::new(a.cos(), a.sin(), 2.0);
            manylight::scene::Light::point(at, 100.0, glam::Vec3::ONE, 1.5e-7)
        })
        .collect();
    let opts = RenderOptions {
        exposure_ev: 15.0,
        ..Default::default()
    };
    let mut gpu = Gpu::new(EsVersion::Es3);
    if std::env::var_os(NO_FLOAT_BLEND).is_some() {
        assert!(!gpu.r().caps().has_extension("GL_EXT_float_blend"));
    }
    let (reference, _) = gpu.render_with("forward", &s, (64, 36), &opts);
    let brightest = reference.pixels().map(|p| p[0]).max().unwrap_or(0);
    assert!(brightest > 10, "the lights show: {brightest} / 255 at most");
    let (img, _) = gpu.render_with("deferred", &s, (64, 36), &opts);
    let d = manylight::metrics::diff(&reference, &img);
    assert!(
        d.max_abs <= 2,
        "deferred is {} / 255 from forward",
        d.max_abs
    );
}

/// The tests above on Mesa without `GL_EXT_float_blend` (a half-float accumulation, as on
/// ANGLE), in a child process (Mesa reads its extension override once per process).
#[test]
fn deferred_equals_forward_on_a_bright_frame_without_float_blending() {
    if std::env::var_os(NO_FLOAT_BLEND).is_some()
        || common::other_implementation_than_mesa("MESA_EXTENSION_OVERRIDE")
    {
        return;
    }
    for test in [
        "deferred_holds_bright_frames_and_refuses_counts_past_what_its_accumulation_holds",
        "deferred_matches_forward_on_occluded_surfaces_under_a_bright_ambient",
        "many_lights_on_a_pixel_sum_as_forward_or_deferred_says_why_not",
        "deferred_keeps_faint_lights_at_a_high_exposure",
    ] {
        common::child::rerun_with(
            test,
            &[
                ("MESA_EXTENSION_OVERRIDE", "-GL_EXT_float_blend"),
                (NO_FLOAT_BLEND, "1"),
            ],
            "without float blending",
        );
    }
}

/// Head lamps: a light at (or a hair from) the eye, over a floor, at near planes that put
/// ten to 10⁹ near-plane distances across its proxy. Guards the two ways deferred lost such
/// light: depth interpolated across a far side the near plane clips into huge faces (drawn
/// full-screen past 2 048; docs/precision.md), and SwiftShader dropping far-side triangles
/// that cross the eye's plane (bounded by a plane there; docs/drivers.md, item 16).
/// A light smaller than a pixel where it lies: its proxy drawn at its size covered no pixel
/// centre on SwiftShader, which snaps vertices to 1/16 pixel, and the pixel it lit stayed
/// ambient (a light of 1/12 pixel: 221/255 from forward). Proxies are at least a pixel wide.
#[test]
fn lights_smaller_than_a_pixel_match_forward() {
    let mut gpu = Gpu::new(EsVersion::Es3);
    let mut scene = scene::builtin::build("plane", None).unwrap();
    scene.camera =
        manylight::Camera::perspective(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, 60.0, 0.1, 100.0);
    let mut rng = Pcg64Mcg::seed_from_u64(11);
    scene.lights = (0..150)
        .map(|i| {
            // The first on a pixel's centre, the rest anywhere over the plane.
            let (x, y) = if i == 0 {
                (0.08019, -0.08019)
            } else {
                (rng.random_range(-3.0..3.0), rng.random_range(-1.6..1.6))
            };
            scene::Light::point(DVec3::new(x, y, 0.0002), 0.002, Vec3::ONE, 1.0)
        })
        .collect();
    let opts = RenderOptions::default();
    gpu.r().set_method_named("forward").unwrap();
    let forward = gpu.render(&scene, 64, 36, &opts);
    gpu.r().set_method_named("deferred").unwrap();
    let deferred = gpu.render(&scene, 64, 36, &opts);
    let lit = forward.pixels().filter(|p| p[0] > 100).count();
    assert!(lit > 0, "no light shows");
    let d = manylight::metrics::diff(&forward, &deferred);
    assert!(
        d.max_abs <= 2,
        "deferred {}/255 from forward on {:.2} % of the pixels",
        d.max_abs,
        100.0 * d.over_2
    );
}

#[test]
fn head_lamps_match_forward_at_any_near_plane() {
    let mut gpu = Gpu::new(EsVersion::Es3);
    let mut random = Seeded(Pcg64Mcg::seed_from_u64(7));
    for case in 0..300 {
        let height = 10f64.powf(random.uniform(-3.0, 1.0));
        let radius = height * 10f64.powf(random.uniform(0.02, 0.6));
        let near = (1.1 * radius / 10f64.powf(random.uniform(1.0, 9.0))).min(height / 3.0);
        let eye = DVec3::new(random.uniform(-1.0, 1.0), random.uniform(-1.0, 1.0), height);
        let (down, around) = (
            random.uniform(10.0, 80.0).to_radians(),
            random.uniform(0.0, std::f64::consts::TAU),
        );
        let look = DVec3::new(
            around.cos() * down.cos(),
            around.sin() * down.cos(),
            -down.sin(),
        );
        let hair = DVec3::new(random.normal(), random.normal(), random.normal())
            * height
            * 10f64.powf(random.uniform(-12.0, -1.0));
        let mut s = scene::builtin::build("plane", None).unwrap();
        // The floor reaches well past the eye, as a level's would.
        s.objects[0].transform = glam::DMat4::from_scale(DVec3::splat((height * 10.0).max(1.0)));
        let fov = [40.0, 60.0, 90.0][case % 3];
        s.camera = scene::Camera::perspective(eye, eye + look, fov, near, height * 100.0);
        s.lights = vec![scene::Light::point(
            eye + hair,
            radius as f32,
            Vec3::ONE,
            (1e3 * height * height) as f32,
        )];
        let (reference, _) = gpu.render_with("forward", &s, (64, 36), &Default::default());
        let (img, _) = gpu.render_with("deferred", &s, (64, 36), &Default::default());
        let d = manylight::metrics::diff(&reference, &img);
        assert!(
            d.max_abs <= 2,
            "deferred {} / 255 from forward, case {case}: {:.3e} near distances across",
            d.max_abs,
            1.1 * radius / near
        );
    }
}

/// A seeded generator for the random cases above: `rand_pcg` with a normal distribution.
struct Seeded(Pcg64Mcg);

impl Seeded {
    fn next(&mut self) -> f64 {
        self.0.random::<f64>()
    }

    fn uniform(&mut self, low: f64, high: f64) -> f64 {
        low + (high - low) * self.next()
    }

    /// A standard normal value (Box–Muller).
    fn normal(&mut self) -> f64 {
        let u = self.next().max(1e-300);
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * self.next()).cos()
    }
}

/// The G-buffer's specular target (8 bytes a pixel) and the metallic-roughness BRDF of the
/// light pass and a sunlit composite follow the materials the G-buffer holds: those of opaque
/// objects. A material no object draws with (an OBJ loader's unused default, a game's
/// palette) or only transparent objects do (the forward fallback's) cost nothing, and the
/// picture stays forward's; an opaque glossy object still gets the target, kept for 120
/// frames after the last such object went (a pickup that comes and goes does not remake it).
#[test]
fn only_materials_in_the_gbuffer_give_it_a_specular_target_or_the_light_pass_its_brdf() {
    use manylight::scene::meshbuild::MeshBuilder;
    let (w, h) = (128, 72);
    let mut base = scene::builtin::build("plane", Some((20, 4))).unwrap();
    for m in &mut base.materials {
        m.specular = Vec3::ZERO;
    }
    base.directional_lights.push(DirectionalLight::new(
        DVec3::new(1.0, -2.0, -1.0),
        Vec3::ONE,
        0.3,
    ));
    let cube = |s: &mut scene::Scene, material: Material| {
        let mut b = MeshBuilder::new();
        b.cuboid(Vec3::splat(-0.3), Vec3::splat(0.3));
        let m = s.add_material(material);
        let at = glam::DMat4::from_translation(DVec3::new(0.0, 0.0, 0.5));
        s.add_object(b.build().unwrap(), m, at);
    };
    let glossy = Material::glossy("glossy", Vec3::ONE, Vec3::splat(0.5), 64.0);
    let metal = Material::metallic_roughness("metal", Vec3::ONE, 1.0, 0.5);
    let see_through = |mut m: Material| {
        m.alpha = 0.5;
        m
    };
    let mut unused = base.clone();
    unused.add_material(glossy.clone());
    unused.add_material(metal.clone());
    let mut transparent = base.clone();
    cube(&mut transparent, see_through(glossy.clone()));
    cube(&mut transparent, see_through(metal.clone()));
    let mut gpu = Gpu::fresh(EsVersion::Es3);
    let matte_bytes = (w * h) as usize * gbuffer::bytes_per_pixel(gpu.r().caps(), false);
    for (what, s) in [("unused", &unused), ("transparent", &transparent)] {
        let (reference, _) = gpu.render_with("forward", s, (w, h), &RenderOptions::default());
        let (img, stats) = gpu.render_with("deferred", s, (w, h), &RenderOptions::default());
        assert_eq!(stats.memory.gbuffer_bytes, matte_bytes, "{what} materials");
        let d = manylight::metrics::diff(&reference, &img);
        assert!(
            d.max_abs <= 2,
            "{what}: deferred is {} / 255 from forward",
            d.max_abs
        );
    }
    // The deferred passes' shaders compiled with the BRDF, by name (the light pass's full-
    // screen one too where a proxy is drawn so, as SwiftShader's bounded ones are).
    let mr_light_passes = |gpu: &mut Gpu| {
        let mut names: Vec<&str> = (gpu.r().program_report().iter())
            .filter(|p| p.shader.starts_with("deferred_"))
            .filter(|p| ShaderFeatures(p.features).has(ShaderFeatures::METALLIC_ROUGHNESS))
            .map(|p| p.shader)
            .collect();
        names.sort();
        names.dedup();
        names
    };
    assert!(
        mr_light_passes(&mut gpu).is_empty(),
        "the BRDF compiled in for nothing"
    );
    let mut opaque = base.clone();
    cube(&mut opaque, glossy);
    cube(&mut opaque, metal);
    let (reference, _) = gpu.render_with("forward", &opaque, (w, h), &RenderOptions::default());
    let (img, stats) = gpu.render_with("deferred", &opaque, (w, h), &RenderOptions::default());
    let specular_bytes = (w * h) as usize * gbuffer::bytes_per_pixel(gpu.r().caps(), true);
    assert_eq!(
        stats.memory.gbuffer_bytes, specular_bytes,
        "an opaque glossy object"
    );
    assert!(manylight::metrics::diff(&reference, &img).max_abs <= 2);
    let names = mr_light_passes(&mut gpu);
    let light_pass = names.iter().any(|n| n.starts_with("deferred_light"));
    assert!(
        names.contains(&"deferred_composite") && light_pass,
        "the light pass and the sunlit composite: {names:?}"
    );
    // Objects that come and go keep the target, with forward's picture, until 120 frames
    // pass without them: the G-buffer is not remade every time.
    let options = RenderOptions::default();
    let unused_reference = gpu.render_with("forward", &unused, (w, h), &options).0;
    let opaque_reference = reference;
    gpu.r().set_method_named("deferred").unwrap();
    let deferred = |gpu: &mut Gpu, s: &scene::Scene, (w, h): (u32, u32)| {
        gpu.r().render_offscreen(s, w, h, &options).unwrap()
    };
    deferred(&mut gpu, &opaque, (w, h));
    let scenes = [&unused, &opaque, &unused, &opaque, &unused];
    for (k, s) in scenes.into_iter().enumerate() {
        let (img, stats) = deferred(&mut gpu, s, (w, h));
        assert_eq!(
            stats.memory.gbuffer_bytes, specular_bytes,
            "frame {k}: kept"
        );
        let reference = [&unused_reference, &opaque_reference][k % 2];
        assert!(
            manylight::metrics::diff(reference, &img).max_abs <= 2,
            "frame {k}"
        );
    }
    let mut bytes = 0;
    for _ in 0..120 {
        bytes = deferred(&mut gpu, &unused, (8, 8)).1.memory.gbuffer_bytes;
    }
    let matte_8x8 = 64 * gbuffer::bytes_per_pixel(gpu.r().caps(), false);
    assert_eq!(bytes, matte_8x8, "dropped after 120 frames without");
}

/// Without spots in the scene a light's instance leaves out the spot terms: 48 bytes, not 64.
/// One renderer across frames of point lights, then with a spot, then without again, draws
/// what forward draws each time, its instance streams made anew for each layout.
#[test]
fn point_lights_take_three_vec4s_an_instance_and_a_spot_four() {
    let points = scene::builtin::build("plane", Some((24, 5))).unwrap();
    assert!(points
        .lights
        .iter()
        .all(|l| matches!(l.kind, scene::LightKind::Point)));
    let mut with_spot = points.clone();
    let cone = scene::Cone {
        direction: DVec3::NEG_Z,
        inner_deg: 15.0,
        outer_deg: 35.0,
    };
    with_spot.lights[0] = scene::Light::spot(DVec3::new(0.0, 0.0, 1.0), 3.0, Vec3::ONE, 2.0, cone);
    let opts = RenderOptions::default();
    let mut reference = Gpu::new(EsVersion::Es3);
    let mut gpu = Gpu::new(EsVersion::Es3);
    gpu.r().set_method_named("deferred").unwrap();
    for (s, instance) in [(&points, 48), (&with_spot, 64), (&points, 48)] {
        let (expected, _) = reference.render_with("forward", s, (64, 36), &opts);
        let (img, stats) = gpu.r().render_offscreen(s, 64, 36, &opts).unwrap();
        assert!(stats.lights.visible > 0);
        let what = format!("{instance}-byte instances");
        assert_eq!(
            stats.memory.upload_bytes,
            stats.lights.visible * instance,
            "{what}"
        );
        let d = manylight::metrics::diff(&expected, &img);
        assert!(d.max_abs <= 2, "{what}: {d:?}");
    }
}
