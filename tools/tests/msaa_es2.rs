//! MSAA on ES 2.0 through `GL_EXT_multisampled_render_to_texture`, which llvmpipe's ES 2.0
//! does not list: this binary adds it with `MESA_EXTENSION_OVERRIDE` before its first context
//! (Mesa reads the variable once per process). Mesa then accepts the extension's calls and
//! completes the framebuffer, but llvmpipe keeps one sample for a texture attachment, so what
//! this checks here is the path — the texture, the EXT depth renderbuffer, the copy pass onto
//! the destination — and that every method still equals plain forward through it; the
//! averaging itself is the driver's (Mali, Adreno, PowerVR), and the edge test asserts the
//! coverage fractions of 4 samples wherever a driver does it.

mod common;

use common::game_target::render_at_origin;
use common::{msaa, Gpu};
use manylight::scene;
use manylight::{EsVersion, RenderOptions};

/// An ES 2.0 renderer on a context that has the extension; `None` on another implementation
/// than Mesa, whose override adds it.
fn es2_with_the_extension() -> Option<Gpu> {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // Every test of this binary calls this before making a context, and the value is the
        // same, so no thread sees it change. Set before the question below, whose context
        // would fix Mesa's extensions without it (Mesa reads the override once a process).
        std::env::set_var(
            "MESA_EXTENSION_OVERRIDE",
            "+GL_EXT_multisampled_render_to_texture",
        );
    });
    if common::other_implementation_than_mesa("MESA_EXTENSION_OVERRIDE") {
        return None;
    }
    let mut gpu = Gpu::new(EsVersion::Es2);
    let caps = gpu.r().caps();
    assert!(
        caps.msaa_render_to_texture && caps.max_samples >= 4,
        "the override did not give this ES 2.0 context the extension ({} samples)",
        caps.max_samples
    );
    Some(gpu)
}

#[test]
fn every_method_with_msaa_matches_forward_with_msaa_on_es2() {
    let Some(mut gpu) = es2_with_the_extension() else {
        return;
    };
    // 4 bytes of colour and 4 of depth (llvmpipe has OES_depth24) per sample, plus the
    // resolved texel.
    assert!(gpu.r().caps().depth24);
    common::assert_methods_match_forward_with_4_samples(&mut gpu, 4 * 8 + 4);
    let scene = scene::builtin::build("courtyard", Some((64, 2))).unwrap();
    // Deferred is ES 3.0 only; more samples than the context has are refused by name.
    let err = gpu
        .r()
        .render_offscreen(&scene, 16, 16, &msaa(64))
        .unwrap_err();
    assert!(err.to_string().contains("GL_MAX_SAMPLES"), "{err}");
}

/// Along the turned square's edges: where the driver really multisamples, the coverage
/// fractions of 4 samples; where it only accepts the extension's calls and renders one sample
/// (llvmpipe under the override: its rasterizer keeps no samples for a texture), exactly the
/// single-sample picture. Either way the copy pass put every texel where it belongs, on a
/// square target and on a 1 536-pixel-wide one (a copy sampling half a texel off fails it).
#[test]
fn edges_resolve_to_sample_coverage_and_the_copy_is_exact_on_es2() {
    let scene = common::turned_square();
    let Some(mut gpu) = es2_with_the_extension() else {
        return;
    };
    let linear = |samples| RenderOptions {
        linear: true,
        ..msaa(samples)
    };
    for (w, h) in [(96, 96), (1536, 24)] {
        let plain = gpu.render(&scene, w, h, &linear(1));
        assert!(
            plain.pixels().all(|p| p[0] == 0 || p[0] == 255),
            "without MSAA every pixel is covered or not"
        );
        let smooth = gpu.render(&scene, w, h, &linear(4));
        let multisampled = smooth.pixels().any(|p| p[0] != 0 && p[0] != 255);
        if multisampled {
            if (w, h) == (96, 96) {
                common::assert_coverage_of_4_samples(&smooth);
            }
        } else {
            let d = manylight::metrics::diff(&plain, &smooth);
            assert_eq!(d.max_abs, 0, "{w}×{h}: the copy moved or changed texels");
        }
        // The square crosses the target: both colours are there.
        assert!(smooth.pixels().any(|p| p[0] == 255) && smooth.pixels().any(|p| p[0] == 0));
    }
}

/// Into part of a game's framebuffer (`RenderOptions::origin`): the copy pass puts the frame at
/// the origin, and every method through it equals forward through it there.
#[test]
fn msaa_at_an_origin_copies_the_frame_there_on_es2() {
    let Some(mut gpu) = es2_with_the_extension() else {
        return;
    };
    let scene = scene::builtin::build("courtyard", Some((64, 2))).unwrap();
    let size = (80, 45);
    let options = RenderOptions {
        origin: [13, 9],
        ..msaa(4)
    };
    let whole = (size.0 + 30, size.1 + 20);
    gpu.r().set_method_named("forward").unwrap();
    let corner = gpu.render(&scene, size.0, size.1, &msaa(4));
    let reference = render_at_origin(&mut gpu, &scene, &options, size, whole, "forward");
    // Edge pixels a rasterizer rounds the other way once moved (viewport_origin.rs).
    let d = manylight::metrics::diff(&corner, &reference);
    assert!(
        d.over_2 <= 0.01,
        "{:.1} % of pixels moved",
        d.over_2 * 100.0
    );
    for method in ["tiled", "clustered", "auto"] {
        gpu.r().set_method_named(method).unwrap();
        let img = render_at_origin(&mut gpu, &scene, &options, size, whole, method);
        let d = manylight::metrics::diff(&reference, &img);
        assert!(d.max_abs <= 2, "{method}: {}/255 from forward", d.max_abs);
    }
}
