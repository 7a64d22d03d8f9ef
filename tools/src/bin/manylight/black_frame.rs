//! A picture that came out black is said, with what can make it so, rather than written in
//! silence: the camera looking away from the geometry or past it, nothing lighting it, every
//! surface cut out or fully transparent, an exposure below 0 EV.

use manylight::scene::Scene;

/// The warning for `image`, drawn at `exposure_ev` stops, when every pixel of it is black;
/// `None` otherwise.
pub fn warning(image: &image::RgbaImage, scene: &Scene, exposure_ev: f32) -> Option<String> {
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
    // A spot of a closed cone lights a sliver (its edge fades over 10⁻⁴ of `1 − cos`).
    let narrow = |l: &manylight::Light| matches!(l.kind, manylight::LightKind::Spot { outer_deg, .. } if outer_deg < 1.0);
    let lit = scene.lights.iter().filter(|l| shines(l.color, l.intensity));
    let suns = scene.directional_lights.iter();
    if !unlit
        && lit.clone().next().is_some()
        && lit.clone().all(narrow)
        && !suns.clone().any(|l| shines(l.color, l.intensity))
        && scene.ambient == glam::Vec3::ZERO
    {
        causes.push("every light is a spot whose cone (outer_deg) is under 1°".to_string());
    }
    if exposure_ev < 0.0 {
        causes.push(format!(
            "the exposure of {exposure_ev} EV (`--exposure`) scales every pixel by {:.1e}",
            f64::from(exposure_ev).exp2()
        ));
    }
    let camera = &scene.camera;
    let (near, far) = camera.near_far();
    let where_ = format!(
        "the camera (at {:?} looking at {:?}, near {near:?}, far {far:?}) ",
        camera.position.to_array(),
        camera.target.to_array(),
    );
    let (min, max) = (bounds.min.to_array(), bounds.max.to_array());
    let aspect = f64::from(image.width().max(1)) / f64::from(image.height().max(1));
    if !box_may_be_in_view(camera, &bounds, aspect) {
        // Nothing else matters: no object can be in view.
        return Some(format!(
            "the picture is black: {where_}looks away from all the geometry (from {min:?} to \
             {max:?})"
        ));
    }
    causes.push(format!(
        "{where_}sees only the space between the objects (their bounds, from {min:?} to \
         {max:?}, reach into its view)"
    ));
    causes.push("every surface in view is fully transparent, cut out or black".into());
    causes.push(
        "the GL implementation drew nothing (try `--method forward`, or another one with \
         `--gles-lib`)"
            .into(),
    );
    Some(format!(
        "the picture is black; it may be that {}",
        causes.join(", or ")
    ))
}

/// Whether a world-space box may lie in the camera's view at `aspect`: false only where all
/// eight corners lie beyond one of the view's six planes (clip space, in f64).
fn box_may_be_in_view(
    camera: &manylight::scene::Camera,
    bounds: &manylight::scene::Aabb,
    aspect: f64,
) -> bool {
    let clip = camera.projection_matrix(aspect) * camera.view_matrix();
    let corners = bounds.corners().map(|c| clip * c.extend(1.0));
    let outside = |beyond: &dyn Fn(&glam::DVec4) -> bool| corners.iter().all(beyond);
    !(outside(&|c| c.x < -c.w)
        || outside(&|c| c.x > c.w)
        || outside(&|c| c.y < -c.w)
        || outside(&|c| c.y > c.w)
        || outside(&|c| c.z < -c.w)
        || outside(&|c| c.z > c.w))
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
        let text = warning(&image, &scene, 0.0).expect("black");
        assert!(
            text.contains("nothing lights it") && text.contains("camera"),
            "{text}"
        );
        // A light of intensity 0 is no light.
        let mut dark = manylight::Light::point(glam::DVec3::Z, 3.0, glam::Vec3::ONE, 0.0);
        scene.lights.push(dark);
        let text = warning(&image, &scene, 0.0).expect("black");
        assert!(text.contains("nothing lights it"), "{text}");
        dark.intensity = 1.0;
        scene.lights = vec![dark];
        let text = warning(&image, &scene, 0.0).expect("black");
        assert!(!text.contains("nothing lights it"), "{text}");
        scene.lights.clear();
        scene.ambient = glam::Vec3::splat(0.1);
        let text = warning(&image, &scene, 0.0).expect("black");
        assert!(!text.contains("nothing lights it"), "{text}");
        // Spots of closed cones alone (a cone of 0° was blamed on the camera alone).
        scene.ambient = glam::Vec3::ZERO;
        let cone = |outer_deg| manylight::Cone {
            direction: -glam::DVec3::Z,
            inner_deg: 0.0,
            outer_deg,
        };
        let spot = |outer_deg| {
            manylight::Light::spot(glam::DVec3::Z, 3.0, glam::Vec3::ONE, 1.0, cone(outer_deg))
        };
        scene.lights = vec![spot(0.0), spot(0.5)];
        let text = warning(&image, &scene, 0.0).expect("black");
        assert!(text.contains("cone (outer_deg) is under 1°"), "{text}");
        scene.lights.push(spot(30.0));
        let text = warning(&image, &scene, 0.0).expect("black");
        assert!(!text.contains("outer_deg"), "{text}");
        // An exposure below 0 EV is one of the causes (it was left out, and the camera blamed).
        let text = warning(&image, &scene, -15.0).expect("black");
        assert!(
            text.contains("exposure of -15 EV") && text.contains("3.1e-5"),
            "{text}"
        );
        image.put_pixel(3, 1, image::Rgba([0, 0, 1, 255]));
        assert_eq!(warning(&image, &scene, 0.0), None);
    }

    /// The camera is named the cause, alone, only where no object can be in its view; where
    /// the geometry's bounds reach into the view it stays one possible cause among the others.
    #[test]
    fn the_camera_is_blamed_alone_only_where_it_looks_away_from_the_bounds() {
        let mut scene = manylight::builtin_scene("plane", None).unwrap();
        let image = image::RgbaImage::new(16, 9);
        let looking_at = |scene: &Scene| warning(&image, scene, 0.0).expect("black");
        let text = looking_at(&scene);
        assert!(
            text.contains("space between the objects")
                && text.contains("transparent")
                && text.contains("drew nothing"),
            "{text}"
        );
        let bounds = scene.bounds().unwrap();
        // Looking up from above the plane, then along it from far beside it, then with the
        // plane past the far plane: each misses the bounds through another of the view's
        // planes.
        assert_eq!(bounds.size().z, 0.0, "the plane lies across Z");
        let eye = bounds.center() + glam::DVec3::Z;
        let beside = eye + glam::DVec3::X * bounds.size().x * 10.0;
        let views = [
            (eye, eye + glam::DVec3::Z, glam::DVec3::Y),
            (beside, beside + glam::DVec3::Y, glam::DVec3::Z),
        ];
        for (position, target, up) in views {
            scene.camera.position = position;
            scene.camera.target = target;
            scene.camera.up = up;
            let text = looking_at(&scene);
            assert!(
                text.contains("looks away from all the geometry") && !text.contains("transparent"),
                "{position} → {target}: {text}"
            );
        }
        scene.camera.position = bounds.center() + glam::DVec3::Z * 1e4;
        scene.camera.target = bounds.center();
        scene.camera.up = glam::DVec3::Y;
        scene.camera.projection = manylight::scene::Projection::Perspective {
            fov_y_deg: 60.0,
            near: 1.0,
            far: 100.0,
        };
        assert!(looking_at(&scene).contains("looks away"));
        scene.camera.projection = manylight::scene::Projection::Perspective {
            fov_y_deg: 60.0,
            near: 1.0,
            far: 2e4,
        };
        assert!(looking_at(&scene).contains("space between the objects"));
    }
}
