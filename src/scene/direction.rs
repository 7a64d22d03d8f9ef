//! Unit vectors of vectors of any finite, non-zero length. Each is divided by its largest
//! component before it is squared, so a spot axis of length 10¹⁵⁵ (whose square overflows
//! `f64`) or 10⁻²⁰⁰ (whose square underflows it), or a vertex normal past `f32`'s square
//! root, keeps its direction instead of becoming zero or NaN.

use glam::{DVec3, Vec3};

/// The unit vector along `v`, or `None` when `v` is zero or not finite.
pub fn unit(v: DVec3) -> Option<DVec3> {
    let largest = v.abs().max_element();
    if !(largest > 0.0 && largest.is_finite()) {
        return None;
    }
    (v / largest).try_normalize()
}

/// [`unit()`] in `f32`.
pub fn unit_f32(v: Vec3) -> Option<Vec3> {
    let largest = v.abs().max_element();
    if !(largest > 0.0 && largest.is_finite()) {
        return None;
    }
    (v / largest).try_normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lengths_whose_squares_leave_the_float_range_keep_their_direction() {
        let want = DVec3::new(3.0, -4.0, 0.0) / 5.0;
        for scale in [1e-310, 1e-200, 1.0, 1e155, 1e300] {
            let u = unit(DVec3::new(3.0, -4.0, 0.0) * scale).unwrap();
            assert!((u - want).length() < 1e-15, "{scale:e}: {u}");
        }
        let want = want.as_vec3();
        for scale in [1e-40f32, 1e-20, 1.0, 1e20, 1e37] {
            let u = unit_f32(Vec3::new(3.0, -4.0, 0.0) * scale).unwrap();
            assert!((u - want).length() < 1e-6, "{scale:e}: {u}");
        }
    }

    #[test]
    fn zero_and_non_finite_vectors_have_no_direction() {
        for v in [
            DVec3::ZERO,
            DVec3::new(f64::NAN, 1.0, 0.0),
            DVec3::new(f64::INFINITY, 0.0, 0.0),
        ] {
            assert_eq!(unit(v), None, "{v}");
        }
        for v in [
            Vec3::ZERO,
            Vec3::new(0.0, f32::NAN, 0.0),
            Vec3::new(0.0, 0.0, f32::NEG_INFINITY),
        ] {
            assert_eq!(unit_f32(v), None, "{v}");
        }
    }
}
