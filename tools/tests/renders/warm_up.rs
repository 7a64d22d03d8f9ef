//! `Renderer::warm_up`: after it, a game's frames build no shader program (each would be a
//! hitch on a phone's driver), whichever method `auto` picks, with MSAA, into an sRGB
//! framebuffer, and when the camera walks into a light's reach under deferred.
#![allow(unsafe_code)] // the game's side: raw glow calls

use crate::common;

use common::game_target::{free_game_framebuffer, game_framebuffer, sized_framebuffer, GameTarget};
use common::Gpu;
use glam::{DMat4, DVec3, Vec3};
use manylight::glow;
use manylight::scene::{self, DirectionalLight, LightKind, Material, Object, Scene};
use manylight::{EsVersion, FrameStats, RenderOptions, ToneMap};

const W: u32 = 64;
const H: u32 = 36;

/// The courtyard with 40 lights (spots among them), a sun, a metallic-roughness object and a
/// transparent one: most of what selects a variant.
pub(crate) fn game_scene() -> Scene {
    let mut s = scene::builtin::build("courtyard", Some((40, 7))).unwrap();
    s.directional_lights.push(DirectionalLight::new(
        DVec3::new(1.0, -2.0, -1.0),
        Vec3::ONE,
        0.5,
    ));
    let mesh = s.objects[0].mesh.clone();
    let mut glass = Material::flat("glass", Vec3::new(0.3, 0.6, 0.9));
    glass.alpha = 0.5;
    let metal = Material::metallic_roughness("metal", Vec3::new(0.9, 0.7, 0.3), 1.0, 0.4);
    for (material, x) in [(metal, -1.0), (glass, 1.0)] {
        s.materials.push(material);
        s.objects.push(Object {
            mesh: mesh.clone(),
            material: s.materials.len() - 1,
            transform: DMat4::from_translation(DVec3::new(x, 0.5, 0.0))
                * DMat4::from_scale(DVec3::splat(0.2)),
        });
    }
    s
}

/// `scene` with only `n` of its lights, spots and points both among them (a spot-free set
/// would be another variant).
fn with_lights(scene: &Scene, n: usize) -> Scene {
    let (mut spots, mut points) = (n / 2, n - n / 2);
    let mut s = scene.clone();
    s.retain_lights(|l| {
        let left = match l.kind {
            LightKind::Spot { .. } => &mut spots,
            _ => &mut points,
        };
        let keep = *left > 0;
        *left = left.saturating_sub(1);
        keep
    });
    assert_eq!(s.lights.len(), n);
    s
}

/// Makes and binds a game framebuffer whose colour has the sized format `colour` (`RGBA8`, or
/// on ES 3.0 `SRGB8_ALPHA8`), with as deep a depth buffer as the context has.
fn bind_game_framebuffer(gpu: &mut Gpu, colour: u32) -> (manylight::glow::Context, GameTarget) {
    let gl = gpu.gl();
    let caps = gpu.r().caps();
    let depth24 = caps.es == EsVersion::Es3 || caps.depth24;
    let size = (W as i32, H as i32);
    let target = match colour {
        glow::RGBA8 => unsafe { game_framebuffer(&gl, depth24, size) },
        _ => unsafe { sized_framebuffer(&gl, colour, size) },
    };
    (gl, target)
}

/// A frame of `scene` into a fresh game framebuffer of colour format `colour` (`RGBA8`,
/// `SRGB8_ALPHA8`), and its stats.
fn frame(gpu: &mut Gpu, colour: u32, scene: &Scene, options: &RenderOptions) -> FrameStats {
    let (gl, target) = bind_game_framebuffer(gpu, colour);
    let stats = gpu.r().render(scene, W, H, options);
    unsafe { free_game_framebuffer(&gl, target) };
    stats.unwrap()
}

#[test]
fn a_warmed_up_renderer_builds_nothing_in_its_frames() {
    let scene = game_scene();
    let few = with_lights(&scene, 8);
    // Every light far below the ground, out of view: the frame is drawn ambient-only.
    let mut away = scene.clone();
    for l in &mut away.lights {
        l.position.y -= 1e5;
    }
    for es in [EsVersion::Es2, EsVersion::Es3] {
        // Fresh: a pooled context's renderer starts with programs other tests built.
        let mut gpu = Gpu::fresh(es);
        let es3 = es == EsVersion::Es3;
        let plain = RenderOptions::default();
        let msaa = RenderOptions {
            samples: 4,
            ..Default::default()
        };
        // (method, options, colour format of the game's framebuffer)
        let mut cases = vec![
            ("auto", plain.clone(), glow::RGBA8),
            ("tiled", plain.clone(), glow::RGBA8),
        ];
        if es3 {
            cases.push(("auto", msaa, glow::SRGB8_ALPHA8));
            cases.push(("deferred", plain, glow::SRGB8_ALPHA8));
        }
        for (i, (method, options, colour)) in cases.into_iter().enumerate() {
            let what = format!("{es} {method} ×{} {colour:#x}", options.samples);
            gpu.r().set_method_named(method).unwrap();
            // Warmed up with the game's framebuffer bound, as a game's loading screen does.
            let (gl, target) = bind_game_framebuffer(&mut gpu, colour);
            let warm = gpu.r().warm_up(&scene, &options);
            unsafe { free_game_framebuffer(&gl, target) };
            let warm = warm.unwrap_or_else(|e| panic!("{what}: {e}"));
            eprintln!("{what}: {warm:?}");
            if i == 0 {
                assert!(warm.programs_built > 3, "{what}: built {warm:?}");
            }
            if method == "auto" {
                // Deferred where it runs: ES 3.0, not into the renderer's MSAA target.
                let expected: &[&str] = match (es3, options.samples) {
                    (true, 1) => &["forward", "clustered", "deferred"],
                    _ => &["forward", "clustered"],
                };
                assert_eq!(warm.methods, expected, "{what}");
            }
            // Auto draws forward for the few lights, clustered for the many; with none in
            // view any method draws ambient-only.
            for s in [&scene, &few, &away, &scene] {
                let stats = frame(&mut gpu, colour, s, &options);
                assert_eq!(stats.programs_built, 0, "{what}: {:?}", stats.auto_choice);
            }
            assert_eq!(frame(&mut gpu, colour, &away, &options).lights.visible, 0);
        }
        // The sRGB MSAA target's fill program only where its clear misses samples.
        let report = gpu.r().program_report();
        let solid = report.iter().any(|p| p.shader == "solid");
        let fills = es3 && gpu.r().caps().clears_one_sample_of_srgb_msaa();
        assert_eq!(solid, fills, "{es}: the fill's program");
        // What auto may pick, each on its own: built already.
        let methods: &[&str] = if es3 {
            &["forward", "clustered", "deferred"]
        } else {
            &["forward", "clustered"]
        };
        for method in methods {
            gpu.r().set_method_named(method).unwrap();
            let stats = frame(&mut gpu, glow::RGBA8, &scene, &RenderOptions::default());
            assert_eq!(
                stats.programs_built, 0,
                "{es} {method} after auto's warm-up"
            );
        }
        // The count counts: a tone map not warmed up is built by the frame that meets it.
        let aces = RenderOptions {
            tone_map: ToneMap::Aces,
            ..Default::default()
        };
        let first = frame(&mut gpu, glow::RGBA8, &scene, &aces);
        assert!(first.programs_built > 0, "{es}: {first:?}");
        let second = frame(&mut gpu, glow::RGBA8, &scene, &aces);
        assert_eq!(second.programs_built, 0, "{es}");
        // Timed frames report what the whole call built, its untimed first frame's too.
        let mut timed = RenderOptions {
            tone_map: ToneMap::Reinhard,
            ..Default::default()
        };
        timed.measure.timed_frames = 2;
        let (_, stats) = gpu.r().render_offscreen(&scene, W, H, &timed).unwrap();
        assert!(stats.programs_built > 0, "{es}: timed frames {stats:?}");
    }
}

#[test]
fn deferred_builds_nothing_when_a_light_takes_the_whole_screen() {
    let mut gpu = Gpu::fresh(EsVersion::Es3);
    let mut scene = scene::builtin::build("plane", None).unwrap();
    let (_, far) = scene.camera.near_far();
    let light = |at: DVec3, radius| scene::Light::point(at, radius, Vec3::ONE, 3.0);
    // Warmed up while every light lies well inside the depth range: only the volumes' sides
    // are drawn, by one program.
    scene.lights = vec![
        light(DVec3::new(0.0, 0.2, 0.0), 1.0),
        light(DVec3::new(1.0, 0.2, 1.0), 1.0),
    ];
    gpu.r().set_method_named("deferred").unwrap();
    let options = RenderOptions::default();
    let (gl, target) = bind_game_framebuffer(&mut gpu, glow::RGBA8);
    let warm = gpu.r().warm_up(&scene, &options).unwrap();
    unsafe { free_game_framebuffer(&gl, target) };
    assert!(warm.programs_built > 0);
    let frame_of = |gpu: &mut Gpu, scene: &Scene| frame(gpu, glow::RGBA8, scene, &options);
    assert_eq!(frame_of(&mut gpu, &scene).programs_built, 0);
    // A light whose reach holds the eye and passes the far plane has neither side of its
    // volume to draw: it is drawn as a full-screen triangle, by a program of its own.
    scene
        .lights
        .push(light(scene.camera.position, 2.0 * far as f32));
    let past = frame_of(&mut gpu, &scene);
    assert_eq!(
        past.programs_built, 0,
        "a light around the eye, past the far plane"
    );
}

/// A warm-up that panics (a game's logger panicking on the warning one of its frames logs)
/// and is caught leaves the renderer as it was: its own method (`auto` stayed the warm-up's
/// forward), its frames counted (`free_unused_programs` freed nothing for good after it), its
/// MSAA target, and no GL object of the warm-up's (a clustered one left 4 textures, a
/// framebuffer and a renderbuffer, each time).
#[test]
fn a_warm_up_that_panics_leaves_the_renderer_as_it_was() {
    use manylight::Method;
    let mut suns = scene::builtin::build("courtyard", Some((16, 7))).unwrap();
    suns.directional_lights.clear();
    let plain = suns.clone();
    for k in 0..=scene::MAX_DIRECTIONAL_LIGHTS {
        let direction = DVec3::new(k as f64 - 2.0, -2.0, -1.0);
        let sun = DirectionalLight::new(direction, Vec3::ONE, 0.2);
        suns.directional_lights.push(sun);
    }
    for (method, samples) in [
        (Method::Clustered, 1),
        (Method::Auto, 4),
        (Method::Deferred, 1),
    ] {
        let mut gpu = Gpu::fresh(EsVersion::Es3);
        gpu.r().set_method(method).unwrap();
        let opts = RenderOptions {
            samples,
            ..RenderOptions::default()
        };
        gpu.r().render_offscreen(&plain, W, H, &opts).unwrap();
        let before = gpu.r().live_gl_objects();
        common::warnings::panic_on_next_warning_containing("directional lights");
        let caught = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            gpu.r().warm_up(&suns, &opts)
        }));
        assert!(caught.is_err(), "{method:?}: the warm-up did not panic");
        assert_eq!(gpu.r().method(), method);
        let after = gpu.r().live_gl_objects();
        let held = |o: manylight::gl::device::LiveObjects| {
            (
                o.textures,
                o.buffers,
                o.framebuffers,
                o.renderbuffers,
                o.vertex_arrays,
            )
        };
        assert_eq!(held(after), held(before), "{method:?}: objects left");
        // The suns' variants, unused by the last two frames, are freed.
        for scene in [&suns, &suns, &plain, &plain] {
            gpu.r().render_offscreen(scene, W, H, &opts).unwrap();
        }
        let freed = gpu.r().free_unused_programs(2).unwrap();
        assert!(freed > 0, "{method:?}: frames are not counted");
        let (img, _) = gpu.r().render_offscreen(&plain, W, H, &opts).unwrap();
        let mut clean = Gpu::new(EsVersion::Es3);
        clean.r().set_method(method).unwrap();
        let (reference, _) = clean.r().render_offscreen(&plain, W, H, &opts).unwrap();
        assert_eq!(
            manylight::metrics::diff(&reference, &img).max_abs,
            0,
            "{method:?}"
        );
    }
}
