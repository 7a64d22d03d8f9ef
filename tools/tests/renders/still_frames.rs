//! A still frame (nothing the light lists are built from changed) draws with the last frame's
//! lists and textures: it assigns and uploads nothing, and its picture is the one a renderer
//! with nothing to reuse draws. Every input of the lists that changes makes the next frame
//! assign again; timed frames always assign.

use glam::{DMat4, DVec3, Vec3};
use manylight::cluster::grid::GridConfig;
use manylight::scene::{self, Light, Projection, Scene};
use manylight::{EsVersion, FrameStats, MeasureOptions, RenderOptions};

use super::common::Gpu;

const SIZE: (u32, u32) = (96, 54);

const CULLED: [&str; 3] = ["tiled", "clustered", "auto"];

/// The pillars under 60 lights (more than `auto` draws with forward), one of them a spot.
fn still_scene() -> Scene {
    super::common::pillars_lit(60)
}

/// A fixed grid, so that a renderer with nothing to reuse builds the very same one.
fn fixed_grid() -> RenderOptions {
    RenderOptions {
        grid: GridConfig::fixed(16.0),
        ..RenderOptions::default()
    }
}

/// What a renderer that has drawn nothing before draws.
fn first_frame(
    es: EsVersion,
    method: &str,
    scene: &Scene,
    opts: &RenderOptions,
) -> image::RgbaImage {
    Gpu::new(es).render_with(method, scene, SIZE, opts).0
}

fn assert_reused(stats: &FrameStats, what: &str) {
    assert!(stats.lists_reused, "{what}: the lists were built again");
    assert_eq!(stats.memory.upload_bytes, 0, "{what}: uploaded");
    assert_eq!(stats.time.assign_ms, 0.0, "{what}: assigned");
}

#[test]
fn a_still_frame_draws_with_the_last_lists_and_uploads_nothing() {
    let scene = still_scene();
    for es in [EsVersion::Es2, EsVersion::Es3] {
        for method in CULLED {
            // The automatic grid too: it chooses on the first frame and keeps the choice.
            for opts in [RenderOptions::default(), fixed_grid()] {
                let mut gpu = Gpu::new(es);
                let what = format!("{es} {method}, grid {:?}", opts.grid.mode);
                let (first, built) = gpu.render_with(method, &scene, SIZE, &opts);
                assert!(!built.lists_reused, "{what}: the first frame reused");
                assert!(built.memory.upload_bytes > 0, "{what}: nothing uploaded");
                for frame in 2..=3 {
                    let (image, stats) = gpu.render_with(method, &scene, SIZE, &opts);
                    let what = format!("{what}, frame {frame}");
                    assert_reused(&stats, &what);
                    assert_eq!(stats.assignment, built.assignment, "{what}");
                    assert_eq!(stats.lights.visible, built.lights.visible, "{what}");
                    assert_eq!(stats.grid.cells, built.grid.cells, "{what}");
                    assert!(image == first, "{what}: not the first frame's picture");
                }
            }
        }
    }
}

/// A change to one input of the lists (or of what a frame draws beside them).
type Change = fn(&mut Scene, &mut RenderOptions);

/// The inputs of the lists and of the light textures: each must make the next frame assign.
const LIST_INPUTS: [(&str, Change); 10] = [
    ("a light moved far", |s, _| {
        s.lights[3].position = DVec3::new(-2.0, 0.5, 1.0)
    }),
    ("a light moved by an f32 ulp", |s, _| {
        let x = &mut s.lights[3].position.x;
        *x = f64::from_bits(x.to_bits() + (1 << 29));
    }),
    ("a light's colour", |s, _| {
        s.lights[5].color = Vec3::new(0.1, 0.2, 1.0)
    }),
    ("a light turned off", |s, _| s.lights[9].intensity = 0.0),
    ("the camera moved", |s, _| s.camera.position.x += 0.5),
    ("the camera's far plane", |s, _| {
        if let Projection::Perspective { far, .. } = &mut s.camera.projection {
            *far = if far.is_finite() { *far * 0.9 } else { 1e4 };
        }
    }),
    ("the grid", |_, o| {
        o.grid = GridConfig::fixed(24.0);
        o.tile_px = 24.0;
    }),
    ("the cell cap", |_, o| {
        o.measure = MeasureOptions {
            cell_cap: Some(2),
            ..o.measure
        }
    }),
    ("the light cut-off", |_, o| o.light_cutoff = Some(0.05)),
    ("the light records' encoding", |_, o| {
        o.measure = MeasureOptions {
            force_rgba8_lights: true,
            ..o.measure
        }
    }),
];

#[test]
fn each_input_of_the_lists_makes_the_next_frame_assign() {
    let base = still_scene();
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::new(es);
        for method in CULLED {
            for (change, apply) in LIST_INPUTS {
                let what = format!("{es} {method}: {change}");
                let (mut scene, mut opts) = (base.clone(), fixed_grid());
                gpu.render_with(method, &scene, SIZE, &opts);
                let (_, still) = gpu.render_with(method, &scene, SIZE, &opts);
                assert_reused(&still, &what);
                apply(&mut scene, &mut opts);
                let (image, stats) = gpu.render_with(method, &scene, SIZE, &opts);
                assert!(!stats.lists_reused, "{what}: the last lists were drawn");
                assert!(stats.memory.upload_bytes > 0, "{what}: nothing uploaded");
                let fresh = first_frame(es, method, &scene, &opts);
                assert!(image == fresh, "{what}: not what a first frame draws");
            }
        }
    }
}

/// Inputs of the frame that the lists do not depend on: the lists stay.
const OTHER_INPUTS: [(&str, Change); 3] = [
    ("the exposure", |_, o| o.exposure_ev = 1.0),
    ("the ambient light", |s, _| {
        s.ambient = Vec3::new(0.2, 0.0, 0.0)
    }),
    ("a material's colour", |s, _| {
        s.materials[0].diffuse = Vec3::new(0.9, 0.1, 0.1)
    }),
];

#[test]
fn inputs_beside_the_lists_keep_them() {
    let base = still_scene();
    let mut gpu = Gpu::new(EsVersion::Es3);
    for method in CULLED {
        for (change, apply) in OTHER_INPUTS {
            let what = format!("{method}: {change}");
            let (mut scene, mut opts) = (base.clone(), fixed_grid());
            gpu.render_with(method, &scene, SIZE, &opts);
            apply(&mut scene, &mut opts);
            let (image, stats) = gpu.render_with(method, &scene, SIZE, &opts);
            assert_reused(&stats, &what);
            let fresh = first_frame(EsVersion::Es3, method, &scene, &opts);
            assert!(image == fresh, "{what}: not what a first frame draws");
        }
    }
}

#[test]
fn timed_frames_assign_each_frame() {
    let scene = still_scene();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let opts = RenderOptions {
        measure: MeasureOptions {
            timed_frames: 3,
            ..MeasureOptions::default()
        },
        ..fixed_grid()
    };
    for method in ["tiled", "clustered"] {
        // Lists the timed frames could reuse, were they not timing an assignment.
        gpu.render_with(method, &scene, SIZE, &opts_untimed(&opts));
        let (_, stats) = gpu.render_with(method, &scene, SIZE, &opts);
        let spread = stats.time.assign_ms_spread.expect("timed frames");
        assert!(!stats.lists_reused, "{method}");
        assert!(stats.memory.upload_bytes > 0, "{method}");
        assert!(spread.p50 > 0.0 && spread.max > 0.0, "{method}: {spread:?}");
        // A still frame after them reuses what the last timed one built.
        let (_, after) = gpu.render_with(method, &scene, SIZE, &opts_untimed(&opts));
        assert_reused(&after, method);
    }
}

fn opts_untimed(opts: &RenderOptions) -> RenderOptions {
    let mut opts = opts.clone();
    opts.measure.timed_frames = 0;
    opts
}

/// An object that moves changes no list: a huge plane sliding along itself keeps the lists
/// (its split copies, made again, are all the frame uploads) and draws what a first frame
/// draws.
#[test]
fn a_moving_object_keeps_the_lists() {
    let mut s = scene::builtin::build("plane", None).unwrap();
    s.lights = (0..40)
        .map(|i| {
            Light::point(
                DVec3::new(i as f64 * 0.1 - 2.0, 0.0, 1.0),
                2.0,
                Vec3::ONE,
                1.0,
            )
        })
        .collect();
    s.objects[0].transform = DMat4::from_scale(DVec3::new(1e8, 1e8, 1.0));
    let mut gpu = Gpu::new(EsVersion::Es3);
    for method in ["tiled", "clustered"] {
        let (_, first) = gpu.render_with(method, &s, SIZE, &fixed_grid());
        let mut moved = s.clone();
        moved.objects[0].transform =
            DMat4::from_translation(DVec3::new(0.25, 0.0, 0.0)) * s.objects[0].transform;
        let (image, stats) = gpu.render_with(method, &moved, SIZE, &fixed_grid());
        assert!(stats.lists_reused, "{method}: the lists were built again");
        assert_eq!(stats.time.assign_ms, 0.0, "{method}");
        let splits = stats.memory.upload_bytes;
        assert!(
            splits > 0 && splits < first.memory.upload_bytes,
            "{method}: {splits}"
        );
        let fresh = first_frame(EsVersion::Es3, method, &moved, &fixed_grid());
        assert!(image == fresh, "{method}: not what a first frame draws");
    }
}
