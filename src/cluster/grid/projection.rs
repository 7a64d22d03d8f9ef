//! The camera as the grid sees it: the depth mapping `f(d)` ([`DepthMapping`]) and the
//! projection's extent at a depth ([`GridProjection`]).

use glam::DMat4;

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
