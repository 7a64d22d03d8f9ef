//! A game that deletes its program while it is current (legal GL: the program lives on until
//! another replaces it) keeps it through a call that draws nothing, and after one that drew
//! gets no program back, rather than the renderer's left current for its uniform writes to
//! land in.

use manylight::glow::{self, HasContext};
use manylight::scene;
use manylight::{EsVersion, HeadlessContext, RenderOptions, Renderer};

/// Links a program with one `mat4` uniform; it and the uniform's location.
unsafe fn game_program(gl: &glow::Context, es3: bool) -> (glow::Program, glow::UniformLocation) {
    let (header, input, output) = if es3 {
        (
            "#version 300 es\n",
            "in",
            "out vec4 c; void main() { c = vec4(1.0); }",
        )
    } else {
        ("", "attribute", "void main() { gl_FragColor = vec4(1.0); }")
    };
    let vertex = format!(
        "{header}uniform mat4 u_game; {input} vec4 p; void main() {{ gl_Position = u_game * p; }}"
    );
    let fragment = format!("{header}precision mediump float; {output}");
    let program = gl.create_program().unwrap();
    for (kind, source) in [
        (glow::VERTEX_SHADER, vertex),
        (glow::FRAGMENT_SHADER, fragment),
    ] {
        let shader = gl.create_shader(kind).unwrap();
        gl.shader_source(shader, &source);
        gl.compile_shader(shader);
        gl.attach_shader(program, shader);
        gl.delete_shader(shader);
    }
    gl.link_program(program);
    assert!(gl.get_program_link_status(program));
    let location = gl.get_uniform_location(program, "u_game").unwrap();
    (program, location)
}

#[test]
fn a_program_the_game_deleted_while_current_is_kept_or_leaves_none_current() {
    let scene = scene::builtin::build("pillars", Some((40, 4))).unwrap();
    let (w, h, opts) = (96, 54, RenderOptions::default());
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let ctx = HeadlessContext::new(es).unwrap();
        let gl = ctx.load_gl().unwrap();
        let mut renderer = Renderer::new(ctx.load_gl().unwrap(), es).unwrap();
        renderer.set_method_named("forward").unwrap();
        let first = renderer.render_offscreen(&scene, w, h, &opts).unwrap().0;
        unsafe {
            let (program, location) = game_program(&gl, es == EsVersion::Es3);
            gl.use_program(Some(program));
            gl.delete_program(program);
            assert_eq!(gl.get_error(), glow::NO_ERROR);
            // A call that makes no program current leaves the game's alive and current.
            renderer.free_unused_uploads(&[&scene]).unwrap();
            assert_eq!(
                gl.get_parameter_program(glow::CURRENT_PROGRAM),
                Some(program)
            );
            gl.uniform_matrix_4_f32_slice(Some(&location), false, &[1.0; 16]);
            assert_eq!(
                gl.get_error(),
                glow::NO_ERROR,
                "{es}: the game's program ended"
            );
            renderer.render_offscreen(&scene, w, h, &opts).unwrap();
            // A frame made its own programs current, which ended the game's: none is left
            // current, and no error is pending for the game.
            assert_eq!(
                gl.get_parameter_program(glow::CURRENT_PROGRAM),
                None,
                "{es}"
            );
            assert_eq!(gl.get_error(), glow::NO_ERROR, "{es}");
            // The game goes on setting "its" uniform: with no program current that is the
            // game's own GL error, and no uniform of the renderer's changes.
            gl.uniform_matrix_4_f32_slice(Some(&location), false, &[0.0; 16]);
            assert_eq!(gl.get_error(), glow::INVALID_OPERATION, "{es}");
        }
        let again = renderer.render_offscreen(&scene, w, h, &opts).unwrap().0;
        let d = manylight::metrics::diff(&first, &again);
        assert_eq!(
            d.max_abs, 0,
            "{es}: the frame after the game's write differs"
        );
    }
}
