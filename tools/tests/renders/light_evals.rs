//! Light-evaluation counts (the papers' efficiency metric): what each method loops over per
//! pixel, checked against the lower bound (lights that really reach the pixel) pixel by pixel,
//! against the cluster lists on the CPU, and against each other.

use crate::common;

use common::Gpu;
use manylight::renderer::{CountKind, LightCounts};
use manylight::scene::{self, Scene};
use manylight::{EsVersion, RenderOptions};

fn counts(gpu: &mut Gpu, scene: &Scene, method: &str, kind: CountKind) -> LightCounts {
    gpu.r().set_method_named(method).unwrap();
    gpu.r()
        .render_light_counts(scene, 256, 144, &RenderOptions::default(), kind)
        .unwrap_or_else(|e| panic!("{method} {kind:?}: {e}"))
        .0
}

/// Conservative culling means no method evaluates fewer lights at a pixel than reach it; and
/// forward evaluates every light everywhere.
#[test]
fn every_method_evaluates_at_least_the_lights_that_reach_each_pixel() {
    for (name, lights) in [("courtyard", 256), ("pillars", 1024), ("bubbles", 64)] {
        let scene = scene::builtin::build(name, Some((lights, 5))).unwrap();
        for es in [EsVersion::Es2, EsVersion::Es3] {
            let mut gpu = Gpu::new(es);
            let bound = counts(&mut gpu, &scene, "forward", CountKind::Reaching);
            assert!(
                bound.covered_pixels() > 1000,
                "{name}: the view shows little"
            );
            assert!(bound.total() > 0, "{name}: no light reaches anything");
            let methods: &[&str] = match es {
                EsVersion::Es2 => &["forward", "tiled", "clustered"],
                EsVersion::Es3 => &["forward", "tiled", "clustered", "deferred"],
            };
            for &method in methods {
                let evals = counts(&mut gpu, &scene, method, CountKind::Evals);
                assert_eq!(
                    evals.covered, bound.covered,
                    "{name} {es} {method}: coverage"
                );
                for (i, (&e, &b)) in evals.counts.iter().zip(&bound.counts).enumerate() {
                    assert!(
                        e >= b,
                        "{name} {es} {method}: pixel {i} evaluates {e} lights, {b} reach it"
                    );
                }
                if method == "forward" {
                    assert!(
                        evals
                            .counts
                            .iter()
                            .zip(&evals.covered)
                            .all(|(&n, &c)| !c || n as usize == lights),
                        "{name} {es}: forward evaluates every light at every covered pixel"
                    );
                }
                eprintln!(
                    "{name} {es} {method}: {:.1} evals per pixel (max {}), bound {:.1}",
                    evals.mean(),
                    evals.max(),
                    bound.mean()
                );
            }
        }
    }
}

/// `Reaching` counts are a plain-forward pass's whatever the method, through
/// `render_offscreen` too: under tiled, clustered, deferred and auto (past its forward
/// threshold) it gave the colour frame, which decodes as counts as well.
#[test]
fn reaching_counts_are_forwards_whatever_the_method_and_the_call() {
    let scene = scene::builtin::build("courtyard", Some((256, 5))).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let bound = counts(&mut gpu, &scene, "forward", CountKind::Reaching);
    let options = RenderOptions {
        count: CountKind::Reaching,
        clear_color: [0.0; 4],
        ..RenderOptions::default()
    };
    for method in ["forward", "tiled", "clustered", "deferred", "auto"] {
        gpu.r().set_method_named(method).unwrap();
        let (image, stats) = gpu
            .r()
            .render_offscreen(&scene, 256, 144, &options)
            .unwrap_or_else(|e| panic!("{method}: {e}"));
        let drawn = LightCounts::decode(&image);
        let differing = (drawn.counts.iter().zip(&bound.counts)).filter(|(a, b)| a != b);
        assert_eq!(
            differing.count(),
            0,
            "{method}: pixels not forward's counts"
        );
        assert_eq!(stats.method, "forward", "{method}");
        // The frame after is the method's own colour again.
        let (_, stats) = gpu
            .r()
            .render_offscreen(&scene, 256, 144, &RenderOptions::default())
            .unwrap();
        assert_eq!(stats.method, method);
    }
}

/// The papers' result: on a scene of many small lights, clustered evaluates no more lights
/// than tiled, and far fewer than forward.
#[test]
fn clustered_evaluates_fewer_lights_than_tiled_and_far_fewer_than_forward() {
    let scene = scene::builtin::build("pillars", Some((1024, 1))).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let total = |gpu: &mut Gpu, m| counts(gpu, &scene, m, CountKind::Evals).total();
    let (forward, tiled, clustered) = (
        total(&mut gpu, "forward"),
        total(&mut gpu, "tiled"),
        total(&mut gpu, "clustered"),
    );
    eprintln!("pillars, 1024 lights: forward {forward}, tiled {tiled}, clustered {clustered}");
    assert!(clustered <= tiled, "clustered {clustered} > tiled {tiled}");
    assert!(
        clustered * 10 < forward,
        "clustered {clustered} is not far below forward {forward}"
    );
}

/// The evaluation counts the shader writes are the lengths of the cell lists the CPU built:
/// at sampled pixels, the surface point found by a CPU ray cast gives the cell, and its list
/// length must equal the GPU's count. Pixels whose point lies within float rounding of a cell
/// boundary (where CPU and GPU may rightly pick neighbours) are skipped.
#[test]
fn counts_equal_the_cpu_cluster_lists_at_sampled_pixels() {
    use manylight::metrics::cpu_reference;
    use manylight::scene::raycast::{pixel_ray, SceneRaycaster};
    let scene = scene::builtin::build("pillars", Some((512, 3))).unwrap();
    let (w, h) = (256u32, 144u32);
    let caster = SceneRaycaster::new(&scene);
    let view = scene.camera.view_matrix();
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::new(es);
        let subpixel_bits = gpu.r().caps().subpixel_bits;
        for method in ["tiled", "clustered"] {
            let gpu_counts = counts(&mut gpu, &scene, method, CountKind::Evals);
            let (grid, lists) = gpu.r().last_light_lists().expect("lists of the last frame");
            let (mut checked, mut nonzero) = (0, 0);
            // The rasterizer shades a fragment at a point up to its vertex snapping away from
            // the pixel centre's ray: pixels whose cell or surface changes within that reach
            // (cell boundaries, silhouettes) are not the lists' to answer for.
            let reach = cpu_reference::snapping_reach(subpixel_bits);
            for y in (0..h).step_by(5) {
                for x in (0..w).step_by(5) {
                    // The cell (and surface) a ray through sub-pixel point (x + dx, y + dy) finds.
                    let cell_at = |dx: f64, dy: f64, widen: f64| {
                        let (cx, cy) = (x as f64 + 0.5 + dx, y as f64 + 0.5 + dy);
                        let (o, d) = pixel_ray(&scene.camera, w, h, cx, cy);
                        let hit = caster.hit(o, d)?;
                        let depth = -view.transform_point3(hit.position).z * widen;
                        // GL window coordinates count rows from the bottom.
                        let cell = grid.cell_of_fragment(cx, h as f64 - cy, depth);
                        Some((grid.cell_index(cell), hit.object))
                    };
                    let Some(here) = cell_at(0.0, 0.0, 1.0) else {
                        continue;
                    };
                    let around = [
                        (reach, 0.0, 1.0),
                        (-reach, 0.0, 1.0),
                        (0.0, reach, 1.0),
                        (0.0, -reach, 1.0),
                        (0.0, 0.0, 1.0 + 1e-5),
                        (0.0, 0.0, 1.0 - 1e-5),
                    ];
                    if around
                        .iter()
                        .any(|&(dx, dy, k)| cell_at(dx, dy, k) != Some(here))
                    {
                        continue;
                    }
                    let (here, _) = here;
                    let expected = lists.counts[here as usize];
                    assert_eq!(
                        gpu_counts.at(x, y),
                        Some(expected),
                        "{es} {method}: pixel ({x}, {y}) in cell {here}"
                    );
                    checked += 1;
                    nonzero += usize::from(expected > 0);
                }
            }
            assert!(
                checked > 800 && nonzero > 400,
                "{es} {method}: only {checked} pixels checked ({nonzero} with lights)"
            );
        }
    }
}

/// Lights a CPU finds reaching `p` (world space): within the radius and, for a spot, the
/// cone; `grow` (±) widens or narrows both, by a fraction of the radius and an angle in
/// degrees, so that lights within rounding of either edge count in one bound only.
fn reaching_on_the_cpu(lights: &[manylight::scene::Light], p: glam::DVec3, grow: f64) -> u32 {
    use manylight::scene::LightKind;
    let mut n = 0;
    for l in lights {
        let to_p = p - l.position;
        let d = to_p.length();
        if d >= l.radius as f64 * (1.0 + 2e-3 * grow) {
            continue;
        }
        if let LightKind::Spot {
            direction,
            outer_deg,
            ..
        } = l.kind
        {
            if outer_deg < 90.0 && d < 1e-9 {
                // At the apex the direction to the point is undefined.
                n += u32::from(grow > 0.0);
                continue;
            }
            let angle = to_p.angle_between(direction).to_degrees();
            // A sharp edge fades just past the outer angle (at most 1e-4 of 1 − cos: 0.81°).
            let edge = outer_deg + if grow > 0.0 { 0.85 } else { 0.0 };
            if d > 1e-9 && angle >= edge + 0.3 * grow {
                continue;
            }
        }
        n += 1;
    }
    n
}

/// The reaching counts (the lower bound every method is checked against above) are what the
/// light model says: at sampled pixels the surface point a CPU ray cast finds is reached by as
/// many lights as the GPU counted, within the rounding of each light's radius and cone.
#[test]
fn reaching_counts_equal_a_cpu_count_at_sampled_pixels() {
    use manylight::scene::raycast::{pixel_ray, SceneRaycaster};
    let (w, h) = (256u32, 144u32);
    for (name, lights) in [("courtyard", 256), ("pillars", 512)] {
        let scene = scene::builtin::build(name, Some((lights, 5))).unwrap();
        let spots = scene
            .lights
            .iter()
            .filter(|l| matches!(l.kind, manylight::scene::LightKind::Spot { .. }))
            .count();
        let caster = SceneRaycaster::new(&scene);
        for es in [EsVersion::Es2, EsVersion::Es3] {
            let mut gpu = Gpu::new(es);
            let gpu_counts = counts(&mut gpu, &scene, "forward", CountKind::Reaching);
            let (mut checked, mut lit, mut tight) = (0, 0, 0);
            for y in (0..h).step_by(3) {
                for x in (0..w).step_by(3) {
                    // The surface at the pixel's centre, and the same one at about the same depth a
                    // little either side (not a silhouette, where the rasterizer may pick the
                    // surface behind).
                    let hit_at = |dx: f64, dy: f64| {
                        let (o, d) = pixel_ray(
                            &scene.camera,
                            w,
                            h,
                            x as f64 + 0.5 + dx,
                            y as f64 + 0.5 + dy,
                        );
                        caster.hit(o, d)
                    };
                    let Some(hit) = hit_at(0.0, 0.0) else {
                        continue;
                    };
                    let same = [(0.3, 0.0), (-0.3, 0.0), (0.0, 0.3), (0.0, -0.3)]
                        .iter()
                        .all(|&(dx, dy)| {
                            hit_at(dx, dy).is_some_and(|o| {
                                o.object == hit.object && (o.t - hit.t).abs() < 1e-2 * hit.t
                            })
                        });
                    if !same {
                        continue;
                    }
                    let (lo, hi) = (
                        reaching_on_the_cpu(&scene.lights, hit.position, -1.0),
                        reaching_on_the_cpu(&scene.lights, hit.position, 1.0),
                    );
                    let got = gpu_counts.at(x, y).expect("in the image");

                    assert!(
                    (lo..=hi).contains(&got),
                    "{name} {es}: pixel ({x}, {y}) at {}: the GPU counts {got} lights reaching, the CPU {lo}..={hi}",
                    hit.position
                );
                    checked += 1;
                    lit += usize::from(lo > 0);
                    tight += usize::from(lo == hi);
                }
            }
            eprintln!("{name} {es}: {checked} pixels checked, {lit} reached, {tight} without an edge; {spots} spots");
            assert!(
                checked > 2000 && lit * 4 > checked && tight * 10 > checked * 9,
                "{name} {es}: {checked} pixels checked, {lit} reached, {tight} without an edge"
            );
        }
    }
}

/// Deferred's proxies skip the surfaces a light cannot reach: a sphere behind the wall by its
/// near side, a sphere around the eye by its far side — which replaced a full-screen pass, so
/// a light around the eye short of the wall now evaluates nowhere, and one reaching the wall
/// evaluates where it reaches, not at every pixel. Where the implementation loses triangles
/// crossing the eye's plane (SwiftShader), a sphere around the eye is bounded by a plane at
/// its far end instead: short of the wall it still evaluates nowhere; reaching it, everywhere
/// on it.
#[test]
fn deferred_proxies_skip_what_a_light_cannot_reach_and_need_no_full_screen_pass_near_the_eye() {
    use glam::{DVec3, Vec3};
    use manylight::scene::Light;
    let base = scene::builtin::build("plane", None).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    // The camera is at z = 5 looking at the plane z = 0; near 0.1.
    let cases = [
        ("behind the wall", DVec3::new(0.5, 0.3, -2.0), 1.5, false),
        (
            "around the eye, short of the wall",
            DVec3::new(0.0, 0.0, 4.8),
            3.0,
            false,
        ),
        (
            "around the eye, reaching the wall",
            DVec3::new(0.0, 0.0, 4.8),
            5.2,
            true,
        ),
    ];
    for (name, position, radius, reaches) in cases {
        let mut scene = base.clone();
        scene.lights = vec![Light::point(position, radius, Vec3::ONE, 1.0)];
        let bound = counts(&mut gpu, &scene, "forward", CountKind::Reaching);
        let evals = counts(&mut gpu, &scene, "deferred", CountKind::Evals);
        assert!(
            bound.covered_pixels() > 30_000,
            "{name}: the wall fills the view"
        );
        assert_eq!(bound.total() > 0, reaches, "{name}: reaching pixels");
        let plane_bound = gpu.r().caps().loses_triangles_crossing_the_eye_plane();
        if reaches && plane_bound {
            assert_eq!(evals.total() as usize, evals.covered_pixels(), "{name}");
        } else if reaches {
            assert!(evals.total() >= bound.total(), "{name}");
            assert!(
                (evals.total() as usize) < evals.covered_pixels() * 3 / 4,
                "{name}: {} of {} pixels evaluated (a full-screen pass?)",
                evals.total(),
                evals.covered_pixels()
            );
        } else {
            assert_eq!(evals.total(), 0, "{name}: evaluated where it cannot reach");
        }
    }
}

/// The per-slice, per-row coverage never makes a pixel evaluate more lights than the
/// per-cascade rectangle of earlier versions with the same grid, and saves many evaluations
/// overall (tiled and clustered, each fixed footprint).
#[test]
fn tight_coverage_never_evaluates_more_than_the_cascade_box() {
    use manylight::cluster::grid::{Coverage, GridConfig};
    let scene = scene::builtin::build("courtyard", Some((1024, 3))).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    for (method, footprint) in [("clustered", 64.0), ("clustered", 16.0), ("tiled", 16.0)] {
        gpu.r().set_method_named(method).unwrap();
        let evals = |gpu: &mut Gpu, coverage| {
            let options = RenderOptions {
                grid: GridConfig {
                    measure: manylight::GridMeasure {
                        coverage,
                        ..Default::default()
                    },
                    ..GridConfig::fixed(footprint)
                },
                tile_px: footprint,
                ..RenderOptions::default()
            };
            gpu.r()
                .render_light_counts(&scene, 256, 144, &options, CountKind::Evals)
                .unwrap()
                .0
        };
        let tight = evals(&mut gpu, Coverage::SliceRows);
        let loose = evals(&mut gpu, Coverage::CascadeBox);
        for (i, (&t, &l)) in tight.counts.iter().zip(&loose.counts).enumerate() {
            assert!(t <= l, "{method} {footprint}: pixel {i}: {t} against {l}");
        }
        // At 256×144 a 64-pixel footprint leaves 4 × 3 tiles (most lights then cover at most
        // 2 × 2 cells, which are not trimmed), and tiles span every depth: less to cut there.
        let saved = match (method, footprint) {
            ("clustered", f) if f < 64.0 => 0.85,
            _ => 0.99,
        };
        assert!(
            (tight.total() as f64) < loose.total() as f64 * saved,
            "{method} {footprint}: {} evaluations against {}",
            tight.total(),
            loose.total()
        );
        eprintln!(
            "{method} {footprint}: {} evaluations against {}",
            tight.total(),
            loose.total()
        );
    }
}

/// Without fragment highp every shader float is mediump (fp16 on llvmpipe, as on a Mali-400):
/// the count encoder divided by 65 536, past fp16, and every count read back 0. Forward's
/// counts there are every light at every covered pixel, as with highp.
#[test]
fn counts_without_fragment_highp_are_every_light_at_every_pixel() {
    let lights = 300;
    let scene = scene::builtin::build("courtyard", Some((lights, 5))).unwrap();
    let mut gpu = Gpu::without_fragment_highp();
    let evals = counts(&mut gpu, &scene, "forward", CountKind::Evals);
    assert!(evals.covered_pixels() > 1000, "the view shows little");
    let wrong = (evals.counts.iter().zip(&evals.covered))
        .filter(|&(&n, &c)| c && n as usize != lights)
        .count();
    assert_eq!(wrong, 0, "covered pixels whose count is not {lights}");
}
