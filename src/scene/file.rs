//! JSON scene files.
//!
//! ```json
//! {
//!   "camera": {"position": [0, 2, 8], "target": [0, 1, 0], "fov_y_deg": 60, "near": 0.1, "far": 100},
//!   "ambient": [0.02, 0.02, 0.02],
//!   "objects": [
//!     {"builtin": "plane"},
//!     {"obj": "models/teapot.obj", "transform": {"translate": [0, 0, -2], "rotate_y_deg": 30, "scale": 0.5},
//!      "color": [0.8, 0.2, 0.2]},
//!     {"builtin": "plane", "metallic": 1, "roughness": 0.3},
//!     {"gltf": "models/lamp.glb", "transform": {"translate": [2, 0, 0]}}
//!   ],
//!   "lights": [
//!     {"kind": "point", "position": [0, 1, 1], "radius": 4, "color": [1, 0.9, 0.8], "intensity": 2,
//!      "motion": {"orbit": {"center": [0, 1, 0], "period_s": 6},
//!                 "flicker": {"amount": 0.3, "rate_hz": 3}}},
//!     {"kind": "spot", "position": [2, 3, 0], "radius": 6, "color": [1, 1, 1], "intensity": 3,
//!      "direction": [0, -1, 0], "inner_deg": 15, "outer_deg": 30,
//!      "motion": {"sweep": {"axis": [1, 0, 0], "angle_deg": 25, "period_s": 4}}}
//!   ],
//!   "directional_lights": [{"direction": [-1, -2, -1], "color": [1, 0.95, 0.9], "intensity": 3}],
//!   "random_lights": {"count": 256, "seed": 7,
//!                     "motion": {"wander": {"radius": 1.5, "period_s": 6}}}
//! }
//! ```
//!
//! Motions (`orbit` round a `center` or on a circle of `radius` through the light, `bob`,
//! `wander`, `flicker`, `sweep`; see [`super::motion`]) are functions of time that start at
//! the light as written; a random set gives each light its own variation.
//!
//! Paths are relative to the scene file. Unknown fields are errors; so are invalid values,
//! which are reported with the path of the field (`lights[1].outer_deg`).

mod json_error;
mod json_size;
pub use json_size::MAX_SCENE_FILE_CONTAINERS;

use std::path::{Path, PathBuf};

use glam::{DMat4, DVec3, Vec3};
use serde::Deserialize;

use super::access::LoadOptions;
use super::camera::{Projection, MAX_CAMERA_COORD};
use super::material::check_color_factor;
use super::model_cache::{self, ModelCache};
use super::motion::{Bob, Flicker, Motion, Orbit, OrbitAbout, Sweep, Wander};
use super::random::{self, LightSetStyle};
use super::{Camera, DirectionalLight, Light, LightKind, MaterialModel, Scene, SceneError};
use super::{LoadReport, Short};

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a scene: a JSON object")]
struct SceneFile {
    camera: Option<CameraSpec>,
    #[serde(default)]
    objects: Vec<ObjectSpec>,
    ambient: Option<[f64; 3]>,
    #[serde(default)]
    lights: Vec<LightSpec>,
    #[serde(default)]
    directional_lights: Vec<DirectionalSpec>,
    random_lights: Option<RandomLightsSpec>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a camera object")]
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
#[serde(deny_unknown_fields, expecting = "an object")]
struct ObjectSpec {
    builtin: Option<String>,
    obj: Option<PathBuf>,
    /// A `.gltf` or `.glb` file: its meshes, materials and lights (placed by `transform`),
    /// and its camera when it is the file's only object and the file names no camera.
    gltf: Option<PathBuf>,
    texture: Option<PathBuf>,
    transform: Option<TransformSpec>,
    color: Option<[f64; 3]>,
    /// With `roughness`: the object's materials become metallic-roughness (glTF BRDF).
    metallic: Option<f64>,
    roughness: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a transform object")]
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
#[serde(deny_unknown_fields, expecting = "a light object")]
struct LightSpec {
    kind: LightKindSpec,
    position: [f64; 3],
    radius: f64,
    color: [f64; 3],
    #[serde(default = "one")]
    intensity: f64,
    direction: Option<[f64; 3]>,
    inner_deg: Option<f64>,
    outer_deg: Option<f64>,
    motion: Option<MotionSpec>,
}

/// A sun: `direction` is the way the light travels (from it towards the scene).
#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a directional light object")]
struct DirectionalSpec {
    direction: [f64; 3],
    color: [f64; 3],
    #[serde(default = "one")]
    intensity: f64,
}

fn one() -> f64 {
    1.0
}

fn up() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

/// `"motion"` of a light or a random set (see [`super::motion`]).
#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a motion object")]
struct MotionSpec {
    orbit: Option<OrbitSpec>,
    bob: Option<BobSpec>,
    wander: Option<WanderSpec>,
    flicker: Option<FlickerSpec>,
    sweep: Option<SweepSpec>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "an orbit object")]
struct OrbitSpec {
    center: Option<[f64; 3]>,
    radius: Option<f64>,
    #[serde(default = "up")]
    axis: [f64; 3],
    period_s: f64,
    #[serde(default)]
    phase_deg: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a bob object")]
struct BobSpec {
    amplitude: [f64; 3],
    period_s: f64,
    #[serde(default)]
    phase_deg: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a wander object")]
struct WanderSpec {
    radius: f64,
    period_s: f64,
    #[serde(default)]
    seed: u64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a flicker object")]
struct FlickerSpec {
    amount: f64,
    rate_hz: f64,
    #[serde(default)]
    seed: u64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a sweep object")]
struct SweepSpec {
    axis: [f64; 3],
    angle_deg: f64,
    period_s: f64,
    #[serde(default)]
    phase_deg: f64,
}

#[derive(Deserialize)]
#[serde(rename_all = "snake_case")]
enum LightKindSpec {
    Point,
    Spot,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a random lights object")]
struct RandomLightsSpec {
    count: usize,
    #[serde(default)]
    seed: u64,
    motion: Option<MotionSpec>,
}

/// `v` as the `f32` a scene keeps it in, or an error naming `field` where it is finite but
/// past `f32`'s range (read straight into an `f32` it would become infinite, and an error
/// would say `inf` of a number the file wrote finite).
fn narrow(field: &str, v: f64) -> Result<f32, SceneError> {
    if v.is_finite() && v.abs() > f64::from(f32::MAX) {
        return Err(SceneError::invalid(
            field,
            format!(
                "{v:e} is past the largest number a scene keeps ({:e})",
                f32::MAX
            ),
        ));
    }
    Ok(v as f32)
}

/// [`narrow`] of each of three values (`field[i]` names the one at fault).
fn narrow3(field: &str, v: [f64; 3]) -> Result<Vec3, SceneError> {
    let mut out = [0.0; 3];
    for (i, (o, v)) in out.iter_mut().zip(v).enumerate() {
        *o = narrow(&format!("{field}[{i}]"), v)?;
    }
    Ok(Vec3::from(out))
}

/// Parses the JSON, naming the field at fault: serde's own messages lack the path, and for an
/// array with too many values say only "trailing characters". Anything after the scene's
/// object but white space is an error too.
fn deserialize(text: &str) -> Result<SceneFile, String> {
    // A UTF-8 byte order mark, as some Windows editors write: skipped, as for OBJ and MTL.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    json_size::check(text)?;
    let mut json = serde_json::Deserializer::from_str(text);
    let file = serde_path_to_error::deserialize(&mut json).map_err(|e| json_error::message(&e))?;
    json.end()
        .map_err(|e| format!("something follows the scene's JSON object: {e}"))?;
    Ok(file)
}

/// What an object of the file takes placed, through loading and a frame, with room to spare
/// over what was measured (docs/cli.md).
const OBJECT_BYTES: u64 = 1024;

/// Loads a scene file. Returns the scene (validated) and the warnings of any OBJ loads.
/// `random_override` = `Some((count, seed))` replaces the file's `random_lights`.
pub fn load(
    path: &Path,
    random_override: Option<(usize, u64)>,
    options: &LoadOptions,
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
        options,
    )
}

/// Parses scene-file text; relative paths are resolved against `base_dir`, `origin` names the
/// source in errors. The models it names may lie anywhere (`../models/a.glb`): a scene file is
/// the user's own, like a command line; what a model file itself names follows `options`.
pub fn parse(
    text: &str,
    base_dir: &Path,
    origin: &Path,
    random_override: Option<(usize, u64)>,
    options: &LoadOptions,
) -> Result<(Scene, LoadReport), SceneError> {
    let file: SceneFile = deserialize(text).map_err(|reason| SceneError::SceneFile {
        path: origin.to_path_buf(),
        reason,
    })?;
    // Past the count limit, that limit's error names the object at fault.
    let count = file.objects.len();
    if count <= super::MAX_SCENE_OBJECTS {
        let placing = count as u64 * OBJECT_BYTES;
        super::alloc_probe::ask(placing, format_args!("placing its {count} objects takes"))
            .map_err(|reason| SceneError::invalid("objects", reason))?;
    }
    let mut scene = Scene::empty();
    let mut report = LoadReport::default();
    let mut builtin_camera = None;
    let mut models = ModelCache::new(*options);
    let mut meshes = model_cache::MeshCount::default();
    for (i, spec) in file.objects.iter().enumerate() {
        let field = format!("objects[{i}]");
        let transform = spec
            .transform
            .as_ref()
            .map_or(Ok(DMat4::IDENTITY), |t| t.matrix(&field))?;
        let first_material = scene.materials.len();
        let first_object = scene.objects.len();
        // Materials this object changes are its own copy; unchanged ones are shared.
        let recolour = spec.color.is_some() || spec.metallic.is_some() || spec.roughness.is_some();
        for (name, path) in [
            ("obj", &spec.obj),
            ("gltf", &spec.gltf),
            ("texture", &spec.texture),
        ] {
            if path.as_ref().is_some_and(|p| p.as_os_str().is_empty()) {
                return Err(SceneError::invalid(
                    format!("{field}.{name}"),
                    "is empty: it must name a file",
                ));
            }
        }
        match (&spec.builtin, &spec.obj, &spec.gltf) {
            (Some(name), None, None) => {
                let camera =
                    models
                        .builtin_camera(name)
                        .ok_or_else(|| SceneError::UnknownBuiltin {
                            name: name.clone(),
                            available: super::builtin::NAMES,
                        })?;
                if spec.texture.is_some() {
                    return Err(SceneError::invalid(
                        format!("{field}.texture"),
                        "only OBJ objects take a texture",
                    ));
                }
                builtin_camera.get_or_insert(camera);
                models.place_builtin(&mut scene, name, transform, recolour);
            }
            (None, Some(obj_path), None) => {
                let tex = spec.texture.as_ref().map(|t| base_dir.join(t));
                let r = models.place_obj(
                    &mut scene,
                    &base_dir.join(obj_path),
                    transform,
                    tex.as_deref(),
                    recolour,
                    &format!("{field}.transform"),
                )?;
                report.warnings.extend(r.warnings);
            }
            (None, None, Some(gltf_path)) => {
                if spec.texture.is_some() {
                    return Err(SceneError::invalid(
                        format!("{field}.texture"),
                        "only OBJ objects take a texture",
                    ));
                }
                let (model_report, camera) = models.place_gltf(
                    &mut scene,
                    &base_dir.join(gltf_path),
                    transform,
                    recolour,
                    &format!("{field}.transform"),
                )?;
                if let Some(camera) = camera {
                    builtin_camera.get_or_insert(camera);
                }
                report.warnings.extend(model_report.warnings);
                if scene.objects.len() == first_object {
                    // A light rig is fine here (on its own, `--scene` refuses it).
                    let msg = format!(
                        "{field}: {} has nothing to draw: only its lights are used",
                        gltf_path.display()
                    );
                    report.say(msg);
                }
            }
            _ => {
                return Err(SceneError::invalid(
                    field,
                    "needs exactly one of `builtin`, `obj` or `gltf`",
                ))
            }
        }
        check_placed(&scene, first_object, &field)?;
        if let Some(c) = spec.color {
            let c = narrow3(&format!("{field}.color"), c)?;
            // Checked here, where the file's field is known (the materials' own check names them).
            check_color_factor(c, &field, "color")?;
            // Recolour this object's materials only (they were appended for it).
            for m in &mut scene.materials[first_material..] {
                m.diffuse = c;
            }
        }
        if spec.metallic.is_some() || spec.roughness.is_some() {
            let unit = |name: &str, v: Option<f64>| match v {
                Some(v) if v.is_finite() && (0.0..=1.0).contains(&v) => Ok(v as f32),
                Some(v) => Err(SceneError::invalid(
                    format!("{field}.{name}"),
                    format!("must be in [0, 1], got {}", Short(v)),
                )),
                None => Err(SceneError::invalid(
                    format!("{field}.{name}"),
                    "is needed with `metallic` and `roughness` (both or neither)",
                )),
            };
            let (metallic, roughness) = (
                unit("metallic", spec.metallic)?,
                unit("roughness", spec.roughness)?,
            );
            for m in &mut scene.materials[first_material..] {
                m.model = MaterialModel::MetallicRoughness;
                (m.metallic, m.roughness) = (metallic, roughness);
            }
        }
        model_cache::check_budget(&scene, &mut meshes, &format!("objects[{i}]"))?;
    }
    if let Some(a) = file.ambient {
        scene.ambient = narrow3("ambient", a)?;
    }
    for (i, l) in file.lights.iter().enumerate() {
        let field = format!("lights[{i}]");
        scene.lights.push(l.to_light(&field)?);
        if let Some(m) = &l.motion {
            let is_spot = matches!(l.kind, LightKindSpec::Spot);
            let motion = m.to_motion(&format!("{field}.motion"), is_spot)?;
            scene.animate_light(scene.lights.len() - 1, motion);
        }
    }
    for (i, d) in file.directional_lights.iter().enumerate() {
        let field = format!("directional_lights[{i}]");
        let color = narrow3(&format!("{field}.color"), d.color)?;
        let intensity = narrow(&format!("{field}.intensity"), d.intensity)?;
        let light = DirectionalLight::new(DVec3::from(d.direction), color, intensity);
        light.validate(&field)?;
        scene.directional_lights.push(light);
    }
    match (&file.camera, builtin_camera) {
        (Some(c), _) => scene.camera = c.to_camera()?,
        (None, Some(c)) if file.objects.len() == 1 => scene.camera = c,
        _ => {
            scene.frame_camera();
            // Objects near the limit leave no room for a camera that sees them all.
            if scene.camera.validate().is_err() {
                return Err(SceneError::invalid(
                    "camera",
                    format!(
                        "the file gives none, and one framing all its objects would lie past \
                         ±{MAX_CAMERA_COORD:e}: give `camera`"
                    ),
                ));
            }
        }
    }
    let random = match (random_override, &file.random_lights) {
        (Some(r), _) => Some((r, "lights")),
        (None, Some(r)) => Some(((r.count, r.seed), "random_lights.count")),
        (None, None) => None,
    };
    if let Some(((count, seed), field)) = random {
        // The count alone here; memory is asked for the total below.
        super::input::light_count(count as u64, field)?;
        let total = count.saturating_add(scene.lights.len());
        if total > super::input::MAX_LIGHTS {
            return Err(SceneError::invalid(
                field,
                format!(
                    "{count} random lights and the file's {} make {total}, more than the {} a \
                     scene may hold",
                    scene.lights.len(),
                    super::input::MAX_LIGHTS
                ),
            ));
        }
        super::input::check_light_count(total, field)?;
        let volume = scene.bounds().ok_or_else(|| {
            SceneError::invalid("random_lights", "needs geometry to place lights in")
        })?;
        let first = scene.lights.len();
        scene
            .lights
            .extend(random::lights(&volume, count, seed, LightSetStyle::Mixed));
        if let Some(m) = file.random_lights.as_ref().and_then(|r| r.motion.as_ref()) {
            // A set's sweep moves its spots only.
            let motion = m.to_motion("random_lights.motion", true)?;
            scene.animate_lights(first..scene.lights.len(), motion, seed);
        }
    }
    scene.validate()?;
    // As for a glTF file alone: a picture of the background only is refused, not drawn black.
    if scene.objects.is_empty() {
        return Err(SceneError::invalid(
            "objects",
            "nothing to draw: no object places a triangle mesh",
        ));
    }
    Ok((scene, report))
}

/// The objects from `first` on, placed by `field`'s transform: their world bounds must be
/// finite and within the camera's coordinate limit, or the transform is at fault.
fn check_placed(scene: &Scene, first: usize, field: &str) -> Result<(), SceneError> {
    // A model placing one mesh many times has its vertices walked once.
    let mut mesh_bounds = std::collections::HashMap::new();
    for o in &scene.objects[first..] {
        let bounds = *mesh_bounds
            .entry(std::sync::Arc::as_ptr(&o.mesh))
            .or_insert_with(|| o.mesh.bounds());
        if let Some(b) = bounds {
            b.check_placed_by(&o.transform, field)?;
        }
    }
    Ok(())
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
                format!("must be finite and non-zero, got {}", super::short3(scale)),
            ));
        }
        Ok(DMat4::from_translation(DVec3::from(self.translate))
            * DMat4::from_rotation_y(self.rotate_y_deg.to_radians())
            * DMat4::from_scale(scale))
    }
}

impl MotionSpec {
    fn to_motion(&self, field: &str, is_spot: bool) -> Result<Motion, SceneError> {
        let orbit = match &self.orbit {
            None => None,
            Some(o) => Some(Orbit {
                about: match (o.center, o.radius) {
                    (Some(c), None) => OrbitAbout::Point(DVec3::from(c)),
                    (None, Some(r)) => OrbitAbout::Radius(r),
                    _ => {
                        return Err(SceneError::invalid(
                            format!("{field}.orbit"),
                            "needs exactly one of `center` (go round a point) or `radius` \
                             (a circle through the light)",
                        ))
                    }
                },
                axis: DVec3::from(o.axis),
                period_s: o.period_s,
                phase_deg: o.phase_deg,
            }),
        };
        let motion = Motion {
            orbit,
            bob: self.bob.as_ref().map(|b| Bob {
                amplitude: DVec3::from(b.amplitude),
                period_s: b.period_s,
                phase_deg: b.phase_deg,
            }),
            wander: self.wander.as_ref().map(|w| Wander {
                radius: w.radius,
                period_s: w.period_s,
                seed: w.seed,
            }),
            flicker: self
                .flicker
                .as_ref()
                .map(|f| {
                    Ok::<_, SceneError>(Flicker {
                        amount: narrow(&format!("{field}.flicker.amount"), f.amount)?,
                        rate_hz: f.rate_hz,
                        seed: f.seed,
                    })
                })
                .transpose()?,
            sweep: self.sweep.as_ref().map(|s| Sweep {
                axis: DVec3::from(s.axis),
                angle_deg: s.angle_deg,
                period_s: s.period_s,
                phase_deg: s.phase_deg,
            }),
        };
        motion.validate(field, is_spot)?;
        Ok(motion)
    }
}

impl CameraSpec {
    fn to_camera(&self) -> Result<Camera, SceneError> {
        // The other projection's field would be ignored without a word, as a light's cone on
        // a point light would: an error, as that is.
        let (stray, wanted, article) = match self.projection {
            ProjectionKind::Perspective => (self.height.map(|_| "height"), "orthographic", "an"),
            ProjectionKind::Orthographic => {
                (self.fov_y_deg.map(|_| "fov_y_deg"), "perspective", "a")
            }
        };
        if let Some(name) = stray {
            return Err(SceneError::invalid(
                format!("camera.{name}"),
                format!("only {article} {wanted} camera has one; use \"projection\": \"{wanted}\""),
            ));
        }
        let near = self.near.unwrap_or(0.1);
        let far = self.far.unwrap_or(1000.0);
        Ok(Camera {
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
        })
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
            radius: narrow(&format!("{field}.radius"), self.radius)?,
            color: narrow3(&format!("{field}.color"), self.color)?,
            intensity: narrow(&format!("{field}.intensity"), self.intensity)?,
        };
        light.validate(field)?;
        Ok(light)
    }
}

#[cfg(test)]
mod tests;
