//! `GlStateHandling::Reset`: from the same hostile game state, set again before each call as
//! such an engine does, every call draws what a clean renderer draws, and returns with what
//! the README lists: the game's framebuffer bound, and GL's initial values (the OpenGL ES 3.0
//! specification's state tables) for the rest of what the renderer changes. What the renderer
//! never touches stays the game's: its texture on a unit past the eighth, and its vertex array
//! 0 where the renderer draws with one of its own.

use super::{set_game_state, Has, GAME_CAPABILITIES, GAME_UNITS};
use crate::common::game_target::read_back;
use manylight::glow::{self, HasContext};
use manylight::{GlStateHandling, HeadlessContext, RenderOptions, Renderer, Scene};

/// What the game had bound as a call started, read back after it.
struct GameBindings {
    framebuffer: i32,
    /// The texture on the last unit the game binds (past the renderer's eight).
    last_unit_texture: i32,
    /// Its attribute arrays at the renderer's locations (enabled, size, type, stride, buffer),
    /// which are vertex array 0's where the game draws with it.
    arrays: Vec<[i32; 5]>,
    /// Its framebuffer's second draw buffer (ES 3.0): attachment 1.
    draw_buffer_1: Option<i32>,
}

/// One attribute parameter of location `index`.
unsafe fn attribute(gl: &glow::Context, index: u32, pname: u32) -> i32 {
    let mut v = [0f32; 4];
    gl.get_vertex_attrib_parameter_f32_slice(index, pname, &mut v);
    v[0] as i32
}

unsafe fn arrays(gl: &glow::Context) -> Vec<[i32; 5]> {
    (0..6)
        .map(|index| {
            [
                glow::VERTEX_ATTRIB_ARRAY_ENABLED,
                glow::VERTEX_ATTRIB_ARRAY_SIZE,
                glow::VERTEX_ATTRIB_ARRAY_TYPE,
                glow::VERTEX_ATTRIB_ARRAY_STRIDE,
                glow::VERTEX_ATTRIB_ARRAY_BUFFER_BINDING,
            ]
            .map(|p| attribute(gl, index, p))
        })
        .collect()
}

unsafe fn game_bindings(gl: &glow::Context, has: Has) -> GameBindings {
    let active = gl.get_parameter_i32(glow::ACTIVE_TEXTURE);
    gl.active_texture(glow::TEXTURE0 + GAME_UNITS - 1);
    let last_unit_texture = gl.get_parameter_i32(glow::TEXTURE_BINDING_2D);
    gl.active_texture(active as u32);
    GameBindings {
        framebuffer: gl.get_parameter_i32(glow::FRAMEBUFFER_BINDING),
        last_unit_texture,
        arrays: arrays(gl),
        draw_buffer_1: has.es3.then(|| gl.get_parameter_i32(glow::DRAW_BUFFER1)),
    }
}

/// The bound draw framebuffer's picture, read past the game's read framebuffer and
/// pixel-store settings (which the caller sets again).
unsafe fn read_drawn(gl: &glow::Context, has: Has, size: (u32, u32)) -> image::RgbaImage {
    if has.es3 {
        let draw = gl.get_parameter_framebuffer(glow::DRAW_FRAMEBUFFER_BINDING);
        gl.bind_framebuffer(glow::READ_FRAMEBUFFER, draw);
    }
    if has.pack_rows {
        gl.pixel_store_i32(glow::PACK_ROW_LENGTH, 0);
        gl.pixel_store_i32(glow::PACK_SKIP_PIXELS, 0);
    }
    read_back(gl, size)
}

/// How the renderer under test draws, and what the call did.
#[derive(Clone, Copy)]
struct Call<'a> {
    /// With a vertex array of its own (ES 3.x, `GL_OES_vertex_array_object`).
    own_vertex_array: bool,
    /// The call drew a frame into the game's framebuffer (`render`).
    drew_into_the_games: bool,
    what: &'a str,
}

/// Checks the state a call with `GlStateHandling::Reset` leaves.
unsafe fn assert_reset(gl: &glow::Context, has: Has, game: &GameBindings, call: Call) {
    let Call {
        own_vertex_array,
        drew_into_the_games,
        what,
    } = call;
    let mut ints = vec![
        (glow::FRAMEBUFFER_BINDING, game.framebuffer),
        (glow::ARRAY_BUFFER_BINDING, 0),
        (glow::CURRENT_PROGRAM, 0),
        (glow::ACTIVE_TEXTURE, glow::TEXTURE0 as i32),
        (glow::RENDERBUFFER_BINDING, 0),
        (glow::BLEND_SRC_RGB, glow::ONE as i32),
        (glow::BLEND_SRC_ALPHA, glow::ONE as i32),
        (glow::BLEND_DST_RGB, 0),
        (glow::BLEND_DST_ALPHA, 0),
        (glow::BLEND_EQUATION_RGB, glow::FUNC_ADD as i32),
        (glow::BLEND_EQUATION_ALPHA, glow::FUNC_ADD as i32),
        (glow::DEPTH_FUNC, glow::LESS as i32),
        (glow::DEPTH_WRITEMASK, 1),
        (glow::CULL_FACE_MODE, glow::BACK as i32),
        (glow::FRONT_FACE, glow::CCW as i32),
        (glow::PACK_ALIGNMENT, 4),
        (glow::UNPACK_ALIGNMENT, 4),
    ];
    let mut disabled = GAME_CAPABILITIES.to_vec();
    if has.es3 {
        ints.extend([
            (glow::READ_FRAMEBUFFER_BINDING, game.framebuffer),
            (glow::VERTEX_ARRAY_BINDING, 0),
            (glow::PIXEL_PACK_BUFFER_BINDING, 0),
            (glow::PIXEL_UNPACK_BUFFER_BINDING, 0),
            (glow::DRAW_BUFFER0, glow::COLOR_ATTACHMENT0 as i32),
            (glow::UNPACK_IMAGE_HEIGHT, 0),
            (glow::UNPACK_SKIP_IMAGES, 0),
        ]);
        // A frame drawn into the framebuffer points it at attachment 0 alone; no other call
        // changes what is the framebuffer object's own state.
        let second = match drew_into_the_games {
            true => glow::NONE as i32,
            false => game.draw_buffer_1.unwrap(),
        };
        ints.push((glow::DRAW_BUFFER1, second));
        disabled.extend([
            glow::RASTERIZER_DISCARD,
            glow::PRIMITIVE_RESTART_FIXED_INDEX,
        ]);
    }
    if has.unpack_rows {
        ints.extend([glow::UNPACK_ROW_LENGTH, glow::UNPACK_SKIP_ROWS].map(|p| (p, 0)));
    }
    if has.pack_rows {
        ints.extend([glow::PACK_ROW_LENGTH, glow::PACK_SKIP_PIXELS].map(|p| (p, 0)));
    }
    for (pname, expected) in ints {
        let value = gl.get_parameter_i32(pname);
        assert_eq!(value, expected, "{what}: 0x{pname:04x}");
    }
    for capability in disabled {
        assert!(!gl.is_enabled(capability), "{what}: 0x{capability:04x} on");
    }
    if has.srgb_write_control {
        assert!(
            gl.is_enabled(glow::FRAMEBUFFER_SRGB),
            "{what}: sRGB writes off"
        );
    }
    for (pname, expected) in [
        (glow::COLOR_CLEAR_VALUE, &[0.0, 0.0, 0.0, 0.0][..]),
        (glow::DEPTH_CLEAR_VALUE, &[1.0]),
        (glow::DEPTH_RANGE, &[0.0, 1.0]),
        (glow::COLOR_WRITEMASK, &[1.0; 4]),
    ] {
        let mut v = vec![0f32; expected.len()];
        gl.get_parameter_f32_slice(pname, &mut v);
        assert_eq!(v, expected, "{what}: 0x{pname:04x}");
    }
    for unit in 0..GAME_UNITS {
        gl.active_texture(glow::TEXTURE0 + unit);
        let texture = gl.get_parameter_i32(glow::TEXTURE_BINDING_2D);
        let sampler = has.es3.then(|| gl.get_parameter_i32(glow::SAMPLER_BINDING));
        if unit < 8 {
            assert_eq!(
                (texture, sampler.unwrap_or(0)),
                (0, 0),
                "{what}: unit {unit}"
            );
        } else if unit == GAME_UNITS - 1 {
            assert_eq!(
                texture, game.last_unit_texture,
                "{what}: the game's unit {unit}"
            );
        }
    }
    gl.active_texture(glow::TEXTURE0);
    let now = arrays(gl);
    for location in 0..6u32 {
        let mut value = [0f32; 4];
        gl.get_vertex_attrib_parameter_f32_slice(location, glow::CURRENT_VERTEX_ATTRIB, &mut value);
        if (2..6).contains(&location) {
            assert_eq!(value, [0.0, 0.0, 0.0, 1.0], "{what}: attribute {location}");
        }
        let array = &now[location as usize];
        if own_vertex_array && !has.es3 {
            // ES 2.0 with `GL_OES_vertex_array_object`: the game's arrays are vertex array
            // 0's, which the renderer never binds into.
            assert_eq!(
                array, &game.arrays[location as usize],
                "{what}: array {location}"
            );
        } else if !own_vertex_array {
            // The context's arrays: off, and no index buffer of the renderer's left bound.
            assert_eq!(array[0], 0, "{what}: array {location} enabled");
            let indices = gl.get_parameter_i32(glow::ELEMENT_ARRAY_BUFFER_BINDING);
            assert_eq!(indices, 0, "{what}: index buffer");
            if has.divisors.is_some() {
                let d = attribute(gl, location, glow::VERTEX_ATTRIB_ARRAY_DIVISOR);
                assert_eq!(d, 0, "{what}: array {location}'s divisor");
            }
        }
    }
}

/// Runs `cases` again with `GlStateHandling::Reset`, on a new renderer on `ctx` that adopts
/// `renderer`'s programs (so meshes and textures upload under the reset call's state, and no
/// shader is compiled again), from the hostile game state set again before each call;
/// `expected`: a clean renderer's pictures of them, `fp16` its precision probe's answer.
pub(super) fn every_call_sets_what_it_needs_and_leaves_gl_initial_values(
    (ctx, gl): (&HeadlessContext, &glow::Context),
    renderer: Renderer,
    has: Has,
    scene: &Scene,
    cases: &[(&str, RenderOptions)],
    (expected, fp16): (&[image::RgbaImage], bool),
) {
    let es = renderer.caps().es;
    let programs = renderer.destroy_keeping_programs();
    let mut renderer = Renderer::new(ctx.load_gl().unwrap(), es).unwrap();
    renderer.adopt_programs(programs);
    renderer.set_gl_state_handling(GlStateHandling::Reset);
    assert_eq!(renderer.gl_state_handling(), GlStateHandling::Reset);
    let caps = renderer.caps();
    let own_vertex_array = has.es3 || caps.has_extension("GL_OES_vertex_array_object");
    let (w, h) = (expected[0].width(), expected[0].height());
    let size = (w as i32, h as i32);
    // Where the game's framebuffer has 16-bit depth (ES 2.0 without `GL_OES_depth24`), unlike
    // an offscreen frame's, the picture `render` must draw is a state-saving call's into the
    // same kind of framebuffer: this renderer's.
    let mut saving = (!has.depth24).then(|| Renderer::new(ctx.load_gl().unwrap(), es).unwrap());
    // Sets the game's state, runs `f`, and checks what it left.
    let mut call = |what: &str, drew_into_the_games: bool, f: &mut dyn FnMut(&mut Renderer)| {
        let game = unsafe {
            set_game_state(gl, has, size);
            game_bindings(gl, has)
        };
        f(&mut renderer);
        let call = Call {
            own_vertex_array,
            drew_into_the_games,
            what,
        };
        unsafe { assert_reset(gl, has, &game, call) };
    };
    for ((m, opts), expected) in cases.iter().zip(expected) {
        let what = format!("reset, {m} ×{}", opts.samples);
        call(&format!("{what} set_method"), false, &mut |r| {
            r.set_method_named(m).unwrap();
        });
        call(&format!("{what} warm_up"), false, &mut |r| {
            r.warm_up(scene, opts).unwrap();
        });
        call(&format!("{what} offscreen"), false, &mut |r| {
            let (img, _) = r.render_offscreen(scene, w, h, opts).unwrap();
            let d = manylight::metrics::diff(expected, &img);
            assert_eq!(d.max_abs, 0, "{what}: the game's state changed the picture");
        });
        // Into the game's own framebuffer, as a game draws.
        let expected = match saving.as_mut() {
            None => expected.clone(),
            Some(saving) => {
                saving.set_method_named(m).unwrap();
                unsafe { set_game_state(gl, has, size) };
                saving.render(scene, w, h, opts).unwrap();
                unsafe { read_drawn(gl, has, (w, h)) }
            }
        };
        call(&format!("{what} render"), true, &mut |r| {
            r.render(scene, w, h, opts).unwrap();
            // Left bound for reading, with GL's pixel-store settings: read as the game would.
            let img = unsafe { read_back(gl, (w, h)) };
            let d = manylight::metrics::diff(&expected, &img);
            assert_eq!(d.max_abs, 0, "{what}: render drew another picture");
        });
    }
    call("reset, the precision probe", false, &mut |r| {
        let measured = r.mediump_is_fp16().unwrap();
        assert_eq!(
            measured, fp16,
            "the game's state changed what the probe measured"
        );
    });
}
