//! Tiled and clustered images against plain forward over all lights (the oracle), pixel by
//! pixel, on ES 2.0 and ES 3.0 contexts, and the overflow policy under a real render.

use crate::common;

use common::warnings::warnings_containing;
use common::Gpu;
use glam::{DVec3, Vec3};
use manylight::metrics::diff;
use manylight::scene::{self, Light};
use manylight::{EsVersion, RenderOptions};

const W: u32 = 256;
const H: u32 = 144;

#[test]
fn tiled_and_clustered_match_forward_within_2_of_255() {
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::new(es);
        for name in ["courtyard", "pillars"] {
            // Linear output changes only the last step, the encoding, whatever the lights: the
            // smaller count checks it. Forward over 1 024 lights at every pixel is a software
            // GPU's slow part: that case (lights on several rows of the light texture, long
            // lists) takes a quarter of the pixels.
            let cases = [
                (64, &[false, true][..], (W, H)),
                (1024, &[false][..], (W / 2, H / 2)),
            ];
            for (lights, encodings, (w, h)) in cases {
                let scene = scene::builtin::build(name, Some((lights, 11))).unwrap();
                for &linear in encodings {
                    let opts = RenderOptions {
                        linear,
                        ..Default::default()
                    };
                    let (reference, _) = gpu.render_with("forward", &scene, (w, h), &opts);
                    for method in ["tiled", "clustered"] {
                        let (img, stats) = gpu.render_with(method, &scene, (w, h), &opts);
                        let d = diff(&reference, &img);
                        eprintln!("{es} {name} {lights} lights {method} linear={linear}: max {} rmse {:.3}, {} cells, {:.1} lights/cell", d.max_abs, d.rmse, stats.assignment.nonempty_clusters, stats.assignment.avg_lights_per_nonempty);
                        assert!(
                            d.max_abs <= 2,
                            "{es} {name} {lights} {method}: max abs error {} > 2/255",
                            d.max_abs
                        );
                        assert_eq!(stats.lights.overflowed, 0);
                        assert!(stats.assignment.clusters > 0 && stats.lights.visible > 0);
                    }
                }
            }
        }
    }
}

/// Culling works: at 1 024 lights clustered cells hold far fewer lights than the scene has.
#[test]
fn clustered_lists_are_short() {
    let mut gpu = Gpu::new(EsVersion::Es3);
    let scene = scene::builtin::build("pillars", Some((1024, 5))).unwrap();
    let (_, tiled) = gpu.render_with("tiled", &scene, (W, H), &RenderOptions::default());
    let (_, clustered) = gpu.render_with("clustered", &scene, (W, H), &RenderOptions::default());
    assert!(
        clustered.assignment.avg_lights_per_nonempty < 1024.0 / 10.0,
        "{}",
        clustered.assignment.avg_lights_per_nonempty
    );
    assert!(
        clustered.assignment.avg_lights_per_nonempty < tiled.assignment.avg_lights_per_nonempty
    );
}

/// 300 lights in one cell with a per-cell cap of 255, on ES 2.0 and ES 3.0 (whose grid texture
/// derives a cell's count from the next cell's start, so the compacted lists must stay
/// contiguous): the overflow is counted, the image stays right away from the overcrowded
/// cell, no GL error or out-of-range read happens, and the user is warned once per renderer
/// (not every frame) naming the settings that avoid it.
#[test]
fn overflow_policy_holds_in_a_real_render() {
    common::warnings::install();
    let warning = "light references left out";
    let mut scene = scene::builtin::build("plane", None).unwrap();
    scene.lights = (0..300)
        .map(|i| {
            Light::point(
                DVec3::new(1.5 + 0.0005 * i as f64, 0.5, 0.05),
                0.08,
                Vec3::ONE,
                0.05,
            )
        })
        .collect();
    scene.lights.push(Light::point(
        DVec3::new(-2.0, -1.0, 1.0),
        2.5,
        Vec3::new(1.0, 0.5, 0.2),
        1.5,
    ));
    let opts = RenderOptions {
        linear: true,
        measure: manylight::MeasureOptions {
            cell_cap: Some(255),
            ..Default::default()
        },
        ..Default::default()
    };
    let mut uncrowded = scene.clone();
    uncrowded.lights.drain(..300);
    for (run, es) in [EsVersion::Es2, EsVersion::Es3].into_iter().enumerate() {
        let mut gpu = Gpu::new(es);
        let (reference, _) = gpu.render_with("forward", &scene, (W, H), &opts);
        let (floor, _) = gpu.render_with("forward", &uncrowded, (W, H), &opts);
        let (img, stats) = gpu.render_with("clustered", &scene, (W, H), &opts);
        assert!(
            stats.assignment.max_lights_per_cluster >= 300,
            "{es}: {}",
            stats.assignment.max_lights_per_cluster
        );
        assert!(
            stats.lights.overflowed >= 45,
            "{es}: overflow not counted: {}",
            stats.lights.overflowed
        );
        // Left half (far from the crowd) is exact; the crowded spot degrades but stays bounded.
        let mut left_max = 0u8;
        for y in 0..H {
            for x in 0..W / 2 {
                let (a, b) = (reference.get_pixel(x, y), img.get_pixel(x, y));
                for c in 0..3 {
                    left_max = left_max.max(a[c].abs_diff(b[c]));
                }
            }
        }
        assert!(
            left_max <= 2,
            "{es}: overflow leaked into unrelated cells: {left_max}"
        );
        // In the crowd, dropping lights only darkens, and the kept lights (at least 255 of the
        // 300 in every cell, the most important to it) still give most of the crowd's light:
        // their share, summed over the image, is at least 3/4 (the 85 % they are of the lights,
        // less room for the brighter ones' overlap). An overfull cell that lost all
        // its lights gives none.
        let (mut crowd, mut kept) = (0i64, 0i64);
        for ((r, f), c) in reference.pixels().zip(floor.pixels()).zip(img.pixels()) {
            for ch in 0..3 {
                let (r, f, c) = (i64::from(r[ch]), i64::from(f[ch]), i64::from(c[ch]));
                assert!(c <= r + 2, "{es}: overflow brightened a pixel: {c} > {r}");
                crowd += r - f;
                kept += c - f;
            }
        }
        let share = kept as f64 / crowd as f64;
        assert!(
            crowd > 0 && share >= 0.75,
            "{es}: the kept lights give {share:.3} of the crowd's light ({kept} of {crowd})"
        );
        let d = diff(&reference, &img);
        eprintln!(
            "{es} overflow: {} dropped, max error {} / 255, rmse {:.3}, kept share {share:.3}",
            stats.lights.overflowed, d.max_abs, d.rmse
        );

        // An index budget far below the lists' length: the cap is lowered, nothing breaks.
        let tight = RenderOptions {
            measure: manylight::MeasureOptions {
                max_indices: Some(64),
                ..opts.measure
            },
            ..opts.clone()
        };
        let (_, stats) = gpu.render_with("clustered", &scene, (W, H), &tight);
        assert!(stats.lights.overflowed > 0);
        let said = warnings_containing(warning);
        assert_eq!(
            said.len(),
            run + 1,
            "{es}: warned once for two frames: {said:?}"
        );
        // The automatic grid drew it: another grid is not the way out (it was suggested).
        assert!(
            said[run].starts_with("clustered:")
                && said[run].contains("at most 255 lights")
                && said[run].contains("the automatic grid chose these cells already")
                && !said[run].contains("grid.footprint_px"),
            "{}",
            said[run]
        );
    }
}

/// A fixed grid too fine for the context's grid texture is refused before anything is
/// assigned, naming the setting; the automatic grid never builds one.
#[test]
fn a_grid_the_texture_cannot_hold_is_a_clear_error() {
    use manylight::cluster::grid::GridConfig;
    let scene = scene::builtin::build("pillars", Some((64, 1))).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    gpu.r().set_method_named("clustered").unwrap();
    // 640 × 360 one-pixel cells, 64 slices in each of 12 cascades: 177 million cells, more
    // than any texture of 1 024-texel rows holds (32 768 rows would be 33.5 million).
    let options = RenderOptions {
        grid: GridConfig {
            max_tiles: 1024,
            max_slices: 64,
            ..GridConfig::fixed(1.0)
        },
        ..RenderOptions::default()
    };
    match gpu.r().render_offscreen(&scene, 640, 360, &options) {
        Err(manylight::Error::Limit(message)) => {
            assert!(
                message.contains("grid.footprint_px") && message.contains("grid texture holds"),
                "{message}"
            )
        }
        other => panic!(
            "expected a limit error, got {:?}",
            other.map(|(_, s)| s.grid.cells)
        ),
    }
    // At the default caps (256 tiles a side, 32 slices) one-pixel cells make 25 million cells
    // at any size, past a texture of 16 384 rows: the message says the caps bound the grid
    // (every size reported the same count, as if a finer footprint added cells). A tiny
    // footprint is written short (`{}` wrote 1e-30 in 32 digits).
    for (footprint, shown) in [(1.0, "a 1 px"), (1e-30, "a 1e-30 px")] {
        if gpu.r().caps().max_texture_size > 16_384 {
            break;
        }
        let capped = RenderOptions {
            grid: GridConfig::fixed(footprint),
            ..RenderOptions::default()
        };
        match gpu.r().render_offscreen(&scene, 640, 360, &capped) {
            Err(manylight::Error::Limit(message)) => assert!(
                message.contains("grid.max_tiles") && message.starts_with(shown),
                "{message}"
            ),
            other => panic!("expected a limit error, got {:?}", other.map(|_| ())),
        }
    }
    let (_, stats) = gpu
        .r()
        .render_offscreen(&scene, 640, 360, &RenderOptions::default())
        .unwrap();
    assert!(stats.grid.cells <= manylight::cluster::auto_grid::CELL_BUDGET);
    assert!(stats.grid.reason.unwrap().starts_with("auto"));
}

/// RGBA8 light records (ES 2.0 without float textures) hold every radius in steps of the
/// largest: beside one light of radius 10⁶ the others' radii are a few steps. A radius rounded
/// up past the one the lights were culled with lit pixels of cells that do not list the light
/// (tiled 25/255 from forward here); records now round inside the culled sphere, so every
/// method draws forward's picture, however coarse the records (the renderer warns of that).
#[test]
fn rgba8_records_light_nothing_outside_the_culled_spheres() {
    let opts = RenderOptions {
        measure: manylight::MeasureOptions {
            force_rgba8_lights: true,
            ..Default::default()
        },
        ..Default::default()
    };
    let mut scene = scene::builtin::build("courtyard", Some((64, 3))).unwrap();
    let huge = Light::point(scene.camera.target, 1e6, Vec3::splat(0.02), 1e-3);
    scene.lights.push(huge);
    let mut gpu = Gpu::new(EsVersion::Es2);
    let (w, h) = (W / 2, H / 2);
    let (reference, stats) = gpu.render_with("forward", &scene, (w, h), &opts);
    assert_eq!(stats.lights.encoding, manylight::LightEncoding::Rgba8);
    assert!(
        common::mean(&reference) > 5.0,
        "the small lights light nothing"
    );
    for method in ["tiled", "clustered"] {
        let (img, _) = gpu.render_with(method, &scene, (w, h), &opts);
        let d = diff(&reference, &img);
        assert!(d.max_abs <= 2, "{method}: {}/255 from forward", d.max_abs);
    }
}
