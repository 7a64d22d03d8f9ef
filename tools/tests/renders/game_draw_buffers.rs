//! A game framebuffer's draw buffers: the frame goes to colour attachment 0. A framebuffer with
//! its colour elsewhere is refused naming it (single-sampled frames there were undefined pixels
//! on Mesa and ANGLE, returning `Ok`), and a game's second draw buffer, an MRT target left
//! bound, keeps its pixels (it took undefined values, or the resolved frame), its list given
//! back after the call.
#![allow(unsafe_code)] // the game's side: raw glow calls

use crate::common;

use common::game_target::MARKER;
use common::Gpu;
use manylight::glow::{self, HasContext};
use manylight::{scene, Error, EsVersion, GlError, RenderOptions};

const W: u32 = 64;
const H: u32 = 36;

/// A game's framebuffer: RGBA8 textures at the colour attachments `at`, cleared to
/// [`MARKER`], 24-bit depth, its draw buffers `draw`; bound.
struct Mrt {
    fbo: glow::Framebuffer,
    colours: Vec<glow::Texture>,
    depth: glow::Renderbuffer,
}

unsafe fn mrt(gl: &glow::Context, at: &[u32], draw: &[u32]) -> Mrt {
    let fbo = gl.create_framebuffer().unwrap();
    gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
    let colours = at
        .iter()
        .map(|&attachment| {
            let t = gl.create_texture().unwrap();
            gl.bind_texture(glow::TEXTURE_2D, Some(t));
            gl.tex_storage_2d(glow::TEXTURE_2D, 1, glow::RGBA8, W as i32, H as i32);
            gl.framebuffer_texture_2d(glow::FRAMEBUFFER, attachment, glow::TEXTURE_2D, Some(t), 0);
            t
        })
        .collect();
    let depth = gl.create_renderbuffer().unwrap();
    gl.bind_renderbuffer(glow::RENDERBUFFER, Some(depth));
    let size = (W as i32, H as i32);
    gl.renderbuffer_storage(glow::RENDERBUFFER, glow::DEPTH_COMPONENT24, size.0, size.1);
    let attach = glow::DEPTH_ATTACHMENT;
    gl.framebuffer_renderbuffer(glow::FRAMEBUFFER, attach, glow::RENDERBUFFER, Some(depth));
    assert_eq!(
        gl.check_framebuffer_status(glow::FRAMEBUFFER),
        glow::FRAMEBUFFER_COMPLETE
    );
    // Every attachment cleared to the marker, then the game's own list.
    gl.draw_buffers(&[
        glow::COLOR_ATTACHMENT0,
        glow::COLOR_ATTACHMENT1,
        glow::COLOR_ATTACHMENT2,
    ]);
    let m = MARKER.map(|c| c as f32 / 255.0);
    gl.clear_color(m[0], m[1], m[2], m[3]);
    gl.clear(glow::COLOR_BUFFER_BIT);
    gl.clear_color(0.0, 0.0, 0.0, 0.0);
    gl.draw_buffers(draw);
    Mrt {
        fbo,
        colours,
        depth,
    }
}

/// The framebuffer's draw buffers 0 to 2 now.
unsafe fn draw_buffers(gl: &glow::Context) -> [u32; 3] {
    [0, 1, 2].map(|i| gl.get_parameter_i32(glow::DRAW_BUFFER0 + i) as u32)
}

/// The pixels of colour attachment `attachment`, bottom row first; then the framebuffer
/// freed (after the last read).
unsafe fn read(gl: &glow::Context, attachment: u32) -> Vec<u8> {
    let mut pixels = vec![0u8; (W * H * 4) as usize];
    gl.read_buffer(attachment);
    let pack = glow::PixelPackData::Slice(Some(&mut pixels));
    let (w, h) = (W as i32, H as i32);
    gl.read_pixels(0, 0, w, h, glow::RGBA, glow::UNSIGNED_BYTE, pack);
    gl.read_buffer(glow::COLOR_ATTACHMENT0);
    pixels
}

unsafe fn free(gl: &glow::Context, target: Mrt) {
    gl.bind_framebuffer(glow::FRAMEBUFFER, None);
    gl.delete_framebuffer(target.fbo);
    for t in target.colours {
        gl.delete_texture(t);
    }
    gl.delete_renderbuffer(target.depth);
}

fn scene() -> manylight::Scene {
    scene::builtin::build("pillars", Some((64, 5))).unwrap()
}

fn options(samples: u32) -> RenderOptions {
    RenderOptions {
        samples,
        ..Default::default()
    }
}

/// The ES 3.0 renderer, and the ES 2.0 renderer on an ES 3.x context (where the context has
/// draw buffers whatever level the renderer plays).
fn levels() -> Vec<EsVersion> {
    let mut levels = vec![EsVersion::Es3];
    if Gpu::new(EsVersion::Es2).r().caps().context_has_es3_state() {
        levels.push(EsVersion::Es2);
    }
    levels
}

#[test]
fn a_colour_buffer_away_from_attachment_zero_is_refused_naming_it() {
    for es in levels() {
        let mut gpu = Gpu::new(es);
        let gl = gpu.gl();
        for samples in [1, 4] {
            let what = format!("{es}, {samples} samples");
            let at1 = [glow::NONE, glow::COLOR_ATTACHMENT1];
            let target = unsafe { mrt(&gl, &[glow::COLOR_ATTACHMENT1], &at1) };
            let result = gpu.r().render(&scene(), W, H, &options(samples));
            let (kept, list) = unsafe { (read(&gl, glow::COLOR_ATTACHMENT1), draw_buffers(&gl)) };
            unsafe { free(&gl, target) };
            match result {
                Err(Error::Gl(GlError::BoundFramebuffer(why))) => {
                    assert!(why.contains("GL_COLOR_ATTACHMENT0"), "{what}: {why}")
                }
                other => panic!("{what}: {other:?}"),
            }
            assert!(kept.chunks(4).all(|p| p == MARKER), "{what}: drawn into");
            assert_eq!(list[..2], at1, "{what}: the game's draw buffers");
        }
    }
}

#[test]
fn a_second_draw_buffer_of_the_game_keeps_its_pixels() {
    for es in levels() {
        let mut gpu = Gpu::new(es);
        let gl = gpu.gl();
        for method in common::methods_on(es) {
            for samples in [1, 4] {
                let what = format!("{es} {method}, {samples} samples");
                let opts = options(samples);
                gpu.r().set_method_named(method).unwrap();
                let offscreen = match gpu.r().render_offscreen(&scene(), W, H, &opts) {
                    Ok((image, _)) => image,
                    // Deferred, and ES 2.0 without the extension, have no MSAA.
                    Err(Error::Msaa { .. }) if samples > 1 => continue,
                    Err(e) => panic!("{what}: {e}"),
                };
                let attachments = [glow::COLOR_ATTACHMENT0, glow::COLOR_ATTACHMENT1];
                let both = [attachments[0], attachments[1], glow::NONE];
                let target = unsafe { mrt(&gl, &attachments, &both) };
                let result = gpu.r().render(&scene(), W, H, &opts);
                let list = unsafe { draw_buffers(&gl) };
                let (frame, second) = unsafe { (read(&gl, both[0]), read(&gl, both[1])) };
                unsafe { free(&gl, target) };
                result.unwrap_or_else(|e| panic!("{what}: {e}"));
                assert_eq!(list, both, "{what}: the game's draw buffers");
                let changed = second.chunks(4).filter(|&p| p != MARKER).count();
                assert_eq!(
                    changed, 0,
                    "{what}: pixels of the second draw buffer changed"
                );
                let bottom_up = image::RgbaImage::from_raw(W, H, frame).unwrap();
                let frame = image::imageops::flip_vertical(&bottom_up);
                let d = manylight::metrics::diff(&offscreen, &frame);
                assert!(d.max_abs <= 1, "{what}: {} / 255 from offscreen", d.max_abs);
            }
        }
    }
}
