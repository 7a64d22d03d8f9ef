//! Without fragment `highp` a light's radiance is uploaded divided by `k²`, `k` taken from its
//! brightest channel, so that it fits fp16 (`cluster::pack::fp16_radiance`): a channel more
//! than 2¹⁴ below the brightest then falls under fp16's smallest normal and is lost (flushed
//! to zero, or a few bits left). Said once a process, naming the light: a warning each frame
//! would flood a game's log.

use std::sync::atomic::{AtomicBool, Ordering};

use glam::Vec3;

use crate::cluster::pack::{fp16_radiance, FP16_MAX_RADIANCE};
use crate::gl::Caps;
use crate::methods::features::FP16_MAX_AMBIENT;
use crate::scene::Scene;

/// fp16's smallest normal number, 2⁻¹⁴.
const FP16_MIN_NORMAL: f32 = 1.0 / 16384.0;

/// A channel worth less than this at full strength would not show in 8 bits anyway.
const VISIBLE: f32 = 1.0 / 255.0;

/// Whether a light losing channels was said (once a process).
static WARNED: AtomicBool = AtomicBool::new(false);

/// Which channels of `radiance` (red, green, blue) would show but its fp16 form loses.
fn lost_channels(radiance: Vec3) -> [bool; 3] {
    // Up to 16, k² ≤ 16 and a channel of 1/255 keeps 1/255 / 16 > 2⁻¹⁴: the cheap test that
    // spares most lights the scaling, every frame on these devices.
    if radiance.max_element() <= 16.0 {
        return [false; 3];
    }
    let (scaled, _) = fp16_radiance(radiance);
    [0, 1, 2].map(|c| radiance[c] >= VISIBLE && scaled[c] < FP16_MIN_NORMAL)
}

/// Every active light's name and radiance, point, spot or directional.
fn radiances(scene: &Scene) -> impl Iterator<Item = ((&'static str, usize), Vec3)> + '_ {
    let points = (scene.lights.iter().enumerate())
        .filter(|(_, l)| l.is_active())
        .map(|(i, l)| (("lights", i), l.color * l.intensity));
    let suns = (scene.directional_lights.iter().enumerate())
        .filter(|(_, l)| l.is_active())
        .map(|(i, l)| (("directional_lights", i), l.radiance()));
    points.chain(suns)
}

/// Without fragment `highp`: warns (once, `warned`) of the first light whose colour ×
/// intensity, times the frame's `pre_exposure`, is past [`FP16_MAX_RADIANCE`] (2³⁰), which
/// its fp16 form takes as 2³⁰. Allocates nothing unless it warns.
pub(super) fn warn_of_capped_radiance(
    caps: &Caps,
    scene: &Scene,
    pre_exposure: f32,
    warned: &mut bool,
) {
    if caps.fragment_has_highp() || *warned {
        return;
    }
    let past = |(_, r): &(_, Vec3)| r.max_element() * pre_exposure > FP16_MAX_RADIANCE;
    let Some(((list, i), radiance)) = radiances(scene).find(past) else {
        return;
    };
    *warned = true;
    // Pre-exposed, the cap is 2³⁰ of what is shown.
    let stops = pre_exposure.log2();
    let most = match stops == 0.0 {
        true => "2³⁰".to_string(),
        false => format!("2^{}", 30.0 - stops),
    };
    log::warn!(
        "{list}[{i}]: colour × intensity {radiance:?} is past {most}, the brightest radiance a \
         light has without fragment highp (fp16) at this exposure: it is drawn as {most}, its \
         channels scaled alike"
    );
}

/// Without fragment `highp`: warns (once, `warned`) when the ambient or its term (ambient ×
/// the largest diffuse factor of a material; textures and vertex colours only darken) passes
/// [`FP16_MAX_AMBIENT`] times the frame's `pre_exposure`, where it is drawn at that cap.
pub(super) fn warn_of_capped_ambient(
    caps: &Caps,
    scene: &Scene,
    pre_exposure: f32,
    warned: &mut bool,
) {
    if caps.fragment_has_highp() || *warned {
        return;
    }
    let albedo = (scene.materials.iter())
        .map(|m| m.diffuse.max_element())
        .fold(1.0, f32::max);
    let peak = scene.ambient.max_element() * albedo;
    let most = FP16_MAX_AMBIENT / pre_exposure;
    if peak <= most {
        return;
    }
    *warned = true;
    log::warn!(
        "ambient {:?} times a diffuse factor of up to {albedo} reaches {peak:e}, past the \
         {most} the ambient term holds without fragment highp at this exposure (fp16: \
         {FP16_MAX_AMBIENT} of what is shown): the ambient is drawn at most {most} (its channels \
         scaled alike), and so is each channel of its term",
        scene.ambient
    );
}

/// Without fragment `highp`: warns (once) of the first light, point, spot or directional,
/// whose colour × intensity (times the frame's `pre_exposure`, as it is drawn) spans more
/// than its fp16 form keeps. Allocates nothing unless it warns.
pub(super) fn warn_of_lost_channels(caps: &Caps, scene: &Scene, pre_exposure: f32) {
    if caps.fragment_has_highp() || WARNED.load(Ordering::Relaxed) {
        return;
    }
    let lossy = |(_, r): &(_, Vec3)| lost_channels(*r * pre_exposure).contains(&true);
    let Some(((list, i), radiance)) = radiances(scene).find(lossy) else {
        return;
    };
    WARNED.store(true, Ordering::Relaxed);
    let lost: Vec<&str> = (["red", "green", "blue"].into_iter())
        .zip(lost_channels(radiance * pre_exposure))
        .filter_map(|(name, lost)| lost.then_some(name))
        .collect();
    log::warn!(
        "{list}[{i}]: colour × intensity {radiance:?} spans more than fp16 keeps: without \
         fragment highp a light's radiance is scaled by its brightest channel, and channels \
         more than 2¹⁴ below it are lost, so this light shows without its {} (keep a light's \
         channels within 2¹⁴ of each other)",
        lost.join(" and ")
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_channels_that_would_show_and_fall_below_fp16_are_lost() {
        // The review's light: red 10⁶ scales green and blue (0.5) to 5·10⁻⁷.
        assert_eq!(lost_channels(Vec3::new(1e6, 0.5, 0.5)), [false, true, true]);
        // Within 2¹⁴ of the brightest: kept.
        assert_eq!(lost_channels(Vec3::new(1e4, 1.0, 1.0)), [false; 3]);
        // Too dim to show at full strength anyway, or zero: nothing lost that would show.
        assert_eq!(lost_channels(Vec3::new(1e6, 1e-3, 0.0)), [false; 3]);
        assert_eq!(lost_channels(Vec3::new(0.5, 0.5, 0.5)), [false; 3]);
    }
}
