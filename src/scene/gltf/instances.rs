//! A file's lights and camera as its nodes instance them, kept in the file's own space so that
//! a placing transform puts them in the world: at the file's load, and again for each later
//! reference a scene file makes to it, without reading the file again.

use glam::DMat4;

use super::fault::Fault;
use super::{camera, ignored, lights};
use crate::scene::{Camera, DirectionalLight, Light};

/// One node's light or camera: the node, the light's or camera's index, and the node's
/// transform in the file's space.
#[derive(Clone, Copy)]
struct Instance {
    node: usize,
    index: usize,
    world: DMat4,
}

impl Instance {
    /// What messages call the node's light.
    fn light_field(&self) -> String {
        let Instance { node, index, .. } = self;
        format!("nodes[{node}] (extensions.KHR_lights_punctual.lights[{index}])")
    }

    /// What messages call the node's camera.
    fn camera_field(&self) -> String {
        let Instance { node, index, .. } = self;
        format!("nodes[{node}] (cameras[{index}])")
    }
}

/// The lights, and the first camera, valid in the file's own space that its nodes instance.
#[derive(Default)]
pub(crate) struct Instances {
    /// In node order.
    lights: Vec<Instance>,
    camera: Option<Instance>,
}

/// A file's instances with what placing them again needs of the file: its lights and cameras
/// alone (the rest of a parsed file may take hundreds of MB).
pub(crate) struct Instanced {
    definitions: gltf::Document,
    instances: Instances,
}

impl Instanced {
    /// Keeps `instances` with the light and camera definitions of `document`.
    pub(super) fn new(document: &gltf::Document, instances: Instances) -> Instanced {
        let json = document.as_json();
        let root = gltf::json::Root {
            // The root's extensions: the lights, and nothing large besides.
            extensions: json.extensions.clone(),
            cameras: json.cameras.clone(),
            ..Default::default()
        };
        Instanced {
            definitions: gltf::Document::from_json_without_validation(root),
            instances,
        }
    }

    /// Lights placing them adds at most (suns included).
    pub(crate) fn most_lights(&self) -> usize {
        self.instances.lights.len()
    }

    /// [`Instances::place`], its warnings said as a load says them (one line for many alike).
    pub(super) fn place(&self, transform: DMat4) -> Result<Placed, Fault> {
        let mut placed = self.instances.place(&self.definitions, transform)?;
        placed.warnings = ignored::once_per_feature(std::mem::take(&mut placed.warnings));
        Ok(placed)
    }
}

/// What placing [`Instances`] gave.
#[derive(Default)]
pub(crate) struct Placed {
    pub lights: Vec<Light>,
    pub directional_lights: Vec<DirectionalLight>,
    pub camera: Option<Camera>,
    /// Lights and a camera the placing transform leaves out, each said why.
    pub warnings: Vec<String>,
}

impl Instances {
    /// Whether any light or camera is instanced.
    pub(super) fn any(&self) -> bool {
        !self.lights.is_empty() || self.camera.is_some()
    }

    /// Checks node `node`'s light in the file's space (`world`) and keeps it to be placed: a
    /// fault there is the file's, a light it skips is said in `warnings`.
    pub(super) fn add_light(
        &mut self,
        light: &gltf::khr_lights_punctual::Light,
        node: usize,
        world: DMat4,
        warnings: &mut Vec<String>,
    ) -> Result<(), Fault> {
        let instance = Instance {
            node,
            index: light.index(),
            world,
        };
        match lights::convert(light, &world, &instance.light_field())? {
            lights::Converted::Skipped(why) => warnings.push(why),
            _ => self.lights.push(instance),
        }
        Ok(())
    }

    /// Checks the file's first camera (on node `node`) in the file's space and keeps it to be
    /// placed; one that is not valid there is said in `warnings` and not used.
    pub(super) fn add_camera(
        &mut self,
        document: &gltf::Document,
        cam: &gltf::Camera,
        node: usize,
        world: DMat4,
        warnings: &mut Vec<String>,
    ) {
        let instance = Instance {
            node,
            index: cam.index(),
            world,
        };
        match camera::convert(document, cam, &world, &instance.camera_field()) {
            Ok(_) => self.camera = Some(instance),
            Err(e) => warnings.push(unused_camera(&e)),
        }
    }

    /// The lights and camera placed by `transform`, their definitions read from `document`
    /// (the file's, or [`Instanced`]'s): a light it puts out of range is a fault of the
    /// placing, a camera it does that to is left out with a warning.
    pub(super) fn place(
        &self,
        document: &gltf::Document,
        transform: DMat4,
    ) -> Result<Placed, Fault> {
        let mut placed = Placed::default();
        for instance in &self.lights {
            let Some(light) = document.lights().and_then(|mut l| l.nth(instance.index)) else {
                continue;
            };
            let world = transform * instance.world;
            let converted = lights::convert(&light, &world, &instance.light_field())
                .map_err(|e| Fault::Placing(format!("placing nodes[{}]: {e}", instance.node)))?;
            match converted {
                lights::Converted::Light(l) => placed.lights.push(l),
                lights::Converted::Directional(l) => placed.directional_lights.push(l),
                lights::Converted::Skipped(why) => placed.warnings.push(why),
            }
        }
        if let Some(instance) = self.camera {
            if let Some(cam) = document.cameras().nth(instance.index) {
                let world = transform * instance.world;
                match camera::convert(document, &cam, &world, &instance.camera_field()) {
                    Ok(camera) => placed.camera = Some(camera),
                    Err(e) => placed.warnings.push(unused_camera(&format!("placing {e}"))),
                }
            }
        }
        Ok(placed)
    }
}

/// The warning for a camera the renderer cannot take (`why`).
fn unused_camera(why: &str) -> String {
    format!(
        "{why}; this camera is not used: without a scene file's camera, the view is framed on \
         the bounds"
    )
}
