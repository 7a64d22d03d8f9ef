//! A material's surface inputs beyond the base colour (glTF's normal, emissive, occlusion and
//! metallic-roughness textures, `KHR_texture_transform`), and their CPU twin in `f64`: what
//! `glsl/surface.glsl` computes from them, for the oracles.
//!
//! Normal, occlusion and metallic-roughness textures hold linear data; emissive and base
//! colour textures are sRGB (decoded in the shader, as base colour always was).

use std::sync::Arc;

use glam::{DVec2, DVec3, Vec2, Vec3};

use super::texture::Texture;

/// Where a texture is sampled: which of the mesh's texture coordinate sets it reads (glTF's
/// `texCoord`), through `KHR_texture_transform`'s `uv' = T·R·S·uv` (offset, rotation
/// counter-clockwise in radians, scale), in the glTF convention (`u' = c·sx·u + s·sy·v + ox`,
/// `v' = −s·sx·u + c·sy·v + oy`, the one its example's "lower left quadrant" needs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureTransform {
    /// Offset of the UV origin.
    pub offset: Vec2,
    /// Rotation, radians.
    pub rotation: f32,
    /// Scale of the UV coordinates.
    pub scale: Vec2,
    /// The coordinate set read: 0 ([`Mesh::uvs`](super::Mesh::uvs), glTF `TEXCOORD_0`) or 1
    /// ([`Mesh::second_uvs`](super::Mesh::second_uvs), `TEXCOORD_1`). A mesh without that
    /// set does not sample the texture.
    pub uv_set: u32,
}

impl Default for TextureTransform {
    fn default() -> Self {
        TextureTransform::IDENTITY
    }
}

impl TextureTransform {
    /// No change.
    pub const IDENTITY: TextureTransform = TextureTransform {
        offset: Vec2::ZERO,
        rotation: 0.0,
        scale: Vec2::ONE,
        uv_set: 0,
    };

    /// True when it reads the first set unchanged (its shader code can be compiled out).
    pub fn is_identity(&self) -> bool {
        *self == TextureTransform::IDENTITY
    }

    /// The two rows of the affine map: `u' = r0·(u, v, 1)`, `v' = r1·(u, v, 1)`.
    pub fn rows(&self) -> [Vec3; 2] {
        let (s, c) = self.rotation.sin_cos();
        let (sx, sy) = (self.scale.x, self.scale.y);
        [
            Vec3::new(c * sx, s * sy, self.offset.x),
            Vec3::new(-s * sx, c * sy, self.offset.y),
        ]
    }

    /// The transformed coordinates, in `f64` (CPU twin).
    pub fn apply(&self, uv: DVec2) -> DVec2 {
        let (s, c) = (self.rotation as f64).sin_cos();
        let (sx, sy) = (self.scale.x as f64, self.scale.y as f64);
        DVec2::new(
            c * sx * uv.x + s * sy * uv.y + self.offset.x as f64,
            -s * sx * uv.x + c * sy * uv.y + self.offset.y as f64,
        )
    }

    /// True when every value is finite.
    pub fn is_finite(&self) -> bool {
        self.offset.is_finite() && self.rotation.is_finite() && self.scale.is_finite()
    }

    /// Finite, with offset and scale within ±`MAX_TEXCOORD` (past it a transformed coordinate
    /// overflows and the surface draws black).
    pub fn is_usable(&self) -> bool {
        let within = |v: Vec2| v.abs().max_element() <= super::mesh::MAX_TEXCOORD;
        self.is_finite() && within(self.offset) && within(self.scale)
    }

    /// The coordinates this transform reads of `mesh`, if it has them.
    pub(crate) fn coordinates<'m>(&self, mesh: &'m super::Mesh) -> Option<&'m [Vec2]> {
        mesh.coordinate_set(self.uv_set)
    }
}

/// Texture coordinate sets a mesh can have ([`TextureTransform::uv_set`] is below it).
pub const UV_SETS: u32 = 2;

/// A texture and where it is sampled.
#[derive(Clone, Debug)]
pub struct MapTexture {
    /// The image (8-bit RGBA; how its values are read depends on the slot).
    pub texture: Arc<Texture>,
    /// Its `KHR_texture_transform`.
    pub transform: TextureTransform,
}

/// The surface inputs a [`super::Material`] has besides its Lambert + Blinn-Phong colours.
/// Each costs shader work and a texture unit only where a material uses it
/// (`methods::ShaderFeatures`).
#[derive(Clone, Debug)]
pub struct SurfaceMaps {
    /// Transform of the base colour (diffuse) texture.
    pub base_transform: TextureTransform,
    /// Tangent-space normal map (linear RGB, `n = 2·rgb − 1`), applied on meshes that have
    /// [`Mesh::tangents`](super::Mesh::tangents) (a mesh built in code:
    /// [`Mesh::with_generated_tangents`](super::Mesh::with_generated_tangents)).
    pub normal: Option<MapTexture>,
    /// `normalTexture.scale`: scales the map's x and y.
    pub normal_scale: f32,
    /// Emitted radiance (linear RGB, `emissiveFactor × KHR_materials_emissive_strength`),
    /// added after the light sum; multiplied by the emissive texture when there is one.
    pub emissive: Vec3,
    /// Emissive texture (sRGB).
    pub emissive_texture: Option<MapTexture>,
    /// Ambient occlusion texture (linear, red channel): scales the ambient term only.
    pub occlusion: Option<MapTexture>,
    /// `occlusionTexture.strength`: `ao' = 1 + strength·(ao − 1)`.
    pub occlusion_strength: f32,
    /// glTF metallic-roughness texture (linear; roughness in G, metallic in B), sampled by
    /// `surfaceMetallicRoughness` in `glsl/surface.glsl`.
    pub metallic_roughness: Option<MapTexture>,
}

impl Default for SurfaceMaps {
    fn default() -> Self {
        SurfaceMaps {
            base_transform: TextureTransform::IDENTITY,
            normal: None,
            normal_scale: 1.0,
            emissive: Vec3::ZERO,
            emissive_texture: None,
            occlusion: None,
            occlusion_strength: 1.0,
            metallic_roughness: None,
        }
    }
}

/// Largest `normal_scale` magnitude: a normal map's x and y scaled past it point the shading
/// normal within a degree of the surface (and 16 × 2 stays exact in fp16).
pub const MAX_NORMAL_SCALE: f32 = 16.0;

/// Largest emitted radiance per channel: the colour tier is fp16 (the same cap as
/// `material::MAX_COLOR_FACTOR`).
pub const MAX_EMISSIVE: f32 = 1024.0;

impl SurfaceMaps {
    /// True when the material emits light.
    pub fn emits(&self) -> bool {
        self.emissive.max_element() > 0.0
    }

    /// Every texture of the maps with its field's name (errors name `maps.<field>`).
    pub fn textures(&self) -> impl Iterator<Item = (&'static str, &MapTexture)> {
        [
            ("normal", &self.normal),
            ("emissive_texture", &self.emissive_texture),
            ("occlusion", &self.occlusion),
            ("metallic_roughness", &self.metallic_roughness),
        ]
        .into_iter()
        .filter_map(|(n, t)| t.as_ref().map(|t| (n, t)))
    }

    /// The textures a shader samples: an occlusion map of strength 0 and an emissive texture
    /// without emission change no pixel, so they are not uploaded
    /// (nor is a metallic-roughness texture on a Blinn-Phong material:
    /// [`Material::sampled_map_textures`](super::Material::sampled_map_textures)).
    pub fn sampled_textures(&self) -> impl Iterator<Item = (&'static str, &MapTexture)> {
        [
            ("normal", self.sampled_normal()),
            ("emissive_texture", self.sampled_emissive()),
            ("occlusion", self.sampled_occlusion()),
            ("metallic_roughness", self.metallic_roughness.as_ref()),
        ]
        .into_iter()
        .filter_map(|(n, t)| t.map(|t| (n, t)))
    }

    /// The normal map, whatever its scale: at scale 0 a texel whose blue is below 128 still
    /// turns the normal round (glTF's `(2·rgb − 1)·(0, 0, 1)`, [`perturbed_normal`]). The glTF
    /// loader leaves out a map of scale 0 that has no such texel ([`turns_no_normal`]).
    pub(crate) fn sampled_normal(&self) -> Option<&MapTexture> {
        self.normal.as_ref()
    }

    /// The emissive texture, where the material emits.
    pub(crate) fn sampled_emissive(&self) -> Option<&MapTexture> {
        self.emissive_texture.as_ref().filter(|_| self.emits())
    }

    /// The occlusion map, where its strength darkens the ambient.
    pub(crate) fn sampled_occlusion(&self) -> Option<&MapTexture> {
        self.occlusion
            .as_ref()
            .filter(|_| self.occlusion_strength > 0.0)
    }

    /// Every texture of the maps, to share equal ones between loads.
    pub fn textures_mut(&mut self) -> impl Iterator<Item = &mut Arc<Texture>> {
        [
            &mut self.normal,
            &mut self.emissive_texture,
            &mut self.occlusion,
            &mut self.metallic_roughness,
        ]
        .into_iter()
        .filter_map(|t| t.as_mut().map(|t| &mut t.texture))
    }

    /// Every transform with the texture it belongs to: `None` for the base colour's
    /// (`base_transform`), else the texture's field name.
    fn transforms(&self) -> impl Iterator<Item = (Option<&'static str>, &TextureTransform)> {
        let textures = self.textures().map(|(name, t)| (Some(name), &t.transform));
        std::iter::once((None, &self.base_transform)).chain(textures)
    }

    /// The field of a transform of [`SurfaceMaps::transforms`], relative to the maps, made
    /// only for an error (validation runs every frame).
    fn transform_field(texture: Option<&str>) -> String {
        texture.map_or("base_transform".into(), |name| format!("{name}.transform"))
    }

    /// The first transform whose numbers are not finite or whose offset or scale passes
    /// ±1e9 (`MAX_TEXCOORD`; a transformed coordinate would overflow
    /// and the surface draw black): its field, relative to the maps.
    pub fn unusable_transform(&self) -> Option<String> {
        let (texture, _) = self.transforms().find(|(_, t)| !t.is_usable())?;
        Some(Self::transform_field(texture))
    }

    /// The first transform reading a set past `UV_SETS`: its field and set.
    pub fn unknown_uv_set(&self) -> Option<(String, u32)> {
        let (texture, t) = self.transforms().find(|(_, t)| t.uv_set >= UV_SETS)?;
        Some((Self::transform_field(texture), t.uv_set))
    }

    /// True when some texture (the base colour's included) is sampled through a transform or
    /// from the second coordinate set.
    pub fn has_transform(&self) -> bool {
        self.transforms().any(|(_, t)| !t.is_identity())
    }
}

/// The shading normal from a normal-map texel (`rgb` in [0, 1], linear), CPU twin of
/// `surfaceNormal` in `glsl/surface.glsl`: `n = normalize(T·x + B·y + N·z)` with
/// `(x, y, z) = (2·rgb − 1)·(scale, scale, 1)` and `B = w·(N × T)`. `normal` and `tangent`
/// are the interpolated unit vectors of the surface (its front face's); a degenerate result
/// keeps `normal`. A back face's shading normal is this reversed whole (`shadingNormal`).
pub fn perturbed_normal(normal: DVec3, tangent: DVec3, w: f64, rgb: DVec3, scale: f64) -> DVec3 {
    let t = (tangent - normal * normal.dot(tangent)).normalize_or_zero();
    let b = normal.cross(t) * w.signum();
    let m = (rgb * 2.0 - DVec3::ONE) * DVec3::new(scale, scale, 1.0);
    let n = t * m.x + b * m.y + normal * m.z;
    n.try_normalize().unwrap_or(normal)
}

/// Whether a normal map of scale 0 leaves every normal as it is: each texel's blue is 128 or
/// more, so `2·b − 1 > 0`, and filtering between such texels keeps it so.
pub fn turns_no_normal(image: &image::RgbaImage) -> bool {
    image.pixels().all(|p| p[2] >= 128)
}

/// Occlusion as it scales the ambient term: `1 + strength·(ao − 1)`.
pub fn occlusion_factor(ao: f64, strength: f64) -> f64 {
    1.0 + strength.clamp(0.0, 1.0) * (ao - 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_transform_matches_the_extensions_lower_left_quadrant_example() {
        let t = TextureTransform {
            offset: Vec2::new(0.0, 1.0),
            rotation: std::f32::consts::FRAC_PI_2,
            scale: Vec2::splat(0.5),
            uv_set: 0,
        };
        for (uv, want) in [
            ((0.0, 0.0), (0.0, 1.0)),
            ((1.0, 0.0), (0.0, 0.5)),
            ((1.0, 1.0), (0.5, 0.5)),
        ] {
            let got = t.apply(DVec2::new(uv.0, uv.1));
            assert!(
                (got - DVec2::new(want.0, want.1)).length() < 1e-6,
                "{uv:?} → {got}"
            );
            let r = t.rows();
            let p = Vec3::new(uv.0 as f32, uv.1 as f32, 1.0);
            assert!((r[0].dot(p) as f64 - got.x).abs() < 1e-6);
            assert!((r[1].dot(p) as f64 - got.y).abs() < 1e-6);
        }
        assert!(TextureTransform::default().is_identity());
        let second = TextureTransform {
            uv_set: 1,
            ..TextureTransform::IDENTITY
        };
        assert!(!second.is_identity() && second.is_usable());
    }

    #[test]
    fn a_flat_normal_map_keeps_the_normal_and_a_tilted_one_turns_it_towards_the_tangent() {
        let flat = perturbed_normal(DVec3::Z, DVec3::X, 1.0, DVec3::new(0.5, 0.5, 1.0), 1.0);
        assert!((flat - DVec3::Z).length() < 1e-12);
        let tilted = perturbed_normal(DVec3::Z, DVec3::X, 1.0, DVec3::new(1.0, 0.5, 0.5), 1.0);
        assert!((tilted - DVec3::X).length() < 1e-12, "{tilted}");
        let flipped = perturbed_normal(DVec3::Z, DVec3::X, -1.0, DVec3::new(0.5, 1.0, 0.5), 1.0);
        assert!((flipped + DVec3::Y).length() < 1e-12, "{flipped}");
        assert_eq!(occlusion_factor(0.25, 1.0), 0.25);
        assert_eq!(occlusion_factor(0.25, 0.0), 1.0);
    }
}
