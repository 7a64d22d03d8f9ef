//! `RenderOptions::clear`: a frame drawn over what the game drew first. Keeping the colour,
//! the game's picture shows wherever the scene has no surface and the rest equals a frame of
//! its own; keeping the depth too, the game's nearer depth hides the scene where it lies
//! (here: the left half at depth 0). Every method alike; an offscreen render ignores it, and
//! the renderer's own MSAA target refuses it.
#![allow(unsafe_code)] // the game's side: raw glow calls

use crate::common;

use common::game_target::{game_framebuffer, stored_then_free, MARKER};
use common::Gpu;
use manylight::glow::{self, HasContext};
use manylight::{scene, Clear, EsVersion, RenderOptions};

const W: u32 = 96;
const H: u32 = 54;

/// The frame drawn with `clear` into a game framebuffer holding `MARKER`, its depth cleared
/// to 1 (or, `near_left`, to 0 on the left half): the stored bytes, bottom row first.
fn drawn(gpu: &mut Gpu, s: &scene::Scene, clear: Clear, near_left: bool) -> Vec<u8> {
    let gl = gpu.gl();
    let depth24 = gpu.r().caps().depth24;
    let target = unsafe {
        let target = game_framebuffer(&gl, depth24, (W as i32, H as i32));
        gl.clear_depth_f32(1.0);
        gl.clear(glow::DEPTH_BUFFER_BIT);
        if near_left {
            gl.enable(glow::SCISSOR_TEST);
            gl.scissor(0, 0, W as i32 / 2, H as i32);
            gl.clear_depth_f32(0.0);
            gl.clear(glow::DEPTH_BUFFER_BIT);
            gl.disable(glow::SCISSOR_TEST);
        }
        target
    };
    let options = RenderOptions {
        clear,
        clear_color: [0.0, 0.0, 0.0, 1.0],
        ..Default::default()
    };
    let rendered = gpu.r().render(s, W, H, &options);
    let pixels = unsafe { stored_then_free(&gl, target, (W, H)) };
    rendered.unwrap();
    pixels
}

fn pixel(bytes: &[u8], x: u32, y: u32) -> [u8; 4] {
    let i = ((y * W + x) * 4) as usize;
    [bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]
}

#[test]
fn a_frame_keeps_the_games_colour_and_depth_when_asked() {
    let s = scene::builtin::build("pillars", Some((64, 5))).unwrap();
    let cases: [(EsVersion, &[&str]); 2] = [
        (EsVersion::Es2, &["forward", "tiled", "clustered", "auto"]),
        (
            EsVersion::Es3,
            &["forward", "tiled", "clustered", "deferred", "auto"],
        ),
    ];
    for (es, methods) in cases {
        let mut gpu = Gpu::new(es);
        for &method in methods {
            keeps(&mut gpu, &s, method);
        }
    }
}

fn keeps(gpu: &mut Gpu, s: &scene::Scene, method: &str) {
    gpu.r().set_method_named(method).unwrap();
    let alone = drawn(gpu, s, Clear::All, false);
    let over_colour = drawn(gpu, s, Clear::Depth, true);
    let over_both = drawn(gpu, s, Clear::Nothing, true);
    let (mut background, mut surface, mut hidden) = (0, 0, 0);
    for y in 0..H {
        for x in 0..W {
            let own = pixel(&alone, x, y);
            let empty = own[..3] == [0, 0, 0];
            if empty {
                background += 1;
            } else {
                surface += 1;
            }
            let expect = if empty { MARKER } else { own };
            let close = |p: [u8; 4]| p.iter().zip(expect).all(|(a, b)| a.abs_diff(b) <= 1);
            let got = pixel(&over_colour, x, y);
            assert!(
                close(got),
                "{method} keeping colour at ({x}, {y}): {got:?}, {expect:?}"
            );
            let got = pixel(&over_both, x, y);
            if x < W / 2 {
                hidden += usize::from(!empty);
                assert_eq!(got, MARKER, "{method}: the game's depth hides ({x}, {y})");
            } else {
                assert!(close(got), "{method} keeping both at ({x}, {y}): {got:?}");
            }
        }
    }
    assert!(
        background > 100 && surface > 100 && hidden > 100,
        "{method}: {background} background, {surface} surface, {hidden} hidden"
    );
}

/// An offscreen render has nothing to keep and ignores `clear` (as it ignores `origin`), so a
/// game's options serve it too; the renderer's own MSAA target refuses it.
#[test]
fn an_offscreen_frame_ignores_clear_and_an_msaa_frame_refuses_it() {
    let s = scene::builtin::build("plane", Some((4, 1))).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let keep = RenderOptions {
        clear: Clear::Nothing,
        ..Default::default()
    };
    let (alone, _) = gpu
        .r()
        .render_offscreen(&s, 32, 18, &RenderOptions::default())
        .unwrap();
    let (kept, _) = gpu.r().render_offscreen(&s, 32, 18, &keep).unwrap();
    assert_eq!(alone, kept);
    let counts = gpu
        .r()
        .render_light_counts(&s, 32, 18, &keep, manylight::CountKind::Evals);
    assert!(counts.is_ok(), "{:?}", counts.err());
    let gl = gpu.gl();
    let depth24 = gpu.r().caps().depth24;
    let target = unsafe { game_framebuffer(&gl, depth24, (32, 18)) };
    let msaa = RenderOptions { samples: 4, ..keep };
    let result = gpu.r().render(&s, 32, 18, &msaa);
    unsafe { stored_then_free(&gl, target, (32, 18)) };
    let err = result.unwrap_err().to_string();
    assert!(err.contains("clear") && err.contains("MSAA"), "{err}");
}
