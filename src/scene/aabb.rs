//! Axis-aligned bounds in `f64`, and the rule for where an object may be placed.

use glam::{DMat4, DVec3};

use super::camera::MAX_CAMERA_COORD;
use super::SceneError;

/// Smallest largest side of an object's world bounds: smaller, the automatic camera's near
/// plane (framed on the bounds) and the vertices' differences fall among f32's subnormal
/// numbers, which GPUs read as zero, and the frame is black (a glTF node scaled by 1e-40).
pub const MIN_PLACED_SIZE: f64 = 1e-36;

/// Largest entry a transform's linear part may hold: the model-view matrix the GPU reads is
/// f32 (at most 3.4·10³⁸), and the view's rotation adds up to three entries into one. A flat
/// object scaled past it along its own normal has finite bounds but infinite matrix entries,
/// and its vertices become 0·∞ = NaN.
pub const MAX_PLACED_SCALE: f64 = 1e37;

/// Axis-aligned bounding box in `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Minimum corner.
    pub min: DVec3,
    /// Maximum corner.
    pub max: DVec3,
}

impl Aabb {
    /// Refuses these object-space bounds placed by `transform` (`field`'s) as
    /// [`Aabb::placement_refusal`] says, naming `field.transform`.
    pub(crate) fn check_placed_by(&self, transform: &DMat4, field: &str) -> Result<(), SceneError> {
        match self.placement_refusal(transform) {
            None => Ok(()),
            Some(reason) => Err(SceneError::invalid(format!("{field}.transform"), reason)),
        }
    }

    /// Why these object-space bounds cannot be placed by `transform`, if they cannot: it is
    /// not finite, their world bounds reach past the camera's coordinate limit, it scales
    /// past [`MAX_PLACED_SCALE`], or the bounds shrink below [`MIN_PLACED_SIZE`]. The message
    /// completes "the transform …".
    pub(crate) fn placement_refusal(&self, transform: &DMat4) -> Option<String> {
        // Bounds drop a NaN corner (`min` keeps the other operand), so NaN is refused here.
        if !transform.is_finite() {
            return Some("is not finite".to_string());
        }
        let reach = self.transformed(transform).reach();
        if !(reach.is_finite() && reach <= MAX_CAMERA_COORD) {
            return Some(format!(
                "places the object's bounds {reach:e} from the origin, past \
                 ±{MAX_CAMERA_COORD:e} (the camera's limit)"
            ));
        }
        // Bounds that stay near (a flat object stretched along its normal) with matrix
        // entries past f32.
        let scale = linear_part_largest(transform);
        if scale > MAX_PLACED_SCALE {
            return Some(format!(
                "scales by {scale:e}, past {MAX_PLACED_SCALE:e} (the f32 matrices the GPU \
                 reads overflow)"
            ));
        }
        // A mesh of one point (a degenerate face alone) has no size to lose: it draws nothing
        // whatever the transform, as it would unplaced.
        let size = self.placed_size(transform);
        let has_size = self.size().max_element() > 0.0;
        (has_size && size < MIN_PLACED_SIZE).then(|| {
            format!(
                "shrinks the object to {size:e} across, below {MIN_PLACED_SIZE:e} (f32's \
                 subnormal numbers, which GPUs read as zero)"
            )
        })
    }

    /// [`Aabb::placement_refusal`] of `bounds`, or of a mesh without any (no vertices):
    /// such a transform need only be finite.
    pub(crate) fn placement_refusal_of(bounds: Option<&Aabb>, transform: &DMat4) -> Option<String> {
        match bounds {
            Some(b) => b.placement_refusal(transform),
            None => (!transform.is_finite()).then(|| "is not finite".to_string()),
        }
    }

    /// The largest side of these bounds scaled, turned and sheared by `transform`, not moved
    /// (a tiny object far out rounds to one point in f64 too, and is refused by area later).
    fn placed_size(&self, transform: &DMat4) -> f64 {
        // A box's extent under a linear map is the map's absolute values times its sides.
        let m = glam::DMat3::from_mat4(*transform);
        let abs = glam::DMat3::from_cols(m.x_axis.abs(), m.y_axis.abs(), m.z_axis.abs());
        (abs * self.size()).max_element()
    }

    /// The largest coordinate magnitude of the box (NaN or infinite where a corner is).
    pub(crate) fn reach(&self) -> f64 {
        self.min.abs().max(self.max.abs()).max_element()
    }

    /// Bounds of a point set (`None` when empty).
    pub fn from_points(points: impl IntoIterator<Item = DVec3>) -> Option<Aabb> {
        let mut it = points.into_iter();
        let first = it.next()?;
        Some(it.fold(
            Aabb {
                min: first,
                max: first,
            },
            |b, p| Aabb {
                min: b.min.min(p),
                max: b.max.max(p),
            },
        ))
    }

    /// Centre point.
    pub fn center(&self) -> DVec3 {
        (self.min + self.max) * 0.5
    }

    /// Edge lengths.
    pub fn size(&self) -> DVec3 {
        self.max - self.min
    }

    /// The box grown by `fraction` of its size on every side.
    pub fn expanded(&self, fraction: f64) -> Aabb {
        let pad = self.size() * fraction;
        Aabb {
            min: self.min - pad,
            max: self.max + pad,
        }
    }

    /// Smallest box containing both.
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// The box's eight corners.
    pub fn corners(&self) -> [DVec3; 8] {
        std::array::from_fn(|i| {
            let pick = |bit: u32, lo: f64, hi: f64| if i & (1 << bit) != 0 { hi } else { lo };
            DVec3::new(
                pick(0, self.min.x, self.max.x),
                pick(1, self.min.y, self.max.y),
                pick(2, self.min.z, self.max.z),
            )
        })
    }

    /// Bounds of this box's eight corners after a transform.
    pub fn transformed(&self, m: &DMat4) -> Aabb {
        let corners = self.corners().map(|c| m.transform_point3(c));
        Aabb::from_points(corners).expect("eight corners")
    }
}

/// The largest entry of `transform`'s linear part, in magnitude.
fn linear_part_largest(transform: &DMat4) -> f64 {
    glam::DMat3::from_mat4(*transform)
        .abs()
        .to_cols_array()
        .into_iter()
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_box() -> Aabb {
        Aabb {
            min: DVec3::splat(-0.5),
            max: DVec3::splat(0.5),
        }
    }

    #[test]
    fn a_placement_is_refused_past_the_cameras_limit_or_below_the_smallest_size() {
        let b = unit_box();
        let scaled = |s: f64| DMat4::from_scale(DVec3::splat(s));
        assert_eq!(b.placement_refusal(&DMat4::IDENTITY), None);
        assert_eq!(b.placement_refusal(&scaled(MIN_PLACED_SIZE)), None);
        let shrunk = b.placement_refusal(&scaled(MIN_PLACED_SIZE / 2.0));
        assert!(shrunk.is_some_and(|r| r.starts_with("shrinks")));
        // One axis of normal size keeps a thin object placeable: the largest side counts.
        let sliver = DMat4::from_scale(DVec3::new(1.0, 1e-300, 1e-300));
        assert_eq!(b.placement_refusal(&sliver), None);

        let far = |x: f64| DMat4::from_translation(DVec3::new(x, 0.0, 0.0));
        assert_eq!(b.placement_refusal(&far(MAX_CAMERA_COORD - 1.0)), None);
        let beyond = b.placement_refusal(&far(MAX_CAMERA_COORD));
        assert!(beyond.is_some_and(|r| r.starts_with("places")));
        // A point has no size to lose (a mesh of one degenerate face was refused).
        let point = Aabb {
            min: DVec3::splat(3.0),
            max: DVec3::splat(3.0),
        };
        assert_eq!(point.placement_refusal(&DMat4::IDENTITY), None);
        assert_eq!(point.placement_refusal(&scaled(1e-300)), None);
        let nan = DMat4::from_scale(DVec3::new(1.0, f64::NAN, 1.0));
        assert!(b.placement_refusal(&nan).is_some());
        // A flat box stretched along its normal keeps finite bounds, not finite f32 matrices.
        let flat = Aabb {
            min: DVec3::new(-1.0, -1.0, 0.0),
            max: DVec3::new(1.0, 1.0, 0.0),
        };
        let stretched = |z: f64| DMat4::from_scale(DVec3::new(1.0, 1.0, z));
        assert_eq!(flat.placement_refusal(&stretched(MAX_PLACED_SCALE)), None);
        let overflowing = flat.placement_refusal(&stretched(MAX_PLACED_SCALE * 2.0));
        assert!(overflowing.is_some_and(|r| r.starts_with("scales by 2e37")));
    }

    #[test]
    fn a_refused_placement_names_the_fields_transform() {
        let err = unit_box()
            .check_placed_by(&DMat4::from_scale(DVec3::splat(1e-40)), "objects[2]")
            .unwrap_err()
            .to_string();
        assert!(err.contains("objects[2].transform"), "{err}");
    }
}
