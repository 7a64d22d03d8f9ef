//! GL-free scene description: camera, lights, meshes, materials, OBJ loading, built-in
//! procedural scenes, seeded random lights and JSON scene files.
//!
//! Positions that can be far from the origin (camera, lights, object transforms) are `f64`;
//! the renderer subtracts the camera in `f64` before anything reaches the GPU as `f32`, so a
//! scene 10 km from the origin loses no precision on the device.

pub mod builtin;
pub mod camera;
pub mod error;
pub mod features;
pub mod file;
pub mod input;
pub mod light;
pub mod material;
pub mod mesh;
pub mod meshbuild;
pub mod obj;
pub mod random;
pub mod shading;

use std::sync::Arc;

use glam::{DMat4, DVec3, Vec3};

pub use camera::{Camera, Projection};
pub use error::SceneError;
pub use light::{Light, LightKind};
pub use material::{Material, Texture};
pub use mesh::{Aabb, Mesh};

/// One placed mesh: shared geometry, its material and a model transform (`f64`, so objects
/// can be placed far from the origin).
#[derive(Clone, Debug)]
pub struct Object {
    /// Geometry in object space.
    pub mesh: Arc<Mesh>,
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// Object space → world space.
    pub transform: DMat4,
}

/// Everything one frame needs: geometry, materials, lights, ambient light and the camera.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Placed meshes.
    pub objects: Vec<Object>,
    /// Materials referenced by [`Object::material`].
    pub materials: Vec<Material>,
    /// Point and spot lights (validated with [`Scene::validate`] before rendering).
    pub lights: Vec<Light>,
    /// Ambient radiance in linear RGB, multiplied by the albedo.
    pub ambient: Vec3,
    /// The viewpoint.
    pub camera: Camera,
}

impl Scene {
    /// An empty scene with a default camera and a dim ambient term.
    pub fn empty() -> Self {
        Scene {
            objects: Vec::new(),
            materials: Vec::new(),
            lights: Vec::new(),
            ambient: Vec3::splat(0.02),
            camera: Camera::default(),
        }
    }

    /// World-space bounds of all objects (`None` for a scene without geometry).
    pub fn bounds(&self) -> Option<Aabb> {
        self.objects
            .iter()
            .filter_map(|o| o.mesh.bounds().map(|b| b.transformed(&o.transform)))
            .reduce(|a, b| a.union(&b))
    }

    /// Adds a material and returns its index.
    pub fn add_material(&mut self, material: Material) -> usize {
        self.materials.push(material);
        self.materials.len() - 1
    }

    /// Checks every value the GPU will see: lights (finite, non-negative radius, valid cones),
    /// ambient colour, camera, material indices and material values. Errors name the field.
    pub fn validate(&self) -> Result<(), SceneError> {
        self.camera.validate()?;
        if !self.ambient.is_finite() || self.ambient.min_element() < 0.0 {
            return Err(SceneError::invalid(
                "ambient",
                format!("must be finite and >= 0, got {:?}", self.ambient),
            ));
        }
        for (i, light) in self.lights.iter().enumerate() {
            light.validate(&format!("lights[{i}]"))?;
        }
        for (i, m) in self.materials.iter().enumerate() {
            m.validate(&format!("materials[{i}] ({})", m.name))?;
        }
        for (i, o) in self.objects.iter().enumerate() {
            if o.material >= self.materials.len() {
                return Err(SceneError::invalid(
                    format!("objects[{i}].material"),
                    format!(
                        "index {} but the scene has {} materials",
                        o.material,
                        self.materials.len()
                    ),
                ));
            }
            if !o.transform.is_finite() {
                return Err(SceneError::invalid(
                    format!("objects[{i}].transform"),
                    "must be finite",
                ));
            }
        }
        Ok(())
    }

    /// Points the camera at the scene bounds from a pleasant three-quarter view.
    pub fn frame_camera(&mut self) {
        if let Some(b) = self.bounds() {
            let c = b.center();
            let extent = b.size().length().max(1e-3);
            let dir = DVec3::new(0.55, 0.45, 1.0).normalize();
            self.camera = Camera::perspective(
                c + dir * extent * 0.95,
                c,
                55.0,
                extent * 1e-3,
                extent * 4.0,
            );
        }
    }
}

/// Loads what the CLI's `--scene` names: a built-in name, an `.obj` file (camera framed on its
/// bounds) or a `.json` scene file. `lights` = `Some((count, seed))` sets seeded random lights
/// (for scene files, it replaces their `random_lights` count but keeps explicit lights).
pub fn load(
    spec: &str,
    lights: Option<(usize, u64)>,
) -> Result<(Scene, obj::LoadReport), SceneError> {
    let path = std::path::Path::new(spec);
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "obj" => {
            if let Some((count, _)) = lights {
                input::check_light_count(count, "lights")?;
            }
            let mut scene = Scene::empty();
            let report = obj::load_into(&mut scene, path, DMat4::IDENTITY, None)?;
            scene.frame_camera();
            if let (Some((count, seed)), Some(bounds)) = (lights, scene.bounds()) {
                // Around the model as well as inside it: lights inside a closed model light nothing.
                let volume = bounds.expanded(0.25);
                scene.lights = random::lights(&volume, count, seed, random::LightSetStyle::Mixed);
            }
            scene.validate()?;
            Ok((scene, report))
        }
        "json" => file::load(path, lights),
        _ => Ok((builtin::build(spec, lights)?, obj::LoadReport::default())),
    }
}
