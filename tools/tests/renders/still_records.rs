//! Forward's and deferred's light records on a still frame (nothing they are made from
//! changed): the frame draws the last frame's upload, uploads nothing, and its picture is the
//! one a renderer with nothing to reuse draws. Every input of the records that changes makes
//! the next frame upload them again.

use glam::{DMat4, DVec3, Vec3};
use manylight::cluster::grid::GridConfig;
use manylight::scene::{Light, Projection, Scene};
use manylight::{EsVersion, FrameStats, MeasureOptions, RenderOptions};

use super::common::Gpu;

const SIZE: (u32, u32) = (48, 27);

/// The methods that upload light records and no lists, on the contexts they run on.
const RECORDS: [(&str, EsVersion); 3] = [
    ("forward", EsVersion::Es2),
    ("forward", EsVersion::Es3),
    ("deferred", EsVersion::Es3),
];

/// The pillars under 40 lights, one a spot, with the floor see-through: deferred draws it
/// with forward. (Not the pillars: their layers of blended faces made each frame cost
/// SwiftShader about five times as much.)
fn still_scene() -> Scene {
    let mut s = super::common::pillars_lit(40);
    assert_eq!(s.materials[0].name, "floor");
    s.materials[0].alpha = 0.6;
    s
}

fn first_frame(
    es: EsVersion,
    method: &str,
    scene: &Scene,
    opts: &RenderOptions,
) -> image::RgbaImage {
    Gpu::new(es).render_with(method, scene, SIZE, opts).0
}

fn assert_reused(stats: &FrameStats, what: &str) {
    assert!(stats.lists_reused, "{what}: the records were made again");
    assert_eq!(stats.memory.upload_bytes, 0, "{what}: uploaded");
}

fn assert_uploaded(stats: &FrameStats, what: &str) {
    assert!(!stats.lists_reused, "{what}: the last records were drawn");
    assert!(stats.memory.upload_bytes > 0, "{what}: nothing uploaded");
}

#[test]
fn a_still_frame_draws_the_last_records_and_uploads_nothing() {
    let scene = still_scene();
    for (method, es) in RECORDS {
        let mut gpu = Gpu::new(es);
        let what = format!("{es} {method}");
        let opts = RenderOptions::default();
        let (first, built) = gpu.render_with(method, &scene, SIZE, &opts);
        assert_uploaded(&built, &what);
        for frame in 2..=3 {
            let (image, stats) = gpu.render_with(method, &scene, SIZE, &opts);
            let what = format!("{what}, frame {frame}");
            assert_reused(&stats, &what);
            assert!(image == first, "{what}: not the first frame's picture");
        }
    }
}

/// A change to one input of the records (or of what a frame draws beside them).
type Change = fn(&mut Scene, &mut RenderOptions);

/// Forward with RGBA8 records, which leave out the lights that reach no pixel of the view.
const FORWARD_RGBA8: &str = "forward, RGBA8 records";

/// The cases: what the methods' frames are told, on the contexts they run on.
fn cases() -> [(&'static str, &'static str, EsVersion, RenderOptions); 4] {
    let rgba8 = RenderOptions {
        measure: MeasureOptions {
            force_rgba8_lights: true,
            ..MeasureOptions::default()
        },
        ..RenderOptions::default()
    };
    [
        (
            "forward",
            "forward",
            EsVersion::Es2,
            RenderOptions::default(),
        ),
        (
            "forward",
            "forward",
            EsVersion::Es3,
            RenderOptions::default(),
        ),
        (FORWARD_RGBA8, "forward", EsVersion::Es3, rgba8),
        (
            "deferred",
            "deferred",
            EsVersion::Es3,
            RenderOptions::default(),
        ),
    ]
}

const ALL: &[&str] = &["forward", FORWARD_RGBA8, "deferred"];

/// Each input, and the cases whose next frame must upload the records again after it: for the
/// others, the frame draws the last ones.
const INPUTS: [(&str, Change, &[&str]); 16] = [
    (
        "a light moved far",
        |s, _| s.lights[3].position = DVec3::new(-2.0, 0.5, 1.0),
        ALL,
    ),
    (
        "a light moved by an f32 ulp",
        |s, _| {
            let x = &mut s.lights[3].position.x;
            *x = f64::from_bits(x.to_bits() + (1 << 29));
        },
        ALL,
    ),
    (
        "a light's colour",
        |s, _| s.lights[5].color = Vec3::new(0.1, 0.2, 1.0),
        ALL,
    ),
    (
        "a light turned off",
        |s, _| s.lights[9].intensity = 0.0,
        ALL,
    ),
    ("the light cut-off", |_, o| o.light_cutoff = Some(0.05), ALL),
    ("the camera moved", |s, _| s.camera.position.x += 0.5, ALL),
    // The view selects lights for RGBA8 records; the planes and the lens choose deferred's
    // proxies (a lens narrow enough sends a wide light full screen).
    (
        "the far plane",
        |s, _| set_plane(s, |_, far| *far = 30.0),
        &[FORWARD_RGBA8, "deferred"],
    ),
    (
        "the near plane",
        |s, _| set_plane(s, |near, _| *near *= 4.0),
        &[FORWARD_RGBA8, "deferred"],
    ),
    (
        "the field of view",
        |s, _| {
            if let Projection::Perspective { fov_y_deg, .. } = &mut s.camera.projection {
                *fov_y_deg *= 1.2;
            }
        },
        &[FORWARD_RGBA8, "deferred"],
    ),
    (
        "the farthest object moved away",
        |s, _| {
            s.objects[0].transform =
                DMat4::from_translation(DVec3::new(0.0, 0.0, -60.0)) * s.objects[0].transform;
        },
        &[FORWARD_RGBA8],
    ),
    // Forward's records, and deferred's forward pass over its see-through objects.
    (
        "the records' encoding",
        |_, o| o.measure.force_rgba8_lights = true,
        &["forward", "deferred"],
    ),
    // Deferred's instances carry the exposure (rounded to a power of two), either way.
    (
        "an exposure of -2 EV",
        |_, o| o.exposure_ev = -2.0,
        &["deferred"],
    ),
    (
        "an exposure of +1 EV",
        |_, o| o.exposure_ev = 1.0,
        &["deferred"],
    ),
    (
        "the ambient light",
        |s, _| s.ambient = Vec3::new(0.2, 0.0, 0.0),
        &[],
    ),
    (
        "a material's colour",
        |s, _| s.materials[0].diffuse = Vec3::new(0.9, 0.1, 0.1),
        &[],
    ),
    (
        "the grid and the cell cap",
        |_, o| {
            o.grid = GridConfig::fixed(24.0);
            o.measure.cell_cap = Some(2);
        },
        &[],
    ),
];

fn set_plane(s: &mut Scene, set: fn(&mut f64, &mut f64)) {
    match &mut s.camera.projection {
        Projection::Perspective { near, far, .. } | Projection::Orthographic { near, far, .. } => {
            set(near, far)
        }
    }
}

#[test]
fn each_input_of_the_records_makes_the_next_frame_upload_them() {
    let base = still_scene();
    for (case, method, es, base_opts) in cases() {
        let mut gpu = Gpu::new(es);
        for (change, apply, uploads) in INPUTS {
            let what = format!("{es} {case}: {change}");
            let (mut scene, mut opts) = (base.clone(), base_opts.clone());
            gpu.render_with(method, &scene, SIZE, &opts);
            let (_, still) = gpu.render_with(method, &scene, SIZE, &opts);
            assert_reused(&still, &what);
            apply(&mut scene, &mut opts);
            let (image, stats) = gpu.render_with(method, &scene, SIZE, &opts);
            if uploads.contains(&case) {
                assert_uploaded(&stats, &what);
            } else {
                assert_reused(&stats, &what);
            }
            let fresh = first_frame(es, method, &scene, &opts);
            assert!(image == fresh, "{what}: not what a first frame draws");
        }
    }
}

/// A frame that fails (its error may be the records' upload) leaves no records to draw again:
/// the next frame of the same lights uploads them, and draws what a fresh renderer draws. The
/// failures are injected at the step that reports them: the frame's check (a data texture's
/// upload into storage it has is checked there, and deferred's instances, which it checked
/// itself).
#[test]
fn a_failed_frame_leaves_no_records_to_draw_again() {
    let before = still_scene();
    let mut after = still_scene();
    after.lights[3].position.x += 1.0;
    let opts = RenderOptions::default();
    for (method, es, step) in [
        ("forward", EsVersion::Es2, "the frame's draws"),
        ("forward", EsVersion::Es3, "the frame's draws"),
        ("clustered", EsVersion::Es3, "the frame's draws"),
        ("deferred", EsVersion::Es3, "the frame's draws"),
    ] {
        let what = format!("{es} {method}, failed at {step}");
        let mut gpu = Gpu::new(es);
        gpu.render_with(method, &before, SIZE, &opts);
        gpu.r().fail_gl_checks_naming(Some(step));
        let failed = gpu.r().render_offscreen(&after, SIZE.0, SIZE.1, &opts);
        gpu.r().fail_gl_checks_naming(None);
        assert!(failed.is_err(), "{what}: the frame did not fail");
        let (image, stats) = gpu.render_with(method, &after, SIZE, &opts);
        assert_uploaded(&stats, &what);
        assert!(
            image == first_frame(es, method, &after, &opts),
            "{what}: the next frame's picture differs"
        );
    }
}

/// Without fragment highp a light too far from the eye for fp16 that reaches nothing is left
/// out: still frames stay still (they drew again every frame), and a far plane that makes
/// it placeable, or no longer, makes the next frame upload. The lamp lies 59 990 behind the
/// eye, where fp16 places it under a far plane of 2 (the view reaches about 3 deep) and not
/// under the scene's (tens deep).
#[test]
fn without_highp_a_light_left_out_keeps_still_frames_still() {
    let mut scene = still_scene();
    let eye = scene.camera.position;
    let behind = (eye - scene.camera.target).normalize();
    scene
        .lights
        .push(Light::point(eye + behind * 59990.0, 1.0, Vec3::ONE, 1.0));
    let mut near_far = scene.clone();
    set_plane(&mut near_far, |_, far| *far = 2.0);
    let mut gpu = Gpu::without_fragment_highp();
    let opts = RenderOptions::default();
    let frame = |gpu: &mut Gpu, s: &Scene| gpu.render_with("forward", s, SIZE, &opts);
    let (first, _) = frame(&mut gpu, &scene);
    for (s, what, active) in [
        (&scene, "a still frame, the lamp left out", None),
        (&near_far, "the far plane at 2", Some(41)),
        (&near_far, "a still frame, the lamp placed", None),
        (&scene, "the scene's far plane", Some(40)),
    ] {
        let (image, stats) = frame(&mut gpu, s);
        match active {
            None => assert_reused(&stats, what),
            Some(n) => {
                assert_uploaded(&stats, what);
                assert_eq!(stats.lights.active, n, "{what}: lights drawn");
            }
        }
        if std::ptr::eq(s, &scene) {
            assert!(image == first, "{what}: not the first frame's picture");
        }
    }
}

/// Timed frames time a frame's whole cost: each uploads the records.
#[test]
fn timed_frames_upload_the_records() {
    let scene = still_scene();
    let opts = RenderOptions {
        measure: MeasureOptions {
            timed_frames: 3,
            ..MeasureOptions::default()
        },
        ..RenderOptions::default()
    };
    for (method, es) in RECORDS {
        let mut gpu = Gpu::new(es);
        let what = format!("{es} {method}");
        gpu.render_with(method, &scene, SIZE, &RenderOptions::default());
        let (_, stats) = gpu.render_with(method, &scene, SIZE, &opts);
        assert_uploaded(&stats, &what);
    }
}
