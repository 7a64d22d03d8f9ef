//! glTF materials → the renderer's metallic-roughness [`Material`] (the glTF 2.0 BRDF).
//!
//! - `baseColorFactor.rgb` → `diffuse`, `baseColorTexture` → `diffuse_texture` (sRGB, as the
//!   renderer decodes it); factors clamped to [0, [`MAX_COLOR_FACTOR`]] with a warning, as
//!   OBJ's are.
//! - `metallicFactor` → `metallic`, `roughnessFactor` → `roughness` (clamped to [0, 1] with a
//!   warning), shaded
//!   by the glTF BRDF ([`crate::scene::brdf`]). `specular`/`shininess` (the dielectric 0.04
//!   grey and the Blinn-Phong ↔ Beckmann match `Ns = 2/α² − 2`, [`shininess`]) are kept for
//!   callers that switch the material to Blinn-Phong.
//! - normal, occlusion, emissive and metallic-roughness textures, emission and every
//!   texture's `KHR_texture_transform` → [`Material::maps`] (`maps.rs`).
//! - `alphaMode`: `OPAQUE` ignores alpha; `BLEND` takes `baseColorFactor.a` as the material's
//!   opacity, times the base colour texture's alpha where some texel is not opaque
//!   ([`Material::alpha_texture`]) and `COLOR_0`'s where some vertex is not
//!   ([`Material::alpha_vertex`], a variant for those primitives); below 1, or with such a
//!   texture or vertex colours, the renderer's transparent path (back to front,
//!   alpha-blended); `MASK` cuts the whole material — invisible (opacity 0) when
//!   `baseColorFactor.a` is below `alphaCutoff` — and else, with a base colour texture or
//!   such vertex colours, each fragment whose texture alpha times vertex alpha times that
//!   factor is below it ([`Material::alpha_cutoff`]: leaves, fences).
//! - `doubleSided` → [`Material::double_sided`]: `true` draws both sides (a back face with its
//!   normals reversed); `false`, glTF's default and the default material's, culls back faces
//!   (the winding's, turned round under a mirroring transform).

use std::collections::HashMap;
use std::path::Path;

use glam::Vec3;
use gltf::material::AlphaMode;

use super::buffers::Buffers;
use super::maps::{self, RawMaterials, Sources};
use super::texture::Textures;
use crate::scene::material::MAX_COLOR_FACTOR;
use crate::scene::shown;
use crate::scene::surface_maps::UV_SETS;
use crate::scene::texture_budget::TextureBudget;
use crate::scene::{short3, Material};

/// Specular reflectance of dielectrics (4 %), the `specular` every glTF material gets.
pub const DIELECTRIC_SPECULAR: f32 = 0.04;

/// Blinn-Phong exponent for a glTF `roughness` in [0, 1]: `2/α² − 2`, `α = roughness²`,
/// capped at 4 096 (what [`Material::shading_exponent`] allows); roughness 1 gives 0.
pub fn shininess(roughness: f32) -> f32 {
    let r = if roughness.is_nan() {
        1.0
    } else {
        roughness.clamp(0.0, 1.0)
    };
    let alpha2 = r.powi(4);
    if alpha2 <= 2.0 / 4098.0 {
        return 4096.0;
    }
    (2.0 / alpha2 - 2.0).clamp(0.0, 4096.0)
}

/// A glTF factor in [0, 1] (the spec's range; NaN, which JSON cannot carry, as 1).
fn unit_factor(f: f32) -> f32 {
    if f.is_nan() {
        1.0
    } else {
        f.clamp(0.0, 1.0)
    }
}

/// `baseColorFactor`'s alpha in [0, 1] (NaN: 1).
fn factor_alpha(m: &gltf::Material) -> f32 {
    let a = m.pbr_metallic_roughness().base_color_factor()[3];
    if a.is_nan() {
        1.0
    } else {
        a.clamp(0.0, 1.0)
    }
}

/// A `MASK` material's `alphaCutoff` (NaN: the spec's default, 0.5).
fn gltf_cutoff(m: &gltf::Material) -> f32 {
    m.alpha_cutoff().filter(|c| !c.is_nan()).unwrap_or(0.5)
}

/// What a `MASK` material's per-fragment alpha (texel alpha × vertex alpha) is cut below, the
/// factor's alpha folded in (`a · factor < cutoff` as `a < cutoff / factor`); `None` where
/// the factor decides alone: below the cutoff everything is cut (the material's opacity is
/// 0), at a cutoff of 0 or less nothing is.
fn mask_cutoff(m: &gltf::Material) -> Option<f32> {
    let factor_alpha = factor_alpha(m);
    let cutoff = gltf_cutoff(m);
    (factor_alpha >= cutoff && cutoff > 0.0).then(|| cutoff / factor_alpha)
}

/// The materials of one glTF file, converted when a primitive first uses them.
pub(super) struct Materials {
    /// Converted materials, in the order first used.
    pub list: Vec<Material>,
    /// glTF material index (`None`: the default material) → index in `list`.
    by_index: HashMap<Option<usize>, usize>,
    /// The same for the variants whose vertex colours' alpha takes part
    /// ([`Materials::get_with_vertex_alpha`]).
    with_vertex_alpha: HashMap<Option<usize>, usize>,
    textures: Textures,
    raw: RawMaterials,
    /// Per texture (by address): whether some texel is not opaque, looked at once.
    translucent: HashMap<usize, bool>,
}

impl Materials {
    /// For the file whose JSON chunk is `json`, its textures taking their part of `budget`.
    pub fn new(json: &[u8], budget: TextureBudget, warnings: &mut Vec<String>) -> Materials {
        Materials {
            list: Vec::new(),
            by_index: HashMap::new(),
            with_vertex_alpha: HashMap::new(),
            textures: Textures::new(budget),
            raw: RawMaterials::parse(json, warnings),
            translucent: HashMap::new(),
        }
    }

    /// The converted materials, and what is left of the texture budget.
    pub fn finish(self) -> (Vec<Material>, TextureBudget) {
        (self.list, self.textures.budget)
    }

    /// The coordinate sets `m`'s textures read, for its primitives' meshes: of `m` converted
    /// (on first use), so a texture that failed to load reads none.
    pub fn sets_read(
        &mut self,
        m: &gltf::Material,
        buffers: &mut Buffers,
        gltf_path: &Path,
        warnings: &mut Vec<String>,
    ) -> Result<crate::scene::texture_sets::TextureSets, String> {
        let i = self.get(m, buffers, gltf_path, warnings)?;
        Ok(self.list[i].texture_sets())
    }

    /// Index in [`Materials::list`] of `m`, converting it on first use.
    pub fn get(
        &mut self,
        m: &gltf::Material,
        buffers: &mut Buffers,
        gltf_path: &Path,
        warnings: &mut Vec<String>,
    ) -> Result<usize, String> {
        if let Some(&i) = self.by_index.get(&m.index()) {
            return Ok(i);
        }
        let material = self.convert(m, buffers, gltf_path, warnings)?;
        let i = self.add(material);
        self.by_index.insert(m.index(), i);
        Ok(i)
    }

    /// Appends `material` to [`Materials::list`]; its index.
    fn add(&mut self, material: Material) -> usize {
        self.list.push(material);
        self.list.len() - 1
    }

    /// [`Materials::get`] for a primitive whose `COLOR_0` is not opaque everywhere: a variant
    /// of `m` in which that alpha multiplies the opacity (`BLEND`) or takes part in the cut
    /// (`MASK`); `m` itself where it ignores alpha (`OPAQUE`, or a `MASK` that cuts all or
    /// nothing).
    pub fn get_with_vertex_alpha(
        &mut self,
        m: &gltf::Material,
        buffers: &mut Buffers,
        gltf_path: &Path,
        warnings: &mut Vec<String>,
    ) -> Result<usize, String> {
        let base = self.get(m, buffers, gltf_path, warnings)?;
        if let Some(&i) = self.with_vertex_alpha.get(&m.index()) {
            return Ok(i);
        }
        let mut variant = self.list[base].clone();
        match m.alpha_mode() {
            AlphaMode::Opaque => return Ok(base),
            AlphaMode::Blend => variant.alpha_vertex = true,
            AlphaMode::Mask => match mask_cutoff(m) {
                Some(cutoff) => {
                    variant.alpha_cutoff = Some(cutoff);
                    variant.alpha_vertex = true;
                }
                None => return Ok(base),
            },
        }
        let i = self.add(variant);
        self.with_vertex_alpha.insert(m.index(), i);
        Ok(i)
    }

    fn convert(
        &mut self,
        m: &gltf::Material,
        buffers: &mut Buffers,
        gltf_path: &Path,
        warnings: &mut Vec<String>,
    ) -> Result<Material, String> {
        let field = match m.index() {
            Some(i) => format!("materials[{i}]"),
            None => "the default material".to_string(),
        };
        let name = match (m.index(), m.name()) {
            (_, Some(n)) => shown::name(n),
            (Some(i), None) => format!("gltf-material-{i}"),
            (None, None) => "gltf-default".to_string(),
        };
        let pbr = m.pbr_metallic_roughness();
        let [r, g, b, _] = pbr.base_color_factor();
        let base = Vec3::new(r, g, b);
        // NaN becomes 0: f32::clamp keeps NaN, max/min do not.
        let diffuse = base.max(Vec3::ZERO).min(Vec3::splat(MAX_COLOR_FACTOR));
        if diffuse != base {
            warnings.push(format!(
                "{field} (`{name}`): baseColorFactor {} clamped to {} (factors are \
                 limited to [0, {MAX_COLOR_FACTOR}], the range the fp16 colour tier holds)",
                short3(base),
                short3(diffuse)
            ));
        }
        let factor_alpha = factor_alpha(m);
        let mut diffuse_texture = None;
        let mut base_transform = Default::default();
        if let Some(info) = pbr.base_color_texture() {
            let path = ["pbrMetallicRoughness", "baseColorTexture"];
            let (transform, tex_coord) = maps::transform_of(
                &self.raw,
                m.index(),
                &path,
                info.tex_coord(),
                &format!("{field}.{}", path.join(".")),
                warnings,
            );
            base_transform = transform;
            if tex_coord >= UV_SETS {
                let at = format!("{field} (`{name}`).baseColorTexture");
                warnings.push(maps::unread_set(
                    &at,
                    tex_coord,
                    "it is not bound (flat colour)",
                ));
            } else {
                diffuse_texture = self
                    .textures
                    .load_texture(&info.texture(), buffers, gltf_path, warnings)
                    .map_err(|e| format!("{field}.pbrMetallicRoughness.baseColorTexture: {e}"))?;
            }
        }
        let (mut alpha_cutoff, mut alpha_texture) = (None, false);
        let alpha = match m.alpha_mode() {
            AlphaMode::Opaque => 1.0,
            AlphaMode::Blend => {
                // The texture's alpha multiplies the factor's where some texel is not opaque
                // (exporters often say BLEND of opaque textures: those stay opaque objects).
                if let Some(t) = &diffuse_texture {
                    let key = std::sync::Arc::as_ptr(&t.image) as usize;
                    alpha_texture = *self
                        .translucent
                        .entry(key)
                        .or_insert_with(|| t.image.pixels().any(|p| p[3] < 255));
                }
                factor_alpha
            }
            AlphaMode::Mask => {
                if diffuse_texture.is_some() {
                    alpha_cutoff = mask_cutoff(m);
                }
                if factor_alpha < gltf_cutoff(m) {
                    0.0
                } else {
                    1.0
                }
            }
        };
        for (what, f) in [
            ("metallicFactor", pbr.metallic_factor()),
            ("roughnessFactor", pbr.roughness_factor()),
        ] {
            if unit_factor(f) != f {
                // No value in the words, so many such materials make one line.
                warnings.push(format!(
                    "{field} (`{name}`): {what} outside [0, 1] (glTF's range): clamped"
                ));
            }
        }
        let mut sources = Sources {
            raw: &self.raw,
            textures: &mut self.textures,
            buffers,
            gltf_path,
        };
        let mut maps = maps::convert(m, &field, &mut sources, warnings)?;
        maps.base_transform = base_transform;
        maps::one_sampling_per_image(&mut diffuse_texture, &mut maps, &field, warnings);
        Ok(Material {
            diffuse_texture,
            specular: Vec3::splat(DIELECTRIC_SPECULAR),
            shininess: shininess(pbr.roughness_factor()),
            alpha,
            alpha_cutoff,
            alpha_texture,
            maps,
            double_sided: m.double_sided(),
            ..Material::metallic_roughness(
                &name,
                diffuse,
                unit_factor(pbr.metallic_factor()),
                unit_factor(pbr.roughness_factor()),
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roughness_maps_to_a_bounded_exponent() {
        assert_eq!(shininess(1.0), 0.0);
        assert_eq!(shininess(0.0), 4096.0);
        assert_eq!(shininess(f32::NAN), 0.0);
        assert_eq!(shininess(7.0), 0.0);
        let mid = shininess(0.5);
        assert!((mid - 30.0).abs() < 1e-3, "{mid}");
        assert!(shininess(0.3) > shininess(0.5));
    }
}
