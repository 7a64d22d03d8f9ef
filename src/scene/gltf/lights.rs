//! `KHR_lights_punctual` → the renderer's [`Light`]s.
//!
//! - Position: the node's world origin; a spot's or a directional light's direction: the
//!   node's world −Z.
//! - Units: glTF is photometric: point and spot intensities in candela, directional ones in
//!   lux. Both come in on one scale, [`PHOTOMETRIC_SCALE`] = 2⁻¹¹: renderer intensity =
//!   cd × 2⁻¹¹ ([`CANDELA_TO_INTENSITY`]) = lux × 2⁻¹¹ ([`LUX_TO_INTENSITY`]), so a surface
//!   square to a sun of 2 048 lux shows radiance 1 × albedo (and one facing a lamp of I cd,
//!   d away, I × 2⁻¹¹ / (d² + 1) × albedo).
//!   This is the default exposure of glTF scenes, −11 EV against the raw numbers: a lamp of a
//!   few hundred cd lights a room a few metres across, and a sun of a few thousand lux an
//!   outdoor scene, without going black or white (the real sun's 100 000 lux needs
//!   `--exposure -6` or a tone map); `--exposure` works on top. The renderer's
//!   falloff is `w(d)² / (d² + 1)` (see [`crate::scene::shading::falloff`]), not glTF's
//!   `w(d) / d²`: within about 1 unit of a light it is dimmer than glTF's, and never
//!   infinite.
//! - Radius: `range` when given (both reach exactly zero there). Without a range glTF's light
//!   reaches to infinity; the renderer's must stop, so the radius is where the inverse-square
//!   term `I / (d² + 1)` of the light's brightest channel falls to [`UNBOUNDED_CUTOFF`]
//!   ([`unbounded_radius`]). With the renderer's smooth window the difference from an
//!   unbounded `I / (d² + 1)` then stays below 1.09 × the cut-off at every distance.
//! - Cones: glTF's half-angles in radians → `inner_deg` / `outer_deg`. glTF fades linearly
//!   in the cosine and squares; the renderer fades with a smoothstep between the same angles.
//! - Node scale moves lights but changes neither their radius nor their intensity (as glTF
//!   says). Directional lights become [`DirectionalLight`]s (a frame shows the brightest four).

use glam::{DMat4, DVec3, Vec3};
use gltf::khr_lights_punctual::Kind;

use crate::scene::camera::MAX_CAMERA_COORD;
use crate::scene::{DirectionalLight, Light, LightKind, Short};

/// The one scale of glTF's photometric units (candela, lux) to the renderer's intensity: in
/// effect a default exposure of −11 EV for glTF files (see the module's notes).
pub const PHOTOMETRIC_SCALE: f64 = 1.0 / 2048.0;

/// Renderer `intensity` per candela of a glTF point or spot light.
pub const CANDELA_TO_INTENSITY: f64 = PHOTOMETRIC_SCALE;

/// Renderer `intensity` per lux of a glTF directional light.
pub const LUX_TO_INTENSITY: f64 = PHOTOMETRIC_SCALE;

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

/// Why a light without a `range` whose brightest channel is at most [`UNBOUNDED_CUTOFF`] is
/// left out: it would be cut off everywhere. The same words for every such light, so that a
/// file of many is one warning (`ignored::once_per_feature`).
fn too_dim(field: &str) -> String {
    format!(
        "{field}: no `range`, and its brightest channel (colour × intensity) is at most the \
         {} cd where a light without a range is cut off (docs/gltf.md, \"Lights\"): it would \
         light nothing, so it is left out; give it a `range` or more intensity to keep it",
        UNBOUNDED_CUTOFF / CANDELA_TO_INTENSITY
    )
}

/// The result of converting one node's light.
pub(super) enum Converted {
    /// A light the renderer shows.
    Light(Light),
    /// A directional light (a sun).
    Directional(DirectionalLight),
    /// Not shown; the warning says why.
    Skipped(String),
}

/// What an infinite value in these messages was in the file: the glTF crate reads the light's
/// numbers as `f32`, so a finite JSON number past its range (`1e39`) arrives infinite.
fn past_f32(infinite: bool) -> String {
    if infinite {
        format!(
            " (a number past f32's range, ±{:.1e}, reads as infinite)",
            f32::MAX
        )
    } else {
        String::new()
    }
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
            "{field}: intensity must be finite and >= 0, got {}{}",
            Short(raw),
            past_f32(raw.is_infinite())
        ));
    }
    if !color.is_finite() || color.min_element() < 0.0 {
        return Err(format!(
            "{field}: color must be finite and >= 0, got {}{}",
            crate::scene::short3(color),
            past_f32(color.to_array().iter().any(|c| c.is_infinite()))
        ));
    }
    let kind = match light.kind() {
        Kind::Directional => {
            let direction = world.transform_vector3(DVec3::NEG_Z);
            if crate::scene::direction::unit(direction).is_none() {
                return Ok(Converted::Skipped(format!(
                    "{field}: the node's transform has no direction (zero scale); skipped"
                )));
            }
            let intensity = (f64::from(raw) * LUX_TO_INTENSITY) as f32;
            let sun = DirectionalLight::new(direction, color, intensity);
            sun.validate(field).map_err(|e| e.to_string())?;
            return Ok(Converted::Directional(sun));
        }
        Kind::Point => LightKind::Point,
        Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => {
            // Named in the file's terms (radians), not as the converted `outer_deg`.
            for (name, angle) in [
                ("innerConeAngle", inner_cone_angle),
                ("outerConeAngle", outer_cone_angle),
            ] {
                if !(0.0..=std::f32::consts::PI).contains(&angle) {
                    return Err(format!(
                        "{field}: spot.{name} ({angle:?}) must be within [0, π] radians"
                    ));
                }
            }
            if inner_cone_angle > outer_cone_angle {
                return Err(format!(
                    "{field}: spot.innerConeAngle ({inner_cone_angle}) must not exceed \
                     spot.outerConeAngle ({outer_cone_angle})"
                ));
            }
            let direction = world.transform_vector3(DVec3::NEG_Z);
            let Some(direction) = crate::scene::direction::unit(direction) else {
                return Ok(Converted::Skipped(format!(
                    "{field}: the node's transform has no direction (zero scale); skipped"
                )));
            };
            // f32's π is 180.000005°: an angle the check above lets through is at most 180°.
            let degrees = |radians: f32| f64::from(radians).to_degrees().min(180.0);
            LightKind::Spot {
                direction,
                inner_deg: degrees(inner_cone_angle),
                outer_deg: degrees(outer_cone_angle),
            }
        }
    };
    let intensity = (f64::from(raw) * CANDELA_TO_INTENSITY) as f32;
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
                "{field}: range must be finite and > 0, got {}{}",
                Short(range),
                past_f32(range.is_infinite())
            ))
        }
        None => {
            let peak = f64::from(color.max_element()) * f64::from(intensity);
            if peak > 0.0 && unbounded_radius(peak) == 0.0 {
                return Ok(Converted::Skipped(too_dim(field)));
            }
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
