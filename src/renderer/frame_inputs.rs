//! A frame's inputs made ready before anything is drawn: the scene checked and uploaded, its
//! lights gathered and placed for the context's precision, the shader features chosen.

use glam::{DMat4, Mat4};

use super::frame_setup::{content_far, gather_directional, gather_lights, shader_features};
use super::Renderer;
use crate::methods::directional::DirectionalFrame;
use crate::methods::ShaderFeatures;
use crate::options::RenderOptions;
use crate::scene::features::SceneFeatures;
use crate::scene::Scene;
use crate::Error;

/// What [`Renderer::set_up_frame`] found for a frame, before anything is drawn.
pub(super) struct FrameSetup {
    /// The objects draw with the shared surface variants (`methods::surface_variants`).
    pub shared_surfaces: bool,
    /// Bytes the split copies of long triangles uploaded.
    pub split_bytes: usize,
    /// Bytes of meshes and images uploaded for the first time.
    pub scene_upload_bytes: usize,
    pub view: DMat4,
    pub projection: Mat4,
    pub scene_features: SceneFeatures,
    pub features: ShaderFeatures,
    /// What the frame's lights, ambient and emission are multiplied by
    /// ([`ShaderFeatures::pre_exposure`]).
    pub pre_exposure: f32,
    pub directional: DirectionalFrame,
    /// The near plane, and the farthest distance the GPU may draw.
    pub near: f64,
    pub far: f64,
    /// How deep the scene's content reaches (where a grid should end).
    pub content_far: f64,
}

impl Renderer {
    /// A frame's setup: the scene validated and uploaded, its lights gathered and placed for
    /// this context's precision (with the warnings these owe), the shader features chosen.
    /// `depth_bits`: the bound framebuffer's depth precision, for the coarse-depth warning.
    pub(super) fn set_up_frame(
        &mut self,
        scene: &Scene,
        (width, height): (u32, u32),
        options: &RenderOptions,
        depth_bits: u32,
    ) -> Result<FrameSetup, Error> {
        if let Some(warning) = self.pending_warning.take() {
            log::warn!("{warning}");
        }
        scene.validate()?;
        super::empty_scene::warn_of_nothing_to_draw(scene, &mut self.warned_nothing_to_draw);
        let shared_surfaces =
            options.measure.full_variants || self.shared_surfaces.needed(scene, self.dev.caps());
        let scene_upload_bytes = self.gpu_scene.upload(&self.dev, scene, shared_surfaces)?;
        self.gpu_scene.check_placement(scene)?;
        let split_bytes = self
            .gpu_scene
            .split_for_frame(&self.dev, scene, (width, height))?;
        let view: DMat4 = scene.camera.view_matrix();
        let projection = scene
            .camera
            .projection_matrix(width as f64 / height as f64)
            .as_mat4();
        if scene.lights.len() != self.lights_probed {
            super::frame_setup::check_light_memory(scene.lights.len())?;
            self.lights_probed = scene.lights.len();
        }
        let scene_features = SceneFeatures::of(scene);
        let features = shader_features(&scene_features, options, self.dev.caps()).with(
            ShaderFeatures::OUTPUT_LINEAR,
            options.linear || self.srgb_destination,
        );
        let pre_exposure = features.pre_exposure(options.exposure_ev);
        if gather_lights(&mut self.lights, scene, &view, options, pre_exposure)
            || self.timing_frames
        {
            self.lights_generation += 1;
        }
        let directional = gather_directional(
            scene,
            &view,
            features,
            pre_exposure,
            &mut self.shown_directional,
            &mut self.warned_directional,
        );
        // Lights are culled at the farthest distance the GPU may draw, not the far plane
        // asked for: a tiny near plane leaves `f32` no far plane to clip at.
        let near = scene.camera.near_far().0;
        let far = scene.camera.far_clip_range().1;
        let content_far = content_far(self.gpu_scene.scene_bounds(scene), &view, near, far);
        if !self.warming_up {
            super::depth_warning::warn_of_unclipped_far(
                &scene.camera,
                &mut self.warned_unclipped_far,
            );
            super::depth_warning::warn_of_coarse_depth(
                &scene.camera,
                content_far,
                depth_bits,
                &mut self.warned_depth_step,
            );
        }
        let reach = super::fp16_range::view_reach(scene, width as f64 / height as f64, content_far);
        let farthest = super::fp16_range::check(self.dev.caps(), scene, &self.lights, reach)?;
        if self.placed.update(&self.lights, farthest) {
            self.lights_generation += 1;
        }
        super::fp16_channels::warn_of_lost_channels(self.dev.caps(), scene, pre_exposure);
        super::fp16_channels::warn_of_capped_radiance(
            self.dev.caps(),
            scene,
            pre_exposure,
            &mut self.warned_capped_radiance,
        );
        super::fp16_channels::warn_of_capped_ambient(
            self.dev.caps(),
            scene,
            pre_exposure,
            &mut self.warned_capped_ambient,
        );
        Ok(FrameSetup {
            shared_surfaces,
            split_bytes,
            scene_upload_bytes,
            view,
            projection,
            scene_features,
            features,
            pre_exposure,
            directional,
            near,
            far,
            content_far,
        })
    }
}
