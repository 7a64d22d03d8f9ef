//! The splits' unit tests.

use super::reach::MAX_TRIANGLE_SPAN_PX;
use super::*;
use crate::scene::{Camera, Projection};

#[test]
fn closest_point_finds_the_face_the_edge_and_the_corner() {
    let (a, b, c) = (
        DVec3::new(-1.0, -1.0, 2.0),
        DVec3::new(3.0, -1.0, 2.0),
        DVec3::new(-1.0, 3.0, 2.0),
    );
    assert_eq!(closest_point(a, b, c), DVec3::new(0.0, 0.0, 2.0));
    let shifted = DVec3::new(5.0, 5.0, 0.0);
    let edge = closest_point(a - shifted, b - shifted, c - shifted) + shifted;
    assert!(
        (edge - DVec3::new(1.0, 1.0, 2.0)).length() < 1e-12,
        "{edge}"
    );
    let far = DVec3::new(-9.0, -9.0, 0.0);
    assert_eq!(closest_point(a - far, b - far, c - far) + far, a);
}

fn quad() -> Mesh {
    let mut b = crate::MeshBuilder::new();
    b.quad(
        glam::Vec3::new(-1.0, -1.0, 0.0),
        glam::Vec3::new(1.0, -1.0, 0.0),
        glam::Vec3::new(1.0, 1.0, 0.0),
        glam::Vec3::new(-1.0, 1.0, 0.0),
    );
    b.build().unwrap()
}

/// [`split_mesh`] with the whole budget.
fn split(transform: &DMat4, eye: DVec3) -> Option<Mesh> {
    let mut budget = MAX_SPLIT_TRIANGLES;
    let split = split_mesh(
        &quad(),
        transform,
        eye,
        &Reach::distance_only(0.1),
        &mut budget,
    );
    split.map(|(mesh, cut_short)| {
        assert!(!cut_short);
        mesh
    })
}

/// Every triangle of `split` within the limit, all together `area`, normals +Z.
fn assert_split_within_the_limit(split: &Mesh, area: f64) {
    let mut sum = 0.0;
    for t in split.indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| split.positions[i as usize].as_dvec3());
        assert!(!too_long(a, b, c, &Reach::distance_only(0.1)));
        sum += (b - a).cross(c - a).length() * 0.5;
    }
    assert!(
        (sum / area - 1.0).abs() < 1e-4,
        "area {sum:e}, not {area:e}"
    );
    assert!(split.normals.iter().all(|n| n.normalize() == glam::Vec3::Z));
}

#[test]
fn only_triangles_too_long_for_their_distance_are_split() {
    let eye = DVec3::new(0.0, 0.0, 5.0);
    let scaled = |s: f64| DMat4::from_scale(DVec3::new(s, s, 1.0));
    assert!(split(&scaled(1e4), eye).is_none());
    let mesh = split(&scaled(1e8), eye).unwrap();
    let n = mesh.triangle_count();
    assert!(n > 2 && n < 2000, "{n} triangles");
    assert_split_within_the_limit(&mesh, 4e16);
    // Seen from within its own plane, the near plane bounds how close a fragment can be.
    assert!(split(&scaled(1e2), DVec3::ZERO).is_none());
    assert!(split(&scaled(1e4), DVec3::ZERO).is_some());
}

/// Cut in four, a quad scaled 10¹⁰ one way made pieces by the million (gigabytes, then an
/// abort): every level cut its whole width into rows. At 10⁷ that made 20 258 pieces, and
/// 60 638 sheared; cut across the longest edge, 442 and 492.
#[test]
fn a_long_thin_or_sheared_quad_splits_into_few_triangles() {
    let eye = DVec3::new(0.0, 0.0, 1.0);
    let thin = DMat4::from_scale(DVec3::new(1e7, 1.0, 1.0));
    let sheared = DMat4::from_cols(
        glam::DVec4::new(1e7, 0.0, 0.0, 0.0),
        glam::DVec4::new(1e7, 1.0, 0.0, 0.0),
        glam::DVec4::Z,
        glam::DVec4::W,
    );
    for (what, transform) in [("thin", thin), ("sheared", sheared)] {
        let area = 4e7;
        let mesh = split(&transform, eye).unwrap();
        let n = mesh.triangle_count();
        assert!(n > 2 && n < 2000, "{what}: {n} triangles");
        assert_split_within_the_limit(&mesh, area);
    }
}

/// Many objects each split near the eye: past the frame's budget the rest are drawn as
/// they are, and the first of them is named.
#[test]
fn a_frame_past_the_budget_names_the_first_object_left_unsplit() {
    let mut scene = Scene::empty();
    scene.camera = Camera::perspective(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, 60.0, 0.1, 50.0);
    let mesh = std::sync::Arc::new(quad());
    let transform = DMat4::from_scale(DVec3::new(1e8, 1e8, 1.0));
    for _ in 0..2000 {
        scene.objects.push(Object {
            mesh: mesh.clone(),
            material: 0,
            transform,
        });
    }
    let measure = |o: &Object| {
        let bounds = o.mesh.bounds().map(|b| b.transformed(&o.transform));
        (longest_edge(&o.mesh), bounds)
    };
    let splits = split_objects(&scene, (256, 144), measure);
    let first = splits.cut_short.expect("past the budget");
    assert!(first > 0 && first < 2000, "{first}");
    // Every object before it split whole; it and those after it as far as the budget went.
    assert!(splits.meshes.iter().all(|(i, _)| *i <= first));
    let added: usize = splits
        .meshes
        .iter()
        .map(|(_, m)| m.triangle_count() - 2)
        .sum();
    assert_eq!(added, MAX_SPLIT_TRIANGLES);
    // One object alone is within it.
    scene.objects.truncate(1);
    assert!(split_objects(&scene, (256, 144), measure)
        .cut_short
        .is_none());
    // A budget the first object spends exactly: a later one that needs no split is not
    // named (it was, unchecked), one that needs a split is.
    let cuts = split_objects(&scene, (256, 144), measure).meshes[0]
        .1
        .triangle_count()
        - 2;
    // Its bounds and longest edge pass the first test, its triangles not: a long one far
    // off, a small one near the eye.
    let (near, far) = (glam::Vec3::ZERO, glam::Vec3::new(1e5, 0.0, 0.0));
    let positions = vec![
        near,
        near + glam::Vec3::X * 0.1,
        near + glam::Vec3::Y * 0.1,
        far,
        far + glam::Vec3::X * 5e8,
        far + glam::Vec3::Y,
    ];
    let mesh = Mesh::new(positions, vec![], vec![], vec![0, 1, 2, 3, 4, 5]).unwrap();
    scene.objects.push(Object {
        mesh: std::sync::Arc::new(mesh),
        material: 0,
        transform: DMat4::IDENTITY,
    });
    let splits = split_objects_within(
        &scene,
        &Reach::new(&scene.camera, (256, 144)),
        measure,
        cuts,
    );
    assert_eq!(splits.cut_short, None);
    assert_eq!(splits.meshes.len(), 1);
    scene.objects[1] = scene.objects[0].clone();
    assert_eq!(
        split_objects_within(
            &scene,
            &Reach::new(&scene.camera, (256, 144)),
            measure,
            cuts
        )
        .cut_short,
        Some(1)
    );
}

/// The `plane` scene's quad (16 m a side) under `camera`, placed as it is.
fn plane_seen_by(camera: Camera) -> Scene {
    let mut scene = Scene::empty();
    scene.camera = camera;
    let mut quad = quad();
    quad.positions.iter_mut().for_each(|p| *p *= 8.0);
    scene.objects.push(Object {
        mesh: std::sync::Arc::new(quad),
        material: 0,
        transform: DMat4::IDENTITY,
    });
    scene
}

/// The splits of `scene`'s objects for a `frame`, each object's bounds and longest edge
/// measured from its mesh.
fn splits_of(scene: &Scene, frame: (u32, u32)) -> Splits {
    split_objects(scene, frame, |o: &Object| {
        let bounds = o.mesh.bounds().map(|b| b.transformed(&o.transform));
        (longest_edge(&o.mesh), bounds)
    })
}

/// A plane seen through a hair-thin lens, or in an orthographic view 10⁻⁶ high, spans
/// 10⁸–10⁹ pixels a triangle, past what SwiftShader draws: the triangles in view are cut
/// until none spans more than the limit, in a few hundred pieces; those out of view are
/// left long. The same plane seen at 60° is not cut.
#[test]
fn triangles_in_view_are_cut_to_the_pixels_they_may_span() {
    let (eye, target) = (DVec3::new(0.3, 0.2, 5.0), DVec3::new(0.3, 0.2, 0.0));
    let frame = (128, 72);
    let cases = [
        (
            "orthographic 1e-6",
            Camera {
                projection: Projection::Orthographic {
                    height: 1e-6,
                    near: 0.0,
                    far: 50.0,
                },
                ..Camera::perspective(eye, target, 60.0, 0.1, 50.0)
            },
        ),
        ("0.001°", Camera::perspective(eye, target, 0.001, 0.1, 50.0)),
    ];
    for (what, camera) in cases {
        let scene = plane_seen_by(camera);
        let splits = splits_of(&scene, frame);
        assert_eq!(splits.cut_short, None, "{what}");
        let [(0, mesh)] = &splits.meshes[..] else {
            panic!("{what}: {} split objects", splits.meshes.len());
        };
        let n = mesh.triangle_count();
        assert!(n > 2 && n < 2000, "{what}: {n} triangles");
        let reach = Reach::new(&scene.camera, frame);
        let rows = f64::from(frame.1);
        let (mut in_view, mut area) = (0, 0.0);
        for t in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| mesh.positions[i as usize].as_dvec3());
            assert!(!too_long(a, b, c, &reach), "{what}");
            area += (b - a).cross(c - a).length() * 0.5;
            if !reach.may_see([a, b, c]) {
                continue;
            }
            in_view += 1;
            // The pixels its longest edge spans at its distance from the eye.
            let pixel = match scene.camera.projection {
                Projection::Orthographic { height, .. } => height / rows,
                Projection::Perspective { fov_y_deg, .. } => {
                    let distance = closest_point(a, b, c).length();
                    2.0 * distance * (fov_y_deg.to_radians() / 2.0).tan() / rows
                }
            };
            let edge = a.distance(b).max(b.distance(c)).max(c.distance(a));
            assert!(
                edge / pixel <= MAX_TRIANGLE_SPAN_PX * 1.0001,
                "{what}: {:e}",
                edge / pixel
            );
        }
        assert!(
            in_view >= 1 && in_view < n,
            "{what}: {in_view} of {n} in view"
        );
        assert!((area / 256.0 - 1.0).abs() < 1e-6, "{what}: area {area}");
    }
    let wide = plane_seen_by(Camera::perspective(eye, target, 60.0, 0.1, 50.0));
    assert!(splits_of(&wide, frame).meshes.is_empty());
}

#[test]
fn splits_stop_at_the_budget_and_say_so() {
    let eye = DVec3::new(0.0, 0.0, 5.0);
    let transform = DMat4::from_scale(DVec3::new(1e8, 1e8, 1.0));
    let reach = Reach::distance_only(0.1);
    let split_within =
        |budget: &mut usize| split_mesh(&quad(), &transform, eye, &reach, budget).expect("a split");
    let mut budget = 10;
    let (mesh, cut_short) = split_within(&mut budget);
    assert!(cut_short);
    assert_eq!(budget, 0);
    // Each cut adds one triangle to the quad's two.
    assert_eq!(mesh.triangle_count(), 12);
    let mut budget = MAX_SPLIT_TRIANGLES;
    let (_, cut_short) = split_within(&mut budget);
    assert!(!cut_short);
    assert!(budget < MAX_SPLIT_TRIANGLES);
}

#[test]
fn a_mirrored_copy_keeps_its_front_faces_on_its_normals_side() {
    let eye = DVec3::new(0.0, 0.0, 5.0);
    for mirror in [1.0, -1.0] {
        let transform = DMat4::from_scale(DVec3::new(1e8 * mirror, 1e8, 1.0));
        let split = split(&transform, eye).unwrap();
        // Drawn unmirrored: each winding must face the way its normals do.
        for t in split.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| split.positions[i as usize]);
            let winding = (b - a).cross(c - a).as_dvec3();
            let normal = split.normals[t[0] as usize].as_dvec3();
            assert!(winding.dot(normal) > 0.0, "mirror {mirror}: {winding}");
        }
    }
}

#[test]
fn coordinates_whose_squares_overflow_still_measure() {
    let [a, b, c] = [
        DVec3::new(-1e200, -1e200, -5e190),
        DVec3::new(1e200, -1e200, -5e190),
        DVec3::new(0.0, 1e200, -5e190),
    ];
    assert!(too_long(a, b, c, &Reach::distance_only(1.0)));
    assert!(!too_long(
        a * 1e-20,
        b * 1e-20,
        c * 1e-20,
        &Reach::distance_only(1e180)
    ));
}
