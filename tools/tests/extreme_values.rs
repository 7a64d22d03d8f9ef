//! Finite values so large or small that the maths overflows, underflows or loses the
//! surface: each either renders what the light model says (the renderer changed its maths) or
//! is refused with the real field named — never a silent black frame or a misleading field.

mod common;

use common::{mean, Gpu};
use glam::{DMat4, DVec3, Vec3};
use manylight::scene::{self, Camera, Light, Projection, Scene};
use manylight::{EsVersion, RenderOptions};

fn plane(lights: Vec<Light>) -> Scene {
    let mut s = scene::builtin::build("plane", None).unwrap();
    s.ambient = Vec3::splat(0.02);
    s.lights = lights;
    s
}

fn point(radius: f32) -> Light {
    Light::point(
        DVec3::new(0.0, 0.0, 1.0),
        radius,
        Vec3::new(1.0, 0.8, 0.6),
        1.0,
    )
}

/// The error a 16 × 16 frame of `s` with `options` is refused with (a test failure if it
/// renders).
fn refusal(gpu: &mut Gpu, s: &Scene, options: &RenderOptions) -> String {
    gpu.r()
        .render_offscreen(s, 16, 16, options)
        .unwrap_err()
        .to_string()
}

#[test]
fn a_light_whose_radius_dwarfs_the_scene_lights_it_as_a_large_one_does() {
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::new(es);
        for method in ["forward", "clustered"] {
            gpu.r().set_method_named(method).unwrap();
            let opts = RenderOptions::default();
            // At 10⁶ the window term is 1 to 10⁻²⁰ across the plane: the same picture as any
            // larger radius, which must not underflow to nothing.
            let large = gpu.render(&plane(vec![point(1e6)]), 64, 36, &opts);
            assert!(mean(&large) > 40.0, "{es} {method}: radius 1e6 too dark");
            for radius in [1e20, 1e30, f32::MAX] {
                let huge = gpu.render(&plane(vec![point(radius)]), 64, 36, &opts);
                let d = manylight::metrics::diff(&large, &huge);
                assert!(
                    d.max_abs <= 1,
                    "{es} {method}: radius {radius:e} differs by {} / 255",
                    d.max_abs
                );
            }
        }
    }
}

/// Radiance past 2¹²⁶ on a device without fragment highp: its fp16 form divided by k² = 2¹²⁸,
/// which is past `f32`, and the light uploaded as black (an ambient-only frame, no warning).
/// A light that bright saturates the plane under it, as it does with highp.
#[test]
fn a_light_brighter_than_2_to_the_126_still_lights_without_fragment_highp() {
    let mut gpu = Gpu::without_fragment_highp();
    let opts = RenderOptions::default();
    let ambient = mean(&gpu.render(&plane(vec![]), 64, 36, &opts));
    for intensity in [5e37f32, 1e38, 3e38] {
        let mut light = point(10.0);
        light.intensity = intensity;
        let lit = mean(&gpu.render(&plane(vec![light]), 64, 36, &opts));
        assert!(
            lit > ambient + 100.0,
            "intensity {intensity:e}: mean {lit:.1}, ambient alone {ambient:.1}"
        );
    }
}

/// Past forward's light cap (no fragment highp: 1 023 lights), bright lights just beside the
/// camera, outside the view, were kept before the one light in it, being nearer the eye: the
/// plane went unlit. They reach no pixel, so they are the first left out.
#[test]
fn forwards_cap_keeps_the_light_in_view_over_lights_beside_it() {
    let mut gpu = Gpu::without_fragment_highp();
    let opts = RenderOptions::default();
    let limit = manylight::methods::forward::max_lights(gpu.r().caps()) as usize;
    let in_view = point(10.0);
    let alone = gpu.render(&plane(vec![in_view]), 64, 36, &opts);
    let mut s = plane(vec![]);
    // 60 units to the right in view space, radius 15: outside the right plane for any field
    // of view up to 90° at 16:9, and ten thousand times as bright as the light in view.
    let to_world = s.camera.view_matrix().inverse();
    let beside = to_world.transform_point3(DVec3::new(60.0, 0.0, -2.0));
    s.lights = vec![Light::point(beside, 15.0, Vec3::ONE, 1e4); limit];
    s.lights.push(in_view);
    let capped = gpu.render(&s, 64, 36, &opts);
    let d = manylight::metrics::diff(&alone, &capped);
    assert!(
        d.max_abs <= 2,
        "the light in view was left out: {} / 255 from it alone (mean {:.1} against {:.1})",
        d.max_abs,
        mean(&capped),
        mean(&alone)
    );
}

/// How far deferred's 128 × 72 frame of `s` lies from forward's, per channel (0–255).
fn deferred_from_forward(gpu: &mut Gpu, s: &Scene) -> u8 {
    let opts = RenderOptions::default();
    gpu.r().set_method_named("forward").unwrap();
    let forward = gpu.render(s, 128, 72, &opts);
    gpu.r().set_method_named("deferred").unwrap();
    let deferred = gpu.render(s, 128, 72, &opts);
    manylight::metrics::diff(&forward, &deferred).max_abs
}

/// A near plane of 10⁻⁵ before the 40 m courtyard: depth steps wider than a light's reach at
/// its far end made deferred's proxy volumes skip lit pixels (184/255 from forward); they
/// now fall back to its full-screen pass there. Every method draws the one coarse picture, so
/// the camera itself is warned of, once, naming `camera.near`; a usual near plane is not.
#[test]
fn a_tiny_near_plane_is_warned_of_and_deferred_still_equals_forward() {
    common::warnings::install();
    let mut s = scene::builtin::build("courtyard", Some((256, 7))).unwrap();
    let warned = || common::warnings::warnings_containing("camera.near 1e-5 leaves").len();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let opts = RenderOptions::default();
    gpu.render(&s, 128, 72, &opts);
    let any = common::warnings::warnings_containing("camera.near");
    assert!(any.is_empty(), "the built-in camera is warned of: {any:?}");
    if let Projection::Perspective { near, .. } = &mut s.camera.projection {
        *near = 1e-5;
    }
    let off = deferred_from_forward(&mut gpu, &s);
    assert!(off <= 2, "deferred {off} / 255 from forward");
    assert_eq!(warned(), 1, "warned once a renderer");
}

/// An orthographic camera with near 0 and far 10⁷: `f32` depth cannot place surfaces within
/// some 0.6 m of the eye plane, so some at or behind it survive clipping. Forward shades them;
/// deferred read their view depth ≤ 0 as "no surface" and left black pixels (109/255).
#[test]
fn deferred_keeps_surfaces_at_an_orthographic_eye_plane() {
    let mut s = scene::builtin::build("courtyard", Some((256, 7))).unwrap();
    s.camera.position = DVec3::new(-18.5, 3.0, 1.5);
    s.camera.target = DVec3::new(6.0, 3.6, -1.0);
    s.camera.projection = Projection::Orthographic {
        height: 20.0,
        near: 0.0,
        far: 1e7,
    };
    let mut gpu = Gpu::new(EsVersion::Es3);
    let off = deferred_from_forward(&mut gpu, &s);
    assert!(off <= 2, "deferred {off} / 255 from forward");
}

/// A light whose proxy spans more pixels than rasterizers keep, here over 2³⁰ pixels across in a
/// 10⁻⁵-high orthographic view, is drawn full screen: its sphere lost the light on every
/// implementation (100/255 from forward on two thirds of a 3 × 2 000 frame, ambient alone).
/// Also where the view shrinks, or the frame grows taller, under a renderer that drew the
/// same lights before: its light instances were drawn again, spheres and all.
#[test]
fn deferred_keeps_a_light_whose_proxy_spans_more_pixels_than_rasterizers_keep() {
    let view = |height: f64| {
        let mut s = plane(vec![Light::point(
            DVec3::new(0.3, 0.1, 1.0),
            4.0,
            Vec3::new(1.0, 0.8, 0.6),
            0.5,
        )]);
        s.camera = Camera {
            position: DVec3::new(0.0, 0.0, 5.0),
            target: DVec3::ZERO,
            up: DVec3::Y,
            projection: Projection::Orthographic {
                height,
                near: 0.0,
                far: 10.0,
            },
        };
        s
    };
    let (tiny, size) = (view(1e-5), (3, 2000));
    let opts = RenderOptions::default();
    let (forward, _) = Gpu::new(EsVersion::Es3).render_with("forward", &tiny, size, &opts);
    assert!(mean(&forward) > 50.0, "the light shows");
    let cases = [
        ("fresh", None),
        ("after a 1-high view", Some((view(1.0), size))),
        ("after a frame 10 rows high", Some((view(1e-5), (3, 10)))),
    ];
    for (what, before) in cases {
        let mut gpu = Gpu::new(EsVersion::Es3);
        gpu.r().set_method_named("deferred").unwrap();
        if let Some((scene, (w, h))) = before {
            gpu.render(&scene, w, h, &opts);
        }
        let deferred = gpu.render(&tiny, size.0, size.1, &opts);
        let off = manylight::metrics::diff(&forward, &deferred).max_abs;
        assert!(off <= 2, "{what}: deferred {off} / 255 from forward");
    }
}

#[test]
fn a_far_plane_near_the_top_of_f64_renders_as_an_infinite_one() {
    let mut gpu = Gpu::new(EsVersion::Es3);
    let with_far = |far: f64| {
        let mut s = plane(vec![point(4.0)]);
        s.camera = Camera::perspective(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, 60.0, 0.1, far);
        s
    };
    let infinite = gpu.render(&with_far(f64::INFINITY), 64, 36, &RenderOptions::default());
    assert!(mean(&infinite) > 20.0);
    for far in [1e300, f64::MAX] {
        let img = gpu.render(&with_far(far), 64, 36, &RenderOptions::default());
        assert_eq!(img, infinite, "far {far:e}");
    }
}

#[test]
fn values_the_maths_cannot_carry_are_refused_naming_the_real_field() {
    let mut gpu = Gpu::new(EsVersion::Es3);
    type Breaker = Box<dyn Fn(&mut Scene)>;
    let cases: Vec<(Breaker, &str)> = vec![
        // Squared lengths of these overflow f64: it used to say camera.up was parallel.
        (
            Box::new(|s: &mut Scene| s.camera.position = DVec3::new(1e200, 0.0, 5.0)),
            "camera.position",
        ),
        (
            Box::new(|s: &mut Scene| s.camera.target = DVec3::new(0.0, -1e300, 0.0)),
            "camera.target",
        ),
        (
            Box::new(|s: &mut Scene| s.camera.up = DVec3::ZERO),
            "camera.up",
        ),
        // A view finer than f32 view-space coordinates resolve (rendered half black).
        (
            Box::new(|s: &mut Scene| {
                s.camera.projection = Projection::Orthographic {
                    height: 1e-9,
                    near: 0.0,
                    far: 10.0,
                }
            }),
            "camera.height",
        ),
        // Its 1/d² underflowed f32: no light at all, however bright.
        (
            Box::new(|s: &mut Scene| {
                s.lights[0].position = DVec3::new(0.0, 0.0, 2e19);
                s.lights[0].radius = 3e38;
                s.lights[0].intensity = 3e38;
            }),
            "lights[0].position",
        ),
        // Finite, but past f32 in the view matrix: the object vanished without a word.
        (
            Box::new(|s: &mut Scene| {
                s.objects[0].transform = DMat4::from_scale(DVec3::splat(1e39))
            }),
            "objects[0].transform",
        ),
        // A flat object stretched so far along its normal: finite bounds, infinite matrix.
        (
            Box::new(|s: &mut Scene| {
                s.objects[0].transform = DMat4::from_scale(DVec3::new(1.0, 1.0, 1e38))
            }),
            "objects[0].transform",
        ),
        (
            Box::new(|s: &mut Scene| {
                s.objects[0].transform = DMat4::from_translation(DVec3::new(0.0, 2e12, 0.0))
            }),
            "objects[0].transform",
        ),
        // Shrunk into f32's subnormal numbers, which a GPU reads as zero: a black frame.
        (
            Box::new(|s: &mut Scene| {
                s.objects[0].transform = DMat4::from_scale(DVec3::splat(1e-40))
            }),
            "objects[0].transform",
        ),
        // Its f32 projection scale was 0: nothing drawn, no error.
        (
            Box::new(|s: &mut Scene| {
                s.camera.projection = Projection::Orthographic {
                    height: 1e39,
                    near: 0.0,
                    far: 10.0,
                }
            }),
            "camera.height",
        ),
    ];
    for (break_it, field) in cases {
        let mut s = plane(vec![point(3.0)]);
        break_it(&mut s);
        let err = refusal(&mut gpu, &s, &RenderOptions::default());
        assert!(err.contains(field), "expected `{field}` in: {err}");
    }
}

/// A flat object stretched along its own normal, which moves none of its points, renders as
/// it did unstretched, turned aside too, on every method: it was refused as having no area
/// (past 10¹²) or drawn unlit (its normal matrix's entry for the normal, the plane's size over
/// the stretch, here 10⁻⁴⁰, flushed to zero in f32). A scene file stretching it loads.
#[test]
fn a_plane_stretched_along_its_normal_renders_as_it_was() {
    // The plane at a thousandth of its size, seen and lit from a thousandth as far.
    let placed = |stretch: f64, turn: f64| {
        let lamp = Light::point(DVec3::new(0.0, 0.0, 1e-3), 3e-3, Vec3::ONE, 1e-6);
        let mut s = plane(vec![lamp]);
        s.camera = Camera::perspective(DVec3::new(0.0, 0.0, 5e-3), DVec3::ZERO, 60.0, 1e-4, 0.05);
        s.objects[0].transform =
            DMat4::from_rotation_y(turn) * DMat4::from_scale(DVec3::new(1e-3, 1e-3, stretch));
        s
    };
    common::each_method(|es, method, gpu| {
        for turn in [0.0, 0.4] {
            let opts = RenderOptions::default();
            let (want, _) = gpu.render_with(method, &placed(1.0, turn), (32, 18), &opts);
            assert!(mean(&want) > 20.0, "{es} {method}: the plane is lit");
            for stretch in [1e13, 1e30, 1e37] {
                let (got, _) = gpu.render_with(method, &placed(stretch, turn), (32, 18), &opts);
                let worst = want
                    .pixels()
                    .zip(got.pixels())
                    .flat_map(|(a, b)| (0..3).map(move |c| a[c].abs_diff(b[c])))
                    .max();
                assert!(
                    worst <= Some(1),
                    "{es} {method}, stretched {stretch:e}, turned {turn}: {worst:?}/255"
                );
            }
        }
    });
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("stretched.json");
    let json = r#"{"objects":[{"builtin":"plane","transform":{"scale":[1,1,1e19]}}],
        "lights":[{"kind":"point","position":[0,0,1],"radius":4,"color":[1,1,1]}]}"#;
    std::fs::write(&file, json).unwrap();
    let loaded = scene::load_scene(file.to_str().unwrap(), None);
    assert!(loaded.is_ok(), "{:?}", loaded.err());
}

/// Grid settings the grid cannot be built from are refused naming the field (a NaN would never
/// equal itself, so the grid would be rebuilt and re-chosen every frame).
#[test]
fn grid_settings_that_are_not_finite_are_refused_naming_the_field() {
    let mut gpu = Gpu::new(EsVersion::Es3);
    let s = plane(vec![point(3.0)]);
    for (field, value) in [
        ("grid.slice_depth", f64::NAN),
        ("grid.slice_depth", f64::INFINITY),
        ("grid.slice_depth", 0.0),
        ("grid.footprint_px", f64::NAN),
        ("grid.footprint_px", -8.0),
        ("grid.assign_budget", f64::NAN),
        ("grid.assign_budget", -0.05),
        ("grid.assign_budget", f64::INFINITY),
    ] {
        let mut options = RenderOptions::default();
        match field {
            "grid.slice_depth" => options.grid.slice_depth = value,
            "grid.assign_budget" => {
                options.grid.mode = manylight::GridMode::Auto {
                    assign_budget: value,
                }
            }
            _ => options.grid.footprint_px = value,
        }
        let err = refusal(&mut gpu, &s, &options);
        assert!(err.contains(field), "{field} = {value}: {err}");
    }
    // In range, or clamped into it: renders.
    for slice_depth in [0.5, 100.0] {
        let mut options = RenderOptions::default();
        options.grid.slice_depth = slice_depth;
        assert!(gpu.r().render_offscreen(&s, 16, 16, &options).is_ok());
    }
}

#[test]
fn obj_vertices_near_the_f32_limit_are_refused_as_vertices_not_as_lights() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.obj");
    std::fs::write(&path, "v -3e38 0 0\nv 3e38 0 0\nv 0 3e38 0\nf 1 2 3\n").unwrap();
    let err = scene::load(path.to_str().unwrap(), Some((16, 1)))
        .unwrap_err()
        .to_string();
    assert!(err.contains("positions[0]"), "{err}");
    assert!(!err.contains("lights"), "{err}");
}

/// A cascade count near 2³² (a corrupt or hostile setting) is refused naming the field, not
/// looped over (a grid built with it would push four billion cascades); counts in range
/// render, and the grid builder itself never makes more than its documented maximum.
#[test]
fn a_huge_cascade_count_is_refused_naming_the_field() {
    use manylight::cluster::grid::{ClusterGrid, GridConfig, GridProjection, MAX_CASCADES};
    let mut gpu = Gpu::new(EsVersion::Es3);
    let s = plane(vec![point(3.0)]);
    for cascades in [u32::MAX, MAX_CASCADES + 1] {
        let mut options = RenderOptions::default();
        options.grid.cascades = cascades;
        let err = refusal(&mut gpu, &s, &options);
        assert!(err.contains("grid.cascades"), "{cascades}: {err}");
    }
    for cascades in [1, 12, MAX_CASCADES] {
        let mut options = RenderOptions::default();
        options.grid.cascades = cascades;
        assert!(gpu.r().render_offscreen(&s, 16, 16, &options).is_ok());
    }
    let config = GridConfig {
        cascades: u32::MAX,
        ..GridConfig::default()
    };
    let tan = 0.5;
    let projection = GridProjection::Perspective {
        tan_x: tan,
        tan_y: tan,
    };
    let grid = ClusterGrid::new(64, 64, projection, 0.1, 100.0, &config);
    assert_eq!(grid.cascades.len(), MAX_CASCADES as usize);
}

/// A timed-frame count near 2³² is refused naming the field before any frame (each timed
/// frame's figures are kept for the percentiles, so it would grow memory as long as it ran).
#[test]
fn a_huge_timed_frame_count_is_refused_naming_the_field() {
    let mut gpu = Gpu::new(EsVersion::Es3);
    let s = plane(vec![point(3.0)]);
    for frames in [u32::MAX, manylight::MAX_TIMED_FRAMES + 1] {
        let options = RenderOptions {
            measure: manylight::MeasureOptions {
                timed_frames: frames,
                ..Default::default()
            },
            ..RenderOptions::default()
        };
        let err = refusal(&mut gpu, &s, &options);
        assert!(err.contains("timed_frames"), "{frames}: {err}");
    }
    let options = RenderOptions {
        measure: manylight::MeasureOptions {
            timed_frames: 3,
            ..Default::default()
        },
        ..RenderOptions::default()
    };
    let (_, stats) = gpu.r().render_offscreen(&s, 16, 16, &options).unwrap();
    assert_eq!(stats.time.frame_ms_spread.map(|s| s.frames), Some(3));
}

/// 1 100 lights all covering a plane, on a 1-px fixed grid: the cells' lists would hold some
/// 5·10⁹ references before the cell cap, which the assignment allocated (an abort, 14 GB) or
/// misnumbered past 2³² (a panic). Clustered refuses the frame naming the footprint, with no
/// overflow warning for a frame it did not draw; `auto` draws it with deferred; the automatic
/// grid draws it; tiled, whose tiles the lights cover too, draws it.
#[test]
fn lights_overlapping_on_a_fine_fixed_grid_are_refused_naming_the_footprint() {
    common::warnings::install();
    let lights = vec![Light::point(DVec3::new(0.0, 0.0, 1.0), 30.0, Vec3::ONE, 0.01); 1100];
    let s = plane(lights);
    let mut gpu = Gpu::new(EsVersion::Es3);
    gpu.r().set_method_named("clustered").unwrap();
    let fine = RenderOptions {
        grid: manylight::GridConfig::fixed(1.0),
        ..Default::default()
    };
    // 160 × 90 px: 4.5 million 1-px cells.
    let msg = (gpu.r().render_offscreen(&s, 160, 90, &fine))
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("would list at least") && msg.contains("grid.footprint_px"),
        "{msg}"
    );
    let dropped = common::warnings::warnings_containing("light references left out");
    assert!(dropped.is_empty(), "{dropped:?}");
    // `auto` on the same grid draws the frame with deferred instead, as past clustered's
    // index limit.
    gpu.r().set_method_named("auto").unwrap();
    let (_, stats) = gpu.r().render_offscreen(&s, 160, 90, &fine).unwrap();
    assert_eq!(
        stats.auto_choice.as_deref(),
        Some("deferred"),
        "{:?}",
        stats.auto_reason
    );
    gpu.r().set_method_named("clustered").unwrap();
    let auto = gpu.render(&s, 16, 16, &RenderOptions::default());
    assert!(mean(&auto) > 0.0);
    gpu.r().set_method_named("tiled").unwrap();
    gpu.render(&s, 16, 16, &RenderOptions::default());
}

/// Without fragment highp a light's radiance is scaled by its brightest channel into fp16: a
/// light of colour (10⁶, 0.5, 0.5) lost its green and blue (a red disc where highp shows
/// white) without a word. The loss is now named, once; a light whose channels lie within 2¹⁴
/// of each other is not.
#[test]
fn channels_fp16_cannot_keep_beside_a_bright_one_are_named() {
    common::warnings::install();
    let mut gpu = Gpu::without_fragment_highp();
    let said = || common::warnings::warnings_containing("spans more than fp16 keeps");
    let mut even = point(4.0);
    even.color = Vec3::new(1e4, 1.0, 1.0);
    gpu.render(&plane(vec![even]), 32, 18, &RenderOptions::default());
    assert!(said().is_empty(), "{:?}", said());
    let mut lopsided = point(4.0);
    lopsided.color = Vec3::new(1e6, 0.5, 0.5);
    let lights = vec![point(4.0), lopsided];
    for _ in 0..2 {
        gpu.render(&plane(lights.clone()), 32, 18, &RenderOptions::default());
    }
    let warned = said();
    assert_eq!(warned.len(), 1, "{warned:?}");
    assert!(
        warned[0].starts_with("lights[1]:") && warned[0].contains("green and blue"),
        "{}",
        warned[0]
    );
}

/// A light 10¹³ from the scene with a radius of 10²⁰ reaches it, but its radius was capped at
/// 10¹² on the GPU, putting it outside its own sphere: every method drew ambient only, without
/// a word. A far light now keeps a radius past its distance; every method lights the plane as
/// forward does, as the light model says (intensity over the squared distance).
#[test]
fn a_light_farther_than_the_radius_cap_still_reaches_the_scene() {
    let mut far = point(1e20);
    far.position = DVec3::new(0.0, 0.0, 1e13);
    far.color = Vec3::ONE;
    far.intensity = 5e25;
    let s = plane(vec![far]);
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::new(es);
        let ambient = mean(&gpu.render(&plane(vec![]), 64, 36, &RenderOptions::default()));
        gpu.r().set_method_named("forward").unwrap();
        let forward = gpu.render(&s, 64, 36, &RenderOptions::default());
        assert!(mean(&forward) > ambient + 60.0, "{es}: {}", mean(&forward));
        for method in common::methods_on(es) {
            gpu.r().set_method_named(method).unwrap();
            let image = gpu.render(&s, 64, 36, &RenderOptions::default());
            let d = manylight::metrics::diff(&forward, &image).max_abs;
            assert!(d <= 2, "{es} {method}: {d} / 255 from forward");
        }
    }
}

/// Without fragment highp a radius past fp16 acts as 65 504: a light of radius 10⁵ lighting a
/// plane up to ~29 000 away is visibly too dark there. That was said only in a frame that also
/// left a light out (too far to place); it is said whenever it shows.
#[test]
fn a_radius_fp16_caps_is_named_where_it_shows() {
    common::warnings::install();
    let mut s = plane(vec![]);
    s.objects[0].transform = DMat4::from_scale(DVec3::splat(3000.0));
    s.camera = Camera::perspective(
        DVec3::new(0.0, 0.0, 15000.0),
        DVec3::ZERO,
        60.0,
        10.0,
        20000.0,
    );
    s.lights = vec![Light::point(
        DVec3::new(0.0, 0.0, 5000.0),
        1e5,
        Vec3::ONE,
        1.0,
    )];
    Gpu::without_fragment_highp().render(&s, 16, 16, &RenderOptions::default());
    let said = common::warnings::warnings_containing("radius 1.000e5 acts as 65504");
    assert_eq!(said.len(), 1, "{said:?}");
}

/// Without fragment highp a light's radiance goes up divided by k², k = 2^⌈log₂(c)/2⌉, and
/// the falloff multiplies k² back: past c = 2¹⁴ (k ≥ 2⁸) that square is past fp16, and
/// within a unit of the light the falloff became its cap, 1.8× too bright with a ring where
/// d = 1 (or NaN where the window flushed to 0). Such a light now draws on the no-highp tier
/// what highp draws: its radiance (not pre-exposed, so k = 2⁸), and its frame at −15 EV.
#[test]
fn a_light_whose_fp16_scale_squares_past_fp16_draws_as_with_highp() {
    let mut mediump = Gpu::without_fragment_highp();
    let mut highp = Gpu::new(EsVersion::Es3);
    let opts = RenderOptions {
        exposure_ev: -15.0,
        linear: true,
        ..Default::default()
    };
    let lit_by = |intensity: f32| {
        let mut light = point(3.0);
        light.position = DVec3::new(0.0, 0.0, 0.5);
        light.color = Vec3::ONE;
        light.intensity = intensity;
        plane(vec![light])
    };
    for intensity in [2f32.powi(15), 2f32.powi(16)] {
        let s = lit_by(intensity);
        let exact = highp.render(&s, 64, 36, &opts);
        let lit = exact.pixels().filter(|p| p[0] > 100).count();
        assert!(
            lit > 30,
            "intensity {intensity:e}: {lit} pixels lit, too few to tell"
        );
        // Forward: the one method this tier runs (the others address textures in highp).
        let image = mediump.render(&s, 64, 36, &opts);
        let d = manylight::metrics::diff(&exact, &image).max_abs;
        assert!(d <= 3, "intensity {intensity:e}: {d} / 255 from highp");
    }
    let s = lit_by(2f32.powi(15));
    let want = radiance(&mut highp, &s);
    let near = want.iter().filter(|p| p[0] > 1000.0).count();
    assert!(near > 30, "{near} pixels near the light, too few to tell");
    let gap = relative_gap(&want, &radiance(&mut mediump, &s));
    assert!(gap <= 0.02, "radiance {gap} (relative) from highp's");
}

/// Without fragment highp the shader sums a pixel's light in fp16. At a positive exposure that
/// sum held raw radiance, and faint lights' shares (2·10⁻⁸ a pixel) rounded to nothing: eight
/// of them at +15 EV drew a 17/255 darker frame than highp's. Lights, a sun, the ambient and
/// emission now come pre-exposed, the exposure uniform taking the rest: each case draws what
/// highp draws (one left out of the pre-exposure would be 2¹⁵ too dark).
#[test]
fn faint_light_at_a_high_exposure_draws_as_with_highp() {
    let opts = RenderOptions {
        exposure_ev: 15.0,
        ..Default::default()
    };
    let mut ring = plane(
        (0..8)
            .map(|i| {
                let a = f64::from(i) * std::f64::consts::FRAC_PI_4;
                let at = DVec3::new(a.cos(), a.sin(), 2.0);
                Light::point(at, 100.0, Vec3::ONE, 1.5e-7)
            })
            .collect(),
    );
    ring.ambient = Vec3::ZERO;
    let mut sun = plane(vec![]);
    sun.ambient = Vec3::ZERO;
    let down = DVec3::new(0.3, 0.2, -1.0);
    sun.directional_lights = vec![scene::DirectionalLight::new(down, Vec3::ONE, 5e-7)];
    let mut glow = plane(vec![]);
    glow.ambient = Vec3::splat(3e-7);
    glow.materials[0].maps.emissive = Vec3::new(2e-7, 1e-7, 0.0);
    let cases = [("lights", ring), ("sun", sun), ("ambient, emission", glow)];
    draw_as_with_highp(&cases, &opts, |exact| {
        let brightest = exact.pixels().map(|p| p[0]).max().unwrap_or(0);
        (brightest > 10)
            .then_some(())
            .ok_or(format!("{brightest} / 255 at most"))
    });
}

/// Each of `cases` drawn without fragment highp is within 3/255 of its frame with highp
/// (ES 2.0, forward), once `shows` says that frame shows enough to tell (or why not).
fn draw_as_with_highp(
    cases: &[(&str, Scene)],
    opts: &RenderOptions,
    shows: impl Fn(&image::RgbaImage) -> Result<(), String>,
) {
    let mut mediump = Gpu::without_fragment_highp();
    let mut highp = Gpu::new(EsVersion::Es2);
    for (name, s) in cases {
        let exact = highp.render(s, 64, 36, opts);
        if let Err(why) = shows(&exact) {
            panic!("{name}: {why}, too dark to tell");
        }
        let image = mediump.render(s, 64, 36, opts);
        let d = manylight::metrics::diff(&exact, &image).max_abs;
        assert!(d <= 3, "{name}: {d} / 255 from highp");
    }
}

/// Sources at f32's largest radiance, which validation allows, at a positive exposure without
/// fragment highp: pre-exposed they passed f32 to infinity, whose fp16 form was NaN (a debug
/// build's assertion failed on the sun). Each draws as highp does, white where it shines.
#[test]
fn sources_at_f32s_largest_radiance_draw_at_a_positive_exposure() {
    let opts = RenderOptions {
        exposure_ev: 1.0,
        ..Default::default()
    };
    let mut light = point(3.0);
    light.color = Vec3::ONE;
    light.intensity = 3e38;
    let lit = plane(vec![light]);
    let mut sun = plane(vec![]);
    let down = DVec3::new(0.3, 0.2, -1.0);
    sun.directional_lights = vec![scene::DirectionalLight::new(down, Vec3::ONE, 3e38)];
    let mut glow = plane(vec![]);
    glow.ambient = Vec3::splat(3e38);
    glow.materials[0].maps.emissive = Vec3::splat(1024.0);
    let cases = [("light", lit), ("sun", sun), ("ambient, emission", glow)];
    draw_as_with_highp(&cases, &opts, |exact| {
        let m = mean(exact);
        (m > 20.0)
            .then_some(())
            .ok_or(format!("a mean of {m:.1} / 255"))
    });
}

/// A metal whose base colour is past glTF's [0, 1] (the loaders take up to 1 024): its Fresnel
/// reflectance F0 grew with it, and times the capped lobe went past fp16, Inf, then NaN where
/// the falloff or spot was 0 (black holes without fragment highp). F0 now stays at most 1, and
/// the no-highp frame is what highp draws, highlight included.
#[test]
fn a_metal_brighter_than_white_stays_finite_and_equals_highp() {
    let mut mediump = Gpu::without_fragment_highp();
    let mut highp = Gpu::new(EsVersion::Es3);
    let opts = RenderOptions {
        linear: true,
        ..Default::default()
    };
    let mut light = point(3.0);
    light.position = DVec3::new(-1.0, 0.5, 1.0);
    light.color = Vec3::ONE;
    // A spot turned sideways: the mirror peak below it lies outside its cone (spot 0).
    let cone = manylight::Cone {
        direction: DVec3::X,
        inner_deg: 20.0,
        outer_deg: 30.0,
    };
    let spot = Light::spot(DVec3::new(0.0, 0.0, 1.0), 10.0, Vec3::ONE, 1.0, cone);
    let mut s = plane(vec![light, spot]);
    s.camera = Camera::perspective(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, 60.0, 0.1, 50.0);
    s.ambient = Vec3::ZERO;
    s.materials[0] = manylight::Material::metallic_roughness("hot", Vec3::splat(1024.0), 1.0, 0.2);
    let exact = highp.render(&s, 64, 36, &opts);
    let lit = exact.pixels().filter(|p| p[0] > 20).count();
    assert!(lit > 4, "{lit} pixels lit, too few to tell");
    let image = mediump.render(&s, 64, 36, &opts);
    let d = manylight::metrics::diff(&exact, &image).max_abs;
    assert!(d <= 3, "{d} / 255 from highp");
}

/// Without fragment highp a light's fp16 scale `k` went past fp16 for radiance past 2³²
/// (k = 2¹⁶): read as infinity, every pixel the light reached was drawn at the shader's cap,
/// white at any exposure. Radiance is now taken as 2³⁰ there (k ≤ 2¹⁵), as a sun's always
/// was, with a warning: the frame's radiance (not pre-exposed, where the cap is reached; a
/// frame at an exposure takes it as 2³⁰ of what is shown) is highp's of that light at 2³⁰.
#[test]
fn a_light_past_what_fp16_radiance_holds_is_drawn_at_that_limit_with_a_warning() {
    // A device played without float textures (the RGBA8 child off Mesa: SwiftShader, ANGLE)
    // has no float render targets either, so no HDR frame to read the cap from; Mesa's child
    // loses float textures alone and runs it.
    if common::child::plays_rgba8_lights() {
        return;
    }
    common::warnings::install();
    let mut mediump = Gpu::without_fragment_highp();
    // ES 2.0, which Mesa still offers without float textures (the RGBA8 child).
    let mut highp = Gpu::new(EsVersion::Es2);
    let light = |intensity: f32| {
        let mut l = point(2000.0);
        l.position = DVec3::new(0.0, 0.0, 330.0);
        l.color = Vec3::ONE;
        l.intensity = intensity;
        l
    };
    let capped = radiance(&mut highp, &plane(vec![light(2f32.powi(30))]));
    let lit = capped.iter().filter(|p| (2e3..6e4).contains(&p[0])).count();
    assert!(lit > 500, "{lit} pixels in the middle, too few to tell");
    let (image, stats) = mediump
        .r()
        .render_offscreen_hdr(&plane(vec![light(1e10)]), 64, 36, &Default::default())
        .unwrap();
    let rgba8 = common::child::rgba8_lights();
    assert_eq!(
        stats.lights.encoding == manylight::LightEncoding::Rgba8,
        rgba8
    );
    let gap = relative_gap(&capped, &image);
    assert!(gap <= 0.02, "{gap} (relative) from highp's radiance at 2³⁰");
    // This light's warning (other tests' renderers may say it of their own lights).
    let said = common::warnings::warnings_containing("is past 2³⁰");
    let this = |w: &&String| w.contains("10000000000.0");
    assert_eq!(said.iter().filter(this).count(), 1, "{said:?}");
    assert!(said
        .iter()
        .filter(this)
        .all(|w| w.starts_with("lights[0]:")));
}

/// The test above with RGBA8 light records (no `GL_OES_texture_float`), whose shader splits
/// the shared exponent into `k` itself, in a child process (on Mesa; elsewhere the child has
/// no HDR output to read the cap from).
#[test]
fn a_light_past_what_fp16_radiance_holds_in_rgba8_records_too() {
    common::child::rerun_with_rgba8_lights(
        "a_light_past_what_fp16_radiance_holds_is_drawn_at_that_limit_with_a_warning",
    );
}

/// Without fragment highp the ambient uniform and its term are fp16: an ambient past 65 504
/// read as infinity, white at any exposure through a tone map (and NaN where a texture or the
/// occlusion is 0). Ambient is now capped at 60 000 a channel there, with a warning: the
/// frame's radiance (not pre-exposed) is highp's at an ambient of 60 000.
#[test]
fn an_ambient_past_fp16_is_drawn_at_the_fp16_cap_with_a_warning() {
    common::warnings::install();
    let mut mediump = Gpu::without_fragment_highp();
    let mut highp = Gpu::new(EsVersion::Es2);
    let with_ambient = |a: f32| {
        let mut s = plane(vec![]);
        s.ambient = Vec3::splat(a);
        s
    };
    let capped = radiance(&mut highp, &with_ambient(60_000.0));
    let exact = radiance(&mut highp, &with_ambient(1e6));
    // The uncapped frame holds at least 65 504 (an fp16 target's largest value), the cap 48 000.
    assert!(relative_gap(&capped, &exact) > 0.25, "the cap shows");
    let said = || common::warnings::warnings_containing("the ambient term holds").len();
    let before = said();
    let gap = relative_gap(&capped, &radiance(&mut mediump, &with_ambient(1e6)));
    assert!(
        gap <= 0.02,
        "{gap} (relative) from highp's radiance at the cap"
    );
    assert_eq!(said(), before + 1, "said once");
    radiance(&mut mediump, &with_ambient(1e6));
    assert_eq!(said(), before + 1, "said once a renderer");
    // A diffuse factor past 1 (up to MAX_COLOR_FACTOR) takes the term past fp16 from a valid
    // ambient: 1 000 × 100 is drawn as a term of 60 000, highp's at an ambient of 600.
    let bright = |a: f32| {
        let mut s = with_ambient(a);
        s.materials[0].diffuse = Vec3::splat(100.0);
        s.materials[0].specular = Vec3::ZERO;
        s
    };
    let capped = radiance(&mut highp, &bright(600.0));
    let gap = relative_gap(&capped, &radiance(&mut mediump, &bright(1000.0)));
    assert!(
        gap <= 0.02,
        "{gap} (relative) from highp's radiance at the term's cap"
    );
}

/// An ambient × albedo past f32 on a surface its occlusion map darkens to nothing: the map
/// scales the albedo before the ambient multiplies it, so such a texel shows its lights
/// alone, as the light model says (∞ · 0 was NaN: black in every method).
#[test]
fn an_ambient_past_f32_on_a_fully_occluded_surface_leaves_its_lights() {
    let lit = common::occluded_quad(8.0, &[0], 0.0);
    let mut huge = lit.clone();
    huge.ambient = Vec3::splat(1e38);
    let opts = RenderOptions::default();
    common::each_method(|es, method, gpu| {
        let want = gpu.render(&lit, 64, 36, &opts);
        assert!(mean(&want) > 5.0, "the lights show");
        let got = gpu.render(&huge, 64, 36, &opts);
        let d = manylight::metrics::diff(&want, &got).max_abs;
        assert!(d <= 1, "{es} {method}: {d} / 255 from the lights alone");
    });
}

/// Without fragment highp the sum of a pixel's lights is fp16 too: eight lights each at the
/// shader's per-light cap summed past 65 504 to infinity, white at any exposure. Pre-exposed
/// (−5 EV), such a sum is white anyway, so the frame through a tone map is highp's. (The
/// shader still caps the sum at 65 504, against a tone map's ∞/∞; llvmpipe and SwiftShader
/// draw this frame white without the cap too.)
#[test]
fn a_light_sum_past_fp16_draws_as_with_highp() {
    let mut mediump = Gpu::without_fragment_highp();
    let mut highp = Gpu::new(EsVersion::Es2);
    let lights = (0..8)
        .map(|i| {
            let mut l = point(1000.0);
            l.position = DVec3::new(0.1 * i as f64 - 0.35, 0.0, 1.0);
            l.color = Vec3::ONE;
            l.intensity = 2f32.powi(29);
            l
        })
        .collect();
    let mut bright = plane(lights);
    bright.ambient = Vec3::ZERO;
    let opts = RenderOptions {
        exposure_ev: -5.0,
        tone_map: manylight::ToneMap::Reinhard,
        linear: true,
        ..Default::default()
    };
    let want = highp.render(&bright, 64, 36, &opts);
    let white = want.pixels().filter(|p| p[0] == 255).count();
    assert!(white > 64 * 36 / 2, "{white} pixels white, too few to tell");
    let d = manylight::metrics::diff(&want, &mediump.render(&bright, 64, 36, &opts)).max_abs;
    assert!(d <= 3, "{d} / 255 from highp");
}

/// A frame's radiance, with no exposure (`render_offscreen_hdr`): nothing is pre-exposed, so
/// the no-highp tier's fp16 caps apply to the radiance itself.
fn radiance(gpu: &mut Gpu, s: &Scene) -> Vec<[f32; 4]> {
    let options = RenderOptions::default();
    gpu.r().render_offscreen_hdr(s, 64, 36, &options).unwrap().0
}

/// The largest gap of `got`'s radiance from `want`'s over every pixel's colour channels,
/// relative to `want`'s brightest channel (the scale at which the frame shows); NaN where
/// `got` has one.
fn relative_gap(want: &[[f32; 4]], got: &[[f32; 4]]) -> f32 {
    assert_eq!(want.len(), got.len());
    let brightest = want
        .iter()
        .flat_map(|p| &p[..3])
        .fold(0f32, |a, &b| a.max(b));
    assert!(brightest > 0.0, "nothing to compare");
    let gaps = (want.iter().zip(got)).flat_map(|(w, g)| (0..3).map(move |c| (g[c] - w[c]).abs()));
    let most = gaps.fold(0.0, |most, gap| {
        if gap.is_nan() || gap > most {
            gap
        } else {
            most
        }
    });
    most / brightest
}
