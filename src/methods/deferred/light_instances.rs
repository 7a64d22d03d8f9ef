//! Deferred's lights as instances of their proxy: each light four `vec4`s in the layout of
//! `glsl/deferred_light_instance.glsl`, three in a variant without spots (the spot terms come
//! last), uploaded and drawn together, so a light costs its 64 or 48 bytes and no GL call of
//! its own. A still frame draws the instances the last frame uploaded.

use glam::Vec4;

use crate::cluster::pack::shader_spot_terms;
use crate::cluster::view_light::GpuLight;
use crate::gl::instances::InstanceStream;
use crate::gl::mesh::BoundMesh;
use crate::gl::{Device, GlError};
use crate::methods::features::pre_exposed;

/// The first of the instance attributes' locations (`layout(location = 6)` onwards in
/// `glsl/deferred_light_instance.glsl`), after the meshes' 0 to 5.
const LIGHT_LOCATION: u32 = 6;

/// `vec4`s a light takes at most: with spots; without, the last is left out.
const LIGHT_VEC4S: usize = 4;

/// `vec4`s a light takes in a variant with spots (`spots`) or without.
pub(super) fn light_vec4s(spots: bool) -> usize {
    if spots {
        LIGHT_VEC4S
    } else {
        LIGHT_VEC4S - 1
    }
}

/// Lights a draw takes at most, and a proxy kind's buffer holds: it grows with its lights up to
/// 65 536 of them, 4 MiB, however many the scene has. A kind with more streams them a batch of
/// this many at a time, so its still frames upload them again.
const BATCH_LIGHTS: usize = 1 << 16;

/// A light as its proxy's instance draws it: position and radius; radiance (times the
/// accumulation's `scale`) and spot scale; the proxy sphere's radius, the count channel (0 to
/// 3) it adds 1 to and the full-screen triangle's depth (`proxy`: radius and depth); spot
/// axis and offset.
pub(super) fn light_instance(
    light: &GpuLight,
    [proxy_radius, depth]: [f32; 2],
    channel: usize,
    scale: f32,
) -> [Vec4; LIGHT_VEC4S] {
    let (direction, spot_scale, spot_offset) = shader_spot_terms(light);
    [
        light.position.extend(light.radius),
        pre_exposed(light.radiance, scale).extend(spot_scale),
        Vec4::new(proxy_radius, channel as f32, depth, 0.0),
        direction.extend(spot_offset),
    ]
}

/// Proxies a light pass draws with, each from its own stream (`proxy::Proxy::ALL`).
pub(super) const PROXIES: usize = super::proxy::Proxy::ALL.len();

/// A stream of instances for each proxy and the batch being filled (kept between frames, so a
/// frame with no more lights than one before allocates nothing). A proxy whose lights fit one
/// batch keeps them in its stream, so a still frame draws them again without uploading.
#[derive(Default)]
pub(super) struct LightInstances {
    streams: [Option<InstanceStream>; PROXIES],
    batch: Vec<[f32; 4]>,
    /// Per proxy: how many lights its stream holds from its last draw, when that was all of
    /// them (none is 0); `None` when they took more than a batch or were never drawn.
    held: [Option<usize>; PROXIES],
    /// Per proxy: light passes in a row that gave it no lights. At
    /// [`SHRINK_AFTER`](crate::gl::texture::SHRINK_AFTER) its stream is freed, so one that a
    /// burst of lights grew does not keep its store for good (its draws shrink it otherwise).
    empty_passes: [u32; PROXIES],
}

impl LightInstances {
    /// Gives back what a burst of lights grew the batch buffer to (each draw fills it afresh;
    /// the streams shrink themselves).
    pub(super) fn fit_buffers(&mut self) {
        crate::cluster::headroom::fit_empty(&mut self.batch);
    }

    /// Draws `mesh` (its arrays bound, with the light program) once for each light, in their
    /// order, a batch at a time, through `proxy`'s stream (made on its first lights, and anew
    /// for another layout), each light its first `vec4s` (see [`light_vec4s`]); returns the
    /// bytes uploaded.
    pub(super) fn draw(
        &mut self,
        dev: &Device,
        proxy: usize,
        mesh: &BoundMesh,
        vec4s: usize,
        lights: impl Iterator<Item = [Vec4; LIGHT_VEC4S]>,
    ) -> Result<usize, GlError> {
        self.held[proxy] = None;
        self.empty_passes[proxy] = 0;
        if let Some(mut other) = self.streams[proxy].take_if(|s| s.attributes() != vec4s) {
            other.destroy(dev);
        }
        let stream = match &mut self.streams[proxy] {
            Some(stream) => stream,
            empty => empty.insert(InstanceStream::new(
                dev,
                LIGHT_LOCATION,
                vec4s,
                BATCH_LIGHTS,
            )?),
        };
        stream.bind(dev);
        self.batch.clear();
        let (mut uploaded, mut drawn) = (0, 0);
        for light in lights {
            self.batch
                .extend(light[..vec4s].iter().map(|v| v.to_array()));
            drawn += 1;
            if self.batch.len() == BATCH_LIGHTS * vec4s {
                uploaded += stream.draw(dev, mesh, &self.batch);
                self.batch.clear();
            }
        }
        uploaded += stream.draw(dev, mesh, &self.batch);
        stream.unbind(dev);
        self.held[proxy] = (drawn <= BATCH_LIGHTS).then_some(drawn);
        Ok(uploaded)
    }

    /// Records that `proxy` has no lights this frame, freeing its stream after
    /// [`SHRINK_AFTER`](crate::gl::texture::SHRINK_AFTER) such frames in a row.
    pub(super) fn draw_none(&mut self, dev: &Device, proxy: usize) {
        self.held[proxy] = Some(0);
        self.empty_passes[proxy] = self.empty_passes[proxy].saturating_add(1);
        if self.empty_passes[proxy] == crate::gl::texture::SHRINK_AFTER {
            if let Some(mut stream) = self.streams[proxy].take() {
                stream.destroy(dev);
            }
        }
    }

    /// Whether every proxy's stream holds all its lights of the last light pass.
    pub(super) fn hold_all(&self) -> bool {
        self.held.iter().all(Option::is_some)
    }

    /// Counts a still frame for each stream that holds lights to draw again: true when one has
    /// held a quarter of its store at most for
    /// [`SHRINK_AFTER`](crate::gl::texture::SHRINK_AFTER) frames, so the frame should draw its
    /// lights anew, which shrinks it (a still scene after a burst of lights uploads nothing).
    pub(super) fn note_still_frame(&mut self) -> bool {
        let mut due = false;
        for (stream, held) in self.streams.iter_mut().zip(self.held) {
            if let (Some(stream), Some(1..)) = (stream, held) {
                due |= stream.note_still_frame();
            }
        }
        due
    }

    /// Lights `proxy`'s stream holds from the last light pass, when it holds them all.
    pub(super) fn held(&self, proxy: usize) -> Option<usize> {
        self.held[proxy]
    }

    /// Draws `mesh` once for each light `proxy`'s stream holds (see [`Self::held`]), uploading
    /// nothing.
    pub(super) fn draw_held(&self, dev: &Device, proxy: usize, mesh: &BoundMesh) {
        if let (Some(stream), Some(count @ 1..)) = (&self.streams[proxy], self.held[proxy]) {
            stream.bind(dev);
            stream.draw_held(dev, mesh, count);
            stream.unbind(dev);
        }
    }

    pub(super) fn gpu_bytes(&self) -> usize {
        self.streams
            .iter()
            .flatten()
            .map(InstanceStream::bytes)
            .sum()
    }

    pub(super) fn destroy(&mut self, dev: &Device) {
        for stream in &mut self.streams {
            if let Some(mut stream) = stream.take() {
                stream.destroy(dev);
            }
        }
        self.held = [None; PROXIES];
    }
}
