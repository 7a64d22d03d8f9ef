//! A small builder for meshes made in code (the procedural built-in scenes among them):
//! boxes, cylinders, spheres, quads and arches with hard (per-face) normals where edges are
//! sharp and smooth normals on curved sides.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::mesh::{MAX_TEXCOORD, MAX_VERTEX_COORD};
use super::{Mesh, SceneError};

/// Most vertices one [`MeshBuilder`] holds (32 bytes each, and up to six 4-byte indices: about
/// 2 GiB at most), as many as one glTF file may decode into. A shape that would pass it adds
/// nothing and [`MeshBuilder::build`] names it.
pub const MAX_BUILT_VERTICES: usize = 1 << 25;

/// Accumulates triangles; [`MeshBuilder::build`] turns them into a [`Mesh`].
///
/// A shape whose values cannot make a mesh (a NaN radius, a sphere of zero segments, vertices
/// past ±1e9, more than 2²⁵ vertices) adds nothing, and `build`
/// returns the error naming the first such shape and value.
#[derive(Default)]
pub struct MeshBuilder {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    indices: Vec<u32>,
    refused: Option<SceneError>,
}

impl MeshBuilder {
    /// An empty builder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Runs `add` (which adds `vertices` vertices and at most `indices` indices) when the
    /// builder has room for them, asked of the allocator first, and keeps what it added only
    /// when every new position is finite and within range.
    fn shape(
        &mut self,
        name: &str,
        vertices: u64,
        indices: u64,
        add: impl FnOnce(&mut Self),
    ) -> &mut Self {
        if self.refused.is_some() {
            return self;
        }
        let start = (self.positions.len(), self.indices.len());
        if vertices > (MAX_BUILT_VERTICES - start.0) as u64 {
            self.refused = Some(SceneError::invalid(
                format!("MeshBuilder::{name}"),
                format!(
                    "{vertices} vertices, past the {MAX_BUILT_VERTICES} one builder holds \
                     ({} already)",
                    start.0
                ),
            ));
            return self;
        }
        // Below MAX_BUILT_VERTICES, so within usize; indices are at most six a vertex.
        if let Err(bytes) = self.reserve(vertices as usize, indices as usize) {
            self.refused = Some(SceneError::invalid(
                format!("MeshBuilder::{name}"),
                format!(
                    "{vertices} vertices need about {} MiB more, which this process cannot \
                     allocate now",
                    bytes.div_ceil(1 << 20)
                ),
            ));
            return self;
        }
        add(self);
        let placed = |p: &Vec3| p.is_finite() && p.abs().max_element() <= MAX_VERTEX_COORD;
        if let Some(p) = self.positions[start.0..].iter().find(|p| !placed(p)) {
            self.refused = Some(SceneError::invalid(
                format!("MeshBuilder::{name}"),
                format!(
                    "its values give a vertex at {p:?}: vertices must be finite and within \
                     ±{MAX_VERTEX_COORD:e}"
                ),
            ));
            self.positions.truncate(start.0);
            self.normals.truncate(start.0);
            self.uvs.truncate(start.0);
            self.indices.truncate(start.1);
        }
        self
    }

    /// Room for `vertices` more vertices and `indices` more indices, grown as a `Vec` grows
    /// (exactly where that is refused); `Err` with the bytes asked for where even that is.
    fn reserve(&mut self, vertices: usize, indices: usize) -> Result<(), u64> {
        fn room<T>(v: &mut Vec<T>, more: usize) -> bool {
            v.try_reserve(more).is_ok() || v.try_reserve_exact(more).is_ok()
        }
        let granted = room(&mut self.positions, vertices)
            && room(&mut self.normals, vertices)
            && room(&mut self.uvs, vertices)
            && room(&mut self.indices, indices);
        match granted {
            true => Ok(()),
            false => Err(vertices as u64 * 32 + indices as u64 * 4),
        }
    }

    /// Texture coordinates are capped at ±[`MAX_TEXCOORD`] (world lengths past it tile at no
    /// visible scale).
    fn vertex(&mut self, p: Vec3, n: Vec3, uv: Vec2) -> u32 {
        self.positions.push(p);
        self.normals.push(n);
        self.uvs
            .push(uv.clamp(Vec2::splat(-MAX_TEXCOORD), Vec2::splat(MAX_TEXCOORD)));
        // Below MAX_BUILT_VERTICES (checked in `shape`), so within u32.
        (self.positions.len() - 1) as u32
    }

    /// A planar quad `a b c d` counter-clockwise when seen from the side its normal faces.
    /// Texture coordinates are in world units so textures tile at a constant scale.
    pub fn quad(&mut self, a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> &mut Self {
        self.shape("quad", 4, 6, |s| s.add_quad(a, b, c, d))
    }

    fn add_quad(&mut self, a: Vec3, b: Vec3, c: Vec3, d: Vec3) {
        let n = (b - a).cross(d - a).normalize_or(Vec3::Y);
        let (u_len, v_len) = ((b - a).length(), (d - a).length());
        let i0 = self.vertex(a, n, Vec2::new(0.0, 0.0));
        let i1 = self.vertex(b, n, Vec2::new(u_len, 0.0));
        let i2 = self.vertex(c, n, Vec2::new(u_len, v_len));
        let i3 = self.vertex(d, n, Vec2::new(0.0, v_len));
        self.indices.extend_from_slice(&[i0, i1, i2, i0, i2, i3]);
    }

    /// An axis-aligned box with outward faces.
    pub fn cuboid(&mut self, min: Vec3, max: Vec3) -> &mut Self {
        let p = move |x: bool, y: bool, z: bool| {
            Vec3::new(
                if x { max.x } else { min.x },
                if y { max.y } else { min.y },
                if z { max.z } else { min.z },
            )
        };
        let (f, t) = (false, true);
        self.shape("cuboid", 24, 36, |s| {
            s.add_quad(p(f, f, t), p(t, f, t), p(t, t, t), p(f, t, t)); // +Z
            s.add_quad(p(t, f, f), p(f, f, f), p(f, t, f), p(t, t, f)); // −Z
            s.add_quad(p(t, f, t), p(t, f, f), p(t, t, f), p(t, t, t)); // +X
            s.add_quad(p(f, f, f), p(f, f, t), p(f, t, t), p(f, t, f)); // −X
            s.add_quad(p(f, t, t), p(t, t, t), p(t, t, f), p(f, t, f)); // +Y
            s.add_quad(p(f, f, f), p(t, f, f), p(t, f, t), p(f, f, t)); // −Y
        })
    }

    /// A vertical cylinder standing on `base` with smooth sides and flat caps.
    pub fn cylinder(&mut self, base: Vec3, radius: f32, height: f32, segments: u32) -> &mut Self {
        let segments_64 = u64::from(segments);
        self.shape("cylinder", 10 * segments_64, 12 * segments_64, |s| {
            s.add_cylinder(base, radius, height, segments)
        })
    }

    fn add_cylinder(&mut self, base: Vec3, radius: f32, height: f32, segments: u32) {
        let top = base + Vec3::Y * height;
        let ring = |i: u32| {
            let a = i as f32 / segments as f32 * 2.0 * PI;
            Vec3::new(a.cos(), 0.0, -a.sin())
        };
        for i in 0..segments {
            let (d0, d1) = (ring(i), ring(i + 1));
            let u0 = i as f32 / segments as f32 * 2.0 * PI * radius;
            let u1 = (i + 1) as f32 / segments as f32 * 2.0 * PI * radius;
            let a = self.vertex(base + d0 * radius, d0, Vec2::new(u0, 0.0));
            let b = self.vertex(base + d1 * radius, d1, Vec2::new(u1, 0.0));
            let c = self.vertex(top + d1 * radius, d1, Vec2::new(u1, height));
            let d = self.vertex(top + d0 * radius, d0, Vec2::new(u0, height));
            self.indices.extend_from_slice(&[a, b, c, a, c, d]);
            for (centre, n, flip) in [(top, Vec3::Y, false), (base, -Vec3::Y, true)] {
                let c0 = self.vertex(centre, n, Vec2::ZERO);
                let c1 = self.vertex(centre + d0 * radius, n, Vec2::new(d0.x, d0.z) * radius);
                let c2 = self.vertex(centre + d1 * radius, n, Vec2::new(d1.x, d1.z) * radius);
                if flip {
                    self.indices.extend_from_slice(&[c0, c2, c1]);
                } else {
                    self.indices.extend_from_slice(&[c0, c1, c2]);
                }
            }
        }
    }

    /// A UV sphere with smooth normals, counter-clockwise seen from outside. `segments` and
    /// `rings` must be at least 1.
    pub fn sphere(&mut self, centre: Vec3, radius: f32, segments: u32, rings: u32) -> &mut Self {
        if self.refused.is_none() && (segments == 0 || rings == 0) {
            self.refused = Some(SceneError::invalid(
                "MeshBuilder::sphere",
                format!("segments and rings must be at least 1, got {segments} and {rings}"),
            ));
        }
        // Saturating: (2³²)² is past u64, and would wrap to 0 vertices.
        let vertices = (segments as u64 + 1).saturating_mul(rings as u64 + 1);
        let indices = u64::from(segments)
            .saturating_mul(u64::from(rings))
            .saturating_mul(6);
        self.shape("sphere", vertices, indices, |s| {
            s.add_sphere(centre, radius, segments, rings)
        })
    }

    fn add_sphere(&mut self, centre: Vec3, radius: f32, segments: u32, rings: u32) {
        let first = self.positions.len() as u32;
        for ring in 0..=rings {
            let theta = ring as f32 / rings as f32 * PI;
            for seg in 0..=segments {
                let phi = seg as f32 / segments as f32 * 2.0 * PI;
                let n = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    -theta.sin() * phi.sin(),
                );
                self.vertex(
                    centre + n * radius,
                    n,
                    Vec2::new(seg as f32 / segments as f32, ring as f32 / rings as f32),
                );
            }
        }
        // Every index is below the vertex count, which `shape` keeps within u32.
        let row = segments + 1;
        for ring in 0..rings {
            for seg in 0..segments {
                let a = first + ring * row + seg;
                let (b, c, d) = (a + row, a + row + 1, a + 1);
                // Skip the degenerate triangles at the poles.
                if ring != 0 {
                    self.indices.extend_from_slice(&[a, b, d]);
                }
                if ring != rings - 1 {
                    self.indices.extend_from_slice(&[d, b, c]);
                }
            }
        }
    }

    /// A semicircular arch in the XY plane (spanning along X) centred at `centre` (the
    /// springing line's midpoint), made of `segments` voussoir blocks of the given thickness
    /// (radial) and depth (along Z).
    pub fn arch_x(
        &mut self,
        centre: Vec3,
        radius: f32,
        thickness: f32,
        depth: f32,
        segments: u32,
    ) -> &mut Self {
        let segments_64 = u64::from(segments);
        self.shape("arch_x", 16 * segments_64, 24 * segments_64, |s| {
            let (r0, r1) = (radius, radius + thickness);
            let dz = Vec3::Z * (depth * 0.5);
            for i in 0..segments {
                let a0 = i as f32 / segments as f32 * PI;
                let a1 = (i + 1) as f32 / segments as f32 * PI;
                let d0 = Vec3::new(a0.cos(), a0.sin(), 0.0);
                let d1 = Vec3::new(a1.cos(), a1.sin(), 0.0);
                let (i0, i1, o0, o1) = (
                    centre + d0 * r0,
                    centre + d1 * r0,
                    centre + d0 * r1,
                    centre + d1 * r1,
                );
                s.add_quad(o0 + dz, o1 + dz, i1 + dz, i0 + dz); // front (+Z)
                s.add_quad(i0 - dz, i1 - dz, o1 - dz, o0 - dz); // back
                s.add_quad(i0 + dz, i1 + dz, i1 - dz, i0 - dz); // intrados, faces the opening
                s.add_quad(o0 - dz, o1 - dz, o1 + dz, o0 + dz); // extrados
            }
        })
    }

    /// The accumulated mesh, or the error naming the first shape whose values could not make
    /// one (see [`MeshBuilder`]).
    pub fn build(self) -> Result<Mesh, SceneError> {
        if let Some(e) = self.refused {
            return Err(e);
        }
        Mesh::new(self.positions, self.normals, self.uvs, self.indices)
    }

    /// [`MeshBuilder::build`] for the library's own fixed shapes (built-in scenes, the
    /// deferred light volume), whose constant values always make a mesh.
    pub(crate) fn build_fixed(self) -> Mesh {
        self.build().expect("fixed shapes make valid meshes")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cuboid_normals_point_outwards() {
        let m = {
            let mut b = MeshBuilder::new();
            b.cuboid(Vec3::splat(-1.0), Vec3::splat(1.0));
            b.build().unwrap()
        };
        assert_eq!(m.triangle_count(), 12);
        for (p, n) in m.positions.iter().zip(&m.normals) {
            assert!(p.dot(*n) > 0.0, "normal {n:?} at {p:?} points inwards");
        }
        // Winding agrees with the normal (counter-clockwise seen from outside).
        for t in m.indices.chunks(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| m.positions[i as usize]);
            let face = (b - a).cross(c - a);
            assert!(face.dot(m.normals[t[0] as usize]) > 0.0);
        }
    }

    #[test]
    fn sphere_winding_faces_outwards() {
        let mut b = MeshBuilder::new();
        b.sphere(Vec3::new(1.0, 2.0, 3.0), 0.5, 16, 8);
        let m = b.build().unwrap();
        for t in m.indices.chunks(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| m.positions[i as usize]);
            let face = (b - a).cross(c - a);
            let outward = (a + b + c) / 3.0 - Vec3::new(1.0, 2.0, 3.0);
            assert!(face.dot(outward) > 0.0, "inward triangle");
        }
    }

    #[test]
    fn cylinder_side_normals_are_radial() {
        let mut b = MeshBuilder::new();
        b.cylinder(Vec3::ZERO, 0.5, 2.0, 12);
        let m = b.build().unwrap();
        for t in m.indices.chunks(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| m.positions[i as usize]);
            let face = (b - a).cross(c - a);
            assert!(
                face.dot(m.normals[t[0] as usize]) > 0.0,
                "winding disagrees with normal"
            );
        }
    }

    /// Values a game may pass from a slider or a level file: each is refused naming the shape,
    /// with nothing added and no panic, and the shapes before it are kept out of the mesh.
    #[test]
    fn shapes_that_cannot_make_a_mesh_are_refused_naming_the_shape() {
        let refused = |add: &dyn Fn(&mut MeshBuilder)| {
            let mut b = MeshBuilder::new();
            b.cuboid(Vec3::ZERO, Vec3::ONE);
            add(&mut b);
            assert_eq!(b.positions.len(), 24, "a refused shape added vertices");
            b.build().unwrap_err().to_string()
        };
        let e = refused(&|b| {
            b.sphere(Vec3::ZERO, 1.0, 0, 8);
        });
        assert!(
            e.contains("MeshBuilder::sphere") && e.contains("at least 1"),
            "{e}"
        );
        let e = refused(&|b| {
            b.sphere(Vec3::ZERO, 1.0, 8, 0);
        });
        assert!(e.contains("MeshBuilder::sphere"), "{e}");
        // 2³² vertices: refused before any is pushed (this would take 128 GiB).
        let e = refused(&|b| {
            b.sphere(Vec3::ZERO, 1.0, u32::MAX, 1);
        });
        assert!(
            e.contains("MeshBuilder::sphere") && e.contains("past the"),
            "{e}"
        );
        // 2⁶⁴ vertices, past u64: they wrapped to 0 and were pushed without end.
        let e = refused(&|b| {
            b.sphere(Vec3::ZERO, 1.0, u32::MAX, u32::MAX);
        });
        assert!(e.contains("past the"), "{e}");
        let e = refused(&|b| {
            b.cylinder(Vec3::ZERO, 1.0, 1.0, u32::MAX);
        });
        assert!(e.contains("MeshBuilder::cylinder"), "{e}");
        let e = refused(&|b| {
            b.cylinder(Vec3::ZERO, f32::NAN, 1.0, 8);
        });
        assert!(
            e.contains("MeshBuilder::cylinder") && e.contains("finite"),
            "{e}"
        );
        let e = refused(&|b| {
            b.quad(Vec3::ZERO, Vec3::X * 2e9, Vec3::ONE, Vec3::Y);
        });
        assert!(e.contains("MeshBuilder::quad"), "{e}");
        let e = refused(&|b| {
            b.arch_x(Vec3::ZERO, f32::INFINITY, 1.0, 1.0, 4);
        });
        assert!(e.contains("MeshBuilder::arch_x"), "{e}");
        // The first refusal is the one named; later shapes add nothing.
        let e = refused(&|b| {
            b.sphere(Vec3::ZERO, 1.0, 0, 0)
                .cuboid(Vec3::ZERO, Vec3::ONE);
        });
        assert!(e.contains("MeshBuilder::sphere"), "{e}");
    }

    /// World-length texture coordinates of a large but valid box pass the texture coordinate
    /// limit; they are capped there, so the mesh builds.
    #[test]
    fn a_box_as_large_as_vertices_may_be_builds() {
        let mut b = MeshBuilder::new();
        b.cuboid(Vec3::splat(-6e8), Vec3::splat(6e8))
            .cylinder(Vec3::ZERO, 1.6e8, 1.0, 8);
        let m = b.build().unwrap();
        assert!(m.uvs.iter().any(|t| t.max_element() == MAX_TEXCOORD));
        assert_eq!(m.triangle_count(), 12 + 8 * 4);
    }
}
