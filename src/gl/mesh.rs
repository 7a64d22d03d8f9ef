//! GPU meshes. ES 2.0 core only has 16-bit indices (32-bit needs `OES_element_index_uint`), so
//! every mesh is split into chunks of at most 65 536 vertices with `u16` indices: one code
//! path that works on every device.
#![allow(unsafe_code)]

use std::collections::HashMap;

use glam::DVec3;
use glow::HasContext;

use super::absent_attributes::{ABSENT, ABSENT_BITS};
use super::uv_sets::UvSets;
use super::{Device, GlError};
use crate::scene::Mesh;

/// Floats per interleaved vertex every mesh has: position (3), normal (3).
pub const VERTEX_FLOATS: usize = 6;

/// Which optional attributes a mesh's vertices carry after the [`VERTEX_FLOATS`]: each is
/// uploaded only when the mesh has it (texture coordinates: 2 floats, colour: 4, tangent: 4,
/// the second texture coordinates: 2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct VertexLayout {
    /// `a_uv` (location 2).
    pub uvs: bool,
    /// `a_color` (location 3).
    pub colors: bool,
    /// `a_tangent` (location 4).
    pub tangents: bool,
    /// `a_uv1` (location 5).
    pub second_uvs: bool,
}

impl VertexLayout {
    /// The layout of `mesh`'s vertices, with the coordinate sets of `uv_sets` it has (those a
    /// texture reads).
    pub fn of(mesh: &Mesh, uv_sets: UvSets) -> VertexLayout {
        let uv_sets = uv_sets.on(mesh);
        VertexLayout {
            uvs: uv_sets.first,
            colors: !mesh.colors.is_empty(),
            tangents: !mesh.tangents.is_empty(),
            second_uvs: uv_sets.second,
        }
    }

    /// Floats per vertex.
    pub fn floats(self) -> usize {
        VERTEX_FLOATS
            + self
                .optional()
                .map(|(_, size)| size as usize)
                .sum::<usize>()
    }

    /// The optional attributes present, as bits of [`ABSENT`] (bit `i`: `ABSENT[i]`).
    fn absent_bits(self) -> u8 {
        let present = |loc| self.optional().any(|(l, _)| l == loc);
        (ABSENT.iter().enumerate())
            .filter(|(_, (loc, _))| present(*loc))
            .fold(0, |bits, (i, _)| bits | 1 << i)
    }

    /// (location, components) of the optional attributes present, in vertex order.
    fn optional(self) -> impl Iterator<Item = (u32, i32)> {
        [
            self.uvs.then_some((2, 2)),
            self.colors.then_some((3, 4)),
            self.tangents.then_some((4, 4)),
            self.second_uvs.then_some((5, 2)),
        ]
        .into_iter()
        .flatten()
    }

    /// (location, components, byte offset) of every attribute present.
    fn attributes(self) -> impl Iterator<Item = (u32, i32, i32)> {
        let mut at = (VERTEX_FLOATS * 4) as i32;
        let optional = self.optional().map(move |(loc, size)| {
            at += 4 * size;
            (loc, size, at - 4 * size)
        });
        [(0, 3, 0), (1, 3, 12)].into_iter().chain(optional)
    }
}

/// One chunk of a mesh, CPU side: interleaved vertices and 16-bit indices.
#[derive(Clone, Debug, PartialEq)]
pub struct Chunk {
    /// `layout.floats()` floats per vertex.
    pub vertices: Vec<f32>,
    /// Triangle list.
    pub indices: Vec<u16>,
    /// Which optional attributes follow the first [`VERTEX_FLOATS`].
    pub layout: VertexLayout,
}

/// Splits a mesh into chunks whose vertices fit 16-bit indices; triangles stay whole.
pub fn split_u16(mesh: &Mesh) -> Vec<Chunk> {
    split_u16_about(mesh, DVec3::ZERO, UvSets::ALL)
}

/// [`split_u16`] with `origin` subtracted from every position (in `f64`, before the vertex
/// becomes `f32`), and the coordinate sets of `uv_sets` only.
pub fn split_u16_about(mesh: &Mesh, origin: DVec3, uv_sets: UvSets) -> Vec<Chunk> {
    const LIMIT: usize = u16::MAX as usize + 1;
    let layout = VertexLayout::of(mesh, uv_sets);
    let floats = layout.floats();
    let mut chunks = Vec::new();
    let mut remap: HashMap<u32, u16> = HashMap::new();
    let mut cur = Chunk {
        vertices: Vec::new(),
        indices: Vec::new(),
        layout,
    };
    for tri in mesh.indices.chunks_exact(3) {
        let new_vertices = tri.iter().filter(|i| !remap.contains_key(i)).count();
        if remap.len() + new_vertices > LIMIT {
            chunks.push(std::mem::replace(
                &mut cur,
                Chunk {
                    vertices: Vec::new(),
                    indices: Vec::new(),
                    layout,
                },
            ));
            remap.clear();
        }
        for &i in tri {
            let local = *remap.entry(i).or_insert_with(|| {
                let v = i as usize;
                let p = (mesh.positions[v].as_dvec3() - origin).as_vec3();
                let n = mesh.normals[v];
                cur.vertices
                    .extend_from_slice(&[p.x, p.y, p.z, n.x, n.y, n.z]);
                if layout.uvs {
                    cur.vertices.extend_from_slice(&mesh.uvs[v].to_array());
                }
                if layout.colors {
                    cur.vertices.extend_from_slice(&mesh.colors[v].to_array());
                }
                if layout.tangents {
                    cur.vertices.extend_from_slice(&mesh.tangents[v].to_array());
                }
                if layout.second_uvs {
                    cur.vertices
                        .extend_from_slice(&mesh.second_uvs[v].to_array());
                }
                (cur.vertices.len() / floats - 1) as u16
            });
            cur.indices.push(local);
        }
    }
    if !cur.indices.is_empty() {
        chunks.push(cur);
    }
    chunks
}

struct GpuChunk {
    vbo: glow::Buffer,
    ibo: glow::Buffer,
    /// Its arrays, set once, where meshes have vertex arrays of their own
    /// ([`Device::mesh_vertex_arrays`]): a draw binds it instead of pointing five attributes.
    vao: Option<glow::VertexArray>,
    index_count: i32,
    layout: VertexLayout,
}

impl GpuChunk {
    /// Uploads `chunk`: its vertex array (where meshes have them) bound first, so that it
    /// takes the index buffer and the arrays. What it made is freed when it fails.
    fn upload(dev: &Device, chunk: &Chunk) -> Result<GpuChunk, GlError> {
        let vao = match dev.mesh_vertex_arrays() {
            true => Some(dev.create_mesh_vertex_array()?),
            false => None,
        };
        if let Some(vao) = vao {
            dev.bind_vertex_array(vao);
        }
        let vertices = bytemuck::cast_slice(&chunk.vertices);
        let indices = bytemuck::cast_slice(&chunk.indices);
        let vbo = static_buffer(dev, glow::ARRAY_BUFFER, vertices);
        let ibo = static_buffer(dev, glow::ELEMENT_ARRAY_BUFFER, indices);
        let (vbo, ibo) = match (vbo, ibo) {
            (Ok(vbo), Ok(ibo)) => (vbo, ibo),
            (vbo, ibo) => {
                for buffer in [&vbo, &ibo].into_iter().flatten() {
                    dev.delete_buffer(*buffer);
                }
                if let Some(vao) = vao {
                    dev.delete_mesh_vertex_array(vao);
                }
                return Err(vbo.and(ibo).expect_err("one failed"));
            }
        };
        let gpu = GpuChunk {
            vbo,
            ibo,
            vao,
            index_count: chunk.indices.len() as i32,
            layout: chunk.layout,
        };
        if vao.is_some() {
            // The vertex buffer is still bound; the arrays the mesh lacks stay disabled.
            gpu.point_arrays(dev);
        }
        Ok(gpu)
    }

    /// Binds the chunk's buffers and points the program's attributes into them, for as many
    /// draws as wanted.
    fn bind_arrays(&self, dev: &Device) -> BoundMesh {
        let gl = &dev.gl;
        if let Some(vao) = self.vao {
            dev.bind_vertex_array(vao);
        } else {
            unsafe {
                gl.bind_buffer(glow::ARRAY_BUFFER, Some(self.vbo));
                gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(self.ibo));
                // Optional attributes the mesh lacks read a constant instead of a stale array.
                for (loc, _) in ABSENT {
                    gl.disable_vertex_attrib_array(loc);
                }
            }
            self.point_arrays(dev);
            let calls = 2 + ABSENT.len() + 2 * self.layout.attributes().count();
            dev.count_state_call(|c| c.vertex_array_calls += calls as u64);
        }
        let arrays = self.layout.absent_bits();
        dev.set_absent_values(!arrays & ABSENT_BITS);
        dev.forget_absent_values(arrays);
        BoundMesh {
            index_count: self.index_count,
        }
    }

    /// Points the attributes the chunk has into its vertex buffer (bound to `ARRAY_BUFFER`).
    fn point_arrays(&self, dev: &Device) {
        let stride = (self.layout.floats() * 4) as i32;
        for (loc, size, offset) in self.layout.attributes() {
            unsafe {
                dev.gl.enable_vertex_attrib_array(loc);
                (dev.gl).vertex_attrib_pointer_f32(loc, size, glow::FLOAT, false, stride, offset);
            }
        }
    }

    fn destroy(&self, dev: &Device) {
        dev.delete_buffer(self.vbo);
        dev.delete_buffer(self.ibo);
        if let Some(vao) = self.vao {
            dev.delete_mesh_vertex_array(vao);
        }
    }
}

/// A one-chunk mesh whose arrays are bound ([`GpuMesh::bind_single_chunk`]).
pub struct BoundMesh {
    index_count: i32,
}

impl BoundMesh {
    /// Draws the mesh once more with the bound program.
    pub fn draw(&self, dev: &Device) {
        dev.count_draw_call();
        unsafe {
            dev.gl
                .draw_elements(glow::TRIANGLES, self.index_count, glow::UNSIGNED_SHORT, 0);
        }
    }

    /// Draws `instances` copies of the mesh with the bound program and instance arrays
    /// (ES 3.0).
    pub fn draw_instanced(&self, dev: &Device, instances: i32) {
        dev.count_draw_call();
        unsafe {
            dev.gl.draw_elements_instanced(
                glow::TRIANGLES,
                self.index_count,
                glow::UNSIGNED_SHORT,
                0,
                instances,
            );
        }
    }
}

/// A mesh uploaded as static vertex and index buffers.
pub struct GpuMesh {
    chunks: Vec<GpuChunk>,
    bytes: usize,
    /// The mesh's coordinate sets its vertices carry.
    uv_sets: UvSets,
    destroyed: bool,
}

impl GpuMesh {
    /// Uploads a mesh, every attribute it has.
    pub fn new(dev: &Device, mesh: &Mesh) -> Result<GpuMesh, GlError> {
        GpuMesh::new_about(dev, mesh, DVec3::ZERO, UvSets::ALL)
    }

    /// Uploads a mesh with its positions relative to `origin` (drawn with the model matrix
    /// translated by `origin`), and of its coordinate sets those of `uv_sets` only.
    pub fn new_about(
        dev: &Device,
        mesh: &Mesh,
        origin: DVec3,
        uv_sets: UvSets,
    ) -> Result<GpuMesh, GlError> {
        let mut out = GpuMesh {
            chunks: Vec::new(),
            bytes: 0,
            uv_sets: uv_sets.on(mesh),
            destroyed: false,
        };
        // A failed upload (out of memory, most likely) frees what it made: the caller may try
        // again next frame.
        let uploaded = out
            .upload_chunks(dev, mesh, origin, uv_sets)
            .and_then(|()| dev.check("mesh upload"));
        match uploaded {
            Ok(()) => Ok(out),
            Err(e) => {
                out.destroy(dev);
                Err(e)
            }
        }
    }

    /// Uploads the mesh's chunks into `self.chunks`, which holds every buffer made so far
    /// when it fails.
    fn upload_chunks(
        &mut self,
        dev: &Device,
        mesh: &Mesh,
        origin: DVec3,
        uv_sets: UvSets,
    ) -> Result<(), GlError> {
        for chunk in split_u16_about(mesh, origin, uv_sets) {
            self.chunks.push(GpuChunk::upload(dev, &chunk)?);
            self.bytes += chunk.vertices.len() * 4 + chunk.indices.len() * 2;
        }
        Ok(())
    }

    /// The mesh's coordinate sets its vertices carry.
    pub fn uv_sets(&self) -> UvSets {
        self.uv_sets
    }

    /// Draws all chunks with the bound program (attributes at [`super::program::ATTRIBUTES`]).
    pub fn draw(&self, dev: &Device) {
        for c in &self.chunks {
            c.bind_arrays(dev).draw(dev);
        }
    }

    /// A mesh of one chunk with its arrays bound for the bound program, to be drawn again and
    /// again with nothing but the draw call (deferred's proxies); `None` for a
    /// mesh of several chunks. Valid until other arrays or buffers are bound.
    pub fn bind_single_chunk(&self, dev: &Device) -> Option<BoundMesh> {
        match &self.chunks[..] {
            [c] => Some(c.bind_arrays(dev)),
            _ => None,
        }
    }

    /// GPU bytes held by the buffers.
    pub fn gpu_bytes(&self) -> usize {
        self.bytes
    }

    /// Frees the buffers.
    pub fn destroy(&mut self, dev: &Device) {
        if !self.destroyed {
            for c in self.chunks.drain(..) {
                c.destroy(dev);
            }
            self.destroyed = true;
        }
    }
}

impl Drop for GpuMesh {
    fn drop(&mut self) {
        if !self.destroyed && !super::left_objects::left_on_purpose() {
            log::warn!("GpuMesh dropped without destroy(): GL buffers leaked");
        }
    }
}

/// A new buffer bound to `target`, holding `bytes` for drawing.
fn static_buffer(dev: &Device, target: u32, bytes: &[u8]) -> Result<glow::Buffer, GlError> {
    let buffer = dev.create_buffer()?;
    unsafe {
        dev.gl.bind_buffer(target, Some(buffer));
        dev.gl
            .buffer_data_u8_slice(target, bytes, glow::STATIC_DRAW);
    }
    Ok(buffer)
}

/// One triangle covering the whole viewport in clip space (full-screen passes).
pub fn fullscreen_triangle() -> Mesh {
    let p = vec![
        glam::Vec3::new(-1.0, -1.0, 0.0),
        glam::Vec3::new(3.0, -1.0, 0.0),
        glam::Vec3::new(-1.0, 3.0, 0.0),
    ];
    Mesh::new(p, vec![], vec![], vec![0, 1, 2]).expect("valid triangle")
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn splits_large_meshes_into_u16_chunks_without_losing_triangles() {
        // 70 000 separate triangles = 210 000 vertices → at least 4 chunks.
        let n = 70_000u32;
        let positions: Vec<Vec3> = (0..n * 3)
            .map(|i| Vec3::new(i as f32, (i % 3) as f32, 0.0))
            .collect();
        let indices: Vec<u32> = (0..n * 3).collect();
        let mesh = Mesh::new(positions.clone(), vec![], vec![], indices).unwrap();
        let chunks = split_u16(&mesh);
        assert!(chunks.len() >= 4);
        let mut seen = 0;
        for c in &chunks {
            assert!(c.vertices.len() / VERTEX_FLOATS <= 65_536);
            for (k, &i) in c.indices.iter().enumerate() {
                let x = c.vertices[i as usize * VERTEX_FLOATS];
                assert_eq!(x, positions[seen + k].x);
            }
            seen += c.indices.len();
        }
        assert_eq!(seen, (n * 3) as usize);
    }
}
