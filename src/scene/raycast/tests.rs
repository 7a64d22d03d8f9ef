//! The ray caster against a brute force over world-space triangles.

use std::sync::Arc;

use glam::Vec3;
use rand::{Rng, SeedableRng};

use super::*;
use crate::scene::{Material, Mesh, Object};

fn scene_of(meshes: Vec<(Mesh, DMat4)>) -> Scene {
    let mut scene = Scene::empty();
    let material = scene.add_material(Material::default());
    for (mesh, transform) in meshes {
        scene.objects.push(Object {
            mesh: Arc::new(mesh),
            material,
            transform,
        });
    }
    scene
}

fn triangle_at(z: f32) -> Mesh {
    let p = vec![
        Vec3::new(-5.0, -5.0, z),
        Vec3::new(5.0, -5.0, z),
        Vec3::new(0.0, 5.0, z),
    ];
    Mesh::new(p, vec![], vec![], vec![0, 1, 2]).unwrap()
}

#[test]
fn quad_hit_point_and_interpolated_normal() {
    // Normals tilt along x only, so the interpolation is the same on both triangles.
    let a = std::f32::consts::FRAC_1_SQRT_2;
    let (left, right) = (Vec3::new(-a, 0.0, a), Vec3::new(a, 0.0, a));
    let quad = Mesh::new(
        vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ],
        vec![left, right, right, left],
        vec![],
        vec![0, 1, 2, 0, 2, 3],
    )
    .unwrap();
    // Non-uniform scale: the normal goes through the inverse transpose, x halved.
    let transform = DMat4::from_translation(DVec3::new(0.0, 0.0, -3.0))
        * DMat4::from_scale(DVec3::new(2.0, 1.0, 1.0));
    let rc = SceneRaycaster::new(&scene_of(vec![(quad, transform)]));
    assert_eq!(rc.triangle_count(), 2);

    let h = rc.hit(DVec3::new(1.0, 0.3, 5.0), -DVec3::Z).unwrap();
    assert!((h.t - 8.0).abs() < 1e-12);
    assert!((h.position - DVec3::new(1.0, 0.3, -3.0)).length() < 1e-12);
    // World x = 1 is object x = 0.5: a quarter of `left` and three quarters of `right`
    // give (0.5a, 0, a) in object space, (0.25a, 0, a) after the normal matrix.
    let expected = DVec3::new(0.25, 0.0, 1.0).normalize();
    assert!((h.normal - expected).length() < 1e-6, "{:?}", h.normal);
    assert_eq!((h.object, h.triangle), (0, 0)); // below the diagonal: triangle 0, 1, 2
    let other = rc.hit(DVec3::new(-1.0, 0.3, 5.0), -DVec3::Z).unwrap();
    assert_eq!(other.triangle, 1);

    assert!((h.face - DVec3::Z).length() < 1e-12, "{}", h.face);
    // Back face: hit too, the same unflipped normal and face.
    let back = rc.hit(DVec3::new(1.0, 0.3, -10.0), DVec3::Z).unwrap();
    assert!((back.t - 7.0).abs() < 1e-12);
    assert!((back.normal - expected).length() < 1e-6);
    assert!((back.face - DVec3::Z).length() < 1e-12);
    // Behind the origin or beside the quad: no hit.
    assert!(rc.hit(DVec3::new(1.0, 0.3, -10.0), -DVec3::Z).is_none());
    assert!(rc.hit(DVec3::new(2.5, 0.0, 5.0), -DVec3::Z).is_none());
}

#[test]
fn nearest_of_two_overlapping_triangles() {
    let rc = SceneRaycaster::new(&scene_of(vec![
        (triangle_at(-1.0), DMat4::IDENTITY),
        (triangle_at(0.0), DMat4::IDENTITY),
    ]));
    let from_front = rc.hit(DVec3::new(0.0, 0.0, 5.0), -DVec3::Z).unwrap();
    assert_eq!(from_front.object, 1);
    assert!((from_front.t - 5.0).abs() < 1e-12);
    let from_back = rc.hit(DVec3::new(0.0, 0.0, -5.0), DVec3::Z).unwrap();
    assert_eq!(from_back.object, 0);
    assert!((from_back.t - 4.0).abs() < 1e-12);

    // Object 1 see-through: the opaque hit is object 0, with object 1 in front of it.
    let r = rc.first_opaque_hit(DVec3::new(0.0, 0.0, 5.0), -DVec3::Z, f64::INFINITY, |o| {
        o == 0
    });
    assert_eq!(r.hit.unwrap().object, 0);
    assert_eq!(r.transparent_t, Some(5.0));
    // The ray ends before the opaque one: only the transparent surface is reported.
    let r = rc.first_opaque_hit(DVec3::new(0.0, 0.0, 5.0), -DVec3::Z, 5.5, |o| o == 0);
    assert_eq!((r.hit, r.transparent_t), (None, Some(5.0)));
    // A transparent surface behind the opaque one is not reported.
    let r = rc.first_opaque_hit(DVec3::new(0.0, 0.0, 5.0), -DVec3::Z, f64::INFINITY, |o| {
        o == 1
    });
    assert_eq!((r.hit.unwrap().object, r.transparent_t), (1, None));
}

/// A face doubled within the depth a GPU can resolve is ambiguous; one 1 % behind is not.
#[test]
fn a_nearly_coplanar_second_surface_is_reported() {
    let doubled = SceneRaycaster::new(&scene_of(vec![
        (triangle_at(0.0), DMat4::IDENTITY),
        (triangle_at(-0.0001), DMat4::IDENTITY),
    ]));
    let r = doubled.first_opaque_hit(DVec3::new(0.0, 0.0, 5.0), -DVec3::Z, f64::INFINITY, |_| {
        true
    });
    assert_eq!(r.hit.unwrap().object, 0);
    assert!((r.runner_up_t.unwrap() - 5.0001).abs() < 1e-9);
    let apart = SceneRaycaster::new(&scene_of(vec![
        (triangle_at(0.0), DMat4::IDENTITY),
        (triangle_at(-0.05), DMat4::IDENTITY),
    ]));
    let r = apart.first_opaque_hit(DVec3::new(0.0, 0.0, 5.0), -DVec3::Z, f64::INFINITY, |_| {
        true
    });
    assert_eq!((r.hit.unwrap().object, r.runner_up_t), (0, None));
}

/// The nearest hits found the simple way: every triangle of every object carried to world
/// space and tested (what the caster did before it was instance-aware), with the normal
/// interpolated from world-space barycentrics; a single-sided material's triangle only where
/// the ray meets its front (its winding's normal, carried as a normal, faces the ray).
fn brute_force(
    scene: &Scene,
    origin: DVec3,
    dir: DVec3,
    opaque: impl Fn(usize) -> bool,
) -> (Option<Hit>, Option<f64>) {
    let (mut best, mut transparent) = (None::<Hit>, f64::INFINITY);
    for (object, o) in scene.objects.iter().enumerate() {
        let m = &o.mesh;
        let nm = crate::scene::normal_matrix::normal_matrix(&DMat3::from_mat4(o.transform));
        for triangle in 0..m.triangle_count() {
            let c = corners(m, triangle as u32);
            let v = c.map(|i| o.transform.transform_point3(m.positions[i].as_dvec3()));
            let Some((t, u, w, _)) = intersect(v, origin, dir) else {
                continue;
            };
            // The object-space winding's normal carried as a normal is, by definition,
            // the front side's.
            let p = c.map(|i| m.positions[i].as_dvec3());
            let face = (nm * (p[1] - p[0]).cross(p[2] - p[0])).normalize();
            if !scene.materials[o.material].double_sided && dir.dot(face) >= 0.0 {
                continue;
            }
            if !opaque(object) {
                transparent = transparent.min(t);
            } else if best.is_none_or(|b| t < b.t) {
                let n = c.map(|i| {
                    crate::scene::direction::unit(nm * m.normals[i].as_dvec3())
                        .unwrap_or(DVec3::ZERO)
                });
                best = Some(Hit {
                    t,
                    position: origin + dir * t,
                    normal: (n[0] * (1.0 - u - w) + n[1] * u + n[2] * w).normalize(),
                    face,
                    object,
                    triangle,
                });
            }
        }
    }
    let limit = best.map_or(f64::INFINITY, |b| b.t);
    (best, (transparent <= limit).then_some(transparent))
}

fn close(a: f64, b: f64) -> bool {
    a == b || (a - b).abs() <= 1e-9 * a.abs().max(1.0)
}

/// Casts `rays` random rays at `scene` and checks every hit against [`brute_force`]: the
/// same object and triangle, `t` and normal to rounding, the same transparent surface.
/// Returns (hits, rays with a transparent surface in front).
fn agrees_with_brute_force(
    scene: &Scene,
    rng: &mut rand_pcg::Pcg64,
    rays: usize,
    spread: f32,
    opaque: impl Fn(usize) -> bool + Copy,
) -> (usize, usize) {
    let rc = SceneRaycaster::new(scene);
    let (mut hits, mut transparent) = (0, 0);
    for _ in 0..rays {
        let origin = rand_point(rng, 2.0 * spread).as_dvec3();
        let dir = (rand_point(rng, 0.8 * spread).as_dvec3() - origin).normalize();
        for (opaque, name) in [
            (&(|_| true) as &dyn Fn(usize) -> bool, "all"),
            (&opaque, "some"),
        ] {
            let (want, want_t) = brute_force(scene, origin, dir, opaque);
            let got = rc.first_opaque_hit(origin, dir, f64::INFINITY, opaque);
            let same = match (got.hit, want) {
                (Some(g), Some(w)) => {
                    (g.object, g.triangle) == (w.object, w.triangle)
                        && close(g.t, w.t)
                        && (g.position - w.position).length() <= 1e-9 * w.t.max(1.0)
                        && (g.normal - w.normal).length() < 1e-6
                        && (g.face - w.face).length() < 1e-6
                }
                (g, w) => g.is_none() && w.is_none(),
            };
            assert!(same, "{name}: {:?} vs {want:?} ({origin}, {dir})", got.hit);
            match (got.transparent_t, want_t) {
                (Some(g), Some(w)) => assert!(close(g, w), "{g} vs {w}"),
                (g, w) => assert_eq!(g, w),
            }
            hits += got.hit.is_some() as usize;
            transparent += got.transparent_t.is_some() as usize;
        }
    }
    (hits, transparent)
}

fn rand_point(rng: &mut rand_pcg::Pcg64, s: f32) -> Vec3 {
    Vec3::new(
        rng.random_range(-s..s),
        rng.random_range(-s..s),
        rng.random_range(-s..s),
    )
}

/// `triangles` random small triangles within ±`size`, with random vertex normals.
fn random_mesh(rng: &mut rand_pcg::Pcg64, triangles: usize, size: f32) -> Mesh {
    let mut positions = Vec::new();
    for _ in 0..triangles {
        let c = rand_point(rng, size);
        for _ in 0..3 {
            positions.push(c + rand_point(rng, 0.08 * size));
        }
    }
    let normals = (0..positions.len())
        .map(|_| rand_point(rng, 1.0) + Vec3::Z * 1.5)
        .collect();
    let indices = (0..positions.len() as u32).collect();
    Mesh::new(positions, normals, vec![], indices).unwrap()
}

#[test]
fn bvh_agrees_with_brute_force() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
    // Several objects with transforms, so object and triangle indices are checked too.
    let mut meshes = Vec::new();
    for o in 0..4 {
        let mesh = random_mesh(&mut rng, 600, 10.0);
        let transform = DMat4::from_translation(DVec3::new(o as f64, 0.0, 0.0))
            * DMat4::from_rotation_y(o as f64 * 0.3);
        meshes.push((mesh, transform));
    }
    let scene = scene_of(meshes);
    let (hits, transparent) =
        agrees_with_brute_force(&scene, &mut rng, 1000, 10.0, |o| o.is_multiple_of(2));
    assert!(
        hits > 1000 && transparent > 250,
        "{hits} hits, {transparent}"
    );
}

/// One mesh placed many times — moved, rotated, mirrored, scaled unevenly, far from the
/// origin, flattened to a plane (no inverse: traced in world space) — is one hierarchy,
/// and every placement is hit where the world-space triangles are.
#[test]
fn repeated_placements_share_one_hierarchy_and_agree_with_brute_force() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
    let mesh = Arc::new(random_mesh(&mut rng, 300, 3.0));
    let mut scene = Scene::empty();
    let material = scene.add_material(Material::default());
    let transforms = [
        DMat4::IDENTITY,
        DMat4::from_translation(DVec3::new(4.0, 1.0, -2.0)) * DMat4::from_rotation_x(1.1),
        DMat4::from_translation(DVec3::new(-3.0, 2.0, 1.0))
            * DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)),
        DMat4::from_translation(DVec3::new(0.0, -4.0, 3.0))
            * DMat4::from_rotation_z(0.4)
            * DMat4::from_scale(DVec3::new(2.5, 0.3, 1.0)),
        DMat4::from_translation(DVec3::new(2.0, 3.0, 4.0))
            * DMat4::from_scale(DVec3::new(1.0, 1.0, 0.0)),
        DMat4::from_translation(DVec3::new(-4.0, -2.0, -3.0))
            * DMat4::from_scale(DVec3::new(0.5, 1e-12, 0.5)),
        DMat4::from_rotation_y(2.0) * DMat4::from_scale(DVec3::splat(-0.7)),
    ];
    for transform in transforms {
        scene.add_object(mesh.clone(), material, transform);
    }
    let rc = SceneRaycaster::new(&scene);
    assert_eq!(rc.mesh_count(), 1);
    assert_eq!(rc.triangle_count(), 300 * transforms.len());
    let flat = rc.instances.iter().filter(|i| i.to_object.is_none());
    // Squashed to 10⁻¹² still has an inverse that works; flattened to 0 has none.
    assert_eq!(
        flat.count(),
        1,
        "the flattened placement is traced in world space"
    );
    let (hits, transparent) = agrees_with_brute_force(&scene, &mut rng, 1500, 5.0, |o| o % 3 != 1);
    assert!(
        hits > 500 && transparent > 100,
        "{hits} hits, {transparent}"
    );

    // Far from the origin: the same, relative to the distance.
    let far = DMat4::from_translation(DVec3::new(3e6, -1e6, 2e6));
    for o in &mut scene.objects {
        o.transform = far * o.transform;
    }
    let rc = SceneRaycaster::new(&scene);
    let mut found = 0;
    for _ in 0..300 {
        let target = far.transform_point3(rand_point(&mut rng, 4.0).as_dvec3());
        let origin = target + rand_point(&mut rng, 20.0).as_dvec3();
        let dir = (target - origin).normalize();
        let (want, _) = brute_force(&scene, origin, dir, |_| true);
        let got = rc.hit(origin, dir);
        assert_eq!(
            got.map(|h| (h.object, h.triangle)),
            want.map(|w| (w.object, w.triangle))
        );
        if let (Some(g), Some(w)) = (got, want) {
            assert!((g.t - w.t).abs() < 1e-6, "{} vs {}", g.t, w.t);
            found += 1;
        }
    }
    assert!(found > 50, "{found}");
}

/// Single-sided placements of the same mesh (moved, mirrored, flattened) beside double-sided
/// ones: only their fronts are hit, where the brute force finds them, and a ray from behind
/// passes through them to what lies beyond.
#[test]
fn single_sided_placements_are_hit_on_their_front_only() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(8);
    let mesh = Arc::new(random_mesh(&mut rng, 300, 3.0));
    let mut scene = Scene::empty();
    let both = scene.add_material(Material::default());
    let front = scene.add_material(Material {
        double_sided: false,
        ..Material::default()
    });
    let transforms = [
        DMat4::IDENTITY,
        DMat4::from_translation(DVec3::new(-3.0, 2.0, 1.0))
            * DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)),
        DMat4::from_translation(DVec3::new(2.0, 3.0, 4.0))
            * DMat4::from_scale(DVec3::new(1.0, 1.0, 0.0)),
        DMat4::from_translation(DVec3::new(2.0, -3.0, -1.0))
            * DMat4::from_scale(DVec3::new(1.0, -1.0, 0.0)),
        // Nearly flat and mirroring: traced in world space, its winding turned round.
        DMat4::from_cols(
            DVec4::X,
            DVec4::Y,
            DVec4::new(0.6, 0.6, -1e-12, 0.0),
            DVec4::new(-1.0, 0.0, 2.0, 1.0),
        ),
        DMat4::from_rotation_y(2.0) * DMat4::from_scale(DVec3::splat(-0.7)),
    ];
    for (i, transform) in transforms.into_iter().enumerate() {
        scene.add_object(mesh.clone(), front, transform);
        if i < 2 {
            scene.add_object(mesh.clone(), both, transform * DMat4::from_rotation_x(0.5));
        }
    }
    let rc = SceneRaycaster::new(&scene);
    let world_mirrored = rc
        .instances
        .iter()
        .filter(|i| i.to_object.is_none() && i.mirrored);
    assert_eq!(
        world_mirrored.count(),
        1,
        "one mirrored placement in world space"
    );
    let (hits, transparent) = agrees_with_brute_force(&scene, &mut rng, 1500, 5.0, |o| o % 3 != 1);
    assert!(hits > 500 && transparent > 50, "{hits} hits, {transparent}");

    // One triangle facing +Z in front of a double-sided one: from +Z the front is hit, from −Z
    // the ray passes through to the one behind; mirrored, the other way round.
    for (mirror, seen_from) in [(1.0, 1.0), (-1.0, -1.0)] {
        let mut scene = Scene::empty();
        let both = scene.add_material(Material::default());
        let front = scene.add_material(Material {
            double_sided: false,
            ..Material::default()
        });
        let flip = DMat4::from_scale(DVec3::new(1.0, 1.0, mirror));
        scene.add_object(Arc::new(triangle_at(0.0)), front, flip);
        let behind = DMat4::from_translation(DVec3::new(0.0, 0.0, -2.0 * seen_from));
        scene.add_object(Arc::new(triangle_at(0.0)), both, behind);
        let rc = SceneRaycaster::new(&scene);
        let from = |z: f64| rc.hit(DVec3::new(0.0, 0.0, z), DVec3::new(0.0, 0.0, -z.signum()));
        assert_eq!(from(5.0 * seen_from).map(|h| h.object), Some(0));
        let through = from(-5.0 * seen_from).expect("the far triangle");
        assert_eq!(through.object, 1, "mirror {mirror}");
        // The front's face points at the eye it is seen from.
        let h = from(5.0 * seen_from).unwrap();
        assert!(h.face.z * seen_from > 0.99, "{:?}", h.face);
    }
}

/// The memory a placement costs does not depend on its mesh: 100 000 placements of a
/// 2 000-triangle mesh hold one mesh hierarchy and a fixed few hundred bytes each.
#[test]
fn memory_per_placement_is_constant() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
    let mesh = Arc::new(random_mesh(&mut rng, 2000, 1.0));
    let placed = |n: usize| {
        let mut scene = Scene::empty();
        let material = scene.add_material(Material::default());
        for i in 0..n {
            let at = DVec3::new((i % 400) as f64 * 3.0, (i / 400) as f64 * 3.0, 0.0);
            scene.add_object(mesh.clone(), material, DMat4::from_translation(at));
        }
        SceneRaycaster::new(&scene)
    };
    let (one, many) = (placed(1), placed(100_000));
    assert_eq!((one.mesh_count(), many.mesh_count()), (1, 1));
    assert_eq!(many.triangle_count(), 2000 * 100_000);
    let per_placement = (many.heap_bytes() - one.heap_bytes()) / 100_000;
    assert!(per_placement <= 400, "{per_placement} bytes a placement");
    // One mesh's hierarchy: about one node per two triangles and an index per triangle.
    assert!(one.heap_bytes() < 2000 * 64, "{} bytes", one.heap_bytes());
}

#[test]
fn pixel_ray_through_the_centre_points_at_the_target() {
    let position = DVec3::new(3.0, 2.0, 7.0);
    let target = DVec3::new(-1.0, 0.5, 0.0);
    let forward = (target - position).normalize();
    let projections = [
        Projection::Perspective {
            fov_y_deg: 50.0,
            near: 0.5,
            far: 100.0,
        },
        Projection::Perspective {
            fov_y_deg: 50.0,
            near: 0.5,
            far: f64::INFINITY,
        },
        Projection::Orthographic {
            height: 4.0,
            near: 0.5,
            far: 100.0,
        },
    ];
    for projection in projections {
        let cam = Camera {
            position,
            target,
            up: DVec3::Y,
            projection,
        };
        let (w, h) = (101, 75);
        let (o, d) = pixel_ray(&cam, w, h, 50.5, 37.5);
        assert!((d - forward).length() < 1e-9, "{projection:?}: {d:?}");
        assert!((o - (position + forward * 0.5)).length() < 1e-9, "{o:?}");
        // The top row looks up: row 0 is the top of the view.
        let (_, top) = pixel_ray(&cam, w, h, 50.5, 0.5);
        let (o_top, _) = pixel_ray(&cam, w, h, 50.5, 0.5);
        let up = forward.cross(DVec3::Y).cross(forward).normalize();
        assert!(top.dot(up) > -1e-12 && (o_top - o).dot(up) > 0.0);
        let (o_left, _) = pixel_ray(&cam, w, h, 0.5, 37.5);
        assert!((o_left - o).dot(forward.cross(DVec3::Y)) < 0.0); // column 0 is the left
    }
}

/// Rebuilding after objects moved keeps every mesh's hierarchy (one built for a new mesh
/// only) and casts what a caster built from scratch casts.
#[test]
fn a_rebuild_keeps_the_hierarchies_of_the_meshes_still_placed() {
    let shared = Arc::new(triangle_at(0.0));
    let mut scene = scene_of(vec![(triangle_at(-1.0), DMat4::IDENTITY)]);
    for x in [-2.0, 2.0] {
        scene.objects.push(Object {
            mesh: shared.clone(),
            material: 0,
            transform: DMat4::from_translation(DVec3::new(x, 0.0, -4.0)),
        });
    }
    let first = SceneRaycaster::new(&scene);
    assert_eq!(first.meshes_built(), 2, "two distinct meshes");
    scene.objects[1].transform = DMat4::from_translation(DVec3::new(-2.0, 1.0, -6.0));
    let moved = SceneRaycaster::rebuilt(Some(first.keep()), &scene);
    assert_eq!(moved.meshes_built(), 0);
    let fresh = SceneRaycaster::new(&scene);
    let mut rng = rand::rngs::StdRng::seed_from_u64(5);
    for _ in 0..200 {
        let dir = DVec3::new(
            rng.random_range(-0.6..0.6),
            rng.random_range(-0.6..0.6),
            -1.0,
        );
        let (a, b) = (
            moved.hit(DVec3::Z * 3.0, dir),
            fresh.hit(DVec3::Z * 3.0, dir),
        );
        assert_eq!(a.map(|h| h.position), b.map(|h| h.position), "{dir}");
    }
    // A mesh replaced by a new one is built; the one no object places any more is dropped.
    scene.objects[0].mesh = Arc::new(triangle_at(-2.0));
    let replaced = SceneRaycaster::rebuilt(Some(moved.keep()), &scene);
    assert_eq!((replaced.meshes_built(), replaced.mesh_count()), (1, 2));
}

/// A kept caster holds no mesh: one the scene drops is freed, and the caster no longer
/// wakes; while the scene keeps them all it wakes to the same hits.
#[test]
fn a_kept_caster_lets_dropped_meshes_go() {
    let mut scene = scene_of(vec![
        (triangle_at(-1.0), DMat4::IDENTITY),
        (triangle_at(-3.0), DMat4::IDENTITY),
    ]);
    let ray = (DVec3::Z * 3.0, DVec3::new(0.1, 0.0, -1.0));
    let first = SceneRaycaster::new(&scene);
    let hit = first.hit(ray.0, ray.1).map(|h| h.position);
    let woken = first.keep().wake().expect("the scene holds its meshes");
    assert_eq!(woken.hit(ray.0, ray.1).map(|h| h.position), hit);
    let kept = woken.keep();
    let nearer = Arc::downgrade(&scene.objects[0].mesh);
    scene.objects.remove(0);
    assert!(nearer.upgrade().is_none(), "the kept caster held the mesh");
    let kept = kept.wake().expect_err("a mesh is gone");
    let rebuilt = SceneRaycaster::rebuilt(Some(kept), &scene);
    assert_eq!((rebuilt.meshes_built(), rebuilt.mesh_count()), (0, 1));
    let far = rebuilt.hit(ray.0, ray.1).expect("the far triangle");
    assert!((far.position.z + 3.0).abs() < 1e-9, "{}", far.position);
    // A wake that fails past a live mesh holds that mesh no more than before.
    let kept = rebuilt.keep();
    scene.objects.push(Object {
        mesh: Arc::new(triangle_at(-5.0)),
        material: 0,
        transform: DMat4::IDENTITY,
    });
    let kept = SceneRaycaster::rebuilt(Some(kept), &scene).keep();
    scene.objects.pop();
    let back = kept.wake().expect_err("a mesh is gone");
    assert_eq!(Arc::strong_count(&scene.objects[0].mesh), 1);
    drop(back);
}

/// Half squares stacked over one another, whose boxes are whole squares: a ray through the
/// other half misses them all and tests each, whatever the hierarchy. Within enough work the
/// bounded search finds what the unbounded one does and leaves what it did not spend; with
/// less it says it ran out.
#[test]
fn a_bounded_search_finds_the_same_hit_or_says_it_ran_out() {
    let layers = 200;
    let half_square = |z: f32| {
        let p = vec![
            Vec3::new(-5.0, -5.0, z),
            Vec3::new(5.0, -5.0, z),
            Vec3::new(-5.0, 5.0, z),
        ];
        Mesh::new(p, vec![], vec![], vec![0, 1, 2]).unwrap()
    };
    let meshes = (0..layers)
        .map(|i| (half_square(-(i as f32) * 0.01), DMat4::IDENTITY))
        .collect();
    let rc = SceneRaycaster::new(&scene_of(meshes));
    let dir = -DVec3::Z;
    let (through, beside) = (DVec3::new(4.0, 4.0, 5.0), DVec3::new(-4.0, -4.0, 5.0));
    assert_eq!(rc.hit(through, dir), None);
    let mut work = u64::MAX;
    assert_eq!(rc.hit_within(through, dir, &mut work), Some(None));
    let spent = u64::MAX - work;
    assert!(spent >= layers, "{spent} tests for {layers} triangles");
    let mut just_enough = spent + 1;
    assert_eq!(rc.hit_within(through, dir, &mut just_enough), Some(None));
    assert_eq!(just_enough, 1);
    let mut short = spent / 2;
    assert_eq!(rc.hit_within(through, dir, &mut short), None);
    assert_eq!(short, 0);
    // A hit, the top layer, is found alike.
    let top = rc.hit(beside, dir).expect("the top layer");
    assert_eq!(top.position.z, 0.0);
    let mut work = u64::MAX;
    assert_eq!(rc.hit_within(beside, dir, &mut work), Some(Some(top)));
}
