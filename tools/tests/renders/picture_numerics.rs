//! Numbers that used to give a silently wrong picture: flat objects, vertex normals of no use,
//! large coordinates, spot axes of any length and large light radii without fragment highp.
//! Each renders what the f64 light model says — checked against the same scene moved to the
//! origin or scaled back, or the CPU reference, all computed here — on ES 3.0, ES 2.0 and a
//! device without fragment highp (fp16), or is refused naming what is at fault.

use crate::common;

use std::sync::Arc;

use common::{max_oracle_error, mean, Gpu};
use glam::{DMat4, DVec3, DVec4, Vec3};
use manylight::metrics::cpu_reference::Encoding;
use manylight::scene::{self, Camera, Light, Mesh, Object, Scene};
use manylight::{EsVersion, RenderOptions};

const W: u32 = 64;
const H: u32 = 36;

/// RMSE bound of a device without fragment highp against the highp picture (as in
/// stability.rs: fp16 positions are 2⁻¹¹ of the view distance apart).
const MEDIUMP_ONLY_RMSE: f64 = 2.0;

/// The three devices every case runs on, made one at a time (a new context becomes current).
fn each_device(mut case: impl FnMut(&str, &mut Gpu)) {
    for (name, es, no_fragment_highp) in [
        ("ES 3.0", EsVersion::Es3, false),
        ("ES 2.0", EsVersion::Es2, false),
        ("ES 2.0 without fragment highp", EsVersion::Es2, true),
    ] {
        let mut gpu = Gpu::restricted(
            es,
            &manylight::gl::Restrictions {
                no_fragment_highp,
                ..Default::default()
            },
        );
        case(name, &mut gpu);
    }
}

/// Every method the device runs.
fn methods(gpu: &mut Gpu) -> Vec<&'static str> {
    ["forward", "tiled", "clustered", "deferred"]
        .into_iter()
        .filter(|m| gpu.r().set_method_named(m).is_ok())
        .collect()
}

fn render(gpu: &mut Gpu, method: &str, s: &Scene) -> image::RgbaImage {
    gpu.r().set_method_named(method).unwrap();
    gpu.render(s, W, H, &RenderOptions::default())
}

/// The `plane` scene without ambient light, lit by one point light 1 m in front of it.
fn lit_plane() -> Scene {
    let mut s = scene::builtin::build("plane", None).unwrap();
    s.ambient = Vec3::ZERO;
    s.lights = vec![Light::point(DVec3::new(0.5, 0.0, 1.0), 3.0, Vec3::ONE, 2.0)];
    s
}

/// Every method of every device draws `s` as it draws `oracle` (within 1/255; the RMSE bound
/// without fragment highp, where fp16 positions differ between the two).
fn assert_draws_as(s: &Scene, oracle: &Scene, what: &str) {
    each_device(|device, gpu| {
        for method in methods(gpu) {
            let want = render(gpu, method, oracle);
            let got = render(gpu, method, s);
            assert!(
                mean(&want) > 2.0,
                "{device} {method}: the oracle of {what} is black"
            );
            let d = manylight::metrics::diff(&want, &got);
            assert!(
                d.max_abs <= 1 || d.rmse <= MEDIUMP_ONLY_RMSE && device.contains("without"),
                "{device} {method} {what}: {} / 255 (rmse {:.2}) from the oracle",
                d.max_abs,
                d.rmse
            );
        }
    });
}

/// Scaled to 0 or 10⁻²⁰ along its normal (the scene-file and glTF forms), or by 10⁹ (the
/// normal matrix then shrinks the normal to 10⁻⁹, which fp16 varyings flushed to zero: NaN).
#[test]
fn a_plane_scaled_to_nothing_or_vastly_along_its_normal_is_lit_as_the_plane() {
    for z in [1e-20, 0.0, 1e9] {
        let mut flat = lit_plane();
        for o in &mut flat.objects {
            o.transform = DMat4::from_scale(DVec3::new(1.0, 1.0, z)) * o.transform;
        }
        assert_draws_as(&flat, &lit_plane(), &format!("scale [1, 1, {z:e}]"));
    }
}

#[test]
fn random_lights_of_a_flat_scene_file_light_it() {
    let dir = tempfile::tempdir().unwrap();
    for scale in ["[1, 1, 1e-20]", "[1, 1, 1]"] {
        let path = dir.path().join("flat.json");
        std::fs::write(
            &path,
            format!(
                r#"{{"objects": [{{"builtin": "plane", "transform": {{"scale": {scale}}}}},
                                 {{"builtin": "plane", "transform": {{"translate": [0, 0, -1e-9], "scale": 1e-3}}}}],
                    "ambient": [0, 0, 0],
                    "camera": {{"position": [0, 0, 12], "target": [0, 0, 0], "up": [0, 1, 0]}},
                    "random_lights": {{"count": 24, "seed": 3}}}}"#
            ),
        )
        .unwrap();
        let (s, _) = scene::load(path.to_str().unwrap(), None).unwrap();
        each_device(|device, gpu| {
            let img = render(gpu, "forward", &s);
            // Lights in the plane itself (the bounds of a flat scene) lit nothing.
            assert!(mean(&img) > 10.0, "{device} {scale}: {:.1}", mean(&img));
            let (e, at, n) = max_oracle_error(&img, &s, Encoding::Srgb, gpu.r().caps());
            // All but the patch where the small plane just behind fights the large one.
            let pixels = (img.width() * img.height()) as usize;
            assert!(
                n * 2 >= pixels,
                "{device} {scale}: {n} of {pixels} compared"
            );
            let bound = f64_model_bound(device);
            assert!(
                e <= bound,
                "{device} {scale}: {e:.1} / 255 off the f64 model at {at:?}"
            );
        });
    }
}

/// Largest error in 8-bit steps allowed against the f64 model: fp16 positions without fragment
/// `highp` round at about 10⁻³ of their distance.
fn f64_model_bound(device: &str) -> f64 {
    if device.contains("without") {
        24.0
    } else {
        2.0
    }
}

/// The plane's quad with the given vertex normals (one for all four corners).
fn plane_with_normals(normal: Vec3) -> Scene {
    let mut s = lit_plane();
    let quad = &s.objects[0].mesh;
    let mesh = Mesh::new(
        quad.positions.clone(),
        vec![normal; quad.positions.len()],
        quad.uvs.clone(),
        quad.indices.clone(),
    )
    .unwrap();
    s.objects[0].mesh = Arc::new(mesh);
    s
}

#[test]
fn vertex_normals_of_no_direction_are_the_faces_and_huge_ones_keep_theirs() {
    for normal in [
        Vec3::ZERO,
        Vec3::NAN,
        Vec3::new(0.0, 0.0, f32::INFINITY),
        Vec3::new(0.0, 0.0, 3e30),
    ] {
        assert_draws_as(
            &plane_with_normals(normal),
            &lit_plane(),
            &format!("normals {normal}"),
        );
    }
}

/// `s` with every position (objects, lights, camera) scaled by `k` about the origin, radii by
/// `k` and intensities by `k²`: the same picture where the falloff's `+1` is negligible.
fn scaled(s: &Scene, k: f64) -> Scene {
    let mut out = s.clone();
    for o in &mut out.objects {
        o.transform = DMat4::from_scale(DVec3::splat(k)) * o.transform;
    }
    for l in &mut out.lights {
        l.position *= k;
        l.radius *= k as f32;
        l.intensity *= (k * k) as f32;
    }
    let c = &s.camera;
    let (near, far) = c.near_far();
    out.camera = Camera::perspective(c.position * k, c.target * k, 60.0, near * k, far * k);
    out
}

#[test]
fn a_scene_scaled_up_renders_as_the_f64_model_says_or_is_refused_without_highp() {
    let base = scaled(&lit_plane(), 100.0);
    each_device(|device, gpu| {
        let caps = gpu.r().caps().clone();
        let want = render(gpu, "forward", &base);
        for k in [1e3, 1e6, 1e8] {
            let s = scaled(&base, k);
            let result = gpu
                .r()
                .render_offscreen(&s, W, H, &RenderOptions::default());
            if device.contains("without") {
                if k * 500.0 > 32768.0 {
                    // fp16 view positions end at 65 504: refused by the field to change.
                    let err = result.unwrap_err().to_string();
                    assert!(err.contains("camera.far"), "{device} ×{k:e}: {err}");
                }
                continue;
            }
            let (img, _) = result.unwrap_or_else(|e| panic!("{device} ×{k:e}: {e}"));
            let (e, at, n) = max_oracle_error(&img, &s, Encoding::Srgb, &caps);
            // A reference that kept (almost) no pixel would compare nothing and read 0.
            assert!(n >= 50, "only {n} pixels compared");
            assert!(
                e <= 2.0,
                "{device} ×{k:e}: {e:.1} / 255 off the f64 model at {at:?}"
            );
            let d = manylight::metrics::diff(&want, &img);
            assert!(d.max_abs <= 1, "{device} ×{k:e}: {} / 255", d.max_abs);
        }
    });
}

#[test]
fn a_triangle_huge_beside_the_camera_renders_as_the_f64_model_says() {
    let placed = |transform: DMat4| {
        let mut s = lit_plane();
        s.objects[0].transform = transform;
        s
    };
    let scaled = |x: f64, y: f64| DMat4::from_scale(DVec3::new(x, y, 1.0));
    // x' = 10¹⁰ (x + y): the plane still fills the view, its triangles long and slanted.
    let sheared = DMat4::from_cols(
        DVec4::new(1e10, 0.0, 0.0, 0.0),
        DVec4::new(1e10, 1.0, 0.0, 0.0),
        DVec4::Z,
        DVec4::W,
    );
    // 10⁶ put the light off centre (29/255), 10⁸ left half the frame black: the plane is
    // split near the eye for the frame. Stretched one way (10¹¹ by 1, or sheared), its splits
    // took gigabytes before they cut only across the longest edge.
    let cases = [
        ("×1e3", scaled(1e3, 1e3)),
        ("×1e6", scaled(1e6, 1e6)),
        ("×1e8", scaled(1e8, 1e8)),
        ("×1e11", scaled(1e11, 1e11)),
        ("×(1e11, 1)", scaled(1e11, 1.0)),
        ("sheared 1e10", sheared),
    ];
    each_device(|device, gpu| {
        let caps = gpu.r().caps().clone();
        for (k, transform) in cases {
            let s = placed(transform);
            for method in methods(gpu) {
                let img = render(gpu, method, &s);
                let (e, at, n) = max_oracle_error(&img, &s, Encoding::Srgb, &caps);
                // The plane fills the frame: most pixels are compared.
                let pixels = (img.width() * img.height()) as usize;
                assert!(
                    n * 10 >= pixels * 9,
                    "{device} {method} {k}: {n} of {pixels} compared"
                );
                let bound = f64_model_bound(device);
                assert!(
                    e <= bound,
                    "{device} {method} {k}: {e:.1} / 255 off the f64 model at {at:?}"
                );
            }
        }
    });
}

/// A plane seen through the narrowest lens a camera may have, or in an orthographic view
/// 10⁻⁶ high, spans 10⁸–10⁹ pixels a triangle. SwiftShader drew such triangles unlit past
/// about 2²⁷ pixels and not at all past 2²⁸, with no error (llvmpipe drew them): the triangles
/// in view are now split for the frame, and the picture is the f64 model's on every
/// implementation.
#[test]
fn a_triangle_spanning_a_billion_pixels_renders_as_the_f64_model_says() {
    let (eye, target) = (DVec3::new(0.3, 0.2, 5.0), DVec3::new(0.3, 0.2, 0.0));
    let mut orthographic = lit_plane();
    orthographic.camera = Camera {
        projection: manylight::Projection::Orthographic {
            height: 1e-6,
            near: 0.0,
            far: 50.0,
        },
        ..Camera::perspective(eye, target, 60.0, 0.1, 50.0)
    };
    let mut narrow = lit_plane();
    narrow.objects[0].transform = DMat4::from_scale(DVec3::new(100.0, 100.0, 1.0));
    narrow.camera = Camera::perspective(eye, target, 0.001, 0.1, 50.0);
    each_device(|device, gpu| {
        let caps = gpu.r().caps().clone();
        for (what, s) in [("orthographic 1e-6", &orthographic), ("0.001°", &narrow)] {
            for method in methods(gpu) {
                let img = render(gpu, method, s);
                let (e, at, n) = max_oracle_error(&img, s, Encoding::Srgb, &caps);
                let pixels = (img.width() * img.height()) as usize;
                assert!(
                    n == pixels,
                    "{device} {method} {what}: {n} of {pixels} compared"
                );
                assert!(
                    mean(&img) > 20.0,
                    "{device} {method} {what}: the lit plane came out dark"
                );
                let bound = f64_model_bound(device);
                assert!(
                    e <= bound,
                    "{device} {method} {what}: {e:.1} / 255 off the f64 model at {at:?}"
                );
            }
        }
    });
}

/// The split copies count in the frame's uploads, and a frame in which nothing moved keeps
/// them; a camera that moved splits anew, and the picture is still the f64 model's and what a
/// renderer that split nothing before draws.
#[test]
fn split_copies_are_counted_and_kept_while_nothing_moves() {
    let unsplit = lit_plane();
    let mut split = lit_plane();
    split.objects[0].transform = DMat4::from_scale(DVec3::new(1e8, 1e8, 1.0));
    let mut moved = split.clone();
    moved.camera.position.x += 0.01;
    let mut gpu = Gpu::new(EsVersion::Es3);
    let caps = gpu.r().caps().clone();
    let opts = RenderOptions::default();
    let frame = |gpu: &mut Gpu, s: &Scene| gpu.render_with("forward", s, (W, H), &opts);
    // Forward uploads its one light's record, and keeps it while the lights stand still: the
    // split frame's uploads are its split copies alone.
    let record = frame(&mut gpu, &unsplit).1.memory.upload_bytes;
    let first = frame(&mut gpu, &split).1;
    assert!(first.lists_reused, "the light record was uploaded again");
    // At least a triangle: three positions of three floats.
    let first = first.memory.upload_bytes;
    assert!(first >= 36, "{first} bytes of split copies");
    let (kept, still) = frame(&mut gpu, &split);
    assert_eq!(still.memory.upload_bytes, 0, "the still frame split again");
    let (image, again) = frame(&mut gpu, &moved);
    assert!(again.memory.upload_bytes >= record + 36, "the camera moved");
    let fresh = Gpu::new(EsVersion::Es3)
        .render_with("forward", &moved, (W, H), &opts)
        .0;
    assert!(image == fresh, "not what a first split draws");
    for (picture, s) in [(&kept, &split), (&image, &moved)] {
        let (e, at, _) = max_oracle_error(picture, s, Encoding::Srgb, &caps);
        let bound = f64_model_bound("ES 3.0");
        assert!(e <= bound, "{e:.1} / 255 off the f64 model at {at:?}");
    }
}

/// Past a frame's budget of split triangles (many huge objects beside the camera) the rest
/// are drawn unsplit, with one warning a renderer naming the first of them; the frame still
/// draws the first plane, split, as it draws it alone. The others lie 1 m behind it: drawn
/// unsplit on the same plane, a driver's depth rounding could put them in front (NVIDIA's
/// did, and drew them unlit, as the warning says they may be).
#[test]
fn splits_past_the_frames_budget_are_warned_of_once() {
    let mut s = lit_plane();
    s.objects[0].transform = DMat4::from_scale(DVec3::new(1e8, 1e8, 1.0));
    let alone = s.clone();
    let mut behind = s.objects[0].clone();
    behind.transform = DMat4::from_translation(DVec3::new(0.0, 0.0, -1.0)) * behind.transform;
    s.objects.resize(2000, behind);
    let mut gpu = Gpu::new(EsVersion::Es3);
    let said = || common::warnings::warnings_containing("splits this frame");
    let before = said().len();
    let img = render(&mut gpu, "forward", &s);
    render(&mut gpu, "forward", &s);
    let warned = said();
    assert_eq!(warned.len() - before, 1, "{warned:?}");
    let first = warned.last().unwrap();
    assert!(
        first.starts_with("objects[") && first.contains("65536"),
        "{first}"
    );
    assert!(mean(&img) > 2.0, "the plane is drawn");
    let d = manylight::metrics::diff(&render(&mut gpu, "forward", &alone), &img);
    assert!(d.max_abs <= 1, "{} / 255 from the plane alone", d.max_abs);
}

/// An OBJ quad of half-size `half` with its corners `offset` from the origin, with its camera
/// framed and 32 random lights as the CLI loads it.
fn obj_quad(dir: &std::path::Path, offset: f64, half: f64) -> Scene {
    let path = dir.join(format!("quad{offset}-{half}.obj"));
    let v = |x: f64, y: f64| format!("v {} {} {}\n", offset + x, offset + y, offset);
    let text = [
        v(-half, -half),
        v(half, -half),
        v(half, half),
        v(-half, half),
    ]
    .concat()
        + "f 1 2 3 4\n";
    std::fs::write(&path, text).unwrap();
    let (mut s, _) = scene::load(path.to_str().unwrap(), Some((32, 5))).unwrap();
    s.ambient = Vec3::ZERO;
    s
}

#[test]
fn an_obj_modelled_far_from_its_origin_renders_as_at_the_origin() {
    let dir = tempfile::tempdir().unwrap();
    let at_origin = obj_quad(dir.path(), 0.0, 4.0);
    for offset in [1e5, 1e7] {
        assert_draws_as(
            &obj_quad(dir.path(), offset, 4.0),
            &at_origin,
            &format!("quad at {offset:e}"),
        );
    }
    // Corners 0.1 apart 1e7 and 1e8 from the origin: f32 there rounds to 1 and 8, but the
    // file is read in f64 and the mesh stored about its centre.
    let fine = obj_quad(dir.path(), 0.0, 0.05);
    for offset in [1e7, 1e8] {
        assert_draws_as(
            &obj_quad(dir.path(), offset, 0.05),
            &fine,
            &format!("fine quad at {offset:e}"),
        );
    }
    // The same through an object transform (f64 all the way).
    let mut moved = at_origin.clone();
    let shift = DVec3::splat(1e9);
    for o in &mut moved.objects {
        o.transform = DMat4::from_translation(shift) * o.transform;
    }
    for l in &mut moved.lights {
        l.position += shift;
    }
    moved.camera.position += shift;
    moved.camera.target += shift;
    assert_draws_as(&moved, &at_origin, "quad moved by 1e9");
}

#[test]
fn spot_axes_of_any_finite_length_light_alike() {
    let spot = |length: f64| {
        let mut s = lit_plane();
        let cone = manylight::Cone {
            direction: DVec3::new(0.2, 0.1, -1.0) * length,
            inner_deg: 30.0,
            outer_deg: 70.0,
        };
        s.lights = vec![Light::spot(
            DVec3::new(0.0, 0.0, 1.5),
            4.0,
            Vec3::ONE,
            2.0,
            cone,
        )];
        s
    };
    for length in [1e155, 1e-200, 1e300] {
        assert_draws_as(
            &spot(length),
            &spot(1.0),
            &format!("spot axis × {length:e}"),
        );
    }
}

#[test]
fn lights_of_large_radius_light_as_every_method_and_the_f64_model_say() {
    for radius in [6e3f32, 6e4, 1e6] {
        let mut s = lit_plane();
        s.lights[0].radius = radius;
        each_device(|device, gpu| {
            let caps = gpu.r().caps().clone();
            let forward = render(gpu, "forward", &s);
            assert!(mean(&forward) > 20.0, "{device} radius {radius:e}: dark");
            let (e, at, n) = max_oracle_error(&forward, &s, Encoding::Srgb, &caps);
            // A reference that kept (almost) no pixel would compare nothing and read 0.
            assert!(n >= 50, "only {n} pixels compared");
            assert!(
                e <= 2.0,
                "{device} radius {radius:e}: {e:.1} / 255 off at {at:?}"
            );
            for method in methods(gpu) {
                let d = manylight::metrics::diff(&forward, &render(gpu, method, &s));
                assert!(
                    d.max_abs <= 2,
                    "{device} {method} radius {radius:e}: {}",
                    d.max_abs
                );
            }
        });
    }
}

#[test]
fn an_object_placed_with_translation_only_keeps_its_own_picture() {
    // A mesh whose vertices are all far from its own origin and an object that moves it back:
    // the picture is the mesh drawn at the origin.
    let s = lit_plane();
    let mesh = &s.objects[0].mesh;
    let offset = Vec3::splat(3e6);
    let far = Mesh::new(
        mesh.positions.iter().map(|p| *p + offset).collect(),
        mesh.normals.clone(),
        mesh.uvs.clone(),
        mesh.indices.clone(),
    )
    .unwrap();
    let mut moved = s.clone();
    moved.objects = vec![Object {
        mesh: Arc::new(far),
        material: s.objects[0].material,
        transform: DMat4::from_translation(-offset.as_dvec3()),
    }];
    assert_draws_as(&moved, &s, "vertices 3e6 from their origin");
}

#[test]
fn without_highp_a_light_too_far_to_place_is_refused_by_name_or_left_out_when_it_reaches_nothing() {
    let with = |light: Light| {
        let mut s = lit_plane();
        s.lights.push(light);
        s
    };
    // A sun 70 km away whose sphere takes in the plane; a lamp as far whose sphere does not.
    let sun = Light::point(DVec3::new(0.0, 0.0, 7e4), 1e5, Vec3::ONE, 2e9);
    let far_lamp = Light::point(DVec3::new(0.0, 0.0, 7e4), 100.0, Vec3::ONE, 2.0);
    each_device(|device, gpu| {
        let caps = gpu.r().caps().clone();
        let alone = render(gpu, "forward", &lit_plane());
        let lamp = render(gpu, "forward", &with(far_lamp));
        assert_eq!(
            manylight::metrics::diff(&alone, &lamp).max_abs,
            0,
            "{device}"
        );
        let s = with(sun);
        match gpu
            .r()
            .render_offscreen(&s, W, H, &RenderOptions::default())
        {
            Ok((img, _)) => {
                assert!(
                    !device.contains("without"),
                    "{device}: the sun cannot be placed"
                );
                let (e, at, n) = max_oracle_error(&img, &s, Encoding::Srgb, &caps);
                // A reference that kept (almost) no pixel would compare nothing and read 0.
                assert!(n >= 50, "only {n} pixels compared");
                assert!(
                    e <= 2.0,
                    "{device}: {e:.1} / 255 off the f64 model at {at:?}"
                );
                assert!(
                    mean(&img) > mean(&alone) + 5.0,
                    "{device}: the sun lights nothing"
                );
            }
            Err(e) => {
                assert!(device.contains("without"), "{device}: {e}");
                assert!(e.to_string().contains("lights[1]"), "{e}");
            }
        }
    });
}

/// A record holds spot terms only where the scene has spots, so its size and layout follow the
/// scene: six point lights of their own colours, then the same with one a spot, on float and
/// RGBA8 records and on the fp16 form, every method, each the f64 model's picture. Forward
/// reads the records as the other methods do and would share a mistake; the model does not.
#[test]
fn records_with_and_without_spot_terms_draw_the_f64_models_picture() {
    let mut s = lit_plane();
    s.lights = (0..6)
        .map(|i| {
            let f = i as f64;
            let colour = Vec3::new(1.0 - 0.15 * i as f32, 0.2 + 0.1 * i as f32, 0.5);
            Light::point(
                DVec3::new(f * 0.6 - 1.5, 0.4 - 0.2 * f, 0.8),
                2.0,
                colour,
                1.5,
            )
        })
        .collect();
    let mut with_spot = s.clone();
    with_spot.lights[2] = Light::spot(
        DVec3::new(0.0, 0.0, 1.5),
        3.0,
        Vec3::new(0.3, 1.0, 0.6),
        2.0,
        scene::Cone {
            direction: DVec3::new(0.3, 0.0, -1.0),
            inner_deg: 15.0,
            outer_deg: 35.0,
        },
    );
    for (device, es, restrictions) in [
        ("ES 3.0", EsVersion::Es3, Default::default()),
        (
            "ES 2.0 without fragment highp",
            EsVersion::Es2,
            manylight::gl::Restrictions {
                no_fragment_highp: true,
                ..Default::default()
            },
        ),
        (
            "ES 2.0 without float textures",
            EsVersion::Es2,
            manylight::gl::Restrictions {
                no_float_textures: true,
                ..Default::default()
            },
        ),
    ] {
        let mut gpu = Gpu::restricted(es, &restrictions);
        for method in methods(&mut gpu) {
            for (scene, what) in [(&s, "points"), (&with_spot, "a spot among them")] {
                let img = render(&mut gpu, method, scene);
                let (e, at, n) = max_oracle_error(&img, scene, Encoding::Srgb, gpu.r().caps());
                assert!(n > 1000, "{device} {method} {what}: {n} compared");
                let bound = f64_model_bound(device);
                assert!(
                    e <= bound,
                    "{device} {method} {what}: {e:.1} / 255 off the f64 model at {at:?}"
                );
            }
        }
    }
}
