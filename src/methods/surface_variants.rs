//! What an object's material and mesh add to its shader variant, and the shared variants a
//! scene with too many combinations of them is drawn with instead.
//!
//! Each distinct combination of surface inputs is a program of its own, compiled at first
//! draw (compile time and driver memory; docs/gltf.md): a small file whose materials cover
//! every combination would ask for hundreds. Past [`MAX_SURFACE_VARIANTS`] a scene's objects take the
//! shared superset of the inputs that have a neutral value (below), so the picture stays the
//! same and the programs stay few.

use super::maps;
use super::ShaderFeatures as F;
use crate::scene::{Material, Mesh, Scene};

/// The most distinct surface variants a scene's objects are drawn with as they are; past it
/// they share the superset variants ([`shared`]). Real scenes have a handful.
pub const MAX_SURFACE_VARIANTS: usize = 32;

/// The surface inputs a shared variant turns on where an object lacks them, each with a value
/// that changes nothing: a white texture for the albedo and the emissive, occlusion and
/// metallic-roughness maps, no emission, no specular colour, identity texture transforms, and
/// the white colour a mesh without vertex colours reads. Normal maps and the alpha modes have
/// no such value and keep their own variants.
const SHARED_INPUTS: u64 = F::TEXTURE
    | F::EMISSIVE
    | F::EMISSIVE_MAP
    | F::OCCLUSION
    | F::TEXTURE_TRANSFORM
    | F::VERTEX_COLOR;

/// The features an object's material and mesh select, on a context with `units` fragment
/// texture units: its surface inputs ([`maps::features`]), whether it samples an albedo
/// texture (`textured`), its alpha cut and blend, and its BRDF.
pub(crate) fn own(material: &Material, mesh: &Mesh, textured: bool, units: i32) -> F {
    let inputs = maps::features(material, mesh, units);
    let metallic_roughness = material.is_metallic_roughness();
    inputs
        .with(F::TEXTURE, textured)
        .with(
            F::ALPHA_MASK,
            (textured || inputs.has(F::VERTEX_ALPHA)) && material.alpha_cutoff.is_some(),
        )
        .with(F::TEXTURE_ALPHA, textured && material.alpha_texture)
        .with(F::SPECULAR, !metallic_roughness && material.has_specular())
        .with(F::METALLIC_ROUGHNESS, metallic_roughness)
}

/// `own` (an object's [`own`] features) widened to the shared variant of its kind: the
/// neutral inputs of [`SHARED_INPUTS`], the metallic-roughness texture for that BRDF and the
/// specular term for Blinn-Phong, each map only where its texture unit exists.
pub(crate) fn shared(own: F, units: i32) -> F {
    let metallic_roughness = own.has(F::METALLIC_ROUGHNESS);
    let mut bits = F(own.0 | SHARED_INPUTS)
        .with(F::SPECULAR, !metallic_roughness)
        .with(F::MR_TEXTURE, metallic_roughness);
    for bit in [F::EMISSIVE_MAP, F::OCCLUSION, F::MR_TEXTURE] {
        if !maps::unit_fits(bit, units) {
            bits = bits.with(bit, false);
        }
    }
    bits
}

/// Counts the distinct [`own`] feature sets of a scene's objects, in buffers kept from frame to
/// frame (a frame allocates nothing once they have grown).
#[derive(Default)]
pub(crate) struct VariantCount {
    /// For each material, the first object of each attribute class.
    firsts: Vec<[u32; 16]>,
    /// The distinct feature sets found so far.
    seen: Vec<u64>,
}

impl VariantCount {
    /// Whether the scene's objects draw with more than `limit` distinct [`own`] feature sets
    /// on a context with `units` fragment texture units. Objects are grouped by material and
    /// by which attributes their mesh has (all [`maps::features`] reads of a mesh), so the work
    /// per object is a look-up.
    pub(crate) fn more_than(&mut self, scene: &Scene, units: i32, limit: usize) -> bool {
        self.firsts.clear();
        self.firsts.resize(scene.materials.len(), [u32::MAX; 16]);
        let mut pairs = 0usize;
        for (i, object) in scene.objects.iter().enumerate() {
            let Some(slot) = self.firsts.get_mut(object.material) else {
                continue;
            };
            let class = attribute_class(&object.mesh);
            if slot[class] == u32::MAX {
                slot[class] = i as u32;
                pairs += 1;
            }
        }
        if pairs <= limit {
            return false;
        }
        self.seen.clear();
        for (material, slot) in scene.materials.iter().zip(&self.firsts) {
            for &first in slot.iter().filter(|&&i| i != u32::MAX) {
                let mesh = &scene.objects[first as usize].mesh;
                let textured = maps::base_textured(material, mesh);
                let bits = own(material, mesh, textured, units).0;
                if !self.seen.contains(&bits) {
                    if self.seen.len() == limit {
                        return true;
                    }
                    self.seen.push(bits);
                }
            }
        }
        false
    }
}

/// Which of the attributes [`maps::features`] looks at `mesh` has, as four bits.
fn attribute_class(mesh: &Mesh) -> usize {
    usize::from(!mesh.colors.is_empty())
        | usize::from(!mesh.uvs.is_empty()) << 1
        | usize::from(!mesh.tangents.is_empty()) << 2
        | usize::from(!mesh.second_uvs.is_empty()) << 3
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::builtin;
    use glam::{DMat4, Vec3};
    use std::sync::Arc;

    /// A scene of `n` objects sharing one mesh, each with its own material, the `k`-th
    /// emitting when bit 0 of `k` is set, blending when bit 1 is, glossy when bit 2 is.
    fn scene_of(n: usize) -> Scene {
        let mut scene = builtin::build("plane", None).unwrap();
        let mesh = scene.objects[0].mesh.clone();
        scene.objects.clear();
        scene.materials.clear();
        for k in 0..n {
            let mut m = Material::flat(&format!("m{k}"), Vec3::splat(0.5));
            if k & 1 != 0 {
                m.maps.emissive = Vec3::ONE;
            }
            if k & 2 != 0 {
                m.alpha = 0.5;
            }
            if k & 4 == 0 {
                m.specular = Vec3::ZERO;
            }
            scene.materials.push(m);
            scene.add_object(Arc::clone(&mesh), k, DMat4::IDENTITY);
        }
        scene
    }

    fn more_than(scene: &Scene, limit: usize) -> bool {
        VariantCount::default().more_than(scene, 8, limit)
    }

    #[test]
    fn counts_distinct_feature_sets_not_materials() {
        // Eight materials, but alpha alone selects no variant: four sets.
        let eight = scene_of(8);
        assert!(more_than(&eight, 3) && !more_than(&eight, 4));
        // A material used by many objects counts once.
        let mut s = scene_of(2);
        let mesh = s.objects[0].mesh.clone();
        for _ in 0..100 {
            s.add_object(Arc::clone(&mesh), 1, DMat4::IDENTITY);
        }
        assert!(more_than(&s, 1) && !more_than(&s, 2));
        // The buffers are kept: a second scene is counted afresh.
        let mut count = VariantCount::default();
        assert!(count.more_than(&eight, 8, 3) && !count.more_than(&s, 8, 3));
    }

    #[test]
    fn a_mesh_without_colours_is_another_variant_than_one_with() {
        let mut s = scene_of(1);
        let mut coloured = (*s.objects[0].mesh).clone();
        coloured.colors = vec![glam::Vec4::ONE; coloured.positions.len()];
        s.add_object(coloured, 0, DMat4::IDENTITY);
        assert!(more_than(&s, 1) && !more_than(&s, 2));
    }

    #[test]
    fn shared_variants_keep_what_has_no_neutral_value() {
        let units = 8;
        let plain = F::default();
        let s = shared(plain, units);
        assert!(s.has(F::TEXTURE) && s.has(F::EMISSIVE_MAP) && s.has(F::SPECULAR));
        assert!(!s.has(F::MR_TEXTURE) && !s.has(F::NORMAL_MAP) && !s.has(F::ALPHA_MASK));
        let mr = shared(F(F::METALLIC_ROUGHNESS), units);
        assert!(mr.has(F::MR_TEXTURE) && !mr.has(F::SPECULAR));
        // Every object of one kind shares one variant, whatever its own inputs.
        let rich = F(F::EMISSIVE | F::OCCLUSION | F::TEXTURE | F::VERTEX_COLOR | F::SPECULAR);
        assert_eq!(shared(rich, units), s);
        // Normal maps and alpha modes stay apart.
        assert_ne!(shared(F(F::NORMAL_MAP), units), s);
        assert_ne!(shared(F(F::TEXTURE | F::ALPHA_MASK), units), s);
        // No map past the context's units.
        let few = shared(plain, 5);
        assert!(!few.has(F::EMISSIVE_MAP) && !few.has(F::OCCLUSION) && few.has(F::EMISSIVE));
    }
}
