//! Multisampling (`RenderOptions::samples`): every method that supports it still equals plain
//! forward with the same samples; along a polygon edge the resolved pixels take exactly the
//! coverage fractions of 4 samples, where without MSAA they are all-or-nothing; unsupported
//! cases are clear errors.

use crate::common;

use common::{msaa, Gpu};
use manylight::scene;
use manylight::{EsVersion, RenderOptions};

#[test]
fn every_method_with_msaa_matches_forward_with_msaa() {
    let mut gpu = Gpu::new(EsVersion::Es3);
    // 4 bytes of colour and 4 of depth per sample.
    let reference = common::assert_methods_match_forward_with_4_samples(&mut gpu, 4 * 8);
    let scene = scene::builtin::build("courtyard", Some((64, 2))).unwrap();
    gpu.r().set_method_named("forward").unwrap();
    let single = gpu.render(&scene, 128, 72, &msaa(1));
    assert_ne!(reference, single, "4 samples changed nothing");
}

#[test]
fn edges_get_the_coverage_fractions_of_their_samples() {
    let scene = common::turned_square();
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
    common::assert_coverage_of_4_samples(&smooth);
}

#[test]
fn unsupported_msaa_is_a_clear_error() {
    let scene = scene::builtin::build("plane", Some((4, 1))).unwrap();
    let mut es3 = Gpu::new(EsVersion::Es3);
    es3.r().set_method_named("deferred").unwrap();
    let err = es3
        .r()
        .render_offscreen(&scene, 16, 16, &msaa(4))
        .unwrap_err();
    assert!(err.to_string().contains("deferred"), "{err}");
    es3.r().set_method_named("clustered").unwrap();
    let err = es3
        .r()
        .render_offscreen(&scene, 16, 16, &msaa(64))
        .unwrap_err();
    assert!(err.to_string().contains("GL_MAX_SAMPLES"), "{err}");
    // Its own variant, so a caller (the CLI names --msaa) can tell it from other limits.
    assert!(
        matches!(err, manylight::Error::Msaa { samples: 64, .. }),
        "{err:?}"
    );
    let err = es3
        .r()
        .render_offscreen_hdr(&scene, 16, 16, &msaa(4))
        .unwrap_err();
    assert!(err.to_string().contains("HDR"), "{err}");
    // HDR is the reason with any method: deferred said it did not support MSAA.
    es3.r().set_method_named("deferred").unwrap();
    let err = es3
        .r()
        .render_offscreen_hdr(&scene, 16, 16, &msaa(4))
        .unwrap_err();
    assert!(err.to_string().contains("not HDR"), "{err}");
    drop(es3);
    // This binary's contexts have no MESA_EXTENSION_OVERRIDE: llvmpipe's ES 2.0 lacks
    // GL_EXT_multisampled_render_to_texture (tests/msaa_es2.rs adds it). An implementation
    // whose ES 2.0 has it (NVIDIA's) must render instead.
    let mut es2 = Gpu::new(EsVersion::Es2);
    if es2.r().caps().max_samples >= 4 {
        let (img, stats) = es2.r().render_offscreen(&scene, 16, 16, &msaa(4)).unwrap();
        assert_eq!((img.width(), stats.samples), (16, 4));
        return;
    }
    let err = es2
        .r()
        .render_offscreen(&scene, 16, 16, &msaa(4))
        .unwrap_err();
    assert!(
        err.to_string()
            .contains("GL_EXT_multisampled_render_to_texture"),
        "{err}"
    );
    let err = es2
        .r()
        .render_offscreen_hdr(&scene, 16, 16, &msaa(4))
        .unwrap_err();
    assert!(err.to_string().contains("not HDR"), "{err}");
}

/// GL rounds a sample count it lacks up to one it has: the stats name the count the frame was
/// drawn with, which is what GL itself says a renderbuffer of that many samples gets.
#[test]
fn stats_name_the_samples_gl_gave() {
    use manylight::glow::{self, HasContext};
    let es = EsVersion::Es3;
    let ctx = manylight::HeadlessContext::new(es).expect("headless ES 3.0 context");
    let gl = ctx.load_gl().unwrap();
    let mut renderer = manylight::Renderer::new(ctx.load_gl().unwrap(), es).expect("renderer");
    let scene = scene::builtin::build("courtyard", Some((4, 1))).unwrap();
    let max = renderer.caps().max_samples.max(0) as u32;
    // ES 3.0 requires GL_MAX_SAMPLES of at least 4: the loop below is never empty.
    assert!(max >= 4, "GL_MAX_SAMPLES {max} on an ES 3.0 context");
    for asked in 2..=max {
        // SAFETY: a renderbuffer of the test's own, on the current context, deleted at once.
        let given = unsafe {
            let rb = gl.create_renderbuffer().expect("renderbuffer");
            gl.bind_renderbuffer(glow::RENDERBUFFER, Some(rb));
            gl.renderbuffer_storage_multisample(
                glow::RENDERBUFFER,
                asked as i32,
                glow::RGBA8,
                4,
                4,
            );
            let n =
                gl.get_renderbuffer_parameter_i32(glow::RENDERBUFFER, glow::RENDERBUFFER_SAMPLES);
            gl.delete_renderbuffer(rb);
            n as u32
        };
        let (_, stats) = renderer
            .render_offscreen(&scene, 16, 9, &msaa(asked))
            .unwrap_or_else(|e| panic!("{asked} samples: {e}"));
        assert_eq!(stats.samples, given, "{asked} samples asked");
    }
    renderer.destroy();
}

/// A floor seen nearly edge-on with MSAA: a pixel its edge crosses is shaded once, and without
/// `centroid` at the pixel's centre, off the triangle, where the interpolated position lies
/// far beyond the scene's depths, past the grid's cells. Forward shaded that point with every
/// light and tiled and clustered with the clamped cell's: 4/255 apart on pixels along the
/// floor's far edge. Shaded inside the triangle (ES 3.0's `centroid`), they agree.
#[test]
fn a_floor_seen_edge_on_is_shaded_inside_its_triangles() {
    use glam::{DVec3, Vec3};
    let mut scene = common::floor_12m();
    scene.lights = (0..60)
        .map(|i| {
            let f = i as f64;
            let at = DVec3::new(
                (f * 0.7).sin() * 5.0,
                0.4 + (f * 0.3).cos().abs(),
                (f * 0.13).cos() * 5.0,
            );
            let colour = Vec3::new(
                0.5 + 0.5 * (f * 1.1).sin() as f32,
                0.5 + 0.5 * (f * 1.7).cos() as f32,
                0.5 + 0.5 * (f * 2.3).sin() as f32,
            );
            manylight::Light::point(at, 2.5, colour, 1.2)
        })
        .collect();
    scene.camera = manylight::Camera {
        position: DVec3::new(0.0, 0.05, 3.0),
        target: DVec3::ZERO,
        up: DVec3::Y,
        projection: manylight::Projection::Orthographic {
            height: 5.0,
            near: 1.0,
            far: 15.0,
        },
    };
    let options = RenderOptions {
        linear: true,
        tone_map: manylight::ToneMap::Aces,
        exposure_ev: 1.0,
        tile_px: 8.0,
        grid: manylight::GridConfig::fixed(8.0),
        ..msaa(4)
    };
    let mut gpu = Gpu::new(EsVersion::Es3);
    // SwiftShader interpolates a centroid varying at the pixel's centre all the same (its
    // forward frame is the same with and without): its gap stays (docs/drivers.md).
    let most = match gpu.r().caps().implementation().as_str() {
        "SwiftShader" => 8,
        _ => 2,
    };
    gpu.r().set_method_named("forward").unwrap();
    let reference = gpu.render(&scene, 96, 64, &options);
    for method in ["tiled", "clustered"] {
        gpu.r().set_method_named(method).unwrap();
        let got = gpu.render(&scene, 96, 64, &options);
        let (worst, count) = got
            .pixels()
            .zip(reference.pixels())
            .map(|(a, b)| (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap())
            .fold((0, 0), |(w, n), d| (w.max(d), n + usize::from(d > 2)));
        assert!(
            worst <= most,
            "{method}: {worst}/255 from forward on {count} pixels"
        );
    }
}

/// A cell border through a pixel that an edge crosses: with MSAA (ES 3.0) the pixel shades at
/// its centroid, left of the border, under a light that reaches only the left. The lights of
/// the pixel centre's cell, right of the border, lacked it: the pixel came out black where
/// forward lights it (helper-122). Cells are found from the point shaded.
#[test]
fn a_cell_border_through_an_edge_pixel_keeps_the_lights_of_the_point_shaded() {
    use glam::{DMat4, DVec3, Vec3};
    let mut scene = manylight::Scene::empty();
    scene.ambient = Vec3::ZERO;
    let grey = scene.add_material(manylight::Material::flat("floor", Vec3::splat(0.8)));
    let mut floor = manylight::MeshBuilder::new();
    let c = |x: f32, z: f32| Vec3::new(x, 0.0, z);
    // The floor ends at x = -0.2: the edge crosses pixel 48 of 97, whose centre is 0.
    floor.quad(c(-60.0, 5.0), c(-0.2, 5.0), c(-0.2, -5.0), c(-60.0, -5.0));
    scene.add_object(floor.build().unwrap(), grey, DMat4::IDENTITY);
    // Reaches the floor left of x = -0.1 only.
    let light = manylight::Light::point(DVec3::new(-2.0, 0.5, 0.0), 1.9, Vec3::ONE, 200.0);
    scene.lights.push(light);
    scene.camera = manylight::Camera {
        position: DVec3::new(0.0, 10.0, 0.0),
        target: DVec3::ZERO,
        up: DVec3::NEG_Z,
        projection: manylight::Projection::Orthographic {
            height: 1.0,
            near: 0.1,
            far: 20.0,
        },
    };
    let mut gpu = Gpu::new(EsVersion::Es3);
    // A 64-px clustered grid and 48.5-px tiles put a border at x = 48.5, inside pixel 48.
    let options = RenderOptions {
        grid: manylight::GridConfig::fixed(64.0),
        tile_px: 48.5,
        ..msaa(4)
    };
    gpu.r().set_method_named("forward").unwrap();
    let reference = gpu.render(&scene, 97, 1, &options);
    // SwiftShader shades at the pixel's centre all the same (docs/drivers.md), unlit there.
    if gpu.r().caps().implementation() != "SwiftShader" {
        let lit = reference.get_pixel(48, 0)[0];
        assert!(lit > 20, "the case lost its lit edge pixel: {lit}");
    }
    for method in ["tiled", "clustered"] {
        gpu.r().set_method_named(method).unwrap();
        let got = gpu.render(&scene, 97, 1, &options);
        for x in 0..97 {
            let (a, b) = (got.get_pixel(x, 0), reference.get_pixel(x, 0));
            let worst = (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap();
            assert!(worst <= 2, "{method}: pixel {x} {a:?}, forward {b:?}");
        }
    }
}
