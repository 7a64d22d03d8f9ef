//! Lights that move: a frame depends on its time only (rendered in sequence or alone, the same
//! picture), and the culled methods still equal plain forward on frames where lights cross
//! cells, the near plane, the camera and the frustum sides.

use crate::common;

use common::Gpu;
use glam::{DVec3, Vec3};
use manylight::cluster::grid::GridConfig;
use manylight::metrics::diff;
use manylight::scene::motion::{Bob, Motion, Orbit, OrbitAbout};
use manylight::scene::{self, Light, Scene};
use manylight::{EsVersion, RenderOptions};

const W: u32 = 256;
const H: u32 = 144;
const FPS: f64 = 4.0;

/// The courtyard's random lights before the crossing ones: enough to fill the cells, few
/// enough that forward over all of them on every frame stays quick on a software GPU.
const RANDOM_LIGHTS: usize = 64;

/// The courtyard's lively random lights plus lights that go round the camera and through it.
fn scene_with_lights_crossing_the_camera() -> Scene {
    let mut scene = scene::builtin::build("courtyard", Some((RANDOM_LIGHTS, 21))).unwrap();
    let cam = scene.camera;
    let forward = (cam.target - cam.position).normalize();
    // Round the eye, 1.5 m out: in front, at the sides, behind; their spheres hold the eye,
    // so they straddle the near plane on every frame.
    for (i, hue) in [Vec3::new(1.0, 0.4, 0.2), Vec3::new(0.2, 0.6, 1.0)]
        .into_iter()
        .enumerate()
    {
        scene.lights.push(Light::point(
            cam.position + forward * 1.5 + DVec3::Y * (i as f64 - 0.5),
            3.5,
            hue,
            2.0,
        ));
        scene.animate_light(
            scene.lights.len() - 1,
            Motion {
                orbit: Some(Orbit {
                    about: OrbitAbout::Point(cam.position),
                    axis: if i == 0 { DVec3::Y } else { DVec3::NEG_Y },
                    period_s: 3.0 + i as f64,
                    phase_deg: 0.0,
                }),
                ..Motion::default()
            },
        );
    }
    // Along the view axis through the eye: from 4 m in front to 4 m behind and back.
    scene.lights.push(Light::spot(
        cam.position + forward * 4.0,
        5.0,
        Vec3::new(0.9, 1.0, 0.6),
        3.0,
        manylight::Cone {
            direction: DVec3::new(0.2, -1.0, 0.1),
            inner_deg: 20.0,
            outer_deg: 45.0,
        },
    ));
    scene.animate_light(
        scene.lights.len() - 1,
        Motion {
            bob: Some(Bob {
                amplitude: -forward * 4.0,
                period_s: 2.5,
                phase_deg: 0.0,
            }),
            ..Motion::default()
        },
    );
    scene.validate().unwrap();
    scene
}

fn time_of(k: u32) -> f64 {
    f64::from(k) / FPS
}

fn fixed_grid() -> RenderOptions {
    RenderOptions {
        grid: GridConfig::fixed(24.0),
        ..RenderOptions::default()
    }
}

#[test]
fn a_frame_is_the_same_rendered_in_sequence_or_alone() {
    let k = 7;
    let mut sequence = Gpu::new(EsVersion::Es3);
    let mut alone = Gpu::new(EsVersion::Es3);
    for method in ["forward", "tiled", "clustered"] {
        sequence.r().set_method_named(method).unwrap();
        alone.r().set_method_named(method).unwrap();
        let mut scene = scene_with_lights_crossing_the_camera();
        let mut in_sequence = None;
        for frame in 0..=k {
            scene.set_time(time_of(frame));
            let image = sequence.render(&scene, W, H, &fixed_grid());
            if frame == k {
                in_sequence = Some(image);
            }
        }
        let mut fresh = scene_with_lights_crossing_the_camera();
        fresh.set_time(time_of(k));
        assert_eq!(
            fresh.lights, scene.lights,
            "the pose at t depends on t only"
        );
        let on_its_own = alone.render(&fresh, W, H, &fixed_grid());
        let d = diff(in_sequence.as_ref().unwrap(), &on_its_own);
        eprintln!(
            "{method}: frame {k} in sequence vs alone: max {}",
            d.max_abs
        );
        assert_eq!(d.max_abs, 0, "{method}: frame {k} differs");
        // And the frame is not the first one: the lights did move.
        let mut still = scene_with_lights_crossing_the_camera();
        still.set_time(0.0);
        let first = alone.render(&still, W, H, &fixed_grid());
        assert!(
            diff(&first, &on_its_own).max_abs > 20,
            "{method}: nothing moved"
        );
    }
}

/// Where the crossing lights are relative to the camera on frame `k`: (some sphere straddles
/// the near plane, some centre is behind the eye, centres in view).
fn crossings(scene: &Scene) -> (bool, bool, usize) {
    let view = scene.camera.view_matrix();
    let (near, _) = scene.camera.near_far();
    let proj = scene.camera.projection_matrix(f64::from(W) / f64::from(H));
    let (mut straddles, mut behind, mut in_view) = (false, false, 0);
    for l in &scene.lights[RANDOM_LIGHTS..] {
        let v = view.transform_point3(l.position);
        let depth = -v.z;
        straddles |= (depth - near).abs() < f64::from(l.radius);
        behind |= depth < 0.0;
        let clip = proj * v.extend(1.0);
        if depth > near && (clip.truncate() / clip.w).abs().max_element() <= 1.0 {
            in_view += 1;
        }
    }
    (straddles, behind, in_view)
}

#[test]
fn culled_methods_match_forward_on_moving_frames() {
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::new(es);
        let mut scene = scene_with_lights_crossing_the_camera();
        let (mut seen_behind, mut seen_in_view, mut seen_out_of_view) = (false, false, false);
        let methods: &[&str] = match es {
            EsVersion::Es2 => &["tiled", "clustered"],
            EsVersion::Es3 => &["tiled", "clustered", "deferred"],
        };
        for k in 0..10 {
            scene.set_time(time_of(k));
            let (straddles, behind, in_view) = crossings(&scene);
            assert!(straddles, "frame {k}: the eye-orbit lights hold the eye");
            seen_behind |= behind;
            seen_in_view |= in_view > 0;
            seen_out_of_view |= in_view < 3;
            gpu.r().set_method_named("forward").unwrap();
            let reference = gpu.render(&scene, W, H, &RenderOptions::default());
            // The automatic grid and a fixed one take turns, five poses each: half the culled
            // renders, a software GPU's slow part.
            let opts = if k % 2 == 0 {
                RenderOptions::default()
            } else {
                fixed_grid()
            };
            for method in methods {
                gpu.r().set_method_named(method).unwrap();
                let (image, stats) = gpu.r().render_offscreen(&scene, W, H, &opts).unwrap();
                let d = diff(&reference, &image);
                assert!(
                    d.max_abs <= 2,
                    "{es} frame {k} {method}: max error {} > 2/255 against forward",
                    d.max_abs
                );
                assert_eq!(stats.lights.overflowed, 0);
            }
        }
        // The test covers what it says: lights went behind the eye, into view and out of it.
        assert!(seen_behind && seen_in_view && seen_out_of_view);
    }
}

#[test]
fn built_in_scenes_move_and_start_where_they_were_built() {
    for name in scene::builtin::NAMES {
        let built = scene::builtin::build(name, Some((64, 3))).unwrap();
        assert!(built.is_animated(), "{name} has no motion");
        let mut posed = built.clone();
        posed.set_time(0.0);
        for (a, b) in posed.lights.iter().zip(&built.lights) {
            assert!(
                (a.position - b.position).length() < 1e-9,
                "{name}: t = 0 moved"
            );
        }
        posed.set_time(2.0);
        let moved = posed
            .lights
            .iter()
            .zip(&built.lights)
            .filter(|(a, b)| (a.position - b.position).length() > 0.05)
            .count();
        assert!(moved > 48, "{name}: only {moved} of 64 lights moved");
        posed.validate().unwrap();
    }
}

/// A game removing a light with `Scene::remove_light` keeps every other light's motion (a
/// varied set included); lights cut off `lights` alone leave tracks that would pose whatever
/// takes their places, an error pointing at `remove_light`.
#[test]
fn removing_a_light_keeps_the_others_moving_as_before() {
    let lights = manylight::RandomLights { count: 16, seed: 3 };
    let original = manylight::builtin_scene("courtyard", Some(lights)).unwrap();
    assert!(original.is_animated());
    let mut scene = original.clone();
    assert!(scene.remove_light(5).is_some());
    assert_eq!(scene.lights.len(), 15);
    scene.validate().unwrap();
    let mut reference = original.clone();
    for t in [0.0, 1.3, 7.9] {
        scene.set_time(t);
        reference.set_time(t);
        let others: Vec<_> = (reference.lights.iter().enumerate())
            .filter(|&(i, _)| i != 5)
            .map(|(_, l)| *l)
            .collect();
        assert_eq!(scene.lights, others, "t = {t}");
    }
    assert!(scene.remove_light(15).is_none());
    let mut cut = scene.clone();
    cut.lights.truncate(10);
    let err = cut.validate().unwrap_err().to_string();
    assert!(err.contains("remove_light"), "{err}");
    while scene.lights.len() > 10 {
        scene.remove_light(scene.lights.len() - 1);
    }
    scene.validate().unwrap();
    scene.set_time(2.0);
}
