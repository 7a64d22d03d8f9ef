//! A scene pays only for what it uses: variants leave out absent features (checked on the
//! assembled source) without changing the image, methods free their resources when switched
//! away, a renderer given an earlier one's programs builds none, zero lights cost nothing,
//! and transparency is lit like everything else.

mod common;

use std::sync::Arc;

use common::Gpu;
use glam::{DMat4, DVec3, Vec3};
use manylight::gl::shader_source::{assemble, Stage};
use manylight::methods::ShaderFeatures;
use manylight::scene::meshbuild::MeshBuilder;
use manylight::scene::{self, Light, Material};
use manylight::{EsVersion, HeadlessContext, LightEncoding, RenderOptions, Renderer};

#[test]
fn variants_without_spots_or_textures_contain_no_such_code() {
    for es in [EsVersion::Es2, EsVersion::Es3] {
        for shader in ["forward", "clustered"] {
            for rgba8 in [false, true] {
                let base = ShaderFeatures::default().with(ShaderFeatures::LIGHTS_RGBA8, rgba8);
                let lean = assemble(shader, Stage::Fragment, es, &base.defines(es, 1024)).unwrap();
                let full_features = base
                    .with(ShaderFeatures::SPOT, true)
                    .with(ShaderFeatures::TEXTURE, true);
                let full = assemble(
                    shader,
                    Stage::Fragment,
                    es,
                    &full_features.defines(es, 1024),
                )
                .unwrap();
                for needle in ["spotScale", "spotOffset", "light.direction"] {
                    assert!(
                        !lean.contains(needle),
                        "{shader} {es}: `{needle}` in a variant without spots"
                    );
                    assert!(
                        full.contains(needle),
                        "{shader} {es}: `{needle}` missing from the spot variant"
                    );
                }
                for needle in ["u_albedoTex", "srgbToLinear"] {
                    assert!(
                        !lean.contains(needle),
                        "{shader} {es}: `{needle}` in a variant without textures"
                    );
                    assert!(
                        full.contains(needle),
                        "{shader} {es}: `{needle}` missing from the texture variant"
                    );
                }
                assert!(lean.len() < full.len());
            }
        }
    }
}

fn point_light_scene() -> scene::Scene {
    let mut s = scene::builtin::build("pillars", None).unwrap();
    s.lights = (0..200)
        .map(|i| {
            let f = i as f64;
            Light::point(
                DVec3::new(
                    (f * 0.7).sin() * 12.0,
                    0.5 + (f * 0.3).cos().abs() * 5.0,
                    (f * 0.11).sin() * 15.0,
                ),
                3.0,
                Vec3::new(1.0, 0.7, 0.4),
                1.5,
            )
        })
        .collect();
    s
}

#[test]
fn lean_variants_render_exactly_like_the_full_ones() {
    let s = point_light_scene();
    for es in [EsVersion::Es2, EsVersion::Es3] {
        // Fresh: the report below is of the variants this renderer built.
        let mut gpu = Gpu::fresh(es);
        for method in ["forward", "tiled", "clustered"] {
            gpu.r().set_method_named(method).unwrap();
            let (lean, stats) = gpu
                .r()
                .render_offscreen(&s, 128, 72, &RenderOptions::default())
                .unwrap();
            assert!(!stats.scene_features.spot_lights && !stats.scene_features.textures);
            let full_opts = RenderOptions {
                measure: manylight::MeasureOptions {
                    full_variants: true,
                    ..Default::default()
                },
                ..Default::default()
            };
            let (full, _) = gpu.r().render_offscreen(&s, 128, 72, &full_opts).unwrap();
            let d = manylight::metrics::diff(&lean, &full);
            assert!(
                d.max_abs <= 1,
                "{es} {method}: lean and full variants differ by {} / 255",
                d.max_abs
            );
        }
        let report = gpu.r().program_report();
        let with_spot = report
            .iter()
            .filter(|p| ShaderFeatures(p.features).has(ShaderFeatures::SPOT))
            .count();
        let without = report
            .iter()
            .filter(|p| {
                p.shader != "depth" && !ShaderFeatures(p.features).has(ShaderFeatures::SPOT)
            })
            .count();
        assert!(with_spot > 0 && without > 0, "both variants were built");
        let size = |spot: bool| {
            report
                .iter()
                .filter(|p| {
                    p.shader == "clustered"
                        && ShaderFeatures(p.features).has(ShaderFeatures::SPOT) == spot
                })
                .map(|p| p.source_bytes)
                .min()
                .unwrap()
        };
        assert!(size(false) < size(true), "the lean variant is smaller");
    }
}

/// What the test harness's pool relies on (`common::Gpu`): a renderer given the programs an
/// earlier one built on the same context builds none of its own, counts them as its own, and
/// draws the same picture.
#[test]
fn a_renderer_given_an_earlier_ones_programs_builds_none_and_draws_the_same() {
    let s = point_light_scene();
    let opts = RenderOptions::default();
    let ctx = HeadlessContext::new(EsVersion::Es3).expect("a headless ES 3.0 context");
    let mut first = Renderer::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    first.set_method_named("clustered").unwrap();
    let (before, _) = first.render_offscreen(&s, 64, 36, &opts).unwrap();
    let built = first.program_report();
    assert!(!built.is_empty());
    let programs = first.destroy_keeping_programs();
    let mut second = Renderer::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    second.adopt_programs(programs);
    assert_eq!(second.live_gl_objects().programs, built.len() as i64);
    second.set_method_named("clustered").unwrap();
    let (after, _) = second.render_offscreen(&s, 64, 36, &opts).unwrap();
    assert_eq!(second.program_report(), built, "programs built again");
    assert_eq!(second.live_gl_objects().programs, built.len() as i64);
    assert!(before == after, "another picture with the same programs");
    second.destroy();
}

#[test]
fn switching_methods_frees_the_previous_methods_resources() {
    let s = point_light_scene();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let opts = RenderOptions::default();
    gpu.r().set_method_named("forward").unwrap();
    gpu.r().render_offscreen(&s, 64, 36, &opts).unwrap();
    let baseline = gpu.r().live_gl_objects();
    for method in ["clustered", "tiled"] {
        gpu.r().set_method_named(method).unwrap();
        for _ in 0..4 {
            gpu.r().render_offscreen(&s, 64, 36, &opts).unwrap();
        }
        let during = gpu.r().live_gl_objects();
        assert!(
            during.textures > baseline.textures,
            "{method} allocated no textures?"
        );
    }
    gpu.r().set_method_named("forward").unwrap();
    gpu.r().render_offscreen(&s, 64, 36, &opts).unwrap();
    let after = gpu.r().live_gl_objects();
    // Programs stay cached; every texture, buffer and framebuffer returns to the baseline.
    assert_eq!(
        (
            after.textures,
            after.buffers,
            after.framebuffers,
            after.renderbuffers
        ),
        (
            baseline.textures,
            baseline.buffers,
            baseline.framebuffers,
            baseline.renderbuffers
        )
    );
}

#[test]
fn a_method_allocates_nothing_before_it_has_lights_to_draw() {
    let mut s = point_light_scene();
    let lights = std::mem::take(&mut s.lights);
    let mut gpu = Gpu::new(EsVersion::Es2);
    gpu.r().set_method_named("clustered").unwrap();
    let (_, stats) = gpu
        .r()
        .render_offscreen(&s, 64, 36, &RenderOptions::default())
        .unwrap();
    assert_eq!(
        (
            stats.memory.upload_bytes,
            stats.time.assign_ms,
            stats.memory.method_gpu_bytes
        ),
        (0, 0.0, 0),
        "zero lights did light work"
    );
    s.lights = lights;
    let (_, stats) = gpu
        .r()
        .render_offscreen(&s, 64, 36, &RenderOptions::default())
        .unwrap();
    assert!(stats.memory.upload_bytes > 0 && stats.memory.method_gpu_bytes > 0);
}

#[test]
fn bubbles_match_forward_with_every_forward_method() {
    // 96 lights: several over every bubble, and forward over all of them at every pixel (a
    // software GPU's slow part) a third of 256's.
    let s = scene::builtin::build("bubbles", Some((96, 4))).unwrap();
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::new(es);
        let opts = RenderOptions::default();
        gpu.r().set_method_named("forward").unwrap();
        let (reference, stats) = gpu.r().render_offscreen(&s, 192, 108, &opts).unwrap();
        assert!(stats.scene_features.transparency);
        for method in ["tiled", "clustered"] {
            gpu.r().set_method_named(method).unwrap();
            let (img, _) = gpu.r().render_offscreen(&s, 192, 108, &opts).unwrap();
            let d = manylight::metrics::diff(&reference, &img);
            assert!(
                d.max_abs <= 2,
                "{es} {method}: bubbles differ from forward by {} / 255",
                d.max_abs
            );
        }
        // The bubbles are really there: the same view without them differs (clustered draws it:
        // any method would, and it equals forward above).
        let mut opaque = s.clone();
        opaque.objects.retain(|o| !opaque_is_transparent(&s, o));
        let (without, _) = gpu.r().render_offscreen(&opaque, 192, 108, &opts).unwrap();
        assert!(
            manylight::metrics::diff(&reference, &without).over_2 > 0.02,
            "{es}: bubbles invisible"
        );
    }
}

/// Transparent objects alone: no method draws a depth prepass (its program built and bound
/// with nothing to draw), and deferred makes no G-buffer nor light pass, which would hold and
/// light nothing (405 504 bytes and four programs at 128×72 for one forward draw's picture).
/// With an opaque object too, deferred lays the opaque depth again for the glass's pass (the
/// depth program; the composite's copy of it may lie a step behind, which showed glass lying
/// on the floor): the glass's forward pass adds no prepass of its own.
#[test]
fn transparent_objects_alone_pay_for_no_depth_pass_or_gbuffer() {
    let mut glass = scene::builtin::build("bubbles", Some((16, 4))).unwrap();
    let all = glass.clone();
    glass.objects.retain(|o| opaque_is_transparent(&all, o));
    assert!(!glass.objects.is_empty());
    let mut mixed = glass.clone();
    let floor = all.objects.iter().find(|o| !opaque_is_transparent(&all, o));
    mixed.objects.push(floor.expect("an opaque object").clone());
    let opts = RenderOptions::default();
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::new(es);
        gpu.r().set_method_named("forward").unwrap();
        let (reference, _) = gpu.r().render_offscreen(&glass, 128, 72, &opts).unwrap();
        for method in common::methods_on(es) {
            // A renderer of its own: the first frame builds every program it draws with.
            let mut fresh = Gpu::fresh(es);
            fresh.r().set_method_named(method).unwrap();
            let (img, stats) = fresh.r().render_offscreen(&glass, 128, 72, &opts).unwrap();
            let what = format!("{es} {method}");
            assert!(stats.lights.visible > 0, "{what}");
            // The shading program alone (auto draws these 16 lights with forward).
            assert_eq!(stats.programs_built, 1, "{what}: programs");
            assert_eq!(stats.memory.gbuffer_bytes, 0, "{what}: G-buffer");
            let d = manylight::metrics::diff(&reference, &img);
            assert!(d.max_abs <= 2, "{what}: {d:?}");
            if *method == "deferred" {
                // The G-buffer, light and composite programs, the floor's depth again, and
                // forward's for the glass.
                let (_, stats) = fresh.r().render_offscreen(&mixed, 128, 72, &opts).unwrap();
                let built: Vec<_> = (fresh.r().program_report().iter())
                    .map(|p| p.shader)
                    .collect();
                assert!(built.contains(&"gbuffer"), "{what}: {built:?}");
                assert!(built.contains(&"depth"), "{what} with a floor: {built:?}");
                let gbuffer = stats.memory.gbuffer_bytes;
                assert!(gbuffer > 0, "{what} with a floor");
                // The floor gone, the G-buffer is kept a while (it may come back), then freed.
                let held: Vec<_> = (0..manylight::methods::IDLE_FRAMES_KEPT)
                    .map(|_| {
                        let (_, stats) =
                            fresh.r().render_offscreen(&glass, 128, 72, &opts).unwrap();
                        stats.memory.method_gpu_bytes
                    })
                    .collect();
                let last = held.len() - 1;
                assert!(held[..last].iter().all(|&b| b == held[0]), "{held:?}");
                assert!(held[last] + gbuffer <= held[0], "{held:?}");
            }
        }
    }
}

fn opaque_is_transparent(s: &scene::Scene, o: &scene::Object) -> bool {
    s.materials[o.material].is_transparent()
}

/// The pillars with a 64×64 texture on their first material: a level with a mesh and an image
/// of its own.
fn textured_pillars() -> scene::Scene {
    let mut s = scene::builtin::build("pillars", Some((8, 1))).unwrap();
    let image = image::RgbaImage::from_fn(64, 64, |x, y| {
        image::Rgba([(x * 4) as u8, (y * 4) as u8, 90, 255])
    });
    s.materials[0].diffuse_texture = Some(Arc::new(scene::Texture::new("checks", image)));
    s
}

/// A texture a game made past `GL_MAX_TEXTURE_SIZE` is uploaded within it, and that is said
/// once a renderer, naming it and both sizes (it was shrunk in silence), also when another
/// replaces it; one within the limit is not.
#[test]
fn a_texture_past_the_texture_limit_is_said_when_uploaded_smaller() {
    common::warnings::install();
    let said = || common::warnings::warnings_containing("past this context's GL_MAX_TEXTURE_SIZE");
    let mut gpu = Gpu::new(EsVersion::Es3);
    let opts = RenderOptions::default();
    gpu.r()
        .render_offscreen(&textured_pillars(), 32, 18, &opts)
        .unwrap();
    assert!(said().is_empty(), "{:?}", said());
    let max = gpu.r().caps().max_texture_size as u32;
    let mut s = textured_pillars();
    for k in 0..3 {
        let wide = image::RgbaImage::from_pixel(max + 1, 1, image::Rgba([200, 90, k, 255]));
        s.materials[0].diffuse_texture = Some(Arc::new(scene::Texture::new("wide", wide)));
        gpu.r().render_offscreen(&s, 32, 18, &opts).unwrap();
    }
    let said = said();
    assert_eq!(said.len(), 1, "{said:?}");
    let expected = format!("`wide` is {}×1, past", max + 1);
    assert!(said[0].contains(&expected), "{}", said[0]);
    assert!(
        said[0].contains(&format!("uploaded at {max}×1")),
        "{}",
        said[0]
    );
}

#[test]
fn uploads_no_scene_draws_are_freed_on_request_while_the_game_holds_them() {
    let mut gpu = Gpu::new(EsVersion::Es3);
    let (level_a, level_b) = (
        textured_pillars(),
        scene::builtin::build("plane", Some((8, 1))).unwrap(),
    );
    let opts = RenderOptions::default();
    let render =
        |gpu: &mut Gpu, s: &scene::Scene| gpu.r().render_offscreen(s, 32, 18, &opts).unwrap();
    let (first_a, stats) = render(&mut gpu, &level_a);
    let a = stats.memory.scene_gpu_bytes;
    // At least the texture's 64×64 texels and their mipmaps.
    assert!(a > 64 * 64 * 4, "{a}");
    let (first_b, stats) = render(&mut gpu, &level_b);
    let both = stats.memory.scene_gpu_bytes;
    assert!(
        both > a,
        "the plane's mesh is uploaded beside the pillars' ({a}, {both})"
    );
    // The game still holds level A's meshes and image: only asked, they go.
    let before = gpu.r().live_gl_objects();
    let freed = gpu.r().free_unused_uploads(&[&level_b]).unwrap();
    assert_eq!(freed, a, "level A's uploads, and only those");
    let after = gpu.r().live_gl_objects();
    assert!(
        after.buffers < before.buffers && after.textures < before.textures,
        "{before:?} → {after:?}"
    );
    let (again_b, stats) = render(&mut gpu, &level_b);
    assert_eq!(stats.memory.scene_gpu_bytes, both - a);
    assert_eq!(manylight::metrics::diff(&first_b, &again_b).max_abs, 0);
    assert_eq!(gpu.r().free_unused_uploads(&[&level_b]).unwrap(), 0);
    // Level A drawn again uploads what it needs, and looks as it did.
    let (again_a, stats) = render(&mut gpu, &level_a);
    assert_eq!(stats.memory.scene_gpu_bytes, both);
    assert_eq!(manylight::metrics::diff(&first_a, &again_a).max_abs, 0);
    assert_eq!(
        gpu.r().free_unused_uploads(&[&level_a, &level_b]).unwrap(),
        0
    );
}

/// A level the game drops (it held the only `Arc`s of its meshes and images) is freed by the
/// next frame of another, its CPU mesh and its GPU uploads, with every method. The automatic
/// grid's ray caster kept the meshes until its next choice (240 frames of a still view): the
/// default method held two levels' uploads for four seconds. The next level is the same one
/// loaded again (new meshes, the same view and extent), so the grid has no cause to choose.
#[test]
fn a_level_the_game_drops_is_freed_by_the_next_frame() {
    common::each_method(|es, method, gpu| {
        let opts = RenderOptions::default();
        let mut render = |s: &scene::Scene| {
            let (_, stats) = gpu.r().render_offscreen(s, 32, 18, &opts).unwrap();
            (stats.memory.scene_gpu_bytes, stats.grid.reason)
        };
        let level = textured_pillars();
        let mesh = Arc::downgrade(&level.objects[0].mesh);
        let (one_level, _) = render(&level);
        assert!(one_level > 64 * 64 * 4);
        for _ in 0..3 {
            render(&level);
        }
        drop(level);
        let (after, reason) = render(&textured_pillars());
        assert!(
            mesh.upgrade().is_none(),
            "{es} {method}: the dropped level's mesh is alive ({reason:?})"
        );
        assert_eq!(after, one_level, "{es} {method}: two levels' uploads");
    });
}

/// `scene_upload_bytes` says what a frame uploaded of the scene's meshes and images: all of
/// it on the first frame, nothing on the next, and a mesh the game rebuilt (a new `Arc` of the
/// same data) on the frame after that, every time it does.
#[test]
fn a_frame_reports_the_meshes_and_images_it_uploaded() {
    common::each_method(|es, method, gpu| {
        let opts = RenderOptions::default();
        let mut uploaded = |s: &scene::Scene| {
            let (_, stats) = gpu.r().render_offscreen(s, 32, 18, &opts).unwrap();
            (
                stats.memory.scene_upload_bytes,
                stats.memory.scene_gpu_bytes,
            )
        };
        let mut level = textured_pillars();
        let (first, held) = uploaded(&level);
        assert_eq!(first, held, "{es} {method}: the first frame");
        assert_eq!(uploaded(&level).0, 0, "{es} {method}: a still frame");
        let rebuilt = Arc::new((*level.objects[0].mesh).clone());
        for _ in 0..2 {
            level.objects[0].mesh = Arc::new((*rebuilt).clone());
            let (bytes, _) = uploaded(&level);
            // The mesh's vertices, 32 bytes or more each, and its indices.
            let least = rebuilt.positions.len() * 32 + rebuilt.indices.len() * 2;
            assert!(
                bytes >= least && bytes < first,
                "{es} {method}: {bytes} bytes for a rebuilt mesh of {least}"
            );
        }
    });
}

/// Lights that reach nothing in view cost what no lights cost, with every method: no
/// assignment, no upload, none counted visible, the ambient-only picture. One whose centre
/// lies outside the view but whose sphere reaches into it still lights the frame's edge.
#[test]
fn lights_out_of_view_cost_nothing_and_one_reaching_in_still_lights() {
    let (w, h) = (64u32, 36u32);
    let mut s = scene::builtin::build("plane", None).unwrap();
    // Straight down at the plane (it lies across z = 0), 2 high and 2·16/9 wide.
    s.camera = scene::Camera {
        position: DVec3::new(0.0, 0.0, 5.0),
        target: DVec3::ZERO,
        up: DVec3::Y,
        projection: scene::Projection::Orthographic {
            height: 4.0,
            near: 0.1,
            far: 10.0,
        },
    };
    let half_x = 2.0 * w as f64 / h as f64;
    let point = |x: f64, z: f64| Light::point(DVec3::new(x, 0.0, z), 1.0, Vec3::ONE, 2.0);
    // Behind the camera, past the far plane and past the right edge, each by more than its
    // radius; then one past the right edge by less.
    let out = vec![point(0.0, 7.0), point(0.0, -6.0), point(half_x + 1.5, 0.2)];
    let mut reaching_in = out.clone();
    reaching_in.push(point(half_x + 0.5, 0.2));
    let mut unlit = s.clone();
    unlit.lights.clear();
    common::each_method(|es, method, gpu| {
        let opts = RenderOptions::default();
        let ambient = gpu.render(&unlit, w, h, &opts);
        s.lights = out.clone();
        let (img, stats) = gpu.r().render_offscreen(&s, w, h, &opts).unwrap();
        assert_eq!(
            (
                stats.memory.upload_bytes,
                stats.time.assign_ms,
                stats.lights.active,
                stats.lights.visible
            ),
            (0, 0.0, 3, 0),
            "{es} {method}: lights out of view did light work"
        );
        assert_eq!(
            manylight::metrics::diff(&ambient, &img).max_abs,
            0,
            "{es} {method}"
        );
        s.lights = reaching_in.clone();
        let (img, stats) = gpu.r().render_offscreen(&s, w, h, &opts).unwrap();
        assert!(
            stats.lights.visible >= 1,
            "{es} {method}: {:?}",
            stats.lights
        );
        let edge = |img: &image::RgbaImage| img.get_pixel(w - 1, h / 2).0;
        let (lit, dark) = (edge(&img), edge(&ambient));
        assert!(
            lit[0] > dark[0] + 20,
            "{es} {method}: the light reaching in left the edge at {lit:?} (ambient {dark:?})"
        );
    });
}

/// An occlusion map of strength 0 and an emissive texture without emission change no pixel:
/// neither is uploaded; a normal map is, on a mesh with tangents only. (A glTF normal map of
/// scale 0 that changes no pixel is left out at load: `second_set.rs`.)
#[test]
fn maps_that_change_no_pixel_are_not_uploaded() {
    use manylight::scene::surface_maps::{MapTexture, TextureTransform};
    let mut s = scene::builtin::build("plane", Some((8, 1))).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let mut scene_bytes = |s: &scene::Scene| {
        let (_, stats) = (gpu.r())
            .render_offscreen(s, 32, 18, &RenderOptions::default())
            .unwrap();
        stats.memory.scene_gpu_bytes
    };
    let bare = scene_bytes(&s);
    let map = |v: u8| {
        let image = image::RgbaImage::from_pixel(64, 64, image::Rgba([v, v, 255, 255]));
        Some(MapTexture {
            texture: Arc::new(scene::Texture::new(format!("map {v}"), image)),
            transform: TextureTransform::IDENTITY,
        })
    };
    for m in &mut s.materials {
        m.maps.occlusion = map(100);
        m.maps.occlusion_strength = 0.0;
        m.maps.emissive_texture = map(50);
        m.maps.emissive = Vec3::ZERO;
    }
    assert_eq!(
        scene_bytes(&s),
        bare,
        "maps that change nothing were uploaded"
    );
    for m in &mut s.materials {
        m.maps.normal = map(128);
    }
    // Not on a mesh without tangents, which cannot apply it.
    assert_eq!(
        scene_bytes(&s),
        bare,
        "a normal map without tangents was uploaded"
    );
    for o in &mut s.objects {
        let (mesh, _) = (*o.mesh).clone().with_generated_tangents().unwrap();
        o.mesh = Arc::new(mesh);
    }
    let mapped = scene_bytes(&s);
    assert!(mapped >= bare + 64 * 64 * 4, "{bare} → {mapped} bytes");
}

/// A metallic-roughness texture on a Blinn-Phong material, whose shader has nothing to read it
/// with, is neither uploaded nor a variant of its own (it was both: 349 525 bytes and a
/// program compiling the same code), and the picture is the same; on a metallic-roughness
/// material it is both.
#[test]
fn a_metallic_roughness_texture_on_a_blinn_phong_material_costs_nothing() {
    use manylight::methods::ShaderFeatures;
    use manylight::scene::surface_maps::{MapTexture, TextureTransform};
    let mut s = scene::builtin::build("plane", Some((20, 2))).unwrap();
    let mut gpu = Gpu::fresh(EsVersion::Es3);
    let mut render = |s: &scene::Scene| {
        let (image, stats) = (gpu.r())
            .render_offscreen(s, 96, 54, &RenderOptions::default())
            .unwrap();
        let report = gpu.r().program_report();
        let mr = (report.iter())
            .filter(|p| ShaderFeatures(p.features).has(ShaderFeatures::MR_TEXTURE))
            .count();
        (image, stats.memory.scene_gpu_bytes, report.len(), mr)
    };
    let (plain, bytes, programs, _) = render(&s);
    let texels = image::RgbaImage::from_fn(256, 256, |x, y| {
        image::Rgba([(x * 7) as u8, (y * 5) as u8, 90, 255])
    });
    for m in &mut s.materials {
        m.maps.metallic_roughness = Some(MapTexture {
            texture: Arc::new(scene::Texture::new("mr", texels.clone())),
            transform: TextureTransform::IDENTITY,
        });
    }
    let (mapped, mapped_bytes, mapped_programs, mr) = render(&s);
    assert_eq!(mapped_bytes, bytes, "the texture was uploaded");
    assert_eq!((mapped_programs, mr), (programs, 0), "a variant of its own");
    assert_eq!(manylight::metrics::diff(&plain, &mapped).max_abs, 0);
    for m in &mut s.materials {
        m.model = scene::MaterialModel::MetallicRoughness;
    }
    let (_, metal_bytes, _, mr) = render(&s);
    assert!(
        metal_bytes >= bytes + 256 * 256 * 4 && mr > 0,
        "{metal_bytes} bytes, {mr}"
    );
}

/// Textures no object can sample are not uploaded: a material no object draws with (a game's
/// palette, an MTL's unused material: it was, 1.4 MB for 512²) and a texture on a mesh
/// without the coordinates it reads. Once an object samples it, it is; and a material whose
/// objects went is freed on request, though the scene still lists it.
#[test]
fn textures_no_object_samples_are_neither_uploaded_nor_kept() {
    let base = scene::builtin::build("plane", Some((8, 1))).unwrap();
    let texels = image::RgbaImage::from_fn(64, 64, |x, y| {
        image::Rgba([(x * 4) as u8, (y * 4) as u8, 90, 255])
    });
    let mut textured = Material::flat("textured", Vec3::splat(0.8));
    textured.diffuse_texture = Some(Arc::new(scene::Texture::new("texels", texels)));
    let mut palette = base.clone();
    let m = palette.add_material(textured);
    let untextured = |s: &scene::Scene| {
        let mut s = s.clone();
        s.materials[m].diffuse_texture = None;
        s
    };
    let mut without_uvs = palette.clone();
    let mut mesh = (*without_uvs.objects[0].mesh).clone();
    mesh.uvs.clear();
    without_uvs.objects[0].mesh = Arc::new(mesh);
    without_uvs.objects[0].material = m;
    let mut drawn = palette.clone();
    drawn.objects[0].material = m;
    let fresh = |s: &scene::Scene| {
        let (image, stats) = (Gpu::new(EsVersion::Es3).r())
            .render_offscreen(s, 64, 36, &RenderOptions::default())
            .unwrap();
        (image, stats.memory.scene_gpu_bytes)
    };
    for (what, s) in [
        ("of a palette material", &palette),
        ("on a mesh without uvs", &without_uvs),
    ] {
        let (with, bytes) = fresh(s);
        let (without, plain_bytes) = fresh(&untextured(s));
        assert_eq!(bytes, plain_bytes, "a texture {what} was uploaded");
        assert_eq!(
            manylight::metrics::diff(&with, &without).max_abs,
            0,
            "{what}"
        );
    }
    let (_, drawn_bytes) = fresh(&drawn);
    let (_, palette_bytes) = fresh(&palette);
    assert!(
        drawn_bytes >= palette_bytes + 64 * 64 * 4,
        "drawn: uploaded"
    );
    let mut gpu = Gpu::new(EsVersion::Es3);
    let opts = RenderOptions::default();
    gpu.r().render_offscreen(&drawn, 64, 36, &opts).unwrap();
    gpu.r().render_offscreen(&palette, 64, 36, &opts).unwrap();
    let freed = gpu.r().free_unused_uploads(&[&palette]).unwrap();
    // The plane's mesh, which the palette scene still draws, keeps the coordinates the texture
    // read (8 bytes a vertex); untextured, it was uploaded without.
    let coordinates = 8 * base.objects[0].mesh.positions.len();
    assert_eq!(
        freed,
        drawn_bytes - palette_bytes - coordinates,
        "the texture whose objects went"
    );
}

/// An image sampled only without mipmaps (glTF `minFilter` NEAREST or LINEAR: pixel art, UI
/// atlases, light maps) has none made: its base level's bytes, a third less than it took.
/// Sampled through mipmaps it gets them in the frame that first does (counted as that
/// frame's scene upload), and the picture is a fresh renderer's.
#[test]
fn mipmaps_are_made_only_for_an_image_sampled_through_them() {
    use manylight::scene::texture::{Filter, Sampling};
    let mut s = scene::builtin::build("plane", Some((8, 1))).unwrap();
    let base = |s: &scene::Scene| {
        let mut s = s.clone();
        s.materials[0].diffuse_texture = None;
        s
    };
    let texels = image::RgbaImage::from_fn(64, 64, |x, y| {
        image::Rgba([(x * 4) as u8, (y * 4) as u8, 90, 255])
    });
    let texture = scene::Texture::new("texels", texels);
    let flat = Sampling {
        mipmap: None,
        ..texture.sampling
    };
    s.materials[0].diffuse_texture = Some(Arc::new(texture.with_sampling(flat)));
    let mut gpu = Gpu::new(EsVersion::Es3);
    let render = |gpu: &mut Gpu, s: &scene::Scene| {
        let (image, stats) = (gpu.r())
            .render_offscreen(s, 64, 36, &RenderOptions::default())
            .unwrap();
        let memory = stats.memory;
        (image, memory.scene_gpu_bytes, memory.scene_upload_bytes)
    };
    let (_, untextured, _) = render(&mut Gpu::new(EsVersion::Es3), &base(&s));
    let (_, bytes, _) = render(&mut gpu, &s);
    // And the mesh's texture coordinates, which the untextured plane does not upload.
    let coordinates = 8 * s.objects[0].mesh.positions.len();
    assert_eq!(
        bytes,
        untextured + 64 * 64 * 4 + coordinates,
        "the base level alone"
    );
    let mipmapped = Sampling {
        mipmap: Some(Filter::Linear),
        ..flat
    };
    let m = &mut s.materials[0];
    let texture = m.diffuse_texture.as_ref().unwrap().with_sampling(mipmapped);
    m.diffuse_texture = Some(Arc::new(texture));
    let (again, bytes, uploaded) = render(&mut gpu, &s);
    assert_eq!(
        bytes,
        untextured + 64 * 64 * 4 * 4 / 3 + coordinates,
        "mipmaps made"
    );
    assert_eq!(uploaded, 64 * 64 * 4 / 3, "the frame's scene upload");
    let (fresh, _, _) = render(&mut Gpu::new(EsVersion::Es3), &s);
    assert_eq!(manylight::metrics::diff(&fresh, &again).max_abs, 0);
}

/// A method frees what it holds for lights after 120 frames in a row without any (a sun-only
/// stretch of a day: deferred's G-buffer alone is about 100 MB at 1080p; they were kept for
/// good), keeps it through 119, and the next lit frame draws as before.
#[test]
fn methods_free_their_light_resources_after_120_frames_without_lights() {
    use manylight::methods::IDLE_FRAMES_KEPT;
    let lit = scene::builtin::build("plane", Some((50, 3))).unwrap();
    let mut unlit = lit.clone();
    unlit.truncate_lights(0);
    let mut gpu = Gpu::new(EsVersion::Es3);
    let opts = RenderOptions::default();
    for method in ["tiled", "clustered", "deferred", "auto"] {
        gpu.r().set_method_named(method).unwrap();
        let mut frame = |s: &scene::Scene| {
            let (image, stats) = gpu.r().render_offscreen(s, 32, 18, &opts).unwrap();
            (image, stats.memory.method_gpu_bytes)
        };
        let (first, held) = frame(&lit);
        for k in 1..IDLE_FRAMES_KEPT {
            assert_eq!(frame(&unlit).1, held, "{method}: kept at {k}");
        }
        let freed = frame(&unlit).1;
        match method {
            "auto" => assert!(freed < held / 4, "{method}: {held} → {freed} bytes"),
            _ => assert_eq!(freed, 0, "{method}: {held} bytes held"),
        }
        let (again, bytes) = frame(&lit);
        assert_eq!(bytes, held, "{method}: made again");
        assert_eq!(
            manylight::metrics::diff(&first, &again).max_abs,
            0,
            "{method}"
        );
    }
}

/// A reaching count (`CountKind::Reaching`) draws with a plain forward pass of the renderer's
/// own, whatever its method. 120 frames without such a count free that pass's light data, as
/// a method's are freed (it held them for the renderer's life: 4 MiB after a count of 60 000
/// lights), and a later count makes it again and counts the same.
#[test]
fn a_reaching_counts_own_pass_is_freed_after_120_frames_without_one() {
    use manylight::methods::IDLE_FRAMES_KEPT;
    use manylight::CountKind;
    let lit = scene::builtin::build("plane", Some((50, 3))).unwrap();
    let mut unlit = lit.clone();
    unlit.truncate_lights(0);
    let mut gpu = Gpu::new(EsVersion::Es3);
    gpu.r().set_method_named("clustered").unwrap();
    let opts = RenderOptions::default();
    let count = |gpu: &mut Gpu| {
        let (counts, stats) = (gpu.r())
            .render_light_counts(&lit, 32, 18, &opts, CountKind::Reaching)
            .unwrap();
        (counts, stats.memory.method_gpu_bytes)
    };
    let (first, held) = count(&mut gpu);
    assert!(held > 0, "the pass holds its lights");
    let bytes = |gpu: &mut Gpu| {
        let (_, stats) = gpu.r().render_offscreen(&unlit, 32, 18, &opts).unwrap();
        stats.memory.method_gpu_bytes
    };
    for k in 1..IDLE_FRAMES_KEPT {
        assert_eq!(bytes(&mut gpu), held, "kept at {k}");
    }
    assert_eq!(bytes(&mut gpu), 0, "{held} bytes held");
    let (again, made) = count(&mut gpu);
    assert_eq!(made, held, "made again");
    assert!(first == again, "the same counts");
}

/// A mesh without texture coordinates (an OBJ without `vt`, a code-built one) uploads its
/// positions and normals alone, 24 bytes a vertex (it uploaded 8 bytes of zeros more), and
/// draws the picture it drew with coordinates, on ES 2.0 and 3.0, after a textured mesh that
/// had them (the constant stands in for the array).
#[test]
fn a_mesh_without_texture_coordinates_uploads_none() {
    let with = scene::builtin::build("plane", Some((8, 2))).unwrap();
    let mut without = with.clone();
    let mut mesh = (*without.objects[0].mesh).clone();
    mesh.uvs.clear();
    let (vertices, indices) = (mesh.positions.len(), mesh.indices.len());
    without.objects[0].mesh = Arc::new(mesh);
    let mut textured = with.clone();
    let texels = image::RgbaImage::from_fn(8, 8, |x, y| {
        image::Rgba([(x * 30) as u8, (y * 30) as u8, 90, 255])
    });
    textured.materials[0].diffuse_texture = Some(Arc::new(scene::Texture::new("t", texels)));
    for es in [EsVersion::Es3, EsVersion::Es2] {
        let mut gpu = Gpu::new(es);
        let mut render = |s: &scene::Scene| {
            let (image, stats) = (gpu.r())
                .render_offscreen(s, 64, 36, &RenderOptions::default())
                .unwrap();
            (image, stats.memory.scene_upload_bytes)
        };
        let (picture, _) = render(&with);
        render(&textured);
        let (bare, bytes) = render(&without);
        assert_eq!(
            bytes,
            vertices * 24 + indices * 2,
            "{es}: the mesh's upload"
        );
        assert_eq!(manylight::metrics::diff(&picture, &bare).max_abs, 0, "{es}");
    }
}

/// A mesh with texture coordinates that no texture reads (the built-ins' meshes, an OBJ with
/// `vt` under an untextured material) uploads positions and normals alone, 24 bytes a vertex
/// where it uploaded 32; once a textured material draws it, the same renderer uploads the
/// coordinates and draws what a fresh renderer does.
#[test]
fn texture_coordinates_no_texture_reads_are_not_uploaded() {
    let plain = scene::builtin::build("plane", Some((8, 2))).unwrap();
    let mesh = &plain.objects[0].mesh;
    assert!(!mesh.uvs.is_empty());
    let (vertices, indices) = (mesh.positions.len(), mesh.indices.len());
    let mut textured = plain.clone();
    let texels = image::RgbaImage::from_fn(8, 8, |x, y| {
        image::Rgba([(x * 30) as u8, (y * 30) as u8, 90, 255])
    });
    let m = textured.objects[0].material;
    textured.materials[m].diffuse_texture = Some(Arc::new(scene::Texture::new("t", texels)));
    let render = |gpu: &mut Gpu, s: &scene::Scene| {
        (gpu.r())
            .render_offscreen(s, 64, 36, &RenderOptions::default())
            .unwrap()
    };
    for es in [EsVersion::Es3, EsVersion::Es2] {
        let mut gpu = Gpu::new(es);
        let (_, stats) = render(&mut gpu, &plain);
        let meshes: usize = (plain.objects.iter())
            .map(|o| o.mesh.positions.len() * 24 + o.mesh.indices.len() * 2)
            .sum();
        assert_eq!(
            plain.objects.len(),
            1,
            "one mesh: {vertices} vertices, {indices} indices"
        );
        assert_eq!(
            stats.memory.scene_upload_bytes, meshes,
            "{es}: the untextured upload"
        );
        let (again, stats) = render(&mut gpu, &textured);
        let (fresh, fresh_stats) = render(&mut Gpu::new(es), &textured);
        assert_eq!(
            stats.memory.scene_gpu_bytes, fresh_stats.memory.scene_gpu_bytes,
            "{es}: the coordinates uploaded"
        );
        assert_eq!(manylight::metrics::diff(&fresh, &again).max_abs, 0, "{es}");
        assert!(fresh_stats.memory.scene_gpu_bytes >= meshes + 8 * vertices + 8 * 8 * 4);
    }
}

/// A burst of lights (5 000 for three frames, an explosion's sparks) leaves the light data
/// near the size the 20 moving lights after it need once the textures (deferred: instance
/// buffers) have been filled to a quarter at most for `SHRINK_AFTER` uploads (clustered held
/// 36× its memory for good, tiled 16×), and the picture is a fresh renderer's.
#[test]
fn a_burst_of_lights_does_not_hold_its_memory_for_good() {
    use manylight::gl::texture::SHRINK_AFTER;
    let few = scene::builtin::build("plane", Some((20, 5))).unwrap();
    let many = scene::builtin::build("plane", Some((5000, 5))).unwrap();
    let opts = RenderOptions::default();
    let moved = |s: &scene::Scene, k: usize| {
        let mut s = s.clone();
        for l in &mut s.lights {
            l.position.x += 1e-3 * k as f64;
        }
        s
    };
    for method in ["forward", "tiled", "clustered", "deferred"] {
        let mut gpu = Gpu::new(EsVersion::Es3);
        gpu.r().set_method_named(method).unwrap();
        let bytes = |gpu: &mut Gpu, s: &scene::Scene| {
            let (image, stats) = gpu.r().render_offscreen(s, 16, 9, &opts).unwrap();
            (image, stats.memory.method_gpu_bytes)
        };
        // Three frames fill the culled methods' ring of three texture sets.
        let mut small = 0;
        for k in 0..3 {
            small = bytes(&mut gpu, &moved(&few, k)).1;
        }
        let mut held = 0;
        for k in 0..3 {
            held = bytes(&mut gpu, &moved(&many, k)).1;
        }
        assert!(
            held >= 4 * small,
            "{method}: {small} → {held} bytes for the burst"
        );
        // The culled methods' three texture sets each take a third of the uploads.
        let mut last = (image::RgbaImage::new(1, 1), held);
        for k in 0..3 * SHRINK_AFTER as usize + 3 {
            last = bytes(&mut gpu, &moved(&few, k));
        }
        // A texture the few fill more than a quarter of keeps its rows (tiled's grid: 2).
        let kept = last.1;
        assert!(
            kept <= 2 * small && 4 * kept <= held,
            "{method}: {small} → {held} → {kept}"
        );
        let k = 3 * SHRINK_AFTER as usize + 2;
        let mut other = Gpu::fresh(EsVersion::Es3);
        other.r().set_method_named(method).unwrap();
        let fresh = bytes(&mut other, &moved(&few, k)).0;
        assert_eq!(
            manylight::metrics::diff(&fresh, &last.0).max_abs,
            0,
            "{method}"
        );
    }
}

/// A burst of lights before a still scene: its frames upload nothing, yet after
/// `SHRINK_AFTER` of them the light data holds what the few lights need (forward kept 16× it
/// for good, clustered 18×), sent once more, and the picture does not change. Clustered's
/// automatic grid settles first, which uploads lists; still frames count from the last.
#[test]
fn a_still_scene_after_a_burst_does_not_hold_its_memory() {
    use manylight::gl::texture::SHRINK_AFTER;
    let few = scene::builtin::build("plane", Some((20, 5))).unwrap();
    let mut many = scene::builtin::build("plane", Some((5000, 5))).unwrap();
    let opts = RenderOptions::default();
    for method in ["forward", "tiled", "clustered", "deferred"] {
        let mut gpu = Gpu::new(EsVersion::Es3);
        gpu.r().set_method_named(method).unwrap();
        let mut frame = |s: &scene::Scene| {
            let (image, stats) = gpu.r().render_offscreen(s, 16, 9, &opts).unwrap();
            (
                image,
                stats.memory.method_gpu_bytes,
                stats.memory.upload_bytes,
            )
        };
        let small = frame(&few).1;
        let mut held = 0;
        for k in 0..3 {
            many.lights[0].position.x += 1e-3 * k as f64;
            held = frame(&many).1;
        }
        assert!(held >= 4 * small, "{method}: {small} → {held} bytes");
        // The last frame that uploaded lists (memory kept), and the last that freed memory.
        let (mut listed, mut shrunk) = (0, None);
        let mut before = frame(&few);
        for i in 1..=2 * SHRINK_AFTER as usize {
            let now = frame(&few);
            if now.1 < before.1 {
                let diff = manylight::metrics::diff(&before.0, &now.0);
                assert_eq!(diff.max_abs, 0, "{method}: the frame that freed memory");
                shrunk = Some(i);
            } else if now.2 > 0 {
                listed = i;
            }
            before = now;
        }
        let kept = before.1;
        assert!(
            kept <= 2 * small && 4 * kept <= held,
            "{method}: {small} → {held} → {kept} bytes"
        );
        let shrunk = shrunk.expect("shrank above");
        assert!(
            listed < shrunk && shrunk <= listed + SHRINK_AFTER as usize,
            "{method}: lists uploaded at frame {listed}, memory freed at {shrunk}"
        );
        assert_eq!(before.2, 0, "{method}: the last frame uploaded");
    }
}

/// Deferred: a burst of lights that take a proxy the later lights do not (lights around the
/// eye: far side or full screen) frees that proxy's instance stream after `SHRINK_AFTER`
/// frames without lights for it; it kept the burst's store for good (helper-148).
#[test]
fn a_burst_on_a_proxy_later_lights_leave_unused_is_freed() {
    use manylight::gl::texture::SHRINK_AFTER;
    let few = scene::builtin::build("plane", Some((20, 5))).unwrap();
    let mut many = scene::builtin::build("plane", Some((5000, 5))).unwrap();
    let eye = many.camera.position;
    for (i, l) in many.lights.iter_mut().enumerate() {
        l.position = eye + DVec3::new((i % 7) as f64 * 0.01, 0.0, -0.05);
        l.radius = 500.0;
    }
    let opts = RenderOptions::default();
    let mut gpu = Gpu::new(EsVersion::Es3);
    gpu.r().set_method_named("deferred").unwrap();
    let mut bytes = |s: &scene::Scene| {
        let (_, stats) = gpu.r().render_offscreen(s, 16, 9, &opts).unwrap();
        stats.memory.method_gpu_bytes
    };
    let mut small = 0;
    for _ in 0..3 {
        small = bytes(&few);
    }
    let held = bytes(&many);
    let mut kept = 0;
    for _ in 0..SHRINK_AFTER {
        kept = bytes(&few);
    }
    assert!(
        4 * kept <= held && kept <= 2 * small,
        "{small} → {held} → {kept} bytes"
    );
}

/// A mesh built with a second coordinate set that no texture reads does not upload it (8 bytes
/// a vertex); once a material reads it, the same renderer uploads it and draws what a fresh
/// one does (the texture's colours at the flipped coordinates, not its texel at (0, 0)).
#[test]
fn a_second_coordinate_set_is_uploaded_once_a_texture_reads_it() {
    let mut s = scene::builtin::build("plane", Some((8, 1))).unwrap();
    let plain_mesh = s.objects[0].mesh.clone();
    let flipped = (plain_mesh.uvs.iter())
        .map(|uv| glam::Vec2::ONE - *uv)
        .collect();
    let with_second = Arc::new((*plain_mesh).clone().with_second_uvs(flipped).unwrap());
    let vertices = with_second.positions.len();
    let texels = image::RgbaImage::from_fn(2, 2, |x, y| {
        image::Rgba([60 + 150 * x as u8, 90, 40 + 150 * y as u8, 255])
    });
    let m = s.objects[0].material;
    s.materials[m].diffuse_texture = Some(Arc::new(scene::Texture::new("checks", texels)));
    let render = |gpu: &mut Gpu, s: &scene::Scene| {
        let (image, stats) = (gpu.r())
            .render_offscreen(s, 64, 36, &RenderOptions::default())
            .unwrap();
        (image, stats.memory.scene_gpu_bytes)
    };
    for es in [EsVersion::Es3, EsVersion::Es2] {
        let mut plain = s.clone();
        plain.objects[0].mesh = plain_mesh.clone();
        let mut unread = s.clone();
        unread.objects[0].mesh = with_second.clone();
        let mut gpu = Gpu::new(es);
        let (_, plain_bytes) = render(&mut gpu, &plain);
        let mut reused = Gpu::new(es);
        let (_, unread_bytes) = render(&mut reused, &unread);
        assert_eq!(
            unread_bytes, plain_bytes,
            "{es}: an unread second set was uploaded"
        );
        let mut read = unread.clone();
        read.materials[m].maps.base_transform.uv_set = 1;
        let (again, read_bytes) = render(&mut reused, &read);
        assert_eq!(
            read_bytes,
            unread_bytes + 8 * vertices,
            "{es}: the set uploaded"
        );
        let (fresh, _) = render(&mut Gpu::new(es), &read);
        let d = manylight::metrics::diff(&fresh, &again);
        assert_eq!(
            d.max_abs, 0,
            "{es}: the reused renderer drew the set it lacked"
        );
        let (first_set, _) = render(&mut Gpu::new(es), &unread);
        assert!(
            manylight::metrics::diff(&fresh, &first_set).max_abs > 20,
            "{es}"
        );
    }
}

/// A frame uploads the records of its lights and no whole rows: forward its light records,
/// deferred its light instances (64 bytes, 48 without spots in the scene), the culled methods also one grid texel a cell (after a
/// two-texel table a cascade, and one more where the last list ends) and the index list's
/// texels. A record is 32 bytes (float) or 16 (RGBA8) without spots in the scene, 64 or 32
/// with them: a power of two texels, so a light never straddles a row, the last texels padding
/// where the shaders read fewer (lights.rs). Packed whole rows of 1 024 texels, one light cost
/// 16 KB; points took a spot's record.
#[test]
fn a_frame_uploads_its_light_records_and_no_whole_rows() {
    let mut s = scene::builtin::build("plane", None).unwrap();
    common::each_method(|es, method, gpu| {
        // One light, then 300 (600 float texels without spots, 1 200 with: a row and part of
        // the next), each without spots and with one.
        for (n, spots) in [(1usize, false), (300, false), (1, true), (300, true)] {
            s.lights = (0..n)
                .map(|i| {
                    let f = i as f64;
                    let at = DVec3::new((f * 0.37).sin() * 3.0, 0.3, (f * 0.23).cos() * 3.0);
                    Light::point(at, 1.5, Vec3::ONE, 1.0)
                })
                .collect();
            if spots {
                let cone = scene::Cone {
                    direction: DVec3::NEG_Y,
                    inner_deg: 20.0,
                    outer_deg: 40.0,
                };
                s.lights[0] = Light::spot(DVec3::new(0.0, 1.0, 0.0), 3.0, Vec3::ONE, 1.0, cone);
            }
            let (_, stats) = (gpu.r())
                .render_offscreen(&s, 64, 36, &RenderOptions::default())
                .unwrap();
            let record = match (stats.lights.encoding, spots) {
                (LightEncoding::Float32, false) => 32,
                (LightEncoding::Float32, true) => 64,
                (LightEncoding::Rgba8, false) => 16,
                (LightEncoding::Rgba8, true) => 32,
            };
            let what = format!("{es} {method}, {n} lights, spots {spots}");
            assert!(stats.lights.visible > 0, "{what}: no light in view");
            let uploaded = stats.memory.upload_bytes;
            match method {
                "forward" => assert_eq!(uploaded, stats.lights.visible * record, "{what}"),
                // Instances: four vec4s a light, three without spots (no spot terms).
                "deferred" => {
                    let instance = if spots { 64 } else { 48 };
                    assert_eq!(uploaded, stats.lights.visible * instance, "{what}");
                }
                _ => {
                    let a = &stats.assignment;
                    let per_texel = if es == EsVersion::Es2 { 2 } else { 4 };
                    let records = stats.lights.visible * record;
                    let cells = (a.clusters as usize + 1) * 4;
                    let indices = a.indices.div_ceil(per_texel) * per_texel * 2;
                    // What is left is the table: 8 bytes a cascade.
                    let table = uploaded.checked_sub(records + cells + indices);
                    let most = manylight::cluster::grid::MAX_CASCADES as usize * 8;
                    assert!(
                        table.is_some_and(|t| t > 0 && t <= most && t % 8 == 0),
                        "{what}: {uploaded} bytes uploaded for {records} of records, {cells} \
                         of cells and {indices} of indices"
                    );
                }
            }
        }
    });
}

/// A frame with no light in view draws each opaque object once: the depth prepass only saves
/// a light loop, which such a frame has not. Its picture is that of a frame whose one light is
/// in view but reaches no surface (drawn with the prepass).
#[test]
fn an_unlit_frame_draws_each_opaque_object_once() {
    let (w, h) = (96, 54);
    let mut unlit = scene::builtin::build("pillars", None).unwrap();
    unlit.lights.clear();
    let opaque = |o: &scene::Object| !unlit.materials[o.material].is_transparent();
    assert!(unlit.objects.iter().all(opaque));
    let mut lit = unlit.clone();
    let eye = lit.camera.position;
    // A tenth of the way to the target, 1.6 m from the eye and metres from every surface.
    let p = eye + (lit.camera.target - eye) * 0.1;
    lit.lights.push(Light::point(p, 0.05, Vec3::ONE, 1.0));
    common::each_method(|es, method, gpu| {
        let opts = RenderOptions::default();
        let (ambient, unlit_stats) = gpu.r().render_offscreen(&unlit, w, h, &opts).unwrap();
        let (dark, lit_stats) = gpu.r().render_offscreen(&lit, w, h, &opts).unwrap();
        assert!(
            lit_stats.lights.visible >= 1,
            "{es} {method}: no light in view"
        );
        assert_eq!(
            unlit_stats.draw_calls,
            unlit.objects.len() as u64,
            "{es} {method}: draws of an unlit frame"
        );
        assert!(
            lit_stats.draw_calls > unlit_stats.draw_calls,
            "{es} {method}: {} draws lit",
            lit_stats.draw_calls
        );
        let d = manylight::metrics::diff(&ambient, &dark);
        assert!(d.max_abs <= 1, "{es} {method}: {d:?}");
    });
}

/// A frame without lights (none active, none in view) draws matte, Blinn-Phong and
/// metallic-roughness materials, a metallic-roughness texture among them, with one program:
/// the ambient term is the albedo's alone, and each lighting model built its own variant,
/// the same code once compiled (three). The picture is that of the same objects with flat
/// materials of those albedos, each in view.
#[test]
fn an_unlit_frame_builds_one_variant_for_every_lighting_model() {
    use manylight::scene::surface_maps::{MapTexture, TextureTransform};
    let mut base = scene::builtin::build("plane", None).unwrap();
    assert!(base.lights.is_empty() && base.directional_lights.is_empty());
    // Four quarters of the plane side by side, one for each material.
    let plane = base.objects[0].clone();
    base.objects = (0..4)
        .map(|k| scene::Object {
            transform: DMat4::from_translation(DVec3::new(k as f64 - 1.5, 0.0, 0.0))
                * DMat4::from_scale(DVec3::splat(0.25))
                * plane.transform,
            ..plane.clone()
        })
        .collect();
    let mut models = base.clone();
    let mut flat = base.clone();
    let colour = |k: usize| Vec3::new(0.2 + 0.2 * k as f32, 0.5, 0.9 - 0.2 * k as f32);
    let texels = image::RgbaImage::from_pixel(4, 4, image::Rgba([0, 128, 255, 255]));
    let mr_texture = Arc::new(scene::Texture::new("mr", texels));
    for k in 0..models.objects.len() {
        let mut m = match k % 4 {
            0 => Material::flat("matte", colour(0)),
            1 => {
                let mut m = Material::flat("glossy", colour(1));
                m.specular = Vec3::splat(0.5);
                m.shininess = 32.0;
                m
            }
            2 => Material::metallic_roughness("metal", colour(2), 1.0, 0.3),
            _ => {
                let mut m = Material::metallic_roughness("mapped", colour(3), 0.5, 0.6);
                m.maps.metallic_roughness = Some(MapTexture {
                    texture: mr_texture.clone(),
                    transform: TextureTransform::IDENTITY,
                });
                m
            }
        };
        m.name = format!("{}{k}", m.name);
        models.objects[k].material = models.add_material(m);
        flat.objects[k].material = flat.add_material(Material::flat("flat", colour(k % 4)));
    }
    for es in [EsVersion::Es2, EsVersion::Es3] {
        for method in common::methods_on(es) {
            let mut gpu = Gpu::fresh(es);
            gpu.r().set_method_named(method).unwrap();
            let opts = RenderOptions::default();
            let (picture, stats) = gpu.r().render_offscreen(&models, 96, 54, &opts).unwrap();
            assert_eq!(stats.programs_built, 1, "{es} {method}");
            let (expected, _) = gpu.r().render_offscreen(&flat, 96, 54, &opts).unwrap();
            let d = manylight::metrics::diff(&expected, &picture);
            assert_eq!(d.max_abs, 0, "{es} {method}: {d:?}");
            let colours: std::collections::HashSet<_> = picture.pixels().collect();
            assert!(
                colours.len() >= 4,
                "{es} {method}: {} colours",
                colours.len()
            );
        }
    }
}

/// Objects that share a material set only their own transforms: the program, the material's
/// values, the frame's constants and the method's light data stay set from one object to the
/// next. 60 small boxes, each its own mesh, added to a scene cost at most three uniforms each
/// (the model-view matrix in the depth prepass and in the shading pass, the normal matrix) and
/// no program bind nor data texture; on ES 3.0 a draw binds the mesh's vertex array and no
/// attribute.
#[test]
fn objects_sharing_a_material_set_only_their_transforms() {
    let (w, h) = (96, 54);
    let base = point_light_scene();
    let mut boxes = base.clone();
    let mut b = MeshBuilder::new();
    b.cuboid(Vec3::splat(-0.1), Vec3::splat(0.1));
    let mesh = b.build().unwrap();
    let material = boxes.objects[0].material;
    let added = 60;
    for i in 0..added {
        let at = DVec3::new(
            -3.0 + 0.5 * (i % 12) as f64,
            1.0 + 0.5 * (i / 12) as f64,
            8.0,
        );
        boxes.add_object(mesh.clone(), material, DMat4::from_translation(at));
    }
    common::each_method(|es, method, gpu| {
        let opts = RenderOptions::default();
        let mut frame_calls = |s: &scene::Scene| {
            // Programs built and data uploaded in the frames before.
            for _ in 0..3 {
                gpu.r().render_offscreen(s, w, h, &opts).unwrap();
            }
            let before = gpu.r().gl_state_calls();
            let (_, stats) = gpu.r().render_offscreen(s, w, h, &opts).unwrap();
            let after = gpu.r().gl_state_calls();
            (
                after.programs_bound - before.programs_bound,
                after.uniforms_set - before.uniforms_set,
                after.vertex_array_calls - before.vertex_array_calls,
                after.data_textures_bound - before.data_textures_bound,
                stats.draw_calls,
            )
        };
        let (base_programs, base_uniforms, base_arrays, base_textures, base_draws) =
            frame_calls(&base);
        let (programs, uniforms, arrays, textures, draws) = frame_calls(&boxes);
        assert!(
            draws >= base_draws + added,
            "{es} {method}: boxes not drawn"
        );
        assert_eq!(programs, base_programs, "{es} {method}: programs bound");
        assert_eq!(
            textures, base_textures,
            "{es} {method}: data textures bound"
        );
        assert!(
            uniforms <= base_uniforms + 3 * added,
            "{es} {method}: {base_uniforms} uniforms set without the boxes, {uniforms} with"
        );
        if es == EsVersion::Es3 {
            assert!(
                arrays - base_arrays <= draws - base_draws,
                "{es} {method}: {} calls for the boxes' {} draws' arrays",
                arrays - base_arrays,
                draws - base_draws
            );
        }
    });
}

/// GL before 4.2 leaves an attribute's constant value undefined after a draw that read an
/// array there: a mesh without vertex colours drawn after one with them sets its white again.
#[test]
fn a_mesh_lacking_an_attribute_sets_its_constant_again_after_one_that_had_it() {
    let (w, h) = (96, 54);
    let base = point_light_scene();
    let mut b = MeshBuilder::new();
    b.cuboid(Vec3::splat(-0.1), Vec3::splat(0.1));
    let plain = Arc::new(b.build().unwrap());
    let colours = vec![glam::Vec4::new(1.0, 0.5, 0.2, 1.0); plain.positions.len()];
    let coloured = Arc::new((*plain).clone().with_colors(colours).unwrap());
    let material = base.objects[0].material;
    let with = |mesh: &Arc<manylight::Mesh>| {
        let mut s = base.clone();
        for i in 0..8 {
            let at = DVec3::new(-2.0 + 0.5 * i as f64, 1.0, 8.0);
            s.add_object(mesh.clone(), material, DMat4::from_translation(at));
        }
        s
    };
    let (plain_boxes, coloured_boxes) = (with(&plain), with(&coloured));
    common::each_method(|es, method, gpu| {
        let opts = RenderOptions::default();
        let mut sets = |s: &scene::Scene| {
            gpu.r().render_offscreen(s, w, h, &opts).unwrap();
            let before = gpu.r().gl_state_calls().absent_values_set;
            gpu.r().render_offscreen(s, w, h, &opts).unwrap();
            gpu.r().gl_state_calls().absent_values_set - before
        };
        let (without, with_colours) = (sets(&plain_boxes), sets(&coloured_boxes));
        assert!(
            with_colours > without,
            "{es} {method}: constants set {without} times a frame without coloured meshes, \
             {with_colours} with"
        );
    });
}
