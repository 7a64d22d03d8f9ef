//! Lights that move every frame, written as a PNG sequence.
//!
//! ```text
//! cargo run --release --example animated_lights -- [OUT_DIR] [FRAMES]
//! ```
//!
//! Per-frame light assignment is the point of the design: nothing about the lights is baked,
//! so moving all of them costs the same as moving none. Each of the courtyard's lights circles
//! its starting point at its own speed; the renderer re-assigns them to the cluster grid every
//! frame. The frames go to `OUT_DIR/frame_000.png` … (turn them into a video with, say,
//! `ffmpeg -i OUT_DIR/frame_%03d.png out.mp4`).

use std::path::Path;

use glam::DVec3;
use manylight::gl::HeadlessContext;
use manylight::metrics::spread::Spread;
use manylight::scene::{self, Scene};
use manylight::{EsVersion, RenderOptions, Renderer};

/// Moves each light on a horizontal circle around where it started: light `i` at time `t`
/// (seconds) is `start + r·(cos, 0, sin)(ω_i·t + φ_i)`, so the motion is a pure function of
/// time and a frame can be recomputed on its own.
pub fn place_lights(scene: &mut Scene, start: &[DVec3], t: f64) {
    for (i, (light, origin)) in scene.lights.iter_mut().zip(start).enumerate() {
        let speed = 0.5 + (i % 7) as f64 * 0.25; // radians per second
        let phase = i as f64 * 2.399_963; // the golden angle spreads the phases
        let angle = speed * t + phase;
        light.position = *origin + DVec3::new(angle.cos(), 0.0, angle.sin()) * 1.5;
    }
}

/// Frame-time figures of a run, in milliseconds.
#[derive(Debug)]
pub struct Timings {
    /// Median frame time.
    pub p50_ms: f64,
    /// 95th-percentile frame time.
    pub p95_ms: f64,
    /// Median light-assignment time (CPU).
    pub assign_p50_ms: f64,
}

/// Renders `frames` frames of `lights` moving lights at `width × height` into `out_dir`.
/// (The renderer frees its GL objects when it is dropped, before the context, on every path.)
pub fn run(
    out_dir: &Path,
    frames: u32,
    lights: usize,
    width: u32,
    height: u32,
) -> Result<Timings, Box<dyn std::error::Error>> {
    std::fs::create_dir_all(out_dir)?;
    let ctx = HeadlessContext::new(EsVersion::Es3)?;
    let mut renderer = Renderer::new(ctx.load_gl(), EsVersion::Es3)?;
    let mut scene = scene::builtin::build("courtyard", Some((lights, 7)))?;
    let start: Vec<DVec3> = scene.lights.iter().map(|l| l.position).collect();
    let options = RenderOptions::default();
    let mut frame_ms = Vec::new();
    let mut assign_ms = Vec::new();
    for frame in 0..frames {
        let t = frame as f64 / 24.0; // 24 frames per second of animation time
        place_lights(&mut scene, &start, t);
        let (image, stats) = renderer.render_offscreen(&scene, width, height, &options)?;
        image.save(out_dir.join(format!("frame_{frame:03}.png")))?;
        frame_ms.push(stats.frame_ms);
        assign_ms.push(stats.assign_ms);
    }
    let frame = Spread::of(frame_ms);
    Ok(Timings {
        p50_ms: frame.map_or(0.0, |s| s.p50),
        p95_ms: frame.map_or(0.0, |s| s.p95),
        assign_p50_ms: Spread::of(assign_ms).map_or(0.0, |s| s.p50),
    })
}

#[allow(dead_code)] // `tests/examples.rs` includes this file and calls `run` itself.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let out = args.next().unwrap_or_else(|| "animated".into());
    let frames = match args.next() {
        Some(n) => n
            .parse()
            .map_err(|_| format!("FRAMES: `{n}` is not a count"))?,
        None => 48,
    };
    let t = run(Path::new(&out), frames, 1024, 640, 360)?;
    println!(
        "{frames} frames in {out}/: frame p50 {:.1} ms, p95 {:.1} ms; assignment p50 {:.2} ms",
        t.p50_ms, t.p95_ms, t.assign_p50_ms
    );
    Ok(())
}
