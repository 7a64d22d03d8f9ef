//! A file's lights and camera as its nodes instance them, kept in the file's own space so that
//! a placing transform puts them in the world: at the file's load, and again for each later
//! reference a scene file makes to it, without reading the file again.

use glam::DMat4;

use super::fault::Fault;
use super::{camera, lights};
use crate::scene::{Camera, DirectionalLight, Light};

/// The nodes whose light, or whose camera, is valid in the file's own space, with their
/// transforms there.
#[derive(Default)]
pub(crate) struct Instances {
    /// Nodes instancing a light, in node order.
    lights: Vec<(usize, DMat4)>,
    /// The first node instancing a camera, when that camera is valid.
    camera: Option<(usize, DMat4)>,
}

/// A file's instances with the document they are read from: what placing the file again
/// needs of it.
pub(crate) struct Instanced {
    pub(super) document: gltf::Document,
    pub(super) instances: Instances,
}

impl Instanced {
    /// [`Instances::place`].
    pub(super) fn place(&self, transform: DMat4) -> Result<Placed, Fault> {
        self.instances.place(&self.document, transform)
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

/// What messages call node `node`'s light.
fn light_field(node: usize, light: usize) -> String {
    format!("nodes[{node}] (extensions.KHR_lights_punctual.lights[{light}])")
}

/// What messages call node `node`'s camera.
fn camera_field(node: usize, camera: usize) -> String {
    format!("nodes[{node}] (cameras[{camera}])")
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
        let field = light_field(node, light.index());
        match lights::convert(light, &world, &field)? {
            lights::Converted::Skipped(why) => warnings.push(why),
            _ => self.lights.push((node, world)),
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
        let field = camera_field(node, cam.index());
        match camera::convert(document, cam, &world, &field) {
            Ok(_) => self.camera = Some((node, world)),
            Err(e) => warnings.push(unused_camera(&e)),
        }
    }

    /// The lights and camera placed by `transform` (the file's `document`, as checked): a
    /// light it puts out of range is a fault of the placing, a camera it does that to is left
    /// out with a warning.
    pub(super) fn place(
        &self,
        document: &gltf::Document,
        transform: DMat4,
    ) -> Result<Placed, Fault> {
        let mut placed = Placed::default();
        let nodes = || document.nodes();
        for &(node, world) in &self.lights {
            let Some(light) = nodes().nth(node).and_then(|n| n.light()) else {
                continue;
            };
            let field = light_field(node, light.index());
            let converted = lights::convert(&light, &(transform * world), &field)
                .map_err(|e| Fault::Placing(format!("placing nodes[{node}]: {e}")))?;
            match converted {
                lights::Converted::Light(l) => placed.lights.push(l),
                lights::Converted::Directional(l) => placed.directional_lights.push(l),
                lights::Converted::Skipped(why) => placed.warnings.push(why),
            }
        }
        if let Some((node, world)) = self.camera {
            if let Some(cam) = nodes().nth(node).and_then(|n| n.camera()) {
                let field = camera_field(node, cam.index());
                match camera::convert(document, &cam, &(transform * world), &field) {
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
