//! The first frame of a fresh renderer, with and without `Renderer::warm_up` before it, taking
//! turns in one run: what a game's first frame costs when it meets the scene's shaders, and
//! what the warm-up moves to a loading screen.
//! `cargo bench --bench first_frame -- [ROUNDS] [WxH] [METHOD] [es2|es3]` (default 5 rounds,
//! 640x360, auto, ES 3.0: the courtyard with 1 024 lights, a sun and a metallic-roughness
//! object). Each round makes a new context and renderer for each case. Set
//! `MESA_SHADER_CACHE_DISABLE=true` on Mesa, whose disk cache would otherwise serve the
//! compiles after the first round.

use std::time::Instant;

use glam::{DMat4, DVec3, Vec3};
use manylight::gl::HeadlessContext;
use manylight::scene::{self, DirectionalLight, Material, Object, Scene};
use manylight::{EsVersion, RenderOptions, Renderer};
use manylight_tools::frame_bench::{median, FrameBenchArgs};

/// The default scene with what selects more shader variants: a sun and a metallic object.
fn scene() -> Result<Scene, Box<dyn std::error::Error>> {
    let mut s = scene::builtin::build("courtyard", Some((1024, 7)))?;
    let sun = DirectionalLight::new(DVec3::new(1.0, -2.0, -1.0), Vec3::ONE, 0.5);
    s.directional_lights.push(sun);
    let metal = Material::metallic_roughness("metal", Vec3::new(0.9, 0.7, 0.3), 1.0, 0.4);
    s.materials.push(metal);
    s.objects.push(Object {
        mesh: s.objects[0].mesh.clone(),
        material: s.materials.len() - 1,
        transform: DMat4::from_scale(DVec3::splat(0.2)),
    });
    Ok(s)
}

/// Milliseconds of the warm-up (0 without) and of the first and second frames, on a fresh
/// context and renderer.
fn one_round(
    es: EsVersion,
    method: &str,
    scene: &Scene,
    (w, h): (u32, u32),
    warm: bool,
) -> Result<[f64; 3], Box<dyn std::error::Error>> {
    let ctx = HeadlessContext::new(es)?;
    let mut renderer = Renderer::new(ctx.load_gl()?, es)?;
    renderer.set_method_named(method)?;
    let options = RenderOptions::default();
    let ms = |start: Instant| start.elapsed().as_secs_f64() * 1e3;
    let start = Instant::now();
    if warm {
        renderer.warm_up(scene, &options)?;
    }
    let warm_ms = if warm { ms(start) } else { 0.0 };
    let start = Instant::now();
    let (_, first) = renderer.render_offscreen(scene, w, h, &options)?;
    let first_ms = ms(start);
    let start = Instant::now();
    renderer.render_offscreen(scene, w, h, &options)?;
    let second_ms = ms(start);
    if warm && first.programs_built > 0 {
        return Err(format!(
            "the first frame after the warm-up built {}",
            first.programs_built
        )
        .into());
    }
    Ok([warm_ms, first_ms, second_ms])
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = FrameBenchArgs::from_env("auto");
    let (rounds, size, method, es) = (args.rounds, args.size, args.method.as_str(), args.es);
    let scene = scene()?;
    let (mut cold, mut warm) = (Vec::new(), Vec::new());
    for _ in 0..rounds {
        cold.push(one_round(es, method, &scene, size, false)?);
        warm.push(one_round(es, method, &scene, size, true)?);
    }
    let column = |runs: &[[f64; 3]], i: usize| median(runs.iter().map(|r| r[i]).collect());
    println!(
        "{es} {method} {}x{}, medians of {rounds} rounds (ms): warm-up, first frame, second frame",
        size.0, size.1
    );
    println!(
        "  cold:           -  {:8.1}  {:8.1}",
        column(&cold, 1),
        column(&cold, 2)
    );
    println!(
        "  warmed up: {:8.1}  {:8.1}  {:8.1}",
        column(&warm, 0),
        column(&warm, 1),
        column(&warm, 2)
    );
    Ok(())
}
