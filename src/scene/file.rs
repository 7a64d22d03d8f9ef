//! JSON scene files.
//!
//! ```json
//! {
//!   "camera": {"position": [0, 2, 8], "target": [0, 1, 0], "fov_y_deg": 60, "near": 0.1, "far": 100},
//!   "ambient": [0.02, 0.02, 0.02],
//!   "objects": [
//!     {"builtin": "plane"},
//!     {"obj": "models/teapot.obj", "transform": {"translate": [0, 0, -2], "rotate_y_deg": 30, "scale": 0.5},
//!      "color": [0.8, 0.2, 0.2]}
//!   ],
//!   "lights": [
//!     {"kind": "point", "position": [0, 1, 1], "radius": 4, "color": [1, 0.9, 0.8], "intensity": 2},
//!     {"kind": "spot", "position": [2, 3, 0], "radius": 6, "color": [1, 1, 1], "intensity": 3,
//!      "direction": [0, -1, 0], "inner_deg": 15, "outer_deg": 30}
//!   ],
//!   "random_lights": {"count": 256, "seed": 7}
//! }
//! ```
//!
//! Paths are relative to the scene file. Unknown fields are errors; so are invalid values,
//! which are reported with the path of the field (`lights[1].outer_deg`).

use std::path::{Path, PathBuf};

use glam::{DMat4, DVec3, Vec3};
use serde::Deserialize;

use super::camera::Projection;
use super::obj::{self, LoadReport};
use super::random::{self, LightSetStyle};
use super::{builtin, Camera, Light, LightKind, Scene, SceneError};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    camera: Option<CameraSpec>,
    #[serde(default)]
    objects: Vec<ObjectSpec>,
    ambient: Option<[f32; 3]>,
    #[serde(default)]
    lights: Vec<LightSpec>,
    random_lights: Option<RandomLightsSpec>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraSpec {
    position: [f64; 3],
    target: [f64; 3],
    up: Option<[f64; 3]>,
    #[serde(default)]
    projection: ProjectionKind,
    fov_y_deg: Option<f64>,
    height: Option<f64>,
    near: Option<f64>,
    far: Option<f64>,
}

#[derive(Deserialize, Default)]
#[serde(rename_all = "snake_case")]
enum ProjectionKind {
    #[default]
    Perspective,
    Orthographic,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectSpec {
    builtin: Option<String>,
    obj: Option<PathBuf>,
    texture: Option<PathBuf>,
    transform: Option<TransformSpec>,
    color: Option<[f32; 3]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TransformSpec {
    #[serde(default)]
    translate: [f64; 3],
    #[serde(default)]
    rotate_y_deg: f64,
    scale: Option<ScaleSpec>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum ScaleSpec {
    Uniform(f64),
    PerAxis([f64; 3]),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightSpec {
    kind: LightKindSpec,
    position: [f64; 3],
    radius: f32,
    color: [f32; 3],
    #[serde(default = "one")]
    intensity: f32,
    direction: Option<[f64; 3]>,
    inner_deg: Option<f64>,
    outer_deg: Option<f64>,
}

fn one() -> f32 {
    1.0
}

#[derive(Deserialize)]
#[serde(rename_all = "snake_case")]
enum LightKindSpec {
    Point,
    Spot,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RandomLightsSpec {
    count: usize,
    #[serde(default)]
    seed: u64,
}

/// Parses the JSON, naming the field at fault: serde's own messages lack the path, and for an
/// array with too many values say only "trailing characters".
fn deserialize(text: &str) -> Result<SceneFile, String> {
    let mut json = serde_json::Deserializer::from_str(text);
    serde_path_to_error::deserialize(&mut json).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.inner().to_string();
        let inner = match inner.strip_prefix("trailing characters") {
            Some(position) if path != "." => format!("too many values{position}"),
            _ => inner,
        };
        if path == "." {
            inner
        } else {
            format!("{path}: {inner}")
        }
    })
}

/// Loads a scene file. Returns the scene (validated) and the warnings of any OBJ loads.
/// `random_override` = `Some((count, seed))` replaces the file's `random_lights`.
pub fn load(
    path: &Path,
    random_override: Option<(usize, u64)>,
) -> Result<(Scene, LoadReport), SceneError> {
    let bytes = super::input::read_bounded(path, super::input::FileKind::SceneFile)?;
    let text = String::from_utf8(bytes).map_err(|e| SceneError::SceneFile {
        path: path.to_path_buf(),
        reason: format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
    })?;
    parse(
        &text,
        path.parent().unwrap_or(Path::new(".")),
        path,
        random_override,
    )
}

/// Parses scene-file text; relative paths are resolved against `base_dir`, `origin` names the
/// source in errors.
pub fn parse(
    text: &str,
    base_dir: &Path,
    origin: &Path,
    random_override: Option<(usize, u64)>,
) -> Result<(Scene, LoadReport), SceneError> {
    let file: SceneFile = deserialize(text).map_err(|reason| SceneError::SceneFile {
        path: origin.to_path_buf(),
        reason,
    })?;
    let mut scene = Scene::empty();
    let mut report = LoadReport::default();
    let mut builtin_camera = None;
    for (i, spec) in file.objects.iter().enumerate() {
        let field = format!("objects[{i}]");
        let transform = spec
            .transform
            .as_ref()
            .map_or(Ok(DMat4::IDENTITY), |t| t.matrix(&field))?;
        let first_material = scene.materials.len();
        match (&spec.builtin, &spec.obj) {
            (Some(name), None) => {
                let built = builtin::geometry(name)
                    .ok_or_else(|| SceneError::UnknownBuiltin(name.clone()))?;
                if spec.texture.is_some() {
                    return Err(SceneError::invalid(
                        format!("{field}.texture"),
                        "only OBJ objects take a texture",
                    ));
                }
                builtin_camera.get_or_insert(built.camera);
                for mut o in built.objects {
                    o.material += first_material;
                    o.transform = transform * o.transform;
                    scene.objects.push(o);
                }
                scene.materials.extend(built.materials);
            }
            (None, Some(obj_path)) => {
                let tex = spec.texture.as_ref().map(|t| base_dir.join(t));
                let r = obj::load_into(
                    &mut scene,
                    &base_dir.join(obj_path),
                    transform,
                    tex.as_deref(),
                )?;
                report.warnings.extend(r.warnings);
            }
            _ => {
                return Err(SceneError::invalid(
                    field,
                    "needs exactly one of `builtin` or `obj`",
                ))
            }
        }
        if let Some(c) = spec.color {
            // Recolour this object's materials only (they were appended for it).
            for m in &mut scene.materials[first_material..] {
                m.diffuse = Vec3::from(c);
            }
        }
    }
    if let Some(a) = file.ambient {
        scene.ambient = Vec3::from(a);
    }
    for (i, l) in file.lights.iter().enumerate() {
        scene.lights.push(l.to_light(&format!("lights[{i}]"))?);
    }
    match (&file.camera, builtin_camera) {
        (Some(c), _) => scene.camera = c.to_camera(),
        (None, Some(c)) if file.objects.len() == 1 => scene.camera = c,
        _ => scene.frame_camera(),
    }
    let random = match (random_override, &file.random_lights) {
        (Some(r), _) => Some((r, "lights")),
        (None, Some(r)) => Some(((r.count, r.seed), "random_lights.count")),
        (None, None) => None,
    };
    if let Some(((count, seed), field)) = random {
        let total = count.saturating_add(scene.lights.len());
        super::input::check_light_count(total, field)?;
        let volume = scene.bounds().ok_or_else(|| {
            SceneError::invalid("random_lights", "needs geometry to place lights in")
        })?;
        scene
            .lights
            .extend(random::lights(&volume, count, seed, LightSetStyle::Mixed));
    }
    scene.validate()?;
    Ok((scene, report))
}

impl TransformSpec {
    fn matrix(&self, field: &str) -> Result<DMat4, SceneError> {
        let scale = match self.scale {
            None => DVec3::ONE,
            Some(ScaleSpec::Uniform(s)) => DVec3::splat(s),
            Some(ScaleSpec::PerAxis(s)) => DVec3::from(s),
        };
        if !scale.is_finite() || scale.cmpeq(DVec3::ZERO).any() {
            return Err(SceneError::invalid(
                format!("{field}.transform.scale"),
                format!("must be finite and non-zero, got {scale:?}"),
            ));
        }
        Ok(DMat4::from_translation(DVec3::from(self.translate))
            * DMat4::from_rotation_y(self.rotate_y_deg.to_radians())
            * DMat4::from_scale(scale))
    }
}

impl CameraSpec {
    fn to_camera(&self) -> Camera {
        let near = self.near.unwrap_or(0.1);
        let far = self.far.unwrap_or(1000.0);
        Camera {
            position: DVec3::from(self.position),
            target: DVec3::from(self.target),
            up: DVec3::from(self.up.unwrap_or([0.0, 1.0, 0.0])),
            projection: match self.projection {
                ProjectionKind::Perspective => Projection::Perspective {
                    fov_y_deg: self.fov_y_deg.unwrap_or(60.0),
                    near,
                    far,
                },
                ProjectionKind::Orthographic => Projection::Orthographic {
                    height: self.height.unwrap_or(10.0),
                    near,
                    far,
                },
            },
        }
    }
}

impl LightSpec {
    fn to_light(&self, field: &str) -> Result<Light, SceneError> {
        let kind = match self.kind {
            LightKindSpec::Point => {
                for (name, present) in [
                    ("direction", self.direction.is_some()),
                    ("inner_deg", self.inner_deg.is_some()),
                    ("outer_deg", self.outer_deg.is_some()),
                ] {
                    if present {
                        return Err(SceneError::invalid(
                            format!("{field}.{name}"),
                            "only spot lights have a cone; use \"kind\": \"spot\"",
                        ));
                    }
                }
                LightKind::Point
            }
            LightKindSpec::Spot => {
                let need = |v: Option<f64>, name: &str| {
                    v.ok_or_else(|| {
                        SceneError::invalid(format!("{field}.{name}"), "required for a spot light")
                    })
                };
                LightKind::Spot {
                    direction: DVec3::from(self.direction.ok_or_else(|| {
                        SceneError::invalid(
                            format!("{field}.direction"),
                            "required for a spot light",
                        )
                    })?),
                    inner_deg: need(self.inner_deg, "inner_deg")?,
                    outer_deg: need(self.outer_deg, "outer_deg")?,
                }
            }
        };
        let light = Light {
            kind,
            position: DVec3::from(self.position),
            radius: self.radius,
            color: Vec3::from(self.color),
            intensity: self.intensity,
        };
        light.validate(field)?;
        Ok(light)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_str(s: &str) -> Result<Scene, SceneError> {
        parse(s, Path::new("."), Path::new("test.json"), None).map(|(s, _)| s)
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
        }
    }
}
