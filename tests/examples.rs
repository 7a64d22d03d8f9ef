//! The examples in `examples/` run, and do what their docs say: each is compiled into this
//! test as a module and its `run` called at a small size.

#[path = "../examples/offscreen.rs"]
mod offscreen;

#[path = "../examples/animated_lights.rs"]
mod animated_lights;

#[path = "../examples/embed_glow.rs"]
mod embed_glow;

use manylight::{builtin_scene, EsVersion, HeadlessContext, RandomLights, RenderOptions, Renderer};

/// The fraction of pixels brighter than `level` (mean of RGB).
fn lit_fraction(img: &image::RgbaImage, level: f64) -> f64 {
    let lit = img
        .pixels()
        .filter(|p| (p[0] as f64 + p[1] as f64 + p[2] as f64) / 3.0 > level)
        .count();
    lit as f64 / (img.width() * img.height()) as f64
}

#[test]
fn offscreen_writes_a_lit_picture_of_the_scene_built_in_code() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("offscreen.png");
    let stats = offscreen::run(&out, 256, 144).expect("example runs");
    let img = image::open(&out).unwrap().to_rgba8();
    assert_eq!(img.dimensions(), (256, 144));
    assert_eq!(
        stats.lights.total,
        offscreen::build_scene().unwrap().lights.len()
    );
    assert!(
        lit_fraction(&img, 20.0) > 0.3,
        "too dark: {:.2} lit",
        lit_fraction(&img, 20.0)
    );
}

#[test]
fn animated_lights_move_every_frame_and_each_frame_depends_on_its_time_only() {
    let dir = tempfile::tempdir().unwrap();
    let timings = animated_lights::run(dir.path(), 3, 128, 160, 90).expect("example runs");
    assert!(timings.p50_ms > 0.0 && timings.p95_ms >= timings.p50_ms);
    let frame = |i: u32| {
        image::open(dir.path().join(format!("frame_{i:03}.png")))
            .unwrap()
            .to_rgba8()
    };
    let (first, second, third) = (frame(0), frame(1), frame(2));
    assert_ne!(first, second, "the lights did not move");
    assert_ne!(second, third, "the lights did not move");
    // Frame 2 rendered on its own, from its time alone, is the sequence's frame 2: the motion
    // is a function of time, and assignment keeps nothing of the frames before.
    let ctx = HeadlessContext::new(EsVersion::Es3).unwrap();
    let mut renderer = Renderer::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    let mut scene = animated_lights::build_scene(128).unwrap();
    scene.set_time(animated_lights::time_of(2));
    let (alone, _) = renderer
        .render_offscreen(&scene, 160, 90, &RenderOptions::default())
        .unwrap();
    renderer.destroy();
    assert_eq!(alone, third, "frame 2 differs when rendered alone");
}

#[test]
fn embedding_draws_into_the_applications_framebuffer_under_its_overlay() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("embedded.png");
    embed_glow::run(&out, 256, 144).expect("example runs");
    let embedded = image::open(&out).unwrap().to_rgba8();
    // The same view rendered by manylight into its own target.
    let ctx = HeadlessContext::new(EsVersion::Es3).unwrap();
    let mut renderer = Renderer::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    let scene = builtin_scene(
        "courtyard",
        Some(RandomLights {
            count: 512,
            seed: 3,
        }),
    )
    .unwrap();
    let (own, _) = renderer
        .render_offscreen(&scene, 256, 144, &RenderOptions::default())
        .unwrap();
    renderer.destroy();
    let overlay_rows = 144 / 16;
    for (x, y, p) in embedded.enumerate_pixels() {
        if y >= 144 - overlay_rows {
            // The overlay's clear colour (0.9, 0.6, 0.1): 229.5 and 25.5 may round either
            // way (NVIDIA gives 229 and 25).
            let expected = [230u8, 153, 26, 255];
            let worst = (0..4).map(|c| p[c].abs_diff(expected[c])).max().unwrap();
            assert!(worst <= 1, "overlay at ({x}, {y}): {p:?}");
        } else {
            let q = own.get_pixel(x, y);
            let worst = (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap();
            assert!(worst <= 1, "({x}, {y}): embedded {p:?}, offscreen {q:?}");
        }
    }
}

#[test]
fn a_renderer_outliving_its_headless_context_says_so() {
    let ctx = HeadlessContext::new(EsVersion::Es3).expect("headless ES 3.0 context");
    let mut renderer = Renderer::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    let scene = builtin_scene("plane", Some(RandomLights { count: 4, seed: 1 })).unwrap();
    drop(ctx);
    let err = renderer
        .render_offscreen(&scene, 16, 9, &RenderOptions::default())
        .unwrap_err();
    assert!(
        matches!(err, manylight::Error::Gl(manylight::GlError::NotCurrent)),
        "{err}"
    );
    assert!(
        err.to_string()
            .contains("its HeadlessContext, or the application's own) dropped"),
        "{err}"
    );
    // Dropping the renderer afterwards must not crash either.
    drop(renderer);
}
