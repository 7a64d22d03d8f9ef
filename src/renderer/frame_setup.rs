//! Per-frame setup that depends only on the scene, the options and the device: the frame's
//! active lights in view space, the shader features the frame is drawn with, and how deep the
//! scene's content reaches (where a cluster grid should end).

use glam::DMat4;

use crate::cluster::view_light::GpuLight;
use crate::gl::Caps;
use crate::methods::directional::DirectionalFrame;
use crate::methods::ShaderFeatures;
use crate::options::{CountKind, RenderOptions, ToneMap};
use crate::scene::features::SceneFeatures;
use crate::scene::{Aabb, Scene};

/// Refills `lights` (keeping its buffer) with the scene's active lights in view space, each
/// light's cull radius shortened to where it falls below `options.light_cutoff` when one is
/// set, and its radiance times `pre_exposure` ([`ShaderFeatures::pre_exposure`]). Returns
/// whether the list differs, bit for bit, from the one `lights` held.
pub(super) fn gather_lights(
    lights: &mut Vec<GpuLight>,
    scene: &Scene,
    view: &DMat4,
    options: &RenderOptions,
    pre_exposure: f32,
) -> bool {
    let gathered = scene.lights.iter().filter(|l| l.is_active()).map(|light| {
        let mut g = GpuLight::from_light(light, view);
        if let Some(cutoff) = options.light_cutoff {
            g.cull_radius = crate::scene::shading::cutoff_distance(
                g.radiance.max_element() as f64,
                g.radius as f64,
                cutoff as f64,
            ) as f32;
        }
        g.radiance = crate::methods::features::pre_exposed(g.radiance, pre_exposure);
        g
    });
    overwrite_lights(lights, gathered)
}

/// Refuses a frame of `count` lights whose memory this process cannot allocate now (an
/// allocation refused inside the frame would abort it), as a load refuses making them.
pub(super) fn check_light_memory(count: usize) -> Result<(), crate::Error> {
    match crate::scene::input::light_memory_refusal(count) {
        Some(reason) => Err(crate::Error::Limit(reason)),
        None => Ok(()),
    }
}

/// Writes `new` over `lights` (keeping its buffer), comparing on the way. Returns whether the
/// list differs, bit for bit, from the one `lights` held.
pub(super) fn overwrite_lights(
    lights: &mut Vec<GpuLight>,
    new: impl Iterator<Item = GpuLight>,
) -> bool {
    let mut changed = false;
    let mut count = 0;
    for g in new {
        match lights.get_mut(count) {
            Some(old) if old.same_bits(&g) => {}
            Some(old) => {
                *old = g;
                changed = true;
            }
            None => {
                lights.push(g);
                changed = true;
            }
        }
        count += 1;
    }
    changed |= lights.len() != count;
    lights.truncate(count);
    changed
}

/// The frame's directional lights in view space (the brightest
/// [`MAX_DIRECTIONAL_LIGHTS`](crate::scene::MAX_DIRECTIONAL_LIGHTS); `shown` keeps which),
/// warning once (`warned`) when a scene has more.
pub(super) fn gather_directional(
    scene: &Scene,
    view: &DMat4,
    features: ShaderFeatures,
    pre_exposure: f32,
    shown: &mut Vec<usize>,
    warned: &mut bool,
) -> DirectionalFrame {
    let fp16 = features.has(ShaderFeatures::FP16_LIGHTS);
    let (frame, dropped) = DirectionalFrame::gather(scene, view, fp16, pre_exposure, shown);
    if dropped > 0 && !*warned {
        *warned = true;
        log::warn!(
            "a frame shows at most {} directional lights; {dropped} of the scene's {} active \
             ones (the dimmest) are left out",
            crate::scene::MAX_DIRECTIONAL_LIGHTS,
            dropped + frame.count as usize
        );
    }
    frame
}

/// The shader features a frame is drawn with: the scene's (spot lights), the options' (output,
/// tone map, counts, precision) and the device's (fp16 lights without fragment highp, RGBA8
/// light texels without float textures).
pub(super) fn shader_features(
    scene_features: &SceneFeatures,
    options: &RenderOptions,
    caps: &Caps,
) -> ShaderFeatures {
    ShaderFeatures::default()
        .with(
            ShaderFeatures::SPOT,
            scene_features.spot_lights || options.measure.full_variants,
        )
        .with(
            ShaderFeatures::DIRECTIONAL,
            scene_features.directional_lights,
        )
        .with(ShaderFeatures::OUTPUT_LINEAR, options.linear)
        .with(
            ShaderFeatures::TONEMAP_REINHARD,
            options.tone_map == ToneMap::Reinhard,
        )
        .with(
            ShaderFeatures::TONEMAP_ACES,
            options.tone_map == ToneMap::Aces,
        )
        .with(
            ShaderFeatures::TONEMAP_NEUTRAL,
            options.tone_map == ToneMap::Neutral,
        )
        .with(ShaderFeatures::OUTPUT_HDR, options.hdr)
        .with(
            ShaderFeatures::REFERENCE_PRECISION,
            options.measure.reference_precision,
        )
        .with(ShaderFeatures::FP16_LIGHTS, !caps.fragment_has_highp())
        .with(
            ShaderFeatures::COUNT_EVALS,
            matches!(options.count, CountKind::Evals | CountKind::Heatmap),
        )
        .with(
            ShaderFeatures::COUNT_HEATMAP,
            options.count == CountKind::Heatmap,
        )
        .with(
            ShaderFeatures::COUNT_REACHING,
            options.count == CountKind::Reaching,
        )
        .with(
            ShaderFeatures::LIGHTS_RGBA8,
            options.measure.force_rgba8_lights || !caps.float_textures,
        )
        .with(
            ShaderFeatures::UNIFORM_LIGHT_LOOP,
            caps.needs_uniform_light_loop(),
        )
        .with(
            ShaderFeatures::SRGB_TEXTURES,
            crate::gl::texture::hardware_srgb(caps),
        )
}

/// Farthest view depth of the scene's geometry, clipped to `[near, far]` (never below a little
/// past the near plane): where a cluster grid should end. Lights beyond it still reach the
/// last slice, which extends to infinity.
pub(super) fn content_far(bounds: Option<Aabb>, view: &DMat4, near: f64, far: f64) -> f64 {
    // View space looks down −Z: the deepest point has the smallest z.
    let deepest = bounds.map_or(far, |b| -b.transformed(view).min.z);
    let floor = if near > 0.0 { near * 2.0 } else { 1e-3 };
    let d = deepest.min(far).max(floor);
    if d.is_finite() {
        d
    } else {
        floor.max(1.0)
    }
}

#[cfg(test)]
mod tests {
    /// A frame of more lights than any machine can hold memory for is refused naming the
    /// count; a few are not asked twice about.
    #[test]
    fn a_frames_lights_are_asked_of_the_allocator() {
        assert!(super::check_light_memory(1_000).is_ok());
        let err = super::check_light_memory(usize::MAX / 512)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(&format!("{} lights need about", usize::MAX / 512)),
            "{err}"
        );
    }
}
