//! The automatic camera of a model without one (OBJ files, glTF files without a camera, scene
//! files without `camera`): a three-quarter view from above right and in front (+Z) that
//! keeps all eight corners of the scene's bounds inside the picture, with a margin, and
//! near/far planes that clip none of them.
//!
//! The scene does not know the aspect ratio it will be rendered at, so the framing is
//! conservative: the bounds fit at every aspect (width / height) of at least
//! [`FRAMED_MIN_ASPECT`] (square and landscape pictures). A portrait picture narrower than
//! that keeps the full height but may cut the sides of a wide model.

use glam::DVec3;

use super::camera::Camera;
use super::mesh::Aabb;

/// Vertical field of view of the automatic camera, degrees.
pub const FRAMED_FOV_Y_DEG: f64 = 55.0;

/// Narrowest picture (width / height) the automatic camera fits the bounds into.
pub const FRAMED_MIN_ASPECT: f64 = 1.0;

/// How much of the half-frame the bounds may fill: the corners project within ±0.9 of the
/// normalized device coordinates, leaving a 5 % margin on each edge.
pub const FRAMED_FILL: f64 = 0.9;

/// Direction from the target to the eye: above, to the right of and in front of the model.
const VIEW_FROM: DVec3 = DVec3::new(0.55, 0.45, 1.0);

/// A perspective camera that sees every corner of `bounds` (see the module's description).
pub fn framing(bounds: &Aabb) -> Camera {
    let center = bounds.center();
    let diagonal = bounds.size().length();
    // A single point has no size: any small distance sees it.
    let extent = if diagonal > 0.0 { diagonal } else { 1e-3 };
    let back = VIEW_FROM.normalize();
    let right = (-back).cross(DVec3::Y).normalize();
    let up = right.cross(-back);
    let tan_y = (FRAMED_FOV_Y_DEG.to_radians() * 0.5).tan() * FRAMED_FILL;
    let tan_x = tan_y * FRAMED_MIN_ASPECT;
    let corners: Vec<DVec3> = (0..8)
        .map(|i| {
            let pick = |bit: u32, lo: f64, hi: f64| if i & (1 << bit) != 0 { hi } else { lo };
            let q = DVec3::new(
                pick(0, bounds.min.x, bounds.max.x),
                pick(1, bounds.min.y, bounds.max.y),
                pick(2, bounds.min.z, bounds.max.z),
            ) - center;
            // Right, up, and towards the eye, in the camera's basis.
            DVec3::new(q.dot(right), q.dot(up), q.dot(back))
        })
        .collect();
    // A corner at (x, y, z) is inside when |y| ≤ tan_y · (distance − z), likewise x, and it
    // stays at least 5 % of the extent in front of the eye.
    let distance = corners
        .iter()
        .map(|c| {
            c.z + (c.x.abs() / tan_x)
                .max(c.y.abs() / tan_y)
                .max(0.05 * extent)
        })
        .fold(0.0, f64::max);
    let depths = corners.iter().map(|c| distance - c.z);
    let nearest = depths.clone().fold(f64::INFINITY, f64::min);
    let farthest = depths.fold(0.0, f64::max);
    Camera::perspective(
        center + back * distance,
        center,
        FRAMED_FOV_Y_DEG,
        nearest * 0.5,
        farthest * 2.0,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec4;

    fn aabb(min: [f64; 3], max: [f64; 3]) -> Aabb {
        Aabb {
            min: DVec3::from(min),
            max: DVec3::from(max),
        }
    }

    #[test]
    fn every_corner_of_every_shape_projects_inside_the_frame_and_depth_range() {
        let shapes = [
            ("cube", aabb([-1.0; 3], [1.0; 3])),
            (
                "box at y 0 (Khronos Box)",
                aabb([-0.5, 0.0, -0.5], [0.5, 1.0, 0.5]),
            ),
            ("tall", aabb([-0.1, 0.0, -0.1], [0.1, 30.0, 0.1])),
            ("wide", aabb([-40.0, 0.0, -0.2], [40.0, 1.0, 0.2])),
            ("deep", aabb([-0.5, 0.0, -50.0], [0.5, 1.0, 50.0])),
            ("flat XZ plane", aabb([-8.0, 0.0, -8.0], [8.0, 0.0, 8.0])),
            ("flat XY plane", aabb([-8.0, -8.0, 0.0], [8.0, 8.0, 0.0])),
            (
                "far from origin",
                aabb([1e6, 2e6, -3e6], [1e6 + 2.0, 2e6 + 1.0, -3e6 + 3.0]),
            ),
            ("tiny", aabb([1e-7, 0.0, 0.0], [3e-7, 1e-7, 2e-7])),
            ("huge", aabb([-1e9, -2e8, -5e8], [1e9, 2e8, 5e8])),
            ("point", aabb([2.0, 3.0, 4.0], [2.0, 3.0, 4.0])),
        ];
        for (name, b) in shapes {
            let cam = framing(&b);
            cam.validate().unwrap();
            for aspect in [FRAMED_MIN_ASPECT, 16.0 / 9.0, 4.0] {
                let m = cam.projection_matrix(aspect) * cam.view_matrix();
                for i in 0..8 {
                    let pick =
                        |bit: u32, lo: f64, hi: f64| if i & (1 << bit) != 0 { hi } else { lo };
                    let p = DVec3::new(
                        pick(0, b.min.x, b.max.x),
                        pick(1, b.min.y, b.max.y),
                        pick(2, b.min.z, b.max.z),
                    );
                    let c = m * DVec4::new(p.x, p.y, p.z, 1.0);
                    let ndc = c.truncate() / c.w;
                    assert!(c.w > 0.0, "{name}: corner {i} behind the eye");
                    // Within the margin on x and y, strictly inside the depth range.
                    let limit = FRAMED_FILL + 1e-6;
                    assert!(
                        ndc.x.abs() <= limit && ndc.y.abs() <= limit,
                        "{name} at aspect {aspect}: corner {i} at {ndc:?}"
                    );
                    assert!(
                        ndc.z > -1.0 && ndc.z < 1.0,
                        "{name}: corner {i} clipped, {ndc:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn the_bounds_fill_the_frame_rather_than_a_corner_of_it() {
        // Tight: some corner reaches the margin (the camera is no farther than it needs).
        let b = aabb([-0.5, 0.0, -0.5], [0.5, 1.0, 0.5]);
        let cam = framing(&b);
        let m = cam.projection_matrix(1.0) * cam.view_matrix();
        let reach = (0..8)
            .map(|i| {
                let p = DVec3::new(
                    if i & 1 != 0 { 0.5 } else { -0.5 },
                    if i & 2 != 0 { 1.0 } else { 0.0 },
                    if i & 4 != 0 { 0.5 } else { -0.5 },
                );
                let c = m * p.extend(1.0);
                (c.x / c.w).abs().max((c.y / c.w).abs())
            })
            .fold(0.0, f64::max);
        assert!((reach - FRAMED_FILL).abs() < 1e-9, "reach {reach}");
    }
}
