//! Soak: many frames per method with moving lights, resident memory sampled as it goes, to
//! show that memory stays flat, and the mean frame time after the first 100 frames.
//! `cargo bench --bench soak -- [FRAMES] [WxH] [LIGHTS] [METHOD]` (default 2 000 frames at
//! 160x90, the courtyard with 256 lights, every method, ES 3.0).

use glam::DVec3;
use manylight::gl::HeadlessContext;
use manylight::methods::METHODS;
use manylight::{scene, EsVersion, RenderOptions, Renderer};

/// Resident set size in MiB, from /proc (Linux); 0 elsewhere.
fn rss_mib() -> f64 {
    let statm = std::fs::read_to_string("/proc/self/statm").unwrap_or_default();
    let pages: f64 = statm
        .split_whitespace()
        .nth(1)
        .and_then(|v| v.parse().ok())
        .unwrap_or(0.0);
    pages * 4096.0 / (1024.0 * 1024.0)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let frames: u32 = args.first().and_then(|a| a.parse().ok()).unwrap_or(2000);
    let (w, h) = args
        .get(1)
        .and_then(|s| s.split_once('x'))
        .and_then(|(a, b)| Some((a.parse().ok()?, b.parse().ok()?)))
        .unwrap_or((160, 90));
    let lights: usize = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(256);
    let only = args.get(3).cloned();
    let ctx = HeadlessContext::new(EsVersion::Es3)?;
    let mut renderer = Renderer::new(ctx.load_gl()?, EsVersion::Es3)?;
    let mut scene = scene::builtin::build("courtyard", Some((lights, 7)))?;
    let start: Vec<DVec3> = scene.lights.iter().map(|l| l.position).collect();
    let options = RenderOptions::default();
    println!(
        "method     frames  RSS (MiB) after 100 frames, then every quarter      growth  ms/frame"
    );
    let methods = METHODS
        .iter()
        .map(|m| m.name)
        .filter(|m| only.as_deref().is_none_or(|o| o == *m));
    for method in methods {
        renderer.set_method_named(method)?;
        let mut after_warmup = 0.0;
        let mut samples = Vec::new();
        let (mut timed, mut timed_frames) = (std::time::Duration::ZERO, 0u32);
        for frame in 0..frames {
            let t = frame as f64 / 30.0;
            for (i, (light, origin)) in scene.lights.iter_mut().zip(&start).enumerate() {
                let a = t + i as f64;
                light.position = *origin + DVec3::new(a.cos(), 0.0, a.sin());
            }
            let started = std::time::Instant::now();
            renderer.render_offscreen(&scene, w, h, &options)?;
            if frame >= 100.min(frames - 1) {
                timed += started.elapsed();
                timed_frames += 1;
            }
            if frame + 1 == 100.min(frames) {
                after_warmup = rss_mib();
            }
            if (frame + 1) % (frames / 4).max(1) == 0 {
                samples.push(format!("{:.1}", rss_mib()));
            }
        }
        let end = rss_mib();
        println!(
            "{method:10} {frames:6}  {after_warmup:6.1} | {:40} {:+.1}  {:8.3}",
            samples.join(" "),
            end - after_warmup,
            timed.as_secs_f64() * 1e3 / f64::from(timed_frames.max(1))
        );
    }
    renderer.destroy();
    Ok(())
}
