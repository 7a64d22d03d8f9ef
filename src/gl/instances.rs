//! Per-instance vertex attributes streamed each frame (ES 3.0 instanced drawing): a buffer of
//! instances, each a few `vec4`s read at consecutive attribute locations, refilled batch by
//! batch. Deferred draws its light proxies this way, one instance a light.
#![allow(unsafe_code)]

use glam::Vec4;
use glow::HasContext;

use super::mesh::BoundMesh;
use super::{Device, GlError};

/// A stream of instances of `attributes` `vec4`s at locations `first..first + attributes`,
/// at most `capacity` a draw. Its store holds the largest batch drawn so far (a power of two
/// of instances, at most `capacity`), so a scene of a few lights holds a few kilobytes, until
/// [`SHRINK_AFTER`](super::texture::SHRINK_AFTER) batches or still frames in a row fill a
/// quarter of it at most (a burst of lights does not hold its memory); each batch orphans it
/// (so the driver need not wait for the previous draw) and writes it anew.
pub(crate) struct InstanceStream {
    buffer: glow::Buffer,
    first: u32,
    attributes: usize,
    capacity: usize,
    /// Instances the store holds.
    store: usize,
    /// Instances the last batch needed: its count's next power of two, within the bounds.
    needed: usize,
    /// Batches and still frames ([`InstanceStream::note_still_frame`]) in a row whose
    /// instances filled a quarter of the store at most.
    small_batches: super::shrink::SmallFrames,
    destroyed: bool,
}

/// Instances a new stream's store holds.
const FIRST_STORE: usize = 64;

impl InstanceStream {
    /// A stream of at most `capacity` instances a draw.
    pub(crate) fn new(
        dev: &Device,
        first: u32,
        attributes: usize,
        capacity: usize,
    ) -> Result<InstanceStream, GlError> {
        let buffer = dev.create_buffer()?;
        let mut stream = InstanceStream {
            buffer,
            first,
            attributes,
            capacity,
            store: FIRST_STORE.min(capacity),
            needed: 0,
            small_batches: Default::default(),
            destroyed: false,
        };
        unsafe {
            dev.gl.bind_buffer(glow::ARRAY_BUFFER, Some(buffer));
            dev.gl
                .buffer_data_size(glow::ARRAY_BUFFER, stream.bytes() as i32, glow::STREAM_DRAW);
        }
        if let Err(e) = dev.check("instance buffer") {
            stream.destroy(dev);
            return Err(e);
        }
        Ok(stream)
    }

    /// `vec4` attributes an instance has.
    pub(crate) fn attributes(&self) -> usize {
        self.attributes
    }

    /// Bytes of its buffer.
    pub(crate) fn bytes(&self) -> usize {
        self.store * self.attributes * std::mem::size_of::<Vec4>()
    }

    /// Points its locations into the buffer, one step an instance (with a mesh's arrays
    /// bound for the vertices); [`InstanceStream::unbind`] undoes it.
    pub(crate) fn bind(&self, dev: &Device) {
        let stride = (self.attributes * std::mem::size_of::<Vec4>()) as i32;
        unsafe {
            dev.gl.bind_buffer(glow::ARRAY_BUFFER, Some(self.buffer));
            for (i, location) in self.locations().enumerate() {
                dev.gl.enable_vertex_attrib_array(location);
                let offset = (i * std::mem::size_of::<Vec4>()) as i32;
                dev.gl
                    .vertex_attrib_pointer_f32(location, 4, glow::FLOAT, false, stride, offset);
                dev.gl.vertex_attrib_divisor(location, 1);
            }
        }
    }

    /// Draws `mesh` once per instance of `instances` (`attributes` `vec4`s each, at most
    /// `capacity` instances), with the stream bound. Returns the bytes uploaded.
    pub(crate) fn draw(&mut self, dev: &Device, mesh: &BoundMesh, instances: &[[f32; 4]]) -> usize {
        let count = instances.len() / self.attributes;
        debug_assert!(count <= self.capacity && instances.len().is_multiple_of(self.attributes));
        if count == 0 {
            return 0;
        }
        let bytes: &[u8] = bytemuck::cast_slice(instances);
        self.needed = count
            .next_power_of_two()
            .max(FIRST_STORE)
            .min(self.capacity);
        if count > self.store || self.small_batches.note(self.needed, self.store) {
            // The orphaning below allocates the store anew at its size either way.
            self.store = self.needed;
            self.small_batches.reset();
        }
        unsafe {
            dev.gl
                .buffer_data_size(glow::ARRAY_BUFFER, self.bytes() as i32, glow::STREAM_DRAW);
            dev.gl
                .buffer_sub_data_u8_slice(glow::ARRAY_BUFFER, 0, bytes);
        }
        mesh.draw_instanced(dev, count as i32);
        bytes.len()
    }

    /// Draws `mesh` once per instance of the last [`InstanceStream::draw`], `count` of them
    /// (with the stream bound), uploading nothing: the store still holds them.
    pub(crate) fn draw_held(&self, dev: &Device, mesh: &BoundMesh, count: usize) {
        debug_assert!(count <= self.store);
        mesh.draw_instanced(dev, count as i32);
    }

    /// Counts a frame that draws the last batch again ([`InstanceStream::draw_held`]), as a
    /// batch counts: true once its instances have filled a quarter of the store at most for
    /// [`SHRINK_AFTER`](super::texture::SHRINK_AFTER) frames, when drawing them again with
    /// [`InstanceStream::draw`] allocates the store at their size.
    pub(crate) fn note_still_frame(&mut self) -> bool {
        self.small_batches.note(self.needed, self.store)
    }

    /// Leaves its locations as every other draw expects them: no array, divisor 0.
    pub(crate) fn unbind(&self, dev: &Device) {
        for location in self.locations() {
            unsafe {
                dev.gl.vertex_attrib_divisor(location, 0);
                dev.gl.disable_vertex_attrib_array(location);
            }
        }
    }

    fn locations(&self) -> impl Iterator<Item = u32> {
        self.first..self.first + self.attributes as u32
    }

    /// Frees the buffer.
    pub(crate) fn destroy(&mut self, dev: &Device) {
        if !self.destroyed {
            dev.delete_buffer(self.buffer);
            self.destroyed = true;
        }
    }
}

impl Drop for InstanceStream {
    fn drop(&mut self) {
        if !self.destroyed && !super::left_objects::left_on_purpose() {
            log::warn!("InstanceStream dropped without destroy(): a GL buffer leaked");
        }
    }
}
