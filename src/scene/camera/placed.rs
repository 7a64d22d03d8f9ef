//! A camera carried with the scene it was made for: a built-in scene placed by a scene file's
//! `transform` keeps the view of its own camera.

use glam::{DMat3, DMat4};

use super::{Camera, Projection};

impl Camera {
    /// This camera moved by `transform` with the scene it looks at: eye, target and up carried,
    /// planes (and an orthographic height) scaled. `None` where `transform` is no similarity
    /// (a shear or an uneven scale would distort the view: frame the scene instead), mirrors
    /// (the picture would be the mirror image) or makes no valid camera (past the coordinate
    /// limit).
    pub fn placed_by(&self, transform: &DMat4) -> Option<Camera> {
        let m = DMat3::from_mat4(*transform);
        if m.determinant() <= 0.0 {
            return None;
        }
        let scale = uniform_scale(&m)?;
        let projection = match self.projection {
            Projection::Perspective {
                fov_y_deg,
                near,
                far,
            } => Projection::Perspective {
                fov_y_deg,
                near: near * scale,
                far: far * scale,
            },
            Projection::Orthographic { height, near, far } => Projection::Orthographic {
                height: height * scale,
                near: near * scale,
                far: far * scale,
            },
        };
        let camera = Camera {
            position: transform.transform_point3(self.position),
            target: transform.transform_point3(self.target),
            up: (m * self.up).normalize_or_zero(),
            projection,
        };
        camera.validate().ok().map(|()| camera)
    }
}

/// The scale of a similarity's linear part `m` (its columns orthogonal and of one length, to
/// within rounding), or `None`.
fn uniform_scale(m: &DMat3) -> Option<f64> {
    let columns = [m.x_axis, m.y_axis, m.z_axis];
    let squared = columns[0].length_squared();
    if !(squared.is_finite() && squared > 0.0) {
        return None;
    }
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * squared;
    let orthogonal = close(columns[0].dot(columns[1]), 0.0)
        && close(columns[1].dot(columns[2]), 0.0)
        && close(columns[0].dot(columns[2]), 0.0);
    let even = columns[1..]
        .iter()
        .all(|c| close(c.length_squared(), squared));
    (orthogonal && even).then(|| squared.sqrt())
}

#[cfg(test)]
mod tests {
    use glam::{DQuat, DVec3};

    use super::*;

    /// Moved, turned and scaled alike, the camera sees what it saw: every point keeps its
    /// place on screen (the view-projection of the moved point is the old one's).
    #[test]
    fn a_similarity_carries_the_view_with_the_scene() {
        let camera = Camera::perspective(DVec3::new(1.0, 2.0, 5.0), DVec3::ZERO, 50.0, 0.1, 80.0);
        let transform = DMat4::from_scale_rotation_translation(
            DVec3::splat(3.0),
            DQuat::from_rotation_y(1.2) * DQuat::from_rotation_x(0.3),
            DVec3::new(100.0, -4.0, 7.0),
        );
        let placed = camera.placed_by(&transform).expect("a similarity");
        let clip = |c: &Camera| c.projection_matrix(16.0 / 9.0) * c.view_matrix();
        for p in [
            DVec3::ZERO,
            DVec3::new(0.5, -0.3, 1.0),
            DVec3::new(-2.0, 1.0, -3.0),
        ] {
            let before = clip(&camera).project_point3(p);
            let after = clip(&placed).project_point3(transform.transform_point3(p));
            assert!(before.abs_diff_eq(after, 1e-9), "{before:?} → {after:?}");
        }
    }

    /// An uneven scale, a shear or a mirror has no camera that keeps the view: none.
    #[test]
    fn a_distorting_transform_places_no_camera() {
        let camera = Camera::default();
        let uneven = DMat4::from_scale(DVec3::new(1.0, 2.0, 1.0));
        assert!(camera.placed_by(&uneven).is_none());
        let mut shear = DMat4::IDENTITY;
        shear.y_axis.x = 0.5;
        assert!(camera.placed_by(&shear).is_none());
        assert!(camera.placed_by(&DMat4::from_scale(DVec3::ZERO)).is_none());
        // A mirror keeps every length but shows the picture the other way round.
        let mirror = DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0));
        assert!(camera.placed_by(&mirror).is_none());
    }
}
