//! The game's side of a frame drawn into part of its framebuffer (`RenderOptions::origin`).
#![allow(unsafe_code)] // raw glow calls, as a game makes them

use manylight::glow::{self, HasContext};
use manylight::scene::Scene;
use manylight::{EsVersion, RenderOptions};

use super::Gpu;

/// The game's colour outside the frame, unlike anything the scene draws.
pub const MARKER: [u8; 4] = [51, 230, 102, 255];

/// The game's framebuffer and its attachments.
pub struct GameTarget {
    fbo: glow::Framebuffer,
    colour: glow::Texture,
    depth: glow::Renderbuffer,
}

impl GameTarget {
    /// The framebuffer object.
    pub fn fbo(&self) -> glow::Framebuffer {
        self.fbo
    }

    /// Its colour texture.
    pub fn colour(&self) -> glow::Texture {
        self.colour
    }
}

/// Makes and binds a `size` RGBA8 framebuffer with depth (24 bits where the context has them,
/// as the README asks of a game's), cleared to [`MARKER`] and to a depth that would hide the
/// whole scene if the renderer drew against it.
pub unsafe fn game_framebuffer(
    gl: &glow::Context,
    depth24: bool,
    (w, h): (i32, i32),
) -> GameTarget {
    let colour = gl.create_texture().unwrap();
    gl.bind_texture(glow::TEXTURE_2D, Some(colour));
    gl.tex_image_2d(
        glow::TEXTURE_2D,
        0,
        glow::RGBA as i32,
        w,
        h,
        0,
        glow::RGBA,
        glow::UNSIGNED_BYTE,
        glow::PixelUnpackData::Slice(None),
    );
    let fbo = gl.create_framebuffer().unwrap();
    gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
    gl.framebuffer_texture_2d(
        glow::FRAMEBUFFER,
        glow::COLOR_ATTACHMENT0,
        glow::TEXTURE_2D,
        Some(colour),
        0,
    );
    let depth = gl.create_renderbuffer().unwrap();
    gl.bind_renderbuffer(glow::RENDERBUFFER, Some(depth));
    let format = if depth24 {
        glow::DEPTH_COMPONENT24
    } else {
        glow::DEPTH_COMPONENT16
    };
    gl.renderbuffer_storage(glow::RENDERBUFFER, format, w, h);
    gl.framebuffer_renderbuffer(
        glow::FRAMEBUFFER,
        glow::DEPTH_ATTACHMENT,
        glow::RENDERBUFFER,
        Some(depth),
    );
    assert_eq!(
        gl.check_framebuffer_status(glow::FRAMEBUFFER),
        glow::FRAMEBUFFER_COMPLETE
    );
    let m = MARKER.map(|c| c as f32 / 255.0);
    gl.clear_color(m[0], m[1], m[2], m[3]);
    gl.clear_depth_f32(0.0);
    gl.clear(glow::COLOR_BUFFER_BIT | glow::DEPTH_BUFFER_BIT);
    GameTarget { fbo, colour, depth }
}

/// Makes and binds a `size` framebuffer whose colour is a texture of the sized format
/// `colour` (`RGBA8`, `SRGB8_ALPHA8`), with a 24-bit depth buffer, uncleared.
pub unsafe fn sized_framebuffer(gl: &glow::Context, colour: u32, (w, h): (i32, i32)) -> GameTarget {
    let texture = gl.create_texture().unwrap();
    gl.bind_texture(glow::TEXTURE_2D, Some(texture));
    gl.tex_storage_2d(glow::TEXTURE_2D, 1, colour, w, h);
    let depth = gl.create_renderbuffer().unwrap();
    gl.bind_renderbuffer(glow::RENDERBUFFER, Some(depth));
    gl.renderbuffer_storage(glow::RENDERBUFFER, glow::DEPTH_COMPONENT24, w, h);
    let fbo = gl.create_framebuffer().unwrap();
    gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
    let attach = (glow::COLOR_ATTACHMENT0, glow::DEPTH_ATTACHMENT);
    gl.framebuffer_texture_2d(
        glow::FRAMEBUFFER,
        attach.0,
        glow::TEXTURE_2D,
        Some(texture),
        0,
    );
    gl.framebuffer_renderbuffer(glow::FRAMEBUFFER, attach.1, glow::RENDERBUFFER, Some(depth));
    GameTarget {
        fbo,
        colour: texture,
        depth,
    }
}

/// The bytes the bound framebuffer stores, bottom row first, and the framebuffer freed.
pub unsafe fn stored_then_free(
    gl: &glow::Context,
    target: GameTarget,
    (w, h): (u32, u32),
) -> Vec<u8> {
    let mut pixels = vec![0u8; (w * h * 4) as usize];
    let pack = glow::PixelPackData::Slice(Some(&mut pixels));
    gl.read_pixels(
        0,
        0,
        w as i32,
        h as i32,
        glow::RGBA,
        glow::UNSIGNED_BYTE,
        pack,
    );
    free_game_framebuffer(gl, target);
    pixels
}

/// Frees the game's framebuffer and puts back the defaults it changed, so the pooled context
/// reaches the next test clean.
pub unsafe fn free_game_framebuffer(gl: &glow::Context, target: GameTarget) {
    gl.bind_framebuffer(glow::FRAMEBUFFER, None);
    gl.clear_color(0.0, 0.0, 0.0, 0.0);
    gl.clear_depth_f32(1.0);
    gl.delete_framebuffer(target.fbo);
    gl.delete_texture(target.colour);
    gl.delete_renderbuffer(target.depth);
}

/// The bound framebuffer's pixels, top row first (as the offscreen renders give them).
pub unsafe fn read_back(gl: &glow::Context, (w, h): (u32, u32)) -> image::RgbaImage {
    let mut pixels = vec![0u8; (w * h * 4) as usize];
    gl.read_pixels(
        0,
        0,
        w as i32,
        h as i32,
        glow::RGBA,
        glow::UNSIGNED_BYTE,
        glow::PixelPackData::Slice(Some(&mut pixels)),
    );
    let bottom_up = image::RgbaImage::from_raw(w, h, pixels).unwrap();
    image::imageops::flip_vertical(&bottom_up)
}

/// The frame drawn at `origin` into a fresh game framebuffer of `whole` pixels: the
/// rectangle's pixels, top row first, after checking that no pixel outside it changed.
pub fn render_at_origin(
    gpu: &mut Gpu,
    scene: &Scene,
    options: &RenderOptions,
    (w, h): (u32, u32),
    whole: (u32, u32),
    what: &str,
) -> image::RgbaImage {
    let gl = gpu.gl();
    let caps = gpu.r().caps();
    let depth24 = caps.es == EsVersion::Es3 || caps.depth24;
    let target = unsafe { game_framebuffer(&gl, depth24, (whole.0 as i32, whole.1 as i32)) };
    let rendered = gpu.r().render(scene, w, h, options);
    let got = unsafe { read_back(&gl, whole) };
    unsafe { free_game_framebuffer(&gl, target) };
    rendered.unwrap_or_else(|e| panic!("{what}: {e}"));
    // The frame's top row is `origin.y + h` rows up from the bottom.
    let [x0, y0] = options.origin;
    let top = whole.1 - y0 - h;
    let inside = |x: u32, y: u32| (x0..x0 + w).contains(&x) && (top..top + h).contains(&y);
    let touched = got
        .enumerate_pixels()
        .filter(|&(x, y, p)| !inside(x, y) && p.0 != MARKER)
        .count();
    assert_eq!(touched, 0, "{what}: pixels outside the frame changed");
    image::imageops::crop_imm(&got, x0, top, w, h).to_image()
}
