//! The command line as a user runs it, including under real driver restrictions
//! (`MESA_GLES_VERSION_OVERRIDE`, `MESA_EXTENSION_OVERRIDE`) applied to child processes.

use crate::common;

use std::path::Path;
use std::process::Command;

use common::cli::{expect_exit, manylight, text};

pub(super) fn stats(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// True when the EGL driver is Mesa, whose `MESA_*` overrides the restriction tests use; on
/// another driver (NVIDIA's, or one chosen with `MANYLIGHT_GLES_LIB`) those tests are not
/// applicable.
fn mesa_driver() -> bool {
    !common::other_implementation_than_mesa("MESA_* driver restrictions")
}

#[test]
fn render_writes_png_and_stats_with_the_documented_fields() {
    let dir = tempfile::tempdir().unwrap();
    let out = manylight(
        &[
            "render", "--scene", "pillars", "--lights", "32", "--size", "96x64", "--out", "p.png",
            "--stats", "s.json", "--es", "2",
        ],
        &[],
        dir.path(),
    );
    assert!(out.status.success(), "{}", text(&out));
    let img = image::open(dir.path().join("p.png")).unwrap();
    assert_eq!((img.width(), img.height()), (96, 64));
    let s = stats(&dir.path().join("s.json"));
    for field in [
        "method",
        "es",
        "gl_version",
        "renderer",
        "width",
        "height",
        "lights",
        "frame_ms",
    ] {
        assert!(s.get(field).is_some(), "stats lack `{field}`: {s}");
    }
    assert_eq!(s["es"], "2.0");
    assert_eq!(s["lights"], 32);
    assert_eq!(s["method"], "clustered", "clustered is the default method");
    for field in [
        "assign_ms",
        "upload_bytes",
        "clusters",
        "nonempty_clusters",
        "avg_lights_per_nonempty",
        "max_lights_per_cluster",
        "overflowed_lights",
    ] {
        assert!(s.get(field).is_some(), "stats lack `{field}`: {s}");
    }
    assert!(s["clusters"].as_u64().unwrap() > 0 && s["upload_bytes"].as_u64().unwrap() > 0);
    assert!(s["frame_ms"].as_f64().unwrap() > 0.0);
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("p.png"),
        "one-line summary names the output"
    );
}

#[test]
fn no_arguments_renders_the_default_scene_to_manylight_png() {
    let dir = tempfile::tempdir().unwrap();
    let out = manylight(&[], &[], dir.path());
    assert!(out.status.success(), "{}", text(&out));
    let img = image::open(dir.path().join("manylight.png"))
        .unwrap()
        .to_rgba8();
    let lit = img
        .pixels()
        .filter(|p| p[0] as u32 + p[1] as u32 + p[2] as u32 > 60)
        .count();
    assert!(
        lit * 2 > img.pixels().len(),
        "default render is mostly dark ({lit} lit pixels)"
    );
    let line = String::from_utf8_lossy(&out.stdout);
    assert!(
        line.contains("courtyard") && line.contains("lights"),
        "{line}"
    );
}

#[test]
fn info_json_reports_versions_limits_and_precision() {
    let dir = tempfile::tempdir().unwrap();
    for es in ["2", "3"] {
        let out = manylight(&["info", "--es", es, "--json"], &[], dir.path());
        assert!(out.status.success(), "{}", text(&out));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let caps = &v["caps"];
        assert_eq!(caps["es"], format!("{es}.0"));
        for field in [
            "gl_version",
            "glsl_version",
            "renderer",
            "max_texture_size",
            "max_fragment_uniform_vectors",
            "max_draw_buffers",
            "max_color_attachments",
            "fragment_highp",
            "extensions",
        ] {
            assert!(caps.get(field).is_some(), "caps lack `{field}`");
        }
        assert!(caps["max_texture_size"].as_i64().unwrap() >= 64);
        assert!(v["methods"]
            .as_array()
            .unwrap()
            .iter()
            .any(|m| m["name"] == "forward"));
    }
}

/// ES 2.0 requested on a driver that returns 3.x: the renderer restricts itself to ES 2.0
/// (draw buffers as ES 2.0 core has them).
#[test]
fn es2_request_is_restricted_to_es2_even_on_an_es3_driver() {
    let dir = tempfile::tempdir().unwrap();
    let caps_with = |env: &[(&str, &str)]| {
        let out = manylight(&["info", "--es", "2", "--json"], env, dir.path());
        assert!(out.status.success(), "{}", text(&out));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let caps = v["caps"].clone();
        assert_eq!(caps["es"], "2.0", "{caps}");
        let has_draw_buffers_ext = caps["extensions"]
            .as_array()
            .unwrap()
            .iter()
            .any(|e| e == "GL_EXT_draw_buffers");
        let buffers = caps["max_draw_buffers"].as_i64().unwrap();
        (has_draw_buffers_ext, buffers)
    };
    // With GL_EXT_draw_buffers (Mesa, ANGLE and SwiftShader list it) the count is GL's.
    let (has, buffers) = caps_with(&[]);
    assert!(buffers >= 1 && (has || buffers == 1), "{has} {buffers}");
    // Without it, ES 2.0 core's one, whatever the ES 3 driver could do.
    if common::other_implementation_than_mesa("MESA_EXTENSION_OVERRIDE") {
        return;
    }
    let (has, buffers) = caps_with(&[("MESA_EXTENSION_OVERRIDE", "-GL_EXT_draw_buffers")]);
    assert!(!has, "the override left GL_EXT_draw_buffers");
    assert_eq!(buffers, 1, "ES 2.0 core has one draw buffer");
}

#[test]
fn capped_driver_says_clearly_that_es3_is_unavailable() {
    let dir = tempfile::tempdir().unwrap();
    if !mesa_driver() {
        return;
    }
    let env = [("MESA_GLES_VERSION_OVERRIDE", "2.0")];
    let out = manylight(
        &["render", "--es", "3", "--size", "32x32"],
        &env,
        dir.path(),
    );
    assert!(!out.status.success());
    let msg = text(&out);
    assert!(msg.contains("OpenGL ES 3.0 is not available"), "{msg}");
    assert!(!msg.contains("panicked"), "{msg}");
    // The switch is named, and EGL's reason reads as a sentence (its parenthesis closed).
    assert!(msg.contains("MESA_GLES_VERSION_OVERRIDE is set"), "{msg}");
    assert_eq!(msg.matches('(').count(), msg.matches(')').count(), "{msg}");
    // A sweep over both versions stops before its first row, not after the ES 2.0 ones.
    let sweep = [
        "bench",
        "--quick",
        "--es",
        "2,3",
        "--scenes",
        "plane",
        "--lights",
        "8",
        "--methods",
        "forward",
        "--size",
        "32x18",
        "--no-knobs",
        "--animated-frames",
        "0",
        "--out",
        "b",
    ];
    let msg = expect_exit(&sweep, &env, dir.path(), 3, "ES 3.0");
    assert!(!msg.contains("ES 2.0 plane"), "rows ran first: {msg}");
    // Removing an extension ES 3.0 needs lowers the version too: that switch is named.
    let removed = [("MESA_EXTENSION_OVERRIDE", "-GL_OES_texture_float")];
    let msg = expect_exit(&["info", "--es", "3"], &removed, dir.path(), 3, "ES 3.0");
    assert!(msg.contains("MESA_EXTENSION_OVERRIDE is set"), "{msg}");
    // ES 2.0 still works on the capped driver, and the context really is 2.0.
    let out = manylight(&["info", "--es", "2", "--json"], &env, dir.path());
    assert!(out.status.success(), "{}", text(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["caps"]["context_version"], "2.0");
    let out = manylight(
        &["render", "--es", "2", "--size", "64x36", "--lights", "16"],
        &env,
        dir.path(),
    );
    assert!(out.status.success(), "{}", text(&out));
}

/// ES 2.0 without `GL_OES_texture_npot` (Mali-400 has none) scales images to a power of two,
/// and says so in its capabilities; with it (as Mesa lists it) images keep their size
/// (`model_files/npot_textures.rs`).
#[test]
fn es2_lists_whether_images_keep_their_size() {
    let dir = tempfile::tempdir().unwrap();
    if !mesa_driver() {
        return;
    }
    for (env, npot) in [
        (&[][..], true),
        // An ES 2.0 context (an ES 3.x one has them whatever level the renderer keeps to)
        // without the extension.
        (
            &[
                ("MESA_GLES_VERSION_OVERRIDE", "2.0"),
                ("MESA_EXTENSION_OVERRIDE", "-GL_OES_texture_npot"),
            ][..],
            false,
        ),
    ] {
        let out = manylight(&["info", "--es", "2", "--json"], env, dir.path());
        assert!(out.status.success(), "{}", text(&out));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["caps"]["npot_textures"], npot, "{env:?}");
        // Mesa without the extension refuses render targets of other sizes too (probed).
        assert_eq!(v["caps"]["npot_targets"], npot, "{env:?}");
    }
}

/// Mesa's ES 2.0 without `GL_OES_texture_npot` refuses every texture of another size (ES 2.0
/// itself allows them clamped and unmipmapped): every frame of a size not a power of two failed
/// with `GL_INVALID_VALUE` allocating the renderer's own target. On such a context
/// (`Caps::npot_targets` false) its targets are allocated at powers of two, the frame in their
/// corner: the picture is the one with the extension, with every method, and through ES 2.0's
/// MSAA extension (whose copy reads the frame's part).
#[test]
fn es2_without_npot_textures_renders_frames_of_any_size() {
    let dir = tempfile::tempdir().unwrap();
    if !mesa_driver() {
        return;
    }
    let msaa_ext = "+GL_EXT_multisampled_render_to_texture";
    for method in ["forward", "tiled", "clustered"] {
        for msaa in [false, true] {
            let (mut pictures, mut msaa_bytes) = (Vec::new(), Vec::new());
            for npot in ["", "-GL_OES_texture_npot"] {
                let extensions = if msaa {
                    format!("{npot} {msaa_ext}")
                } else {
                    npot.to_string()
                };
                let env = [
                    ("MESA_GLES_VERSION_OVERRIDE", "2.0"),
                    ("MESA_EXTENSION_OVERRIDE", extensions.trim()),
                ];
                let out_file = format!("{method}{msaa}{}.png", npot.len());
                let mut args = vec![
                    "render", "--es", "2", "--method", method, "--lights", "32", "--size", "60x36",
                    "--out", &out_file, "--stats", "s.json",
                ];
                if msaa {
                    args.extend(["--msaa", "4"]);
                }
                let out = manylight(&args, &env, dir.path());
                if msaa && text(&out).contains("GL_MAX_SAMPLES (1)") {
                    // A driver without MSAA (softpipe) has no samples to give, extension or not.
                    eprintln!("{method}: no MSAA on this driver");
                    break;
                }
                assert!(out.status.success(), "{env:?} {args:?}: {}", text(&out));
                pictures.push(image::open(dir.path().join(&out_file)).unwrap().to_rgba8());
                msaa_bytes.push(
                    stats(&dir.path().join("s.json"))["msaa_bytes"]
                        .as_f64()
                        .unwrap(),
                );
            }
            if pictures.is_empty() {
                continue;
            }
            assert!(
                pictures[0] == pictures[1],
                "{method}, MSAA {msaa}: another picture without GL_OES_texture_npot"
            );
            // The MSAA target's memory is its 64 × 64 storage's.
            if msaa {
                let ratio = msaa_bytes[1] / msaa_bytes[0];
                assert_eq!(ratio, 64.0 * 64.0 / (60.0 * 36.0), "{msaa_bytes:?}");
            }
        }
    }
}

#[test]
fn without_float_textures_es2_falls_back_to_rgba8_lights_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    if !mesa_driver() {
        return;
    }
    let env = [("MESA_EXTENSION_OVERRIDE", "-GL_OES_texture_float")];
    let out = manylight(
        &[
            "render", "--es", "2", "--size", "64x36", "--lights", "16", "--stats", "s.json",
        ],
        &env,
        dir.path(),
    );
    assert!(out.status.success(), "{}", text(&out));
    assert!(
        text(&out).contains("GL_OES_texture_float"),
        "the fallback is announced: {}",
        text(&out)
    );
    let s = stats(&dir.path().join("s.json"));
    assert_eq!(s["light_encoding"], "rgba8");
    assert_eq!(s["support"]["status"], "fallback");
}

/// A played device without fragment highp starts with forward (the default method needs
/// highp), says so, and renders a lit image.
#[test]
fn without_fragment_highp_es2_renders_with_forward_and_says_why() {
    let dir = tempfile::tempdir().unwrap();
    let out = manylight(
        &[
            "render",
            "--es",
            "2",
            "--no-fragment-highp",
            "--size",
            "64x36",
            "--lights",
            "64",
            "--stats",
            "s.json",
        ],
        &[],
        dir.path(),
    );
    assert!(out.status.success(), "{}", text(&out));
    assert!(text(&out).contains("no highp"), "{}", text(&out));
    let s = stats(&dir.path().join("s.json"));
    assert_eq!(s["method"], "forward");
    assert_eq!(s["support"]["status"], "fallback");
    // The stats say forward stands in for the default, not only the warning does.
    let reason = s["support"]["reason"].as_str().unwrap();
    assert!(
        reason.starts_with("the default method `clustered` is unsupported here (")
            && reason.contains("mediump"),
        "{reason}"
    );
    let img = image::open(dir.path().join("manylight.png"))
        .unwrap()
        .to_rgba8();
    assert!(img.pixels().any(|p| p[0] > 40), "a lit image");
}

#[test]
fn bad_requests_are_clear_errors_not_panics() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("bad.json"),
        r#"{"objects": [{"builtin": "plane"}],
            "lights": [{"kind": "point", "position": [0, 0, 1], "radius": -2, "color": [1, 1, 1]}]}"#,
    )
    .unwrap();
    std::fs::write(
        dir.path().join("typo.json"),
        r#"{"objects": [{"builtin": "plane"}], "ambiant": [0, 0, 0]}"#,
    )
    .unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["render", "--scene", "bad.json"], "lights[0].radius"),
        (&["render", "--scene", "typo.json"], "ambiant"),
        (&["render", "--scene", "nowhere.obj"], "nowhere.obj"),
        (&["render", "--scene", "atlantis"], "unknown built-in scene"),
        (
            &["render", "--method", "raytraced", "--size", "8x8"],
            "unknown method `raytraced`",
        ),
        (
            &[
                "render",
                "--es",
                "2",
                "--no-fragment-highp",
                "--method",
                "clustered",
                "--size",
                "8x8",
            ],
            "no highp",
        ),
    ];
    for (args, needle) in cases {
        // A method this context cannot run is status 3; bad input 1.
        let code = if needle.contains("no highp") { 3 } else { 1 };
        expect_exit(args, &[], dir.path(), code, needle);
    }
}

#[test]
fn usage_errors_exit_2_and_name_the_flags() {
    let dir = tempfile::tempdir().unwrap();
    let cases: &[(&[&str], &str)] = &[
        // The flag combination is the fault, not the driver.
        (
            &["render", "--no-fragment-highp", "--size", "8x8"],
            "--es 2",
        ),
        (&["info", "--no-fragment-highp", "--es", "3"], "--es 2"),
        (
            &["render", "--no-float-textures", "--size", "8x8"],
            "--no-float-textures plays an OpenGL ES 2.0 device",
        ),
        (
            &["info", "--no-float-textures", "--es", "3"],
            "--no-float-textures plays",
        ),
        (&["render", "--frames", "many"], "--frames"),
        (&["render", "--size", "0x10"], "empty"),
        (&["render", "--bogus"], "--bogus"),
        (
            &["render", "--gles-lib", "a", "--gles-lib", "b"],
            "only `matrix` compares several",
        ),
        // A negative count is a bad value of its option, not a stray argument `-1`.
        (
            &["render", "--lights", "-1"],
            "invalid value '-1' for '--lights",
        ),
        (&["matrix", "--max-error", "-1"], "for '--max-error"),
        // Not a negative number either, but the value of the option it follows.
        (
            &["render", "--lights", "-inf"],
            "invalid value '-inf' for '--lights",
        ),
        (&["bench-assign", "--runs", "-nan"], "for '--runs"),
        // Nor a size or a list: each is its option's value, refused as one.
        (
            &["render", "--size", "-64x36"],
            "invalid value '-64x36' for '--size",
        ),
        (
            &["bench", "--lights", "-1,2"],
            "invalid value '-1' for '--lights",
        ),
        (&["bench-assign", "--runs", "-2"], "for '--runs"),
    ];
    for (args, needle) in cases {
        let msg = expect_exit(args, &[], dir.path(), 2, needle);
        // A usage line under the message is the subcommand's, as clap's own errors show it.
        assert!(
            !msg.contains("Usage: manylight [OPTIONS]"),
            "{args:?}: {msg}"
        );
        if args[..2] == ["info", "--no-fragment-highp"] {
            assert!(msg.contains("Usage: manylight info [OPTIONS]"), "{msg}");
        }
    }
}

/// A GLES folder that is missing or holds no libraries is one error naming the folder and what
/// it lacks, from the option and from the variable alike.
#[test]
fn a_bad_gles_folder_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nowhere");
    let missing = missing.to_str().unwrap();
    let msg = expect_exit(
        &["info", "--gles-lib", missing],
        &[],
        dir.path(),
        1,
        "nowhere",
    );
    assert!(msg.contains("is not a folder"), "{msg}");
    // The chosen folder is at fault, not a missing system libEGL.
    assert!(!msg.contains("install libegl1"), "{msg}");
    let empty = dir.path().to_str().unwrap();
    let msg = expect_exit(
        &["render", "--size", "8x8"],
        &[("MANYLIGHT_GLES_LIB", empty)],
        dir.path(),
        1,
        "holds none of libGLESv2.so.2, libGLESv2.so",
    );
    assert!(msg.contains(empty), "{msg}");
}

#[cfg(not(feature = "window"))]
#[test]
fn view_in_a_build_without_the_window_feature_says_how_to_get_it() {
    let dir = tempfile::tempdir().unwrap();
    expect_exit(&["view"], &[], dir.path(), 2, "--features window");
}

/// A device without fragment highp runs the default command at its default light count:
/// forward keeps the 1 023 lights its loop can hold, warns once, counts the rest; asking for a
/// method it cannot run is one error that lists the methods it can, with no warning first
/// about a default nobody asked for.
#[test]
fn without_fragment_highp_the_default_light_count_renders_and_errors_suggest_what_runs() {
    let dir = tempfile::tempdir().unwrap();
    let base = [
        "render",
        "--es",
        "2",
        "--no-fragment-highp",
        "--size",
        "32x18",
    ];
    let out = manylight(
        &[&base[..], &["--frames", "0", "--stats", "s.json"]].concat(),
        &[],
        dir.path(),
    );
    let msg = text(&out);
    assert!(out.status.success(), "{msg}");
    assert_eq!(msg.matches("at most 1023 lights").count(), 1, "{msg}");
    let s = stats(&dir.path().join("s.json"));
    assert_eq!(s["lights"], 1024);
    assert_eq!(s["overflowed_lights"], 1);
    let msg = expect_exit(
        &[&base[..], &["--method", "tiled"]].concat(),
        &[],
        dir.path(),
        3,
        "methods that run here: forward, auto",
    );
    assert!(!msg.contains("WARN"), "a warning before the error: {msg}");
}

/// ES 2.0 with float textures removed from the driver: clustered still renders, within the
/// measured error of the RGBA8 light packing against a float-texture forward reference.
#[test]
fn clustered_without_float_textures_stays_within_the_packing_error() {
    let dir = tempfile::tempdir().unwrap();
    if !mesa_driver() {
        return;
    }
    let common = [
        "--es", "2", "--size", "128x72", "--lights", "128", "--linear", "--frames", "0",
    ];
    for scene in ["courtyard", "plane"] {
        let reference = manylight(
            &[
                &[
                    "render", "--scene", scene, "--method", "forward", "--out", "ref.png",
                ][..],
                &common,
            ]
            .concat(),
            &[],
            dir.path(),
        );
        assert!(reference.status.success(), "{}", text(&reference));
        let env = [("MESA_EXTENSION_OVERRIDE", "-GL_OES_texture_float")];
        let packed = manylight(
            &[
                &[
                    "render",
                    "--scene",
                    scene,
                    "--method",
                    "clustered",
                    "--out",
                    "rgba8.png",
                    "--stats",
                    "s.json",
                ][..],
                &common,
            ]
            .concat(),
            &env,
            dir.path(),
        );
        assert!(packed.status.success(), "{}", text(&packed));
        assert_eq!(stats(&dir.path().join("s.json"))["light_encoding"], "rgba8");
        let a = image::open(dir.path().join("ref.png")).unwrap().to_rgba8();
        let b = image::open(dir.path().join("rgba8.png"))
            .unwrap()
            .to_rgba8();
        let d = manylight::metrics::diff(&a, &b);
        eprintln!(
            "{scene}: RGBA8 lights vs float forward: max {} rmse {:.3}",
            d.max_abs, d.rmse
        );
        assert!(
            d.max_abs <= 3,
            "{scene}: packing error {} exceeds the measured bound 3/255",
            d.max_abs
        );
    }
}

/// A Mali-400-class device: no fragment highp and no float textures, so forward reads its
/// lights as 16-bit RGBA8 pairs in fp16. The decoder's constant 256 / 65 535, folded in fp16,
/// was 0: every light sat at the origin with radius 0 and the frame was ambient only (228/255
/// off). It now draws what the same tier draws from float light data, within fp16's error:
/// positions are decoded about the range's centre, so a small coordinate keeps its low byte.
#[test]
fn without_fragment_highp_or_float_textures_forward_still_draws_its_lights() {
    let dir = tempfile::tempdir().unwrap();
    if !mesa_driver() {
        return;
    }
    let args = |out: &'static str| {
        [
            "render",
            "--es",
            "2",
            "--no-fragment-highp",
            "--method",
            "forward",
            "--size",
            "64x36",
            "--lights",
            "300",
            "--frames",
            "0",
            "--linear",
            "--out",
            out,
            "--stats",
            "s.json",
        ]
    };
    let float = manylight(&args("float.png"), &[], dir.path());
    assert!(float.status.success(), "{}", text(&float));
    let env = [("MESA_EXTENSION_OVERRIDE", "-GL_OES_texture_float")];
    let packed = manylight(&args("rgba8.png"), &env, dir.path());
    assert!(packed.status.success(), "{}", text(&packed));
    assert_eq!(stats(&dir.path().join("s.json"))["light_encoding"], "rgba8");
    let a = image::open(dir.path().join("float.png"))
        .unwrap()
        .to_rgba8();
    let b = image::open(dir.path().join("rgba8.png"))
        .unwrap()
        .to_rgba8();
    let d = manylight::metrics::diff(&a, &b);
    eprintln!(
        "RGBA8 lights vs float, no highp: max {} rmse {:.3}",
        d.max_abs, d.rmse
    );
    // Both frames carry fp16's position error (docs/precision.md: up to 21/255 near a light;
    // 9/255, RMSE 0.38 measured here).
    assert!(
        d.max_abs <= 21 && d.rmse < 1.0,
        "{} / 255 (RMSE {:.2}) from the float lights' frame",
        d.max_abs,
        d.rmse
    );
}

#[test]
fn bench_assign_prints_json_for_scripts() {
    let dir = tempfile::tempdir().unwrap();
    // `bench-assign --json` at `lights` on a rayon pool of `pool` threads, whatever the host
    // and the caller's environment say: its rows.
    let rows_on = |lights: &str, pool: &str| -> Vec<serde_json::Value> {
        let args = ["bench-assign", "--lights", lights, "--runs", "3", "--json"];
        let out = manylight(&args, &[("RAYON_NUM_THREADS", pool)], dir.path());
        assert!(out.status.success(), "{}", text(&out));
        let rows: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        rows.as_array().unwrap().clone()
    };
    let rows = rows_on("16,256", "2");
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0]["lights"], 16);
    assert_eq!(rows[1]["lights"], 256);
    for r in &rows {
        assert!(r["assign_ms"].as_f64().unwrap() > 0.0);
        assert!(r["indices"].as_u64().unwrap() > 0);
        // An assignment takes no more threads than its pool has.
        let threads = r["threads"].as_u64().unwrap();
        assert!((1..=2).contains(&threads), "{r}");
    }
    // A pool of one: every row says one thread.
    for r in rows_on("16,65536", "1") {
        assert_eq!(r["threads"], 1, "{r}");
    }
}

/// `bench-assign --threads 1,2` times each count on a pool of one thread and on one of two,
/// taking turns: a row per pool, each on no more threads than its pool has, with the same
/// lists; a pool of no threads, or a ninth pool, is refused.
#[test]
fn bench_assign_times_pools_side_by_side() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "bench-assign",
        "--lights",
        "16,256",
        "--runs",
        "3",
        "--threads",
        "1,2",
        "--json",
    ];
    // The global pool's size must not matter: the rows say their own pools.
    let out = manylight(&args, &[("RAYON_NUM_THREADS", "1")], dir.path());
    assert!(out.status.success(), "{}", text(&out));
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = rows.as_array().unwrap();
    let got: Vec<_> = rows
        .iter()
        .map(|r| (r["lights"].as_u64(), r["pool"].as_u64()))
        .collect();
    let expected = [(16, 1), (16, 2), (256, 1), (256, 2)].map(|(l, p)| (Some(l), Some(p)));
    assert_eq!(got, expected);
    for pair in rows.chunks(2) {
        assert_eq!(pair[0]["threads"], 1, "{}", pair[0]);
        let threads = pair[1]["threads"].as_u64().unwrap();
        assert!((1..=2).contains(&threads), "{}", pair[1]);
        assert_eq!(pair[0]["indices"], pair[1]["indices"]);
        assert!(pair[0]["indices"].as_u64().unwrap() > 0);
    }
    let text_out = manylight(
        &[
            "bench-assign",
            "--lights",
            "64",
            "--runs",
            "2",
            "--threads",
            "1,2",
        ],
        &[],
        dir.path(),
    );
    assert!(text_out.status.success(), "{}", text(&text_out));
    assert!(
        text(&text_out).contains("x the pool of 1"),
        "{}",
        text(&text_out)
    );
    // No pool of no threads, and not more pools than the command keeps at once.
    let nine = ["1"; 9].join(",");
    for threads in ["0", nine.as_str()] {
        let args = ["bench-assign", "--threads", threads];
        let said = expect_exit(&args, &[], dir.path(), 2, "--threads");
        // A usage line, where there is one, is the subcommand's (the nine pools' has one).
        assert!(!said.contains("Usage: manylight ["), "{said}");
        if threads == nine {
            assert!(said.contains("Usage: manylight bench-assign"), "{said}");
        }
    }
}

/// A list option of `bench` or `bench-assign` takes at most 64 values (each a run of its own),
/// over all its uses: more is a usage error naming the option, before any work.
#[test]
fn bench_lists_past_64_values_are_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let many = |value: &str| vec![value; 65].join(",");
    let cases: [(&str, &str, String); 5] = [
        ("bench-assign", "--lights", many("1")),
        ("bench", "--lights", many("1")),
        ("bench", "--scenes", many("plane")),
        ("bench", "--methods", many("forward")),
        ("bench", "--es", many("3")),
    ];
    for (subcommand, option, list) in cases {
        let args = [subcommand, option, list.as_str(), "--out", "r"];
        let args = if subcommand == "bench" {
            &args[..]
        } else {
            &args[..3]
        };
        let said = expect_exit(args, &[], dir.path(), 2, option);
        assert!(said.contains("lists 65 values; at most 64"), "{said}");
        assert!(
            said.contains(&format!("Usage: manylight {subcommand}")),
            "{said}"
        );
    }
    // The uses of an option add up.
    let sixty_four = vec!["1"; 64].join(",");
    let split = ["bench-assign", "--lights", &sixty_four, "--lights", "1,1"];
    let said = expect_exit(&split, &[], dir.path(), 2, "--lights");
    assert!(said.contains("lists 66 values"), "{said}");
    // 64 values pass the check: the sweep goes on to load its scene.
    let args = ["bench", "--lights", &sixty_four, "--scenes", "missing.obj"];
    let said = expect_exit(&args, &[], dir.path(), 1, "missing.obj");
    assert!(!said.contains("at most 64"), "{said}");
    assert!(
        !dir.path().join("r").exists(),
        "a refused bench wrote its report"
    );
}

/// The command line's thread (which renders, and so assigns the lights) is one of rayon's pool,
/// so a parallel assignment starts on it at once; the pool still has the threads asked for.
#[test]
fn the_command_lines_thread_is_one_of_the_assignment_pool() {
    let dir = tempfile::tempdir().unwrap();
    for (pool, taken) in [(1, 1), (3, 3), (12, 8)] {
        let threads = pool.to_string();
        let env = [("RAYON_NUM_THREADS", threads.as_str())];
        let out = manylight(&["info", "--json"], &env, dir.path());
        assert!(out.status.success(), "{}", text(&out));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["assign_pool"]["threads"], pool, "{}", v["assign_pool"]);
        // One assignment takes at most 8 of them (MAX_ASSIGN_THREADS), and `info` says so.
        let most = &v["assign_pool"]["most_an_assignment_takes"];
        assert_eq!(*most, taken, "{}", v["assign_pool"]);
        let out = manylight(&["info"], &env, dir.path());
        let said = format!("up to {taken} CPU threads (of rayon's pool of {pool},");
        assert!(text(&out).contains(&said), "{}", text(&out));
        assert_eq!(
            v["assign_pool"]["caller_in_pool"], true,
            "{}",
            v["assign_pool"]
        );
    }
    // rayon's older variable, read where the first is no count, within the same cap: rayon
    // itself read it unchecked, and 3 000 started 3 000 threads.
    let env = [("RAYON_NUM_THREADS", ""), ("RAYON_RS_NUM_CPUS", "3000")];
    let out = manylight(&["info", "--json"], &env, dir.path());
    assert!(out.status.success(), "{}", text(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["assign_pool"]["threads"], 256, "{}", v["assign_pool"]);
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(
        said.contains("RAYON_RS_NUM_CPUS=3000 taken as 256"),
        "{said}"
    );
}

#[test]
fn a_missing_texture_is_warned_once() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("m.mtl"),
        "newmtl red\nKd 0.9 0.1 0.1\nmap_Kd nothere.png\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("t.obj"),
        "mtllib m.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl red\nf 1/1 2/2 3/3\n",
    )
    .unwrap();
    let out = manylight(
        &[
            "render", "--scene", "t.obj", "--size", "16x9", "--lights", "2",
        ],
        &[],
        dir.path(),
    );
    let msg = text(&out);
    assert!(out.status.success(), "{msg}");
    assert_eq!(msg.matches("nothere.png").count(), 1, "{msg}");
}

/// `--seed` where the scene keeps its own lights changes nothing: it says so, rather than
/// rendering the file's own lights as if the seed had been taken.
#[test]
fn a_seed_the_scene_does_not_use_is_warned() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("s.json"),
        r#"{"objects": [{"builtin": "plane"}], "random_lights": {"count": 4, "seed": 3}}"#,
    )
    .unwrap();
    let run = |args: &[&str]| {
        let mut all = vec!["render", "--size", "16x9", "--frames", "0"];
        all.extend_from_slice(args);
        let out = manylight(&all, &[], dir.path());
        let msg = text(&out);
        assert!(out.status.success(), "{args:?}: {msg}");
        msg
    };
    let unused = run(&["--scene", "s.json", "--seed", "7"]);
    assert!(unused.contains("--seed 7 is not used"), "{unused}");
    // Taken with --lights, and by a built-in: no warning, nor without --seed.
    for args in [
        &["--scene", "s.json", "--seed", "7", "--lights", "4"][..],
        &["--scene", "plane", "--seed", "7", "--lights", "4"],
        &["--scene", "s.json"],
    ] {
        let msg = run(args);
        assert!(!msg.contains("--seed"), "{args:?}: {msg}");
    }
}

/// Hostile files and counts end in one clear error or a documented fallback: no panic, no
/// hang on a FIFO, no endless read of `/dev/zero`, no allocation for 2⁶⁴ lights.
#[test]
fn hostile_files_and_counts_are_refused_quickly_and_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, text: &str| std::fs::write(dir.path().join(name), text).unwrap();
    let triangle = "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nusemtl m\nf 1 2 3\n";
    write("zero.obj", &format!("mtllib /dev/zero\n{triangle}"));
    write("short.mtl", "newmtl m\nKd 1\n");
    write("short.obj", &format!("mtllib short.mtl\n{triangle}"));
    write(
        "many.json",
        r#"{"objects": [{"builtin": "plane"}], "random_lights": {"count": 18446744073709551615, "seed": 1}}"#,
    );
    write("plain.obj", triangle);
    let fifo = dir.path().join("fifo.obj");
    let made = Command::new("mkfifo").arg(&fifo).status();
    let small = ["--size", "16x9"];
    // (arguments, environment, text the output must contain, exit status)
    type Case<'a> = (Vec<&'a str>, &'a [(&'a str, &'a str)], &'a str, i32);
    let mut cases: Vec<Case> = vec![
        // A material library outside the model's folder: refused with a warning naming it.
        (
            vec!["render", "--scene", "zero.obj", "--lights", "2"],
            &[],
            "`/dev/zero` is outside the model's folder",
            0,
        ),
        // Allowed, it never ends: a warning, the flat default, a rendered frame.
        (
            vec![
                "render",
                "--scene",
                "zero.obj",
                "--lights",
                "2",
                "--allow-outside-files",
            ],
            &[],
            "/dev/zero",
            0,
        ),
        // A truncated colour line (tobj would panic): a warning naming the line.
        (
            vec!["render", "--scene", "short.obj", "--lights", "2"],
            &[],
            "line 2",
            0,
        ),
        (
            vec!["render", "--scene", "many.json"],
            &[],
            "random_lights.count",
            1,
        ),
        // A count past the scene's limit is a bad value of the option (exit 2), on every path,
        // near 2⁶⁴ and past it alike.
        (
            vec!["render", "--lights", "4294967296"],
            &[],
            "not a light count from 0 to 4194304",
            2,
        ),
        (
            vec!["render", "--lights", "18446744073709551615"],
            &[],
            "not a light count",
            2,
        ),
        (
            vec!["render", "--lights", "18446744073709551616"],
            &[],
            "not a light count",
            2,
        ),
        (
            vec!["matrix", "--lights", "4194305"],
            &[],
            "not a light count",
            2,
        ),
        (
            vec!["render", "--scene", "plain.obj", "--lights", "2"],
            &[("MANYLIGHT_MAX_FILE_MB", "0")],
            "MANYLIGHT_MAX_FILE_MB",
            1,
        ),
        // Not a number: warned of, the default limits kept (the file loads).
        (
            vec!["render", "--scene", "plain.obj", "--lights", "2"],
            &[("MANYLIGHT_MAX_FILE_MB", "abc")],
            "MANYLIGHT_MAX_FILE_MB is not a whole number",
            0,
        ),
    ];
    if made.is_ok_and(|s| s.success()) {
        cases.push((
            vec!["render", "--scene", "fifo.obj"],
            &[],
            "not a regular file",
            1,
        ));
    }
    for (args, env, needle, code) in cases {
        let args = [&args[..], &small[..]].concat();
        expect_exit(&args, env, dir.path(), code, needle);
    }
}

/// Errors found before or during a bench name what is at fault and print nothing else: no
/// "GL … leaked" warnings from the error path. A scene that does not load is found before the
/// first row (the scenes before it are not measured first: their pictures would be written).
#[test]
fn bench_errors_name_the_fault_without_leak_warnings() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("file"), b"").unwrap();
    let cases: &[(&[&str], &str, i32)] = &[
        (
            &["bench", "--quick", "--methods", "raytraced"],
            "unknown method `raytraced`",
            1,
        ),
        (&["bench", "--quick", "--out", "file/sub"], "file/sub", 1),
        (
            &[
                "bench",
                "--quick",
                "--no-knobs",
                "--es",
                "3",
                "--scenes",
                "plane,nowhere.obj",
                "--out",
                "scenes",
            ],
            "nowhere.obj",
            1,
        ),
        // During the sweep: the renderer exists when its first target is refused, which this
        // context cannot do (status 3).
        (
            &[
                "bench",
                "--quick",
                "--no-knobs",
                "--es",
                "3",
                "--lights",
                "0",
                "--size",
                "65536x16",
                "--out",
                "size",
            ],
            "--size 65536x16",
            3,
        ),
    ];
    for &(args, needle, status) in cases {
        let msg = expect_exit(args, &[], dir.path(), status, needle);
        assert!(!msg.contains("leaked"), "{args:?}: {msg}");
    }
    let written: Vec<_> = std::fs::read_dir(dir.path().join("scenes"))
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert!(
        written.is_empty(),
        "a bench whose second scene does not load measured the first: {written:?}"
    );
}

#[test]
fn tone_map_flags_render_and_bad_values_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let base = ["render", "--size", "16x9", "--lights", "8", "--frames", "0"];
    let out = manylight(
        &[&base[..], &["--tonemap", "neutral", "--exposure", "-1.5"]].concat(),
        &[],
        dir.path(),
    );
    assert!(out.status.success(), "{}", text(&out));
    let args = [&base[..], &["--tonemap", "filmic"]].concat();
    expect_exit(&args, &[], dir.path(), 2, "filmic");
    // A usage error naming the flag typed, not the library's field.
    for ev in ["40", "-15.5", "NaN"] {
        let args = [&base[..], &["--exposure", ev]].concat();
        expect_exit(&args, &[], dir.path(), 2, "--exposure");
    }
}

#[test]
fn msaa_flag_renders_and_says_where_it_cannot() {
    let dir = tempfile::tempdir().unwrap();
    let base = ["render", "--size", "16x9", "--lights", "8", "--frames", "0"];
    let out = manylight(
        &[&base[..], &["--msaa", "4", "--stats", "s.json"]].concat(),
        &[],
        dir.path(),
    );
    assert!(out.status.success(), "{}", text(&out));
    assert_eq!(stats(&dir.path().join("s.json"))["samples"], 4);
    let args = [&base[..], &["--msaa", "4", "--method", "deferred"]].concat();
    expect_exit(&args, &[], dir.path(), 3, "deferred");
    // Not a power of two (the counts implementations have): refused by name.
    for bad in ["0", "3", "4x"] {
        let args = [&base[..], &["--msaa", bad]].concat();
        expect_exit(&args, &[], dir.path(), 2, "not a sample count");
    }
}

#[test]
fn slice_depth_flag_makes_thinner_slices_and_refuses_bad_ratios() {
    let dir = tempfile::tempdir().unwrap();
    let base = [
        "render", "--size", "160x90", "--lights", "8", "--frames", "0",
    ];
    let cells = |extra: &[&str]| {
        let args = [&base[..], &["--grid", "8", "--stats", "s.json"], extra].concat();
        let out = manylight(&args, &[], dir.path());
        assert!(out.status.success(), "{}", text(&out));
        stats(&dir.path().join("s.json"))["grid_cells"]
            .as_f64()
            .unwrap()
    };
    let (cubical, thin) = (cells(&[]), cells(&["--slice-depth", "0.5"]));
    assert!(
        (1.4..2.4).contains(&(thin / cubical)),
        "{thin} cells against {cubical}"
    );
    for bad in ["0", "nan", "-0.5", "100"] {
        let args = [&base[..], &["--slice-depth", bad]].concat();
        expect_exit(&args, &[], dir.path(), 2, "slice depth");
    }
}

/// `--assign-budget` reaches the automatic grid (its reason states the budget; what the budget
/// does to the choice is tested in `cluster::auto_grid`); bad shares are refused.
#[test]
fn assign_budget_flag_bounds_the_automatic_grid() {
    let dir = tempfile::tempdir().unwrap();
    let base = [
        "render", "--size", "160x90", "--lights", "64", "--frames", "0",
    ];
    let reason = |budget: &str| {
        let args = [&base[..], &["--assign-budget", budget, "--stats", "s.json"]].concat();
        let out = manylight(&args, &[], dir.path());
        assert!(out.status.success(), "{}", text(&out));
        stats(&dir.path().join("s.json"))["grid_reason"]
            .as_str()
            .unwrap()
            .to_string()
    };
    for (budget, said) in [("0.05", "(budget 5.0 %)"), ("1", "(budget 100.0 %)")] {
        let why = reason(budget);
        assert!(why.starts_with("auto") && why.contains(said), "{why}");
    }
    for bad in ["-0.1", "nan", "1.5", "x"] {
        let args = [&base[..], &["--assign-budget", bad]].concat();
        expect_exit(&args, &[], dir.path(), 2, "share of the frame");
    }
}

/// Frame, light and run counts past what a run can hold are usage errors, not a process that
/// grows until it is killed or panics.
#[test]
fn counts_near_two_to_the_32_or_64_are_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &["render", "--frames", "4294967295"][..],
        &["render", "--frames", "65537"],
        &["bench", "--frames", "4294967295"],
        &["bench", "--animated-frames", "65537"],
    ] {
        expect_exit(args, &[], dir.path(), 2, "..=65536");
    }
    // bench-assign built a scene of 2⁶⁴ lights (a panic) and collected 2⁶⁴ run times (a
    // capacity overflow panic).
    let huge = "18446744073709551615";
    expect_exit(
        &["bench-assign", "--lights", huge],
        &[],
        dir.path(),
        2,
        "not a light count",
    );
    for runs in [huge, "0"] {
        expect_exit(
            &["bench-assign", "--lights", "8", "--runs", runs],
            &[],
            dir.path(),
            2,
            "not a number of runs",
        );
    }
}

#[test]
fn record_writes_the_sequence_and_a_frame_alone_matches_it() {
    let dir = tempfile::tempdir().unwrap();
    let base = ["render", "--size", "64x36", "--lights", "48", "--fps", "2"];
    let out = manylight(
        &[
            &base[..],
            &[
                "--frames",
                "5",
                "--record",
                "seq",
                "--stats",
                "s.json",
                "--out",
                "first.png",
            ],
        ]
        .concat(),
        &[],
        dir.path(),
    );
    let msg = text(&out);
    assert!(out.status.success(), "{msg}");
    assert!(msg.contains("moving lights"), "{msg}");
    let frame = |k: u32| {
        image::open(dir.path().join(format!("seq/frame_{k:05}.png")))
            .unwrap()
            .to_rgba8()
    };
    assert!(!dir.path().join("seq/frame_00005.png").exists());
    let s = stats(&dir.path().join("s.json"));
    for key in ["frame_ms_spread", "assign_ms_spread", "upload_bytes_spread"] {
        assert_eq!(s[key]["frames"], 5, "{key}: {}", s[key]);
    }
    // Frame 3 of the sequence (t = 1.5 s at 2 fps) rendered alone with --time.
    let out = manylight(
        &[
            &base[..],
            &["--frames", "0", "--time", "1.5", "--out", "alone.png"],
        ]
        .concat(),
        &[],
        dir.path(),
    );
    assert!(out.status.success(), "{}", text(&out));
    let alone = image::open(dir.path().join("alone.png"))
        .unwrap()
        .to_rgba8();
    assert!(
        alone == frame(3),
        "--time 1.5 differs from frame 3 of the sequence"
    );
    assert!(
        alone != frame(0),
        "the lights did not move between t = 0 and 1.5 s"
    );
    // --out is the first frame of the sequence.
    let first = image::open(dir.path().join("first.png"))
        .unwrap()
        .to_rgba8();
    assert!(first == frame(0));
}

#[test]
fn record_to_a_gif_writes_every_frame() {
    use image::AnimationDecoder;
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "render", "--size", "32x18", "--lights", "16", "--frames", "4", "--record", "a.gif",
    ];
    let out = manylight(&args, &[], dir.path());
    assert!(out.status.success(), "{}", text(&out));
    let file = std::io::BufReader::new(std::fs::File::open(dir.path().join("a.gif")).unwrap());
    let frames = image::codecs::gif::GifDecoder::new(file)
        .unwrap()
        .into_frames()
        .collect_frames()
        .unwrap();
    assert_eq!(frames.len(), 4);
    assert_eq!(frames[0].buffer().dimensions(), (32, 18));
}

#[test]
fn bad_animation_flags_are_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    for (flag, value) in [("--fps", "0"), ("--fps", "nan"), ("--time", "inf")] {
        expect_exit(&["render", flag, value], &[], dir.path(), 2, flag);
    }
    // A file where the recording directory should go.
    std::fs::write(dir.path().join("taken"), b"x").unwrap();
    let args = [
        "render", "--size", "8x8", "--frames", "1", "--record", "taken",
    ];
    let msg = expect_exit(&args, &[], dir.path(), 1, "--record");
    assert!(msg.contains("not a folder"), "{msg}");
    // A device there too (it said "cannot create /dev/null: File exists").
    let args = [
        "render",
        "--size",
        "8x8",
        "--frames",
        "1",
        "--record",
        "/dev/null",
    ];
    let msg = expect_exit(&args, &[], dir.path(), 1, "--record");
    assert!(msg.contains("not a folder"), "{msg}");
    // `-` is standard output for --out and --stats; a recording cannot go there (it made a
    // folder named `-`).
    let args = ["render", "--size", "8x8", "--frames", "1", "--record", "-"];
    let msg = expect_exit(&args, &[], dir.path(), 2, "--record -");
    assert!(msg.contains("standard output"), "{msg}");
    assert!(!dir.path().join("-").exists());
}

#[test]
fn info_scene_reports_the_scenes_own_features_and_variants() {
    let dir = tempfile::tempdir().unwrap();
    let scene = r#"{"objects": [{"builtin": "plane"}],
        "directional_lights": [{"direction": [0, 0, -1], "color": [1, 1, 1]}]}"#;
    std::fs::write(dir.path().join("sun.json"), scene).unwrap();
    let out = manylight(&["info", "--json", "--scene", "sun.json"], &[], dir.path());
    assert!(out.status.success(), "{}", text(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let f = &v["scene"]["features"];
    // A sun and no point or spot light: no light-list code, no cone code.
    assert_eq!(f["directional_lights"], true, "{f}");
    assert_eq!(f["point_lights"], false, "{f}");
    assert_eq!(f["spot_lights"], false, "{f}");
    for variant in v["scene"]["variants"].as_array().unwrap() {
        let names = variant["features"].to_string();
        assert!(!names.contains("\"spot\""), "{variant}");
    }
}

/// A method past its limits with the scene is reported with its reason, and the others still
/// are (over 65 536 visible lights tiled and clustered cannot index, and the whole report
/// failed with their error).
#[test]
fn info_scene_reports_a_method_that_cannot_render_it_and_the_rest() {
    let dir = tempfile::tempdir().unwrap();
    let light = r#"{"kind": "point", "position": [0, 0, 1], "radius": 1, "color": [1, 1, 1]}"#;
    let lights = vec![light; 65_600].join(",");
    // The plane shrunk to a few pixels, the camera where the plane's own was: few fragments
    // loop over all 65 600 lights.
    let plane = r#"{"builtin": "plane", "transform": {"scale": 0.02}}"#;
    let camera = r#"{"position": [0, 0, 5], "target": [0, 0, 0]}"#;
    let scene = format!(r#"{{"objects": [{plane}], "camera": {camera}, "lights": [{lights}]}}"#);
    std::fs::write(dir.path().join("many.json"), scene).unwrap();
    let out = manylight(&["info", "--json", "--scene", "many.json"], &[], dir.path());
    assert!(out.status.success(), "{}", text(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let methods = v["scene"]["methods"].as_array().unwrap();
    let error = |name: &str| {
        let m = methods.iter().find(|m| m["method"] == name).unwrap();
        m["error"].as_str().map(str::to_string)
    };
    for name in ["tiled", "clustered"] {
        let e = error(name).unwrap_or_default();
        assert!(e.contains("65536"), "{name}: {methods:?}");
    }
    assert_eq!(error("forward"), None, "{methods:?}");
}

/// A built-in scene is reported with the lights `render` gives it by default (it had none:
/// every method then held no light data and only the no-lights variant was built).
#[test]
fn info_scene_of_a_built_in_has_renders_default_lights() {
    let dir = tempfile::tempdir().unwrap();
    let out = manylight(&["info", "--json", "--scene", "plane"], &[], dir.path());
    assert!(out.status.success(), "{}", text(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let scene = &v["scene"];
    assert_eq!(scene["features"]["point_lights"], true, "{scene}");
    let clustered = scene["methods"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["method"] == "clustered")
        .unwrap_or_else(|| panic!("no clustered entry: {scene}"));
    assert!(clustered["gpu_bytes"].as_u64().unwrap() > 0, "{clustered}");
    let variants = scene["variants"].to_string();
    assert!(variants.contains("clustered"), "{variants}");
}

/// No message carries a file's bytes as they are: a name with a terminal's escape sequence is
/// shown escaped, and a name of 100 000 characters is cut (an error and a warning alike).
#[test]
fn messages_show_names_from_files_escaped_and_cut() {
    let dir = tempfile::tempdir().unwrap();
    let long = "n".repeat(100_000);
    // A vertex past the object-space limit: an error naming the object.
    let bad_vertex = format!("o \u{1b}]0;PWN\u{7}{long}\nv 2e9 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    std::fs::write(dir.path().join("bad.obj"), bad_vertex).unwrap();
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl \u{1b}[31mred\nf 1 2 3\n";
    std::fs::write(dir.path().join("hot.obj"), obj).unwrap();
    std::fs::write(
        dir.path().join("m.mtl"),
        "newmtl \u{1b}[31mred\nKd 5000 1 1\n",
    )
    .unwrap();
    let small = ["--size", "16x9", "--lights", "2", "--frames", "0"];
    let error = expect_exit(
        &[&["render", "--scene", "bad.obj"], &small[..]].concat(),
        &[],
        dir.path(),
        1,
        "\\u{1b}]0;PWN\\u{7}",
    );
    assert!(error.len() < 1_000, "{} bytes", error.len());
    assert!(error.contains("characters more"), "{error}");
    let out = manylight(
        &[&["render", "--scene", "hot.obj"], &small[..]].concat(),
        &[],
        dir.path(),
    );
    let warned = text(&out);
    assert!(out.status.success(), "{warned}");
    assert!(warned.contains("\\u{1b}[31mred"), "{warned}");
    for said in [&error, &warned] {
        assert!(
            !said.chars().any(|c| c.is_control() && c != '\n'),
            "{said:?}"
        );
    }
}

/// A picture that comes out black is warned of with what can cause it (here a camera turned
/// away from the geometry, then a scene nothing lights); a lit one is not.
#[test]
fn a_black_picture_is_warned_of_with_its_likely_causes() {
    let dir = tempfile::tempdir().unwrap();
    let away = r#"{"camera": {"position": [0, 1, 5], "target": [0, 1, 10]},
        "objects": [{"builtin": "plane"}], "random_lights": {"count": 8}}"#;
    let unlit = r#"{"objects": [{"builtin": "plane"}], "ambient": [0, 0, 0]}"#;
    std::fs::write(dir.path().join("away.json"), away).unwrap();
    std::fs::write(dir.path().join("unlit.json"), unlit).unwrap();
    let run = |scene: &str| {
        let out = manylight(
            &["--scene", scene, "--size", "32x18", "--out", "o.png"],
            &[],
            dir.path(),
        );
        let msg = text(&out);
        assert!(out.status.success(), "{msg}");
        msg
    };
    let msg = run("away.json");
    assert!(
        msg.contains("the picture is black") && msg.contains("looks away from all the geometry"),
        "{msg}"
    );
    let msg = run("unlit.json");
    assert!(
        msg.contains("nothing lights it") && !msg.contains("looks away"),
        "{msg}"
    );
    let msg = run("plane");
    assert!(!msg.contains("the picture is black"), "{msg}");
}

/// A method name, an output path or a GLES folder from the command line reaches its error with
/// line ends escaped and cut short (they were printed as given: a line end split the one-line
/// error, a 3 000-character name came back whole).
#[test]
fn command_line_names_in_errors_are_escaped_and_cut() {
    let dir = tempfile::tempdir().unwrap();
    let long = "m".repeat(3000);
    let cases: [&[&str]; 4] = [
        &["--size", "8x8", "--frames", "0", "--method", "a\nb"],
        &[
            "--size",
            "8x8",
            "--frames",
            "0",
            "--out",
            "missing/a\nb.png",
        ],
        &["info", "--gles-lib", "/missing\nfolder"],
        &["--size", "8x8", "--frames", "0", "--method", &long],
    ];
    for args in cases {
        let out = manylight(args, &[], dir.path());
        assert!(!out.status.success(), "{args:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        let error = stderr
            .lines()
            .find(|l| l.starts_with("error:"))
            .unwrap_or("");
        assert!(
            error.contains("\\u{a}") || error.contains("…"),
            "{args:?}: {stderr}"
        );
        assert!(error.len() < 1500, "{args:?}: {stderr}");
        assert!(
            !stderr.contains("a\nb") && !stderr.contains("missing\nfolder"),
            "{stderr}"
        );
    }
}

/// The summary line is one line whatever the output's name, and counts in words that agree
/// (`1 lights` and a raw line end from `--out` were printed).
#[test]
fn the_summary_line_escapes_the_output_name_and_counts_one_light() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        "--size", "8x8", "--frames", "1", "--lights", "1", "--out", "a\nb.png",
    ];
    let out = manylight(&args, &[], dir.path());
    assert!(out.status.success(), "{}", text(&out));
    assert!(dir.path().join("a\nb.png").is_file());
    let summary = String::from_utf8_lossy(&out.stdout);
    assert_eq!(summary.lines().count(), 1, "{summary}");
    assert!(summary.contains("a\\u{a}b.png"), "{summary}");
    assert!(summary.contains(" · 1 light · "), "{summary}");
}

/// `--no-float-textures` plays the device `MESA_EXTENSION_OVERRIDE` makes by removing float
/// textures: the same light records, so the same picture from every method that runs, and the
/// same capabilities and fallback in the JSON (the matrix's played rows reported float textures
/// and a method `supported` while their lights went through RGBA8 records). ES 3.0 has float
/// textures core, so the flag with `--es 3` is a usage error.
#[test]
fn no_float_textures_plays_the_device_without_them() {
    let dir = tempfile::tempdir().unwrap();
    if !mesa_driver() {
        return;
    }
    let removed = [(
        "MESA_EXTENSION_OVERRIDE",
        "-GL_OES_texture_float -GL_OES_texture_half_float",
    )];
    let info = |args: &[&str], env: &[(&str, &str)]| {
        let out = manylight(args, env, dir.path());
        assert!(out.status.success(), "{args:?}: {}", text(&out));
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let played = info(&["info", "--es", "2", "--no-float-textures", "--json"], &[]);
    let real = info(&["info", "--es", "2", "--json"], &removed);
    for v in [&played, &real] {
        assert_eq!(v["caps"]["float_textures"], false, "{}", v["caps"]);
        let listed = v["caps"]["extensions"].as_array().unwrap();
        assert!(
            !listed.iter().any(|e| e == "GL_OES_texture_float"),
            "{listed:?}"
        );
    }
    assert_eq!(played["methods"], real["methods"]);
    assert_eq!(played["methods"][0]["support"]["status"], "fallback");
    for method in ["forward", "clustered"] {
        let picture = |png: &str, extra: &[&str], env: &[(&str, &str)]| {
            let mut args = vec!["--es", "2", "--method", method, "--size", "48x27"];
            args.extend([
                "--lights", "32", "--frames", "0", "--out", png, "--stats", "s.json",
            ]);
            args.extend(extra);
            let out = manylight(&args, env, dir.path());
            assert!(out.status.success(), "{method}: {}", text(&out));
            assert_eq!(stats(&dir.path().join("s.json"))["light_encoding"], "rgba8");
            image::open(dir.path().join(png)).unwrap().into_rgba8()
        };
        let a = picture("played.png", &["--no-float-textures"], &[]);
        let b = picture("real.png", &[], &removed);
        let d = manylight::metrics::diff(&a, &b);
        assert!(
            d.max_abs <= 1,
            "{method}: played {}/255 from the real one",
            d.max_abs
        );
    }
    // A usage error naming the flag (the library's own refusal named its field).
    expect_exit(
        &["info", "--es", "3", "--no-float-textures"],
        &[],
        dir.path(),
        2,
        "--no-float-textures plays an OpenGL ES 2.0 device",
    );
}

/// The automatic grid's surface sample is a ray cast bounded in work: half squares stacked
/// 8 000 deep, whose boxes are whole squares, make each ray through their other half test
/// every one (a 1 MB model of such triangles took 30 s a sample). The sample stops at its
/// bound, and the grid's reason says so; 100 layers are sampled whole.
#[test]
fn the_automatic_grids_surface_sample_is_bounded_in_work() {
    let dir = tempfile::tempdir().unwrap();
    let reason = |layers: usize| {
        let mut obj = String::new();
        for i in 0..layers {
            let z = -(i as f64) * 1e-3;
            obj.push_str(&format!("v -5 -5 {z}\nv 5 -5 {z}\nv -5 5 {z}\n"));
            let k = 3 * i + 1;
            obj.push_str(&format!("f {k} {} {}\n", k + 1, k + 2));
        }
        std::fs::write(dir.path().join("stack.obj"), obj).unwrap();
        // Looking straight down at the stack, whose boxes fill the view.
        let scene = r#"{"camera": {"position": [0, 0, 3], "target": [0, 0, 0],
            "up": [0, 1, 0], "projection": "perspective", "fov_y_deg": 60, "near": 0.1,
            "far": 100}, "objects": [{"obj": "stack.obj"}], "random_lights": {"count": 4}}"#;
        std::fs::write(dir.path().join("stack.json"), scene).unwrap();
        let args = [
            "render",
            "--scene",
            "stack.json",
            "--size",
            "64x36",
            "--frames",
            "0",
            "--method",
            "clustered",
            "--stats",
            "s.json",
        ];
        let out = manylight(&args, &[], dir.path());
        assert!(out.status.success(), "{}", text(&out));
        let said = text(&out).contains("surface sample stopped after");
        let reason = stats(&dir.path().join("s.json"))["grid_reason"]
            .as_str()
            .unwrap()
            .to_string();
        (reason, said)
    };
    let (deep, said) = reason(8000);
    assert!(deep.contains("surface sample cut to") && said, "{deep}");
    let (shallow, said) = reason(100);
    assert!(
        !shallow.contains("surface sample cut") && !said,
        "{shallow}"
    );
}
