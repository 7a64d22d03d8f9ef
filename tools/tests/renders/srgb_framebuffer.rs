//! A game's framebuffer that encodes sRGB itself (an `SRGB8_ALPHA8` attachment; a window
//! surface made with an sRGB colour space is the same to GL): the renderer gives it linear
//! values, so what it stores is the picture an RGBA8 framebuffer gets, not one encoded twice,
//! with every method and with MSAA.
#![allow(unsafe_code)] // the game's side: raw glow calls

use crate::common;

use common::game_target::{sized_framebuffer, stored_then_free};
use common::Gpu;
use manylight::glow::{self, HasContext};
use manylight::{scene, EsVersion, RenderOptions};

const W: u32 = 128;
const H: u32 = 72;

/// Draws `scene` with `options` into a fresh game framebuffer whose colour texture has the
/// sized format `colour` (with a 24-bit depth buffer) and reads back the bytes it stores.
fn stored(gpu: &mut Gpu, colour: u32, scene: &scene::Scene, options: &RenderOptions) -> Vec<u8> {
    try_stored(gpu, colour, scene, options).unwrap()
}

/// [`stored`], or the render's error (the framebuffer freed either way).
fn try_stored(
    gpu: &mut Gpu,
    colour: u32,
    scene: &scene::Scene,
    options: &RenderOptions,
) -> Result<Vec<u8>, manylight::Error> {
    let gl = gpu.gl();
    let target = unsafe { sized_framebuffer(&gl, colour, (W as i32, H as i32)) };
    let rendered = gpu.r().render(scene, W, H, options);
    let pixels = unsafe { stored_then_free(&gl, target, (W, H)) };
    rendered.map(|_| pixels)
}

#[test]
fn an_srgb_framebuffer_stores_what_an_rgba8_one_does_with_every_method_and_msaa() {
    let s = scene::builtin::build(scene::builtin::DEFAULT, Some((128, 3))).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    for (method, samples) in [
        ("forward", 1),
        ("tiled", 1),
        ("clustered", 1),
        ("deferred", 1),
        ("clustered", 4),
    ] {
        gpu.r().set_method_named(method).unwrap();
        let options = RenderOptions {
            samples,
            ..Default::default()
        };
        let plain = stored(&mut gpu, glow::RGBA8, &s, &options);
        let srgb = stored(&mut gpu, glow::SRGB8_ALPHA8, &s, &options);
        let lit = plain.chunks(4).filter(|p| p[0] > 20).count();
        assert!(
            lit > (W * H / 4) as usize,
            "{method}: only {lit} lit pixels"
        );
        // The shader's encode and the hardware's round apart by a step at most. With MSAA,
        // an sRGB resolve averages an edge pixel's samples as linear values (as it should),
        // the RGBA8 one as encoded ones: only pixels whose samples all agree (the RGBA8
        // frame's pixel equals its single-sampled one) are compared there.
        let single = if samples > 1 {
            let one = RenderOptions {
                samples: 1,
                ..options
            };
            Some(stored(&mut gpu, glow::RGBA8, &s, &one))
        } else {
            None
        };
        let mut compared = 0;
        for (i, (a, b)) in plain.chunks(4).zip(srgb.chunks(4)).enumerate() {
            if let Some(single) = &single {
                if single[i * 4..i * 4 + 3] != a[..3] {
                    continue;
                }
            }
            compared += 1;
            let d = (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap_or(0);
            assert!(
                d <= 2,
                "{method} ×{samples}: pixel {i} of the sRGB framebuffer is {d}/255 from the \
                 RGBA8 one's ({b:?} against {a:?})"
            );
        }
        assert!(
            compared > (W * H / 2) as usize,
            "{method}: {compared} compared"
        );
    }
}

/// 4× MSAA into an sRGB framebuffer draws what it draws into an RGBA8 one: the full-screen
/// fill before its clear is SwiftShader's workaround alone (it ran on every implementation, a
/// pass over every sample each frame), and there it is one draw more. The background it is
/// for is checked by the test above and the next, on every implementation.
#[test]
fn msaa_into_an_srgb_framebuffer_fills_it_only_where_the_clear_misses_samples() {
    let s = scene::builtin::build("plane", Some((20, 3))).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let options = RenderOptions {
        samples: 4,
        ..Default::default()
    };
    let mut calls = [0u64; 2];
    for (format, calls) in [glow::RGBA8, glow::SRGB8_ALPHA8]
        .into_iter()
        .zip(&mut calls)
    {
        let gl = gpu.gl();
        let target = unsafe { sized_framebuffer(&gl, format, (W as i32, H as i32)) };
        let stats = gpu.r().render(&s, W, H, &options);
        unsafe { stored_then_free(&gl, target, (W, H)) };
        *calls = stats.unwrap().draw_calls;
    }
    let fill = u64::from(gpu.r().caps().clears_one_sample_of_srgb_msaa());
    assert_eq!(
        calls[1],
        calls[0] + fill,
        "draw calls into RGBA8 and into sRGB"
    );
}

/// The background and the light-count heatmap, given as stored values, are stored so in an
/// sRGB framebuffer too; exact counts, which an encode would change, are refused there.
#[test]
fn the_clear_colour_and_the_heatmap_are_stored_as_given_and_exact_counts_and_linear_values_refused()
{
    let mut plane = scene::builtin::build("plane", Some((64, 2))).unwrap();
    // Far enough that the background shows around the plane.
    plane.camera = manylight::Camera::perspective(
        glam::DVec3::new(0.0, 0.0, 30.0),
        glam::DVec3::ZERO,
        60.0,
        0.1,
        100.0,
    );
    let mut gpu = Gpu::new(EsVersion::Es3);
    gpu.r().set_method_named("clustered").unwrap();
    let cases = [
        RenderOptions {
            clear_color: [0.4, 0.25, 0.75, 1.0],
            ..Default::default()
        },
        RenderOptions {
            clear_color: [0.4, 0.25, 0.75, 1.0],
            samples: 4,
            ..Default::default()
        },
        RenderOptions {
            count: manylight::CountKind::Heatmap,
            ..Default::default()
        },
    ];
    for options in &cases {
        let plain = stored(&mut gpu, glow::RGBA8, &plane, options);
        let srgb = stored(&mut gpu, glow::SRGB8_ALPHA8, &plane, options);
        // No channel halfway between two steps, where drivers round either way (NVIDIA
        // stores 0.5 as 127).
        let background = plain.chunks(4).filter(|p| p[..3] == [102, 64, 191]).count();
        if options.count == manylight::CountKind::None {
            assert!(
                background > (W * H / 4) as usize,
                "{background} background pixels, {} samples (a corner is {:?})",
                options.samples,
                &plain[..4]
            );
        }
        // With MSAA, edge pixels are averaged in linear space in the sRGB one (see above).
        let one = RenderOptions {
            samples: 1,
            ..options.clone()
        };
        let single = stored(&mut gpu, glow::RGBA8, &plane, &one);
        let worst = (0..plain.len() / 4)
            .filter(|i| single[i * 4..i * 4 + 3] == plain[i * 4..i * 4 + 3])
            .flat_map(|i| (0..3).map(move |c| i * 4 + c))
            .map(|k| plain[k].abs_diff(srgb[k]))
            .max()
            .unwrap_or(0);
        assert!(
            worst <= 2,
            "{} samples, {:?}: the sRGB framebuffer stores values {worst}/255 from the RGBA8 \
             one's",
            options.samples,
            options.count
        );
    }
    let exact = RenderOptions {
        count: manylight::CountKind::Evals,
        ..Default::default()
    };
    match try_stored(&mut gpu, glow::SRGB8_ALPHA8, &plane, &exact) {
        Err(manylight::Error::InvalidOption { field: "count", .. }) => {}
        other => panic!(
            "exact counts into an sRGB framebuffer: {:?}",
            other.map(|_| ())
        ),
    }
    // Into an RGBA8 one they are drawn.
    try_stored(&mut gpu, glow::RGBA8, &plane, &exact).unwrap();
    // Linear values likewise: an sRGB framebuffer stored them encoded (74/255 from RGBA8's).
    let linear = RenderOptions {
        linear: true,
        ..Default::default()
    };
    match try_stored(&mut gpu, glow::SRGB8_ALPHA8, &plane, &linear) {
        Err(manylight::Error::InvalidOption {
            field: "linear", ..
        }) => {}
        other => panic!(
            "linear values into an sRGB framebuffer: {:?}",
            other.map(|_| ())
        ),
    }
    try_stored(&mut gpu, glow::RGBA8, &plane, &linear).unwrap();
}

/// A game that switched sRGB writes off (`GL_EXT_sRGB_write_control`: a UI pass that stores
/// values it encoded itself) still gets the RGBA8 picture: the renderer's calls switch them
/// on, then back off.
#[test]
fn srgb_writes_the_game_switched_off_still_encode_the_renderers_picture() {
    let s = scene::builtin::build(scene::builtin::DEFAULT, Some((128, 3))).unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    if !gpu.r().caps().has_extension("GL_EXT_sRGB_write_control") {
        // SwiftShader has none (sRGB writes always encode); Mesa and ANGLE have it.
        if manylight::gl::gles_lib::chosen_folder().is_none() {
            common::skip("no GL_EXT_sRGB_write_control here");
        } else {
            eprintln!("no GL_EXT_sRGB_write_control here: sRGB writes always encode");
        }
        return;
    }
    let options = RenderOptions::default();
    let plain = stored(&mut gpu, glow::RGBA8, &s, &options);
    let gl = gpu.gl();
    unsafe { gl.disable(glow::FRAMEBUFFER_SRGB) };
    let srgb = stored(&mut gpu, glow::SRGB8_ALPHA8, &s, &options);
    assert!(
        !unsafe { gl.is_enabled(glow::FRAMEBUFFER_SRGB) },
        "the game's setting was not given back"
    );
    unsafe { gl.enable(glow::FRAMEBUFFER_SRGB) };
    let worst = plain
        .chunks(4)
        .zip(srgb.chunks(4))
        .flat_map(|(a, b)| (0..3).map(move |c| a[c].abs_diff(b[c])))
        .max()
        .unwrap_or(0);
    let lit = plain.chunks(4).filter(|p| p[0] > 20).count();
    assert!(lit > (W * H / 4) as usize, "only {lit} lit pixels");
    assert!(
        worst <= 2,
        "with sRGB writes off, the sRGB framebuffer stores values {worst}/255 from the RGBA8 one's"
    );
}
