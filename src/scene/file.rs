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
mod map_only;
mod spec;
pub use json_size::MAX_SCENE_FILE_CONTAINERS;

use std::path::Path;

use glam::DMat4;

use super::access::LoadOptions;
use super::camera::{Camera, MAX_CAMERA_COORD};
use super::material::check_color_factor;
use super::model_cache::{self, ModelCache};
use super::random::{self, LightSetStyle};
use super::{LoadReport, MaterialModel, Scene, SceneError, Short};
use spec::{narrow3, LightKindSpec, ObjectSpec, SceneFile};

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
    let in_file = |error| SceneError::in_scene_file(origin, error);
    let (mut scene, report) = build(&file, base_dir, options).map_err(in_file)?;
    let motion = file.random_lights.as_ref().and_then(|r| r.motion.as_ref());
    // A set's sweep moves its spots only.
    let motion = motion
        .map(|m| m.to_motion("random_lights.motion", true))
        .transpose()
        .map_err(in_file)?;
    // The command line's count is not the file's: its errors name `lights` alone.
    match (random_override, &file.random_lights) {
        // Nothing to place them in: the file is refused below for that.
        _ if scene.objects.is_empty() => {}
        (Some((count, seed)), _) => add_random_lights(&mut scene, count, seed, "lights", motion)?,
        (None, Some(r)) => {
            add_random_lights(&mut scene, r.count, r.seed, "random_lights.count", motion)
                .map_err(in_file)?
        }
        (None, None) => {}
    }
    scene.validate().map_err(in_file)?;
    // As for a glTF file alone: a picture of the background only is refused, not drawn black.
    if scene.objects.is_empty() {
        return Err(in_file(SceneError::invalid(
            "objects",
            "nothing to draw: no object places a triangle mesh",
        )));
    }
    Ok((scene, report))
}

/// The scene the file's objects, lights, ambient and camera make, before its random lights.
fn build(
    file: &SceneFile,
    base_dir: &Path,
    options: &LoadOptions,
) -> Result<(Scene, LoadReport), SceneError> {
    // Past the count limit, that limit's error names the object at fault.
    let count = file.objects.len();
    if count <= super::MAX_SCENE_OBJECTS {
        let placing = count as u64 * OBJECT_BYTES;
        super::alloc_probe::ask(placing, format_args!("placing its {count} objects takes"))
            .map_err(|reason| SceneError::invalid("objects", reason))?;
    }
    let mut scene = Scene::empty();
    // The file's own lights first, so that a light's index in the scene is its index in the
    // file (errors name it, some at frame time); the objects' glTF lights follow.
    add_lights(&mut scene, file)?;
    let mut report = LoadReport::default();
    let mut models = ModelCache::new(*options);
    let mut meshes = model_cache::MeshCount::default();
    let mut model_camera = None;
    for (i, spec) in file.objects.iter().enumerate() {
        let field = format!("objects[{i}]");
        let placed = Placing {
            spec,
            field: &field,
            base_dir,
        };
        if let Some(camera) = placed.place(&mut scene, &mut models, &mut report)? {
            model_camera.get_or_insert(camera);
        }
        model_cache::check_budget(&scene, &mut meshes, &field)?;
    }
    if let Some(a) = file.ambient {
        scene.ambient = narrow3("ambient", a)?;
    }
    scene.camera = match (&file.camera, model_camera) {
        (Some(c), _) => c.to_camera()?,
        (None, Some(c)) if file.objects.len() == 1 => c,
        _ => framing_camera(&mut scene)?,
    };
    Ok((scene, report))
}

/// One entry of the file's `objects`, named `field` in errors, its paths relative to
/// `base_dir`.
struct Placing<'a> {
    spec: &'a ObjectSpec,
    field: &'a str,
    base_dir: &'a Path,
}

impl Placing<'_> {
    /// Adds the object's meshes and materials to `scene`, recoloured as the entry says;
    /// returns the camera its model brings (a built-in's, or a glTF file's), if any.
    fn place(
        &self,
        scene: &mut Scene,
        models: &mut ModelCache,
        report: &mut LoadReport,
    ) -> Result<Option<Camera>, SceneError> {
        let (spec, field) = (self.spec, self.field);
        let transform = spec
            .transform
            .as_ref()
            .map_or(Ok(DMat4::IDENTITY), |t| t.matrix(field))?;
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
        let only_obj_textured = || {
            SceneError::invalid(
                format!("{field}.texture"),
                "only OBJ objects take a texture",
            )
        };
        let transform_field = format!("{field}.transform");
        let camera = match (&spec.builtin, &spec.obj, &spec.gltf) {
            (Some(name), None, None) => {
                let camera =
                    models
                        .builtin_camera(name)
                        .ok_or_else(|| SceneError::UnknownBuiltin {
                            name: name.clone(),
                            available: super::builtin::NAMES,
                        })?;
                if spec.texture.is_some() {
                    return Err(only_obj_textured());
                }
                models.place_builtin(scene, name, transform, recolour);
                // Carried with the scene, as a glTF's camera is by its transform; a transform
                // that distorts (or none valid) leaves the view to the framing.
                camera.placed_by(&transform)
            }
            (None, Some(obj_path), None) => {
                let tex = spec.texture.as_ref().map(|t| self.base_dir.join(t));
                let r = models.place_obj(
                    scene,
                    &self.base_dir.join(obj_path),
                    transform,
                    tex.as_deref(),
                    recolour,
                    &transform_field,
                )?;
                report.warnings.extend(r.warnings);
                None
            }
            (None, None, Some(gltf_path)) => {
                if spec.texture.is_some() {
                    return Err(only_obj_textured());
                }
                let (model_report, camera) = models.place_gltf(
                    scene,
                    &self.base_dir.join(gltf_path),
                    transform,
                    recolour,
                    &transform_field,
                )?;
                report.warnings.extend(model_report.warnings);
                if scene.objects.len() == first_object {
                    // A light rig is fine here (on its own, `--scene` refuses it).
                    let msg = format!(
                        "{field}: {} has nothing to draw: only its lights are used",
                        gltf_path.display()
                    );
                    report.say(msg);
                }
                camera
            }
            _ => {
                return Err(SceneError::invalid(
                    field,
                    "needs exactly one of `builtin`, `obj` or `gltf`",
                ))
            }
        };
        check_placed(scene, first_object, field)?;
        self.recolour(&mut scene.materials[first_material..])?;
        Ok(camera)
    }

    /// Applies the entry's `color`, `metallic` and `roughness` to `materials` (its object's
    /// own copies).
    fn recolour(&self, materials: &mut [super::Material]) -> Result<(), SceneError> {
        let (spec, field) = (self.spec, self.field);
        if let Some(c) = spec.color {
            let c = narrow3(&format!("{field}.color"), c)?;
            // Checked here, where the file's field is known (the materials' own check names them).
            check_color_factor(c, field, "color")?;
            for m in materials.iter_mut() {
                m.diffuse = c;
            }
        }
        if spec.metallic.is_none() && spec.roughness.is_none() {
            return Ok(());
        }
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
        for m in materials {
            m.model = MaterialModel::MetallicRoughness;
            (m.metallic, m.roughness) = (metallic, roughness);
        }
        Ok(())
    }
}

/// The file's `lights`, with their motions, and its `directional_lights`.
fn add_lights(scene: &mut Scene, file: &SceneFile) -> Result<(), SceneError> {
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
        let light = d.to_light(&format!("directional_lights[{i}]"))?;
        scene.directional_lights.push(light);
    }
    Ok(())
}

/// A camera framing all of `scene`'s objects, for a file that names none.
fn framing_camera(scene: &mut Scene) -> Result<Camera, SceneError> {
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
    Ok(scene.camera)
}

/// `count` random lights (`seed`) placed in the scene's bounds, each moving by its own
/// variation of `motion` if given; `field` names the count in errors.
fn add_random_lights(
    scene: &mut Scene,
    count: usize,
    seed: u64,
    field: &str,
    motion: Option<super::motion::Motion>,
) -> Result<(), SceneError> {
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
    let volume = scene
        .bounds()
        .ok_or_else(|| SceneError::invalid("random_lights", "needs geometry to place lights in"))?;
    let first = scene.lights.len();
    scene
        .lights
        .extend(random::lights(&volume, count, seed, LightSetStyle::Mixed));
    if let Some(motion) = motion {
        scene.animate_lights(first..scene.lights.len(), motion, seed);
    }
    Ok(())
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

#[cfg(test)]
mod tests;
