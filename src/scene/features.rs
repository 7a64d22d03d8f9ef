//! What a scene actually uses, so shaders and resources can leave out the rest.

use serde::Serialize;

use super::{LightKind, Scene};

/// Features present in a scene. Shader variants are compiled with only these (see
/// `methods::ShaderFeatures`), and a scene without lights does no light work at all.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct SceneFeatures {
    /// At least one active point light.
    pub point_lights: bool,
    /// At least one active spot light (cone code compiled in).
    pub spot_lights: bool,
    /// At least one active directional light (a sun), evaluated outside the light lists.
    pub directional_lights: bool,
    /// At least one material with a diffuse texture.
    pub textures: bool,
    /// At least one material with a specular term.
    pub specular: bool,
    /// At least one transparent material (alpha below 1).
    pub transparency: bool,
    /// At least one metallic-roughness material (glTF BRDF code compiled in for it).
    pub metallic_roughness: bool,
    /// Any active point or spot light at all.
    pub lights: bool,
}

impl SceneFeatures {
    /// The features of `scene`: only lights that can contribute count, and only materials an
    /// object draws with (an OBJ's fallback material, say, may have none).
    pub fn of(scene: &Scene) -> SceneFeatures {
        let active = || scene.lights.iter().filter(|l| l.is_active());
        let mut features = SceneFeatures {
            point_lights: active().any(|l| matches!(l.kind, LightKind::Point)),
            spot_lights: active().any(|l| matches!(l.kind, LightKind::Spot { .. })),
            directional_lights: scene.directional_lights.iter().any(|l| l.is_active()),
            lights: active().next().is_some(),
            ..SceneFeatures::default()
        };
        for m in (scene.objects.iter()).filter_map(|o| scene.materials.get(o.material)) {
            features.textures |= m.diffuse_texture.is_some();
            features.specular |= m.has_specular();
            features.transparency |= m.is_transparent();
            features.metallic_roughness |= m.is_metallic_roughness();
        }
        features
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::builtin;

    #[test]
    fn features_follow_the_scene() {
        let plane = builtin::build("plane", None).unwrap();
        let f = SceneFeatures::of(&plane);
        assert!(!f.lights && !f.spot_lights && !f.textures && !f.transparency && f.specular);
        let court = builtin::build("courtyard", Some((8, 1))).unwrap();
        let f = SceneFeatures::of(&court);
        assert!(f.lights && f.point_lights && f.spot_lights && !f.transparency);
        assert!(SceneFeatures::of(&builtin::build("bubbles", None).unwrap()).transparency);
        let mut sunny = builtin::build("plane", None).unwrap();
        assert!(!SceneFeatures::of(&sunny).directional_lights);
        let sun = crate::scene::DirectionalLight::new(glam::DVec3::NEG_Y, glam::Vec3::ONE, 0.0);
        sunny.directional_lights.push(sun);
        assert!(
            !SceneFeatures::of(&sunny).directional_lights,
            "a dark sun is not active"
        );
        sunny.directional_lights[0].intensity = 2.0;
        assert!(SceneFeatures::of(&sunny).directional_lights);
        assert!(!SceneFeatures::of(&sunny).metallic_roughness);
        let mr = crate::scene::Material::metallic_roughness("m", glam::Vec3::ONE, 1.0, 0.5);
        sunny.materials.push(mr);
        assert!(
            !SceneFeatures::of(&sunny).metallic_roughness,
            "no object draws with it"
        );
        sunny.objects[0].material = sunny.materials.len() - 1;
        assert!(SceneFeatures::of(&sunny).metallic_roughness);
        // The plane's own material, specular, is now drawn by nothing.
        assert!(!SceneFeatures::of(&sunny).specular);
    }
}
