//! `Renderer::free_unused_programs`: the shader variants no recent frame drew with are freed
//! when a game asks, the others kept, and a frame that needs a freed one again builds it and
//! draws what it drew before.

use crate::common;
use crate::warm_up::game_scene;

use common::Gpu;
use manylight::metrics::diff;
use manylight::scene::{self, Scene};
use manylight::{EsVersion, FrameStats, RenderOptions};

const W: u32 = 48;
const H: u32 = 27;

fn frame(gpu: &mut Gpu, scene: &Scene) -> (image::RgbaImage, FrameStats) {
    gpu.r()
        .render_offscreen(scene, W, H, &RenderOptions::default())
        .unwrap()
}

/// The programs the renderer's context holds, by the device's own count of GL objects.
fn live_programs(gpu: &mut Gpu) -> i64 {
    gpu.r().live_gl_objects().programs
}

#[test]
fn variants_no_recent_frame_drew_with_are_freed_on_request() {
    // Level A: spots, a sun, a metallic-roughness and a transparent object; level B: a plain
    // floor under point lights. A needs variants B does not.
    let (level_a, level_b) = (
        game_scene(),
        scene::builtin::build("plane", Some((8, 1))).unwrap(),
    );
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::fresh(es);
        let (first_a, _) = frame(&mut gpu, &level_a);
        let (first_b, b) = frame(&mut gpu, &level_b);
        let held = b.memory.shader_programs;
        let live = live_programs(&mut gpu);
        // Calls refused before they drew (a minimised window's empty frame, a bad option)
        // are no frames.
        assert!(gpu
            .r()
            .render(&level_a, 0, 0, &RenderOptions::default())
            .is_err());
        let bad = RenderOptions {
            tile_px: 0.0,
            ..Default::default()
        };
        assert!(gpu.r().render_offscreen(&level_a, W, H, &bad).is_err());
        // Level B's frame is the last one: what only level A drew with goes.
        let freed = gpu.r().free_unused_programs(1).unwrap();
        assert!(freed > 0, "{es}: level A's own variants");
        assert_eq!(live_programs(&mut gpu), live - freed as i64, "{es}");
        let (again_b, stats) = frame(&mut gpu, &level_b);
        assert_eq!(stats.programs_built, 0, "{es}: level B's variants kept");
        assert_eq!(stats.memory.shader_programs, held - freed, "{es}");
        assert_eq!(diff(&first_b, &again_b).max_abs, 0, "{es}");
        // Level A comes back: it builds what was freed, and looks as it did.
        let (again_a, stats) = frame(&mut gpu, &level_a);
        assert_eq!(stats.programs_built, freed, "{es}");
        assert_eq!(diff(&first_a, &again_a).max_abs, 0, "{es}");
        // The last two frames drew both levels: nothing goes.
        assert_eq!(gpu.r().free_unused_programs(2).unwrap(), 0, "{es}");
        // After a warm-up, 0 frames keeps what the warm-up drew with, and no more: the next
        // frame of its scene builds nothing.
        gpu.r()
            .warm_up(&level_b, &RenderOptions::default())
            .unwrap();
        let before = live_programs(&mut gpu);
        let freed = gpu.r().free_unused_programs(0).unwrap();
        assert!(freed > 0, "{es}: level A's own variants again");
        assert_eq!(live_programs(&mut gpu), before - freed as i64, "{es}");
        assert_eq!(frame(&mut gpu, &level_b).1.programs_built, 0, "{es}");
        // 0 frames and no warm-up since: everything goes, and the next frame builds its own.
        let all = frame(&mut gpu, &level_b).1.memory.shader_programs;
        assert_eq!(gpu.r().free_unused_programs(0).unwrap(), all, "{es}");
        let (third_b, stats) = frame(&mut gpu, &level_b);
        assert!(stats.programs_built > 0, "{es}");
        assert_eq!(diff(&first_b, &third_b).max_abs, 0, "{es}");
    }
}

/// Every method draws with variants built again after all were freed what it drew before:
/// nothing it keeps between frames (uniforms set once, texture units) belonged to the
/// programs freed. ES 2.0's tiled and clustered set the uniforms ES 3.0's do not (a
/// software implementation compiles each variant in a second or so: not every pair).
#[test]
fn every_method_draws_the_same_with_its_variants_built_again() {
    let level = common::pillars_lit(40);
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::fresh(es);
        let methods: &[&str] = match es {
            EsVersion::Es2 => &["clustered"],
            EsVersion::Es3 => common::methods_on(es),
        };
        for method in methods {
            gpu.r().set_method_named(method).unwrap();
            let (first, _) = frame(&mut gpu, &level);
            let (second, stats) = frame(&mut gpu, &level);
            assert_eq!(stats.programs_built, 0, "{es} {method}");
            assert!(
                gpu.r().free_unused_programs(0).unwrap() > 0,
                "{es} {method}"
            );
            let (again, stats) = frame(&mut gpu, &level);
            assert!(stats.programs_built > 0, "{es} {method}");
            assert_eq!(diff(&first, &second).max_abs, 0, "{es} {method}");
            assert_eq!(diff(&first, &again).max_abs, 0, "{es} {method}");
        }
    }
}
