//! `--material-model metallic-roughness`: the scenes' Blinn-Phong materials converted.

use manylight::scene::{self, Scene};

/// Every Blinn-Phong material as a dielectric metallic-roughness one of the same colour, its
/// roughness the glTF loader's exponent match inverted (`Ns = 2/α² − 2`, `α = roughness²`).
/// Only the reflectance changes: opacity, cut-outs, sides, surface maps and depth bias stay.
pub(super) fn to_metallic_roughness(scene: &mut Scene) {
    for m in &mut scene.materials {
        if !m.is_metallic_roughness() {
            m.roughness = (2.0 / (m.shading_exponent() + 2.0)).powf(0.25);
            m.model = scene::MaterialModel::MetallicRoughness;
            m.metallic = 0.0;
            // Not read by metallic-roughness: as `Material::metallic_roughness` leaves it.
            m.specular = glam::Vec3::ZERO;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The conversion changes the reflectance alone: a decal's bias, a cut-out, a single side
    /// and its opacity stay; a metallic-roughness material is left as it was.
    #[test]
    fn converting_to_metallic_roughness_keeps_everything_but_the_reflectance() {
        use manylight::scene::{Material, MaterialModel};
        let mut scene = Scene::empty();
        let mut glossy = Material {
            depth_bias: 2.0,
            alpha: 0.5,
            alpha_cutoff: Some(0.3),
            alpha_texture: true,
            alpha_vertex: true,
            double_sided: false,
            ..Material::glossy(
                "decal",
                glam::Vec3::new(0.8, 0.2, 0.1),
                glam::Vec3::ONE,
                30.0,
            )
        };
        glossy.maps.emissive = glam::Vec3::new(0.1, 0.2, 0.3);
        scene.add_material(glossy.clone());
        let metal = Material::metallic_roughness("metal", glam::Vec3::ONE, 1.0, 0.4);
        scene.add_material(metal.clone());
        to_metallic_roughness(&mut scene);
        let converted = &scene.materials[0];
        assert_eq!(converted.model, MaterialModel::MetallicRoughness);
        assert_eq!(
            (converted.metallic, converted.diffuse),
            (0.0, glossy.diffuse)
        );
        // Ns 30 = 2/α² − 2 with α = roughness².
        let alpha = converted.roughness.powi(2);
        assert!((2.0 / (alpha * alpha) - 2.0 - 30.0).abs() < 1e-3, "{alpha}");
        let kept = |m: &Material| {
            let alpha = (m.alpha, m.alpha_cutoff, m.alpha_texture, m.alpha_vertex);
            (m.depth_bias, alpha, m.double_sided, m.maps.emissive)
        };
        assert_eq!(kept(converted), kept(&glossy));
        let reflectance = |m: &Material| (m.model, m.metallic, m.roughness);
        assert_eq!(reflectance(&scene.materials[1]), reflectance(&metal));
    }
}
