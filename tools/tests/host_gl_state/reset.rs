//! `GlStateHandling::Reset`: from the same hostile game state, set again before each call as
//! such an engine does, every call draws what a clean renderer draws, and returns with what
//! the README lists: the game's framebuffer bound, and GL's initial values (the OpenGL ES 3.0
//! specification's state tables) for the rest of what the renderer changes. What the renderer
//! never touches stays the game's: its texture on a unit past the eighth, and its vertex array
//! 0 where the renderer draws with one of its own.

use super::{set_game_state, Has, GAME_UNITS};
use crate::common::game_target::read_back;
use manylight::glow::{self, HasContext};
use manylight::{GlStateHandling, RenderOptions, Renderer, Scene};

/// What the game had bound as a call started, read back after it.
struct GameBindings {
    framebuffer: i32,
    /// The texture on the last unit the game binds (past the renderer's eight).
    last_unit_texture: i32,
    /// Its attribute arrays at the renderer's locations (enabled, size, type, stride, buffer),
    /// which are vertex array 0's where the game draws with it.
    arrays: Vec<[i32; 5]>,
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

unsafe fn game_bindings(gl: &glow::Context) -> GameBindings {
    let active = gl.get_parameter_i32(glow::ACTIVE_TEXTURE);
    gl.active_texture(glow::TEXTURE0 + GAME_UNITS - 1);
    let last_unit_texture = gl.get_parameter_i32(glow::TEXTURE_BINDING_2D);
    gl.active_texture(active as u32);
    GameBindings {
        framebuffer: gl.get_parameter_i32(glow::FRAMEBUFFER_BINDING),
        last_unit_texture,
        arrays: arrays(gl),
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

/// Checks the state a call with `GlStateHandling::Reset` leaves. `own_vertex_array`: the
/// renderer draws with a vertex array of its own (ES 3.x, `GL_OES_vertex_array_object`).
unsafe fn assert_reset(
    gl: &glow::Context,
    has: Has,
    game: &GameBindings,
    own_vertex_array: bool,
    what: &str,
) {
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
    let mut disabled = vec![
        glow::BLEND,
        glow::CULL_FACE,
        glow::DEPTH_TEST,
        glow::SCISSOR_TEST,
        glow::STENCIL_TEST,
        glow::POLYGON_OFFSET_FILL,
        glow::SAMPLE_ALPHA_TO_COVERAGE,
        glow::SAMPLE_COVERAGE,
    ];
    if has.es3 {
        ints.extend([
            (glow::READ_FRAMEBUFFER_BINDING, game.framebuffer),
            (glow::VERTEX_ARRAY_BINDING, 0),
            (glow::PIXEL_PACK_BUFFER_BINDING, 0),
            (glow::PIXEL_UNPACK_BUFFER_BINDING, 0),
            (glow::DRAW_BUFFER0, glow::COLOR_ATTACHMENT0 as i32),
        ]);
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
            assert_eq!(array[0], 0, "{what}: array {location} enabled");
            if has.divisors.is_some() {
                let d = attribute(gl, location, glow::VERTEX_ATTRIB_ARRAY_DIVISOR);
                assert_eq!(d, 0, "{what}: array {location}'s divisor");
            }
        }
    }
}

/// Runs `cases` again on `renderer` with `GlStateHandling::Reset`, from the hostile game state
/// set again before each call; `expected`: a clean renderer's pictures of them.
pub(super) fn every_call_sets_what_it_needs_and_leaves_gl_initial_values(
    gl: &glow::Context,
    renderer: &mut Renderer,
    has: Has,
    scene: &Scene,
    cases: &[(&str, RenderOptions)],
    expected: &[image::RgbaImage],
) {
    let (w, h) = (expected[0].width(), expected[0].height());
    renderer.set_gl_state_handling(GlStateHandling::Reset);
    assert_eq!(renderer.gl_state_handling(), GlStateHandling::Reset);
    let caps = renderer.caps();
    let own_vertex_array = has.es3 || caps.has_extension("GL_OES_vertex_array_object");
    let size = (w as i32, h as i32);
    for ((m, opts), expected) in cases.iter().zip(expected) {
        let what = format!("reset, {m} ×{}", opts.samples);
        let game = unsafe {
            set_game_state(gl, has, size);
            game_bindings(gl)
        };
        renderer.set_method_named(m).unwrap();
        unsafe {
            assert_reset(
                gl,
                has,
                &game,
                own_vertex_array,
                &format!("{what} set_method"),
            )
        };
        unsafe { set_game_state(gl, has, size) };
        let game = unsafe { game_bindings(gl) };
        renderer.warm_up(scene, opts).unwrap();
        unsafe { assert_reset(gl, has, &game, own_vertex_array, &format!("{what} warm_up")) };
        unsafe { set_game_state(gl, has, size) };
        let game = unsafe { game_bindings(gl) };
        let (img, _) = renderer.render_offscreen(scene, w, h, opts).unwrap();
        let d = manylight::metrics::diff(expected, &img);
        assert_eq!(d.max_abs, 0, "{what}: the game's state changed the picture");
        unsafe {
            assert_reset(
                gl,
                has,
                &game,
                own_vertex_array,
                &format!("{what} offscreen"),
            )
        };
        // Into the game's own framebuffer, as a game draws. Where it has 16-bit depth (ES 2.0
        // without `GL_OES_depth24`), unlike an offscreen frame's, the picture to draw is the
        // state-saving call's into the same kind of framebuffer.
        let expected = match has.depth24 {
            true => expected.clone(),
            false => {
                renderer.set_gl_state_handling(GlStateHandling::SaveAndRestore);
                unsafe { set_game_state(gl, has, size) };
                renderer.render(scene, w, h, opts).unwrap();
                renderer.set_gl_state_handling(GlStateHandling::Reset);
                unsafe { read_drawn(gl, has, (w, h)) }
            }
        };
        unsafe { set_game_state(gl, has, size) };
        let game = unsafe { game_bindings(gl) };
        renderer.render(scene, w, h, opts).unwrap();
        unsafe { assert_reset(gl, has, &game, own_vertex_array, &format!("{what} render")) };
        // Left bound for reading, with GL's pixel-store settings: read as the game would.
        let img = unsafe { read_back(gl, (w, h)) };
        let d = manylight::metrics::diff(&expected, &img);
        assert_eq!(d.max_abs, 0, "{what}: render drew another picture");
    }
    renderer.set_gl_state_handling(GlStateHandling::SaveAndRestore);
}
