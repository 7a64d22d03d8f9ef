//! The material's surface inputs beyond the base colour (`glsl/surface_maps.glsl`): which
//! shader features an object needs, its textures' units and its uniforms.
//!
//! Texture units: the base colour has unit 0 and the methods' geometry programs use units 1
//! to 3 (clustered's lights, grid and index list), so the four maps take units 4 to 7 — within
//! the 8 fragment units ES 2.0 guarantees. A context with fewer leaves out the maps that do
//! not fit, with a warning naming them (once per process).

use std::sync::atomic::{AtomicBool, Ordering};

use glam::{Mat3, Vec2, Vec3};

use super::ShaderFeatures as F;
use crate::gl::program::{Resolver, Sampler, Uniform};
use crate::gl::Device;
use crate::gpu_scene::GpuScene;
use crate::scene::surface_maps::{MapTexture, TextureTransform};
use crate::scene::texture::{Sampling, Wrap};
use crate::scene::{Material, Mesh};

/// First texture unit of the maps: after the most any geometry program's method uses
/// (checked against `geometry::UNIT_METHOD` there).
pub const UNIT_MAPS: u32 = 4;

/// The map slots: feature bit, texture unit, name for warnings.
const SLOTS: [(u64, u32, &str); 4] = [
    (F::NORMAL_MAP, UNIT_MAPS, "normal map"),
    (F::EMISSIVE_MAP, UNIT_MAPS + 1, "emissive texture"),
    (F::OCCLUSION, UNIT_MAPS + 2, "occlusion texture"),
    (F::MR_TEXTURE, UNIT_MAPS + 3, "metallic-roughness texture"),
];

/// Whether each slot's missing-unit warning was given.
static WARNED: [AtomicBool; 4] = [
    AtomicBool::new(false),
    AtomicBool::new(false),
    AtomicBool::new(false),
    AtomicBool::new(false),
];

/// Whether a normal map on a mesh without tangents was warned of (once a process).
static WARNED_TANGENTLESS: AtomicBool = AtomicBool::new(false);

/// Whether `material`'s base colour texture is sampled on `mesh`: the mesh has the
/// coordinate set it reads. Without, every pixel would read one texel: the material's flat
/// colours draw it, as the loaders warn.
pub(crate) fn base_textured(material: &Material, mesh: &Mesh) -> bool {
    material.diffuse_texture.is_some() && material.maps.base_transform.coordinates(mesh).is_some()
}

/// The surface-input features of `material` on `mesh`, on a context with `units` fragment
/// texture units: each only where the material (or mesh) has it. A map is sampled only where
/// the mesh has the coordinate set it reads.
pub fn features(material: &Material, mesh: &Mesh, units: i32) -> F {
    let maps = &material.maps;
    let emits = maps.emits();
    let sampled =
        |map: Option<&MapTexture>| map.is_some_and(|m| m.transform.coordinates(mesh).is_some());
    let normal_mapped = sampled(maps.sampled_normal());
    if normal_mapped
        && mesh.tangents.is_empty()
        && !WARNED_TANGENTLESS.swap(true, Ordering::Relaxed)
    {
        log::warn!(
            "the normal map of material `{}` is not applied on a mesh without tangents: give a \
             mesh built in code its tangents with Mesh::with_generated_tangents (the glTF \
             loader makes them)",
            material.name
        );
    }
    let mut bits = [
        (F::VERTEX_COLOR, !mesh.colors.is_empty()),
        (
            F::VERTEX_ALPHA,
            material.alpha_vertex && !mesh.colors.is_empty(),
        ),
        (F::NORMAL_MAP, normal_mapped && !mesh.tangents.is_empty()),
        (F::EMISSIVE, emits),
        (F::EMISSIVE_MAP, sampled(maps.sampled_emissive())),
        (F::OCCLUSION, sampled(maps.sampled_occlusion())),
        (
            F::MR_TEXTURE,
            sampled(material.sampled_metallic_roughness()),
        ),
    ]
    .into_iter()
    .fold(F::default(), |f, (bit, on)| f.with(bit, on));
    for (k, (bit, unit, name)) in SLOTS.iter().enumerate() {
        if bits.has(*bit) && *unit as i32 >= units {
            bits = bits.with(*bit, false);
            if !WARNED[k].swap(true, Ordering::Relaxed) {
                log::warn!(
                    "the {name} of material `{}` is not applied: it needs texture unit {unit} \
                     and this context has {units} fragment texture units",
                    material.name
                );
            }
        }
    }
    let base = base_textured(material, mesh).then_some(&maps.base_transform);
    let slots = [
        (F::NORMAL_MAP, &maps.normal),
        (F::EMISSIVE_MAP, &maps.emissive_texture),
        (F::OCCLUSION, &maps.occlusion),
        (F::MR_TEXTURE, &maps.metallic_roughness),
    ];
    let mut read = slots
        .iter()
        .filter(|(bit, _)| bits.has(*bit))
        .filter_map(|(_, t)| t.as_ref().map(|t| &t.transform))
        .chain(base);
    let second = read.clone().any(|t| t.uv_set == 1);
    let transformed = read.any(|t| !t.is_identity());
    bits.with(F::TEXTURE_TRANSFORM, transformed)
        .with(F::SECOND_UVS, second)
}

/// Whether the map of feature `bit` has its texture unit on a context with `units`.
pub(crate) fn unit_fits(bit: u64, units: i32) -> bool {
    (SLOTS.iter()).any(|(b, unit, _)| *b == bit && (*unit as i32) < units)
}

/// One map as [`MapUniforms::set`] binds it: feature bit, texture, sampler, UV transform and
/// coordinate set.
type MapSlot<'a> = (
    u64,
    &'a Option<MapTexture>,
    &'a Uniform<Sampler>,
    &'a Uniform<Mat3>,
    &'a Uniform<f32>,
);

/// The uniforms of `surface_maps.glsl`.
pub struct MapUniforms {
    albedo_uv: Uniform<Mat3>,
    normal_uv: Uniform<Mat3>,
    emissive_uv: Uniform<Mat3>,
    occlusion_uv: Uniform<Mat3>,
    mr_uv: Uniform<Mat3>,
    /// Each texture's coordinate set (`HAS_SECOND_UVS`).
    albedo_set: Uniform<f32>,
    normal_set: Uniform<f32>,
    emissive_set: Uniform<f32>,
    occlusion_set: Uniform<f32>,
    mr_set: Uniform<f32>,
    normal_tex: Uniform<Sampler>,
    normal_scale: Uniform<f32>,
    emissive: Uniform<Vec3>,
    emissive_tex: Uniform<Sampler>,
    occlusion_tex: Uniform<Sampler>,
    occlusion_strength: Uniform<f32>,
    mr_tex: Uniform<Sampler>,
}

impl MapUniforms {
    /// `colour`: whether the variant computes a colour (not a count) and so reads the maps.
    /// The metallic-roughness texture is optional: its reader is the light model's.
    pub(crate) fn resolve(r: &mut Resolver<'_>, colour: bool) -> Self {
        let f = F(r.features());
        let on = |bit| colour && f.has(bit);
        // The transforms are mesh.vert's; a slot the variant does not sample may be dropped.
        MapUniforms {
            albedo_uv: r.optional("u_albedoUvTransform"),
            normal_uv: r.optional("u_normalUvTransform"),
            emissive_uv: r.optional("u_emissiveUvTransform"),
            occlusion_uv: r.optional("u_occlusionUvTransform"),
            mr_uv: r.optional("u_metallicRoughnessUvTransform"),
            albedo_set: r.optional("u_albedoUvSet"),
            normal_set: r.optional("u_normalUvSet"),
            emissive_set: r.optional("u_emissiveUvSet"),
            occlusion_set: r.optional("u_occlusionUvSet"),
            mr_set: r.optional("u_metallicRoughnessUvSet"),
            normal_tex: r.required_when(on(F::NORMAL_MAP), "u_normalTex"),
            normal_scale: r.required_when(on(F::NORMAL_MAP), "u_normalScale"),
            emissive: r.required_when(on(F::EMISSIVE), "u_emissive"),
            emissive_tex: r.required_when(on(F::EMISSIVE_MAP), "u_emissiveTex"),
            occlusion_tex: r.required_when(on(F::OCCLUSION), "u_occlusionTex"),
            occlusion_strength: r.required_when(on(F::OCCLUSION), "u_occlusionStrength"),
            mr_tex: r.optional("u_metallicRoughnessTex"),
        }
    }

    /// Binds the maps `features` selected and sets their uniforms. Where `features` has an
    /// input the object's `own` features lack (a shared variant:
    /// [`super::surface_variants::shared`]), the input's neutral value stands in: the white
    /// texture, no emission, an identity transform on the first coordinate set. The emission
    /// is times `pre_exposure`, as the frame's lights are ([`F::pre_exposure`]).
    pub(crate) fn set(
        &self,
        dev: &Device,
        material: &Material,
        features: F,
        own: F,
        scene: &GpuScene,
        pre_exposure: f32,
    ) {
        let maps = &material.maps;
        let transformed = own.has(F::TEXTURE_TRANSFORM);
        let second = features.has(F::SECOND_UVS);
        if features.has(F::TEXTURE_TRANSFORM) {
            let sampling = material.diffuse_texture.as_ref().map(|t| t.sampling);
            let albedo = transformed.then(|| uv_matrix(&maps.base_transform, sampling));
            self.albedo_uv.set(dev, albedo.unwrap_or(Mat3::IDENTITY));
        }
        if second {
            let base = own.has(F::TEXTURE).then_some(maps.base_transform.uv_set);
            self.albedo_set.set(dev, base.unwrap_or(0) as f32);
        }
        let slots: [MapSlot<'_>; 4] = [
            (
                F::NORMAL_MAP,
                &maps.normal,
                &self.normal_tex,
                &self.normal_uv,
                &self.normal_set,
            ),
            (
                F::EMISSIVE_MAP,
                &maps.emissive_texture,
                &self.emissive_tex,
                &self.emissive_uv,
                &self.emissive_set,
            ),
            (
                F::OCCLUSION,
                &maps.occlusion,
                &self.occlusion_tex,
                &self.occlusion_uv,
                &self.occlusion_set,
            ),
            (
                F::MR_TEXTURE,
                &maps.metallic_roughness,
                &self.mr_tex,
                &self.mr_uv,
                &self.mr_set,
            ),
        ];
        for ((bit, map, sampler, uv, set), (_, unit, _)) in slots.into_iter().zip(SLOTS) {
            if !features.has(bit) {
                continue;
            }
            let own_map = map.as_ref().filter(|_| own.has(bit));
            let uploaded = |m: &MapTexture| scene.texture_of(&m.texture, bit == F::EMISSIVE_MAP);
            let own_texture = own_map.and_then(|m| Some((m, uploaded(m)?)));
            // The upload follows the same conditions as the variant: a map without one would
            // sample whatever the unit held last.
            debug_assert!(
                own_map.is_none() || own_texture.is_some(),
                "a map not uploaded"
            );
            match own_texture {
                Some((map, t)) => t.bind(dev, unit, &map.texture.sampling),
                None => {
                    if let Some(white) = scene.white() {
                        white.bind(dev, unit, &Default::default());
                    }
                }
            }
            if features.has(F::TEXTURE_TRANSFORM) {
                let transform = own_map.filter(|_| transformed);
                uv.set(
                    dev,
                    transform.map_or(Mat3::IDENTITY, |m| {
                        uv_matrix(&m.transform, Some(m.texture.sampling))
                    }),
                );
            }
            if second {
                set.set(dev, own_map.map_or(0, |m| m.transform.uv_set) as f32);
            }
            sampler.set(dev, unit);
        }
        if features.has(F::NORMAL_MAP) {
            self.normal_scale.set(dev, maps.normal_scale);
        }
        if features.has(F::EMISSIVE) {
            let emission = if own.has(F::EMISSIVE) {
                super::features::pre_exposed(maps.emissive, pre_exposure)
            } else {
                Vec3::ZERO
            };
            self.emissive.set(dev, emission);
        }
        if features.has(F::OCCLUSION) {
            let strength = if own.has(F::OCCLUSION) {
                maps.occlusion_strength
            } else {
                0.0
            };
            self.occlusion_strength.set(dev, strength);
        }
    }
}

/// The transform as the shader's `mat3` (columns; `uv' = (M · (uv, 1)).xy`), its offset
/// reduced to one period of the wrap of the texture sampled (`sampling`), the same map
/// through that wrap: an offset of 65 536.25 added in `f32` per vertex kept the coordinates
/// 2⁻⁷ of the texture apart, one of 10⁶ 1/16 (a texture scrolled every frame gets there).
fn uv_matrix(t: &TextureTransform, sampling: Option<Sampling>) -> Mat3 {
    let reduced = |offset: f32, wrap: Option<Wrap>| {
        let period = match wrap {
            Some(Wrap::Repeat) => 1.0,
            Some(Wrap::MirroredRepeat) => 2.0,
            Some(Wrap::ClampToEdge) | None => return offset,
        };
        // Exact (an f32's remainder by a power of two is an f32), but that a tiny negative
        // offset rounds to the period itself: the same map.
        (offset as f64).rem_euclid(period) as f32
    };
    let offset = Vec2::new(
        reduced(t.offset.x, sampling.map(|s| s.wrap_u)),
        reduced(t.offset.y, sampling.map(|s| s.wrap_v)),
    );
    let [r0, r1] = TextureTransform { offset, ..*t }.rows();
    Mat3::from_cols(
        Vec3::new(r0.x, r1.x, 0.0),
        Vec3::new(r0.y, r1.y, 0.0),
        Vec3::new(r0.z, r1.z, 1.0),
    )
}

#[cfg(test)]
mod tests {
    use super::{uv_matrix, Sampling, TextureTransform, Vec2, Wrap};
    use glam::Vec3;

    /// The offset column `uv_matrix` gives for `offset` sampled with `wrap` on both axes.
    fn offset_sent(offset: Vec2, wrap: Option<Wrap>) -> Vec2 {
        let t = TextureTransform {
            offset,
            ..TextureTransform::IDENTITY
        };
        let sampling = wrap.map(|wrap| Sampling {
            wrap_u: wrap,
            wrap_v: wrap,
            ..Sampling::default()
        });
        let column = uv_matrix(&t, sampling).z_axis;
        assert_eq!(column.z, 1.0);
        Vec3::truncate(column)
    }

    #[test]
    fn an_offset_is_sent_as_its_remainder_by_the_wraps_period() {
        let far = Vec2::new(65_536.25, -1_000_000.5);
        assert_eq!(offset_sent(far, Some(Wrap::Repeat)), Vec2::new(0.25, 0.5));
        // Every other copy mirrored: a period of two copies.
        assert_eq!(
            offset_sent(far + Vec2::X, Some(Wrap::MirroredRepeat)),
            Vec2::new(1.25, 1.5)
        );
        // Clamped, or no texture: as given.
        assert_eq!(offset_sent(far, Some(Wrap::ClampToEdge)), far);
        assert_eq!(offset_sent(far, None), far);
    }
}
