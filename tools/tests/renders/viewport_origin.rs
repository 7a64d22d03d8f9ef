//! A frame drawn into part of a game's framebuffer (`RenderOptions::origin`: split screen, a
//! view beside an editor's panel): every method, with and without MSAA, draws inside the
//! rectangle what it draws into a framebuffer of its own, and every pixel outside the
//! rectangle stays as the game left it.

use crate::common;

use common::game_target::render_at_origin;
use common::Gpu;
use manylight::glam::{DVec3, Vec3};
use manylight::scene;
use manylight::{CountKind, DirectionalLight, EsVersion, RenderOptions};

/// The pillars' lights, and bubbles (transparent objects: deferred's forward pass over them)
/// under a sun (the deferred composite's surface point).
fn scenes() -> Vec<manylight::Scene> {
    let pillars = scene::builtin::build("pillars", Some((300, 4))).unwrap();
    let mut bubbles = scene::builtin::build("bubbles", Some((64, 2))).unwrap();
    bubbles.directional_lights.push(DirectionalLight::new(
        DVec3::new(-1.0, -2.0, -0.5),
        Vec3::new(1.0, 0.9, 0.8),
        0.5,
    ));
    vec![pillars, bubbles]
}

#[test]
fn a_frame_at_an_origin_draws_only_its_rectangle_and_draws_it_as_at_the_corner() {
    for scene in scenes() {
        frame_at_an_origin(&scene);
    }
}

fn frame_at_an_origin(scene: &manylight::Scene) {
    let size = (96u32, 54u32);
    // Odd offsets, and room on every side of the frame.
    let origin = [23u32, 17];
    let whole = (size.0 + 41, size.1 + 30);
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let es3 = es == EsVersion::Es3;
        let methods: &[&str] = if es3 {
            &["forward", "tiled", "clustered", "deferred", "auto"]
        } else {
            &["forward", "tiled", "clustered"]
        };
        // MSAA: ES 3.0's renderbuffers (llvmpipe's ES 2.0 has no multisampled extension).
        let sample_counts: &[u32] = if es3 { &[1, 4] } else { &[1] };
        let mut gpu = Gpu::new(es);
        for &samples in sample_counts {
            let at_corner = RenderOptions {
                samples,
                ..Default::default()
            };
            let moved = RenderOptions {
                origin,
                ..at_corner.clone()
            };
            for &m in methods {
                if samples > 1 && m == "deferred" {
                    continue;
                }
                let what = format!("{es} ×{samples} {m}");
                gpu.r().set_method_named(m).unwrap();
                let (corner, _) = gpu
                    .r()
                    .render_offscreen(scene, size.0, size.1, &at_corner)
                    .unwrap();
                // The offscreen render ignores the origin: its image is the frame.
                let (offscreen, _) = gpu
                    .r()
                    .render_offscreen(scene, size.0, size.1, &moved)
                    .unwrap();
                assert_eq!(
                    manylight::metrics::diff(&corner, &offscreen).max_abs,
                    0,
                    "{what}: the origin moved an offscreen render"
                );
                // Moved by whole pixels, a rasterizer may still round an edge the other way
                // (llvmpipe: one pixel of the bubbles): a frame shifted, cut, looked up in the
                // wrong cells or drawn against the game's depth changes far more. That each
                // method at the corner equals forward is the other tests' (culled_vs_forward,
                // deferred, msaa).
                let img = render_at_origin(&mut gpu, scene, &moved, size, whole, &what);
                let d = manylight::metrics::diff(&corner, &img);
                assert!(
                    d.over_2 <= 0.01,
                    "{what}: {:.1} % of the pixels differ from the frame at the corner",
                    d.over_2 * 100.0
                );
            }
        }
    }
}

/// Light counts drawn as a heat map through `render` (the viewer's view) find their cells at
/// the origin too: each method's map there is its map at the corner.
#[test]
fn a_heat_map_at_an_origin_is_the_one_at_the_corner() {
    let scene = scene::builtin::build("pillars", Some((300, 4))).unwrap();
    let size = (96u32, 54u32);
    let whole = (size.0 + 41, size.1 + 30);
    let mut gpu = Gpu::new(EsVersion::Es3);
    for m in ["tiled", "clustered", "deferred"] {
        gpu.r().set_method_named(m).unwrap();
        let heat = RenderOptions {
            count: CountKind::Heatmap,
            heat_scale: 16.0,
            ..Default::default()
        };
        let (corner, _) = gpu
            .r()
            .render_offscreen(&scene, size.0, size.1, &heat)
            .unwrap();
        let moved = RenderOptions {
            origin: [23, 17],
            ..heat
        };
        let img = render_at_origin(&mut gpu, &scene, &moved, size, whole, m);
        let d = manylight::metrics::diff(&corner, &img);
        assert!(
            d.over_2 <= 0.01,
            "{m}: {:.1} % of the heat map moved",
            d.over_2 * 100.0
        );
    }
}

#[test]
fn an_origin_past_gl_window_coordinates_is_refused_naming_it() {
    let mut gpu = Gpu::new(EsVersion::Es3);
    let scene = scene::builtin::build("plane", Some((8, 1))).unwrap();
    let options = RenderOptions {
        origin: [0, i32::MAX as u32 - 10],
        ..Default::default()
    };
    let err = gpu.r().render(&scene, 32, 18, &options).unwrap_err();
    let text = err.to_string();
    assert!(text.contains("origin"), "{text}");
    assert!(text.contains("2147483647"), "{text}");
}
