//! The uniform groups the geometry-pass programs share (`mesh.vert`, `surface.glsl`,
//! `light_data.glsl`), resolved once per linked program (see [`crate::gl::program`]).
//!
//! Each group says which of its uniforms a variant must have: those its output reads in every
//! variant with those features. The others (read only by code a feature compiles out, or by
//! code whose result the variant discards) may be optimised out by the driver.

use glam::{DMat3, DMat4, Mat3, Mat4, Vec3};

use super::features::FP16_MAX_AMBIENT;
use super::maps::MapUniforms;
use super::ShaderFeatures;
use crate::gl::program::{Resolver, Sampler, Uniform};
use crate::gl::texture::DataTexture;
use crate::gl::{Device, EsVersion};
use crate::scene::Material;

/// The variant's feature bits.
pub(crate) fn features(r: &Resolver<'_>) -> ShaderFeatures {
    ShaderFeatures(r.features())
}

/// `mesh.vert`: the object's transforms.
pub struct Transforms {
    model_view: Uniform<Mat4>,
    normal_matrix: Uniform<Mat3>,
    projection: Uniform<Mat4>,
    tangent_sign: Uniform<f32>,
}

impl Transforms {
    /// `normals`: whether the variant's output reads the normal.
    pub(crate) fn resolve(r: &mut Resolver<'_>, normals: bool) -> Self {
        Transforms {
            model_view: r.required("u_modelView"),
            normal_matrix: r.required_when(normals, "u_normalMatrix"),
            projection: r.required("u_projection"),
            // Normal-mapped variants only.
            tangent_sign: r.optional("u_tangentSign"),
        }
    }

    /// `model_view` in f64 with the camera already subtracted, so far-from-origin scenes stay
    /// exact in f32.
    pub(crate) fn set(&self, dev: &Device, model_view: &DMat4, projection: &Mat4) {
        let normal_matrix =
            crate::scene::normal_matrix::normal_matrix(&DMat3::from_mat4(*model_view));
        self.model_view.set(dev, model_view.as_mat4());
        self.normal_matrix.set(dev, normal_matrix.as_mat3());
        self.projection.set(dev, *projection);
        // A mirroring transform flips the bitangent (N × T turns the other way).
        let sign = if is_mirroring(model_view) { -1.0 } else { 1.0 };
        self.tangent_sign.set(dev, sign);
    }
}

/// Whether `model_view` mirrors what it places: its front faces are then clockwise on screen.
pub(crate) fn is_mirroring(model_view: &DMat4) -> bool {
    crate::scene::normal_matrix::mirrors(&DMat3::from_mat4(*model_view))
}

/// `surface.glsl`: the material, the ambient light and the output encoding.
pub struct Surface {
    albedo: Uniform<Vec3>,
    specular: Uniform<Vec3>,
    shininess: Uniform<f32>,
    metallic: Uniform<f32>,
    roughness: Uniform<f32>,
    alpha: Uniform<f32>,
    alpha_cutoff: Uniform<f32>,
    ambient: Uniform<Vec3>,
    exposure: Uniform<f32>,
    orthographic: Uniform<f32>,
    heat_scale: Uniform<f32>,
    albedo_tex: Uniform<Sampler>,
    front_sign: Uniform<f32>,
    maps: MapUniforms,
}

/// The ambient uniform's value: where it is fp16 (`fp16`: the `FP16_LIGHTS` tier) scaled down,
/// its channels alike, so that none passes [`FP16_MAX_AMBIENT`].
pub(crate) fn ambient_uniform(ambient: Vec3, fp16: bool) -> Vec3 {
    match fp16 {
        true => crate::cluster::pack::scaled_alike_within(ambient, FP16_MAX_AMBIENT),
        false => ambient,
    }
}

/// What a frame sets on every object's [`Surface`] besides its material.
pub(crate) struct SurfaceFrame {
    /// The scene's ambient radiance.
    pub ambient: Vec3,
    /// 2^exposure.
    pub exposure: f32,
    /// Whether the camera is orthographic.
    pub orthographic: bool,
    /// The heatmap's top count.
    pub heat_scale: f32,
}

/// Whether a variant cuts fragments by its texture's alpha (`surfaceCut`: only with one).
fn cuts(f: ShaderFeatures) -> bool {
    f.has(ShaderFeatures::ALPHA_MASK)
        && (f.has(ShaderFeatures::TEXTURE) || f.has(ShaderFeatures::VERTEX_ALPHA))
}

impl Surface {
    /// For a shader that lights and encodes a colour (forward, clustered): `lit` is whether
    /// the variant runs the light model.
    pub(crate) fn shaded(r: &mut Resolver<'_>, lit: bool) -> Self {
        let f = features(r);
        let colour = !f.counting();
        let mr = colour && f.has(ShaderFeatures::METALLIC_ROUGHNESS);
        Surface {
            albedo: r.required_when(colour, "u_albedo"),
            specular: r.required_when(lit && f.has(ShaderFeatures::SPECULAR), "u_specular"),
            shininess: r.required_when(lit && f.has(ShaderFeatures::SPECULAR), "u_shininess"),
            metallic: r.required_when(lit && mr, "u_metallic"),
            roughness: r.required_when(lit && mr, "u_roughness"),
            alpha: r.required_when(colour, "u_alpha"),
            alpha_cutoff: r.required_when(colour && cuts(f), "u_alphaCutoff"),
            ambient: r.required_when(colour, "u_ambient"),
            exposure: r.required_when(colour && !f.has(ShaderFeatures::OUTPUT_HDR), "u_exposure"),
            // The view direction: the highlights' (both sides' normals come from the winding).
            orthographic: r.required_when(
                lit && (mr || f.has(ShaderFeatures::SPECULAR)),
                "u_orthographic",
            ),
            // A light-less count is a constant a compiler may fold through the colour map.
            heat_scale: r.required_when(
                f.counting()
                    && f.has(ShaderFeatures::COUNT_HEATMAP)
                    && !f.has(ShaderFeatures::NO_LIGHTS),
                "u_heatScale",
            ),
            albedo_tex: r.required_when(colour && f.has(ShaderFeatures::TEXTURE), "u_albedoTex"),
            // Which side is seen: read with the normal.
            front_sign: r.required_when(lit, "u_frontSign"),
            maps: MapUniforms::resolve(r, colour),
        }
    }

    /// For the G-buffer pass, which stores the material and never encodes a colour.
    pub(crate) fn gbuffer(r: &mut Resolver<'_>) -> Self {
        let f = features(r);
        Surface {
            albedo: r.required("u_albedo"),
            specular: r.required_when(f.has(ShaderFeatures::SPECULAR), "u_specular"),
            shininess: r.required_when(f.has(ShaderFeatures::SPECULAR), "u_shininess"),
            metallic: r.required_when(f.has(ShaderFeatures::METALLIC_ROUGHNESS), "u_metallic"),
            roughness: r.required_when(f.has(ShaderFeatures::METALLIC_ROUGHNESS), "u_roughness"),
            alpha: r.optional("u_alpha"),
            alpha_cutoff: r.required_when(cuts(f), "u_alphaCutoff"),
            ambient: r.optional("u_ambient"),
            exposure: r.optional("u_exposure"),
            orthographic: r.required("u_orthographic"),
            heat_scale: r.optional("u_heatScale"),
            albedo_tex: r.required_when(f.has(ShaderFeatures::TEXTURE), "u_albedoTex"),
            front_sign: r.required("u_frontSign"),
            maps: MapUniforms::resolve(r, true),
        }
    }

    /// Sets the material (its texture, when it has one, bound at `texture_unit`) and the
    /// frame's values; the heat scale only for a `heatmap` variant.
    pub(crate) fn set(
        &self,
        dev: &Device,
        material: &Material,
        texture_unit: Option<u32>,
        frame: &SurfaceFrame,
        heatmap: bool,
    ) {
        self.albedo.set(dev, material.diffuse);
        self.specular.set(dev, material.specular);
        self.shininess.set(dev, material.shading_exponent());
        self.metallic.set(dev, material.metallic);
        self.roughness.set(dev, material.roughness);
        self.alpha.set(dev, material.alpha);
        self.alpha_cutoff
            .set(dev, material.alpha_cutoff.unwrap_or(0.0));
        if heatmap {
            self.heat_scale.set(dev, frame.heat_scale);
        }
        self.ambient.set(dev, frame.ambient);
        self.exposure.set(dev, frame.exposure);
        self.orthographic
            .set(dev, if frame.orthographic { 1.0 } else { 0.0 });
        if let Some(unit) = texture_unit {
            self.albedo_tex.set(dev, unit);
        }
    }

    /// Whether the object drawn is placed by a mirroring transform ([`is_mirroring`]), which
    /// turns round the winding that tells which side is seen.
    pub(crate) fn set_mirrored(&self, dev: &Device, mirrored: bool) {
        self.front_sign.set(dev, if mirrored { -1.0 } else { 1.0 });
    }

    /// `surface_maps.glsl`'s uniforms and textures (see [`MapUniforms::set`]).
    pub(crate) fn maps(&self) -> &MapUniforms {
        &self.maps
    }
}

/// `light_data.glsl`: the light records' texture and how to read it (the count is the
/// forward program's own).
pub struct LightData {
    lights: Uniform<Sampler>,
    inv_height: Uniform<f32>,
    ranges: Uniform<[f32; 2]>,
}

impl LightData {
    /// `reads`: whether the variant fetches light records.
    pub(crate) fn resolve(r: &mut Resolver<'_>, reads: bool) -> Self {
        let rgba8 = features(r).has(ShaderFeatures::LIGHTS_RGBA8);
        let es2 = r.es() == EsVersion::Es2;
        LightData {
            lights: r.required_when(reads, "u_lights"),
            inv_height: r.required_when(reads && es2, "u_lightTexInvHeight"),
            ranges: r.required_when(reads && rgba8, "u_lightRanges"),
        }
    }

    /// Binds `texture` at `unit` and sets how its records read (`ranges`: the RGBA8
    /// encoding's position and radius ranges).
    pub(crate) fn bind(&self, dev: &Device, texture: &DataTexture, unit: u32, ranges: [f32; 2]) {
        texture.bind(dev, unit);
        self.lights.set(dev, unit);
        self.inv_height.set(dev, inv_height(texture));
        self.ranges.set(dev, ranges);
    }
}

/// 1 / the texture's height in rows (ES 2.0 addresses data texels with normalised
/// coordinates).
pub(crate) fn inv_height(texture: &DataTexture) -> f32 {
    1.0 / texture.size().1.max(1) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gl::context::context_or_skip;
    use crate::gl::program::{ProgramCache, ProgramKey, UniformSet};
    use crate::methods::culled::ClusteredProgram;
    use crate::methods::deferred::{CompositeProgram, GBufferProgram, LightProgram};
    use crate::methods::forward::ForwardProgram;
    use crate::methods::geometry::DepthProgram;
    use crate::methods::ShaderFeatures as F;

    /// Variants that switch the uniforms' uses on and off, alone and together.
    const VARIANTS: &[u64] = &[
        0,
        F::TEXTURE,
        F::SPECULAR,
        F::SPOT | F::SPECULAR | F::TEXTURE,
        F::LIGHTS_RGBA8,
        F::LIGHTS_RGBA8 | F::FP16_LIGHTS | F::SPOT,
        F::OUTPUT_HDR | F::SPECULAR,
        F::OUTPUT_LINEAR | F::TONEMAP_ACES,
        F::REFERENCE_PRECISION | F::SPECULAR,
        F::COUNT_EVALS,
        F::COUNT_EVALS | F::COUNT_HEATMAP | F::TEXTURE,
        F::COUNT_REACHING | F::LIGHTS_RGBA8 | F::SPOT,
        F::UNIFORM_LIGHT_LOOP | F::SPECULAR,
        F::METALLIC_ROUGHNESS,
        F::METALLIC_ROUGHNESS | F::SPOT | F::TEXTURE | F::REFERENCE_PRECISION,
        F::METALLIC_ROUGHNESS | F::LIGHTS_RGBA8 | F::FP16_LIGHTS,
        F::NO_LIGHTS,
        F::NO_LIGHTS | F::TEXTURE | F::SPECULAR,
        F::NO_LIGHTS | F::COUNT_EVALS | F::COUNT_HEATMAP,
        F::DIRECTIONAL,
        F::DIRECTIONAL | F::SPECULAR | F::SPOT,
        F::DIRECTIONAL | F::LIGHTS_RGBA8 | F::FP16_LIGHTS,
        F::DIRECTIONAL | F::NO_LIGHTS | F::TEXTURE,
        F::DIRECTIONAL | F::NO_LIGHTS | F::NORMAL_MAP,
        F::DIRECTIONAL | F::COUNT_EVALS,
        F::DIRECTIONAL | F::UNIFORM_LIGHT_LOOP,
        F::SURFACE_INPUTS | F::TEXTURE | F::SPECULAR | F::SPOT,
        F::NORMAL_MAP | F::TEXTURE_TRANSFORM,
        F::EMISSIVE | F::OCCLUSION | F::VERTEX_COLOR | F::LIGHTS_RGBA8,
        F::VERTEX_COLOR | F::VERTEX_ALPHA | F::ALPHA_MASK,
        F::VERTEX_COLOR | F::VERTEX_ALPHA | F::TEXTURE | F::TEXTURE_ALPHA,
        F::VERTEX_COLOR | F::VERTEX_ALPHA,
        F::NO_LIGHTS | F::EMISSIVE | F::EMISSIVE_MAP | F::TEXTURE | F::TEXTURE_TRANSFORM,
    ];

    fn build<U: UniformSet>(
        programs: &mut ProgramCache,
        dev: &Device,
        shader: &'static str,
        features: ShaderFeatures,
    ) {
        let key = ProgramKey {
            shader,
            features: features.0,
            dialect: dev.es(),
        };
        if let Err(e) = programs.bind::<U>(dev, key, || features.defines(dev.es(), 64)) {
            panic!("{shader} {:?} ({}): {e}", features.names(), dev.es());
        }
    }

    /// Every program of every method links with its uniform set in each variant: no required
    /// uniform is missing, no name misspelt, no type mismatched.
    #[test]
    fn every_variant_links_with_its_uniforms() {
        // ES 2.0, ES 2.0 playing a device without fragment highp, ES 3.0.
        for (es, no_fragment_highp) in [
            (EsVersion::Es2, false),
            (EsVersion::Es2, true),
            (EsVersion::Es3, false),
        ] {
            let Some(ctx) = context_or_skip(es) else {
                return;
            };
            let restrictions = crate::gl::Restrictions {
                no_fragment_highp,
                ..Default::default()
            };
            let dev =
                Device::restricted(ctx.load_gl().expect("gl"), es, &restrictions).expect("device");
            let mut programs = ProgramCache::new();
            build::<DepthProgram>(&mut programs, &dev, "depth", F::default());
            for &bits in VARIANTS {
                let f = ShaderFeatures(bits);
                build::<ForwardProgram>(&mut programs, &dev, "forward", f);
                if f.has(F::NO_LIGHTS) || f.has(F::COUNT_REACHING) || no_fragment_highp {
                    // Forward-only variants and devices.
                    continue;
                }
                build::<ClusteredProgram>(&mut programs, &dev, "clustered", f);
                if es == EsVersion::Es3 && !f.has(F::LIGHTS_RGBA8) {
                    build::<GBufferProgram>(&mut programs, &dev, "gbuffer", f);
                    // The full-screen passes never see a material's surface inputs.
                    let frame = ShaderFeatures(f.0 & !F::SURFACE_INPUTS);
                    let lights = frame.with(F::SPECULAR, true);
                    build::<LightProgram>(&mut programs, &dev, "deferred_light", lights);
                    build::<LightProgram>(&mut programs, &dev, "deferred_light_fullscreen", lights);
                    build::<CompositeProgram>(&mut programs, &dev, "deferred_composite", frame);
                }
            }
            programs.destroy(&dev);
        }
    }
}
