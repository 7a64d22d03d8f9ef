//! Lights that move every frame, written as a PNG sequence.
//!
//! ```text
//! cargo run --release --example animated_lights -- [OUT_DIR] [FRAMES]
//! ```
//!
//! Per-frame light assignment is the point of the design: nothing about the lights is baked,
//! so moving all of them costs the same as moving none. The courtyard's random lights come with
//! the built-in scenes' motion (they wander, flicker, spots sweep); this example adds a bright
//! spot light that circles the fountain, built in code. `Scene::set_time(t)` poses every light
//! at time `t`, a pure function of time, so a frame can be recomputed on its own. The frames go
//! to `OUT_DIR/frame_000.png` … (turn them into a video with, say,
//! `ffmpeg -i OUT_DIR/frame_%03d.png out.mp4`, or use `manylight --record DIR|FILE.gif`).

use std::path::Path;

use manylight::glam::{DVec3, Vec3};
use manylight::motion::{Motion, Orbit, OrbitAbout};
use manylight::{
    builtin_scene, Cone, EsVersion, HeadlessContext, Light, RandomLights, RenderOptions, Renderer,
    Scene, Spread,
};

/// Animation time of frame `frame`: 24 frames per second.
pub fn time_of(frame: u32) -> f64 {
    f64::from(frame) / 24.0
}

/// The courtyard with `lights` moving random lights and a spot light circling the fountain.
pub fn build_scene(lights: usize) -> Result<Scene, Box<dyn std::error::Error>> {
    let mut scene = builtin_scene(
        "courtyard",
        Some(RandomLights {
            count: lights,
            seed: 7,
        }),
    )?;
    scene.lights.push(Light::spot(
        DVec3::new(4.0, 6.0, 0.0),
        14.0,
        Vec3::new(1.0, 0.9, 0.7),
        40.0,
        Cone {
            direction: DVec3::new(-0.5, -1.0, 0.0),
            inner_deg: 12.0,
            outer_deg: 25.0,
        },
    ));
    let spot = scene.lights.len() - 1;
    scene.animate_light(
        spot,
        Motion {
            orbit: Some(Orbit {
                about: OrbitAbout::Point(DVec3::ZERO),
                axis: DVec3::Y,
                period_s: 3.0,
                phase_deg: 0.0,
            }),
            ..Motion::default()
        },
    );
    scene.validate()?;
    Ok(scene)
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
    let mut renderer = Renderer::new(ctx.load_gl()?, EsVersion::Es3)?;
    let mut scene = build_scene(lights)?;
    let options = RenderOptions::default();
    let mut frame_ms = Vec::new();
    let mut assign_ms = Vec::new();
    for frame in 0..frames {
        scene.set_time(time_of(frame));
        let (image, stats) = renderer.render_offscreen(&scene, width, height, &options)?;
        image.save(out_dir.join(format!("frame_{frame:03}.png")))?;
        frame_ms.push(stats.time.frame_ms);
        assign_ms.push(stats.time.assign_ms);
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
