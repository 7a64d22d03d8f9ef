//! Directional lights (a sun): parallel light from infinitely far away, the same everywhere.
//!
//! They have no position and no radius, so they cannot be culled into clusters: every method
//! evaluates them for every pixel, outside its light lists, from a few uniforms. At most
//! [`MAX_DIRECTIONAL_LIGHTS`] are shown; a scene with more keeps the brightest
//! ([`shown_directional_lights`]).

use glam::{DVec3, Vec3};

use super::SceneError;

/// How many directional lights a frame evaluates (the shaders' constant loop bound).
pub const MAX_DIRECTIONAL_LIGHTS: usize = 4;

/// A light from infinitely far away along `direction`: every surface facing it receives
/// `color × intensity` (the irradiance of a surface square to it, before the albedo).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    /// The direction the light travels, from the sun towards the scene, in world space (any
    /// finite, non-zero length).
    pub direction: DVec3,
    /// Linear RGB colour, each channel >= 0.
    pub color: Vec3,
    /// Scalar multiplier of `color`, >= 0.
    pub intensity: f32,
}

impl DirectionalLight {
    /// A light shining along `direction` (from the light towards the scene).
    pub fn new(direction: DVec3, color: Vec3, intensity: f32) -> Self {
        DirectionalLight {
            direction,
            color,
            intensity,
        }
    }

    /// `color × intensity`.
    pub fn radiance(&self) -> Vec3 {
        self.color * self.intensity
    }

    /// True when the light can contribute anything (some radiance and a direction).
    pub fn is_active(&self) -> bool {
        self.radiance().max_element() > 0.0 && super::direction::unit(self.direction).is_some()
    }

    /// Unit vector from a surface towards the light (the opposite of `direction`); zero when
    /// the direction is not valid.
    pub fn to_light(&self) -> DVec3 {
        super::direction::unit(-self.direction).unwrap_or(DVec3::ZERO)
    }

    /// Checks the values the GPU will see; `field` is the path used in the error, e.g.
    /// `directional_lights[0]`.
    pub fn validate(&self, field: &str) -> Result<(), SceneError> {
        if super::direction::unit(self.direction).is_none() {
            return Err(SceneError::invalid(
                format!("{field}.direction"),
                format!("must be finite and non-zero, got {:?}", self.direction),
            ));
        }
        super::light::validate_emission(self.color, self.intensity, field)?;
        Ok(())
    }
}

/// The directional lights a frame shows, in scene order: the active ones, or when there are
/// more than [`MAX_DIRECTIONAL_LIGHTS`], the brightest (by largest channel; ties: the earlier)
/// of them. Fills `shown` (indices into `lights`) and returns how many active lights were left
/// out. Allocates nothing once `shown` has grown to [`MAX_DIRECTIONAL_LIGHTS`].
pub fn shown_directional_lights(lights: &[DirectionalLight], shown: &mut Vec<usize>) -> usize {
    shown.clear();
    let mut active = 0;
    for (i, light) in lights.iter().enumerate() {
        if !light.is_active() {
            continue;
        }
        active += 1;
        let brightness = |j: usize| lights[j].radiance().max_element();
        if shown.len() < MAX_DIRECTIONAL_LIGHTS {
            shown.push(i);
            continue;
        }
        // Replace the dimmest kept light (the later of equals) when this one is brighter.
        let (slot, dimmest) = shown
            .iter()
            .enumerate()
            .min_by(|a, b| {
                brightness(*a.1)
                    .total_cmp(&brightness(*b.1))
                    .then(b.0.cmp(&a.0))
            })
            .map(|(slot, &j)| (slot, brightness(j)))
            .expect("full");
        if light.radiance().max_element() > dimmest {
            shown.remove(slot);
            shown.push(i);
        }
    }
    active - shown.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sun(intensity: f32) -> DirectionalLight {
        DirectionalLight::new(DVec3::NEG_Y, Vec3::ONE, intensity)
    }

    #[test]
    fn the_brightest_four_are_shown_in_scene_order() {
        let lights: Vec<_> = [1.0, 5.0, 0.0, 3.0, 2.0, 4.0, 2.0].map(sun).to_vec();
        let mut shown = Vec::new();
        assert_eq!(shown_directional_lights(&lights, &mut shown), 2);
        assert_eq!(shown, [1, 3, 4, 5]);
        assert_eq!(shown_directional_lights(&lights[..4], &mut shown), 0);
        assert_eq!(shown, [0, 1, 3], "the dark one is not active");
    }

    #[test]
    fn validation_names_the_field() {
        let bad = DirectionalLight::new(DVec3::ZERO, Vec3::ONE, 1.0);
        let e = bad
            .validate("directional_lights[2]")
            .unwrap_err()
            .to_string();
        assert!(e.contains("directional_lights[2].direction"), "{e}");
        let bad = DirectionalLight::new(DVec3::X, Vec3::new(1.0, -1.0, 0.0), 1.0);
        assert!(bad
            .validate("d")
            .unwrap_err()
            .to_string()
            .contains("d.color"));
        let bad = DirectionalLight::new(DVec3::X, Vec3::ONE, f32::NAN);
        assert!(bad
            .validate("d")
            .unwrap_err()
            .to_string()
            .contains("d.intensity"));
        // Any finite non-zero length is a direction.
        assert!(DirectionalLight::new(DVec3::X * 1e300, Vec3::ONE, 1.0)
            .validate("d")
            .is_ok());
        assert_eq!(sun(1.0).to_light(), DVec3::Y);
    }
}
