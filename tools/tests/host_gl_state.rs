//! A game draws with the same GL context as the renderer: every renderer call gives the game's
//! GL state back as it found it, and the game's state (a scissor box, a stencil test, blend
//! equations, a bound pixel buffer, its vertex array…) does not change what the renderer draws.
//! And a renderer used while another context is current refuses instead of drawing into, or
//! freeing, that context's objects.
#![allow(unsafe_code)] // the game's side: raw glow calls

mod common;

#[path = "host_gl_state/deleted_program.rs"]
mod deleted_program;
#[path = "host_gl_state/reset.rs"]
mod reset;

use common::game_target::game_framebuffer;
use common::Gpu;
use manylight::gl::GlError;
use manylight::glow::{self, HasContext};
use manylight::scene;
use manylight::{EsVersion, GlStateHandling, HeadlessContext, RenderOptions, Renderer};

/// Texture units the game binds: past the renderer's eight (every context here has at least
/// 16 combined units).
const GAME_UNITS: u32 = 12;

/// The ES 2.0 capabilities the game leaves on (all off by default): the renderer's picture
/// depends on none of them.
const GAME_CAPABILITIES: [u32; 8] = [
    glow::BLEND,
    glow::CULL_FACE,
    glow::DEPTH_TEST,
    glow::SCISSOR_TEST,
    glow::STENCIL_TEST,
    glow::POLYGON_OFFSET_FILL,
    glow::SAMPLE_ALPHA_TO_COVERAGE,
    glow::SAMPLE_COVERAGE,
];

/// What the game's context has of the state the game sets here.
#[derive(Clone, Copy)]
struct Has {
    /// ES 3.0 state: vertex arrays, samplers, pixel buffers, a separate read framebuffer.
    es3: bool,
    /// Attribute divisors: ES 3.0's, or an ES 2.0 instanced-arrays extension's setter.
    divisors: Option<Divisors>,
    /// Row lengths and skips: ES 3.0, `GL_EXT_unpack_subimage`, `GL_NV_pack_subimage`.
    unpack_rows: bool,
    pack_rows: bool,
    /// `GL_FRAMEBUFFER_SRGB_EXT` (`GL_EXT_sRGB_write_control`).
    srgb_write_control: bool,
    /// 24-bit depth renderbuffers: the game's framebuffer has the depth an offscreen frame
    /// draws with, so its picture is the same.
    depth24: bool,
}

#[derive(Clone, Copy)]
enum Divisors {
    Core,
    Extension(manylight::gl::ext_fns::VertexAttribDivisor),
}

impl Has {
    fn of(caps: &manylight::Caps) -> Has {
        let es3 = caps.context_has_es3_state();
        let has = |name: &str| caps.has_extension(name);
        let extension = manylight::gl::ext_fns::vertex_attrib_divisor_ext(has);
        Has {
            es3,
            divisors: if es3 {
                Some(Divisors::Core)
            } else {
                extension.map(Divisors::Extension)
            },
            unpack_rows: es3 || has("GL_EXT_unpack_subimage"),
            pack_rows: es3 || has("GL_NV_pack_subimage"),
            srgb_write_control: has("GL_EXT_sRGB_write_control"),
            depth24: es3 || caps.depth24,
        }
    }

    fn set_divisor(&self, gl: &glow::Context, index: u32, divisor: u32) {
        match self.divisors {
            Some(Divisors::Core) => unsafe { gl.vertex_attrib_divisor(index, divisor) },
            Some(Divisors::Extension(set)) => unsafe { set(index, divisor) },
            None => {}
        }
    }
}

/// Everything the game set, read back the same way after each renderer call.
#[derive(Debug, PartialEq)]
struct Snapshot {
    ints: Vec<(u32, i32)>,
    floats: Vec<(u32, Vec<f32>)>,
    enabled: Vec<(u32, bool)>,
    units: Vec<(u32, i32, i32)>,
    /// Locations 0 to 4 (the renderer's): enabled, size, type, normalized, stride, buffer,
    /// divisor, pointer and current value.
    attributes: Vec<([i32; 7], usize, [f32; 4])>,
}

fn snapshot(gl: &glow::Context, has: Has) -> Snapshot {
    let es3 = has.es3;
    let mut ints = vec![
        glow::ARRAY_BUFFER_BINDING,
        glow::ELEMENT_ARRAY_BUFFER_BINDING,
        glow::CURRENT_PROGRAM,
        glow::ACTIVE_TEXTURE,
        glow::FRAMEBUFFER_BINDING,
        glow::RENDERBUFFER_BINDING,
        glow::BLEND_SRC_RGB,
        glow::BLEND_DST_RGB,
        glow::BLEND_SRC_ALPHA,
        glow::BLEND_DST_ALPHA,
        glow::BLEND_EQUATION_RGB,
        glow::BLEND_EQUATION_ALPHA,
        glow::DEPTH_FUNC,
        glow::DEPTH_WRITEMASK,
        glow::CULL_FACE_MODE,
        glow::FRONT_FACE,
        glow::PACK_ALIGNMENT,
        glow::UNPACK_ALIGNMENT,
    ];
    let mut enabled = GAME_CAPABILITIES.to_vec();
    if es3 {
        ints.extend([
            glow::VERTEX_ARRAY_BINDING,
            glow::READ_FRAMEBUFFER_BINDING,
            glow::PIXEL_UNPACK_BUFFER_BINDING,
            glow::DRAW_BUFFER0,
            glow::DRAW_BUFFER1,
            glow::UNPACK_IMAGE_HEIGHT,
            glow::UNPACK_SKIP_IMAGES,
        ]);
        enabled.push(glow::RASTERIZER_DISCARD);
        enabled.push(glow::PRIMITIVE_RESTART_FIXED_INDEX);
    }
    if has.unpack_rows {
        ints.extend([glow::UNPACK_ROW_LENGTH, glow::UNPACK_SKIP_ROWS]);
    }
    if has.pack_rows {
        ints.extend([glow::PACK_ROW_LENGTH, glow::PACK_SKIP_PIXELS]);
    }
    if has.srgb_write_control {
        enabled.push(glow::FRAMEBUFFER_SRGB);
    }
    unsafe {
        let floats = [
            (glow::VIEWPORT, 4),
            (glow::SCISSOR_BOX, 4),
            (glow::COLOR_CLEAR_VALUE, 4),
            (glow::DEPTH_CLEAR_VALUE, 1),
            (glow::DEPTH_RANGE, 2),
            (glow::COLOR_WRITEMASK, 4),
        ]
        .into_iter()
        .map(|(p, n)| {
            let mut v = vec![0f32; n];
            gl.get_parameter_f32_slice(p, &mut v);
            (p, v)
        })
        .collect();
        let active = gl.get_parameter_i32(glow::ACTIVE_TEXTURE);
        let units = (0..GAME_UNITS)
            .map(|u| {
                gl.active_texture(glow::TEXTURE0 + u);
                let texture = gl.get_parameter_i32(glow::TEXTURE_BINDING_2D);
                let sampler = if es3 {
                    gl.get_parameter_i32(glow::SAMPLER_BINDING)
                } else {
                    0
                };
                (u, texture, sampler)
            })
            .collect();
        gl.active_texture(active as u32);
        // The game's arrays (on ES 3.0 in its vertex array; on ES 2.0 the context's own).
        let pointers = manylight::gl::ext_fns::attrib_pointer_fns().expect("core entry points");
        let attributes = (0..6)
            .map(|index| {
                let read = |pname| {
                    let mut v = [0f32; 4];
                    gl.get_vertex_attrib_parameter_f32_slice(index, pname, &mut v);
                    v
                };
                let array = [
                    glow::VERTEX_ATTRIB_ARRAY_ENABLED,
                    glow::VERTEX_ATTRIB_ARRAY_SIZE,
                    glow::VERTEX_ATTRIB_ARRAY_TYPE,
                    glow::VERTEX_ATTRIB_ARRAY_NORMALIZED,
                    glow::VERTEX_ATTRIB_ARRAY_STRIDE,
                    glow::VERTEX_ATTRIB_ARRAY_BUFFER_BINDING,
                    glow::VERTEX_ATTRIB_ARRAY_DIVISOR,
                ]
                .map(|p| match p {
                    glow::VERTEX_ATTRIB_ARRAY_DIVISOR if has.divisors.is_none() => 0,
                    p => read(p)[0] as i32,
                });
                let mut pointer = std::ptr::null_mut();
                (pointers.get)(index, glow::VERTEX_ATTRIB_ARRAY_POINTER, &mut pointer);
                (array, pointer as usize, read(glow::CURRENT_VERTEX_ATTRIB))
            })
            .collect();
        Snapshot {
            ints: ints
                .into_iter()
                .map(|p| (p, gl.get_parameter_i32(p)))
                .collect(),
            floats,
            enabled: enabled.into_iter().map(|c| (c, gl.is_enabled(c))).collect(),
            units,
            attributes,
        }
    }
}

/// Sets state a game might leave on (every value unlike the GL default), with its own objects
/// bound: a vertex array (ES 3.0), buffers, a program, textures on eight units, a sampler, a
/// framebuffer with a texture, bound.
unsafe fn set_game_state(gl: &glow::Context, has: Has, size: (i32, i32)) {
    let es3 = has.es3;
    if es3 {
        // Set again over its own state, the game's framebuffer texture takes no pixels from
        // its pixel buffer.
        gl.bind_buffer(glow::PIXEL_UNPACK_BUFFER, None);
        let vao = gl.create_vertex_array().unwrap();
        gl.bind_vertex_array(Some(vao));
    }
    let vbo = gl.create_buffer().unwrap();
    gl.bind_buffer(glow::ARRAY_BUFFER, Some(vbo));
    gl.buffer_data_size(glow::ARRAY_BUFFER, 64, glow::STATIC_DRAW);
    gl.vertex_attrib_pointer_f32(0, 2, glow::FLOAT, false, 8, 0);
    gl.enable_vertex_attrib_array(0);
    // Unlike anything the renderer sets: a normalized byte array at an offset, one left off
    // with its own array, and constant values where the renderer sets its own.
    gl.vertex_attrib_pointer_f32(1, 4, glow::UNSIGNED_BYTE, true, 12, 4);
    gl.enable_vertex_attrib_array(1);
    gl.vertex_attrib_pointer_f32(2, 3, glow::SHORT, false, 16, 6);
    gl.vertex_attrib_4_f32(3, 0.25, 0.5, 0.75, 2.0);
    gl.vertex_attrib_4_f32(4, -1.0, 3.0, 0.0, 0.5);
    // Where the renderer's second texture coordinates go: an array of the game's, and the
    // constant value under it.
    gl.vertex_attrib_4_f32(5, 7.0, -2.0, 0.5, 3.0);
    gl.vertex_attrib_pointer_f32(5, 2, glow::UNSIGNED_SHORT, true, 20, 8);
    gl.enable_vertex_attrib_array(5);
    // Per-instance arrays where the renderer's positions and normals go: its meshes would
    // collapse to their first vertex.
    has.set_divisor(gl, 0, 1);
    has.set_divisor(gl, 1, 3);
    let ibo = gl.create_buffer().unwrap();
    gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(ibo));
    gl.buffer_data_size(glow::ELEMENT_ARRAY_BUFFER, 12, glow::STATIC_DRAW);
    let other = gl.create_buffer().unwrap();
    gl.bind_buffer(glow::ARRAY_BUFFER, Some(other));
    let program = gl.create_program().unwrap();
    let shaders = [
        (
            glow::VERTEX_SHADER,
            "attribute vec2 p; void main() { gl_Position = vec4(p, 0.0, 1.0); }",
        ),
        (
            glow::FRAGMENT_SHADER,
            "void main() { gl_FragColor = vec4(1.0); }",
        ),
    ];
    for (kind, source) in shaders {
        let shader = gl.create_shader(kind).unwrap();
        gl.shader_source(shader, source);
        gl.compile_shader(shader);
        gl.attach_shader(program, shader);
    }
    gl.link_program(program);
    assert!(gl.get_program_link_status(program));
    gl.use_program(Some(program));
    for unit in 0..8 {
        gl.active_texture(glow::TEXTURE0 + unit);
        let t = gl.create_texture().unwrap();
        gl.bind_texture(glow::TEXTURE_2D, Some(t));
    }
    // The game's framebuffer, its colour texture bound on unit 5.
    gl.active_texture(glow::TEXTURE5);
    game_framebuffer(gl, has.depth24, size);
    if es3 {
        // Drawn into as a G-buffer is: a second colour texture (on unit 6) at attachment 1 in
        // its draw buffers, which the frame must neither draw into nor change for good.
        gl.active_texture(glow::TEXTURE6);
        let second = gl.create_texture().unwrap();
        gl.bind_texture(glow::TEXTURE_2D, Some(second));
        let (w, h) = size;
        let rgba = glow::RGBA;
        let none = glow::PixelUnpackData::Slice(None);
        gl.tex_image_2d(
            glow::TEXTURE_2D,
            0,
            rgba as i32,
            w,
            h,
            0,
            rgba,
            glow::UNSIGNED_BYTE,
            none,
        );
        let attachment = glow::COLOR_ATTACHMENT1;
        gl.framebuffer_texture_2d(
            glow::FRAMEBUFFER,
            attachment,
            glow::TEXTURE_2D,
            Some(second),
            0,
        );
        gl.draw_buffers(&[glow::COLOR_ATTACHMENT0, attachment]);
    }
    // Left active: a unit past those the renderer binds (a game's shadow map, say), whose
    // texture an upload bound on the active unit would replace.
    gl.active_texture(glow::TEXTURE0 + GAME_UNITS - 1);
    let t = gl.create_texture().unwrap();
    gl.bind_texture(glow::TEXTURE_2D, Some(t));
    if es3 {
        let sampler = gl.create_sampler().unwrap();
        gl.sampler_parameter_i32(sampler, glow::TEXTURE_MIN_FILTER, glow::NEAREST as i32);
        gl.bind_sampler(1, Some(sampler));
        let unpack = gl.create_buffer().unwrap();
        gl.bind_buffer(glow::PIXEL_UNPACK_BUFFER, Some(unpack));
        gl.buffer_data_size(glow::PIXEL_UNPACK_BUFFER, 16, glow::STATIC_DRAW);
        // A read framebuffer of its own, apart from the draw one.
        let read = gl.create_framebuffer().unwrap();
        gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(read));
        gl.blend_equation_separate(glow::MAX, glow::MIN);
        gl.enable(glow::RASTERIZER_DISCARD);
        gl.enable(glow::PRIMITIVE_RESTART_FIXED_INDEX);
        // Left by a 3D or array texture's upload: SwiftShader applies the skip to 2D uploads
        // too, and read past the renderer's light data (a dark frame, then a hang).
        gl.pixel_store_i32(glow::UNPACK_IMAGE_HEIGHT, 3);
        gl.pixel_store_i32(glow::UNPACK_SKIP_IMAGES, 2);
    } else {
        gl.blend_equation_separate(glow::FUNC_SUBTRACT, glow::FUNC_REVERSE_SUBTRACT);
    }
    if has.unpack_rows {
        gl.pixel_store_i32(glow::UNPACK_ROW_LENGTH, 7);
        gl.pixel_store_i32(glow::UNPACK_SKIP_ROWS, 1);
    }
    if has.pack_rows {
        gl.pixel_store_i32(glow::PACK_ROW_LENGTH, 5);
        gl.pixel_store_i32(glow::PACK_SKIP_PIXELS, 2);
    }
    if has.srgb_write_control {
        // Drawing linear values into an sRGB target unencoded (a game's UI pass, say).
        gl.disable(glow::FRAMEBUFFER_SRGB);
    }
    gl.viewport(3, 4, 50, 60);
    gl.clear_color(0.25, 0.5, 0.75, 1.0);
    gl.clear_depth_f32(0.5);
    gl.depth_range_f32(0.25, 0.75);
    gl.pixel_store_i32(glow::PACK_ALIGNMENT, 8);
    gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 8);
    for c in GAME_CAPABILITIES {
        gl.enable(c);
    }
    // Left on, it would drop every sample of the renderer's MSAA target.
    gl.sample_coverage(0.0, false);
    gl.scissor(0, 0, 2, 2);
    gl.stencil_func(glow::EQUAL, 1, 0xff);
    gl.polygon_offset(50.0, 50.0);
    gl.blend_func_separate(
        glow::SRC_ALPHA,
        glow::ONE_MINUS_SRC_ALPHA,
        glow::DST_COLOR,
        glow::ZERO,
    );
    gl.depth_func(glow::GREATER);
    gl.depth_mask(false);
    gl.color_mask(true, false, true, false);
    gl.cull_face(glow::FRONT);
    gl.front_face(glow::CW);
}

/// Set in the child process that runs the test below on Mesa capped to ES 2.0.
const PURE_ES2: &str = "MANYLIGHT_TEST_PURE_ES2";

/// The pillars, with one object drawn through a second coordinate set (its texture reads
/// location 5, where the game keeps an array of its own).
fn pillars_with_a_second_set() -> manylight::Scene {
    let mut scene = scene::builtin::build("pillars", Some((300, 4))).unwrap();
    let object = scene
        .objects
        .iter()
        .position(|o| !o.mesh.uvs.is_empty())
        .unwrap();
    let mesh = &scene.objects[object].mesh;
    let flipped = mesh
        .uvs
        .iter()
        .map(|uv| manylight::glam::Vec2::ONE - *uv)
        .collect();
    let mesh = (**mesh).clone().with_second_uvs(flipped).unwrap();
    let texels = image::RgbaImage::from_fn(2, 2, |x, y| {
        image::Rgba([60 + 150 * x as u8, 90, 40 + 150 * y as u8, 255])
    });
    let mut material = manylight::Material::flat("second set", manylight::glam::Vec3::splat(0.9));
    material.diffuse_texture = Some(std::sync::Arc::new(manylight::Texture::new(
        "checks", texels,
    )));
    material.maps.base_transform.uv_set = 1;
    let material = scene.add_material(material);
    scene.objects[object].mesh = std::sync::Arc::new(mesh);
    scene.objects[object].material = material;
    scene
}

#[test]
fn every_call_gives_the_games_gl_state_back_and_draws_as_from_a_clean_one() {
    let scene = pillars_with_a_second_set();
    let (w, h) = (96, 54);
    let pure_es2 = std::env::var_os(PURE_ES2).is_some();
    let levels: &[EsVersion] = if pure_es2 {
        &[EsVersion::Es2]
    } else {
        &[EsVersion::Es2, EsVersion::Es3]
    };
    for &es in levels {
        let es3 = es == EsVersion::Es3;
        // MSAA: ES 3.0's renderbuffers (llvmpipe's ES 2.0 has no multisampled extension).
        let sample_counts: &[u32] = if es3 { &[1, 4] } else { &[1] };
        let methods: &[&str] = if es3 {
            &["forward", "clustered", "deferred", "auto"]
        } else {
            &["forward", "tiled", "clustered"]
        };
        // Every method, with MSAA where it runs (deferred has none).
        let cases: Vec<(&str, RenderOptions)> = methods
            .iter()
            .flat_map(|&m| {
                let counts = sample_counts
                    .iter()
                    .filter(move |&&n| n == 1 || m != "deferred");
                counts.map(move |&samples| {
                    let opts = RenderOptions {
                        samples,
                        ..Default::default()
                    };
                    (m, opts)
                })
            })
            .collect();
        // What each draws from the default state, on a renderer of its own.
        let mut clean = Gpu::fresh(es);
        let fp16 = clean.r().mediump_is_fp16().unwrap();
        let expected: Vec<_> = cases
            .iter()
            .map(|(m, opts)| {
                clean.r().set_method_named(m).unwrap();
                clean.r().render_offscreen(&scene, w, h, opts).unwrap().0
            })
            .collect();
        drop(clean);
        let ctx = HeadlessContext::new(es).unwrap();
        let gl = ctx.load_gl().unwrap();
        let mut renderer = Renderer::new(ctx.load_gl().unwrap(), es).unwrap();
        // An ES 2.0-level renderer on an ES 3.x context (Mesa's, asked for 2.0) meets the
        // context's ES 3.0 state too: a vertex array, samplers, pixel buffers, a separate read
        // framebuffer.
        let has = Has::of(renderer.caps());
        assert!(!(pure_es2 && has.es3), "the cap gave an ES 3.x context");
        unsafe { set_game_state(&gl, has, (w as i32, h as i32)) };
        let before = snapshot(&gl, has);
        for ((m, opts), expected) in cases.iter().zip(&expected) {
            let what = format!("{es} {m} ×{}", opts.samples);
            renderer.set_method_named(m).unwrap();
            assert_eq!(
                snapshot(&gl, has),
                before,
                "{what}: set_method changed the game's state"
            );
            // Warmed up first: the picture below must be the clean renderer's all the same.
            renderer.warm_up(&scene, opts).unwrap();
            assert_eq!(
                snapshot(&gl, has),
                before,
                "{what}: warm_up changed the game's state"
            );
            let (img, _) = renderer.render_offscreen(&scene, w, h, opts).unwrap();
            let d = manylight::metrics::diff(expected, &img);
            assert_eq!(d.max_abs, 0, "{what}: the game's state changed the picture");
            assert_eq!(
                snapshot(&gl, has),
                before,
                "{what}: render_offscreen changed the game's state"
            );
            // Into the game's own framebuffer, as a game draws.
            renderer.render(&scene, w, h, opts).unwrap();
            assert_eq!(
                snapshot(&gl, has),
                before,
                "{what}: render changed the game's state"
            );
        }
        // The game culls front faces: the probe's triangle must still be drawn (culled, an
        // empty pixel read as fp16: wrong on SwiftShader, whose mediump is fp32; llvmpipe's
        // is fp16, so there the two agree).
        assert_eq!(
            renderer.mediump_is_fp16().unwrap(),
            fp16,
            "{es}: the game's state changed what the precision probe measured"
        );
        assert_eq!(
            snapshot(&gl, has),
            before,
            "{es}: the precision probe changed the game's state"
        );
        reset::every_call_sets_what_it_needs_and_leaves_gl_initial_values(
            (&ctx, &gl),
            renderer,
            has,
            &scene,
            &cases,
            (&expected, fp16),
        );
        drop(ctx);
    }
}

/// Mesa asked for ES 2.0 gives an ES 3.2 context, where the renderer keeps its arrays in a
/// vertex array object of its own. Capped to ES 2.0 (a Mali-400's context) its row lengths
/// come from `GL_EXT_unpack_subimage`, and its vertex arrays from
/// `GL_OES_vertex_array_object`; without that extension the game's arrays are the context's,
/// saved and given back one by one. The test above runs again in both, each in a child
/// process, since Mesa reads the cap once per process. (SwiftShader's and ANGLE's ES 2.0
/// contexts are ES 2.0 already, with instanced arrays.)
#[test]
fn every_call_gives_the_games_gl_state_back_on_a_pure_es2_context() {
    if std::env::var_os(PURE_ES2).is_some()
        || common::other_implementation_than_mesa("MESA_GLES_VERSION_OVERRIDE")
    {
        return;
    }
    let test = "every_call_gives_the_games_gl_state_back_and_draws_as_from_a_clean_one";
    let es2 = [("MESA_GLES_VERSION_OVERRIDE", "2.0"), (PURE_ES2, "1")];
    common::child::rerun_with(test, &es2, "on ES 2.0");
    let without_vao = [
        es2[0],
        es2[1],
        ("MESA_EXTENSION_OVERRIDE", "-GL_OES_vertex_array_object"),
    ];
    common::child::rerun_with(test, &without_vao, "on ES 2.0 without vertex arrays");
}

#[test]
fn a_renderer_refuses_another_current_context_and_leaves_its_objects() {
    let scene = scene::builtin::build("plane", Some((8, 1))).unwrap();
    let a = HeadlessContext::new(EsVersion::Es3).unwrap();
    let mut on_a = Renderer::new(a.load_gl().unwrap(), EsVersion::Es3).unwrap();
    on_a.render_offscreen(&scene, 32, 18, &RenderOptions::default())
        .unwrap();
    let b = HeadlessContext::new(EsVersion::Es3).unwrap(); // now current
    let mut on_b = Renderer::new(b.load_gl().unwrap(), EsVersion::Es3).unwrap();
    let (reference, _) = on_b
        .render_offscreen(&scene, 32, 18, &RenderOptions::default())
        .unwrap();
    let err = on_a
        .render_offscreen(&scene, 32, 18, &RenderOptions::default())
        .unwrap_err();
    assert!(
        matches!(err, manylight::Error::Gl(GlError::OtherContext)),
        "{err}"
    );
    assert!(err.to_string().contains("another GL context"), "{err}");
    assert!(matches!(
        on_a.set_method_named("forward"),
        Err(manylight::Error::Gl(GlError::OtherContext))
    ));
    // Dropped while b is current: a's names are not b's to delete.
    drop(on_a);
    let (after, _) = on_b
        .render_offscreen(&scene, 32, 18, &RenderOptions::default())
        .unwrap();
    assert_eq!(manylight::metrics::diff(&reference, &after).max_abs, 0);
    // Back on a, a new renderer works; one whose context is lost is abandoned without a GL
    // call, whatever is current.
    a.make_current().unwrap();
    let mut again = Renderer::new(a.load_gl().unwrap(), EsVersion::Es3).unwrap();
    again
        .render_offscreen(&scene, 32, 18, &RenderOptions::default())
        .unwrap();
    b.make_current().unwrap();
    again.abandon();
    let (after_abandon, _) = on_b
        .render_offscreen(&scene, 32, 18, &RenderOptions::default())
        .unwrap();
    assert_eq!(
        manylight::metrics::diff(&reference, &after_abandon).max_abs,
        0
    );
}

/// ANGLE and SwiftShader give a new context the handle of the one destroyed before it. A game
/// that replaces its renderer on the new context (`renderer = Renderer::new(..)`) drops the old
/// one with the new context current: the old one must neither draw with the new renderer's
/// objects, which have its objects' names, nor delete them.
#[test]
fn a_renderer_whose_context_is_gone_leaves_the_next_context_alone() {
    let scene = scene::builtin::build("plane", Some((8, 1))).unwrap();
    let options = RenderOptions::default();
    let mut context = HeadlessContext::new(EsVersion::Es3).unwrap();
    let mut renderer = Renderer::new(context.load_gl().unwrap(), EsVersion::Es3).unwrap();
    let (reference, _) = renderer.render_offscreen(&scene, 32, 18, &options).unwrap();
    for cycle in 0..4 {
        drop(context);
        context = HeadlessContext::new(EsVersion::Es3).unwrap();
        let mut fresh = Renderer::new(context.load_gl().unwrap(), EsVersion::Es3).unwrap();
        fresh.render_offscreen(&scene, 32, 18, &options).unwrap();
        let err = renderer
            .render_offscreen(&scene, 32, 18, &options)
            .unwrap_err();
        assert!(
            matches!(err, manylight::Error::Gl(GlError::OtherContext)),
            "cycle {cycle}: {err}"
        );
        assert!(err.to_string().contains("Renderer::abandon"), "{err}");
        renderer = fresh;
        let (picture, _) = renderer
            .render_offscreen(&scene, 32, 18, &options)
            .unwrap_or_else(|e| panic!("cycle {cycle}: the new renderer after the old went: {e}"));
        assert_eq!(manylight::metrics::diff(&reference, &picture).max_abs, 0);
    }
}

/// A mesh whose first 16-bit chunk holds 65 536 vertices, the last of them (local index
/// 65 535, the fixed restart index) a corner of a large triangle in view: 21 844 triangles of
/// zero area, then a quad before the camera.
fn scene_with_index_65535_in_view() -> manylight::Scene {
    use manylight::glam::{DMat4, Vec3};
    let mut scene = scene::builtin::build("plane", Some((8, 1))).unwrap();
    let cam = &scene.camera;
    let forward = (cam.target - cam.position).normalize();
    let right = forward.cross(cam.up).normalize();
    let up = right.cross(forward);
    let centre = cam.position + forward * 3.0;
    let mut positions = vec![centre.as_vec3(); 21_844 * 3];
    let corner = |x: f64, y: f64| (centre + right * x + up * y).as_vec3();
    positions.extend([
        corner(-1.0, -1.0),
        corner(1.0, -1.0),
        corner(1.0, 1.0),
        corner(-1.0, 1.0),
    ]);
    let mut indices: Vec<u32> = (0..21_844 * 3).collect();
    indices.extend([65_532, 65_533, 65_534, 65_532, 65_534, 65_535]);
    let mesh = manylight::Mesh::new(positions, vec![], vec![], indices).unwrap();
    let material = scene.add_material(manylight::Material::flat("quad", Vec3::splat(0.8)));
    scene.objects.push(manylight::Object {
        mesh: std::sync::Arc::new(mesh),
        material,
        transform: DMat4::IDENTITY,
    });
    scene
}

/// The game's `PRIMITIVE_RESTART_FIXED_INDEX` (ES 3.0 state) does not cut the triangles of a
/// mesh chunk that use local index 65 535: the picture equals a clean renderer's, whether the
/// call saves the game's state or resets it.
#[test]
fn the_games_primitive_restart_does_not_cut_large_meshes() {
    let scene = scene_with_index_65535_in_view();
    let (w, h) = (64, 36);
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut clean = Gpu::fresh(es);
        let expected = clean
            .r()
            .render_offscreen(&scene, w, h, &RenderOptions::default())
            .unwrap()
            .0;
        drop(clean);
        let ctx = HeadlessContext::new(es).unwrap();
        let gl = ctx.load_gl().unwrap();
        let mut renderer = Renderer::new(ctx.load_gl().unwrap(), es).unwrap();
        if !renderer.caps().context_has_es3_state() {
            continue;
        }
        for handling in [GlStateHandling::SaveAndRestore, GlStateHandling::Reset] {
            renderer.set_gl_state_handling(handling);
            unsafe { gl.enable(glow::PRIMITIVE_RESTART_FIXED_INDEX) };
            let (img, _) = renderer
                .render_offscreen(&scene, w, h, &RenderOptions::default())
                .unwrap();
            let d = manylight::metrics::diff(&expected, &img);
            assert_eq!(
                d.max_abs, 0,
                "{es} {handling:?}: the game's restart cut the quad"
            );
            // Given back, or left at GL's initial value.
            let on = unsafe { gl.is_enabled(glow::PRIMITIVE_RESTART_FIXED_INDEX) };
            assert_eq!(
                on,
                handling == GlStateHandling::SaveAndRestore,
                "{handling:?}"
            );
        }
    }
}

/// An entry point of the GLES library the context came from, which the ES version (or an
/// extension) in question has: the first of `names` it gives.
fn entry_point(names: &[&str]) -> *const std::ffi::c_void {
    let library = manylight::gl::gles_lib::library().unwrap();
    let found = names.iter().map(|name| library.proc_address(name));
    found
        .into_iter()
        .find(|f| !f.is_null())
        .unwrap_or_else(|| panic!("no {names:?}"))
}

/// The game's `capability`, switched on after `set(true)` made it change samples (`set(false)`
/// undoes that), changes no 4× MSAA picture of the renderer's, whether the call saves the
/// game's state or resets it; it is on again after the call (off, where the call resets the
/// state). Where the context lacks it (`has`), ES 3.0's SwiftShader and ANGLE, nothing is
/// checked; Mesa's ES 3.2 context has it.
fn an_msaa_frame_ignores_the_games(
    capability: u32,
    what: &str,
    has: impl FnOnce(&glow::Context, &Renderer) -> bool,
    set: impl Fn(bool),
) {
    let scene = scene::builtin::build(scene::builtin::DEFAULT, Some((16, 3))).unwrap();
    let opts = RenderOptions {
        samples: 4,
        ..RenderOptions::default()
    };
    let (w, h) = (64, 36);
    let expected = Gpu::fresh(EsVersion::Es3).render(&scene, w, h, &opts);
    let ctx = HeadlessContext::new(EsVersion::Es3).unwrap();
    let gl = ctx.load_gl().unwrap();
    let mut renderer = Renderer::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    if !has(&gl, &renderer) {
        if !common::other_implementation_than_mesa(what) {
            common::skip(&format!("this context has no {what} to check"));
        }
        return;
    }
    set(true);
    for handling in [GlStateHandling::SaveAndRestore, GlStateHandling::Reset] {
        renderer.set_gl_state_handling(handling);
        unsafe { gl.enable(capability) };
        let (img, _) = renderer.render_offscreen(&scene, w, h, &opts).unwrap();
        let d = manylight::metrics::diff(&expected, &img);
        assert_eq!(
            d.max_abs, 0,
            "{handling:?}: the game's {what} changed the frame"
        );
        // Given back, or left at GL's initial value.
        let on = unsafe { gl.is_enabled(capability) };
        assert_eq!(
            on,
            handling == GlStateHandling::SaveAndRestore,
            "{handling:?}"
        );
    }
    set(false);
    unsafe { gl.disable(capability) };
}

/// The game's sample mask (ES 3.1 state), keeping no sample, does not drop samples of the
/// renderer's MSAA target.
#[test]
fn the_games_sample_mask_does_not_drop_the_renderers_samples() {
    let has = |gl: &glow::Context, _: &Renderer| (gl.version().major, gl.version().minor) >= (3, 1);
    an_msaa_frame_ignores_the_games(glow::SAMPLE_MASK, "ES 3.1 sample mask", has, |on| {
        // SAFETY: glSampleMaski's type in the ES 3.1 specification.
        let sample_mask_i: extern "system" fn(u32, u32) =
            unsafe { std::mem::transmute(entry_point(&["glSampleMaski"])) };
        sample_mask_i(0, if on { 0 } else { !0 });
    });
}

/// The game's sample shading (ES 3.2 state), every sample shaded, does not shade each sample of
/// the renderer's MSAA target on its own (at four times the cost, and at the samples'
/// positions).
#[test]
fn the_games_sample_shading_does_not_shade_the_renderers_samples() {
    let has = |gl: &glow::Context, r: &Renderer| {
        (gl.version().major, gl.version().minor) >= (3, 2)
            || r.caps().has_extension("GL_OES_sample_shading")
    };
    an_msaa_frame_ignores_the_games(glow::SAMPLE_SHADING, "ES 3.2 sample shading", has, |on| {
        let names = ["glMinSampleShading", "glMinSampleShadingOES"];
        // SAFETY: glMinSampleShading's type in the ES 3.2 specification.
        let min_sample_shading: extern "system" fn(f32) =
            unsafe { std::mem::transmute(entry_point(&names)) };
        min_sample_shading(if on { 1.0 } else { 0.0 });
    });
}

/// A material's depth bias sets the polygon offset during the call only: the game's offset
/// (switched on, with its own factor, units and, where `GL_EXT_polygon_offset_clamp` is
/// listed, clamp) is on again with its values after a call that drew a biased surface; with the
/// state reset, it is off with GL's initial values. A call with no biased surface leaves the
/// values alone even then.
#[test]
fn a_biased_material_gives_the_games_polygon_offset_back() {
    let mut biased = scene::builtin::build("plane", Some((8, 1))).unwrap();
    for material in &mut biased.materials {
        material.depth_bias = 2.0;
    }
    let unbiased = scene::builtin::build("plane", Some((8, 1))).unwrap();
    let ctx = HeadlessContext::new(EsVersion::Es3).unwrap();
    let gl = ctx.load_gl().unwrap();
    let mut renderer = Renderer::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    let clamps = renderer.caps().has_extension("GL_EXT_polygon_offset_clamp");
    if !clamps && !common::other_implementation_than_mesa("GL_EXT_polygon_offset_clamp") {
        common::skip("this Mesa lists no GL_EXT_polygon_offset_clamp to check");
    }
    // SAFETY: the extension's type for glPolygonOffsetClampEXT.
    let set_clamp: Option<extern "system" fn(f32, f32, f32)> =
        clamps.then(|| unsafe { std::mem::transmute(entry_point(&["glPolygonOffsetClampEXT"])) });
    let offset = || unsafe {
        let on = gl.is_enabled(glow::POLYGON_OFFSET_FILL);
        let factor = gl.get_parameter_f32(glow::POLYGON_OFFSET_FACTOR);
        let units = gl.get_parameter_f32(glow::POLYGON_OFFSET_UNITS);
        let clamp = clamps.then(|| gl.get_parameter_f32(glow::POLYGON_OFFSET_CLAMP));
        (on, factor, units, clamp)
    };
    let opts = RenderOptions::default();
    for handling in [GlStateHandling::SaveAndRestore, GlStateHandling::Reset] {
        renderer.set_gl_state_handling(handling);
        for (scene, biased) in [(&unbiased, false), (&biased, true)] {
            // The game's offset switched on, and off (the renderer's must not stay on).
            for on in [true, false] {
                unsafe {
                    if on {
                        gl.enable(glow::POLYGON_OFFSET_FILL);
                    } else {
                        gl.disable(glow::POLYGON_OFFSET_FILL);
                    }
                    gl.polygon_offset(3.0, 5.0);
                }
                if let Some(set_clamp) = set_clamp {
                    set_clamp(3.0, 5.0, -0.25);
                }
                renderer.render_offscreen(scene, 32, 18, &opts).unwrap();
                let clamp = |c| clamps.then_some(c);
                let expected = match (handling, biased) {
                    (GlStateHandling::SaveAndRestore, _) => (on, 3.0, 5.0, clamp(-0.25)),
                    (GlStateHandling::Reset, false) => (false, 3.0, 5.0, clamp(-0.25)),
                    (GlStateHandling::Reset, true) => (false, 0.0, 0.0, clamp(0.0)),
                };
                assert_eq!(
                    offset(),
                    expected,
                    "{handling:?}, biased: {biased}, on: {on}"
                );
            }
        }
    }
}
