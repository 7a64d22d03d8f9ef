//! Scenes that load and draw but would show a dark or empty frame for a reason the user can
//! fix: said at load as warnings, never left silent.

use super::{shading, shown, Object, Scene};
use std::path::Path;

/// A model whose largest extent is at most this many times the distance the shaders leave
/// out around a light ([`shading::LIGHT_MIN_DISTANCE`], 2⁻¹³) is warned of when a light lies
/// at it (within 2⁻¹³ of its bounds): that light leaves more than 1/64 of the model unlit.
/// 2⁻⁷: about 8 mm, in metres.
pub(crate) const TINY_MODEL_EXTENT: f64 = 64.0 * shading::LIGHT_MIN_DISTANCE;

/// The warnings for `scene`, loaded from `path`.
pub(crate) fn warnings(scene: &Scene, path: &Path) -> Vec<String> {
    let shown_path = path.display().to_string();
    let name = shown::text(&shown_path);
    let mut warnings = Vec::new();
    if !scene.objects.is_empty() && scene.objects.iter().all(|o| invisible(scene, o)) {
        warnings.push(format!(
            "{name}: every object is fully transparent (alpha 0: MTL `d 0`, a glTF base colour or \
             COLOR_0 alpha of 0, or a glTF MASK material cut out everywhere): the frame shows \
             the background only"
        ));
    }
    let near = shading::LIGHT_MIN_DISTANCE;
    // Lights that would shine (some radiance) but reach nothing.
    let shining = |l: &&super::Light| l.intensity > 0.0 && l.color.max_element() > 0.0;
    let unlit = (scene.lights.iter().filter(shining))
        .filter(|l| f64::from(l.radius) <= near)
        .count();
    if unlit > 0 {
        warnings.push(format!(
            "{name}: {unlit} of {} lights have a radius of at most 2⁻¹³ ({near:.3e}; 0 \
             included) and light nothing: the shaders leave out what lies that near a light \
             (above fp16's smallest normal, docs/precision.md); give them a radius, or scale \
             the model up (its transform, or the units it was exported in)",
            scene.lights.len()
        ));
    }
    // A tiny model matters where a light that reaches further lies within 2⁻¹³ of it: a light
    // a metre from a 5 mm model leaves out none of it.
    let bounds = scene.bounds();
    let extent = bounds.map_or(0.0, |b| b.size().max_element());
    let at_model = |l: &super::Light| {
        bounds.is_some_and(|b| {
            (l.position - b.min).min_element() >= -near
                && (b.max - l.position).min_element() >= -near
        })
    };
    let reaching = (scene.lights.iter().filter(shining))
        .filter(|l| f64::from(l.radius) > near)
        .any(at_model);
    if reaching && extent > 0.0 && extent <= TINY_MODEL_EXTENT {
        warnings.push(format!(
            "{name}: the model is {extent:.3e} across, and the shaders leave out what lies \
             within 2⁻¹³ ({near:.3e}) of a light (above fp16's smallest normal, \
             docs/precision.md): more than 1/64 of it, so surfaces near a light show unlit; \
             scale the model up (its transform, or the units it was exported in)"
        ));
    }
    warnings
}

/// Whether `object` is drawn fully transparent: its material's alpha is 0, or its vertex
/// colours' alpha is 0 everywhere where the material takes it.
fn invisible(scene: &Scene, object: &Object) -> bool {
    scene.materials.get(object.material).is_some_and(|m| {
        let colors = &object.mesh.colors;
        m.alpha <= 0.0
            || (m.alpha_vertex && !colors.is_empty() && colors.iter().all(|c| c.w <= 0.0))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Light;
    use glam::{DVec3, Vec3};

    fn unlit_said(lights: Vec<Light>) -> bool {
        let scene = Scene {
            lights,
            ..Scene::empty()
        };
        let said = warnings(&scene, Path::new("s.json"));
        said.iter().any(|w| w.contains("light nothing"))
    }

    /// A shining light of radius 0 lights nothing, as one of 10⁻⁵ does: both said (radius 0
    /// was passed over). One that does not shine (intensity or colour 0) is off, not unlit.
    #[test]
    fn shining_lights_that_reach_nothing_are_said_off_ones_are_not() {
        let light = |radius, intensity, color| Light::point(DVec3::ZERO, radius, color, intensity);
        assert!(unlit_said(vec![light(0.0, 2.0, Vec3::ONE)]));
        assert!(unlit_said(vec![light(1e-5, 2.0, Vec3::ONE)]));
        assert!(!unlit_said(vec![light(0.0, 0.0, Vec3::ONE)]));
        assert!(!unlit_said(vec![light(0.0, 2.0, Vec3::ZERO)]));
        assert!(!unlit_said(vec![light(1.0, 2.0, Vec3::ONE)]));
    }

    /// A 5 mm model is said to be too small only where a light that reaches it lies at it.
    #[test]
    fn a_tiny_model_is_said_only_with_a_light_at_it() {
        let tiny_said = |at: DVec3| {
            let mut scene = crate::scene::builtin::build("plane", None).unwrap();
            let b = scene.bounds().unwrap();
            // Scaled about the origin to 5 mm across.
            let scale = 5e-3 / b.size().max_element();
            for o in &mut scene.objects {
                o.transform = glam::DMat4::from_scale(DVec3::splat(scale)) * o.transform;
            }
            let at = scene.bounds().unwrap().center() + at;
            scene.lights = vec![Light::point(at, 1.0, Vec3::ONE, 2.0)];
            let said = warnings(&scene, Path::new("s.json"));
            said.iter().any(|w| w.contains("the model is"))
        };
        assert!(tiny_said(DVec3::new(0.0, 1e-4, 0.0)));
        assert!(!tiny_said(DVec3::new(0.0, 1.0, 0.0)));
    }
}
