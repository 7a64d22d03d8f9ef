//! A frame drawn into part of a game's framebuffer (`RenderOptions::origin`: split screen, a
//! view beside an editor's panel): every method, with and without MSAA, draws inside the
//! rectangle what forward draws there, forward draws what it draws at the framebuffer's
//! corner, and every pixel outside the rectangle stays as the game left it.

mod common;

use common::game_target::render_at_origin;
use common::Gpu;
use manylight::scene;
use manylight::{EsVersion, RenderOptions};

#[test]
fn a_frame_at_an_origin_draws_only_its_rectangle_and_draws_it_as_at_the_corner() {
    let scene = scene::builtin::build("pillars", Some((300, 4))).unwrap();
    let size = (96u32, 54u32);
    // Odd offsets, and room on every side of the frame.
    let origin = [23u32, 17];
    let whole = (size.0 + 41, size.1 + 30);
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let es3 = es == EsVersion::Es3;
        let methods: &[&str] = if es3 {
            &["tiled", "clustered", "deferred", "auto"]
        } else {
            &["tiled", "clustered"]
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
            gpu.r().set_method_named("forward").unwrap();
            let (corner, _) = gpu
                .r()
                .render_offscreen(&scene, size.0, size.1, &at_corner)
                .unwrap();
            // The offscreen render ignores the origin: its image is the frame.
            let (offscreen, _) = gpu
                .r()
                .render_offscreen(&scene, size.0, size.1, &moved)
                .unwrap();
            let what = format!("{es} ×{samples}");
            assert_eq!(
                manylight::metrics::diff(&corner, &offscreen).max_abs,
                0,
                "{what}: the origin moved an offscreen render"
            );
            // Moved by whole pixels, a rasterizer may still round a triangle's edge the other
            // way (llvmpipe: 14 of 5 184 pixels): a frame shifted, cut or drawn against the
            // game's depth changes far more.
            let reference = render_at_origin(&mut gpu, &scene, &moved, size, whole, &what);
            let d = manylight::metrics::diff(&corner, &reference);
            assert!(
                d.over_2 <= 0.01,
                "{what} forward: {:.1} % of the pixels differ from the frame at the corner",
                d.over_2 * 100.0
            );
            // Each method at the origin equals forward at the origin.
            for &m in methods {
                if samples > 1 && m == "deferred" {
                    continue;
                }
                let what = format!("{what} {m}");
                gpu.r().set_method_named(m).unwrap();
                let img = render_at_origin(&mut gpu, &scene, &moved, size, whole, &what);
                let d = manylight::metrics::diff(&reference, &img);
                assert!(d.max_abs <= 2, "{what}: {}/255 from forward", d.max_abs);
            }
        }
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
