//! Measures how the fragment stage really evaluates `mediump`: phones (and llvmpipe) use fp16,
//! desktop drivers fp32. The stability tests use it as a canary, so they keep
//! testing fp16 behaviour rather than silently passing on an fp32 driver.
#![allow(unsafe_code)]

use glow::HasContext;

use super::framebuffer::OffscreenTarget;
use super::program::{Program, Resolver, Uniform, UniformSet};
use super::{Device, GlError};

/// The probe's two operands.
struct ProbeUniforms {
    big: Uniform<f32>,
    one: Uniform<f32>,
}

impl UniformSet for ProbeUniforms {
    fn resolve(r: &mut Resolver<'_>) -> Self {
        ProbeUniforms {
            big: r.required("u_big"),
            one: r.required("u_one"),
        }
    }
}

/// True when `mediump` arithmetic in the fragment stage rounds like fp16.
pub fn mediump_is_fp16(dev: &Device) -> Result<bool, GlError> {
    let mut target = OffscreenTarget::new(dev, 1, 1)?;
    let result =
        Program::build::<ProbeUniforms>(dev, "precision_probe", &[], 0).and_then(|mut program| {
            let pixel = draw_probe(dev, &target, &program);
            program.destroy(dev);
            pixel
        });
    target.destroy(dev);
    dev.bind_default_framebuffer();
    Ok(result?.get_pixel(0, 0)[0] < 128)
}

/// Draws the probe's pixel into `target` with `program` and reads it back.
fn draw_probe(
    dev: &Device,
    target: &OffscreenTarget,
    program: &Program,
) -> Result<image::RgbaImage, GlError> {
    let gl = &dev.gl;
    // One clip-space triangle covering the pixel.
    let vertices: [f32; 9] = [-1.0, -1.0, 0.0, 3.0, -1.0, 0.0, -1.0, 3.0, 0.0];
    unsafe {
        let buffer = dev.create_buffer()?;
        gl.bind_buffer(glow::ARRAY_BUFFER, Some(buffer));
        gl.buffer_data_u8_slice(
            glow::ARRAY_BUFFER,
            bytemuck::cast_slice(&vertices),
            glow::STATIC_DRAW,
        );
        target.bind(dev);
        gl.disable(glow::DEPTH_TEST);
        gl.disable(glow::BLEND);
        // A game's culling (kept while the renderer works) could cull the probe's triangle.
        gl.disable(glow::CULL_FACE);
        gl.color_mask(true, true, true, true);
        program.bind(dev);
        if let Some(u) = program.uniforms::<ProbeUniforms>() {
            u.big.set(dev, 2048.0);
            u.one.set(dev, 1.0);
        }
        dev.bind_own_vertex_array();
        gl.enable_vertex_attrib_array(0);
        gl.vertex_attrib_pointer_f32(0, 3, glow::FLOAT, false, 12, 0);
        for loc in 1..3 {
            gl.disable_vertex_attrib_array(loc);
        }
        gl.draw_arrays(glow::TRIANGLES, 0, 3);
        let pixel = target.read_rgba8(dev);
        // The renderer's own vertex array keeps no array into the buffer deleted below.
        gl.disable_vertex_attrib_array(0);
        dev.delete_buffer(buffer);
        pixel
    }
}
