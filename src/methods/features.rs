//! Shader feature bits → `#define`s. A variant depends only on what the scene and material
//! have, never on how many lights there are, so the program cache stays small.

use crate::cluster::pack::{LightEncoding, LightLayout, DATA_TEXTURE_WIDTH};
use crate::gl::EsVersion;
use crate::scene::light::SPOT_MIN_COS_DELTA;

/// Without fragment highp, the most one directional light adds to a pixel (in the fp16-range
/// form): four of them stay below fp16's 65 504. Only a contribution at least a quarter of
/// this (radiance / k² > 1/4) is ever capped: pre-exposed ([`ShaderFeatures::pre_exposure`]),
/// one that shows white anyway (4 000 · 2^−½ and more; a tone map's input is capped at 1 000).
pub const DIRECTIONAL_FP16_CAP: f32 = 16000.0;

/// Without fragment highp (where they are fp16, past 65 504 infinity), the largest ambient a
/// channel and the largest ambient term (ambient × albedo, which may pass 1): the uniform is
/// scaled down to it, its channels alike (`uniforms::ambient_uniform`); the term is capped at
/// it per channel in `glsl/surface_maps.glsl`.
pub const FP16_MAX_AMBIENT: f32 = 60000.0;

/// `radiance` times a frame's pre-exposure (`by`: [`ShaderFeatures::pre_exposure`], or
/// deferred's accumulation scale), within f32: validation allows radiance up to f32's largest
/// value, and Inf would be NaN further on (times a falloff of 0, or the fp16 form's scaling).
pub(crate) fn pre_exposed(radiance: glam::Vec3, by: f32) -> glam::Vec3 {
    (radiance * by).min(glam::Vec3::MAX)
}

/// Feature bitset of a shader variant.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ShaderFeatures(pub u64);

impl ShaderFeatures {
    /// The material has a diffuse texture.
    pub const TEXTURE: u64 = 1 << 0;
    /// The scene has spot lights (cone code compiled in).
    pub const SPOT: u64 = 1 << 1;
    /// The material has a specular term.
    pub const SPECULAR: u64 = 1 << 2;
    /// Light records are RGBA8-packed (ES 2.0 without float textures).
    pub const LIGHTS_RGBA8: u64 = 1 << 3;
    /// Write linear values (no sRGB encoding).
    pub const OUTPUT_LINEAR: u64 = 1 << 4;
    /// Write linear values without clamping (float targets: NaN and Inf stay visible).
    pub const OUTPUT_HDR: u64 = 1 << 5;
    /// No lights at all: the light loop and its data are compiled out.
    pub const NO_LIGHTS: u64 = 1 << 6;
    /// The reference variant: the light model's mediump tier (`MEDP`) at highp too, so the
    /// image is what the light model gives at the best precision the device has.
    pub const REFERENCE_PRECISION: u64 = 1 << 7;
    /// The device has no fragment highp: light radiance is read in its fp16-range form (see
    /// `cluster::pack`), so a bright light does not overflow to infinity.
    pub const FP16_LIGHTS: u64 = 1 << 8;
    /// Instead of a colour, write the number of lights the fragment's loop runs over (the
    /// light-evaluation count; see [`crate::options::CountKind`]).
    pub const COUNT_EVALS: u64 = 1 << 9;
    /// Instead of a colour, write the number of lights whose sphere (and cone) reaches the
    /// fragment: the lower bound of any per-pixel culling (forward only).
    pub const COUNT_REACHING: u64 = 1 << 10;
    /// With [`Self::COUNT_EVALS`]: draw the count through a colour map (0 to `u_heatScale`
    /// lights) instead of encoding it exactly, for looking at (the viewer's heatmap).
    pub const COUNT_HEATMAP: u64 = 1 << 11;
    /// Reinhard tone map before the encode (see [`crate::options::ToneMap`]).
    pub const TONEMAP_REINHARD: u64 = 1 << 12;
    /// ACES (Narkowicz fit) tone map before the encode.
    pub const TONEMAP_ACES: u64 = 1 << 13;
    /// Khronos PBR Neutral tone map before the encode.
    pub const TONEMAP_NEUTRAL: u64 = 1 << 14;
    /// Driver workaround (see [`crate::gl::Caps::needs_uniform_light_loop`]): the cell's light
    /// loop runs the same iterations in every fragment of a draw (to the frame's longest list),
    /// selecting each fragment's own contributions, so no fragment leaves the loop before its
    /// neighbours.
    pub const UNIFORM_LIGHT_LOOP: u64 = 1 << 15;
    /// The glTF metallic-roughness BRDF instead of Blinn-Phong: set for the variants of
    /// materials that use it, and for the deferred light pass of a scene that has any (which
    /// then picks the BRDF per pixel from its G-buffer).
    pub const METALLIC_ROUGHNESS: u64 = 1 << 16;
    /// The scene has directional lights: up to four, evaluated for every pixel from uniforms,
    /// outside the light lists (`glsl/directional.glsl`).
    pub const DIRECTIONAL: u64 = 1 << 17;

    /// The mesh has vertex colours (glTF `COLOR_0`): they multiply the base colour.
    pub const VERTEX_COLOR: u64 = 1 << 18;
    /// The material has a normal map (and the mesh tangents).
    pub const NORMAL_MAP: u64 = 1 << 19;
    /// The material emits light (added after the light sum).
    pub const EMISSIVE: u64 = 1 << 20;
    /// With [`Self::EMISSIVE`]: an emissive texture multiplies the emission.
    pub const EMISSIVE_MAP: u64 = 1 << 21;
    /// The material has an ambient occlusion texture (scales the ambient term).
    pub const OCCLUSION: u64 = 1 << 22;
    /// The material has a glTF metallic-roughness texture.
    pub const MR_TEXTURE: u64 = 1 << 23;
    /// Some texture the material samples has a `KHR_texture_transform`.
    pub const TEXTURE_TRANSFORM: u64 = 1 << 24;
    /// The material cuts fragments by its base colour texture's alpha, or `COLOR_0`'s with
    /// [`Self::VERTEX_ALPHA`] (glTF `MASK`).
    pub const ALPHA_MASK: u64 = 1 << 25;
    /// Colour textures are sRGB textures the sampler decodes before filtering (ES 3.0 level);
    /// without, the shader decodes the filtered texel (ES 2.0).
    pub const SRGB_TEXTURES: u64 = 1 << 26;
    /// The material's opacity is multiplied by its base colour texture's alpha (glTF `BLEND`).
    pub const TEXTURE_ALPHA: u64 = 1 << 27;
    /// With [`Self::VERTEX_COLOR`]: `COLOR_0`'s alpha multiplies the opacity (glTF `BLEND`) or
    /// takes part in the cut (glTF `MASK`).
    pub const VERTEX_ALPHA: u64 = 1 << 28;
    /// Some texture the material samples reads the mesh's second coordinate set (glTF
    /// `TEXCOORD_1`); implies [`Self::TEXTURE_TRANSFORM`], whose per-texture coordinates
    /// carry each texture's set.
    pub const SECOND_UVS: u64 = 1 << 29;

    /// The flags a material's (and its mesh's) surface inputs set, as opposed to the scene's,
    /// the frame's and the device's.
    pub const SURFACE_INPUTS: u64 = Self::VERTEX_COLOR
        | Self::NORMAL_MAP
        | Self::EMISSIVE
        | Self::EMISSIVE_MAP
        | Self::OCCLUSION
        | Self::MR_TEXTURE
        | Self::TEXTURE_TRANSFORM
        | Self::ALPHA_MASK
        | Self::TEXTURE_ALPHA
        | Self::VERTEX_ALPHA
        | Self::SECOND_UVS;

    /// Every flag with its name.
    pub const NAMED: [(u64, &'static str); 30] = [
        (Self::TEXTURE, "texture"),
        (Self::SPOT, "spot"),
        (Self::SPECULAR, "specular"),
        (Self::LIGHTS_RGBA8, "lights_rgba8"),
        (Self::OUTPUT_LINEAR, "output_linear"),
        (Self::OUTPUT_HDR, "output_hdr"),
        (Self::NO_LIGHTS, "no_lights"),
        (Self::REFERENCE_PRECISION, "reference_precision"),
        (Self::FP16_LIGHTS, "fp16_lights"),
        (Self::COUNT_EVALS, "count_evals"),
        (Self::COUNT_REACHING, "count_reaching"),
        (Self::COUNT_HEATMAP, "count_heatmap"),
        (Self::TONEMAP_REINHARD, "tonemap_reinhard"),
        (Self::TONEMAP_ACES, "tonemap_aces"),
        (Self::TONEMAP_NEUTRAL, "tonemap_neutral"),
        (Self::UNIFORM_LIGHT_LOOP, "uniform_light_loop"),
        (Self::METALLIC_ROUGHNESS, "metallic_roughness"),
        (Self::DIRECTIONAL, "directional"),
        (Self::VERTEX_COLOR, "vertex_color"),
        (Self::NORMAL_MAP, "normal_map"),
        (Self::EMISSIVE, "emissive"),
        (Self::EMISSIVE_MAP, "emissive_map"),
        (Self::OCCLUSION, "occlusion"),
        (Self::MR_TEXTURE, "mr_texture"),
        (Self::TEXTURE_TRANSFORM, "texture_transform"),
        (Self::ALPHA_MASK, "alpha_mask"),
        (Self::SRGB_TEXTURES, "srgb_textures"),
        (Self::TEXTURE_ALPHA, "texture_alpha"),
        (Self::VERTEX_ALPHA, "vertex_alpha"),
        (Self::SECOND_UVS, "second_uvs"),
    ];

    /// Names of the set flags.
    pub fn names(self) -> Vec<&'static str> {
        Self::NAMED
            .iter()
            .filter(|(b, _)| self.has(*b))
            .map(|(_, n)| *n)
            .collect()
    }

    /// True when `bit` is set.
    pub fn has(self, bit: u64) -> bool {
        self.0 & bit != 0
    }

    /// With `bit` set or cleared.
    pub fn with(self, bit: u64, on: bool) -> Self {
        ShaderFeatures(if on { self.0 | bit } else { self.0 & !bit })
    }

    /// True for the count variants (light evaluations or reaching lights instead of colour).
    pub fn counting(self) -> bool {
        self.has(Self::COUNT_EVALS) || self.has(Self::COUNT_REACHING)
    }

    /// Light encoding these features select.
    pub fn light_encoding(self) -> LightEncoding {
        if self.has(Self::LIGHTS_RGBA8) {
            LightEncoding::Rgba8
        } else {
            LightEncoding::Float32
        }
    }

    /// What this variant's lights, ambient and emission are multiplied by before the shader
    /// sums them, the exposure taking the rest: without fragment highp (`FP16_LIGHTS`), 2 to
    /// the exposure rounded (exact), so the fp16 sum holds what is shown rather than raw
    /// radiance, whose faint lights' shares rounded to zero at a positive exposure and whose
    /// bright ones (a sun in lux) passed fp16's caps at a negative one; else 1. HDR output
    /// takes no exposure.
    pub fn pre_exposure(self, exposure_ev: f32) -> f32 {
        if self.has(Self::FP16_LIGHTS) && !self.has(Self::OUTPUT_HDR) {
            exposure_ev.round().exp2()
        } else {
            1.0
        }
    }

    /// How this variant's light records are laid out.
    pub fn light_layout(self) -> LightLayout {
        LightLayout {
            encoding: self.light_encoding(),
            spots: self.has(Self::SPOT),
            fp16: self.has(Self::FP16_LIGHTS),
        }
    }

    /// The `#define`s of this variant: feature switches plus the constants shared with Rust.
    pub fn defines(self, dialect: EsVersion, max_lights: u32) -> Vec<(String, String)> {
        let flag = |bit| if self.has(bit) { "1" } else { "0" }.to_string();
        vec![
            ("HAS_TEXTURE".into(), flag(Self::TEXTURE)),
            ("HAS_SPOT".into(), flag(Self::SPOT)),
            ("HAS_SPECULAR".into(), flag(Self::SPECULAR)),
            ("LIGHTS_RGBA8".into(), flag(Self::LIGHTS_RGBA8)),
            ("OUTPUT_LINEAR".into(), flag(Self::OUTPUT_LINEAR)),
            ("OUTPUT_HDR".into(), flag(Self::OUTPUT_HDR)),
            ("NO_LIGHTS".into(), flag(Self::NO_LIGHTS)),
            ("FP16_LIGHTS".into(), flag(Self::FP16_LIGHTS)),
            ("COUNT_EVALS".into(), flag(Self::COUNT_EVALS)),
            ("COUNT_REACHING".into(), flag(Self::COUNT_REACHING)),
            ("COUNT_HEATMAP".into(), flag(Self::COUNT_HEATMAP)),
            ("UNIFORM_LIGHT_LOOP".into(), flag(Self::UNIFORM_LIGHT_LOOP)),
            ("METALLIC_ROUGHNESS".into(), flag(Self::METALLIC_ROUGHNESS)),
            ("HAS_DIRECTIONAL".into(), flag(Self::DIRECTIONAL)),
            (
                "DIRECTIONAL_FP16_CAP".into(),
                format!("{DIRECTIONAL_FP16_CAP:.1}"),
            ),
            ("FP16_MAX_AMBIENT".into(), format!("{FP16_MAX_AMBIENT:.1}")),
            (
                "MAX_DIRECTIONAL".into(),
                crate::scene::MAX_DIRECTIONAL_LIGHTS.to_string(),
            ),
            ("HAS_VERTEX_COLOR".into(), flag(Self::VERTEX_COLOR)),
            ("HAS_NORMAL_MAP".into(), flag(Self::NORMAL_MAP)),
            ("HAS_EMISSIVE".into(), flag(Self::EMISSIVE)),
            ("HAS_EMISSIVE_MAP".into(), flag(Self::EMISSIVE_MAP)),
            ("HAS_OCCLUSION".into(), flag(Self::OCCLUSION)),
            ("HAS_MR_TEXTURE".into(), flag(Self::MR_TEXTURE)),
            (
                "HAS_TEXTURE_TRANSFORM".into(),
                flag(Self::TEXTURE_TRANSFORM),
            ),
            ("HAS_ALPHA_MASK".into(), flag(Self::ALPHA_MASK)),
            ("SRGB_TEXTURES".into(), flag(Self::SRGB_TEXTURES)),
            ("HAS_TEXTURE_ALPHA".into(), flag(Self::TEXTURE_ALPHA)),
            ("HAS_VERTEX_ALPHA".into(), flag(Self::VERTEX_ALPHA)),
            ("HAS_SECOND_UVS".into(), flag(Self::SECOND_UVS)),
            (
                "TONEMAP".into(),
                if self.has(Self::TONEMAP_REINHARD) {
                    "1"
                } else if self.has(Self::TONEMAP_ACES) {
                    "2"
                } else if self.has(Self::TONEMAP_NEUTRAL) {
                    "3"
                } else {
                    "0"
                }
                .into(),
            ),
            (
                "MEDP".into(),
                if self.has(Self::REFERENCE_PRECISION) {
                    "HIGHP"
                } else {
                    "mediump"
                }
                .into(),
            ),
            ("DATA_WIDTH".into(), DATA_TEXTURE_WIDTH.to_string()),
            (
                "LIGHT_TEXELS".into(),
                self.light_layout().texels_per_light().to_string(),
            ),
            ("MAX_LIGHTS".into(), max_lights.to_string()),
            (
                "CELL_CAP".into(),
                crate::cluster::pack::RGBA8_CELL_CAP.to_string(),
            ),
            (
                "SPOT_MIN_COS_DELTA".into(),
                format!("{SPOT_MIN_COS_DELTA:e}"),
            ),
            (
                "ES_DIALECT".into(),
                match dialect {
                    EsVersion::Es2 => "2",
                    EsVersion::Es3 => "3",
                }
                .into(),
            ),
        ]
    }
}
