//! A picture that came out black is said, with what can make it so, rather than written in
//! silence: the camera looking away from the geometry or past it, nothing lighting it, every
//! surface cut out or fully transparent.

use manylight::scene::Scene;

/// The warning for `image` when every pixel of it is black; `None` otherwise.
pub fn warning(image: &image::RgbaImage, scene: &Scene) -> Option<String> {
    if image.pixels().any(|p| p[0] | p[1] | p[2] != 0) {
        return None;
    }
    let Some(bounds) = scene.bounds() else {
        return Some("the picture is black: the scene has no geometry".into());
    };
    let mut causes = Vec::new();
    // A light of intensity or colour 0 lights nothing either.
    let shines = |color: glam::Vec3, intensity: f32| intensity > 0.0 && color.max_element() > 0.0;
    let unlit = !scene.lights.iter().any(|l| shines(l.color, l.intensity))
        && !(scene.directional_lights.iter()).any(|l| shines(l.color, l.intensity))
        && scene.ambient == glam::Vec3::ZERO
        && !scene.materials.iter().any(|m| m.maps.emits());
    if unlit {
        causes.push(
            "nothing lights it (no light brighter than 0, ambient 0, no emissive material)"
                .to_string(),
        );
    }
    let camera = &scene.camera;
    let (near, far) = camera.near_far();
    causes.push(format!(
        "the camera (at {:?} looking at {:?}, near {near:?}, far {far:?}) sees none of the \
         geometry (from {:?} to {:?})",
        camera.position.to_array(),
        camera.target.to_array(),
        bounds.min.to_array(),
        bounds.max.to_array()
    ));
    causes.push("every surface in view is fully transparent, cut out or black".into());
    Some(format!(
        "the picture is black; it may be that {}",
        causes.join(", or ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_black_picture_is_warned_of_and_an_unlit_scene_is_named() {
        let mut scene = manylight::builtin_scene("plane", None).unwrap();
        let mut image = image::RgbaImage::new(4, 2);
        scene.lights.clear();
        scene.directional_lights.clear();
        scene.ambient = glam::Vec3::ZERO;
        let text = warning(&image, &scene).expect("black");
        assert!(
            text.contains("nothing lights it") && text.contains("camera"),
            "{text}"
        );
        // A light of intensity 0 is no light.
        let mut dark = manylight::Light::point(glam::DVec3::Z, 3.0, glam::Vec3::ONE, 0.0);
        scene.lights.push(dark);
        let text = warning(&image, &scene).expect("black");
        assert!(text.contains("nothing lights it"), "{text}");
        dark.intensity = 1.0;
        scene.lights = vec![dark];
        let text = warning(&image, &scene).expect("black");
        assert!(!text.contains("nothing lights it"), "{text}");
        scene.lights.clear();
        scene.ambient = glam::Vec3::splat(0.1);
        let text = warning(&image, &scene).expect("black");
        assert!(!text.contains("nothing lights it"), "{text}");
        image.put_pixel(3, 1, image::Rgba([0, 0, 1, 255]));
        assert_eq!(warning(&image, &scene), None);
    }
}
