//! MSAA into the framebuffers a game really binds: window surfaces without alpha (`RGB8`,
//! `RGB565`) and other normalized and float formats, which a multisample resolve cannot blit into
//! directly (it needs identical formats), and a framebuffer that is multisampled itself (a
//! window surface made with `EGL_SAMPLES`), which samples the frame on its own.
#![allow(unsafe_code)] // the game's side: raw glow calls

use crate::common;

use common::game_target::{free_game_framebuffer, sized_framebuffer, stored_then_free};
use common::Gpu;
use manylight::glow::{self, HasContext};
use manylight::{scene, EsVersion, RenderOptions};

const W: u32 = 128;
const H: u32 = 72;

fn msaa() -> RenderOptions {
    RenderOptions {
        samples: 4,
        ..Default::default()
    }
}

/// The bytes a fresh game framebuffer with colour format `colour` stores after the frame.
fn stored(gpu: &mut Gpu, colour: u32, s: &scene::Scene) -> Vec<u8> {
    let gl = gpu.gl();
    let target = unsafe { sized_framebuffer(&gl, colour, (W as i32, H as i32)) };
    let rendered = gpu.r().render(s, W, H, &msaa());
    let pixels = unsafe { stored_then_free(&gl, target, (W, H)) };
    rendered.unwrap_or_else(|e| panic!("format 0x{colour:x}: {e}"));
    pixels
}

/// The largest difference of the red, green and blue channels.
fn max_rgb_diff(a: &[u8], b: &[u8]) -> u8 {
    a.chunks(4)
        .zip(b.chunks(4))
        .flat_map(|(p, q)| (0..3).map(move |c| p[c].abs_diff(q[c])))
        .max()
        .unwrap_or(0)
}

fn lit(pixels: &[u8]) -> usize {
    pixels.chunks(4).filter(|p| p[0] > 20).count()
}

#[test]
fn msaa_resolves_into_framebuffers_of_other_colour_formats() {
    let s = scene::builtin::build(scene::builtin::DEFAULT, Some((128, 3))).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let rgba8 = stored(&mut gpu, glow::RGBA8, &s);
    assert!(lit(&rgba8) > (W * H / 4) as usize);
    // Each format's bound: half its step and 2/255 of rounding.
    for (name, colour, bound) in [
        ("RGB8", glow::RGB8, 2),
        ("RGB565", glow::RGB565, 7),
        ("RGBA4", glow::RGBA4, 11),
        ("RGB10_A2", glow::RGB10_A2, 2),
    ] {
        let pixels = stored(&mut gpu, colour, &s);
        let diff = max_rgb_diff(&rgba8, &pixels);
        assert!(diff <= bound, "{name}: {diff}/255 from RGBA8");
    }
}

/// Float colour formats a game may render into (`GL_EXT_color_buffer_float`) take the resolved
/// frame too, through the same copy: the values RGBA8 stores, within its rounding.
#[test]
fn msaa_resolves_into_float_framebuffers() {
    let s = scene::builtin::build(scene::builtin::DEFAULT, Some((128, 3))).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let gl = gpu.gl();
    let extensions = gl.supported_extensions().clone();
    if !extensions.contains("GL_EXT_color_buffer_float") {
        common::skip("no GL_EXT_color_buffer_float: float framebuffers are not renderable");
        return;
    }
    let rgba8 = stored(&mut gpu, glow::RGBA8, &s);
    // Each format's bound: half its step below 1 (blue's 5-bit mantissa: 2⁻⁶) and 2/255.
    for (name, colour, bound) in [
        ("RGBA16F", glow::RGBA16F, 2),
        ("R11F_G11F_B10F", glow::R11F_G11F_B10F, 4),
        ("RGBA32F", glow::RGBA32F, 2),
    ] {
        let gl = gpu.gl();
        let target = unsafe { sized_framebuffer(&gl, colour, (W as i32, H as i32)) };
        let rendered = gpu.r().render(&s, W, H, &msaa());
        let mut bytes = vec![0u8; (W * H * 16) as usize];
        unsafe {
            let pack = glow::PixelPackData::Slice(Some(&mut bytes));
            gl.read_pixels(0, 0, W as i32, H as i32, glow::RGBA, glow::FLOAT, pack);
            assert_eq!(gl.get_error(), glow::NO_ERROR, "{name}: reading floats");
            free_game_framebuffer(&gl, target);
        }
        rendered.unwrap_or_else(|e| panic!("{name}: {e}"));
        let pixels: Vec<u8> = bytes
            .chunks(4)
            .map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]]))
            .map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
            .collect();
        let diff = max_rgb_diff(&rgba8, &pixels);
        assert!(diff <= bound, "{name}: {diff}/255 from RGBA8");
    }
}

/// Makes and binds a 4-sample RGBA8 framebuffer with 24-bit depth (a window surface made with
/// `EGL_SAMPLES`): the framebuffer and its colour and depth renderbuffers.
unsafe fn multisampled_framebuffer(
    gl: &glow::Context,
    (w, h): (i32, i32),
) -> (glow::Framebuffer, [glow::Renderbuffer; 2]) {
    let buffers = [
        gl.create_renderbuffer().unwrap(),
        gl.create_renderbuffer().unwrap(),
    ];
    let fbo = gl.create_framebuffer().unwrap();
    gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
    for (rb, format, attachment) in [
        (buffers[0], glow::RGBA8, glow::COLOR_ATTACHMENT0),
        (buffers[1], glow::DEPTH_COMPONENT24, glow::DEPTH_ATTACHMENT),
    ] {
        gl.bind_renderbuffer(glow::RENDERBUFFER, Some(rb));
        gl.renderbuffer_storage_multisample(glow::RENDERBUFFER, 4, format, w, h);
        gl.framebuffer_renderbuffer(glow::FRAMEBUFFER, attachment, glow::RENDERBUFFER, Some(rb));
    }
    assert_eq!(
        gl.check_framebuffer_status(glow::FRAMEBUFFER),
        glow::FRAMEBUFFER_COMPLETE
    );
    (fbo, buffers)
}

/// Into a framebuffer multisampled itself, `auto` past clustered's index limit can still take
/// deferred (its G-buffer is single-sampled, the framebuffer samples the composite): the
/// renderer's own MSAA is what rules deferred out, not `samples` as asked.
#[test]
fn auto_takes_deferred_into_a_multisampled_game_framebuffer() {
    let s = common::light_lattice::plane_past_the_index_limit();
    let mut gpu = Gpu::new(EsVersion::Es3);
    gpu.r().set_method_named("auto").unwrap();
    let gl = gpu.gl();
    let (fbo, buffers) = unsafe { multisampled_framebuffer(&gl, (32, 18)) };
    let stats = gpu.r().render(&s, 32, 18, &msaa());
    unsafe {
        gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        gl.delete_framebuffer(fbo);
        buffers.iter().for_each(|&rb| gl.delete_renderbuffer(rb));
    }
    let stats = stats.unwrap();
    assert_eq!(
        stats.auto_choice.as_deref(),
        Some("deferred"),
        "{:?}",
        stats.auto_reason
    );
}

#[test]
fn a_multisampled_game_framebuffer_samples_the_frame_itself() {
    let s = scene::builtin::build(scene::builtin::DEFAULT, Some((128, 3))).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let reference = stored(&mut gpu, glow::RGBA8, &s);
    let gl = gpu.gl();
    let (w, h) = (W as i32, H as i32);
    let (fbo, buffers) = unsafe { multisampled_framebuffer(&gl, (w, h)) };
    let stats = gpu.r().render(&s, W, H, &msaa());
    // The game resolves its own framebuffer, into a single-sampled one to read.
    let single = unsafe { sized_framebuffer(&gl, glow::RGBA8, (w, h)) };
    let pixels = unsafe {
        gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(fbo));
        gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, Some(single.fbo()));
        gl.blit_framebuffer(
            0,
            0,
            w,
            h,
            0,
            0,
            w,
            h,
            glow::COLOR_BUFFER_BIT,
            glow::NEAREST,
        );
        gl.bind_framebuffer(glow::FRAMEBUFFER, Some(single.fbo()));
        let pixels = stored_then_free(&gl, single, (W, H));
        gl.delete_framebuffer(fbo);
        buffers.iter().for_each(|&rb| gl.delete_renderbuffer(rb));
        pixels
    };
    let stats = stats.expect("a multisampled game framebuffer takes an MSAA frame");
    assert!(stats.samples >= 4, "{}", stats.samples);
    assert_eq!(
        stats.memory.msaa_bytes, 0,
        "no target of the renderer's own"
    );
    assert!(lit(&pixels) > (W * H / 4) as usize);
    let diff = max_rgb_diff(&reference, &pixels);
    assert!(diff <= 2, "{diff}/255 from the renderer's own MSAA");
}

/// A game that turns MSAA off gets the target's memory back at its next frame (it was held
/// until the renderer was dropped: tens of MB at 1080p).
#[test]
fn turning_msaa_off_frees_the_multisampled_target() {
    let s = scene::builtin::build(scene::builtin::DEFAULT, Some((16, 3))).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let (_, single) = gpu
        .r()
        .render_offscreen(&s, W, H, &RenderOptions::default())
        .unwrap();
    let before = gpu.r().live_gl_objects();
    let (_, multi) = gpu.r().render_offscreen(&s, W, H, &msaa()).unwrap();
    assert!(multi.memory.msaa_bytes > 0);
    let held = gpu.r().live_gl_objects();
    assert!(
        held.renderbuffers > before.renderbuffers,
        "{held:?} {before:?}"
    );
    let (_, after) = gpu
        .r()
        .render_offscreen(&s, W, H, &RenderOptions::default())
        .unwrap();
    assert_eq!(after.memory.msaa_bytes, single.memory.msaa_bytes);
    // (Textures are the method's, which may grow with the frame's needs.)
    let live = gpu.r().live_gl_objects();
    assert_eq!(
        (live.renderbuffers, live.framebuffers),
        (before.renderbuffers, before.framebuffers),
        "the target is freed"
    );
    // And made again when asked.
    let (_, again) = gpu.r().render_offscreen(&s, W, H, &msaa()).unwrap();
    assert_eq!(again.memory.msaa_bytes, multi.memory.msaa_bytes);
}
