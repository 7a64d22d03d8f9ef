//! `manylight view` (feature `window`) in a virtual X server: the built binary opens a real
//! window with an EGL OpenGL ES context, renders 5 frames, reads the last one back from the
//! window's framebuffer and quits. The screenshot must have the window's size, show a lit
//! scene, and match the same view rendered offscreen by `manylight render`.
//!
//! Needs Xvfb (`apt-get install xvfb xauth`). Each test starts its own `Xvfb -displayfd`,
//! which picks a free display itself, so tests running in parallel never race for a display
//! number the way concurrent `xvfb-run -a` calls can. Without Xvfb the tests print
//! `SKIPPED: …` and pass (they fail instead where `MANYLIGHT_REQUIRE_ALL_TESTS` is set, as CI
//! sets it).
#![cfg(feature = "window")]

mod common;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::Duration;

const BIN: &str = env!("CARGO_BIN_EXE_manylight");
/// Window size asked for (Xvfb has no window manager, so the window gets exactly this).
const SIZE: (u32, u32) = (320, 240);
/// X screen of the virtual server: 24-bit colour so EGL finds RGB8 configs.
const SCREEN: &str = "1024x768x24";
/// Longest a viewer run may take before the test gives up on it.
const TIMEOUT: Duration = Duration::from_secs(180);

/// An executable named `name` on `PATH`.
fn which(name: &str) -> Option<PathBuf> {
    std::env::split_paths(&std::env::var_os("PATH")?)
        .map(|dir| dir.join(name))
        .find(|p| p.is_file())
}

/// An `Xvfb` this test started; stopped with SIGTERM when dropped, so it removes its socket
/// and lock file.
struct Server(Child);

impl Drop for Server {
    fn drop(&mut self) {
        let terminated = Command::new("kill")
            .arg(self.0.id().to_string())
            .status()
            .is_ok_and(|s| s.success());
        if !terminated {
            let _ = self.0.kill();
        }
        let _ = self.0.wait();
    }
}

/// Starts `Xvfb` on a display it picks itself (`-displayfd`) and returns it once it accepts
/// connections.
fn start_xvfb(xvfb: &Path) -> (Server, String) {
    let child = Command::new(xvfb)
        .args([
            "-displayfd",
            "1",
            "-screen",
            "0",
            SCREEN,
            "-nolisten",
            "tcp",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("spawn Xvfb");
    let mut server = Server(child);
    // Xvfb writes the display number to fd 1 when it is ready (EOF if it failed).
    // The pipe stays open (in `server.0`): Xvfb must not die of SIGPIPE before it cleans up.
    let mut line = String::new();
    let stdout = server.0.stdout.as_mut().expect("piped stdout");
    std::io::BufRead::read_line(&mut std::io::BufReader::new(stdout), &mut line)
        .expect("read Xvfb's display number");
    let number: u32 = line
        .trim()
        .parse()
        .unwrap_or_else(|_| panic!("Xvfb did not start (printed {line:?})"));
    (server, format!(":{number}"))
}

/// Runs `manylight view ARGS` with extra environment in a virtual X server; `None` when no
/// Xvfb exists.
fn run_view(args: &[&str], env: &[(&str, &str)]) -> Option<Output> {
    let Some(xvfb) = which("Xvfb") else {
        common::skip("no Xvfb on PATH (apt-get install xvfb xauth)");
        return None;
    };
    let (_server, display) = start_xvfb(&xvfb);
    let mut cmd = Command::new(BIN);
    cmd.env("DISPLAY", display);
    // X11 only: a Wayland session in the caller's environment would win otherwise.
    cmd.env_remove("WAYLAND_DISPLAY")
        .envs(env.iter().copied())
        .arg("view")
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let child = cmd.spawn().expect("spawn manylight view");
    Some(common::cli::wait_with_timeout(
        child,
        "manylight view",
        TIMEOUT,
    ))
}

/// The fraction of `image`'s pixels for which `keep(x, y)` holds.
fn fraction(image: &image::RgbaImage, keep: impl Fn(u32, u32) -> bool) -> f64 {
    let kept = image
        .enumerate_pixels()
        .filter(|(x, y, _)| keep(*x, *y))
        .count();
    kept as f64 / (image.width() * image.height()) as f64
}

/// Renders 5 frames of the default scene in a window (`extra` arguments and `env`), checks
/// the screenshot and compares it with `manylight render` of the same view (`render_extra`
/// arguments). Returns the viewer's stdout and stderr, or `None` when skipped.
fn check_window_frame(
    extra: &[&str],
    render_extra: &[&str],
    env: &[(&str, &str)],
) -> Option<(String, String)> {
    let dir = tempfile::tempdir().expect("tempdir");
    let shot = dir.path().join("view.png");
    let size = format!("{}x{}", SIZE.0, SIZE.1);
    let shot_arg = shot.to_str().expect("utf-8 temp path");
    // Paused: the lights hold their pose at t = 0, the frame `render` draws.
    let mut args = vec![
        "--frames",
        "5",
        "--screenshot",
        shot_arg,
        "--lights",
        "256",
        "--paused",
    ];
    args.extend(["--size", &size]);
    args.extend(extra);
    let out = run_view(&args, env)?;
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "manylight view failed:\n{stderr}");
    assert!(stdout.contains("5 frames"), "stdout: {stdout}");

    let image = image::open(&shot)
        .unwrap_or_else(|e| panic!("screenshot {}: {e}", shot.display()))
        .to_rgba8();
    assert_eq!(image.dimensions(), SIZE, "screenshot has the window's size");
    let lit = fraction(&image, |x, y| {
        image.get_pixel(x, y).0[..3].iter().any(|&c| c > 8)
    });
    println!("{:.1}% of the pixels are lit", lit * 100.0);
    assert!(lit > 0.5, "only {:.1}% lit: {stdout}", lit * 100.0);

    // The same view rendered offscreen through headless EGL must look the same.
    let reference = dir.path().join("render.png");
    let out = Command::new(BIN)
        .args([
            "render", "--lights", "256", "--frames", "0", "--size", &size,
        ])
        .args(render_extra)
        .arg("--out")
        .arg(&reference)
        // The window renders through the system's libEGL (glutin loads it), whatever
        // MANYLIGHT_GLES_LIB selects for headless contexts: so does its reference.
        .env_remove(manylight::gl::gles_lib::GLES_LIB_ENV)
        .envs(env.iter().copied())
        .output()
        .expect("run manylight render");
    assert!(
        out.status.success(),
        "manylight render failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let reference = image::open(&reference).expect("render.png").to_rgba8();
    assert_eq!(reference.dimensions(), SIZE);
    let same = fraction(&image, |x, y| {
        let (a, b) = (image.get_pixel(x, y), reference.get_pixel(x, y));
        (0..3).all(|c| a.0[c].abs_diff(b.0[c]) <= 2)
    });
    println!(
        "{:.2}% of the pixels match the offscreen render",
        same * 100.0
    );
    assert!(
        same > 0.99,
        "window and offscreen renders differ: {:.2}% match",
        same * 100.0
    );
    Some((stdout, stderr))
}

#[test]
fn view_renders_a_lit_frame_into_the_window() {
    if let Some((stdout, _)) = check_window_frame(&[], &[], &[]) {
        assert!(
            stdout.contains("clustered · ES 3.0 · 256 lights"),
            "{stdout}"
        );
    }
}

/// 4× MSAA resolved into the window's back buffer matches `render --msaa 4`.
#[test]
fn view_resolves_msaa_into_the_window() {
    let msaa = ["--msaa", "4"];
    if let Some((_, stderr)) = check_window_frame(&msaa, &msaa, &[]) {
        assert!(!stderr.contains("MSAA off"), "{stderr}");
    }
}

/// ES 2.0's MSAA (`GL_EXT_multisampled_render_to_texture`, added by Mesa's override) in the
/// window: its entry point comes from the implementation the window's context uses, also in a
/// run where `MANYLIGHT_GLES_LIB` names another one for headless contexts (loading that one's
/// EGL made the viewer fail with "no GL context is current").
#[test]
fn view_resolves_es2_msaa_through_the_extension() {
    let es2_msaa = ["--es", "2", "--msaa", "4"];
    let extension = [(
        "MESA_EXTENSION_OVERRIDE",
        "+GL_EXT_multisampled_render_to_texture",
    )];
    if let Some((stdout, stderr)) = check_window_frame(&es2_msaa, &es2_msaa, &extension) {
        assert!(stdout.contains("ES 2.0"), "{stdout}");
        assert!(
            !stderr.contains("MSAA off") && !stderr.contains("could not be loaded"),
            "{stderr}"
        );
    }
}

/// The window posed at `--time` (paused) is `render --time`'s frame: the moving lights are
/// where the same function of time puts them.
#[test]
fn view_poses_moving_lights_at_the_given_time() {
    let at = ["--time", "2.5"];
    if check_window_frame(&at, &at, &[]).is_none() {
        return;
    }
    // The window matched `render --time 2.5` on 99 % of its pixels; that frame must differ from
    // t = 0's on far more, or a window that ignored `--time` would pass too.
    let dir = tempfile::tempdir().expect("tempdir");
    let size = format!("{}x{}", SIZE.0, SIZE.1);
    let frame_at = |t: &str| {
        let out_path = dir.path().join(format!("t{t}.png"));
        let out = Command::new(BIN)
            .args([
                "render", "--lights", "256", "--frames", "0", "--size", &size,
            ])
            .args(["--time", t, "--out"])
            .arg(&out_path)
            .output()
            .expect("run manylight render");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        image::open(&out_path).expect("render png").to_rgba8()
    };
    let (moved, rest) = (frame_at("2.5"), frame_at("0"));
    let differ = fraction(&moved, |x, y| {
        let (a, b) = (moved.get_pixel(x, y), rest.get_pixel(x, y));
        (0..3).any(|c| a.0[c].abs_diff(b.0[c]) > 2)
    });
    println!("t = 2.5 and t = 0 differ on {:.2}%", differ * 100.0);
    assert!(
        differ > 0.05,
        "t = 2.5 and t = 0 differ on {:.2}%",
        differ * 100.0
    );
}

#[test]
fn view_renders_on_es2() {
    let es2_tiled = ["--es", "2", "--method", "tiled"];
    if let Some((stdout, _)) = check_window_frame(&es2_tiled, &es2_tiled, &[]) {
        assert!(stdout.contains("tiled · ES 2.0"), "{stdout}");
    }
}

#[test]
fn view_falls_back_to_es2_where_the_driver_has_no_es3() {
    let capped = [("MESA_GLES_VERSION_OVERRIDE", "2.0")];
    if let Some((stdout, stderr)) = check_window_frame(&[], &["--es", "2"], &capped) {
        assert!(stdout.contains("ES 2.0"), "{stdout}");
        assert!(stderr.contains("falling back to ES 2.0"), "{stderr}");
    }
}

#[test]
fn view_rejects_bad_input_without_panicking() {
    let Some(out) = run_view(&["--frames", "1", "--method", "no-such-method"], &[]) else {
        return;
    };
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "stderr: {stderr}");
    assert!(stderr.contains("unknown method"), "stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "stderr: {stderr}");
    // A side past X11's 16 bits panicked inside winit (exit 101): a usage error now.
    let Some(out) = run_view(&["--frames", "1", "--size", "65536x36"], &[]) else {
        return;
    };
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {stderr}");
    assert!(stderr.contains("at most 65535"), "stderr: {stderr}");
}

/// `--screenshot` naming a texture the scene reads is refused once the scene is loaded, before
/// any window opens (so no display is needed); it replaced the texture with the screenshot.
#[test]
fn a_screenshot_naming_a_file_the_scene_reads_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let obj = "mtllib q.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n";
    std::fs::write(dir.path().join("q.obj"), obj).unwrap();
    std::fs::write(dir.path().join("q.mtl"), "newmtl m\nmap_Kd t.png\n").unwrap();
    let texture = dir.path().join("t.png");
    image::RgbaImage::from_pixel(2, 2, image::Rgba([200, 100, 50, 255]))
        .save(&texture)
        .unwrap();
    let before = std::fs::read(&texture).unwrap();
    let out = Command::new(BIN)
        .current_dir(dir.path())
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .args([
            "view",
            "--scene",
            "q.obj",
            "--frames",
            "1",
            "--screenshot",
            "t.png",
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("names a file the scene reads"), "{stderr}");
    assert_eq!(std::fs::read(&texture).unwrap(), before);
}

/// The heatmap view (`--heatmap`, H in the window): every covered pixel is a colour of the
/// viridis map the shader draws counts with, and the counts vary across the clustered view.
/// The screenshot goes to standard output (`-`), which then holds the PNG alone: the viewer's
/// lines go to standard error.
#[test]
fn view_draws_the_light_evaluation_heatmap() {
    let size = format!("{}x{}", SIZE.0, SIZE.1);
    let args = [
        "--frames",
        "3",
        "--heatmap",
        "--lights",
        "256",
        "--size",
        &size,
        "--screenshot",
        "-",
    ];
    let Some(out) = run_view(&args, &[]) else {
        return;
    };
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("controls:") && stderr.contains("3 frames"),
        "{stderr}"
    );
    // A PNG ends with its IEND chunk (its 4-byte CRC after the type).
    let png = &out.stdout;
    assert!(
        png.len() > 12 && &png[png.len() - 8..png.len() - 4] == b"IEND",
        "standard output is not the PNG alone: {:?}",
        String::from_utf8_lossy(&png[png.len().saturating_sub(200)..])
    );
    let image = image::load_from_memory(png).expect("screenshot").to_rgba8();
    // The five stops of the shader's map (glsl/surface.glsl), in 8-bit steps.
    let stops: Vec<[f64; 3]> = [
        [0.267, 0.005, 0.329],
        [0.230, 0.322, 0.546],
        [0.128, 0.567, 0.551],
        [0.369, 0.789, 0.383],
        [0.993, 0.906, 0.144],
    ]
    .iter()
    .map(|c| c.map(|v| v * 255.0))
    .collect();
    let off_map = |p: [f64; 3]| {
        stops
            .windows(2)
            .map(|w| {
                let d: Vec<f64> = (0..3).map(|i| w[1][i] - w[0][i]).collect();
                let len2: f64 = d.iter().map(|v| v * v).sum();
                let t =
                    ((0..3).map(|i| (p[i] - w[0][i]) * d[i]).sum::<f64>() / len2).clamp(0.0, 1.0);
                (0..3)
                    .map(|i| (p[i] - w[0][i] - t * d[i]).powi(2))
                    .sum::<f64>()
                    .sqrt()
            })
            .fold(f64::INFINITY, f64::min)
    };
    let (mut on_map, mut colours) = (0usize, std::collections::HashSet::new());
    for p in image.pixels() {
        let c = [p[0] as f64, p[1] as f64, p[2] as f64];
        if p.0[..3] == [0, 0, 0] {
            continue; // background
        }
        assert!(off_map(c) <= 3.0, "pixel {p:?} is not a heatmap colour");
        on_map += 1;
        colours.insert(p.0);
    }
    let total = (image.width() * image.height()) as usize;
    assert!(on_map * 2 > total, "only {on_map} of {total} pixels drawn");
    assert!(colours.len() > 5, "a flat heatmap: {colours:?}");
}

#[test]
fn without_a_display_view_says_how_to_get_one() {
    let out = Command::new(BIN)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .args(["view", "--frames", "1"])
        .output()
        .expect("run manylight view");
    let msg = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{msg}");
    assert!(
        msg.contains("xvfb-run -a") && msg.contains("--out"),
        "{msg}"
    );
    assert!(!msg.contains(".rs:"), "winit's source path leaked: {msg}");
}

/// A screenshot naming the scene file would replace it with a PNG: a usage error before any
/// window opens (no display needed), the scene left as it was.
#[test]
fn a_screenshot_naming_the_scene_is_a_usage_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = r#"{"objects": [{"builtin": "plane"}]}"#;
    let path = dir.path().join("s.json");
    std::fs::write(&path, scene).unwrap();
    let out = Command::new(BIN)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .args(["view", "--frames", "1", "--scene"])
        .arg(&path)
        .arg("--screenshot")
        .arg(&path)
        .output()
        .expect("run manylight view");
    let msg = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{msg}");
    assert!(msg.contains("names the scene file"), "{msg}");
    assert_eq!(std::fs::read_to_string(&path).unwrap(), scene);
}
