//! Deferred's lights as instances of their proxy: each light four `vec4`s in the layout of
//! `glsl/deferred_light_instance.glsl`, drawn a batch at a time, so a light costs its 64 bytes
//! and no GL call of its own.

use glam::Vec4;

use crate::cluster::view_light::GpuLight;
use crate::gl::instances::InstanceStream;
use crate::gl::mesh::BoundMesh;
use crate::gl::{Device, GlError};

/// The first of the instance attributes' locations (`layout(location = 5)` onwards in
/// `glsl/deferred_light_instance.glsl`), after the meshes' 0 to 4.
const LIGHT_LOCATION: u32 = 5;

/// `vec4`s a light takes.
const LIGHT_VEC4S: usize = 4;

/// Lights a draw takes at most: the buffer grows with the scene's lights up to 4 096 of them,
/// 256 KiB, however many the scene has.
const BATCH_LIGHTS: usize = 4096;

/// `vec4`s a full batch holds.
const BATCH_VEC4S: usize = BATCH_LIGHTS * LIGHT_VEC4S;

/// A light as its proxy's instance draws it: position and radius; radiance (times the
/// accumulation's `scale`) and spot scale; spot axis and offset; the proxy sphere's radius and
/// the count channel (0 to 3) it adds 1 to.
pub(super) fn light_instance(
    light: &GpuLight,
    proxy_radius: f32,
    channel: usize,
    scale: f32,
) -> [Vec4; LIGHT_VEC4S] {
    [
        light.position.extend(light.radius),
        (light.radiance * scale).extend(light.spot_scale),
        light.direction.extend(light.spot_offset),
        Vec4::new(proxy_radius, channel as f32, 0.0, 0.0),
    ]
}

/// The instance buffer and the batch being filled (kept between frames: a frame allocates
/// nothing).
pub(super) struct LightInstances {
    stream: InstanceStream,
    batch: Vec<[f32; 4]>,
}

impl LightInstances {
    pub(super) fn new(dev: &Device) -> Result<LightInstances, GlError> {
        Ok(LightInstances {
            stream: InstanceStream::new(dev, LIGHT_LOCATION, LIGHT_VEC4S, BATCH_LIGHTS)?,
            batch: Vec::with_capacity(BATCH_VEC4S),
        })
    }

    /// Draws `mesh` (its arrays bound, with the light program) once for each light, in their
    /// order, a batch at a time; returns the bytes uploaded.
    pub(super) fn draw(
        &mut self,
        dev: &Device,
        mesh: &BoundMesh,
        lights: impl Iterator<Item = [Vec4; LIGHT_VEC4S]>,
    ) -> usize {
        self.stream.bind(dev);
        self.batch.clear();
        let mut uploaded = 0;
        for light in lights {
            self.batch.extend(light.map(|v| v.to_array()));
            if self.batch.len() == BATCH_VEC4S {
                uploaded += self.stream.draw(dev, mesh, &self.batch);
                self.batch.clear();
            }
        }
        uploaded += self.stream.draw(dev, mesh, &self.batch);
        self.stream.unbind(dev);
        uploaded
    }

    pub(super) fn gpu_bytes(&self) -> usize {
        self.stream.bytes()
    }

    pub(super) fn destroy(&mut self, dev: &Device) {
        self.stream.destroy(dev);
    }
}
