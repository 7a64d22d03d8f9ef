//! Renders a scene built in code, lit by lights of one's own, offscreen into a PNG.
//!
//! ```text
//! cargo run --release --example offscreen -- [OUT.png]
//! ```
//!
//! No window and no display: a headless EGL context (Mesa's llvmpipe works), as a render test
//! or a server would use it.

use std::path::Path;

use manylight::glam::{DMat4, DVec3, Vec3};
use manylight::{
    Camera, Cone, EsVersion, FrameStats, HeadlessContext, Light, Material, MeshBuilder,
    RenderOptions, Renderer, Scene,
};

/// A floor with a row of boxes, lit by a ring of coloured point lights and one white spot.
pub fn build_scene() -> Result<Scene, manylight::SceneError> {
    let mut scene = Scene::empty();
    let stone = scene.add_material(Material::flat("stone", Vec3::new(0.6, 0.58, 0.55)));
    let painted = scene.add_material(Material::glossy(
        "painted",
        Vec3::new(0.2, 0.3, 0.7),
        Vec3::splat(0.4),
        32.0,
    ));
    let mut floor = MeshBuilder::new();
    floor.quad(
        Vec3::new(-10.0, 0.0, 10.0),
        Vec3::new(10.0, 0.0, 10.0),
        Vec3::new(10.0, 0.0, -10.0),
        Vec3::new(-10.0, 0.0, -10.0),
    );
    let mut boxes = MeshBuilder::new();
    for i in -3..=3 {
        let x = i as f32 * 2.5;
        boxes.cuboid(Vec3::new(x - 0.5, 0.0, -0.5), Vec3::new(x + 0.5, 1.5, 0.5));
    }
    scene.add_object(floor.build()?, stone, DMat4::IDENTITY);
    scene.add_object(boxes.build()?, painted, DMat4::IDENTITY);
    // 200 point lights on a ring just above the floor, hue going round.
    for i in 0..200 {
        let t = i as f64 / 200.0 * std::f64::consts::TAU;
        let position = DVec3::new(8.0 * t.cos(), 0.4, 8.0 * t.sin() * 0.6);
        let hue = Vec3::new(
            0.5 + 0.5 * (t as f32).cos(),
            0.5 + 0.5 * (t as f32 + 2.1).cos(),
            0.5 + 0.5 * (t as f32 + 4.2).cos(),
        );
        scene.lights.push(Light::point(position, 2.5, hue, 1.5));
    }
    scene.lights.push(Light::spot(
        DVec3::new(0.0, 6.0, 3.0),
        12.0,
        Vec3::ONE,
        4.0,
        Cone {
            direction: DVec3::new(0.0, -1.0, -0.4),
            inner_deg: 15.0,
            outer_deg: 25.0,
        },
    ));
    scene.camera = Camera::perspective(
        DVec3::new(0.0, 5.0, 12.0),
        DVec3::new(0.0, 0.5, 0.0),
        50.0,
        0.1,
        60.0,
    );
    Ok(scene)
}

/// Renders [`build_scene`] at `width × height` on ES 3.0 (ES 2.0 where that is all the driver
/// gives) and writes the image to `out`.
pub fn run(out: &Path, width: u32, height: u32) -> Result<FrameStats, Box<dyn std::error::Error>> {
    let (ctx, es) = match HeadlessContext::new(EsVersion::Es3) {
        Ok(ctx) => (ctx, EsVersion::Es3),
        Err(_) => (HeadlessContext::new(EsVersion::Es2)?, EsVersion::Es2),
    };
    let mut renderer = Renderer::new(ctx.load_gl()?, es)?;
    let scene = build_scene()?;
    let result = renderer.render_offscreen(&scene, width, height, &RenderOptions::default());
    // Free the GL objects before the context goes, whatever happened.
    renderer.destroy();
    let (image, stats) = result?;
    image.save(out)?;
    Ok(stats)
}

#[allow(dead_code)] // `tests/examples.rs` includes this file and calls `run` itself.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "offscreen.png".into());
    let stats = run(Path::new(&out), 640, 360)?;
    println!(
        "{out}: {} lights, method {}, {:.1} ms (of which light assignment {:.2} ms)",
        stats.lights.total, stats.method, stats.time.frame_ms, stats.time.assign_ms
    );
    Ok(())
}
