//! Triangles too large for `f32` interpolation near the camera are split on the CPU in `f64`.
//!
//! A fragment's view position is interpolated from its triangle's vertices in `f32` (clipping
//! too), so it is off by about 2⁻²⁴ of the vertices' distance from the eye. Near a triangle
//! much larger than its distance from the eye that error is a visible part of the distance
//! itself: a plane scaled 10⁸ seen from 5 m was half black, at 10⁶ its light sat off centre.
//! Such an object is drawn, for the frame, from a copy of its mesh in camera-relative world
//! space whose triangles near the eye are cut in two across their longest edge until none is
//! longer than [`reach::MAX_TRIANGLE_REACH`] times its distance. Only those near the eye are
//! cut, and a long, thin triangle only along its length, so a plane seen from close by takes
//! a few hundred pieces however unevenly it is scaled; a frame makes at most
//! [`MAX_SPLIT_TRIANGLES`] new ones, and past that draws the rest uncut.
//!
//! A triangle in view is also cut until it spans at most [`reach::MAX_TRIANGLE_SPAN_PX`]
//! pixels: SwiftShader drew a plane seen through a 0.001° lens, or a 10⁻⁵-high orthographic
//! view, unlit past about 2²⁷ pixels a triangle and not at all past 2²⁸, without an error.

use glam::{DMat3, DMat4, DVec2, DVec3, DVec4};

use super::normal_matrix::normal_matrix;
use super::{Aabb, Mesh, Object, Scene};

mod reach;

use reach::Reach;

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

/// The objects of `scene` that need splitting this frame of `frame` pixels (width, height),
/// each with its split mesh in camera-relative world space (drawn with the model matrix
/// `translation(eye)`). `measure` gives an object's longest edge in object space and its world
/// bounds (kept by the caller per mesh); objects whose longest edge and bounds clear the
/// limit cost one test.
pub fn split_objects(
    scene: &Scene,
    frame: (u32, u32),
    measure: impl Fn(&Object) -> (f64, Option<Aabb>),
) -> Splits {
    let reach = Reach::new(&scene.camera, frame);
    split_objects_within(scene, &reach, measure, MAX_SPLIT_TRIANGLES)
}

/// [`split_objects`] with a budget of `budget` cuts.
fn split_objects_within(
    scene: &Scene,
    reach: &Reach,
    measure: impl Fn(&Object) -> (f64, Option<Aabb>),
    mut budget: usize,
) -> Splits {
    let eye = scene.camera.position;
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
        let seen = || bounds.is_some_and(|b| reach.may_see(b.corners().map(|c| c - eye)));
        if !reach.exceeded(longest, distance, 1.0, seen) {
            continue;
        }
        let cuts_left = budget;
        let split = split_mesh(&object.mesh, &object.transform, eye, reach, &mut budget);
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

/// An upper bound of how much `m` lengthens a vector (3 × its largest entry bounds the
/// Frobenius norm, which bounds the stretch).
fn largest_scale(m: &DMat4) -> f64 {
    let cols = [m.x_axis, m.y_axis, m.z_axis].map(|c| c.truncate().abs().max_element());
    cols.into_iter().fold(0.0, f64::max) * 3.0
}

/// A vertex being split: camera-relative world position, world normal, texture coordinates.
#[derive(Clone, Copy)]
struct Vertex {
    p: DVec3,
    n: DVec3,
    uv: DVec2,
    uv1: DVec2,
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
            uv1: (a.uv1 + b.uv1) * 0.5,
            color: (a.color + b.color) * 0.5,
            tangent: ((a.tangent + b.tangent) * 0.5).with_w(a.tangent.w),
        }
    }
}

/// Whether triangle `abc` (relative to the eye) is longer than `reach` allows at its distance
/// and place, measured in units of its largest coordinate so no square leaves f64.
fn too_long(a: DVec3, b: DVec3, c: DVec3, reach: &Reach) -> bool {
    let unit = [a, b, c]
        .iter()
        .map(|v| v.abs().max_element())
        .fold(0.0, f64::max);
    if !(unit > 0.0 && unit.is_finite()) {
        return false;
    }
    let placed = [a, b, c];
    let [a, b, c] = placed.map(|v| v / unit);
    let edge = a.distance(b).max(b.distance(c)).max(c.distance(a));
    let distance = closest_point(a, b, c).length();
    let distance = if distance.is_finite() {
        distance
    } else {
        a.length().min(b.length()).min(c.length())
    };
    reach.exceeded(edge, distance, unit, || reach.may_see(placed))
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
    reach: &Reach,
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
            uv1: mesh.second_uvs.get(i).map_or(DVec2::ZERO, |t| t.as_dvec2()),
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
        .any(|[a, b, c]| too_long(a.p, b.p, c.p, reach))
    {
        return None;
    }
    let mut out = Mesh::default();
    let mut stack: Vec<([Vertex; 3], u32)> = placed.into_iter().map(|t| (t, 0)).collect();
    let mut cut_short = false;
    while let Some(([a, b, c], depth)) = stack.pop() {
        if depth < MAX_CUTS && too_long(a.p, b.p, c.p, reach) {
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
            out.uvs.push(v.uv.as_vec2());
            out.second_uvs.push(v.uv1.as_vec2());
            out.colors.push(v.color.as_vec4());
            out.tangents.push(v.tangent.as_vec4());
        }
    }
    if mesh.uvs.is_empty() {
        out.uvs.clear();
    }
    if mesh.second_uvs.is_empty() {
        out.second_uvs.clear();
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
mod tests;
