//! Directional lights on the GPU: the frame's (at most four) suns as uniforms of
//! `glsl/directional.glsl`, evaluated by every method for every pixel outside its light lists
//! (forward and the culled methods in their shading pass, deferred in its composite).

use glam::{DMat4, Mat4, Vec3};

use super::ShaderFeatures;
use crate::cluster::pack::fp16_radiance;
use crate::gl::program::{Resolver, Uniform};
use crate::gl::Device;
use crate::scene::directional::shown_directional_lights;
use crate::scene::{Scene, MAX_DIRECTIONAL_LIGHTS};

/// The frame's directional lights as the shader reads them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DirectionalFrame {
    /// How many columns are used (at most [`MAX_DIRECTIONAL_LIGHTS`]).
    pub count: i32,
    /// Column i: unit direction from a surface to light i, in view space (xyz); for `fp16`
    /// frames k in w.
    pub to_light: Mat4,
    /// Light i's radiance; for `fp16` frames radiance / k².
    pub radiance: [Vec3; MAX_DIRECTIONAL_LIGHTS],
}

impl DirectionalFrame {
    /// The scene's shown directional lights ([`shown_directional_lights`], indices kept in
    /// `shown`) in view space, their radiance times `pre_exposure`
    /// ([`ShaderFeatures::pre_exposure`](super::ShaderFeatures::pre_exposure)); `fp16`: in the
    /// fp16-range form. Returns the frame and how many active lights past
    /// [`MAX_DIRECTIONAL_LIGHTS`] were left out.
    pub fn gather(
        scene: &Scene,
        view: &DMat4,
        fp16: bool,
        pre_exposure: f32,
        shown: &mut Vec<usize>,
    ) -> (Self, usize) {
        let dropped = shown_directional_lights(&scene.directional_lights, shown);
        let mut frame = DirectionalFrame::default();
        for (column, &i) in shown.iter().enumerate().take(MAX_DIRECTIONAL_LIGHTS) {
            let light = &scene.directional_lights[i];
            let to_light = crate::scene::direction::unit(view.transform_vector3(light.to_light()))
                .unwrap_or_default()
                .as_vec3();
            let radiance = super::features::pre_exposed(light.radiance(), pre_exposure);
            let (radiance, k) = if fp16 {
                fp16_radiance(radiance)
            } else {
                (radiance, 1.0)
            };
            *frame.to_light.col_mut(column) = to_light.extend(k);
            frame.radiance[column] = radiance;
            frame.count += 1;
        }
        debug_assert!(frame.radiance.iter().all(|r| r.is_finite()) && frame.to_light.is_finite());
        (frame, dropped)
    }
}

/// `directional.glsl`'s uniforms.
pub struct DirectionalUniforms {
    count: Uniform<i32>,
    to_light: Uniform<Mat4>,
    radiance: Uniform<[Vec3; MAX_DIRECTIONAL_LIGHTS]>,
}

impl DirectionalUniforms {
    /// `lit`: whether the variant's output runs the light model (the uniforms are needed when
    /// the variant also has [`ShaderFeatures::DIRECTIONAL`]).
    pub(crate) fn resolve(r: &mut Resolver<'_>, lit: bool) -> Self {
        let used = lit && ShaderFeatures(r.features()).has(ShaderFeatures::DIRECTIONAL);
        DirectionalUniforms {
            count: r.required_when(used, "u_directionalCount"),
            to_light: r.required_when(used, "u_directionalToLight"),
            radiance: r.required_when(used, "u_directionalRadiance"),
        }
    }

    /// Sets the frame's lights (nothing in a variant without them).
    pub(crate) fn set(&self, dev: &Device, frame: &DirectionalFrame) {
        self.count.set(dev, frame.count);
        self.to_light.set(dev, frame.to_light);
        self.radiance.set(dev, frame.radiance);
    }
}
