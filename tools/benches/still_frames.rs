//! What a still frame costs against a moving one, taking turns in one run: a still frame
//! (nothing the light lists are built from changed) draws with the last frame's lists, so it
//! neither assigns nor uploads them (forward's and deferred's light records likewise).
//! `cargo bench --bench still_frames -- [ROUNDS] [WxH] [METHOD] [es2|es3] [LIGHTS]` (default 5
//! rounds, 640x360, clustered, ES 3.0, the courtyard with 1 024 lights). Each round renders 20 frames
//! of the lights standing at t = 1 s, then 20 of them moving on from there at 30 frames a second,
//! on one renderer; prints the medians over all rounds of the frame time (`render_offscreen`,
//! read-back included), the assignment time and the bytes uploaded, and the frames that reused
//! their lists.

use std::time::Instant;

use manylight::gl::HeadlessContext;
use manylight::scene::{self, Scene};
use manylight::{RenderOptions, Renderer};
use manylight_tools::frame_bench::{median, FrameBenchArgs};

const FRAMES: usize = 20;

/// One frame's figures: wall ms, assignment ms, bytes uploaded, lists reused.
type Frame = (f64, f64, f64, bool);

fn frames(
    renderer: &mut Renderer,
    scene: &mut Scene,
    size: (u32, u32),
    moving: bool,
) -> Result<Vec<Frame>, Box<dyn std::error::Error>> {
    let options = RenderOptions::default();
    (0..FRAMES)
        .map(|k| {
            let t = if moving {
                1.0 + (k + 1) as f64 / 30.0
            } else {
                1.0
            };
            scene.set_time(t);
            let start = Instant::now();
            let (_, s) = renderer.render_offscreen(scene, size.0, size.1, &options)?;
            let ms = start.elapsed().as_secs_f64() * 1e3;
            let bytes = s.memory.upload_bytes as f64;
            Ok((ms, s.time.assign_ms, bytes, s.lists_reused))
        })
        .collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = FrameBenchArgs::from_env("clustered");
    let (rounds, size, method, es) = (args.rounds, args.size, args.method.as_str(), args.es);
    let lights = args.lights;
    let mut scene = scene::builtin::build("courtyard", Some((lights, 7)))?;
    let ctx = HeadlessContext::new(es)?;
    let mut renderer = Renderer::new(ctx.load_gl()?, es)?;
    renderer.set_method_named(method)?;
    renderer.warm_up(&scene, &RenderOptions::default())?;
    let (mut still, mut moving) = (Vec::new(), Vec::new());
    for _ in 0..rounds {
        still.extend(frames(&mut renderer, &mut scene, size, false)?);
        moving.extend(frames(&mut renderer, &mut scene, size, true)?);
    }
    println!(
        "{es} {method} {}x{}, courtyard, {lights} lights, {rounds} rounds of {FRAMES} frames each, \
         medians: frame ms, assignment ms, bytes uploaded; frames that reused their lists",
        size.0, size.1
    );
    for (name, runs) in [("still", &still), ("moving", &moving)] {
        let column = |f: fn(&Frame) -> f64| median(runs.iter().map(f).collect());
        println!(
            "  {name:>6}: {:8.2} {:8.3} {:10.0}   {} of {}",
            column(|f| f.0),
            column(|f| f.1),
            column(|f| f.2),
            runs.iter().filter(|f| f.3).count(),
            runs.len()
        );
    }
    let ratio =
        median(still.iter().map(|f| f.0).collect()) / median(moving.iter().map(|f| f.0).collect());
    println!("  still / moving frame time: {ratio:.2}x");
    Ok(())
}
