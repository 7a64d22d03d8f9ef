//! Triangles too large for `f32` interpolation near the camera are refused, naming the object.
//!
//! A fragment's view position is interpolated from its triangle's vertices in `f32` (clipping
//! too), so it is off by about 2⁻²⁴ of the vertices' distance from the eye. Near a triangle
//! much larger than its distance from the eye that error is a visible part of the distance
//! itself: a plane scaled 10⁸ seen from 5 m was half black, at 10⁶ its light sat off centre.
//! Past [`MAX_TRIANGLE_REACH`] the frame is refused instead of drawn wrong.

use glam::{DMat4, DVec3};

use crate::gpu_scene::GpuScene;
use crate::scene::{Camera, Mesh, Projection, Scene};
use crate::Error;

/// Largest ratio of a triangle's longest edge to its distance from the eye (at least the near
/// plane's): positions are then within about 10⁻³ of their distance, a pixel at 1 000 pixels
/// across.
pub const MAX_TRIANGLE_REACH: f64 = 16384.0;

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

/// Refuses the frame when a triangle of an object is longer than [`MAX_TRIANGLE_REACH`] times
/// its distance from the eye. Objects whose longest edge and bounds clear the limit cost one
/// test; only the others are checked triangle by triangle (in `f64`).
pub fn check(scene: &Scene, gpu_scene: &GpuScene) -> Result<(), Error> {
    let camera = &scene.camera;
    let floor = closest_fragment(camera);
    let eye = camera.position;
    for (i, object) in scene.objects.iter().enumerate() {
        let scale = largest_scale(&object.transform);
        let longest = gpu_scene.longest_edge(object) * scale;
        let distance = gpu_scene
            .world_bounds(object)
            .map_or(f64::INFINITY, |b| (b.min - eye).max(eye - b.max).max(DVec3::ZERO).length());
        if longest <= MAX_TRIANGLE_REACH * distance.max(floor) {
            continue;
        }
        if let Some((edge, distance)) = worst_triangle(&object.mesh, &object.transform, eye, floor)
        {
            return Err(Error::Limit(format!(
                "objects[{i}]: a triangle {edge:.3e} long is {distance:.3e} from the camera, \
                 more than {MAX_TRIANGLE_REACH} times its distance (the near plane's at least); \
                 f32 interpolation would misplace its surface. Split it into smaller triangles \
                 or keep the camera farther away"
            )));
        }
    }
    Ok(())
}

/// How close to the eye a fragment can be: the near plane, or an orthographic view's height.
fn closest_fragment(camera: &Camera) -> f64 {
    match camera.projection {
        Projection::Perspective { near, .. } => near,
        Projection::Orthographic { height, near, .. } => height.max(near),
    }
}

/// An upper bound of how much `m` lengthens a vector (√3 × its largest entry).
fn largest_scale(m: &DMat4) -> f64 {
    let cols = [m.x_axis, m.y_axis, m.z_axis].map(|c| c.truncate().abs().max_element());
    cols.into_iter().fold(0.0, f64::max) * 3f64.sqrt()
}

/// The first triangle past the limit, as (longest edge, distance from `eye`).
fn worst_triangle(mesh: &Mesh, transform: &DMat4, eye: DVec3, floor: f64) -> Option<(f64, f64)> {
    for t in mesh.indices.chunks_exact(3) {
        let world = [t[0], t[1], t[2]]
            .map(|i| transform.transform_point3(mesh.positions[i as usize].as_dvec3()) - eye);
        // In units of the largest coordinate, so no square leaves f64.
        let unit = world.iter().map(|v| v.abs().max_element()).fold(0.0, f64::max);
        if !(unit > 0.0 && unit.is_finite()) {
            continue;
        }
        let [a, b, c] = world.map(|v| v / unit);
        let edge = a.distance(b).max(b.distance(c)).max(c.distance(a));
        let distance = closest_point(a, b, c).length();
        let distance = if distance.is_finite() {
            distance
        } else {
            a.length().min(b.length()).min(c.length())
        };
        if edge > MAX_TRIANGLE_REACH * distance.max(floor / unit) {
            return Some((edge * unit, distance * unit));
        }
    }
    None
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
        assert!((edge - DVec3::new(1.0, 1.0, 2.0)).length() < 1e-12, "{edge}");
        let far = DVec3::new(-9.0, -9.0, 0.0);
        assert_eq!(closest_point(a - far, b - far, c - far) + far, a);
    }

    #[test]
    fn a_triangle_passes_or_fails_by_its_size_against_its_distance() {
        let quad = {
            let mut b = crate::MeshBuilder::new();
            b.quad(
                glam::Vec3::new(-1.0, -1.0, 0.0),
                glam::Vec3::new(1.0, -1.0, 0.0),
                glam::Vec3::new(1.0, 1.0, 0.0),
                glam::Vec3::new(-1.0, 1.0, 0.0),
            );
            b.build()
        };
        let eye = DVec3::new(0.0, 0.0, 5.0);
        let scaled = |s: f64| DMat4::from_scale(DVec3::new(s, s, 1.0));
        assert_eq!(worst_triangle(&quad, &scaled(1e4), eye, 0.1), None);
        let (edge, distance) = worst_triangle(&quad, &scaled(1e6), eye, 0.1).unwrap();
        assert!((edge - 2e6 * 2f64.sqrt()).abs() < 1.0 && (distance - 5.0).abs() < 1e-6);
        // Seen from within its own plane, the near plane bounds how close a fragment can be.
        let inside = DVec3::new(0.0, 0.0, 0.0);
        assert!(worst_triangle(&quad, &scaled(1e2), inside, 0.1).is_none());
        assert!(worst_triangle(&quad, &scaled(1e4), inside, 0.1).is_some());
        // Coordinates whose squares overflow f64 still measure.
        assert!(worst_triangle(&quad, &scaled(1e200), eye * 1e190, 1.0).is_some());
    }
}
