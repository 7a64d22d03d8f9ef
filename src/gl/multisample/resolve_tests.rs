//! The ES 3.0 resolve where the driver refuses the direct blit it was told would work.
#![allow(unsafe_code)]

use glow::HasContext;

use super::MultisampleTarget;
use crate::gl::context::context_or_skip;
use crate::gl::program::ProgramCache;
use crate::gl::{Device, EsVersion};

/// An `RGB565` framebuffer of `size`, bound: what a window surface without alpha stores.
unsafe fn rgb565_framebuffer(gl: &glow::Context, size: i32) -> glow::Framebuffer {
    let colour = gl.create_renderbuffer().unwrap();
    gl.bind_renderbuffer(glow::RENDERBUFFER, Some(colour));
    gl.renderbuffer_storage(glow::RENDERBUFFER, glow::RGB565, size, size);
    let fbo = gl.create_framebuffer().unwrap();
    gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
    let attachment = glow::COLOR_ATTACHMENT0;
    gl.framebuffer_renderbuffer(
        glow::FRAMEBUFFER,
        attachment,
        glow::RENDERBUFFER,
        Some(colour),
    );
    fbo
}

/// Told the formats are identical (as NVIDIA's sizes say of an `RGBA4` destination it stores as
/// RGBA8), the resolve still lands: a refused blit goes through the single-sampled copy.
#[test]
fn a_refused_direct_resolve_goes_through_the_copy() {
    let Some(ctx) = context_or_skip(EsVersion::Es3) else {
        return;
    };
    let dev = Device::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    let mut programs = ProgramCache::new();
    let mut target = MultisampleTarget::new(&dev, 8, 8, 4).unwrap();
    let gl = &dev.gl;
    target.bind(&dev);
    unsafe {
        gl.clear_color(1.0, 0.0, 1.0, 1.0);
        gl.clear(glow::COLOR_BUFFER_BIT);
    }
    let destination = unsafe { rgb565_framebuffer(gl, 8) };
    dev.check("the test's framebuffers").unwrap();
    let same_format = true;
    target
        .resolve(&dev, &mut programs, Some(destination), [0, 0], same_format)
        .unwrap();
    let mut pixel = [0u8; 4];
    unsafe {
        let pack = glow::PixelPackData::Slice(Some(&mut pixel));
        gl.read_pixels(3, 3, 1, 1, glow::RGBA, glow::UNSIGNED_BYTE, pack);
    }
    assert_eq!(&pixel[..3], &[255, 0, 255], "the cleared colour, resolved");
    target.destroy(&dev);
    unsafe { gl.delete_framebuffer(destination) };
}
