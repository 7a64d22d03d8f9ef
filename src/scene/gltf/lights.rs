//! `KHR_lights_punctual` → the renderer's [`Light`]s.
//!
//! - Position: the node's world origin; a spot's direction: the node's world −Z.
//! - Units: glTF gives point and spot intensities in candela. The renderer's `intensity` is
//!   taken as candela × [`CANDELA_TO_INTENSITY`] (= 1): a surface 1 unit from a 1 cd light
//!   receives 1 lux, which the renderer shows as radiance 1 × albedo. The renderer's
//!   falloff is `w(d)² / (d² + 1)` (see [`crate::scene::shading::falloff`]), not glTF's
//!   `w(d) / d²`: within about 1 unit of a light it is dimmer than glTF's, and never
//!   infinite. Physically based exports (Blender writes W × 683 / 4π cd) come out bright:
//!   `--exposure` brings them down.
//! - Radius: `range` when given (both reach exactly zero there). Without a range glTF's light
//!   reaches to infinity; the renderer's must stop, so the radius is where the inverse-square
//!   term `I / (d² + 1)` of the light's brightest channel falls to [`UNBOUNDED_CUTOFF`]
//!   ([`unbounded_radius`]). With the renderer's smooth window the difference from an
//!   unbounded `I / (d² + 1)` then stays below 1.09 × the cut-off at every distance.
//! - Cones: glTF's half-angles in radians → `inner_deg` / `outer_deg`. glTF fades linearly
//!   in the cosine and squares; the renderer fades with a smoothstep between the same angles.
//! - Node scale moves lights but changes neither their radius nor their intensity (as glTF
//!   says). Directional lights cannot be shown (every light needs a finite radius): each is
//!   skipped with a warning.

use glam::{DMat4, DVec3, Vec3};
use gltf::khr_lights_punctual::Kind;

use crate::scene::camera::MAX_CAMERA_COORD;
use crate::scene::{Light, LightKind};

/// Renderer `intensity` per candela of a glTF point or spot light.
pub const CANDELA_TO_INTENSITY: f64 = 1.0;

/// Radiance (linear, before the surface's albedo) at which a light without a `range` is cut
/// off: 1/1024, about one 8-bit step of the sRGB output over the default ambient.
pub const UNBOUNDED_CUTOFF: f64 = 1.0 / 1024.0;

/// Radius for a light of peak radiance `peak` (its brightest channel of colour × intensity)
/// that glTF lets reach to infinity: where `peak / (d² + 1)` is [`UNBOUNDED_CUTOFF`]; 0 when
/// even its peak is below the cut-off.
pub fn unbounded_radius(peak: f64) -> f64 {
    // NaN falls here too.
    if peak.is_nan() || peak <= UNBOUNDED_CUTOFF {
        return 0.0;
    }
    (peak / UNBOUNDED_CUTOFF - 1.0).sqrt()
}

/// The result of converting one node's light.
pub(super) enum Converted {
    /// A light the renderer shows.
    Light(Light),
    /// Not shown; the warning says why.
    Skipped(String),
}

/// Converts `light` on a node with world transform `world`; `field` names it
/// (`nodes[3] (extensions.KHR_lights_punctual.lights[1])`).
pub(super) fn convert(
    light: &gltf::khr_lights_punctual::Light,
    world: &DMat4,
    field: &str,
) -> Result<Converted, String> {
    let color = Vec3::from(light.color());
    let raw = light.intensity();
    if !raw.is_finite() || raw < 0.0 {
        return Err(format!(
            "{field}: intensity must be finite and >= 0, got {raw}"
        ));
    }
    if !color.is_finite() || color.min_element() < 0.0 {
        return Err(format!(
            "{field}: color must be finite and >= 0, got {color:?}"
        ));
    }
    let intensity = (f64::from(raw) * CANDELA_TO_INTENSITY) as f32;
    let kind = match light.kind() {
        Kind::Directional => {
            return Ok(Converted::Skipped(format!(
                "{field}: directional lights are not supported by the renderer (every light \
                 needs a finite radius); skipped"
            )))
        }
        Kind::Point => LightKind::Point,
        Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => {
            let direction = world.transform_vector3(DVec3::NEG_Z);
            let Some(direction) = crate::scene::direction::unit(direction) else {
                return Ok(Converted::Skipped(format!(
                    "{field}: the node's transform has no direction (zero scale); skipped"
                )));
            };
            LightKind::Spot {
                direction,
                inner_deg: f64::from(inner_cone_angle).to_degrees(),
                outer_deg: f64::from(outer_cone_angle).to_degrees(),
            }
        }
    };
    let position = world.transform_point3(DVec3::ZERO);
    let reach = position.abs().max_element();
    if !reach.is_finite() || reach > MAX_CAMERA_COORD {
        return Err(format!(
            "{field}: world position {position:?} is not within ±{MAX_CAMERA_COORD:e}"
        ));
    }
    let radius = match light.range() {
        Some(range) if range.is_finite() && range > 0.0 => range,
        Some(range) => {
            return Err(format!(
                "{field}: range must be finite and > 0, got {range}"
            ))
        }
        None => {
            let peak = f64::from(color.max_element()) * f64::from(intensity);
            unbounded_radius(peak) as f32
        }
    };
    let light = Light {
        kind,
        position,
        radius,
        color,
        intensity,
    };
    // Names the value (`….outer_deg`, `….intensity` when colour × intensity overflows).
    light.validate(field).map_err(|e| e.to_string())?;
    Ok(Converted::Light(light))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::shading::falloff;

    #[test]
    fn the_unbounded_radius_is_where_the_light_meets_the_cutoff() {
        for peak in [0.01, 1.0, 50.0, 1e6] {
            let r = unbounded_radius(peak);
            assert!(
                (peak / (r * r + 1.0) - UNBOUNDED_CUTOFF).abs() < 1e-12,
                "{peak}"
            );
            assert_eq!(falloff(r, r), 0.0, "exactly zero at the radius");
            // The windowed falloff never differs from the unbounded I/(d²+1) by more than
            // 1.09 × the cut-off.
            for k in 1..200 {
                let d = r * k as f64 / 100.0;
                let unbounded = peak / (d * d + 1.0);
                assert!(
                    unbounded - peak * falloff(d, r) <= 1.09 * UNBOUNDED_CUTOFF,
                    "{peak} {d}"
                );
            }
        }
        assert_eq!(unbounded_radius(UNBOUNDED_CUTOFF * 0.5), 0.0);
        assert_eq!(unbounded_radius(f64::NAN), 0.0);
    }
}
