//! Built-in procedural scenes, so the renderer runs with no files at all.
//!
//! * `courtyard` (default) — an atrium with a two-storey arcade of columns and arches, a
//!   gallery, walls and a fountain: the role Sponza plays in the papers (long view, occluders,
//!   many surfaces at many depths).
//! * `pillars` — a forest of thin pillars: many depth discontinuities per tile, the worst case
//!   for 2D tiling.
//! * `plane` — one flat quad facing the camera, for analytic checks against the light model.
//! * `bubbles` — the courtyard with translucent spheres floating in it: transparency lit by the
//!   same light lists as the opaque surfaces.

use std::sync::Arc;

use glam::{DMat4, DVec3, Vec3};

use super::mesh::Aabb;
use super::meshbuild::MeshBuilder;
use super::motion::{Flicker, Motion, Orbit, OrbitAbout, Sweep, Wander};
use super::random::{self, LightSetStyle};
use super::{Camera, Material, Mesh, Object, Scene, SceneError};

/// Names of the built-in scenes (`builtin_scene` takes them), default first.
pub const NAMES: &[&str] = &["courtyard", "pillars", "plane", "bubbles"];

/// The default scene's name.
pub const DEFAULT: &str = "courtyard";

/// Builds a built-in scene; `lights` = `Some((count, seed))` adds seeded random lights inside
/// the scene's light volume.
pub fn build(name: &str, lights: Option<(usize, u64)>) -> Result<Scene, SceneError> {
    let (mut scene, volume, style) = match name {
        "courtyard" => courtyard(),
        "pillars" => pillars(),
        "plane" => plane(),
        "bubbles" => bubbles(),
        other => {
            return Err(SceneError::UnknownBuiltin {
                name: other.to_string(),
                available: NAMES,
            })
        }
    };
    if let Some((count, seed)) = lights {
        super::input::check_light_count(count, "lights")?;
        scene.lights = random::lights(&volume, count, seed, style);
        let all = 0..scene.lights.len();
        scene.animate_lights(all, lively_motion(name, &volume), seed);
    }
    Ok(scene)
}

/// The built-in scenes' random lights move (`t = 0` is the still scene, so stills are
/// unchanged): they wander about a metre or two on slow seeded paths, flicker a little, spots
/// sweep; the plane's lights circle in planes parallel to the quad, so its analytic checks
/// hold on every frame.
pub fn lively_motion(name: &str, volume: &Aabb) -> Motion {
    let reach = (volume.size().length() * 0.035).clamp(0.05, 2.0);
    if name == "plane" {
        return Motion {
            orbit: Some(Orbit {
                about: OrbitAbout::Radius(reach * 2.0),
                axis: DVec3::Z,
                period_s: 5.0,
                phase_deg: 0.0,
            }),
            ..Motion::default()
        };
    }
    Motion {
        wander: Some(Wander {
            radius: reach,
            period_s: 6.0,
            seed: 0,
        }),
        flicker: Some(Flicker {
            amount: 0.2,
            rate_hz: 1.5,
            seed: 0,
        }),
        sweep: Some(Sweep {
            axis: DVec3::X,
            angle_deg: 15.0,
            period_s: 5.0,
            phase_deg: 0.0,
        }),
        ..Motion::default()
    }
}

/// Geometry of a built-in as objects and materials only (for scene files that place a
/// built-in with their own transform); `None` for an unknown name.
pub fn geometry(name: &str) -> Option<Scene> {
    build(name, None).ok()
}

fn push(scene: &mut Scene, mesh: Mesh, material: Material) {
    let material = scene.add_material(material);
    scene.objects.push(Object {
        mesh: Arc::new(mesh),
        material,
        transform: DMat4::IDENTITY,
    });
}

fn courtyard() -> (Scene, Aabb, LightSetStyle) {
    const HALF_X: f32 = 20.0;
    const HALF_Z: f32 = 12.0;
    const ARCADE_Z: f32 = 8.5;
    const STOREY: f32 = 5.0;
    let mut scene = Scene::empty();

    let mut floor = MeshBuilder::new();
    floor.cuboid(
        Vec3::new(-HALF_X, -0.2, -HALF_Z),
        Vec3::new(HALF_X, 0.0, HALF_Z),
    );
    push(
        &mut scene,
        floor.build_fixed(),
        Material::glossy(
            "floor",
            Vec3::new(0.45, 0.42, 0.38),
            Vec3::splat(0.25),
            48.0,
        ),
    );

    let mut walls = MeshBuilder::new();
    let h = 2.0 * STOREY + 3.0;
    walls
        .cuboid(
            Vec3::new(-HALF_X - 0.5, 0.0, -HALF_Z - 0.5),
            Vec3::new(HALF_X + 0.5, h, -HALF_Z),
        )
        .cuboid(
            Vec3::new(-HALF_X - 0.5, 0.0, HALF_Z),
            Vec3::new(HALF_X + 0.5, h, HALF_Z + 0.5),
        )
        .cuboid(
            Vec3::new(-HALF_X - 0.5, 0.0, -HALF_Z),
            Vec3::new(-HALF_X, h, HALF_Z),
        )
        .cuboid(
            Vec3::new(HALF_X, 0.0, -HALF_Z),
            Vec3::new(HALF_X + 0.5, h, HALF_Z),
        );
    push(
        &mut scene,
        walls.build_fixed(),
        Material::flat("walls", Vec3::new(0.72, 0.64, 0.52)),
    );

    // Two storeys of arcades on both long sides: columns, arches, and the gallery slab the
    // upper storey stands on.
    let mut columns = MeshBuilder::new();
    let mut arches = MeshBuilder::new();
    let mut gallery = MeshBuilder::new();
    let spacing = 4.0;
    for side in [-1.0f32, 1.0] {
        let z = side * ARCADE_Z;
        for storey in 0..2 {
            let y0 = storey as f32 * (STOREY + 0.4);
            let col_h = if storey == 0 { 3.2 } else { 2.6 };
            let radius = if storey == 0 { 0.35 } else { 0.25 };
            let mut x = -HALF_X + 2.0;
            while x <= HALF_X - 2.0 + 1e-3 {
                columns.cylinder(Vec3::new(x, y0, z), radius, col_h, 14);
                columns.cuboid(
                    Vec3::new(x - 0.5, y0 + col_h, z - 0.5),
                    Vec3::new(x + 0.5, y0 + col_h + 0.25, z + 0.5),
                );
                if x + spacing <= HALF_X - 2.0 + 1e-3 {
                    arches.arch_x(
                        Vec3::new(x + spacing * 0.5, y0 + col_h + 0.25, z),
                        spacing * 0.5 - 0.5,
                        0.45,
                        0.9,
                        10,
                    );
                }
                x += spacing;
            }
            // Entablature above the arches.
            let top = y0 + col_h + 0.25 + spacing * 0.5;
            gallery.cuboid(
                Vec3::new(-HALF_X, top - 0.05, z - 0.45),
                Vec3::new(HALF_X, top + 0.4, z + 0.45),
            );
        }
        // Gallery floor between the arcade and the wall.
        let (z0, z1) = if side < 0.0 {
            (-HALF_Z, z - 0.45)
        } else {
            (z + 0.45, HALF_Z)
        };
        gallery.cuboid(
            Vec3::new(-HALF_X, STOREY, z0),
            Vec3::new(HALF_X, STOREY + 0.4, z1),
        );
        // Balustrade of the gallery.
        gallery.cuboid(
            Vec3::new(-HALF_X, STOREY + 0.4, z - 0.15),
            Vec3::new(HALF_X, STOREY + 1.3, z + 0.15),
        );
    }
    push(
        &mut scene,
        columns.build_fixed(),
        Material::glossy("marble", Vec3::new(0.85, 0.84, 0.8), Vec3::splat(0.5), 96.0),
    );
    push(
        &mut scene,
        arches.build_fixed(),
        Material::flat("arches", Vec3::new(0.78, 0.6, 0.45)),
    );
    push(
        &mut scene,
        gallery.build_fixed(),
        Material::flat("gallery", Vec3::new(0.6, 0.58, 0.55)),
    );

    let mut fountain = MeshBuilder::new();
    fountain
        .cylinder(Vec3::new(0.0, 0.0, 0.0), 2.4, 0.6, 32)
        .cylinder(Vec3::new(0.0, 0.6, 0.0), 0.35, 1.6, 16)
        .cylinder(Vec3::new(0.0, 2.2, 0.0), 1.0, 0.25, 24);
    push(
        &mut scene,
        fountain.build_fixed(),
        Material::glossy(
            "fountain",
            Vec3::new(0.3, 0.45, 0.55),
            Vec3::splat(0.6),
            128.0,
        ),
    );

    scene.camera = Camera::perspective(
        DVec3::new(-18.5, 3.0, 1.5),
        DVec3::new(6.0, 3.6, -1.0),
        62.0,
        0.1,
        80.0,
    );
    let volume = Aabb {
        min: DVec3::new(-HALF_X as f64 + 0.5, 0.3, -HALF_Z as f64 + 0.5),
        max: DVec3::new(
            HALF_X as f64 - 0.5,
            2.0 * STOREY as f64 + 2.0,
            HALF_Z as f64 - 0.5,
        ),
    };
    (scene, volume, LightSetStyle::Mixed)
}

fn bubbles() -> (Scene, Aabb, LightSetStyle) {
    let (mut scene, volume, style) = courtyard();
    // Deterministic placement along the view down the courtyard, nearest first.
    for i in 0..14 {
        let f = i as f32;
        let centre = Vec3::new(
            -13.0 + f * 1.9,
            1.6 + (f * 1.3).sin().abs() * 3.5,
            (f * 2.1).sin() * 4.5,
        );
        let radius = 0.6 + 0.5 * (f * 0.7).cos().abs();
        let tint = Vec3::new(
            0.4 + 0.5 * (f * 0.9).sin().abs(),
            0.6,
            0.4 + 0.5 * (f * 0.5).cos().abs(),
        );
        let mut mesh = MeshBuilder::new();
        mesh.sphere(centre, radius, 24, 12);
        let material = Material {
            alpha: 0.3 + 0.04 * (i % 5) as f32,
            ..Material::glossy(&format!("bubble{i}"), tint, Vec3::splat(0.8), 128.0)
        };
        push(&mut scene, mesh.build_fixed(), material);
    }
    (scene, volume, style)
}

fn pillars() -> (Scene, Aabb, LightSetStyle) {
    let mut scene = Scene::empty();
    let mut floor = MeshBuilder::new();
    floor.cuboid(Vec3::new(-15.0, -0.2, -20.0), Vec3::new(15.0, 0.0, 15.0));
    push(
        &mut scene,
        floor.build_fixed(),
        Material::flat("floor", Vec3::new(0.5, 0.5, 0.52)),
    );
    let mut pillars = MeshBuilder::new();
    // A jittered 14 × 16 grid, deterministic (a tiny hash, not the light RNG, so adding lights
    // never moves the pillars).
    for i in 0..14 {
        for j in 0..16 {
            let hash = ((i * 73 + j * 151) % 97) as f32 / 97.0;
            let x = -13.0 + i as f32 * 2.0 + (hash - 0.5) * 1.2;
            let z = -18.0 + j as f32 * 2.0 + (0.5 - hash) * 1.2;
            let w = 0.12 + 0.1 * hash;
            pillars.cuboid(
                Vec3::new(x - w, 0.0, z - w),
                Vec3::new(x + w, 5.0 + 3.0 * hash, z + w),
            );
        }
    }
    push(
        &mut scene,
        pillars.build_fixed(),
        Material::glossy(
            "pillars",
            Vec3::new(0.75, 0.72, 0.68),
            Vec3::splat(0.3),
            64.0,
        ),
    );
    scene.camera = Camera::perspective(
        DVec3::new(0.5, 2.2, 16.0),
        DVec3::new(0.0, 2.0, 0.0),
        60.0,
        0.1,
        60.0,
    );
    let volume = Aabb {
        min: DVec3::new(-14.0, 0.2, -19.0),
        max: DVec3::new(14.0, 7.0, 14.0),
    };
    (scene, volume, LightSetStyle::Mixed)
}

/// The analytic scene: a 16 × 16 quad at z = 0 facing +Z, camera at (0, 0, 5) looking at the
/// origin, so every pixel's surface point is a ray–plane intersection.
fn plane() -> (Scene, Aabb, LightSetStyle) {
    let mut scene = Scene::empty();
    let mut quad = MeshBuilder::new();
    let s = 8.0;
    quad.quad(
        Vec3::new(-s, -s, 0.0),
        Vec3::new(s, -s, 0.0),
        Vec3::new(s, s, 0.0),
        Vec3::new(-s, s, 0.0),
    );
    push(
        &mut scene,
        quad.build_fixed(),
        Material::glossy("plane", Vec3::splat(0.8), Vec3::splat(0.25), 24.0),
    );
    scene.camera = Camera::perspective(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, 60.0, 0.1, 50.0);
    let volume = Aabb {
        min: DVec3::new(-5.0, -3.0, 0.1),
        max: DVec3::new(5.0, 3.0, 2.5),
    };
    (scene, volume, LightSetStyle::PointsOnly)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_builds_validates_and_has_geometry() {
        for name in NAMES {
            let scene = build(name, Some((100, 1))).unwrap();
            scene.validate().unwrap();
            assert!(!scene.objects.is_empty(), "{name} has no geometry");
            assert_eq!(scene.lights.len(), 100);
        }
        assert!(matches!(
            build("nope", None),
            Err(SceneError::UnknownBuiltin { .. })
        ));
    }

    /// A projective object transform drew a wrong picture or none, unsaid; an affine one
    /// that rounding left a little off (an inverse's) is kept.
    #[test]
    fn an_object_transform_that_is_not_affine_is_refused_naming_it() {
        let mut scene = build("plane", None).unwrap();
        let turned = DMat4::from_rotation_y(0.3) * DMat4::from_translation(DVec3::X);
        scene.objects[0].transform = turned.inverse().inverse();
        scene.validate().unwrap();
        let mut projective = DMat4::IDENTITY;
        projective.x_axis.w = 0.5;
        scene.objects[0].transform = projective;
        let e = scene.validate().unwrap_err().to_string();
        assert!(
            e.contains("objects[0].transform") && e.contains("affine"),
            "{e}"
        );
        // A tiny value reads as one: it was written out in 300 digits.
        projective.x_axis.w = 1e-300;
        projective.w_axis.w = 0.0;
        scene.objects[0].transform = projective;
        let e = scene.validate().unwrap_err().to_string();
        assert!(e.contains("last row 1e-300 0 0 0,") && e.len() < 200, "{e}");
    }

    #[test]
    fn lights_are_seeded() {
        let a = build("courtyard", Some((50, 9))).unwrap().lights;
        let b = build("courtyard", Some((50, 9))).unwrap().lights;
        let c = build("courtyard", Some((50, 10))).unwrap().lights;
        assert_eq!(a, b);
        assert_ne!(a, c);
    }
}
