//! Point and spot lights and their validation.
//!
//! Every light has a finite radius at which its contribution reaches exactly zero (see
//! [`super::shading`]), which is what makes conservative culling exact.

use glam::{DVec3, Vec3};

use super::SceneError;

/// Point or spot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// Emits in all directions.
    Point,
    /// Emits in a cone around `direction`, full intensity inside `inner_deg` (half-angle),
    /// fading smoothly to zero at `outer_deg` (an edge sharper than 10⁻⁴ of `1 − cos` fades
    /// over that much just past it).
    Spot {
        /// Cone axis in world space (need not be normalised; must not be zero).
        direction: DVec3,
        /// Inner half-angle in degrees, 0 ≤ inner ≤ outer.
        inner_deg: f64,
        /// Outer half-angle in degrees, inner ≤ outer ≤ 180.
        outer_deg: f64,
    },
}

/// A spot light's cone, for [`Light::spot`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    /// Axis in world space (need not be normalised; must not be zero).
    pub direction: DVec3,
    /// Half-angle in degrees of full intensity, 0 ≤ inner ≤ outer.
    pub inner_deg: f64,
    /// Half-angle in degrees where the light reaches zero, inner ≤ outer ≤ 180 (just past it
    /// for an edge sharper than 10⁻⁴ of `1 − cos`).
    pub outer_deg: f64,
}

/// A dynamic light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Point or spot, with the cone for spots.
    pub kind: LightKind,
    /// World position (`f64` for scenes far from the origin).
    pub position: DVec3,
    /// Distance at which the contribution reaches exactly zero, >= 0.
    pub radius: f32,
    /// Linear RGB colour, each channel >= 0.
    pub color: Vec3,
    /// Scalar multiplier of `color`, >= 0.
    pub intensity: f32,
}

impl Light {
    /// A point light. The position is `f64` so a scene far from the origin keeps its
    /// precision (lights are moved into the camera's space in `f64` before they reach the GPU
    /// as `f32`); radius, colour and intensity are what the GPU gets, so they are `f32`.
    pub fn point(position: DVec3, radius: f32, color: Vec3, intensity: f32) -> Self {
        Light {
            kind: LightKind::Point,
            position,
            radius,
            color,
            intensity,
        }
    }

    /// A spot light: a point light's arguments, then its [`Cone`] (named fields, so the two
    /// angles and the direction cannot be swapped unnoticed).
    pub fn spot(position: DVec3, radius: f32, color: Vec3, intensity: f32, cone: Cone) -> Self {
        let Cone {
            direction,
            inner_deg,
            outer_deg,
        } = cone;
        Light {
            kind: LightKind::Spot {
                direction,
                inner_deg,
                outer_deg,
            },
            position,
            radius,
            color,
            intensity,
        }
    }

    /// `color × intensity`: what the shader multiplies the falloff with.
    pub fn radiance(&self) -> Vec3 {
        self.color * self.intensity
    }

    /// True when the light can contribute anything at all (radius and radiance non-zero).
    pub fn is_active(&self) -> bool {
        self.radius > 0.0 && self.radiance().max_element() > 0.0
    }

    /// Spot cone as `(scale, offset)` with `t = clamp(offset − scale · (1 − cos θ), 0, 1)`, the
    /// argument of the smoothstep, θ the angle off the axis: `scale = 1 / max(cos inner − cos
    /// outer, SPOT_MIN_COS_DELTA)` and `offset = 1 + scale · (1 − cos inner)` (`scale · (1 −
    /// cos outer)` where the edge is wider than the minimum): 1 at the inner angle, 0 one width
    /// past it, so `offset / scale` is `1 − cos` of where the light ends. Point lights get
    /// `(0, 1)` so `t = 1`.
    /// Precomputed on the CPU (in `f64`) so that `inner == outer`, where GLSL's `smoothstep`
    /// is undefined, is still a well-defined (steep) edge.
    ///
    /// Written with `1 − cos`, not `cos`, because the shaders get `1 − cos θ` as half the
    /// squared chord `|L + axis|²` between two unit vectors: small for a narrow cone and exact
    /// to a few bits even in fp16, where `cos θ` of a 0.5° cone (1 − 4·10⁻⁵) is not
    /// representable at all. Both differences of cosines here are taken as `2 sin²(α/2)` for
    /// the same reason.
    pub fn spot_scale_offset(&self) -> (f32, f32) {
        match self.kind {
            LightKind::Point => (0.0, 1.0),
            // Full intensity in every direction: a point light.
            LightKind::Spot { inner_deg, .. } if inner_deg >= 180.0 => (0.0, 1.0),
            LightKind::Spot {
                inner_deg,
                outer_deg,
                ..
            } => {
                let (scale, offset) = spot_terms(outer_deg, inner_deg);
                (scale as f32, offset as f32)
            }
        }
    }

    /// Checks the values the GPU will see; `field` is the path used in the error, e.g.
    /// `lights[3]`.
    pub fn validate(&self, field: &str) -> Result<(), SceneError> {
        if !self.position.is_finite() {
            return Err(SceneError::invalid(
                format!("{field}.position"),
                format!("must be finite, got {:?}", self.position),
            ));
        }
        if self.position.abs().max_element() > MAX_LIGHT_COORD {
            return Err(SceneError::invalid(
                format!("{field}.position"),
                format!(
                    "must be within ±{MAX_LIGHT_COORD:e} (past it the falloff's 1/d² leaves \
                     f32 and the light vanishes), got {:?}",
                    self.position
                ),
            ));
        }
        if !(self.radius.is_finite() && self.radius >= 0.0) {
            return Err(SceneError::invalid(
                format!("{field}.radius"),
                format!("must be finite and >= 0, got {:?}", self.radius),
            ));
        }
        validate_emission(self.color, self.intensity, field)?;
        if let LightKind::Spot {
            direction,
            inner_deg,
            outer_deg,
        } = self.kind
        {
            // A length whose square leaves f64 (10¹⁵⁵, 10⁻²⁰⁰) is still a direction.
            if super::direction::unit(direction).is_none() {
                return Err(SceneError::invalid(
                    format!("{field}.direction"),
                    format!("must be finite and non-zero, got {direction:?}"),
                ));
            }
            if !(inner_deg.is_finite() && (0.0..=180.0).contains(&inner_deg)) {
                return Err(SceneError::invalid(
                    format!("{field}.inner_deg"),
                    format!("must be in [0, 180], got {inner_deg:?}"),
                ));
            }
            if !(outer_deg.is_finite() && (0.0..=180.0).contains(&outer_deg)) {
                return Err(SceneError::invalid(
                    format!("{field}.outer_deg"),
                    format!("must be in [0, 180], got {outer_deg:?}"),
                ));
            }
            if outer_deg < inner_deg {
                return Err(SceneError::invalid(
                    format!("{field}.outer_deg"),
                    format!("must be >= inner_deg ({inner_deg:?}), got {outer_deg:?}"),
                ));
            }
        }
        Ok(())
    }
}

/// Largest light position coordinate, in world units: from the camera (at most
/// [`super::camera::MAX_CAMERA_COORD`] away) `1/d²` stays a normal `f32` (10⁻³⁶), where a light
/// 10¹⁹ away drew nothing at all, however bright.
pub const MAX_LIGHT_COORD: f64 = 1e18;

/// Smallest `cos(inner) − cos(outer)` used for the spot smoothstep, so a hard-edged cone
/// (`inner == outer`) has a finite slope. A cone whose edge is sharper than this fades out
/// over this width just outside its inner angle, so it keeps full intensity up to the inner
/// angle however narrow it is (a 0.5° cone faded from its axis when the width lay inside it).
pub const SPOT_MIN_COS_DELTA: f64 = 1e-4;

/// `(scale, offset)` of a cone of half-angles `outer_deg` ≥ `inner_deg` (see
/// [`Light::spot_scale_offset`]).
pub fn spot_terms(outer_deg: f64, inner_deg: f64) -> (f64, f64) {
    spot_terms_from_half_sines(half_sine(outer_deg), half_sine(inner_deg))
}

/// `sin(α/2)` of a cone half-angle `α` in degrees: what the RGBA8 light records store, so the
/// shader rebuilds the cone with arithmetic alone (no `sin`, whose precision GLSL ES leaves
/// to the implementation).
pub fn half_sine(deg: f64) -> f64 {
    (deg.to_radians() * 0.5).sin()
}

/// `cos(α/2)` of a cone half-angle `α` in degrees: what an RGBA8 record stores for a cone
/// past 90° inside, whose `1 + cos α = 2 cos²(α/2)` is small near 180°.
pub fn half_cosine(deg: f64) -> f64 {
    (deg.to_radians() * 0.5).cos()
}

/// [`spot_terms_from_half_sines`] turned round, from the cone's [`half_cosine`]s: `scale` is
/// `−s` and `offset` is `1 − s·(1 + cos inner)`, so that with the axis reversed the shaders'
/// `t = offset − scale·|L − axis|²/2 = offset + s·(1 + cos θ)` is the same `t`.
pub fn spot_terms_from_half_cosines(outer: f64, inner: f64) -> (f64, f64) {
    let (outer, inner) = (2.0 * outer * outer, 2.0 * inner * inner);
    let scale = 1.0 / (inner - outer).max(SPOT_MIN_COS_DELTA);
    (-scale, 1.0 - scale * inner)
}

/// [`spot_terms`] from the cone's [`half_sine`]s: `1 − cos α = 2 sin²(α/2)`, precise for small
/// angles. The RGBA8 light shader and decoder compute exactly this.
///
/// `t = offset − scale·(1 − cos θ)` is 1 at the inner angle and 0 one width (`1/scale`)
/// further out: at the outer angle, or [`SPOT_MIN_COS_DELTA`] past the inner one when the edge
/// is sharper than that (whose `1 − cos` the cluster assignment reads as `offset / scale`).
pub fn spot_terms_from_half_sines(outer: f64, inner: f64) -> (f64, f64) {
    let (outer, inner) = (2.0 * outer * outer, 2.0 * inner * inner);
    let scale = 1.0 / (outer - inner).max(SPOT_MIN_COS_DELTA);
    (scale, 1.0 + scale * inner)
}

/// A light's `color` and `intensity` (point, spot or directional): finite, non-negative, and
/// their product finite; errors name `field.color` or `field.intensity`.
pub(super) fn validate_emission(
    color: Vec3,
    intensity: f32,
    field: &str,
) -> Result<(), SceneError> {
    if !color.is_finite() || color.min_element() < 0.0 {
        return Err(SceneError::invalid(
            format!("{field}.color"),
            format!("must be finite and >= 0, got {color:?}"),
        ));
    }
    if !(intensity.is_finite() && intensity >= 0.0) {
        return Err(SceneError::invalid(
            format!("{field}.intensity"),
            format!("must be finite and >= 0, got {intensity:?}"),
        ));
    }
    if !(color * intensity).is_finite() {
        return Err(SceneError::invalid(
            format!("{field}.intensity"),
            "color × intensity overflows f32",
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn base() -> Light {
        Light::point(DVec3::ZERO, 1.0, Vec3::ONE, 1.0)
    }

    #[test]
    fn rejects_bad_values_naming_the_field() {
        let cases: Vec<(Light, &str)> = vec![
            (
                Light {
                    radius: f32::NAN,
                    ..base()
                },
                "lights[0].radius",
            ),
            (
                Light {
                    radius: -1.0,
                    ..base()
                },
                "lights[0].radius",
            ),
            (
                Light {
                    intensity: f32::INFINITY,
                    ..base()
                },
                "lights[0].intensity",
            ),
            (
                Light {
                    color: Vec3::new(1.0, -1.0, 0.0),
                    ..base()
                },
                "lights[0].color",
            ),
            (
                Light {
                    position: DVec3::new(0.0, f64::NAN, 0.0),
                    ..base()
                },
                "lights[0].position",
            ),
            (
                Light::spot(
                    DVec3::ZERO,
                    1.0,
                    Vec3::ONE,
                    1.0,
                    Cone {
                        direction: DVec3::Z,
                        inner_deg: 30.0,
                        outer_deg: 20.0,
                    },
                ),
                "lights[0].outer_deg",
            ),
            (
                Light::spot(
                    DVec3::ZERO,
                    1.0,
                    Vec3::ONE,
                    1.0,
                    Cone {
                        direction: DVec3::ZERO,
                        inner_deg: 10.0,
                        outer_deg: 20.0,
                    },
                ),
                "lights[0].direction",
            ),
        ];
        for (light, field) in cases {
            let err = light.validate("lights[0]").unwrap_err().to_string();
            assert!(err.contains(field), "expected {field} in: {err}");
        }
        assert!(base().validate("lights[0]").is_ok());
    }

    #[test]
    fn spot_scale_offset_is_finite_for_hard_cones() {
        let l = Light::spot(
            DVec3::ZERO,
            1.0,
            Vec3::ONE,
            1.0,
            Cone {
                direction: DVec3::Z,
                inner_deg: 10.0,
                outer_deg: 10.0,
            },
        );
        let (s, o) = l.spot_scale_offset();
        assert!(s.is_finite() && o.is_finite());
        let (s, o) = base().spot_scale_offset();
        assert_eq!((s, o), (0.0, 1.0));
    }

    /// The spot term `t = offset − scale·(1 − cos θ)` is full (≥ 1) up to the inner angle and
    /// gone (≤ 0) one width past it, at the outer angle where the edge is wider than
    /// `SPOT_MIN_COS_DELTA`: cones narrower than that width (under 0.81°) kept their axis at
    /// (1 − cos(outer)) / 10⁻⁴ of the intensity (32 % at 0.5°, 0 at 0°).
    #[test]
    fn every_cone_is_full_up_to_its_inner_angle_and_dark_past_its_edge() {
        let one_minus_cos = |deg: f64| 1.0 - deg.to_radians().cos();
        for outer in [0.0, 0.2, 0.5, 0.8, 1.0, 10.0, 35.0, 89.0, 170.0] {
            for inner in [0.0, 0.5 * outer, outer] {
                let (scale, offset) = spot_terms(outer, inner);
                let t = |deg: f64| offset - scale * one_minus_cos(deg);
                assert!(t(0.0) >= 1.0 - 1e-9, "{outer}/{inner}: axis {}", t(0.0));
                assert!(
                    t(inner) >= 1.0 - 1e-6,
                    "{outer}/{inner}: inner {}",
                    t(inner)
                );
                let width = (one_minus_cos(outer) - one_minus_cos(inner)).max(SPOT_MIN_COS_DELTA);
                let edge = (1.0 - one_minus_cos(inner) - width).acos().to_degrees();
                assert!(
                    t(edge + 1e-3) <= 0.0,
                    "{outer}/{inner}: past the edge {}",
                    t(edge)
                );
                assert!(
                    edge >= outer - 1e-9,
                    "{outer}/{inner}: the edge {edge} inside the cone"
                );
            }
        }
    }

    /// A cone turned round (RGBA8 records and the shaders, past 90° inside) fades as the
    /// cone does from the front: the same `t` at every angle.
    #[test]
    fn a_cone_turned_round_has_the_same_fade() {
        for outer in [95.0, 120.0, 170.0, 179.9, 180.0] {
            for inner in [91.0, outer - 10.0, outer - 0.01, outer] {
                let (scale, offset) = spot_terms(outer, inner);
                let (back_scale, back_offset) =
                    spot_terms_from_half_cosines(half_cosine(outer), half_cosine(inner));
                assert!(back_scale < 0.0, "{outer}/{inner}");
                for deg in (0..=1800).map(|d| d as f64 * 0.1) {
                    let cos = deg.to_radians().cos();
                    let front = offset - scale * (1.0 - cos);
                    let back = back_offset - back_scale * (1.0 + cos);
                    assert!(
                        (front - back).abs() <= 1e-9 * offset.abs().max(1.0),
                        "{outer}/{inner} at {deg}°: {front} from the front, {back} turned"
                    );
                }
            }
        }
    }
}
