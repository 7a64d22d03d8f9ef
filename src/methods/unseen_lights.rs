//! Lights that reach nothing in view, darkened before their RGBA8 records are packed: the
//! records share one fixed-point range, set by the farthest and largest light packed, so one
//! such light coarsens every light's steps, and forward, tiled and clustered must choose the
//! range from the same lights to draw the same picture.

use glam::DVec3;

use crate::cluster::grid::ViewVolume;
use crate::cluster::view_light::GpuLight;

/// `light`, or, where it reaches nothing in `volume` (the frustum up to the farthest
/// geometry), the same light at the eye with radius 0: it lights no pixel either way, and the
/// range is then set by the lights that do.
pub(crate) fn darkened_if_unseen(volume: &ViewVolume, light: &GpuLight) -> GpuLight {
    let (centre, radius) = reach_sphere(light);
    if volume.excludes(centre, radius) {
        GpuLight {
            position: glam::Vec3::ZERO,
            radius: 0.0,
            cull_radius: 0.0,
            ..*light
        }
    } else {
        *light
    }
}

/// A sphere holding all `light` reaches: its own sphere, or for a spot whose outer half-angle
/// α is under 90° the smaller sphere around its cone (through the apex and the cone's rim,
/// `r / (2 cos α)` across, under 45°; around the rim from 45°).
pub(crate) fn reach_sphere(light: &GpuLight) -> (DVec3, f64) {
    let (position, r) = (light.position.as_dvec3(), f64::from(light.radius));
    let alpha = f64::from(light.cone_deg.0).to_radians();
    let axis = light.direction.as_dvec3();
    if light.spot_scale == 0.0 || alpha >= std::f64::consts::FRAC_PI_2 || axis == DVec3::ZERO {
        return (position, r);
    }
    if alpha < std::f64::consts::FRAC_PI_4 {
        let half = r / (2.0 * alpha.cos());
        (position + axis * half, half)
    } else {
        (position + axis * (r * alpha.cos()), r * alpha.sin())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::light::Cone;
    use crate::scene::Light;
    use glam::{DMat4, Vec3};

    /// Every point a spot reaches (its sphere within its cone) lies in its reach sphere, which
    /// is smaller than its own sphere for cones under 90°.
    #[test]
    fn a_spots_reach_sphere_holds_its_cone() {
        for outer in [1.0, 10.0, 30.0, 44.9, 45.0, 60.0, 89.0, 90.0, 120.0] {
            let cone = Cone {
                direction: glam::DVec3::new(0.3, 0.4, -1.0),
                inner_deg: outer * 0.5,
                outer_deg: outer,
            };
            let spot = Light::spot(glam::DVec3::new(1.0, -2.0, 3.0), 5.0, Vec3::ONE, 1.0, cone);
            let l = GpuLight::from_light(&spot, &DMat4::IDENTITY);
            let (centre, radius) = reach_sphere(&l);
            let (apex, axis) = (l.position.as_dvec3(), l.direction.as_dvec3());
            let a = outer.to_radians();
            // The apex, and points of the cone's rim and cap at every angle around the axis.
            let side = axis.any_orthonormal_vector();
            for k in 0..64 {
                let turn = glam::DQuat::from_axis_angle(axis, f64::from(k) * 0.1);
                for (angle, distance) in [(a, 5.0), (a, 2.5), (a * 0.5, 5.0), (0.0, 5.0)] {
                    let dir = glam::DQuat::from_axis_angle(turn * side, angle) * axis;
                    let p = apex + dir * distance;
                    assert!(p.distance(centre) <= radius * (1.0 + 1e-9), "{outer}°: {p}");
                }
            }
            assert!(apex.distance(centre) <= radius * (1.0 + 1e-9));
            if outer < 90.0 {
                assert!(radius < 5.0, "{outer}°: {radius}");
            } else {
                assert_eq!(radius, 5.0);
            }
        }
    }
}
