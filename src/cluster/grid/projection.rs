//! The camera as the grid sees it: the depth mapping `f(d)` ([`DepthMapping`]) and the
//! projection's extent at a depth ([`GridProjection`]).

use glam::{DMat4, DVec3};

/// The view between two depths, for testing many spheres against it: the side planes' norms
/// are worked out once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewVolume {
    projection: GridProjection,
    norms: [f64; 2],
    near: f64,
    far: f64,
}

impl ViewVolume {
    /// `projection`'s view from the depth `near` to `far` (which may be infinite).
    pub fn new(projection: GridProjection, near: f64, far: f64) -> ViewVolume {
        ViewVolume {
            projection,
            norms: projection.side_plane_norms(),
            near,
            far,
        }
    }

    /// True when the view-space sphere (`center`, `radius`) lies wholly outside the volume
    /// (outside a side plane, before `near` or past `far`): it reaches no pixel. Conservative
    /// by a part in 10⁶ of the radius.
    pub fn excludes(&self, center: DVec3, radius: f64) -> bool {
        let radius = radius * (1.0 + 1e-6);
        let d = -center.z;
        d + radius < self.near
            || d - radius > self.far
            || self
                .projection
                .sphere_outside_sides(center, radius, self.norms)
    }
}

/// How view depth maps to the grid coordinate `t`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum DepthMapping {
    /// `f(d) = log2(d)`.
    Log2,
    /// `f(d) = d`.
    Linear,
}

/// The projection as the grid needs it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GridProjection {
    /// Perspective: view x/y at depth `d` spans `±d·tan_x`, `±d·tan_y`.
    Perspective {
        /// tan(fov_y / 2) × aspect.
        tan_x: f64,
        /// tan(fov_y / 2).
        tan_y: f64,
    },
    /// Orthographic: view x/y spans `±half_x`, `±half_y`.
    Orthographic {
        /// Half the visible width.
        half_x: f64,
        /// Half the visible height.
        half_y: f64,
    },
}

impl GridProjection {
    /// The view's half extents as the shaders take them (`u_halfExtent`, `u_cellProjection`):
    /// per unit depth for a perspective, absolute for an orthographic one (then `true`).
    pub fn half_extents(&self) -> ([f32; 2], bool) {
        match *self {
            GridProjection::Perspective { tan_x, tan_y } => ([tan_x as f32, tan_y as f32], false),
            GridProjection::Orthographic { half_x, half_y } => {
                ([half_x as f32, half_y as f32], true)
            }
        }
    }

    /// From a GL projection matrix (perspective or orthographic, symmetric).
    pub fn from_matrix(p: &DMat4) -> GridProjection {
        if p.w_axis.w == 0.0 {
            GridProjection::Perspective {
                tan_x: 1.0 / p.x_axis.x,
                tan_y: 1.0 / p.y_axis.y,
            }
        } else {
            GridProjection::Orthographic {
                half_x: 1.0 / p.x_axis.x,
                half_y: 1.0 / p.y_axis.y,
            }
        }
    }

    /// What turns the side planes' offsets (`|x| − tan·d`) into distances along their unit
    /// normals: `1/√(1 + tan²)` per axis in perspective, 1 in orthographic.
    pub fn side_plane_norms(&self) -> [f64; 2] {
        match *self {
            GridProjection::Perspective { tan_x, tan_y } => {
                [tan_x, tan_y].map(|t| 1.0 / (1.0 + t * t).sqrt())
            }
            GridProjection::Orthographic { .. } => [1.0; 2],
        }
    }

    /// True when the view-space sphere (`center`, `radius`) lies wholly outside one of the
    /// view frustum's four side planes; `norms` is [`GridProjection::side_plane_norms`].
    #[inline]
    pub fn sphere_outside_sides(&self, center: DVec3, radius: f64, norms: [f64; 2]) -> bool {
        // By symmetry the nearer of the two planes of an axis decides: |x| against the right.
        match *self {
            GridProjection::Perspective { tan_x, tan_y } => {
                let d = -center.z;
                (center.x.abs() - tan_x * d) * norms[0] > radius
                    || (center.y.abs() - tan_y * d) * norms[1] > radius
            }
            GridProjection::Orthographic { half_x, half_y } => {
                center.x.abs() - half_x > radius || center.y.abs() - half_y > radius
            }
        }
    }

    /// True when the view-space sphere (`center`, `radius`) lies wholly outside the view
    /// between the depths `near` and `far`: [`ViewVolume::excludes`] for one sphere.
    pub fn sphere_outside_view(&self, center: DVec3, radius: f64, near: f64, far: f64) -> bool {
        ViewVolume::new(*self, near, far).excludes(center, radius)
    }

    /// View-space half extent in x and y at view depth `d`.
    pub fn half_extent(&self, d: f64) -> (f64, f64) {
        match *self {
            GridProjection::Perspective { tan_x, tan_y } => (d * tan_x, d * tan_y),
            GridProjection::Orthographic { half_x, half_y } => (half_x, half_y),
        }
    }
}

#[cfg(test)]
impl GridProjection {
    /// The view the unit tests share: a 60° vertical field of view at 16:9.
    pub(crate) fn test_view() -> GridProjection {
        let t = 30f64.to_radians().tan();
        GridProjection::Perspective {
            tan_x: t * 16.0 / 9.0,
            tan_y: t,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sphere just inside a side plane, or reaching over the near or far depth, is in view;
    /// one just past them is not.
    #[test]
    fn spheres_outside_the_view_are_told_from_those_touching_it() {
        let view = GridProjection::test_view();
        let GridProjection::Perspective { tan_x, .. } = view else {
            unreachable!()
        };
        let (near, far) = (0.5, 40.0);
        let d = 10.0;
        // The right plane's unit normal, pointing out of the view.
        let normal = DVec3::new(1.0, 0.0, tan_x).normalize();
        let on_plane = DVec3::new(tan_x * d, 0.0, -d);
        for (gap, outside) in [(0.999, false), (1.001, true)] {
            let center = on_plane + normal * (2.0 * gap);
            let got = view.sphere_outside_view(center, 2.0, near, far);
            assert_eq!(got, outside, "side, {gap}");
            let mirrored = DVec3::new(-center.x, center.y, center.z);
            assert_eq!(view.sphere_outside_view(mirrored, 2.0, near, far), outside);
        }
        for (z, outside) in [(0.0, false), (0.6, true), (-40.9, false), (-41.1, true)] {
            let got = view.sphere_outside_view(DVec3::new(0.0, 0.0, z), 1.0, near, far);
            assert_eq!(got, outside, "depth {z}");
        }
        let ortho = GridProjection::Orthographic {
            half_x: 4.0,
            half_y: 3.0,
        };
        assert!(!ortho.sphere_outside_view(DVec3::new(4.9, 0.0, -5.0), 1.0, 0.0, 10.0));
        assert!(ortho.sphere_outside_view(DVec3::new(0.0, 4.1, -5.0), 1.0, 0.0, 10.0));
    }
}
