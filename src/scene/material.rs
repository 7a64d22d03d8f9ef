//! Materials (from MTL `Kd`, `map_Kd`, `Ks`, `Ns`) and their textures.

use std::sync::Arc;

use glam::Vec3;

use super::surface_maps::{SurfaceMaps, MAX_NORMAL_SCALE};
pub use super::texture::Texture;
use super::SceneError;

/// Largest Blinn-Phong exponent the light model uses (a larger `shininess` shades as this).
pub const MAX_SHININESS: f32 = 4096.0;

/// Which reflectance model a material is shaded with (one light model, two BRDFs; see
/// `glsl/light_model.glsl` and its CPU twin `scene::shading`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MaterialModel {
    /// Lambert diffuse plus a Blinn-Phong highlight (`diffuse`, `specular`, `shininess`):
    /// OBJ/MTL and the built-in scenes.
    #[default]
    BlinnPhong,
    /// The glTF 2.0 metallic-roughness BRDF (`diffuse` as base colour, `metallic`,
    /// `roughness`): glTF materials.
    MetallicRoughness,
}

/// A material in linear RGB: Lambert + Blinn-Phong, or glTF metallic-roughness (see
/// [`MaterialModel`]).
#[derive(Clone, Debug)]
pub struct Material {
    /// Name from the MTL file or the built-in scene.
    pub name: String,
    /// Diffuse albedo (`Kd`), multiplied by the texture when there is one. For
    /// [`MaterialModel::MetallicRoughness`] the base colour (`baseColorFactor`).
    pub diffuse: Vec3,
    /// Diffuse texture (`map_Kd`), sRGB encoded.
    pub diffuse_texture: Option<Arc<Texture>>,
    /// Specular colour (`Ks`).
    pub specular: Vec3,
    /// Blinn-Phong exponent (`Ns`); values below 1 are shaded as 1 (see [`Material::shading_exponent`]).
    pub shininess: f32,
    /// Opacity (`d` in MTL): 1 is opaque; below 1 the object is drawn after the opaque ones,
    /// back to front, alpha-blended.
    pub alpha: f32,
    /// A cut-out (glTF `alphaMode: MASK`): fragments where the diffuse texture's alpha is below
    /// this are not drawn (the factor's alpha already folded in). `None`: nothing is cut.
    pub alpha_cutoff: Option<f32>,
    /// The diffuse texture's alpha multiplies `alpha` (glTF `BLEND` with a texture some of
    /// whose texels are not opaque): the object is transparent.
    pub alpha_texture: bool,
    /// The mesh's vertex colours' alpha (glTF `COLOR_0`, where not all opaque) multiplies the
    /// opacity: blended (glTF `BLEND`: the object is transparent) or, with `alpha_cutoff`,
    /// cut (`MASK`).
    pub alpha_vertex: bool,
    /// The reflectance model; `specular`/`shininess` are read by Blinn-Phong only,
    /// `metallic`/`roughness` by metallic-roughness only.
    pub model: MaterialModel,
    /// Metalness in [0, 1] (glTF `metallicFactor`).
    pub metallic: f32,
    /// Perceptual roughness in [0, 1] (glTF `roughnessFactor`; α = roughness²). Shaded with
    /// at least 0.089 (`MIN_ROUGHNESS`: fp16 safety, docs/precision.md).
    pub roughness: f32,
    /// Normal, emissive, occlusion and metallic-roughness inputs and texture transforms
    /// (glTF; defaults for OBJ and built-in materials).
    pub maps: SurfaceMaps,
    /// Drawn from both sides, a back face with its normals reversed (OBJ and built-in
    /// materials, also in scene files; glTF `doubleSided: true`); `false` draws only the side the
    /// triangles' winding faces (counter-clockwise, clockwise under a mirroring transform), as
    /// glTF's default `doubleSided: false` asks: a back face is culled, and what lies behind
    /// it shows.
    pub double_sided: bool,
    /// How far the surface is drawn toward the camera, in steps of the depth buffer and as
    /// many times its depth's change across a pixel (a polygon offset, `glPolygonOffset(−b,
    /// −b)`), so that a decal lying on another surface wins the depth test there with every
    /// method. 0, the default, draws it where it lies; 2 lifts a decal clear of its surface,
    /// seen head-on or at a grazing angle (deferred's depth may be a step off,
    /// docs/architecture.md). Within ±1 024 (`MAX_DEPTH_BIAS`).
    pub depth_bias: f32,
}

impl Default for Material {
    fn default() -> Self {
        Material::flat("default", Vec3::splat(0.8))
    }
}

/// Largest diffuse or specular factor a material may have. The colour factors run at
/// `mediump` (fp16 on phones, max 65 504): `albedo·cosθ + Ks·spec` and the ambient term must
/// stay finite there, so each factor is capped far below that; reflectances above 1 are not
/// physical anyway (MTL files with `Kd 30000` or `Ks 1e20` exist, and turned surfaces black).
pub const MAX_COLOR_FACTOR: f32 = 1024.0;

/// Largest [`Material::depth_bias`] either way, in depth-buffer steps: a 16-bit depth buffer
/// has 65 536, and a decal needs a few.
pub const MAX_DEPTH_BIAS: f32 = 1024.0;

/// Checks that a colour factor is finite and within [0, [`MAX_COLOR_FACTOR`]], naming
/// `field.name` (built only when it is not).
pub(crate) fn check_color_factor(v: Vec3, field: &str, name: &str) -> Result<(), SceneError> {
    if v.is_finite() && v.min_element() >= 0.0 && v.max_element() <= MAX_COLOR_FACTOR {
        return Ok(());
    }
    Err(SceneError::invalid(
        format!("{field}.{name}"),
        format!(
            "must be in [0, {MAX_COLOR_FACTOR}] (the range the fp16 colour tier holds), got {v:?}"
        ),
    ))
}

impl Material {
    /// A matte material of one colour with a faint highlight.
    pub fn flat(name: &str, diffuse: Vec3) -> Self {
        Material {
            name: name.to_string(),
            diffuse,
            diffuse_texture: None,
            specular: Vec3::splat(0.04),
            shininess: 32.0,
            alpha: 1.0,
            alpha_cutoff: None,
            alpha_texture: false,
            alpha_vertex: false,
            model: MaterialModel::BlinnPhong,
            metallic: 0.0,
            roughness: 1.0,
            maps: SurfaceMaps::default(),
            double_sided: true,
            depth_bias: 0.0,
        }
    }

    /// A glTF metallic-roughness material.
    pub fn metallic_roughness(name: &str, base_color: Vec3, metallic: f32, roughness: f32) -> Self {
        Material {
            model: MaterialModel::MetallicRoughness,
            metallic,
            roughness,
            specular: Vec3::ZERO,
            ..Material::flat(name, base_color)
        }
    }

    /// True when the material is shaded with the metallic-roughness BRDF.
    pub fn is_metallic_roughness(&self) -> bool {
        self.model == MaterialModel::MetallicRoughness
    }

    /// A material with a specular colour and exponent.
    pub fn glossy(name: &str, diffuse: Vec3, specular: Vec3, shininess: f32) -> Self {
        Material {
            specular,
            shininess,
            ..Material::flat(name, diffuse)
        }
    }

    /// The exponent the light model uses: `Ns` clamped to [1, 4096]. `pow(0, 0)` is undefined
    /// in GLSL, and MTL files commonly say `Ns 0` for "no highlight" together with `Ks 0`.
    pub fn shading_exponent(&self) -> f32 {
        self.shininess.clamp(1.0, MAX_SHININESS)
    }

    /// True when the material is see-through: alpha below 1, or a diffuse texture whose alpha
    /// it blends by ([`Material::alpha_texture`]).
    pub fn is_transparent(&self) -> bool {
        self.alpha < 1.0
            || (self.alpha_texture && self.diffuse_texture.is_some())
            || (self.alpha_vertex && self.alpha_cutoff.is_none())
    }

    /// The coordinate set each texture the material samples reads.
    pub(crate) fn texture_sets(&self) -> super::texture_sets::TextureSets {
        let maps = &self.maps;
        let set = |t: Option<&super::surface_maps::MapTexture>| t.map(|t| t.transform.uv_set);
        let base = self.diffuse_texture.as_ref();
        super::texture_sets::TextureSets([
            ("baseColorTexture", base.map(|_| maps.base_transform.uv_set)),
            (
                "metallicRoughnessTexture",
                set(self.sampled_metallic_roughness()),
            ),
            ("normalTexture", set(maps.sampled_normal())),
            ("occlusionTexture", set(maps.sampled_occlusion())),
            ("emissiveTexture", set(maps.sampled_emissive())),
        ])
    }

    /// The metallic-roughness texture, where the material is shaded with that BRDF (a
    /// Blinn-Phong material's shader has nothing to read it with).
    pub(crate) fn sampled_metallic_roughness(&self) -> Option<&super::surface_maps::MapTexture> {
        (self.maps.metallic_roughness.as_ref()).filter(|_| self.is_metallic_roughness())
    }

    /// The textures of the maps a shader of this material samples
    /// ([`SurfaceMaps::sampled_textures`], less a metallic-roughness texture on a Blinn-Phong
    /// material), by their field names.
    pub fn sampled_map_textures(
        &self,
    ) -> impl Iterator<Item = (&'static str, &super::surface_maps::MapTexture)> {
        let read =
            |(slot, _): &(&str, _)| *slot != "metallic_roughness" || self.is_metallic_roughness();
        self.maps.sampled_textures().filter(read)
    }

    /// True when the material has a non-zero Blinn-Phong specular term (never for
    /// metallic-roughness, whose specular lobe is always there).
    pub fn has_specular(&self) -> bool {
        !self.is_metallic_roughness() && self.specular.max_element() > 0.0
    }

    /// Checks colours and exponent; `field` names the material in errors.
    pub fn validate(&self, field: &str) -> Result<(), SceneError> {
        for (name, v) in [("diffuse", self.diffuse), ("specular", self.specular)] {
            check_color_factor(v, field, name)?;
        }
        if !(self.alpha.is_finite() && (0.0..=1.0).contains(&self.alpha)) {
            return Err(SceneError::invalid(
                format!("{field}.alpha"),
                format!("must be in [0, 1], got {:?}", self.alpha),
            ));
        }
        let bias = self.depth_bias;
        if !(bias.is_finite() && bias.abs() <= MAX_DEPTH_BIAS) {
            return Err(SceneError::invalid(
                format!("{field}.depth_bias"),
                format!("must be within ±{MAX_DEPTH_BIAS} depth steps, got {bias:?}"),
            ));
        }
        if let Some(c) = self.alpha_cutoff {
            if !(c.is_finite() && (0.0..=1.0).contains(&c)) {
                return Err(SceneError::invalid(
                    format!("{field}.alpha_cutoff"),
                    format!("must be in [0, 1], got {c:?}"),
                ));
            }
        }
        for (name, v) in [("metallic", self.metallic), ("roughness", self.roughness)] {
            if !(v.is_finite() && (0.0..=1.0).contains(&v)) {
                return Err(SceneError::invalid(
                    format!("{field}.{name}"),
                    format!("must be in [0, 1], got {v:?}"),
                ));
            }
        }
        check_color_factor(self.maps.emissive, field, "emissive")?;
        if let Some((t, set)) = self.maps.unknown_uv_set() {
            return Err(SceneError::invalid(
                format!("{field}.maps.{t}.uv_set"),
                format!("must be 0 or 1 (a mesh has at most two sets), got {set}"),
            ));
        }
        if let Some(t) = self.maps.unusable_transform() {
            return Err(SceneError::invalid(
                format!("{field}.maps.{t}"),
                format!(
                    "offset and scale must be within ±{:e} and every number finite",
                    super::mesh::MAX_TEXCOORD
                ),
            ));
        }
        let maps = &self.maps;
        let scale = maps.normal_scale;
        if !(scale.is_finite() && scale.abs() <= MAX_NORMAL_SCALE) {
            return Err(SceneError::invalid(
                format!("{field}.maps.normal_scale"),
                format!("must be within ±{MAX_NORMAL_SCALE}, got {scale:?}"),
            ));
        }
        let strength = maps.occlusion_strength;
        if !(strength.is_finite() && (0.0..=1.0).contains(&strength)) {
            return Err(SceneError::invalid(
                format!("{field}.maps.occlusion_strength"),
                format!("must be in [0, 1], got {strength:?}"),
            ));
        }
        // An image without pixels has nothing to sample (uploaded, it read as black). Named
        // only on failure: a scene is validated every frame.
        let base = self
            .diffuse_texture
            .as_ref()
            .map(|t| ("", "diffuse_texture", t));
        let in_maps = maps.textures().map(|(n, t)| ("maps.", n, &t.texture));
        let empty = |t: &Arc<Texture>| t.image.width() == 0 || t.image.height() == 0;
        let mut textures = base.into_iter().chain(in_maps);
        if let Some((prefix, name, texture)) = textures.find(|(_, _, t)| empty(t)) {
            let (w, h) = texture.image.dimensions();
            return Err(SceneError::invalid(
                format!("{field}.{prefix}{name}"),
                format!("an image of {w}×{h} pixels has nothing to sample"),
            ));
        }
        if !(self.shininess.is_finite() && self.shininess >= 0.0) {
            return Err(SceneError::invalid(
                format!("{field}.shininess"),
                format!("must be finite and >= 0, got {:?}", self.shininess),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factors_past_the_fp16_colour_range_are_refused_naming_the_field() {
        let mut m = Material::glossy("m", Vec3::ONE, Vec3::splat(0.5), 8.0);
        assert!(m.validate("materials[0]").is_ok());
        m.specular = Vec3::new(0.0, 2000.0, 0.0);
        let err = m.validate("materials[0]").unwrap_err().to_string();
        assert!(err.contains("materials[0].specular"), "{err}");
        m.specular = Vec3::splat(MAX_COLOR_FACTOR);
        assert!(m.validate("materials[0]").is_ok());
    }

    #[test]
    fn a_depth_bias_past_the_limit_or_not_finite_is_refused_naming_the_field() {
        let mut m = Material::flat("decal", Vec3::ONE);
        for ok in [0.0, 2.0, -MAX_DEPTH_BIAS, MAX_DEPTH_BIAS] {
            m.depth_bias = ok;
            assert!(m.validate("materials[2]").is_ok(), "{ok}");
        }
        for bad in [f32::NAN, f32::INFINITY, MAX_DEPTH_BIAS * 2.0, -1e30] {
            m.depth_bias = bad;
            let err = m.validate("materials[2]").unwrap_err().to_string();
            assert!(err.contains("materials[2].depth_bias"), "{bad}: {err}");
        }
    }

    #[test]
    fn metallic_and_roughness_outside_0_1_are_refused_naming_the_field() {
        let mut m = Material::metallic_roughness("m", Vec3::ONE, 1.0, 0.0);
        assert!(m.validate("materials[1]").is_ok());
        m.roughness = f32::NAN;
        let err = m.validate("materials[1]").unwrap_err().to_string();
        assert!(err.contains("materials[1].roughness"), "{err}");
        m.roughness = 0.5;
        m.metallic = 1.5;
        let err = m.validate("materials[1]").unwrap_err().to_string();
        assert!(err.contains("materials[1].metallic"), "{err}");
    }

    /// What the glTF loader keeps in range with a warning, and images without pixels (which
    /// drew black), are refused in a material built in code, naming the field.
    #[test]
    fn map_strengths_out_of_range_and_empty_images_are_refused_naming_the_field() {
        use crate::scene::surface_maps::{MapTexture, TextureTransform};
        let ok = Material::metallic_roughness("m", Vec3::ONE, 0.0, 0.5);
        let texture = |w, h| Arc::new(Texture::new("t", image::RgbaImage::new(w, h)));
        let refused = |change: &dyn Fn(&mut Material), said: &str| {
            let mut m = ok.clone();
            change(&mut m);
            let err = m.validate("materials[2]").unwrap_err().to_string();
            assert!(err.contains(said), "{said}: {err}");
        };
        refused(
            &|m| m.maps.normal_scale = f32::INFINITY,
            "materials[2].maps.normal_scale",
        );
        refused(
            &|m| m.maps.normal_scale = -17.0,
            "materials[2].maps.normal_scale",
        );
        refused(
            &|m| m.maps.occlusion_strength = 2.0,
            "maps.occlusion_strength",
        );
        refused(
            &|m| m.maps.occlusion_strength = f32::NAN,
            "maps.occlusion_strength",
        );
        refused(
            &|m| m.diffuse_texture = Some(texture(0, 0)),
            "materials[2].diffuse_texture",
        );
        let empty = MapTexture {
            texture: texture(4, 0),
            transform: Default::default(),
        };
        refused(
            &|m| m.maps.occlusion = Some(empty.clone()),
            "materials[2].maps.occlusion",
        );
        let third_set = MapTexture {
            texture: texture(1, 1),
            transform: TextureTransform {
                uv_set: 2,
                ..Default::default()
            },
        };
        refused(
            &|m| m.maps.occlusion = Some(third_set.clone()),
            "materials[2].maps.occlusion.transform.uv_set",
        );
        refused(
            &|m| m.maps.emissive_texture = Some(third_set.clone()),
            "materials[2].maps.emissive_texture.transform.uv_set",
        );
        refused(
            &|m| m.maps.base_transform.uv_set = u32::MAX,
            "materials[2].maps.base_transform.uv_set",
        );
        let mut edges = ok.clone();
        edges.maps.normal_scale = -MAX_NORMAL_SCALE;
        edges.maps.occlusion_strength = 0.0;
        edges.diffuse_texture = Some(texture(1, 1));
        edges.maps.base_transform.uv_set = 1;
        assert!(edges.validate("materials[2]").is_ok());
    }
}
