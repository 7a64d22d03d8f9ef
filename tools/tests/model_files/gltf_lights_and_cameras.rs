//! glTF lights (`KHR_lights_punctual`) and cameras, on files the tests write: point and spot
//! lights with their positions, directions, radii and cones, and suns; a glTF object in a JSON
//! scene file bringing its lights and camera placed by its transform; perspective and
//! orthographic cameras; a file lit only by a sun rendered against the f64 model; a spot cone
//! wider than the spec allows.

use crate::common;

use common::files::{load, write};
use common::gltf::Builder;
use common::gltf_models::{floor, lights_document, primitive, quat, triangle};
use common::Gpu;
use glam::{DMat4, DQuat, DVec3, Vec3};
use manylight::scene::{self, LightKind};
use manylight::{EsVersion, RenderOptions};
use serde_json::{json, Value};

#[test]
fn point_and_spot_lights_come_with_positions_directions_radii_and_cones() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let doc = lights_document(&mut b);
    let path = write(dir.path(), "lights.gltf", b.gltf(doc));
    let (scene, report) = load(&path).unwrap();
    assert_eq!(scene.lights.len(), 3);
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    // The directional light: the node's −Z, lux on the candela's scale.
    assert_eq!(scene.directional_lights.len(), 1);
    let sun = &scene.directional_lights[0];
    assert_eq!(sun.direction, DVec3::NEG_Z);
    assert_eq!(sun.color, Vec3::ONE);
    assert_eq!(
        f64::from(sun.intensity),
        100.0 * scene::gltf::LUX_TO_INTENSITY
    );
    let point = &scene.lights[0];
    assert_eq!(point.kind, LightKind::Point);
    assert_eq!(point.position, DVec3::new(1.0, 2.0, 3.0));
    assert_eq!(point.radius, 7.0);
    assert_eq!(point.color, Vec3::new(1.0, 0.5, 0.25));
    assert_eq!(
        f64::from(point.intensity),
        3.0 * scene::gltf::CANDELA_TO_INTENSITY
    );
    // One photometric scale: 2 048 cd is intensity 1.
    assert_eq!(scene.lights[1].intensity, 1.0);
    // No range: where 1 / (d² + 1) falls to the cut-off; scale does not change it.
    let unbounded = &scene.lights[1];
    let want = (1.0 / scene::gltf::UNBOUNDED_CUTOFF - 1.0).sqrt();
    assert!(
        (f64::from(unbounded.radius) - want).abs() < 1e-4,
        "{}",
        unbounded.radius
    );
    assert!((unbounded.radius - 31.98).abs() < 0.01);
    let spot = &scene.lights[2];
    assert_eq!(spot.position, DVec3::new(0.0, 4.0, 0.0));
    assert_eq!(spot.radius, 9.0);
    let LightKind::Spot {
        direction,
        inner_deg,
        outer_deg,
    } = spot.kind
    else {
        panic!("not a spot: {spot:?}");
    };
    assert!((direction - DVec3::NEG_Y).length() < 1e-9, "{direction}");
    assert!(
        (inner_deg - 0.25f32.to_degrees() as f64).abs() < 1e-4,
        "{inner_deg}"
    );
    assert!((outer_deg - 28.6479).abs() < 1e-3, "{outer_deg}");
}

/// A light without a `range` whose brightest channel is at most the cut-off (2 cd on the
/// photometric scale) would light nothing anywhere: left out with a warning naming it, not
/// kept silently with a radius of 0 (the file would then count as lit). With a `range`, or a
/// little brighter, it is kept; a light of intensity 0 is the file's own choice, kept silently.
#[test]
fn a_light_too_dim_to_reach_anywhere_without_a_range_is_left_out_and_named() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let mut doc = lights_document(&mut b);
    let cut_cd = scene::gltf::UNBOUNDED_CUTOFF / scene::gltf::CANDELA_TO_INTENSITY;
    doc["extensions"]["KHR_lights_punctual"]["lights"] = json!([
        {"type": "point", "intensity": 1.0},
        {"type": "point", "intensity": 1.0, "range": 5},
        {"type": "point", "intensity": cut_cd * 1.01},
        {"type": "spot", "intensity": 4.0, "color": [0.5, 0.2, 0.1], "spot": {}},
        {"type": "point", "intensity": 0.0}
    ]);
    let lights: Vec<Value> = (0..5)
        .map(|i| json!({"translation": [0, i, 0], "extensions": {"KHR_lights_punctual": {"light": i}}}))
        .collect();
    let mut nodes = lights;
    nodes.push(json!({"mesh": 0}));
    doc["nodes"] = json!(nodes);
    doc["scenes"] = json!([{"nodes": [0, 1, 2, 3, 4, 5]}]);
    let path = write(dir.path(), "dim.gltf", b.gltf(doc));
    let (scene, report) = load(&path).unwrap();
    let heights: Vec<f64> = scene.lights.iter().map(|l| l.position.y).collect();
    assert_eq!(heights, [1.0, 2.0, 4.0], "{:?}", scene.lights);
    assert!(scene.lights[1].radius > 0.0);
    let dim: Vec<&String> = report
        .warnings
        .iter()
        .filter(|w| w.contains("left out"))
        .collect();
    // Both in one warning, the first named, the other counted.
    assert_eq!(dim.len(), 1, "{:?}", report.warnings);
    assert!(
        dim[0].contains("lights[0]") && dim[0].contains("at most the 2 cd"),
        "{}",
        dim[0]
    );
    assert!(dim[0].ends_with("(and 1 more like it)"), "{}", dim[0]);
}

#[test]
fn a_gltf_object_in_a_json_scene_brings_its_lights_and_camera_placed_by_its_transform() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let mut doc = lights_document(&mut b);
    doc["cameras"] = json!([{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}]);
    doc["nodes"][4]["camera"] = json!(0);
    doc["nodes"][4]["translation"] = json!([0, 0, 5]);
    write(dir.path(), "lamps.gltf", b.gltf(doc));
    let json_path = write(
        dir.path(),
        "scene.json",
        r#"{"objects": [{"gltf": "lamps.gltf",
             "transform": {"translate": [10, 0, 0], "rotate_y_deg": 90}}],
            "lights": [{"kind": "point", "position": [0, 0, 0], "radius": 1, "color": [1, 1, 1]}]}"#,
    );
    let (scene, _) = scene::load(json_path.to_str().unwrap(), None).unwrap();
    assert_eq!(
        scene.lights.len(),
        4,
        "one from the JSON, three from the glTF"
    );
    // The file's own lights first, at their indices in the file.
    assert_eq!(scene.lights[0].position, DVec3::ZERO);
    let place = DMat4::from_translation(DVec3::new(10.0, 0.0, 0.0))
        * DMat4::from_rotation_y(90f64.to_radians());
    let want = place.transform_point3(DVec3::new(1.0, 2.0, 3.0));
    assert!((scene.lights[1].position - want).length() < 1e-9);
    assert!((scene.lights[1].position - DVec3::new(13.0, 2.0, -1.0)).length() < 1e-9);
    assert_eq!(scene.lights[1].radius, 7.0, "radius not scaled");
    // An error about the file's light names it as the file does (it named lights[3], the
    // index behind the glTF's three).
    let far = write(
        dir.path(),
        "far.json",
        r#"{"objects": [{"gltf": "lamps.gltf"}],
            "lights": [{"kind": "point", "position": [9.999999995e17, 0, 0], "radius": 1,
                        "color": [1, 1, 1],
                        "motion": {"bob": {"amplitude": [1e9, 0, 0], "period_s": 1}}}]}"#,
    );
    let err = scene::load(far.to_str().unwrap(), None)
        .unwrap_err()
        .to_string();
    assert!(err.contains("`lights[0].motion`"), "{err}");
    // The sun turned with the object: the quarter turn about +Y takes −Z to −X.
    let sun = scene.directional_lights[0].direction;
    assert!((sun - DVec3::NEG_X).length() < 1e-9, "{sun}");
    // The camera: the only object's own, placed too, looking down the turned −Z (−X).
    let cam = scene.camera;
    assert!((cam.position - place.transform_point3(DVec3::new(0.0, 0.0, 5.0))).length() < 1e-9);
    let forward = (cam.target - cam.position).normalize();
    assert!((forward - DVec3::NEG_X).length() < 1e-9, "{forward}");
    // Both `obj` and `gltf` on one object is an error naming it.
    let both = write(
        dir.path(),
        "both.json",
        r#"{"objects": [{"gltf": "lamps.gltf", "obj": "x.obj"}]}"#,
    );
    let err = scene::load(both.to_str().unwrap(), None)
        .unwrap_err()
        .to_string();
    assert!(err.contains("objects[0]") && err.contains("gltf"), "{err}");
}

#[test]
fn cameras_perspective_with_infinite_far_and_orthographic() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let p = b.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3");
    let turn = DQuat::from_rotation_y(std::f64::consts::FRAC_PI_2);
    let doc = |camera: Value| {
        json!({
            "scenes": [{"nodes": [0, 1, 2]}],
            "cameras": [camera, {"type": "perspective", "perspective": {"yfov": 1.5, "znear": 1}}],
            "nodes": [
                {"mesh": 0},
                // A parent moves the camera's node; a second camera later is not used.
                {"translation": [0, 1, 0], "children": [3]},
                {"camera": 1},
                {"camera": 0, "translation": [4, 0, 0], "rotation": quat(turn), "scale": [3, 3, 3]}
            ],
            "meshes": [{"primitives": [{"attributes": {"POSITION": p}}]}],
        })
    };
    let persp = doc(json!({"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.05}}));
    let path = write(dir.path(), "persp.gltf", b.gltf(persp));
    let (scene, _) = load(&path).unwrap();
    let cam = scene.camera;
    assert_eq!(cam.position, DVec3::new(4.0, 1.0, 0.0));
    let forward = (cam.target - cam.position).normalize();
    assert!(
        (forward - DVec3::NEG_X).length() < 1e-12,
        "−Z turned a quarter about Y: {forward}"
    );
    assert!((cam.up - DVec3::Y).length() < 1e-12);
    match cam.projection {
        scene::Projection::Perspective {
            fov_y_deg,
            near,
            far,
        } => {
            assert!((fov_y_deg - 0.7f32.to_degrees() as f64).abs() < 1e-4);
            assert_eq!(near, 0.05f32 as f64);
            assert!(far.is_infinite(), "no zfar: an infinite far plane");
        }
        p => panic!("{p:?}"),
    }
    let ortho = doc(json!({"type": "orthographic",
        "orthographic": {"xmag": 3, "ymag": 2, "znear": 0.5, "zfar": 40}}));
    let path = write(dir.path(), "ortho.gltf", b.gltf(ortho));
    let (scene, _) = load(&path).unwrap();
    assert_eq!(
        scene.camera.projection,
        scene::Projection::Orthographic {
            height: 4.0,
            near: 0.5,
            far: 40.0
        }
    );
    // Values the renderer cannot take are named as the file writes them (radians, `ymag`),
    // in a warning: the model is drawn, framed on its bounds.
    for (camera, named) in [
        (
            json!({"type": "perspective", "perspective": {"yfov": 3.2, "znear": 0.1}}),
            "`cameras[0].perspective.yfov` must be in",
        ),
        (
            json!({"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1, "zfar": 0.05}}),
            "`cameras[0].perspective.zfar` must be finite and > znear",
        ),
        (
            json!({"type": "orthographic",
                "orthographic": {"xmag": 1, "ymag": 1e-9, "znear": 0, "zfar": 4}}),
            "`cameras[0].orthographic.ymag` must be finite",
        ),
        (
            json!({"type": "orthographic",
                "orthographic": {"xmag": 1, "ymag": 1, "znear": 2, "zfar": 1}}),
            "`cameras[0].orthographic.zfar`",
        ),
        // The file's 1e-300 is f32's 0: the message says why it reads 0.
        (
            json!({"type": "perspective", "perspective": {"yfov": 0.7, "znear": 1e-300}}),
            "`cameras[0].perspective.znear` must be finite and > 0, got 0.0 (read as f32: \
             magnitudes below 1e-45 read as 0)",
        ),
    ] {
        let path = write(dir.path(), "bad.gltf", b.gltf(doc(camera)));
        let (mut scene, report) = load(&path).unwrap();
        let said = report.warnings.join("\n");
        assert!(said.contains(named), "{named}: {said}");
        assert!(said.contains("this camera is not used"), "{said}");
        // A value is written short: `{}` wrote ymag 1e-9 as 0.000000001.
        assert!(!said.contains("00000000"), "{said}");
        assert!(
            !said.contains("camera.fov_y_deg") && !said.contains("camera.far"),
            "{said}"
        );
        let camera = scene.camera;
        scene.frame_camera();
        assert_eq!(camera, scene.camera, "{named}: framed");
    }
    // No camera: framed on the bounds as for OBJ.
    let mut none = doc(json!({"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.05}}));
    none["nodes"] = json!([{"mesh": 0}]);
    none["scenes"] = json!([{"nodes": [0]}]);
    none.as_object_mut().unwrap().remove("cameras");
    let path = write(dir.path(), "framed.gltf", b.gltf(none));
    let (mut scene, _) = load(&path).unwrap();
    let camera = scene.camera;
    scene.frame_camera();
    assert_eq!(camera, scene.camera);
}

#[test]
fn a_file_lit_only_by_a_sun_is_lit_as_the_model_says() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let floor_prim = primitive(&mut b, &floor(), Some(0));
    // The sun's node aimed down and forward: −Z turned 50° about +X.
    let sun_turn = DQuat::from_rotation_x(-50f64.to_radians());
    let cam_turn = DQuat::from_rotation_x(-20f64.to_radians());
    let gltf = json!({
        "extensionsUsed": ["KHR_lights_punctual"],
        // 2 048 lux: intensity 1 on the photometric scale (docs/gltf.md).
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "directional", "color": [1, 0.9, 0.8], "intensity": 2048}
        ]}},
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [
            {"mesh": 0},
            {"translation": [0, 5, 0], "rotation": quat(sun_turn),
             "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"camera": 0, "translation": [0, 2, 5], "rotation": quat(cam_turn)}
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.05, "zfar": 50}}],
        "meshes": [{"primitives": [floor_prim]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1]}}],
    });
    let path = write(dir.path(), "sunny.gltf", b.gltf(gltf));
    let (scene, report) = load(&path).unwrap();
    assert!(report.warnings.is_empty(), "{:?}", report.warnings);
    assert!(scene.lights.is_empty());
    let sun = scene.directional_lights[0];
    assert!((sun.direction - sun_turn * DVec3::NEG_Z).length() < 1e-9);
    assert_eq!(sun.intensity, 1.0);
    let mut gpu = Gpu::new(EsVersion::Es3);
    let img = gpu.render(&scene, 96, 54, &RenderOptions::default());
    let caps = gpu.r().caps().clone();
    let encoding = manylight::metrics::cpu_reference::Encoding::Srgb;
    let (err, at, n) = common::max_oracle_error(&img, &scene, encoding, &caps);
    assert!(
        n > 96 * 54 / 8 && err <= 2.0,
        "{err:.2}/255 at {at:?} over {n}"
    );
    // Neither black nor white: the floor at 0.8 × cos 40° of the sun (sRGB 207).
    let lit: Vec<u8> = img
        .pixels()
        .map(|p| p[0].max(p[1]).max(p[2]))
        .filter(|&v| v > 40)
        .collect();
    assert!(lit.len() > 96 * 54 / 8, "only {} lit pixels", lit.len());
    let peak = lit.iter().max().copied().unwrap_or(0);
    assert!((150..=240).contains(&peak), "brightest {peak}/255");
}

#[test]
fn a_spot_cone_wider_than_the_spec_allows_is_drawn_as_given_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let spot = json!({"type": "spot", "intensity": 100, "spot": {"outerConeAngle": 2.0}});
    let path = write(dir.path(), "wide.gltf", triangle_lit_by(spot));
    let (scene, report) = load(&path).unwrap();
    assert_eq!(scene.lights.len(), 1, "drawn");
    assert!(
        report
            .warnings
            .iter()
            .any(|w| w.contains("lights[0]") && w.contains("spot.outerConeAngle (2) is past π/2")),
        "{:?}",
        report.warnings
    );
    // Past π it is no cone: refused in the file's terms, not as the converted degrees.
    let spot = json!({"type": "spot", "intensity": 100, "spot": {"outerConeAngle": 10.0}});
    let path = write(dir.path(), "past_pi.gltf", triangle_lit_by(spot));
    let err = load(&path).unwrap_err().to_string();
    assert!(
        err.contains("spot.outerConeAngle (10.0) must be within [0, π] radians"),
        "{err}"
    );
    // π itself is a cone (a half-angle of π lights every direction): f32's π, 180.000005°,
    // was refused as `outer_deg`.
    let pi = std::f64::consts::PI;
    let spot = json!({"type": "spot", "intensity": 100,
        "spot": {"innerConeAngle": pi, "outerConeAngle": pi}});
    let path = write(dir.path(), "pi.gltf", triangle_lit_by(spot));
    let (scene, _) = load(&path).unwrap();
    match scene.lights[0].kind {
        manylight::scene::LightKind::Spot {
            inner_deg,
            outer_deg,
            ..
        } => assert_eq!((inner_deg, outer_deg), (180.0, 180.0)),
        ref other => panic!("not a spot: {other:?}"),
    }
}

#[test]
fn light_values_past_f32_are_errors_naming_the_field_and_the_range() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            json!({"type": "point", "intensity": 1e39}),
            "intensity",
            true,
        ),
        (
            json!({"type": "point", "color": [1, 1e39, 1]}),
            "color",
            true,
        ),
        (json!({"type": "point", "range": 1e39}), "range", true),
        (
            json!({"type": "point", "intensity": -1}),
            "intensity",
            false,
        ),
        (
            json!({"type": "point", "intensity": -3.4e38}),
            "intensity",
            false,
        ),
        (json!({"type": "point", "range": -3.4e38}), "range", false),
    ];
    for (i, (light, field, past_f32)) in cases.into_iter().enumerate() {
        let path = write(
            dir.path(),
            &format!("light{i}.gltf"),
            triangle_lit_by(light),
        );
        let err = load(&path).unwrap_err().to_string();
        assert!(
            err.contains(&format!("lights[0]): {field} must be")),
            "{field}: {err}"
        );
        assert_eq!(err.contains("past f32's range"), past_f32, "{err}");
        // A value is written short: `{}` wrote -3.4e38 in 39 digits.
        assert!(!err.contains("00000000"), "{err}");
    }
}

/// A glTF file: a triangle and `light` (a `KHR_lights_punctual` light) on a node one
/// unit above it.
fn triangle_lit_by(light: Value) -> String {
    let mut b = Builder::default();
    let mut doc = triangle(&mut b);
    doc["nodes"] = json!([
        {"mesh": 0},
        {"translation": [0, 0, 1], "extensions": {"KHR_lights_punctual": {"light": 0}}}
    ]);
    doc["scenes"] = json!([{"nodes": [0, 1]}]);
    doc["extensionsUsed"] = json!(["KHR_lights_punctual"]);
    doc["extensions"] = json!({"KHR_lights_punctual": {"lights": [light]}});
    b.gltf(doc)
}

/// A file whose only lights are suns, with no camera, placed from a scene file twice: each
/// placement brings its sun, turned with it (such a file was once cached as a light-free
/// model, and the scene came out black without a warning).
#[test]
fn a_sun_only_gltf_placed_from_a_scene_file_brings_its_sun_each_time() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let floor_prim = primitive(&mut b, &floor(), Some(0));
    let gltf = json!({
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "directional", "color": [1, 1, 1], "intensity": 2048}
        ]}},
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [
            {"mesh": 0},
            {"extensions": {"KHR_lights_punctual": {"light": 0}}}
        ],
        "meshes": [{"primitives": [floor_prim]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1]}}],
    });
    write(dir.path(), "sun.gltf", b.gltf(gltf));
    let json_path = write(
        dir.path(),
        "scene.json",
        r#"{"objects": [{"gltf": "sun.gltf"},
                        {"gltf": "sun.gltf", "transform": {"rotate_y_deg": 90}}]}"#,
    );
    let (scene, _) = scene::load(json_path.to_str().unwrap(), None).unwrap();
    let suns: Vec<DVec3> = scene
        .directional_lights
        .iter()
        .map(|s| s.direction)
        .collect();
    assert_eq!(suns.len(), 2, "one sun a placement: {suns:?}");
    assert!((suns[0] - DVec3::NEG_Z).length() < 1e-9, "{suns:?}");
    assert!((suns[1] - DVec3::NEG_X).length() < 1e-9, "{suns:?}");
}

/// A scene file in `dir` placing `objects` (JSON), beside `lamp.gltf`: a triangle lit by a
/// point light whose file uses the unsupported `extension` (a warning).
fn scene_with_lamp(dir: &std::path::Path, extension: &str, objects: &str) -> std::path::PathBuf {
    let light = json!({"type": "point", "intensity": 100});
    let mut doc: Value = serde_json::from_str(&triangle_lit_by(light)).unwrap();
    doc["extensionsUsed"] = json!(["KHR_lights_punctual", extension]);
    write(dir, "lamp.gltf", doc.to_string());
    write(dir, "scene.json", format!(r#"{{"objects": {objects}}}"#))
}

/// A glTF with lights placed twice in a scene file (its lights move with it) says its
/// warnings once, in the report and in the log (when it was read again for each placement,
/// they were logged three times for two placements).
#[test]
fn a_gltf_with_lights_placed_twice_warns_once() {
    let dir = tempfile::tempdir().unwrap();
    let twice =
        r#"[{"gltf": "lamp.gltf"}, {"gltf": "lamp.gltf", "transform": {"translate": [3, 0, 0]}}]"#;
    let json_path = scene_with_lamp(dir.path(), "EXT_not_a_real_one", twice);
    let unsupported = "extension EXT_not_a_real_one is not supported";
    let logged_before = common::warnings::warnings_containing(unsupported).len();
    let (scene, report) = scene::load(json_path.to_str().unwrap(), None).unwrap();
    assert_eq!(scene.lights.len(), 2, "one lamp a placement");
    let said: Vec<_> = report
        .warnings
        .iter()
        .filter(|w| w.contains(unsupported))
        .collect();
    assert_eq!(said.len(), 1, "{:?}", report.warnings);
    let logged = common::warnings::warnings_containing(unsupported).len();
    assert_eq!(logged - logged_before, 1, "logged once");
}

/// Warnings said before a load fails are still logged: they may explain the error.
#[test]
fn warnings_before_a_failed_load_are_logged() {
    common::warnings::install();
    let dir = tempfile::tempdir().unwrap();
    let then_missing = r#"[{"gltf": "lamp.gltf"}, {"gltf": "missing.gltf"}]"#;
    let json_path = scene_with_lamp(dir.path(), "EXT_said_before_failing", then_missing);
    let said = "extension EXT_said_before_failing is not supported";
    assert!(scene::load(json_path.to_str().unwrap(), None).is_err());
    assert_eq!(common::warnings::warnings_containing(said).len(), 1);
}
