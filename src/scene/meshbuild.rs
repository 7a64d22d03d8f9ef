//! A small builder for the procedural built-in scenes: boxes, cylinders, quads and arches with
//! hard (per-face) normals where edges are sharp and smooth normals on curved sides.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};

use super::Mesh;

/// Accumulates triangles; [`MeshBuilder::build`] turns them into a [`Mesh`].
#[derive(Default)]
pub struct MeshBuilder {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    indices: Vec<u32>,
}

impl MeshBuilder {
    /// An empty builder.
    pub fn new() -> Self {
        Self::default()
    }

    fn vertex(&mut self, p: Vec3, n: Vec3, uv: Vec2) -> u32 {
        self.positions.push(p);
        self.normals.push(n);
        self.uvs.push(uv);
        (self.positions.len() - 1) as u32
    }

    /// A planar quad `a b c d` counter-clockwise when seen from the side its normal faces.
    /// Texture coordinates are in world units so textures tile at a constant scale.
    pub fn quad(&mut self, a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> &mut Self {
        let n = (b - a).cross(d - a).normalize_or(Vec3::Y);
        let (u_len, v_len) = ((b - a).length(), (d - a).length());
        let i0 = self.vertex(a, n, Vec2::new(0.0, 0.0));
        let i1 = self.vertex(b, n, Vec2::new(u_len, 0.0));
        let i2 = self.vertex(c, n, Vec2::new(u_len, v_len));
        let i3 = self.vertex(d, n, Vec2::new(0.0, v_len));
        self.indices.extend_from_slice(&[i0, i1, i2, i0, i2, i3]);
        self
    }

    /// An axis-aligned box with outward faces.
    pub fn cuboid(&mut self, min: Vec3, max: Vec3) -> &mut Self {
        let p = |x: bool, y: bool, z: bool| {
            Vec3::new(
                if x { max.x } else { min.x },
                if y { max.y } else { min.y },
                if z { max.z } else { min.z },
            )
        };
        let (f, t) = (false, true);
        self.quad(p(f, f, t), p(t, f, t), p(t, t, t), p(f, t, t)); // +Z
        self.quad(p(t, f, f), p(f, f, f), p(f, t, f), p(t, t, f)); // −Z
        self.quad(p(t, f, t), p(t, f, f), p(t, t, f), p(t, t, t)); // +X
        self.quad(p(f, f, f), p(f, f, t), p(f, t, t), p(f, t, f)); // −X
        self.quad(p(f, t, t), p(t, t, t), p(t, t, f), p(f, t, f)); // +Y
        self.quad(p(f, f, f), p(t, f, f), p(t, f, t), p(f, f, t)) // −Y
    }

    /// A vertical cylinder standing on `base` with smooth sides and flat caps.
    pub fn cylinder(&mut self, base: Vec3, radius: f32, height: f32, segments: u32) -> &mut Self {
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
        self
    }

    /// A UV sphere with smooth normals, counter-clockwise seen from outside.
    pub fn sphere(&mut self, centre: Vec3, radius: f32, segments: u32, rings: u32) -> &mut Self {
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
        self
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
            self.quad(o0 + dz, o1 + dz, i1 + dz, i0 + dz) // front (+Z)
                .quad(i0 - dz, i1 - dz, o1 - dz, o0 - dz) // back
                .quad(i0 + dz, i1 + dz, i1 - dz, i0 - dz) // intrados, faces the opening
                .quad(o0 - dz, o1 - dz, o1 + dz, o0 + dz); // extrados
        }
        self
    }

    /// The accumulated mesh. Panics never: the builder only produces valid indices.
    pub fn build(self) -> Mesh {
        Mesh::new(self.positions, self.normals, self.uvs, self.indices)
            .expect("MeshBuilder produces valid meshes")
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
            b.build()
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
        let m = b.build();
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
        let m = b.build();
        for t in m.indices.chunks(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| m.positions[i as usize]);
            let face = (b - a).cross(c - a);
            assert!(
                face.dot(m.normals[t[0] as usize]) > 0.0,
                "winding disagrees with normal"
            );
        }
    }
}
