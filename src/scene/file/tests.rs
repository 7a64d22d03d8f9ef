//! Scene-file parsing and validation: each field's errors and what a valid file builds.

use super::*;
use glam::{DVec3, Vec3};

fn parse_str(s: &str) -> Result<Scene, SceneError> {
    parse(
        s,
        Path::new("."),
        Path::new("test.json"),
        None,
        &LoadOptions::default(),
    )
    .map(|(s, _)| s)
}

#[test]
fn json_errors_name_the_field_and_too_many_values_say_so() {
    let err = parse_str(
        r#"{"objects": [{"builtin": "plane"}],
            "lights": [{"kind": "spot", "position": [0, 0, 1], "radius": 2,
                        "color": [1, 1, 1], "direction": [0, 0, -1, 0, 0]}]}"#,
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("lights[0].direction: too many values"),
        "{err}"
    );
    let err = parse_str(r#"{"objects": [{"builtin": "plane"}], "ambient": [1, "x", 0]}"#)
        .unwrap_err()
        .to_string();
    assert!(err.contains("ambient"), "{err}");
}

/// A value of the wrong type is named in the file's words, not Rust's: serde wrote `expected
/// struct SceneFile`, `expected struct LightSpec` and `expected usize`.
#[test]
fn wrong_types_are_named_without_rust_type_names() {
    let cases = [
        // An array is not an object, though serde's derive reads one field by field.
        (
            "[1, 2, 3]",
            "invalid type: sequence, expected a scene: a JSON object",
        ),
        ("1", "expected a scene: a JSON object"),
        (
            r#"{"objects": [["plane"]]}"#,
            "objects[0]: invalid type: sequence, expected an object",
        ),
        (
            r#"{"objects": [{"builtin": "plane"}], "camera": [[0, 2, 8], [0, 1, 0]]}"#,
            "camera: invalid type: sequence, expected a camera object",
        ),
        (
            r#"{"objects": [{"builtin": "plane", "transform": [[1, 2, 3]]}]}"#,
            "objects[0].transform: invalid type: sequence, expected a transform object",
        ),
        (
            r#"{"objects": [{"builtin": "plane"}], "lights": [["point", [0, 1, 0], 2, [1, 1, 1]]]}"#,
            "lights[0]: invalid type: sequence, expected a light object",
        ),
        (
            r#"{"objects": [{"builtin": "plane"}], "directional_lights": [[[0, -1, 0], [1, 1, 1]]]}"#,
            "directional_lights[0]: invalid type: sequence, expected a directional light object",
        ),
        (
            r#"{"objects": [{"builtin": "plane"}], "random_lights": [8, 1]}"#,
            "random_lights: invalid type: sequence, expected a random lights object",
        ),
        (
            r#"{"objects": [{"builtin": "plane"}], "random_lights": {"count": 8, "motion": [null]}}"#,
            "random_lights.motion: invalid type: sequence, expected a motion object",
        ),
        (
            r#"{"objects": [{"builtin": "plane"}], "random_lights": {"count": 8, "motion": {"orbit": [[0, 0, 0], 6]}}}"#,
            "random_lights.motion.orbit: invalid type: sequence, expected an orbit object",
        ),
        (
            r#"{"objects": [{"builtin": "plane"}], "lights": [null]}"#,
            "lights[0]: invalid type: null, expected a light object",
        ),
        (
            r#"{"objects": [{"builtin": "plane"}], "random_lights": {"count": -1}}"#,
            "expected a whole number from 0 to 18446744073709551615",
        ),
        (
            r#"{"objects": [{"builtin": "plane"}], "random_lights": {"count": 1, "seed": 1e30}}"#,
            "expected a whole number from 0 to 18446744073709551615",
        ),
        (
            r#"{"objects": [{"builtin": "plane"}], "camera": {"fov_y_deg": "x"}}"#,
            "expected a number",
        ),
        // An untagged enum: serde wrote `data did not match any variant of untagged enum
        // ScaleSpec`.
        (
            r#"{"objects": [{"builtin": "plane", "transform": {"scale": [1, 2]}}]}"#,
            "objects[0].transform.scale: expected a number or three numbers [x, y, z]",
        ),
    ];
    for (json, want) in cases {
        let err = parse_str(json).unwrap_err().to_string();
        assert!(err.contains(want), "{json}: {err}");
        for rust in ["struct ", "usize", "f64", "Spec", "enum"] {
            assert!(!err.contains(rust), "{json}: {err}");
        }
    }
}

/// Random lights past the limit with the file's own: both counts named, not their sum as if it
/// were the file's count.
#[test]
fn random_lights_past_the_limit_name_the_files_own_lights_too() {
    let light = r#"{"kind": "point", "position": [0, 1, 1], "radius": 4, "color": [1, 1, 1]}"#;
    let json = format!(
        r#"{{"objects": [{{"builtin": "plane"}}], "lights": [{light}, {light}],
            "random_lights": {{"count": 4194303}}}}"#
    );
    let err = parse_str(&json).unwrap_err().to_string();
    assert!(
        err.contains("random_lights.count")
            && err.contains("4194303 random lights and the file's 2 make 4194305"),
        "{err}"
    );
    // A count past the limit alone is named alone, not in a sum that saturates.
    let json = json.replace("4194303", "18446744073709551615");
    let err = parse_str(&json).unwrap_err().to_string();
    assert!(
        err.contains("18446744073709551615 lights is more than") && !err.contains("make"),
        "{err}"
    );
}

#[test]
fn finite_numbers_past_f32_are_named_as_written_not_as_infinite() {
    let light = |field: &str, value: &str| {
        let mut l = serde_json::json!({"kind": "point", "position": [0, 0, 1], "radius": 2,
                                       "color": [1, 1, 1]});
        l[field] = serde_json::from_str(value).unwrap();
        format!(r#"{{"objects": [{{"builtin": "plane"}}], "lights": [{l}]}}"#)
    };
    for (text, field) in [
        (
            r#"{"objects": [{"builtin": "plane"}], "ambient": [1e308, 0, 0]}"#.to_string(),
            "`ambient[0]`",
        ),
        (light("radius", "1e308"), "`lights[0].radius`"),
        (light("color", "[1, -1e39, 1]"), "`lights[0].color[1]`"),
        (light("intensity", "1e300"), "`lights[0].intensity`"),
        (
            r#"{"objects": [{"builtin": "plane", "color": [1, 1, 5e38]}]}"#.to_string(),
            "`objects[0].color[2]`",
        ),
        (
            r#"{"objects": [{"builtin": "plane"}], "directional_lights":
                [{"direction": [0, -1, 0], "color": [1, 1, 1], "intensity": 1e39}]}"#
                .to_string(),
            "`directional_lights[0].intensity`",
        ),
    ] {
        let err = parse_str(&text).unwrap_err().to_string();
        assert!(err.contains(field) && err.contains("e3"), "{field}: {err}");
        assert!(err.contains("past the largest number"), "{err}");
        assert!(!err.contains("inf"), "{err}");
    }
}

/// A colour past the materials' range is named as the file wrote it, not as the material the
/// object's model made (`materials[6] (plane).diffuse` said nothing the user wrote).
#[test]
fn an_objects_colour_out_of_range_names_the_object() {
    for (color, shown) in [("[2000, 0, 0]", "2000"), ("[0.5, -1, 0]", "-1")] {
        let text = format!(
            r#"{{"objects": [{{"builtin": "plane"}}, {{"builtin": "plane", "color": {color}}}]}}"#
        );
        let err = parse_str(&text).unwrap_err().to_string();
        assert!(
            err.contains("`objects[1].color`") && err.contains(shown),
            "{err}"
        );
    }
}

#[test]
fn anything_after_the_scenes_object_is_an_error_and_keys_are_shown_escaped() {
    let scene = r#"{"objects": [{"builtin": "plane"}]}"#;
    assert!(parse_str(&format!("{scene} \n\t ")).is_ok());
    for tail in [" xx", "\0", " {}"] {
        let err = parse_str(&format!("{scene}{tail}"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("something follows the scene's JSON object"),
            "{err}"
        );
    }
    // A key with a terminal's escape sequence: named, its control characters escaped.
    let err = parse_str(r#"{"\u001b]0;PWN\u0007": 1}"#)
        .unwrap_err()
        .to_string();
    assert!(err.contains("\\u{1b}]0;PWN\\u{7}"), "{err}");
    assert!(!err.chars().any(char::is_control), "{err:?}");
}

#[test]
fn directional_lights_parse_and_errors_name_the_field() {
    let s = parse_str(
        r#"{"objects": [{"builtin": "plane"}],
            "directional_lights": [{"direction": [0, -3, 0], "color": [1, 0.5, 0.25]},
                                   {"direction": [1, -1, 0], "color": [1, 1, 1], "intensity": 2.5}]}"#,
    )
    .unwrap();
    assert_eq!(s.directional_lights.len(), 2);
    assert_eq!(
        s.directional_lights[0].intensity, 1.0,
        "intensity defaults to 1"
    );
    assert_eq!(s.directional_lights[0].to_light(), DVec3::Y);
    assert_eq!(s.directional_lights[1].radiance(), Vec3::splat(2.5));
    for (bad, field) in [
        (
            r#"{"direction": [0, 0, 0], "color": [1, 1, 1]}"#,
            "directional_lights[0].direction",
        ),
        (
            r#"{"direction": [0, -1, 0], "color": [1, -1, 1]}"#,
            "directional_lights[0].color",
        ),
        (
            r#"{"direction": [0, -1, 0], "color": [1, 1, 1], "intensity": -2}"#,
            "directional_lights[0].intensity",
        ),
        (
            r#"{"direction": [0, -1, 0], "color": [1, 1, 1], "radius": 2}"#,
            "directional_lights[0]",
        ),
        (r#"{"color": [1, 1, 1]}"#, "directional_lights[0]"),
    ] {
        let text =
            format!(r#"{{"objects": [{{"builtin": "plane"}}], "directional_lights": [{bad}]}}"#);
        let err = parse_str(&text).unwrap_err().to_string();
        assert!(err.contains(field), "{bad}: {err}");
    }
}

#[test]
fn parses_a_full_scene() {
    let s = parse_str(
        r#"{"camera": {"position": [0,0,5], "target": [0,0,0]},
            "objects": [{"builtin": "plane", "transform": {"translate": [0,1,0], "scale": 2}, "color": [1,0,0]}],
            "ambient": [0.1, 0.1, 0.1],
            "lights": [{"kind":"point","position":[0,0,1],"radius":3,"color":[1,1,1],"intensity":2},
                       {"kind":"spot","position":[0,0,2],"radius":3,"color":[1,1,1],
                        "direction":[0,0,-1],"inner_deg":10,"outer_deg":20}],
            "random_lights": {"count": 5, "seed": 3}}"#,
    )
    .unwrap();
    assert_eq!(s.lights.len(), 7);
    assert_eq!(s.materials[0].diffuse, Vec3::new(1.0, 0.0, 0.0));
    assert_eq!(s.ambient, Vec3::splat(0.1));
}

#[test]
fn metallic_and_roughness_make_an_objects_materials_metallic_roughness() {
    let s = parse_str(r#"{"objects": [{"builtin": "plane", "metallic": 1, "roughness": 0.25}]}"#)
        .unwrap();
    let m = &s.materials[0];
    assert_eq!(m.model, MaterialModel::MetallicRoughness);
    assert_eq!((m.metallic, m.roughness), (1.0, 0.25));
    for (json, field) in [
        (
            r#"{"builtin": "plane", "metallic": 1}"#,
            "objects[0].roughness",
        ),
        (
            r#"{"builtin": "plane", "metallic": 2, "roughness": 0}"#,
            "objects[0].metallic",
        ),
        (
            r#"{"builtin": "plane", "metallic": 0, "roughness": -1e300}"#,
            "objects[0].roughness",
        ),
    ] {
        let err = parse_str(&format!(r#"{{"objects": [{json}]}}"#))
            .unwrap_err()
            .to_string();
        assert!(err.contains(field), "{err}");
        // Written short: `{}` wrote -1e300 in 301 digits.
        assert!(err.len() < 200, "{err}");
    }
}

#[test]
fn motions_parse_animate_and_start_at_the_written_state() {
    let mut s = parse_str(
        r#"{"objects": [{"builtin": "plane"}],
            "lights": [{"kind":"point","position":[0,0,1],"radius":3,"color":[1,1,1],
                        "motion": {"orbit": {"center": [0,0,0], "period_s": 4},
                                   "flicker": {"amount": 0.5, "rate_hz": 2}}},
                       {"kind":"spot","position":[0,0,2],"radius":3,"color":[1,1,1],
                        "direction":[0,0,-1],"inner_deg":10,"outer_deg":20,
                        "motion": {"sweep": {"axis": [1,0,0], "angle_deg": 30, "period_s": 2}}},
                       {"kind":"point","position":[1,1,1],"radius":3,"color":[1,1,1]}],
            "random_lights": {"count": 8, "seed": 3,
                              "motion": {"wander": {"radius": 0.5, "period_s": 3},
                                         "sweep": {"axis": [1,0,0], "angle_deg": 10, "period_s": 2}}}}"#,
    )
    .unwrap();
    assert_eq!(s.lights.len(), 11);
    // Two single-light tracks and one for the random set; the third light stands still.
    assert_eq!(s.animation.len(), 2 + 1);
    let written = s.lights.clone();
    s.set_time(0.0);
    for (a, b) in s.lights.iter().zip(&written) {
        assert!((a.position - b.position).length() < 1e-12);
    }
    s.set_time(1.0);
    // A quarter turn round the origin about +Y: (0, 0, 1) → (1, 0, 0).
    assert!(
        (s.lights[0].position - DVec3::X).length() < 1e-9,
        "{:?}",
        s.lights[0].position
    );
    assert_ne!(s.lights[1].kind, written[1].kind, "the spot swept");
    assert_eq!(s.lights[2], written[2], "a light without motion stays");
    assert!(s.lights[3..]
        .iter()
        .zip(&written[3..])
        .all(|(a, b)| a.position != b.position));
    s.validate().unwrap();
}

#[test]
fn motion_errors_name_the_field() {
    let light = |motion: &str| {
        format!(
            r#"{{"objects": [{{"builtin": "plane"}}],
                 "lights": [{{"kind":"point","position":[0,0,1],"radius":3,"color":[1,1,1],
                              "motion": {motion}}}]}}"#
        )
    };
    let cases = [
        (
            light(r#"{"orbit": {"period_s": 2}}"#),
            "lights[0].motion.orbit",
        ),
        (
            light(r#"{"orbit": {"center": [0,0,0], "radius": 1, "period_s": 2}}"#),
            "lights[0].motion.orbit",
        ),
        // A start angle on an orbit about a point was ignored without a word.
        (
            light(r#"{"orbit": {"center": [0,0,0], "period_s": 2, "phase_deg": 90}}"#),
            "lights[0].motion.orbit.phase_deg",
        ),
        (
            light(r#"{"bob": {"amplitude": [0,1,0], "period_s": -1}}"#),
            "lights[0].motion.bob.period_s",
        ),
        (
            light(r#"{"sweep": {"axis": [1,0,0], "angle_deg": 5, "period_s": 1}}"#),
            "lights[0].motion.sweep",
        ),
        (
            light(r#"{"flicker": {"amount": 2, "rate_hz": 1}}"#),
            "lights[0].motion.flicker.amount",
        ),
        (light(r#"{"spin": {}}"#), "lights[0].motion"),
        (
            r#"{"objects": [{"builtin": "plane"}], "random_lights": {"count": 2,
                "motion": {"wander": {"radius": 1e300, "period_s": 1}}}}"#
                .to_string(),
            "random_lights.motion.wander.radius",
        ),
    ];
    for (text, needle) in cases {
        let err = parse_str(&text).unwrap_err().to_string();
        assert!(err.contains(needle), "expected `{needle}` in: {err}");
    }
}

#[test]
fn errors_name_the_field() {
    let cases = [
        (r#"{"objects": [], "lihgts": []}"#, "lihgts"),
        (
            r#"{"lights": [{"kind":"point","position":[0,0,0],"radius":-1,"color":[1,1,1]}]}"#,
            "lights[0].radius",
        ),
        (
            r#"{"lights": [{"kind":"spot","position":[0,0,0],"radius":1,"color":[1,1,1],
               "direction":[0,-1,0],"inner_deg":40,"outer_deg":20}]}"#,
            "lights[0].outer_deg",
        ),
        (
            r#"{"lights": [{"kind":"spot","position":[0,0,0],"radius":1,"color":[1,1,1]}]}"#,
            "lights[0].direction",
        ),
        (
            r#"{"lights": [{"kind":"point","position":[0,0,0],"radius":1,"color":[1,1,1],"inner_deg":3}]}"#,
            "lights[0].inner_deg",
        ),
        (
            r#"{"objects": [{"builtin": "plane", "obj": "x.obj"}]}"#,
            "objects[0]",
        ),
        (r#"{"objects": [{"builtin": "nope"}]}"#, "nope"),
        // An empty name reads the scene file's folder: named as the field, not as a path.
        (
            r#"{"objects": [{"obj": ""}]}"#,
            "`objects[0].obj`: is empty",
        ),
        (
            r#"{"objects": [{"builtin": "plane"}, {"gltf": ""}]}"#,
            "`objects[1].gltf`: is empty",
        ),
        (
            r#"{"objects": [{"obj": "x.obj", "texture": ""}]}"#,
            "`objects[0].texture`: is empty",
        ),
        (
            r#"{"camera": {"position": [0,0,0], "target": [0,0,0]}}"#,
            "camera.target",
        ),
        (
            r#"{"lights": [{"kind":"point","position":[0,0,0],"radius":1,"color":[1,1,1],"intensity":-2}]}"#,
            "lights[0].intensity",
        ),
    ];
    for (text, needle) in cases {
        let err = parse_str(text).unwrap_err().to_string();
        assert!(err.contains(needle), "expected `{needle}` in: {err}");
        // Syntax and value errors alike say which file they are about.
        assert!(err.starts_with("scene file test.json: "), "{err}");
    }
}

/// A file's value past its limits names the file; the same count given in place of the
/// file's (the command line's `--lights`) names only `lights`, which the file did not write.
#[test]
fn value_errors_name_the_file_and_a_count_given_in_its_place_does_not() {
    let json =
        r#"{"objects": [{"builtin": "plane"}], "random_lights": {"count": 18446744073709551615}}"#;
    let err = parse_str(json).unwrap_err().to_string();
    assert!(
        err.starts_with("scene file test.json: invalid value for `random_lights.count`"),
        "{err}"
    );
    let replaced = parse(
        r#"{"objects": [{"builtin": "plane"}]}"#,
        Path::new("."),
        Path::new("test.json"),
        Some((usize::MAX, 1)),
        &LoadOptions::default(),
    );
    let err = replaced.map(|_| ()).unwrap_err().to_string();
    assert!(err.starts_with("invalid value for `lights`"), "{err}");
    let err = parse_str(r#"{"objects": []}"#).unwrap_err().to_string();
    assert!(
        err.starts_with("scene file test.json: invalid value for `objects`: nothing to draw"),
        "{err}"
    );
}

#[test]
fn a_byte_order_mark_is_skipped_and_huge_values_are_shown_short() {
    let plain = r#"{"objects": [{"builtin": "plane"}]}"#;
    assert!(parse_str(&format!("\u{feff}{plain}")).is_ok());
    let err = parse_str(
        r#"{"objects": [{"builtin": "plane"}],
            "lights": [{"kind": "point", "position": [0, 0, 1], "radius": 2,
                        "color": [1, 1, 1],
                        "motion": {"wander": {"radius": 1e300, "period_s": 4}}}]}"#,
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("wander.radius") && err.contains("1e300"),
        "{err}"
    );
    assert!(err.len() < 300, "{err}");
}

#[test]
fn a_camera_too_near_its_target_says_so_and_up_of_any_length_is_a_direction() {
    let scene = |target: &str, up: &str, near: &str| {
        parse_str(&format!(
            r#"{{"objects": [{{"builtin": "plane"}}],
                "camera": {{"position": [0, 0, 4], "target": {target}, "up": {up},
                            "near": {near}}}}}"#
        ))
    };
    let camera = |target: &str, up: &str| scene(target, up, "0.1").unwrap_err().to_string();
    let err = camera("[0, 0, 3.9999999999999999]", "[0, 1, 0]");
    assert!(err.contains("equals camera.position"), "{err}");
    let err = camera("[1e-170, 0, 4]", "[0, 1, 0]");
    assert!(err.contains("too near"), "{err}");
    let err = camera("[0, 0, 0]", "[0, 0, 0]");
    assert!(err.contains("must be non-zero"), "{err}");
    // A direction's length is no coordinate: a tiny or huge `up` (refused as too short, or
    // as past the coordinate limit) gives the unit one's view.
    let view = |up: &str| scene("[0, 0, 0]", up, "0.1").unwrap().camera.view_matrix();
    let unit = view("[0, 1, 0]");
    for up in ["[0, 1e-200, 0]", "[0, 1e308, 0]", "[1e-300, 3e-300, 0]"] {
        let v = view(up);
        assert!(v.is_finite(), "{up}: {v}");
        if up != "[1e-300, 3e-300, 0]" {
            assert!(v.abs_diff_eq(unit, 1e-12), "{up}: {v} against {unit}");
        }
    }
    // The other projection's field is an error naming it (it was ignored without a word).
    let other = |camera: &str| {
        let text = format!(r#"{{"objects": [{{"builtin": "plane"}}], "camera": {camera}}}"#);
        parse_str(&text).unwrap_err().to_string()
    };
    let err = other(r#"{"position": [0, 0, 4], "target": [0, 0, 0], "height": 3}"#);
    assert!(
        err.contains("`camera.height`") && err.contains("orthographic"),
        "{err}"
    );
    let err = other(
        r#"{"position": [0, 0, 4], "target": [0, 0, 0], "projection": "orthographic",
            "fov_y_deg": 30}"#,
    );
    assert!(
        err.contains("`camera.fov_y_deg`") && err.contains("a perspective"),
        "{err}"
    );
    // A near plane past the coordinate limit is `camera.near`'s fault, not `camera.far`'s.
    for near in ["1e308", "3.5e38", "18446744073709551615"] {
        let err = scene("[0, 0, 0]", "[0, 1, 0]", near)
            .unwrap_err()
            .to_string();
        assert!(err.contains("`camera.near`"), "{near}: {err}");
    }
}

/// A key, a name or a string from the file is quoted at most `MAX_SHOWN_NAME` characters long
/// wherever a JSON error shows it (a 300-character key was shown whole, twice).
#[test]
fn file_text_in_json_errors_is_cut() {
    let k = "k".repeat(300);
    let errors = [
        format!(r#"{{"{k}": 1}}"#),
        format!(r#"{{"objects": [{{"builtin": "plane", "{k}": 2}}]}}"#),
        format!(r#"{{"objects": [{{"builtin": "plane"}}], "ambient": "{k}"}}"#),
        format!(
            r#"{{"objects": [{{"builtin": "plane"}}], "lights": [{{"position": [0, 1, "{k}"]}}]}}"#
        ),
    ]
    .map(|s| parse_str(&s).unwrap_err().to_string());
    let cut = format!("{}… (236 characters more)", "k".repeat(64));
    for err in errors {
        assert!(err.contains(&cut), "{err}");
        assert!(!err.contains(&"k".repeat(65)), "{err}");
    }
}

/// An unknown key is named once, in serde's reason, after the path to the object holding it.
#[test]
fn an_unknown_key_is_named_once() {
    let top = parse_str(r#"{"objects": [{"builtin": "plane"}], "lightz": []}"#)
        .unwrap_err()
        .to_string();
    assert_eq!(top.matches("lightz").count(), 1, "{top}");
    assert!(
        top.contains("unknown field `lightz`, expected one of"),
        "{top}"
    );
    let nested = parse_str(r#"{"objects": [{"builtin": "plane", "colour": 1}]}"#)
        .unwrap_err()
        .to_string();
    assert_eq!(nested.matches("colour").count(), 1, "{nested}");
    assert!(
        nested.contains("objects[0]: unknown field `colour`"),
        "{nested}"
    );
}

/// 16 MiB of `{},` in `objects` parsed into 1.25 GB before the first was refused: objects
/// and arrays past the limit are refused before parsing, naming the count. At the limit the
/// parse goes on (and names the first element it cannot take, at once).
#[test]
fn json_past_its_container_limit_is_refused_before_parsing() {
    let lights = |n: usize| format!(r#"{{"lights": [{}]}}"#, vec!["[]"; n].join(","));
    // The file's object and its `lights` array are two more.
    let at_limit = lights(MAX_SCENE_FILE_CONTAINERS - 2);
    let err = parse_str(&at_limit).map(|_| ()).unwrap_err().to_string();
    assert!(!err.contains("objects and arrays"), "{err}");
    let past = lights(MAX_SCENE_FILE_CONTAINERS - 1);
    let err = parse_str(&past).map(|_| ()).unwrap_err().to_string();
    assert!(
        err.contains(&format!(
            "its JSON holds {} objects and arrays, more than the {MAX_SCENE_FILE_CONTAINERS}",
            MAX_SCENE_FILE_CONTAINERS + 1
        )),
        "{err}"
    );
}

/// One OBJ placed twice, once made metallic-roughness: each placement keeps its own model.
/// Unrecoloured placements share materials, and `metallic`/`roughness` did not count as a
/// recolouring: the plain copy after a metallic one drew metallic, and a metallic one after a
/// plain one changed nothing.
#[cfg(feature = "obj")]
#[test]
fn metallic_and_roughness_change_only_their_own_placement_of_a_shared_obj() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("q.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let metallic = r#"{"obj": "q.obj", "metallic": 1, "roughness": 0.3}"#;
    let plain = r#"{"obj": "q.obj"}"#;
    for (objects, metallic_at) in [([metallic, plain], 0), ([plain, metallic], 1)] {
        let text = format!(r#"{{"objects": [{}]}}"#, objects.join(","));
        let path = dir.path().join("s.json");
        let (s, _) = parse(&text, dir.path(), &path, None, &LoadOptions::default()).unwrap();
        for (i, o) in s.objects.iter().enumerate() {
            let model = s.materials[o.material].model;
            let want = if i == metallic_at {
                MaterialModel::MetallicRoughness
            } else {
                MaterialModel::BlinnPhong
            };
            assert_eq!(model, want, "{objects:?}: object {i}");
        }
    }
}

/// A built-in placed alone by a `transform` keeps its own view, carried with it (as a glTF's
/// camera is): the plane moved to x = 100 and turned kept the camera at the origin, and drew
/// black. A transform that distorts leaves the view to the framing.
#[test]
fn a_builtin_placed_alone_carries_its_camera_with_it() {
    let own = crate::scene::builtin::build("plane", None).unwrap().camera;
    let moved = r#"{"objects": [{"builtin": "plane",
                     "transform": {"translate": [100, 0, 0], "rotate_y_deg": 90}}]}"#;
    let scene = parse_str(moved).unwrap();
    let transform = glam::DMat4::from_translation(glam::DVec3::new(100.0, 0.0, 0.0))
        * glam::DMat4::from_rotation_y(90f64.to_radians());
    let want = own.placed_by(&transform).unwrap();
    assert!(scene.camera.position.abs_diff_eq(want.position, 1e-9));
    assert!(scene.camera.target.abs_diff_eq(want.target, 1e-9));
    assert!((scene.camera.target - glam::DVec3::new(100.0, 0.0, 0.0)).length() < 1e-9);
    let stretched = r#"{"objects": [{"builtin": "plane", "transform": {"scale": [1, 2, 1]}}]}"#;
    let scene = parse_str(stretched).unwrap();
    assert_ne!(
        scene.camera.position, own.position,
        "not the builtin's camera"
    );
}

/// A syntax error past the last value of the file's object (a comment before its `}`) names no
/// path it cannot tell: it read `?: expected `,` or `}` at line 1 column 34`.
#[test]
fn a_syntax_error_after_the_last_value_names_its_position_alone() {
    let text = r#"{"objects":[{"builtin":"plane"}] /* c */}"#;
    let err = parse_str(text).unwrap_err().to_string();
    assert!(!err.contains('?'), "{err}");
    assert!(err.contains("line 1 column"), "{err}");
}
