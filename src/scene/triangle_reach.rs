//! Triangles too large for `f32` interpolation near the camera are split on the CPU in `f64`.
//!
//! A fragment's view position is interpolated from its triangle's vertices in `f32` (clipping
//! too), so it is off by about 2⁻²⁴ of the vertices' distance from the eye. Near a triangle
//! much larger than its distance from the eye that error is a visible part of the distance
//! itself: a plane scaled 10⁸ seen from 5 m was half black, at 10⁶ its light sat off centre.
//! Such an object is drawn, for the frame, from a copy of its mesh in camera-relative world
//! space whose triangles near the eye are cut in two across their longest edge until none is
//! longer than [`MAX_TRIANGLE_REACH`] times its distance. Only those near the eye are cut,
//! and a long, thin triangle only along its length, so a plane seen from close by takes a few
//! hundred pieces however unevenly it is scaled; a frame makes at most
//! [`MAX_SPLIT_TRIANGLES`] new ones, and past that draws the rest uncut.

use glam::{DMat3, DMat4, DVec2, DVec3, DVec4, Vec2};

use super::normal_matrix::normal_matrix;
use super::{Aabb, Camera, Mesh, Object, Projection, Scene};

/// Largest ratio of a triangle's longest edge to its distance from the eye (at least the near
/// plane's) that is drawn as it is: positions are then within about 10⁻³ of their distance.
pub const MAX_TRIANGLE_REACH: f64 = 16384.0;

/// Most cuts in one triangle's line: two cuts leave its longest edge at most √3/2 as long, so
/// 600 leave at most 2⁻⁶² of it, below any near plane that edge could need.
const MAX_CUTS: u32 = 600;

/// Most triangles a frame's splits add (each cut adds one), over all objects: about 12 MiB
/// besides the split objects' own triangles, which their copies hold too. Past it the
/// remaining triangles are drawn as they are, with a warning; the budget goes to the objects
/// in scene order.
pub const MAX_SPLIT_TRIANGLES: usize = 1 << 16;

/// A frame's split copies: per object that needs one, its index and split mesh.
pub struct Splits {
    pub meshes: Vec<(usize, Mesh)>,
    /// The first object whose split ran out of [`MAX_SPLIT_TRIANGLES`].
    pub cut_short: Option<usize>,
}

/// The longest triangle edge of a mesh in object space (0 without triangles).
pub fn longest_edge(mesh: &Mesh) -> f64 {
    mesh.indices
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| mesh.positions[i as usize].as_dvec3());
            a.distance(b).max(b.distance(c)).max(c.distance(a))
        })
        .fold(0.0, f64::max)
}

/// The objects of `scene` that need splitting this frame, each with its split mesh in
/// camera-relative world space (drawn with the model matrix `translation(eye)`). `measure`
/// gives an object's longest edge in object space and its world bounds (kept by the caller
/// per mesh); objects whose longest edge and bounds clear the limit cost one test.
pub fn split_objects(scene: &Scene, measure: impl Fn(&Object) -> (f64, Option<Aabb>)) -> Splits {
    split_objects_within(scene, measure, MAX_SPLIT_TRIANGLES)
}

/// [`split_objects`] with a budget of `budget` cuts.
fn split_objects_within(
    scene: &Scene,
    measure: impl Fn(&Object) -> (f64, Option<Aabb>),
    mut budget: usize,
) -> Splits {
    let camera = &scene.camera;
    let floor = closest_fragment(camera);
    let eye = camera.position;
    let mut out = Splits {
        meshes: Vec::new(),
        cut_short: None,
    };
    for (i, object) in scene.objects.iter().enumerate() {
        let scale = largest_scale(&object.transform);
        let (longest, bounds) = measure(object);
        let longest = longest * scale;
        let distance = bounds.map_or(f64::INFINITY, |b| {
            (b.min - eye).max(eye - b.max).max(DVec3::ZERO).length()
        });
        if longest <= MAX_TRIANGLE_REACH * distance.max(floor) {
            continue;
        }
        let cuts_left = budget;
        let split = split_mesh(&object.mesh, &object.transform, eye, floor, &mut budget);
        if let Some((mesh, cut_short)) = split {
            if cut_short {
                out.cut_short.get_or_insert(i);
            }
            // With no cut left the copy is the object as it is: drawn from its own mesh.
            if cuts_left > 0 {
                out.meshes.push((i, mesh));
            }
        }
    }
    out
}

/// How close to the eye a fragment can be: the near plane, or an orthographic view's height.
fn closest_fragment(camera: &Camera) -> f64 {
    match camera.projection {
        Projection::Perspective { near, .. } => near,
        Projection::Orthographic { height, near, .. } => height.max(near),
    }
}

/// An upper bound of how much `m` lengthens a vector (3 × its largest entry bounds the
/// Frobenius norm, which bounds the stretch).
fn largest_scale(m: &DMat4) -> f64 {
    let cols = [m.x_axis, m.y_axis, m.z_axis].map(|c| c.truncate().abs().max_element());
    cols.into_iter().fold(0.0, f64::max) * 3.0
}

/// A vertex being split: camera-relative world position, world normal, texture coordinate.
#[derive(Clone, Copy)]
struct Vertex {
    p: DVec3,
    n: DVec3,
    uv: DVec2,
    /// Vertex colour and tangent (bitangent sign in `w`), kept when the mesh has them.
    color: DVec4,
    tangent: DVec4,
}

impl Vertex {
    fn mid(a: &Vertex, b: &Vertex) -> Vertex {
        Vertex {
            p: (a.p + b.p) * 0.5,
            n: (a.n + b.n) * 0.5,
            uv: (a.uv + b.uv) * 0.5,
            color: (a.color + b.color) * 0.5,
            tangent: ((a.tangent + b.tangent) * 0.5).with_w(a.tangent.w),
        }
    }
}

/// Whether triangle `abc` (relative to the eye) is longer than the limit allows at its
/// distance, measured in units of its largest coordinate so no square leaves f64.
fn too_long(a: DVec3, b: DVec3, c: DVec3, floor: f64) -> bool {
    let unit = [a, b, c]
        .iter()
        .map(|v| v.abs().max_element())
        .fold(0.0, f64::max);
    if !(unit > 0.0 && unit.is_finite()) {
        return false;
    }
    let [a, b, c] = [a, b, c].map(|v| v / unit);
    let edge = a.distance(b).max(b.distance(c)).max(c.distance(a));
    let distance = closest_point(a, b, c).length();
    let distance = if distance.is_finite() {
        distance
    } else {
        a.length().min(b.length()).min(c.length())
    };
    edge > MAX_TRIANGLE_REACH * distance.max(floor / unit)
}

/// Triangle `[a, b, c]` turned (its winding kept) so that `a`–`b` is its longest edge,
/// measured in units of its largest coordinate difference so no square leaves f64.
fn longest_edge_first([a, b, c]: [Vertex; 3]) -> [Vertex; 3] {
    let edges = [b.p - a.p, c.p - b.p, a.p - c.p];
    let unit = edges
        .iter()
        .map(|e| e.abs().max_element())
        .fold(0.0, f64::max);
    if !(unit > 0.0 && unit.is_finite()) {
        return [a, b, c];
    }
    let [ab, bc, ca] = edges.map(|e| (e / unit).length_squared());
    if ab >= bc && ab >= ca {
        [a, b, c]
    } else if bc >= ca {
        [b, c, a]
    } else {
        [c, a, b]
    }
}

/// `mesh` placed by `transform`, relative to `eye`, with the triangles too long for their
/// distance cut in two across their longest edge until they are not, each cut taken from
/// `budget`, and whether one was left too long for want of budget; `None` when no triangle
/// needs it (or the placed mesh is not finite, which no split can mend).
fn split_mesh(
    mesh: &Mesh,
    transform: &DMat4,
    eye: DVec3,
    floor: f64,
    budget: &mut usize,
) -> Option<(Mesh, bool)> {
    let linear = DMat3::from_mat4(*transform);
    let normals = normal_matrix(&linear);
    // A mirroring transform flips the bitangent's handedness; the split copy is drawn
    // unmirrored, so the flip is baked into `w`.
    let mirrored = super::normal_matrix::mirrors(&linear);
    let handedness = if mirrored { -1.0 } else { 1.0 };
    let vertex = |i: u32| {
        let i = i as usize;
        Vertex {
            p: transform.transform_point3(mesh.positions[i].as_dvec3()) - eye,
            n: normals * mesh.normals[i].as_dvec3(),
            uv: mesh.uvs.get(i).map_or(DVec2::ZERO, |t| t.as_dvec2()),
            color: mesh.colors.get(i).map_or(DVec4::ONE, |c| c.as_dvec4()),
            tangent: mesh.tangents.get(i).map_or(DVec4::X, |t| {
                let t = t.as_dvec4();
                transform
                    .transform_vector3(t.truncate())
                    .extend(t.w * handedness)
            }),
        }
    };
    // The copy is drawn unmirrored, so a mirroring transform's triangles are wound the other
    // way to keep their front faces on their normals' side.
    let (second, third) = if mirrored { (2, 1) } else { (1, 2) };
    let placed: Vec<[Vertex; 3]> = mesh
        .indices
        .chunks_exact(3)
        .map(|t| [vertex(t[0]), vertex(t[second]), vertex(t[third])])
        .collect();
    if placed.iter().flatten().any(|v| !v.p.is_finite()) {
        return None;
    }
    if !placed
        .iter()
        .any(|[a, b, c]| too_long(a.p, b.p, c.p, floor))
    {
        return None;
    }
    let mut out = Mesh::default();
    let mut stack: Vec<([Vertex; 3], u32)> = placed.into_iter().map(|t| (t, 0)).collect();
    let mut cut_short = false;
    while let Some(([a, b, c], depth)) = stack.pop() {
        if depth < MAX_CUTS && too_long(a.p, b.p, c.p, floor) {
            if *budget == 0 {
                cut_short = true;
            } else {
                // Across the longest edge only: a long, thin triangle is cut along its length,
                // never across its width, so its pieces grow with the levels, not its area.
                *budget -= 1;
                let [a, b, c] = longest_edge_first([a, b, c]);
                let m = Vertex::mid(&a, &b);
                stack.push(([a, m, c], depth + 1));
                stack.push(([m, b, c], depth + 1));
                continue;
            }
        }
        for v in [a, b, c] {
            out.indices.push(out.positions.len() as u32);
            out.positions.push(v.p.as_vec3());
            out.normals.push(v.n.as_vec3());
            out.uvs.push(Vec2::new(v.uv.x as f32, v.uv.y as f32));
            out.colors.push(v.color.as_vec4());
            out.tangents.push(v.tangent.as_vec4());
        }
    }
    if mesh.uvs.is_empty() {
        out.uvs.clear();
    }
    if mesh.colors.is_empty() {
        out.colors.clear();
    }
    if mesh.tangents.is_empty() {
        out.tangents.clear();
    }
    Some((out, cut_short))
}

/// The point of triangle `abc` closest to the origin (Ericson, Real-Time Collision Detection,
/// 5.1.5).
fn closest_point(a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, -a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = -b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = -c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let split = split_mesh(&quad(), transform, eye, 0.1, &mut budget);
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
            assert!(!too_long(a, b, c, 0.1));
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
        let splits = split_objects(&scene, measure);
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
        assert!(split_objects(&scene, measure).cut_short.is_none());
        // A budget the first object spends exactly: a later one that needs no split is not
        // named (it was, unchecked), one that needs a split is.
        let cuts = split_objects(&scene, measure).meshes[0].1.triangle_count() - 2;
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
        let splits = split_objects_within(&scene, measure, cuts);
        assert_eq!(splits.cut_short, None);
        assert_eq!(splits.meshes.len(), 1);
        scene.objects[1] = scene.objects[0].clone();
        assert_eq!(
            split_objects_within(&scene, measure, cuts).cut_short,
            Some(1)
        );
    }

    #[test]
    fn splits_stop_at_the_budget_and_say_so() {
        let eye = DVec3::new(0.0, 0.0, 5.0);
        let transform = DMat4::from_scale(DVec3::new(1e8, 1e8, 1.0));
        let mut budget = 10;
        let (mesh, cut_short) = split_mesh(&quad(), &transform, eye, 0.1, &mut budget).unwrap();
        assert!(cut_short);
        assert_eq!(budget, 0);
        // Each cut adds one triangle to the quad's two.
        assert_eq!(mesh.triangle_count(), 12);
        let mut budget = MAX_SPLIT_TRIANGLES;
        let (_, cut_short) = split_mesh(&quad(), &transform, eye, 0.1, &mut budget).unwrap();
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
        assert!(too_long(a, b, c, 1.0));
        assert!(!too_long(a * 1e-20, b * 1e-20, c * 1e-20, 1e180));
    }
}
