//! How long a triangle may be where it lies: against its distance from the eye, for `f32`
//! interpolation, and in view, for the pixels it spans.

use glam::{DMat4, DVec3, DVec4};

use crate::scene::{Camera, Projection};

/// Largest ratio of a triangle's longest edge to its distance from the eye (at least the near
/// plane's) that is drawn as it is: positions are then within about 10⁻³ of their distance.
pub const MAX_TRIANGLE_REACH: f64 = 16384.0;

/// Most pixels a triangle in view may span at its closest point to the eye: SwiftShader lost
/// a triangle's lights past about 2²⁷ pixels and the triangle past 2²⁸; this leaves eight
/// times less. At a 60° field of view it is the looser limit up to 1 182 rows of frame.
pub const MAX_TRIANGLE_SPAN_PX: f64 = (1u64 << 24) as f64;

/// How far beyond the frame's edges, in frame sizes, a triangle counts as in view.
const GUARD: f64 = 2.0;

/// How long a triangle may be where it lies, for one camera and frame.
#[derive(Clone, Copy, Debug)]
pub struct Reach {
    /// How close to the eye a fragment can be: the near plane, or an orthographic view's
    /// height.
    floor: f64,
    /// Longest edge in view per unit of distance from the eye (a perspective view's pixels
    /// grow with it), and at any distance (an orthographic view's pixels do not).
    in_view_per_distance: f64,
    in_view_at_most: f64,
    /// Eye-relative world space to clip space: which triangles are in view.
    clip: DMat4,
}

impl Reach {
    /// The limits for `camera` drawing a `width × height` frame.
    pub fn new(camera: &Camera, (width, height): (u32, u32)) -> Reach {
        let rows = f64::from(height.max(1));
        let aspect = f64::from(width.max(1)) / rows;
        let clip = camera.projection_matrix(aspect) * camera.view_rotation();
        let (floor, in_view_per_distance, in_view_at_most) = match camera.projection {
            Projection::Perspective {
                fov_y_deg, near, ..
            } => {
                // A pixel at distance d is 2·d·tan(fov/2)/rows across.
                let pixel = 2.0 * (fov_y_deg.to_radians() * 0.5).tan() / rows;
                (near, MAX_TRIANGLE_SPAN_PX * pixel, f64::INFINITY)
            }
            Projection::Orthographic {
                height: h, near, ..
            } => (h.max(near), f64::INFINITY, MAX_TRIANGLE_SPAN_PX * h / rows),
        };
        Reach {
            floor,
            in_view_per_distance,
            in_view_at_most,
            clip,
        }
    }

    /// Limits by the eye's distance alone, with no frame to be in view of.
    #[cfg(test)]
    pub(super) fn distance_only(floor: f64) -> Reach {
        Reach {
            floor,
            in_view_per_distance: f64::INFINITY,
            in_view_at_most: f64::INFINITY,
            clip: DMat4::IDENTITY,
        }
    }

    /// Whether an edge of length `edge` at `distance` from the eye (both in units of `unit`) is
    /// past the limit; `seen` (whether it may lie in view, a few matrix products) is asked
    /// only where the answer turns on it.
    pub(super) fn exceeded(
        &self,
        edge: f64,
        distance: f64,
        unit: f64,
        seen: impl FnOnce() -> bool,
    ) -> bool {
        edge > self.longest(distance, unit, false)
            || edge > self.longest(distance, unit, true) && seen()
    }

    /// The longest edge allowed at `distance` from the eye (both in units of `unit`), for a
    /// triangle in view or not.
    fn longest(&self, distance: f64, unit: f64, in_view: bool) -> f64 {
        let distance = distance.max(self.floor / unit);
        let mut longest = MAX_TRIANGLE_REACH * distance;
        if in_view {
            // An orthographic view's pixels have one size (`in_view_per_distance` is infinite).
            if self.in_view_per_distance.is_finite() {
                longest = longest.min(self.in_view_per_distance * distance);
            }
            longest = longest.min(self.in_view_at_most / unit);
        }
        longest
    }

    /// Whether some of the eye-relative `points` may lie in view (within [`GUARD`] frames of
    /// it): false when all lie beyond one side of the frame, or behind the near plane.
    pub(super) fn may_see<const N: usize>(&self, points: [DVec3; N]) -> bool {
        let clip = points.map(|p| self.clip * p.extend(1.0));
        let beyond = |side: fn(DVec4) -> f64| clip.iter().all(|&c| side(c) < 0.0);
        !(beyond(|c| c.x + GUARD * c.w)
            || beyond(|c| GUARD * c.w - c.x)
            || beyond(|c| c.y + GUARD * c.w)
            || beyond(|c| GUARD * c.w - c.y)
            || beyond(|c| c.z + c.w))
    }
}
