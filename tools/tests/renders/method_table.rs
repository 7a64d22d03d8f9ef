//! The method table: what each context supports, and `auto`'s choices.

use crate::common;

use common::Gpu;
use manylight::methods::{Support, METHODS};
use manylight::scene;
use manylight::{EsVersion, Method, RenderOptions};

#[test]
fn the_table_lists_every_method_with_its_support_per_context() {
    let names: Vec<_> = METHODS.iter().map(|m| m.name).collect();
    assert_eq!(names, ["forward", "tiled", "clustered", "deferred", "auto"]);
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::new(es);
        assert_eq!(gpu.r().method(), Method::default(), "{es}: the default");
        let caps = gpu.renderer.as_ref().unwrap().caps().clone();
        for m in METHODS {
            let support = (m.supported)(&caps);
            let expect_unsupported = m.name == "deferred" && es == EsVersion::Es2;
            assert_eq!(
                matches!(support, Support::Unsupported(_)),
                expect_unsupported,
                "{es} {}: {support:?}",
                m.name
            );
            assert!(m.min_es <= es || expect_unsupported, "{}", m.name);
        }
        for m in Method::ALL {
            if gpu.r().set_method(m).is_ok() {
                assert_eq!(gpu.r().method(), m, "{es}: the method just set");
            }
        }
    }
}

#[test]
fn auto_picks_forward_for_few_lights_and_clustered_for_many_and_says_why() {
    let mut gpu = Gpu::new(EsVersion::Es2);
    for (lights, expected) in [(8, "forward"), (1024, "clustered")] {
        let s = scene::builtin::build("pillars", Some((lights, 3))).unwrap();
        gpu.r().set_method_named("forward").unwrap();
        let (reference, _) = gpu
            .r()
            .render_offscreen(&s, 128, 72, &RenderOptions::default())
            .unwrap();
        gpu.r().set_method_named("auto").unwrap();
        let (img, stats) = gpu
            .r()
            .render_offscreen(&s, 128, 72, &RenderOptions::default())
            .unwrap();
        assert_eq!(stats.method, "auto");
        assert_eq!(
            stats.auto_choice.as_deref(),
            Some(expected),
            "{lights} lights"
        );
        assert!(stats
            .auto_reason
            .as_deref()
            .is_some_and(|r| r.contains("lights")));
        assert!(manylight::metrics::diff(&reference, &img).max_abs <= 2);
    }
}

/// More lights visible than tiled and clustered can index: clustered refuses the frame with an
/// error naming the limit, and `auto` renders it with deferred where a single-sampled ES 3.0
/// frame allows (no index limit, no light left out), else with forward, and says why.
#[test]
fn auto_renders_with_deferred_or_forward_when_more_lights_are_visible_than_clustered_indexes() {
    use manylight::cluster::pack::MAX_INDEXED_LIGHTS;
    use manylight::scene::Light;
    let mut s = scene::builtin::build("plane", None).unwrap();
    // A 320 × 208 lattice just above the plane, all of it in view.
    let side = 320;
    s.lights = (0..MAX_INDEXED_LIGHTS + 1_000)
        .map(|i| {
            let (x, y) = ((i % side) as f64, (i / side) as f64);
            let at = glam::DVec3::new(x / side as f64 * 4.0 - 2.0, y / 208.0 * 2.4 - 1.2, 0.2);
            Light::point(at, 0.3, glam::Vec3::ONE, 1e-3)
        })
        .collect();
    // Small: forward and deferred over 66 536 lights are a software GPU's slow part.
    let (w, h) = (8, 4);
    let mut gpu = Gpu::new(EsVersion::Es3);
    let mut render = |method: &str, options: &RenderOptions| {
        gpu.r().set_method_named(method).unwrap();
        gpu.r().render_offscreen(&s, w, h, options)
    };
    let single = RenderOptions::default();
    let err = render("clustered", &single).unwrap_err().to_string();
    assert!(
        err.contains("visible") && err.contains(&MAX_INDEXED_LIGHTS.to_string()),
        "{err}"
    );
    let (reference, _) = render("deferred", &single).unwrap();
    let (img, stats) = render("auto", &single).unwrap();
    assert_eq!(stats.auto_choice.as_deref(), Some("deferred"));
    let reason = stats.auto_reason.unwrap_or_default();
    assert!(
        reason.contains("more than clustered can index: deferred renders"),
        "{reason}"
    );
    assert_eq!(manylight::metrics::diff(&reference, &img).max_abs, 0);
    let gbuffer = stats.memory.gbuffer_bytes;
    assert!(gbuffer > 0);

    // Deferred has no multisampled G-buffer: with 4 samples auto renders with forward.
    let msaa = RenderOptions {
        samples: 4,
        ..RenderOptions::default()
    };
    let (reference, _) = render("forward", &msaa).unwrap();
    let (img, stats) = render("auto", &msaa).unwrap();
    assert_eq!(stats.auto_choice.as_deref(), Some("forward"));
    let reason = stats.auto_reason.unwrap_or_default();
    assert!(
        reason.contains("forward renders this frame (deferred cannot: 4 MSAA samples"),
        "{reason}"
    );
    assert!(manylight::metrics::diff(&reference, &img).max_abs <= 2);

    // With few of them in view again, the same method goes back to clustered; deferred's
    // G-buffer is kept for a while (the count may cross the limit again), then freed.
    let (_, stats) = render("auto", &single).unwrap();
    assert_eq!(stats.auto_choice.as_deref(), Some("deferred"));
    s.lights.truncate(2_000);
    let mut held = vec![stats.memory.method_gpu_bytes];
    for _ in 0..manylight::methods::IDLE_FRAMES_KEPT {
        // A light moves: a still scene's frames free clustered's texture sets it does not read.
        s.lights[0].position.x += 1e-3;
        let (_, stats) = gpu.r().render_offscreen(&s, w, h, &single).unwrap();
        assert_eq!(stats.auto_choice.as_deref(), Some("clustered"));
        assert_eq!(stats.memory.gbuffer_bytes, 0, "clustered's frame");
        held.push(stats.memory.method_gpu_bytes);
    }
    // Memory drops by the G-buffer's size on the last frame, not before. (Forward, which
    // drew the MSAA frame, the one before deferred's last, frees its records a frame earlier.)
    let drops: Vec<_> = held.windows(2).map(|w| w[0].saturating_sub(w[1])).collect();
    let last = drops.len() - 1;
    assert!(drops[last] >= gbuffer, "freed on the last frame: {held:?}");
    assert!(
        drops[..last - 1].iter().all(|&d| d < gbuffer),
        "kept before: {held:?}"
    );
    // Frames with no lights at all (ambient only, drawn without the method) count too.
    let all = common::light_lattice::plane_past_the_index_limit();
    let (_, stats) = gpu.r().render_offscreen(&all, w, h, &single).unwrap();
    assert_eq!(stats.auto_choice.as_deref(), Some("deferred"));
    let with_gbuffer = gpu.r().render_offscreen(&all, w, h, &single).unwrap().1;
    s.lights.clear();
    let unlit: Vec<usize> = (0..manylight::methods::IDLE_FRAMES_KEPT)
        .map(|_| {
            let (_, stats) = gpu.r().render_offscreen(&s, w, h, &single).unwrap();
            stats.memory.method_gpu_bytes
        })
        .collect();
    let freed = with_gbuffer.memory.method_gpu_bytes - unlit[unlit.len() - 1];
    assert!(freed >= gbuffer, "{unlit:?}");
    // Transparent objects alone: deferred, which auto picks, makes no G-buffer for them (it
    // made one before drawing none; made again after its 120 frames, it was kept for good).
    let mut glass = all.clone();
    for m in &mut glass.materials {
        m.alpha = 0.5;
    }
    let mut fresh = Gpu::new(EsVersion::Es3);
    fresh.r().set_method_named("auto").unwrap();
    let (_, stats) = fresh.r().render_offscreen(&glass, w, h, &single).unwrap();
    assert_eq!(stats.auto_choice.as_deref(), Some("deferred"));
    assert_eq!(
        stats.memory.gbuffer_bytes, 0,
        "a G-buffer for transparent objects"
    );
}

/// A light count hovering round forward's limit: `auto` alternates forward and clustered, and
/// each keeps what it holds while the other draws. Clustered's textures were freed on every
/// forward frame and made again on the next (344 064 bytes at 320×180), and its grid, made
/// anew each time, never got past its priors. Once forward alone has drawn for
/// `IDLE_FRAMES_KEPT` frames, clustered's resources go.
#[test]
fn auto_keeps_both_methods_while_the_count_hovers_round_forwards_limit() {
    use manylight::methods::auto::FORWARD_UP_TO;
    use manylight::methods::IDLE_FRAMES_KEPT;
    let mut s = scene::builtin::build("plane", None).unwrap();
    let side = 11;
    s.lights = (0..FORWARD_UP_TO + 1)
        .map(|i| {
            let (x, y) = ((i % side) as f64, (i / side) as f64);
            let at = glam::DVec3::new(x / side as f64 * 4.0 - 2.0, y / 3.0 * 2.4 - 1.2, 0.2);
            scene::Light::point(at, 0.6, glam::Vec3::ONE, 1.0)
        })
        .collect();
    let mut gpu = Gpu::new(EsVersion::Es3);
    gpu.r().set_method_named("auto").unwrap();
    let mut frame = |dark: bool| {
        s.lights[0].intensity = if dark { 0.0 } else { 1.0 };
        let (_, stats) = gpu
            .r()
            .render_offscreen(&s, 64, 36, &RenderOptions::default())
            .unwrap();
        stats
    };
    let hovering: Vec<_> = (0..60).map(|k| frame(k % 2 == 1)).collect();
    let choices: Vec<_> = hovering.iter().map(|f| f.auto_choice.as_deref()).collect();
    for (k, choice) in choices.iter().enumerate() {
        let expected = if k % 2 == 1 { "forward" } else { "clustered" };
        assert_eq!(*choice, Some(expected), "frame {k}: {choices:?}");
    }
    let held: Vec<_> = hovering.iter().map(|f| f.memory.method_gpu_bytes).collect();
    // After the first, a forward frame neither frees nor makes anything: clustered's
    // textures stay. (Its own frames may resize them, as its grid calibrates.)
    assert!(
        (3..held.len()).step_by(2).all(|k| held[k] == held[k - 1]),
        "both methods' memory is kept: {held:?}"
    );
    // Its grid's search spans frames: 20 frames of clustered's own, here 40 of auto's.
    let reason = hovering[58].grid.reason.clone().unwrap_or_default();
    assert!(reason.contains("calibrated"), "{reason}");
    // Clustered last drew frame 58: frame 59 was the first of its idle ones.
    let forward_only: Vec<_> = (1..IDLE_FRAMES_KEPT)
        .map(|_| frame(true).memory.method_gpu_bytes)
        .collect();
    let last = forward_only.len() - 1;
    assert!(
        forward_only[..last].iter().all(|&b| b == held[59]),
        "kept while idle: {forward_only:?}"
    );
    assert!(
        forward_only[last] < held[59] / 2 && forward_only[last] > 0,
        "clustered freed on the {IDLE_FRAMES_KEPT}th forward frame: {forward_only:?}"
    );
}

/// ES 2.0 has no G-buffer: past clustered's index limit `auto` renders with forward.
#[test]
fn auto_renders_with_forward_past_the_index_limit_on_es2() {
    let s = common::light_lattice::plane_past_the_index_limit();
    let mut gpu = Gpu::new(EsVersion::Es2);
    gpu.r().set_method_named("forward").unwrap();
    let (reference, _) = gpu
        .r()
        .render_offscreen(&s, 16, 9, &RenderOptions::default())
        .unwrap();
    gpu.r().set_method_named("auto").unwrap();
    let (img, stats) = gpu
        .r()
        .render_offscreen(&s, 16, 9, &RenderOptions::default())
        .unwrap();
    assert_eq!(stats.auto_choice.as_deref(), Some("forward"));
    let reason = stats.auto_reason.unwrap_or_default();
    assert!(
        reason.contains("deferred cannot: needs OpenGL ES 3.0"),
        "{reason}"
    );
    assert!(manylight::metrics::diff(&reference, &img).max_abs <= 2);
}

/// `Renderer::support` answers for every method without switching, as the table does; a
/// refused `set_method` leaves the default method, and the warning about its fallback still
/// reaches the log at the first frame.
#[test]
fn support_answers_without_switching_and_a_refusal_keeps_the_default_methods_warning() {
    use common::warnings::warnings_containing;
    let mut gpu = Gpu::without_fragment_highp();
    let caps = gpu.r().caps().clone();
    for m in Method::ALL {
        let row = METHODS.iter().find(|d| d.name == m.name()).unwrap();
        assert_eq!(gpu.r().support(m), (row.supported)(&caps), "{m:?}");
    }
    assert!(matches!(
        gpu.r().support(Method::Deferred),
        Support::Unsupported(_)
    ));
    assert!(matches!(
        gpu.r().support(Method::Forward),
        Support::Supported | Support::Fallback(_)
    ));
    let default = gpu.r().method();
    let warning = format!("method `{default}` runs with a fallback");
    assert!(gpu.r().set_method(Method::Deferred).is_err());
    assert_eq!(
        gpu.r().method(),
        default,
        "a refused method switches nothing"
    );
    let before = warnings_containing(&warning).len();
    let s = scene::builtin::build("plane", Some((4, 1))).unwrap();
    gpu.r()
        .render_offscreen(&s, 32, 18, &RenderOptions::default())
        .unwrap();
    assert_eq!(warnings_containing(&warning).len(), before + 1, "{warning}");
}

/// More lights over one spot than a cell lists (4 400 against ES 2.0's cap of 4 095): clustered leaves
/// references out (warned, the overflow policy), where forward and deferred draw every light.
/// `auto` picked clustered anyway, 23/255 off forward; it now draws such a frame with forward
/// where forward's one loop holds every light, and says why (not deferred: its half-float
/// accumulation, without float blending, drifts under thousands of lights on one pixel).
#[test]
fn auto_draws_every_light_where_clustered_cells_would_overflow() {
    use manylight::scene::Light;
    let mut s = scene::builtin::build("plane", None).unwrap();
    s.lights = (0..4_400)
        .map(|i| {
            let colour = if i < 4_000 {
                glam::Vec3::X
            } else {
                glam::Vec3::Y
            };
            let at = glam::DVec3::new(0.0, 0.0, 0.3 + i as f64 * 1e-5);
            Light::point(at, 2.0, colour, 2e-3)
        })
        .collect();
    let (w, h) = (32, 18);
    // ES 3.0 lists more a cell: there a smaller cap plays the same crowd.
    let es3_cap = RenderOptions {
        measure: manylight::MeasureOptions {
            cell_cap: Some(1_000),
            ..Default::default()
        },
        ..Default::default()
    };
    let cases = [
        (EsVersion::Es2, RenderOptions::default(), "forward"),
        (EsVersion::Es3, es3_cap, "forward"),
    ];
    for (es, options, expected) in cases {
        let mut gpu = Gpu::new(es);
        let mut render = |method: &str| {
            gpu.r().set_method_named(method).unwrap();
            gpu.r().render_offscreen(&s, w, h, &options).unwrap()
        };
        let (_, clustered) = render("clustered");
        assert!(clustered.lights.overflowed > 0, "{es}: nothing overflowed");
        let (reference, _) = render("forward");
        let (img, stats) = render("auto");
        assert_eq!(stats.auto_choice.as_deref(), Some(expected), "{es}");
        let reason = stats.auto_reason.unwrap_or_default();
        assert!(reason.contains("per-cell cap"), "{es}: {reason}");
        assert_eq!(stats.lights.overflowed, 0, "{es}");
        let d = manylight::metrics::diff(&reference, &img).max_abs;
        assert!(d <= 2, "{es}: auto {d} / 255 from forward");
    }
    // Past OVERFLOW_TO_FORWARD lights forward's loop would cost every pixel them all: the
    // frame stays clustered, under its overflow policy.
    let extra = manylight::methods::auto::OVERFLOW_TO_FORWARD + 1 - s.lights.len();
    let crowd = s.lights[0];
    s.lights.extend(std::iter::repeat_n(crowd, extra));
    let mut gpu = Gpu::new(EsVersion::Es2);
    gpu.r().set_method_named("auto").unwrap();
    let (_, stats) = gpu
        .r()
        .render_offscreen(&s, w, h, &RenderOptions::default())
        .unwrap();
    assert_eq!(stats.auto_choice.as_deref(), Some("clustered"));
    assert!(stats.lights.overflowed > 0);
}
